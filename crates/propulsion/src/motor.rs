//! Brushless DC motor (steady state), propulsion seed eqs (1)-(4), (8)-(15), (19)-(20).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `N` | motor speed | rpm |
//! | `Q` | shaft torque | N m |
//! | `K_v` | voltage (speed) constant | rpm/V |
//! | `K_t` | torque constant | N m/A |
//! | `V_a` | armature (back-emf) voltage, `V_a = N / K_v` (eq 3) | V |
//! | `I_a` | armature current producing torque, `Q = K_t I_a` (eq 2) | A |
//! | `I_r` | current that overcomes rotational (core + mechanical) loss | A |
//! | `I_m` | motor current, `I_m = I_a + I_r` (eq 20) | A |
//! | `R_m` | composite resistance `R_a + R_e` (armature + ESC switches) | ohm |
//! | `P_ps` | power supplied to the ESC | W |
//!
//! Units: in consistent SI units `K_t = 1 / K_v[rad/(V s)] = 60 / (2 pi K_v[rpm/V])`; in the
//! hobby units of the seed (oz in/A and rpm/V) the product is `K_v K_t = 1352` (eq 4).
//!
//! Rotational loss: either the constant no-load-current model (seed Fig. 4, `I_r = I_0`) or the
//! speed-dependent loss of eq (8), `P_r = K_1 N + K_2 N^2`.
//!
//! # Deviation
//! Eq (15), the current form of eq (8), is garbled in the seed text (`I_r = K_1 K_11 + K_2 K_12 N`).
//! It is derived here as the seed describes it, dividing eq (8) by the armature voltage of
//! eq (3): `I_r = P_r / V_a = K_v (K_1 + K_2 N)`.

use crate::error::{current_limit, kv, non_negative, resistance, PropulsionError};
use std::f64::consts::PI;

/// Newton metres per ounce-force inch.
pub const NM_PER_OZ_IN: f64 = 0.007_061_551_814;

/// The seed's eq (4) constant, `K_v K_t` in rpm/V x oz in/A.
pub const KV_KT_HOBBY: f64 = 1352.0;

/// Torque constant, N m/A, from a velocity constant in rpm/V: `K_t = 60 / (2 pi K_v)`.
pub fn kt_nm_per_a(kv_rpm_per_v: f64) -> f64 {
    60.0 / (2.0 * PI * kv_rpm_per_v)
}

/// Torque constant in the seed's hobby units, oz in/A (eq 4 uses these).
pub fn kt_oz_in_per_a(kv_rpm_per_v: f64) -> f64 {
    kt_nm_per_a(kv_rpm_per_v) / NM_PER_OZ_IN
}

/// Velocity constant in rad/(V s) from rpm/V.
pub fn kv_radps_per_v(kv_rpm_per_v: f64) -> f64 {
    kv_rpm_per_v * 2.0 * PI / 60.0
}

/// Rotational (core + mechanical) loss model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RotationalLoss {
    /// Constant no-load current `I_r = I_0` (seed Fig. 4); valid near the no-load speed.
    NoLoadCurrent {
        /// No-load current, A.
        current_a: f64,
    },
    /// Speed-dependent loss `P_r = K_1 N + K_2 N^2` (seed eq 8), N in rpm.
    SpeedDependent {
        /// `K_1`, W/rpm.
        k1_w_per_rpm: f64,
        /// `K_2`, W/rpm^2.
        k2_w_per_rpm2: f64,
    },
}

/// A brushless DC motor with its ESC switch resistance folded into `R_m`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motor {
    kv_rpm_per_v: f64,
    armature_resistance_ohm: f64,
    loss: RotationalLoss,
    max_current_a: f64,
}

impl Motor {
    /// A motor from its velocity constant, armature resistance, rotational-loss model and
    /// current limit (use `f64::INFINITY` for none).
    ///
    /// # Errors
    /// Non-positive or non-finite Kv, negative resistance or loss coefficients, a non-positive
    /// current limit.
    pub fn new(
        kv_rpm_per_v: f64,
        armature_resistance_ohm: f64,
        loss: RotationalLoss,
        max_current_a: f64,
    ) -> Result<Self, PropulsionError> {
        let kv_rpm_per_v = kv(kv_rpm_per_v)?;
        let armature_resistance_ohm =
            resistance("motor armature_resistance_ohm", armature_resistance_ohm)?;
        match loss {
            RotationalLoss::NoLoadCurrent { current_a } => {
                non_negative("motor no_load_current_a", current_a, "A")?;
            }
            RotationalLoss::SpeedDependent {
                k1_w_per_rpm,
                k2_w_per_rpm2,
            } => {
                non_negative("motor k1_w_per_rpm", k1_w_per_rpm, "W/rpm")?;
                non_negative("motor k2_w_per_rpm2", k2_w_per_rpm2, "W/rpm^2")?;
            }
        }
        current_limit("motor max_current_a", max_current_a)?;
        Ok(Self {
            kv_rpm_per_v,
            armature_resistance_ohm,
            loss,
            max_current_a,
        })
    }

    /// Velocity constant, rpm/V.
    pub fn kv_rpm_per_v(&self) -> f64 {
        self.kv_rpm_per_v
    }

    /// Torque constant, N m/A.
    pub fn kt_nm_per_a(&self) -> f64 {
        kt_nm_per_a(self.kv_rpm_per_v)
    }

    /// Armature resistance, ohm.
    pub fn armature_resistance_ohm(&self) -> f64 {
        self.armature_resistance_ohm
    }

    /// Rotational-loss model.
    pub fn rotational_loss(&self) -> RotationalLoss {
        self.loss
    }

    /// Motor current limit, A.
    pub fn max_current_a(&self) -> f64 {
        self.max_current_a
    }

    /// Armature (back-emf) voltage `V_a = N / K_v`, eq (3).
    pub fn back_emf_v(&self, speed_rpm: f64) -> f64 {
        speed_rpm / self.kv_rpm_per_v
    }

    /// Armature current that makes `torque_nm`, eq (2): `I_a = Q / K_t`.
    pub fn armature_current_a(&self, torque_nm: f64) -> f64 {
        torque_nm / self.kt_nm_per_a()
    }

    /// Current that overcomes the rotational loss at `speed_rpm`: `I_0`, or the derived form of
    /// eq (15), `I_r = K_v (K_1 + K_2 N)`.
    pub fn rotational_current_a(&self, speed_rpm: f64) -> f64 {
        match self.loss {
            RotationalLoss::NoLoadCurrent { current_a } => current_a,
            RotationalLoss::SpeedDependent {
                k1_w_per_rpm,
                k2_w_per_rpm2,
            } => self.kv_rpm_per_v * (k1_w_per_rpm + k2_w_per_rpm2 * speed_rpm),
        }
    }

    /// Rotational loss power at `speed_rpm`, W: eq (8), or `I_0 V_a` for the constant model
    /// (eq 14).
    pub fn rotational_loss_w(&self, speed_rpm: f64) -> f64 {
        self.rotational_current_a(speed_rpm) * self.back_emf_v(speed_rpm)
    }

    /// Motor current `I_m` drawn through the ESC from a measured supply power, eq (19) (eq 13 is
    /// the same solve at no load): the positive root of `R_m I^2 + (N/K_v) I + (P_e - P_ps) = 0`.
    ///
    /// `composite_resistance_ohm` is `R_m = R_a + R_e`; `net_power_w` is `P_ps - P_e`.
    pub fn current_from_supply_power_a(
        &self,
        speed_rpm: f64,
        net_power_w: f64,
        composite_resistance_ohm: f64,
    ) -> f64 {
        let va = self.back_emf_v(speed_rpm);
        if composite_resistance_ohm <= 0.0 {
            return net_power_w / va;
        }
        (-va + (va * va + 4.0 * net_power_w * composite_resistance_ohm).sqrt())
            / (2.0 * composite_resistance_ohm)
    }

    /// Motor efficiency, shaft power over electrical power into the motor terminals
    /// (`Q Omega / (I_m V_a + I_m^2 R_a)`), at a given speed and torque.
    pub fn efficiency(&self, speed_rpm: f64, torque_nm: f64) -> f64 {
        let im = self.armature_current_a(torque_nm) + self.rotational_current_a(speed_rpm);
        let p_in = im * self.back_emf_v(speed_rpm) + im * im * self.armature_resistance_ohm;
        if p_in <= 0.0 {
            return 0.0;
        }
        torque_nm * speed_rpm * 2.0 * PI / 60.0 / p_in
    }
}

/// Builds a [`Motor`] with the constant no-load-current model.
///
/// # Errors
/// As [`Motor::new`].
pub fn motor_with_no_load_current(
    kv_rpm_per_v: f64,
    armature_resistance_ohm: f64,
    no_load_current_a: f64,
    max_current_a: f64,
) -> Result<Motor, PropulsionError> {
    Motor::new(
        kv_rpm_per_v,
        armature_resistance_ohm,
        RotationalLoss::NoLoadCurrent {
            current_a: no_load_current_a,
        },
        max_current_a,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_val_eq4_kv_kt_product_in_hobby_units() {
        // Eq (4): K_v K_t = 1352 in rpm/V x oz in/A. The exact value is
        // 60 / (2 pi) / 0.0070615518 = 1352.3; the seed rounds to 4 digits, so 0.05 % is the
        // rounding tolerance.
        for kv in [515.0, 775.0, 2300.0] {
            let p = kv * kt_oz_in_per_a(kv);
            assert!((p / KV_KT_HOBBY - 1.0).abs() < 5e-4, "{p}");
        }
    }

    #[test]
    fn eq15_derived_current_times_back_emf_is_eq8_power() {
        let m = Motor::new(
            515.0,
            0.07,
            RotationalLoss::SpeedDependent {
                k1_w_per_rpm: 2e-3,
                k2_w_per_rpm2: 1e-7,
            },
            55.0,
        )
        .unwrap();
        for n in [2000.0, 5000.0, 9000.0] {
            let p8 = 2e-3 * n + 1e-7 * n * n;
            // exact identity up to rounding
            assert!((m.rotational_loss_w(n) / p8 - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn eq19_inverts_eq28() {
        let m = motor_with_no_load_current(515.0, 0.07, 1.5, 55.0).unwrap();
        let (n, im, rm) = (7000.0, 40.0, 0.075);
        let p = im * im * rm + im * m.back_emf_v(n);
        assert!((m.current_from_supply_power_a(n, p, rm) / im - 1.0).abs() < 1e-12);
    }

    #[test]
    fn bad_motor_inputs_are_typed_errors() {
        for bad in [0.0, -100.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                motor_with_no_load_current(bad, 0.07, 1.5, 55.0),
                Err(PropulsionError::InvalidKv { .. })
            ));
        }
        assert!(matches!(
            motor_with_no_load_current(515.0, -0.1, 1.5, 55.0),
            Err(PropulsionError::InvalidResistance { .. })
        ));
        assert!(motor_with_no_load_current(515.0, 0.07, -1.0, 55.0).is_err());
        assert!(motor_with_no_load_current(515.0, 0.07, 1.0, 0.0).is_err());
    }
}
