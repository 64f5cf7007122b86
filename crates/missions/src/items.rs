//! MAVLink mission items to mission segments: the semantics both readers share.
//!
//! A reader turns its file into a list of [`RawItem`]s (command, frame, the seven parameters,
//! the operator's item number) and a [`Source`] (home, autopilot, how jumps are addressed, the
//! planning speed); [`translate`] flies them in order (DO_JUMPs unrolled, see `jumps.rs`) and
//! says what each costs, as segments of the mission spec that carry the item's number.
//!
//! | command (MAV_CMD id) | what aloft flies |
//! |---|---|
//! | NAV_WAYPOINT (16), SPLINE_WAYPOINT (82) | a leg to the point; p1 > 0: a hover of p1 s there; p2: acceptance radius. A spline is flown straight (noted) |
//! | NAV_TAKEOFF (22) | on the ground: a vertical climb to p7; PX4 then flies to the item's position when it has one (ArduPilot climbs where it is). In the air: a waypoint (noted) |
//! | NAV_LAND (21) | a leg to the point at the present height (lat/lon 0: here), a descent at the autopilot's rate to 10 m, the landing at its landing rate. A following position item takes off again from there |
//! | NAV_RETURN_TO_LAUNCH (20) | a return over home (at the RTL altitude of the vehicle or `--rtl-altitude-m`, else the present height) and a landing; the route ends there |
//! | NAV_LOITER_TIME (19) | a leg to the point and a hover of p1 s |
//! | NAV_LOITER_TURNS (18) | an orbit of p1 turns, radius abs(p3) about the point (p3 < 0: counter-clockwise), at ArduPilot's default circle rate of 20 deg/s (`CIRCLE_RATE`), at most the planning speed |
//! | NAV_LOITER_TO_ALT (31) | a leg to the point, then a vertical climb or descent to p7 |
//! | NAV_LOITER_UNLIM (17) | a leg to the point, then a loiter until the reserve: the route ends (the rest is unreachable, warned); with [`ReadOptions::loiter_unlimited_s`], a hover of that long and the route goes on (said) |
//! | NAV_DELAY (93), CONDITION_DELAY (112) | a hover of p1 s (in the air) |
//! | DO_CHANGE_SPEED (178) | p1 0 (air) or 1 (ground): the ground speed of the following legs is p2; -1 no change; -2 back to the planning speed. p1 2 or 3 (climb, descent): noted, not modelled |
//! | DO_JUMP (177) | unrolled (`jumps.rs`) |
//! | DO_GRIPPER (211) | p2 0 (release): the payload is 0 kg after the last segment flown; p2 1 (grab): noted (mass unknown) |
//! | camera, gimbal, ROI, mode, servo, relay, fence items | nothing: counted |
//! | NAV_VTOL_TAKEOFF (84), NAV_VTOL_LAND (85), DO_VTOL_TRANSITION (3000) | refused |
//! | anything else | nothing, with a warning naming the item and the command |
//!
//! Positions: latitude/longitude both 0 (or not set) mean "here". Heights from `frame` and p7:
//! 0 and 5 (GLOBAL, AMSL) minus the home's AMSL altitude (warned when below home); 3 and 6
//! (relative to home) as they are; 10 and 11 (terrain) as relative, warned (aloft has no
//! terrain model). p7 not set keeps the present height, and so does p7 = 0 for ArduPilot, whose
//! missions use 0 for "the present altitude". A height that is not above the ground (a PX4
//! waypoint at 0 m) is flown at [`MIN_HEIGHT_M`], warned. A position item on the ground without a
//! take-off before it gets a vertical take-off to its height first, warned.

use aloft_planner::{OrbitDirection, SegmentSpec};

use crate::commands::{self, role, CommandName, Role};
use crate::error::ImportError;
use crate::geo::{distance_m, LatLon};
use crate::jumps::{flying_order, JumpsBy};
use crate::kept::FlownItem;
use crate::notes::Notes;
use crate::raw_item::RawItem;
use crate::ItemCounts;

/// Lowest height a position item is flown at, m: a height at or below the ground (a waypoint at
/// 0 m above home) is raised to it, with a warning.
pub const MIN_HEIGHT_M: f64 = 1.0;

/// Below this height a landing slows to the autopilot's landing rate, m (ArduPilot's
/// `LAND_ALT_LOW` and PX4's `MPC_LAND_ALT1` default to 10 m).
const LAND_SLOW_HEIGHT_M: f64 = 10.0;

/// ArduPilot's default circle rate (`CIRCLE_RATE`), rad/s.
const CIRCLE_RATE_RADPS: f64 = 20.0 * std::f64::consts::PI / 180.0;

/// The autopilot a file was planned for, where their semantics differ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Autopilot {
    /// ArduPilot (a `.plan` with `firmwareType` 3, every `.waypoints` file).
    ArduPilot,
    /// PX4 and any other.
    Px4,
}

impl Autopilot {
    /// Take-off climb rate, m/s: ArduPilot `WPNAV_SPEED_UP` 2.5, PX4 `MPC_TKO_SPEED` 1.5.
    fn take_off_rate_mps(self) -> f64 {
        match self {
            Autopilot::ArduPilot => 2.5,
            Autopilot::Px4 => 1.5,
        }
    }

    /// Descent rate above [`LAND_SLOW_HEIGHT_M`], m/s: ArduPilot `WPNAV_SPEED_DN` 1.5, PX4
    /// `MPC_Z_V_AUTO_DN` 1.0.
    fn descent_rate_mps(self) -> f64 {
        match self {
            Autopilot::ArduPilot => 1.5,
            Autopilot::Px4 => 1.0,
        }
    }

    /// Landing rate below it, m/s: ArduPilot `LAND_SPEED` 0.5, PX4 `MPC_LAND_SPEED` 0.7.
    fn landing_rate_mps(self) -> f64 {
        match self {
            Autopilot::ArduPilot => 0.5,
            Autopilot::Px4 => 0.7,
        }
    }
}

/// How a reader flies what a file leaves to the operator.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReadOptions {
    /// An unlimited loiter (NAV_LOITER_UNLIM) flown as a hover of this long, s, after which the
    /// route goes on with the items after it (`aloft plan`: the operator continues the mission);
    /// `None`: a loiter until the reserve, where the route ends (`aloft mission`: how long it
    /// can loiter).
    pub loiter_unlimited_s: Option<f64>,
    /// Terrain-frame items (frame 10/11) are flown over the ground by the caller, which has the
    /// terrain: their heights are above the ground under the vehicle, said without the warning
    /// that they are flown as relative to home (default false: no terrain).
    pub terrain: bool,
}

/// Home and the file's conventions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Source {
    /// Home (launch point).
    pub(crate) home: LatLon,
    /// Home's altitude above mean sea level, m, when the file gives it.
    pub(crate) home_amsl_m: Option<f64>,
    /// Whose semantics.
    pub(crate) autopilot: Autopilot,
    /// How DO_JUMP names its target.
    pub(crate) jumps_by: JumpsBy,
    /// The file's planning speed, m/s (orbits are flown at most at it).
    pub(crate) default_speed_mps: f64,
    /// How what the file leaves to the operator is flown.
    pub(crate) options: ReadOptions,
}

/// What the items fly.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Translation {
    /// Segments, each with its item's number.
    pub(crate) segments: Vec<SegmentSpec>,
    /// The items by role.
    pub(crate) counts: ItemCounts,
    /// Warnings.
    pub(crate) notes: Vec<String>,
    /// The items flown, in order, with the segments each made.
    pub(crate) flown: Vec<FlownItem>,
}

/// Fly `items` from `source`'s home.
///
/// # Errors
/// A VTOL item, a position out of range or in an unsupported frame, a jump that cannot be
/// unrolled, too many items, nothing that flies.
pub(crate) fn translate(
    items: &[RawItem],
    source: &Source,
    notes: Notes,
) -> Result<Translation, ImportError> {
    check_items(items)?;
    let mut flight = Flight::new(source, notes, items.len());
    let order = flying_order(items, source.jumps_by, &mut flight.notes)?;
    let mut end = None;
    for &k in &order {
        flight.reached[k] = true;
        let first = flight.segments.len();
        let ends = flight.item(&items[k])?;
        flight.flown.push(FlownItem {
            item: k,
            segments: first..flight.segments.len(),
        });
        if let Some(why) = ends {
            end = Some((items[k].at, why));
            break;
        }
    }
    flight.finish(items, end)
}

/// Refuse what aloft cannot fly before anything is flown: VTOL items and values out of range.
fn check_items(items: &[RawItem]) -> Result<(), ImportError> {
    for item in items {
        if role(item.command) == Role::Vtol {
            return Err(ImportError::Refused {
                at: item.at,
                what: CommandName(item.command).to_string(),
                reason: "a VTOL take-off, landing or transition: aloft models multirotors",
            });
        }
        check_params(item)?;
    }
    Ok(())
}

/// Each parameter finite or not set; a position item's latitude within (-90, 90), longitude
/// within [-180, 180], altitude within 1e6 m.
pub(crate) fn check_params(item: &RawItem) -> Result<(), ImportError> {
    const KEYS: [&str; 7] = [
        "param1",
        "param2",
        "param3",
        "param4",
        "param5 (latitude)",
        "param6 (longitude)",
        "param7 (altitude)",
    ];
    let bad = |k: usize, expected| ImportError::BadValue {
        at: item.at,
        command: item.command,
        key: KEYS[k],
        value: item.params[k],
        expected,
    };
    for (k, v) in item.params.iter().enumerate() {
        if v.is_infinite() {
            return Err(bad(k, "a finite number, or null for not set"));
        }
    }
    if !has_position(item.command) {
        return Ok(());
    }
    let [.., lat, lon, alt] = item.params;
    if lat.abs() >= 90.0 {
        return Err(bad(4, "a latitude within (-90, 90) degrees"));
    }
    if lon.abs() > 180.0 {
        return Err(bad(5, "a longitude within [-180, 180] degrees"));
    }
    if alt.abs() > 1e6 {
        return Err(bad(6, "an altitude within 1e6 m"));
    }
    Ok(())
}

/// Commands whose p5-p7 are a position.
pub(crate) fn has_position(command: u32) -> bool {
    use commands::*;
    matches!(
        command,
        NAV_WAYPOINT
            | NAV_LOITER_UNLIM
            | NAV_LOITER_TURNS
            | NAV_LOITER_TIME
            | NAV_LAND
            | NAV_TAKEOFF
            | NAV_LOITER_TO_ALT
            | NAV_SPLINE_WAYPOINT
    )
}

/// A parameter that holds a code (an enum value written as a float): the whole number, else none.
fn code(x: f64) -> Option<i64> {
    (x.is_finite() && x.fract() == 0.0 && x.abs() < 1e15).then_some(x as i64)
}

/// Where an item sends the vehicle: a point (none: here) and a height above home (none: the
/// present height).
#[derive(Debug, Clone, Copy)]
struct Target {
    point: Option<LatLon>,
    height_m: Option<f64>,
}

/// The vehicle flying the items: where it is, whether it is in the air, the speed set by the
/// last DO_CHANGE_SPEED, and the segments so far.
struct Flight<'a> {
    source: &'a Source,
    segments: Vec<SegmentSpec>,
    notes: Notes,
    here: LatLon,
    height_m: f64,
    airborne: bool,
    speed_mps: Option<f64>,
    reached: Vec<bool>,
    flown: Vec<FlownItem>,
}

impl<'a> Flight<'a> {
    fn new(source: &'a Source, notes: Notes, items: usize) -> Self {
        Self {
            source,
            segments: Vec::new(),
            notes,
            here: source.home,
            height_m: 0.0,
            airborne: false,
            speed_mps: None,
            reached: vec![false; items],
            flown: Vec::new(),
        }
    }

    /// Fly one item; `Some(why)` when the route ends with it.
    fn item(&mut self, item: &RawItem) -> Result<Option<&'static str>, ImportError> {
        use commands::*;
        match item.command {
            NAV_WAYPOINT | NAV_SPLINE_WAYPOINT => self.waypoint(item)?,
            NAV_TAKEOFF => self.take_off(item)?,
            NAV_LAND => self.land(item)?,
            NAV_LOITER_TIME => self.loiter_time(item)?,
            NAV_LOITER_TURNS => self.loiter_turns(item)?,
            NAV_LOITER_TO_ALT => self.loiter_to_alt(item)?,
            NAV_DELAY | CONDITION_DELAY => self.delay(item)?,
            NAV_RETURN_TO_LAUNCH => return self.return_to_launch(item).map(Some),
            NAV_LOITER_UNLIM => match self.source.options.loiter_unlimited_s {
                Some(hold_s) => self.loiter_for(item, hold_s)?,
                None => return self.loiter_unlimited(item).map(Some),
            },
            DO_CHANGE_SPEED => self.change_speed(item),
            DO_GRIPPER => self.gripper(item)?,
            c if role(c) == Role::Unknown => self.notes.add(
                item.at,
                format!(
                    "unknown {}: not flown (aloft counts it as costing nothing)",
                    CommandName(c)
                ),
            ),
            // DO_JUMP (unrolled already) and the items that cost nothing.
            _ => {}
        }
        Ok(None)
    }

    // ---- One method per command ----

    /// NAV_WAYPOINT (16), SPLINE_WAYPOINT (82): a leg, then the hold of p1 s.
    fn waypoint(&mut self, item: &RawItem) -> Result<(), ImportError> {
        if item.command == commands::NAV_SPLINE_WAYPOINT {
            self.notes.add(
                item.at,
                "SPLINE_WAYPOINT flown as a straight waypoint (the spline is not modelled)",
            );
        }
        let target = self.target(item)?;
        self.climb_if_landed(item, target)?;
        let acceptance = item.params[1];
        // Always a leg, of no length for a repeated point: every waypoint has its line in the
        // answer.
        self.fly_to_always(item, target, (acceptance > 0.0).then_some(acceptance))?;
        self.hover(item, item.params[0])
    }

    /// NAV_TAKEOFF (22): on the ground, a vertical climb (then, for PX4, to its position); in the
    /// air, a waypoint.
    fn take_off(&mut self, item: &RawItem) -> Result<(), ImportError> {
        let target = self.target(item)?;
        if self.airborne {
            self.notes
                .add(item.at, "TAKEOFF in the air flown as a waypoint");
            return self.fly_to(item, target, None);
        }
        let height_m = self.ground_height(item, target.height_m);
        self.vertical_take_off(item, height_m)?;
        match (self.source.autopilot, target.point) {
            (Autopilot::Px4, Some(p)) if distance_m(self.here, p) > 0.1 => {
                let to = Target {
                    point: Some(p),
                    height_m: None,
                };
                self.fly_to(item, to, None)
            }
            _ => Ok(()),
        }
    }

    /// NAV_LAND (21): to the point at the present height, then down.
    fn land(&mut self, item: &RawItem) -> Result<(), ImportError> {
        if !self.airborne {
            self.notes.add(item.at, "LAND on the ground: nothing flown");
            return Ok(());
        }
        self.check_position_frame(item)?;
        let point = self.point(item);
        self.fly_to(
            item,
            Target {
                point,
                height_m: None,
            },
            None,
        )?;
        self.descend_and_land(item)
    }

    /// NAV_LOITER_TIME (19): to the point, then a hover of p1 s.
    fn loiter_time(&mut self, item: &RawItem) -> Result<(), ImportError> {
        let target = self.target(item)?;
        self.climb_if_landed(item, target)?;
        self.fly_to(item, target, None)?;
        self.hover(item, item.params[0])
    }

    /// NAV_LOITER_TURNS (18): p1 turns of radius abs(p3) about the point.
    fn loiter_turns(&mut self, item: &RawItem) -> Result<(), ImportError> {
        let target = self.target(item)?;
        self.climb_if_landed(item, target)?;
        let (turns, radius_m) = (item.params[0], item.params[2].abs());
        if !(turns > 0.0 && radius_m > 0.0) {
            self.notes.add(
                item.at,
                "LOITER_TURNS without turns (p1) or radius (p3): flown to its point, no circle",
            );
            return self.fly_to(item, target, None);
        }
        let speed_cap = self.speed_mps.unwrap_or(self.source.default_speed_mps);
        let centre = target.point.unwrap_or(self.here);
        self.push(
            item,
            SegmentSpec::Orbit {
                centre_east_m: None,
                centre_north_m: None,
                centre_latitude_deg: Some(centre.latitude_deg),
                centre_longitude_deg: Some(centre.longitude_deg),
                altitude_m: target.height_m,
                radius_m,
                ground_speed_mps: Some((radius_m * CIRCLE_RATE_RADPS).min(speed_cap)),
                direction: if item.params[2] < 0.0 {
                    OrbitDirection::CounterClockwise
                } else {
                    OrbitDirection::Clockwise
                },
                laps: Some(turns),
                duration_s: None,
                item: Some(item.number),
            },
        )?;
        self.here = centre;
        self.height_m = target.height_m.unwrap_or(self.height_m);
        Ok(())
    }

    /// NAV_LOITER_TO_ALT (31): to the point, then straight up or down to p7.
    fn loiter_to_alt(&mut self, item: &RawItem) -> Result<(), ImportError> {
        let target = self.target(item)?;
        self.climb_if_landed(item, target)?;
        let level = Target {
            point: target.point,
            height_m: None,
        };
        self.fly_to(item, level, None)?;
        let vertical = Target {
            point: None,
            height_m: target.height_m,
        };
        self.fly_to(item, vertical, None)
    }

    /// NAV_LOITER_UNLIM (17): to the point, then a loiter until the reserve; the route ends.
    fn loiter_unlimited(&mut self, item: &RawItem) -> Result<&'static str, ImportError> {
        let target = self.target(item)?;
        self.climb_if_landed(item, target)?;
        self.fly_to(item, target, None)?;
        self.push(
            item,
            SegmentSpec::LoiterUntilReserve {
                item: Some(item.number),
            },
        )?;
        self.notes.add(
            item.at,
            "LOITER_UNLIM: the route ends here with a loiter until the reserve",
        );
        Ok("the LOITER_UNLIM")
    }

    /// NAV_LOITER_UNLIM (17) flown for `hold_s` ([`ReadOptions::loiter_unlimited_s`]): to the
    /// point, a hover of `hold_s`, and on (said).
    fn loiter_for(&mut self, item: &RawItem, hold_s: f64) -> Result<(), ImportError> {
        let target = self.target(item)?;
        self.climb_if_landed(item, target)?;
        self.fly_to(item, target, None)?;
        self.hover(item, hold_s)?;
        self.notes.add(
            item.at,
            format!(
                "LOITER_UNLIM: flown as a loiter of {} s, then the items after it (the operator continues the mission)",
                aloft_core::Num(hold_s)
            ),
        );
        Ok(())
    }

    /// NAV_RETURN_TO_LAUNCH (20): back over home and land; the route ends.
    fn return_to_launch(&mut self, item: &RawItem) -> Result<&'static str, ImportError> {
        if !self.airborne {
            self.notes
                .add(item.at, "RETURN_TO_LAUNCH on the ground: nothing flown");
            return Ok("the RETURN_TO_LAUNCH");
        }
        self.push(
            item,
            SegmentSpec::Return {
                ground_speed_mps: None,
                altitude_m: None,
                item: Some(item.number),
            },
        )?;
        self.here = self.source.home;
        self.descend_and_land(item)?;
        Ok("the RETURN_TO_LAUNCH")
    }

    /// NAV_DELAY (93), CONDITION_DELAY (112): a hover of p1 s in the air.
    fn delay(&mut self, item: &RawItem) -> Result<(), ImportError> {
        let seconds = item.params[0];
        if seconds.is_nan() || seconds < 0.0 {
            self.notes.add(
                item.at,
                "delay without a duration (p1 < 0: until a time of day): not flown",
            );
            return Ok(());
        }
        if !self.airborne {
            self.notes.add(item.at, "delay on the ground: no energy");
            return Ok(());
        }
        self.hover(item, seconds)
    }

    /// DO_CHANGE_SPEED (178): the ground speed of the following legs.
    fn change_speed(&mut self, item: &RawItem) {
        let [kind, speed, ..] = item.params;
        // Not set: a ground speed.
        let kind = if kind.is_nan() { Some(1) } else { code(kind) };
        if matches!(kind, Some(2 | 3)) {
            self.notes.add(
                item.at,
                "DO_CHANGE_SPEED of the climb or descent speed (p1 2 or 3): not modelled",
            );
            return;
        }
        if kind == Some(0) {
            self.notes.add(
                item.at,
                "DO_CHANGE_SPEED of the airspeed (p1 0) flown as ground speed, as multirotor autopilots do",
            );
        }
        if speed > 0.0 {
            self.speed_mps = Some(speed);
            return;
        }
        match code(speed) {
            Some(-2) => self.speed_mps = None,
            Some(-1) => {}
            _ => self.notes.add(
                item.at,
                "DO_CHANGE_SPEED without a speed (p2 not positive, -1 or -2): no change",
            ),
        }
    }

    /// DO_GRIPPER (211): p2 0 releases the payload after the last segment flown.
    fn gripper(&mut self, item: &RawItem) -> Result<(), ImportError> {
        if code(item.params[1]) != Some(0) {
            self.notes.add(
                item.at,
                "DO_GRIPPER grab: the mass picked up is unknown, not added",
            );
            return Ok(());
        }
        let last = self.segments.last_mut();
        match last {
            Some(SegmentSpec::Leg {
                payload_after_kg, ..
            })
            | Some(SegmentSpec::Hover {
                payload_after_kg, ..
            })
            | Some(SegmentSpec::Landing {
                payload_after_kg, ..
            }) => {
                *payload_after_kg = Some(0.0);
                Ok(())
            }
            Some(_) if self.airborne => {
                // After a take-off, an orbit or a return: a leg to here carries the release.
                let here = Target {
                    point: None,
                    height_m: None,
                };
                self.fly_to_always(item, here, None)?;
                self.gripper(item)
            }
            _ => {
                self.notes.add(
                    item.at,
                    "DO_GRIPPER release before the flight: the payload given at take-off is flown",
                );
                Ok(())
            }
        }
    }
}

mod steps;

#[cfg(test)]
mod tests;
