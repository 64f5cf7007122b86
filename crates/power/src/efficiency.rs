//! Overall efficiency from measured power.
//!
//! [`efficiency_from_hover`] is the power seed's definition (section IV-E):
//! `eta = P_ideal / P_measured` with `P_ideal = m g vh` the theoretical hover power from eq (10) and
//! `P_measured` the mean electrical power measured in hover. With the paper's one-disk eq (10) this
//! `eta` also absorbs the disk-area convention (see [`crate::DiskArea`]).
//!
//! # Deviation
//! That definition leaves out the profile power that eq (14) then divides by the same `eta`, so a
//! model calibrated with it overestimates the very hover it was calibrated on by `P_pro / P_ind`
//! (13 % for the M100). [`calibrate_efficiency`] instead returns the `eta` with which the full
//! model reproduces a measured power at a given flight state; aloft's built-in vehicles and its
//! in-flight re-estimate use it.

use crate::error::{positive, PowerError, Result};
use crate::four_term::{FlightState, PowerModel};
use crate::vehicle::Vehicle;

/// The paper's efficiency: ideal hover power of `vehicle` over the measured hover power.
///
/// The vehicle's own `efficiency` is ignored; its mass, gravity, air density and disk area are used.
/// Errors when the measured power is not positive or is below the ideal power (eta > 1).
pub fn efficiency_from_hover(vehicle: &Vehicle, measured_hover_power_w: f64) -> Result<f64> {
    positive("measured_hover_power_w", measured_hover_power_w)?;
    let eta = vehicle.ideal_hover_power_w() / measured_hover_power_w;
    if eta > 1.0 {
        return Err(PowerError::OutOfRange {
            name: "measured_hover_power_w",
            value: measured_hover_power_w,
            min: vehicle.ideal_hover_power_w(),
            max: f64::INFINITY,
        });
    }
    Ok(eta)
}

/// The efficiency with which `model` (its terms and options, any `eta`) reproduces
/// `measured_power_w` at `state`: `eta = P_req(state) / P_measured`, eqs (7) and (14).
///
/// Errors when the state is invalid, the measured power is not positive, the model's
/// aerodynamic power there is not positive, or the result exceeds 1.
pub fn calibrate_efficiency(
    model: &PowerModel,
    state: &FlightState,
    measured_power_w: f64,
) -> Result<f64> {
    positive("measured_power_w", measured_power_w)?;
    let aero = positive("aero_w", model.evaluate(state)?.aero_w)?;
    let eta = aero / measured_power_w;
    if eta > 1.0 {
        return Err(PowerError::OutOfRange {
            name: "measured_power_w",
            value: measured_power_w,
            min: aero,
            max: f64::INFINITY,
        });
    }
    Ok(eta)
}

/// Mean electrical power of a hover that uses `energy_wh` in `duration_s`, W.
pub fn mean_power_w(energy_wh: f64, duration_s: f64) -> Result<f64> {
    positive("energy_wh", energy_wh)?;
    positive("duration_s", duration_s)?;
    Ok(energy_wh * 3600.0 / duration_s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicle::{DiskArea, VehicleParams};

    fn vehicle(mass_kg: f64) -> Vehicle {
        Vehicle::new(VehicleParams {
            mass_kg,
            gravity_mps2: 9.80665,
            air_density_kg_m3: 1.225,
            rotor_count: 4,
            rotor_radius_m: 0.172,
            disk_area: DiskArea::OneRotor,
            mu1_n_s_per_m: 0.0,
            mu2_n_s2_per_m2: 0.0,
            mu3_n_s3_per_m3: 0.0,
            kappa1_w_per_n1_5: 0.0,
            kappa2_w_s2_per_m2_n0_5: 0.0,
            efficiency: 1.0,
            mu2_x_n_s2_per_m2: None,
            mu2_y_n_s2_per_m2: None,
            efficiency_relative_sd: None,
        })
        .unwrap()
    }

    #[test]
    fn efficiency_is_ideal_over_measured() {
        let v = vehicle(3.0);
        let eta = efficiency_from_hover(&v, 2.0 * v.ideal_hover_power_w()).unwrap();
        assert!((eta - 0.5).abs() < 1e-15);
    }

    #[test]
    fn impossible_measurements_are_rejected() {
        let v = vehicle(3.0);
        assert!(efficiency_from_hover(&v, 0.5 * v.ideal_hover_power_w()).is_err());
        assert!(efficiency_from_hover(&v, -1.0).is_err());
        assert!(efficiency_from_hover(&v, f64::NAN).is_err());
        assert!(mean_power_w(99.9, 0.0).is_err());
    }

    #[test]
    fn calibrated_model_reproduces_the_measured_power() {
        let v = Vehicle::new(VehicleParams {
            kappa1_w_per_n1_5: 0.275,
            ..vehicle(3.0).params().clone()
        })
        .unwrap();
        let hover = FlightState::new(0.0, 0.0, 0.0, 0.0);
        let eta = calibrate_efficiency(&PowerModel::new(v.clone()), &hover, 600.0).unwrap();
        let model = PowerModel::new(v.with_efficiency(eta).unwrap());
        let p = model.evaluate(&hover).unwrap().electrical_w;
        assert!((p - 600.0).abs() < 1e-9, "{p}");
        // The paper's definition is lower by the profile share.
        let paper = efficiency_from_hover(&v, 600.0).unwrap();
        let profile_share = 0.275 * v.weight_n().powf(1.5) / v.ideal_hover_power_w();
        assert!((eta / paper - 1.0 - profile_share).abs() < 1e-12);
        assert!(
            calibrate_efficiency(&model, &hover, 100.0).is_err(),
            "eta > 1"
        );
    }

    #[test]
    fn mean_power_from_energy_and_time() {
        // 99.9 Wh in 13 min = 461.08 W.
        let p = mean_power_w(99.9, 13.0 * 60.0).unwrap();
        assert!((p - 99.9 * 60.0 / 13.0).abs() < 1e-12);
    }
}
