//! The seam between a log file and the logbook: [`read_flight`] turns one log into the figures
//! of one `flights` row ([`FlightFacts`]). Everything the logbook knows of a log comes through
//! here.

use std::path::Path;

use aloft_logs::{open_log_with, read_battery_log, BinaryOptions, OpenOptions, Profile, Sample};
use aloft_packs::analyse;

/// How a log is read: the CSV profile and the battery instance.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadOptions {
    /// CSV profile: `kaist`, `px4`, or a column-map TOML file; `None`: recognised from the file.
    pub profile: Option<String>,
    /// ULog and DataFlash: the battery instance to read (0: the first).
    pub battery_instance: u8,
}

/// What one log says of its flight: the figures of a `flights` row before the keys are chosen.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FlightFacts {
    /// The log's container: `ulog`, `dataflash`, `csv`, `mcap`.
    pub format: String,
    /// The vehicle's identity in the log (PX4 `sys_uuid`, ArduPilot `BRD_SERIAL_NUM`).
    pub vehicle_id: Option<String>,
    /// The pack's identity in the log (a smart pack's serial, ArduPilot `BATT_SERIAL_NUM`).
    pub pack_id: Option<String>,
    /// The pack's rated capacity (parameters), mAh.
    pub rated_capacity_mah: Option<f64>,
    /// Cells in series (parameters).
    pub cells_series: Option<u32>,
    /// Start of the log, Unix time, s (when the log has a clock that says it).
    pub start_unix_s: Option<f64>,
    /// Time from the first to the last battery sample, s.
    pub duration_s: f64,
    /// Energy drawn from the pack (trapezoid of V x I), Wh.
    pub energy_wh: f64,
    /// Charge drawn from the pack (trapezoid of I), mAh.
    pub discharged_mah: Option<f64>,
    /// Largest current, A.
    pub max_current_a: Option<f64>,
    /// Lowest voltage, V.
    pub min_voltage_v: Option<f64>,
    /// Mean power over the battery samples (energy / duration), W.
    pub mean_power_w: Option<f64>,
    /// Mean power while hovering (see [`hover_power_w`]), W.
    pub hover_power_w: Option<f64>,
    /// The pack's internal resistance from current steps, ohm.
    pub resistance_ohm: Option<f64>,
    /// The autopilot's own estimate of the pack's resistance, ohm.
    pub autopilot_resistance_ohm: Option<f64>,
    /// Usable capacity between two rested points, mAh.
    pub capacity_mah: Option<f64>,
    /// Why no capacity was estimated.
    pub capacity_refusal: Option<String>,
    /// Minutes with a cell more than 0.01 V from the others.
    pub imbalance_minor_min: Option<f64>,
    /// Minutes with a cell more than 0.07 V from the others.
    pub imbalance_major_min: Option<f64>,
    /// Time in the air (the log's landed state, or armed and not landed), s; `None` where the
    /// log says neither.
    pub air_s: Option<f64>,
    /// The pack's high voltage: the 95th percentile of its records' (a spike of a few records
    /// aside), V: the pack's cells where its log does not state them ([`crate::cells_of`]).
    pub high_voltage_v: Option<f64>,
}

impl FlightFacts {
    /// The mean power of a flight, W: its energy over its duration, where the log measured the
    /// current (`discharged_mah` is known; without it the energy is not the pack's).
    pub fn mean_power_w(
        duration_s: f64,
        energy_wh: f64,
        discharged_mah: Option<f64>,
    ) -> Option<f64> {
        (duration_s > 0.0 && discharged_mah.is_some()).then(|| energy_wh * 3600.0 / duration_s)
    }
}

/// Read the log at `path` into the figures of its flight: the pack's figures from its battery
/// records ([`aloft_logs::read_battery_log`], [`aloft_packs::analyse`]), the hover power from
/// its samples joined onto the motion (absent when the log has no velocity).
///
/// # Errors
/// Why the log is not a flight of the logbook, in words (the `skipped` table's reason): it
/// cannot be opened or decoded, or it has fewer than two battery records.
pub fn read_flight(path: &Path, options: &ReadOptions) -> Result<FlightFacts, String> {
    refuse_unread(path)?;
    read(path, options).map_err(|reason| {
        // The reason is stored beside the file's name: without the path the readers lead with.
        let prefix = format!("{}: ", path.display());
        reason
            .strip_prefix(&prefix)
            .map_or_else(|| reason.clone(), str::to_string)
    })
}

/// What the first bytes of a file say it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogKind {
    /// PX4 ULog, ArduPilot DataFlash or MCAP (by their magic bytes), or text (a CSV): read by
    /// [`read_flight`].
    Readable,
    /// A MAVLink telemetry log (`.tlog`): a plausible timestamp (µs since 1970, years 2000 to
    /// 2100, big-endian) and a MAVLink magic byte (`0xFE`, `0xFD`) after it. The logbook takes
    /// its flight from a reader of MAVLink ([`crate::Logbook::add_with`]).
    Tlog,
    /// Anything else (binary, and none of the above).
    Other,
}

/// Bytes of a file looked at to say what it is.
const HEAD_LEN: usize = 4096;
/// 2000-01-01 and 2100-01-01, µs since 1970 (a `.tlog`'s timestamps).
const TLOG_TIME_US: std::ops::Range<u64> = 946_684_800_000_000..4_102_444_800_000_000;

/// What the file at `path` is, from its first bytes (`Readable` when it cannot be read: the
/// reader then says why).
pub fn log_kind(path: &Path) -> LogKind {
    use std::io::Read;
    let mut head = Vec::with_capacity(HEAD_LEN);
    let read =
        std::fs::File::open(path).and_then(|f| f.take(HEAD_LEN as u64).read_to_end(&mut head));
    if read.is_err() || head.is_empty() {
        return LogKind::Readable;
    }
    kind_of(&head)
}

/// [`log_kind`] of a file's first bytes.
pub fn kind_of(head: &[u8]) -> LogKind {
    const MAGIC: [&[u8]; 3] = [b"ULog", &[0xA3, 0x95], b"\x89MCAP"];
    if MAGIC.iter().any(|m| head.starts_with(m)) {
        return LogKind::Readable;
    }
    if head.len() > 8 && matches!(head[8], 0xFE | 0xFD) {
        let t = u64::from_be_bytes(head[..8].try_into().unwrap_or_default());
        if TLOG_TIME_US.contains(&t) {
            return LogKind::Tlog;
        }
    }
    // Text: UTF-8 (a character cut by the end of the head aside) without NUL.
    let text = match std::str::from_utf8(head) {
        Ok(_) => true,
        Err(e) => e.error_len().is_none(),
    };
    if text && !head.contains(&0) {
        LogKind::Readable
    } else {
        LogKind::Other
    }
}

/// A file the logbook does not read, refused in words before a reader tries it.
fn refuse_unread(path: &Path) -> Result<(), String> {
    match log_kind(path) {
        LogKind::Readable => Ok(()),
        LogKind::Tlog => Err(
            "a MAVLink telemetry log (.tlog): read by aloft's command line (aloft logbook add), \
             not by this library alone"
                .to_string(),
        ),
        LogKind::Other => Err(NOT_A_LOG.to_string()),
    }
}

/// Why a file of no format the logbook reads is skipped.
pub const NOT_A_LOG: &str = "not a log the logbook reads (PX4 ULog, ArduPilot DataFlash, \
     MCAP, CSV, MAVLink .tlog)";

fn read(path: &Path, options: &ReadOptions) -> Result<FlightFacts, String> {
    let profile = options
        .profile
        .as_deref()
        .map(Profile::resolve)
        .transpose()
        .map_err(|e| e.to_string())?;
    let open = OpenOptions {
        binary: BinaryOptions {
            battery_instance: options.battery_instance,
            ..BinaryOptions::default()
        },
        ..OpenOptions::default()
    };
    let battery = read_battery_log(path, profile.as_ref(), &open).map_err(|e| e.to_string())?;
    let r = analyse(&battery).map_err(|e| e.to_string())?;
    let high_voltage_v = high_voltage_v(battery.samples.iter().map(|s| s.voltage_v));
    let (hover_power_w, air_s) = motion_of(path, profile.as_ref(), &open);
    Ok(FlightFacts {
        format: r.format,
        vehicle_id: r.vehicle_id,
        pack_id: r.pack_id,
        rated_capacity_mah: r.rated_capacity_mah,
        cells_series: r.cells_series,
        start_unix_s: r.start_unix_s,
        duration_s: r.duration_s,
        energy_wh: r.energy_wh,
        discharged_mah: r.discharged_mah,
        max_current_a: r.max_current_a,
        min_voltage_v: Some(r.min_voltage_v).filter(|v| v.is_finite()),
        mean_power_w: FlightFacts::mean_power_w(r.duration_s, r.energy_wh, r.discharged_mah),
        hover_power_w,
        resistance_ohm: r.internal_resistance_ohm,
        autopilot_resistance_ohm: r.autopilot_internal_resistance_ohm,
        capacity_mah: r.capacity_mah,
        capacity_refusal: r.capacity_refused,
        imbalance_minor_min: r.imbalance_minor_min,
        imbalance_major_min: r.imbalance_major_min,
        air_s,
        high_voltage_v,
    })
}

/// The hover power and the time in the air of the log's samples (`None` when they cannot be
/// read: the battery figures stand without them).
fn motion_of(
    path: &Path,
    profile: Option<&Profile>,
    open: &OpenOptions,
) -> (Option<f64>, Option<f64>) {
    let Some(log) = open_log_with(path, profile, open)
        .ok()
        .and_then(|mut reader| reader.read_rest(&path.display().to_string()).ok())
    else {
        return (None, None);
    };
    (hover_power_w(&log.samples), air_s(&log.samples))
}

/// The 95th percentile of the finite positive `volts`, V: the pack's high voltage, a spike of
/// up to one record in twenty aside (one KAIST flight logs 90 V on a 12S pack of 50 V).
pub fn high_voltage_v(volts: impl Iterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = volts.filter(|v| v.is_finite() && *v > 0.0).collect();
    v.sort_by(f64::total_cmp);
    let i = (v.len().checked_sub(1)? as f64 * 0.95).floor() as usize;
    v.get(i).copied()
}

/// Time in the air: each sample the log says is not landed, weighted by the time to the next
/// sample; `None` where no sample says the landed state.
pub fn air_s(samples: &[Sample]) -> Option<f64> {
    samples.iter().find(|s| s.landed.is_some())?;
    Some(
        samples
            .windows(2)
            .filter(|w| w[0].landed == Some(false))
            .map(|w| (w[1].time_s - w[0].time_s).max(0.0))
            .sum(),
    )
}

/// Horizontal ground speed below which a sample is hovering, m/s.
const HOVER_SPEED_MPS: f64 = 1.0;
/// Vertical speed below which a sample is hovering, m/s.
const HOVER_CLIMB_MPS: f64 = 0.5;
/// Without a logged landed state, the least power of a hover sample as a fraction of the
/// flight's largest (ground idle draws a few percent).
const HOVER_MIN_POWER_FRACTION: f64 = 0.25;
/// The least hover time for a hover power, s.
const HOVER_MIN_S: f64 = 10.0;
/// The longest interval between samples counted as hover, s (longer ones are gaps).
const HOVER_MAX_STEP_S: f64 = 1.0;

/// Mean electrical power while hovering: samples airborne (the log's landed state, else power at
/// least [`HOVER_MIN_POWER_FRACTION`] of the largest), slower than [`HOVER_SPEED_MPS`]
/// horizontally and [`HOVER_CLIMB_MPS`] vertically, each weighted by the time to the next
/// sample; `None` with less than [`HOVER_MIN_S`] of such time or no velocity in the log.
pub fn hover_power_w(samples: &[Sample]) -> Option<f64> {
    let max_w = samples
        .iter()
        .filter_map(Sample::electrical_power_w)
        .filter(|p| p.is_finite())
        .reduce(f64::max)?;
    let (mut energy_j, mut time_s) = (0.0, 0.0);
    for w in samples.windows(2) {
        let s = &w[0];
        let dt = w[1].time_s - s.time_s;
        if !(dt > 0.0 && dt <= HOVER_MAX_STEP_S) {
            continue;
        }
        let (Some(p), Some(v)) = (s.electrical_power_w(), s.vel_enu_mps) else {
            continue;
        };
        let airborne = match s.landed {
            Some(landed) => !landed,
            None => p >= HOVER_MIN_POWER_FRACTION * max_w,
        };
        let still = v[0].hypot(v[1]) < HOVER_SPEED_MPS && v[2].abs() < HOVER_CLIMB_MPS;
        if airborne && still && p.is_finite() {
            energy_j += p * dt;
            time_s += dt;
        }
    }
    (time_s >= HOVER_MIN_S).then(|| energy_j / time_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, v: f64, i: f64, speed: f64) -> Sample {
        Sample {
            time_s: t,
            voltage_v: Some(v),
            current_a: Some(i),
            vel_enu_mps: Some([speed, 0.0, 0.0]),
            ..Sample::default()
        }
    }

    /// 100 s at 20 V and 10 A, still for the first 50: the hover power is 200 W; with fewer
    /// than ten still seconds there is none.
    #[test]
    fn hover_power_of_the_still_samples() {
        let s: Vec<Sample> = (0..=100)
            .map(|k| sample(f64::from(k), 20.0, 10.0, if k < 50 { 0.2 } else { 5.0 }))
            .collect();
        assert!((hover_power_w(&s).unwrap() - 200.0).abs() < 1e-9);
        let fast: Vec<Sample> = (0..=100)
            .map(|k| sample(f64::from(k), 20.0, 10.0, if k < 5 { 0.2 } else { 5.0 }))
            .collect();
        assert_eq!(hover_power_w(&fast), None);
    }
}
