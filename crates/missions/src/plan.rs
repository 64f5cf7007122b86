//! The QGroundControl `.plan` reader (JSON).
//!
//! The file: `{"fileType": "Plan", "version": 1, "mission": {...}, "geoFence": {...},
//! "rallyPoints": {...}}`; `mission` holds `version` (2), `firmwareType` (MAV_AUTOPILOT: 3
//! ArduPilot, 12 PX4), `vehicleType` (MAV_TYPE), `hoverSpeed` (the multirotor planning speed),
//! `plannedHomePosition` `[lat, lon, alt AMSL]` and `items`. The specification is
//! QGroundControl's own loader (`MissionController`, `MissionItem::load`,
//! `TransectStyleComplexItem`):
//!
//! - a SimpleItem has `type`, `command`, `frame`, `params` (7 values, `null` = not set),
//!   `autoContinue` and optionally `doJumpId`. Older layouts are converted as QGroundControl
//!   does: V1 (`param1`..`param4` keys, `type` "missionItem") and V2 (`params` of 4 values and a
//!   `coordinate` `[lat, lon, alt]`). The `Altitude`, `AltitudeMode` and `AMSLAltAboveTerrain`
//!   keys are display hints and are not read: the altitude is `params[6]` in `frame`;
//! - a ComplexItem `survey` or `CorridorScan` stores the generated items in
//!   `TransectStyleComplexItem.Items`, flattened here and numbered in sequence; a
//!   `StructureScan` stores no path and is refused, and so are fixed-wing and VTOL landing
//!   patterns;
//! - VTOL vehicle types (MAV_TYPE 19-25) are refused; a fixed-wing `vehicleType` (1) is the
//!   planner's offline vehicle and only warned about: aloft flies the file as a multirotor.
//!
//! Items are numbered as QGroundControl uploads them: home is 0, the first item 1.

use serde_json::{Map, Value};

use crate::error::{ImportError, Place};
use crate::geo::LatLon;
use crate::items::{translate, Autopilot, ReadOptions, Source};
use crate::jumps::JumpsBy;
use crate::kept::{Home, ItemOrigin, PlanFile, PlanHeader};
use crate::notes::Notes;
use crate::raw_item::RawItem;
use crate::survey::{ImportedSurvey, Survey};
use crate::{assemble, Imported, SourceFormat};

/// QGroundControl's default multirotor planning speed (`hoverSpeed`), m/s, for a file without one.
const QGC_DEFAULT_HOVER_SPEED_MPS: f64 = 5.0;

/// The keys every SimpleItem has (after conversion of the old layouts).
const SIMPLE_KEYS: [&str; 4] = ["type", "command", "frame", "autoContinue"];

/// Read a QGroundControl `.plan`.
///
/// # Errors
/// Invalid JSON, a `fileType` other than "Plan", a mission version other than 2, missing or
/// mistyped keys (naming the item and the key), refused items and vehicles, and the errors of
/// the items' semantics (see the crate's docs).
pub fn read_plan(text: &str) -> Result<Imported, ImportError> {
    read_plan_with(text, ReadOptions::default())
}

/// [`read_plan`] with `options`.
///
/// # Errors
/// As [`read_plan`].
pub fn read_plan_with(text: &str, options: ReadOptions) -> Result<Imported, ImportError> {
    let root: Value = serde_json::from_str(text.trim_start_matches('\u{feff}')).map_err(|e| {
        ImportError::Json {
            line: e.line(),
            column: e.column(),
            message: aloft_core::file_message(&e.to_string()),
        }
    })?;
    let root = object(&root, Place::File, None, "(top level)")?;
    check_file_type(root)?;
    let mission = match root.get("mission") {
        Some(m) => object(m, Place::File, None, "mission")?,
        None => return Err(missing(Place::File, None, &["mission"])),
    };
    check_version(mission)?;
    let airspace = crate::Airspace::read(root)?;
    let (home, home_amsl_m) = planned_home(mission)?;
    let mut notes = Notes::default();
    let mut surveys = Vec::new();
    let mut origins = Vec::new();
    let items = flatten(mission, &mut notes, (&mut surveys, &mut origins))?;
    check_vehicle_type(mission, &mut notes)?;
    let autopilot = match mission.get("firmwareType").and_then(Value::as_u64) {
        Some(3) => Autopilot::ArduPilot,
        _ => Autopilot::Px4,
    };
    let source = Source {
        home,
        home_amsl_m,
        autopilot,
        jumps_by: JumpsBy::DoJumpId,
        default_speed_mps: hover_speed(mission, &mut notes)?,
        options,
    };
    let translation = translate(&items, &source, notes)?;
    let description = format!(
        "QGroundControl plan for {}, {} items",
        match autopilot {
            Autopilot::ArduPilot => "ArduPilot",
            Autopilot::Px4 => "PX4",
        },
        items.len()
    );
    let file_home = Home {
        latitude_deg: home.latitude_deg,
        longitude_deg: home.longitude_deg,
        altitude_amsl_m: home_amsl_m,
    };
    let mut imported = assemble(
        translation,
        &source,
        (&items, Some(file_home)),
        SourceFormat::QgcPlan,
        description,
    );
    imported.surveys = surveys;
    imported.plan = Some(PlanFile {
        header: header(mission),
        origins,
        airspace,
    });
    Ok(imported)
}

/// The mission keys kept for a writer, where they are numbers of their type.
fn header(mission: &Map<String, Value>) -> PlanHeader {
    let whole = |key| {
        mission
            .get(key)
            .and_then(Value::as_u64)
            .and_then(|v| u32::try_from(v).ok())
    };
    let number = |key| mission.get(key).and_then(Value::as_f64);
    PlanHeader {
        firmware_type: whole("firmwareType"),
        vehicle_type: whole("vehicleType"),
        cruise_speed_mps: number("cruiseSpeed"),
        hover_speed_mps: number("hoverSpeed"),
        global_plan_altitude_mode: mission
            .get("globalPlanAltitudeMode")
            .and_then(Value::as_i64),
    }
}

/// `fileType` must be "Plan".
fn check_file_type(root: &Map<String, Value>) -> Result<(), ImportError> {
    match root.get("fileType") {
        Some(Value::String(s)) if s == "Plan" => Ok(()),
        Some(other) => Err(ImportError::WrongFileType {
            found: short(other),
        }),
        None => Err(missing(Place::File, None, &["fileType"])),
    }
}

/// `mission.version` must be 2.
fn check_version(mission: &Map<String, Value>) -> Result<(), ImportError> {
    match mission.get("version") {
        Some(v) if v.as_u64() == Some(2) => Ok(()),
        Some(v) => Err(ImportError::BadKey {
            at: Place::File,
            command: None,
            key: "mission.version".into(),
            found: short(v),
            expected: "2 (QGroundControl's mission format since 2017)",
        }),
        None => Err(missing(Place::File, None, &["mission.version"])),
    }
}

/// `plannedHomePosition`: `[lat, lon, alt AMSL]` (the altitude may be null).
fn planned_home(mission: &Map<String, Value>) -> Result<(LatLon, Option<f64>), ImportError> {
    let key = "mission.plannedHomePosition";
    let v = mission
        .get("plannedHomePosition")
        .ok_or_else(|| missing(Place::File, None, &[key]))?;
    let bad = |expected| ImportError::BadKey {
        at: Place::File,
        command: None,
        key: key.into(),
        found: short(v),
        expected,
    };
    let a = v
        .as_array()
        .filter(|a| a.len() == 3)
        .ok_or_else(|| bad("[latitude, longitude, altitude above mean sea level]"))?;
    let (lat, lon) = match (a[0].as_f64(), a[1].as_f64()) {
        (Some(la), Some(lo)) if la.abs() < 90.0 && lo.abs() <= 180.0 => (la, lo),
        _ => {
            return Err(bad(
                "a latitude within (-90, 90) and a longitude within [-180, 180]",
            ))
        }
    };
    let amsl = match &a[2] {
        Value::Null => None,
        x => Some(
            x.as_f64()
                .filter(|h| h.abs() <= 1e6)
                .ok_or_else(|| bad("an altitude within 1e6 m, or null"))?,
        ),
    };
    Ok((
        LatLon {
            latitude_deg: lat,
            longitude_deg: lon,
        },
        amsl,
    ))
}

/// VTOL vehicle types are refused; a fixed-wing planner vehicle is warned about.
fn check_vehicle_type(mission: &Map<String, Value>, notes: &mut Notes) -> Result<(), ImportError> {
    match mission.get("vehicleType").and_then(Value::as_u64) {
        Some(t @ 19..=25) => Err(ImportError::Refused {
            at: Place::File,
            what: format!("key mission.vehicleType {t} (a VTOL, MAV_TYPE 19-25)"),
            reason: "aloft models multirotors",
        }),
        Some(1) => {
            notes.add(
                Place::File,
                "planned for a fixed-wing vehicle (vehicleType 1, the planner's offline vehicle): flown as a multirotor",
            );
            Ok(())
        }
        _ => Ok(()),
    }
}

/// `hoverSpeed`, else QGroundControl's default (warned).
fn hover_speed(mission: &Map<String, Value>, notes: &mut Notes) -> Result<f64, ImportError> {
    match mission.get("hoverSpeed") {
        None => {
            notes.add(
                Place::File,
                format!("no mission.hoverSpeed: QGroundControl's default {QGC_DEFAULT_HOVER_SPEED_MPS} m/s is the planning speed"),
            );
            Ok(QGC_DEFAULT_HOVER_SPEED_MPS)
        }
        Some(v) => {
            v.as_f64()
                .filter(|s| *s > 0.0 && *s <= 1e3)
                .ok_or_else(|| ImportError::BadKey {
                    at: Place::File,
                    command: None,
                    key: "mission.hoverSpeed".into(),
                    found: short(v),
                    expected: "a speed in m/s, positive and at most 1000",
                })
        }
    }
}

/// The mission's items, complex items flattened, numbered from 1; each survey's description
/// kept in `surveys`, each item's entry in `origins`.
fn flatten(
    mission: &Map<String, Value>,
    notes: &mut Notes,
    (surveys, origins): (&mut Vec<ImportedSurvey>, &mut Vec<ItemOrigin>),
) -> Result<Vec<RawItem>, ImportError> {
    let list = match mission.get("items") {
        Some(Value::Array(a)) => a,
        Some(v) => {
            return Err(ImportError::BadKey {
                at: Place::File,
                command: None,
                key: "mission.items".into(),
                found: short(v),
                expected: "an array of mission items",
            })
        }
        None => return Err(missing(Place::File, None, &["mission.items"])),
    };
    let mut items = Vec::with_capacity(list.len());
    for (entry, v) in list.iter().enumerate() {
        let at = Place::Item(next_number(&items)?);
        let obj = object(v, at, None, "item")?;
        let before = items.len();
        let origin = match obj.get("type").and_then(Value::as_str) {
            Some("ComplexItem") => {
                let survey = surveys.len();
                let kind = complex_item(v, &mut items, notes, surveys)?;
                match kind {
                    ComplexKind::Survey => ItemOrigin::Survey { entry, survey },
                    ComplexKind::CorridorScan => ItemOrigin::CorridorScan { entry },
                }
            }
            _ => {
                items.push(simple_item(obj, next_number(&items)?, notes)?);
                ItemOrigin::Simple { entry }
            }
        };
        origins.resize(origins.len() + items.len() - before, origin);
    }
    Ok(items)
}

/// The number of the next item: one more than the last (the first is 1).
fn next_number(items: &[RawItem]) -> Result<u32, ImportError> {
    u32::try_from(items.len() + 1).map_err(|_| ImportError::TooManyItems {
        at: Place::File,
        limit: u32::MAX as usize,
    })
}

/// The complex items whose stored path aloft flies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ComplexKind {
    Survey,
    CorridorScan,
}

/// A ComplexItem: a survey's or corridor scan's stored items (and a survey's description), or
/// a refusal.
fn complex_item(
    item: &Value,
    items: &mut Vec<RawItem>,
    notes: &mut Notes,
    surveys: &mut Vec<ImportedSurvey>,
) -> Result<ComplexKind, ImportError> {
    let first_item = next_number(items)?;
    let at = Place::Item(first_item);
    let obj = object(item, at, None, "item")?;
    let kind = flown_kind(obj, at)?;
    let stored = obj
        .get("TransectStyleComplexItem")
        .and_then(Value::as_object)
        .and_then(|t| t.get("Items"))
        .and_then(Value::as_array)
        .ok_or_else(|| missing(at, None, &["TransectStyleComplexItem.Items"]))?;
    for v in stored {
        let number = next_number(items)?;
        let inner = object(
            v,
            Place::Item(number),
            None,
            "TransectStyleComplexItem.Items[]",
        )?;
        items.push(simple_item(inner, number, notes)?);
    }
    if kind == "survey" {
        surveys.push(ImportedSurvey {
            first_item,
            item_count: stored.len(),
            survey: Survey::from_complex_item(item, first_item),
            complex_item: item.clone(),
        });
        return Ok(ComplexKind::Survey);
    }
    Ok(ComplexKind::CorridorScan)
}

/// The `complexItemType` of a complex item whose stored path aloft flies (a survey or corridor
/// scan), else a refusal naming it.
fn flown_kind(obj: &Map<String, Value>, at: Place) -> Result<&str, ImportError> {
    let kind = match obj.get("complexItemType") {
        Some(Value::String(s)) => s.as_str(),
        Some(v) => {
            return Err(bad_key(
                at,
                None,
                "complexItemType",
                v,
                "a complex item type name",
            ))
        }
        None => return Err(missing(at, None, &["complexItemType"])),
    };
    let refused = |reason| ImportError::Refused {
        at,
        what: format!("ComplexItem {kind}"),
        reason,
    };
    match kind {
        "survey" | "CorridorScan" => Ok(kind),
        "StructureScan" => Err(refused(
            "a structure scan stores no flight path (QGroundControl generates it on upload)",
        )),
        "fwLandingPattern" | "vtolLandingPattern" => Err(refused(
            "a fixed-wing or VTOL landing pattern: aloft models multirotors",
        )),
        _ => Err(refused("an unknown complex item: its path cannot be read")),
    }
}

mod item;
pub(crate) use item::{bad_key, missing, short};
use item::{object, simple_item};

#[cfg(test)]
mod tests {
    use aloft_planner::SegmentSpec;
    use serde_json::json;

    use super::*;

    fn item(command: u32, params: serde_json::Value) -> Value {
        json!({"type": "SimpleItem", "command": command, "frame": 3, "params": params, "autoContinue": true})
    }

    fn plan(mission: Value) -> String {
        json!({"fileType": "Plan", "version": 1, "mission": mission}).to_string()
    }

    fn mission(items: Vec<Value>) -> Value {
        json!({
            "version": 2, "firmwareType": 12, "vehicleType": 2, "hoverSpeed": 6,
            "plannedHomePosition": [47.0, 8.0, 400.0], "items": items,
        })
    }

    fn takeoff() -> Value {
        item(22, json!([0, 0, 0, null, 47.0, 8.0, 30]))
    }

    fn err(text: &str) -> String {
        read_plan(text).unwrap_err().to_string()
    }

    #[test]
    fn the_file_type_and_versions_are_checked_naming_the_key() {
        let fence = json!({"fileType": "GeoFence", "mission": {}}).to_string();
        assert_eq!(
            err(&fence),
            "key fileType is \"GeoFence\", not \"Plan\": not a QGroundControl mission plan"
        );
        assert_eq!(
            err(&json!({"mission": {}}).to_string()),
            "file: missing key \"fileType\""
        );
        let mut m = mission(vec![takeoff()]);
        m["version"] = 1.into();
        assert!(err(&plan(m)).starts_with("file: key mission.version is 1: expected 2"));
        let mut m = mission(vec![takeoff()]);
        m.as_object_mut().unwrap().remove("plannedHomePosition");
        assert_eq!(
            err(&plan(m)),
            "file: missing key \"mission.plannedHomePosition\""
        );
        let mut m = mission(vec![takeoff()]);
        m["plannedHomePosition"] = json!([95.0, 8.0, 0.0]);
        assert!(err(&plan(m)).contains("key mission.plannedHomePosition is [95.0,8.0,0.0]"));
        let e = err("{\"fileType\": \"Plan\", \"mission\": ");
        assert!(e.starts_with("not valid JSON at line 1, column"), "{e}");
    }

    #[test]
    fn missing_and_mistyped_item_keys_name_the_item_and_the_key() {
        let mut bare = takeoff();
        for k in ["type", "frame", "autoContinue"] {
            bare.as_object_mut().unwrap().remove(k);
        }
        let e = err(&plan(mission(vec![takeoff(), bare])));
        assert_eq!(
            e,
            "item 2 (command 22 NAV_TAKEOFF): missing keys \"type\", \"frame\", \"autoContinue\""
        );
        let six = item(16, json!([0, 0, 0, 0, 47.0, 8.0]));
        let e = err(&plan(mission(vec![takeoff(), six])));
        assert!(
            e.starts_with("item 2 (command 16 NAV_WAYPOINT): key params is 6 values: expected 7"),
            "{e}"
        );
        let text = item(16, json!([0, "x", 0, 0, 47.0, 8.0, 30]));
        let e = err(&plan(mission(vec![takeoff(), text])));
        assert!(
            e.starts_with("item 2 (command 16 NAV_WAYPOINT): key params[1] is \"x\""),
            "{e}"
        );
        let mut frame = takeoff();
        frame["frame"] = json!("relative");
        let e = err(&plan(mission(vec![frame])));
        assert!(
            e.starts_with("item 1 (command 22 NAV_TAKEOFF): key frame is \"relative\""),
            "{e}"
        );
        let huge = item(16, json!([0, 0, 0, 0, 1e300, 8.0, 30]));
        let e = err(&plan(mission(vec![takeoff(), huge])));
        assert!(
            e.starts_with("item 2 (command 16 NAV_WAYPOINT): param5 (latitude) = 1e300"),
            "{e}"
        );
    }

    #[test]
    fn null_params_are_not_set_and_the_altitude_key_is_never_read() {
        let mut wp = item(16, json!([null, null, null, null, 47.001, 8.0, 30]));
        wp["Altitude"] = 99.into();
        let i = read_plan(&plan(mission(vec![takeoff(), wp]))).unwrap();
        match &i.spec.segments[1] {
            SegmentSpec::Leg {
                altitude_m,
                acceptance_radius_m,
                ..
            } => {
                assert_eq!((*altitude_m, *acceptance_radius_m), (Some(30.0), None));
            }
            s => panic!("{s:?}"),
        }
        assert_eq!(i.spec.segments.len(), 2, "no hold from a null p1");
        assert_eq!(i.spec.default_speed_mps, Some(6.0));
        assert_eq!(i.spec.home.altitude_amsl_m, Some(400.0));
    }

    #[test]
    fn old_item_layouts_are_converted_as_qgroundcontrol_does() {
        // V1: param1..param4 and a coordinate; V2: four params and a coordinate.
        let v1 = json!({"type": "missionItem", "command": 16, "frame": 3, "autoContinue": true,
            "param1": 5, "param2": 0, "param3": 0, "param4": 0, "coordinate": [47.001, 8.0, 30]});
        let v2 = json!({"type": "SimpleItem", "command": 16, "frame": 3, "autoContinue": true,
            "params": [0, 0, 0, 0], "coordinate": [47.002, 8.0, 35]});
        let i = read_plan(&plan(mission(vec![takeoff(), v1, v2]))).unwrap();
        let kinds: Vec<&str> = i.spec.segments.iter().map(SegmentSpec::kind).collect();
        assert_eq!(kinds, ["take-off", "leg", "hover", "leg"]);
        assert_eq!(i.spec.segments[2].item(), Some(2));
        assert_eq!(i.spec.segments[3].item(), Some(3));
    }

    #[test]
    fn surveys_are_flattened_in_sequence_and_path_less_items_refused() {
        let inner = vec![
            item(16, json!([0, 0, 0, null, 47.001, 8.0, 30])),
            item(206, json!([25, 0, 1, 0, 0, 0, 0])),
            item(16, json!([0, 0, 0, null, 47.002, 8.0, 30])),
        ];
        let survey = json!({"type": "ComplexItem", "complexItemType": "survey", "version": 5,
            "TransectStyleComplexItem": {"Items": inner}});
        let rtl = item(20, json!([0, 0, 0, 0, 0, 0, 0]));
        let i = read_plan(&plan(mission(vec![takeoff(), survey, rtl]))).unwrap();
        let items: Vec<Option<u32>> = i.spec.segments.iter().map(SegmentSpec::item).collect();
        assert_eq!(items, [1, 2, 4, 5, 5, 5].map(Some));
        assert_eq!((i.counted.total, i.counted.free), (5, 1));
        for (kind, what) in [
            ("StructureScan", "stores no flight path"),
            ("fwLandingPattern", "landing pattern"),
            ("vtolLandingPattern", "landing pattern"),
            ("somethingNew", "unknown complex item"),
        ] {
            let c = json!({"type": "ComplexItem", "complexItemType": kind});
            let e = err(&plan(mission(vec![takeoff(), c])));
            assert!(
                e.starts_with(&format!("item 2: ComplexItem {kind} is refused")),
                "{e}"
            );
            assert!(e.contains(what), "{e}");
        }
        let old = json!({"type": "ComplexItem", "complexItemType": "survey", "version": 3});
        let e = err(&plan(mission(vec![takeoff(), old])));
        assert_eq!(e, "item 2: missing key \"TransectStyleComplexItem.Items\"");
    }

    #[test]
    fn vtol_vehicles_are_refused_and_a_fixed_wing_planner_vehicle_is_a_warning() {
        let mut m = mission(vec![takeoff()]);
        m["vehicleType"] = 21.into();
        assert!(err(&plan(m))
            .starts_with("file: key mission.vehicleType 21 (a VTOL, MAV_TYPE 19-25) is refused"));
        let mut m = mission(vec![takeoff()]);
        m["vehicleType"] = 1.into();
        let i = read_plan(&plan(m)).unwrap();
        assert!(i.warnings.iter().any(|w| w.contains("vehicleType 1")));
    }

    #[test]
    fn arbitrary_bytes_never_panic() {
        assert_eq!(
            crate::import_bytes(b"QGC WPL 110\n\xff").unwrap_err(),
            ImportError::NotText { offset: 12 }
        );
        for t in [
            "{}",
            "[]",
            "{\"fileType\": 3}",
            "{\"fileType\":\"Plan\",\"mission\":[]}",
            "QGC WPL 110",
        ] {
            let _ = crate::import(t);
        }
    }
}
