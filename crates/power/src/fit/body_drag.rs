//! Body-axis drag from the force balance: the quadratic (frontal-area) coefficient of eq (6)
//! along the body's forward and right axes (`aloft_power::drag`, "Deviation"), given the scalar
//! law's `mu1` and `mu3`.
//!
//! The horizontal force balance of [`super::drag`] gives the whole drag vector per unit mass,
//! not only its component along the freestream: with the thrust axis `t` (attitude) and the
//! acceleration `a` (ENU),
//!
//! `d = (g + a_z) t_h / t_z - a_h`,
//!
//! which is split along the heading `f = (sin psi, cos psi)` and its right `r = (cos psi,
//! -sin psi)` (yaw `psi` clockwise from north), as is the air velocity (`v_f`, `v_r`). On each
//! axis `b` the residual of the common terms is regressed on the quadratic term alone,
//!
//! `d_b - (mu1 + mu3 v^2) v_b / m = (mu2_b / m) v v_b`, `v = |v_h|`,
//!
//! one linear least-squares coefficient per axis (no intercept), samples beyond `outlier_sigma`
//! robust standard deviations dropped after a first pass.
//!
//! # Identifiability
//! The two coefficients are kept only when the data separates them: each axis needs
//! [`MIN_AXIS_ROWS`] samples flying faster than the threshold along it, and the difference
//! `mu2_x - mu2_y` must exceed twice its standard error. Samples at 10 Hz are not independent
//! (the residual is a slowly varying gust and manoeuvre signal), so each standard error uses an
//! effective sample size `n (1 - rho) / (1 + rho)` from the lag-one autocorrelation `rho` of the
//! axis's residuals (an AR(1) approximation), not `n`.

use serde::Serialize;

use super::drag::ForceSample;
use crate::angle_of_attack::thrust_axis_enu;

/// Fewest samples per body axis, flying faster than the threshold along that axis.
pub const MIN_AXIS_ROWS: usize = 300;

/// Body-axis quadratic drag coefficients fitted from the force balance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BodyAxisDragFit {
    /// `[mu2_x, mu2_y]` (forward, right) for the given mass, N s^2/m^2.
    pub mu2_n: [f64; 2],
    /// Their standard errors (effective sample size), N s^2/m^2.
    pub std_error: [f64; 2],
    /// Samples used on each axis.
    pub samples_used: [usize; 2],
}

/// Why the body-axis coefficients were not fitted.
#[derive(Debug, Clone, PartialEq)]
pub enum BodyAxisRefusal {
    /// Too few samples fly along one axis.
    TooFewSamples {
        /// Samples along the forward and right axes.
        rows: [usize; 2],
    },
    /// The two coefficients do not differ by more than twice the standard error of their
    /// difference: the scalar law describes the data as well.
    NotSeparated {
        /// The coefficients that were estimated, N s^2/m^2.
        fit: BodyAxisDragFit,
    },
}

/// One axis's regression rows: `(x, y)` with `y = c x`, `x = v v_b`.
type AxisRows = Vec<(f64, f64)>;

/// The rows of both axes: samples faster than `min_airspeed_mps` along the axis, thrust axis
/// within 84 deg of vertical.
fn axis_rows(
    gravity_mps2: f64,
    samples: &[ForceSample],
    mu_per_kg: [f64; 3],
    min_airspeed_mps: f64,
) -> [AxisRows; 2] {
    let mut rows: [AxisRows; 2] = [Vec::new(), Vec::new()];
    for s in samples {
        let v = s.vel_air_enu_mps;
        let speed = v[0].hypot(v[1]);
        let t = thrust_axis_enu(s.roll_rad, s.pitch_rad, s.yaw_rad);
        if !(speed.is_finite() && t.z > 0.1) {
            continue;
        }
        let a = s.acc_enu_mps2;
        let d = [
            s.mass_ratio * ((gravity_mps2 + a[2]) * t.x / t.z - a[0]),
            s.mass_ratio * ((gravity_mps2 + a[2]) * t.y / t.z - a[1]),
        ];
        let (se, ce) = s.yaw_rad.sin_cos();
        let axes = [[se, ce], [ce, -se]];
        let common = mu_per_kg[0] + mu_per_kg[2] * speed * speed;
        for (b, e) in axes.iter().enumerate() {
            let v_b = v[0] * e[0] + v[1] * e[1];
            let d_b = d[0] * e[0] + d[1] * e[1];
            let (x, y) = (speed * v_b, d_b - common * v_b);
            if v_b.abs() > min_airspeed_mps && x.is_finite() && y.is_finite() {
                rows[b].push((x, y));
            }
        }
    }
    rows
}

/// Least squares `y = c x`: the coefficient, its standard error with the effective sample
/// size, and the rows kept after one pass of outlier rejection.
fn fit_axis(rows: &[(f64, f64)], outlier_sigma: f64) -> Option<(f64, f64, usize)> {
    let solve = |rows: &[(f64, f64)]| {
        let sxx: f64 = rows.iter().map(|r| r.0 * r.0).sum();
        let sxy: f64 = rows.iter().map(|r| r.0 * r.1).sum();
        (sxx > 0.0).then(|| (sxy / sxx, sxx))
    };
    let (c, _) = solve(rows)?;
    let residuals: Vec<f64> = rows.iter().map(|r| r.1 - c * r.0).collect();
    let kept = super::within_robust_sd(rows, &residuals, outlier_sigma);
    let (c, sxx) = solve(&kept)?;
    let residuals: Vec<f64> = kept.iter().map(|r| r.1 - c * r.0).collect();
    let n = residuals.len() as f64;
    let ssr: f64 = residuals.iter().map(|r| r * r).sum();
    let lag1: f64 = residuals.windows(2).map(|w| w[0] * w[1]).sum();
    let rho = if ssr > 0.0 {
        (lag1 / ssr).clamp(0.0, 0.999)
    } else {
        0.0
    };
    let n_eff = (n * (1.0 - rho) / (1.0 + rho)).max(2.0);
    // Variance of the slope with independent residuals is s^2 / sxx; correlated residuals
    // inflate it by n / n_eff.
    let variance = ssr / (n - 1.0).max(1.0) / sxx * (n / n_eff);
    Some((c, variance.sqrt(), kept.len()))
}

/// Fit `mu2_x`, `mu2_y` (for `mass_kg`) given the scalar law's `mu_n = [mu1, mu2, mu3]` (see
/// the module docs).
///
/// # Errors
/// [`BodyAxisRefusal`] when the data does not identify the two coefficients apart.
pub fn fit_body_axis_drag(
    mu_n: [f64; 3],
    mass_kg: f64,
    gravity_mps2: f64,
    samples: &[ForceSample],
    min_airspeed_mps: f64,
    outlier_sigma: f64,
) -> Result<BodyAxisDragFit, BodyAxisRefusal> {
    let per_kg = mu_n.map(|m| m / mass_kg);
    let rows = axis_rows(gravity_mps2, samples, per_kg, min_airspeed_mps);
    let counts = [rows[0].len(), rows[1].len()];
    if counts.iter().any(|&n| n < MIN_AXIS_ROWS) {
        return Err(BodyAxisRefusal::TooFewSamples { rows: counts });
    }
    let (Some(x), Some(y)) = (
        fit_axis(&rows[0], outlier_sigma),
        fit_axis(&rows[1], outlier_sigma),
    ) else {
        return Err(BodyAxisRefusal::TooFewSamples { rows: counts });
    };
    let fit = BodyAxisDragFit {
        mu2_n: [mass_kg * x.0, mass_kg * y.0],
        std_error: [mass_kg * x.1, mass_kg * y.1],
        samples_used: [x.2, y.2],
    };
    let difference = (fit.mu2_n[0] - fit.mu2_n[1]).abs();
    if difference <= 2.0 * fit.std_error[0].hypot(fit.std_error[1]) {
        return Err(BodyAxisRefusal::NotSeparated { fit });
    }
    Ok(fit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3 as V3;

    /// Force samples of a vehicle with body-axis drag `mu2 = [x, y]` (mu1, mu3 common), flown at
    /// headings and courses that cover both axes.
    fn synthetic(mu: [f64; 3], mu2: [f64; 2], m: f64, g: f64) -> Vec<ForceSample> {
        (0..3000)
            .map(|i| {
                let speed = 1.5 + 6.0 * f64::from(i % 97) / 97.0;
                let yaw = 0.9;
                let beta = 0.37 * f64::from(i % 17);
                let course = yaw + beta;
                let (se, ce) = (course.sin(), course.cos());
                let v = V3::new(speed * se, speed * ce, 0.0);
                let f = V3::new(yaw.sin(), yaw.cos(), 0.0);
                let r = V3::new(yaw.cos(), -yaw.sin(), 0.0);
                let (vf, vr) = (v.dot(&f), v.dot(&r));
                let k = |m2: f64| mu[0] + speed * (m2 + speed * mu[2]);
                let drag = f * (k(mu2[0]) * vf) + r * (k(mu2[1]) * vr);
                let thrust = V3::new(0.0, 0.0, m * g) + drag;
                let t = thrust.normalize();
                // Roll and pitch of a thrust axis at heading `yaw` (forward-right-down body).
                let t_f = t.dot(&f);
                let t_r = t.dot(&r);
                let roll = t_r.asin();
                let pitch = (-t_f).atan2(t.z);
                ForceSample {
                    vel_air_enu_mps: [v.x, v.y, 0.0],
                    acc_enu_mps2: [0.0; 3],
                    roll_rad: roll,
                    pitch_rad: pitch,
                    yaw_rad: yaw,
                    mass_ratio: 1.0,
                }
            })
            .collect()
    }

    #[test]
    fn recovers_body_axis_areas_from_a_synthetic_force_balance() {
        let (m, g) = (8.0, 9.80665);
        let mu = [0.7, 0.0, 0.01];
        let samples = synthetic(mu, [0.08, 0.02], m, g);
        let axis = thrust_axis_enu(samples[5].roll_rad, samples[5].pitch_rad, 0.9);
        assert!(axis.z > 0.9, "{axis:?}");
        let fit = fit_body_axis_drag(mu, m, g, &samples, 0.3, 5.0).unwrap();
        // Exact data: the coefficients come back to rounding.
        assert!((fit.mu2_n[0] - 0.08).abs() < 1e-9, "{fit:?}");
        assert!((fit.mu2_n[1] - 0.02).abs() < 1e-9, "{fit:?}");
    }

    #[test]
    fn equal_areas_are_not_separated() {
        let (m, g) = (8.0, 9.80665);
        let mu = [0.7, 0.05, 0.01];
        let mut samples = synthetic(mu, [0.05, 0.05], m, g);
        // Noise in the attitude so the standard errors are not zero.
        for (i, s) in samples.iter_mut().enumerate() {
            s.roll_rad += 0.01 * (f64::from(i as u32) * 1.7).sin();
            s.pitch_rad += 0.01 * (f64::from(i as u32) * 2.3).cos();
        }
        let e = fit_body_axis_drag(mu, m, g, &samples, 0.3, 5.0).unwrap_err();
        assert!(matches!(e, BodyAxisRefusal::NotSeparated { .. }), "{e:?}");
        let few = fit_body_axis_drag(mu, m, g, &samples[..100], 0.3, 5.0).unwrap_err();
        assert!(
            matches!(few, BodyAxisRefusal::TooFewSamples { .. }),
            "{few:?}"
        );
    }
}
