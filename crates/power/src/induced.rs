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
//! whose root continuous with hover (`v_i = vh` at `v_inf = 0`) is the induced velocity. Under the
//! paper's approximations (3)-(4), `Vp^2 + Vn^2` is not `v_inf^2`; the quartic keeps both terms as
//! given. The solver (the quartic normalised by `vh`, its start, Halley steps, the branch-free fast
//! path and the safeguarded fallback) is in `quartic.rs`.
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
//! For `Vn >= 0` (climb, or forward flight with the disk tilted into the wind) there is exactly one
//! positive root. In a descent through the disk (`Vn < 0`) with little edgewise flow the quartic
//! can have three positive roots; the one continuous with hover is the largest, and it exists only
//! until the hover branch folds away (the vortex-ring / windmill-brake region, where momentum
//! theory does not hold). There [`induced_velocity_mps`] returns
//! [`PowerError::NoPhysicalInducedVelocity`] rather than a root on another branch (the argument is
//! in `quartic.rs`).
//!
//! # Deviation
//! The authors' public analysis scripts use `cos a` in the cubic term, unlike eq (9); aloft follows
//! the paper's equation.

use crate::error::{finite, positive, PowerError, Result};
use crate::quartic::solve_normalised;

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
        fn root_below_vh_for_nonnegative_inflow(vn in 0.0f64..40.0, vp in 0.0f64..40.0, vh in 1.0f64..30.0) {
            let v = induced_velocity_mps(vn, vp, vh).unwrap();
            prop_assert!(v <= vh * (1.0 + 1e-12));
        }
    }
}
