//! Writers of the planner formats: QGroundControl `.plan` ([`write_plan`]) and Mission Planner
//! `.waypoints` ([`write_waypoints`]), and [`write_like_source`], which writes a file read by
//! [`crate::import`] back in its own format.
//!
//! Sans-I/O like the readers: they return the text; writing it to a file (a temporary name in
//! the same folder, then a rename) is the caller's job. What they write is read back by aloft's
//! readers, by MAVSDK's QGroundControl importer and by pymavlink's `mavwp` (the tests
//! `tests/it/missions_writers.rs` and `crates/missions/tests/writers_data_val.rs`).
//!
//! Sources of the rules: the project's research notes `research/writing-plans.md` (section 1a:
//! what QGroundControl's loader and MAVSDK's importer require of a `.plan`; 1e: surveys; 5: the
//! MAVLink encodings and the QGC WPL 110 format), QGroundControl's `MissionController`,
//! `MissionItem::load` and `SimpleMissionItem::load`, MAVSDK's
//! `src/mavsdk/plugins/mission_raw/mission_import.cpp`, pymavlink's `mavwp.py`
//! (`_read_waypoints_v110`, `save`) and Mission Planner's `GCSViews/FlightPlanner.cs`
//! (`savewaypoints`).
//!
//! ## `.plan` (JSON)
//! `fileType` "Plan", `version` 1, `groundStation` "aloft"; `mission` with `version` 2,
//! `firmwareType` (0, MAV_AUTOPILOT_GENERIC, when the header has none: QGroundControl requires
//! the key), `vehicleType`, `cruiseSpeed`, `hoverSpeed` and `globalPlanAltitudeMode` where the
//! header has them, `plannedHomePosition` `[lat, lon, alt AMSL]` (`null` for an altitude the
//! home has not) and `items`; the read file's `geoFence` and `rallyPoints` as it gave them
//! ([`crate::Airspace`]), else `{"version": 2, "circles": [], "polygons": []}` and
//! `{"version": 2, "points": []}` (MAVSDK refuses a file without them, and QGroundControl a
//! `rallyPoints` without `version`). Each item is a SimpleItem: `type`,
//! `command`, `frame`, `params` (exactly 7, NaN written `null`), `autoContinue` true and
//! `doJumpId` its MAVLink sequence number (the first item 1, a survey's stored items counted),
//! as QGroundControl saves it; the `Altitude`, `AltitudeMode` and `AMSLAltAboveTerrain` hints are
//! not written (QGroundControl derives the mode from `frame`). A survey complex item
//! ([`MissionEntry::Survey`]) is written verbatim: it must hold its items in
//! `TransectStyleComplexItem.Items` (they take the sequence numbers that follow), and MAVSDK
//! reads only its version 5, which [`crate::survey::reangle_survey_item`] writes.
//!
//! Numbers: serde_json's shortest decimal that reads back as the same `f64` (whole values below
//! 2^53 as integers, as Qt writes them), so every value, latitude and longitude included, reads
//! back to the last bit.
//!
//! ## `.waypoints` (QGC WPL 110)
//! Line 1 `QGC WPL 110`; row 0 the home, `0 1 0 16 0 0 0 0 lat lon amsl 1` (as Mission Planner
//! writes it); then one row per item, 12 tab-separated fields: INDEX (from 1, in order),
//! CURRENT 0, FRAME, COMMAND, P1-P4, LAT, LON, ALT, AUTOCONTINUE 1; `\n` line ends. Numbers are
//! Rust's shortest decimal that reads back as the same `f64` (no exponent), to the last bit
//! again.
//!
//! A parameter that is not set (NaN):
//! - P1-P4 are written `NaN`, as Mission Planner writes a NaN (`double.ToString("0.00000000",
//!   en-US)`) and reads it (`double.Parse`); pymavlink writes `nan` and reads either
//!   (`float()`), and aloft's reader reads either as "not set". Writing 0 instead would change
//!   the meaning: a NAV_WAYPOINT's yaw 0 is north, NaN "as the autopilot's yaw mode says".
//! - LAT, LON and ALT of an item without a position (a camera or speed item) are written 0:
//!   MISSION_ITEM_INT carries latitude and longitude as integers, where "not set" is 0 (MAVSDK's
//!   importer also turns a `.plan`'s `null` into 0), and aloft's reader, like Mission Planner's,
//!   wants numbers there.
//!
//! A survey complex item is refused: the caller flattens it (its stored items).
//!
//! ## Refused by both
//! - DO_JUMP (177): the callers write jump-free missions, and a jump's target (a `doJumpId` in a
//!   `.plan`, a row in a `.waypoints` file) would have to be renumbered with the items;
//! - a parameter that is infinite (neither format can hold it);
//! - a position item (NAV_WAYPOINT, TAKEOFF, LAND, the loiters, SPLINE_WAYPOINT) whose latitude,
//!   longitude or altitude is NaN ("NaN coordinates": what an unset position means differs between
//!   autopilots and encodings, MAVSDK turns it into latitude 0, longitude 0), or out of range (a
//!   latitude within (-90, 90), a longitude within [-180, 180], an altitude within 1e6 m, as the
//!   readers take them);
//! - a home whose latitude or longitude is NaN or out of range, or whose altitude is not finite
//!   (a `.waypoints` home row must have one).
//!
//! Errors name the item by the `seq` the caller gave it ([`crate::Place::Item`]).

mod plan;
mod wpl;

use aloft_logs::telemetry::MissionItem;

use crate::commands::{CommandName, DO_JUMP};
use crate::error::{ImportError, Place};
use crate::items::{check_params, has_position};
use crate::kept::{Home, ItemOrigin};
use crate::raw_item::RawItem;
use crate::{Imported, SourceFormat};

pub use plan::write_plan;
pub use wpl::{write_waypoint_rows, write_waypoints};

/// One entry of a mission to write.
#[derive(Debug, Clone, PartialEq)]
pub enum MissionEntry {
    /// A mission item: a `.plan` SimpleItem, a `.waypoints` row. Its `seq` names it in errors;
    /// the writers number the items in order.
    Item(MissionItem),
    /// A `.plan` survey complex item, written verbatim (as [`crate::survey::ImportedSurvey`]
    /// keeps it, or [`crate::survey::reangle_survey_item`] makes it); refused in a
    /// `.waypoints` file.
    Survey(serde_json::Value),
}

/// The file `imported` was read from, written again in its format with its own items: a `.plan`
/// with its header, home, items and surveys (verbatim; a corridor scan's stored items are
/// written as SimpleItems, as MAVSDK reads no corridor scan), its geofence and rally points as
/// given; a `.waypoints` file (or a link's
/// items) with its home row when it had one, its items numbered in order. Reading the text
/// gives the same mission spec and route figures, but for a `.waypoints` file whose INDEX
/// column did not count up by one (numbered in order now, its warning gone).
///
/// # Errors
/// [`ImportError::UnknownFormat`] for an `Imported` of aloft's own formats, and the writers'
/// refusals (a DO_JUMP, a position not set: see the module's docs).
pub fn write_like_source(imported: &Imported) -> Result<String, ImportError> {
    match (imported.format, &imported.plan) {
        (SourceFormat::QgcPlan, Some(plan)) => {
            let home = imported.home.ok_or(ImportError::NoHome {
                at: Place::File,
                hint: "a .plan is written with its plannedHomePosition",
            })?;
            write_plan(
                &plan.header,
                &home,
                &plan_entries(imported, &[])?,
                &plan.airspace,
            )
        }
        (SourceFormat::QgcWpl | SourceFormat::MavlinkItems, _) => {
            let entries: Vec<MissionEntry> = imported
                .items
                .iter()
                .map(|i| MissionEntry::Item(*i))
                .collect();
            wpl::write_waypoint_rows(imported.home.as_ref(), &entries)
        }
        _ => Err(ImportError::UnknownFormat),
    }
}

/// The entries of the `.plan` read as `imported`, in file order: its SimpleItems (a corridor
/// scan's stored items among them), and each survey once, where its first item was: its complex
/// item as read, or regenerated at the grid angle `angles` gives it (pairs of an index in
/// [`Imported::surveys`] and an angle in degrees, with [`crate::survey::reangle_survey_item`]
/// in QGroundControl's default projection). No entries for a file that is not a `.plan`.
///
/// # Errors
/// The errors of [`crate::survey::reangle_survey_item`] for a survey given an angle.
pub fn plan_entries(
    imported: &Imported,
    angles: &[(usize, f64)],
) -> Result<Vec<MissionEntry>, ImportError> {
    let Some(plan) = &imported.plan else {
        return Ok(Vec::new());
    };
    let mut entries = Vec::with_capacity(imported.items.len());
    let mut last_survey = None;
    for (item, origin) in imported.items.iter().zip(&plan.origins) {
        match *origin {
            ItemOrigin::Survey { survey, .. } => {
                if last_survey != Some(survey) {
                    let read = &imported.surveys[survey];
                    let json = match angles.iter().find(|(s, _)| *s == survey) {
                        Some(&(_, angle)) => crate::survey::reangle_survey_item(
                            &read.complex_item,
                            angle,
                            read.first_item,
                            crate::survey::QgcProjection::default(),
                        )?,
                        None => read.complex_item.clone(),
                    };
                    entries.push(MissionEntry::Survey(json));
                    last_survey = Some(survey);
                }
            }
            ItemOrigin::Simple { .. } | ItemOrigin::CorridorScan { .. } => {
                entries.push(MissionEntry::Item(*item));
            }
        }
    }
    Ok(entries)
}

/// An item both formats can hold: no DO_JUMP, parameters finite or NaN, a position item's
/// coordinates set and in range.
fn check_item(item: &MissionItem) -> Result<(), ImportError> {
    let at = Place::Item(item.seq);
    if item.command == DO_JUMP {
        return Err(ImportError::Refused {
            at,
            what: CommandName(DO_JUMP).to_string(),
            reason: "the writers write jump-free missions (a jump's target would be renumbered with the items)",
        });
    }
    let raw = RawItem {
        at,
        number: item.seq,
        command: item.command,
        frame: item.frame,
        params: item.params,
        jump_id: None,
    };
    check_params(&raw)?;
    if has_position(item.command) {
        const KEYS: [&str; 3] = [
            "param5 (latitude)",
            "param6 (longitude)",
            "param7 (altitude)",
        ];
        for (key, value) in KEYS.into_iter().zip(&item.params[4..]) {
            if value.is_nan() {
                return Err(ImportError::BadValue {
                    at,
                    command: item.command,
                    key,
                    value: *value,
                    expected: "a number: a position item is written with its latitude, longitude and altitude (0, 0 for \"here\")",
                });
            }
        }
    }
    Ok(())
}

/// A home either format can hold: latitude within (-90, 90), longitude within [-180, 180],
/// altitude within 1e6 m, as the readers take them; `altitude_required` for a `.waypoints` home
/// row.
fn check_home(home: &Home, altitude_required: bool) -> Result<(), ImportError> {
    let bad = |what, value, expected| ImportError::BadHome {
        what,
        value,
        expected,
    };
    // Written so that NaN is refused too.
    if home.latitude_deg.is_nan() || home.latitude_deg.abs() >= 90.0 {
        return Err(bad(
            "latitude",
            home.latitude_deg,
            "a latitude within (-90, 90) degrees",
        ));
    }
    if home.longitude_deg.is_nan() || home.longitude_deg.abs() > 180.0 {
        return Err(bad(
            "longitude",
            home.longitude_deg,
            "a longitude within [-180, 180] degrees",
        ));
    }
    match home.altitude_amsl_m {
        Some(h) if h.is_nan() || h.abs() > 1e6 => Err(bad(
            "altitude above mean sea level",
            h,
            "an altitude within 1e6 m",
        )),
        None if altitude_required => Err(bad(
            "altitude above mean sea level",
            f64::NAN,
            "an altitude: a .waypoints home row has one",
        )),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests;
