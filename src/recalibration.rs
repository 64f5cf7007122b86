//! In-flight re-calibration of the efficiency that cannot do worse than none on average: the
//! estimate from measured power, shrunk toward the fitted efficiency by the uncertainty of each.
//!
//! The power seed's efficiency (eq 14, `P_hat = P_req / eta`) is the one constant that a
//! measured power re-estimates in flight. Over a window the least-biased estimate is the energy
//! ratio `r_d = E_measured / E_predicted` (`eta_d = eta_0 / r_d`). Two minutes of a flight do
//! not predict the rest of it exactly: the ratio drifts with gusts, manoeuvres and the pack. Taken
//! alone (`r = r_d`), it made the leave-one-day-out error worse on some KAIST flights than no
//! calibration at all.
//!
//! Both the fitted model and the window are estimates of the rest of the flight's ratio, each
//! with an uncertainty, so the combination with the least expected squared error weighs each by
//! the inverse of its variance (on the log scale, where a ratio's errors are symmetric):
//!
//! `ln r = w ln r_d`, `w = s_p^2 / (s_p^2 + s_d^2)`,
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `r_d` | measured over predicted energy in the window | - |
//! | `s_p` | prior: relative spread of the efficiency between the fitted flights (`efficiency_relative_sd` of the vehicle file, from `aloft fit`) | - |
//! | `s_d` | relative standard error of `r_d`: `sd(e) / (mean(P_measured) sqrt(n_eff))` | - |
//! | `e` | residual `P_measured - r_d P_predicted` in the window | W |
//! | `n_eff` | effective sample size `n / tau`, `tau = 1 + 2 sum_k rho_k` over the residual's autocorrelations up to the first that is not positive | - |
//!
//! Samples at 10 Hz are not independent (a residual stays on one side for tens of seconds), so
//! `n` samples carry the information of `n / tau`; with `n` the window's ratio would look ten or
//! more times surer than it is. The shrinkage is James-Stein's and Kalman's measurement update
//! in one step: with the two variances right its expected squared error is below that of either
//! estimate alone, so on average it does no worse than no calibration. The alternative, a
//! recursive estimate with a forgetting factor, needs a forgetting time that nothing in the
//! data fixes (it would be tuned to the days at hand) and still starts from a two-minute
//! estimate; the shrinkage takes both variances from the data: the prior's from the fit's flights,
//! the window's from the window itself.
//!
//! Without a prior spread (a vehicle file written by hand, or fitted on one log) the window's
//! ratio is taken alone, as before.

use serde::Serialize;

/// The shrunk re-estimate of one window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Shrunk {
    /// Measured over predicted energy in the window alone, `r_d`.
    pub window_ratio: f64,
    /// The shrunk ratio `r` applied to the predictions.
    pub ratio: f64,
    /// Weight `w` of the window (0: the fit alone, 1: the window alone).
    pub window_weight: f64,
    /// Relative standard error of the window's ratio, `s_d`.
    pub window_relative_sd: f64,
    /// Effective sample size of the window, `n_eff`.
    pub effective_samples: f64,
}

/// Effective sample size of a series, `n / tau` with `tau = 1 + 2 sum rho_k` summed while the
/// autocorrelation `rho_k` stays positive (at most `n / 2` lags); `n` for a series without
/// variance.
pub fn effective_sample_size(residuals: &[f64]) -> f64 {
    let n = residuals.len();
    let mean = residuals.iter().sum::<f64>() / n.max(1) as f64;
    let centred: Vec<f64> = residuals.iter().map(|r| r - mean).collect();
    let c0: f64 = centred.iter().map(|r| r * r).sum();
    if n < 3 || c0 <= 0.0 {
        return n as f64;
    }
    let mut tau = 1.0;
    for k in 1..n / 2 {
        let ck: f64 = centred.iter().zip(&centred[k..]).map(|(a, b)| a * b).sum();
        let rho = ck / c0;
        if rho <= 0.0 {
            break;
        }
        tau += 2.0 * rho;
    }
    (n as f64 / tau).clamp(1.0, n as f64)
}

/// The window's ratio shrunk toward 1 (the fitted model) by the prior spread
/// `prior_relative_sd` (see the module docs). `measured_w` and `predicted_w` are the window's
/// samples (equal lengths, at least two); `window_ratio` is its energy ratio.
pub fn shrink(
    window_ratio: f64,
    measured_w: &[f64],
    predicted_w: &[f64],
    prior_relative_sd: Option<f64>,
) -> Shrunk {
    let residuals: Vec<f64> = measured_w
        .iter()
        .zip(predicted_w)
        .map(|(m, p)| m - window_ratio * p)
        .collect();
    let n = residuals.len().max(1) as f64;
    let mean_measured = measured_w.iter().sum::<f64>() / n;
    let sd = (residuals.iter().map(|r| r * r).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    let effective_samples = effective_sample_size(&residuals);
    let window_relative_sd = sd / (mean_measured * effective_samples.sqrt());
    let window_weight = match prior_relative_sd {
        Some(sp) if window_relative_sd.is_finite() => {
            let (vp, vd) = (sp * sp, window_relative_sd * window_relative_sd);
            if vp + vd > 0.0 {
                vp / (vp + vd)
            } else {
                1.0
            }
        }
        _ => 1.0,
    };
    Shrunk {
        window_ratio,
        ratio: (window_weight * window_ratio.ln()).exp(),
        window_weight,
        window_relative_sd,
        effective_samples,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn independent_noise_counts_every_sample_and_a_slow_drift_few() {
        // A deterministic pseudo-random sequence (xorshift64) with no serial correlation.
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let white: Vec<f64> = (0..1000)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let n_white = effective_sample_size(&white);
        assert!(n_white > 500.0, "{n_white}");
        // A sine of period 200 samples: strongly correlated over tens of samples.
        let slow: Vec<f64> = (0..1000)
            .map(|i| (i as f64 / 200.0 * std::f64::consts::TAU).sin())
            .collect();
        let n_slow = effective_sample_size(&slow);
        assert!(n_slow < 30.0, "{n_slow}");
    }

    #[test]
    fn shrinkage_weighs_by_the_variances_and_keeps_the_window_without_a_prior() {
        let predicted = vec![1000.0; 400];
        let measured: Vec<f64> = (0..400)
            .map(|i| 1040.0 + 60.0 * (i as f64 / 40.0).sin())
            .collect();
        let r = measured.iter().sum::<f64>() / predicted.iter().sum::<f64>();
        let alone = shrink(r, &measured, &predicted, None);
        assert!((alone.ratio - r).abs() < 1e-12 && (alone.window_weight - 1.0).abs() < 1e-12);
        let sure_prior = shrink(r, &measured, &predicted, Some(1e-6));
        assert!((sure_prior.ratio - 1.0).abs() < 1e-6, "{sure_prior:?}");
        let equal = shrink(r, &measured, &predicted, Some(alone.window_relative_sd));
        assert!((equal.window_weight - 0.5).abs() < 1e-12, "{equal:?}");
        assert!((equal.ratio - r.sqrt()).abs() < 1e-12);
    }
}
