//! The trapezoid rule, the one integrator of sampled data in aloft.
//!
//! For samples `(t_k, v_k)` the integral is `sum_k (v_{k-1} + v_k) / 2 (t_k - t_{k-1})`, exact for
//! data that vary linearly between samples. Energies are power integrated this way (joules from
//! watts and seconds; divide by [`crate::SECONDS_PER_HOUR`] for watt-hours).
//!
//! [`Trapezoid`] accumulates sample by sample (a log read as a stream, a flight as it goes);
//! [`trapezoid`] integrates two slices. Both add the same terms in the same order, so they give
//! the same bits.

/// The trapezoid rule accumulated one sample at a time.
///
/// ```
/// let mut e = aloft_core::Trapezoid::new();
/// for (t, p) in [(0.0, 100.0), (1.0, 200.0), (3.0, 200.0)] {
///     e.push(t, p);
/// }
/// assert_eq!(e.integral(), 550.0);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Trapezoid {
    last: Option<(f64, f64)>,
    integral: f64,
}

impl Trapezoid {
    /// Nothing integrated yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Add the sample `value` at `time`: the panel from the previous sample is
    /// `0.5 (previous + value) (time - previous time)` (nothing for the first sample).
    #[inline]
    pub fn push(&mut self, time: f64, value: f64) {
        if let Some((t0, v0)) = self.last {
            self.integral += panel(t0, v0, time, value);
        }
        self.last = Some((time, value));
    }

    /// As [`Trapezoid::push`], but a step from the previous sample that is not forward or is
    /// longer than `max_gap` (a gap in the data) adds no panel; the sample is the last either way.
    #[inline]
    pub fn push_bridging(&mut self, time: f64, value: f64, max_gap: f64) {
        if let Some((t0, v0)) = self.last {
            let dt = time - t0;
            if dt > 0.0 && dt <= max_gap {
                self.integral += panel(t0, v0, time, value);
            }
        }
        self.last = Some((time, value));
    }

    /// The integral so far (0 before the second sample), in value units times time units.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The last sample pushed, `(time, value)`.
    pub fn last(&self) -> Option<(f64, f64)> {
        self.last
    }
}

/// One panel of the rule: `0.5 (v0 + v1) (t1 - t0)`.
#[inline(always)]
fn panel(t0: f64, v0: f64, t1: f64, v1: f64) -> f64 {
    0.5 * (v0 + v1) * (t1 - t0)
}

/// Trapezoidal integral of `values` over `times` (pairs up to the shorter slice), in value units
/// times time units; 0 for fewer than two samples.
pub fn trapezoid(times: &[f64], values: &[f64]) -> f64 {
    let mut acc = Trapezoid::new();
    for (&t, &v) in times.iter().zip(values) {
        acc.push(t, v);
    }
    acc.integral()
}

/// Trapezoidal integral of the piecewise-linear `values` over `times` (sorted) on the window
/// `[a, b]`: from `a` valued `at(a)`, through the samples strictly inside the window, to `b`
/// valued `at(b)` (the caller says how an end between or beyond the samples is valued:
/// interpolated, held, ...).
pub fn trapezoid_window(
    times: &[f64],
    values: &[f64],
    (a, b): (f64, f64),
    at: impl Fn(f64) -> f64,
) -> f64 {
    let mut acc = Trapezoid::new();
    acc.push(a, at(a));
    for (&t, &v) in times.iter().zip(values) {
        if t > a && t < b {
            acc.push(t, v);
        }
    }
    acc.push(b, at(b));
    acc.integral()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn exact_for_piecewise_linear_data() {
        // The integral of 2t + 1 over [0, 4] is 16 + 4 = 20, exact at any sampling.
        let t = [0.0, 0.5, 2.0, 2.25, 4.0];
        let v: Vec<f64> = t.iter().map(|x| 2.0 * x + 1.0).collect();
        assert!((trapezoid(&t, &v) - 20.0).abs() < 1e-12);
    }

    #[test]
    fn fewer_than_two_samples_integrate_to_zero() {
        assert_eq!(trapezoid(&[], &[]).to_bits(), 0f64.to_bits());
        assert_eq!(trapezoid(&[1.0], &[5.0]).to_bits(), 0f64.to_bits());
        assert_eq!(Trapezoid::new().last(), None);
    }

    #[test]
    fn a_gap_or_a_step_back_is_not_bridged() {
        // Panels 0-1 s (150) and 5-7 s (400) with gaps of at most 5 s; the 4 s step from 1 to 5
        // is bridged (800), the 6 s step from 7 to 13 and the step back to 12 are not.
        let mut acc = Trapezoid::new();
        for (t, v) in [(0.0, 100.0), (1.0, 200.0), (5.0, 200.0), (7.0, 200.0)] {
            acc.push_bridging(t, v, 5.0);
        }
        // Whole numbers: exact in binary, so compared bit for bit.
        assert_eq!(acc.integral().to_bits(), 1350f64.to_bits());
        acc.push_bridging(13.0, 200.0, 5.0);
        acc.push_bridging(12.0, 200.0, 5.0);
        assert_eq!(acc.integral().to_bits(), 1350f64.to_bits());
        assert_eq!(acc.last(), Some((12.0, 200.0)));
    }

    #[test]
    fn a_window_runs_from_its_ends_through_the_samples_inside() {
        // v = 2t sampled at 0, 1, 2, 3; over [0.5, 2.5] with the ends on the line: the panels
        // 0.5-1, 1-2, 2-2.5 are 0.75 + 3 + 2.25 = 6 (= 2.5^2 - 0.5^2); quarters and halves,
        // exact in binary.
        let (t, v) = ([0.0, 1.0, 2.0, 3.0], [0.0, 2.0, 4.0, 6.0]);
        let line = |x: f64| 2.0 * x;
        assert_eq!(
            trapezoid_window(&t, &v, (0.5, 2.5), line).to_bits(),
            6f64.to_bits()
        );
        // No sample inside: one panel between the ends; the ends held at 10 instead: 10 x 0.5.
        assert_eq!(
            trapezoid_window(&t, &v, (1.25, 1.75), |_| 10.0).to_bits(),
            5f64.to_bits()
        );
    }

    proptest! {
        /// The streaming and slice forms add the same panels in the same order: same bits.
        #[test]
        fn streaming_equals_slices(v in proptest::collection::vec(-1e3f64..1e3, 0..50)) {
            let t: Vec<f64> = (0..v.len()).map(|k| 0.1 * k as f64 + (k % 3) as f64 * 0.01).collect();
            let mut acc = Trapezoid::new();
            for (&a, &b) in t.iter().zip(&v) {
                acc.push(a, b);
            }
            prop_assert_eq!(acc.integral().to_bits(), trapezoid(&t, &v).to_bits());
        }

        /// Additive over a split at any sample.
        #[test]
        fn additive_over_a_split(v in proptest::collection::vec(0f64..1e3, 2..50), cut in 0usize..50) {
            let t: Vec<f64> = (0..v.len()).map(|k| k as f64).collect();
            let k = cut % v.len();
            let whole = trapezoid(&t, &v);
            let parts = trapezoid(&t[..=k], &v[..=k]) + trapezoid(&t[k..], &v[k..]);
            prop_assert!((whole - parts).abs() <= 1e-9 * whole.abs().max(1.0));
        }
    }
}
