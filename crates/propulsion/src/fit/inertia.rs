//! Rotor inertia (and ESC delay) from a measured step response.
//!
//! With the motor constants, resistance and load coefficient known, the step response of eq (2)
//! depends on the total inertia `J_r` (and on the ESC dead time). Both are fitted by simulating
//! eq (2) with RK4 and minimising the RMSE of the measured speed. This replaces the seed's
//! procedure (fitting a first-order response, eq 6, and inverting eq 7) by a fit of the
//! nonlinear model itself.

use super::{check_columns, minimize, rmse};
use crate::error::PropulsionError;
use crate::transient::RotorTransient;

/// Result of an inertia fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaFit {
    /// Total rotor inertia `J_m + J_p`, kg m^2.
    pub inertia_kgm2: f64,
    /// ESC dead time, s.
    pub delay_s: f64,
    /// RMSE of the speed, rad/s.
    pub rmse_radps: f64,
}

/// Simulates `rotor` with total inertia `j` and delay, sampled at `time_s` (linear interpolation).
fn simulate_at(
    rotor: &RotorTransient,
    j: f64,
    delay_s: f64,
    from: f64,
    to: f64,
    time_s: &[f64],
    dt_s: f64,
) -> Option<Vec<f64>> {
    let r = rotor.with_total_inertia(j).with_delay(delay_s);
    let t_end = time_s.iter().fold(0.0f64, |a, &b| a.max(b)) + dt_s;
    let resp = r.simulate_step(from, to, t_end.max(dt_s * 2.0), dt_s).ok();
    let (ts, ws) = match resp {
        Some(s) => (s.time_s, s.speed_radps),
        None => return None,
    };
    Some(
        time_s
            .iter()
            .map(|&t| {
                let k = ((t / dt_s).floor() as usize).min(ts.len() - 2);
                let a = (t - ts[k]) / dt_s;
                ws[k] + a * (ws[k + 1] - ws[k])
            })
            .collect(),
    )
}

/// Fits the total inertia (and, if `fit_delay`, the ESC delay) of `rotor` to a measured step
/// from `from_radps` to `to_radps` commanded at `t = 0`. `time_s` must be non-negative.
///
/// # Errors
/// Mismatched or non-finite columns, fewer than 5 samples, an invalid step, a failed fit.
pub fn fit_rotor_inertia(
    rotor: &RotorTransient,
    from_radps: f64,
    to_radps: f64,
    time_s: &[f64],
    speed_radps: &[f64],
    fit_delay: bool,
) -> Result<InertiaFit, PropulsionError> {
    check_columns(
        "rotor inertia",
        &[("time_s", time_s), ("speed_radps", speed_radps)],
        5,
    )?;
    if let Some((index, &value)) = time_s.iter().enumerate().find(|(_, &t)| t < 0.0) {
        return Err(PropulsionError::NonFiniteData {
            what: "time_s (negative)",
            index,
            value,
        });
    }
    // Validate the step once.
    rotor.summary(from_radps, to_radps)?;
    let tau0 = rotor.time_constant_linearised_s(to_radps);
    let dt = (tau0 / 100.0).clamp(1e-6, 1e-4);
    let j0 = rotor.inertia_kgm2();
    let cost = |p: &[f64]| {
        let j = p[0].exp();
        let delay = if fit_delay {
            p[1].abs()
        } else {
            rotor.delay_s()
        };
        match simulate_at(rotor, j, delay, from_radps, to_radps, time_s, dt) {
            Some(w) => w
                .iter()
                .zip(speed_radps)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>(),
            None => f64::INFINITY,
        }
    };
    let (p, _) = if fit_delay {
        minimize(
            "rotor inertia",
            cost,
            &[j0.ln(), rotor.delay_s()],
            &[0.3, 0.2 * tau0],
            400,
        )?
    } else {
        minimize("rotor inertia", cost, &[j0.ln()], &[0.3], 200)?
    };
    let j = p[0].exp();
    let delay = if fit_delay {
        p[1].abs()
    } else {
        rotor.delay_s()
    };
    let w = simulate_at(rotor, j, delay, from_radps, to_radps, time_s, dt).ok_or(
        PropulsionError::FitDidNotConverge {
            model: "rotor inertia",
        },
    )?;
    Ok(InertiaFit {
        inertia_kgm2: j,
        delay_s: delay,
        rmse_radps: rmse(w.iter().zip(speed_radps).map(|(a, b)| a - b)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transient::RotorConstants;

    #[test]
    fn recovers_inertia_and_delay_from_a_simulated_step() {
        let truth = RotorTransient::new(RotorConstants {
            kt_nm_per_a: 4e-3,
            resistance_ohm: 0.12,
            no_load_current_a: 0.4,
            supply_voltage_v: 11.1,
            motor_inertia_kgm2: 1.1e-6,
            prop_inertia_kgm2: 2.4e-6,
            torque_coefficient_nms2: 1.4e-8,
            delay_s: 0.004,
        })
        .unwrap();
        // sampled at 130 Hz like the seed's dynamometer
        let t: Vec<f64> = (0..40).map(|k| k as f64 / 130.0).collect();
        let s = truth.simulate_step(800.0, 1400.0, 0.31, 1e-5).unwrap();
        let w: Vec<f64> = t
            .iter()
            .map(|&x| s.speed_radps[((x / 1e-5).round() as usize).min(s.speed_radps.len() - 1)])
            .collect();
        let start = truth.with_prop_inertia(1.0e-6).with_delay(0.0);
        let f = fit_rotor_inertia(&start, 800.0, 1400.0, &t, &w, true).unwrap();
        // noise-free samples: inertia within 1 %, delay within 0.5 ms
        assert!((f.inertia_kgm2 / 3.5e-6 - 1.0).abs() < 0.01, "{f:?}");
        assert!((f.delay_s - 0.004).abs() < 5e-4, "{f:?}");
    }
}
