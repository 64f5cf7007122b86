//! The vehicle's battery failsafes, read from its parameters and judged as its autopilot
//! judges them ([`VehicleFailsafes`]), and a monitor that steps them sample by sample
//! ([`FailsafeMonitor`]): fed the measured samples during a flight so its filters and timers
//! stand where the autopilot's stand at "now", then cloned and stepped along a predicted trace.
//!
//! # What each autopilot watches
//!
//! **ArduPilot** (`libraries/AP_BattMonitor/AP_BattMonitor_Backend.cpp`
//! `update_failsafes` / `check_failsafe_types` / `update_resistance_estimate`,
//! `AP_BattMonitor.cpp` `check_failsafes`, `AP_BattMonitor_Params.cpp`; master as stored,
//! commit `00a8a8fe`), first monitor (`BATT_`) only:
//! - `BATT_LOW_VOLT` / `BATT_CRT_VOLT` (V, 0 = off): the voltage must stay below the threshold
//!   for longer than `BATT_LOW_TIMER` (default 10 s; 0 disables the voltage failsafes): the
//!   timer starts at the first sample below, any sample at or above resets it, and the
//!   failsafe triggers at the first sample more than the timer after the start;
//! - the voltage is the raw one (`BATT_FS_VOLTSRC` 0) or the sag-compensated one (1):
//!   `max(V, V + I·R)` with `R` ArduPilot's own running estimate (logged as `BAT.Res`),
//!   emulated here ([`ArduPilotResistance`]) rather than taken from the pack file, so that the
//!   compensation is the one the vehicle applies;
//! - `BATT_LOW_MAH` / `BATT_CRT_MAH` (0 = off): `BATT_CAPACITY − drawn < threshold`, at once
//!   (no timer), and only with a current sensor; drawn is ArduPilot's count since boot
//!   (it takes the pack as full at boot);
//! - `BATT_FS_LOW_ACT` / `BATT_FS_CRT_ACT` 0 is no action: ArduPilot still announces the
//!   failsafe ("Battery 1 is low"), so it is kept and flagged [`FailsafeAction::WarnOnly`];
//! - a failsafe level only goes up while armed; failsafes are checked only while armed.
//!
//! **PX4** (v1.14): `BAT_LOW_THR`, `BAT_CRIT_THR`, `BAT_EMERGEN_THR` act on PX4's own
//! estimate, emulated by [`crate::px4`]; the commander latches the worst warning while armed.
//! Low only warns; critical and emergency act as `COM_LOW_BAT_ACT` says (0 warning only).
//!
//! **Generic thresholds** (`--low-voltage-v`, `--critical-voltage-v`, a pack file's
//! `[failsafe]`): the voltage under load averaged over the last 5 s
//! ([`LOADED_AVERAGE_WINDOW_S`], time-weighted) below the threshold. A generic threshold of
//! a kind replaces ArduPilot's voltage failsafe of that kind; the capacity and PX4 failsafes
//! stay.
//!
//! # Deviation
//!
//! - Each failsafe triggers once, on its own condition. ArduPilot acts on a low failsafe only
//!   if no critical one came first (its level only goes up); a low one listed after a
//!   critical has triggered is what ArduPilot's condition says, not a second action.
//! - A voltage parameter the map lacks is off (ArduPilot Copter's `BATT_LOW_VOLT` default is
//!   10.5 V, other vehicles' 0: the vehicle type is not known here).
//! - Armed is assumed from the first step.

use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

use crate::px4::{invalid, Px4Battery, Px4BatteryParams, Px4Estimate, Px4Resume, Px4Warning};
use crate::PackError;

/// The window of the generic thresholds' loaded-voltage average, s.
pub const LOADED_AVERAGE_WINDOW_S: f64 = 5.0;
/// ArduPilot's `BATT_LOW_TIMER` default, s.
pub const ARDUPILOT_LOW_TIMER_DEFAULT_S: f64 = 10.0;
/// ArduPilot's `BATT_CAPACITY` default, mA h.
pub const ARDUPILOT_CAPACITY_DEFAULT_MAH: f64 = 3300.0;
/// The most failsafes one monitor watches.
pub const MAX_FAILSAFES: usize = 64;

/// How urgent a failsafe is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum FailsafeKind {
    /// `low`.
    Low,
    /// `critical`.
    Critical,
    /// `emergency` (PX4).
    Emergency,
}

impl FailsafeKind {
    /// `low`, `critical` or `emergency`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Low => "low",
            Self::Critical => "critical",
            Self::Emergency => "emergency",
        }
    }
}

/// What a failsafe's threshold is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FailsafeUnit {
    /// The pack's voltage, V.
    Volt,
    /// PX4's estimate of the state of charge, 0-1.
    Fraction,
    /// Charge left (capacity − drawn), mA h.
    MilliampHour,
}

impl FailsafeUnit {
    /// `V`, `fraction` or `mAh`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Volt => "V",
            Self::Fraction => "fraction",
            Self::MilliampHour => "mAh",
        }
    }
}

/// How a failsafe's condition is judged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Judged {
    /// ArduPilot: the voltage below the threshold for longer than `timer_s` (0: never).
    ArduPilotVoltage {
        /// `BATT_LOW_TIMER`, s.
        timer_s: f64,
        /// `BATT_FS_VOLTSRC` 1: `max(V, V + I·R)` with ArduPilot's resistance estimate.
        sag_compensated: bool,
    },
    /// ArduPilot: `capacity − drawn` below the threshold, at once.
    ArduPilotRemaining {
        /// `BATT_CAPACITY`, mA h.
        capacity_mah: f64,
    },
    /// PX4: the commander's latched warning of PX4's emulated estimate at this level.
    Px4Estimate,
    /// The voltage under load averaged over the last `window_s`, below the threshold.
    LoadedVoltageAverage {
        /// The averaging window, s.
        window_s: f64,
    },
}

/// What the vehicle does when the failsafe triggers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FailsafeAction {
    /// Only a warning (`BATT_FS_LOW_ACT` 0, PX4's low level, `COM_LOW_BAT_ACT` 0).
    WarnOnly,
    /// An action: the parameter that sets it and its value (the vehicle type's meaning).
    Acts {
        /// `BATT_FS_LOW_ACT`, `BATT_FS_CRT_ACT`, `COM_LOW_BAT_ACT`.
        param: &'static str,
        /// Its value.
        value: i64,
    },
    /// Not known (a flag's threshold, or the action parameter not in the map).
    Unknown,
}

/// One failsafe the vehicle watches.
#[derive(Debug, Clone, PartialEq)]
pub struct Failsafe {
    /// How urgent.
    pub kind: FailsafeKind,
    /// Where the threshold comes from: the parameter (`BATT_LOW_VOLT`, `BAT_LOW_THR`), the
    /// flag (`--low-voltage-v`) or the pack file (`[failsafe]`).
    pub source: String,
    /// The threshold, in [`Self::unit`].
    pub threshold: f64,
    /// What the threshold is in.
    pub unit: FailsafeUnit,
    /// A voltage threshold per cell, V (when the cells are known).
    pub threshold_cell_v: Option<f64>,
    /// How it is judged.
    pub judged: Judged,
    /// What the vehicle does then.
    pub action: FailsafeAction,
}

/// A voltage threshold given by a flag or a pack file.
#[derive(Debug, Clone, PartialEq)]
pub struct VoltageThreshold {
    /// How urgent.
    pub kind: FailsafeKind,
    /// The pack voltage, V.
    pub voltage_v: f64,
    /// `--low-voltage-v`, `--critical-voltage-v` or `[failsafe]`.
    pub source: String,
}

/// The battery failsafes a vehicle watches, from its parameters and the caller's thresholds.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleFailsafes {
    /// Each failsafe watched.
    pub failsafes: Vec<Failsafe>,
    /// PX4's battery parameters, when the map is a PX4 vehicle's.
    pub px4: Option<Px4BatteryParams>,
}

impl VehicleFailsafes {
    /// The failsafes from a vehicle's parameter map (ArduPilot's `BATT_*`, PX4's `BAT*`;
    /// either, both or neither present), the cells in series (for the per-cell thresholds)
    /// and the generic voltage thresholds (which replace ArduPilot's voltage failsafe of
    /// their kind).
    ///
    /// # Errors
    /// [`PackError::InvalidParameter`] naming a parameter or threshold that is not finite or
    /// out of range; [`PackError::EmptyNotBelowCharged`] for PX4's cell voltages.
    pub fn from_parameters(
        params: &BTreeMap<String, f64>,
        cells_series: Option<u32>,
        thresholds: &[VoltageThreshold],
    ) -> Result<Self, PackError> {
        let mut failsafes = generic_failsafes(thresholds)?;
        let replaced: Vec<FailsafeKind> = failsafes.iter().map(|f| f.kind).collect();
        failsafes.extend(
            ardupilot_failsafes(params)?
                .into_iter()
                .filter(|f| f.unit != FailsafeUnit::Volt || !replaced.contains(&f.kind)),
        );
        let px4 = Px4BatteryParams::from_parameters(params)?;
        if let Some(p) = &px4 {
            failsafes.extend(px4_failsafes(p));
        }
        if failsafes.len() > MAX_FAILSAFES {
            return Err(invalid(
                "failsafes",
                failsafes.len() as f64,
                "at most 64 failsafes",
            ));
        }
        let cells = cells_series.filter(|&n| n > 0).map(f64::from);
        for f in &mut failsafes {
            if f.unit == FailsafeUnit::Volt {
                f.threshold_cell_v = cells.map(|n| f.threshold / n);
            }
        }
        Ok(Self { failsafes, px4 })
    }

    /// A monitor of these failsafes, nothing seen yet (PX4's estimate from boot).
    pub fn monitor(&self) -> FailsafeMonitor {
        FailsafeMonitor::new(self)
    }
}

/// The flags' and pack file's thresholds, each a positive finite voltage.
fn generic_failsafes(thresholds: &[VoltageThreshold]) -> Result<Vec<Failsafe>, PackError> {
    thresholds
        .iter()
        .map(|t| {
            if !(t.voltage_v.is_finite() && t.voltage_v > 0.0 && t.voltage_v <= 1e4) {
                return Err(invalid(
                    &t.source,
                    t.voltage_v,
                    "a positive pack voltage up to 10000 V",
                ));
            }
            Ok(Failsafe {
                kind: t.kind,
                source: t.source.clone(),
                threshold: t.voltage_v,
                unit: FailsafeUnit::Volt,
                threshold_cell_v: None,
                judged: Judged::LoadedVoltageAverage {
                    window_s: LOADED_AVERAGE_WINDOW_S,
                },
                action: FailsafeAction::Unknown,
            })
        })
        .collect()
}

/// An ArduPilot parameter: finite, at least 0, or `default` when absent.
fn non_negative(
    params: &BTreeMap<String, f64>,
    name: &str,
    default: f64,
) -> Result<f64, PackError> {
    match params.get(name) {
        None => Ok(default),
        Some(&v) if v.is_finite() && v >= 0.0 => Ok(v),
        Some(&v) => Err(invalid(name, v, "a finite value of 0 or more")),
    }
}

/// A failsafe action parameter: 0 only warns, another whole number acts.
fn action(params: &BTreeMap<String, f64>, name: &'static str) -> Result<FailsafeAction, PackError> {
    match params.get(name) {
        None => Ok(FailsafeAction::Unknown),
        Some(&v) if v.is_finite() && v.fract() == 0.0 && v.abs() < 1e6 => Ok(if v == 0.0 {
            FailsafeAction::WarnOnly
        } else {
            FailsafeAction::Acts {
                param: name,
                value: v as i64,
            }
        }),
        Some(&v) => Err(invalid(name, v, "a whole number (0: no action)")),
    }
}

/// ArduPilot's first battery monitor's failsafes; none when no `BATT_` parameter is in the
/// map or `BATT_MONITOR` is 0.
fn ardupilot_failsafes(params: &BTreeMap<String, f64>) -> Result<Vec<Failsafe>, PackError> {
    let has_batt = params.keys().any(|k| k.starts_with("BATT_"));
    if !has_batt || params.get("BATT_MONITOR").is_some_and(|&m| m == 0.0) {
        return Ok(Vec::new());
    }
    let timer_s = non_negative(params, "BATT_LOW_TIMER", ARDUPILOT_LOW_TIMER_DEFAULT_S)?;
    let source = params.get("BATT_FS_VOLTSRC").copied().unwrap_or(0.0);
    let sag_compensated = match (source.fract() == 0.0).then_some(source as i64) {
        Some(0) => false,
        Some(1) => true,
        _ => {
            return Err(invalid(
                "BATT_FS_VOLTSRC",
                source,
                "0 (raw voltage) or 1 (sag compensated)",
            ))
        }
    };
    let capacity_mah = non_negative(params, "BATT_CAPACITY", ARDUPILOT_CAPACITY_DEFAULT_MAH)?;
    let mut out = Vec::new();
    let levels = [
        (
            FailsafeKind::Low,
            "BATT_LOW_VOLT",
            "BATT_LOW_MAH",
            "BATT_FS_LOW_ACT",
        ),
        (
            FailsafeKind::Critical,
            "BATT_CRT_VOLT",
            "BATT_CRT_MAH",
            "BATT_FS_CRT_ACT",
        ),
    ];
    for (kind, volt, mah, act) in levels {
        let action = action(params, act)?;
        let voltage_v = non_negative(params, volt, 0.0)?;
        if voltage_v > 0.0 {
            let judged = Judged::ArduPilotVoltage {
                timer_s,
                sag_compensated,
            };
            out.push(failsafe(
                kind,
                volt,
                voltage_v,
                FailsafeUnit::Volt,
                judged,
                action.clone(),
            ));
        }
        let left_mah = non_negative(params, mah, 0.0)?;
        if left_mah > 0.0 {
            if capacity_mah <= 0.0 {
                return Err(invalid(
                    "BATT_CAPACITY",
                    capacity_mah,
                    "a capacity above 0 mAh (a mAh failsafe is set)",
                ));
            }
            let judged = Judged::ArduPilotRemaining { capacity_mah };
            out.push(failsafe(
                kind,
                mah,
                left_mah,
                FailsafeUnit::MilliampHour,
                judged,
                action,
            ));
        }
    }
    Ok(out)
}

/// PX4's three warning levels on its emulated estimate.
fn px4_failsafes(p: &Px4BatteryParams) -> Vec<Failsafe> {
    let acts = || match p.low_bat_action {
        None => FailsafeAction::Unknown,
        Some(0) => FailsafeAction::WarnOnly,
        Some(value) => FailsafeAction::Acts {
            param: "COM_LOW_BAT_ACT",
            value,
        },
    };
    let unit = FailsafeUnit::Fraction;
    vec![
        failsafe(
            FailsafeKind::Low,
            "BAT_LOW_THR",
            p.low_thr,
            unit,
            Judged::Px4Estimate,
            FailsafeAction::WarnOnly,
        ),
        failsafe(
            FailsafeKind::Critical,
            "BAT_CRIT_THR",
            p.crit_thr,
            unit,
            Judged::Px4Estimate,
            acts(),
        ),
        failsafe(
            FailsafeKind::Emergency,
            "BAT_EMERGEN_THR",
            p.emergen_thr,
            unit,
            Judged::Px4Estimate,
            acts(),
        ),
    ]
}

fn failsafe(
    kind: FailsafeKind,
    source: &str,
    threshold: f64,
    unit: FailsafeUnit,
    judged: Judged,
    action: FailsafeAction,
) -> Failsafe {
    Failsafe {
        kind,
        source: source.to_string(),
        threshold,
        unit,
        threshold_cell_v: None,
        judged,
        action,
    }
}

/// ArduPilot's running estimate of the pack's resistance (`update_resistance_estimate`,
/// time constants 0.5 s and 0.1) and the sag-compensated voltage it gives.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ArduPilotResistance {
    /// The estimate, Ω (`BAT.Res`).
    pub resistance_ohm: f64,
    voltage_filt_v: f64,
    current_filt_a: f64,
    current_max_a: f64,
    voltage_ref_v: f64,
    current_ref_a: f64,
    resting_v: f64,
}

impl ArduPilotResistance {
    /// One sample: a current that is absent or not positive leaves the estimate as it is.
    pub fn update(&mut self, dt_s: f64, voltage_v: f64, current_a: Option<f64>) {
        let Some(i) = current_a.filter(|i| *i > 0.0) else {
            return;
        };
        self.current_max_a = self.current_max_a.max(i);
        let delta_a = i - self.current_filt_a;
        if delta_a.abs() < f64::from(f32::EPSILON) {
            return;
        }
        if voltage_v > self.voltage_ref_v {
            self.voltage_ref_v = voltage_v;
            self.current_ref_a = i;
        }
        let filt_alpha = (dt_s / (dt_s + 0.5)).clamp(0.0, 0.5);
        let resistance_alpha = (0.1 * (delta_a / self.current_max_a).abs()).min(1.0);
        let estimate_ohm = -(voltage_v - self.voltage_filt_v) / delta_a;
        if estimate_ohm > f64::from(f32::EPSILON) {
            self.resistance_ohm =
                self.resistance_ohm * (1.0 - resistance_alpha) + estimate_ohm * resistance_alpha;
        }
        if self.voltage_ref_v > voltage_v && i > self.current_ref_a {
            let max_ohm = (self.voltage_ref_v - voltage_v) / (i - self.current_ref_a);
            self.resistance_ohm = self.resistance_ohm.min(max_ohm);
        }
        self.voltage_filt_v = self.voltage_filt_v * (1.0 - filt_alpha) + voltage_v * filt_alpha;
        self.current_filt_a = self.current_filt_a * (1.0 - filt_alpha) + i * filt_alpha;
        self.resting_v = voltage_v + i * self.resistance_ohm;
    }

    /// The sag-compensated voltage ArduPilot compares: never below the raw one.
    pub fn resting_voltage_v(&self, voltage_v: f64) -> f64 {
        voltage_v.max(self.resting_v)
    }
}

/// The voltage under load averaged over a window, time-weighted.
#[derive(Debug, Clone, PartialEq)]
struct LoadedAverage {
    /// (duration, voltage) of the samples in the window, oldest first.
    samples: VecDeque<(f64, f64)>,
}

impl LoadedAverage {
    fn push(&mut self, dt_s: f64, voltage_v: f64) -> f64 {
        self.samples.push_back((dt_s, voltage_v));
        let mut excess_s = self.samples.iter().map(|s| s.0).sum::<f64>() - LOADED_AVERAGE_WINDOW_S;
        while excess_s > 0.0 && self.samples.len() > 1 {
            let oldest = &mut self.samples[0];
            if oldest.0 <= excess_s {
                excess_s -= oldest.0;
                self.samples.pop_front();
            } else {
                oldest.0 -= excess_s;
                excess_s = 0.0;
            }
        }
        let weight_s: f64 = self.samples.iter().map(|s| s.0).sum();
        if weight_s > 0.0 {
            self.samples.iter().map(|s| s.0 * s.1).sum::<f64>() / weight_s
        } else {
            voltage_v
        }
    }
}

/// Which failsafes triggered in one step: indexes into [`FailsafeMonitor::failsafes`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Triggered {
    mask: u64,
}

impl Triggered {
    /// None triggered.
    pub fn is_empty(self) -> bool {
        self.mask == 0
    }

    /// Whether failsafe `index` triggered.
    pub fn contains(self, index: usize) -> bool {
        index < MAX_FAILSAFES && self.mask & (1 << index) != 0
    }

    /// The indexes that triggered, ascending.
    pub fn indexes(self) -> impl Iterator<Item = usize> {
        (0..MAX_FAILSAFES).filter(move |&i| self.contains(i))
    }

    /// The kinds that triggered (one per failsafe, in list order).
    pub fn kinds(self, failsafes: &[Failsafe]) -> impl Iterator<Item = FailsafeKind> + '_ {
        self.indexes()
            .filter_map(|i| failsafes.get(i).map(|f| f.kind))
    }
}

/// One failsafe's timer and latch.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Watch {
    /// When the condition began to hold (ArduPilot's voltage timer), s.
    below_since_s: Option<f64>,
    triggered: bool,
}

/// The failsafes stepped sample by sample. `Clone` is cheap (the list is shared; the state is
/// a few numbers and the last 5 s of voltages).
#[derive(Debug, Clone)]
pub struct FailsafeMonitor {
    failsafes: Arc<[Failsafe]>,
    watches: Vec<Watch>,
    elapsed_s: f64,
    drawn_mah: Option<f64>,
    px4: Option<Px4Battery>,
    px4_estimate: Option<Px4Estimate>,
    resistance: Option<ArduPilotResistance>,
    average: Option<LoadedAverage>,
    average_v: Option<f64>,
}

impl FailsafeMonitor {
    /// A monitor of `vehicle`'s failsafes, nothing seen yet.
    pub fn new(vehicle: &VehicleFailsafes) -> Self {
        let any = |p: &dyn Fn(&Judged) -> bool| vehicle.failsafes.iter().any(|f| p(&f.judged));
        let sag = any(&|j| {
            matches!(
                j,
                Judged::ArduPilotVoltage {
                    sag_compensated: true,
                    ..
                }
            )
        });
        let average = any(&|j| matches!(j, Judged::LoadedVoltageAverage { .. }));
        Self {
            failsafes: vehicle.failsafes.clone().into(),
            watches: vec![Watch::default(); vehicle.failsafes.len()],
            elapsed_s: 0.0,
            drawn_mah: None,
            px4: vehicle.px4.as_ref().map(Px4Battery::new),
            px4_estimate: None,
            resistance: sag.then(ArduPilotResistance::default),
            average: average.then(|| LoadedAverage {
                samples: VecDeque::new(),
            }),
            average_v: None,
        }
    }

    /// Resume PX4's estimate where the vehicle stands (its filters settled), instead of from
    /// boot; no effect on a vehicle without PX4 parameters.
    pub fn resume_px4(&mut self, state: &Px4Resume) {
        if let Some(p) = self.px4.as_ref().map(|b| *b.params()) {
            self.px4 = Some(Px4Battery::resumed(&p, state));
        }
    }

    /// The failsafes watched ([`Triggered`] indexes into this).
    pub fn failsafes(&self) -> &[Failsafe] {
        &self.failsafes
    }

    /// Whether failsafe `index` has triggered.
    pub fn has_triggered(&self, index: usize) -> bool {
        self.watches.get(index).is_some_and(|w| w.triggered)
    }

    /// PX4's emulated estimate after the last step.
    pub fn px4_estimate(&self) -> Option<Px4Estimate> {
        self.px4_estimate
    }

    /// The loaded voltage averaged over the last 5 s, V (when a generic threshold is watched).
    pub fn loaded_average_v(&self) -> Option<f64> {
        self.average_v
    }

    /// ArduPilot's resistance estimate, Ω (when a sag-compensated failsafe is watched).
    pub fn ardupilot_resistance_ohm(&self) -> Option<f64> {
        self.resistance.map(|r| r.resistance_ohm)
    }

    /// The charge drawn as the monitor counts it, mA h.
    pub fn drawn_mah(&self) -> Option<f64> {
        self.drawn_mah
    }

    /// Time stepped, s.
    pub fn elapsed_s(&self) -> f64 {
        self.elapsed_s
    }

    /// One sample: `dt_s` since the previous one, the pack's voltage under load, its current
    /// (`None` when not measured) and the charge drawn since the autopilot started (`None`:
    /// the monitor counts on from the last value with the current). Returns the failsafes
    /// that trigger at this sample; each triggers once. A `dt_s` that is negative or not
    /// finite, or a voltage that is not finite, changes nothing.
    pub fn step(
        &mut self,
        dt_s: f64,
        voltage_v: f64,
        current_a: Option<f64>,
        drawn_mah: Option<f64>,
    ) -> Triggered {
        if !(dt_s.is_finite() && dt_s >= 0.0 && voltage_v.is_finite()) {
            return Triggered::default();
        }
        let current_a = current_a.filter(|i| i.is_finite());
        self.elapsed_s += dt_s;
        self.count_drawn(dt_s, current_a, drawn_mah);
        if let Some(b) = self.px4.as_mut() {
            self.px4_estimate = Some(b.update(dt_s, voltage_v, current_a));
        }
        if let Some(r) = self.resistance.as_mut() {
            r.update(dt_s, voltage_v, current_a);
        }
        if let Some(a) = self.average.as_mut() {
            self.average_v = Some(a.push(dt_s, voltage_v));
        }
        self.judge_all(voltage_v, current_a.is_some())
    }

    /// The drawn charge: as given, else counted on with the current.
    fn count_drawn(&mut self, dt_s: f64, current_a: Option<f64>, drawn_mah: Option<f64>) {
        match (drawn_mah.filter(|d| d.is_finite()), current_a) {
            (Some(d), _) => self.drawn_mah = Some(d),
            (None, Some(i)) => {
                self.drawn_mah = Some(self.drawn_mah.unwrap_or(0.0) + i * dt_s * 1e3 / 3600.0);
            }
            (None, None) => {}
        }
    }

    /// Each failsafe not yet triggered, judged on this sample.
    fn judge_all(&mut self, voltage_v: f64, has_current: bool) -> Triggered {
        let mut out = Triggered::default();
        for index in 0..self.failsafes.len() {
            if self.watches[index].triggered {
                continue;
            }
            let f = &self.failsafes[index];
            let fires = match f.judged {
                Judged::ArduPilotVoltage {
                    timer_s,
                    sag_compensated,
                } => {
                    let used_v = match (sag_compensated, self.resistance) {
                        (true, Some(r)) => r.resting_voltage_v(voltage_v),
                        _ => voltage_v,
                    };
                    let below = used_v > 0.0 && used_v < f.threshold;
                    self.voltage_timer(index, below, timer_s)
                }
                Judged::ArduPilotRemaining { capacity_mah } => {
                    has_current
                        && self
                            .drawn_mah
                            .is_some_and(|d| capacity_mah - d < f.threshold)
                }
                Judged::Px4Estimate => self
                    .px4_estimate
                    .is_some_and(|e| e.failsafe_warning >= px4_level(self.failsafes[index].kind)),
                Judged::LoadedVoltageAverage { .. } => {
                    self.average_v.is_some_and(|v| v < f.threshold)
                }
            };
            if fires {
                self.watches[index].triggered = true;
                out.mask |= 1 << index;
            }
        }
        out
    }

    /// ArduPilot's timer: started at the first sample below, reset by any sample at or above;
    /// fires at the first sample more than `timer_s` after the start (never with 0).
    fn voltage_timer(&mut self, index: usize, below: bool, timer_s: f64) -> bool {
        let watch = &mut self.watches[index];
        if !below {
            watch.below_since_s = None;
            return false;
        }
        match watch.below_since_s {
            None => {
                watch.below_since_s = Some(self.elapsed_s);
                false
            }
            Some(since_s) => timer_s > 0.0 && self.elapsed_s - since_s > timer_s,
        }
    }
}

/// PX4's warning level for a failsafe kind.
fn px4_level(kind: FailsafeKind) -> Px4Warning {
    match kind {
        FailsafeKind::Low => Px4Warning::Low,
        FailsafeKind::Critical => Px4Warning::Critical,
        FailsafeKind::Emergency => Px4Warning::Emergency,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(entries: &[(&str, f64)]) -> BTreeMap<String, f64> {
        entries.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    }

    /// Steps `monitor` at `dt_s` through `(duration_s, voltage_v, current_a)` segments; the
    /// time after the first sample at which each failsafe triggered.
    fn run(
        monitor: &mut FailsafeMonitor,
        dt_s: f64,
        segments: &[(f64, f64, f64)],
    ) -> Vec<Option<f64>> {
        let mut out = vec![None; monitor.failsafes().len()];
        let mut t = 0.0;
        let mut first = true;
        for &(duration_s, v, i) in segments {
            let steps = (duration_s / dt_s).round() as usize;
            for _ in 0..steps {
                let step_s = if first { 0.0 } else { dt_s };
                first = false;
                t += step_s;
                for k in monitor.step(step_s, v, Some(i), None).indexes() {
                    out[k] = Some(t);
                }
            }
        }
        out
    }

    /// ArduPilot's timer (default 10 s): a voltage below `BATT_LOW_VOLT` for 9 s that then
    /// recovers does not trigger; one that stays triggers at the first sample more than 10 s
    /// after the first one below.
    #[test]
    fn ardupilot_low_voltage_needs_the_timer() {
        let v = VehicleFailsafes::from_parameters(&map(&[("BATT_LOW_VOLT", 10.5)]), Some(3), &[])
            .unwrap();
        assert_eq!(v.failsafes.len(), 1);
        assert_eq!(v.failsafes[0].action, FailsafeAction::Unknown);
        assert!((v.failsafes[0].threshold_cell_v.unwrap() - 3.5).abs() < 1e-12);
        let mut m = v.monitor();
        let t = run(
            &mut m,
            0.1,
            &[(1.0, 11.0, 10.0), (9.0, 10.0, 10.0), (5.0, 11.0, 10.0)],
        );
        assert_eq!(t, vec![None]);
        let mut m = v.monitor();
        let t = run(&mut m, 0.1, &[(1.0, 11.0, 10.0), (30.0, 10.0, 10.0)]);
        // First below at 1.0 s; fires at the first sample past 11.0 s (0.1 s steps).
        let fired = t[0].expect("triggers");
        assert!(fired > 11.0 - 1e-9 && fired < 11.1 + 1e-9, "{fired}");
        // BATT_LOW_TIMER 0 disables it.
        let off = VehicleFailsafes::from_parameters(
            &map(&[("BATT_LOW_VOLT", 10.5), ("BATT_LOW_TIMER", 0.0)]),
            None,
            &[],
        )
        .unwrap();
        assert_eq!(
            run(&mut off.monitor(), 0.1, &[(60.0, 10.0, 10.0)]),
            vec![None]
        );
    }

    /// A purely resistive pack (12 V behind 0.05 Ω): 30 s of current steps between 5 and
    /// 10 A (11.75 and 11.5 V, not below an 11.5 V threshold), then steps between 5 and 20 A
    /// (11.0 V at 20 A, below). On the raw voltage the failsafe fires 2 s (the timer) after
    /// the first 20 A sample; sag-compensated with ArduPilot's estimate, which has converged
    /// to 0.05 Ω by then (`−ΔV/ΔI` of values filtered alike is R exactly on such a pack), it
    /// reads 12 V and never fires.
    #[test]
    fn sag_compensation_uses_ardupilots_resistance() {
        let pack = |i: f64| (3.0, 12.0 - 0.05 * i, i);
        let mut segments: Vec<(f64, f64, f64)> = (0..10)
            .map(|k| pack(if k % 2 == 0 { 5.0 } else { 10.0 }))
            .collect();
        segments.extend((0..10).map(|k| pack(if k % 2 == 0 { 20.0 } else { 5.0 })));
        let raw_params = map(&[("BATT_LOW_VOLT", 11.5), ("BATT_LOW_TIMER", 2.0)]);
        let raw = VehicleFailsafes::from_parameters(&raw_params, None, &[]).unwrap();
        let t = run(&mut raw.monitor(), 0.1, &segments);
        // The first 20 A sample is at 30.0 s (samples from 0 s every 0.1 s).
        assert!(t[0].is_some_and(|t| t > 32.0 && t < 32.2), "{t:?}");
        let params = map(&[
            ("BATT_LOW_VOLT", 11.5),
            ("BATT_LOW_TIMER", 2.0),
            ("BATT_FS_VOLTSRC", 1.0),
        ]);
        let sag = VehicleFailsafes::from_parameters(&params, None, &[]).unwrap();
        let mut m = sag.monitor();
        let t = run(&mut m, 0.1, &segments);
        let r = m.ardupilot_resistance_ohm().unwrap();
        assert!((r - 0.05).abs() < 1e-3, "{r}");
        assert_eq!(t, vec![None]);
    }

    /// `BATT_LOW_MAH` 1000 and `BATT_CRT_MAH` 500 of a 5000 mA h capacity: at a constant 7 A
    /// the charge left, `5000 − 7 t / 3.6`, falls below 1000 at 2057.1 s and below 500 at
    /// 2314.3 s; each fires at once (no timer), on the first sample past. Action 0 is kept,
    /// flagged as a warning only.
    #[test]
    fn ardupilot_capacity_thresholds() {
        let params = map(&[
            ("BATT_CAPACITY", 5000.0),
            ("BATT_LOW_MAH", 1000.0),
            ("BATT_CRT_MAH", 500.0),
            ("BATT_FS_LOW_ACT", 0.0),
            ("BATT_FS_CRT_ACT", 1.0),
        ]);
        let v = VehicleFailsafes::from_parameters(&params, None, &[]).unwrap();
        let kinds: Vec<_> = v
            .failsafes
            .iter()
            .map(|f| (f.kind, f.unit, f.action.clone()))
            .collect();
        assert_eq!(
            kinds,
            vec![
                (
                    FailsafeKind::Low,
                    FailsafeUnit::MilliampHour,
                    FailsafeAction::WarnOnly
                ),
                (
                    FailsafeKind::Critical,
                    FailsafeUnit::MilliampHour,
                    FailsafeAction::Acts {
                        param: "BATT_FS_CRT_ACT",
                        value: 1
                    }
                ),
            ]
        );
        let t = run(&mut v.monitor(), 1.0, &[(2500.0, 11.0, 7.0)]);
        assert!(t[0].is_some_and(|t| (t - 2058.0).abs() < 1e-6), "{t:?}");
        assert!(t[1].is_some_and(|t| (t - 2315.0).abs() < 1e-6), "{t:?}");
    }

    /// PX4's levels through the monitor: a 3S pack whose loaded voltage falls linearly (no
    /// current: no load correction) crosses 0.15, 0.07 and 0.05 of the voltage range; each
    /// fires once, 1 s (the voltage filter's lag) after the voltage itself crosses.
    #[test]
    fn px4_levels_fire_in_order_once() {
        let params = map(&[
            ("BAT1_N_CELLS", 3.0),
            ("BAT1_V_EMPTY", 3.5),
            ("BAT1_V_CHARGED", 4.2),
            ("COM_LOW_BAT_ACT", 3.0),
        ]);
        let v = VehicleFailsafes::from_parameters(&params, Some(3), &[]).unwrap();
        let sources: Vec<_> = v.failsafes.iter().map(|f| f.source.as_str()).collect();
        assert_eq!(sources, ["BAT_LOW_THR", "BAT_CRIT_THR", "BAT_EMERGEN_THR"]);
        assert_eq!(v.failsafes[0].action, FailsafeAction::WarnOnly);
        let mut m = v.monitor();
        // soc(t) = 0.5 − 0.001 t: 0.15 at 350 s, 0.07 at 430 s, 0.05 at 450 s.
        let dt = 0.01;
        let mut fired = [None; 3];
        for k in 0..50_000 {
            let t = k as f64 * dt;
            let soc = 0.5 - 0.001 * t;
            let volts = 3.0 * (3.5 + 0.7 * soc);
            for i in m
                .step(if k == 0 { 0.0 } else { dt }, volts, Some(0.0), None)
                .indexes()
            {
                assert!(fired[i].is_none());
                fired[i] = Some(t);
            }
        }
        for (i, at) in [351.0, 431.0, 451.0].into_iter().enumerate() {
            let t = fired[i].unwrap();
            assert!((t - at).abs() < 0.02, "{i}: {t} vs {at}");
        }
    }

    /// A `--low-voltage-v` threshold of 11 V on the voltage averaged over 5 s: a dip from 12 V
    /// to 10 V for 2 s averages 11.2 V and does not trigger; one of 3 s averages 10.8 V at its
    /// end and does (the average falls below 11 V at 2.5 s into the dip). It replaces
    /// `BATT_LOW_VOLT`; `BATT_CRT_VOLT` stays.
    #[test]
    fn generic_threshold_on_the_5_s_average() {
        let flag = VoltageThreshold {
            kind: FailsafeKind::Low,
            voltage_v: 11.0,
            source: "--low-voltage-v".into(),
        };
        let params = map(&[("BATT_LOW_VOLT", 10.5), ("BATT_CRT_VOLT", 9.0)]);
        let v =
            VehicleFailsafes::from_parameters(&params, None, std::slice::from_ref(&flag)).unwrap();
        let sources: Vec<_> = v.failsafes.iter().map(|f| f.source.as_str()).collect();
        assert_eq!(sources, ["--low-voltage-v", "BATT_CRT_VOLT"]);
        let only = VehicleFailsafes::from_parameters(&BTreeMap::new(), None, &[flag]).unwrap();
        let t = run(
            &mut only.monitor(),
            0.1,
            &[(10.0, 12.0, 10.0), (2.0, 10.0, 10.0), (10.0, 12.0, 10.0)],
        );
        assert_eq!(t, vec![None]);
        let t = run(
            &mut only.monitor(),
            0.1,
            &[(10.0, 12.0, 10.0), (3.0, 10.0, 10.0), (10.0, 12.0, 10.0)],
        );
        // The dip's samples start at 10.0 s (held from there); 10 V over 2.5 of 5 s is 11 V.
        assert!(t[0].is_some_and(|t| t > 12.4 && t < 12.7), "{t:?}");
    }

    #[test]
    fn bad_thresholds_are_named() {
        for (entries, name) in [
            (vec![("BATT_LOW_VOLT", f64::NAN)], "BATT_LOW_VOLT"),
            (vec![("BATT_LOW_MAH", -10.0)], "BATT_LOW_MAH"),
            (vec![("BATT_FS_VOLTSRC", 2.0)], "BATT_FS_VOLTSRC"),
            (
                vec![("BATT_LOW_MAH", 500.0), ("BATT_CAPACITY", 0.0)],
                "BATT_CAPACITY",
            ),
            (
                vec![("BAT1_N_CELLS", 3.0), ("BAT1_CAPACITY", -2.0)],
                "BAT1_CAPACITY",
            ),
        ] {
            let err = VehicleFailsafes::from_parameters(&map(&entries), None, &[]).unwrap_err();
            assert!(err.to_string().contains(name), "{err}");
        }
        let flag = VoltageThreshold {
            kind: FailsafeKind::Critical,
            voltage_v: -1.0,
            source: "--critical-voltage-v".into(),
        };
        let err = VehicleFailsafes::from_parameters(&BTreeMap::new(), None, &[flag]).unwrap_err();
        assert!(err.to_string().contains("--critical-voltage-v"), "{err}");
    }

    /// A clone at "now" steps on from the same timers: the original's trigger time is the
    /// clone's.
    #[test]
    fn a_clone_carries_the_timers() {
        let v =
            VehicleFailsafes::from_parameters(&map(&[("BATT_LOW_VOLT", 10.5)]), None, &[]).unwrap();
        let mut m = v.monitor();
        let t = run(&mut m, 0.1, &[(6.0, 10.0, 10.0)]);
        assert_eq!(t, vec![None]);
        let mut copy = m.clone();
        let mut fired_after_s = None;
        for k in 1..=100 {
            if !copy.step(0.1, 10.0, Some(10.0), None).is_empty() {
                fired_after_s = Some(k as f64 * 0.1);
                break;
            }
        }
        // Below since 0 s, 5.9 s stepped: fires 10 s after the start, 4.1-4.2 s on.
        assert!(
            fired_after_s.is_some_and(|s| s > 4.05 && s < 4.25),
            "{fired_after_s:?}"
        );
        assert!(!m.has_triggered(0));
    }
}
