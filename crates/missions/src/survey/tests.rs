//! Tests of the survey regeneration: refusals, item placement, corners and passes, and the
//! geometric invariants over random convex polygons. The comparison with QGroundControl's own
//! output is `tests/survey_data_val.rs`.

use proptest::prelude::*;
use serde_json::{json, Value};

use super::projection::{forward, qt_distance_m, Xy};
use super::transects::grid_angle_deg;
use super::write::generate;
use super::*;

fn ll(latitude_deg: f64, longitude_deg: f64) -> LatLon {
    LatLon {
        latitude_deg,
        longitude_deg,
    }
}

/// A 205 m (east) by 120 m (north) rectangle at 47 N, vertices from the south-west corner
/// anticlockwise; 1 deg of latitude ~ 111.2 km, of longitude ~ 75.8 km there. At a spacing of
/// 30 m its lines are 20, 50, ... 200 m east of the west side (the first line is 1000 m west
/// of the tangent point, a whole number of spacings from none of its sides): 7 transects.
fn rectangle() -> Vec<LatLon> {
    let (dlat, dlon) = (120.0 / 111_200.0, 205.0 / 75_840.0);
    vec![
        ll(47.0, 8.0),
        ll(47.0, 8.0 + dlon),
        ll(47.0 + dlat, 8.0 + dlon),
        ll(47.0 + dlat, 8.0),
    ]
}

/// The rectangle's survey: north-south lines 30 m apart, 50 m up, a photo every 20 m, 10 m
/// turnarounds with the camera on (the coverage module's tests too).
pub(super) fn params() -> SurveyParams {
    SurveyParams {
        first_item: 3,
        polygon: rectangle(),
        angle_deg: 0.0,
        turnaround_m: 10.0,
        camera_in_turnaround: true,
        altitude_m: 50.0,
        spacing_m: 30.0,
        trigger_distance_m: 20.0,
        ..SurveyParams::default()
    }
}

pub(super) fn survey(p: SurveyParams) -> Survey {
    Survey::new(p).unwrap()
}

/// The survey's items, as (command, frame, p1, p3) with the hold, distance and photo count.
fn items(p: SurveyParams) -> Vec<(u32, u32, f64, f64)> {
    let s = survey(p);
    let t = s.transects(QgcProjection::SphereMean);
    let g = generate(s.params(), &t).unwrap();
    g.iter()
        .map(|g| (g.command, g.frame, g.params[0], g.params[2]))
        .collect()
}

fn err(p: SurveyParams) -> String {
    Survey::new(p).unwrap_err().to_string()
}

// ---- Refusals ----

#[test]
fn degenerate_polygons_are_refused_naming_the_item_and_key() {
    let r = rectangle();
    let mut p = params();
    p.polygon = vec![r[0], r[1], r[0], r[1]];
    assert_eq!(
        err(p),
        "item 3: key polygon is 2 distinct vertices: expected at least 3 distinct vertices"
    );
    let mut p = params();
    let mid = ll(47.0, (r[0].longitude_deg + r[1].longitude_deg) / 2.0);
    p.polygon = vec![r[0], mid, r[1]];
    let e = err(p);
    assert!(e.starts_with("item 3: key polygon is an area of"), "{e}");
    assert!(
        e.ends_with("expected a polygon enclosing at least 1 m^2"),
        "{e}"
    );
    let mut p = params();
    p.polygon[2].latitude_deg = f64::NAN;
    assert!(err(p).starts_with("item 3: key polygon[2] is [NaN, "));
    let mut p = params();
    p.polygon[1].longitude_deg = f64::INFINITY;
    assert!(err(p).starts_with("item 3: key polygon[1] is [47, inf]"));
    let mut p = params();
    p.polygon[0].latitude_deg = 90.0;
    assert!(err(p).contains("polygon[0]"));
    let mut p = params();
    p.polygon[2] = ll(47.5, 8.0);
    let e = err(p);
    assert!(
        e.contains("a vertex 55") && e.contains("within 50 km"),
        "{e}"
    );
}

#[test]
fn spacings_qgroundcontrol_would_replace_and_bad_numbers_are_refused() {
    let key = "key TransectStyleComplexItem.CameraCalc.AdjustedFootprintSide is";
    for spacing in [0.0, -25.0, 0.3, 0.499, f64::NAN] {
        let e = err(SurveyParams {
            spacing_m: spacing,
            ..params()
        });
        assert!(e.starts_with(&format!("item 3: {key}")), "{e}");
        assert!(e.contains("replaces a smaller one by 100 km"), "{e}");
    }
    assert!(Survey::new(SurveyParams {
        spacing_m: MIN_SPACING_M,
        ..params()
    })
    .is_ok());
    type Change = fn(&mut SurveyParams);
    let cases: [(Change, &str); 5] = [
        (|p| p.angle_deg = 400.0, "key angle is 400"),
        (|p| p.angle_deg = f64::INFINITY, "key angle is inf"),
        (|p| p.turnaround_m = -1.0, "TurnAroundDistance is -1"),
        (
            |p| p.trigger_distance_m = f64::NAN,
            "AdjustedFootprintFrontal is NaN",
        ),
        (
            |p| p.min_trigger_interval_s = Some(-2.0),
            "MinTriggerInterval is -2",
        ),
    ];
    for (change, text) in cases {
        let mut p = params();
        change(&mut p);
        let e = err(p);
        assert!(e.contains(text), "{e}");
    }
}

/// A complex item as QGroundControl writes it (the shape of the shared survey).
fn complex_item() -> Value {
    let polygon: Vec<Value> = rectangle()
        .iter()
        .map(|q| json!([q.latitude_deg, q.longitude_deg]))
        .collect();
    json!({
        "type": "ComplexItem", "complexItemType": "survey", "version": 5, "angle": 0,
        "entryLocation": 0, "flyAlternateTransects": false, "splitConcavePolygons": false,
        "polygon": polygon,
        "TransectStyleComplexItem": {
            "version": 2, "TurnAroundDistance": 10, "CameraTriggerInTurnAround": true,
            "HoverAndCapture": false, "Refly90Degrees": false, "CameraShots": 0,
            "VisualTransectPoints": [], "Items": [],
            "CameraCalc": {
                "version": 2, "CameraName": "Manual (no camera specs)", "DistanceToSurface": 50,
                "DistanceMode": 1, "AdjustedFootprintSide": 30, "AdjustedFootprintFrontal": 20,
            },
        },
    })
}

#[test]
fn the_complex_item_is_read_and_its_refusals_name_the_key() {
    let s = Survey::from_complex_item(&complex_item(), 3).unwrap();
    assert_eq!(s.params(), &params());
    let e = |edit: fn(&mut Value)| {
        let mut v = complex_item();
        edit(&mut v);
        Survey::from_complex_item(&v, 7).unwrap_err().to_string()
    };
    const INNER: &str = "TransectStyleComplexItem";
    assert_eq!(
        e(|v| {
            v[INNER]["CameraCalc"]
                .as_object_mut()
                .unwrap()
                .remove("AdjustedFootprintSide");
        }),
        "item 7: missing key \"TransectStyleComplexItem.CameraCalc.AdjustedFootprintSide\""
    );
    assert!(e(|v| v["entryLocation"] = 7.into()).starts_with("item 7: key entryLocation is 7"));
    assert!(e(|v| v[INNER]["CameraCalc"]["DistanceMode"] = 9.into())
        .starts_with("item 7: key TransectStyleComplexItem.CameraCalc.DistanceMode is 9"));
    assert!(e(|v| v[INNER]["HoverAndCapture"] = 1.into())
        .starts_with("item 7: key TransectStyleComplexItem.HoverAndCapture is 1"));
    assert!(e(|v| v["polygon"][1] = json!(["a", 8])).starts_with("item 7: key polygon[1] is"));
    assert!(e(|v| v["version"] = 3.into()).starts_with("item 7: survey version 3 is refused"));
    assert!(e(|v| v["complexItemType"] = "CorridorScan".into())
        .starts_with("item 7: complexItemType \"CorridorScan\" is refused: not a survey"));
    assert!(e(|v| v["TransectStyleComplexItem"] = json!([]))
        .starts_with("item 7: key TransectStyleComplexItem is []"));
}

#[test]
fn older_camera_keys_give_the_altitude_mode() {
    let mut v = complex_item();
    let camera = v["TransectStyleComplexItem"]["CameraCalc"]
        .as_object_mut()
        .unwrap();
    camera.remove("DistanceMode");
    camera.insert("DistanceToSurfaceRelative".into(), false.into());
    let s = Survey::from_complex_item(&v, 3).unwrap();
    assert_eq!(s.params().altitude_mode, DistanceMode::Amsl);
    v["TransectStyleComplexItem"]["FollowTerrain"] = true.into();
    let s = Survey::from_complex_item(&v, 3).unwrap();
    assert_eq!(s.params().altitude_mode, DistanceMode::CalcAboveTerrain);
}

#[test]
fn terrain_calculated_altitudes_are_drawn_but_their_items_refused() {
    let s = survey(SurveyParams {
        altitude_mode: DistanceMode::CalcAboveTerrain,
        ..params()
    });
    assert!(!s.transects(QgcProjection::SphereMean).is_empty());
    let e = s
        .regenerate(QgcProjection::SphereMean)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(
            "item 3: a survey with DistanceMode 3 (altitudes calculated above terrain) is refused"
        ),
        "{e}"
    );
}

// ---- Items ----

/// The rectangle's 7 north-south transects.
const LINES: usize = 7;

#[test]
fn images_in_turnarounds_trigger_at_the_first_turnaround_every_entry_and_stop_at_the_last() {
    let got = items(params());
    let n = LINES;
    assert_eq!(
        survey(params()).transects(QgcProjection::SphereMean).len(),
        n
    );
    assert_eq!(got.len(), 4 * n + n + 2);
    let wp = (16, 3, 0.0, 0.0);
    let start = (206, 2, 20.0, 1.0);
    assert_eq!(got[..6], [wp, start, wp, start, wp, wp]);
    assert_eq!(got[got.len() - 2..], [wp, (206, 2, 0.0, 1.0)]);
}

#[test]
fn without_images_in_turnarounds_each_transect_starts_and_stops_the_camera() {
    let got = items(SurveyParams {
        camera_in_turnaround: false,
        ..params()
    });
    let (wp, on, off) = ((16, 3, 0.0, 0.0), (206, 2, 20.0, 1.0), (206, 2, 0.0, 1.0));
    assert_eq!(got[..6], [wp, wp, on, wp, off, wp]);
    assert_eq!(got.len(), LINES * 6);
}

#[test]
fn hover_and_capture_holds_and_shoots_at_every_photo_point() {
    let p = SurveyParams {
        hover_and_capture: true,
        ..params()
    };
    let s = survey(p.clone());
    let t = &s.transects(QgcProjection::SphereMean)[0];
    // About 120 m at 20 m: floor(length / 20 m) photo points after the entry (on Qt's sphere).
    let q = &t.points;
    let photos = (qt_distance_m(q[1].position, q[q.len() - 2].position) / 20.0).floor() as usize;
    assert!(photos == 5 || photos == 6, "{photos}");
    let kinds: Vec<PointKind> = q.iter().map(|q| q.kind).collect();
    assert_eq!(kinds.len(), 2 + 2 + photos);
    assert_eq!(kinds[1], PointKind::Entry);
    assert!(kinds[2..2 + photos]
        .iter()
        .all(|k| *k == PointKind::HoverTrigger));
    let got = items(p);
    let (wp, hold, shot) = ((16, 3, 0.0, 0.0), (16, 3, 4.0, 0.0), (2000, 2, 0.0, 1.0));
    assert_eq!(got[..5], [wp, hold, shot, hold, shot]);
    assert!(!got.iter().any(|g| g.0 == 206));
}

#[test]
fn no_camera_no_turnaround_and_the_frames_of_each_altitude_mode() {
    let got = items(SurveyParams {
        trigger_distance_m: 0.0,
        turnaround_m: 0.0,
        ..params()
    });
    assert_eq!(got.len(), 2 * LINES);
    assert!(got.iter().all(|g| *g == (16, 3, 0.0, 0.0)));
    let got = items(SurveyParams {
        turnaround_m: 0.0,
        ..params()
    });
    assert_eq!(
        got[..3],
        [(16, 3, 0.0, 0.0), (206, 2, 20.0, 1.0), (16, 3, 0.0, 0.0)]
    );
    assert_eq!(got[got.len() - 1], (206, 2, 0.0, 1.0));
    for (mode, frame) in [(DistanceMode::Amsl, 0), (DistanceMode::TerrainFrame, 10)] {
        let got = items(SurveyParams {
            altitude_mode: mode,
            ..params()
        });
        assert!(got.iter().filter(|g| g.0 == 16).all(|g| g.1 == frame));
    }
}

#[test]
fn items_are_numbered_from_the_first_and_carry_the_altitude() {
    let s = survey(params());
    let r = s.regenerate(QgcProjection::SphereMean).unwrap();
    assert_eq!(r.items[0]["doJumpId"], 3);
    assert_eq!(
        r.items[1],
        json!({"autoContinue": true, "command": 206, "doJumpId": 4,
        "frame": 2, "params": [20, 0, 1, 0, 0, 0, 0], "type": "SimpleItem"})
    );
    assert_eq!(r.items[0]["params"][3], Value::Null);
    assert_eq!(r.items[0]["params"][6], 50);
    let raw = generate(s.params(), &s.transects(QgcProjection::SphereMean)).unwrap();
    let numbers: Vec<(u32, Option<i64>)> = raw.iter().map(|r| (r.number, r.jump_id)).collect();
    assert_eq!(numbers[..2], [(3, Some(3)), (4, Some(4))]);
    assert_eq!(raw[0].at, crate::Place::Item(3));
    assert_eq!(r.visual_points.len(), LINES * 4);
}

// ---- Corners, passes, angles ----

/// First points of the first two transects' entries, by corner.
fn entries(corner: EntryCorner) -> Vec<LatLon> {
    let s = survey(SurveyParams {
        entry: corner,
        turnaround_m: 0.0,
        ..params()
    });
    let t = s.transects(QgcProjection::SphereMean);
    t.iter().map(|t| t.points[0].position).collect()
}

#[test]
fn entry_corners_reverse_points_and_order_and_lines_alternate() {
    let s = survey(SurveyParams {
        turnaround_m: 0.0,
        ..params()
    });
    let t = s.transects(QgcProjection::SphereMean);
    let ends: Vec<[LatLon; 2]> = t
        .iter()
        .map(|t| [t.points[0].position, t.points[1].position])
        .collect();
    // Top left: lines west to east, each drawn from south to north, then the lawnmower.
    assert!(ends[0][0].latitude_deg < ends[0][1].latitude_deg);
    assert!(ends[1][0].latitude_deg > ends[1][1].latitude_deg);
    assert!(ends[0][0].longitude_deg < ends[1][0].longitude_deg);
    let drawn = |k: usize| {
        if k % 2 == 1 {
            [ends[k][1], ends[k][0]]
        } else {
            ends[k]
        }
    };
    let last = LINES - 1;
    assert_eq!(entries(EntryCorner::BottomLeft)[0], drawn(0)[1]);
    assert_eq!(entries(EntryCorner::TopRight)[0], drawn(last)[0]);
    assert_eq!(entries(EntryCorner::BottomRight)[0], drawn(last)[1]);
}

#[test]
fn alternate_transects_fly_even_lines_out_and_odd_lines_back() {
    let plain = entries(EntryCorner::TopLeft);
    let s = survey(SurveyParams {
        fly_alternate_transects: true,
        turnaround_m: 0.0,
        ..params()
    });
    let t = s.transects(QgcProjection::SphereMean);
    let lon: Vec<f64> = t
        .iter()
        .map(|t| t.points[0].position.longitude_deg)
        .collect();
    let line = |k: usize| plain[k].longitude_deg;
    let order = [0, 2, 4, 6, 5, 3, 1];
    for (got, k) in lon.iter().zip(order) {
        assert!((got - line(k)).abs() < 1e-7, "{lon:?}"); // lines 4e-4 deg apart
    }
}

#[test]
fn refly_adds_a_perpendicular_pass_starting_near_the_first_pass_end() {
    let s = survey(SurveyParams {
        refly_90: true,
        ..params()
    });
    let t = s.transects(QgcProjection::SphereMean);
    // 120 m north-south at 30 m: 3 or 4 east-west lines after the first pass.
    let refly = t.len() - LINES;
    assert!(refly == 3 || refly == 4, "{}", t.len());
    let second = &t[LINES].points;
    let (a, b) = (second[1].position, second[2].position);
    assert!((a.latitude_deg - b.latitude_deg).abs() < 1e-6, "east-west"); // 30 m: 3e-4 deg
    let end = t[LINES - 1].points.last().unwrap().position;
    let start = second[0].position;
    let far = t.last().unwrap().points.last().unwrap().position;
    assert!(qt_distance_m(end, start) < qt_distance_m(end, far));
}

#[test]
fn angles_a_half_turn_apart_draw_the_same_survey() {
    let at = |angle_deg| {
        survey(SurveyParams {
            angle_deg,
            ..params()
        })
        .transects(QgcProjection::SphereMean)
    };
    assert_eq!(at(0.0), at(180.0));
    assert_eq!(at(-60.0), at(120.0));
    assert!((grid_angle_deg(300.0) - 120.0).abs() < 1e-12); // one step of 180 only
}

#[test]
fn a_polygon_narrower_than_two_lines_gets_one_transect_through_its_box_centre() {
    let s = survey(SurveyParams {
        spacing_m: 500.0,
        turnaround_m: 0.0,
        ..params()
    });
    let t = s.transects(QgcProjection::SphereMean);
    assert_eq!(t.len(), 1);
    let r = rectangle();
    let mid = (r[0].longitude_deg + r[1].longitude_deg) / 2.0;
    assert!((t[0].points[0].position.longitude_deg - mid).abs() < 1e-9);
}

#[test]
fn the_reader_keeps_each_survey_and_still_reads_a_survey_it_cannot_regenerate() {
    let take_off = json!({"type": "SimpleItem", "command": 22, "frame": 3, "autoContinue": true,
        "params": [0, 0, 0, null, 47.0, 8.0, 30]});
    let mut item = complex_item();
    let r = reangle_survey_item(&item, 0.0, 2, QgcProjection::SphereMean).unwrap();
    item["TransectStyleComplexItem"] = r["TransectStyleComplexItem"].clone();
    let plan = |survey: &Value| {
        json!({"fileType": "Plan", "version": 1, "mission": {"version": 2, "firmwareType": 12,
            "hoverSpeed": 5, "plannedHomePosition": [47.0, 8.0, 400], "items": [take_off, survey]}})
        .to_string()
    };
    let good = crate::read_plan(&plan(&item)).unwrap();
    assert_eq!(good.surveys.len(), 1);
    let s = &good.surveys[0];
    assert_eq!((s.first_item, s.item_count), (2, LINES * 5 + 2));
    let kept = s.survey.as_ref().unwrap().params();
    assert_eq!(kept.polygon, rectangle());
    assert!((kept.spacing_m - 30.0).abs() < 1e-12 && kept.first_item == 2);
    item["TransectStyleComplexItem"]["CameraCalc"]["AdjustedFootprintSide"] = 0.2.into();
    let bad = crate::read_plan(&plan(&item)).unwrap();
    assert_eq!(bad.spec, good.spec);
    assert_eq!(bad.warnings, good.warnings);
    let e = bad.surveys[0].survey.as_ref().unwrap_err().to_string();
    assert!(
        e.starts_with(
            "item 2: key TransectStyleComplexItem.CameraCalc.AdjustedFootprintSide is 0.2"
        ),
        "{e}"
    );
}

/// The items `generate` hands on fly exactly as the same items written to a `.plan` and read
/// back: the same segments, counts and warnings (float_roundtrip JSON is exact).
#[test]
fn regenerated_items_fly_as_the_same_items_read_from_a_file() {
    use crate::items::{translate, Autopilot, Source};
    let take_off_json = json!({"type": "SimpleItem", "command": 22, "frame": 3,
        "autoContinue": true, "params": [0, 0, 0, null, 47.0, 8.0, 30]});
    let s = survey(SurveyParams {
        first_item: 2,
        ..params()
    });
    let r = s.regenerate(QgcProjection::SphereMean).unwrap();
    let mut item = complex_item();
    item["TransectStyleComplexItem"]["Items"] = r.items.into();
    let text = json!({"fileType": "Plan", "version": 1, "mission": {"version": 2,
        "firmwareType": 12, "hoverSpeed": 5, "plannedHomePosition": [47.0, 8.0, 400],
        "items": [take_off_json, item]}})
    .to_string();
    let read = crate::read_plan(&text).unwrap();
    let take_off = crate::raw_item::RawItem {
        at: crate::Place::Item(1),
        number: 1,
        command: 22,
        frame: 3,
        params: [0.0, 0.0, 0.0, f64::NAN, 47.0, 8.0, 30.0],
        jump_id: None,
    };
    let mut raw = vec![take_off];
    raw.extend(generate(s.params(), &s.transects(QgcProjection::SphereMean)).unwrap());
    let source = Source {
        home: ll(47.0, 8.0),
        home_amsl_m: Some(400.0),
        autopilot: Autopilot::Px4,
        jumps_by: crate::jumps::JumpsBy::DoJumpId,
        default_speed_mps: 5.0,
        options: crate::ReadOptions::default(),
    };
    let flown = translate(&raw, &source, crate::notes::Notes::default()).unwrap();
    assert_eq!(flown.segments, read.spec.segments);
    assert_eq!(flown.counts, read.counted);
    assert_eq!(flown.notes, read.warnings);
}

// ---- Invariants over random convex polygons ----

/// A convex polygon: `n` points of an ellipse (semi-axes `rx_m`, `ry_m`, turned `turn_rad`) at
/// increasing angles about `centre`, placed on the ellipsoid through the plane tangent there.
fn ellipse_polygon(
    centre: LatLon,
    radii_m: (f64, f64),
    turn_rad: f64,
    mut at: Vec<f64>,
) -> Vec<LatLon> {
    at.sort_by(f64::total_cmp);
    at.iter()
        .map(|t| {
            let (x, y) = (radii_m.0 * t.cos(), radii_m.1 * t.sin());
            let (s, c) = turn_rad.sin_cos();
            let xy = Xy {
                x: x * c - y * s,
                y: x * s + y * c,
            };
            super::projection::reverse(xy, centre, QgcProjection::LocalCartesian)
        })
        .collect()
}

/// The plane tangent at a survey's first vertex, with its box and grid.
struct Plane {
    projection: QgcProjection,
    origin: LatLon,
    /// The polygon, closed.
    closed: Vec<Xy>,
    bbox: super::transects::BoundingBox,
    grid_deg: f64,
    spacing_m: f64,
    /// What a point loses through latitude/longitude and back, m (see the property's docs).
    tol_m: f64,
}

impl Plane {
    fn new(p: &SurveyParams, projection: QgcProjection) -> Self {
        let origin = p.polygon[0];
        let mut closed: Vec<Xy> = p
            .polygon
            .iter()
            .map(|q| forward(*q, origin, projection))
            .collect();
        closed.push(closed[0]);
        let local = projection == QgcProjection::LocalCartesian;
        Plane {
            projection,
            origin,
            bbox: super::transects::bounding_box(&closed),
            closed,
            grid_deg: grid_angle_deg(p.angle_deg),
            spacing_m: p.spacing_m,
            tol_m: if local { 1e-3 } else { 1e-6 },
        }
    }

    fn xy(&self, q: LatLon) -> Xy {
        forward(q, self.origin, self.projection)
    }

    /// Signed offset of `q` across the grid lines from the box centre, m.
    fn offset_m(&self, q: Xy) -> f64 {
        let a = self.grid_deg.to_radians();
        (q.x - self.bbox.centre.x) * a.cos() - (q.y - self.bbox.centre.y) * a.sin()
    }

    /// Distance from `q` to the polygon's sides, m.
    fn to_sides_m(&self, q: Xy) -> f64 {
        let sides = self.closed.windows(2);
        sides
            .map(|w| to_segment_m(q, w[0], w[1]))
            .fold(f64::MAX, f64::min)
    }
}

/// Distance from `q` to the segment `a`-`b`, m.
fn to_segment_m(q: Xy, a: Xy, b: Xy) -> f64 {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let t = (((q.x - a.x) * dx + (q.y - a.y) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (q.x - a.x - t * dx).hypot(q.y - a.y - t * dy)
}

/// One transect: at the grid angle, from side to side, its turnaround behind its entry. Returns
/// its offset and direction (entry to exit).
fn check_transect(f: &Plane, t: &Transect, turnaround_m: f64) -> Result<(f64, Xy), TestCaseError> {
    let k = usize::from(turnaround_m > 0.0);
    let (e, x) = (f.xy(t.points[k].position), f.xy(t.points[k + 1].position));
    let d = Xy {
        x: x.x - e.x,
        y: x.y - e.y,
    };
    let (sin_a, cos_a) = f.grid_deg.to_radians().sin_cos();
    prop_assert!(
        (d.x * cos_a - d.y * sin_a).abs() < f.tol_m,
        "parallel {d:?}"
    );
    for q in [e, x] {
        let side_m = f.to_sides_m(q);
        prop_assert!(side_m < f.tol_m, "on the boundary: {side_m}");
    }
    let o = f.offset_m(e);
    if turnaround_m > 0.0 {
        let (b, entry) = (t.points[0].position, t.points[1].position);
        prop_assert!((qt_distance_m(b, entry) - turnaround_m).abs() < 1e-6);
        let b = f.xy(b);
        prop_assert!((f.offset_m(b) - o).abs() < 0.05, "on the line");
        prop_assert!(
            (b.x - e.x) * d.x + (b.y - e.y) * d.y < 0.0,
            "before the entry"
        );
    }
    Ok((o, d))
}

/// The lines' phase and spacing, and every sampled point of the polygon (a point of a triangle
/// of its fan) within half a spacing of a line between the outermost two, one outside them.
fn check_grid(
    f: &Plane,
    mut offsets: Vec<f64>,
    samples: &[(f64, f64, usize)],
) -> Result<(), TestCaseError> {
    let half_m = (f.bbox.larger_side_m + 2000.0) / 2.0;
    for o in &offsets {
        let steps = (o + half_m) / f.spacing_m;
        prop_assert!(
            (steps - steps.round()).abs() * f.spacing_m < f.tol_m,
            "phase {steps}"
        );
    }
    offsets.sort_by(f64::total_cmp);
    for w in offsets.windows(2) {
        prop_assert!((w[1] - w[0] - f.spacing_m).abs() < f.tol_m, "spacing {w:?}");
    }
    let (low, high) = (offsets[0], offsets[offsets.len() - 1]);
    let v = &f.closed;
    for &(a, b, k) in samples {
        let k = 1 + k % (v.len() - 3);
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let q = Xy {
            x: v[0].x + a * (v[k].x - v[0].x) + b * (v[k + 1].x - v[0].x),
            y: v[0].y + a * (v[k].y - v[0].y) + b * (v[k + 1].y - v[0].y),
        };
        let o = f.offset_m(q);
        let nearest_m = offsets
            .iter()
            .map(|l| (l - o).abs())
            .fold(f64::MAX, f64::min);
        let bound_m = if (low..=high).contains(&o) {
            f.spacing_m / 2.0
        } else {
            f.spacing_m
        };
        prop_assert!(nearest_m <= bound_m + f.tol_m, "{nearest_m} > {bound_m}");
    }
    Ok(())
}

fn projections() -> impl Strategy<Value = QgcProjection> {
    prop::sample::select(vec![
        QgcProjection::SphereMean,
        QgcProjection::SphereEquatorial,
        QgcProjection::LocalCartesian,
    ])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// In the plane tangent at the first vertex: every transect runs at the grid angle from one
    /// side of the polygon to the other; the lines sit at whole spacings from
    /// `centre - (max(width, height) + 2000) / 2` (the first-vertex and box-centre convention);
    /// neighbours are one spacing apart and fly opposite ways; every point of the polygon is
    /// within half a spacing of a transect between the outermost two, and within one spacing
    /// outside them (QGroundControl's lines have no half-spacing inset: a side strip narrower
    /// than a spacing is covered from one line only). Tolerances: what is computed in the plane
    /// comes back through latitude/longitude, exactly for the spheres (1e-6 m), and for
    /// `LocalCartesian` displaced by about d^3 / 2R^2, 0.4 mm at the 3 km of the largest
    /// polygons (QGroundControl drops the plane's up coordinate; see `projection.rs`): 1e-3 m;
    /// 5 cm for the turnaround placed on Qt's sphere (its azimuth is the sphere's, not the
    /// plane's: a few millimetres over 30 m at these distances).
    #[test]
    fn transects_are_parallel_spaced_and_cover_the_polygon(
        lat in -60.0..60.0f64, lon in -179.0..179.0f64,
        radii in (100.0..1500.0f64, 100.0..1500.0f64), turn in 0.0..3.2f64,
        at in prop::collection::vec(0.0..std::f64::consts::TAU, 3..12),
        angle_deg in -360.0..360.0f64, spacing_m in 5.0..30.0f64,
        entry in 0u64..4, turnaround_m in 0.0..30.0f64, projection in projections(),
        samples in prop::collection::vec((0.0..1.0f64, 0.0..1.0f64, 0usize..100), 30),
    ) {
        let polygon = ellipse_polygon(ll(lat, lon), radii, turn, at);
        let p = SurveyParams {
            polygon, angle_deg, spacing_m, turnaround_m,
            entry: EntryCorner::from_index(entry).unwrap(),
            trigger_distance_m: 10.0, camera_in_turnaround: true,
            ..params()
        };
        let Ok(s) = Survey::new(p.clone()) else { return Ok(()) }; // a sliver under 1 m^2
        let plane = Plane::new(&p, projection);
        let transects = s.transects(projection);
        let mut offsets = Vec::new();
        let mut previous: Option<Xy> = None;
        for t in &transects {
            let (o, d) = check_transect(&plane, t, turnaround_m)?;
            if let Some(b) = previous {
                prop_assert!(b.x * d.x + b.y * d.y < 0.0, "lawnmower");
            }
            previous = Some(d);
            offsets.push(o);
        }
        if transects.len() == 1 {
            // Narrower than two spacings across the lines: the line through the box centre.
            prop_assert!(offsets[0].abs() < plane.tol_m);
        } else {
            check_grid(&plane, offsets, &samples)?;
        }
    }

    /// Any description, valid or not: an answer or an error, never a panic, and the items of an
    /// answer are finite where set.
    #[test]
    fn any_description_never_panics(
        n in 0usize..6, lat in -100.0..100.0f64, spread in -1.0..1.0f64,
        angle_deg in -400.0..400.0f64, spacing_m in -1.0..300.0f64, turnaround_m in -1.0..50.0f64,
        hover in any::<bool>(), refly in any::<bool>(), inside in any::<bool>(),
    ) {
        let polygon = (0..n)
            .map(|k| ll(lat + spread * 1e-3 * (k as f64).sin(), 8.0 + 1e-3 * (k as f64).cos()))
            .collect();
        let p = SurveyParams {
            polygon, angle_deg, spacing_m, turnaround_m, hover_and_capture: hover,
            refly_90: refly, camera_in_turnaround: inside, ..params()
        };
        if let Ok(s) = Survey::new(p) {
            let r = s.regenerate(QgcProjection::LocalCartesian).unwrap();
            for item in &r.items {
                for v in item["params"].as_array().unwrap() {
                    prop_assert!(v.is_null() || v.as_f64().unwrap().is_finite());
                }
            }
        }
    }
}
