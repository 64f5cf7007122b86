//! The Mission Planner / ArduPilot `.waypoints` reader ("QGC WPL 110").
//!
//! A first line `QGC WPL 110`, then one item per line: 12 tab-separated fields
//! `INDEX CURRENT FRAME COMMAND P1 P2 P3 P4 LAT LON ALT AUTOCONTINUE` (QGroundControl's
//! `MissionItem::load(QTextStream&)` and ArduPilot's `AP_Mission` text format). CRLF line ends,
//! trailing blank space and blank lines are tolerated; a line whose fields are separated by
//! spaces instead of tabs is read when it has 12 of them. P1-P4 may be `NaN` (or `nan`): MAVLink's
//! "not set", as a `.plan`'s `null` (Mission Planner writes a NaN parameter so, pymavlink as
//! `nan`); LAT, LON and ALT must be finite numbers.
//!
//! Row 0 is the home position (AMSL altitude) when it is a home row: INDEX 0, NAV_WAYPOINT (16),
//! frame 0. A script-written file whose row 0 is something else (a take-off) keeps it as a
//! mission item; its home is then the first position in the file (warned), and an AMSL altitude
//! in it is refused (there is no home altitude to measure it against). Items are numbered by
//! their INDEX; a DO_JUMP's target is a row INDEX. The semantics are ArduPilot's (latitude and
//! longitude 0, and altitude 0, mean "here").

use crate::error::{ImportError, Place};
use crate::geo::LatLon;
use crate::items::{translate, Autopilot, ReadOptions, Source};
use crate::jumps::JumpsBy;
use crate::kept::Home;
use crate::notes::Notes;
use crate::raw_item::RawItem;
use crate::{assemble, Imported, SourceFormat};

/// ArduPilot's default waypoint speed (`WPNAV_SPEED`, 1000 cm/s), m/s: the planning speed of a
/// `.waypoints` file, which holds none.
const ARDUPILOT_WPNAV_SPEED_MPS: f64 = 10.0;

/// Column names, for messages.
const FIELDS: [&str; 12] = [
    "INDEX",
    "CURRENT",
    "FRAME",
    "COMMAND",
    "P1",
    "P2",
    "P3",
    "P4",
    "LAT",
    "LON",
    "ALT",
    "AUTOCONTINUE",
];

/// Read a `.waypoints` file.
///
/// # Errors
/// A header other than `QGC WPL 110`, a line without 12 fields, a field that is not a finite
/// number (naming the line and the column; P1-P4 may also be `NaN`, "not set"), no home
/// position, and the errors of the items' semantics (see the crate's docs).
pub fn read_waypoints(text: &str) -> Result<Imported, ImportError> {
    read_waypoints_with(text, ReadOptions::default())
}

/// [`read_waypoints`] with `options`.
///
/// # Errors
/// As [`read_waypoints`].
pub fn read_waypoints_with(text: &str, options: ReadOptions) -> Result<Imported, ImportError> {
    let text = text.trim_start_matches('\u{feff}');
    let mut lines = text.lines().enumerate();
    let header = lines.next().map_or("", |(_, l)| l.trim());
    if header != "QGC WPL 110" {
        let version = header
            .strip_prefix("QGC WPL")
            .map(str::trim)
            .filter(|v| {
                (1..=8).contains(&v.len()) && v.bytes().all(|b| b.is_ascii_digit() || b == b'.')
            })
            .map(str::to_string);
        return Err(ImportError::BadHeader { version });
    }
    let mut rows = Vec::new();
    for (k, line) in lines {
        if !line.trim().is_empty() {
            rows.push(row(k + 1, line)?);
        }
    }
    from_rows(rows, SourceFormat::QgcWpl, "QGC WPL 110 waypoints", options)
}

/// Read a mission as a MAVLink link or log carries it (MISSION_ITEM_INT, DataFlash `CMD`): the
/// rows of a `.waypoints` file, ArduPilot's semantics (item 0 is home when it is a home row). A
/// NaN parameter is MAVLink's "not set", as in a `.plan`. Messages name an item by its sequence
/// number.
///
/// # Errors
/// The errors of the items' semantics, as [`read_waypoints`] (an infinite coordinate, say).
pub fn read_items(items: &[aloft_logs::telemetry::MissionItem]) -> Result<Imported, ImportError> {
    read_items_with(items, ReadOptions::default())
}

/// [`read_items`] with `options`.
///
/// # Errors
/// As [`read_items`].
pub fn read_items_with(
    items: &[aloft_logs::telemetry::MissionItem],
    options: ReadOptions,
) -> Result<Imported, ImportError> {
    let rows = items
        .iter()
        .map(|item| RawItem {
            at: Place::Item(item.seq),
            number: item.seq,
            command: item.command,
            frame: item.frame,
            params: item.params,
            jump_id: None,
        })
        .collect();
    from_rows(rows, SourceFormat::MavlinkItems, "MAVLink mission", options)
}

/// The home row apart, then the items' semantics: what a `.waypoints` file and a link's
/// mission share.
fn from_rows(
    rows: Vec<RawItem>,
    format: SourceFormat,
    what: &str,
    options: ReadOptions,
) -> Result<Imported, ImportError> {
    let mut notes = Notes::default();
    let home_row = home_row(&rows);
    let (home, home_amsl_m, items) = split_home(rows, &mut notes)?;
    let source = Source {
        home,
        home_amsl_m,
        autopilot: Autopilot::ArduPilot,
        jumps_by: JumpsBy::RowIndex,
        default_speed_mps: ARDUPILOT_WPNAV_SPEED_MPS,
        options,
    };
    let translation = translate(&items, &source, notes)?;
    let description = format!("{what}, {} items", items.len());
    Ok(assemble(
        translation,
        &source,
        (&items, home_row),
        format,
        description,
    ))
}

/// The home row (INDEX 0, NAV_WAYPOINT, frame 0) as written, when the first row is one.
fn home_row(rows: &[RawItem]) -> Option<Home> {
    rows.first()
        .filter(|r| r.number == 0 && r.command == 16 && r.frame == 0)
        .map(|r| Home {
            latitude_deg: r.params[4],
            longitude_deg: r.params[5],
            altitude_amsl_m: Some(r.params[6]),
        })
}

/// One line (number `line`, from 1) as an item.
fn row(line: usize, text: &str) -> Result<RawItem, ImportError> {
    let text = text.trim_end();
    let mut fields: Vec<&str> = text.split('\t').map(str::trim).collect();
    if fields.len() != 12 {
        let spaced: Vec<&str> = text.split_whitespace().collect();
        if spaced.len() != 12 {
            return Err(ImportError::FieldCount {
                line,
                found: fields.len(),
            });
        }
        fields = spaced;
    }
    let whole = |k: usize| -> Result<u32, ImportError> {
        fields[k].parse::<u32>().map_err(|_| ImportError::BadField {
            line,
            field: FIELDS[k],
            found: fields[k].chars().take(24).collect(),
        })
    };
    let index = whole(0)?;
    let (frame, command) = (whole(2)?, whole(3)?);
    let mut params = [0.0; 7];
    for (j, p) in params.iter_mut().enumerate() {
        let k = 4 + j;
        // P1-P4 may be NaN (MAVLink's "not set", as Mission Planner writes a NaN parameter).
        *p = fields[k]
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() || (j < 4 && v.is_nan()))
            .ok_or_else(|| ImportError::BadField {
                line,
                field: FIELDS[k],
                found: fields[k].chars().take(24).collect(),
            })?;
    }
    whole(1)?;
    whole(11)?;
    Ok(RawItem {
        at: Place::Row(index),
        number: index,
        command,
        frame,
        params,
        jump_id: None,
    })
}

/// The home row (INDEX 0, NAV_WAYPOINT, frame 0) apart from the items; without one, the first
/// position in the file is home (warned).
fn split_home(
    mut rows: Vec<RawItem>,
    notes: &mut Notes,
) -> Result<(LatLon, Option<f64>, Vec<RawItem>), ImportError> {
    let home_row = home_row(&rows).is_some();
    if home_row {
        let h = rows.remove(0);
        let [.., lat, lon, alt] = h.params;
        if lat.abs() < 90.0 && lon.abs() <= 180.0 && !(lat == 0.0 && lon == 0.0) {
            check_sequence(&rows, 1, notes);
            let home = LatLon {
                latitude_deg: lat,
                longitude_deg: lon,
            };
            return Ok((home, Some(alt), rows));
        }
        notes.add(
            h.at,
            "home row without a position: home is the first position in the file",
        );
    }
    check_sequence(&rows, if home_row { 1 } else { 0 }, notes);
    let first = rows.iter().find(|r| {
        let [.., lat, lon, _] = r.params;
        !(lat == 0.0 && lon == 0.0) && lat.abs() < 90.0 && lon.abs() <= 180.0
    });
    match first {
        Some(r) => {
            notes.add(
                r.at,
                "no home row: home (the launch point) is this row's position, its altitude unknown",
            );
            let home = LatLon {
                latitude_deg: r.params[4],
                longitude_deg: r.params[5],
            };
            Ok((home, None, rows))
        }
        None => Err(ImportError::NoHome {
            at: Place::File,
            hint: "no home row (INDEX 0, command 16, frame 0) and no row with a position",
        }),
    }
}

/// INDEX should count up by one from `first`; a file that does not is read by its INDEX
/// values (warned), which DO_JUMP targets name.
fn check_sequence(rows: &[RawItem], first: u32, notes: &mut Notes) {
    let out_of_order = rows
        .iter()
        .zip(first..)
        .find(|(r, expected)| r.number != *expected);
    if let Some((r, expected)) = out_of_order {
        notes.add(
            r.at,
            format!(
                "INDEX {} where {expected} was expected: items are numbered by INDEX",
                r.number
            ),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HOME: &str = "0\t1\t0\t16\t0\t0\t0\t0\t-35.0\t149.0\t100.0\t1";
    const TAKEOFF: &str = "1\t0\t3\t22\t0\t0\t0\t0\t0\t0\t20\t1";

    fn err(text: &str) -> String {
        read_waypoints(text).unwrap_err().to_string()
    }

    #[test]
    fn the_header_fields_and_numbers_are_checked_naming_the_line_and_column() {
        assert_eq!(
            err("QGC WPL 120\n"),
            "line 1: the header is version 120 of the format, expected \"QGC WPL 110\""
        );
        let short = format!("QGC WPL 110\n{HOME}\n1\t0\t3\t22\t0\t0\t0\t0\t0\t0\t20\n");
        assert!(err(&short).starts_with("line 3: 11 tab-separated fields, expected 12"));
        let word = format!("QGC WPL 110\n{HOME}\n1\t0\t3\t22\t0\t0\t0\t0\tnorth\t0\t20\t1\n");
        assert_eq!(err(&word), "line 3: field LAT is \"north\", not a number");
        let nan = format!("QGC WPL 110\n{HOME}\n1\t0\t3\t22\t0\t0\t0\t0\t0\t0\tNaN\t1\n");
        assert_eq!(err(&nan), "line 3: field ALT is \"NaN\", not a number");
        let inf = format!("QGC WPL 110\n{HOME}\n1\t0\t3\t22\tinf\t0\t0\t0\t0\t0\t20\t1\n");
        assert_eq!(err(&inf), "line 3: field P1 is \"inf\", not a number");
        let index = format!("QGC WPL 110\n{HOME}\n-1\t0\t3\t22\t0\t0\t0\t0\t0\t0\t20\t1\n");
        assert_eq!(err(&index), "line 3: field INDEX is \"-1\", not a number");
    }

    /// Mission Planner writes a NaN parameter `NaN`, pymavlink `nan`: P1-P4 not set.
    #[test]
    fn nan_in_p1_to_p4_is_not_set_and_refused_in_a_position() {
        let t = format!(
            "QGC WPL 110\n{HOME}\n{TAKEOFF}\n2\t0\t3\t16\tnan\t0\t0\tNaN\t-35.001\t149.0\t20\t1\n"
        );
        let i = read_waypoints(&t).unwrap();
        assert!(i.items[1].params[0].is_nan() && i.items[1].params[3].is_nan());
        let zero = t.replace("nan", "0").replace("NaN", "0");
        assert_eq!(i.spec, read_waypoints(&zero).unwrap().spec);
        let lat = t.replace("-35.001", "NaN");
        assert_eq!(err(&lat), "line 4: field LAT is \"NaN\", not a number");
    }

    #[test]
    fn crlf_trailing_blanks_and_blank_lines_are_tolerated() {
        let t = format!("QGC WPL 110\r\n{HOME}  \r\n\r\n{TAKEOFF}\t\r\n");
        let i = read_waypoints(&t).unwrap();
        assert_eq!(i.spec.segments.len(), 1);
        assert_eq!(i.spec.home.altitude_amsl_m, Some(100.0));
        assert_eq!(i.spec.default_speed_mps, Some(ARDUPILOT_WPNAV_SPEED_MPS));
    }

    #[test]
    fn a_file_without_a_home_row_keeps_row_0_and_refuses_amsl_heights() {
        let t = "QGC WPL 110\n0\t0\t3\t22\t0\t0\t0\t0\t-35.0\t149.0\t10\t1\n";
        let i = read_waypoints(t).unwrap();
        assert_eq!(i.spec.segments[0].item(), Some(0));
        assert!(i.warnings[0].starts_with("row 0: no home row"));
        let amsl = format!("{t}1\t0\t0\t16\t0\t0\t0\t0\t-35.001\t149.0\t110\t1\n");
        assert!(err(&amsl).starts_with("row 1: no home position: an altitude above mean sea level"));
        let nowhere = "QGC WPL 110\n0\t0\t2\t178\t1\t5\t0\t0\t0\t0\t0\t1\n";
        assert!(err(nowhere).starts_with("file: no home position"));
    }

    #[test]
    fn rows_out_of_sequence_are_numbered_by_their_index_with_a_warning() {
        let t = format!("QGC WPL 110\n{HOME}\n7\t0\t3\t22\t0\t0\t0\t0\t0\t0\t20\t1\n");
        let i = read_waypoints(&t).unwrap();
        assert_eq!(i.spec.segments[0].item(), Some(7));
        assert!(i.warnings[0].starts_with("row 7: INDEX 7 where 1 was expected"));
    }

    /// A mission from a link's items flies as the `.waypoints` file of the same rows.
    #[test]
    fn items_from_a_link_read_as_their_waypoints_file() {
        let item = |seq: u32, frame: u32, command: u32, lat: f64, lon: f64, alt: f64| {
            aloft_logs::telemetry::MissionItem {
                seq,
                frame,
                command,
                params: [0.0, 0.0, 0.0, 0.0, lat, lon, alt],
            }
        };
        let items = [
            item(0, 0, 16, -35.0, 149.0, 100.0),
            item(1, 3, 22, 0.0, 0.0, 20.0),
            item(2, 3, 16, -35.001, 149.0, 20.0),
            item(3, 3, 21, 0.0, 0.0, 0.0),
        ];
        let text = format!(
            "QGC WPL 110\n{HOME}\n{TAKEOFF}\n2\t0\t3\t16\t0\t0\t0\t0\t-35.001\t149.0\t20\t1\n\
             3\t0\t3\t21\t0\t0\t0\t0\t0\t0\t0\t1\n"
        );
        let (from_link, from_file) = (read_items(&items).unwrap(), read_waypoints(&text).unwrap());
        assert_eq!(from_link.spec.segments, from_file.spec.segments);
        assert_eq!(from_link.spec.home, from_file.spec.home);
        assert_eq!(from_link.spec.description, "MAVLink mission, 3 items");
        assert_eq!(from_link.format, SourceFormat::MavlinkItems);
        // NaN is MAVLink's "not set" (a waypoint's yaw); an infinite latitude names the item.
        let mut unset = items;
        unset[2].params[3] = f64::NAN;
        assert_eq!(
            read_items(&unset).unwrap().spec.segments,
            from_file.spec.segments
        );
        let mut bad = items;
        bad[2].params[4] = f64::INFINITY;
        let e = read_items(&bad).unwrap_err().to_string();
        assert!(e.starts_with("item 2"), "{e}");
    }
}
