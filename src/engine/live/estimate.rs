//! The efficiency of the flight so far, as a ratio of measured to predicted energy, with how sure
//! it is: what every update of `aloft live` predicts the rest with.
//!
//! 1. the ratio `r_d = E_measured / E_predicted` over the samples so far (trapezoid rule) is
//!    shrunk toward the fitted model by the uncertainty of each ([`crate::recalibration`]; power
//!    seed eqs 7 and 14): `r = exp(w ln r_d)`;
//! 2. its spread on the log scale is the sum of two variances: the estimate's, `w s_d^2 =
//!    s_p^2 s_d^2 / (s_p^2 + s_d^2)` (the fit's spread `s_p` between flights, or the scenarios'
//!    3 % model error for a vehicle without one, with the window's standard error `s_d`), and
//!    the drift of the ratio along the flight: the variance of the log ratios of the 60 s blocks
//!    so far over the number of independent blocks the rest holds (blocks that drift together
//!    counted by their autocorrelation);
//! 3. and at least the estimator's own record on this flight (prequential): at the end of every
//!    60 s block so far, the ratio up to there against the ratio from there to now, root mean
//!    square. Both variances above assume the ratio of the rest is the ratio so far plus noise;
//!    on the held-out KAIST flights it is not (a steady offset of 1-2 % between the parts of a
//!    flight), and the record sees it: the p5-p95 band held the measured rest in 68 % of the
//!    updates with the two variances alone, 90 % with the record (docs/validation.md).
//!
//! Memory is bounded whatever the flight's length: the samples are kept as at most
//! [`MAX_POINTS`] points, each the mean of `2^level` consecutive samples; when the buffer fills,
//! neighbours merge and the level goes up. The energies are running sums of every sample, so the
//! ratio is exact; the spread is computed from the points (the same as from the samples up to
//! [`MAX_POINTS`] samples: every shared KAIST flight).

use aloft_core::Trapezoid;

/// Shortest window the efficiency is re-estimated from, s: before it the fitted model alone.
pub(crate) const MIN_WINDOW_S: f64 = 10.0;

/// Length of the blocks whose ratios measure how the ratio drifts along a flight, s.
const DRIFT_BLOCK_S: f64 = 60.0;

/// Most points kept (a power of two).
pub(crate) const MAX_POINTS: usize = 16_384;

/// Lowest efficiency a vehicle is flown at (a ratio of measured to predicted power above 100
/// times the fitted efficiency is not a vehicle the file describes).
const MIN_EFFICIENCY: f64 = 0.01;

/// What an update says where the efficiency is held at 1.
pub(crate) const EFFICIENCY_HELD_NOTE: &str = "the measured power is below the model's at any \
    efficiency up to 1: the vehicle file does not describe this vehicle (the rest is flown at \
    efficiency 1)";

/// The efficiency the rest is flown at and reported: the fitted `eta0` over the re-estimated
/// `ratio` of measured to predicted power, held in `[0.01, 1]` (above 1 the measured power is
/// below the model's at any efficiency: the rest is flown at 1, as the update's note says); the
/// fitted one where the ratio gives no number.
pub(crate) fn flown_efficiency(eta0: f64, ratio: f64) -> f64 {
    let eta = eta0 / ratio;
    match eta.is_finite() {
        true => eta.clamp(MIN_EFFICIENCY, 1.0),
        false => eta0,
    }
}

/// The fitted model's relative spread between flights (its vehicle file's
/// `efficiency_relative_sd`), else the model error the scenarios assume.
pub(crate) fn prior_sd(model: &aloft_power::PowerModel) -> f64 {
    model
        .vehicle()
        .params()
        .efficiency_relative_sd
        .unwrap_or(crate::engine::uncertainty::scenarios::DEFAULT_POWER_SD_PERCENT / 100.0)
}

/// The ratio of the rest and its spread.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ratio {
    /// Measured over predicted power for the rest, `r`.
    pub ratio: f64,
    /// Standard deviation of `ln r`.
    pub log_sd: f64,
}

/// Measured against predicted power, sample by sample (see the module docs).
#[derive(Debug, Clone)]
pub(crate) struct RatioEstimator {
    prior_sd: f64,
    measured_j: Trapezoid,
    predicted_j: Trapezoid,
    first_s: Option<f64>,
    /// Points: end time, mean measured and mean predicted power of `2^level` samples.
    t: Vec<f64>,
    measured_w: Vec<f64>,
    predicted_w: Vec<f64>,
    level: u32,
    /// Samples of the point being filled: count, sums of measured and predicted power, last time.
    pending: (u32, f64, f64, f64),
}

impl RatioEstimator {
    /// An estimator with the fitted model's relative spread `prior_sd` (the vehicle file's
    /// `efficiency_relative_sd`, else the scenarios' default model error).
    pub(crate) fn new(prior_sd: f64) -> Self {
        Self {
            prior_sd,
            measured_j: Trapezoid::new(),
            predicted_j: Trapezoid::new(),
            first_s: None,
            t: Vec::new(),
            measured_w: Vec::new(),
            predicted_w: Vec::new(),
            level: 0,
            pending: (0, 0.0, 0.0, 0.0),
        }
    }

    /// Add a sample at `time_s` (after the last one; the caller checks it): measured and
    /// predicted electrical power, W.
    pub(crate) fn push(&mut self, time_s: f64, measured_w: f64, predicted_w: f64) {
        self.first_s.get_or_insert(time_s);
        self.measured_j.push(time_s, measured_w);
        self.predicted_j.push(time_s, predicted_w);
        let (n, m, p, _) = self.pending;
        self.pending = (n + 1, m + measured_w, p + predicted_w, time_s);
        if self.pending.0 == 1 << self.level {
            let (n, m, p, t) = std::mem::take(&mut self.pending);
            let n = f64::from(n);
            self.t.push(t);
            self.measured_w.push(m / n);
            self.predicted_w.push(p / n);
            if self.t.len() == MAX_POINTS {
                self.merge();
            }
        }
    }

    /// Halve the points: each pair becomes its mean.
    fn merge(&mut self) {
        for v in [&mut self.measured_w, &mut self.predicted_w] {
            let merged: Vec<f64> = v.chunks(2).map(|c| c.iter().sum::<f64>() / 2.0).collect();
            *v = merged;
        }
        let ends: Vec<f64> = self.t.chunks(2).map(|c| c[c.len() - 1]).collect();
        self.t = ends;
        self.level += 1;
    }

    /// The last sample's time, s.
    pub(crate) fn last_s(&self) -> Option<f64> {
        self.measured_j.last().map(|(t, _)| t)
    }

    /// Measured and predicted energy so far, J.
    pub(crate) fn energies_j(&self) -> (f64, f64) {
        (self.measured_j.integral(), self.predicted_j.integral())
    }

    /// Span of the samples so far, s.
    pub(crate) fn elapsed_s(&self) -> f64 {
        match (self.first_s, self.last_s()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }

    /// The ratio for a rest of `rest_s` seconds: the fitted model (ratio 1, the prior's spread)
    /// until [`MIN_WINDOW_S`] of samples with energy, then the shrunk estimate.
    pub(crate) fn ratio(&self, rest_s: f64) -> Ratio {
        let (m, p) = self.energies_j();
        if self.elapsed_s() < MIN_WINDOW_S || p <= 0.0 || self.t.len() < 3 {
            return Ratio {
                ratio: 1.0,
                log_sd: self.prior_sd,
            };
        }
        let shrunk = crate::recalibration::shrink(
            m / p,
            &self.measured_w,
            &self.predicted_w,
            Some(self.prior_sd),
        );
        // The shrunk estimate's variance is the window's times its weight: `w s_d^2`; without a
        // finite window spread, the prior's.
        let estimate_sd = match shrunk.window_relative_sd {
            sd if sd.is_finite() => shrunk.window_weight.sqrt() * sd,
            _ => self.prior_sd,
        };
        Ratio {
            ratio: shrunk.ratio,
            log_sd: {
                let blocks = self.blocks();
                estimate_sd
                    .hypot(drift_sd(&blocks, rest_s))
                    .max(prequential_sd(&blocks))
            },
        }
    }

    /// Sums of measured and predicted power over the [`DRIFT_BLOCK_S`] blocks so far (the last
    /// one until now, however short).
    fn blocks(&self) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        let (mut from_t, mut m, mut p) = (self.first_s.unwrap_or(0.0), 0.0, 0.0);
        for k in 0..self.t.len() {
            m += self.measured_w[k];
            p += self.predicted_w[k];
            if self.t[k] - from_t >= DRIFT_BLOCK_S {
                out.push((m, p));
                (from_t, m, p) = (self.t[k], 0.0, 0.0);
            }
        }
        if p > 0.0 {
            out.push((m, p));
        }
        out
    }
}

/// How far the ratio of the rest may drift from the flight's so far: the spread of the log
/// ratios of the [`DRIFT_BLOCK_S`] blocks so far, over the square root of the blocks the rest
/// holds (at least one); 0 with fewer than three blocks so far.
fn drift_sd(blocks: &[(f64, f64)], rest_s: f64) -> f64 {
    let logs: Vec<f64> = blocks
        .iter()
        .filter(|(m, p)| *m > 0.0 && *p > 0.0)
        .map(|(m, p)| (m / p).ln())
        .collect();
    if logs.len() < 3 {
        return 0.0;
    }
    let n = logs.len() as f64;
    let mean = logs.iter().sum::<f64>() / n;
    let var = logs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    // Blocks that drift together count as fewer: `tau` blocks per independent one, from
    // their autocorrelation (as the window's effective sample size).
    let tau = n / crate::recalibration::effective_sample_size(&logs);
    (var / (rest_s / DRIFT_BLOCK_S / tau).max(1.0)).sqrt()
}

/// How far this estimator's own past predictions were off: at the end of every
/// [`DRIFT_BLOCK_S`] block so far, the ratio up to there against the ratio from there to
/// now, `e_j = ln(r_(j..now) / r_(0..j))`; the root mean square of the `e_j` (0 with fewer
/// than two). A forecaster's spread checked on its own record: it holds the ratio's drift
/// along this flight whatever its shape.
fn prequential_sd(blocks: &[(f64, f64)]) -> f64 {
    let (m_all, p_all) = blocks
        .iter()
        .fold((0.0, 0.0), |(a, b), (m, p)| (a + m, b + p));
    let (mut m, mut p) = (0.0, 0.0);
    let mut sq = Vec::new();
    for (bm, bp) in &blocks[..blocks.len().saturating_sub(1)] {
        m += bm;
        p += bp;
        let (later_m, later_p) = (m_all - m, p_all - p);
        if m > 0.0 && p > 0.0 && later_m > 0.0 && later_p > 0.0 {
            let e = ((later_m / later_p) / (m / p)).ln();
            sq.push(e * e);
        }
    }
    if sq.len() < 2 {
        return 0.0;
    }
    (sq.iter().sum::<f64>() / sq.len() as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The efficiency flown and reported is in [0.01, 1] whatever the ratio, the fitted one
    /// where the ratio gives no number.
    #[test]
    fn the_efficiency_flown_stays_in_its_range() {
        // Exact: a clamp returns its bound, and one division.
        let same = |a: f64, b: f64| (a - b).abs() < 1e-15;
        // 0.74 / 0.6 = 1.23: the model above the measured power at any efficiency.
        assert!(same(flown_efficiency(0.74, 0.6), 1.0));
        assert!(same(flown_efficiency(0.74, 1.1), 0.74 / 1.1));
        assert!(same(flown_efficiency(0.74, 1e6), MIN_EFFICIENCY));
        for r in [0.0, f64::NAN, f64::INFINITY, -1.0] {
            let eta = flown_efficiency(0.74, r);
            assert!(eta > 0.0 && eta <= 1.0, "{r}: {eta}");
        }
    }

    /// A flight that draws 10 % more than predicted, with a slow swing: the ratio converges to
    /// 1.1 as the window grows, and merging the points when the buffer fills keeps the energies.
    #[test]
    fn the_ratio_follows_the_flight_and_memory_stays_bounded() {
        let mut e = RatioEstimator::new(0.03);
        assert!((e.ratio(100.0).ratio - 1.0).abs() < 1e-15);
        let n = 3 * MAX_POINTS + 7;
        for k in 0..n {
            let t = k as f64 * 0.1;
            let p = 200.0 + 20.0 * (t / 50.0).sin();
            // Measurement noise that averages out over the flight.
            e.push(t, 1.1 * p + 5.0 * (1.7 * t).sin(), p);
        }
        assert!(e.t.len() < MAX_POINTS, "{} points", e.t.len());
        assert_eq!(e.level, 2);
        let (m, p) = e.energies_j();
        assert!((m / p - 1.1).abs() < 1e-4, "{}", m / p);
        let r = e.ratio(600.0);
        // Shrunk toward 1 by the 3 % prior, by very little: the window is 4915 s long.
        assert!(r.ratio > 1.09 && r.ratio < 1.1, "{r:?}");
        assert!(r.log_sd > 0.0 && r.log_sd < 0.03, "{r:?}");
    }
}
