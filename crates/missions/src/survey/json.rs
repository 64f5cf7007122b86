//! The survey's description read from its `.plan` complex item (QGroundControl's
//! `SurveyComplexItem::_loadV4V5`, `TransectStyleComplexItem::_load`, `CameraCalc::load` and
//! `QGCMapPolygon::loadFromJson`), every refusal naming the item and the key.

use serde_json::{Map, Value};

use super::{DistanceMode, EntryCorner, Survey, SurveyParams};
use crate::error::{ImportError, Place};
use crate::geo::LatLon;
use crate::plan::{bad_key, missing, short};

/// The complex item's keys this reader needs, below the item.
const INNER: &str = "TransectStyleComplexItem";

impl Survey {
    /// The survey of a `.plan` complex item (`complexItemType` "survey", version 4 or 5) whose
    /// first item has the sequence number `first_item`.
    ///
    /// # Errors
    /// [`ImportError::MissingKey`] and [`ImportError::BadKey`] naming the item and the key
    /// (`TransectStyleComplexItem.CameraCalc.AdjustedFootprintSide`), [`ImportError::Refused`]
    /// for another complex item or version, and the refusals of [`Survey::new`].
    pub fn from_complex_item(item: &Value, first_item: u32) -> Result<Self, ImportError> {
        let at = Place::Item(first_item);
        let obj = object(item, at, "item")?;
        check_kind(obj, at)?;
        let inner = object(required(obj, at, INNER)?, at, INNER)?;
        let camera_key = "TransectStyleComplexItem.CameraCalc";
        let camera = object(required_in(inner, at, "CameraCalc")?, at, camera_key)?;
        let mut params = SurveyParams {
            first_item,
            polygon: polygon(required(obj, at, "polygon")?, at)?,
            angle_deg: number(obj, at, "", "angle")?,
            entry: entry(obj, at)?,
            fly_alternate_transects: optional_bool(obj, at, "", "flyAlternateTransects")?,
            ..SurveyParams::default()
        };
        read_transect_style(inner, at, &mut params)?;
        read_camera(camera, at, &mut params)?;
        Survey::new(params)
    }
}

/// `type` "ComplexItem", `complexItemType` "survey", `version` 4 or 5.
fn check_kind(obj: &Map<String, Value>, at: Place) -> Result<(), ImportError> {
    let kind = obj.get("complexItemType").and_then(Value::as_str);
    if kind != Some("survey") {
        return Err(ImportError::Refused {
            at,
            what: format!(
                "complexItemType {}",
                obj.get("complexItemType").map_or("missing".into(), short)
            ),
            reason: "not a survey",
        });
    }
    match obj.get("version").and_then(Value::as_u64) {
        Some(4 | 5) => Ok(()),
        _ => Err(ImportError::Refused {
            at,
            what: format!(
                "survey version {}",
                obj.get("version").map_or("missing".into(), short)
            ),
            reason: "only versions 4 and 5 store the survey this way (QGroundControl converts older ones when it saves the plan again)",
        }),
    }
}

/// `TurnAroundDistance`, `CameraTriggerInTurnAround`, `HoverAndCapture`, `Refly90Degrees`.
fn read_transect_style(
    inner: &Map<String, Value>,
    at: Place,
    p: &mut SurveyParams,
) -> Result<(), ImportError> {
    let prefix = "TransectStyleComplexItem.";
    p.turnaround_m = number(inner, at, prefix, "TurnAroundDistance")?;
    p.camera_in_turnaround = boolean(inner, at, prefix, "CameraTriggerInTurnAround")?;
    p.hover_and_capture = boolean(inner, at, prefix, "HoverAndCapture")?;
    p.refly_90 = boolean(inner, at, prefix, "Refly90Degrees")?;
    // Version 1 of the inner object: terrain following was a flag of its own.
    if optional_bool(inner, at, prefix, "FollowTerrain")? {
        p.altitude_mode = DistanceMode::CalcAboveTerrain;
    }
    Ok(())
}

/// `DistanceToSurface`, `DistanceMode` (or version 1's `DistanceToSurfaceRelative`),
/// `AdjustedFootprintSide`, `AdjustedFootprintFrontal`, `MinTriggerInterval`.
fn read_camera(
    camera: &Map<String, Value>,
    at: Place,
    p: &mut SurveyParams,
) -> Result<(), ImportError> {
    let prefix = "TransectStyleComplexItem.CameraCalc.";
    p.altitude_m = number(camera, at, prefix, "DistanceToSurface")?;
    p.spacing_m = number(camera, at, prefix, "AdjustedFootprintSide")?;
    p.trigger_distance_m = number(camera, at, prefix, "AdjustedFootprintFrontal")?;
    p.min_trigger_interval_s = match camera.get("MinTriggerInterval") {
        None => None,
        Some(_) => Some(number(camera, at, prefix, "MinTriggerInterval")?),
    };
    if p.altitude_mode == DistanceMode::CalcAboveTerrain {
        return Ok(());
    }
    p.altitude_mode = match camera.get("DistanceMode") {
        Some(v) => v
            .as_u64()
            .and_then(DistanceMode::from_index)
            .ok_or_else(|| {
                let key = format!("{prefix}DistanceMode");
                bad_key(
                    at,
                    None,
                    &key,
                    v,
                    "1 (relative), 2 (AMSL), 3 (calculated above terrain) or 4 (terrain frame)",
                )
            })?,
        None if camera.contains_key("DistanceToSurfaceRelative") => {
            let relative = boolean(camera, at, prefix, "DistanceToSurfaceRelative")?;
            if relative {
                DistanceMode::Relative
            } else {
                DistanceMode::Amsl
            }
        }
        None => {
            return Err(missing(
                at,
                None,
                &["TransectStyleComplexItem.CameraCalc.DistanceMode"],
            ))
        }
    };
    Ok(())
}

/// `polygon`: `[[lat, lon], ...]` (numbers; validated by [`Survey::new`]).
fn polygon(v: &Value, at: Place) -> Result<Vec<LatLon>, ImportError> {
    let expected = "an array of [latitude, longitude] in degrees";
    let list = v
        .as_array()
        .ok_or_else(|| bad_key(at, None, "polygon", v, expected))?;
    list.iter()
        .enumerate()
        .map(|(k, q)| {
            let pair = q.as_array().filter(|a| a.len() >= 2);
            match pair.map(|a| (a[0].as_f64(), a[1].as_f64())) {
                Some((Some(latitude_deg), Some(longitude_deg))) => Ok(LatLon {
                    latitude_deg,
                    longitude_deg,
                }),
                _ => Err(bad_key(
                    at,
                    None,
                    &format!("polygon[{k}]"),
                    q,
                    "[latitude, longitude] in degrees",
                )),
            }
        })
        .collect()
}

/// `entryLocation`: 0-3.
fn entry(obj: &Map<String, Value>, at: Place) -> Result<EntryCorner, ImportError> {
    let v = required(obj, at, "entryLocation")?;
    v.as_u64().and_then(EntryCorner::from_index).ok_or_else(|| {
        bad_key(
            at,
            None,
            "entryLocation",
            v,
            "0 (top left), 1 (top right), 2 (bottom left) or 3 (bottom right)",
        )
    })
}

/// The value of a key that must be there.
fn required<'a>(
    obj: &'a Map<String, Value>,
    at: Place,
    key: &str,
) -> Result<&'a Value, ImportError> {
    obj.get(key).ok_or_else(|| missing(at, None, &[key]))
}

/// The value of a key of `TransectStyleComplexItem` that must be there.
fn required_in<'a>(
    inner: &'a Map<String, Value>,
    at: Place,
    key: &str,
) -> Result<&'a Value, ImportError> {
    inner
        .get(key)
        .ok_or_else(|| missing(at, None, &[format!("{INNER}.{key}").as_str()]))
}

/// `v` as an object.
fn object<'a>(v: &'a Value, at: Place, key: &str) -> Result<&'a Map<String, Value>, ImportError> {
    v.as_object()
        .ok_or_else(|| bad_key(at, None, key, v, "a JSON object"))
}

/// A number that must be there; `prefix` names the object in messages.
fn number(
    obj: &Map<String, Value>,
    at: Place,
    prefix: &str,
    key: &str,
) -> Result<f64, ImportError> {
    read_key(obj, (at, prefix, key), Value::as_f64, "a number")
}

/// A boolean that must be there.
fn boolean(
    obj: &Map<String, Value>,
    at: Place,
    prefix: &str,
    key: &str,
) -> Result<bool, ImportError> {
    read_key(obj, (at, prefix, key), Value::as_bool, "true or false")
}

/// The value of `key` read by `read` (`what` it must be), which must be there.
fn read_key<T>(
    obj: &Map<String, Value>,
    (at, prefix, key): (Place, &str, &str),
    read: fn(&Value) -> Option<T>,
    what: &'static str,
) -> Result<T, ImportError> {
    let full = format!("{prefix}{key}");
    let v = obj
        .get(key)
        .ok_or_else(|| missing(at, None, &[full.as_str()]))?;
    read(v).ok_or_else(|| bad_key(at, None, &full, v, what))
}

/// A boolean that may be absent (false).
fn optional_bool(
    obj: &Map<String, Value>,
    at: Place,
    prefix: &str,
    key: &str,
) -> Result<bool, ImportError> {
    match obj.get(key) {
        None => Ok(false),
        Some(_) => boolean(obj, at, prefix, key),
    }
}
