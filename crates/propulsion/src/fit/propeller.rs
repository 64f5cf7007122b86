//! Propeller coefficients from static tables and thrust-stand runs.
//!
//! Model: `C_T(N) = C_T0 + s_T N/1000`, `C_P(N) = C_P0 + s_P N/1000` (propeller convention,
//! N in rpm), with the slopes fixed at zero unless `speed_dependent` is asked for. A speed
//! dependence is the Reynolds-number effect visible in low-Reynolds tables such as UIUC's; use it
//! only when it lowers the held-back error, and only inside the fitted speed range.

use super::{check_columns, minimize, rmse};
use crate::error::{positive, PropulsionError};
use crate::propeller::Propeller;
use std::f64::consts::PI;

/// Result of a propeller fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PropellerFit {
    /// `C_T0`, propeller convention.
    pub ct: f64,
    /// `C_P0`, propeller convention.
    pub cp: f64,
    /// `C_T` slope per 1000 rpm (0 unless speed dependent).
    pub ct_per_krpm: f64,
    /// `C_P` slope per 1000 rpm (0 unless speed dependent).
    pub cp_per_krpm: f64,
    /// RMSE of `C_T` (table fit) or of thrust in N (stand fit).
    pub rmse_thrust: f64,
    /// RMSE of `C_P` (table fit) or of torque in N m (stand fit).
    pub rmse_power: f64,
    /// Points used.
    pub points: usize,
    /// Lowest speed in the data, rpm.
    pub min_speed_rpm: f64,
    /// Highest speed in the data, rpm.
    pub max_speed_rpm: f64,
}

impl PropellerFit {
    /// The fitted propeller with diameter `diameter_m`.
    ///
    /// # Errors
    /// Non-positive diameter or a fit with non-positive coefficients.
    pub fn to_propeller(&self, diameter_m: f64) -> Result<Propeller, PropulsionError> {
        Propeller::new(diameter_m, self.ct, self.cp)?
            .with_speed_dependence(self.ct_per_krpm, self.cp_per_krpm)
    }

    /// `C_T` at `speed_rpm`.
    pub fn ct_at(&self, speed_rpm: f64) -> f64 {
        self.ct + self.ct_per_krpm * speed_rpm / 1000.0
    }

    /// `C_P` at `speed_rpm`.
    pub fn cp_at(&self, speed_rpm: f64) -> f64 {
        self.cp + self.cp_per_krpm * speed_rpm / 1000.0
    }
}

fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

/// Minimises `cost(&[c0, slope])` over `C_0` and, when `speed_dependent`, the slope per
/// 1000 rpm (from `x0` with initial steps `step`); otherwise over `C_0` alone, the slope 0.
fn fit_coefficient(
    name: &'static str,
    cost: impl Fn(&[f64]) -> f64,
    x0: [f64; 2],
    step: [f64; 2],
    speed_dependent: bool,
) -> Result<[f64; 2], PropulsionError> {
    if speed_dependent {
        let (p, _) = minimize(name, cost, &x0, &step, 2000)?;
        Ok([p[0], p[1]])
    } else {
        let (p, _) = minimize(
            name,
            |q: &[f64]| cost(&[q[0], 0.0]),
            &x0[..1],
            &step[..1],
            1000,
        )?;
        Ok([p[0], 0.0])
    }
}

/// Fits a static coefficient table (`RPM CT CP`, e.g. UIUC `*_static_*.txt`).
///
/// # Errors
/// Mismatched or non-finite columns, fewer than 2 (3 when speed dependent) points.
pub fn fit_static_table(
    speed_rpm: &[f64],
    ct: &[f64],
    cp: &[f64],
    speed_dependent: bool,
) -> Result<PropellerFit, PropulsionError> {
    let n = check_columns(
        "propeller static table",
        &[("speed_rpm", speed_rpm), ("ct", ct), ("cp", cp)],
        if speed_dependent { 3 } else { 2 },
    )?;
    let (ct0, cts, rct) = fit_table_column(speed_rpm, ct, "propeller C_T", speed_dependent)?;
    let (cp0, cps, rcp) = fit_table_column(speed_rpm, cp, "propeller C_P", speed_dependent)?;
    let (lo, hi) = range(speed_rpm);
    Ok(PropellerFit {
        ct: ct0,
        cp: cp0,
        ct_per_krpm: cts,
        cp_per_krpm: cps,
        rmse_thrust: rct,
        rmse_power: rcp,
        points: n,
        min_speed_rpm: lo,
        max_speed_rpm: hi,
    })
}

/// `C_0 + slope N/1000` fitted to one coefficient column `y` of a table, from its mean:
/// `(C_0, slope, RMSE)`.
fn fit_table_column(
    speed_rpm: &[f64],
    y: &[f64],
    name: &'static str,
    speed_dependent: bool,
) -> Result<(f64, f64, f64), PropulsionError> {
    let x0 = [y.iter().sum::<f64>() / speed_rpm.len() as f64, 0.0];
    let cost = |p: &[f64]| {
        let slope = if speed_dependent { p[1] } else { 0.0 };
        speed_rpm
            .iter()
            .zip(y)
            .map(|(&s, &v)| (p[0] + slope * s / 1000.0 - v).powi(2))
            .sum::<f64>()
    };
    let step = [0.1 * x0[0].abs().max(1e-3), 0.01 * x0[0].abs().max(1e-3)];
    let p = fit_coefficient(name, cost, x0, step, speed_dependent)?;
    let r = rmse(
        speed_rpm
            .iter()
            .zip(y)
            .map(|(&s, &v)| p[0] + p[1] * s / 1000.0 - v),
    );
    Ok((p[0], p[1], r))
}

/// A thrust-stand row: speed (rpm), thrust (N), torque (N m).
type StandRow = (f64, f64, f64);

/// Fits `C_T`, `C_P` to a thrust-stand run (speed, thrust, torque). Rows with zero or negative
/// speed are skipped (stand at rest). Residuals are in N and N m.
///
/// # Errors
/// Mismatched or non-finite columns, too few moving rows, invalid diameter or density.
pub fn fit_thrust_stand(
    speed_rpm: &[f64],
    thrust_n: &[f64],
    torque_nm: &[f64],
    diameter_m: f64,
    rho_kg_m3: f64,
    speed_dependent: bool,
) -> Result<PropellerFit, PropulsionError> {
    check_columns(
        "propeller thrust stand",
        &[
            ("speed_rpm", speed_rpm),
            ("thrust_n", thrust_n),
            ("torque_nm", torque_nm),
        ],
        0,
    )?;
    let d = positive("diameter_m", diameter_m, "m")?;
    let rho = positive("air_density_kg_m3", rho_kg_m3, "kg/m^3")?;
    let rows = moving_rows(speed_rpm, thrust_n, torque_nm, speed_dependent)?;
    // Thrust over C_T and torque over C_P at a speed: T = C_T rho n^2 D^4, Q = C_P rho n^2 D^5 / 2 pi.
    let kt = |s: f64| rho * (s / 60.0).powi(2) * d.powi(4);
    let kq = |s: f64| rho * (s / 60.0).powi(2) * d.powi(5) / (2.0 * PI);
    let thrust = |r: &StandRow| r.1;
    let torque = |r: &StandRow| r.2;
    let (ct, cts, rt) =
        fit_stand_column(&rows, kt, thrust, "propeller C_T (stand)", speed_dependent)?;
    let (cp, cps, rq) =
        fit_stand_column(&rows, kq, torque, "propeller C_P (stand)", speed_dependent)?;
    let speeds: Vec<f64> = rows.iter().map(|r| r.0).collect();
    let (lo, hi) = range(&speeds);
    Ok(PropellerFit {
        ct,
        cp,
        ct_per_krpm: cts,
        cp_per_krpm: cps,
        rmse_thrust: rt,
        rmse_power: rq,
        points: rows.len(),
        min_speed_rpm: lo,
        max_speed_rpm: hi,
    })
}

/// The rows with the rotor turning (speed > 0): at least 2, or 3 when speed dependent.
fn moving_rows(
    speed_rpm: &[f64],
    thrust_n: &[f64],
    torque_nm: &[f64],
    speed_dependent: bool,
) -> Result<Vec<StandRow>, PropulsionError> {
    let rows: Vec<StandRow> = speed_rpm
        .iter()
        .zip(thrust_n)
        .zip(torque_nm)
        .filter(|((&s, _), _)| s > 0.0)
        .map(|((&s, &t), &q)| (s, t, q))
        .collect();
    let required = if speed_dependent { 3 } else { 2 };
    if rows.len() < required {
        return Err(PropulsionError::InsufficientData {
            model: "propeller thrust stand",
            points: rows.len(),
            required,
        });
    }
    Ok(rows)
}

/// `(C_0 + slope N/1000) f(N)` fitted to the stand column `y` (thrust or torque), from the
/// closed-form least squares of the constant model: `(C_0, slope, RMSE)`.
fn fit_stand_column(
    rows: &[StandRow],
    f: impl Fn(f64) -> f64,
    y: impl Fn(&StandRow) -> f64,
    name: &'static str,
    speed_dependent: bool,
) -> Result<(f64, f64, f64), PropulsionError> {
    let c0 = rows.iter().map(|r| y(r) * f(r.0)).sum::<f64>()
        / rows.iter().map(|r| f(r.0).powi(2)).sum::<f64>();
    let cost = |p: &[f64]| {
        let slope = if speed_dependent { p[1] } else { 0.0 };
        rows.iter()
            .map(|r| ((p[0] + slope * r.0 / 1000.0) * f(r.0) - y(r)).powi(2))
            .sum::<f64>()
    };
    let p = fit_coefficient(
        name,
        cost,
        [c0, 0.0],
        [0.1 * c0, 0.01 * c0],
        speed_dependent,
    )?;
    let r = rmse(
        rows.iter()
            .map(|r| (p[0] + p[1] * r.0 / 1000.0) * f(r.0) - y(r)),
    );
    Ok((p[0], p[1], r))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_known_speed_dependence() {
        let rpm: Vec<f64> = (0..12).map(|k| 2000.0 + 400.0 * k as f64).collect();
        let ct: Vec<f64> = rpm.iter().map(|s| 0.09 + 0.002 * s / 1000.0).collect();
        let cp: Vec<f64> = rpm.iter().map(|s| 0.04 - 0.0005 * s / 1000.0).collect();
        let f = fit_static_table(&rpm, &ct, &cp, true).unwrap();
        // noise-free data: Nelder-Mead to 1e-14 sd tolerance recovers to ~1e-6 relative
        assert!((f.ct - 0.09).abs() < 1e-6 && (f.ct_per_krpm - 0.002).abs() < 1e-6);
        assert!((f.cp - 0.04).abs() < 1e-6 && (f.cp_per_krpm + 0.0005).abs() < 1e-6);
        assert!(f.rmse_thrust < 1e-6);
    }

    #[test]
    fn stand_fit_recovers_coefficients() {
        let p = Propeller::new(0.254, 0.11, 0.045).unwrap();
        let rpm: Vec<f64> = (1..15).map(|k| 500.0 * k as f64).collect();
        let t: Vec<f64> = rpm.iter().map(|&s| p.thrust_n(s, 1.2)).collect();
        let q: Vec<f64> = rpm.iter().map(|&s| p.torque_nm(s, 1.2)).collect();
        let f = fit_thrust_stand(&rpm, &t, &q, 0.254, 1.2, false).unwrap();
        assert!((f.ct / 0.11 - 1.0).abs() < 1e-6);
        assert!((f.cp / 0.045 - 1.0).abs() < 1e-6);
        assert!(fit_thrust_stand(&rpm[..1], &t[..1], &q[..1], 0.254, 1.2, false).is_err());
        assert!(matches!(
            fit_thrust_stand(&rpm, &t[..3], &q, 0.254, 1.2, false),
            Err(PropulsionError::LengthMismatch { .. })
        ));
    }
}
