//! Steps 9-10 of the module's docs: the items QGroundControl uploads for the transects
//! (`TransectStyleComplexItem.cc` `_buildAndAppendMissionItems` and the `_append*` functions),
//! its photo count, and the survey's complex item written back with a new angle.

use serde_json::{json, Map, Value};

use super::projection::qt_distance_m;
use super::{
    DistanceMode, PointKind, QgcProjection, Regenerated, Survey, SurveyParams, Transect,
    HOVER_AND_CAPTURE_S,
};
use crate::error::{ImportError, Place};
use crate::geo::LatLon;
use crate::raw_item::RawItem;

/// MAV_CMD_NAV_WAYPOINT.
const NAV_WAYPOINT: u32 = 16;
/// MAV_CMD_DO_SET_CAM_TRIGG_DIST.
const DO_SET_CAM_TRIGG_DIST: u32 = 206;
/// MAV_CMD_IMAGE_START_CAPTURE.
const IMAGE_START_CAPTURE: u32 = 2000;
/// MAV_FRAME_MISSION (no position).
const FRAME_MISSION: u32 = 2;

/// One item before it is numbered: command, frame, the seven parameters (NaN: not set).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Generated {
    command: u32,
    frame: u32,
    params: [f64; 7],
}

/// The transects, items and photo count of `survey`.
pub(super) fn regenerate(
    survey: &Survey,
    projection: QgcProjection,
) -> Result<Regenerated, ImportError> {
    let p = survey.params();
    let transects = survey.transects(projection);
    let items = generate(p, &transects)?.iter().map(item_json).collect();
    let visual_points: Vec<LatLon> = transects
        .iter()
        .flat_map(|t| t.points.iter().map(|q| q.position))
        .collect();
    Ok(Regenerated {
        camera_shots: camera_shots(p, &transects, &visual_points),
        transects,
        visual_points,
        items,
    })
}

/// The items of `transects` (step 9), numbered from the survey's first item, as the readers
/// hand items on (so they fly as items read from a file).
///
/// # Errors
/// [`ImportError::Refused`] for `DistanceMode` 3 and for no transect.
pub(crate) fn generate(
    p: &SurveyParams,
    transects: &[Transect],
) -> Result<Vec<RawItem>, ImportError> {
    let at = Place::Item(p.first_item);
    if p.altitude_mode == DistanceMode::CalcAboveTerrain {
        return Err(ImportError::Refused {
            at,
            what: "a survey with DistanceMode 3 (altitudes calculated above terrain)".into(),
            reason:
                "QGroundControl takes each item's altitude from terrain tiles aloft does not have",
        });
    }
    let path: Vec<(LatLon, PointKind)> = transects
        .iter()
        .flat_map(|t| t.points.iter().map(|q| (q.position, q.kind)))
        .collect();
    if path.is_empty() {
        return Err(ImportError::Refused {
            at,
            what: "a survey".into(),
            reason: "no grid line crosses its polygon",
        });
    }
    let mut out = Vec::with_capacity(path.len() * 2);
    let last = path.len() - 1;
    for (k, (position, kind)) in path.iter().enumerate() {
        point_items(p, *position, *kind, (k == 0, k == last), &mut out);
    }
    Ok((p.first_item..)
        .zip(&out)
        .map(|(n, g)| raw_item(g, n))
        .collect())
}

/// The items of one point of the path; `ends`: whether it is the path's first, last point.
fn point_items(
    p: &SurveyParams,
    q: LatLon,
    kind: PointKind,
    ends: (bool, bool),
    out: &mut Vec<Generated>,
) {
    let camera = p.trigger_distance_m != 0.0;
    let hover = p.hover_and_capture;
    let at_ends = camera && !hover && p.camera_in_turnaround;
    let trigger = |d: f64| Some(d);
    let (hold_s, after) = match kind {
        PointKind::Turnaround if at_ends && ends.0 => (0.0, trigger(p.trigger_distance_m)),
        PointKind::Turnaround if at_ends && ends.1 => (0.0, trigger(0.0)),
        PointKind::Turnaround => (0.0, None),
        PointKind::HoverTrigger => (HOVER_AND_CAPTURE_S, None),
        PointKind::Entry | PointKind::Exit if camera && hover => (HOVER_AND_CAPTURE_S, None),
        PointKind::Entry if camera => (0.0, trigger(p.trigger_distance_m)),
        PointKind::Exit if at_ends && p.turnaround_m == 0.0 && ends.1 => (0.0, trigger(0.0)),
        PointKind::Exit if camera && !p.camera_in_turnaround => (0.0, trigger(0.0)),
        PointKind::Entry | PointKind::Exit => (0.0, None),
    };
    out.push(waypoint(p, q, hold_s));
    if let Some(d) = after {
        out.push(trigger_distance(d));
    }
    let photo_point = matches!(kind, PointKind::HoverTrigger)
        || (camera && hover && matches!(kind, PointKind::Entry | PointKind::Exit));
    if photo_point {
        out.push(single_photo());
    }
}

/// `_appendWaypoint`: NAV_WAYPOINT at the survey's altitude, held `hold_s` (a C++ `float`),
/// acceptance radius 0, pass-through 0, yaw not set.
fn waypoint(p: &SurveyParams, q: LatLon, hold_s: f64) -> Generated {
    Generated {
        command: NAV_WAYPOINT,
        frame: p.altitude_mode.frame(),
        params: [
            f64::from(hold_s as f32),
            0.0,
            0.0,
            f64::NAN,
            q.latitude_deg,
            q.longitude_deg,
            p.altitude_m,
        ],
    }
}

/// `_appendCameraTriggerDistance`: the distance (a C++ `float`; 0 stops), shutter 0, one photo
/// now (p3 1).
fn trigger_distance(distance_m: f64) -> Generated {
    Generated {
        command: DO_SET_CAM_TRIGG_DIST,
        frame: FRAME_MISSION,
        params: [f64::from(distance_m as f32), 0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
    }
}

/// `_appendSinglePhotoCapture`: IMAGE_START_CAPTURE of one photo.
fn single_photo() -> Generated {
    let nan = f64::NAN;
    Generated {
        command: IMAGE_START_CAPTURE,
        frame: FRAME_MISSION,
        params: [0.0, 0.0, 1.0, 0.0, nan, nan, nan],
    }
}

/// A generated item as the readers' item, numbered `number` (its `doJumpId` too).
fn raw_item(g: &Generated, number: u32) -> RawItem {
    RawItem {
        at: Place::Item(number),
        number,
        command: g.command,
        frame: g.frame,
        params: g.params,
        jump_id: Some(i64::from(number)),
    }
}

/// An item as QGroundControl saves it (`MissionItem::save`, `doJumpId` its number): NaN as
/// `null`, whole numbers without a fraction as Qt writes them.
fn item_json(item: &RawItem) -> Value {
    let params: Vec<Value> = item.params.iter().map(|v| number_json(*v)).collect();
    json!({
        "autoContinue": true,
        "command": item.command,
        "doJumpId": item.number,
        "frame": item.frame,
        "params": params,
        "type": "SimpleItem",
    })
}

/// A number as Qt's JSON writes it: whole values below 2^53 as integers, NaN as `null`. It
/// reads back as the same `f64` to the last bit (serde_json writes the shortest decimal that
/// does; -0 keeps its sign as `-0.0`).
pub(crate) fn number_json(v: f64) -> Value {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
    let negative_zero = v == 0.0 && v.is_sign_negative();
    if !v.is_finite() {
        Value::Null
    } else if v.fract() == 0.0 && v.abs() < EXACT && !negative_zero {
        Value::from(v as i64)
    } else {
        Value::from(v)
    }
}

/// Step 10 (`_recalcCameraShots` after a rebuild): with images in turnarounds, the path length
/// (`_recalcComplexDistance`, Qt's sphere) over the trigger distance, rounded up; else the sum
/// over transects of the photographed length over it, each rounded up. No camera: 0.
fn camera_shots(p: &SurveyParams, transects: &[Transect], path: &[LatLon]) -> u64 {
    let d = p.trigger_distance_m;
    if d == 0.0 {
        return 0;
    }
    if p.camera_in_turnaround {
        let length_m: f64 = path.windows(2).map(|w| qt_distance_m(w[0], w[1])).sum();
        return (length_m / d).ceil() as u64;
    }
    let inner = p.turnaround_m > 0.0 && !p.hover_and_capture;
    transects
        .iter()
        .map(|t| {
            let n = t.points.len();
            let (a, b) = if inner && n >= 4 {
                (1, n - 2)
            } else {
                (0, n - 1)
            };
            let length_m = qt_distance_m(t.points[a].position, t.points[b].position);
            (length_m / d).ceil() as u64
        })
        .sum()
}

/// The JSON of a `.plan` survey complex item at a new grid angle: `angle`, the regenerated
/// `TransectStyleComplexItem.Items`, `VisualTransectPoints` and `CameraShots`, `version` 5
/// (with `splitConcavePolygons` false when the item lacks it); every other key as it was.
///
/// `first_item` is the sequence number of the survey's first item in its mission (the item
/// numbers and `doJumpId`s follow from it: [`super::ImportedSurvey::first_item`]);
/// `projection` is the QGroundControl version's tangent plane.
///
/// # Errors
/// The errors of [`Survey::from_complex_item`], [`Survey::with_angle`] and
/// [`Survey::regenerate`].
pub fn reangle_survey_item(
    item: &Value,
    angle_deg: f64,
    first_item: u32,
    projection: QgcProjection,
) -> Result<Value, ImportError> {
    let survey = Survey::from_complex_item(item, first_item)?.with_angle(angle_deg)?;
    let r = survey.regenerate(projection)?;
    let mut out = item.clone();
    let obj = out.as_object_mut().expect("read as an object above");
    obj.insert("angle".into(), number_json(angle_deg));
    obj.insert("version".into(), 5.into());
    obj.entry("splitConcavePolygons").or_insert(false.into());
    let inner = obj
        .get_mut("TransectStyleComplexItem")
        .and_then(Value::as_object_mut)
        .expect("read as an object above");
    store(inner, &r);
    Ok(out)
}

/// The regenerated keys of `TransectStyleComplexItem`.
fn store(inner: &mut Map<String, Value>, r: &Regenerated) {
    let points: Vec<Value> = r
        .visual_points
        .iter()
        .map(|q| json!([q.latitude_deg, q.longitude_deg]))
        .collect();
    inner.insert("Items".into(), Value::Array(r.items.clone()));
    inner.insert("VisualTransectPoints".into(), Value::Array(points));
    inner.insert("CameraShots".into(), r.camera_shots.into());
}
