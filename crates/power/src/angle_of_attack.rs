//! Angle of attack of the rotor plane: the paper's approximation (eqs 3-4) and the exact geometry.
//!
//! `alpha` is the angle between the freestream and the rotor plane. The power model needs its two
//! projections of the airspeed `v_inf`:
//!
//! - `Vp = v_inf cos(alpha)`: the freestream component in the rotor plane, m/s;
//! - `Vn = v_inf sin(alpha)`: the component along the rotor axis, positive when the air passes
//!   through the disk in the direction of the induced flow (top to bottom), as in climb or in
//!   forward flight with the disk tilted into the wind, m/s.
//!
//! # Paper approximation, eqs (3)-(4)
//! Assuming level flight and planar wind, the paper writes `cos(alpha) = cos(phi) cos(theta)` and
//! `sin(alpha) = sin(phi) sin(theta)` from roll `phi` and pitch `theta` alone. These do not satisfy
//! `cos^2 + sin^2 = 1`; both projections are kept exactly as written.
//!
//! # Exact geometry
//! From the attitude and the air-relative velocity vector `v_air` of the vehicle (its velocity
//! relative to the air; the freestream is `-v_air`): with `t` the unit thrust axis (body up),
//! `Vn = v_air . t` and `Vp = |v_air - (v_air . t) t|`.
//!
//! The two agree exactly when the attitude is level (any horizontal air velocity), at zero airspeed,
//! and in `Vp` for a pure pitch with the air along the nose or a pure roll with the air from the
//! side; elsewhere they differ (the approximation gives `Vn = 0` for any single-axis tilt).
//!
//! # Attitude convention
//! Roll `phi`, pitch `theta`, yaw `psi` are the aerospace Z-Y-X Euler angles of the body
//! (x forward, y right, z down) relative to north-east-down: positive roll lowers the right side,
//! positive pitch raises the nose, yaw is the heading clockwise from north. The paper's Fig. 2 uses
//! the same signs (z down, positive pitch nose up). Results are returned in east-north-up (ENU),
//! the frame aloft's missions use.

use nalgebra::{Rotation3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::PowerError;

/// Which angle-of-attack model the power model uses.
///
/// Written `paper` or `geometric` everywhere: in files (serde), on the command line
/// ([`std::str::FromStr`]) and in output ([`std::fmt::Display`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AoaModel {
    /// The paper's eqs (3)-(4), from roll and pitch only.
    #[default]
    Paper,
    /// The exact angle between the air-relative velocity and the rotor plane.
    Geometric,
}

impl AoaModel {
    /// Both models, the default first.
    pub const ALL: [AoaModel; 2] = [AoaModel::Paper, AoaModel::Geometric];

    /// The name in files, on the command line and in output: `paper` or `geometric`.
    pub fn name(self) -> &'static str {
        match self {
            AoaModel::Paper => "paper",
            AoaModel::Geometric => "geometric",
        }
    }
}

impl std::fmt::Display for AoaModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for AoaModel {
    type Err = PowerError;

    /// `paper` or `geometric` (exactly, as in files); anything else is
    /// [`PowerError::UnknownAoaModel`], naming what was found and what is accepted.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| PowerError::UnknownAoaModel {
                found: s.to_string(),
            })
    }
}

/// The freestream decomposed on the rotor disk.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Inflow {
    /// `Vn = v_inf sin(alpha)`, along the rotor axis in the direction of the induced flow, m/s.
    pub normal_mps: f64,
    /// `Vp = v_inf cos(alpha) >= 0`, in the rotor plane, m/s.
    pub parallel_mps: f64,
}

impl Inflow {
    /// The angle of attack `alpha = atan2(Vn, Vp)`, rad.
    pub fn alpha_rad(&self) -> f64 {
        self.normal_mps.atan2(self.parallel_mps)
    }
}

/// The paper's inflow from eqs (3)-(4): `Vp = v cos(phi) cos(theta)`, `Vn = v sin(phi) sin(theta)`.
///
/// `cos(phi) cos(theta)` is positive for tilts below 90 deg, so `Vp >= 0` for `airspeed_mps >= 0`.
#[inline]
pub fn paper_inflow(airspeed_mps: f64, roll_rad: f64, pitch_rad: f64) -> Inflow {
    let (sr, cr) = roll_rad.sin_cos();
    let (sp, cp) = pitch_rad.sin_cos();
    Inflow {
        normal_mps: airspeed_mps * sr * sp,
        parallel_mps: airspeed_mps * cr * cp,
    }
}

/// Exact inflow from the unit thrust axis `t` and the air-relative velocity `v_air` of the vehicle,
/// both in the same frame: `Vn = v_air . t`, `Vp = |v_air - Vn t|`.
#[inline]
pub fn geometric_inflow(thrust_axis: &Vector3<f64>, vel_air_mps: &Vector3<f64>) -> Inflow {
    let normal = vel_air_mps.dot(thrust_axis);
    let parallel = (vel_air_mps - thrust_axis * normal).norm();
    Inflow {
        normal_mps: normal,
        parallel_mps: parallel,
    }
}

/// Rotation from the body frame (forward-right-down) to north-east-down for Z-Y-X Euler angles.
#[inline]
pub fn body_to_ned(roll_rad: f64, pitch_rad: f64, yaw_rad: f64) -> Rotation3<f64> {
    // nalgebra's from_euler_angles(roll, pitch, yaw) is Rz(yaw) * Ry(pitch) * Rx(roll).
    Rotation3::from_euler_angles(roll_rad, pitch_rad, yaw_rad)
}

/// Convert a north-east-down vector to east-north-up.
#[inline]
pub fn ned_to_enu(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.y, v.x, -v.z)
}

/// Convert an east-north-up vector to north-east-down.
#[inline]
pub fn enu_to_ned(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.y, v.x, -v.z)
}

/// Unit thrust axis (body up, `-z` of forward-right-down) in east-north-up for the given attitude.
#[inline]
pub fn thrust_axis_enu(roll_rad: f64, pitch_rad: f64, yaw_rad: f64) -> Vector3<f64> {
    let up_body = Vector3::new(0.0, 0.0, -1.0);
    ned_to_enu(&(body_to_ned(roll_rad, pitch_rad, yaw_rad) * up_body))
}

/// Exact inflow for a point query: horizontal air-relative velocity of magnitude `airspeed_mps` in
/// the direction `air_direction_rad` from the nose (0 = flying forward through the air, +90 deg =
/// flying to the right), attitude `roll_rad`, `pitch_rad`.
pub fn body_relative_inflow(
    airspeed_mps: f64,
    roll_rad: f64,
    pitch_rad: f64,
    air_direction_rad: f64,
) -> Inflow {
    // Heading north (yaw 0): the nose points north, the right side east.
    let (s, c) = air_direction_rad.sin_cos();
    let vel_air_enu = Vector3::new(airspeed_mps * s, airspeed_mps * c, 0.0);
    geometric_inflow(&thrust_axis_enu(roll_rad, pitch_rad, 0.0), &vel_air_enu)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn aoa_model_names_agree_in_files_arguments_and_output() {
        for m in AoaModel::ALL {
            // serde (files), Display (output) and FromStr (arguments) use the same word.
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{m}\""));
            assert_eq!(serde_json::from_str::<AoaModel>(&json).unwrap(), m);
            assert_eq!(m.to_string().parse::<AoaModel>().unwrap(), m);
        }
        assert_eq!("paper".parse::<AoaModel>().unwrap(), AoaModel::Paper);
        assert_eq!(
            "geometric".parse::<AoaModel>().unwrap(),
            AoaModel::Geometric
        );
        assert_eq!(AoaModel::default(), AoaModel::Paper);
    }

    #[test]
    fn unknown_aoa_model_names_what_was_found_and_what_is_accepted() {
        for bad in ["exact", "Paper", " paper", ""] {
            let e = bad.parse::<AoaModel>().unwrap_err();
            assert_eq!(
                e,
                PowerError::UnknownAoaModel {
                    found: bad.to_string()
                }
            );
            let message = e.to_string();
            assert!(message.contains(&format!("'{bad}'")), "{message}");
            for m in AoaModel::ALL {
                assert!(message.contains(m.name()), "{message} should offer {m}");
            }
        }
        assert!(serde_json::from_str::<AoaModel>("\"exact\"").is_err());
    }

    fn close(a: f64, b: f64) -> bool {
        // Trigonometric round-off through a rotation matrix: a few ulp of the airspeed.
        (a - b).abs() < 1e-12 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn thrust_axis_tilts_forward_when_nose_down() {
        let t = thrust_axis_enu(0.0, -0.3, 0.0);
        // Heading north, nose down: thrust gains a north (+y ENU) component.
        assert!(t.y > 0.0 && t.z > 0.0 && t.x.abs() < 1e-15);
        let t = thrust_axis_enu(0.3, 0.0, 0.0);
        // Right side down: thrust tilts to the right (east, +x ENU).
        assert!(t.x > 0.0);
        assert!(close(t.norm(), 1.0));
    }

    #[test]
    fn forward_flight_nose_down_has_positive_normal_inflow() {
        let theta: f64 = -0.2;
        let i = body_relative_inflow(10.0, 0.0, theta, 0.0);
        assert!(close(i.normal_mps, -10.0 * theta.sin()));
        assert!(close(i.parallel_mps, 10.0 * theta.cos()));
        assert!(i.normal_mps > 0.0);
    }

    #[test]
    fn climb_is_positive_normal_inflow() {
        let i = geometric_inflow(&Vector3::z(), &Vector3::new(0.0, 0.0, 3.0));
        assert!(close(i.normal_mps, 3.0) && close(i.parallel_mps, 0.0));
    }

    #[test]
    fn single_axis_tilts_agree_in_parallel_component() {
        // Pure pitch with the air along the nose, pure roll with the air from the side.
        let (p, g) = (
            paper_inflow(7.0, 0.0, 0.4),
            body_relative_inflow(7.0, 0.0, 0.4, 0.0),
        );
        assert!(close(p.parallel_mps, g.parallel_mps));
        let (p, g) = (
            paper_inflow(7.0, 0.4, 0.0),
            body_relative_inflow(7.0, 0.4, 0.0, std::f64::consts::FRAC_PI_2),
        );
        assert!(close(p.parallel_mps, g.parallel_mps));
        // ...but not in the normal component: the approximation drops it for a single-axis tilt.
        assert!(p.normal_mps.abs() < 1e-15 && g.normal_mps.abs() > 2.0);
    }

    proptest! {
        /// Level attitude: the approximation is exact for any horizontal air direction.
        #[test]
        fn level_attitude_agrees(v in 0.0f64..40.0, dir in -3.2f64..3.2) {
            let p = paper_inflow(v, 0.0, 0.0);
            let g = body_relative_inflow(v, 0.0, 0.0, dir);
            prop_assert!(close(p.normal_mps, g.normal_mps) && close(p.parallel_mps, g.parallel_mps));
        }

        /// Zero airspeed: both give no inflow for any attitude.
        #[test]
        fn hover_agrees(r in -1.0f64..1.0, q in -1.0f64..1.0, dir in -3.2f64..3.2) {
            let g = body_relative_inflow(0.0, r, q, dir);
            let p = paper_inflow(0.0, r, q);
            prop_assert!(g.normal_mps.abs() < 1e-15 && p.normal_mps.abs() < 1e-15);
        }

        /// The exact decomposition is a true one: Vn^2 + Vp^2 = v^2.
        #[test]
        fn geometric_is_orthogonal(v in 0.0f64..40.0, r in -1.0f64..1.0, q in -1.0f64..1.0, dir in -3.2f64..3.2) {
            let g = body_relative_inflow(v, r, q, dir);
            prop_assert!(close(g.normal_mps.hypot(g.parallel_mps), v));
        }

        /// The exact inflow equals its closed form for yaw 0:
        /// Vn = -v (cos(beta) cos(phi) sin(theta) - sin(beta) sin(phi)).
        #[test]
        fn geometric_closed_form(v in 0.0f64..40.0, r in -1.0f64..1.0, q in -1.0f64..1.0, b in -3.2f64..3.2) {
            let g = body_relative_inflow(v, r, q, b);
            let vn = -v * (b.cos() * r.cos() * q.sin() - b.sin() * r.sin());
            prop_assert!(close(g.normal_mps, vn));
        }
    }
}
