//! A survey as large as the held-out ones, built from a shared one: the QGroundControl survey of
//! `neilvaltec_test.plan` (a 16-gon about 300 m across, 5 km of flight) with its polygon scaled
//! about its centre and its transects drawn again as QGroundControl draws them
//! (`aloft_missions::survey::reangle_survey_item`), the spacing and camera kept. Shared by the
//! tests and the plan bench (included by path).

use std::path::Path;

use serde_json::Value;

/// The text of the `.plan` at `path` with every survey's polygon scaled by `factor` about its
/// centre (lengths: a factor 2.8 makes a survey of about 7.8 times the area and the transects).
///
/// # Panics
/// A file that is not a `.plan` with a survey aloft can draw again.
pub fn scaled_survey(path: &Path, factor: f64) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut plan: Value = serde_json::from_str(&text).expect("a .plan is JSON");
    let items = plan["mission"]["items"]
        .as_array_mut()
        .expect("mission.items");
    // Sequence numbers: each simple item one, a survey as many as its own items.
    let mut seq = 1u32;
    for item in items.iter_mut() {
        if item["complexItemType"] == "survey" {
            let polygon = item["polygon"].as_array_mut().expect("a survey's polygon");
            let n = polygon.len() as f64;
            let centre =
                [0, 1].map(|k| polygon.iter().map(|p| p[k].as_f64().unwrap()).sum::<f64>() / n);
            for p in polygon.iter_mut() {
                for k in 0..2 {
                    let v = p[k].as_f64().unwrap();
                    p[k] = (centre[k] + factor * (v - centre[k])).into();
                }
            }
            let angle = item["angle"].as_f64().unwrap_or(0.0);
            *item = aloft_missions::survey::reangle_survey_item(
                item,
                angle,
                seq,
                aloft_missions::survey::QgcProjection::default(),
            )
            .expect("the scaled survey is drawn again");
            seq += item["TransectStyleComplexItem"]["Items"]
                .as_array()
                .map_or(0, |a| a.len() as u32);
        } else {
            seq += 1;
        }
    }
    serde_json::to_string_pretty(&plan).expect("JSON")
}
