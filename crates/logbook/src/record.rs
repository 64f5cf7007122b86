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
}

/// Read the log at `path` into the figures of its flight: the pack's figures from its battery
/// records ([`aloft_logs::read_battery_log`], [`aloft_packs::analyse`]), the hover power from
/// its samples joined onto the motion (absent when the log has no velocity).
///
/// # Errors
/// Why the log is not a flight of the logbook, in words (the `skipped` table's reason): it
/// cannot be opened or decoded, or it has fewer than two battery records.
pub fn read_flight(path: &Path, options: &ReadOptions) -> Result<FlightFacts, String> {
    read(path, options).map_err(|reason| {
        // The reason is stored beside the file's name: without the path the readers lead with.
        let prefix = format!("{}: ", path.display());
        reason
            .strip_prefix(&prefix)
            .map_or_else(|| reason.clone(), str::to_string)
    })
}

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
        mean_power_w: (r.duration_s > 0.0 && r.discharged_mah.is_some())
            .then(|| r.energy_wh * 3600.0 / r.duration_s),
        hover_power_w: hover_of(path, profile.as_ref(), &open),
        resistance_ohm: r.internal_resistance_ohm,
        autopilot_resistance_ohm: r.autopilot_internal_resistance_ohm,
        capacity_mah: r.capacity_mah,
        capacity_refusal: r.capacity_refused,
        imbalance_minor_min: r.imbalance_minor_min,
        imbalance_major_min: r.imbalance_major_min,
    })
}

/// The hover power of the log's samples (`None` when they cannot be read: the battery figures
/// stand without it).
fn hover_of(path: &Path, profile: Option<&Profile>, open: &OpenOptions) -> Option<f64> {
    let mut reader = open_log_with(path, profile, open).ok()?;
    let log = reader.read_rest(&path.display().to_string()).ok()?;
    hover_power_w(&log.samples)
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
