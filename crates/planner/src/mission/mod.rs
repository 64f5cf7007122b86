//! Missions: what to fly (the mission spec and its file format) and its compilation into
//! trajectory pieces for one airframe.
//!
//! - `spec.rs`: [`MissionSpec`] and its parts, plain data with public fields; the TOML reader
//!   [`MissionSpec::from_toml_str`] (serde, units in the keys, unknown keys rejected);
//! - `compile.rs`: [`MissionSpec::compile`], a compiler with one method per segment kind;
//! - `checks.rs`: the checks of segment values and the resolver of points;
//! - here: the compiled [`Mission`].
//!
//! # Mission sources
//! Every mission source produces a [`MissionSpec`]: the TOML file read here, the same structure in
//! JSON (read by the engine through serde), and the importers of operator formats (QGroundControl
//! `.plan`, Mission Planner `.waypoints`), which build the spec in code from its public fields. A
//! source only translates its format into segments; it knows no airframe and flies nothing.
//! [`MissionSpec::compile`] is the one place where segments become trajectory pieces, so a mission
//! is flown the same whatever it was written in. A new kind of segment is a new [`SegmentSpec`]
//! variant and one more method of the compiler.
//!
//! # The mission file
//! ```toml
//! name = "survey"
//! payload_kg = 0.0            # payload at take-off (optional)
//! reserve_percent = 20.0      # reserve of usable capacity required at landing (optional)
//! time_step_s = 0.1           # sampling step (optional)
//!
//! [home]                      # east_m/north_m, or latitude_deg/longitude_deg
//! east_m = 0.0
//! north_m = 0.0
//!
//! [[segment]]
//! kind = "take-off"
//! altitude_m = 30.0
//! climb_rate_mps = 2.5
//!
//! [[segment]]
//! kind = "leg"                # to a waypoint: east_m/north_m or latitude_deg/longitude_deg
//! east_m = 200.0
//! north_m = 0.0
//! altitude_m = 30.0           # optional: keep the present altitude
//! ground_speed_mps = 8.0
//! payload_after_kg = 0.0      # optional: payload after this waypoint (a delivery)
//!
//! [[segment]]
//! kind = "orbit"
//! centre_east_m = 100.0
//! centre_north_m = 100.0
//! radius_m = 25.0
//! ground_speed_mps = 5.0
//! direction = "clockwise"     # or "counter-clockwise", seen from above
//! laps = 2.0                  # or duration_s
//!
//! [[segment]]
//! kind = "hover"
//! duration_s = 30.0
//!
//! [[segment]]
//! kind = "return"             # straight back over home at the present altitude
//! ground_speed_mps = 8.0
//!
//! [[segment]]
//! kind = "descent"            # vertical, to a lower altitude
//! altitude_m = 10.0
//! rate_mps = 2.0
//!
//! [[segment]]
//! kind = "landing"
//! rate_mps = 1.0
//! ```
//!
//! Altitudes are heights above the home point; the ground is flat at height 0.
//!
//! # Compilation
//! The mission as a whole is checked first: at least one segment; a home point given at most one
//! way (`east_m`/`north_m` or `latitude_deg`/`longitude_deg`; by default the origin); a take-off
//! payload that is not negative, with a take-off mass within the airframe's limit. The segments are
//! then compiled in order, and the first error found wins (within a segment, in the order its
//! method checks).
//!
//! The vehicle starts on the ground at home, nose north. A take-off must start on the ground,
//! every other kind in the air, and the mission must end on the ground. Every segment is flown
//! from rest to rest (see [`crate::trajectory`]); before a leg, a return or an orbit the vehicle
//! yaws to the new heading at the airframe's yaw rate, hovering. An orbit starts with a straight
//! transit from the present position to the nearest point of its circle, and its load in still
//! air, `v^2 / r`, must be within `g tan(max tilt)`. Legs that change altitude keep the commanded
//! ground speed; the vertical rate that implies must be within the airframe's climb or descent
//! limit (a purely vertical leg flies at that limit). A `payload_after_kg` starts a new mass
//! phase after its segment, checked against the take-off mass limit.

mod checks;
mod compile;
mod corners;
mod spec;

pub use checks::{HOME_AMSL_RANGE_M, MAX_MISSION_VALUE, MAX_PIECE_S};
pub use compile::MAX_SEGMENTS;
pub use corners::{DEFAULT_ACCEPTANCE_RADIUS_M, MIN_CORNER_SPEED_MPS};
pub use spec::{
    CornerMode, HomeSpec, MissionSpec, OrbitDirection, SegmentSpec, WindProfileKind, WindSpec,
};

use crate::trajectory::Piece;

/// A mission compiled for an airframe ([`MissionSpec::compile`]): trajectory pieces and the
/// payload of each mass phase.
#[derive(Debug, Clone, PartialEq)]
pub struct Mission {
    /// The spec's name.
    name: String,
    /// Home, ENU m (height 0).
    home_m: [f64; 3],
    /// Trajectory pieces in order; each names its segment and mass phase.
    pieces: Vec<Piece>,
    /// The kind of each segment, as written.
    kinds: Vec<&'static str>,
    /// The payload of each mass phase, kg: the take-off payload, then one per change.
    payloads_kg: Vec<f64>,
    /// The operator's item number of each segment (from a planner file).
    items: Vec<Option<u32>>,
    /// The route ends in the air (a planner file without landing, or a loiter until the reserve).
    ends_in_air: bool,
    /// The route ends in a loiter until the reserve.
    loiter_until_reserve: bool,
    /// What the compiler adjusted (a speed beyond the vehicle's flown at its maximum).
    warnings: Vec<String>,
}

impl Mission {
    /// The operator's item number of each segment (from a planner file), in order.
    pub fn segment_items(&self) -> &[Option<u32>] {
        &self.items
    }
    /// What the compiler adjusted, for the reader (a speed beyond the vehicle's flown at its
    /// maximum).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }
    /// Whether the route ends in the air (no landing): its reserve is judged where it ends.
    pub fn ends_in_air(&self) -> bool {
        self.ends_in_air
    }
    /// Whether the route ends in a loiter until the reserve.
    pub fn ends_in_loiter_until_reserve(&self) -> bool {
        self.loiter_until_reserve
    }
    /// Name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Home, ENU m (height 0).
    pub fn home_m(&self) -> [f64; 3] {
        self.home_m
    }
    /// Trajectory pieces in order.
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }
    /// Kind of each mission segment.
    pub fn segment_kinds(&self) -> &[&'static str] {
        &self.kinds
    }
    /// Payload of each mass phase, kg.
    pub fn payloads_kg(&self) -> &[f64] {
        &self.payloads_kg
    }
    /// Total duration, s.
    pub fn duration_s(&self) -> f64 {
        self.pieces.iter().map(Piece::duration_s).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::m100_airframe;

    /// Fuzz finding `fixtures/fuzz/mission-toml/f421c065e260953e.bin`: a home altitude of NaN
    /// or infinity was accepted, and the mission's JSON wrote it as `null`.
    #[test]
    fn home_altitude_amsl_not_finite_or_out_of_range_is_refused_by_name() {
        for (amsl, ok) in [
            ("nan", false),
            ("inf", false),
            ("-inf", false),
            ("1e5", false),
            ("-501.0", false),
            ("-430.0", true),
            ("488.0", true),
            ("8849.0", true),
        ] {
            let text = format!(
                "[home]\naltitude_amsl_m = {amsl}\n\
                 [[segment]]\nkind = \"take-off\"\naltitude_m = 10.0\nclimb_rate_mps = 2.0\n\
                 [[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n"
            );
            let spec = MissionSpec::from_toml_str(&text).unwrap();
            match spec.compile(&m100_airframe(), 0.68, None) {
                Ok(_) => assert!(ok, "{amsl} m accepted"),
                Err(e) => {
                    assert!(!ok, "{amsl} m refused: {e}");
                    let msg = e.to_string();
                    assert!(msg.contains("home altitude_amsl_m"), "{msg}");
                    assert!(msg.contains(" m"), "{msg}");
                }
            }
        }
    }

    #[test]
    fn the_default_spec_is_the_empty_file() {
        assert_eq!(
            MissionSpec::from_toml_str("").unwrap(),
            MissionSpec::default()
        );
    }

    /// The contract of every mission source: a spec built in code is the spec the file reader
    /// makes, and it compiles to the same pieces, bit for bit (`Mission` compares its f64s exactly).
    #[test]
    fn a_spec_built_in_code_flies_as_the_same_file() {
        let text = r#"
            name = "coded"
            payload_kg = 0.5
            [home]
            latitude_deg = 47.3769
            longitude_deg = 8.5417
            [[segment]]
            kind = "take-off"
            altitude_m = 20.0
            climb_rate_mps = 2.0
            [[segment]]
            kind = "leg"
            latitude_deg = 47.379
            longitude_deg = 8.545
            ground_speed_mps = 8.0
            payload_after_kg = 0.0
            [[segment]]
            kind = "orbit"
            centre_east_m = 100.0
            centre_north_m = 100.0
            radius_m = 25.0
            ground_speed_mps = 4.0
            direction = "clockwise"
            laps = 1.5
            [[segment]]
            kind = "return"
            ground_speed_mps = 8.0
            [[segment]]
            kind = "landing"
            rate_mps = 1.0
        "#;
        let coded = MissionSpec {
            name: "coded".into(),
            payload_kg: 0.5,
            home: HomeSpec {
                latitude_deg: Some(47.3769),
                longitude_deg: Some(8.5417),
                ..HomeSpec::default()
            },
            segments: vec![
                SegmentSpec::TakeOff {
                    altitude_m: 20.0,
                    climb_rate_mps: 2.0,
                    item: None,
                },
                SegmentSpec::Leg {
                    east_m: None,
                    north_m: None,
                    latitude_deg: Some(47.379),
                    longitude_deg: Some(8.545),
                    altitude_m: None,
                    ground_speed_mps: Some(8.0),
                    payload_after_kg: Some(0.0),
                    acceptance_radius_m: None,
                    item: None,
                },
                SegmentSpec::Orbit {
                    centre_east_m: Some(100.0),
                    centre_north_m: Some(100.0),
                    centre_latitude_deg: None,
                    centre_longitude_deg: None,
                    altitude_m: None,
                    radius_m: 25.0,
                    ground_speed_mps: Some(4.0),
                    direction: OrbitDirection::Clockwise,
                    laps: Some(1.5),
                    duration_s: None,
                    item: None,
                },
                SegmentSpec::Return {
                    ground_speed_mps: Some(8.0),
                    altitude_m: None,
                    item: None,
                },
                SegmentSpec::Landing {
                    rate_mps: 1.0,
                    payload_after_kg: None,
                    item: None,
                    ground_m: None,
                },
            ],
            ..MissionSpec::default()
        };
        let read = MissionSpec::from_toml_str(text).unwrap();
        assert_eq!(coded, read);
        let airframe = m100_airframe();
        let mission = coded.compile(&airframe, 0.6, None).unwrap();
        assert_eq!(mission, read.compile(&airframe, 0.6, None).unwrap());
        assert_eq!(mission.payloads_kg(), [0.5, 0.0]);
        assert_eq!(
            mission.segment_kinds(),
            ["take-off", "leg", "orbit", "return", "landing"]
        );
    }
    /// Legs far from home keep their length: each leg is placed in its own tangent plane, not
    /// in one flat frame at home (which stretches an east-west leg 300 km north of home at
    /// 25 deg by about 2 %). The length is checked against the haversine distance on a sphere
    /// of the WGS-84 radius of curvature there, written out here (sphere against ellipsoid:
    /// agreement to 1e-4 over 1 km).
    #[test]
    fn a_leg_far_from_home_has_its_own_length() {
        let text = r#"
            [home]
            latitude_deg = 25.0
            longitude_deg = 120.0
            [[segment]]
            kind = "take-off"
            altitude_m = 50.0
            climb_rate_mps = 5.0
            [[segment]]
            kind = "leg"
            latitude_deg = 27.7
            longitude_deg = 120.0
            ground_speed_mps = 15.0
            [[segment]]
            kind = "leg"
            latitude_deg = 27.7
            longitude_deg = 120.01
            ground_speed_mps = 15.0
            [[segment]]
            kind = "landing"
            rate_mps = 2.0
        "#;
        let mut spec = MissionSpec::from_toml_str(text).unwrap();
        spec.corners = Some(CornerMode::Stop);
        let mission = spec.compile(&m100_airframe(), 0.68, None).unwrap();
        let legs: Vec<f64> = mission
            .pieces()
            .iter()
            .filter(|p| matches!(p.shape, crate::trajectory::Shape::Line { dir, .. } if dir[2].abs() < 1e-9))
            .map(|p| p.profile.length_m)
            .collect();
        let lat = 27.7f64.to_radians();
        // Prime-vertical radius of curvature at 27.7 deg (WGS-84).
        let n = 6_378_137.0 / (1.0 - 6.694_379_990_14e-3 * lat.sin().powi(2)).sqrt();
        let dlon = 0.01f64.to_radians();
        let haversine = 2.0 * n * (lat.cos() * (dlon / 2.0).sin()).asin();
        assert_eq!(legs.len(), 2);
        assert!(
            (legs[1] / haversine - 1.0).abs() < 1e-4,
            "{} against {haversine}",
            legs[1]
        );
    }
    /// A leg steeper than the climb limit allows at its ground speed compiles as planned (the
    /// flight envelope slows it to the climb limit when flown: `plan::tests`), in an aloft
    /// mission and a planner file alike.
    #[test]
    fn a_steep_leg_compiles_as_planned() {
        let text = &crate::test_support::steep_leg();
        let mut spec = MissionSpec::from_toml_str(text).unwrap();
        let aloft = spec.compile(&m100_airframe(), 0.68, None).unwrap();
        spec.clamp_speeds = true;
        let planner = spec.compile(&m100_airframe(), 0.68, None).unwrap();
        assert_eq!(aloft.pieces(), planner.pieces());
        assert!(aloft.warnings().is_empty() && planner.warnings().is_empty());
    }
}
