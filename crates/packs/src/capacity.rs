//! Charge drawn and the pack's capacity between two rested points.
//!
//! # Coulomb count
//! `Q = ∫ I dt` (trapezoid over consecutive records with a current; an interval longer than
//! [`MAX_GAP_S`] is not bridged), in mA h.
//!
//! # Capacity between rests
//! A rested voltage is a point on the open-circuit curve, so two rests bracket a known change
//! of state of charge:
//!
//! `C = Q₁₂ / (SoC₁ − SoC₂)`
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | Q₁₂ | charge drawn from the end of the first rest to the start of the last | mA h |
//! | SoC₁, SoC₂ | state of charge read from the rested voltage per cell on `OcvCurve::typical_lipo()` | 0-1 |
//! | C | the pack's usable capacity | mA h |
//!
//! **Rest rule**: |I| below [`REST_C_RATE`] × the rated capacity (0.05 C), or below
//! [`REST_CURRENT_UNRATED_A`] when the capacity is unknown, held for at least [`REST_HOLD_S`];
//! the rested voltage is the last of the span (the most relaxed). The first rest must begin at
//! the log's first record and the last end at its last, with a drop of state of charge of at
//! least [`MIN_SOC_DROP`] between them; otherwise the capacity is refused with the reason
//! ([`PackError`]). A pack read straight after landing still recovers (surface charge, §2.4 of
//! the research note), which is why the rest must hold.

use aloft_core::Trapezoid;
use aloft_logs::BatterySample;
use aloft_propulsion::OcvCurve;
use serde::Serialize;

use crate::PackError;

/// Longest interval between two records that the coulomb count bridges, s.
pub const MAX_GAP_S: f64 = 5.0;
/// Rest current as a C-rate of the rated capacity, 1/h.
pub const REST_C_RATE: f64 = 0.05;
/// Rest current when the capacity is unknown, A.
pub const REST_CURRENT_UNRATED_A: f64 = 1.0;
/// How long a rest must hold, s.
pub const REST_HOLD_S: f64 = 30.0;
/// Smallest drop of state of charge between the rests for a capacity, 0-1.
pub const MIN_SOC_DROP: f64 = 0.1;

/// Charge drawn over `samples` (trapezoid, gaps over [`MAX_GAP_S`] not bridged), mA h.
pub fn coulomb_count_mah(samples: &[BatterySample]) -> f64 {
    let mut q_as = Trapezoid::new();
    for s in samples {
        let Some(i) = s.current_a.filter(|i| i.is_finite()) else {
            continue;
        };
        q_as.push_bridging(s.time_s, i, MAX_GAP_S);
    }
    q_as.integral() / 3.6
}

/// A capacity from two rests.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CapacityEstimate {
    /// The capacity, mA h.
    pub capacity_mah: f64,
    /// State of charge at the rest before, 0-1.
    pub soc_before: f64,
    /// State of charge at the rest after, 0-1.
    pub soc_after: f64,
    /// Charge drawn between the rests, mA h.
    pub charge_between_mah: f64,
    /// Rested pack voltage before, V.
    pub rest_before_v: f64,
    /// Rested pack voltage after, V.
    pub rest_after_v: f64,
}

/// The rest current limit for a pack of `rated_capacity_mah`, A.
pub fn rest_limit_a(rated_capacity_mah: Option<f64>) -> f64 {
    rated_capacity_mah
        .filter(|c| c.is_finite() && *c > 0.0)
        .map_or(REST_CURRENT_UNRATED_A, |c| REST_C_RATE * c / 1000.0)
}

/// The capacity of the pack from the rests at the start and the end of `samples` (see the
/// module docs for the rule).
///
/// # Errors
/// The reason, in words, when there is no current, no cell count, no rest before or after, or
/// too small a drop of state of charge.
pub fn capacity_between_rests(
    samples: &[BatterySample],
    cells_series: Option<u32>,
    rated_capacity_mah: Option<f64>,
) -> Result<CapacityEstimate, PackError> {
    let pts: Vec<(f64, f64, f64)> = samples
        .iter()
        .filter_map(|s| Some((s.time_s, s.voltage_v, s.current_a?)))
        .collect();
    let (Some(first), Some(last)) = (pts.first(), pts.last()) else {
        return Err(PackError::NoCurrent);
    };
    let limit_a = rest_limit_a(rated_capacity_mah);
    let rested = |p: &(f64, f64, f64)| p.2.abs() < limit_a;
    // The rest before: from the first record to the first load.
    let load_from = pts.iter().position(|p| !rested(p));
    let load_to = pts.iter().rposition(|p| !rested(p));
    let (Some(a), Some(b)) = (load_from, load_to) else {
        // Never loaded: a log at rest throughout has no discharge to count; its last (most
        // relaxed) voltage says the state of charge it rests at.
        return Err(never_loaded(last.1, cells_series, limit_a));
    };
    if a == 0 {
        return Err(PackError::NoRestBefore {
            current_a: first.2,
            limit_a,
            hold_s: REST_HOLD_S,
        });
    }
    if pts[a].0 - first.0 < REST_HOLD_S {
        return Err(PackError::RestBeforeTooShort {
            rested_s: pts[a].0 - first.0,
            limit_a,
            hold_s: REST_HOLD_S,
        });
    }
    if last.0 - pts[b].0 < REST_HOLD_S {
        return Err(PackError::NoRestAfter {
            tail_s: last.0 - pts[b].0,
            limit_a,
            hold_s: REST_HOLD_S,
        });
    }
    let n = cells_series
        .filter(|n| *n > 0)
        .ok_or(PackError::CellsUnknown)?;
    let ocv = OcvCurve::typical_lipo();
    let (v1, v2) = (pts[a - 1].1, last.1);
    let soc = |v: f64| ocv.soc_at(v / f64::from(n));
    let (soc_before, soc_after) = (soc(v1), soc(v2));
    let drop = soc_before - soc_after;
    if drop < MIN_SOC_DROP {
        return Err(PackError::SocDropTooSmall {
            soc_before,
            soc_after,
            drop,
            min_drop: MIN_SOC_DROP,
        });
    }
    let t1 = pts[a - 1].0;
    let t2 = pts[b + 1..].first().map_or(last.0, |p| p.0);
    let between: Vec<BatterySample> = samples
        .iter()
        .filter(|s| s.time_s >= t1 && s.time_s <= t2)
        .cloned()
        .collect();
    let q = coulomb_count_mah(&between);
    Ok(CapacityEstimate {
        capacity_mah: q / drop,
        soc_before,
        soc_after,
        charge_between_mah: q,
        rest_before_v: v1,
        rest_after_v: v2,
    })
}

/// Why a log that never drew the rest limit has no capacity: with the cells known, the state of
/// charge its rested voltage `voltage_v` reads on the typical LiPo curve.
fn never_loaded(voltage_v: f64, cells_series: Option<u32>, limit_a: f64) -> PackError {
    match cells_series.filter(|n| *n > 0) {
        Some(n) => {
            let cell_v = voltage_v / f64::from(n);
            PackError::NeverLoaded {
                limit_a,
                voltage_v,
                cell_v,
                soc: OcvCurve::typical_lipo().soc_at(cell_v),
            }
        }
        None => PackError::NeverLoadedCellsUnknown { limit_a },
    }
}

/// The drop of charge the pack or the autopilot reported over the log, mA h, and where it came
/// from: the pack's remaining mA h (a BMS gauge), else the autopilot's consumed counter, else
/// the remaining fraction times the rated capacity.
pub fn reported_drop_mah(
    samples: &[BatterySample],
    rated_capacity_mah: Option<f64>,
) -> Option<(f64, &'static str)> {
    fn ends(it: impl Iterator<Item = f64> + Clone) -> Option<(f64, f64)> {
        let first = it.clone().next()?;
        let last = it.last()?;
        Some((first, last))
    }
    let finite = |x: Option<f64>| x.filter(|v| v.is_finite());
    if let Some((a, b)) = ends(samples.iter().filter_map(|s| finite(s.remaining_mah))) {
        return Some((a - b, "pack remaining mAh"));
    }
    if let Some((a, b)) = ends(samples.iter().filter_map(|s| finite(s.consumed_mah))) {
        return Some((b - a, "autopilot consumed mAh"));
    }
    let rated = rated_capacity_mah.filter(|c| c.is_finite() && *c > 0.0)?;
    let (a, b) = ends(samples.iter().filter_map(|s| finite(s.remaining)))?;
    Some(((a - b) * rated, "remaining fraction x rated capacity"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::sample as s;

    /// A 4S pack at 4.11 V/cell (90 %) resting 60 s, drawing 20 A for 540 s (3000 mA h), resting
    /// 60 s at 3.84 V/cell (50 %): 3000 / 0.4 = 7500 mA h.
    #[test]
    fn two_rests_give_the_capacity() {
        let mut v = Vec::new();
        for k in 0..=60 {
            v.push(s(k as f64, 4.0 * 4.11, 0.1));
        }
        for k in 61..=600 {
            v.push(s(k as f64, 15.0, 20.0));
        }
        for k in 601..=660 {
            v.push(s(k as f64, 4.0 * 3.84, 0.1));
        }
        let c = capacity_between_rests(&v, Some(4), None).unwrap();
        assert!((c.soc_before - 0.9).abs() < 1e-9 && (c.soc_after - 0.5).abs() < 1e-9);
        // Charge: 20 A over 539 s full, plus two ramp halves (60->61, 600->601) and the
        // rest current: 20*539 + 2*0.5*(20.1) ... computed closed form below.
        let q_as = 20.0 * 539.0 + 2.0 * 0.5 * (20.0 + 0.1);
        let want = q_as / 3.6 / 0.4;
        assert!((c.capacity_mah - want).abs() < 1e-6, "{c:?} {want}");
    }

    #[test]
    fn no_rest_after_is_refused_with_the_tail() {
        let mut v: Vec<BatterySample> = (0..=60).map(|k| s(k as f64, 16.4, 0.0)).collect();
        v.extend((61..=300).map(|k| s(k as f64, 15.0, 20.0)));
        v.extend((301..=302).map(|k| s(k as f64, 15.5, 0.0)));
        let e = capacity_between_rests(&v, Some(4), None).unwrap_err();
        assert!(matches!(e, PackError::NoRestAfter { .. }), "{e}");
        assert!(e.to_string().contains("the log ends 2.0 s after"), "{e}");
    }

    #[test]
    fn no_rest_before_is_refused() {
        let v: Vec<BatterySample> = (0..=300).map(|k| s(k as f64, 15.0, 20.0)).collect();
        let e = capacity_between_rests(&v, Some(4), Some(5000.0)).unwrap_err();
        assert!(
            e.to_string().starts_with("no rest before the flight"),
            "{e}"
        );
    }

    /// Issue 41: a pack at rest throughout was said to fall "from 0.000 to 0.000"; a 3S pack
    /// resting at 12.3 V (4.10 V a cell) is about 88 % on the typical LiPo curve (4.08 V 85 %,
    /// 4.11 V 90 %).
    #[test]
    fn a_pack_never_loaded_says_the_state_of_charge_it_rests_at() {
        let v: Vec<BatterySample> = (0..20).map(|k| s(k as f64 * 0.1, 12.3, 0.0)).collect();
        let e = capacity_between_rests(&v, Some(3), Some(5000.0)).unwrap_err();
        let PackError::NeverLoaded { soc, cell_v, .. } = e else {
            panic!("{e}")
        };
        assert!((cell_v - 4.1).abs() < 1e-12);
        assert!((0.85..=0.90).contains(&soc), "{soc}");
        assert!(e.to_string().contains("state of charge 0.8"), "{e}");
        let e = capacity_between_rests(&v, None, None).unwrap_err();
        assert!(
            matches!(e, PackError::NeverLoadedCellsUnknown { .. }),
            "{e}"
        );
    }

    /// A rest at the start that is too short says how long it was, not that the current was
    /// above the limit (it was not).
    #[test]
    fn a_short_rest_before_says_how_long_it_was() {
        let mut v: Vec<BatterySample> = (0..=50).map(|k| s(k as f64 * 0.2, 12.3, 0.0)).collect();
        v.extend((51..=300).map(|k| s(k as f64 * 0.2, 11.5, 20.0)));
        let e = capacity_between_rests(&v, Some(3), Some(5000.0)).unwrap_err();
        assert!(
            matches!(e, PackError::RestBeforeTooShort { rested_s, .. } if (rested_s - 10.2).abs() < 1e-9),
            "{e}"
        );
        assert!(
            e.to_string()
                .contains("below the rest limit of 0.25 A for only 10.2 s"),
            "{e}"
        );
    }

    #[test]
    fn coulomb_count_of_a_constant_current() {
        let v: Vec<BatterySample> = (0..=3600).map(|k| s(k as f64, 15.0, 2.0)).collect();
        assert!((coulomb_count_mah(&v) - 2000.0).abs() < 1e-9);
    }
}
