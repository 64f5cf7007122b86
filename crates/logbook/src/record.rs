//! The seam between a log file and the logbook: [`read_flight`] turns one log into the figures
//! of one `flights` row ([`FlightFacts`]). Everything the logbook knows of a log comes through
//! here.

use std::path::Path;

use aloft_logs::{open_log_with, BinaryOptions, LogFormat, OpenOptions, Profile, Sample};

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
    /// The log's container: `csv`, `px4_csv`, `mcap`, `px4_ulog`, `ardupilot_dataflash`.
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
}

/// The snake_case name of a log format (as `aloft log info` writes it).
pub(crate) fn format_name(f: LogFormat) -> &'static str {
    match f {
        LogFormat::Csv => "csv",
        LogFormat::Px4Csv => "px4_csv",
        LogFormat::Mcap => "mcap",
        LogFormat::Px4Ulog => "px4_ulog",
        LogFormat::ArduPilotDataflash => "ardupilot_dataflash",
    }
}

/// Read the log at `path` into the figures of its flight.
///
/// # Errors
/// Why the log is not a flight of the logbook, in words (the `skipped` table's reason): it
/// cannot be opened or decoded, or it has no battery data (voltage and current) to measure.
pub fn read_flight(path: &Path, options: &ReadOptions) -> Result<FlightFacts, String> {
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
    let mut reader = open_log_with(path, profile.as_ref(), &open).map_err(|e| e.to_string())?;
    let log = reader
        .read_rest(&path.display().to_string())
        .map_err(|e| e.to_string())?;
    let binary = reader.binary_summary();
    if let Some(reason) = binary.and_then(|b| b.no_power_reason()) {
        return Err(reason);
    }
    let mut facts = battery_figures(&log.samples).ok_or_else(|| {
        "the log has no battery data: fewer than two samples with voltage and current".to_string()
    })?;
    facts.format = format_name(reader.format()).to_string();
    if let Some(b) = binary {
        // A binary log's energy is the trapezoid over its own battery records (not the samples
        // joined onto the motion topic).
        if let Some(e) = b.energy_wh() {
            facts.energy_wh = e;
        }
        facts.cells_series = b.battery_cells;
        facts.rated_capacity_mah = b.battery_capacity_ah.map(|c| c * 1000.0);
    }
    facts.mean_power_w =
        (facts.duration_s > 0.0).then(|| facts.energy_wh * 3600.0 / facts.duration_s);
    facts.hover_power_w = hover_power_w(&log.samples);
    Ok(facts)
}

/// Duration, energy, charge and extremes over the samples that carry voltage and current
/// (trapezoids between consecutive such samples; a step back in time adds nothing).
fn battery_figures(samples: &[Sample]) -> Option<FlightFacts> {
    let vi: Vec<(f64, f64, f64)> = samples
        .iter()
        .filter_map(|s| Some((s.time_s, s.voltage_v?, s.current_a?)))
        .filter(|(t, v, i)| t.is_finite() && v.is_finite() && i.is_finite())
        .collect();
    if vi.len() < 2 {
        return None;
    }
    let (mut energy_j, mut charge_c) = (0.0, 0.0);
    for w in vi.windows(2) {
        let dt = (w[1].0 - w[0].0).max(0.0);
        energy_j += 0.5 * (w[0].1 * w[0].2 + w[1].1 * w[1].2) * dt;
        charge_c += 0.5 * (w[0].2 + w[1].2) * dt;
    }
    let first = vi.first().map_or(0.0, |s| s.0);
    let last = vi.last().map_or(0.0, |s| s.0);
    Some(FlightFacts {
        duration_s: (last - first).max(0.0),
        energy_wh: energy_j / 3600.0,
        discharged_mah: Some(charge_c / 3.6),
        max_current_a: vi.iter().map(|s| s.2).reduce(f64::max),
        min_voltage_v: vi.iter().map(|s| s.1).reduce(f64::min),
        ..FlightFacts::default()
    })
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

    /// 100 s at 20 V and 10 A: 200 W, 5.555... Wh, 277.7... mAh; the hover power is that of
    /// the still samples only.
    #[test]
    fn figures_of_a_constant_draw() {
        let s: Vec<Sample> = (0..=100)
            .map(|k| sample(f64::from(k), 20.0, 10.0, if k < 50 { 0.2 } else { 5.0 }))
            .collect();
        let f = battery_figures(&s).unwrap();
        assert!((f.duration_s - 100.0).abs() < 1e-9);
        assert!((f.energy_wh - 2000.0 / 3.6 / 100.0).abs() < 1e-9);
        assert!((f.discharged_mah.unwrap() - 1000.0 / 3.6).abs() < 1e-9);
        assert!((hover_power_w(&s).unwrap() - 200.0).abs() < 1e-9);
        // Fewer than ten still seconds: no hover power.
        let fast: Vec<Sample> = (0..=100)
            .map(|k| sample(f64::from(k), 20.0, 10.0, if k < 5 { 0.2 } else { 5.0 }))
            .collect();
        assert_eq!(hover_power_w(&fast), None);
    }

    #[test]
    fn one_sample_is_no_flight() {
        assert!(battery_figures(&[sample(0.0, 20.0, 1.0, 0.0)]).is_none());
    }
}
