//! The fixture the plan's tests fly: the M100 with a TB48D and a survey with every kind of piece.

use crate::aircraft::Aircraft;
use crate::battery::Pack;
use crate::mission::Mission;
use crate::test_support::{compile_mission, m100_aircraft, tb48d};

/// The M100 and its TB48D pack.
pub(super) fn m100() -> (Aircraft, Pack) {
    (m100_aircraft(), Pack::new(&tb48d()).unwrap())
}

/// The M100, its TB48D pack and [`SURVEY`] compiled for them.
pub(super) fn m100_survey() -> (Aircraft, Pack, Mission) {
    let (aircraft, battery) = m100();
    let mission = compile_mission(SURVEY, &aircraft, &battery);
    (aircraft, battery, mission)
}

/// A survey: take-off, a leg, a hover, a climbing leg, an orbit, the return, the landing.
pub(super) const SURVEY: &str = r#"
        [[segment]]
        kind = "take-off"
        altitude_m = 30.0
        climb_rate_mps = 2.0
        [[segment]]
        kind = "leg"
        east_m = 400.0
        north_m = 0.0
        ground_speed_mps = 9.0
        [[segment]]
        kind = "hover"
        duration_s = 20.0
        [[segment]]
        kind = "leg"
        east_m = 400.0
        north_m = 250.0
        altitude_m = 45.0
        ground_speed_mps = 7.0
        [[segment]]
        kind = "orbit"
        centre_east_m = 400.0
        centre_north_m = 150.0
        radius_m = 100.0
        ground_speed_mps = 6.0
        direction = "clockwise"
        laps = 1.0
        [[segment]]
        kind = "return"
        ground_speed_mps = 9.0
        [[segment]]
        kind = "landing"
        rate_mps = 1.0
    "#;
