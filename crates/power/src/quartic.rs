//! The normalised quartic of eq (9) and its solver: the numerics behind
//! [`crate::induced::induced_velocity_mps`] and the power model's induced term.
//!
//! # The quartic
//! Eq (9) of the power seed, `v_i = vh^2 / sqrt((v_inf cos a)^2 + (v_i + v_inf sin a)^2)`, with
//! `Vp = v_inf cos a` and `Vn = v_inf sin a`, squares to the quartic
//!
//! `v^4 + 2 Vn v^3 + (Vn^2 + Vp^2) v^2 - vh^4 = 0`.
//!
//! Divided by `vh^4` and written in `x = v/vh`, `a = Vn/vh`, `b = Vp/vh`, it is
//!
//! `g(x) = x^2 ((x+a)^2 + b^2) = 1`,
//!
//! the form every function here solves (one vehicle constant, `vh`, scales out).
//!
//! # Which root
//! The root continuous with hover (`x = 1` at `a = b = 0`). For `a >= 0` (climb, or forward
//! flight with the disk tilted into the wind) `g` is increasing on `x > 0` and there is exactly
//! one positive root. For `a < 0` (descent through the disk) `g` has a local maximum and minimum
//! on `x > 0` when `b^2 < a^2 / 8`; the root continuous with hover along the ray from hover is then
//! the largest root, which exists only while `g` at its local minimum stays below 1. Past that the
//! hover branch has folded away (the vortex-ring / windmill-brake region, where momentum theory
//! does not hold) and [`solve_normalised`] returns `None` rather than a root on another branch;
//! [`crate::induced::induced_velocity_mps`] turns that into
//! [`crate::PowerError::NoPhysicalInducedVelocity`].
//!
//! # The paths
//! - [`solve_normalised`]: the checked solver every scalar evaluation uses. Where the root is
//!   unique, Halley steps from [`corrected_guess`] return the first iterate that meets
//!   [`RESIDUAL_BOUND`] (the first step unchecked where [`SETTLED_RESIDUAL`] proves it settled);
//!   anything left after five steps, and the three-root side of a descent, goes to
//!   [`solve_safeguarded`].
//! - [`solve_normalised_fast`]: the same iterates without data-dependent branches, for the vector
//!   lanes of `crate::kernels`; NaN where it cannot settle, and the caller then runs
//!   [`solve_normalised`]. Bit for bit the root [`solve_normalised`] returns (tests
//!   `scalar_and_lane_solvers_return_the_same_root` and
//!   `settled_first_step_meets_the_residual_bound` below).
//! - [`solve_safeguarded`]: Halley steps kept inside a bracket, with bisection when a step leaves
//!   it; also detects the fold.
//!
//! # Convergence
//! The start's error is of order `a^2` ([`corrected_guess`]) and Halley's step converges
//! cubically, so one step reaches the residual bound for the paper's small inflows and two for
//! `|a|` up to about 0.5. The stopping rule `|g(x) - 1| <= 1e-12` bounds eq (9)'s own relative
//! residual by about 5e-13 ([`solve_normalised`]); the property tests of `crate::induced` check
//! 1e-10 over the envelope.

/// Solve `x^2((x+a)^2 + b^2) = 1` for the root continuous with hover; `None` in the fold region.
///
/// Safeguarded Halley iteration (cubic convergence, one division a step): each iterate stays inside
/// a bracket `[lo, hi]` with `g(lo) < 1 < g(hi)`, falling back to bisection when a step leaves it.
/// The start is the exact root for `a = 0` moved by the first-order term in `a`, so typical flight
/// states converge in one or two steps. At least one step is always taken. Stops when
/// `|g(x) - 1| <= 1e-12`: since eq (9) reads `h(x) = x sqrt((x+a)^2 + b^2) = 1` with `g = h^2`,
/// its relative residual `|1 - 1/h|` is about `|g - 1| / 2`, at most 5e-13 (the issue asks for
/// 1e-10).
#[inline(always)]
pub(crate) fn solve_normalised(a: f64, b: f64) -> Option<f64> {
    let b2 = b * b;
    if a >= 0.0 || 8.0 * b2 >= a * a {
        // g is increasing on x > 0: the positive root is unique, and any positive x meeting the
        // residual bound is it. Fast path: Halley steps from the first-order guess, returning the
        // first iterate that meets the bound. One step suffices for the paper's inflow in typical
        // flight, two for |a| up to about 0.5 (forward flight with the exact inflow); the
        // safeguarded loop below takes anything left after five.
        //
        // Where the start's own residual already shows the first step lands inside the bound (see
        // SETTLED_RESIDUAL), that step is returned without evaluating the residual again: the
        // test waits only for the start, not for the end of the step.
        let x0 = corrected_guess(a, b);
        let (s, q, f) = residual(x0, a, b2);
        let mut x = halley_update(x0, s, q, f);
        if (f.abs() <= SETTLED_RESIDUAL) & (a.abs() <= SETTLED_INFLOW) {
            return Some(x);
        }
        for _ in 0..5 {
            let (s, q, f) = residual(x, a, b2);
            if x > 0.0 && f.abs() <= RESIDUAL_BOUND {
                return Some(x);
            }
            x = halley_update(x, s, q, f);
        }
    }
    solve_safeguarded(a, b2)
}

/// The safeguarded path of [`solve_normalised`] (kept out of line: rare, and large).
#[cold]
#[inline(never)]
fn solve_safeguarded(a: f64, b2: f64) -> Option<f64> {
    // Root of x sqrt(x^2 + c) = 1, written without cancellation: exact when a = 0, and an upper
    // bound of the root when a > 0 (since (x+a)^2 >= x^2 + a^2 there).
    let c = a * a + b2;
    let guess = (2.0 / (c + (c * c + 4.0).sqrt())).sqrt();
    let (mut lo, mut hi) = if a >= 0.0 {
        (0.0, guess)
    } else {
        let upper = 1.0 - a; // g(1 - a) = (1-a)^2 (1 + b^2) >= 1
        if b2 < a * a / 8.0 {
            // g has a local minimum at xm; the hover branch lies to its right.
            let xm = (-3.0 * a + (a * a - 8.0 * b2).sqrt()) / 4.0;
            let s = xm + a;
            if xm * xm * (s * s + b2) >= 1.0 {
                return None;
            }
            (xm, upper)
        } else {
            (0.0, upper)
        }
    };
    let mut x = if guess > lo && guess <= hi {
        guess
    } else {
        0.5 * (lo + hi)
    };
    for _ in 0..200 {
        let (s, q, f) = residual(x, a, b2);
        if f.abs() <= RESIDUAL_BOUND {
            return Some(x);
        }
        if f > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let mut next = halley_update(x, s, q, f);
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        x = next;
    }
    Some(x)
}

/// Branch-free fast path of [`solve_normalised`] for batches: where the root is unique, the first
/// of the guess's first two Halley iterates that meets the residual bound, otherwise NaN (the
/// caller then runs [`solve_normalised`]). It is the iterate [`solve_normalised`] returns, so the
/// results are bit-identical: where that function skips the check of the first step (see
/// [`SETTLED_RESIDUAL`]), the step meets the bound (test
/// `settled_first_step_meets_the_residual_bound`). Without data-dependent branches, consecutive
/// calls overlap in the CPU.
#[inline(always)]
pub(crate) fn solve_normalised_fast(a: f64, b: f64) -> f64 {
    let b2 = b * b;
    let x0 = corrected_guess(a, b);
    let (s0, q0, f0) = residual(x0, a, b2);
    let x1 = halley_update(x0, s0, q0, f0);
    let (s1, q1, f1) = residual(x1, a, b2);
    let x2 = halley_update(x1, s1, q1, f1);
    let (_, _, f2) = residual(x2, a, b2);
    let unique = (a >= 0.0) | (8.0 * b2 >= a * a);
    let c1 = (x1 > 0.0) & (f1.abs() <= RESIDUAL_BOUND);
    let c2 = (x2 > 0.0) & (f2.abs() <= RESIDUAL_BOUND);
    let x = if c2 { x2 } else { f64::NAN };
    let x = if c1 { x1 } else { x };
    if unique {
        x
    } else {
        f64::NAN
    }
}

/// Where [`solve_normalised`] returns the first Halley step without checking it: a start `x0`
/// with `|g(x0) - 1| <= SETTLED_RESIDUAL` and `|a| <= SETTLED_INFLOW`.
///
/// Halley's step converges cubically: the residual after it is about `C |g(x0) - 1|^3`. With
/// `|a| <= 0.5` the root has `x g'/g >= 2` (the slope at the root cannot vanish), so `C` stays
/// moderate, and a start within 1e-5 lands near 1e-15, far inside [`RESIDUAL_BOUND`]. A dense
/// sweep over `|a| <= 0.5`, `0 <= b <= 40` finds at most 1.0e-15 after the step (and 8e-14 even
/// with a start within 1e-4); the test `settled_first_step_meets_the_residual_bound` holds the
/// region to 1e-14.
const SETTLED_RESIDUAL: f64 = 1e-5;
/// See [`SETTLED_RESIDUAL`].
const SETTLED_INFLOW: f64 = 0.5;

/// Stopping rule of every path: `|g(x) - 1| <= 1e-12`, so eq (9)'s relative residual is at most
/// about 5e-13 (see [`solve_normalised`]).
const RESIDUAL_BOUND: f64 = 1e-12;

/// Starting point of every path: the exact root for `a = 0`, `y0 = x0^2 = (r - b^2)/2` with
/// `r = sqrt(b^4 + 4)`, moved by the first-order term in `a`, `dx/da = -x0^2 / (2 x0^2 + b^2)`
/// (implicit differentiation of the quartic at `a = 0`), where `2 y0 + b^2 = r`. Written so the
/// second square root and the division run side by side. `r - b^2` loses about `b^4 eps` relative
/// to cancellation (1e-10 at `b = 30`), harmless in a starting point; the guess's error is of
/// order `a^2`, so one Halley step (cubic convergence) reaches the residual bound for the paper's
/// small inflows and two for `|a|` up to about 0.5.
#[inline(always)]
fn corrected_guess(a: f64, b: f64) -> f64 {
    // With u = b^2/2 (computed beside b^2, not after it): r/2 = sqrt(u^2 + 1) and
    // y0 = sqrt(u^2 + 1) - u. Scaling by 2 and 4 is exact in floating point, so these are the
    // same numbers as r/2 and (r - b^2)/2 computed from b^2, with two operations fewer between b
    // and the root.
    let u = b * (0.5 * b);
    let half_r = (u * u + 1.0).sqrt();
    let y0 = half_r - u;
    let step = (0.5 * a) * y0 / half_r;
    // Far outside its range (large a) the correction can overshoot past zero: keep x0 where it
    // would leave less than a tenth of it, `step > 0.9 x0`. Tested on `x0^2 = y0` and written as a
    // branch (which the CPU predicts), so the root below never waits for the choice.
    let step = if step <= 0.0 || step * step < 0.81 * y0 {
        step
    } else {
        0.0
    };
    y0.sqrt() - step
}

/// `(x + a, (x + a)^2 + b^2, g(x) - 1)` for `g(x) = x^2 ((x+a)^2 + b^2)`: the residual and the
/// pieces a Halley step reuses.
#[inline(always)]
fn residual(x: f64, a: f64, b2: f64) -> (f64, f64, f64) {
    let s = x + a;
    let q = s * s + b2;
    (s, q, x * x * q - 1.0)
}

/// One Halley step for `g(x) = 1` from `x`, given [`residual`]'s `(s, q, f)` there, with
/// `g' = 2 x (q + x s)` and `g'' = 2 q + 8 x s + 2 x^2`.
#[inline(always)]
fn halley_update(x: f64, s: f64, q: f64, f: f64) -> f64 {
    let fp = 2.0 * x * (q + x * s);
    // g''/2: the step 2 f g' / (2 g'^2 - f g'') written as f g' / (g'^2 - f g''/2), the same value
    // bit for bit (the factors of 2 are exact) with one multiplication fewer on the chain.
    let half_fpp = q + 4.0 * x * s + x * x;
    x - f * fp / (fp * fp - f * half_fpp)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The start's residual and the first Halley step from it, as [`solve_normalised`] takes them.
    fn first_step(a: f64, b: f64) -> (f64, f64) {
        let b2 = b * b;
        let x0 = corrected_guess(a, b);
        let (s, q, f) = residual(x0, a, b2);
        (f, halley_update(x0, s, q, f))
    }

    #[test]
    fn settled_first_step_meets_the_residual_bound() {
        // Over the whole settled region of a (|a| <= 0.5) and b (0..40, denser near 0) where the
        // root is unique, wherever the start's residual is within SETTLED_RESIDUAL, the unchecked
        // first step is positive
        // and its residual is below 1e-14 (the sweep in the docs finds 1.0e-15), so it is the
        // iterate the checked paths return too.
        let (mut settled, mut worst) = (0u32, 0.0f64);
        for i in 0..=400 {
            let a = SETTLED_INFLOW * (f64::from(i) / 200.0 - 1.0);
            for j in 0..=400 {
                let t = f64::from(j) / 400.0;
                let b = 40.0 * t * t * t;
                let (f0, x1) = first_step(a, b);
                // Outside the unique-root region the safeguarded solver starts elsewhere.
                let unique = a >= 0.0 || 8.0 * b * b >= a * a;
                if !unique || f0.abs() > SETTLED_RESIDUAL {
                    continue;
                }
                settled += 1;
                assert!(x1 > 0.0, "a {a} b {b}");
                worst = worst.max(residual(x1, a, b * b).2.abs());
                assert_eq!(
                    solve_normalised(a, b).map(f64::to_bits),
                    Some(x1.to_bits()),
                    "a {a} b {b}"
                );
                assert_eq!(solve_normalised_fast(a, b).to_bits(), x1.to_bits());
            }
        }
        assert!(worst <= 1e-14, "worst residual {worst:e}");
        // The region is not empty: small inflows at every b settle.
        assert!(settled > 10_000, "{settled}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]

        #[test]
        fn scalar_and_lane_solvers_return_the_same_root(a in -3.0f64..3.0, b in 0.0f64..40.0) {
            // The lane solver returns the scalar solver's root bit for bit, or leaves it (NaN).
            let fast = solve_normalised_fast(a, b);
            if !fast.is_nan() {
                prop_assert_eq!(solve_normalised(a, b).map(f64::to_bits), Some(fast.to_bits()));
            }
            if let Some(x) = solve_normalised(a, b) {
                prop_assert!(residual(x, a, b * b).2.abs() <= RESIDUAL_BOUND);
            }
        }
    }
}
