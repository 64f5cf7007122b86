//! Internal-resistance coefficients `r_1, r_2, r_3` of eq (17) from current / voltage pairs.
//!
//! Each pair is a load current `I_b` and the drop `dV_b` between the resting and the loaded pack
//! voltage (eq 16, `R_b = dV_b / I_b`). Eq (17) times the current gives
//! `dV = r_1 I + r_2 ln I + r_3`, which is fitted (least squares in volts) by Nelder-Mead. The
//! valid range reported is the range of currents in the data.

use super::{check_columns, minimize, rmse};
use crate::battery::{Eq17Resistance, InternalResistance};
use crate::error::PropulsionError;
use aloft_core::{trapezoid, SECONDS_PER_HOUR};

/// Result of an eq (17) fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResistanceFit {
    /// The coefficients, valid between the smallest and the largest current in the data.
    pub eq17: Eq17Resistance,
    /// RMSE of the voltage drop, V.
    pub rmse_voltage_v: f64,
}

impl ResistanceFit {
    /// The fit as an [`InternalResistance`] valid over the data's current range.
    pub fn to_model(&self) -> InternalResistance {
        InternalResistance::Logarithmic(self.eq17)
    }

    /// Resistance at `current_a` (unclamped eq 17), ohm.
    pub fn resistance_ohm(&self, current_a: f64) -> f64 {
        self.eq17.resistance_ohm(current_a)
    }
}

/// Fits eq (17) to current / voltage-drop pairs. Pairs with current at or below 0 are skipped.
///
/// # Errors
/// Mismatched or non-finite columns, fewer than 4 positive-current pairs.
pub fn fit_internal_resistance(
    current_a: &[f64],
    voltage_drop_v: &[f64],
) -> Result<ResistanceFit, PropulsionError> {
    check_columns(
        "battery eq (17)",
        &[("current_a", current_a), ("voltage_drop_v", voltage_drop_v)],
        0,
    )?;
    let rows: Vec<(f64, f64)> = current_a
        .iter()
        .zip(voltage_drop_v)
        .filter(|(&i, _)| i > 0.0)
        .map(|(&i, &v)| (i, v))
        .collect();
    if rows.len() < 4 {
        return Err(PropulsionError::InsufficientData {
            model: "battery eq (17)",
            points: rows.len(),
            required: 4,
        });
    }
    let model = |p: &[f64], i: f64| p[0] * i + p[1] * i.ln() + p[2];
    let cost = |p: &[f64]| {
        rows.iter()
            .map(|&(i, v)| (model(p, i) - v).powi(2))
            .sum::<f64>()
    };
    // Start from a constant resistance through the origin.
    let r0 =
        rows.iter().map(|r| r.0 * r.1).sum::<f64>() / rows.iter().map(|r| r.0 * r.0).sum::<f64>();
    let (p, _) = minimize(
        "battery eq (17)",
        cost,
        &[r0, 0.0, 0.0],
        &[0.3 * r0.abs().max(1e-3), 0.05, 0.05],
        6000,
    )?;
    let (lo, hi) = rows
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
            (a.min(r.0), b.max(r.0))
        });
    Ok(ResistanceFit {
        eq17: Eq17Resistance {
            r1_ohm: p[0],
            r2_ohm_a: p[1],
            r3_ohm_a: p[2],
            min_current_a: lo,
            max_current_a: hi,
        },
        rmse_voltage_v: rmse(rows.iter().map(|&(i, v)| model(&p, i) - v)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_eq17_coefficients() {
        let (r1, r2, r3) = (0.05, 0.03, 0.2);
        let truth = Eq17Resistance {
            r1_ohm: r1,
            r2_ohm_a: r2,
            r3_ohm_a: r3,
            min_current_a: 3.0,
            max_current_a: 60.0,
        };
        let i: Vec<f64> = (1..=20).map(|k| 3.0 * k as f64).collect();
        let dv: Vec<f64> = i.iter().map(|&x| truth.resistance_ohm(x) * x).collect();
        let f = fit_internal_resistance(&i, &dv).unwrap();
        let e = f.eq17;
        // noise-free: recovered to 1e-4 absolute (Nelder-Mead with restart)
        assert!((e.r1_ohm - r1).abs() < 1e-4, "{f:?}");
        assert!((e.r2_ohm_a - r2).abs() < 1e-3, "{f:?}");
        assert!((e.r3_ohm_a - r3).abs() < 3e-3, "{f:?}");
        assert!(f.rmse_voltage_v < 1e-3);
        assert!((e.min_current_a - 3.0).abs() < 1e-12 && (e.max_current_a - 60.0).abs() < 1e-12);
    }
}

/// Result of [`fit_pack_resistance`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PackResistanceFit {
    /// Open-circuit voltage at the start of the data, V.
    pub ocv_start_v: f64,
    /// Slope of the open-circuit voltage with discharged charge, V/Ah (negative).
    pub ocv_slope_v_per_ah: f64,
    /// Internal resistance, ohm.
    pub resistance_ohm: f64,
    /// Standard error of the resistance, ohm.
    pub resistance_std_error_ohm: f64,
    /// RMS residual of the terminal voltage, V.
    pub rmse_v: f64,
    /// Samples used.
    pub samples: usize,
}

/// Pack internal resistance from a flight's terminal voltage and current.
///
/// Over one discharge the open-circuit voltage falls nearly linearly with the charge drawn, so the
/// terminal voltage is modelled as `V = V0 + b Q - R I` (eq 16 with a linear open-circuit voltage),
/// with `Q` the charge drawn since the first sample (the integral of the current, trapezoids over
/// `time_s`). Linear least squares in `V0`, `b`, `R`; the standard error of `R` from the residual
/// variance. `R` is identified by the current varying faster than the charge: a flight at constant
/// current cannot separate it.
///
/// # Errors
/// Mismatched or non-finite columns; fewer than 10 samples; a singular system (constant current).
pub fn fit_pack_resistance(
    time_s: &[f64],
    current_a: &[f64],
    voltage_v: &[f64],
) -> Result<PackResistanceFit, PropulsionError> {
    let n = check_columns(
        "pack resistance",
        &[
            ("time_s", time_s),
            ("current_a", current_a),
            ("voltage_v", voltage_v),
        ],
        10,
    )?;
    use nalgebra::{Matrix3, Vector3};
    // R is identified only by the current varying: require a spread of at least 0.1 % of the mean.
    let mean = current_a.iter().sum::<f64>() / n as f64;
    let sd = (current_a.iter().map(|i| (i - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
    if sd <= 1e-3 * mean.abs().max(1e-9) {
        return Err(PropulsionError::FitDidNotConverge {
            model: "pack resistance (current does not vary)",
        });
    }
    let mut charge_ah = 0.0;
    let mut xtx = Matrix3::zeros();
    let mut xty = Vector3::zeros();
    let mut rows = Vec::with_capacity(n);
    for i in 0..n {
        if i > 0 {
            // The charge at each sample, one trapezoid panel at a time, in A h.
            charge_ah += trapezoid(&time_s[i - 1..=i], &current_a[i - 1..=i]) / SECONDS_PER_HOUR;
        }
        let x = Vector3::new(1.0, charge_ah, -current_a[i]);
        xtx += x * x.transpose();
        xty += x * voltage_v[i];
        rows.push(x);
    }
    let inv = xtx
        .try_inverse()
        .ok_or(PropulsionError::FitDidNotConverge {
            model: "pack resistance (current does not vary)",
        })?;
    let c = inv * xty;
    let ssr: f64 = rows
        .iter()
        .zip(voltage_v)
        .map(|(x, v)| (v - x.dot(&c)).powi(2))
        .sum();
    let sigma2 = ssr / (n - 3) as f64;
    Ok(PackResistanceFit {
        ocv_start_v: c[0],
        ocv_slope_v_per_ah: c[1],
        resistance_ohm: c[2],
        resistance_std_error_ohm: (sigma2 * inv[(2, 2)]).max(0.0).sqrt(),
        rmse_v: (ssr / n as f64).sqrt(),
        samples: n,
    })
}

#[cfg(test)]
mod pack_tests {
    use super::*;

    #[test]
    fn recovers_resistance_and_ocv_slope_of_a_synthetic_discharge() {
        let (r, v0, b) = (0.045, 50.0, -0.35);
        let mut q = 0.0;
        let (mut t, mut i_a, mut v) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..3000 {
            let time = f64::from(k) * 0.1;
            let current = 25.0 + 8.0 * (f64::from(k) * 0.05).sin();
            if k > 0 {
                q += 0.1 * 0.5 * (current + i_a[k as usize - 1]) / 3600.0;
            }
            t.push(time);
            i_a.push(current);
            v.push(v0 + b * q - r * current);
        }
        let fit = fit_pack_resistance(&t, &i_a, &v).unwrap();
        assert!((fit.resistance_ohm - r).abs() < 1e-9, "{fit:?}");
        assert!((fit.ocv_slope_v_per_ah - b).abs() < 1e-6, "{fit:?}");
        let flat = vec![20.0; 3000];
        assert!(fit_pack_resistance(&t, &flat, &v).is_err());
    }
}
