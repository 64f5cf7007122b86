//! The fixture the plan's tests fly: the M100 with a TB48D and a survey with every kind of piece.

use crate::aircraft::Aircraft;
use crate::battery::Pack;
use crate::mission::Mission;
use crate::mission_toml::{
    at_altitude, hover, landing, leg, orbit, return_home, take_off, OrbitFor,
};
use crate::test_support::{compile_mission, m100_aircraft, tb48d};

/// The M100 and its TB48D pack.
pub(super) fn m100() -> (Aircraft, Pack) {
    (m100_aircraft(), Pack::new(&tb48d()).unwrap())
}

/// The M100, its TB48D pack and [`survey`] compiled for them.
pub(super) fn m100_survey() -> (Aircraft, Pack, Mission) {
    let (aircraft, battery) = m100();
    let mission = compile_mission(&survey(), &aircraft, &battery);
    (aircraft, battery, mission)
}

/// A survey: take-off, a leg, a hover, a climbing leg, an orbit, the return, the landing.
pub(super) fn survey() -> String {
    [
        take_off(30.0, 2.0),
        leg(400.0, 0.0, 9.0),
        hover(20.0),
        at_altitude(leg(400.0, 250.0, 7.0), 45.0),
        orbit([400.0, 150.0], 100.0, 6.0, "clockwise", OrbitFor::Laps(1.0)),
        return_home(9.0),
        landing(1.0),
    ]
    .concat()
}
