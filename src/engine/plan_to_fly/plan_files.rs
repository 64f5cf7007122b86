//! A sortie of a planner file (`.plan`, `.waypoints`) as the file to fly: the operator's own items
//! for the stretch of route it flies, with what it needs to fly them alone. The route is cut by
//! [`crate::engine::missions::sorties`]; each sortie's mission is the file written here and read back as
//! `aloft mission` reads it, so that the file flies to the answer `aloft plan` gives.
//!
//! A sortie's items, in order:
//!
//! | the first sortie | a later one |
//! |---|---|
//! | the file's own items up to where the route begins (its take-off and what comes before) | a take-off at home (NAV_TAKEOFF 22) to the height of where it resumes; the camera stopped (DO_SET_CAM_TRIGG_DIST 206 with 0); a waypoint where it resumes (the last one's turn, less the overlap), then the items in force there (below) |
//!
//! then the items of the route it flies (a leg it resumes inside of is flown to its waypoint from
//! where it resumes), and, where it turns home inside a leg, a waypoint there (NAV_WAYPOINT 16,
//! in the leg's frame: Positions below); the camera stopped when it was on (206 with 0; IMAGE_STOP_CAPTURE 2001 after a
//! timed capture: QGroundControl #5737, cameras that kept triggering through RTL); a return to
//! launch (NAV_RETURN_TO_LAUNCH 20). The last sortie flies the file's own way down (the camera
//! stopped and a return to launch written when the file ends in the air).
//!
//! A `.plan` flown whole on one pack with its own speeds keeps its survey complex items (turned
//! to the wind where the plan turned them), so that QGroundControl shows and edits them; a survey
//! cut between packs, or given speeds, is written as its items.
//!
//! **Items in force** where a sortie resumes (as QGroundControl's resume mission keeps them,
//! `MissionManager::generateResumeMission`): the last of each of DO_CHANGE_SPEED (178, per speed
//! type), DO_SET_CAM_TRIGG_DIST (206), the region of interest (DO_SET_ROI 201,
//! DO_SET_ROI_LOCATION 195, DO_SET_ROI_NONE 197), DO_MOUNT_CONFIGURE (204), DO_MOUNT_CONTROL
//! (205), DO_DIGICAM_CONFIGURE (202), DO_DIGICAM_CONTROL (203), the gimbal manager (1000, 1001),
//! SET_CAMERA_MODE (530), a timed image capture (IMAGE_START_CAPTURE 2000 with no count, or
//! IMAGE_STOP_CAPTURE 2001), video (2500, 2501), DO_FENCE_ENABLE (207). A counted capture (2000
//! with a count) is not repeated.
//!
//! **Speeds** the plan changed are written as DO_CHANGE_SPEED items (speed type 1, ground speed,
//! as QGroundControl writes them for multirotors) before the items whose speed differs from the
//! one in force, in place of the file's own; the planning speed is written as its value (an
//! autopilot may ignore "back to default").
//!
//! **DO_JUMP loops** are unrolled: the items follow the flying order the reader gives (its loops
//! repeated, at most as many items as it flies), without the DO_JUMP items.
//!
//! **Positions**: a point inside a leg is placed as the planner places the leg, in the tangent
//! plane of the leg's start (the last position before it, home at first), so that the file read
//! back puts it where the plan cut the route. Its altitude (and a later sortie's take-off's) is
//! in the frame of the item whose leg it cuts: above home in the relative frame (3, 6), above
//! mean sea level in the AMSL frame (0, 5: the height above home plus the file's home altitude),
//! in the terrain frame (10, 11) the height the leg has there as the reader flies it (linear
//! between its items' terrain altitudes); above home (frame 3) for an AMSL leg in a file without
//! a home altitude.

use aloft_logs::telemetry::MissionItem;
use aloft_missions::{write_plan, write_waypoint_rows, Home, Imported, MissionEntry, SourceFormat};
use aloft_planner::geodesy::LocalFrame;
use aloft_planner::{MissionSpec, SegmentSpec};

use crate::engine::missions::flight::Flight;
use crate::engine::missions::mission::flown_mission;
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_options::MissionOptions;
use crate::engine::missions::sorties::{Cut, FlyOutSpeed, Route, SortieMaker};
use crate::engine::vehicles::vehicle::Vehicle;

/// MAV_CMD numbers of the items written or read here.
mod cmd {
    pub const NAV_WAYPOINT: u32 = 16;
    pub const NAV_RETURN_TO_LAUNCH: u32 = 20;
    pub const NAV_TAKEOFF: u32 = 22;
    pub const DO_JUMP: u32 = 177;
    pub const DO_CHANGE_SPEED: u32 = 178;
    pub const DO_SET_CAM_TRIGG_DIST: u32 = 206;
    pub const IMAGE_START_CAPTURE: u32 = 2000;
    pub const IMAGE_STOP_CAPTURE: u32 = 2001;
}

/// MAV_FRAME_MISSION (2): the frame of items without a position.
const FRAME_MISSION: u32 = 2;
/// MAV_FRAME_GLOBAL_RELATIVE_ALT (3): heights above home.
const FRAME_RELATIVE: u32 = 3;

/// The sorties of a planner file, each the file of its items read back.
pub(in crate::engine) struct PlannerSorties<'a> {
    /// The route cut.
    pub(in crate::engine) route: &'a Route<'a>,
    /// What the file keeps to be written again.
    pub(in crate::engine) kept: &'a Imported,
    /// The mission flown (the candidate's: its legs' speeds).
    pub(in crate::engine) spec: &'a MissionSpec,
    /// Whether the plan changed speeds (then every speed is written from `spec`).
    pub(in crate::engine) speeds_changed: bool,
    /// The vehicle and the request's options, to read a file back as `aloft mission` does.
    pub(in crate::engine) vehicle: &'a Vehicle,
    /// The request's options.
    pub(in crate::engine) options: &'a MissionOptions,
    /// The request's flight, to fly a file as `aloft mission` does.
    pub(in crate::engine) flight: &'a Flight<'a>,
    /// How a file is read back (as the mission was read: an unlimited loiter's time).
    pub(in crate::engine) read: aloft_missions::ReadOptions,
    /// The speed of a resumed sortie's fly-out, when aloft chooses it.
    pub(in crate::engine) fly_out: Option<&'a dyn FlyOutSpeed>,
    /// The request's terrain tiles, open (none: a flat Earth).
    pub(in crate::engine) terrain: Option<&'a aloft_terrain::Terrain>,
}

impl SortieMaker for PlannerSorties<'_> {
    fn sortie(&self, start: Option<Cut>, end: Option<Cut>) -> Result<MissionSpec, String> {
        let text = self.text(start, end)?;
        let mission = Mission::from_text_with(&text, "the sortie's file", self.read)
            .map_err(|e| e.to_string())?;
        // Over terrain, the file is flown over the ground as `aloft mission` flies it.
        let mission = match self.terrain {
            Some(t) => {
                crate::engine::missions::mission::over_these_tiles(&mission, self.options, t)
                    .map_err(|e| e.to_string())?
            }
            None => mission,
        };
        let payload_kg = self.route.payload_at_kg(start);
        let flown = flown_mission(
            self.flight,
            &mission,
            self.vehicle,
            (self.options, Some(payload_kg)),
        )
        .map_err(|e| e.to_string())?;
        let mut spec = flown.spec;
        spec.payload_kg = payload_kg;
        Ok(spec)
    }
}

impl PlannerSorties<'_> {
    /// The file of the sortie from `start` to `end`, in the input's format.
    ///
    /// # Errors
    /// A file without a home, and the writers' refusals.
    pub(in crate::engine) fn text(
        &self,
        start: Option<Cut>,
        end: Option<Cut>,
    ) -> Result<String, String> {
        let home = self.home()?;
        let entries = match self.whole_with_surveys(start, end) {
            Some(entries) => entries,
            None => self
                .items(&home, start, end)
                .into_iter()
                .map(MissionEntry::Item)
                .collect(),
        };
        let written = match (self.kept.format, &self.kept.plan) {
            (SourceFormat::QgcPlan, Some(plan)) => {
                write_plan(&plan.header, &home, &entries, &plan.airspace)
            }
            // A file without a home row is written without one, as it was read: its first
            // position (the take-off) is home.
            _ => write_waypoint_rows(self.kept.home.as_ref(), &entries),
        };
        written.map_err(|e| e.to_string())
    }

    /// The entries of a `.plan` flown whole on one pack with its own speeds, when it has a
    /// survey: the file's own, each survey as its complex item (turned, where the plan turned
    /// it), so that QGroundControl shows and edits the survey; a return to launch after them
    /// when the file ends in the air. `None` otherwise (the items are then written one by one).
    fn whole_with_surveys(
        &self,
        start: Option<Cut>,
        end: Option<Cut>,
    ) -> Option<Vec<MissionEntry>> {
        let whole = start.is_none() && end.is_none() && !self.speeds_changed;
        if !whole || self.kept.surveys.is_empty() {
            return None;
        }
        let mut entries = aloft_missions::plan_entries(self.kept, &[]).ok()?;
        let flown = self.flown_items(0..self.kept.flown.len());
        let last = flown
            .iter()
            .rev()
            .find(|i| has_position(i.command) || ends(i.command));
        if !last.is_some_and(|i| ends(i.command)) {
            let mut home_items = flown;
            let n = home_items.len();
            self.home_items(&mut home_items);
            entries.extend(home_items.drain(n..).map(MissionEntry::Item));
        }
        Some(entries)
    }

    /// The file's home, or where a file without a home row launches (its first position, the
    /// home `aloft mission` flies from; its altitude unknown).
    fn home(&self) -> Result<Home, String> {
        if let Some(home) = self.kept.home {
            return Ok(home);
        }
        match (self.spec.home.latitude_deg, self.spec.home.longitude_deg) {
            (Some(latitude_deg), Some(longitude_deg)) => Ok(Home {
                latitude_deg,
                longitude_deg,
                altitude_amsl_m: None,
            }),
            _ => Err("a planner file without a home position cannot be cut into sorties".into()),
        }
    }

    /// The sortie's items (see the module's table), numbered in order from 1.
    fn items(&self, home: &Home, start: Option<Cut>, end: Option<Cut>) -> Vec<MissionItem> {
        let flown = &self.kept.flown;
        let first = self.flown_at(self.route.resumes_at(start));
        let mut out = match start {
            None => self.flown_items(0..first),
            Some(c) => self.resume_items(home, c, first),
        };
        match end {
            None => {
                out.extend(self.flown_items(first..flown.len()));
                // A file that ends in the air gets its way home written (every file lands).
                let last = out
                    .iter()
                    .rev()
                    .find(|i| has_position(i.command) || ends(i.command));
                if !last.is_some_and(|i| ends(i.command)) {
                    self.home_items(&mut out);
                }
            }
            Some(e) if e.fraction >= 1.0 => {
                out.extend(self.flown_items(first..self.flown_at(e.segment) + 1));
                self.home_items(&mut out);
            }
            Some(e) => {
                let at = self.flown_at(e.segment);
                out.extend(self.flown_items(first..at));
                // The leg's own number: the point is on its leg, flown at its speed.
                let mut turn = waypoint(self.point_deg(home, e), self.altitude(home, e));
                turn.seq = self.kept.items[flown[at].item].seq;
                out.push(turn);
                self.home_items(&mut out);
            }
        }
        let mut out = match self.speeds_changed {
            true => self.with_speeds(out, start.and_then(|c| self.fly_out_mps(c))),
            false => out,
        };
        for (k, item) in out.iter_mut().enumerate() {
            item.seq = u32::try_from(k + 1).unwrap_or(u32::MAX);
        }
        out
    }

    /// The index in the flying order of the item that made segment `segment` (the last item for
    /// a segment past the route, a way home the engine added).
    fn flown_at(&self, segment: usize) -> usize {
        let flown = &self.kept.flown;
        flown
            .iter()
            .position(|f| f.segments.contains(&segment))
            .unwrap_or(flown.len())
    }

    /// The items of the flying order `range`. The flying order has its DO_JUMP loops unrolled
    /// (as the reader flies them, bounded): the DO_JUMP items themselves are left out, as their
    /// targets' numbers are not the written file's.
    fn flown_items(&self, range: std::ops::Range<usize>) -> Vec<MissionItem> {
        self.kept.flown[range]
            .iter()
            .map(|f| self.kept.items[f.item])
            .filter(|it| it.command != cmd::DO_JUMP)
            .collect()
    }

    /// The take-off, the stopped camera, the waypoint where the sortie resumes and the items in
    /// force there (the flying order before `first`).
    fn resume_items(&self, home: &Home, cut: Cut, first: usize) -> Vec<MissionItem> {
        let altitude = self.altitude(home, cut);
        let restored = in_force(&self.flown_items(0..first));
        // The fly-out at its own speed, and the route's restored after it (the speed in force
        // there, else the planning speed); with the speeds written from the plan's spec, those
        // are written there.
        let planning = self.spec.default_speed_mps;
        let fly_out = self
            .fly_out_mps(cut)
            .filter(|v| !self.speeds_changed && planning.is_none_or(|p| (v - p).abs() >= 0.05));
        let speed = |v: f64| {
            item(
                cmd::DO_CHANGE_SPEED,
                FRAME_MISSION,
                [1.0, v, -1.0, 0.0, 0.0, 0.0, 0.0],
            )
        };
        let has_speed = restored
            .iter()
            .any(|i| i.command == cmd::DO_CHANGE_SPEED && i.params[0] <= 1.0);
        let mut out = vec![
            item(
                cmd::NAV_TAKEOFF,
                altitude.frame,
                [
                    0.0,
                    0.0,
                    0.0,
                    f64::NAN,
                    home.latitude_deg,
                    home.longitude_deg,
                    altitude.value_m,
                ],
            ),
            camera_trigger(0.0),
        ];
        out.extend(fly_out.map(speed));
        out.push(waypoint(self.point_deg(home, cut), altitude));
        if fly_out.is_some() && !has_speed {
            out.extend(planning.map(speed));
        }
        out.extend(restored);
        out
    }

    /// The ground speed of the fly-out to `cut`, when aloft chooses it.
    fn fly_out_mps(&self, cut: Cut) -> Option<f64> {
        self.fly_out?.speed_mps(self.route.point_m(cut))
    }

    /// The camera stopped when it is on, and a return to launch.
    fn home_items(&self, out: &mut Vec<MissionItem>) {
        let trigger = out
            .iter()
            .rev()
            .find(|i| i.command == cmd::DO_SET_CAM_TRIGG_DIST)
            .is_some_and(|i| i.params[0] > 0.0);
        if trigger {
            out.push(camera_trigger(0.0));
        }
        let timed = out
            .iter()
            .rev()
            .find(|i| {
                matches!(
                    i.command,
                    cmd::IMAGE_START_CAPTURE | cmd::IMAGE_STOP_CAPTURE
                )
            })
            .is_some_and(|i| i.command == cmd::IMAGE_START_CAPTURE);
        if timed {
            out.push(item(
                cmd::IMAGE_STOP_CAPTURE,
                FRAME_MISSION,
                [0.0, f64::NAN, f64::NAN, f64::NAN, 0.0, 0.0, 0.0],
            ));
        }
        out.push(item(cmd::NAV_RETURN_TO_LAUNCH, FRAME_MISSION, [0.0; 7]));
    }

    /// Latitude and longitude of the route at `cut` (module docs, Positions).
    fn point_deg(&self, home: &Home, cut: Cut) -> [f64; 2] {
        let at = self.flown_at(cut.segment);
        let start = self.position_before(home, at);
        let end = self.item_position(at).unwrap_or(start);
        let frame = LocalFrame::new(start[0], start[1]);
        let d = frame.to_local_m(end[0], end[1]);
        let f = cut.fraction.clamp(0.0, 1.0);
        frame.to_lat_lon_deg(f * d[0], f * d[1])
    }

    /// The altitude of the route at `cut` in the frame of the item whose leg it cuts (module
    /// docs, Positions): the height above home in the relative and terrain frames (the reader
    /// flies a terrain frame as relative), that plus the file's home altitude in the AMSL
    /// frames; relative to home for any other frame, or an AMSL one without a home altitude.
    fn altitude(&self, home: &Home, cut: Cut) -> Altitude {
        let height_m = self.route.point_m(cut)[2] - self.route.home_up_m();
        let frame = self
            .kept
            .flown
            .get(self.flown_at(cut.segment))
            .map(|f| &self.kept.items[f.item])
            .filter(|i| has_position(i.command))
            .map_or(FRAME_RELATIVE, |i| i.frame);
        match (frame, home.altitude_amsl_m) {
            (3 | 6 | 10 | 11, _) => Altitude {
                frame,
                value_m: height_m,
            },
            (0 | 5, Some(home_m)) => Altitude {
                frame,
                value_m: height_m + home_m,
            },
            _ => Altitude {
                frame: FRAME_RELATIVE,
                value_m: height_m,
            },
        }
    }

    /// The latitude and longitude of the item at `at` in the flying order, when it has a
    /// position ("here", 0 and 0, is none).
    fn item_position(&self, at: usize) -> Option<[f64; 2]> {
        let f = self.kept.flown.get(at)?;
        let p = self.kept.items[f.item].params;
        let positioned = has_position(self.kept.items[f.item].command);
        (positioned && (p[4] != 0.0 || p[5] != 0.0) && p[4].is_finite() && p[5].is_finite())
            .then_some([p[4], p[5]])
    }

    /// The last position before the item at `at` in the flying order (home at first).
    fn position_before(&self, home: &Home, at: usize) -> [f64; 2] {
        (0..at)
            .rev()
            .find_map(|k| self.item_position(k))
            .unwrap_or([home.latitude_deg, home.longitude_deg])
    }

    /// `items` with every speed written from the plan's spec (module docs, Speeds).
    /// A resumed sortie's first move (its fly-out) at `fly_out_mps` when given.
    fn with_speeds(&self, items: Vec<MissionItem>, fly_out_mps: Option<f64>) -> Vec<MissionItem> {
        let mut out = Vec::with_capacity(items.len() + 8);
        let mut in_force: Option<f64> = None;
        let mut fly_out = fly_out_mps;
        let planning = self.spec.default_speed_mps;
        for it in items {
            let horizontal = it.command == cmd::DO_CHANGE_SPEED && it.params[0] <= 1.0;
            if horizontal {
                continue;
            }
            let want = match moves(&it) {
                true => fly_out.take().or(self.speed_of(&it)).or(planning),
                false => None,
            };
            if let Some(want) = want {
                if in_force.is_none_or(|v| (v - want).abs() > 1e-9) {
                    out.push(item(
                        cmd::DO_CHANGE_SPEED,
                        FRAME_MISSION,
                        [1.0, want, -1.0, 0.0, 0.0, 0.0, 0.0],
                    ));
                    in_force = Some(want);
                }
            }
            out.push(it);
        }
        out
    }

    /// The ground speed the plan gives the leg an item flies to (its number names it).
    fn speed_of(&self, it: &MissionItem) -> Option<f64> {
        self.spec.segments.iter().find_map(|s| match s {
            SegmentSpec::Leg {
                ground_speed_mps,
                item: Some(n),
                ..
            } if *n == it.seq => *ground_speed_mps,
            _ => None,
        })
    }
}

/// Whether an item flies to a position (its leg has a speed).
fn moves(it: &MissionItem) -> bool {
    has_position(it.command) && it.command != cmd::NAV_TAKEOFF
}

/// Whether a command ends the flight (a return to launch, a landing).
fn ends(command: u32) -> bool {
    matches!(command, cmd::NAV_RETURN_TO_LAUNCH | 21)
}

/// Whether a command has a position.
fn has_position(command: u32) -> bool {
    matches!(command, 16..=19 | 21 | 22 | 31 | 82)
}

/// An item of `command` in `frame` with `params`.
fn item(command: u32, frame: u32, params: [f64; 7]) -> MissionItem {
    MissionItem {
        seq: 0,
        frame,
        command,
        params,
    }
}

/// A waypoint flown through at `[lat, lon]`, `height_m` above home.
fn waypoint(at: [f64; 2], altitude: Altitude) -> MissionItem {
    item(
        cmd::NAV_WAYPOINT,
        altitude.frame,
        [0.0, 0.0, 0.0, f64::NAN, at[0], at[1], altitude.value_m],
    )
}

/// An item's altitude: its MAV_FRAME and its value in it, m.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Altitude {
    frame: u32,
    value_m: f64,
}

/// DO_SET_CAM_TRIGG_DIST at `distance_m` (0: stop).
fn camera_trigger(distance_m: f64) -> MissionItem {
    item(
        cmd::DO_SET_CAM_TRIGG_DIST,
        FRAME_MISSION,
        [distance_m, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    )
}

/// The items of `before` still in force after it (module docs, Items in force), in order.
fn in_force(before: &[MissionItem]) -> Vec<MissionItem> {
    let mut kept: Vec<(u32, MissionItem)> = Vec::new();
    for it in before {
        let Some(key) = state_key(it) else {
            continue;
        };
        kept.retain(|(k, _)| *k != key);
        kept.push((key, *it));
    }
    kept.into_iter()
        .map(|(_, it)| it)
        .filter(|it| !(it.command == cmd::IMAGE_START_CAPTURE && it.params[2] != 0.0))
        .collect()
}

/// The state an item sets (items of one key replace each other), when it sets one.
fn state_key(it: &MissionItem) -> Option<u32> {
    Some(match it.command {
        // One per speed type.
        cmd::DO_CHANGE_SPEED => 178_000 + it.params[0].clamp(0.0, 9.0) as u32,
        // The region of interest, however it is set.
        195 | 197 | 201 => 201,
        2000 | 2001 => 2000,
        2500 | 2501 => 2500,
        c @ (202 | 203 | 204 | 205 | 206 | 207 | 530 | 1000 | 1001) => c,
        _ => return None,
    })
}
