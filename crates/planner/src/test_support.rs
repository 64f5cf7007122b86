//! Fixtures shared by the crate's unit tests: the power seed's M100 with DJI's packs.

use crate::aircraft::Aircraft;
use crate::airframe::{Airframe, AirframeSpec};
use crate::battery::{BatterySpec, Pack};
use crate::mission::{Mission, MissionSpec};
use crate::mission_toml::{at_altitude, landing, leg, take_off};

/// The M100 airframe of `fixtures/vehicles/dji-m100.toml` (DJI's specification).
pub(crate) fn m100_airframe() -> Airframe {
    Airframe::new(AirframeSpec {
        mass_kg: 1.755,
        max_takeoff_mass_kg: 3.6,
        max_thrust_n: None,
        max_tilt_deg: 35.0,
        max_speed_mps: 17.0,
        max_airspeed_mps: None,
        max_climb_rate_mps: 5.0,
        max_descent_rate_mps: 4.0,
        acceleration_mps2: 2.0,
        vertical_acceleration_mps2: 1.5,
        yaw_rate_deg_s: 60.0,
        rotor_height_m: 0.3,
        acceptance_radius_m: None,
        cruise_speed_mps: None,
        rtl_altitude_m: None,
    })
    .unwrap()
}

/// The M100 with the power seed's constants and the calibrated efficiency.
pub(crate) fn m100_aircraft() -> Aircraft {
    let vehicle = aloft_power::Vehicle::new(m100_vehicle_params()).unwrap();
    Aircraft::four_term(m100_airframe(), vehicle, Default::default())
}

/// The M100's power-model parameters: the power seed's constants and the calibrated efficiency.
pub(crate) fn m100_vehicle_params() -> aloft_power::VehicleParams {
    aloft_power::VehicleParams {
        mass_kg: 3.29,
        gravity_mps2: 9.8066,
        air_density_kg_m3: 1.225,
        rotor_count: 4,
        rotor_radius_m: 0.172,
        disk_area: aloft_power::DiskArea::OneRotor,
        mu1_n_s_per_m: 0.1816,
        mu2_n_s2_per_m2: -0.02326,
        mu3_n_s3_per_m3: 0.004045,
        kappa1_w_per_n1_5: 0.275,
        kappa2_w_s2_per_m2_n0_5: 0.0,
        efficiency: 0.9703,
        mu2_x_n_s2_per_m2: None,
        mu2_y_n_s2_per_m2: None,
        efficiency_relative_sd: None,
    }
}

/// DJI's TB47D pack (6S, 4500 mAh, 99.9 Wh, 600 g) with the fixture's assumed resistance.
pub(crate) fn tb47d() -> BatterySpec {
    BatterySpec {
        name: "TB47D".into(),
        default: true,
        cells_series: 6,
        capacity_mah: 4500.0,
        nominal_v: Some(22.2),
        energy_wh: Some(99.9),
        mass_kg: Some(0.6),
        internal_resistance_ohm: Some(0.048),
        cutoff_cell_v: Some(3.0),
        ..BatterySpec::default()
    }
}

/// DJI's TB48D pack (6S, 5700 mAh, 129.96 Wh, 676 g), resistance scaled by capacity.
pub(crate) fn tb48d() -> BatterySpec {
    BatterySpec {
        name: "TB48D".into(),
        capacity_mah: 5700.0,
        nominal_v: Some(22.8),
        energy_wh: Some(129.96),
        mass_kg: Some(0.676),
        internal_resistance_ohm: Some(0.04),
        ..tb47d()
    }
}

/// `text` read as a mission and compiled for `aircraft` carrying `battery`.
pub(crate) fn compile_mission(text: &str, aircraft: &Aircraft, battery: &Pack) -> Mission {
    MissionSpec::from_toml_str(text)
        .unwrap()
        .compile(aircraft.airframe(), battery.mass_kg(), None)
        .unwrap()
}

/// A leg steeper than the M100's 5 m/s climb limit allows at its ground speed: 30 m up over
/// 20 m east at 10 m/s over the ground (15 m/s up).
pub(crate) fn steep_leg() -> String {
    let steep = at_altitude(leg(20.0, 0.0, 10.0), 40.0);
    [take_off(10.0, 2.0), steep, landing(1.0)].concat()
}
