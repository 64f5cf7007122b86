//! What is flown: the mission spec with the request's choices applied, decided here once.
//!
//! - the planning speed (the ground speed of legs, orbits and returns that give none): the
//!   options' `speed_mps` (`--speed`), else the vehicle's `cruise_speed_mps`, else the mission's
//!   `default_speed_mps` (a QGroundControl plan's `hoverSpeed`); the answer says which;
//! - the lowest height of a return to home: the options' `rtl_altitude_m` (`--rtl-altitude-m`),
//!   else the vehicle's, else the mission's;
//! - corners: the options' `corners` (`--corners`), else the mission's, else pass-through.

use serde::{Deserialize, Serialize};

use aloft_planner::MissionSpec;

use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_options::MissionOptions;
use crate::engine::vehicles::vehicle::Vehicle;

/// The planning speed a mission was flown with and where it came from (in the answer when the
/// mission has one).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanningSpeed {
    /// Ground speed of the legs, orbits and returns that give none, m/s.
    pub speed_mps: f64,
    /// Where it came from: `option` (`--speed`), `vehicle` (its `cruise_speed_mps`) or `mission`
    /// (the file's default: a `.plan`'s `hoverSpeed`, an aloft mission's `default_speed_mps`).
    pub source: String,
}

/// The mission spec to fly with `vehicle` and `options`, and the planning speed it flies with.
pub(in crate::engine) fn flown_spec(
    mission: &Mission,
    vehicle: &Vehicle,
    options: &MissionOptions,
) -> (MissionSpec, Option<PlanningSpeed>) {
    let mut spec = mission.spec().clone();
    let flight = vehicle.flight_defaults();
    let speed = [
        (options.speed_mps, "option"),
        (flight.cruise_speed_mps, "vehicle"),
        (spec.default_speed_mps, "mission"),
    ]
    .into_iter()
    .find_map(|(v, source)| {
        v.map(|speed_mps| PlanningSpeed {
            speed_mps,
            source: source.to_string(),
        })
    });
    spec.default_speed_mps = speed.as_ref().map(|s| s.speed_mps);
    spec.rtl_altitude_m = options
        .rtl_altitude_m
        .or(flight.rtl_altitude_m)
        .or(spec.rtl_altitude_m);
    spec.corners = Some(options.corners.or(spec.corners).unwrap_or_default());
    (spec, speed)
}
