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
//! half a line spacing of a camera-on line as the operator's angle does (a 3 m grid:
//! [`aloft_missions::survey::Survey::covered_points`]) (surveys one after the other, each with
//! the angles already chosen for those before it). [`crate::engine::plan_to_fly::fly_plan`] then
//! plans the turned mission beside the
//! mission as given and keeps the one with fewer batteries, then less energy.

use serde::{Deserialize, Serialize};

use aloft_missions::survey::candidate_angles;
use aloft_missions::{plan_entries, write_plan, Imported};
use aloft_planner::Wind;

use crate::engine::basics::step_meter::WorkBounds;
use crate::engine::missions::mission_file::Mission;
use crate::error::Error;

/// The step of the candidate angles, deg (the geometry of a survey's turn, its coverage and
/// its candidate angles, is `aloft_missions::survey`'s).
pub use aloft_missions::survey::ANGLE_STEP_DEG;

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

/// A survey kept at its grid angle, and why (the answer's `changes.angles_kept`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleKept {
    /// The survey's first item in the input.
    pub item: u32,
    /// Its grid angle, kept, deg.
    pub angle_deg: f64,
    /// The angle of least energy tried (absent: none covered the polygon as the operator's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tried_deg: Option<f64>,
    /// Why it was kept: what the angle tried would have cost, or covered.
    pub why: String,
}

/// The mission with its surveys turned to the wind, and the turns (`None` when no survey can
/// be turned or no turn saves energy); and the surveys kept at their angle, with why.
///
/// # Errors
/// [`Error::Cancelled`] once `bounds` say the caller gave up. `energy_wh` flies a mission whole
/// as the plan would (`None`: it cannot be flown).
pub(in crate::engine) fn turned_to_wind(
    mission: &Mission,
    wind: &Wind,
    energy_wh: &dyn Fn(&Mission) -> Option<f64>,
    bounds: &WorkBounds,
) -> Result<Turned, Error> {
    let none = || Ok((None, Vec::new()));
    let Some(imported) = mission.kept().filter(|k| k.plan.is_some()) else {
        return none();
    };
    let turnable: Vec<usize> = (0..imported.surveys.len())
        .filter(|&s| imported.surveys[s].survey.is_ok())
        .collect();
    if turnable.is_empty() {
        return none();
    }
    let Some(mut best_wh) = energy_wh(mission) else {
        return none();
    };
    let mut angles: Vec<(usize, f64)> = Vec::new();
    let mut best_mission: Option<Mission> = None;
    let mut kept: Vec<AngleKept> = Vec::new();
    for s in turnable {
        let Ok(survey) = &imported.surveys[s].survey else {
            continue;
        };
        let mut chosen: Option<(f64, Mission)> = None;
        let Some(own_covered) = survey.covered_points() else {
            continue;
        };
        let own_deg = survey.params().angle_deg;
        // The least energy of an angle tried that covers the polygon, and the most points an
        // angle that did not cover it covered.
        let mut least: Option<(f64, f64)> = None;
        let mut short: Option<(f64, usize)> = None;
        let own_wh = best_wh;
        for angle in candidate_angles(survey.params(), wind) {
            if bounds.cancelled() {
                return Err(Error::Cancelled);
            }
            // The polygon covered as before (a line lost at a corner is a gap in the images).
            let turned_survey = survey.with_angle(angle).ok();
            let covered = turned_survey
                .as_ref()
                .and_then(aloft_missions::survey::Survey::covered_points);
            if covered.is_none_or(|n| n < own_covered) {
                let n = covered.unwrap_or(0);
                if short.is_none_or(|(_, m)| n > m) {
                    short = Some((angle, n));
                }
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
            if (angle - own_deg).abs() > 1e-9 && least.is_none_or(|(_, w)| wh < w) {
                least = Some((angle, wh));
            }
            // A saving of at least a part in 10^6: an angle as good as the operator's is not a
            // change.
            if wh < best_wh * (1.0 - 1e-6) {
                best_wh = wh;
                chosen = Some((angle, turned));
            }
        }
        match chosen {
            Some((angle, turned)) => {
                angles.push((s, angle));
                best_mission = Some(turned);
            }
            None => kept.push(why_kept(
                imported.surveys[s].first_item,
                (own_deg, own_wh, own_covered),
                least,
                short,
            )),
        }
    }
    let Some(turned) = best_mission else {
        return Ok((None, kept));
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
    Ok((Some((turned, changes)), kept))
}

/// What [`turned_to_wind`] answers: the mission turned and its turns, when one saves energy;
/// the surveys kept at their angle, with why.
pub(in crate::engine) type Turned = (Option<(Mission, Vec<AngleChange>)>, Vec<AngleKept>);

/// Why the survey at `item` is kept at its angle `own_deg` (its mission flown whole costs
/// `own_wh` and its angle covers `own_covered` points of the polygon): the angle of least
/// energy tried (`least`: angle, Wh) saves none, or no other angle covered the polygon
/// (`short`: the best of those, angle and points).
fn why_kept(
    item: u32,
    (own_deg, own_wh, own_covered): (f64, f64, usize),
    least: Option<(f64, f64)>,
    short: Option<(f64, usize)>,
) -> AngleKept {
    let (tried_deg, why) = match (least, short) {
        (Some((deg, wh)), _) => (
            Some(deg),
            format!(
                "no angle saves energy: the least of those tried, {deg:.1}\u{b0}, costs {wh:.1} Wh \
                 flown whole against {own_wh:.1} Wh at {own_deg:.1}\u{b0}"
            ),
        ),
        (None, Some((deg, n))) => (
            Some(deg),
            format!(
                "every other angle tried leaves part of the polygon uncovered: the best, \
                 {deg:.1}\u{b0}, covers {n} of the {own_covered} points {own_deg:.1}\u{b0} covers \
                 (a 3 m grid)"
            ),
        ),
        (None, None) => (None, "no other angle could be drawn or flown".to_string()),
    };
    AngleKept {
        item,
        angle_deg: own_deg,
        tried_deg,
        why,
    }
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

/// The mission of the `.plan` `imported` with its surveys at `angles`, written and read back.
fn turned_mission(
    mission: &Mission,
    imported: &Imported,
    angles: &[(usize, f64)],
) -> Option<Mission> {
    let plan = imported.plan.as_ref()?;
    let home = imported.home?;
    let entries = plan_entries(imported, angles).ok()?;
    let text = write_plan(&plan.header, &home, &entries, &plan.airspace).ok()?;
    Mission::from_text_with(&text, mission.origin(), mission.read_options()).ok()
}
