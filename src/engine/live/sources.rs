//! Where `aloft live` reads a flight from: a flight log replayed as events (always), a telemetry
//! log or a live MAVLink link (the `live` feature, through the `aloft-link` crate).

use std::path::PathBuf;

use aloft_logs::telemetry::{Paced, TelemetrySource};

use super::super::logs::FlightLogs;
use crate::error::Error;

/// A source of `aloft live`.
#[derive(Debug, Clone, PartialEq)]
pub enum LiveSource {
    /// A flight log (CSV with a profile, MCAP, ULog, DataFlash), as if live, at `speed` times its
    /// own time (`None`: as fast as it goes): its samples, and a DataFlash log's mode, arming and
    /// mission.
    Replay {
        /// The log and how to read it.
        logs: FlightLogs,
        /// Times its own time.
        speed: Option<f64>,
    },
    /// A telemetry log (`.tlog`) at `speed` times its own time (`None`: as fast as it goes).
    Tlog {
        /// The file.
        path: PathBuf,
        /// Times its own time.
        speed: Option<f64>,
        /// A forward step of the log's clock longer than this is a lost link (not waited
        /// through, not counted as flight time), s.
        timeout_s: f64,
    },
    /// A live MAVLink link.
    Connect {
        /// `udpin:HOST:PORT`, `udpout:HOST:PORT`, `tcpout:HOST:PORT` or `serial:PATH:BAUD`.
        url: String,
        /// aloft's system id on the link.
        system_id: u8,
        /// aloft's component id.
        component_id: u8,
        /// Silence after which the link is said lost, s.
        timeout_s: f64,
    },
}

impl LiveSource {
    /// Open the source.
    ///
    /// # Errors
    /// A log or telemetry log that cannot be opened or read, a link address that is not one of
    /// the four forms or cannot be opened, and `--tlog`/`--connect` in a build without the `live`
    /// feature.
    pub fn open(&self) -> Result<Box<dyn TelemetrySource>, Error> {
        match self {
            LiveSource::Replay { logs, speed } => {
                let source: Box<dyn TelemetrySource> = Box::new(logs.events_of_first()?);
                Ok(paced(source, *speed))
            }
            LiveSource::Tlog {
                path,
                speed,
                timeout_s,
            } => Ok(paced(open_tlog(path, *timeout_s)?, *speed)),
            LiveSource::Connect {
                url,
                system_id,
                component_id,
                timeout_s,
            } => connect(url, *system_id, *component_id, *timeout_s),
        }
    }
}

/// `source` at `speed` times its own time, or as fast as it goes.
fn paced(source: Box<dyn TelemetrySource>, speed: Option<f64>) -> Box<dyn TelemetrySource> {
    match speed {
        Some(x) => Box::new(Paced::new(source, x)),
        None => source,
    }
}

#[cfg(feature = "live")]
fn open_tlog(path: &std::path::Path, timeout_s: f64) -> Result<Box<dyn TelemetrySource>, Error> {
    let source = aloft_link::TlogSource::open(path).map_err(|e| Error::Link(e.to_string()))?;
    Ok(Box::new(source.with_link_timeout(timeout(timeout_s)?)))
}

/// `--link-timeout` as a duration (one too long for a duration is refused, not a panic).
#[cfg(feature = "live")]
fn timeout(timeout_s: f64) -> Result<std::time::Duration, Error> {
    std::time::Duration::try_from_secs_f64(timeout_s).map_err(|_| Error::InvalidInput {
        name: "link-timeout",
        value: timeout_s,
        unit: "s",
        expected: "a positive number of seconds, at most 1e9",
    })
}

#[cfg(feature = "live")]
fn connect(
    url: &str,
    system_id: u8,
    component_id: u8,
    timeout_s: f64,
) -> Result<Box<dyn TelemetrySource>, Error> {
    let options = aloft_link::LinkOptions {
        system_id,
        component_id,
        timeout: timeout(timeout_s)?,
        ..aloft_link::LinkOptions::default()
    };
    let link =
        aloft_link::LinkSource::connect(url, options).map_err(|e| Error::Link(e.to_string()))?;
    Ok(Box::new(link))
}

#[cfg(not(feature = "live"))]
fn open_tlog(path: &std::path::Path, _: f64) -> Result<Box<dyn TelemetrySource>, Error> {
    Err(Error::Link(format!(
        "{}: telemetry logs need aloft built with the `live` feature",
        path.display()
    )))
}

#[cfg(not(feature = "live"))]
fn connect(url: &str, _: u8, _: u8, _: f64) -> Result<Box<dyn TelemetrySource>, Error> {
    Err(Error::Link(format!(
        "{url}: MAVLink links need aloft built with the `live` feature"
    )))
}
