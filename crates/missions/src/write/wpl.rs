//! The `.waypoints` writer (the rules are in the module's docs).

use std::fmt::Write as _;

use aloft_logs::telemetry::MissionItem;

use super::{check_home, check_item, MissionEntry};
use crate::error::{ImportError, Place};
use crate::items::has_position;
use crate::kept::Home;

/// A Mission Planner `.waypoints` file ("QGC WPL 110") of `entries`, `home` its row 0.
///
/// # Errors
/// The refusals of the module's docs, naming the item by its `seq`: a DO_JUMP, a position not
/// set, an infinite value; a survey entry (named by the row it would take); a home without an
/// altitude or out of range.
pub fn write_waypoints(home: &Home, entries: &[MissionEntry]) -> Result<String, ImportError> {
    write_waypoint_rows(Some(home), entries)
}

/// A `.waypoints` file of `entries` with `home` as its row 0 when there is one (the items from
/// INDEX 1), else the items from INDEX 0: a file read without a home row, written as it was (its
/// home is the first position in it).
///
/// # Errors
/// As [`write_waypoints`].
pub fn write_waypoint_rows(
    home: Option<&Home>,
    entries: &[MissionEntry],
) -> Result<String, ImportError> {
    let mut out = String::from("QGC WPL 110\n");
    let mut index: u32 = 0;
    if let Some(h) = home {
        check_home(h, true)?;
        let amsl = h.altitude_amsl_m.unwrap_or(0.0);
        let (lat, lon) = (h.latitude_deg, h.longitude_deg);
        // Infallible: writing to a String.
        let _ = writeln!(out, "0\t1\t0\t16\t0\t0\t0\t0\t{lat}\t{lon}\t{amsl}\t1");
        index = 1;
    }
    for entry in entries {
        match entry {
            MissionEntry::Item(item) => {
                check_item(item)?;
                out.push_str(&row(index, item));
            }
            MissionEntry::Survey(_) => {
                return Err(ImportError::Refused {
                    at: Place::Item(index),
                    what: "ComplexItem survey".into(),
                    reason: "a .waypoints file holds mission items only: write the survey's stored items (TransectStyleComplexItem.Items) instead",
                })
            }
        }
        index = index.saturating_add(1);
    }
    Ok(out)
}

/// One item's row, INDEX `index`.
fn row(index: u32, item: &MissionItem) -> String {
    let p = &item.params;
    let position = has_position(item.command);
    let mut fields = vec![
        index.to_string(),
        "0".into(),
        item.frame.to_string(),
        item.command.to_string(),
    ];
    fields.extend(p[..4].iter().map(|v| number(*v, "NaN")));
    // Not set on an item without a position: 0 (a position item's are checked to be set).
    fields.extend(
        p[4..]
            .iter()
            .map(|v| number(*v, if position { "NaN" } else { "0" })),
    );
    fields.push("1".into());
    let mut line = fields.join("\t");
    line.push('\n');
    line
}

/// `v` as the shortest decimal that reads back to the last bit, `nan` when it is NaN.
fn number(v: f64, nan: &str) -> String {
    if v.is_nan() {
        nan.to_string()
    } else {
        v.to_string()
    }
}
