//! Opening any supported log: format detection, profiles, and one reader type for all sources.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use serde::Serialize;

use crate::column_map::ColumnMap;
use crate::csv_read::CsvSamples;
use crate::error::{LogError, Result};
use crate::mcap_read::{McapOptions, McapSamples, TopicInfo};
use crate::px4::{px4_prefix, table, Px4Options, Px4Samples, PX4_TOPICS};
use crate::sample::{DroppedValue, GeoOrigin, Log, Sample, TimeReport};

/// Built-in CSV profiles.
pub const BUILTIN_PROFILES: [&str; 2] = ["kaist", "px4"];

/// The KAIST header, used to recognise the layout without a profile.
const KAIST_HEADER: &str = "timestamp,lat,log,alt,roll,pitch,yaw,vel_x,vel_y,vel_z,acc_x,acc_y,acc_z,act_vx,act_vy,act_yr,capacity,vol,cur,power";

/// How to read a CSV log.
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// [`ColumnMap::kaist`].
    Kaist,
    /// PX4 per-topic tables, joined ([`crate::px4`]).
    Px4,
    /// A user column map.
    Map(Box<ColumnMap>),
}

impl Profile {
    /// A built-in profile by name, or a column-map TOML file by path.
    pub fn resolve(name_or_path: &str) -> Result<Self> {
        match name_or_path {
            "kaist" => Ok(Profile::Kaist),
            "px4" => Ok(Profile::Px4),
            p if Path::new(p).is_file() => {
                Ok(Profile::Map(Box::new(ColumnMap::from_file(Path::new(p))?)))
            }
            _ => Err(LogError::UnknownProfile {
                name: name_or_path.to_string(),
                known: BUILTIN_PROFILES.join(", "),
            }),
        }
    }

    /// A name for messages.
    pub fn name(&self) -> String {
        match self {
            Profile::Kaist => "kaist".into(),
            Profile::Px4 => "px4".into(),
            Profile::Map(m) if m.name.is_empty() => "column map".into(),
            Profile::Map(m) => m.name.clone(),
        }
    }
}

/// The container of a log.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LogFormat {
    /// One CSV table.
    Csv,
    /// PX4 per-topic CSV tables.
    Px4Csv,
    /// MCAP.
    Mcap,
}

/// A reader of any supported log, yielding [`Sample`]s.
pub enum LogReader {
    /// One CSV table through a column map.
    Csv(Box<CsvSamples<BufReader<File>>>),
    /// PX4 tables.
    Px4(Box<Px4Samples>),
    /// MCAP.
    Mcap(Box<McapSamples<BufReader<File>>>),
}

const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

fn is_mcap(path: &Path) -> Result<bool> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
    {
        return Ok(true);
    }
    if !path.is_file() {
        return Ok(false);
    }
    let mut f = File::open(path).map_err(LogError::reading(path))?;
    let mut head = [0u8; 8];
    let n = f.read(&mut head).map_err(LogError::reading(path))?;
    Ok(n == 8 && head == MCAP_MAGIC)
}

fn first_line(path: &Path) -> Result<String> {
    let f = File::open(path).map_err(LogError::reading(path))?;
    let mut line = String::new();
    // A header longer than 64 KiB is not a layout we know; read at most that much.
    BufReader::new(f.take(1 << 16))
        .read_line(&mut line)
        .map_err(LogError::reading(path))?;
    Ok(line.trim_end().to_string())
}

/// Open a log. MCAP is recognised by extension or magic; a CSV uses `profile`, or without one is
/// recognised as KAIST by its header or as PX4 by its table name.
pub fn open_log(path: &Path, profile: Option<&Profile>, mcap: &McapOptions) -> Result<LogReader> {
    if is_mcap(path)? {
        return Ok(LogReader::Mcap(Box::new(McapSamples::open(
            path,
            mcap.clone(),
        )?)));
    }
    let profile = match profile {
        Some(p) => p.clone(),
        None => {
            if px4_prefix(path).is_some_and(|p| table(&p, PX4_TOPICS[0]).exists()) {
                Profile::Px4
            } else if !path.exists() {
                return Err(LogError::Io {
                    path: path.to_path_buf(),
                    cause: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
                });
            } else if first_line(path)? == KAIST_HEADER {
                Profile::Kaist
            } else {
                return Err(LogError::UnsupportedFormat {
                    path: path.to_path_buf(),
                    reason: "CSV layout not recognised: give a profile (kaist, px4) or a column-map TOML file".into(),
                });
            }
        }
    };
    Ok(match profile {
        Profile::Kaist => LogReader::Csv(Box::new(CsvSamples::open(path, &ColumnMap::kaist())?)),
        Profile::Map(m) => LogReader::Csv(Box::new(CsvSamples::open(path, &m)?)),
        Profile::Px4 => LogReader::Px4(Box::new(Px4Samples::open(path, Px4Options::default())?)),
    })
}

impl LogReader {
    /// The container.
    pub fn format(&self) -> LogFormat {
        match self {
            LogReader::Csv(_) => LogFormat::Csv,
            LogReader::Px4(_) => LogFormat::Px4Csv,
            LogReader::Mcap(_) => LogFormat::Mcap,
        }
    }

    /// Absolute time of the first sample in the source's clock, s (after the first sample).
    pub fn start_time_s(&self) -> Option<f64> {
        match self {
            LogReader::Csv(r) => r.start_time_s(),
            LogReader::Px4(r) => r.start_time_s(),
            LogReader::Mcap(r) => r.start_time_s(),
        }
    }

    /// Time report of the samples read so far.
    pub fn time_report(&self) -> TimeReport {
        match self {
            LogReader::Csv(r) => r.time_report(),
            LogReader::Px4(r) => r.time_report(),
            LogReader::Mcap(r) => r.time_report(),
        }
    }

    /// Origin of geodetic positions.
    pub fn origin(&self) -> Option<GeoOrigin> {
        match self {
            LogReader::Csv(r) => r.origin(),
            _ => None,
        }
    }

    /// CSV header columns (for a single table).
    pub fn columns(&self) -> Option<&[String]> {
        match self {
            LogReader::Csv(r) => Some(r.columns()),
            _ => None,
        }
    }

    /// MCAP topics seen so far.
    pub fn topics(&self) -> Option<&[TopicInfo]> {
        match self {
            LogReader::Mcap(r) => Some(r.topics()),
            _ => None,
        }
    }

    /// PX4 per-topic time reports.
    pub fn px4_topic_reports(&self) -> Option<Vec<(&'static str, TimeReport)>> {
        match self {
            LogReader::Px4(r) => Some(r.topic_reports()),
            _ => None,
        }
    }

    /// Values dropped as isolated contradictions so far (CSV sources).
    pub fn dropped(&self) -> (u64, Vec<DroppedValue>) {
        match self {
            LogReader::Csv(r) => {
                let (n, v) = r.dropped();
                (n, v.to_vec())
            }
            _ => (0, Vec::new()),
        }
    }

    /// Read every sample into memory (for small logs).
    pub fn read_all(mut self, source: &str) -> Result<Log> {
        let mut samples = Vec::new();
        for s in self.by_ref() {
            samples.push(s?);
        }
        let (dropped_count, dropped) = self.dropped();
        Ok(Log {
            dropped_count,
            dropped,
            source: source.to_string(),
            samples,
            origin: self.origin(),
            start_time_s: self.start_time_s().unwrap_or(0.0),
            time: self.time_report(),
        })
    }
}

impl Iterator for LogReader {
    type Item = Result<Sample>;

    fn next(&mut self) -> Option<Self::Item> {
        match self {
            LogReader::Csv(r) => r.next(),
            LogReader::Px4(r) => r.next(),
            LogReader::Mcap(r) => r.next(),
        }
    }
}

/// Open and read a whole log.
pub fn read_log(path: &Path, profile: Option<&Profile>, mcap: &McapOptions) -> Result<Log> {
    open_log(path, profile, mcap)?.read_all(&path.display().to_string())
}
