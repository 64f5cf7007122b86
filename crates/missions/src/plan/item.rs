//! One SimpleItem of a `.plan`, its older layouts converted (QGroundControl's
//! `MissionItem::_convertJsonV1ToV2` and `_convertJsonV2ToV3`), and the JSON helpers of the reader.

use serde_json::{Map, Value};

use super::SIMPLE_KEYS;
use crate::error::{ImportError, Place};
use crate::notes::Notes;
use crate::raw_item::RawItem;

/// The SimpleItem `obj`, numbered `number`.
pub(super) fn simple_item(
    obj: &Map<String, Value>,
    number: u32,
    notes: &mut Notes,
) -> Result<RawItem, ImportError> {
    let at = Place::Item(number);
    let command = obj.get("command").and_then(Value::as_u64);
    let command = command.and_then(|c| u32::try_from(c).ok());
    let absent = absent_keys(obj);
    if !absent.is_empty() {
        return Err(missing(at, command, &absent));
    }
    match obj.get("type").and_then(Value::as_str) {
        Some("SimpleItem" | "missionItem") => {}
        _ => {
            let v = &obj["type"];
            return Err(bad_key(
                at,
                command,
                "type",
                v,
                "\"SimpleItem\" or \"ComplexItem\"",
            ));
        }
    }
    let Some(command) = command else {
        let v = &obj["command"];
        return Err(bad_key(at, None, "command", v, "a MAV_CMD number"));
    };
    let frame = obj["frame"]
        .as_u64()
        .and_then(|f| u32::try_from(f).ok())
        .ok_or_else(|| {
            bad_key(
                at,
                Some(command),
                "frame",
                &obj["frame"],
                "a MAV_FRAME number",
            )
        })?;
    match obj["autoContinue"].as_bool() {
        Some(true) => {}
        Some(false) => notes.add(
            at,
            "autoContinue false: the vehicle waits there for the operator (not modelled)",
        ),
        None => {
            let v = &obj["autoContinue"];
            return Err(bad_key(
                at,
                Some(command),
                "autoContinue",
                v,
                "true or false",
            ));
        }
    }
    let params = params(obj, at, command)?;
    let jump_id = match obj.get("doJumpId") {
        None | Some(Value::Null) => None,
        Some(v) => Some(
            v.as_i64()
                .ok_or_else(|| bad_key(at, Some(command), "doJumpId", v, "an integer"))?,
        ),
    };
    Ok(RawItem {
        at,
        number,
        command,
        frame,
        params,
        jump_id,
    })
}

/// The keys a SimpleItem lacks: [`SIMPLE_KEYS`], and `params` (or the V1 layout's
/// `param1`..`param4`).
fn absent_keys(obj: &Map<String, Value>) -> Vec<&'static str> {
    let mut absent: Vec<&str> = SIMPLE_KEYS
        .iter()
        .copied()
        .filter(|k| !obj.contains_key(*k))
        .collect();
    if !obj.contains_key("params") {
        let v1 = ["param1", "param2", "param3", "param4"];
        if v1.iter().any(|k| obj.contains_key(*k)) {
            absent.extend(v1.into_iter().filter(|k| !obj.contains_key(*k)));
        } else {
            // Neither layout: name the current one.
            absent.push("params");
        }
    }
    absent
}

/// The seven parameters: `params` (7 values, or 4 with a V2 `coordinate`), or the V1 keys
/// `param1`..`param4` with a `coordinate`; `null` is "not set" (NaN).
fn params(obj: &Map<String, Value>, at: Place, command: u32) -> Result<[f64; 7], ImportError> {
    let mut values: Vec<(String, &Value)> = match obj.get("params") {
        Some(Value::Array(a)) => a
            .iter()
            .enumerate()
            .map(|(k, v)| (format!("params[{k}]"), v))
            .collect(),
        Some(v) => {
            return Err(bad_key(
                at,
                Some(command),
                "params",
                v,
                "an array of 7 numbers or null",
            ))
        }
        None => (1..=4)
            .map(|k| (format!("param{k}"), &obj[&format!("param{k}")]))
            .collect(),
    };
    if let Some(c) = obj.get("coordinate") {
        let coordinate = c.as_array().filter(|a| a.len() == 3).ok_or_else(|| {
            bad_key(
                at,
                Some(command),
                "coordinate",
                c,
                "[latitude, longitude, altitude]",
            )
        })?;
        values.extend(
            coordinate
                .iter()
                .enumerate()
                .map(|(k, v)| (format!("coordinate[{k}]"), v)),
        );
    }
    if values.len() != 7 {
        return Err(ImportError::BadKey {
            at,
            command: Some(command),
            key: "params".into(),
            found: format!("{} values", values.len()),
            expected: "7 values (4 with a coordinate of 3 in the older layout)",
        });
    }
    let mut out = [f64::NAN; 7];
    for (slot, (key, v)) in out.iter_mut().zip(&values) {
        *slot = match v {
            Value::Null => f64::NAN,
            Value::Number(n) => n.as_f64().unwrap_or(f64::NAN),
            other => return Err(bad_key(at, Some(command), key, other, "a number or null")),
        };
    }
    Ok(out)
}

/// `v` as an object, else an error naming `key`.
pub(super) fn object<'a>(
    v: &'a Value,
    at: Place,
    command: Option<u32>,
    key: &str,
) -> Result<&'a Map<String, Value>, ImportError> {
    v.as_object()
        .ok_or_else(|| bad_key(at, command, key, v, "a JSON object"))
}

/// Keys missing at `at`.
pub(crate) fn missing(at: Place, command: Option<u32>, keys: &[&str]) -> ImportError {
    let quoted: Vec<String> = keys.iter().map(|k| format!("\"{k}\"")).collect();
    let word = if keys.len() == 1 { "key" } else { "keys" };
    ImportError::MissingKey {
        at,
        command,
        keys: format!("{word} {}", quoted.join(", ")),
    }
}

/// A key whose value is not what is expected.
pub(crate) fn bad_key(
    at: Place,
    command: Option<u32>,
    key: &str,
    found: &Value,
    expected: &'static str,
) -> ImportError {
    ImportError::BadKey {
        at,
        command,
        key: key.to_string(),
        found: short(found),
        expected,
    }
}

/// A value as JSON, at most 60 characters.
pub(crate) fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() <= 60 {
        s
    } else {
        let mut t: String = s.chars().take(57).collect();
        t.push_str("...");
        t
    }
}
