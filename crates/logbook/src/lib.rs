//! # aloft-logbook
//!
//! The operator's logbook: flights, vehicles and packs from their own flight logs, in one
//! SQLite file ([`Logbook`]). A log is added once, keyed by the SHA-256 of its content
//! ([`Logbook::add`]); a log that is not a flight (damaged, no battery data) is recorded in
//! `skipped` with the reason, in the same single transaction per file, so a failure never
//! leaves half a row. Vehicles are keyed by the log's own identity (PX4 `sys_uuid`, ArduPilot
//! `BRD_SERIAL_NUM`), else an operator's label, else [`UNKNOWN`]; packs likewise (a smart pack's
//! serial, `BATT_SERIAL_NUM`, a label, [`UNKNOWN`]), never guessed.
//!
//! The schema ([`schema`]) is versioned in `PRAGMA user_version` and migrated forward on open;
//! the file is in WAL mode with a [`BUSY_TIMEOUT`], so two processes adding at once both land.
//! The queries ([`Logbook::flights`], [`Logbook::vehicles`], [`Logbook::packs`]) live here
//! beside the schema. The library never prints or exits; it reads only the files it is handed.
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
pub mod schema;

pub use error::{LogbookError, Result};
pub use file::APPLICATION_ID;
pub use ingest::{file_sha256, AddOutcome, Labels, Logbook, BUSY_TIMEOUT, UNKNOWN};
pub use query::{
    trend, Flight, PackPoint, PackSummary, PowerDrift, PowerPoint, Skipped, Trend, VehicleSummary,
    DRIFT_FLIGHTS,
};
pub use record::{read_flight, FlightFacts, ReadOptions};
pub use schema::SCHEMA_VERSION;
