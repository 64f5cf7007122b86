//! Where `aloft live` reads a flight from: a flight log replayed as events (always), a telemetry
//! log or a live MAVLink link (the `live` feature, through the `aloft-link` crate).

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use aloft_logs::telemetry::{Paced, Reply, Telemetry, TelemetrySource};

use crate::engine::basics::logs::FlightLogs;
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
        /// The component of the vehicle's system aloft's displayed replies come from.
        display_component_id: u8,
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
        self.open_with(None)
    }

    /// Open the source, to end (as at the end of the log, not as an error) once `stop` is set:
    /// between two events, in a paced wait, or within 250 ms on a link waiting for its vehicle
    /// (`aloft live` on Ctrl-C).
    ///
    /// # Errors
    /// As [`LiveSource::open`].
    pub fn open_until(&self, stop: Arc<AtomicBool>) -> Result<Box<dyn TelemetrySource>, Error> {
        let source = self.open_with(Some(stop.clone()))?;
        Ok(Box::new(Until { source, stop }))
    }

    fn open_with(&self, stop: Option<Arc<AtomicBool>>) -> Result<Box<dyn TelemetrySource>, Error> {
        match self {
            LiveSource::Replay { logs, speed } => {
                let source: Box<dyn TelemetrySource> = Box::new(logs.events_of_first()?);
                Ok(paced(source, *speed, stop))
            }
            LiveSource::Tlog {
                path,
                speed,
                timeout_s,
            } => Ok(paced(open_tlog(path, *timeout_s)?, *speed, stop)),
            LiveSource::Connect {
                url,
                system_id,
                component_id,
                display_component_id,
                timeout_s,
            } => connect(
                url,
                [*system_id, *component_id, *display_component_id],
                *timeout_s,
                stop,
            ),
        }
    }
}

/// A source that ends once its flag is set.
struct Until {
    source: Box<dyn TelemetrySource>,
    stop: Arc<AtomicBool>,
}

impl TelemetrySource for Until {
    fn next_event(&mut self) -> Result<Option<Telemetry>, String> {
        if self.stop.load(Ordering::Relaxed) {
            return Ok(None);
        }
        self.source.next_event()
    }

    fn skipped(&self) -> String {
        self.source.skipped()
    }

    fn reply(&mut self, reply: &Reply) -> Result<(), String> {
        self.source.reply(reply)
    }
}

/// `source` at `speed` times its own time (its waits ended by `stop`), or as fast as it goes.
fn paced(
    source: Box<dyn TelemetrySource>,
    speed: Option<f64>,
    stop: Option<Arc<AtomicBool>>,
) -> Box<dyn TelemetrySource> {
    match (speed, stop) {
        (Some(x), Some(stop)) => Box::new(Paced::new(source, x).until(stop)),
        (Some(x), None) => Box::new(Paced::new(source, x)),
        (None, _) => source,
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
    [system_id, component_id, display_component_id]: [u8; 3],
    timeout_s: f64,
    stop: Option<Arc<AtomicBool>>,
) -> Result<Box<dyn TelemetrySource>, Error> {
    let options = aloft_link::LinkOptions {
        system_id,
        component_id,
        display_component_id,
        timeout: timeout(timeout_s)?,
        ..aloft_link::LinkOptions::default()
    };
    let link =
        aloft_link::LinkSource::connect(url, options).map_err(|e| Error::Link(e.to_string()))?;
    Ok(match stop {
        Some(stop) => Box::new(link.until(stop)),
        None => Box::new(link),
    })
}

#[cfg(not(feature = "live"))]
fn open_tlog(path: &std::path::Path, _: f64) -> Result<Box<dyn TelemetrySource>, Error> {
    Err(Error::Link(format!(
        "{}: telemetry logs need aloft built with the `live` feature",
        path.display()
    )))
}

#[cfg(not(feature = "live"))]
fn connect(
    url: &str,
    _: [u8; 3],
    _: f64,
    _: Option<Arc<AtomicBool>>,
) -> Result<Box<dyn TelemetrySource>, Error> {
    Err(Error::Link(format!(
        "{url}: MAVLink links need aloft built with the `live` feature"
    )))
}

#[cfg(all(test, feature = "live"))]
mod tests {
    /// The engine's default display component is the link's (the engine builds without the
    /// link crate, so it keeps its own copy).
    #[test]
    fn the_display_component_defaults_agree() {
        assert_eq!(
            super::super::DEFAULT_DISPLAY_COMPONENT_ID,
            aloft_link::DISPLAY_COMPONENT_ID
        );
    }
}
