//! The one survey QGroundControl wrote among the shared missions, `neilvaltec_test.plan`
//! (`ALOFT_DATA_DIR/missions`; never copied into the repository): a survey at angle 0 over a
//! 16-vertex polygon in Taipei, 25 m spacing and trigger distance, 10 m turnarounds, entry top
//! left, images in turnarounds, 67 items. Regenerated from its polygon, angle, spacing,
//! turnaround and entry, it must give QGroundControl's 67 items and 52 drawn points.
//!
//! Tolerance, 1e-7 deg (1.1 cm): the regeneration repeats QGroundControl's floating-point
//! operations in its order, so what is left are last-bit differences of `sin`, `cos`, `acos` and
//! `atan2` between the machine that wrote the file and this one. The worst conditioned step,
//! the arc cosine of a cosine near 1 for vertices 300 m from the tangent point, turns one unit
//! in the last place into about 1e-10 deg. Any departure from QGroundControl's algorithm is far
//! larger: the sphere of the WGS-84 semi-major axis (QGroundControl 2024-2026) moves the lines by
//! 1.6e-5 deg, which the test checks it sees.

use aloft_missions::survey::{reangle_survey_item, QgcProjection, Survey};
use aloft_missions::{distance_m, read_plan, LatLon};
use serde_json::Value;

/// Largest coordinate difference accepted, deg (see the module's docs).
const TOLERANCE_DEG: f64 = 1e-7;

/// The shared data folder, as the root's tests find it.
#[path = "../../../tests/it/common/data.rs"]
mod data;
use data::data_dir;

fn plan_text() -> String {
    let path = data_dir().join("missions/neilvaltec_test.plan");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The survey complex item of the file (the third of its items).
fn survey_item(root: &Value) -> &Value {
    let item = &root["mission"]["items"][2];
    assert_eq!(item["complexItemType"], "survey");
    item
}

/// The largest difference of two coordinate lists, deg and m.
#[derive(Debug, Default, Clone, Copy)]
struct Worst {
    deg: f64,
    m: f64,
}

impl Worst {
    fn add(&mut self, got: LatLon, want: LatLon) {
        let deg = (got.latitude_deg - want.latitude_deg)
            .abs()
            .max((got.longitude_deg - want.longitude_deg).abs());
        self.deg = self.deg.max(deg);
        self.m = self.m.max(distance_m(got, want));
    }
}

fn latlon(pair: &Value) -> LatLon {
    LatLon {
        latitude_deg: pair[0].as_f64().unwrap(),
        longitude_deg: pair[1].as_f64().unwrap(),
    }
}

/// Items equal but for latitude and longitude, which are compared in `worst`.
fn compare_items(got: &[Value], want: &[Value], worst: &mut Worst) {
    assert_eq!(got.len(), want.len());
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        for key in ["type", "command", "frame", "autoContinue", "doJumpId"] {
            assert_eq!(g[key], w[key], "item {k} key {key}");
        }
        let (gp, wp) = (
            g["params"].as_array().unwrap(),
            w["params"].as_array().unwrap(),
        );
        for p in [0, 1, 2, 3, 6] {
            assert_eq!(gp[p].as_f64(), wp[p].as_f64(), "item {k} param {}", p + 1);
        }
        if w["command"] == 16 {
            worst.add(
                latlon(&Value::from(&gp[4..6])),
                latlon(&Value::from(&wp[4..6])),
            );
        } else {
            assert_eq!(gp[4..].to_vec(), wp[4..].to_vec(), "item {k}");
        }
    }
}

/// Drawn points within the tolerance, compared in `worst`.
fn compare_points(got: &[Value], want: &[Value], worst: &mut Worst) {
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        worst.add(latlon(g), latlon(w));
    }
}

#[test]
fn data_val_neilvaltec_survey_regenerated_as_qgroundcontrol_drew_it() {
    let text = plan_text();
    let root: Value = serde_json::from_str(&text).unwrap();
    let stored = &survey_item(&root)["TransectStyleComplexItem"];
    let imported = read_plan(&text).unwrap();
    assert_eq!(imported.surveys.len(), 1);
    let s = &imported.surveys[0];
    assert_eq!((s.first_item, s.item_count), (3, 67));
    let survey: &Survey = s.survey.as_ref().unwrap();
    assert_eq!(survey.params().polygon.len(), 16);
    let r = survey.regenerate(QgcProjection::SphereMean).unwrap();
    let mut worst = Worst::default();
    compare_items(&r.items, stored["Items"].as_array().unwrap(), &mut worst);
    let points: Vec<Value> = r
        .visual_points
        .iter()
        .map(|q| serde_json::json!([q.latitude_deg, q.longitude_deg]))
        .collect();
    compare_points(
        &points,
        stored["VisualTransectPoints"].as_array().unwrap(),
        &mut worst,
    );
    assert_eq!(r.camera_shots, stored["CameraShots"].as_u64().unwrap());
    println!(
        "neilvaltec survey: {} items and {} drawn points match, largest difference {:e} deg ({:e} m)",
        r.items.len(),
        points.len(),
        worst.deg,
        worst.m
    );
    assert!(worst.deg <= TOLERANCE_DEG, "{worst:?}");
    // The test tells QGroundControl's projections apart.
    let other = survey.regenerate(QgcProjection::SphereEquatorial).unwrap();
    let mut moved = Worst::default();
    compare_items(
        &other.items,
        stored["Items"].as_array().unwrap(),
        &mut moved,
    );
    assert!(moved.deg > 1e-5, "{moved:?}");
}

#[test]
fn data_val_neilvaltec_survey_item_rewritten_at_its_own_angle_is_the_file_s() {
    let root: Value = serde_json::from_str(&plan_text()).unwrap();
    let original = survey_item(&root);
    let rewritten = reangle_survey_item(original, 0.0, 3, QgcProjection::SphereMean).unwrap();
    let regenerated = ["Items", "VisualTransectPoints"];
    let (mut a, mut b) = (original.clone(), rewritten.clone());
    for key in regenerated {
        a["TransectStyleComplexItem"][key] = Value::Null;
        b["TransectStyleComplexItem"][key] = Value::Null;
    }
    assert_eq!(
        a, b,
        "every other key as it was (CameraShots recomputed: 159)"
    );
    let (o, r) = (
        &original["TransectStyleComplexItem"],
        &rewritten["TransectStyleComplexItem"],
    );
    let mut worst = Worst::default();
    compare_items(
        r["Items"].as_array().unwrap(),
        o["Items"].as_array().unwrap(),
        &mut worst,
    );
    let (rp, op) = (&r["VisualTransectPoints"], &o["VisualTransectPoints"]);
    compare_points(rp.as_array().unwrap(), op.as_array().unwrap(), &mut worst);
    assert!(worst.deg <= TOLERANCE_DEG, "{worst:?}");
}

/// The file with its survey replaced by `item`.
fn with_survey(root: &Value, item: Value) -> String {
    let mut root = root.clone();
    root["mission"]["items"][2] = item;
    serde_json::to_string_pretty(&root).unwrap()
}

#[test]
fn data_val_neilvaltec_rewritten_plans_read_back_and_fly_as_written() {
    let text = plan_text();
    let root: Value = serde_json::from_str(&text).unwrap();
    let original = read_plan(&text).unwrap();
    let same = reangle_survey_item(survey_item(&root), 0.0, 3, QgcProjection::SphereMean).unwrap();
    let again = read_plan(&with_survey(&root, same)).unwrap();
    assert_eq!(again.counted, original.counted);
    assert_eq!(again.warnings, original.warnings);
    assert_eq!(again.spec.segments.len(), original.spec.segments.len());
    let (h0, h1) = (original.route.horizontal_m, again.route.horizontal_m);
    assert!((h1 - h0).abs() < 1e-3, "{h0} {h1}"); // 52 legs, each within 1.1 cm
                                                  // At 45 deg: read back, its stored items are what its description regenerates.
    let turned =
        reangle_survey_item(survey_item(&root), 45.0, 3, QgcProjection::SphereMean).unwrap();
    let read = read_plan(&with_survey(&root, turned.clone())).unwrap();
    let survey = read.surveys[0].survey.as_ref().unwrap();
    assert_eq!(survey.params().angle_deg, 45.0);
    let r = survey.regenerate(QgcProjection::SphereMean).unwrap();
    assert_eq!(
        Value::from(r.items),
        turned["TransectStyleComplexItem"]["Items"]
    );
    assert_eq!(read.surveys[0].item_count, read.counted.total - 3);
}
