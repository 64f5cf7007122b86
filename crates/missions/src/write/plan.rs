//! The `.plan` writer (the rules are in the module's docs).

use aloft_logs::telemetry::MissionItem;
use serde::Serialize;
use serde_json::{json, Map, Value};

use super::{check_home, check_item, MissionEntry};
use crate::error::{ImportError, Place};
use crate::kept::{Home, PlanHeader};
use crate::plan::short;
use crate::survey::number_json;
use crate::Airspace;

/// What the file says wrote it.
const GROUND_STATION: &str = "aloft";

/// A QGroundControl `.plan` of `entries`, with `header`'s mission keys, `home` as
/// `plannedHomePosition` and `airspace`'s geofence and rally points as the file gave them.
///
/// # Errors
/// The refusals of the module's docs (naming the item by its `seq`), a `cruiseSpeed` or
/// `hoverSpeed` that is not a positive finite number, and a survey entry that is not a survey
/// complex item with its stored items (naming the sequence number it would start at).
pub fn write_plan(
    header: &PlanHeader,
    home: &Home,
    entries: &[MissionEntry],
    airspace: &Airspace,
) -> Result<String, ImportError> {
    check_home(home, false)?;
    let mut items = Vec::with_capacity(entries.len());
    let mut next: u32 = 1;
    for entry in entries {
        match entry {
            MissionEntry::Item(item) => {
                check_item(item)?;
                items.push(simple_item(item, next));
                next = next.saturating_add(1);
            }
            MissionEntry::Survey(survey) => {
                let stored = stored_items(survey, next)?;
                items.push(survey.clone());
                next = next.saturating_add(stored);
            }
        }
    }
    let root = json!({
        "fileType": "Plan",
        "version": 1,
        "groundStation": GROUND_STATION,
        "mission": mission(header, home, items)?,
        "geoFence": airspace.geo_fence_json(),
        "rallyPoints": airspace.rally_points_json(),
    });
    Ok(pretty(&root))
}

/// The `mission` object.
fn mission(header: &PlanHeader, home: &Home, items: Vec<Value>) -> Result<Value, ImportError> {
    let mut m = Map::new();
    m.insert("version".into(), 2.into());
    m.insert(
        "firmwareType".into(),
        header.firmware_type.unwrap_or(0).into(),
    );
    if let Some(t) = header.vehicle_type {
        m.insert("vehicleType".into(), t.into());
    }
    for (key, speed) in [
        ("cruiseSpeed", header.cruise_speed_mps),
        ("hoverSpeed", header.hover_speed_mps),
    ] {
        if let Some(v) = speed {
            if !(v.is_finite() && v > 0.0) {
                return Err(ImportError::BadKey {
                    at: Place::File,
                    command: None,
                    key: format!("mission.{key}"),
                    found: aloft_core::Num(v).to_string(),
                    expected: "a speed in m/s, positive and finite",
                });
            }
            m.insert(key.into(), number_json(v));
        }
    }
    if let Some(mode) = header.global_plan_altitude_mode {
        m.insert("globalPlanAltitudeMode".into(), mode.into());
    }
    let altitude = home.altitude_amsl_m.map_or(Value::Null, number_json);
    m.insert(
        "plannedHomePosition".into(),
        json!([
            number_json(home.latitude_deg),
            number_json(home.longitude_deg),
            altitude
        ]),
    );
    m.insert("items".into(), Value::Array(items));
    Ok(Value::Object(m))
}

/// A SimpleItem as QGroundControl saves it, `doJumpId` its sequence number.
fn simple_item(item: &MissionItem, number: u32) -> Value {
    let params: Vec<Value> = item.params.iter().map(|v| number_json(*v)).collect();
    json!({
        "type": "SimpleItem",
        "command": item.command,
        "frame": item.frame,
        "params": params,
        "autoContinue": true,
        "doJumpId": number,
    })
}

/// How many items a survey complex item stores (`TransectStyleComplexItem.Items`); `first` is
/// the sequence number of the first, for the error.
fn stored_items(survey: &Value, first: u32) -> Result<u32, ImportError> {
    let is_survey = survey.get("type").and_then(Value::as_str) == Some("ComplexItem")
        && survey.get("complexItemType").and_then(Value::as_str) == Some("survey");
    let stored = survey
        .get("TransectStyleComplexItem")
        .and_then(|t| t.get("Items"))
        .and_then(Value::as_array)
        .filter(|_| is_survey);
    match stored {
        Some(items) => Ok(u32::try_from(items.len()).unwrap_or(u32::MAX)),
        None => Err(ImportError::BadKey {
            at: Place::Item(first),
            command: None,
            key: "(survey entry)".into(),
            found: short(survey),
            expected: "a survey complex item (type ComplexItem, complexItemType survey) with its TransectStyleComplexItem.Items",
        }),
    }
}

/// JSON indented by four spaces, as QGroundControl writes it, with a final line end.
fn pretty(root: &Value) -> String {
    let mut out = Vec::new();
    let formatter = serde_json::ser::PrettyFormatter::with_indent(b"    ");
    let mut ser = serde_json::Serializer::with_formatter(&mut out, formatter);
    root.serialize(&mut ser)
        .expect("a JSON value serialises into memory");
    let mut text = String::from_utf8(out).expect("serde_json writes UTF-8");
    text.push('\n');
    text
}
