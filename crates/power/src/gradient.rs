//! Analytic gradient of the electrical power of a point query with respect to airspeed, roll and pitch.
//!
//! The paper (section VI-B) judges a model by whether the sign of its gradient matches the measured
//! one; planners that descend on power need it exactly. Chain rule through eq (5) for the thrust,
//! the angle-of-attack model for `Vn` and `Vp^2`, implicit differentiation of the quartic for `v_i`
//! (see [`crate::induced::induced_velocity_partials`]), and eqs (8), (11), (12), (14).
//! `vh` (eq 10) depends only on the weight, so it is constant here.
//!
//! At the hybrid cutoff and where the electrical floor at 0 is active the power is not
//! differentiable; the gradient returned is that of the active branch.

use serde::Serialize;

use crate::error::Result;
use crate::four_term::{AoaInput, FlightState, PowerModel};
use crate::induced::induced_velocity_partials;

/// Gradient of the electrical power `P_hat`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PowerGradient {
    /// `d P_hat / d v_inf`, W per m/s.
    pub d_airspeed_w_per_mps: f64,
    /// `d P_hat / d phi`, W per rad.
    pub d_roll_w_per_rad: f64,
    /// `d P_hat / d theta`, W per rad.
    pub d_pitch_w_per_rad: f64,
}

/// Partial derivatives of one quantity with respect to (airspeed, roll, pitch).
#[derive(Clone, Copy)]
struct D3([f64; 3]);

impl PowerModel {
    /// Electrical power and its gradient with respect to airspeed, roll and pitch.
    pub fn electrical_gradient(&self, state: &FlightState) -> Result<PowerGradient> {
        // Validates the state (and gives the terms the chain rule needs).
        let p = self.evaluate(state)?;
        let v = state.airspeed_mps;
        let (sr, cr) = state.roll_rad.sin_cos();
        let (sp, cp) = state.pitch_rad.sin_cos();
        let thrust = p.thrust_n;
        // eq (5): dT/dphi = T tan(phi), dT/dtheta = T tan(theta).
        let d_t = D3([0.0, thrust * sr / cr, thrust * sp / cp]);
        // Vn and its partials; Vp^2 and its partials.
        let (vn, d_vn, vp2, d_vp2) = match state.aoa {
            AoaInput::Paper => {
                let vn = v * sr * sp;
                let vp = v * cr * cp;
                let d_vn = D3([sr * sp, v * cr * sp, v * sr * cp]);
                let d_vp = [cr * cp, -v * sr * cp, -v * cr * sp];
                (vn, d_vn, vp * vp, D3(d_vp.map(|d| 2.0 * vp * d)))
            }
            AoaInput::Geometric { air_direction_rad } => {
                let (sb, cb) = air_direction_rad.sin_cos();
                let k = -(cb * cr * sp - sb * sr);
                let vn = v * k;
                let d_vn = D3([k, v * (cb * sr * sp + sb * cr), -v * cb * cr * cp]);
                let vp2 = (v * v - vn * vn).max(0.0);
                let d_vp2 = D3([
                    2.0 * v - 2.0 * vn * d_vn.0[0],
                    -2.0 * vn * d_vn.0[1],
                    -2.0 * vn * d_vn.0[2],
                ]);
                (vn, d_vn, vp2, d_vp2)
            }
        };
        let vi = p.induced_velocity_mps;
        let (dvi_dvn, dvi_dvp2) = induced_velocity_partials(vi, vn, vp2);
        let veh = self.vehicle();
        let terms = self.options().terms;
        let profile_on =
            terms.profile && self.options().profile_cutoff_mps.is_none_or(|cut| v <= cut);
        let sqrt_t = thrust.sqrt();
        let mut grad = [0.0; 3];
        for (i, g) in grad.iter_mut().enumerate() {
            let dvi = dvi_dvn * d_vn.0[i] + dvi_dvp2 * d_vp2.0[i];
            let mut d = 0.0;
            if terms.induced {
                // Both AoA models: induced + acceleration work = T (v_i + Vn) (four_term docs);
                // with the geometric one the acceleration term subtracts the drag work that
                // eq (11) adds back below.
                d += d_t.0[i] * (vi + vn) + thrust * (dvi + d_vn.0[i]);
                if matches!(state.aoa, AoaInput::Geometric { .. }) && i == 0 {
                    d -= veh.drag().parasitic_power_derivative(v);
                }
            }
            if terms.parasitic && i == 0 {
                d += veh.drag().parasitic_power_derivative(v);
            }
            if profile_on {
                d += 1.5 * veh.kappa1() * sqrt_t * d_t.0[i]
                    + veh.kappa2() * (d_vp2.0[i] * sqrt_t + vp2 * 0.5 / sqrt_t * d_t.0[i]);
            }
            *g = if p.aero_w > 0.0 {
                d / veh.efficiency()
            } else {
                0.0
            };
        }
        Ok(PowerGradient {
            d_airspeed_w_per_mps: grad[0],
            d_roll_w_per_rad: grad[1],
            d_pitch_w_per_rad: grad[2],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::four_term::{ModelOptions, Terms};
    use crate::vehicle::tests::m100_params;
    use crate::vehicle::{Vehicle, VehicleParams};
    use proptest::prelude::*;

    fn model(kappa2: f64) -> PowerModel {
        PowerModel::with_options(
            Vehicle::new(VehicleParams {
                kappa2_w_s2_per_m2_n0_5: kappa2,
                ..m100_params()
            })
            .unwrap(),
            ModelOptions {
                terms: Terms::ALL,
                profile_cutoff_mps: None,
            },
        )
        .unwrap()
    }

    /// Five-point central difference: truncation O(h^4), round-off about eps * P / h.
    fn five_point(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
        (-f(x + 2.0 * h) + 8.0 * f(x + h) - 8.0 * f(x - h) + f(x - 2.0 * h)) / (12.0 * h)
    }

    fn check(m: &PowerModel, s: FlightState) -> std::result::Result<(), TestCaseError> {
        let g = m.electrical_gradient(&s).unwrap();
        let p = |s: FlightState| m.evaluate(&s).unwrap().electrical_w;
        let h = 1e-3;
        // The electrical power is floored at 0 (no regeneration), where it has a kink and no
        // gradient: a strongly decelerating state with the exact angle of attack can get there.
        // Test only where every stencil point is clear of the floor.
        let aero = |s: FlightState| m.evaluate(&s).unwrap().aero_w;
        for k in [-2.0, -1.0, 0.0, 1.0, 2.0] {
            let d = k * h;
            for probe in [
                FlightState {
                    airspeed_mps: s.airspeed_mps + d,
                    ..s
                },
                FlightState {
                    roll_rad: s.roll_rad + d,
                    ..s
                },
                FlightState {
                    pitch_rad: s.pitch_rad + d,
                    ..s
                },
            ] {
                prop_assume!(aero(probe) > 1.0, "at the no-regeneration floor");
            }
        }
        let fd = [
            five_point(
                |x| {
                    p(FlightState {
                        airspeed_mps: x,
                        ..s
                    })
                },
                s.airspeed_mps,
                h,
            ),
            five_point(|x| p(FlightState { roll_rad: x, ..s }), s.roll_rad, h),
            five_point(|x| p(FlightState { pitch_rad: x, ..s }), s.pitch_rad, h),
        ];
        let an = [
            g.d_airspeed_w_per_mps,
            g.d_roll_w_per_rad,
            g.d_pitch_w_per_rad,
        ];
        for i in 0..3 {
            // 1e-6 relative; gradients below 1 W per unit are compared to 1e-6 W per unit absolute
            // (a relative test of a gradient through zero is meaningless). The stencil's own error
            // (h^4 terms and eps*P/h, about 1e-10 W here) is far inside that.
            let tol = 1e-6 * an[i].abs().max(1.0);
            prop_assert!(
                (an[i] - fd[i]).abs() <= tol,
                "component {} analytic {} fd {} at {:?}",
                i,
                an[i],
                fd[i],
                s
            );
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]

        #[test]
        fn gradient_matches_finite_differences_paper_aoa(
            v in 0.01f64..25.0, r in -0.6f64..0.6, q in -0.6f64..0.6, c in -3.0f64..3.0, k2 in 0.0f64..0.05,
        ) {
            // Airspeed starts above 2h so the stencil stays at v >= 0.
            check(&model(k2), FlightState::new(v, r, q, c))?;
        }

        #[test]
        fn gradient_matches_finite_differences_geometric_aoa(
            v in 0.01f64..25.0, r in -0.6f64..0.6, q in -0.6f64..0.6, b in -3.1f64..3.1, k2 in 0.0f64..0.05,
        ) {
            let s = FlightState { aoa: AoaInput::Geometric { air_direction_rad: b }, ..FlightState::new(v, r, q, 0.0) };
            check(&model(k2), s)?;
        }
    }
}
