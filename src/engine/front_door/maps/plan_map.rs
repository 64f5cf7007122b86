//! A plan to fly on the map (the page of `aloft serve`, its `Plan to fly`): each sortie's flown
//! path, from its own file.
//!
//! Each sortie's file ([`FlyPlan::texts`]) is read back as `aloft mission` reads it
//! ([`Mission::from_text_with`], an unlimited loiter as the plan flew it), planned in the plan's conditions ([`FlyPlanRequest::options`]) and
//! drawn by [`mission_map`]: so the path on the map is the one the file flies, corners and the
//! way home the planner adds included, in east-north-up metres from home and, for a planner file
//! (a geographic home), in latitude and longitude.
//!
//! The path is given in three parts, as the sorties are made ([`crate::engine::missions::sorties`]):
//!
//! | part | segments |
//! |---|---|
//! | `way_out` | the take-off; for a sortie after the first, also the transit to where it resumes the route |
//! | `route` | the route it flies, up to where it turns home |
//! | `way_home` | the trailing return, descents and landing |

use serde::Serialize;

use crate::engine::front_door::maps::mission_map::{mission_map, MapPoint, SegmentPath};
use crate::engine::missions::ground::GroundAt;
use crate::engine::missions::mission::plan_mission;
use crate::engine::missions::mission_file::Mission;
use crate::engine::plan_to_fly::fly_plan::{FlyPlan, FlyPlanRequest};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// The flown path of one sortie of a plan (in the order of [`FlyPlan::sorties`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SortieMap {
    /// Its file's name.
    pub file: String,
    /// Home, when the file gives it as latitude and longitude.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub home: Option<GroundAt>,
    /// Take-off and transit to the route, one path per segment (numbered as the file's).
    pub way_out: Vec<SegmentPath>,
    /// The route it flies, one path per segment.
    pub route: Vec<SegmentPath>,
    /// Return, descents and landing, one path per segment.
    pub way_home: Vec<SegmentPath>,
    /// Its point of no return, when part of the sortie lies past it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub point_of_no_return: Option<MapPoint>,
}

/// The map of each sortie of `plan` (made for `request` with `vehicle`): its file read back and
/// flown as `aloft mission` flies it (see the module docs).
///
/// # Errors
/// As [`Mission::from_text`] and [`plan_mission`] (a file the plan wrote always reads back).
pub fn fly_plan_map(
    vehicle: &Vehicle,
    plan: &FlyPlan,
    request: &FlyPlanRequest,
) -> Result<Vec<SortieMap>, Error> {
    plan.sorties
        .iter()
        .zip(&plan.texts)
        .enumerate()
        .map(|(k, (sortie, text))| {
            let read = aloft_missions::ReadOptions {
                loiter_unlimited_s: Some(request.loiter_unlimited_s),
                ..aloft_missions::ReadOptions::default()
            };
            let mission = Mission::from_text_with(text, &sortie.file, read)?;
            let flown = plan_mission(vehicle, &mission, &request.options)?;
            let map = mission_map(&flown, &mission, None);
            // Every sortie after the first resumes the route: a take-off and a transit.
            let out = if k == 0 { 1 } else { 2 };
            Ok(parts(
                &sortie.file,
                map.home,
                map.segments,
                out,
                map.point_of_no_return,
            ))
        })
        .collect()
}

/// The segments split into way out (the first `out`, at most), route and way home.
fn parts(
    file: &str,
    home: Option<GroundAt>,
    mut segments: Vec<SegmentPath>,
    out: usize,
    point_of_no_return: Option<MapPoint>,
) -> SortieMap {
    let down = |s: &SegmentPath| matches!(s.kind.as_str(), "return" | "descent" | "landing");
    let home_from = segments.iter().rposition(|s| !down(s)).map_or(0, |i| i + 1);
    let way_home = segments.split_off(home_from);
    let route = segments.split_off(out.min(segments.len()));
    SortieMap {
        file: file.to_string(),
        home,
        way_out: segments,
        route,
        way_home,
        point_of_no_return,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(index: usize, kind: &str) -> SegmentPath {
        SegmentPath {
            index,
            kind: kind.to_string(),
            item: None,
            points_m: vec![[index as f64, 0.0, 0.0]],
            points_deg: Vec::new(),
        }
    }

    fn indices(s: &[SegmentPath]) -> Vec<usize> {
        s.iter().map(|s| s.index).collect()
    }

    #[test]
    fn a_resumed_sortie_is_way_out_route_and_way_home() {
        let kinds = [
            "take-off", "leg", "leg", "orbit", "leg", "return", "descent", "landing",
        ];
        let segments: Vec<SegmentPath> = kinds
            .iter()
            .enumerate()
            .map(|(k, kind)| seg(k + 1, kind))
            .collect();
        let m = parts("a-2-of-3.plan", None, segments.clone(), 2, None);
        assert_eq!(indices(&m.way_out), [1, 2]);
        assert_eq!(indices(&m.route), [3, 4, 5]);
        assert_eq!(indices(&m.way_home), [6, 7, 8]);
        // The first sortie flies its own take-off only before the route.
        let m = parts("a-1-of-3.plan", None, segments, 1, None);
        assert_eq!(indices(&m.way_out), [1]);
        assert_eq!(indices(&m.route), [2, 3, 4, 5]);
    }

    #[test]
    fn a_landing_inside_the_route_is_route_and_a_short_sortie_is_all_way() {
        // A landing before a leg (a delivery) is route; only the trailing way down is way home.
        let kinds = ["take-off", "leg", "landing", "take-off", "leg", "landing"];
        let segments: Vec<SegmentPath> = kinds
            .iter()
            .enumerate()
            .map(|(k, kind)| seg(k + 1, kind))
            .collect();
        let m = parts("d.plan", None, segments, 1, None);
        assert_eq!(indices(&m.route), [2, 3, 4, 5]);
        assert_eq!(indices(&m.way_home), [6]);
        // Fewer segments than the way out would take: nothing is lost.
        let m = parts(
            "s.plan",
            None,
            vec![seg(1, "take-off"), seg(2, "landing")],
            2,
            None,
        );
        assert_eq!(indices(&m.way_out), [1]);
        assert!(m.route.is_empty());
        assert_eq!(indices(&m.way_home), [2]);
    }
}
