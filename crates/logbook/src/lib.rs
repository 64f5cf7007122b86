//! # aloft-logbook
//!
//! The operator's logbook: flights, vehicles and packs from their own flight logs, in one
//! SQLite file ([`Logbook`]) marked as aloft's ([`APPLICATION_ID`]; another program's SQLite file
//! is refused untouched, see [`file`](mod@file)). A log is added once, keyed by the SHA-256 of its content
//! ([`Logbook::add`]); a second log of a flight already there (the same vehicle over an
//! overlapping span: a truncated copy, the telemetry of the flight) is recorded as a copy of it
//! ([`AddOutcome::Copy`]) and counted once; a log that is not a flight (damaged, no battery data)
//! is recorded in `skipped` with the reason, in the same single transaction per file, so a
//! failure never leaves half a row. Vehicles are keyed by the log's own identity (PX4
//! `sys_uuid`, ArduPilot `BRD_SERIAL_NUM`), else an operator's label, else [`UNKNOWN`]; packs by
//! a smart pack's serial or `BATT_SERIAL_NUM`, else a label, else their vehicle, cells and rated
//! capacity ([`derived_pack_key`]: `unknown 3S 5000 mAh on quad-1`), never guessed beyond what
//! the log says; [`Logbook::relabel`] renames one afterwards. Formats this crate does not decode
//! (MAVLink telemetry) come in as a record read elsewhere ([`Logbook::add_with`]).
//!
//! The schema ([`schema`]) is versioned in `PRAGMA user_version` and migrated forward on open;
//! the file is in WAL mode with a [`BUSY_TIMEOUT`], so two processes adding at once both land.
//! The queries ([`Logbook::flights`], [`Logbook::vehicles`], [`Logbook::packs`]) live here
//! beside the schema, and read a read-only file or folder ([`Logbook::open_read_only`]). The
//! library never prints or exits; it reads only the files it is handed.
//!
//! ```no_run
//! use std::path::Path;
//! use aloft_logbook::{Labels, Logbook, ReadOptions};
//! let mut book = Logbook::open(Path::new("logbook.sqlite"))?;
//! book.add(Path::new("flight.ulg"), &Labels::default(), &ReadOptions::default())?;
//! for v in book.vehicles()? {
//!     println!("{}: {} flights, {:.1} h", v.key, v.flights, v.hours);
//! }
//! # Ok::<(), aloft_logbook::LogbookError>(())
//! ```

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

mod error;
pub mod file;
mod ingest;
mod query;
pub mod record;
mod relabel;
pub mod schema;

pub use error::{LogbookError, Result};
pub use file::{APPLICATION_ID, BUSY_TIMEOUT};
pub use ingest::{
    cells_from_voltage, cells_of, check_label, derived_pack_key, file_sha256, AddOutcome, Labels,
    Logbook, MAX_CELL_V, MIN_FLOWN_CELL_V, MIN_RATED_CAPACITY_MAH, UNKNOWN,
};
pub use query::{
    trend, Flight, PackPoint, PackSummary, PowerDrift, PowerPoint, Skipped, Trend, VehicleSummary,
    DRIFT_FLIGHTS,
};
pub use record::{
    high_voltage_v, log_kind, read_flight, FlightFacts, LogKind, ReadOptions, NOT_A_LOG,
};
pub use relabel::KeyKind;
pub use schema::SCHEMA_VERSION;
