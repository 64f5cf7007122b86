//! Cubic drag, eq (6), and parasitic power, eq (11), of the power seed.
//!
//! `f_D = mu1 v + mu2 v^2 + mu3 v^3`, directed along the freestream, and `P_par = f_D v`.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `v` | airspeed, the norm of the freestream `v_inf` | m/s |
//! | `mu1`, `mu2`, `mu3` | drag coefficients | N s/m, N s^2/m^2, N s^3/m^3 |
//! | `f_D` | drag force | N |
//! | `P_par` | parasitic power | W |
//!
//! The paper fits the cubic to drag estimated from level flights of its M100 up to about 10 m/s
//! (Fig. 3); outside the fitted range the cubic is an extrapolation.
//!
//! # Deviation: body-axis drag (optional)
//! Eq (6) assumes the drag is co-linear with the freestream ("we assume that f_D is always
//! co-linear with v_inf"). A multirotor's frontal area differs between its body axes (arms,
//! battery and payload are not round), so with [`CubicDrag::with_body_axes`] the quadratic
//! (area) coefficient differs by horizontal body axis `b` (forward `x`, right `y`):
//!
//! `D_b = (mu1 + mu2_b |v| + mu3 |v|^2) v_b`, `b = x, y`; vertically `D_z = f_D(|v|) v_z / |v|`,
//!
//! which is eq (6) again when `mu2_x = mu2_y = mu2`. `mu1` (rotor drag, proportional to speed)
//! and `mu3` stay common to both axes: the quadratic term is the one that scales with a frontal
//! area, `mu2_b = rho C_D A_b / 2`. The drag vector then points along the freestream only when
//! flying along an axis. Without the body-axis keys the law is the scalar eq (6), bit for bit.

use crate::error::{finite, PowerError, Result};

/// Highest airspeed at which [`CubicDrag::new`] checks that the drag force is not negative, m/s.
pub const DRAG_CHECK_MAX_MPS: f64 = 60.0;

/// The cubic drag law of eq (6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubicDrag {
    mu1: f64,
    mu2: f64,
    mu3: f64,
    body_mu2: Option<[f64; 2]>,
}

impl CubicDrag {
    /// Build the drag law, rejecting coefficients that give a negative drag force anywhere in
    /// 0-[`DRAG_CHECK_MAX_MPS`] m/s (drag that pushes the vehicle forward is not physical).
    pub fn new(mu1_n_s_per_m: f64, mu2_n_s2_per_m2: f64, mu3_n_s3_per_m3: f64) -> Result<Self> {
        finite("mu1_n_s_per_m", mu1_n_s_per_m)?;
        finite("mu2_n_s2_per_m2", mu2_n_s2_per_m2)?;
        finite("mu3_n_s3_per_m3", mu3_n_s3_per_m3)?;
        let drag = Self {
            mu1: mu1_n_s_per_m,
            mu2: mu2_n_s2_per_m2,
            mu3: mu3_n_s3_per_m3,
            body_mu2: None,
        };
        // f_D(v) = v q(v) with q(v) = mu1 + mu2 v + mu3 v^2; f_D < 0 for some v > 0 iff q < 0 there.
        // q is a parabola: its minimum over [0, vmax] is at an end or at the vertex.
        let mut candidates = vec![1e-9, DRAG_CHECK_MAX_MPS];
        if mu3_n_s3_per_m3 > 0.0 {
            let vertex = -mu2_n_s2_per_m2 / (2.0 * mu3_n_s3_per_m3);
            if vertex > 0.0 && vertex < DRAG_CHECK_MAX_MPS {
                candidates.push(vertex);
            }
        }
        for v in candidates {
            let f = drag.force_n(v);
            if f < 0.0 {
                return Err(PowerError::NegativeDrag {
                    airspeed_mps: v,
                    drag_n: f,
                });
            }
        }
        Ok(drag)
    }

    /// Drag force magnitude `f_D` at airspeed `v`, eq (6), N.
    #[inline]
    pub fn force_n(&self, airspeed_mps: f64) -> f64 {
        let v = airspeed_mps;
        v * (self.mu1 + v * (self.mu2 + v * self.mu3))
    }

    /// The airspeed at which the drag is `force_n`, m/s: the inverse of eq (6) on
    /// `[0, max_mps]` by bisection to the last bit (the first crossing where the law is not
    /// monotonic); `None` where the law stays below `force_n` up to `max_mps`, or for a force that
    /// is negative or not finite.
    pub fn airspeed_for_force(&self, force_n: f64, max_mps: f64) -> Option<f64> {
        if !(force_n.is_finite() && force_n >= 0.0) || self.force_n(max_mps) < force_n {
            return None;
        }
        let (lo, hi) = aloft_core::bisect(0.0, max_mps, 64, |v| self.force_n(v) < force_n);
        Some(0.5 * (lo + hi))
    }

    /// Parasitic power `P_par = f_D v`, eq (11), W.
    #[inline]
    pub fn parasitic_power_w(&self, airspeed_mps: f64) -> f64 {
        self.force_n(airspeed_mps) * airspeed_mps
    }

    /// Derivative of the parasitic power with respect to airspeed, `d P_par / d v`, W s/m.
    #[inline]
    pub fn parasitic_power_derivative(&self, airspeed_mps: f64) -> f64 {
        let v = airspeed_mps;
        v * (2.0 * self.mu1 + v * (3.0 * self.mu2 + v * 4.0 * self.mu3))
    }

    /// The same law with body-axis quadratic coefficients `mu2_x` (forward) and `mu2_y` (right),
    /// N s^2/m^2 (see the module docs), each axis checked as [`Self::new`] checks the scalar law.
    pub fn with_body_axes(self, mu2_x_n_s2_per_m2: f64, mu2_y_n_s2_per_m2: f64) -> Result<Self> {
        for (name, mu2) in [
            ("mu2_x_n_s2_per_m2", mu2_x_n_s2_per_m2),
            ("mu2_y_n_s2_per_m2", mu2_y_n_s2_per_m2),
        ] {
            finite(name, mu2)?;
            Self::new(self.mu1, mu2, self.mu3)?;
        }
        Ok(Self {
            body_mu2: Some([mu2_x_n_s2_per_m2, mu2_y_n_s2_per_m2]),
            ..self
        })
    }

    /// The body-axis quadratic coefficients `[mu2_x, mu2_y]`, N s^2/m^2, when the law has them.
    pub fn body_axes(&self) -> Option<[f64; 2]> {
        self.body_mu2
    }

    /// Drag force over air velocity per axis, `[k_x, k_y, k_z]` with `D = k_x v_x e_x + k_y v_y
    /// e_y + k_z v_z e_z` in the body-heading frame (forward, right, up), N s/m: the scalar law's
    /// `f_D(v) / v` on every axis without body-axis coefficients.
    #[inline]
    pub fn axis_coefficients(&self, speed_mps: f64) -> [f64; 3] {
        let v = speed_mps;
        let k = self.mu1 + v * (self.mu2 + v * self.mu3);
        match self.body_mu2 {
            None => [k, k, k],
            Some([mx, my]) => [
                self.mu1 + v * (mx + v * self.mu3),
                self.mu1 + v * (my + v * self.mu3),
                k,
            ],
        }
    }

    /// Parasitic power `D . v`, W, of a horizontal air velocity `forward_mps` along the body's
    /// forward axis and `right_mps` along its right axis: eq (11) for the scalar law.
    #[inline]
    pub fn parasitic_power_body_w(&self, forward_mps: f64, right_mps: f64) -> f64 {
        let speed = forward_mps.hypot(right_mps);
        let [kx, ky, _] = self.axis_coefficients(speed);
        kx * forward_mps * forward_mps + ky * right_mps * right_mps
    }

    /// The coefficients `(mu1, mu2, mu3)`.
    pub fn coefficients(&self) -> (f64, f64, f64) {
        (self.mu1, self.mu2, self.mu3)
    }

    /// Drag force vector opposing the air-relative velocity `vel_air` (any frame), N.
    ///
    /// Zero at zero airspeed.
    pub fn force_vector_n(&self, vel_air_mps: [f64; 3]) -> [f64; 3] {
        let speed =
            (vel_air_mps[0].powi(2) + vel_air_mps[1].powi(2) + vel_air_mps[2].powi(2)).sqrt();
        if speed == 0.0 {
            return [0.0; 3];
        }
        let scale = -self.force_n(speed) / speed;
        [
            vel_air_mps[0] * scale,
            vel_air_mps[1] * scale,
            vel_air_mps[2] * scale,
        ]
    }
}

#[cfg(test)]
// Exact comparisons here check values that are exact by construction (zeros of removed terms and
// of zero airspeed, bit-identical results of the same arithmetic).
#[allow(clippy::float_cmp)]
mod tests {
    #[test]
    fn airspeed_for_force_inverts_eq_6() {
        // The power seed's M100 constants (Fig. 3): mu2 < 0, still increasing over 0-30 m/s.
        let d = CubicDrag::new(0.1816, -0.02326, 0.004045).unwrap();
        for v in [0.0, 0.5, 3.0, 12.0, 25.0] {
            let back = d.airspeed_for_force(d.force_n(v), 50.0).unwrap();
            assert!((back - v).abs() < 1e-9, "{v} -> {back}");
        }
        assert_eq!(d.airspeed_for_force(d.force_n(60.0), 50.0), None);
        assert_eq!(d.airspeed_for_force(f64::NAN, 50.0), None);
    }

    use super::*;

    fn m100() -> CubicDrag {
        CubicDrag::new(0.1816, -0.02326, 0.004045).unwrap()
    }

    #[test]
    fn paper_val_parasitic_power_is_zero_at_zero_airspeed() {
        assert_eq!(m100().parasitic_power_w(0.0), 0.0);
        assert_eq!(m100().force_n(0.0), 0.0);
    }

    #[test]
    fn paper_val_fig3_drag_at_10_mps_by_hand() {
        // 0.1816*10 - 0.02326*100 + 0.004045*1000 = 1.816 - 2.326 + 4.045 = 3.535 N.
        let f = m100().force_n(10.0);
        assert!((f - 3.535).abs() < 1e-12, "{f}");
        assert!((m100().parasitic_power_w(10.0) - 35.35).abs() < 1e-10);
    }

    #[test]
    fn derivative_matches_finite_difference() {
        let d = m100();
        for v in [0.5, 3.0, 12.0, 30.0] {
            let h = 1e-5;
            let fd = (d.parasitic_power_w(v + h) - d.parasitic_power_w(v - h)) / (2.0 * h);
            let an = d.parasitic_power_derivative(v);
            assert!(
                (fd - an).abs() <= 1e-7 * an.abs().max(1.0),
                "{v}: {fd} vs {an}"
            );
        }
    }

    #[test]
    fn negative_drag_is_rejected() {
        // q(v) = 0.1 - 0.1 v + 0.001 v^2 is negative at v = 50 (vertex).
        let err = CubicDrag::new(0.1, -0.1, 0.001).unwrap_err();
        assert!(matches!(err, PowerError::NegativeDrag { .. }), "{err}");
        assert!(CubicDrag::new(-0.1, 0.0, 0.0).is_err());
        assert!(CubicDrag::new(f64::NAN, 0.0, 0.0).is_err());
    }

    #[test]
    fn force_vector_opposes_motion() {
        let f = m100().force_vector_n([3.0, 4.0, 0.0]);
        let mag = m100().force_n(5.0);
        assert!((f[0] + mag * 0.6).abs() < 1e-12 && (f[1] + mag * 0.8).abs() < 1e-12);
        assert_eq!(m100().force_vector_n([0.0; 3]), [0.0; 3]);
    }
}
