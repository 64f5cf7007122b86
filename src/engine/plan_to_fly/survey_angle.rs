//! The survey turned to the wind (`aloft plan`): the grid angle of each QGroundControl survey
//! complex item of a `.plan` chosen for the day's wind.
//!
//! For each survey the file describes well enough to be drawn again
//! ([`aloft_missions::survey::Survey`]), the transects are regenerated from its polygon, line
//! spacing, turnaround distance and entry corner at candidate angles, as QGroundControl draws
//! them ([`aloft_missions::plan_entries`]): the operator's angle, every
//! [`ANGLE_STEP_DEG`] degrees of a half turn, and along and across the wind at the survey's
//! centre. The spacing and the trigger distance are the survey's own, so the polygon is covered
//! as before. Each angle's mission is the file written and read back, flown whole with the legs'
//! speeds for the wind ([`crate::engine::plan_to_fly::fly_plan`] step 2); the angle of least energy is kept when it
//! saves energy over the operator's and covers as many points of the polygon within
//! half a line spacing of a camera-on line as the operator's angle does (a 3 m grid) (surveys one after the other, each with the angles already
//! chosen for those before it). [`crate::engine::plan_to_fly::fly_plan`] then plans the turned mission beside the
//! mission as given and keeps the one with fewer batteries, then less energy.

use serde::{Deserialize, Serialize};

use aloft_missions::{plan_entries, write_plan, Imported};
use aloft_planner::geodesy::LocalFrame;
use aloft_planner::Wind;

use crate::engine::missions::mission_file::Mission;
use crate::engine::step_meter::WorkBounds;
use crate::error::Error;

/// The step of the candidate angles, deg.
pub const ANGLE_STEP_DEG: f64 = 15.0;

/// A survey given another grid angle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleChange {
    /// The survey's first item in the input.
    pub item: u32,
    /// Its grid angle as given, deg (the transects' azimuth, clockwise from north).
    pub from_deg: f64,
    /// Its grid angle in the plan, deg.
    pub to_deg: f64,
}

/// The mission with its surveys turned to the wind, and the turns; `None` when no survey can
/// be turned or no turn saves energy.
///
/// # Errors
/// [`Error::Cancelled`] once `bounds` say the caller gave up. `energy_wh` flies a mission whole
/// as the plan would (`None`: it cannot be flown).
pub(in crate::engine) fn turned_to_wind(
    mission: &Mission,
    wind: &Wind,
    energy_wh: &dyn Fn(&Mission) -> Option<f64>,
    bounds: &WorkBounds,
) -> Result<Option<(Mission, Vec<AngleChange>)>, Error> {
    let Some(imported) = mission.kept().filter(|k| k.plan.is_some()) else {
        return Ok(None);
    };
    let turnable: Vec<usize> = (0..imported.surveys.len())
        .filter(|&s| imported.surveys[s].survey.is_ok())
        .collect();
    if turnable.is_empty() {
        return Ok(None);
    }
    let Some(mut best_wh) = energy_wh(mission) else {
        return Ok(None);
    };
    let mut angles: Vec<(usize, f64)> = Vec::new();
    let mut best_mission: Option<Mission> = None;
    for s in turnable {
        let Ok(survey) = &imported.surveys[s].survey else {
            continue;
        };
        let mut chosen: Option<(f64, Mission)> = None;
        let Some(own_covered) = covered_points(survey) else {
            continue;
        };
        for angle in candidate_angles(survey.params(), wind) {
            if bounds.cancelled() {
                return Err(Error::Cancelled);
            }
            // The polygon covered as before (a line lost at a corner is a gap in the images).
            let turned_survey = survey.with_angle(angle).ok();
            if turned_survey
                .as_ref()
                .and_then(covered_points)
                .is_none_or(|n| n < own_covered)
            {
                continue;
            }
            let mut trial = angles.clone();
            trial.push((s, angle));
            let Some(turned) = turned_mission(mission, imported, &trial) else {
                continue;
            };
            let Some(wh) = energy_wh(&turned) else {
                continue;
            };
            // A saving of at least a part in 10^6: an angle as good as the operator's is not a
            // change.
            if wh < best_wh * (1.0 - 1e-6) {
                best_wh = wh;
                chosen = Some((angle, turned));
            }
        }
        if let Some((angle, turned)) = chosen {
            angles.push((s, angle));
            best_mission = Some(turned);
        }
    }
    let Some(turned) = best_mission else {
        return Ok(None);
    };
    let changes = angles
        .iter()
        .filter_map(|&(s, to_deg)| {
            let read = &imported.surveys[s];
            let from_deg = read.survey.as_ref().ok()?.params().angle_deg;
            Some(AngleChange {
                item: read.first_item,
                from_deg,
                to_deg,
            })
        })
        .collect();
    Ok(Some((turned, changes)))
}

/// Why each survey of `mission` that cannot be drawn again is flown as its stored items and not
/// turned (a polygon of fewer than 3 distinct vertices, a spacing of 0, a coordinate that is not
/// a number: the reader's reason, naming the survey's first item and the key).
pub(in crate::engine) fn unturnable(mission: &Mission) -> Vec<String> {
    let Some(imported) = mission.kept() else {
        return Vec::new();
    };
    imported
        .surveys
        .iter()
        .filter_map(|s| s.survey.as_ref().err())
        .map(|e| format!("survey not turned, flown as its stored items: {e}"))
        .collect()
}

/// The grid on which coverage is counted, m.
const COVERAGE_GRID_M: f64 = 3.0;

/// How far beyond half a line spacing a point still counts as covered, m (what two tangent
/// planes' geodesy leaves over a survey's extent).
const COVERAGE_TOLERANCE_M: f64 = 0.5;

/// How many points of a [`COVERAGE_GRID_M`] grid inside the survey's polygon lie within half a
/// line spacing of a camera-on stretch of its transects (entry to exit, and the turnarounds
/// where the camera triggers through them), in the plane tangent at the polygon's first vertex;
/// `None` for a survey without transects.
fn covered_points(survey: &aloft_missions::survey::Survey) -> Option<usize> {
    use aloft_missions::survey::{PointKind, QgcProjection};
    let p = survey.params();
    let origin = p.polygon.first()?;
    let frame = LocalFrame::new(origin.latitude_deg, origin.longitude_deg);
    let local = |q: &aloft_missions::LatLon| frame.to_local_m(q.latitude_deg, q.longitude_deg);
    let polygon: Vec<[f64; 2]> = p.polygon.iter().map(local).collect();
    let mut lines: Vec<([f64; 2], [f64; 2])> = Vec::new();
    for t in survey.transects(QgcProjection::default()) {
        let on: Vec<[f64; 2]> = t
            .points
            .iter()
            .filter(|q| p.camera_in_turnaround || q.kind != PointKind::Turnaround)
            .map(|q| local(&q.position))
            .collect();
        lines.extend(on.windows(2).map(|w| (w[0], w[1])));
    }
    if lines.is_empty() {
        return None;
    }
    let reach = 0.5 * p.spacing_m + COVERAGE_TOLERANCE_M;
    let covered = grid_inside(&polygon, COVERAGE_GRID_M)
        .filter(|q| lines.iter().any(|(a, b)| to_segment_m(*q, *a, *b) <= reach))
        .count();
    Some(covered)
}

/// The points of a `step_m` grid inside `polygon` (even-odd rule), bounded to a million.
fn grid_inside(polygon: &[[f64; 2]], step_m: f64) -> impl Iterator<Item = [f64; 2]> + '_ {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for q in polygon {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    // A coarser grid for a large survey: at most about a million points.
    let area = (hi[0] - lo[0]).max(0.0) * (hi[1] - lo[1]).max(0.0);
    let step_m = step_m.max((area / 1e6).sqrt());
    let nx = ((hi[0] - lo[0]) / step_m).floor().max(0.0) as usize;
    let ny = ((hi[1] - lo[1]) / step_m).floor().max(0.0) as usize;
    (0..ny)
        .flat_map(move |j| (0..nx).map(move |i| (i, j)))
        .map(move |(i, j)| {
            [
                lo[0] + (i as f64 + 0.5) * step_m,
                lo[1] + (j as f64 + 0.5) * step_m,
            ]
        })
        .filter(move |q| inside(polygon, *q))
}

/// Whether `q` is inside `polygon` (even-odd rule).
fn inside(polygon: &[[f64; 2]], q: [f64; 2]) -> bool {
    let mut c = false;
    for (k, a) in polygon.iter().enumerate() {
        let b = polygon[(k + 1) % polygon.len()];
        if (a[1] > q[1]) != (b[1] > q[1]) {
            let x = a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if q[0] < x {
                c = !c;
            }
        }
    }
    c
}

/// Distance from `q` to the segment `a`-`b`, m.
fn to_segment_m(q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let t = match len2 > 0.0 {
        true => (((q[0] - a[0]) * d[0] + (q[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0),
        false => 0.0,
    };
    (q[0] - a[0] - t * d[0]).hypot(q[1] - a[1] - t * d[1])
}

/// The candidate angles of a survey (module docs), deg in [0, 180), without repeats.
fn candidate_angles(survey: &aloft_missions::survey::SurveyParams, wind: &Wind) -> Vec<f64> {
    let mut out: Vec<f64> = (0..)
        .map(|k| f64::from(k) * ANGLE_STEP_DEG)
        .take_while(|a| *a < 180.0)
        .collect();
    if let Some(bearing) = wind_bearing_deg(survey, wind) {
        out.push(bearing.rem_euclid(180.0));
        out.push((bearing + 90.0).rem_euclid(180.0));
    }
    let own = survey.angle_deg.rem_euclid(180.0);
    out.retain(|a| (a - own).abs() > 1e-9);
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    out
}

/// The bearing the wind blows towards at the survey's first vertex and height, deg clockwise
/// from north; `None` in still air there.
fn wind_bearing_deg(survey: &aloft_missions::survey::SurveyParams, wind: &Wind) -> Option<f64> {
    let w = wind.mean_at([0.0, 0.0, survey.altitude_m.max(1.0)])?;
    (w[0].hypot(w[1]) > 1e-6).then(|| w[0].atan2(w[1]).to_degrees())
}

/// The mission of the `.plan` `imported` with its surveys at `angles`, written and read back.
fn turned_mission(
    mission: &Mission,
    imported: &Imported,
    angles: &[(usize, f64)],
) -> Option<Mission> {
    let plan = imported.plan.as_ref()?;
    let home = imported.home?;
    let entries = plan_entries(imported, angles).ok()?;
    let text = write_plan(&plan.header, &home, &entries).ok()?;
    Mission::from_text(&text, mission.origin()).ok()
}
