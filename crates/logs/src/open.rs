//! Opening any supported log: format detection, profiles, and one reader type for all sources.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use serde::Serialize;

use crate::binary_samples::{BinaryOptions, BinarySamples, BinarySummary};
use crate::column_map::ColumnMap;
use crate::csv_read::CsvSamples;
use crate::dataflash::{dataflash_samples, is_dataflash, DataflashDecoder};
use crate::error::{LogError, Result};
use crate::mcap_read::{McapOptions, McapSamples, TopicInfo};
use crate::px4::{px4_prefix, table, Px4Options, Px4Samples, PX4_TOPICS};
use crate::sample::{DroppedValue, GeoOrigin, Log, Sample, TimeReport};
use crate::ulog::{is_ulog, ulog_samples, UlogDecoder};

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
    /// PX4 ULog (`.ulg`).
    Px4Ulog,
    /// ArduPilot DataFlash (`.bin`).
    #[serde(rename = "ardupilot_dataflash")]
    ArduPilotDataflash,
}

/// A reader of any supported log, yielding [`Sample`]s.
pub enum LogReader {
    /// One CSV table through a column map.
    Csv(Box<CsvSamples<BufReader<File>>>),
    /// PX4 tables.
    Px4(Box<Px4Samples>),
    /// MCAP.
    Mcap(Box<McapSamples<BufReader<File>>>),
    /// PX4 ULog.
    Ulog(Box<BinarySamples<BufReader<File>, UlogDecoder>>),
    /// ArduPilot DataFlash.
    Dataflash(Box<BinarySamples<BufReader<File>, DataflashDecoder>>),
}

/// How to open a log of any format.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OpenOptions {
    /// MCAP options.
    pub mcap: McapOptions,
    /// ULog and DataFlash options.
    pub binary: BinaryOptions,
}

/// The container recognised from the first bytes of `path` (`None`: not a binary log).
fn binary_format(path: &Path) -> Result<Option<LogFormat>> {
    if !path.is_file() {
        return Ok(None);
    }
    let mut f = aloft_core::open_regular_file(path).map_err(LogError::reading(path))?;
    let mut head = [0u8; 8];
    let mut n = 0;
    while n < head.len() {
        match f.read(&mut head[n..]).map_err(LogError::reading(path))? {
            0 => break,
            k => n += k,
        }
    }
    Ok(if is_ulog(&head[..n]) {
        Some(LogFormat::Px4Ulog)
    } else if is_dataflash(&head[..n]) {
        Some(LogFormat::ArduPilotDataflash)
    } else {
        None
    })
}

fn open_binary(path: &Path, format: LogFormat, o: &BinaryOptions) -> Result<LogReader> {
    let f = aloft_core::open_regular_file(path).map_err(LogError::reading(path))?;
    let r = BufReader::with_capacity(1 << 16, f);
    Ok(match format {
        LogFormat::Px4Ulog => LogReader::Ulog(Box::new(ulog_samples(r, o, path)?)),
        _ => LogReader::Dataflash(Box::new(dataflash_samples(r, o, path)?)),
    })
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
    let mut f = aloft_core::open_regular_file(path).map_err(LogError::reading(path))?;
    let mut head = [0u8; 8];
    let n = f.read(&mut head).map_err(LogError::reading(path))?;
    Ok(n == 8 && head == MCAP_MAGIC)
}

fn first_line(path: &Path) -> Result<String> {
    let f = aloft_core::open_regular_file(path).map_err(LogError::reading(path))?;
    let mut line = String::new();
    // A header longer than 64 KiB is not a layout we know; read at most that much.
    BufReader::new(f.take(1 << 16))
        .read_line(&mut line)
        .map_err(LogError::reading(path))?;
    Ok(line.trim_end().to_string())
}

/// A log path that exists must be a regular file: a FIFO, device or directory is refused before
/// it is opened (opening a FIFO blocks until a writer comes). A PX4 prefix need not exist.
fn refuse_non_regular(path: &Path) -> Result<()> {
    if std::fs::metadata(path).is_ok() {
        aloft_core::open_regular_file(path).map_err(LogError::reading(path))?;
    }
    Ok(())
}

/// Open a log. MCAP is recognised by extension or magic; a CSV uses `profile`, or without one is
/// recognised as KAIST by its header or as PX4 by its table name. A path that is not a regular
/// file (a FIFO, device or directory) is refused before it is opened.
pub fn open_log(path: &Path, profile: Option<&Profile>, mcap: &McapOptions) -> Result<LogReader> {
    let o = OpenOptions {
        mcap: mcap.clone(),
        ..OpenOptions::default()
    };
    open_log_with(path, profile, &o)
}

/// [`open_log`] with the options of every format. PX4 ULog (magic `55 4C 6F 67 01 12 35`) and
/// ArduPilot DataFlash (`A3 95 80`) are recognised by their first bytes, whatever the profile.
pub fn open_log_with(path: &Path, profile: Option<&Profile>, o: &OpenOptions) -> Result<LogReader> {
    refuse_non_regular(path)?;
    if let Some(format) = binary_format(path)? {
        return open_binary(path, format, &o.binary);
    }
    let mcap = &o.mcap;
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
            LogReader::Ulog(_) => LogFormat::Px4Ulog,
            LogReader::Dataflash(_) => LogFormat::ArduPilotDataflash,
        }
    }

    /// Absolute time of the first sample in the source's clock, s (after the first sample).
    pub fn start_time_s(&self) -> Option<f64> {
        match self {
            LogReader::Csv(r) => r.start_time_s(),
            LogReader::Px4(r) => r.start_time_s(),
            LogReader::Mcap(r) => r.start_time_s(),
            LogReader::Ulog(r) => r.start_time_s(),
            LogReader::Dataflash(r) => r.start_time_s(),
        }
    }

    /// Time report of the samples read so far.
    pub fn time_report(&self) -> TimeReport {
        match self {
            LogReader::Csv(r) => r.time_report(),
            LogReader::Px4(r) => r.time_report(),
            LogReader::Mcap(r) => r.time_report(),
            LogReader::Ulog(r) => r.time_report(),
            LogReader::Dataflash(r) => r.time_report(),
        }
    }

    /// Origin of geodetic positions.
    pub fn origin(&self) -> Option<GeoOrigin> {
        match self {
            LogReader::Csv(r) => r.origin(),
            LogReader::Dataflash(r) => r.origin(),
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

    /// What a ULog or DataFlash log holds besides its samples: battery records, energy,
    /// warnings (complete once every sample has been read).
    pub fn binary_summary(&self) -> Option<&BinarySummary> {
        match self {
            LogReader::Ulog(r) => Some(r.summary()),
            LogReader::Dataflash(r) => Some(r.summary()),
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
        self.read_rest(source)
    }

    /// Read every remaining sample into memory, keeping the reader (for what it learnt on the
    /// way, e.g. [`Self::binary_summary`]).
    pub fn read_rest(&mut self, source: &str) -> Result<Log> {
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
            LogReader::Ulog(r) => r.next(),
            LogReader::Dataflash(r) => r.next(),
        }
    }
}

/// Open and read a whole log.
pub fn read_log(path: &Path, profile: Option<&Profile>, mcap: &McapOptions) -> Result<Log> {
    open_log(path, profile, mcap)?.read_all(&path.display().to_string())
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::path::PathBuf;
    use std::sync::mpsc;
    use std::time::Duration;

    /// `open_log(path)`, which must answer within 10 s (opening a FIFO blocks for ever).
    fn open_at_once(path: PathBuf) -> Result<LogReader> {
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let r = open_log(&path, None, &McapOptions::default());
            let _ = tx.send(r);
        });
        rx.recv_timeout(Duration::from_secs(10))
            .expect("open_log did not return: it blocked on the path")
    }

    fn mkfifo(path: &Path) -> bool {
        std::process::Command::new("mkfifo")
            .arg(path)
            .status()
            .is_ok_and(|s| s.success())
    }

    #[test]
    fn fifos_directories_and_devices_are_refused_before_they_are_opened() {
        let dir = std::env::temp_dir().join(format!("aloft-logs-open-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut cases = vec![(dir.clone(), "directory")];
        // A FIFO under each name a log can have: MCAP, CSV, a PX4 table.
        for name in ["log.mcap", "log.csv", "flight_vehicle_local_position_0.csv"] {
            let p = dir.join(name);
            if mkfifo(&p) {
                cases.push((p, "FIFO"));
            }
        }
        if Path::new("/dev/zero").exists() {
            cases.push((PathBuf::from("/dev/zero"), "device"));
        }
        assert!(cases.len() > 1, "no FIFO could be made");
        for (path, kind) in cases {
            let e = open_at_once(path.clone())
                .err()
                .unwrap_or_else(|| panic!("{} was opened", path.display()));
            let msg = e.to_string();
            assert!(
                msg.contains(&path.display().to_string()) && msg.contains(kind),
                "{msg}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A PX4 log whose other tables are regular, one of them a FIFO: refused, not blocked on.
    #[test]
    fn a_fifo_among_px4_tables_is_refused() {
        let dir = std::env::temp_dir().join(format!("aloft-logs-px4fifo-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let prefix = dir.join("flight");
        std::fs::write(
            table(&prefix, PX4_TOPICS[0]),
            "timestamp,x,y,z,vx,vy,vz,ax,ay,az\n1,0,0,0,0,0,0,0,0,0\n",
        )
        .unwrap();
        std::fs::write(
            table(&prefix, PX4_TOPICS[2]),
            "timestamp,q[0],q[1],q[2],q[3]\n1,1,0,0,0\n",
        )
        .unwrap();
        if mkfifo(&table(&prefix, PX4_TOPICS[1])) {
            let e = open_at_once(table(&prefix, PX4_TOPICS[0]))
                .err()
                .expect("a FIFO table was opened");
            assert!(e.to_string().contains("FIFO"), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
