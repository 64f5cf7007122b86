//! The battery as a log recorded it: every battery record with what the autopilot or the smart
//! pack said about it, the pack's and vehicle's identity, and the battery parameters.
//!
//! The records and what they carry, below the readers that fill them (`ulog`, `dataflash`)
//! and [`crate::battery_log`], which reads a whole log into a [`BatteryLog`].
//!
//! [`crate::read_battery_log`] reads any log `aloft fit` reads (PX4 ULog, ArduPilot DataFlash, a CSV
//! through a profile or column map, PX4 CSV tables, MCAP) into one [`BatteryLog`]. It is what
//! the pack analysis (`aloft-packs`) and the logbook take.
//!
//! # Units and conventions
//! SI units with the unit in the name; currents positive when discharging. Times are seconds
//! from the log's first battery record ([`BatterySample::time_s`]).
//!
//! # Resistance: the whole pack, always
//! [`BatterySample::autopilot_resistance_ohm`] is the resistance of the whole pack:
//! ArduPilot `BAT.Res` is logged as the pack's (ohm); PX4
//! `battery_status.internal_resistance_estimate` is **per cell** (ohm) and is multiplied by the
//! number of cells in series (the record's `cell_count`, else `BAT1_N_CELLS`, else the cells
//! logged). When the cell count is unknown the PX4 value is not reported at all: a per-cell
//! figure is never passed off as a pack figure.
//!
//! # PX4 thresholds are fractions, not volts
//! PX4 `BAT_LOW_THR`, `BAT_CRIT_THR` and `BAT_EMERGEN_THR` are thresholds of the **state of
//! charge** (0-1), not voltages; they are kept in [`BatteryLog::parameters`] and
//! [`BatteryLog::low_soc_threshold`], never in [`BatteryLog::low_voltage_failsafe_v`], which is
//! ArduPilot's `BATT_LOW_VOLT` (pack volts).
//!
//! # Cells
//! Cell voltages (PX4 `voltage_cell_v[]`, ArduPilot `BCL.V1..V12` in mV) of 0, 65.535 V (PX4 and
//! ArduPilot's "not present" 65535 mV) or not finite are dropped.

use std::collections::BTreeMap;

use serde::Serialize;

/// Largest battery capacity a log's parameters may give, mA h (10,000 A h): beyond it a value is
/// a unit slip, not a pack.
pub const MAX_BATTERY_CAPACITY_MAH: f64 = aloft_core::BATTERY_CAPACITY_RANGE_MAH.1;
/// Smallest battery capacity a log's parameters may give, mA h: below it (PX4's unset -1, a
/// `BAT1_CAPACITY` of 1e-38) the capacity is unset.
pub const MIN_BATTERY_CAPACITY_MAH: f64 = aloft_core::BATTERY_CAPACITY_RANGE_MAH.0;

/// A logged capacity parameter, mA h, when it is a pack's (from [`MIN_BATTERY_CAPACITY_MAH`] to
/// [`MAX_BATTERY_CAPACITY_MAH`]).
pub(crate) fn plausible_capacity_mah(mah: f64) -> Option<f64> {
    (MIN_BATTERY_CAPACITY_MAH..=MAX_BATTERY_CAPACITY_MAH)
        .contains(&mah)
        .then_some(mah)
}

/// The autopilot's flight-envelope parameters a log's [`BatteryLog::parameters`] keeps besides
/// the battery's: what a vehicle file's `[airframe]` holds (PX4 in SI units, ArduPilot in
/// centidegrees and cm/s), and the rotor count.
pub const ENVELOPE_PARAMETERS: [&str; 20] = [
    "MPC_TILTMAX_AIR",
    "MPC_XY_VEL_MAX",
    "MPC_XY_CRUISE",
    "MPC_Z_VEL_MAX_UP",
    "MPC_Z_VEL_MAX_DN",
    "MPC_ACC_HOR",
    "MPC_ACC_UP_MAX",
    "MPC_YAWRAUTO_MAX",
    "RTL_RETURN_ALT",
    "CA_ROTOR_COUNT",
    "ANGLE_MAX",
    "WPNAV_SPEED",
    "WPNAV_SPEED_UP",
    "WPNAV_SPEED_DN",
    "WPNAV_ACCEL",
    "WPNAV_ACCEL_Z",
    "PILOT_SPEED_UP",
    "PILOT_SPEED_DN",
    "ATC_RATE_Y_MAX",
    "RTL_ALT",
];

/// Parameters read from a log into [`BatteryLog::parameters`]: every PX4 parameter starting
/// `BAT` and every ArduPilot parameter starting `BATT_` (instance 1: the first battery),
/// `BRD_SERIAL_NUM`, and the [`ENVELOPE_PARAMETERS`].
pub fn is_kept_parameter(name: &str) -> bool {
    name.starts_with("BAT") || name == "BRD_SERIAL_NUM" || ENVELOPE_PARAMETERS.contains(&name)
}

/// One battery record of a log.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct BatterySample {
    /// Time from the first battery record of the log, s.
    pub time_s: f64,
    /// Terminal voltage of the pack, V.
    pub voltage_v: f64,
    /// Current, positive when discharging, A (`None`: not measured, e.g. PX4 `current_a` = -1).
    pub current_a: Option<f64>,
    /// Remaining charge as the autopilot or the smart pack reports it, fraction 0-1 (PX4
    /// `remaining`, ArduPilot `BAT.RemPct`/100; `None` when unknown).
    pub remaining: Option<f64>,
    /// Remaining charge the pack's own gauge reports, mA h (KAIST's BMS `capacity`; a CSV
    /// `charge` column).
    pub remaining_mah: Option<f64>,
    /// Charge drawn as the autopilot counts it, mA h (PX4 `discharged_mah`, ArduPilot
    /// `BAT.CurrTot`). A counter: its absolute value may not start at 0, use differences.
    pub consumed_mah: Option<f64>,
    /// Cell voltages, V (empty when not logged; 0, 65.535 V and non-finite cells dropped).
    pub cell_v: Vec<f64>,
    /// The autopilot's estimate of the internal resistance of the whole pack, ohm (see the
    /// module docs: PX4's per-cell value times the cells).
    pub autopilot_resistance_ohm: Option<f64>,
    /// Pack temperature, deg C.
    pub temperature_c: Option<f64>,
}

/// The battery records of one log and what the log says about the pack.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct BatteryLog {
    /// The file name as given.
    pub source: String,
    /// The container: `ulog`, `dataflash`, `csv` (a CSV table or PX4 CSV tables) or `mcap`.
    pub format: String,
    /// The vehicle's identity: PX4 `sys_uuid` (ULog info), ArduPilot `BRD_SERIAL_NUM` when
    /// non-zero.
    pub vehicle_id: Option<String>,
    /// The pack's identity: a smart pack's serial (PX4 `battery_status.serial_number`,
    /// non-zero; `uint16` or `char[32]`), ArduPilot `BATT_SERIAL_NUM` when not -1 or 0.
    pub pack_id: Option<String>,
    /// Cells in series: the logged cell count, else PX4 `BAT1_N_CELLS`/`BAT_N_CELLS`, else the
    /// number of cell voltages logged.
    pub cells_series: Option<u32>,
    /// Rated capacity from the parameters (PX4 `BAT1_CAPACITY`, ArduPilot `BATT_CAPACITY`, when
    /// positive), mA h.
    pub rated_capacity_mah: Option<f64>,
    /// ArduPilot's low-voltage failsafe `BATT_LOW_VOLT` (pack volts, when positive), V.
    pub low_voltage_failsafe_v: Option<f64>,
    /// ArduPilot's critical-voltage failsafe `BATT_CRT_VOLT` (pack volts, when positive), V.
    pub critical_voltage_failsafe_v: Option<f64>,
    /// PX4's low-battery threshold `BAT_LOW_THR`: a fraction of the state of charge (0-1), not a
    /// voltage.
    pub low_soc_threshold: Option<f64>,
    /// PX4's critical threshold `BAT_CRIT_THR`: a fraction of the state of charge (0-1).
    pub critical_soc_threshold: Option<f64>,
    /// A smart pack's charge cycle count (PX4 `cycle_count`, last non-zero value).
    pub cycle_count: Option<u32>,
    /// A smart pack's state of health (PX4 `state_of_health`, full-charge / design capacity,
    /// last non-zero value), percent.
    pub state_of_health_percent: Option<f64>,
    /// Battery and vehicle parameters read ([`is_kept_parameter`]), by name.
    pub parameters: BTreeMap<String, f64>,
    /// Wall-clock time of the first battery record (GPS time, UTC), s since 1970; `None` when
    /// the log has none.
    pub start_unix_s: Option<f64>,
    /// The battery records, in time order.
    pub samples: Vec<BatterySample>,
    /// What was left out or looked wrong while reading.
    pub warnings: Vec<String>,
    /// Why the logged capacity parameter is not the pack's, when it is set but outside
    /// [`MIN_BATTERY_CAPACITY_MAH`]..[`MAX_BATTERY_CAPACITY_MAH`] (a `BAT1_CAPACITY` of 1e-38):
    /// [`Self::rated_capacity_mah`] is then unset.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacity_note: Option<String>,
}

impl BatteryLog {
    /// Span from the first to the last battery record, s.
    pub fn duration_s(&self) -> f64 {
        match (self.samples.first(), self.samples.last()) {
            (Some(a), Some(b)) => (b.time_s - a.time_s).max(0.0),
            _ => 0.0,
        }
    }

    /// Whether any record measures the current.
    pub fn has_current(&self) -> bool {
        self.samples.iter().any(|s| s.current_a.is_some())
    }
}

/// A cell voltage that counts: finite, above 0 and not the 65.535 V of "no cell".
pub(crate) fn valid_cell(v: f64) -> bool {
    // Cells are logged in mV as u16: 65535 mV (and 65534 after ArduPilot's +1 mV offset) means
    // none; no cell chemistry reaches 10 V.
    v.is_finite() && v > 0.0 && v < 10.0
}

/// An identity from a `char[]` field: the printable text before the first NUL, `None` when
/// empty or all zeros.
pub(crate) fn text_id(b: &[u8]) -> Option<String> {
    let end = b.iter().position(|c| *c == 0).unwrap_or(b.len());
    let t: String = String::from_utf8_lossy(&b[..end])
        .chars()
        .filter(|c| !c.is_control())
        .collect();
    let t = t.trim();
    (!t.is_empty() && t.chars().any(|c| c != '0')).then(|| t.to_string())
}

/// What the binary decoders collect when [`crate::BinaryOptions::battery_details`] is set.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct BatteryDetails {
    /// Records with their boot time, s (converted to [`BatterySample::time_s`] at the end).
    pub samples: Vec<BatterySample>,
    pub parameters: BTreeMap<String, f64>,
    pub vehicle_id: Option<String>,
    pub pack_id: Option<String>,
    pub cells_logged: Option<u32>,
    pub cycle_count: Option<u32>,
    pub state_of_health_percent: Option<f64>,
    /// A GPS fix: (boot time s, UTC s since 1970).
    pub gps_clock: Option<(f64, f64)>,
    /// PX4 per-cell resistance seen while the cell count was unknown (reported at the end).
    pub per_cell_resistance: Vec<(usize, f64)>,
}

impl BatteryDetails {
    /// The log's [`BatteryLog`] from what was collected.
    pub(crate) fn into_log(
        mut self,
        source: &str,
        format: &str,
        warnings: Vec<String>,
    ) -> BatteryLog {
        let param = |k: &str| self.parameters.get(k).copied();
        let cells = self
            .cells_logged
            .or_else(|| {
                param("BAT1_N_CELLS")
                    .or_else(|| param("BAT_N_CELLS"))
                    .filter(|n| *n >= 1.0 && *n <= 64.0)
                    .map(|n| n as u32)
            })
            .or_else(|| {
                let n = self.samples.iter().map(|s| s.cell_v.len()).max()?;
                (n > 0).then_some(n as u32)
            });
        // PX4's per-cell resistance becomes the pack's only with a known cell count.
        if let Some(n) = cells {
            for (i, r) in std::mem::take(&mut self.per_cell_resistance) {
                if let Some(s) = self.samples.get_mut(i) {
                    s.autopilot_resistance_ohm = Some(r * f64::from(n));
                }
            }
        }
        let positive = |v: Option<f64>| v.filter(|v| v.is_finite() && *v > 0.0);
        let (key, logged) = match param("BAT1_CAPACITY") {
            Some(c) => ("BAT1_CAPACITY", Some(c)),
            None => ("BATT_CAPACITY", param("BATT_CAPACITY")),
        };
        let rated = logged.and_then(plausible_capacity_mah);
        // A value that is set (PX4's unset is -1, ArduPilot's 0) but no pack's is said.
        let capacity_note = logged
            .filter(|c| rated.is_none() && (c.is_nan() || *c > 0.0))
            .map(|c| {
                // Parameters are logged as f32: shown as logged (1e-38, not 9.9999993e-39).
                let shown = (c as f32).to_string().parse().unwrap_or(c);
                format!(
                    "{key} = {} mA h is not a pack's capacity (from 10 mA h to 1e7 mA h): taken as unset",
                    aloft_core::Num(shown)
                )
            });
        let fraction = |v: Option<f64>| v.filter(|v| v.is_finite() && *v > 0.0 && *v < 1.0);
        let vehicle_id = self.vehicle_id.clone().or_else(|| {
            param("BRD_SERIAL_NUM")
                .filter(|v| v.is_finite() && v.abs() >= 0.5)
                .map(|v| format!("{}", v.round() as i64))
        });
        let pack_id = self.pack_id.clone().or_else(|| {
            param("BATT_SERIAL_NUM")
                .filter(|v| v.is_finite() && v.abs() >= 0.5 && (*v + 1.0).abs() >= 0.5)
                .map(|v| format!("{}", v.round() as i64))
        });
        let t0 = self.samples.first().map_or(0.0, |s| s.time_s);
        let start_unix_s = self.gps_clock.map(|(boot, utc)| utc - (boot - t0));
        for s in &mut self.samples {
            s.time_s -= t0;
        }
        BatteryLog {
            source: source.to_string(),
            format: format.to_string(),
            vehicle_id,
            pack_id,
            cells_series: cells,
            rated_capacity_mah: rated,
            low_voltage_failsafe_v: positive(param("BATT_LOW_VOLT")),
            critical_voltage_failsafe_v: positive(param("BATT_CRT_VOLT")),
            low_soc_threshold: fraction(param("BAT_LOW_THR")),
            critical_soc_threshold: fraction(param("BAT_CRIT_THR")),
            cycle_count: self.cycle_count,
            state_of_health_percent: self.state_of_health_percent,
            parameters: self.parameters,
            start_unix_s,
            samples: self.samples,
            warnings,
            capacity_note,
        }
    }
}
