//! Flight logs: what a log holds ([`log_info`]), a log as MCAP ([`convert_log`]), and the logs
//! a fit or a validation reads ([`FlightLogs`]).

use std::path::{Path, PathBuf};

use serde::Serialize;

use aloft_logs::ground::IDLE_FRACTION_OF_HOVER;
use aloft_logs::sample::{Gap, NonMonotonic};
use aloft_logs::{
    estimate_lag_s, open_log_with, resample_uniform, BinaryOptions, BinarySummary, Channel,
    DroppedValue, InfoAccumulator, LogError, LogFormat, LogReader, McapFile, McapOptions, McapTime,
    OpenOptions, Profile, TimeReport,
};
use aloft_logs::{GroundDetector, GroundOptions, GroundPoint, GroundReport, Log};
use aloft_power::AoaModel;

use crate::engine::basics::files::check_output;
use crate::engine::basics::finite::finite;
use crate::error::Error;
use crate::identify::{align_flight, AlignOptions, AlignedFlight};

/// How to read a log: the CSV profile and the MCAP options (the options every log command
/// shares).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LogReadOptions {
    /// CSV profile: `kaist`, `px4`, or a column-map TOML file; `None`: recognised from the file.
    pub profile: Option<String>,
    /// MCAP: decode only these topics; empty: chosen by message type.
    pub topics: Vec<String>,
    /// MCAP: use the header stamps instead of the recording's log time.
    pub header_time: bool,
    /// MCAP: `sensor_msgs/BatteryState` current positive while discharging.
    pub battery_current_positive: bool,
    /// ULog and DataFlash: the battery instance to read (0: the first).
    pub battery_instance: u8,
}

/// Check a CSV profile (`kaist`, `px4`, or a column-map TOML file) without reading a log.
///
/// # Errors
/// An unknown profile name, a column map that cannot be read or is not one.
pub fn check_profile(profile: &str) -> Result<(), Error> {
    Profile::resolve(profile)?;
    Ok(())
}

impl LogReadOptions {
    fn profile(&self) -> Result<Option<Profile>, Error> {
        Ok(self.profile.as_deref().map(Profile::resolve).transpose()?)
    }

    fn mcap(&self) -> McapOptions {
        let mut o = McapOptions {
            topics: self.topics.clone(),
            ..McapOptions::default()
        };
        if self.header_time {
            o.time = McapTime::HeaderStamp;
        }
        o.decode.battery_current_positive_discharging = self.battery_current_positive;
        o
    }

    fn open_options(&self) -> OpenOptions {
        OpenOptions {
            mcap: self.mcap(),
            binary: BinaryOptions {
                battery_instance: self.battery_instance,
                ..BinaryOptions::default()
            },
        }
    }

    /// Open `path` as a stream of samples.
    fn open(&self, path: &Path) -> Result<(LogReader, Option<Profile>), Error> {
        let profile = self.profile()?;
        let reader = open_log_with(path, profile.as_ref(), &self.open_options())?;
        Ok((reader, profile))
    }
}

/// One channel of a log: how many samples and at what rate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogChannel {
    /// The channel.
    pub channel: Channel,
    /// Samples that carry it.
    pub samples: u64,
    /// Mean rate, Hz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
}

/// One MCAP topic.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogTopic {
    /// Topic name.
    pub topic: String,
    /// Schema name.
    pub schema: String,
    /// Message encoding.
    pub message_encoding: String,
    /// Messages on the topic.
    pub messages: u64,
    /// Messages decoded.
    pub decoded: u64,
    /// Mean rate, Hz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
    /// Channels it fed.
    pub used_for: Vec<Channel>,
}

/// The regularity of a log's time base (the first ten gaps and backward steps).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogTime {
    /// The typical sample period, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal_period_s: Option<f64>,
    /// Gaps longer than three periods.
    pub gap_count: u64,
    /// Steps backwards in time.
    pub non_monotonic_count: u64,
    /// The first gaps.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub gaps: Vec<Gap>,
    /// The first backward steps.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub non_monotonic: Vec<NonMonotonic>,
}

impl From<&TimeReport> for LogTime {
    fn from(r: &TimeReport) -> Self {
        Self {
            nominal_period_s: r.nominal_period_s,
            gap_count: r.gap_count,
            non_monotonic_count: r.non_monotonic_count,
            gaps: r.gaps.iter().take(10).copied().collect(),
            non_monotonic: r.non_monotonic.iter().take(10).copied().collect(),
        }
    }
}

/// The lag of power behind ground speed, by cross-correlation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LagInfo {
    /// Lag, s.
    pub lag_s: f64,
    /// Correlation at the lag.
    pub correlation: f64,
    /// Correlation at zero lag.
    pub correlation_at_zero: f64,
    /// True when the best lag is at the edge of the search window.
    pub at_window_edge: bool,
    /// Log time up to which the samples were used, s, when the log was longer than the search
    /// keeps (about 2 million samples of each series); absent when the whole log was used.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub used_until_s: Option<f64>,
}

/// What a PX4 ULog or ArduPilot DataFlash log holds besides its samples.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BinaryLogInfo {
    /// Records decoded, by topic or record type (the kinds aloft reads).
    pub records: std::collections::BTreeMap<String, u64>,
    /// The battery instance read.
    pub battery_instance: u8,
    /// Battery instances with records.
    pub battery_instances: Vec<u8>,
    /// Battery records of the instance read.
    pub battery_records: u64,
    /// Of them, used for the energy.
    pub battery_valid: u64,
    /// Left out: current unknown (PX4 `current_a` < 0).
    pub battery_unknown_current: u64,
    /// Left out: voltage not positive (no sensor).
    pub battery_no_voltage: u64,
    /// Time from the first to the last valid battery record, s.
    pub battery_span_s: f64,
    /// Battery cells (parameters).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub battery_cells: Option<u32>,
    /// Battery capacity (parameters), A h.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub battery_capacity_ah: Option<f64>,
    /// Mean air density (PX4 `vehicle_air_data`, ArduPilot `BARO`), kg/m^3.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub air_density_kg_m3: Option<f64>,
    /// Time not landed (PX4 `vehicle_land_detected`), s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub in_air_s: Option<f64>,
    /// Bytes skipped over corrupt data.
    pub bytes_skipped: u64,
    /// Bytes read.
    pub bytes: u64,
}

impl BinaryLogInfo {
    fn of(s: &BinarySummary, battery_instance: u8) -> Self {
        Self {
            records: s.records.clone(),
            battery_instance,
            battery_instances: s.battery_instances.clone(),
            battery_records: s.battery.records,
            battery_valid: s.battery.valid,
            battery_unknown_current: s.battery.unknown_current,
            battery_no_voltage: s.battery.no_voltage,
            battery_span_s: s.battery.span_s(),
            battery_cells: s.battery_cells,
            battery_capacity_ah: s.battery_capacity_ah,
            air_density_kg_m3: s.air_density_kg_m3,
            in_air_s: s.in_air_s,
            bytes_skipped: s.bytes_skipped,
            bytes: s.bytes,
        }
    }
}

/// What a log holds: the JSON of `aloft log info --format json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogInfo {
    /// The file.
    pub file: String,
    /// Its format.
    pub format: LogFormat,
    /// The CSV profile used.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub profile: Option<String>,
    /// Samples read.
    pub samples: u64,
    /// Time from the first to the last sample, s.
    pub duration_s: f64,
    /// Time of the first sample in the log's own clock, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_time_s: Option<f64>,
    /// Channels found.
    pub channels: Vec<LogChannel>,
    /// CSV columns.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub columns: Option<Vec<String>>,
    /// MCAP topics.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub topics: Option<Vec<LogTopic>>,
    /// Whether the log has electrical power (voltage and current, or a power channel).
    pub power_available: bool,
    /// Energy used (trapezoid of V x I), Wh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_wh: Option<f64>,
    /// Mean power, W.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_power_w: Option<f64>,
    /// Largest power, W.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_power_w: Option<f64>,
    /// Regularity of the time base.
    pub time: LogTime,
    /// Values left out as isolated contradictions (e.g. power far from V x I on one row).
    pub dropped_values: u64,
    /// The first ten of them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dropped: Vec<DroppedValue>,
    /// With a lag search (`--max-lag`): the lag of power behind ground speed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lag: Option<LagInfo>,
    /// ULog and DataFlash: records, battery records, parameters.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub log: Option<BinaryLogInfo>,
    /// What went wrong or was left out while reading (corrupt or truncated data with its byte
    /// offset, records left out, no battery data).
    pub warnings: Vec<String>,
}

/// Energy, power availability, warnings and the binary details of a log just read: a ULog or
/// DataFlash log's battery records decide (the trapezoid over the records themselves); any other
/// log's joined samples.
fn power_facts(
    reader: &LogReader,
    stats: &aloft_logs::LogStats,
    battery_instance: u8,
) -> (Option<f64>, bool, Vec<String>, Option<BinaryLogInfo>) {
    match reader.binary_summary() {
        Some(b) => (
            b.energy_wh(),
            b.power_available(),
            b.warnings.clone(),
            Some(BinaryLogInfo::of(b, battery_instance)),
        ),
        None => {
            let available = stats.power.energy_wh.is_some() || stats.power.mean_power_w.is_some();
            let warnings = if available {
                Vec::new()
            } else {
                vec![
                    "the log has no battery data: no voltage and current (or power) channel".into(),
                ]
            };
            (stats.power.energy_wh, available, warnings, None)
        }
    }
}

/// Most samples of each series the lag search keeps (58 hours at 10 Hz): memory stays bounded
/// whatever the log's length; a longer log's lag is estimated from its first part (and says so).
const LAG_SAMPLES: usize = 1 << 21;

/// Power and ground-speed series kept for the lag search.
#[derive(Default)]
struct LagSeries {
    power_t: Vec<f64>,
    power_w: Vec<f64>,
    speed_t: Vec<f64>,
    speed_mps: Vec<f64>,
    /// Time of the first sample left out when a series was full.
    full_at_s: Option<f64>,
}

impl LagSeries {
    fn push(&mut self, s: &aloft_logs::Sample) {
        let full = self.power_t.len() >= LAG_SAMPLES || self.speed_t.len() >= LAG_SAMPLES;
        if full {
            self.full_at_s.get_or_insert(s.time_s);
            return;
        }
        if let Some(w) = s.electrical_power_w() {
            self.power_t.push(s.time_s);
            self.power_w.push(w);
        }
        if let Some(u) = s.vel_enu_mps {
            self.speed_t.push(s.time_s);
            self.speed_mps.push(u[0].hypot(u[1]));
        }
    }
}

/// Summarise the log at `path`: duration, rates, channels or topics, energy used, the regularity
/// of the time base; with `max_lag_s` (`--max-lag`), the lag of power behind ground speed
/// searched within +-that many seconds.
///
/// # Errors
/// A log that cannot be opened or decoded; a lag search on a log without power or velocity.
pub fn log_info(
    path: &Path,
    options: &LogReadOptions,
    max_lag_s: Option<f64>,
) -> Result<LogInfo, Error> {
    let (mut reader, profile) = options.open(path)?;
    let mut acc = InfoAccumulator::new();
    let mut series = LagSeries::default();
    for s in reader.by_ref() {
        let s = s?;
        acc.push(&s);
        if max_lag_s.is_some() {
            series.push(&s);
        }
    }
    let stats = acc.finish();
    let time = reader.time_report();
    let (dropped_values, mut dropped) = reader.dropped();
    dropped.truncate(10);
    let file = path.display().to_string();
    let (energy_wh, power_available, warnings, log) =
        power_facts(&reader, &stats, options.battery_instance);
    let lag = match max_lag_s {
        None => None,
        Some(max) => Some(lag_of(&file, &series, time.nominal_period_s, max)?),
    };
    finite(
        LogInfo {
            format: reader.format(),
            profile: match reader.format() {
                LogFormat::Mcap | LogFormat::Px4Ulog | LogFormat::ArduPilotDataflash => None,
                LogFormat::Px4Csv => Some("px4".into()),
                LogFormat::Csv => Some(profile.map_or("kaist".into(), |p| p.name())),
            },
            samples: stats.samples,
            duration_s: stats.duration_s,
            start_time_s: reader.start_time_s(),
            channels: stats
                .channels
                .iter()
                .map(|c| LogChannel {
                    channel: c.channel,
                    samples: c.samples,
                    rate_hz: c.rate_hz(),
                })
                .collect(),
            columns: reader.columns().map(|c| c.to_vec()),
            topics: reader.topics().map(|t| t.iter().map(topic).collect()),
            power_available,
            energy_wh,
            mean_power_w: stats.power.mean_power_w,
            max_power_w: stats.power.max_power_w,
            time: LogTime::from(&time),
            dropped_values,
            dropped,
            lag,
            file,
            log,
            warnings,
        },
        "log info",
        || path.display().to_string(),
    )
}

fn topic(t: &aloft_logs::TopicInfo) -> LogTopic {
    LogTopic {
        topic: t.topic.clone(),
        schema: t.schema.clone(),
        message_encoding: t.message_encoding.clone(),
        messages: t.messages,
        decoded: t.decoded,
        rate_hz: t.rate_hz(),
        used_for: t.used_for.clone(),
    }
}

/// The lag of power behind ground speed: both series resampled on one grid over their common
/// span, then cross-correlated.
fn lag_of(
    file: &str,
    s: &LagSeries,
    nominal_period_s: Option<f64>,
    max_lag_s: f64,
) -> Result<LagInfo, Error> {
    if s.power_w.is_empty() {
        return Err(Error::MissingChannel {
            origin: file.to_string(),
            needed_for: "--max-lag",
            channel: "power data (voltage and current)",
        });
    }
    if s.speed_mps.is_empty() {
        return Err(Error::MissingChannel {
            origin: file.to_string(),
            needed_for: "--max-lag",
            channel: "velocity data",
        });
    }
    let dt = nominal_period_s.unwrap_or(0.1);
    let (t0p, pu) = resample_uniform(&s.power_t, &s.power_w, dt)?;
    let (t0v, vu) = resample_uniform(&s.speed_t, &s.speed_mps, dt)?;
    // Align both grids on their common span (none when one series ends before the other
    // starts: the offsets are then clamped to the grids and no sample is left to correlate).
    let off_p = (((t0v - t0p) / dt).round().max(0.0) as usize).min(pu.len());
    let off_v = (((t0p - t0v) / dt).round().max(0.0) as usize).min(vu.len());
    let n = pu
        .len()
        .saturating_sub(off_p)
        .min(vu.len().saturating_sub(off_v));
    if n < 10 {
        // Say what is wrong: the series do not share enough time, not the search window.
        let span = |t0: f64, len: usize| format!("{t0:.3} to {:.3} s", t0 + dt * len as f64);
        return Err(Error::NoCommonSpan {
            origin: file.to_string(),
            power: span(t0p, pu.len()),
            velocity: span(t0v, vu.len()),
            shared: n,
            step: format!(
                "{} s",
                format!("{dt:.6}")
                    .trim_end_matches('0')
                    .trim_end_matches('.')
            ),
        });
    }
    let e = estimate_lag_s(&pu[off_p..off_p + n], &vu[off_v..off_v + n], dt, max_lag_s).map_err(
        |e| Error::Log {
            origin: "lag estimation".to_string(),
            source: Box::new(e),
        },
    )?;
    Ok(LagInfo {
        lag_s: e.lag_s,
        correlation: e.correlation,
        correlation_at_zero: e.correlation_at_zero,
        at_window_edge: e.at_window_edge,
        used_until_s: s.full_at_s,
    })
}

/// Messages written to one topic by [`convert_log`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TopicCount {
    /// Topic name.
    pub topic: String,
    /// Messages written.
    pub messages: u64,
}

/// The answer of [`convert_log`] (the JSON of `aloft convert --format json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConvertSummary {
    /// The log read.
    pub input: String,
    /// The MCAP file written.
    pub output: String,
    /// Samples converted.
    pub samples: u64,
    /// Messages per topic.
    pub topics: Vec<TopicCount>,
    /// Gaps and backward steps of the input's time base, kept as they are (not part of the JSON).
    #[serde(skip)]
    pub time_notes: Option<(u64, u64)>,
}

/// Convert the log at `input` to MCAP (JSON with JSON Schemas) at `output`, written in aloft's
/// one way ([`McapFile`]): to a temporary file beside it, placed when the whole log is written,
/// so a bad input or a failure while converting leaves nothing; an existing file is replaced only
/// with `force`.
///
/// # Errors
/// A log that cannot be opened or decoded, holds no samples, or an output that exists (without
/// `force`) or cannot be written.
pub fn convert_log(
    input: &Path,
    options: &LogReadOptions,
    output: &Path,
    force: bool,
) -> Result<ConvertSummary, Error> {
    check_output(output, force)?;
    let (mut reader, _) = options.open(input)?;
    let first = match reader.next() {
        Some(s) => s?,
        None => {
            return Err(Error::EmptyLog {
                origin: input.display().to_string(),
            })
        }
    };
    let mut w = McapFile::create(output, force)?;
    if let Some(t) = reader.start_time_s().filter(|t| *t > 0.0) {
        w.set_start_ns((t * 1e9).round() as u64);
    }
    w.write_sample(0, &first)?;
    let mut n = 1u64;
    let result = (|| -> Result<(), Error> {
        for s in reader.by_ref() {
            w.write_sample(n as usize, &s?)?;
            n += 1;
        }
        Ok(())
    })();
    // On an error the half-written file goes with `w`: nothing is placed.
    result?;
    let summary = w.commit()?;
    let time = reader.time_report();
    finite(
        ConvertSummary {
            input: input.display().to_string(),
            output: output.display().to_string(),
            samples: n,
            topics: summary
                .messages
                .iter()
                .map(|(t, m)| TopicCount {
                    topic: t.clone(),
                    messages: *m,
                })
                .collect(),
            time_notes: (!time.is_clean()).then_some((time.gap_count, time.non_monotonic_count)),
        },
        "convert",
        || input.display().to_string(),
    )
}

/// A flight log as given: its file and the payload that flight carried beyond the request's.
#[derive(Debug, Clone, PartialEq)]
pub struct LogArg {
    /// The file.
    pub path: PathBuf,
    /// Payload, kg (0: none beyond the request's).
    pub payload_kg: f64,
}

impl LogArg {
    /// `FILE` or `FILE:payload_kg=KG` (KG finite, 0 to 1000). A file whose whole name exists is
    /// that file, whatever it holds.
    ///
    /// # Errors
    /// The message of a payload that is not a number of kilograms, or a key other than
    /// `payload_kg`.
    pub fn parse(text: &str) -> Result<Self, String> {
        const KEY: &str = ":payload_kg=";
        let whole = || Self {
            path: PathBuf::from(text),
            payload_kg: 0.0,
        };
        if Path::new(text).exists() {
            return Ok(whole());
        }
        let Some((file, value)) = text.rsplit_once(KEY) else {
            if let Some((_, rest)) = text.rsplit_once(':') {
                if let Some((key, _)) = rest.split_once('=') {
                    return Err(format!(
                        "'{key}' is not a per-log option (expected FILE:payload_kg=KG)"
                    ));
                }
            }
            return Ok(whole());
        };
        match value.trim().parse::<f64>() {
            Ok(kg) if kg.is_finite() && (0.0..=1000.0).contains(&kg) => Ok(Self {
                path: PathBuf::from(file),
                payload_kg: kg,
            }),
            _ => Err(format!(
                "payload_kg '{value}' of {file} is not a payload in kg from 0 to 1000"
            )),
        }
    }
}

/// The flight logs a fit or a validation reads, and how to align power with motion in them.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightLogs {
    /// The log files (CSV or MCAP).
    pub logs: Vec<PathBuf>,
    /// Per log, in `logs`' order, the payload that flight carried beyond the request's, kg
    /// (`--log FILE:payload_kg=KG`); a log past its end carried none.
    pub payloads_kg: Vec<f64>,
    /// CSV profile: `kaist`, `px4` or a column-map TOML; `None`: recognised from the file.
    pub profile: Option<String>,
    /// Angle-of-attack model for the logged states.
    pub aoa: AoaModel,
    /// Use this lag of power behind motion instead of estimating it, s.
    pub lag_s: Option<f64>,
    /// Search window of the lag estimate, s.
    pub max_lag_s: f64,
    /// ULog and DataFlash: the battery instance to read.
    pub battery_instance: u8,
}

impl Default for FlightLogs {
    fn default() -> Self {
        Self {
            logs: Vec::new(),
            payloads_kg: Vec::new(),
            profile: None,
            aoa: AoaModel::Geometric,
            lag_s: None,
            max_lag_s: 10.0,
            battery_instance: 0,
        }
    }
}

impl FlightLogs {
    /// The payload the `index`-th log's flight carried beyond the request's, kg.
    pub fn payload_kg(&self, index: usize) -> f64 {
        self.payloads_kg.get(index).copied().unwrap_or(0.0)
    }

    /// These logs with only the files `keep` keeps (each with its payload).
    pub(crate) fn retain_files(&self, keep: impl Fn(&Path) -> bool) -> Self {
        let (logs, payloads_kg) = self
            .logs
            .iter()
            .enumerate()
            .filter(|(_, p)| keep(p))
            .map(|(i, p)| (p.clone(), self.payload_kg(i)))
            .unzip();
        Self {
            logs,
            payloads_kg,
            ..self.clone()
        }
    }

    /// The profile and reading options every log is opened with.
    fn open_options(&self) -> Result<(Option<Profile>, OpenOptions), Error> {
        let profile = self.profile.as_deref().map(Profile::resolve).transpose()?;
        let open = OpenOptions {
            binary: BinaryOptions {
                battery_instance: self.battery_instance,
                ..BinaryOptions::default()
            },
            ..OpenOptions::default()
        };
        Ok((profile, open))
    }

    /// The first log as events, read as it is (no alignment): a ULog's or DataFlash log's
    /// battery parameters (`BAT*`, `BATT_*`: what its failsafes act on) before its first
    /// record, its samples, and a DataFlash log's mode, arming and mission
    /// ([`aloft_logs::flight_events`]) from a second pass over the file.
    pub(crate) fn events_of_first(&self) -> Result<aloft_logs::telemetry::LogEvents, Error> {
        let (profile, mut open) = self.open_options()?;
        // The parameters are collected with the battery's details.
        open.binary.battery_details = true;
        let path = self.logs.first().ok_or_else(|| Error::InvalidInput {
            name: "replay",
            value: 0.0,
            unit: "logs",
            expected: "one flight log",
        })?;
        let mut reader = open_log_with(path, profile.as_ref(), &open)?;
        let log = reader.read_rest(&path.display().to_string())?;
        let events = match reader.format() {
            LogFormat::ArduPilotDataflash => {
                let file = std::fs::File::open(path).map_err(|source| Error::Io {
                    origin: path.display().to_string(),
                    source,
                })?;
                let file = std::io::BufReader::new(file);
                aloft_logs::flight_events::dataflash_events(file, log.start_time_s)
            }
            _ => Vec::new(),
        };
        let parameters = reader
            .binary_summary()
            .and_then(|s| s.kept_parameters())
            .map(|p| {
                p.iter()
                    .filter(|(name, _)| name.starts_with("BAT"))
                    .map(|(name, value)| (name.clone(), *value))
                    .collect()
            })
            .unwrap_or_default();
        Ok(aloft_logs::telemetry::LogEvents::with_events(log, events).with_parameters(parameters))
    }

    /// Read every log, align power with motion, and set the angle-of-attack model.
    pub(crate) fn load(&self) -> Result<Vec<(AlignedFlight, aloft_logs::Log)>, Error> {
        self.load_each(AlignOptions::default().idle_power_fraction)?
            .into_iter()
            .collect()
    }

    /// The logs that can be used, read and aligned, and those that cannot, each with its reason
    /// (the one rule of `aloft fit` and `aloft validate`: a log that cannot be read, never flew
    /// ([`check_flew`]) or cannot be aligned is left out and said). Samples below
    /// `idle_power_fraction` of a flight's median power are left out as on the ground
    /// ([`AlignOptions::idle_power_fraction`]; 0 keeps them all).
    ///
    /// # Errors
    /// [`Error::NoUsableLog`] when no log can be used; what every log shares (a profile).
    pub(crate) fn usable(
        &self,
        idle_power_fraction: f64,
    ) -> Result<(Vec<Loaded>, Vec<SkippedLog>), Error> {
        let mut flights = Vec::new();
        let mut skipped = Vec::new();
        for (path, loaded) in self.logs.iter().zip(self.load_each(idle_power_fraction)?) {
            match loaded {
                Ok(flight) => flights.push(flight),
                Err(e) => skipped.push(SkippedLog {
                    file: path.display().to_string(),
                    reason: e.to_string(),
                }),
            }
        }
        if flights.is_empty() {
            let reasons: Vec<&str> = skipped.iter().map(|s| s.reason.as_str()).collect();
            return Err(Error::NoUsableLog {
                reasons: reasons.join("; "),
            });
        }
        Ok((flights, skipped))
    }

    /// These logs without the ones `skipped` names (each kept log with its payload).
    pub(crate) fn without(&self, skipped: &[SkippedLog]) -> Self {
        self.retain_files(|p| !skipped.iter().any(|s| s.file == p.display().to_string()))
    }

    /// [`Self::load`], each log on its own: a log that cannot be read or aligned is its error,
    /// and the others are read all the same (a fit skips it). The error of the whole is only for
    /// what every log shares (a profile that cannot be read).
    pub(crate) fn load_each(&self, idle_power_fraction: f64) -> Result<Vec<LoadedLog>, Error> {
        let (profile, open) = self.open_options()?;
        let align = AlignOptions {
            max_lag_s: self.max_lag_s,
            lag_s: self.lag_s,
            idle_power_fraction,
        };
        Ok(self
            .logs
            .iter()
            .map(|path| self.load_one(path, profile.as_ref(), &open, &align))
            .collect())
    }

    fn load_one(
        &self,
        path: &Path,
        profile: Option<&Profile>,
        open: &OpenOptions,
        align: &AlignOptions,
    ) -> LoadedLog {
        let mut reader = open_log_with(path, profile, open)?;
        let log = reader.read_rest(&path.display().to_string())?;
        if let Some(reason) = reader.binary_summary().and_then(|b| b.no_power_reason()) {
            return Err(LogError::NoBatteryData {
                source_name: path.display().to_string(),
                reason,
            }
            .into());
        }
        // A log that never left the ground is said so, before its lag is searched for.
        check_flew(&log)?;
        let mut flight = align_flight(&log, align)?;
        flight.air_density_kg_m3 = reader
            .binary_summary()
            .and_then(|b| b.air_density_kg_m3)
            .filter(|rho| rho.is_finite() && (0.3..=1.6).contains(rho));
        if self.aoa == AoaModel::Paper {
            for s in &mut flight.samples {
                s.state.aoa = aloft_power::AoaInput::Paper;
            }
        }
        Ok((flight, log))
    }
}

/// A log a request left out (`aloft fit`, `aloft pack fit`), and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkippedLog {
    /// The log.
    pub file: String,
    /// Why, in words (the error that reading or using it gave).
    pub reason: String,
}

/// A log read and aligned: its flight and its samples.
pub(crate) type Loaded = (AlignedFlight, aloft_logs::Log);

/// One log of [`FlightLogs::load_each`]: aligned with its samples, or why not.
pub(crate) type LoadedLog = Result<Loaded, Error>;

/// Whether a log flew, the one rule of `aloft fit` and `aloft validate` (through
/// [`crate::engine::basics::logs::FlightLogs::usable`]): a log whose own landed state (PX4
/// `vehicle_land_detected`, ArduPilot's arming and landing) keeps it on the ground from its first
/// record to its last never flew. A log without a landed state is not judged here (nothing in
/// it tells a hover from the ground without a model of the vehicle).
///
/// # Errors
/// [`Error::NeverFlew`] with the log's span.
pub(crate) fn check_flew(log: &Log) -> Result<(), Error> {
    let ground = ground_time(log, None);
    if ground.airborne.is_empty() && ground.logged_points > 0 {
        return Err(Error::NeverFlew {
            origin: log.source.clone(),
            duration_s: ground.last_s - ground.first_s,
        });
    }
    Ok(())
}

/// The ground time of the log: its own landed state where it has one, else detected from height,
/// speed and power, with a power under [`IDLE_FRACTION_OF_HOVER`] of the model's hover power
/// `hover_w` counting as idle ([`aloft_logs::ground`]).
pub(crate) fn ground_time(log: &Log, hover_w: Option<f64>) -> GroundReport {
    let mut detector = GroundDetector::new(GroundOptions {
        idle_max_w: hover_w
            .filter(|w| w.is_finite() && *w > 0.0)
            .map(|w| IDLE_FRACTION_OF_HOVER * w),
        ..GroundOptions::default()
    });
    for s in &log.samples {
        detector.push(&GroundPoint::from(s));
    }
    detector.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression (found by aloft-fuzz on an MCAP log): power and velocity series that do not
    /// overlap in time (the power ends before the velocity starts) made the grid offset exceed
    /// the power grid, and `log info --lag` (now `--max-lag`) panicked slicing it. It is now an
    /// error.
    #[test]
    fn a_lag_search_on_series_that_do_not_overlap_is_an_error() {
        let s = LagSeries {
            power_t: (0..5).map(f64::from).collect(),
            power_w: vec![100.0; 5],
            speed_t: (40..50).map(f64::from).collect(),
            speed_mps: vec![3.0; 10],
            full_at_s: None,
        };
        let e = lag_of("log.mcap", &s, Some(1.0), 5.0).unwrap_err();
        assert!(e.to_string().contains("lag"), "{e}");
        // And the other way round.
        let s = LagSeries {
            power_t: s.speed_t.clone(),
            power_w: vec![100.0; 10],
            speed_t: (0..5).map(f64::from).collect(),
            speed_mps: vec![3.0; 5],
            full_at_s: None,
        };
        assert!(lag_of("log.mcap", &s, Some(1.0), 5.0).is_err());
    }
}
