//! The mission answer's JSON contract: [`MissionSummary`] serialises to exactly what
//! `aloft mission --format json` prints (the C ABI and the Python package return the same).

use serde::{Deserialize, Serialize};

use aloft_missions::RouteFigures;
use aloft_planner::wind::speed_and_from_deg;
use aloft_planner::{Limit, MissionReport, SegmentReport, Shortfall};

use crate::engine::conditions::air::Air;
use crate::engine::missions::flown::PlanningSpeed;
pub use crate::engine::missions::ground::GroundAt;
use crate::engine::missions::loiter::LoiterSummary;
use crate::engine::missions::sorties::SortieSummary;
use crate::error::Error;

/// One segment of a [`MissionSummary`] (keys as `aloft mission --format json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentSummary {
    /// Segment number, from 1.
    pub index: usize,
    /// Segment kind (`take-off`, `leg`, `orbit`, ...).
    pub kind: String,
    /// The operator's mission item number, when the mission came from a planner file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub item: Option<u32>,
    /// Duration, s.
    pub duration_s: f64,
    /// Distance flown, m.
    pub distance_m: f64,
    /// Electrical energy drawn from the pack, Wh.
    pub energy_wh: f64,
    /// Mean electrical power, W.
    pub mean_power_w: f64,
    /// Peak electrical power, W.
    pub peak_power_w: f64,
    /// State of charge at the end of the segment, fraction.
    pub end_soc: f64,
    /// Time flown beyond the plan because the vehicle flew at the edge of its envelope, s
    /// (absent when the segment was flown as planned).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_lost_s: Option<f64>,
    /// The lowest speed along the path at cruise where the envelope slowed the vehicle, m/s
    /// (over the ground; vertical for a climb or descent). Absent when the segment was flown as
    /// planned, or only its speed changes at the ends were slowed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_ground_speed_mps: Option<f64>,
    /// The limit the vehicle flew at where it was slowest: `tilt`, `thrust`, `airspeed`,
    /// `climb` or `descent` (absent when flown as planned).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limit: Option<Limit>,
    /// The least height above the ground along the segment's whole path, m (with terrain only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_clearance_m: Option<f64>,
    /// Where it occurs (with terrain only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_clearance_at: Option<GroundAt>,
}

/// Where the point of no return lies (flattened into the [`MissionSummary`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointOfNoReturnSummary {
    /// East of home, m.
    pub point_of_no_return_east_m: f64,
    /// North of home, m.
    pub point_of_no_return_north_m: f64,
    /// Above home, m.
    pub point_of_no_return_up_m: f64,
    /// Segment it lies in, from 1.
    pub point_of_no_return_segment: usize,
    /// The operator's mission item of that segment, when the mission came from a planner file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point_of_no_return_item: Option<u32>,
}

/// When an autopilot's voltage failsafe would trigger: the first time the predicted terminal
/// voltage under load falls below its threshold.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailsafeTime {
    /// `low` (ArduPilot `BATT_LOW_VOLT`) or `critical` (`BATT_CRT_VOLT`).
    pub kind: String,
    /// The threshold, pack volts.
    pub voltage_v: f64,
    /// Time from take-off when the voltage first falls below it, s (absent: never).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
    /// The segment it falls in, from 1 (absent: never).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segment: Option<usize>,
    /// The operator's mission item of that segment, when the mission came from a planner file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub item: Option<u32>,
}

/// The summary of a planned mission: its JSON is exactly that of `aloft mission --format json`
/// (same keys in the same order, same values; absent values omitted). The keys are documented in
/// `aloft mission`'s JSON keys in docs/guide.md.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MissionSummary {
    /// Mission name (the file's `name`, else its origin).
    pub mission: String,
    /// Vehicle name.
    pub vehicle: String,
    /// Battery pack name.
    pub battery: String,
    /// True when the mission can be flown and lands with the reserve.
    pub feasible: bool,
    /// Why not, when not feasible.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Take-off mass, kg.
    pub takeoff_mass_kg: f64,
    /// Payload at take-off, kg.
    pub payload_kg: f64,
    /// The air flown in: `air_density_kg_m3`, `density_source`, `elevation_m`,
    /// `temperature_c`, ... (see [`Air`]).
    #[serde(flatten)]
    pub air: Air,
    /// Flight time, s.
    pub duration_s: f64,
    /// Time flown beyond the plan because the vehicle flew at the edge of its envelope (slower
    /// than planned into a wind, a climb at the rate limit), s; absent when none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_lost_s: Option<f64>,
    /// Distance flown, m.
    pub distance_m: f64,
    /// Electrical energy drawn from the pack, Wh.
    pub energy_wh: f64,
    /// Heat in the pack's internal resistance, Wh.
    pub pack_heat_wh: f64,
    /// State of charge at take-off.
    pub start_soc: f64,
    /// State of charge at the end.
    pub end_soc: f64,
    /// Lowest pack voltage, V.
    pub min_voltage_v: f64,
    /// Peak electrical power, W.
    pub peak_power_w: f64,
    /// Peak pack current, A.
    pub peak_current_a: f64,
    /// Mean electrical power, W.
    pub mean_power_w: f64,
    /// Usable fraction left at landing.
    pub reserve_soc: f64,
    /// Usable fraction required at landing.
    pub required_reserve_soc: f64,
    /// Time of the point of no return, s (absent when there is none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point_of_no_return_s: Option<f64>,
    /// Where it lies (absent when there is none).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub point_of_no_return: Option<PointOfNoReturnSummary>,
    /// The planning speed (the ground speed of legs that give none) and where it came from;
    /// absent when the mission gives a speed on every leg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planning_speed: Option<PlanningSpeed>,
    /// The loiter of a route that ends in a loiter until the reserve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loiter: Option<LoiterSummary>,
    /// Packs the route takes (1 when one suffices); absent when it cannot be told (a mission
    /// that ends in the air and falls short, a route that cannot be split: see `warnings`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub batteries_required: Option<u32>,
    /// The sorties, when the route takes more than one pack.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sorties: Vec<SortieSummary>,
    /// The voltage failsafes watched (`--low-voltage-v`, `--critical-voltage-v`, a pack file's
    /// `[failsafe]`) and when each would trigger.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failsafes: Vec<FailsafeTime>,
    /// The least height above the ground of the segments in the air, take-off and landing
    /// excepted, m (with terrain only; each segment's in `segments`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_clearance_m: Option<f64>,
    /// What the reader should know: speeds clamped to the vehicle's, why a route was not split.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// The planned route as the file describes it (format, horizontal path, climb, descent,
    /// holds, the items of a planner file and what its reader noticed).
    pub route: RouteFigures,
    /// Per segment.
    pub segments: Vec<SegmentSummary>,
}

impl MissionSummary {
    /// Pretty JSON, as the CLI prints it (without the CLI's trailing newline).
    ///
    /// # Errors
    /// [`Error::OptionsFormat`] if serialisation fails (it does not for finite numbers).
    pub fn to_json(&self) -> Result<String, Error> {
        pretty_json(self, "mission summary")
    }
}

/// Pretty JSON of an answer (`what` names it in the error), as the CLI prints it (without the
/// CLI's trailing newline).
pub(in crate::engine) fn pretty_json(
    answer: &impl Serialize,
    what: &'static str,
) -> Result<String, Error> {
    serde_json::to_string_pretty(answer).map_err(|e| Error::OptionsFormat {
        what,
        message: e.to_string(),
    })
}

/// The summary of `report`, as `aloft mission --format json` prints it: `mission_name` is the
/// mission file's name (else its origin), `payload_kg` the take-off payload of the compiled
/// mission (`mission.payloads_kg()[0]`).
pub fn mission_summary(
    report: &MissionReport,
    mission_name: &str,
    vehicle_name: &str,
    battery_name: &str,
    payload_kg: f64,
) -> MissionSummary {
    let pnr = report.point_of_no_return;
    MissionSummary {
        mission: mission_name.to_string(),
        vehicle: vehicle_name.to_string(),
        battery: battery_name.to_string(),
        feasible: report.feasible,
        reason: report
            .shortfall
            .as_ref()
            .map(|s| reason(s, &report.segments, vehicle_name)),
        takeoff_mass_kg: report.takeoff_mass_kg,
        payload_kg,
        air: Air::sea_level(),
        duration_s: report.duration_s,
        time_lost_s: Some(report.segments.iter().map(|s| s.time_lost_s).sum::<f64>())
            .filter(|&t| t > 0.0),
        distance_m: report.distance_m,
        energy_wh: report.energy_wh,
        pack_heat_wh: report.pack_heat_wh,
        start_soc: report.start_soc,
        end_soc: report.end_soc,
        min_voltage_v: report.min_voltage_v,
        peak_power_w: report.peak_power_w,
        peak_current_a: report.peak_current_a,
        mean_power_w: if report.duration_s > 0.0 {
            report.energy_wh * 3600.0 / report.duration_s
        } else {
            0.0
        },
        reserve_soc: report.reserve_soc,
        required_reserve_soc: report.required_reserve_soc,
        point_of_no_return_s: pnr.map(|p| p.time_s),
        point_of_no_return: pnr.map(|p| PointOfNoReturnSummary {
            point_of_no_return_east_m: p.position_m[0],
            point_of_no_return_north_m: p.position_m[1],
            point_of_no_return_up_m: p.position_m[2],
            point_of_no_return_segment: p.segment,
            point_of_no_return_item: p
                .segment
                .checked_sub(1)
                .and_then(|i| report.segments.get(i))
                .and_then(|s| s.item),
        }),
        planning_speed: None,
        loiter: None,
        batteries_required: report.feasible.then_some(1),
        sorties: Vec::new(),
        failsafes: Vec::new(),
        min_clearance_m: None,
        warnings: Vec::new(),
        route: RouteFigures::default(),
        segments: report
            .segments
            .iter()
            .map(|s| SegmentSummary {
                index: s.index,
                kind: s.kind.to_string(),
                item: s.item,
                duration_s: s.duration_s,
                distance_m: s.distance_m,
                energy_wh: s.energy_wh,
                mean_power_w: s.mean_power_w,
                peak_power_w: s.peak_power_w,
                end_soc: s.end_soc,
                time_lost_s: s.edge.map(|_| s.time_lost_s),
                min_ground_speed_mps: s.edge.and_then(|e| e.slowest_mps),
                limit: s.edge.map(|e| e.limit),
                min_clearance_m: None,
                min_clearance_at: None,
            })
            .collect(),
    }
}

/// The segment `segment` (from 1) in words: `item 7 (leg)` for a segment from a planner file,
/// else `segment 3 (leg)`.
fn segment_name(segments: &[SegmentReport], segment: usize, kind: &str) -> String {
    match segments
        .iter()
        .find(|s| s.index == segment)
        .and_then(|s| s.item)
    {
        Some(i) => format!("item {i} ({kind})"),
        None => format!("segment {segment} ({kind})"),
    }
}

/// Why a mission falls short, in words: the planner's, with the operator's item and the
/// vehicle's name where the vehicle cannot make progress.
pub(in crate::engine) fn reason(
    shortfall: &Shortfall,
    segments: &[SegmentReport],
    vehicle: &str,
) -> String {
    let Shortfall::NoProgress(stuck) = shortfall else {
        return shortfall.to_string();
    };
    let p = stuck.position_m;
    format!(
        "at {}, t = {}, {:.0} m up ({:.0} m east, {:.0} m north of home): {}, so it cannot {}",
        segment_name(segments, stuck.segment, stuck.kind),
        clock(stuck.time_s),
        p[2],
        p[0],
        p[1],
        stuck.why(vehicle),
        if stuck.moving {
            "make headway along the track"
        } else {
            "hold its position"
        }
    )
}

/// A time as `m:ss.s`.
fn clock(t: f64) -> String {
    let t = t.max(0.0);
    format!("{}:{:04.1}", (t / 60.0).floor(), t % 60.0)
}

/// Time lost at the edge below which a segment gets no warning, s: it rounds to 0.0 s in the
/// message (its keys in the answer still say it).
const WARN_FROM_S: f64 = 0.05;

/// The warnings of the segments flown at the edge of the envelope that lost 0.1 s or more:
/// where, how slow, at which limit, in what wind, and the time lost.
pub(in crate::engine) fn edge_warnings(report: &MissionReport, vehicle: &str) -> Vec<String> {
    report
        .segments
        .iter()
        .filter(|s| s.time_lost_s >= WARN_FROM_S)
        .filter_map(|s| {
            let e = s.edge?;
            let (wind, from_deg) = speed_and_from_deg(e.wind_mps);
            let name = segment_name(&report.segments, s.index, s.kind);
            let held = match e.slowest_mps {
                Some(v) => format!(
                    "holds {v:.1} m/s along its path (planned {:.1} m/s)",
                    e.planned_mps
                ),
                None => "changes speed more slowly than planned".to_string(),
            };
            Some(format!(
                "{name}: in a {wind:.1} m/s wind from {from_deg:.0} deg at {:.0} m the {vehicle} {held} at its {} limit, {:.1} s longer than planned",
                e.up_m,
                e.limit.name(),
                s.time_lost_s
            ))
        })
        .collect()
}
