//! Hover operating point of the whole propulsion chain, propulsion seed eqs (2)-(3), (21)-(22),
//! (28)-(31) and the chart of Fig. 13.
//!
//! From a take-off mass `m`:
//!
//! 1. thrust per rotor `T = m g / N_rotors`; stand thrust `T / (1 - loss)` (installed loss, 11 %
//!    in the seed);
//! 2. rotor speed `N` and shaft torque `Q` from the propeller coefficients (eqs 21-22);
//! 3. armature current `I_a = Q / K_t` (eq 2), rotational-loss current `I_r`, motor current
//!    `I_m = I_a + I_r` (eq 20), back-emf `V_a = N / K_v` (eq 3);
//! 4. supply power per motor, eq (28): `P_ps = P_e + I_m^2 R_m + I_m V_a`;
//! 5. each pack feeds `N_rotors / N_packs` motors; pack current from eqs (29)-(30), heat
//!    `I^2 R_b`, flight duration eq (31).
//!
//! The seed's airframe has one pack per motor (four packs, four motors).

use crate::battery::Battery;
use crate::error::{mass, positive, PropulsionError};
use crate::esc::Esc;
use crate::motor::Motor;
use crate::propeller::Propeller;
use serde::Serialize;
use std::f64::consts::PI;

/// A multirotor propulsion system: identical rotors (propeller + motor + ESC) fed by identical
/// packs.
#[derive(Debug, Clone, PartialEq)]
pub struct PropulsionSystem {
    /// Propeller of each rotor.
    pub propeller: Propeller,
    /// Motor of each rotor.
    pub motor: Motor,
    /// ESC of each rotor.
    pub esc: Esc,
    /// Each pack.
    pub battery: Battery,
    rotor_count: u32,
    pack_count: u32,
    empty_mass_kg: f64,
    gravity_mps2: f64,
    rho_kg_m3: f64,
}

/// The state of one rotor at a required thrust.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RotorOperatingPoint {
    /// Thrust the installed rotor must make, N.
    pub thrust_n: f64,
    /// Thrust the propeller makes on a stand at the same speed, N.
    pub stand_thrust_n: f64,
    /// Rotor speed, rpm.
    pub speed_rpm: f64,
    /// Shaft torque, N m.
    pub torque_nm: f64,
    /// Shaft power, W.
    pub shaft_power_w: f64,
    /// Armature (torque-producing) current, A.
    pub armature_current_a: f64,
    /// Rotational-loss current, A.
    pub rotational_current_a: f64,
    /// Motor current `I_a + I_r`, A.
    pub motor_current_a: f64,
    /// Back-emf `N / K_v`, V.
    pub back_emf_v: f64,
    /// Voltage the ESC must apply, `V_a + I_m R_m`, V.
    pub motor_voltage_v: f64,
    /// Power supplied to the ESC, eq (28), W.
    pub supply_power_w: f64,
    /// Shaft power over supply power.
    pub efficiency: f64,
}

/// Hover result for the whole vehicle (the seed's worked example and each point of Fig. 13).
///
/// The first nine fields are the JSON contract of `aloft propulsion`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HoverResult {
    /// Take-off mass, kg.
    pub takeoff_mass_kg: f64,
    /// Thrust each installed rotor makes, `m g / N_rotors`, N.
    pub thrust_per_rotor_n: f64,
    /// Rotor speed, rpm.
    pub rotor_speed_rpm: f64,
    /// Motor current `I_m` of each motor, A.
    pub motor_current_a: f64,
    /// Current drawn from each pack, A.
    pub pack_current_a: f64,
    /// Total power required by all ESCs (`P_ps` summed, eq 28), W.
    pub power_required_w: f64,
    /// Total power drawn from the cells of all packs (`P_t = V_f I` summed, eq 30), W.
    pub power_drawn_w: f64,
    /// Heat dissipated in all packs, W.
    pub battery_heat_w: f64,
    /// Flight duration, eq (31), min.
    pub flight_time_min: f64,
    /// Shaft torque of each rotor, N m.
    pub torque_nm: f64,
    /// Stand thrust of each propeller, N.
    pub stand_thrust_per_rotor_n: f64,
    /// Supply power of each motor, W.
    pub power_per_motor_w: f64,
    /// Armature current of each motor, A.
    pub armature_current_a: f64,
    /// Back-emf of each motor, V.
    pub back_emf_v: f64,
    /// Voltage each ESC applies to its motor, V.
    pub motor_voltage_v: f64,
    /// Pack terminal voltage in the seed's model, `V_f - I R_b`, V.
    pub pack_terminal_voltage_v: f64,
    /// Number of rotors.
    pub rotor_count: u32,
    /// Number of packs.
    pub pack_count: u32,
}

impl PropulsionSystem {
    /// Builds a system.
    ///
    /// # Errors
    /// Zero rotors or packs, more packs than rotors, a non-positive empty mass, gravity or air
    /// density.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        propeller: Propeller,
        motor: Motor,
        esc: Esc,
        battery: Battery,
        rotor_count: u32,
        pack_count: u32,
        empty_mass_kg: f64,
        gravity_mps2: f64,
        rho_kg_m3: f64,
    ) -> Result<Self, PropulsionError> {
        if rotor_count == 0 {
            return Err(PropulsionError::InvalidCount {
                name: "rotor_count",
                count: rotor_count,
                expected: "at least one rotor",
            });
        }
        if pack_count == 0 || pack_count > rotor_count {
            return Err(PropulsionError::InvalidCount {
                name: "packs_count",
                count: pack_count,
                expected: "between one and the number of rotors",
            });
        }
        Ok(Self {
            propeller,
            motor,
            esc,
            battery,
            rotor_count,
            pack_count,
            empty_mass_kg: mass("empty_mass_kg", empty_mass_kg)?,
            gravity_mps2: positive("gravity_mps2", gravity_mps2, "m/s^2")?,
            rho_kg_m3: positive("air_density_kg_m3", rho_kg_m3, "kg/m^3")?,
        })
    }

    /// Number of rotors.
    pub fn rotor_count(&self) -> u32 {
        self.rotor_count
    }

    /// Number of packs.
    pub fn pack_count(&self) -> u32 {
        self.pack_count
    }

    /// Empty mass (without payload), kg.
    pub fn empty_mass_kg(&self) -> f64 {
        self.empty_mass_kg
    }

    /// Gravity, m/s^2.
    pub fn gravity_mps2(&self) -> f64 {
        self.gravity_mps2
    }

    /// Air density, kg/m^3.
    pub fn rho_kg_m3(&self) -> f64 {
        self.rho_kg_m3
    }

    /// State of one rotor making `thrust_n` (installed).
    ///
    /// # Errors
    /// A negative or non-finite thrust; [`PropulsionError::CurrentLimitExceeded`] when the motor
    /// current would exceed the motor's limit.
    pub fn rotor_at_thrust(&self, thrust_n: f64) -> Result<RotorOperatingPoint, PropulsionError> {
        if !(thrust_n.is_finite() && thrust_n >= 0.0) {
            return Err(PropulsionError::InvalidThrust { thrust_n });
        }
        let stand = self.propeller.stand_thrust_n(thrust_n);
        let speed_rpm = self.propeller.speed_for_thrust_rpm(stand, self.rho_kg_m3)?;
        let torque_nm = self.propeller.torque_nm(speed_rpm, self.rho_kg_m3);
        let shaft_power_w = torque_nm * speed_rpm * 2.0 * PI / 60.0;
        let ia = self.motor.armature_current_a(torque_nm);
        let ir = self.motor.rotational_current_a(speed_rpm);
        let im = ia + ir;
        if im > self.motor.max_current_a() {
            return Err(PropulsionError::CurrentLimitExceeded {
                thrust_n,
                current_a: im,
                limit_a: self.motor.max_current_a(),
            });
        }
        let rm = self.motor.armature_resistance_ohm() + self.esc.resistance_ohm();
        let va = self.motor.back_emf_v(speed_rpm);
        let p_ps = self.esc.electronics_power_w() + im * im * rm + im * va;
        Ok(RotorOperatingPoint {
            thrust_n,
            stand_thrust_n: stand,
            speed_rpm,
            torque_nm,
            shaft_power_w,
            armature_current_a: ia,
            rotational_current_a: ir,
            motor_current_a: im,
            back_emf_v: va,
            motor_voltage_v: va + im * rm,
            supply_power_w: p_ps,
            efficiency: if p_ps > 0.0 {
                shaft_power_w / p_ps
            } else {
                0.0
            },
        })
    }

    /// Hover at a take-off mass.
    ///
    /// # Errors
    /// A non-positive mass; the motor current limit; a power or current the packs cannot deliver.
    pub fn hover_at_takeoff_mass(
        &self,
        takeoff_mass_kg: f64,
    ) -> Result<HoverResult, PropulsionError> {
        let m = mass("takeoff_mass_kg", takeoff_mass_kg)?;
        let thrust = m * self.gravity_mps2 / self.rotor_count as f64;
        let rotor = self.rotor_at_thrust(thrust)?;
        let motors_per_pack = self.rotor_count as f64 / self.pack_count as f64;
        let pack_power = motors_per_pack * rotor.supply_power_w;
        let i_pack = self.battery.current_for_power_a(pack_power)?;
        let packs = self.pack_count as f64;
        Ok(HoverResult {
            takeoff_mass_kg: m,
            thrust_per_rotor_n: thrust,
            rotor_speed_rpm: rotor.speed_rpm,
            motor_current_a: rotor.motor_current_a,
            pack_current_a: i_pack,
            power_required_w: rotor.supply_power_w * self.rotor_count as f64,
            power_drawn_w: self.battery.total_power_w(i_pack) * packs,
            battery_heat_w: self.battery.heat_w(i_pack) * packs,
            flight_time_min: self.battery.flight_duration_min(i_pack),
            torque_nm: rotor.torque_nm,
            stand_thrust_per_rotor_n: rotor.stand_thrust_n,
            power_per_motor_w: rotor.supply_power_w,
            armature_current_a: rotor.armature_current_a,
            back_emf_v: rotor.back_emf_v,
            motor_voltage_v: rotor.motor_voltage_v,
            pack_terminal_voltage_v: self.battery.terminal_v(i_pack),
            rotor_count: self.rotor_count,
            pack_count: self.pack_count,
        })
    }

    /// Hover with `payload_kg` on top of the empty mass (the seed's worked example uses
    /// 10 lb = 4.536 kg).
    ///
    /// # Errors
    /// A negative or non-finite payload, and everything [`Self::hover_at_takeoff_mass`] rejects.
    pub fn hover_with_payload(&self, payload_kg: f64) -> Result<HoverResult, PropulsionError> {
        if !(payload_kg.is_finite() && payload_kg >= 0.0) {
            return Err(PropulsionError::InvalidMass {
                name: "payload_kg",
                mass_kg: payload_kg,
            });
        }
        self.hover_at_takeoff_mass(self.empty_mass_kg + payload_kg)
    }

    /// Pack current for one rotor thrust (thrust -> speed -> current -> eq 28 -> eqs 29-30), A.
    /// The fast path benched as `propulsion/operating_point`.
    ///
    /// # Errors
    /// As [`Self::rotor_at_thrust`] and [`Battery::current_for_power_a`].
    pub fn pack_current_for_thrust_a(
        &self,
        thrust_per_rotor_n: f64,
    ) -> Result<f64, PropulsionError> {
        let rotor = self.rotor_at_thrust(thrust_per_rotor_n)?;
        let motors_per_pack = self.rotor_count as f64 / self.pack_count as f64;
        self.battery
            .current_for_power_a(motors_per_pack * rotor.supply_power_w)
    }

    /// The seed's Fig. 13 chart: hover results over a list of take-off masses. Each point is
    /// computed independently, so an infeasible mass (e.g. beyond the motor current limit) gives
    /// an error at that point only.
    pub fn sweep_takeoff_mass(
        &self,
        masses_kg: &[f64],
    ) -> Vec<Result<HoverResult, PropulsionError>> {
        masses_kg
            .iter()
            .map(|&m| self.hover_at_takeoff_mass(m))
            .collect()
    }
}

/// Take-off masses `from, from + step, ..., <= to` (inclusive within 1e-9 of a step), for
/// [`PropulsionSystem::sweep_takeoff_mass`] (e.g. `7:13:0.5`).
///
/// # Errors
/// Non-positive masses or step, `to < from`, or more than 100 000 points.
pub fn mass_range_kg(from_kg: f64, to_kg: f64, step_kg: f64) -> Result<Vec<f64>, PropulsionError> {
    let from_kg = mass("sweep from_kg", from_kg)?;
    let to_kg = mass("sweep to_kg", to_kg)?;
    let step_kg = positive("sweep step_kg", step_kg, "kg")?;
    if to_kg < from_kg {
        return Err(PropulsionError::InvalidMass {
            name: "sweep to_kg (below from_kg)",
            mass_kg: to_kg,
        });
    }
    let n = ((to_kg - from_kg) / step_kg + 1e-9).floor();
    // `n` is not negative (NaN cannot reach here): `<=` is the negation of `>`.
    let expected = "a step giving at most 100000 points";
    aloft_core::parameter("sweep step_kg", step_kg, "kg", n <= 1e5, expected)?;
    Ok((0..=n as usize)
        .map(|k| from_kg + k as f64 * step_kg)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motor::motor_with_no_load_current;
    use aloft_core::{ISA_SEA_LEVEL_DENSITY_KG_M3, STANDARD_GRAVITY_MPS2};

    fn system() -> PropulsionSystem {
        PropulsionSystem::new(
            Propeller::new(0.3556, 0.10, 0.039)
                .unwrap()
                .with_installed_loss(0.11)
                .unwrap(),
            motor_with_no_load_current(515.0, 0.07, 1.5, 55.0).unwrap(),
            Esc::ideal(),
            Battery::new(crate::battery::seed_pack_constants(0.07)).unwrap(),
            4,
            4,
            7.484,
            STANDARD_GRAVITY_MPS2,
            ISA_SEA_LEVEL_DENSITY_KG_M3,
        )
        .unwrap()
    }

    #[test]
    fn energy_balance_closes() {
        let s = system();
        let h = s.hover_at_takeoff_mass(11.0).unwrap();
        // drawn = required + heat, exactly by eq (29)
        assert!((h.power_drawn_w - h.power_required_w - h.battery_heat_w).abs() < 1e-9);
        let r = s.rotor_at_thrust(h.thrust_per_rotor_n).unwrap();
        assert!(r.shaft_power_w < r.supply_power_w);
    }

    #[test]
    fn thrust_beyond_current_limit_is_an_error() {
        let s = system();
        assert!(matches!(
            s.hover_at_takeoff_mass(30.0),
            Err(PropulsionError::CurrentLimitExceeded { .. })
        ));
        assert!(s.hover_at_takeoff_mass(0.0).is_err());
        assert!(s.hover_with_payload(-1.0).is_err());
        assert!(s.rotor_at_thrust(f64::NAN).is_err());
    }

    #[test]
    fn mass_range_is_inclusive() {
        let r = mass_range_kg(7.0, 13.0, 0.5).unwrap();
        assert_eq!(r.len(), 13);
        assert!((r[12] - 13.0).abs() < 1e-12);
        assert!(mass_range_kg(7.0, 6.0, 0.5).is_err());
        assert!(mass_range_kg(7.0, 8.0, 0.0).is_err());
    }

    #[test]
    fn shared_packs_carry_more_current() {
        let one_per_motor = system();
        let mut shared = system();
        shared.pack_count = 2;
        let a = one_per_motor.hover_at_takeoff_mass(9.0).unwrap();
        let b = shared.hover_at_takeoff_mass(9.0).unwrap();
        assert!(b.pack_current_a > 2.0 * a.pack_current_a);
    }
}
