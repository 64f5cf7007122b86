//! Bisection, the one root bracketing of aloft: the speed at which a drag law reaches a force,
//! and the reference searches of the tests.

/// Halve `[lo, hi]` `iterations` times, keeping the half where `below` changes from true to
/// false: the bracket of the crossing of a `below` that holds at `lo` and not at `hi` (the ends
/// are not checked). Each step tries the midpoint `0.5 (lo + hi)`.
///
/// ```
/// let (lo, hi) = aloft_core::bisect(0.0, 2.0, 60, |x| x * x < 2.0);
/// assert!(lo <= std::f64::consts::SQRT_2 && std::f64::consts::SQRT_2 <= hi);
/// assert!(hi - lo < 1e-15);
/// ```
pub fn bisect(
    mut lo: f64,
    mut hi: f64,
    iterations: u32,
    mut below: impl FnMut(f64) -> bool,
) -> (f64, f64) {
    for _ in 0..iterations {
        let mid = 0.5 * (lo + hi);
        if below(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, hi)
}
