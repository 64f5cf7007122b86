//! Missions: the TOML description (serde, units in the keys, unknown keys rejected) and its
//! compilation into trajectory pieces for one airframe.
//!
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
//! Every segment is flown from rest to rest (see [`crate::trajectory`]); before a leg, a return
//! or an orbit the vehicle yaws to the new heading at the airframe's yaw rate, hovering. An orbit
//! starts with a straight transit from the present position to the nearest point of its circle.
//! Legs that change altitude keep the commanded ground speed; the vertical rate that implies must
//! be within the airframe's climb or descent limit.

use serde::{Deserialize, Serialize};

use crate::airframe::Airframe;
use crate::error::PlannerError;
use crate::geodesy::LocalFrame;
use crate::trajectory::{Piece, Profile, Shape};
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
        /// Horizontal ground speed, m/s.
        ground_speed_mps: f64,
        /// Payload after the waypoint, kg (a pick-up or delivery).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        payload_after_kg: Option<f64>,
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
        /// Ground speed on the circle, m/s.
        ground_speed_mps: f64,
        /// Direction seen from above.
        direction: OrbitDirection,
        /// Number of laps (give this or `duration_s`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        laps: Option<f64>,
        /// Time on the circle, s.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        duration_s: Option<f64>,
    },
    /// Hover in place.
    Hover {
        /// Duration, s.
        duration_s: f64,
        /// Payload after the hover, kg (a winch delivery).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        payload_after_kg: Option<f64>,
    },
    /// Straight back over home at the present height.
    Return {
        /// Horizontal ground speed, m/s.
        ground_speed_mps: f64,
    },
    /// Vertical descent to a lower height.
    Descent {
        /// Height to descend to, m.
        altitude_m: f64,
        /// Descent rate, m/s.
        rate_mps: f64,
    },
    /// Vertical descent to the ground.
    Landing {
        /// Descent rate, m/s.
        rate_mps: f64,
        /// Payload after landing, kg.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        payload_after_kg: Option<f64>,
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

/// A mission file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
    /// Segments, in order.
    #[serde(default, rename = "segment")]
    pub segments: Vec<SegmentSpec>,
}

/// A mission compiled for an airframe: trajectory pieces and the payload of each mass phase.
#[derive(Debug, Clone, PartialEq)]
pub struct Mission {
    name: String,
    home_m: [f64; 3],
    pieces: Vec<Piece>,
    kinds: Vec<&'static str>,
    payloads_kg: Vec<f64>,
}

fn bad_seg(
    index: usize,
    kind: &'static str,
    name: &'static str,
    value: f64,
    unit: &'static str,
    expected: &'static str,
) -> PlannerError {
    PlannerError::InvalidSegment {
        index: index + 1,
        kind,
        name,
        value,
        unit,
        expected,
    }
}

fn seg_positive(
    i: usize,
    kind: &'static str,
    name: &'static str,
    v: f64,
    unit: &'static str,
) -> Result<f64, PlannerError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else if name.contains("altitude") {
        Err(bad_seg(
            i,
            kind,
            name,
            v,
            unit,
            "the height above home must be above the ground (positive)",
        ))
    } else {
        Err(bad_seg(
            i,
            kind,
            name,
            v,
            unit,
            "must be positive and finite",
        ))
    }
}

fn seg_limit(
    i: usize,
    kind: &'static str,
    name: &'static str,
    v: f64,
    limit: f64,
    unit: &'static str,
) -> Result<(), PlannerError> {
    // 1e-9 relative: a value typed equal to the limit passes despite rounding.
    if v > limit * (1.0 + 1e-9) {
        Err(PlannerError::Unreachable {
            index: i + 1,
            kind,
            name,
            value: v,
            limit,
            unit,
        })
    } else {
        Ok(())
    }
}

fn seg_payload(i: usize, kind: &'static str, p: Option<f64>) -> Result<Option<f64>, PlannerError> {
    match p {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err(bad_seg(
            i,
            kind,
            "payload_after_kg",
            v,
            "kg",
            "must be finite and not negative",
        )),
        other => Ok(other),
    }
}

/// Resolves points given in either local metres or latitude/longitude.
struct Points {
    frame: Option<LocalFrame>,
}

impl Points {
    #[allow(clippy::too_many_arguments)]
    fn resolve(
        &self,
        i: usize,
        kind: &'static str,
        east: Option<f64>,
        north: Option<f64>,
        lat: Option<f64>,
        lon: Option<f64>,
        names: [&'static str; 4],
    ) -> Result<[f64; 2], PlannerError> {
        match (east, north, lat, lon) {
            (Some(e), Some(n), None, None) => {
                for (v, name) in [(e, names[0]), (n, names[1])] {
                    if !v.is_finite() {
                        return Err(bad_seg(i, kind, name, v, "m", "must be finite"));
                    }
                }
                Ok([e, n])
            }
            (None, None, Some(la), Some(lo)) => {
                let frame = self.frame.ok_or(PlannerError::SegmentOrder {
                    index: i + 1,
                    kind,
                    reason: "a point in latitude/longitude needs the home point in latitude/longitude",
                })?;
                if !(la.is_finite() && la.abs() < 90.0) {
                    return Err(bad_seg(i, kind, names[2], la, "deg", "must be within (-90, 90)"));
                }
                if !lo.is_finite() {
                    return Err(bad_seg(i, kind, names[3], lo, "deg", "must be finite"));
                }
                Ok(frame.to_local_m(la, lo))
            }
            _ => Err(PlannerError::SegmentOrder {
                index: i + 1,
                kind,
                reason: "give the point as east_m and north_m, or as latitude_deg and longitude_deg (exactly one pair)",
            }),
        }
    }
}

/// Heading change (absolute, rad) from `from` to `to` (unit east-north vectors).
fn turn_rad(from: [f64; 2], to: [f64; 2]) -> f64 {
    let cross = from[0] * to[1] - from[1] * to[0];
    let dot = from[0] * to[0] + from[1] * to[1];
    cross.atan2(dot).abs()
}

impl MissionSpec {
    /// Parse a mission from TOML text (the caller reads the file).
    ///
    /// # Errors
    /// [`PlannerError::MissionFormat`] when the text is not a valid mission file; the message
    /// names the line and the key.
    pub fn from_toml_str(text: &str) -> Result<Self, PlannerError> {
        toml::from_str(text).map_err(|e| PlannerError::MissionFormat {
            message: e.to_string().trim_end().to_string(),
        })
    }

    /// Validate and compile for `airframe`. `payload_kg` overrides the file's take-off payload.
    ///
    /// # Errors
    /// No segments; a segment with a negative, zero or non-finite value where a positive one is
    /// needed; an altitude below the ground; a speed, rate or turn load beyond the airframe's
    /// limits; segments in an order that cannot be flown (a leg before take-off, ending in the air);
    /// a take-off mass above the airframe's limit.
    pub fn compile(
        &self,
        airframe: &Airframe,
        battery_mass_kg: f64,
        payload_kg: Option<f64>,
    ) -> Result<Mission, PlannerError> {
        if self.segments.is_empty() {
            return Err(PlannerError::EmptyMission);
        }
        let frame =
            match (
                self.home.east_m,
                self.home.north_m,
                self.home.latitude_deg,
                self.home.longitude_deg,
            ) {
                (None, None, Some(la), Some(lo)) => {
                    if !(la.is_finite() && la.abs() < 90.0 && lo.is_finite()) {
                        return Err(PlannerError::InvalidParameter {
                            name: "home latitude_deg",
                            value: la,
                            unit: "deg",
                            expected: "a latitude within (-90, 90) and a finite longitude",
                        });
                    }
                    Some(LocalFrame::new(la, lo))
                }
                (_, _, None, None) => None,
                _ => return Err(PlannerError::InvalidParameter {
                    name: "home latitude_deg",
                    value: self.home.latitude_deg.unwrap_or(f64::NAN),
                    unit: "deg",
                    expected:
                        "home as east_m/north_m or as latitude_deg/longitude_deg, not both or half",
                }),
            };
        let home = [
            self.home.east_m.unwrap_or(0.0),
            self.home.north_m.unwrap_or(0.0),
            0.0,
        ];
        for (v, name) in [(home[0], "home east_m"), (home[1], "home north_m")] {
            if !v.is_finite() {
                return Err(PlannerError::InvalidParameter {
                    name,
                    value: v,
                    unit: "m",
                    expected: "a finite coordinate",
                });
            }
        }
        let points = Points { frame };
        let start_payload = payload_kg.unwrap_or(self.payload_kg);
        crate::error::non_negative("payload_kg", start_payload, "kg")?;
        let mut payloads = vec![start_payload];
        let check_mass = |payload: f64| -> Result<(), PlannerError> {
            let m = airframe.mass_kg() + battery_mass_kg + payload;
            if m > airframe.max_takeoff_mass_kg() * (1.0 + 1e-9) {
                return Err(PlannerError::Unreachable {
                    index: 0,
                    kind: "mission",
                    name: "take-off mass (airframe + battery + payload)",
                    value: m,
                    limit: airframe.max_takeoff_mass_kg(),
                    unit: "kg",
                });
            }
            Ok(())
        };
        check_mass(start_payload)?;

        let mut pieces = Vec::new();
        let mut kinds = Vec::new();
        let mut pos = home;
        let mut airborne = false;
        let mut heading = [0.0, 1.0];
        let a_h = airframe.acceleration_mps2();
        let a_v = airframe.vertical_acceleration_mps2();
        let g = 9.80665;
        let max_centripetal = g * airframe.max_tilt_rad().tan();

        for (i, seg) in self.segments.iter().enumerate() {
            let kind = seg.kind();
            kinds.push(kind);
            let phase = payloads.len() - 1;
            let push = |pieces: &mut Vec<Piece>, shape, profile: Profile, fwd| {
                if profile.duration_s > 0.0 {
                    pieces.push(Piece {
                        shape,
                        profile,
                        segment: i,
                        mass_phase: phase,
                        forward: fwd,
                    });
                }
            };
            let need_air = |airborne: bool| {
                if airborne {
                    Ok(())
                } else {
                    Err(PlannerError::SegmentOrder {
                        index: i + 1,
                        kind,
                        reason: "the vehicle is on the ground: take off first",
                    })
                }
            };
            // A straight path from `pos` to `to` with a horizontal ground speed; yaws first.
            let straight = |pieces: &mut Vec<Piece>,
                            pos: &mut [f64; 3],
                            heading: &mut [f64; 2],
                            to: [f64; 3],
                            speed: f64|
             -> Result<(), PlannerError> {
                let d = [to[0] - pos[0], to[1] - pos[1], to[2] - pos[2]];
                let h = d[0].hypot(d[1]);
                let len = (h * h + d[2] * d[2]).sqrt();
                if len < 1e-9 {
                    return Ok(());
                }
                let (path_speed, path_acc) = if h > 1e-9 {
                    let fwd = [d[0] / h, d[1] / h];
                    let turn = turn_rad(*heading, fwd);
                    if turn > 1e-6 {
                        push(
                            pieces,
                            Shape::Hold { pos_m: *pos },
                            Profile::hold(turn / airframe.yaw_rate_radps()),
                            *heading,
                        );
                    }
                    *heading = fwd;
                    let vz = speed * d[2].abs() / h;
                    let (vlim, name) = if d[2] >= 0.0 {
                        (airframe.max_climb_rate_mps(), "climb rate of the leg")
                    } else {
                        (airframe.max_descent_rate_mps(), "descent rate of the leg")
                    };
                    seg_limit(i, kind, name, vz, vlim, "m/s")?;
                    let acc = if d[2].abs() > 1e-9 {
                        (a_h * len / h).min(a_v * len / d[2].abs())
                    } else {
                        a_h
                    };
                    (speed * len / h, acc)
                } else {
                    // Vertical leg: the ground speed does not apply; use the rate limit.
                    let v = if d[2] > 0.0 {
                        airframe.max_climb_rate_mps()
                    } else {
                        airframe.max_descent_rate_mps()
                    };
                    (v, a_v)
                };
                push(
                    pieces,
                    Shape::Line {
                        start_m: *pos,
                        dir: [d[0] / len, d[1] / len, d[2] / len],
                    },
                    Profile::rest_to_rest(len, path_speed, path_acc),
                    *heading,
                );
                *pos = to;
                Ok(())
            };
            let vertical = |pieces: &mut Vec<Piece>,
                            pos: &mut [f64; 3],
                            heading: [f64; 2],
                            to_z: f64,
                            rate: f64| {
                let len = (to_z - pos[2]).abs();
                if len > 0.0 {
                    push(
                        pieces,
                        Shape::Line {
                            start_m: *pos,
                            dir: [0.0, 0.0, (to_z - pos[2]).signum()],
                        },
                        Profile::rest_to_rest(len, rate, a_v),
                        heading,
                    );
                }
                pos[2] = to_z;
            };
            let mut payload_after = None;
            match *seg {
                SegmentSpec::TakeOff {
                    altitude_m,
                    climb_rate_mps,
                } => {
                    if airborne {
                        return Err(PlannerError::SegmentOrder {
                            index: i + 1,
                            kind,
                            reason: "the vehicle is already in the air",
                        });
                    }
                    seg_positive(i, kind, "altitude_m", altitude_m, "m")?;
                    seg_positive(i, kind, "climb_rate_mps", climb_rate_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "climb_rate_mps",
                        climb_rate_mps,
                        airframe.max_climb_rate_mps(),
                        "m/s",
                    )?;
                    vertical(&mut pieces, &mut pos, heading, altitude_m, climb_rate_mps);
                    airborne = true;
                }
                SegmentSpec::Leg {
                    east_m,
                    north_m,
                    latitude_deg,
                    longitude_deg,
                    altitude_m,
                    ground_speed_mps,
                    payload_after_kg,
                } => {
                    need_air(airborne)?;
                    let [e, n] = points.resolve(
                        i,
                        kind,
                        east_m,
                        north_m,
                        latitude_deg,
                        longitude_deg,
                        ["east_m", "north_m", "latitude_deg", "longitude_deg"],
                    )?;
                    let z = altitude_m.unwrap_or(pos[2]);
                    seg_positive(i, kind, "altitude_m", z, "m")?;
                    seg_positive(i, kind, "ground_speed_mps", ground_speed_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "ground_speed_mps",
                        ground_speed_mps,
                        airframe.max_speed_mps(),
                        "m/s",
                    )?;
                    straight(
                        &mut pieces,
                        &mut pos,
                        &mut heading,
                        [e, n, z],
                        ground_speed_mps,
                    )?;
                    payload_after = seg_payload(i, kind, payload_after_kg)?;
                }
                SegmentSpec::Return { ground_speed_mps } => {
                    need_air(airborne)?;
                    seg_positive(i, kind, "ground_speed_mps", ground_speed_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "ground_speed_mps",
                        ground_speed_mps,
                        airframe.max_speed_mps(),
                        "m/s",
                    )?;
                    let to = [home[0], home[1], pos[2]];
                    straight(&mut pieces, &mut pos, &mut heading, to, ground_speed_mps)?;
                }
                SegmentSpec::Orbit {
                    centre_east_m,
                    centre_north_m,
                    centre_latitude_deg,
                    centre_longitude_deg,
                    altitude_m,
                    radius_m,
                    ground_speed_mps,
                    direction,
                    laps,
                    duration_s,
                } => {
                    need_air(airborne)?;
                    let c = points.resolve(
                        i,
                        kind,
                        centre_east_m,
                        centre_north_m,
                        centre_latitude_deg,
                        centre_longitude_deg,
                        [
                            "centre_east_m",
                            "centre_north_m",
                            "centre_latitude_deg",
                            "centre_longitude_deg",
                        ],
                    )?;
                    seg_positive(i, kind, "radius_m", radius_m, "m")?;
                    seg_positive(i, kind, "ground_speed_mps", ground_speed_mps, "m/s")?;
                    let z = altitude_m.unwrap_or(pos[2]);
                    seg_positive(i, kind, "altitude_m", z, "m")?;
                    seg_limit(
                        i,
                        kind,
                        "ground_speed_mps",
                        ground_speed_mps,
                        airframe.max_speed_mps(),
                        "m/s",
                    )?;
                    // Centripetal load in still air: v^2 / r <= g tan(tilt_max).
                    seg_limit(
                        i,
                        kind,
                        "centripetal acceleration v^2/r",
                        ground_speed_mps * ground_speed_mps / radius_m,
                        max_centripetal,
                        "m/s^2",
                    )?;
                    let length = match (laps, duration_s) {
                        (Some(l), None) => {
                            seg_positive(i, kind, "laps", l, "")? * std::f64::consts::TAU * radius_m
                        }
                        (None, Some(d)) => {
                            let d = seg_positive(i, kind, "duration_s", d, "s")?;
                            // Trapezoid time L / v + v / a = d.
                            let l = ground_speed_mps * (d - ground_speed_mps / a_h);
                            if l <= 0.0 {
                                return Err(bad_seg(
                                    i,
                                    kind,
                                    "duration_s",
                                    d,
                                    "s",
                                    "too short to reach the orbit speed and stop again",
                                ));
                            }
                            l
                        }
                        _ => {
                            return Err(PlannerError::SegmentOrder {
                                index: i + 1,
                                kind,
                                reason: "give exactly one of laps and duration_s",
                            })
                        }
                    };
                    // Transit to the nearest point of the circle.
                    let rel = [pos[0] - c[0], pos[1] - c[1]];
                    let dist = rel[0].hypot(rel[1]);
                    let phi0 = if dist > 1e-9 {
                        rel[1].atan2(rel[0])
                    } else {
                        0.0
                    };
                    let entry = [
                        c[0] + radius_m * phi0.cos(),
                        c[1] + radius_m * phi0.sin(),
                        z,
                    ];
                    straight(&mut pieces, &mut pos, &mut heading, entry, ground_speed_mps)?;
                    let sign = match direction {
                        OrbitDirection::CounterClockwise => 1.0,
                        OrbitDirection::Clockwise => -1.0,
                    };
                    let tangent = [-sign * phi0.sin(), sign * phi0.cos()];
                    let turn = turn_rad(heading, tangent);
                    if turn > 1e-6 {
                        push(
                            &mut pieces,
                            Shape::Hold { pos_m: pos },
                            Profile::hold(turn / airframe.yaw_rate_radps()),
                            heading,
                        );
                    }
                    let arc = Piece {
                        shape: Shape::Arc {
                            centre_m: c,
                            radius_m,
                            up_m: z,
                            phi0_rad: phi0,
                            sign,
                        },
                        profile: Profile::rest_to_rest(length, ground_speed_mps, a_h),
                        segment: i,
                        mass_phase: phase,
                        forward: tangent,
                    };
                    pos = arc.end_m();
                    let end = arc.at(arc.duration_s());
                    // Heading at the end: the tangent there.
                    heading = end.forward;
                    pieces.push(arc);
                }
                SegmentSpec::Hover {
                    duration_s,
                    payload_after_kg,
                } => {
                    need_air(airborne)?;
                    seg_positive(i, kind, "duration_s", duration_s, "s")?;
                    push(
                        &mut pieces,
                        Shape::Hold { pos_m: pos },
                        Profile::hold(duration_s),
                        heading,
                    );
                    payload_after = seg_payload(i, kind, payload_after_kg)?;
                }
                SegmentSpec::Descent {
                    altitude_m,
                    rate_mps,
                } => {
                    need_air(airborne)?;
                    seg_positive(i, kind, "altitude_m", altitude_m, "m")?;
                    seg_positive(i, kind, "rate_mps", rate_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "rate_mps",
                        rate_mps,
                        airframe.max_descent_rate_mps(),
                        "m/s",
                    )?;
                    if altitude_m >= pos[2] {
                        return Err(bad_seg(
                            i,
                            kind,
                            "altitude_m",
                            altitude_m,
                            "m",
                            "a descent must end below the present height",
                        ));
                    }
                    vertical(&mut pieces, &mut pos, heading, altitude_m, rate_mps);
                }
                SegmentSpec::Landing {
                    rate_mps,
                    payload_after_kg,
                } => {
                    need_air(airborne)?;
                    seg_positive(i, kind, "rate_mps", rate_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "rate_mps",
                        rate_mps,
                        airframe.max_descent_rate_mps(),
                        "m/s",
                    )?;
                    vertical(&mut pieces, &mut pos, heading, 0.0, rate_mps);
                    airborne = false;
                    payload_after = seg_payload(i, kind, payload_after_kg)?;
                }
            }
            if let Some(p) = payload_after {
                check_mass(p)?;
                payloads.push(p);
            }
        }
        if airborne {
            return Err(PlannerError::SegmentOrder {
                index: self.segments.len(),
                kind: self.segments[self.segments.len() - 1].kind(),
                reason: "the mission ends in the air: add a landing",
            });
        }
        Ok(Mission {
            name: self.name.clone(),
            home_m: home,
            pieces,
            kinds,
            payloads_kg: payloads,
        })
    }
}

impl Mission {
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
