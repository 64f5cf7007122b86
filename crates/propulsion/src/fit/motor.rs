//! Motor Kv, composite resistance and rotational loss from thrust-stand runs.
//!
//! Each row gives supply voltage `V_ps`, supply current `I_ps`, speed `N` and shaft torque `Q`.
//! The model predicts the supply current from `(V_ps, N, Q)` by the power balance of eq (28):
//!
//! ```text
//! I_m  = Q / K_t + I_r(N)          (eqs 2, 20; I_r = I_0 or K_v (K_1 + K_2 N), eq 8 / derived eq 15)
//! P_ps = I_m^2 R_m + I_m N / K_v   (eq 28 with P_e = 0: P_e is not separable from I_0 here)
//! I_ps = P_ps / V_ps
//! ```
//!
//! Parameters are fitted in log space (they are positive) by Nelder-Mead on the RMSE of `I_ps`.
//!
//! # Identifiability
//! With the torque measured, `P_ps - Q Omega = I_r N / K_v + R_m (Q K_v' + I_r)^2` (`K_v'` in
//! rad/(V s)): the data fixes only `I_0 / K_v` and `R_m K_v^2`, not `K_v` itself (a fit of all
//! three reaches a near-zero residual at very different Kv values). `K_v` is therefore an input
//! (catalogue value, or no-load speed over voltage), and the fit returns `R_m` and `I_0`
//! (or `K_1`, `K_2`) for that `K_v`.
//! `R_m` is the composite resistance (armature + ESC switches, plus whatever wiring lies between
//! the measured voltage and the motor).

use super::{check_columns, minimize, rmse};
use crate::error::PropulsionError;
use crate::motor::{kt_nm_per_a, Motor, RotationalLoss};

/// Which rotational-loss form to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LossForm {
    /// Constant no-load current `I_0`.
    NoLoadCurrent,
    /// Speed-dependent `P_r = K_1 N + K_2 N^2` (eq 8).
    SpeedDependent,
}

/// Result of a motor fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorFit {
    /// Kv used (an input of the fit), rpm/V.
    pub kv_rpm_per_v: f64,
    /// Fitted composite resistance `R_m`, ohm.
    pub resistance_ohm: f64,
    /// Fitted rotational loss.
    pub loss: RotationalLoss,
    /// RMSE of the supply current, A.
    pub rmse_current_a: f64,
    /// Rows used.
    pub points: usize,
}

impl MotorFit {
    /// Predicted supply current at supply voltage, speed and torque, A.
    pub fn supply_current_a(&self, voltage_v: f64, speed_rpm: f64, torque_nm: f64) -> f64 {
        predict(
            self.kv_rpm_per_v,
            self.resistance_ohm,
            self.loss,
            voltage_v,
            speed_rpm,
            torque_nm,
        )
    }

    /// The fitted motor as a [`Motor`] (resistance as armature resistance), with a current limit.
    ///
    /// # Errors
    /// As [`Motor::new`].
    pub fn to_motor(&self, max_current_a: f64) -> Result<Motor, PropulsionError> {
        Motor::new(
            self.kv_rpm_per_v,
            self.resistance_ohm,
            self.loss,
            max_current_a,
        )
    }
}

fn predict(kv: f64, r: f64, loss: RotationalLoss, v: f64, n: f64, q: f64) -> f64 {
    let ir = match loss {
        RotationalLoss::NoLoadCurrent { current_a } => current_a,
        RotationalLoss::SpeedDependent {
            k1_w_per_rpm,
            k2_w_per_rpm2,
        } => kv * (k1_w_per_rpm + k2_w_per_rpm2 * n),
    };
    let im = q / kt_nm_per_a(kv) + ir;
    (im * im * r + im * n / kv) / v
}

/// Fits a motor to thrust-stand rows. Rows with non-positive speed or voltage are skipped.
///
/// `kv_rpm_per_v` is held fixed (see the module's Identifiability section).
///
/// # Errors
/// Mismatched or non-finite columns, fewer usable rows than 2 x the parameter count, a
/// non-converging fit.
pub fn fit_motor(
    voltage_v: &[f64],
    current_a: &[f64],
    speed_rpm: &[f64],
    torque_nm: &[f64],
    kv_rpm_per_v: f64,
    form: LossForm,
) -> Result<MotorFit, PropulsionError> {
    check_columns(
        "motor",
        &[
            ("voltage_v", voltage_v),
            ("current_a", current_a),
            ("speed_rpm", speed_rpm),
            ("torque_nm", torque_nm),
        ],
        0,
    )?;
    let kv0 = crate::error::kv(kv_rpm_per_v)?;
    let rows: Vec<[f64; 4]> = (0..voltage_v.len())
        .filter(|&i| speed_rpm[i] > 0.0 && voltage_v[i] > 0.0)
        .map(|i| [voltage_v[i], current_a[i], speed_rpm[i], torque_nm[i]])
        .collect();
    let n_par = match form {
        LossForm::NoLoadCurrent => 2,
        LossForm::SpeedDependent => 3,
    };
    if rows.len() < 2 * n_par {
        return Err(PropulsionError::InsufficientData {
            model: "motor",
            points: rows.len(),
            required: 2 * n_par,
        });
    }
    let loss_of = |p: &[f64]| match form {
        LossForm::NoLoadCurrent => RotationalLoss::NoLoadCurrent {
            current_a: p[1].exp(),
        },
        LossForm::SpeedDependent => RotationalLoss::SpeedDependent {
            k1_w_per_rpm: p[1].exp(),
            k2_w_per_rpm2: p[2].exp(),
        },
    };
    let cost = |p: &[f64]| {
        let (kv, r, loss) = (kv0, p[0].exp(), loss_of(p));
        rows.iter()
            .map(|x| (predict(kv, r, loss, x[0], x[2], x[3]) - x[1]).powi(2))
            .sum::<f64>()
    };
    // Start: Kv guess, 0.1 ohm, and a loss of 2 % of the largest electrical power.
    let p_max = rows.iter().map(|x| x[0] * x[1]).fold(0.0, f64::max);
    let n_max = rows.iter().map(|x| x[2]).fold(0.0, f64::max);
    let mut x0 = vec![0.1f64.ln()];
    match form {
        LossForm::NoLoadCurrent => x0.push((0.02 * p_max / (n_max / kv0)).max(1e-3).ln()),
        LossForm::SpeedDependent => {
            x0.push((0.01 * p_max / n_max).max(1e-9).ln());
            x0.push((0.01 * p_max / (n_max * n_max)).max(1e-15).ln());
        }
    }
    let step = vec![0.2; n_par];
    let (p, _) = minimize("motor", cost, &x0, &step, 4000)?;
    let (kv, r, loss) = (kv0, p[0].exp(), loss_of(&p));
    let rmse_current_a = rmse(
        rows.iter()
            .map(|x| predict(kv, r, loss, x[0], x[2], x[3]) - x[1]),
    );
    Ok(MotorFit {
        kv_rpm_per_v: kv,
        resistance_ohm: r,
        loss,
        rmse_current_a,
        points: rows.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_synthetic_motor() {
        let loss = RotationalLoss::NoLoadCurrent { current_a: 0.6 };
        let (kv, r) = (900.0, 0.12);
        let mut v = vec![];
        let mut i = vec![];
        let mut n = vec![];
        let mut q = vec![];
        for k in 1..=20 {
            let speed = 400.0 * k as f64;
            let torque = 2e-9 * speed * speed;
            let volts = 12.0 - 0.02 * k as f64;
            v.push(volts);
            n.push(speed);
            q.push(torque);
            i.push(predict(kv, r, loss, volts, speed, torque));
        }
        let f = fit_motor(&v, &i, &n, &q, kv, LossForm::NoLoadCurrent).unwrap();
        // noise-free, well-conditioned: recovered to better than 1 %, residual < 1 mA
        match f.loss {
            RotationalLoss::NoLoadCurrent { current_a } => {
                assert!((current_a / 0.6 - 1.0).abs() < 0.01, "{f:?}")
            }
            RotationalLoss::SpeedDependent { .. } => panic!("wrong loss form"),
        }
        assert!((f.resistance_ohm / r - 1.0).abs() < 0.01, "{f:?}");
        assert!(f.rmse_current_a < 1e-3);
        assert!(fit_motor(
            &v[..3],
            &i[..3],
            &n[..3],
            &q[..3],
            kv,
            LossForm::NoLoadCurrent
        )
        .is_err());
    }
}
