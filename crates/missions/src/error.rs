//! The one error type of the importers: every refusal names where it is (the item number the
//! operator sees, the row of a `.waypoints` file, or the line) and the command or key at fault.

use std::fmt;

use aloft_core::Num;
use thiserror::Error;

use crate::commands::CommandName;

/// Where in a mission file an error is: what the operator looks up in their planner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Place {
    /// The file as a whole (its header or top-level keys).
    File,
    /// A `.plan` mission item, by its MAVLink sequence number (home is 0, the first item 1, the
    /// items of a survey numbered in sequence, as QGroundControl shows and uploads them).
    Item(u32),
    /// A `.waypoints` row, by its INDEX column (home is row 0).
    Row(u32),
    /// A line of a text file, from 1 (where no row number can be trusted).
    Line(usize),
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Place::File => write!(f, "file"),
            Place::Item(i) => write!(f, "item {i}"),
            Place::Row(r) => write!(f, "row {r}"),
            Place::Line(l) => write!(f, "line {l}"),
        }
    }
}

/// Everything the importers refuse, and what the writers ([`mod@crate::write`]) refuse to write.
/// Each message is one line that names the place ([`Place`]) and the command or key.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ImportError {
    /// Bytes that are not UTF-8 text.
    #[error("not UTF-8 text: invalid byte at offset {offset}")]
    NotText {
        /// Offset of the first invalid byte.
        offset: usize,
    },
    /// Text that is none of the planner formats (QGroundControl `.plan`, `QGC WPL 110`).
    #[error(
        "not a QGroundControl .plan (JSON with a fileType key) nor a QGC WPL 110 .waypoints file"
    )]
    UnknownFormat,
    /// A `.plan` that is not valid JSON.
    #[error("not valid JSON at line {line}, column {column}: {message}")]
    Json {
        /// Line, from 1.
        line: usize,
        /// Column, from 1.
        column: usize,
        /// The parser's message.
        message: String,
    },
    /// A JSON file whose `fileType` is not `"Plan"` (a fence or rally file, another tool's file).
    #[error("key fileType is {found}, not \"Plan\": not a QGroundControl mission plan")]
    WrongFileType {
        /// The value found, as JSON.
        found: String,
    },
    /// Required keys missing.
    #[error("{at}{}: missing {keys}", CommandNote(*.command))]
    MissingKey {
        /// Where.
        at: Place,
        /// The item's command, when known.
        command: Option<u32>,
        /// The missing keys: `key "fileType"`, `keys "type", "frame"`.
        keys: String,
    },
    /// A key whose value has the wrong type or an unsupported value.
    #[error("{at}{}: key {key} is {found}: expected {expected}", CommandNote(*.command))]
    BadKey {
        /// Where.
        at: Place,
        /// The item's command, when known.
        command: Option<u32>,
        /// The key (`mission.version`, `params`, `frame`).
        key: String,
        /// What was found, as JSON or text.
        found: String,
        /// What is accepted.
        expected: &'static str,
    },
    /// A `.waypoints` file whose first line is not `QGC WPL 110`.
    #[error("line 1: the header is {}, expected \"QGC WPL 110\"", match .version { Some(v) => format!("version {v} of the format"), None => "not a version of the format".to_string() })]
    BadHeader {
        /// The version the header names, when it is a short number (nothing else of the line is
        /// quoted: the file may be any file).
        version: Option<String>,
    },
    /// A `.waypoints` line that does not have 12 tab-separated fields.
    #[error("line {line}: {found} tab-separated fields, expected 12 (INDEX CURRENT FRAME COMMAND P1 P2 P3 P4 LAT LON ALT AUTOCONTINUE)")]
    FieldCount {
        /// Line, from 1.
        line: usize,
        /// Fields found.
        found: usize,
    },
    /// A `.waypoints` field that is not a number.
    #[error("line {line}: field {field} is {found:?}, not a number")]
    BadField {
        /// Line, from 1.
        line: usize,
        /// Column name (`INDEX`, `LAT`, ...).
        field: &'static str,
        /// The text found (shortened).
        found: String,
    },
    /// A parameter of an item out of its range (a latitude beyond 90, a non-finite altitude).
    #[error("{at} ({}): {key} = {} is invalid: expected {expected}", CommandName(*.command), Num(*.value))]
    BadValue {
        /// Where.
        at: Place,
        /// The item's command.
        command: u32,
        /// The parameter (`param5 (latitude)`).
        key: &'static str,
        /// Its value.
        value: f64,
        /// What is accepted.
        expected: &'static str,
    },
    /// Something aloft does not fly (a VTOL or fixed-wing item or vehicle, a structure scan), or
    /// does not write (a DO_JUMP, a survey in a `.waypoints` file).
    #[error("{at}: {what} is refused: {reason}")]
    Refused {
        /// Where.
        at: Place,
        /// What (`command 84 (NAV_VTOL_TAKEOFF)`, `ComplexItem StructureScan`, `vehicleType 21`).
        what: String,
        /// Why.
        reason: &'static str,
    },
    /// A position item in a frame aloft cannot place (local or body frames, or frame 2 which
    /// carries no position).
    #[error("{at} ({}): frame {frame} is not supported for a position: {expected}", CommandName(*.command))]
    UnsupportedFrame {
        /// Where.
        at: Place,
        /// The item's command.
        command: u32,
        /// The frame (MAV_FRAME).
        frame: u32,
        /// What is accepted.
        expected: &'static str,
    },
    /// A DO_JUMP whose target is not in the file.
    #[error("{at} (command 177 DO_JUMP): param1 target {target} is not {kind} in the file")]
    JumpTarget {
        /// Where.
        at: Place,
        /// The target as written.
        target: f64,
        /// What the target addresses (`a doJumpId`, `a row INDEX`).
        kind: &'static str,
    },
    /// A DO_JUMP that repeats forever (repeat count -1) or a count that is not a whole number.
    #[error("{at} (command 177 DO_JUMP): param2 repeat count {} cannot be flown: expected a whole number of repeats from 0 (an endless loop never lands)", Num(*.repeat))]
    EndlessJump {
        /// Where.
        at: Place,
        /// The repeat count as written.
        repeat: f64,
    },
    /// The jumps add more passes of items than [`crate::MAX_REPEATED_ITEMS`].
    #[error("{at}: the jumps repeat more than {limit} items by here (a loop repeated too often)")]
    TooManyItems {
        /// Where the limit was passed.
        at: Place,
        /// The limit.
        limit: usize,
    },
    /// A file without a home position.
    #[error("{at}: no home position: {hint}")]
    NoHome {
        /// Where.
        at: Place,
        /// Where a home would be.
        hint: &'static str,
    },
    /// A home position a writer cannot write (a coordinate out of range or not a number, no
    /// altitude for a `.waypoints` home row).
    #[error("home: {what} = {} is invalid: expected {expected}", Num(*.value))]
    BadHome {
        /// The value (`latitude`, `longitude`, `altitude above mean sea level`).
        what: &'static str,
        /// Its value (NaN when there is none).
        value: f64,
        /// What is accepted.
        expected: &'static str,
    },
    /// A file none of whose items flies (only camera or speed items, or no items).
    #[error("no mission item that flies ({items} items read): nothing to plan")]
    NothingToFly {
        /// Items read.
        items: usize,
    },
}

/// ` (command 22 NAV_TAKEOFF)` when the command is known, else nothing.
struct CommandNote(Option<u32>);

impl fmt::Display for CommandNote {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(c) => write!(f, " ({})", CommandName(c)),
            None => Ok(()),
        }
    }
}
