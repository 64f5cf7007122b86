//! PX4's own battery estimate, emulated: the `remaining` a PX4 vehicle reports and the warning
//! levels its battery failsafes act on, computed from the voltage and current it measures.
//!
//! # The model (PX4 v1.14, `src/lib/battery/battery.cpp`)
//!
//! Each PX4 cycle (`battery_status` publishes at 100 Hz, [`PX4_CYCLE_S`]):
//!
//! 1. the pack voltage and the current pass first-order filters, `y += α (u − y)` with
//!    `α = Δt₀ / (Δt₀ + τ)`, `Δt₀` = [`PX4_CYCLE_S`], τ = 1 s for the voltage and 0.5 s for the
//!    current ([`VOLTAGE_FILTER_TAU_S`], [`CURRENT_FILTER_TAU_S`]); until the battery is
//!    initialised (2 s connected, [`INIT_DELAY_S`]) they are reset to each raw sample;
//! 2. a cell voltage `v = V_f / BAT1_N_CELLS`, corrected for the load: `+ BAT1_R_INTERNAL · I_f`
//!    when `BAT1_R_INTERNAL ≥ 0` and `I_f > FLT_EPSILON`, else `+ thrust · BAT1_V_LOAD_DROP`
//!    (thrust = the length of the thrust setpoint, 0-1);
//! 3. the voltage-based state of charge, linear in `v` between `BAT1_V_EMPTY` (0) and
//!    `BAT1_V_CHARGED` (1), clamped to 0-1;
//! 4. with `BAT1_CAPACITY > 0` (and the battery initialised), fused with the coulomb count:
//!    `s ← (1 − w) s + w s_v` with `w = 3·10⁻⁴ (1 − s_v)` ([`VOLTAGE_WEIGHT`]), then
//!    `s ← s − ΔQ / C`, `s ≥ 0`, and `s ≤ 1 − Q / C`; without a capacity, `s = s_v`: the
//!    reported `remaining` is the voltage estimate itself and sags under load;
//! 5. the warning: emergency below `BAT_EMERGEN_THR`, critical below `BAT_CRIT_THR`, low below
//!    `BAT_LOW_THR` (strict `<`, re-evaluated each cycle: `battery.cpp` does not latch it);
//!    the commander (`HealthAndArmingChecks/checks/batteryCheck.cpp`) latches it while armed
//!    (a warning only goes up) and its failsafe (`commander/failsafe/failsafe.cpp`) acts on
//!    the latched level: low only warns; critical and emergency act as `COM_LOW_BAT_ACT`
//!    says (0 warning, 1 return, 2 land, 3 return at critical and land at emergency).
//!
//! With `BAT1_N_CELLS` 0 (the default: not configured) v1.14 divides by zero: the cell
//! voltage is infinite and `remaining` is 1.0 whatever the pack holds, so no battery
//! warning ever comes. The guard that reports −1 instead (PX4 PR #19915) was merged after
//! v1.14. The shared flights `log_20` and `log_30` show it: `cell_count` 0, `remaining` 1.0
//! in every record.
//!
//! The version: the shared flights' ULog `ver_sw` is `18898f18…`, `ver_sw_release`
//! `0x010e0080` (v1.14.0). The reference read is `battery.cpp` as of 2024 (before the
//! online resistance estimate, PR #23205) with the two later changes taken back out: the
//! `n_cells == 0` guard (#19915) and the voltage weight of 3·10⁻² (#22761, February 2024;
//! v1.14 and the 1.13 files read have 3·10⁻⁴). A negative `BAT1_R_INTERNAL` in v1.14 means
//! "use `BAT1_V_LOAD_DROP`" (the online estimate it selects in later versions came after).
//! Defaults are v1.14's, as the flights' untouched `BAT2_*` parameters show them:
//! `V_EMPTY` 3.6 V, `V_CHARGED` 4.05 V, `R_INTERNAL` 0.005 Ω, `V_LOAD_DROP` 0.1 V,
//! `N_CELLS` 0, `CAPACITY` −1 (unset); `BAT_LOW_THR` 0.15, `BAT_CRIT_THR` 0.07,
//! `BAT_EMERGEN_THR` 0.05 (`battery_params_common.c`).
//!
//! # Deviation
//!
//! - PX4 runs every 10 ms; here a step lasts any `dt_s`. The filters and the fusion weight
//!   are applied as `dt_s / Δt₀` PX4 cycles with the sample held (`(1 − α)^(dt_s/Δt₀)`), so
//!   a step of 10 ms is PX4's own cycle exactly. Fed a log's 5 Hz records (one PX4 sample in
//!   twenty), the filtered voltage differs from PX4's by the samples it never saw: on the
//!   shared flights `remaining` agrees to 1.3-1.6 % RMS (worst 4.4-5.1 %), and to float
//!   precision when fed PX4's own filtered values (`tests/px4_data_val.rs`).
//! - A current that is unknown (`None`), negative or not finite is PX4's "invalid current":
//!   the coulomb count stops and restarts a sample later, and the load correction takes the
//!   thrust branch. PX4 then keeps subtracting the last counted increment each cycle; here
//!   it is not subtracted again.
//! - "Connected" is the filtered voltage at or above 2.1 V (PX4's recognition voltage); the
//!   driver's own connection flag is not modelled.
//! - The warning's commander latch is modelled as if armed from the first step.
//! - f64 throughout (PX4 computes in f32).

use std::collections::BTreeMap;

use crate::PackError;

/// PX4's battery cycle, s: `battery_status` runs at 100 Hz (the shared logs' first records
/// are 10 ms apart) and the filters' coefficients are set for that period.
pub const PX4_CYCLE_S: f64 = 0.01;
/// Time constant of PX4's voltage filter, s.
pub const VOLTAGE_FILTER_TAU_S: f64 = 1.0;
/// Time constant of PX4's current filter, s.
pub const CURRENT_FILTER_TAU_S: f64 = 0.5;
/// Below this filtered pack voltage PX4 takes the battery as disconnected, V.
pub const RECOGNITION_VOLTAGE_V: f64 = 2.1;
/// How long the battery must be connected before PX4 trusts its filters, s.
pub const INIT_DELAY_S: f64 = 2.0;
/// The weight of the voltage estimate in the fusion with the coulomb count, per PX4 cycle,
/// at an empty voltage estimate (times `1 − s_v`); v1.14.
pub const VOLTAGE_WEIGHT: f64 = 3e-4;
/// C's `FLT_EPSILON`, the current above which PX4 corrects with `BAT1_R_INTERNAL`, A.
const FLT_EPSILON: f64 = f32::EPSILON as f64;

/// The parameters PX4's battery estimate reads (battery 1) and its warning thresholds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Px4BatteryParams {
    /// `BAT1_N_CELLS`: cells in series; 0 = not configured (`remaining` stays 1.0).
    pub n_cells: u32,
    /// `BAT1_V_EMPTY`: the cell voltage read as empty, V.
    pub v_empty_v: f64,
    /// `BAT1_V_CHARGED`: the cell voltage read as full, V.
    pub v_charged_v: f64,
    /// `BAT1_R_INTERNAL`: the cell's internal resistance, Ω; negative = use
    /// [`Self::v_load_drop_v`] with the thrust instead.
    pub r_internal_ohm: f64,
    /// `BAT1_V_LOAD_DROP`: the cell's voltage drop at full thrust, V (used when
    /// `BAT1_R_INTERNAL` is negative or no current flows).
    pub v_load_drop_v: f64,
    /// `BAT1_CAPACITY`, mA h; `None` when unset (−1 or 0): the estimate is the voltage's alone.
    pub capacity_mah: Option<f64>,
    /// `BAT_LOW_THR`, state of charge 0-1.
    pub low_thr: f64,
    /// `BAT_CRIT_THR`, state of charge 0-1.
    pub crit_thr: f64,
    /// `BAT_EMERGEN_THR`, state of charge 0-1.
    pub emergen_thr: f64,
    /// `COM_LOW_BAT_ACT`: what the commander does at critical and emergency (0 warning,
    /// 1 return, 2 land, 3 return then land); `None` when the map does not give it.
    pub low_bat_action: Option<i64>,
}

/// The parameters whose presence says the map is a PX4 vehicle's battery setup.
const PX4_BATTERY_KEYS: [&str; 8] = [
    "BAT1_N_CELLS",
    "BAT1_V_EMPTY",
    "BAT1_V_CHARGED",
    "BAT1_R_INTERNAL",
    "BAT1_CAPACITY",
    "BAT_LOW_THR",
    "BAT_CRIT_THR",
    "BAT_EMERGEN_THR",
];

impl Default for Px4BatteryParams {
    /// PX4 v1.14's defaults.
    fn default() -> Self {
        Self {
            n_cells: 0,
            v_empty_v: 3.6,
            v_charged_v: 4.05,
            r_internal_ohm: 0.005,
            v_load_drop_v: 0.1,
            capacity_mah: None,
            low_thr: 0.15,
            crit_thr: 0.07,
            emergen_thr: 0.05,
            low_bat_action: None,
        }
    }
}

/// A parameter's value, finite, or PX4's default when the map lacks it.
fn finite(params: &BTreeMap<String, f64>, name: &str, default: f64) -> Result<f64, PackError> {
    let Some(&value) = params.get(name) else {
        return Ok(default);
    };
    if value.is_finite() {
        Ok(value)
    } else {
        Err(invalid(name, value, "a finite number"))
    }
}

/// The error for a parameter out of range.
pub(crate) fn invalid(name: &str, value: f64, expected: &'static str) -> PackError {
    PackError::InvalidParameter {
        name: name.to_string(),
        value,
        expected,
    }
}

/// A parameter within `lo..=hi`, or PX4's default.
fn within(
    params: &BTreeMap<String, f64>,
    name: &str,
    default: f64,
    (lo, hi): (f64, f64),
    expected: &'static str,
) -> Result<f64, PackError> {
    let value = finite(params, name, default)?;
    if (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(invalid(name, value, expected))
    }
}

impl Px4BatteryParams {
    /// Reads PX4's battery parameters from a vehicle's parameter map (names as PX4 spells
    /// them); a parameter the map lacks takes v1.14's default. `None` when the map holds none
    /// of `BAT1_N_CELLS`, `BAT1_V_EMPTY`, `BAT1_V_CHARGED`, `BAT1_R_INTERNAL`,
    /// `BAT1_CAPACITY`, `BAT_LOW_THR`, `BAT_CRIT_THR`, `BAT_EMERGEN_THR` (not a PX4 vehicle).
    ///
    /// # Errors
    /// [`PackError::InvalidParameter`] naming a value that is not finite or out of range
    /// (cells 0-16 whole; cell voltages in (0, 5] V; `BAT1_R_INTERNAL` in [−1, 0.2] Ω;
    /// `BAT1_V_LOAD_DROP` in [0, 1] V; `BAT1_CAPACITY` −1, 0 or up to 100 000 mA h;
    /// thresholds 0-1; `COM_LOW_BAT_ACT` a whole number);
    /// [`PackError::EmptyNotBelowCharged`] when `BAT1_V_EMPTY ≥ BAT1_V_CHARGED`.
    pub fn from_parameters(params: &BTreeMap<String, f64>) -> Result<Option<Self>, PackError> {
        if !PX4_BATTERY_KEYS.iter().any(|k| params.contains_key(*k)) {
            return Ok(None);
        }
        let d = Self::default();
        let cells = within(
            params,
            "BAT1_N_CELLS",
            0.0,
            (0.0, 16.0),
            "0 (not set) to 16 cells",
        )?;
        if cells.fract() != 0.0 {
            return Err(invalid(
                "BAT1_N_CELLS",
                cells,
                "a whole number of cells, 0-16",
            ));
        }
        let cell_v = (f64::MIN_POSITIVE, 5.0);
        let v_empty_v = within(
            params,
            "BAT1_V_EMPTY",
            d.v_empty_v,
            cell_v,
            "a cell voltage in (0, 5] V",
        )?;
        let v_charged_v = within(
            params,
            "BAT1_V_CHARGED",
            d.v_charged_v,
            cell_v,
            "a cell voltage in (0, 5] V",
        )?;
        if v_empty_v >= v_charged_v {
            return Err(PackError::EmptyNotBelowCharged {
                empty_name: "BAT1_V_EMPTY".into(),
                empty_v: v_empty_v,
                charged_name: "BAT1_V_CHARGED".into(),
                charged_v: v_charged_v,
            });
        }
        let fraction = (0.0, 1.0);
        let out = Self {
            n_cells: cells as u32,
            v_empty_v,
            v_charged_v,
            r_internal_ohm: within(
                params,
                "BAT1_R_INTERNAL",
                d.r_internal_ohm,
                (-1.0, 0.2),
                "-1 to 0.2 ohm a cell (negative: use BAT1_V_LOAD_DROP)",
            )?,
            v_load_drop_v: within(
                params,
                "BAT1_V_LOAD_DROP",
                d.v_load_drop_v,
                (0.0, 1.0),
                "0-1 V a cell",
            )?,
            capacity_mah: capacity(params)?,
            low_thr: within(
                params,
                "BAT_LOW_THR",
                d.low_thr,
                fraction,
                "a state of charge 0-1",
            )?,
            crit_thr: within(
                params,
                "BAT_CRIT_THR",
                d.crit_thr,
                fraction,
                "a state of charge 0-1",
            )?,
            emergen_thr: within(
                params,
                "BAT_EMERGEN_THR",
                d.emergen_thr,
                fraction,
                "a state of charge 0-1",
            )?,
            low_bat_action: low_bat_action(params)?,
        };
        Ok(Some(out))
    }
}

/// `BAT1_CAPACITY`: −1 (PX4's "unset") and 0 are no capacity; any other negative is an error.
fn capacity(params: &BTreeMap<String, f64>) -> Result<Option<f64>, PackError> {
    let expected = "-1 (unset) or a capacity up to 100000 mAh";
    let value = finite(params, "BAT1_CAPACITY", -1.0)?;
    // PX4 stores -1 as a float: within half a unit of -1 is the unset value.
    if (value + 1.0).abs() < 0.5 || value == 0.0 {
        Ok(None)
    } else if value > 0.0 && value <= 100_000.0 {
        Ok(Some(value))
    } else {
        Err(invalid("BAT1_CAPACITY", value, expected))
    }
}

/// `COM_LOW_BAT_ACT`, a whole number when given.
fn low_bat_action(params: &BTreeMap<String, f64>) -> Result<Option<i64>, PackError> {
    let Some(&value) = params.get("COM_LOW_BAT_ACT") else {
        return Ok(None);
    };
    if value.is_finite() && value.fract() == 0.0 && value.abs() < 1e6 {
        Ok(Some(value as i64))
    } else {
        Err(invalid(
            "COM_LOW_BAT_ACT",
            value,
            "a whole number (0 warning, 1 return, 2 land, 3 return or land)",
        ))
    }
}

/// PX4's battery warning levels (`battery_status.warning`), ordered by urgency.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Px4Warning {
    /// No warning.
    #[default]
    None,
    /// Below `BAT_LOW_THR`.
    Low,
    /// Below `BAT_CRIT_THR`.
    Critical,
    /// Below `BAT_EMERGEN_THR`.
    Emergency,
}

/// What PX4 reports after one update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Px4Estimate {
    /// `battery_status.remaining`, 0-1.
    pub remaining: f64,
    /// The voltage-based state of charge (step 3), 0-1.
    pub remaining_voltage_based: f64,
    /// `battery_status.warning` as `battery.cpp` sets it this cycle.
    pub warning: Px4Warning,
    /// The commander's warning while armed: the worst so far (what its failsafe acts on).
    pub failsafe_warning: Px4Warning,
    /// `battery_status.voltage_filtered_v`, V.
    pub voltage_filtered_v: f64,
    /// `battery_status.current_filtered_a`, A.
    pub current_filtered_a: f64,
    /// `battery_status.discharged_mah`: PX4's coulomb count since the emulation started, mA h.
    pub discharged_mah: f64,
}

/// PX4's battery state, to resume an emulation where a vehicle already runs (its filters
/// settled, its estimate known), e.g. from a log's first `battery_status` record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Px4Resume {
    /// `voltage_filtered_v`, V.
    pub voltage_filtered_v: f64,
    /// `current_filtered_a`, A.
    pub current_filtered_a: f64,
    /// `remaining`, 0-1.
    pub remaining: f64,
    /// `discharged_mah`, mA h.
    pub discharged_mah: f64,
}

/// PX4's battery estimate, stepped sample by sample. `Copy`: clone it at "now" and step the
/// copy along a predicted trace.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Px4Battery {
    params: Px4BatteryParams,
    /// Time since the first update, s.
    elapsed_s: f64,
    /// Whether a sample has been taken.
    started: bool,
    voltage_filtered_v: f64,
    current_filtered_a: f64,
    /// Connected for more than [`INIT_DELAY_S`].
    initialized: bool,
    last_unconnected_s: f64,
    /// The previous current was valid, so this one is counted (PX4's `_last_timestamp != 0`).
    counting: bool,
    discharged_mah: f64,
    discharged_step_mah: f64,
    soc_voltage_based: f64,
    state_of_charge: f64,
    warning: Px4Warning,
    failsafe_warning: Px4Warning,
}

impl Px4Battery {
    /// A battery just connected (PX4's state at boot): the first 2 s its filters follow the
    /// raw samples and no warning is set.
    pub fn new(params: &Px4BatteryParams) -> Self {
        Self {
            params: *params,
            elapsed_s: 0.0,
            started: false,
            voltage_filtered_v: 0.0,
            current_filtered_a: 0.0,
            initialized: false,
            last_unconnected_s: 0.0,
            counting: false,
            discharged_mah: 0.0,
            discharged_step_mah: 0.0,
            soc_voltage_based: 0.0,
            state_of_charge: 0.0,
            warning: Px4Warning::None,
            failsafe_warning: Px4Warning::None,
        }
    }

    /// A battery PX4 has followed for a while: filters, estimate and count resumed from
    /// `state` (the commander's latch starts at the warning `state.remaining` gives).
    pub fn resumed(params: &Px4BatteryParams, state: &Px4Resume) -> Self {
        let mut b = Self::new(params);
        b.started = true;
        b.initialized = true;
        b.last_unconnected_s = -2.0 * INIT_DELAY_S;
        b.counting = true;
        b.voltage_filtered_v = state.voltage_filtered_v;
        b.current_filtered_a = state.current_filtered_a;
        b.discharged_mah = state.discharged_mah;
        b.state_of_charge = state.remaining.clamp(0.0, 1.0);
        b.soc_voltage_based = b.voltage_based(state.current_filtered_a, 0.0);
        b.warning = b.determine_warning(b.state_of_charge);
        b.failsafe_warning = b.warning;
        b
    }

    /// The parameters.
    pub fn params(&self) -> &Px4BatteryParams {
        &self.params
    }

    /// One update: `dt_s` since the previous sample, the pack's voltage and current (`None`
    /// when not measured). No thrust is known: where PX4 would correct with
    /// `thrust · BAT1_V_LOAD_DROP`, the thrust is taken as 0 (see [`Self::update_with_thrust`]).
    pub fn update(&mut self, dt_s: f64, voltage_v: f64, current_a: Option<f64>) -> Px4Estimate {
        self.update_with_thrust(dt_s, voltage_v, current_a, 0.0)
    }

    /// One update with the thrust setpoint's length (0-1), which PX4 uses to correct the
    /// voltage when `BAT1_R_INTERNAL` is negative or no current flows. A `dt_s` that is
    /// negative or not finite, or a voltage that is not finite, changes nothing.
    pub fn update_with_thrust(
        &mut self,
        dt_s: f64,
        voltage_v: f64,
        current_a: Option<f64>,
        thrust: f64,
    ) -> Px4Estimate {
        if !(dt_s.is_finite() && dt_s >= 0.0 && voltage_v.is_finite()) {
            return self.estimate();
        }
        let current_a = current_a.filter(|i| i.is_finite());
        let thrust = if thrust.is_finite() {
            thrust.clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.filter_samples(dt_s, voltage_v, current_a);
        self.update_connection(voltage_v, current_a);
        self.sum_discharged(dt_s, current_a);
        let load_current_a = if current_a.is_some() {
            self.current_filtered_a
        } else {
            0.0
        };
        self.soc_voltage_based = self.voltage_based(load_current_a, thrust);
        self.fuse(dt_s);
        if self.voltage_filtered_v >= RECOGNITION_VOLTAGE_V && self.initialized {
            self.warning = self.determine_warning(self.state_of_charge);
            self.failsafe_warning = self.failsafe_warning.max(self.warning);
        }
        self.estimate()
    }

    /// What PX4 reports now.
    pub fn estimate(&self) -> Px4Estimate {
        Px4Estimate {
            remaining: self.state_of_charge,
            remaining_voltage_based: self.soc_voltage_based,
            warning: self.warning,
            failsafe_warning: self.failsafe_warning,
            voltage_filtered_v: self.voltage_filtered_v,
            current_filtered_a: self.current_filtered_a,
            discharged_mah: self.discharged_mah,
        }
    }

    /// Step 1: the filters take the sample, held for `dt_s` (`dt_s / Δt₀` PX4 cycles).
    fn filter_samples(&mut self, dt_s: f64, voltage_v: f64, current_a: Option<f64>) {
        if !self.started {
            self.started = true;
            self.voltage_filtered_v = voltage_v;
            self.current_filtered_a = current_a.unwrap_or(0.0);
            return;
        }
        self.elapsed_s += dt_s;
        let cycles = dt_s / PX4_CYCLE_S;
        let keep = |tau_s: f64| (1.0 - PX4_CYCLE_S / (PX4_CYCLE_S + tau_s)).powf(cycles);
        let kv = keep(VOLTAGE_FILTER_TAU_S);
        self.voltage_filtered_v = voltage_v + (self.voltage_filtered_v - voltage_v) * kv;
        if let Some(i) = current_a {
            let ki = keep(CURRENT_FILTER_TAU_S);
            self.current_filtered_a = i + (self.current_filtered_a - i) * ki;
        }
    }

    /// Until initialised the filters follow the raw samples; the battery is initialised
    /// once connected for more than [`INIT_DELAY_S`].
    fn update_connection(&mut self, voltage_v: f64, current_a: Option<f64>) {
        if !self.initialized {
            self.voltage_filtered_v = voltage_v;
            if let Some(i) = current_a {
                self.current_filtered_a = i;
            }
        }
        // (The first sample's time is 0, where `last_unconnected_s` starts.)
        if self.voltage_filtered_v < RECOGNITION_VOLTAGE_V {
            self.last_unconnected_s = self.elapsed_s;
        }
        let connected = self.voltage_filtered_v >= RECOGNITION_VOLTAGE_V;
        self.initialized = connected && self.elapsed_s > self.last_unconnected_s + INIT_DELAY_S;
    }

    /// The coulomb count from the raw current; an invalid current stops it for this sample
    /// and the next.
    fn sum_discharged(&mut self, dt_s: f64, current_a: Option<f64>) {
        self.discharged_step_mah = 0.0;
        match current_a {
            Some(i) if i >= 0.0 => {
                if self.counting {
                    self.discharged_step_mah = i * 1e3 * dt_s / 3600.0;
                    self.discharged_mah += self.discharged_step_mah;
                }
                self.counting = true;
            }
            _ => self.counting = false,
        }
    }

    /// Steps 2-3: the load-corrected cell voltage read linearly between empty and full.
    fn voltage_based(&self, current_a: f64, thrust: f64) -> f64 {
        let p = &self.params;
        if p.n_cells == 0 {
            // v1.14 divides by zero cells: an infinite cell voltage, read as full.
            return 1.0;
        }
        let mut cell_v = self.voltage_filtered_v / f64::from(p.n_cells);
        if p.r_internal_ohm >= 0.0 && current_a > FLT_EPSILON {
            cell_v += p.r_internal_ohm * current_a;
        } else {
            cell_v += thrust * p.v_load_drop_v;
        }
        interpolate(cell_v, p.v_empty_v, p.v_charged_v)
    }

    /// Step 4: the fusion with the coulomb count when the capacity is known.
    fn fuse(&mut self, dt_s: f64) {
        let Some(capacity_mah) = self.params.capacity_mah.filter(|_| self.initialized) else {
            self.state_of_charge = self.soc_voltage_based;
            return;
        };
        let w_cycle = VOLTAGE_WEIGHT * (1.0 - self.soc_voltage_based);
        let w = 1.0 - (1.0 - w_cycle).powf(dt_s / PX4_CYCLE_S);
        let mut soc = (1.0 - w) * self.state_of_charge + w * self.soc_voltage_based;
        soc = (soc - self.discharged_step_mah / capacity_mah).max(0.0);
        let counted = (1.0 - self.discharged_mah / capacity_mah).max(0.0);
        self.state_of_charge = soc.min(counted);
    }

    /// Step 5: the warning level of a state of charge (strict `<`, the worst first).
    fn determine_warning(&self, soc: f64) -> Px4Warning {
        let p = &self.params;
        if soc < p.emergen_thr {
            Px4Warning::Emergency
        } else if soc < p.crit_thr {
            Px4Warning::Critical
        } else if soc < p.low_thr {
            Px4Warning::Low
        } else {
            Px4Warning::None
        }
    }
}

/// PX4's `math::interpolate` onto 0-1: 0 at or below `lo`, 1 above `hi`, linear between.
fn interpolate(x: f64, lo: f64, hi: f64) -> f64 {
    if x <= lo {
        0.0
    } else if x > hi {
        1.0
    } else {
        (x - lo) / (hi - lo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params_3s() -> Px4BatteryParams {
        Px4BatteryParams {
            n_cells: 3,
            v_empty_v: 3.5,
            v_charged_v: 4.2,
            r_internal_ohm: 0.01,
            ..Px4BatteryParams::default()
        }
    }

    /// A pack whose cell open-circuit voltage is linear in the state of charge between
    /// `V_EMPTY` and `V_CHARGED`, with PX4's resistance, discharged at a constant current: PX4's
    /// voltage-only estimate is the true state of charge delayed by the voltage filter: PX4's
    /// filter `y ← y + α (u − y)`, `α = Δt₀/(Δt₀ + τ)`, settles on a ramp `(1 − α)/α` cycles
    /// behind it, `(1 − α)/α · Δt₀ = τ` = 1 s exactly.
    #[test]
    fn constant_current_voltage_only_estimate_is_the_linear_formula() {
        let p = params_3s();
        let (current_a, capacity_mah, soc0) = (15.0, 5000.0, 0.95);
        let soc = |t: f64| soc0 - current_a * t / 3.6 / capacity_mah;
        let terminal_v = |t: f64| {
            let ocv_cell = p.v_empty_v + (p.v_charged_v - p.v_empty_v) * soc(t);
            3.0 * (ocv_cell - p.r_internal_ohm * current_a)
        };
        let mut b = Px4Battery::new(&p);
        let dt_s = 0.01;
        let tau = 1.0;
        for k in 0..=60_000 {
            let t = k as f64 * dt_s;
            let e = b.update(
                if k == 0 { 0.0 } else { dt_s },
                terminal_v(t),
                Some(current_a),
            );
            if k % 6000 == 0 && t > 20.0 {
                // After 20 s (20 τ) the filter's start has decayed below 1e-8 of the range.
                let expected = soc(t - tau);
                assert!(
                    (e.remaining - expected).abs() < 1e-6,
                    "t {t}: {} vs {expected}",
                    e.remaining
                );
            }
        }
    }

    /// `BAT1_N_CELLS` 0: v1.14 reads the pack as full whatever its voltage.
    #[test]
    fn no_cells_reads_full() {
        let p = Px4BatteryParams::default();
        let mut b = Px4Battery::new(&p);
        for _ in 0..100 {
            let e = b.update(0.1, 9.0, Some(20.0));
            assert!((e.remaining - 1.0).abs() < 1e-12);
            assert_eq!(e.warning, Px4Warning::None);
        }
    }

    /// The cell voltage (no current) whose estimate is `soc`.
    fn pack_v(p: &Px4BatteryParams, soc: f64) -> f64 {
        3.0 * (p.v_empty_v + (p.v_charged_v - p.v_empty_v) * soc)
    }

    /// Held 5 s at a state of charge just above and just below each threshold: strict `<`.
    /// The warning from `battery.cpp` follows the estimate back up; the commander's does not.
    #[test]
    fn warning_levels_at_their_thresholds() {
        let p = params_3s();
        let cases = [
            (p.low_thr + 1e-4, Px4Warning::None),
            (p.low_thr - 1e-4, Px4Warning::Low),
            (p.crit_thr + 1e-4, Px4Warning::Low),
            (p.crit_thr - 1e-4, Px4Warning::Critical),
            (p.emergen_thr + 1e-4, Px4Warning::Critical),
            (p.emergen_thr - 1e-4, Px4Warning::Emergency),
        ];
        for (soc, expected) in cases {
            let mut b = Px4Battery::new(&p);
            let mut e = b.estimate();
            for _ in 0..50 {
                e = b.update(0.1, pack_v(&p, soc), Some(0.0));
            }
            assert_eq!(e.warning, expected, "soc {soc}");
            assert_eq!(e.failsafe_warning, expected, "soc {soc}");
            for _ in 0..100 {
                e = b.update(0.1, pack_v(&p, 0.5), Some(0.0));
            }
            assert_eq!(e.warning, Px4Warning::None, "recovered from {soc}");
            assert_eq!(e.failsafe_warning, expected, "latched at {soc}");
        }
    }

    /// No warning in the first 2 s: PX4 waits for the battery to be initialised.
    #[test]
    fn no_warning_before_initialised() {
        let p = params_3s();
        let mut b = Px4Battery::new(&p);
        // Up to 1.9 s after the first sample: none.
        for k in 0..20 {
            let e = b.update(if k == 0 { 0.0 } else { 0.1 }, pack_v(&p, 0.01), Some(0.0));
            assert_eq!(e.warning, Px4Warning::None, "step {k}");
        }
        // 2.0 s is the boundary (PX4: strictly later, here subject to the sum of 0.1 s steps);
        // 2.1 s is past it.
        b.update(0.1, pack_v(&p, 0.01), Some(0.0));
        assert_eq!(
            b.update(0.1, pack_v(&p, 0.01), Some(0.0)).warning,
            Px4Warning::Emergency
        );
    }

    /// With a capacity and no current, the estimate relaxes to the voltage's as
    /// `s_v + (s₀ − s_v)(1 − w)^(t/Δt₀)`, `w = 3·10⁻⁴ (1 − s_v)`; a current then draws it down
    /// by the count, never above `1 − Q/C`.
    #[test]
    fn capacity_fusion_relaxes_to_the_voltage_and_counts_the_charge() {
        let p = Px4BatteryParams {
            capacity_mah: Some(5000.0),
            ..params_3s()
        };
        let state = Px4Resume {
            voltage_filtered_v: pack_v(&p, 0.5),
            current_filtered_a: 0.0,
            remaining: 0.9,
            discharged_mah: 0.0,
        };
        let mut b = Px4Battery::resumed(&p, &state);
        let mut e = b.estimate();
        for _ in 0..100 {
            e = b.update(0.1, pack_v(&p, 0.5), Some(0.0));
        }
        let w: f64 = 3e-4 * 0.5;
        let expected = 0.5 + 0.4 * (1.0 - w).powf(10.0 / 0.01);
        assert!(
            (e.remaining - expected).abs() < 1e-9,
            "{} vs {expected}",
            e.remaining
        );
        // 1000 mAh drawn with the voltage reading full: the count bounds it, 1 − 1000/5000.
        let loaded_v = pack_v(&p, 1.0) - 3.0 * p.r_internal_ohm * 5.0;
        let full = Px4Resume {
            voltage_filtered_v: loaded_v,
            current_filtered_a: 5.0,
            remaining: 1.0,
            discharged_mah: 0.0,
        };
        let mut b = Px4Battery::resumed(&p, &full);
        // Resumed mid-flight, the first step is counted: 720 steps of 1 s at 5 A.
        for _ in 0..720 {
            e = b.update(1.0, loaded_v, Some(5.0));
        }
        assert!(
            (e.discharged_mah - 1000.0).abs() < 1e-9,
            "{}",
            e.discharged_mah
        );
        assert!((e.remaining - 0.8).abs() < 1e-9, "{}", e.remaining);
    }

    /// `BAT1_R_INTERNAL` negative: v1.14 corrects by `thrust · BAT1_V_LOAD_DROP` even with a
    /// current; with a resistance but no current flowing, also by the thrust.
    #[test]
    fn load_drop_with_the_thrust() {
        let p = Px4BatteryParams {
            r_internal_ohm: -1.0,
            v_load_drop_v: 0.1,
            ..params_3s()
        };
        // Cell 3.75 V + 0.6 × 0.1 V = 3.81 V: (3.81 − 3.5) / 0.7.
        let mut b = Px4Battery::new(&p);
        let e = b.update_with_thrust(0.0, 3.0 * 3.75, Some(20.0), 0.6);
        assert!((e.remaining - 0.31 / 0.7).abs() < 1e-12, "{}", e.remaining);
        let mut b = Px4Battery::new(&params_3s());
        let e = b.update_with_thrust(0.0, 3.0 * 3.75, Some(0.0), 0.6);
        assert!(
            (e.remaining - (3.75 + 0.6 * 0.1 - 3.5) / 0.7).abs() < 1e-12,
            "{}",
            e.remaining
        );
        let e = b.update_with_thrust(0.0, 3.0 * 3.75, Some(20.0), 0.6);
        assert!(
            (e.remaining - (3.75 + 0.01 * 20.0 - 3.5) / 0.7).abs() < 1e-12,
            "{}",
            e.remaining
        );
    }

    fn map(entries: &[(&str, f64)]) -> BTreeMap<String, f64> {
        entries.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    }

    #[test]
    fn bad_parameters_are_named() {
        let name_of = |e: PackError| match e {
            PackError::InvalidParameter { name, .. } => name,
            PackError::EmptyNotBelowCharged { empty_name, .. } => empty_name,
            other => panic!("{other}"),
        };
        for (entries, name) in [
            (
                vec![("BAT1_N_CELLS", 3.0), ("BAT1_V_EMPTY", f64::NAN)],
                "BAT1_V_EMPTY",
            ),
            (
                vec![("BAT1_N_CELLS", 3.0), ("BAT1_CAPACITY", -5.0)],
                "BAT1_CAPACITY",
            ),
            (vec![("BAT1_N_CELLS", 2.5)], "BAT1_N_CELLS"),
            (vec![("BAT_LOW_THR", 1.5)], "BAT_LOW_THR"),
            (
                vec![("BAT1_V_EMPTY", 4.3), ("BAT1_V_CHARGED", 4.2)],
                "BAT1_V_EMPTY",
            ),
            (vec![("BAT1_R_INTERNAL", f64::INFINITY)], "BAT1_R_INTERNAL"),
        ] {
            let err = Px4BatteryParams::from_parameters(&map(&entries)).unwrap_err();
            assert!(err.to_string().contains(name), "{err}");
            assert_eq!(name_of(err), name);
        }
        let unset = map(&[("BAT1_N_CELLS", 3.0), ("BAT1_CAPACITY", -1.0)]);
        let p = Px4BatteryParams::from_parameters(&unset).unwrap().unwrap();
        assert_eq!(p.capacity_mah, None);
        assert_eq!(
            Px4BatteryParams::from_parameters(&map(&[("BATT_LOW_VOLT", 10.5)])).unwrap(),
            None
        );
    }
}
