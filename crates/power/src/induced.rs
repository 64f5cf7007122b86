//! Induced velocity and induced power: eqs (8)-(10) of the power seed.
//!
//! Hover induced velocity, eq (10): `vh = sqrt(m g / (2 rho A))` with `A` the disk area the vehicle
//! file chooses (see [`crate::DiskArea`]).
//!
//! Induced velocity, eq (9): `v_i = vh^2 / sqrt((v_inf cos a)^2 + (v_i + v_inf sin a)^2)`.
//! With `Vp = v_inf cos a` (in the rotor plane) and `Vn = v_inf sin a` (along the rotor axis, in the
//! direction of the induced flow), squaring gives the quartic
//!
//! `v^4 + 2 Vn v^3 + (Vn^2 + Vp^2) v^2 - vh^4 = 0`,
//!
//! solved here for the root continuous with hover (`v_i = vh` at `v_inf = 0`). Under the paper's
//! approximations (3)-(4), `Vp^2 + Vn^2` is not `v_inf^2`; the quartic keeps both terms as given.
//!
//! Induced power, eq (8): `P_ind = T (v_i + Vn)`; the paper writes `Vn = v_inf sin(phi) sin(theta)`.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `T` | total thrust | N |
//! | `vh` | hover induced velocity | m/s |
//! | `v_i` | induced velocity | m/s |
//! | `Vn`, `Vp` | freestream along the rotor axis / in the rotor plane | m/s |
//!
//! # Which root
//! Write `x = v/vh`, `a = Vn/vh`, `b = Vp/vh`; the quartic is `g(x) = x^2((x+a)^2 + b^2) = 1`.
//! For `a >= 0` (climb, or forward flight with the disk tilted into the wind) `g` is increasing on
//! `x > 0` and there is exactly one positive root. For `a < 0` (descent through the disk) `g` has a
//! local maximum and minimum on `x > 0` when `b^2 < a^2 / 8`; the root continuous with hover along
//! the ray from hover is then the largest root, which exists only while `g` at its local minimum
//! stays below 1. Past that the hover branch has folded away (the vortex-ring / windmill-brake
//! region, where momentum theory does not hold) and [`induced_velocity_mps`] returns
//! [`PowerError::NoPhysicalInducedVelocity`] rather than a root on another branch.
//!
//! # Deviation
//! The authors' public analysis scripts use `cos a` in the cubic term, unlike eq (9); aloft follows
//! the paper's equation.

use crate::error::{finite, positive, PowerError, Result};

/// Hover induced velocity, eq (10): `vh = sqrt(W / (2 rho A))`, m/s.
///
/// `weight_n` is `m g` (N), `air_density_kg_m3` is `rho`, `disk_area_m2` is `A`.
#[inline]
pub fn hover_induced_velocity_mps(weight_n: f64, air_density_kg_m3: f64, disk_area_m2: f64) -> f64 {
    (weight_n / (2.0 * air_density_kg_m3 * disk_area_m2)).sqrt()
}

/// Induced velocity `v_i` of eq (9), m/s: the root of the quartic continuous with hover.
///
/// `normal_mps` is `Vn` (positive when the freestream passes through the disk in the direction of
/// the induced flow: climb, or forward flight with the disk tilted into the wind), `parallel_mps` is
/// `Vp >= 0`, `hover_mps` is `vh > 0`.
///
/// Errors: non-finite inputs, negative `Vp`, non-positive `vh`, and the vortex-ring region where no
/// root is continuous with hover (see the module docs).
pub fn induced_velocity_mps(normal_mps: f64, parallel_mps: f64, hover_mps: f64) -> Result<f64> {
    finite("normal_inflow_mps", normal_mps)?;
    finite("parallel_inflow_mps", parallel_mps)?;
    positive("hover_induced_velocity_mps", hover_mps)?;
    if parallel_mps < 0.0 {
        return Err(PowerError::Negative {
            name: "parallel_inflow_mps",
            value: parallel_mps,
        });
    }
    let a = normal_mps / hover_mps;
    let b = parallel_mps / hover_mps;
    match solve_normalised(a, b) {
        Some(x) => Ok(x * hover_mps),
        None => Err(PowerError::NoPhysicalInducedVelocity {
            normal_mps,
            parallel_mps,
            hover_mps,
        }),
    }
}

/// Solve `x^2((x+a)^2 + b^2) = 1` for the root continuous with hover; `None` in the fold region.
///
/// Safeguarded Halley iteration (cubic convergence, one division a step): each iterate stays inside
/// a bracket `[lo, hi]` with `g(lo) < 1 < g(hi)`, falling back to bisection when a step leaves it.
/// The start is the exact root for `a = 0` moved by the first-order term in `a`, so typical flight
/// states converge in one or two steps. At least one step is always taken. Stops when `|g(x) - 1| <= 1e-12`: since eq (9) reads `h(x) = x sqrt((x+a)^2 + b^2) = 1` with
/// `g = h^2`, its relative residual `|1 - 1/h|` is about `|g - 1| / 2`, at most 5e-13 (the issue
/// asks for 1e-10).
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

/// Partial derivatives of `v_i` with respect to `Vn` and `Vp^2`, by implicit differentiation of
/// the quartic `F = v^2((v+Vn)^2 + Vp^2) - vh^4 = 0` (`vh` held fixed).
///
/// Returns `(d v_i / d Vn, d v_i / d (Vp^2))`.
#[inline]
pub fn induced_velocity_partials(
    induced_mps: f64,
    normal_mps: f64,
    parallel_sq: f64,
) -> (f64, f64) {
    let v = induced_mps;
    let s = v + normal_mps;
    let f_v = 2.0 * v * (s * s + parallel_sq) + 2.0 * v * v * s;
    let f_vn = 2.0 * v * v * s;
    let f_vp2 = v * v;
    (-f_vn / f_v, -f_vp2 / f_v)
}

/// Induced power, eq (8): `P_ind = T (v_i + Vn)`, W.
#[inline]
pub fn induced_power_w(thrust_n: f64, induced_mps: f64, normal_mps: f64) -> f64 {
    thrust_n * (induced_mps + normal_mps)
}

/// Eq (8) from the normalised root `x = v_i / vh`: `T (v_i + Vn)` written as `x (T vh) + T Vn`,
/// W. The factors that do not wait for the root are multiplied first, so one multiply-add follows
/// the solver (the form [`crate::PowerModel`] uses; [`induced_power_w`] is the same equation from
/// `v_i`).
#[inline(always)]
pub(crate) fn induced_power_of_root_w(
    thrust_n: f64,
    x: f64,
    hover_mps: f64,
    normal_mps: f64,
) -> f64 {
    x * (thrust_n * hover_mps) + thrust_n * normal_mps
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Relative residual of eq (9) itself (not of the squared quartic).
    fn eq9_residual(v: f64, vn: f64, vp: f64, vh: f64) -> f64 {
        let rhs = vh * vh / (vp * vp + (v + vn) * (v + vn)).sqrt();
        (v - rhs).abs() / v
    }

    #[test]
    fn paper_val_eq9_hover_gives_vh() {
        for vh in [1.0, 7.3, 11.9, 30.0] {
            let v = induced_velocity_mps(0.0, 0.0, vh).unwrap();
            assert!((v - vh).abs() <= 1e-14 * vh, "{v} vs {vh}");
        }
    }

    #[test]
    fn paper_val_eq9_axial_climb_closed_form() {
        // Pure axial climb (Vp = 0, Vn = Vc > 0): v (v + Vc) = vh^2, so
        // v = -Vc/2 + sqrt(Vc^2/4 + vh^2) (Leishman's climb solution).
        let (vh, vc) = (10.0f64, 4.0f64);
        let expected = -vc / 2.0 + (vc * vc / 4.0 + vh * vh).sqrt();
        let v = induced_velocity_mps(vc, 0.0, vh).unwrap();
        assert!((v - expected).abs() < 1e-12 * expected, "{v} vs {expected}");
    }

    #[test]
    fn paper_val_eq9_edgewise_closed_form() {
        // Edgewise flight (Vn = 0): v^2 (v^2 + Vp^2) = vh^4, so
        // v^2 = (-Vp^2 + sqrt(Vp^4 + 4 vh^4)) / 2.
        let (vh, vp) = (11.0f64, 8.0f64);
        let v2 = (-vp * vp + (vp.powi(4) + 4.0 * vh.powi(4)).sqrt()) / 2.0;
        let v = induced_velocity_mps(0.0, vp, vh).unwrap();
        assert!((v - v2.sqrt()).abs() < 1e-12 * v, "{v}");
    }

    #[test]
    fn slow_axial_descent_stays_on_the_hover_branch() {
        // Vn = -Vd with Vd < 2 vh: the only root with v + Vn > 0 is the climb formula continued.
        let (vh, vd) = (10.0f64, 5.0f64);
        let expected = vd / 2.0 + (vd * vd / 4.0 + vh * vh).sqrt();
        let v = induced_velocity_mps(-vd, 0.0, vh).unwrap();
        assert!((v - expected).abs() < 1e-12 * expected, "{v} vs {expected}");
    }

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

    #[test]
    fn vortex_ring_region_is_a_typed_error() {
        // A steep axial descent with a small edgewise component: the hover branch has folded.
        let err = induced_velocity_mps(-30.0, 1.0, 1.0).unwrap_err();
        assert!(
            matches!(err, PowerError::NoPhysicalInducedVelocity { .. }),
            "{err}"
        );
        assert!(induced_velocity_mps(f64::NAN, 0.0, 1.0).is_err());
        assert!(induced_velocity_mps(0.0, -1.0, 1.0).is_err());
        assert!(induced_velocity_mps(0.0, 1.0, 0.0).is_err());
    }

    #[test]
    fn paper_val_eq8_hover_induced_power_is_thrust_times_vh() {
        let vh = hover_induced_velocity_mps(32.26, 1.225, std::f64::consts::PI * 0.172 * 0.172);
        let v = induced_velocity_mps(0.0, 0.0, vh).unwrap();
        let p = induced_power_w(32.26, v, 0.0);
        assert!((p - 32.26 * vh).abs() < 1e-12 * p);
        // The model's form from the normalised root is the same equation.
        for (x, vn) in [(1.0, 0.0), (0.8, 1.5), (1.3, -2.0)] {
            let a = induced_power_of_root_w(32.26, x, vh, vn);
            let b = induced_power_w(32.26, x * vh, vn);
            assert!((a - b).abs() < 1e-14 * b.abs(), "{a} vs {b}");
        }
    }

    #[test]
    fn partials_match_finite_differences() {
        let (vh, vn, vp) = (10.0, 2.0, 6.0);
        let v = induced_velocity_mps(vn, vp, vh).unwrap();
        let (dvn, dvp2) = induced_velocity_partials(v, vn, vp * vp);
        let h = 1e-6;
        let fd_n = (induced_velocity_mps(vn + h, vp, vh).unwrap()
            - induced_velocity_mps(vn - h, vp, vh).unwrap())
            / (2.0 * h);
        let vp_hi = (vp * vp + h).sqrt();
        let vp_lo = (vp * vp - h).sqrt();
        let fd_p = (induced_velocity_mps(vn, vp_hi, vh).unwrap()
            - induced_velocity_mps(vn, vp_lo, vh).unwrap())
            / (2.0 * h);
        assert!((dvn - fd_n).abs() < 1e-7, "{dvn} vs {fd_n}");
        assert!((dvp2 - fd_p).abs() < 1e-7, "{dvp2} vs {fd_p}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]

        /// The envelope: airspeed 0-40 m/s, tilt up to 60 deg (so |Vn| <= 40 sin 60,
        /// Vp <= 40), vh 1-30 m/s, both signs of Vn. Every returned root satisfies eq (9) to 1e-10
        /// relative and is positive; where no root is returned, the error is the vortex-ring one.
        #[test]
        fn eq9_residual_below_1e10(
            airspeed in 0.0f64..40.0,
            alpha_deg in -60.0f64..60.0,
            vh in 1.0f64..30.0,
        ) {
            let alpha = alpha_deg.to_radians();
            let vn = airspeed * alpha.sin();
            let vp = airspeed * alpha.cos();
            match induced_velocity_mps(vn, vp, vh) {
                Ok(v) => {
                    prop_assert!(v > 0.0);
                    prop_assert!(eq9_residual(v, vn, vp, vh) < 1e-10, "residual {}", eq9_residual(v, vn, vp, vh));
                }
                Err(e) => {
                    let vortex = matches!(e, PowerError::NoPhysicalInducedVelocity { .. });
                    prop_assert!(vortex, "unexpected error {}", e);
                }
            }
        }

        /// The paper's approximation gives Vp = v cos(phi) cos(theta), Vn = v sin(phi) sin(theta),
        /// which is not a unit decomposition; the solver must take any such pair.
        #[test]
        fn eq9_residual_paper_approximation(
            airspeed in 0.0f64..40.0,
            roll_deg in -60.0f64..60.0,
            pitch_deg in -60.0f64..60.0,
            vh in 1.0f64..30.0,
        ) {
            let (r, p) = (roll_deg.to_radians(), pitch_deg.to_radians());
            let vn = airspeed * r.sin() * p.sin();
            let vp = airspeed * r.cos() * p.cos();
            if let Ok(v) = induced_velocity_mps(vn, vp, vh) {
                prop_assert!(eq9_residual(v, vn, vp, vh) < 1e-10);
            }
        }

        /// Continuity with hover: for Vn >= 0 the root decreases as inflow grows and never exceeds vh.
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

        #[test]
        fn root_below_vh_for_nonnegative_inflow(vn in 0.0f64..40.0, vp in 0.0f64..40.0, vh in 1.0f64..30.0) {
            let v = induced_velocity_mps(vn, vp, vh).unwrap();
            prop_assert!(v <= vh * (1.0 + 1e-12));
        }
    }
}
