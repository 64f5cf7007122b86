//! Serde specs: the `[propulsion]` table of a vehicle TOML file and the inputs of
//! `aloft rotor`. Keys carry their units; unknown keys are rejected; conversion into the models
//! validates every value and returns typed errors.
//!
//! ```toml
//! [propulsion]
//! empty_mass_kg = 7.484
//! rotor_count = 4
//! packs_count = 4
//! gravity_mps2 = 9.80665
//! air_density_kg_m3 = 1.225
//!
//! [propulsion.propeller]
//! diameter_in = 14.0
//! thrust_coefficient_ct = 0.1003      # T / (rho n^2 D^4)
//! power_coefficient_cp = 0.0393       # P / (rho n^3 D^5)
//! installed_thrust_loss_fraction = 0.11
//!
//! [propulsion.motor]
//! kv_rpm_per_v = 515.0
//! armature_resistance_ohm = 0.07
//! no_load_current_a = 1.5             # or k1_w_per_rpm + k2_w_per_rpm2 (eq 8)
//! max_current_a = 55.0
//!
//! [propulsion.esc]
//! electronics_power_w = 0.0
//! resistance_ohm = 0.0
//!
//! [propulsion.battery]
//! cells_series = 5
//! cells_parallel = 4
//! capacity_mah = 8000.0
//! effective_capacity_fraction = 0.9
//! full_charge_cell_v = 4.1
//! nominal_v = 18.5
//! internal_resistance_ohm = 0.07      # or r1_ohm, r2_ohm_a, r3_ohm_a + eq17_{min,max}_current_a
//! ```

use aloft_core::{ISA_SEA_LEVEL_DENSITY_KG_M3, STANDARD_GRAVITY_MPS2};

use crate::battery_spec::BatterySpec;
use crate::error::{mass, positive, PropulsionError};
use crate::esc::Esc;
use crate::motor::{Motor, RotationalLoss};
use crate::operating_point::PropulsionSystem;
use crate::propeller::{Propeller, M_PER_IN};
use crate::transient::{
    kt_from_kv, motor_inertia_kgm2, prop_inertia_kgm2, EscProtocol, RotorConstants, RotorTransient,
    RotorTransientResult,
};
use serde::{Deserialize, Serialize};

fn default_gravity() -> f64 {
    STANDARD_GRAVITY_MPS2
}
fn default_rho() -> f64 {
    ISA_SEA_LEVEL_DENSITY_KG_M3
}

/// The `[propulsion]` table of a vehicle file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropulsionSpec {
    /// Mass without payload, kg.
    pub empty_mass_kg: f64,
    /// Number of rotors.
    pub rotor_count: u32,
    /// Number of battery packs (each feeds `rotor_count / packs_count` motors).
    pub packs_count: u32,
    /// Gravity, m/s^2 (default 9.80665).
    #[serde(default = "default_gravity")]
    pub gravity_mps2: f64,
    /// Air density, kg/m^3 (default ISA sea level, 1.225).
    #[serde(default = "default_rho")]
    pub air_density_kg_m3: f64,
    /// `[propulsion.propeller]`.
    pub propeller: PropellerSpec,
    /// `[propulsion.motor]`.
    pub motor: MotorSpec,
    /// `[propulsion.esc]` (default: ideal ESC).
    #[serde(default)]
    pub esc: EscSpec,
    /// `[propulsion.battery]`.
    pub battery: BatterySpec,
}

/// `[propulsion.propeller]`: propeller-table coefficients (`C_T = T/(rho n^2 D^4)`,
/// `C_P = P/(rho n^3 D^5)`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropellerSpec {
    /// Diameter, inches.
    pub diameter_in: f64,
    /// Static thrust coefficient, propeller convention.
    pub thrust_coefficient_ct: f64,
    /// Static power coefficient, propeller convention.
    pub power_coefficient_cp: f64,
    /// Change of `C_T` per 1000 rpm (Reynolds effect), default 0.
    #[serde(default)]
    pub ct_per_krpm: f64,
    /// Change of `C_P` per 1000 rpm, default 0.
    #[serde(default)]
    pub cp_per_krpm: f64,
    /// Installed-thrust loss (seed: 0.11), default 0.
    #[serde(default)]
    pub installed_thrust_loss_fraction: f64,
}

/// `[propulsion.motor]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorSpec {
    /// Velocity constant, rpm/V.
    pub kv_rpm_per_v: f64,
    /// Armature resistance, ohm.
    pub armature_resistance_ohm: f64,
    /// Constant no-load current, A (give this, or `k1_w_per_rpm` and `k2_w_per_rpm2`).
    #[serde(default)]
    pub no_load_current_a: Option<f64>,
    /// `K_1` of eq (8), W/rpm.
    #[serde(default)]
    pub k1_w_per_rpm: Option<f64>,
    /// `K_2` of eq (8), W/rpm^2.
    #[serde(default)]
    pub k2_w_per_rpm2: Option<f64>,
    /// Motor current limit, A (default none).
    #[serde(default)]
    pub max_current_a: Option<f64>,
}

/// `[propulsion.esc]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EscSpec {
    /// Electronics power `P_e`, W (eq 5).
    #[serde(default)]
    pub electronics_power_w: f64,
    /// Switch resistance `R_e`, ohm.
    #[serde(default)]
    pub resistance_ohm: f64,
}

impl PropellerSpec {
    /// Validated [`Propeller`].
    ///
    /// # Errors
    /// Invalid diameter, coefficients or loss.
    pub fn into_model(self) -> Result<Propeller, PropulsionError> {
        let d_in = positive("propeller diameter_in", self.diameter_in, "in")?;
        Propeller::new(
            d_in * M_PER_IN,
            self.thrust_coefficient_ct,
            self.power_coefficient_cp,
        )?
        .with_speed_dependence(self.ct_per_krpm, self.cp_per_krpm)?
        .with_installed_loss(self.installed_thrust_loss_fraction)
    }
}

impl MotorSpec {
    /// Validated [`Motor`].
    ///
    /// # Errors
    /// Invalid values, or neither/both of the rotational-loss forms.
    pub fn into_model(self) -> Result<Motor, PropulsionError> {
        let loss = match (
            self.no_load_current_a,
            self.k1_w_per_rpm,
            self.k2_w_per_rpm2,
        ) {
            (Some(i0), None, None) => RotationalLoss::NoLoadCurrent { current_a: i0 },
            (None, Some(k1), Some(k2)) => RotationalLoss::SpeedDependent {
                k1_w_per_rpm: k1,
                k2_w_per_rpm2: k2,
            },
            _ => {
                return Err(PropulsionError::ConflictingKeys {
                    table: "propulsion.motor",
                    problem:
                        "give either no_load_current_a, or both k1_w_per_rpm and k2_w_per_rpm2",
                })
            }
        };
        Motor::new(
            self.kv_rpm_per_v,
            self.armature_resistance_ohm,
            loss,
            self.max_current_a.unwrap_or(f64::INFINITY),
        )
    }
}

impl EscSpec {
    /// Validated [`Esc`].
    ///
    /// # Errors
    /// Negative or non-finite values.
    pub fn into_model(self) -> Result<Esc, PropulsionError> {
        Esc::new(self.electronics_power_w, self.resistance_ohm)
    }
}

impl PropulsionSpec {
    /// Validated [`PropulsionSystem`].
    ///
    /// # Errors
    /// The first invalid value found, as a typed error naming it with its unit.
    pub fn into_model(self) -> Result<PropulsionSystem, PropulsionError> {
        PropulsionSystem::new(
            self.propeller.into_model()?,
            self.motor.into_model()?,
            self.esc.into_model()?,
            self.battery.to_seed_model()?,
            self.rotor_count,
            self.packs_count,
            mass("empty_mass_kg", self.empty_mass_kg)?,
            self.gravity_mps2,
            self.air_density_kg_m3,
        )
    }
}

/// Inputs of `aloft rotor` (flags or a rotor TOML file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorSpec {
    /// Motor speed constant, rpm/V.
    pub motor_kv_rpm_per_v: f64,
    /// Motor resistance, ohm.
    pub motor_resistance_ohm: f64,
    /// No-load current, A.
    pub no_load_current_a: f64,
    /// Supply (nominal) voltage, V.
    pub voltage_v: f64,
    /// Motor mass, g.
    pub motor_mass_g: f64,
    /// Motor outer diameter, mm.
    pub motor_diameter_mm: f64,
    /// Propeller mass, g.
    pub prop_mass_g: f64,
    /// Propeller diameter, in.
    pub prop_diameter_in: f64,
    /// Load-torque coefficient `c` of `tau = c w^2`, N m s^2.
    pub torque_coefficient_nms2: f64,
    /// ESC protocol (adds the Table 4 delay); none means no delay.
    #[serde(default)]
    pub protocol: Option<EscProtocol>,
    /// Speed before the step, rad/s (default 0).
    #[serde(default)]
    pub step_from_radps: Option<f64>,
    /// Speed after the step, rad/s (default: the steady speed at the full `voltage_v`).
    #[serde(default)]
    pub step_to_radps: Option<f64>,
}

impl RotorSpec {
    /// Validated [`RotorTransient`].
    ///
    /// # Errors
    /// Zero, negative or non-finite values (named with units), inertia fits out of range.
    pub fn into_model(&self) -> Result<RotorTransient, PropulsionError> {
        let kt = kt_from_kv(
            self.motor_kv_rpm_per_v,
            self.voltage_v,
            self.no_load_current_a,
            self.motor_resistance_ohm,
        )?;
        let motor_mass_kg = mass("motor_mass_g (in kg)", self.motor_mass_g * 1e-3)?;
        let prop_mass_kg = mass("prop_mass_g (in kg)", self.prop_mass_g * 1e-3)?;
        let motor_d_m = positive("motor_diameter_mm", self.motor_diameter_mm, "mm")? * 1e-3;
        let prop_d_m = positive("prop_diameter_in", self.prop_diameter_in, "in")? * M_PER_IN;
        RotorTransient::new(RotorConstants {
            kt_nm_per_a: kt,
            resistance_ohm: self.motor_resistance_ohm,
            no_load_current_a: self.no_load_current_a,
            supply_voltage_v: self.voltage_v,
            motor_inertia_kgm2: motor_inertia_kgm2(motor_mass_kg, motor_d_m)?,
            prop_inertia_kgm2: prop_inertia_kgm2(prop_mass_kg, prop_d_m)?,
            torque_coefficient_nms2: self.torque_coefficient_nms2,
            delay_s: self.protocol.map_or(0.0, EscProtocol::added_delay_s),
        })
    }
}

/// `aloft rotor`: inertias, time constants, simulated rise and settling time and steady current
/// for the step described by `spec`.
///
/// # Errors
/// Invalid inputs, or a step the supply voltage cannot reach.
pub fn rotor_step_response(spec: &RotorSpec) -> Result<RotorTransientResult, PropulsionError> {
    let rotor = spec.into_model()?;
    let from = spec.step_from_radps.unwrap_or(0.0);
    let to = spec
        .step_to_radps
        .unwrap_or_else(|| rotor.full_voltage_speed_radps());
    rotor.summary(from, to)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn motor_spec() -> MotorSpec {
        MotorSpec {
            kv_rpm_per_v: 515.0,
            armature_resistance_ohm: 0.07,
            no_load_current_a: Some(1.5),
            k1_w_per_rpm: None,
            k2_w_per_rpm2: None,
            max_current_a: Some(55.0),
        }
    }

    #[test]
    fn motor_spec_needs_exactly_one_loss_model() {
        assert!(motor_spec().into_model().is_ok());
        let mut both = motor_spec();
        both.k1_w_per_rpm = Some(1e-3);
        both.k2_w_per_rpm2 = Some(1e-7);
        assert!(matches!(
            both.into_model(),
            Err(PropulsionError::ConflictingKeys { .. })
        ));
        let mut bad_kv = motor_spec();
        bad_kv.kv_rpm_per_v = -515.0;
        assert!(matches!(
            bad_kv.into_model(),
            Err(PropulsionError::InvalidKv { kv_rpm_per_v }) if kv_rpm_per_v < 0.0
        ));
    }

    #[test]
    fn rotor_spec_rejects_bad_values() {
        let good = RotorSpec {
            motor_kv_rpm_per_v: 2300.0,
            motor_resistance_ohm: 0.117,
            no_load_current_a: 0.4,
            voltage_v: 11.1,
            motor_mass_g: 18.0,
            motor_diameter_mm: 23.0,
            prop_mass_g: 1.86,
            prop_diameter_in: 6.0,
            torque_coefficient_nms2: 1.4e-8,
            protocol: Some(EscProtocol::Dshot300),
            step_from_radps: None,
            step_to_radps: None,
        };
        assert!(rotor_step_response(&good).is_ok());
        let mut s = good.clone();
        s.motor_mass_g = 0.0;
        assert!(matches!(
            rotor_step_response(&s),
            Err(PropulsionError::InvalidMass { .. })
        ));
        let mut s = good.clone();
        s.voltage_v = -3.0;
        assert!(matches!(
            rotor_step_response(&s),
            Err(PropulsionError::InvalidVoltage { .. })
        ));
        let mut s = good.clone();
        s.motor_kv_rpm_per_v = f64::NAN;
        assert!(matches!(
            rotor_step_response(&s),
            Err(PropulsionError::InvalidKv { .. })
        ));
        let mut s = good;
        s.prop_diameter_in = 3.0;
        assert!(rotor_step_response(&s).is_err());
    }
}
