//! Pack internal resistance from current steps.
//!
//! # Model
//! Across a fast current step the open-circuit voltage cannot move (the charge drawn in one
//! telemetry period is tiny), so the change of terminal voltage is the resistive drop:
//!
//! `R_k = −ΔV_k / ΔI_k`
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | ΔV_k | terminal voltage change between two consecutive updates | V |
//! | ΔI_k | current change between the same updates (discharge positive) | A |
//! | R_k | one step's estimate of the pack's internal resistance | Ω |
//!
//! An *update* is a record whose voltage or current differs from the previous one (logs that
//! repeat a 1 Hz reading at 10 Hz, as KAIST's, give one update per reading). A pair counts as a
//! step when the updates are less than [`MAX_STEP_DT_S`] apart and |ΔI| exceeds
//! max([`MIN_STEP_A`], [`STEP_FRACTION_OF_MAX`] × the flight's largest current). The estimate is
//! the **median** of all R_k, so a glitch sample (one 90 V record) moves it by at most a rank or
//! two; it must come out positive. This is the step-response (HPPC pulse) method; see the
//! research note `air-packs.md` §2.4.
//!
//! # Deviation: negative steps are kept
//! A step's ratio carries the voltage noise divided by ΔI, symmetric about the true R. Keeping
//! only the positive ratios truncates that noise on one side and biases the median up: on the
//! five flugdrohne flights (3S, 5 Hz) it gave 0.047-0.062 Ω where the median of all ratios gives
//! 0.031-0.049 Ω, the research note's step figures (§2.5). So every ratio enters the median.
//!
//! # Why not a least-squares fit of V on I over the flight
//! Over a flight the open-circuit voltage falls while the current rises (constant power draws
//! more current from a lower voltage), so a constant-OCV regression of V on I attributes the
//! discharge to the resistance: on the KAIST flights it gives 7-17 × the step value (§2.5).

use aloft_logs::BatterySample;
use serde::Serialize;

/// Longest time between the two updates of a step, s.
pub const MAX_STEP_DT_S: f64 = 1.5;
/// Smallest current change of a step, A.
pub const MIN_STEP_A: f64 = 2.0;
/// Smallest current change of a step as a fraction of the flight's largest current (5 %: on
/// the shared flights, 30-40 A at most, the 2 A floor governs, as in the research note's §2.5).
pub const STEP_FRACTION_OF_MAX: f64 = 0.05;
/// Fewest steps for an estimate.
pub const MIN_STEPS: usize = 3;

/// The pack's internal resistance from its current steps.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResistanceEstimate {
    /// Median of the step estimates, Ω (the whole pack).
    pub ohm: f64,
    /// Steps used.
    pub steps: usize,
    /// 25th percentile of the step estimates, Ω.
    pub p25_ohm: f64,
    /// 75th percentile of the step estimates, Ω.
    pub p75_ohm: f64,
    /// The current change a step needed, A.
    pub threshold_a: f64,
}

/// The updates of a log: (time s, voltage V, current A) of each record with a current whose
/// voltage or current differs from the previous record's.
pub fn updates(samples: &[BatterySample]) -> Vec<(f64, f64, f64)> {
    let mut out: Vec<(f64, f64, f64)> = Vec::new();
    for s in samples {
        let Some(i) = s.current_a else { continue };
        if !(s.voltage_v.is_finite() && i.is_finite() && s.time_s.is_finite()) {
            continue;
        }
        // Exact repeats are the same reading logged again (a 1 Hz value in 10 Hz rows).
        #[allow(clippy::float_cmp)]
        let same = out
            .last()
            .is_some_and(|&(_, v, a)| v == s.voltage_v && a == i);
        if !same {
            out.push((s.time_s, s.voltage_v, i));
        }
    }
    out
}

/// The value at fraction `q` (0-1) of sorted `v` (linear between ranks).
pub(crate) fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let x = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let (lo, hi) = (x.floor() as usize, x.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (x - lo as f64)
}

/// The median of `v` (`None` when empty); sorts `v`.
pub(crate) fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(quantile(v, 0.5))
}

/// The pack's internal resistance from the current steps of `samples` (see the module docs);
/// `None` with fewer than [`MIN_STEPS`] steps or no current.
pub fn resistance_from_steps(samples: &[BatterySample]) -> Option<ResistanceEstimate> {
    let u = updates(samples);
    let i_max = u.iter().map(|p| p.2).fold(0.0_f64, f64::max);
    let threshold_a = MIN_STEP_A.max(STEP_FRACTION_OF_MAX * i_max);
    let mut r: Vec<f64> = u
        .windows(2)
        .filter_map(|w| {
            let (t0, v0, i0) = w[0];
            let (t1, v1, i1) = w[1];
            let (dt, di) = (t1 - t0, i1 - i0);
            (dt > 0.0 && dt < MAX_STEP_DT_S && di.abs() > threshold_a)
                .then(|| -(v1 - v0) / di)
                .filter(|r| r.is_finite())
        })
        .collect();
    if r.len() < MIN_STEPS {
        return None;
    }
    let ohm = median(&mut r).filter(|r| *r > 0.0)?;
    Some(ResistanceEstimate {
        ohm,
        steps: r.len(),
        p25_ohm: quantile(&r, 0.25),
        p75_ohm: quantile(&r, 0.75),
        threshold_a,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::sample;

    /// A square-wave load on a pack of known resistance with a falling OCV: the steps give the
    /// resistance exactly (the OCV moves little within one step).
    #[test]
    fn square_wave_gives_the_resistance() {
        let r = 0.05;
        let s: Vec<BatterySample> = (0..600)
            .map(|k| {
                let t = k as f64 * 0.2;
                let i = if (k / 10) % 2 == 0 { 10.0 } else { 30.0 };
                let ocv = 25.0 - 0.01 * t;
                sample(t, ocv - r * i, i)
            })
            .collect();
        let e = resistance_from_steps(&s).unwrap();
        // Each step spans 0.2 s of OCV drift (0.002 V over 20 A: 1e-4 ohm either way).
        assert!((e.ohm - r).abs() < 2e-4, "{e:?}");
        assert!(e.steps > 50);
    }

    /// Repeated readings (10 Hz rows of a 1 Hz value) are one update.
    #[test]
    fn repeated_rows_are_one_update() {
        let s = vec![
            sample(0.0, 25.0, 10.0),
            sample(0.1, 25.0, 10.0),
            sample(0.2, 24.0, 30.0),
        ];
        assert_eq!(updates(&s).len(), 2);
    }

    #[test]
    fn no_current_no_estimate() {
        let s: Vec<BatterySample> = (0..10)
            .map(|k| BatterySample {
                time_s: k as f64,
                voltage_v: 12.0,
                ..BatterySample::default()
            })
            .collect();
        assert!(resistance_from_steps(&s).is_none());
    }
}
