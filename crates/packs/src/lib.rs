//! # aloft-packs
//!
//! A battery pack's health from its own flight logs: the internal resistance from current
//! steps ([`resistance_from_steps`]), the charge drawn and the capacity between two rested
//! points ([`capacity_between_rests`]), equivalent full cycles, cell balance
//! ([`cell_balance`]), and the autopilot's own figures beside them ([`analyse`] →
//! [`PackReport`]), the pack's own open-circuit curve ([`flight_ocv`], [`combine_flight_ocv`]).
//! Input is an [`aloft_logs::BatteryLog`] (read by
//! [`aloft_logs::read_battery_log`]); this crate does no I/O.
//!
//! Units: SI with the unit in the name, except charge in mA h (`_mah`, as packs are rated) and
//! imbalance time in minutes (`_min`, as fleet tools report it). Currents are positive when
//! discharging.

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod balance;
pub mod capacity;
pub mod combine;
pub mod error;
pub mod failsafes;
pub mod ocv_fit;
pub mod px4;
pub mod rc;
pub mod resistance;
pub mod soc_filter;

pub use balance::{cell_balance, CellBalance, MAJOR_SPREAD_V, MINOR_SPREAD_V};
pub use capacity::{
    capacity_between_rests, coulomb_count_mah, reported_drop_mah, rest_limit_a, CapacityEstimate,
    REST_CURRENT_UNRATED_A, REST_C_RATE, REST_HOLD_S,
};
pub use combine::{combine_flights, median_finite, FlightsCombined};
pub use error::PackError;
pub use failsafes::{
    ArduPilotResistance, Failsafe, FailsafeAction, FailsafeKind, FailsafeMonitor, FailsafeUnit,
    Judged, Triggered, VehicleFailsafes, VoltageThreshold, LOADED_AVERAGE_WINDOW_S,
};
pub use ocv_fit::{
    combine_flight_ocv, flight_ocv, ChargeAnchor, FittedOcv, FlightOcv, OcvBin, MIN_MEASURED_BINS,
    MIN_RECORDS_PER_BIN, OCV_BIN_SOC,
};
pub use px4::{Px4Battery, Px4BatteryParams, Px4Estimate, Px4Resume, Px4Warning};
pub use rc::{rc_from_flight, rc_of_flights, RcEstimate};
pub use resistance::{resistance_from_steps, updates, ResistanceEstimate};
pub use soc_filter::{Circuit, FilterTuning, ReportKind, SocEstimate, SocFilter};

use aloft_logs::BatteryLog;
use serde::Serialize;

/// What the caller knows about the pack that the log may not say.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PackOptions {
    /// Rated capacity, mA h (overrides the log's parameter).
    pub rated_capacity_mah: Option<f64>,
    /// Cells in series (overrides the log's).
    pub cells_series: Option<u32>,
}

/// Everything one log says about its pack. Keys carry their units; what a log does not give is
/// left out of the JSON (never `null`).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct PackReport {
    /// The log.
    pub source: String,
    /// Its container (`ulog`, `dataflash`, `csv`, `mcap`).
    pub format: String,
    /// The vehicle's identity, when logged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vehicle_id: Option<String>,
    /// The pack's identity, when logged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pack_id: Option<String>,
    /// Wall-clock start, s since 1970 (UTC), when logged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_unix_s: Option<f64>,
    /// Cells in series.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cells_series: Option<u32>,
    /// Rated capacity, mA h.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rated_capacity_mah: Option<f64>,
    /// Battery records.
    pub records: usize,
    /// First to last battery record, s.
    pub duration_s: f64,
    /// Energy drawn, ∫V·I dt, W h.
    pub energy_wh: f64,
    /// Lowest terminal voltage, V.
    pub min_voltage_v: f64,
    /// Highest terminal voltage, V.
    pub max_voltage_v: f64,
    /// Largest current, A.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_current_a: Option<f64>,
    /// Charge drawn, ∫I dt (the coulomb count), mA h.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub discharged_mah: Option<f64>,
    /// The drop of charge the pack or autopilot reported over the log, mA h.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reported_drop_mah: Option<f64>,
    /// Where [`Self::reported_drop_mah`] comes from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reported_drop_source: Option<String>,
    /// Coulomb count / reported drop.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coulomb_to_reported_ratio: Option<f64>,
    /// Discharged charge / rated charge.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub equivalent_cycles: Option<f64>,
    /// The pack's internal resistance from current steps (median), Ω.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub internal_resistance_ohm: Option<f64>,
    /// The resistance estimate in full.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resistance: Option<ResistanceEstimate>,
    /// The autopilot's own resistance estimate of the whole pack (median of its log), Ω.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub autopilot_internal_resistance_ohm: Option<f64>,
    /// Capacity between two rests, mA h.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacity_mah: Option<f64>,
    /// The capacity estimate in full.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacity: Option<CapacityEstimate>,
    /// Why there is no capacity, in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacity_refused: Option<String>,
    /// Time with a cell spread above 0.01 V, min.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub imbalance_minor_min: Option<f64>,
    /// Time with a cell spread above 0.07 V, min.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub imbalance_major_min: Option<f64>,
    /// Cell balance in full.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cell_balance: Option<CellBalance>,
    /// A smart pack's cycle count.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_count: Option<u32>,
    /// A smart pack's state of health, percent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub state_of_health_percent: Option<f64>,
    /// ArduPilot's low-voltage failsafe, V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub low_voltage_failsafe_v: Option<f64>,
    /// ArduPilot's critical-voltage failsafe, V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub critical_voltage_failsafe_v: Option<f64>,
}

/// [`analyse_with`] with what the log says.
///
/// # Errors
/// [`PackError::TooFewRecords`] with fewer than two battery records.
pub fn analyse(log: &BatteryLog) -> Result<PackReport, PackError> {
    analyse_with(log, &PackOptions::default())
}

/// Everything `log` says about its pack; `options` fill in what it does not.
///
/// # Errors
/// [`PackError::TooFewRecords`] with fewer than two battery records.
pub fn analyse_with(log: &BatteryLog, options: &PackOptions) -> Result<PackReport, PackError> {
    let s = &log.samples;
    if s.len() < 2 {
        return Err(PackError::TooFewRecords {
            source_name: log.source.clone(),
            records: s.len(),
        });
    }
    let rated = options
        .rated_capacity_mah
        .or(log.rated_capacity_mah)
        .filter(|c| c.is_finite() && *c > 0.0);
    let cells = options.cells_series.or(log.cells_series);
    let has_current = log.has_current();
    let discharged = has_current.then(|| coulomb_count_mah(s));
    let reported = reported_drop_mah(s, rated);
    let resistance = resistance_from_steps(s);
    let capacity = capacity_between_rests(s, cells, rated);
    let balance = cell_balance(s);
    let mut ap: Vec<f64> = s
        .iter()
        .filter_map(|x| x.autopilot_resistance_ohm)
        .filter(|r| r.is_finite() && *r > 0.0)
        .collect();
    let ratio = match (discharged, reported) {
        (Some(q), Some((r, _))) if r > 0.0 => Some(q / r),
        _ => None,
    };
    let (cap_ok, cap_err) = match capacity {
        Ok(c) => (Some(c), None),
        Err(e) => (None, Some(e.to_string())),
    };
    Ok(PackReport {
        source: log.source.clone(),
        format: log.format.clone(),
        vehicle_id: log.vehicle_id.clone(),
        pack_id: log.pack_id.clone(),
        start_unix_s: log.start_unix_s.filter(|t| t.is_finite()),
        cells_series: cells,
        rated_capacity_mah: rated,
        records: s.len(),
        duration_s: log.duration_s(),
        energy_wh: energy_wh(log),
        min_voltage_v: s.iter().map(|x| x.voltage_v).fold(f64::INFINITY, f64::min),
        max_voltage_v: s.iter().map(|x| x.voltage_v).fold(0.0, f64::max),
        max_current_a: s.iter().filter_map(|x| x.current_a).reduce(f64::max),
        discharged_mah: discharged,
        reported_drop_mah: reported.map(|r| r.0),
        reported_drop_source: reported.map(|r| r.1.to_string()),
        coulomb_to_reported_ratio: ratio,
        equivalent_cycles: discharged.zip(rated).map(|(q, c)| q / c),
        internal_resistance_ohm: resistance.as_ref().map(|r| r.ohm),
        resistance,
        autopilot_internal_resistance_ohm: resistance::median(&mut ap),
        capacity_mah: cap_ok.as_ref().map(|c| c.capacity_mah),
        capacity: cap_ok,
        capacity_refused: cap_err,
        imbalance_minor_min: balance.as_ref().map(|b| b.imbalance_minor_min),
        imbalance_major_min: balance.as_ref().map(|b| b.imbalance_major_min),
        cell_balance: balance,
        cycle_count: log.cycle_count,
        state_of_health_percent: log.state_of_health_percent,
        low_voltage_failsafe_v: log.low_voltage_failsafe_v,
        critical_voltage_failsafe_v: log.critical_voltage_failsafe_v,
    })
}

/// Energy drawn, ∫V·I dt (trapezoid; gaps over [`capacity::MAX_GAP_S`] not bridged), W h.
pub fn energy_wh(log: &BatteryLog) -> f64 {
    let mut e = aloft_core::Trapezoid::new();
    for s in &log.samples {
        let Some(i) = s.current_a else { continue };
        e.push_bridging(s.time_s, s.voltage_v * i, capacity::MAX_GAP_S);
    }
    e.integral() / 3600.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use aloft_logs::BatterySample;

    /// A battery record at `time_s` drawing `current_a` at `voltage_v`: the samples of this
    /// crate's tests.
    pub(crate) fn sample(time_s: f64, voltage_v: f64, current_a: f64) -> BatterySample {
        BatterySample {
            time_s,
            voltage_v,
            current_a: Some(current_a),
            ..BatterySample::default()
        }
    }

    fn log(samples: Vec<BatterySample>) -> BatteryLog {
        BatteryLog {
            source: "t".into(),
            format: "csv".into(),
            rated_capacity_mah: Some(1000.0),
            samples,
            ..BatteryLog::default()
        }
    }

    /// 1 h at 0.5 A from a 1000 mA h pack: 500 mA h, half a cycle; 12 V: 6 W h.
    #[test]
    fn cycles_and_energy() {
        let s = (0..=3600).map(|k| sample(k as f64, 12.0, 0.5)).collect();
        let r = analyse(&log(s)).unwrap();
        assert!((r.discharged_mah.unwrap() - 500.0).abs() < 1e-9);
        assert!((r.equivalent_cycles.unwrap() - 0.5).abs() < 1e-12);
        assert!((r.energy_wh - 6.0).abs() < 1e-9);
        let j = serde_json::to_value(&r).unwrap();
        for k in ["discharged_mah", "equivalent_cycles", "energy_wh"] {
            assert!(j[k].is_number(), "{k} missing");
        }
        // What the log does not give is left out, never null (issue 41): a constant current
        // has no steps, no rests, no cells and no autopilot estimate.
        for k in [
            "internal_resistance_ohm",
            "capacity_mah",
            "autopilot_internal_resistance_ohm",
            "imbalance_minor_min",
            "imbalance_major_min",
        ] {
            assert!(j.get(k).is_none(), "{k}: {}", j[k]);
        }
        assert!(!j.to_string().contains("null"), "{j}");
    }

    #[test]
    fn one_record_is_an_error() {
        let e = analyse(&log(vec![BatterySample::default()])).unwrap_err();
        assert!(matches!(e, PackError::TooFewRecords { records: 1, .. }));
    }
}
