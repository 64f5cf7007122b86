//! Cell balance: how long the cells of the pack stood apart, as fleet tools count it.
//!
//! The spread of a record is max − min of its cell voltages; each record holds until the next
//! (at most [`MAX_HOLD_S`]). Minutes with a spread above [`MINOR_SPREAD_V`] (0.01 V) and above
//! [`MAJOR_SPREAD_V`] (0.07 V) are AirData's "minor" and "major" deviation (research note §2.1).
//! The worst cell is the one furthest below the mean of its pack, on average.

use aloft_logs::BatterySample;
use serde::Serialize;

/// Spread of a minor imbalance, V.
pub const MINOR_SPREAD_V: f64 = 0.01;
/// Spread of a major imbalance, V.
pub const MAJOR_SPREAD_V: f64 = 0.07;
/// Longest time one record's spread is held, s.
pub const MAX_HOLD_S: f64 = 2.0;

/// How the cells of a log stood apart.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellBalance {
    /// Records with at least two cells.
    pub records: usize,
    /// Time with a spread above 0.01 V, min.
    pub imbalance_minor_min: f64,
    /// Time with a spread above 0.07 V, min.
    pub imbalance_major_min: f64,
    /// Largest spread, V.
    pub max_spread_v: f64,
    /// The cell furthest below its pack's mean on average, numbered from 1 (as ArduPilot's
    /// `V1` and PX4's `voltage_cell_v[0]`).
    pub worst_cell: usize,
}

/// The balance of the cells of `samples`; `None` when no record has two cells.
pub fn cell_balance(samples: &[BatterySample]) -> Option<CellBalance> {
    let with: Vec<&BatterySample> = samples.iter().filter(|s| s.cell_v.len() >= 2).collect();
    if with.is_empty() {
        return None;
    }
    let (mut minor_s, mut major_s, mut max_spread) = (0.0, 0.0, 0.0_f64);
    let n_cells = with.iter().map(|s| s.cell_v.len()).max().unwrap_or(0);
    let mut below = vec![(0.0_f64, 0usize); n_cells];
    for (k, s) in with.iter().enumerate() {
        let hi = s.cell_v.iter().copied().fold(f64::MIN, f64::max);
        let lo = s.cell_v.iter().copied().fold(f64::MAX, f64::min);
        let spread = hi - lo;
        max_spread = max_spread.max(spread);
        let hold = with
            .get(k + 1)
            .map_or(0.0, |n| (n.time_s - s.time_s).clamp(0.0, MAX_HOLD_S));
        if spread > MINOR_SPREAD_V {
            minor_s += hold;
        }
        if spread > MAJOR_SPREAD_V {
            major_s += hold;
        }
        let mean = s.cell_v.iter().sum::<f64>() / s.cell_v.len() as f64;
        for (c, v) in s.cell_v.iter().enumerate() {
            below[c].0 += mean - v;
            below[c].1 += 1;
        }
    }
    let worst = below
        .iter()
        .enumerate()
        .filter(|(_, (_, n))| *n > 0)
        .max_by(|a, b| (a.1 .0 / a.1 .1 as f64).total_cmp(&(b.1 .0 / b.1 .1 as f64)))
        .map_or(0, |(c, _)| c);
    Some(CellBalance {
        records: with.len(),
        imbalance_minor_min: minor_s / 60.0,
        imbalance_major_min: major_s / 60.0,
        max_spread_v: max_spread,
        worst_cell: worst + 1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 60 records 1 s apart, cell 3 sagging 0.02 V for the first 30 s and 0.1 V for the next
    /// 30: 59 s above 0.01 V (the last record holds nothing) and 29 s above 0.07 V.
    #[test]
    fn minutes_of_spread_and_the_worst_cell() {
        let s: Vec<BatterySample> = (0..60)
            .map(|k| {
                let sag = if k < 30 { 0.02 } else { 0.1 };
                BatterySample {
                    time_s: k as f64,
                    voltage_v: 15.0,
                    cell_v: vec![3.8, 3.8, 3.8 - sag, 3.8],
                    ..BatterySample::default()
                }
            })
            .collect();
        let b = cell_balance(&s).unwrap();
        assert!((b.imbalance_minor_min - 59.0 / 60.0).abs() < 1e-9, "{b:?}");
        assert!((b.imbalance_major_min - 29.0 / 60.0).abs() < 1e-9, "{b:?}");
        assert_eq!(b.worst_cell, 3);
    }
}
