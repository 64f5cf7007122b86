//! The least-squares straight line through values taken one step apart.
//!
//! For `y_0, y_1, ..., y_{n-1}` at `x = k`:
//!
//! `b = Σ (k − x̄)(y_k − ȳ) / Σ (k − x̄)²`, the line `y = ȳ + b (x − x̄)`
//!
//! | symbol | meaning |
//! |---|---|
//! | x̄ | mean step, `(n − 1) / 2` |
//! | ȳ | mean value |
//! | b | slope, value units per step (0 for fewer than two values) |

/// The least-squares line through `(k, y_k)`, `k = 0, 1, ...` (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IndexLine {
    /// Mean step, `(n - 1) / 2`.
    pub mean_x: f64,
    /// Mean value (NaN for no values).
    pub mean_y: f64,
    /// Slope per step (0 for fewer than two values).
    pub slope: f64,
}

impl IndexLine {
    /// The line through `y`.
    pub fn of(y: &[f64]) -> Self {
        let n = y.len() as f64;
        let mean_x = (n - 1.0) / 2.0;
        let mean_y = y.iter().sum::<f64>() / n;
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for (k, v) in y.iter().enumerate() {
            let dx = k as f64 - mean_x;
            sxy += dx * (v - mean_y);
            sxx += dx * dx;
        }
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        Self {
            mean_x,
            mean_y,
            slope,
        }
    }

    /// The line's value at step `x`.
    pub fn at(&self, x: f64) -> f64 {
        self.mean_y + self.slope * (x - self.mean_x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_line_is_found_exactly() {
        // 1, 3, 5, 7: slope 2, mean 4 at step 1.5, 1 at step 0 (sums of halves and whole
        // numbers: exact in binary, so compared bit for bit).
        let l = IndexLine::of(&[1.0, 3.0, 5.0, 7.0]);
        let bits = |v: [f64; 4]| v.map(f64::to_bits);
        assert_eq!(
            bits([l.mean_x, l.mean_y, l.slope, l.at(0.0)]),
            bits([1.5, 4.0, 2.0, 1.0])
        );
    }

    #[test]
    fn the_slope_through_scatter_is_the_hand_computed_one() {
        // x = 0, 1, 2 (mean 1), y = 1, 0, 4 (mean 5/3): sxy = (-1)(-2/3) + 0 + (1)(7/3) = 3,
        // sxx = 2, slope 1.5.
        let l = IndexLine::of(&[1.0, 0.0, 4.0]);
        assert!((l.slope - 1.5).abs() < 1e-15, "{l:?}");
    }

    #[test]
    fn one_value_has_no_slope() {
        let l = IndexLine::of(&[5.0]);
        let bits = |v: [f64; 3]| v.map(f64::to_bits);
        assert_eq!(bits([l.mean_x, l.mean_y, l.slope]), bits([0.0, 5.0, 0.0]));
    }
}
