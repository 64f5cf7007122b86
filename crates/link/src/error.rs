//! The crate's typed error: each variant names the file (with the byte offset) or the link at fault.

use std::path::PathBuf;

use thiserror::Error;

/// Errors of `aloft-link`. Damaged frames inside a telemetry log are not errors (they are
/// skipped and counted in [`crate::TlogStats`]); these are what ends a stream or refuses a link.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum LinkError {
    /// A telemetry log could not be opened.
    #[error("cannot open {path}: {cause}")]
    Open {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        cause: std::io::Error,
    },
    /// Reading a telemetry log failed.
    #[error("{name}: read error at byte {offset}: {cause}")]
    Read {
        /// The file (or the name the reader was given).
        name: String,
        /// Byte offset in the file where the read was to continue.
        offset: u64,
        /// The operating system's error.
        cause: std::io::Error,
    },
    /// A telemetry log in which not one frame could be read (no MAVLink frame after a timestamp
    /// of the years 2000 to 2100 with a valid CRC and a payload the dialect decodes).
    #[error(
        "{name}: not a telemetry log: no MAVLink frame with a timestamp (µs since 1970, years \
         2000 to 2100) and a valid CRC in its {bytes} bytes"
    )]
    NothingReadable {
        /// The file (or the name the reader was given).
        name: String,
        /// Bytes read.
        bytes: u64,
    },
    /// A telemetry log in which the vehicle is never armed: no flight.
    #[error("{name}: the vehicle is never armed in the telemetry (HEARTBEAT): no flight")]
    NeverArmed {
        /// The file.
        name: String,
    },
    /// A telemetry log without two battery records with a voltage while the vehicle is armed
    /// (SYS_STATUS `voltage_battery` 0, no BATTERY_STATUS cells).
    #[error(
        "{name}: no battery voltage in the telemetry while armed (SYS_STATUS voltage 0 or \
         absent, no BATTERY_STATUS cells): no energy to record"
    )]
    NoBatteryVoltage {
        /// The file.
        name: String,
    },
    /// A link address that is not one of the supported forms.
    #[error(
        "{url}: not a link address (udpin:HOST:PORT, udpout:HOST:PORT, tcpout:HOST:PORT or \
         serial:PATH:BAUD)"
    )]
    Address {
        /// The address given.
        url: String,
    },
    /// The link could not be opened (socket bind, TCP connect, serial port).
    #[error("{url}: cannot open the link: {cause}")]
    Connect {
        /// The address given.
        url: String,
        /// The operating system's error.
        cause: std::io::Error,
    },
    /// The link ended: the connection was closed or failed while reading.
    #[error("{url}: link closed: {cause}")]
    Closed {
        /// The address given.
        url: String,
        /// What ended it.
        cause: std::io::Error,
    },
    /// A message could not be sent on the link.
    #[error("{url}: cannot send {message}: {cause}")]
    Send {
        /// The address given.
        url: String,
        /// The MAVLink message (`NAMED_VALUE_FLOAT`, `STATUSTEXT`, ...).
        message: &'static str,
        /// The writer's error.
        cause: std::io::Error,
    },
}

/// `Result` with [`LinkError`].
pub type Result<T> = std::result::Result<T, LinkError>;
