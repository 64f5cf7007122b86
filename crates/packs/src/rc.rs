//! The RC pair of a pack's equivalent circuit from a flight's records, where they allow it.
//!
//! # Model
//! With the series resistance `R_0` known (the step estimate, [`crate::resistance`]), the
//! terminal voltage is `V = V_oc(s) - R_0 I - v_1`, and the RC pair's voltage is the current
//! low-passed at its time constant: `v_1 = R_1 lp_tau(I)` (`lp_tau` the first-order filter the
//! state-of-charge filter steps, `a = exp(-dt / tau)`). Over a flight `V_oc` falls slowly, and
//! its error against any curve moves slowly too, so both sides are taken less their moving mean
//! over [`DETREND_S`]: what is left is the fast part, `r = -(R_1 d_tau)` with `r` the detrended
//! `V + R_0 I` and `d_tau` the detrended `lp_tau(I)`. For each `tau` of [`TAU_GRID_S`], `R_1` by
//! least squares and the residual's root mean square.
//!
//! # When the records allow it
//! A flight identifies the time constant where the best `tau`'s fit explains at least
//! [`MIN_EXPLAINED`] of the fast part's variance more than the grid's worst `tau` does (a
//! minimum, not a plateau: a broadband current fits every `tau` alike, `R_1` trading against
//! `tau`), the best lies inside the grid (not at its end), and its `R_1` is positive. A pack's
//! pair ([`rc_of_flights`]) needs [`MIN_FLIGHTS`] flights that identify one, whose time
//! constants agree within a factor of [`MAX_TAU_SPREAD`]: the median of theirs. Otherwise the
//! answer says why, and the state-of-charge filter keeps its default pair
//! ([`crate::soc_filter::DEFAULT_RC_TIME_CONSTANT_S`]) and learns `R_1` in flight. On the shared
//! logs (`tests/packs_data_val.rs`) the flights that identify one disagree: 5-120 s on KAIST's
//! days, 10-120 s on the PX4 flights.

use aloft_logs::BatterySample;
use serde::Serialize;

use crate::resistance::updates;

/// The span of the moving mean taken off both sides, s.
pub const DETREND_S: f64 = 120.0;

/// The time constants tried, s.
pub const TAU_GRID_S: [f64; 8] = [2.0, 5.0, 10.0, 20.0, 30.0, 60.0, 90.0, 120.0];

/// How much more of the fast part's variance the best time constant must explain than the worst.
pub const MIN_EXPLAINED: f64 = 0.05;

/// Fewest updates for a fit (ten minutes at KAIST's 1 Hz readings would be 600).
pub const MIN_UPDATES: usize = 120;

/// Fewest flights that identify a pair for the pack's.
pub const MIN_FLIGHTS: usize = 3;

/// Most the flights' time constants may spread, as the ratio of the largest to the smallest.
pub const MAX_TAU_SPREAD: f64 = 2.0;

/// The RC pair found, or why not.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RcEstimate {
    /// The RC pair's resistance, ohm (where identified).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rc_resistance_ohm: Option<f64>,
    /// Its time constant, s (where identified).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rc_time_constant_s: Option<f64>,
    /// Share of the fast part's variance the best and the worst time constant explain.
    pub explained: (f64, f64),
    /// Why the records do not identify it (absent where they do).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_identified: Option<String>,
}

/// The RC pair of the records `samples` with the series resistance `r0_ohm` (see the module
/// docs); `None` where the records are too few or carry no current.
pub fn rc_from_flight(samples: &[BatterySample], r0_ohm: f64) -> Option<RcEstimate> {
    let u = updates(samples);
    if u.len() < MIN_UPDATES || !r0_ohm.is_finite() {
        return None;
    }
    let t: Vec<f64> = u.iter().map(|x| x.0).collect();
    let rest: Vec<f64> = u.iter().map(|x| x.1 + r0_ohm * x.2).collect();
    let current: Vec<f64> = u.iter().map(|x| x.2).collect();
    let r = detrended(&t, &rest);
    let total: f64 = r.iter().map(|x| x * x).sum();
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let fits: Vec<(f64, f64, f64)> = TAU_GRID_S
        .iter()
        .map(|&tau| {
            let d = detrended(&t, &low_passed(&t, &current, tau));
            let dd: f64 = d.iter().map(|x| x * x).sum();
            let rd: f64 = r.iter().zip(&d).map(|(a, b)| a * b).sum();
            let r1 = if dd > 0.0 { -rd / dd } else { 0.0 };
            // The variance explained: (r.d)^2 / (d.d), over the total.
            let explained = if dd > 0.0 { rd * rd / dd / total } else { 0.0 };
            (tau, r1, explained)
        })
        .collect();
    let best =
        fits.iter().copied().fold(
            (0.0, 0.0, f64::NEG_INFINITY),
            |a, b| {
                if b.2 > a.2 {
                    b
                } else {
                    a
                }
            },
        );
    let worst = fits.iter().map(|f| f.2).fold(f64::INFINITY, f64::min);
    let why = if best.2 - worst < MIN_EXPLAINED {
        Some(format!(
            "every time constant from {} to {} s explains the voltage's fast part alike ({:.0}-{:.0} %): the current does not separate them",
            TAU_GRID_S[0],
            TAU_GRID_S[TAU_GRID_S.len() - 1],
            100.0 * worst,
            100.0 * best.2
        ))
    } else if best.0 >= TAU_GRID_S[TAU_GRID_S.len() - 1] {
        Some(format!(
            "the best time constant is the longest tried, {} s: a slower drift, not a pair",
            best.0
        ))
    } else if best.1 <= 0.0 {
        Some("the best fit's RC resistance is not positive".to_string())
    } else {
        None
    };
    Some(RcEstimate {
        rc_resistance_ohm: why.is_none().then_some(best.1),
        rc_time_constant_s: why.is_none().then_some(best.0),
        explained: (best.2, worst),
        not_identified: why,
    })
}

/// The pack's pair from its flights' (see the module docs): the median time constant and
/// resistance of the flights that identify one, where at least [`MIN_FLIGHTS`] do and agree;
/// else why not.
pub fn rc_of_flights(flights: &[RcEstimate]) -> Result<(f64, f64), String> {
    let mut found: Vec<(f64, f64)> = flights
        .iter()
        .filter_map(|e| e.rc_time_constant_s.zip(e.rc_resistance_ohm))
        .collect();
    if found.len() < MIN_FLIGHTS {
        return Err(format!(
            "{} of {} flights identify an RC pair (at least {MIN_FLIGHTS} are needed)",
            found.len(),
            flights.len()
        ));
    }
    found.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (lo, hi) = (found[0].0, found[found.len() - 1].0);
    if hi > MAX_TAU_SPREAD * lo {
        return Err(format!(
            "the flights' time constants disagree ({lo}-{hi} s)"
        ));
    }
    let mut r: Vec<f64> = found.iter().map(|f| f.1).collect();
    r.sort_by(f64::total_cmp);
    Ok((found[found.len() / 2].0, r[r.len() / 2]))
}

/// The current low-passed at `tau` s, as the filter steps its RC pair.
fn low_passed(t: &[f64], x: &[f64], tau: f64) -> Vec<f64> {
    let mut y = Vec::with_capacity(x.len());
    let mut v = x[0];
    y.push(v);
    for k in 1..x.len() {
        let a = (-(t[k] - t[k - 1]).max(0.0) / tau).exp();
        v = a * v + (1.0 - a) * x[k];
        y.push(v);
    }
    y
}

/// `x` less its mean over the records within [`DETREND_S`] / 2 either side (two pointers over
/// the sorted times).
fn detrended(t: &[f64], x: &[f64]) -> Vec<f64> {
    let half = DETREND_S / 2.0;
    let (mut lo, mut hi, mut sum) = (0usize, 0usize, 0.0);
    let mut out = Vec::with_capacity(x.len());
    for k in 0..x.len() {
        while hi < x.len() && t[hi] < t[k] + half {
            sum += x[hi];
            hi += 1;
        }
        while t[lo] <= t[k] - half {
            sum -= x[lo];
            lo += 1;
        }
        out.push(x[k] - sum / (hi - lo) as f64);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records of a pack with an RC pair of `r1` ohm and `tau` s, `R_0` 0.02 ohm, its open-circuit
    /// voltage falling 1 V over the flight, under a current of `current(t)`, at 1 Hz.
    fn flight(r1: f64, tau: f64, current: &dyn Fn(f64) -> f64) -> Vec<BatterySample> {
        let mut v1 = 0.0;
        (0..900)
            .map(|k| {
                let t = f64::from(k);
                let i = current(t);
                let a = (-1.0 / tau).exp();
                v1 = a * v1 + r1 * (1.0 - a) * i;
                BatterySample {
                    time_s: t,
                    voltage_v: 48.0 - t / 900.0 - 0.02 * i - v1,
                    current_a: Some(i),
                    ..BatterySample::default()
                }
            })
            .collect()
    }

    #[test]
    fn steps_held_for_a_minute_identify_the_pair() {
        // 20 A and 35 A in turn, a minute each: the relaxation after each step shows the pair.
        let steps = |t: f64| {
            if (t / 60.0) as u64 % 2 == 0 {
                20.0
            } else {
                35.0
            }
        };
        let e = rc_from_flight(&flight(0.03, 20.0, &steps), 0.02).unwrap();
        assert_eq!(e.rc_time_constant_s, Some(20.0), "{e:?}");
        let r1 = e.rc_resistance_ohm.unwrap();
        assert!((r1 - 0.03).abs() < 0.003, "{r1}");
    }

    #[test]
    fn a_current_that_does_not_separate_the_time_constants_is_said() {
        // A current that never holds: a new level every second, pseudo-random.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let levels: Vec<f64> = (0..900)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                20.0 + (state % 1000) as f64 / 1000.0 * 15.0
            })
            .collect();
        let noisy = |t: f64| levels[t as usize];
        let e = rc_from_flight(&flight(0.0, 20.0, &noisy), 0.02).unwrap();
        assert!(e.not_identified.is_some(), "{e:?}");
        assert_eq!(e.rc_resistance_ohm, None);
    }

    #[test]
    fn flights_that_agree_give_the_pack_its_pair_and_others_say_why() {
        let e = |tau: f64, r1: f64| RcEstimate {
            rc_resistance_ohm: Some(r1),
            rc_time_constant_s: Some(tau),
            explained: (0.3, 0.1),
            not_identified: None,
        };
        let agree = [e(20.0, 0.03), e(30.0, 0.04), e(20.0, 0.035)];
        assert_eq!(rc_of_flights(&agree), Ok((20.0, 0.035)));
        let disagree = [e(5.0, 0.02), e(20.0, 0.05), e(90.0, 0.2)];
        assert!(rc_of_flights(&disagree).unwrap_err().contains("disagree"));
        assert!(rc_of_flights(&agree[..2]).unwrap_err().contains("2 of 2"));
    }

    #[test]
    fn too_few_records_give_nothing() {
        let steps = |t: f64| if t < 30.0 { 20.0 } else { 35.0 };
        let short: Vec<BatterySample> = flight(0.03, 20.0, &steps).into_iter().take(60).collect();
        assert_eq!(rc_from_flight(&short, 0.02), None);
    }
}
