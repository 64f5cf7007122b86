//! Percentiles over scenarios, by nearest rank: the figures of a mission flown in many drawn
//! conditions (`aloft mission --samples`), and the landing charge of a plan's sorties (`aloft
//! plan --confidence`).

use serde::{Deserialize, Serialize};

/// The 5th, 50th and 95th percentiles of a figure over scenarios (nearest rank: the `p`-th
/// percentile of `n` values is the `ceil(p n / 100)`-th smallest).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Percentiles {
    /// 5th percentile.
    pub p5: f64,
    /// Median.
    pub p50: f64,
    /// 95th percentile.
    pub p95: f64,
}

impl Percentiles {
    /// The percentiles of `values` (sorted in place); `None` when there are none.
    pub fn of(values: &mut [f64]) -> Option<Self> {
        if values.is_empty() {
            return None;
        }
        values.sort_by(f64::total_cmp);
        Some(Self {
            p5: nearest_rank(values, 5),
            p50: nearest_rank(values, 50),
            p95: nearest_rank(values, 95),
        })
    }
}

/// The `p`-th percentile (`p` in 1..=100) of sorted, non-empty `values` by nearest rank, in
/// integer arithmetic (`ceil(p n / 100)`, so 5 % of 1000 is the 50th value exactly).
pub fn nearest_rank(sorted: &[f64], p: usize) -> f64 {
    let n = sorted.len();
    let rank = (p * n).div_ceil(100).clamp(1, n);
    sorted[rank - 1]
}

/// The value of sorted, non-empty `values` that at least a share `share` (0 to 1) of them reach
/// or exceed: the `ceil((1 - share) n)`-th smallest by nearest rank, the first when that is 0
/// (`share` 0.95 of 1000 values: the 50th smallest, as [`nearest_rank`] at 5).
pub fn reached_by(sorted: &[f64], share: f64) -> f64 {
    let n = sorted.len();
    // In thousandths of a per cent, so that 0.95 of 1000 is 50 exactly.
    let below = ((1.0 - share.clamp(0.0, 1.0)) * 100_000.0).round() as usize;
    let rank = (below * n).div_ceil(100_000).clamp(1, n);
    sorted[rank - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nearest rank on 1..=1000: the 5th percentile is the 50th value, the median the 500th;
    /// `reached_by` 0.95 is the same value and at least 95 % of the values reach it; one value
    /// is every percentile.
    #[test]
    // The percentiles are values of the input, picked, not computed: compared exactly.
    #[allow(clippy::float_cmp)]
    fn nearest_rank_and_reached_by_agree_at_five_percent() {
        let v: Vec<f64> = (1..=1000).map(f64::from).collect();
        assert_eq!(nearest_rank(&v, 5), 50.0);
        assert_eq!(nearest_rank(&v, 50), 500.0);
        assert_eq!(reached_by(&v, 0.95), 50.0);
        let share = v.iter().filter(|x| **x >= 50.0).count() as f64 / 1000.0;
        assert!(share >= 0.95, "{share}");
        // 0.9 of 7 values: ceil(0.7) = the 1st smallest; 0.5 of 7: the 4th.
        let seven: Vec<f64> = (1..=7).map(f64::from).collect();
        assert_eq!(reached_by(&seven, 0.9), 1.0);
        assert_eq!(reached_by(&seven, 0.5), 4.0);
        assert_eq!(reached_by(&[3.0], 0.99), 3.0);
        let p = Percentiles::of(&mut [3.0, 1.0, 2.0]).unwrap();
        assert_eq!((p.p5, p.p50, p.p95), (1.0, 2.0, 3.0));
        assert_eq!(Percentiles::of(&mut []), None);
    }
}
