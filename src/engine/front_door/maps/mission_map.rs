//! A planned mission as a map and a chart draw it (the page of `aloft serve`): the route over the
//! ground, segment by segment, in east-north-up metres from home and, for a mission with a
//! geographic home (every planner file), in latitude and longitude; the point of no return; the
//! state of charge over time; with scenarios its 5-95 % band; and with terrain the route's profile
//! over the ground ([`route_profile`](crate::engine::front_door::maps::profile::route_profile), set by
//! `answers::mission_map_answer_with`).
//!
//! The route is the compiled mission's pieces (the path the planner flies, corners and the way
//! home it adds included): a line by its ends, an arc by 36 points, a hold by its
//! point. Latitude and longitude come from the local tangent plane at home
//! ([`LocalFrame::to_lat_lon_deg`], the inverse of the frame the planner files were read in).

use serde::Serialize;

use aloft_planner::geodesy::LocalFrame;

use crate::engine::front_door::maps::profile::TerrainProfile;
use crate::engine::missions::ground::GroundAt;
use crate::engine::missions::mission::Plan;
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_outputs::segment_paths;
use crate::engine::uncertainty::scenario_stats::SocFan;

/// Most points of the state-of-charge line: a longer flight's chart samples are thinned evenly.
pub const MAP_CHART_POINTS: usize = 2_000;

/// The page's view of a planned mission (keys with their units, as every JSON answer of aloft).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MissionMap {
    /// Home, when the mission gives it as latitude and longitude.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub home: Option<GroundAt>,
    /// The route, one path per segment flown, in order.
    pub segments: Vec<SegmentPath>,
    /// The point of no return, when part of the mission lies past it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub point_of_no_return: Option<MapPoint>,
    /// State of charge over time (the plan's chart samples).
    pub battery: SocLine,
    /// Its 5th, 50th and 95th percentiles over time, with scenarios (`samples`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub band: Option<SocFan>,
    /// The route's altitude and the ground under it along the path, with terrain (`--terrain`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub profile: Option<TerrainProfile>,
}

/// The path of one segment.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SegmentPath {
    /// Segment number, from 1 (the `index` of the mission answer's segments).
    pub index: usize,
    /// Segment kind (`take-off`, `leg`, `orbit`, ...).
    pub kind: String,
    /// The operator's mission item, when the mission came from a planner file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub item: Option<u32>,
    /// The path, east, north and up of home, m.
    pub points_m: Vec<[f64; 3]>,
    /// The path, latitude and longitude, deg (with a geographic home).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub points_deg: Vec<[f64; 2]>,
}

/// A marked point of the route.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MapPoint {
    /// Mission time, s.
    pub time_s: f64,
    /// Segment it lies in, from 1.
    pub segment: usize,
    /// East, north and up of home, m.
    pub position_m: [f64; 3],
    /// Latitude and longitude, deg (with a geographic home).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position_deg: Option<[f64; 2]>,
}

/// State of charge over time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SocLine {
    /// Mission time, s.
    pub time_s: Vec<f64>,
    /// State of charge, fraction of capacity.
    pub soc: Vec<f64>,
}

/// The map of `plan` (planned with the chart samples kept) of `mission`, with the band of `fan`.
pub fn mission_map(plan: &Plan, mission: &Mission, fan: Option<SocFan>) -> MissionMap {
    let home = &mission.spec().home;
    let geo = match (home.latitude_deg, home.longitude_deg) {
        (Some(la), Some(lo)) if la.is_finite() && lo.is_finite() && la.abs() < 90.0 => Some((
            GroundAt {
                latitude_deg: la,
                longitude_deg: lo,
            },
            LocalFrame::new(la, lo),
        )),
        _ => None,
    };
    let origin = plan.home_m();
    let to_deg = |p: [f64; 3]| {
        geo.map(|(_, frame)| frame.to_lat_lon_deg(p[0] - origin[0], p[1] - origin[1]))
    };
    let compiled = plan.compiled();
    let kinds = compiled.segment_kinds();
    let items = compiled.segment_items();
    let segments = segment_paths(compiled)
        .into_iter()
        .map(|(k, points_m)| SegmentPath {
            index: k + 1,
            kind: kinds.get(k).copied().unwrap_or("segment").to_string(),
            item: items.get(k).copied().flatten(),
            points_deg: points_m.iter().filter_map(|p| to_deg(*p)).collect(),
            points_m,
        })
        .collect();
    let point_of_no_return = plan.report().point_of_no_return.map(|p| MapPoint {
        time_s: p.time_s,
        segment: p.segment,
        position_m: p.position_m,
        position_deg: to_deg(p.position_m),
    });
    MissionMap {
        home: geo.map(|(g, _)| g),
        segments,
        point_of_no_return,
        battery: soc_line(plan),
        band: fan,
        profile: None,
    }
}

/// The plan's chart samples as a state-of-charge line from take-off (the start's state of
/// charge at 0 s) of at most [`MAP_CHART_POINTS`] + 1 points (evenly thinned; the last sample
/// always kept).
fn soc_line(plan: &Plan) -> SocLine {
    let samples = plan.plot_samples();
    let stride = samples.len().div_ceil(MAP_CHART_POINTS).max(1);
    let mut line = SocLine {
        time_s: vec![0.0],
        soc: vec![plan.report().start_soc],
    };
    let last = samples.len().saturating_sub(1);
    for (k, s) in samples.iter().enumerate() {
        if k % stride == 0 || k == last {
            line.time_s.push(s.time_s);
            line.soc.push(s.soc);
        }
    }
    line
}
