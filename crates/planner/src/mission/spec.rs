//! The mission description: what to fly, in the words of the mission file.
//!
//! These are plain data types with public fields. The TOML reader ([`MissionSpec::from_toml_str`])
//! and the JSON reader of the engine fill them through serde (units in the keys, unknown keys
//! rejected); any other mission source may build them in code. Nothing here knows an airframe:
//! [`MissionSpec::compile`] turns a spec into trajectory pieces.

use serde::{Deserialize, Serialize};

use crate::error::PlannerError;
use crate::wind::{Gusts, Profile as WindProfile, Wind};

/// Home point: local east/north metres, or latitude and longitude.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HomeSpec {
    /// East, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub east_m: Option<f64>,
    /// North, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub north_m: Option<f64>,
    /// Latitude, deg (WGS-84).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub latitude_deg: Option<f64>,
    /// Longitude, deg (WGS-84).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub longitude_deg: Option<f64>,
    /// Ground altitude above mean sea level, m (informational; heights are above home).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub altitude_amsl_m: Option<f64>,
}

/// Orbit direction seen from above.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OrbitDirection {
    /// Clockwise.
    Clockwise,
    /// Counter-clockwise.
    CounterClockwise,
}

/// One `[[segment]]` of a mission file, tagged by `kind`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum SegmentSpec {
    /// Vertical climb from the ground.
    TakeOff {
        /// Height to climb to, m.
        altitude_m: f64,
        /// Climb rate, m/s.
        climb_rate_mps: f64,
        /// The operator's mission item number (from a planner file), named in the reports.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        item: Option<u32>,
    },
    /// Straight leg to a waypoint.
    Leg {
        /// Waypoint east, m.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        east_m: Option<f64>,
        /// Waypoint north, m.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        north_m: Option<f64>,
        /// Waypoint latitude, deg.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        latitude_deg: Option<f64>,
        /// Waypoint longitude, deg.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        longitude_deg: Option<f64>,
        /// Waypoint height, m (default: the present one).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        altitude_m: Option<f64>,
        /// Horizontal ground speed, m/s (default: the mission's `default_speed_mps`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ground_speed_mps: Option<f64>,
        /// Payload after the waypoint, kg (a pick-up or delivery).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        payload_after_kg: Option<f64>,
        /// Acceptance radius of the waypoint, m: how far from it a pass-through corner may start
        /// (default: the airframe's).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        acceptance_radius_m: Option<f64>,
        /// The operator's mission item number (from a planner file), named in the reports.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        item: Option<u32>,
    },
    /// Circles about a centre.
    Orbit {
        /// Centre east, m.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        centre_east_m: Option<f64>,
        /// Centre north, m.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        centre_north_m: Option<f64>,
        /// Centre latitude, deg.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        centre_latitude_deg: Option<f64>,
        /// Centre longitude, deg.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        centre_longitude_deg: Option<f64>,
        /// Height, m (default: the present one).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        altitude_m: Option<f64>,
        /// Radius, m.
        radius_m: f64,
        /// Ground speed on the circle, m/s (default: the mission's `default_speed_mps`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ground_speed_mps: Option<f64>,
        /// Direction seen from above.
        direction: OrbitDirection,
        /// Number of laps (give this or `duration_s`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        laps: Option<f64>,
        /// Time on the circle, s.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        duration_s: Option<f64>,
        /// The operator's mission item number (from a planner file), named in the reports.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        item: Option<u32>,
    },
    /// Hover in place.
    Hover {
        /// Duration, s.
        duration_s: f64,
        /// Payload after the hover, kg (a winch delivery).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        payload_after_kg: Option<f64>,
        /// The operator's mission item number (from a planner file), named in the reports.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        item: Option<u32>,
    },
    /// Straight back over home at the present height (or at `altitude_m`, reached first), as an
    /// autopilot's return-to-launch; a landing follows.
    Return {
        /// Horizontal ground speed, m/s (default: the mission's `default_speed_mps`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ground_speed_mps: Option<f64>,
        /// Height to return at, m (default: the present height, or the mission's
        /// `rtl_altitude_m` when that is higher).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        altitude_m: Option<f64>,
        /// The operator's mission item number (from a planner file), named in the reports.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        item: Option<u32>,
    },
    /// Vertical descent to a lower height.
    Descent {
        /// Height to descend to, m.
        altitude_m: f64,
        /// Descent rate, m/s.
        rate_mps: f64,
        /// The operator's mission item number (from a planner file), named in the reports.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        item: Option<u32>,
    },
    /// Vertical descent to the ground.
    Landing {
        /// Descent rate, m/s.
        rate_mps: f64,
        /// Payload after landing, kg.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        payload_after_kg: Option<f64>,
        /// The operator's mission item number (from a planner file), named in the reports.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        item: Option<u32>,
        /// The ground's height where it lands, above home's ground, m (default 0: level with
        /// home; set from the terrain under a mission flown over it).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ground_m: Option<f64>,
    },
    /// Hover here until the pack must fly home with the reserve: an open-ended loiter (an
    /// autopilot's "loiter unlimited"), which ends the route. The report says how long the
    /// vehicle can stay.
    LoiterUntilReserve {
        /// The operator's mission item number (from a planner file), named in the reports.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        item: Option<u32>,
    },
}

impl SegmentSpec {
    /// The kind as written in the file.
    pub fn kind(&self) -> &'static str {
        match self {
            SegmentSpec::TakeOff { .. } => "take-off",
            SegmentSpec::Leg { .. } => "leg",
            SegmentSpec::Orbit { .. } => "orbit",
            SegmentSpec::Hover { .. } => "hover",
            SegmentSpec::Return { .. } => "return",
            SegmentSpec::Descent { .. } => "descent",
            SegmentSpec::Landing { .. } => "landing",
            SegmentSpec::LoiterUntilReserve { .. } => "loiter-until-reserve",
        }
    }

    /// The horizontal point the segment names, as written: `[east_m, north_m, latitude_deg,
    /// longitude_deg]` of a leg's waypoint or an orbit's centre (local, geographic or
    /// incomplete, as the file gives it); all `None` for the kinds that name none.
    pub fn point(&self) -> [Option<f64>; 4] {
        match *self {
            SegmentSpec::Leg {
                east_m,
                north_m,
                latitude_deg,
                longitude_deg,
                ..
            } => [east_m, north_m, latitude_deg, longitude_deg],
            SegmentSpec::Orbit {
                centre_east_m,
                centre_north_m,
                centre_latitude_deg,
                centre_longitude_deg,
                ..
            } => [
                centre_east_m,
                centre_north_m,
                centre_latitude_deg,
                centre_longitude_deg,
            ],
            _ => [None; 4],
        }
    }

    /// The operator's mission item number, when the segment came from a planner file.
    pub fn item(&self) -> Option<u32> {
        match *self {
            SegmentSpec::TakeOff { item, .. }
            | SegmentSpec::Leg { item, .. }
            | SegmentSpec::Orbit { item, .. }
            | SegmentSpec::Hover { item, .. }
            | SegmentSpec::Return { item, .. }
            | SegmentSpec::Descent { item, .. }
            | SegmentSpec::Landing { item, .. }
            | SegmentSpec::LoiterUntilReserve { item } => item,
        }
    }
}

/// Wind profile names of a `[wind]` table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum WindProfileKind {
    /// The same speed at every height.
    #[default]
    Uniform,
    /// Power law `(z / z_ref)^exponent`.
    PowerLaw,
    /// Logarithmic `ln(z / z0) / ln(z_ref / z0)`.
    Log,
}

/// The optional `[wind]` table of a mission file (the command line overrides it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindSpec {
    /// Speed, m/s (at the reference height for a profile).
    pub speed_mps: f64,
    /// Direction the wind blows from, deg clockwise from north.
    pub from_deg: f64,
    /// Variation with height.
    #[serde(default)]
    pub profile: WindProfileKind,
    /// Reference height of a profile, m (default 10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_height_m: Option<f64>,
    /// Power-law exponent (default 1/7).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exponent: Option<f64>,
    /// Roughness length of the log profile, m (default 0.03, open grass).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughness_m: Option<f64>,
    /// Gust standard deviation per horizontal axis, m/s (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust_std_mps: Option<f64>,
    /// Gust seed (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust_seed: Option<u64>,
}

impl WindSpec {
    /// A steady wind of `speed_mps` from `from_deg` (clockwise from north), the same at every
    /// height, without gusts.
    pub fn uniform(speed_mps: f64, from_deg: f64) -> Self {
        Self {
            speed_mps,
            from_deg,
            profile: WindProfileKind::Uniform,
            reference_height_m: None,
            exponent: None,
            roughness_m: None,
            gust_std_mps: None,
            gust_seed: None,
        }
    }

    /// The wind this table describes.
    ///
    /// # Errors
    /// As [`Wind::profiled`] and [`Gusts::new`].
    pub fn to_wind(&self) -> Result<Wind, PlannerError> {
        let z_ref = self.reference_height_m.unwrap_or(10.0);
        let profile = match self.profile {
            WindProfileKind::Uniform => WindProfile::Uniform,
            WindProfileKind::PowerLaw => WindProfile::PowerLaw {
                reference_height_m: z_ref,
                exponent: self.exponent.unwrap_or(1.0 / 7.0),
            },
            WindProfileKind::Log => WindProfile::Log {
                reference_height_m: z_ref,
                roughness_m: self.roughness_m.unwrap_or(0.03),
            },
        };
        let w = Wind::profiled(self.speed_mps, self.from_deg, profile)?;
        Ok(match self.gust_std_mps {
            Some(s) => w.with_gusts(Gusts::new(s, self.gust_seed.unwrap_or(1))?),
            None => w,
        })
    }
}

/// A mission: what every mission source produces (see [Mission sources](super#mission-sources))
/// and [`MissionSpec::compile`] flies. Its serde form is the mission file; its [`Default`] is the
/// empty file (every optional key at its default, no segments).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissionSpec {
    /// Short name.
    #[serde(default)]
    pub name: String,
    /// One line about the mission.
    #[serde(default)]
    pub description: String,
    /// Payload at take-off, kg.
    #[serde(default)]
    pub payload_kg: f64,
    /// Reserve of the usable capacity required at landing, percent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reserve_percent: Option<f64>,
    /// Sampling step, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_step_s: Option<f64>,
    /// Home point.
    #[serde(default)]
    pub home: HomeSpec,
    /// Wind (optional; the command line overrides it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<WindSpec>,
    /// Ground speed of the legs, orbits and returns that give none, m/s (a planner file's
    /// planning speed; the command line or the vehicle may set it instead).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default_speed_mps: Option<f64>,
    /// Fly a speed beyond the vehicle's maximum at the maximum, with a warning, instead of
    /// refusing the mission (planner files, written for another vehicle; default false).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub clamp_speeds: bool,
    /// How the vehicle flies through a waypoint without a hold: `pass` (the default: through a
    /// corner at a speed its turn allows, as autopilots do) or `stop` (stop, turn, go on).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corners: Option<CornerMode>,
    /// Lowest height of a return to home, m: a `return` below it climbs to it first (an
    /// autopilot's RTL altitude; default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtl_altitude_m: Option<f64>,
    /// Accept a mission that ends in the air (a planner file without a landing or a return): its
    /// reserve is judged where it ends (default false: a mission lands).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub allow_end_in_air: bool,
    /// The heights are judged against the ground under the route (a mission flown over terrain:
    /// the engine checks each segment's clearance), so a leg, orbit or return at or below home's
    /// height (over a valley) is flown instead of refused. Not a key of the file.
    #[serde(skip)]
    pub over_terrain: bool,
    /// Segments, in order.
    #[serde(default, rename = "segment")]
    pub segments: Vec<SegmentSpec>,
    /// Where the flight starts when it starts in the air, at rest: east, north, up from home, m
    /// (the rest of a flight in progress, as `aloft live` plans it; not a key of the file).
    /// `None`, the default: on the ground at home, so the first segment is a take-off.
    #[serde(skip)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_in_air_m: Option<[f64; 3]>,
}

/// How the vehicle flies through a waypoint that has no hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CornerMode {
    /// Through a corner at the speed the turn allows: the turn angle, the lateral acceleration
    /// limit and the acceptance radius (as PX4's multicopter trajectory and ArduPilot's S-curve
    /// navigation fly waypoints).
    #[default]
    Pass,
    /// Stop at the waypoint, yaw to the next leg, go on (the planner's mode before corners).
    Stop,
}

impl MissionSpec {
    /// Parse a mission from TOML text (the caller reads the file).
    ///
    /// # Errors
    /// [`PlannerError::MissionFormat`] when the text is not a valid mission file; the message
    /// names the line and the key.
    pub fn from_toml_str(text: &str) -> Result<Self, PlannerError> {
        toml::from_str(text).map_err(|e| PlannerError::MissionFormat {
            message: aloft_core::file_message(&e.to_string()),
        })
    }
}
