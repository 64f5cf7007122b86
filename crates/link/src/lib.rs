//! # aloft-link
//!
//! MAVLink for `aloft live`: telemetry logs (`.tlog`) and live links (UDP, TCP, serial) turned
//! into aloft's telemetry events ([`aloft_logs::telemetry`]): SI units, positions and velocities
//! in east-north-up (ENU) from the stream's first fix, attitude as aerospace Euler angles relative
//! to north-east-down, seconds from the stream's start.
//!
//! Layers, each usable alone:
//! - [`TlogReader`] ([`tlog`]): the frames of a `.tlog` from any reader (sans-I/O: a `&[u8]`
//!   works), with bounded memory, CRC-checked by the `mavlink` crate's ArduPilot dialect, damage
//!   skipped and counted ([`TlogStats`]).
//! - [`Decoder`] ([`decode`]): messages of the vehicle into [`Telemetry`] events; the mission
//!   assembled from the mission protocol ([`mission`]).
//! - [`read_tlog_flight`] ([`flight`]): what a telemetry log says of its flight (armed, in the
//!   air, the energy drawn), for a logbook.
//! - [`TlogSource`] and [`LinkSource`] ([`source`]): the two as
//!   [`TelemetrySource`]s; a live link reads on a thread,
//!   reports silence as [`Event::LinkLost`], answers with
//!   [`LinkSource::reply`] (on `udpin`, to the vehicle's address only), and downloads the
//!   mission when none passed ([`request`]) and the vehicle's failsafe parameters
//!   ([`params`]); a telemetry log's clock steps are taken out of its
//!   times and said ([`Event::LinkLost`], [`Event::ClockBack`]).
//!
//! Positions are believed only on the Earth and within a multirotor's reach of the last one
//! ([`decode::fix`]).
//!
//! ```no_run
//! use std::path::Path;
//! use aloft_link::TlogSource;
//! let mut source = TlogSource::open(Path::new("flight.tlog"))?;
//! while let Some(t) = source.next_telemetry()? {
//!     println!("{:.2} {:?}", t.time_s, t.event);
//! }
//! eprintln!("{}", aloft_link::describe_stats(source.stats()));
//! # Ok::<(), aloft_link::LinkError>(())
//! ```
//!
//! The library never prints or exits; every failure is a [`LinkError`] naming the file and byte
//! offset, or the link.

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod decode;
pub mod error;
pub mod flight;
pub mod mission;
mod modes;
pub mod params;
pub mod request;
pub mod source;
pub mod tlog;
mod transport;

pub use aloft_logs::telemetry::{
    BatteryReply, BatteryState, ChargeState, Event, Heartbeat, MissionItem, Reply, Severity,
    Telemetry, TelemetrySource,
};
pub use decode::{Decoder, FixStats};
pub use error::{LinkError, Result};
pub use flight::{read_tlog_flight, TlogFlight};
/// The `mavlink` crate aloft-link is built on (its ArduPilot dialect's message types appear in
/// [`TlogFrame`] and [`Decoder::push`]).
pub use mavlink;
pub use mission::MAX_MISSION_ITEMS;
pub use modes::mode_name;
pub use source::{
    battery_status, describe_fixes, describe_stats, gcs_heartbeat, LinkOptions, LinkSource,
    LinkStats, TlogSource, DISPLAY_COMPONENT_ID, DISPLAY_HEARD,
};
pub use tlog::{TlogFrame, TlogReader, TlogStats};
