//! The cubic drag of eq (6) from the force balance, as the power seed fits its own (Fig. 3:
//! "drag estimates are based on the residual dynamics of the quadrotor, where we assume thrust and
//! acceleration are known").
//!
//! With the thrust along the unit axis `t` (from the attitude), the vertical balance gives
//! `T = m (g + a_z) / t_z`, and along the horizontal air-velocity direction `e`:
//!
//! `D / m = (g + a_z) (t . e) / t_z - a . e`
//!
//! Drag per unit mass is then regressed on `v, v^2, v^3` (linear least squares, no intercept:
//! eq 6 has none), dropping samples beyond `outlier_sigma` robust standard deviations after a first
//! pass. Mass is not identifiable from a force balance without a force measurement: the result is
//! `mu_k / m`, mapped back with a given mass. Samples below `min_airspeed_mps` carry no direction and
//! are left out.

use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

use crate::angle_of_attack::thrust_axis_enu;
use crate::error::FitError;

/// One sample of the force balance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceSample {
    /// Air-relative velocity, east-north-up, m/s.
    pub vel_air_enu_mps: [f64; 3],
    /// Acceleration over the ground, east-north-up, m/s^2.
    pub acc_enu_mps2: [f64; 3],
    /// Roll, rad (forward-right-down body, aerospace Z-Y-X, as [`crate::angle_of_attack`]).
    pub roll_rad: f64,
    /// Pitch, rad.
    pub pitch_rad: f64,
    /// Yaw (heading clockwise from north), rad.
    pub yaw_rad: f64,
    /// The sample's mass over the one the fit is for (1: that mass): the drag force is the mass
    /// times the force balance's acceleration, so a heavier flight's drag per unit of the fit's
    /// mass is this many times its own.
    pub mass_ratio: f64,
}

/// Result of [`fit_drag`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DragFit {
    /// `mu1, mu2, mu3` for the given mass, N s^k/m^k.
    pub mu_n: [f64; 3],
    /// Their standard errors.
    pub std_error: [f64; 3],
    /// RMS residual of the drag force, N.
    pub rmse_n: f64,
    /// Samples used.
    pub samples_used: usize,
    /// Samples dropped as outliers.
    pub outliers_rejected: usize,
}

/// Fewest samples above the airspeed threshold a drag fit takes.
pub(crate) const MIN_FORWARD_ROWS: usize = 30;

/// Airspeed and drag per unit mass of each sample faster than `min_airspeed_mps` whose thrust
/// axis is within 84 deg of the vertical.
pub(crate) fn force_rows(
    gravity_mps2: f64,
    samples: &[ForceSample],
    min_airspeed_mps: f64,
) -> Vec<(f64, f64)> {
    let mut rows = Vec::with_capacity(samples.len());
    for s in samples {
        let v = s.vel_air_enu_mps;
        let speed = v[0].hypot(v[1]);
        if !(speed.is_finite() && speed > min_airspeed_mps) {
            continue;
        }
        let e = [v[0] / speed, v[1] / speed];
        let t = thrust_axis_enu(s.roll_rad, s.pitch_rad, s.yaw_rad);
        if t.z.is_nan() || t.z <= 0.1 {
            continue;
        }
        let a = s.acc_enu_mps2;
        let d_per_m = s.mass_ratio
            * ((gravity_mps2 + a[2]) * (t.x * e[0] + t.y * e[1]) / t.z
                - (a[0] * e[0] + a[1] * e[1]));
        if d_per_m.is_finite() {
            rows.push((speed, d_per_m));
        }
    }
    rows
}

/// Fit `mu1..mu3` (for `mass_kg`) to the force balance of `samples`.
pub fn fit_drag(
    mass_kg: f64,
    gravity_mps2: f64,
    samples: &[ForceSample],
    min_airspeed_mps: f64,
    outlier_sigma: f64,
) -> Result<DragFit, FitError> {
    let rows = force_rows(gravity_mps2, samples, min_airspeed_mps);
    if rows.len() < MIN_FORWARD_ROWS {
        return Err(FitError::NoForwardFlight {
            parameter: "mu1_n_s_per_m",
            above: rows.len(),
            total: samples.len(),
            airspeed_mps: min_airspeed_mps,
        });
    }
    let solve = |rows: &[(f64, f64)]| -> Option<(Vector3<f64>, Matrix3<f64>, f64)> {
        let mut xtx = Matrix3::zeros();
        let mut xty = Vector3::zeros();
        for &(v, y) in rows {
            let x = Vector3::new(v, v * v, v * v * v);
            xtx += x * x.transpose();
            xty += x * y;
        }
        let inv = xtx.try_inverse()?;
        let c = inv * xty;
        let ssr: f64 = rows
            .iter()
            .map(|&(v, y)| (y - v * (c[0] + v * (c[1] + v * c[2]))).powi(2))
            .sum();
        Some((c, inv, ssr))
    };
    let singular = || FitError::NotIdentifiable {
        parameter: "mu1_n_s_per_m",
        value: f64::NAN,
        std_error: f64::INFINITY,
        unit: "N s/m",
    };
    let (c, _, _) = solve(&rows).ok_or_else(singular)?;
    let residuals: Vec<f64> = rows
        .iter()
        .map(|&(v, y)| y - v * (c[0] + v * (c[1] + v * c[2])))
        .collect();
    let kept = super::within_robust_sd(&rows, &residuals, outlier_sigma);
    let (c, inv, ssr) = solve(&kept).ok_or_else(singular)?;
    let n = kept.len();
    let sigma2 = ssr / (n.saturating_sub(3).max(1)) as f64;
    let mut std_error = [0.0; 3];
    for (k, se) in std_error.iter_mut().enumerate() {
        *se = mass_kg * (sigma2 * inv[(k, k)]).max(0.0).sqrt();
    }
    Ok(DragFit {
        mu_n: [mass_kg * c[0], mass_kg * c[1], mass_kg * c[2]],
        std_error,
        rmse_n: mass_kg * (ssr / n as f64).sqrt(),
        samples_used: n,
        outliers_rejected: rows.len() - n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angle_of_attack::{enu_to_ned, ned_to_enu};
    use nalgebra::Vector3 as V3;

    /// Attitude whose thrust axis is `t` (ENU unit vector), heading `yaw`.
    fn attitude_for_axis(t: V3<f64>, yaw: f64) -> (f64, f64) {
        // Body-frame axis for zero roll/pitch is up; rotate the world axis into the yawed frame.
        let t_ned = enu_to_ned(&t);
        let (s, c) = yaw.sin_cos();
        // Rotate by -yaw about down: express in heading frame (forward, right, down).
        let f = c * t_ned.x + s * t_ned.y;
        let r = -s * t_ned.x + c * t_ned.y;
        let d = t_ned.z;
        // t = -(z_body) = -(c_phi s_theta, -s_phi, c_phi c_theta) in the heading frame.
        let roll = (r).asin();
        let pitch = (-f).atan2(-d);
        (roll, pitch)
    }

    /// Level and accelerated flight of a vehicle of mass `m` with drag `mu` (eq 6), every
    /// direction and heading, its attitude from the force balance `m a = T + m g + D`.
    fn synthetic(m: f64, g: f64, mu: [f64; 3]) -> Vec<ForceSample> {
        let mut samples = Vec::new();
        for i in 0..2000 {
            let speed = 1.0 + 13.0 * f64::from(i % 200) / 200.0;
            let course = 0.7 * f64::from(i % 13);
            let yaw = course + 0.3 * (f64::from(i) * 0.37).sin();
            let e = V3::new(course.sin(), course.cos(), 0.0);
            let acc = V3::new(
                0.5 * (f64::from(i) * 0.11).sin(),
                0.3 * (f64::from(i) * 0.07).cos(),
                0.2 * (f64::from(i) * 0.05).sin(),
            );
            let drag = speed * (mu[0] + speed * (mu[1] + speed * mu[2]));
            // Thrust vector from m a = T + m g + D.
            let thrust = acc * m + V3::new(0.0, 0.0, m * g) + e * drag;
            let t = thrust.normalize();
            let (roll, pitch) = attitude_for_axis(t, yaw);
            let back = thrust_axis_enu(roll, pitch, yaw);
            assert!(
                (back - t).norm() < 1e-12,
                "attitude construction {back:?} vs {t:?}"
            );
            samples.push(ForceSample {
                vel_air_enu_mps: [e.x * speed, e.y * speed, 0.0],
                acc_enu_mps2: [acc.x, acc.y, acc.z],
                roll_rad: roll,
                pitch_rad: pitch,
                yaw_rad: yaw,
                mass_ratio: 1.0,
            });
        }
        samples
    }

    #[test]
    fn recovers_the_m100_drag_from_a_synthetic_force_balance() {
        let (m, g) = (3.29, 9.8066);
        let mu = [0.1816, -0.02326, 0.004045];
        let samples = synthetic(m, g, mu);
        let fit = fit_drag(m, g, &samples, 0.5, 5.0).unwrap();
        for (got, want) in fit.mu_n.iter().zip(mu) {
            assert!((got - want).abs() < 1e-9, "{fit:?}");
        }
        let _ = ned_to_enu(&V3::zeros());
    }

    /// Flights 1.5 times heavier, each sample's `mass_ratio` saying so: the drag of the fit's
    /// mass is recovered; without the ratio it reads 1/1.5 of it.
    #[test]
    fn a_heavier_flight_is_scaled_by_its_mass_ratio() {
        let (m, g) = (3.29, 9.8066);
        let mu = [0.1816, -0.02326, 0.004045];
        let mut samples = synthetic(1.5 * m, g, mu);
        let blind = fit_drag(m, g, &samples, 0.5, 5.0).unwrap();
        assert!((blind.mu_n[0] * 1.5 - mu[0]).abs() < 1e-9, "{blind:?}");
        for s in &mut samples {
            s.mass_ratio = 1.5;
        }
        let fit = fit_drag(m, g, &samples, 0.5, 5.0).unwrap();
        for (got, want) in fit.mu_n.iter().zip(mu) {
            assert!((got - want).abs() < 1e-9, "{fit:?}");
        }
    }

    #[test]
    fn hover_data_refuses_drag() {
        let s = ForceSample {
            vel_air_enu_mps: [0.1, 0.0, 0.0],
            acc_enu_mps2: [0.0; 3],
            roll_rad: 0.0,
            pitch_rad: 0.0,
            yaw_rad: 0.0,
            mass_ratio: 1.0,
        };
        let e = fit_drag(3.0, 9.8, &vec![s; 100], 0.5, 5.0).unwrap_err();
        assert!(matches!(e, FitError::NoForwardFlight { .. }), "{e}");
    }
}
