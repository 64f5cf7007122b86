//! The pack's state of charge in flight: [`aloft_packs::SocFilter`] (an extended Kalman filter
//! over the pack's equivalent circuit) fed the flight's current and voltage.
//!
//! - **Started** on the ground from what [`super::charge`] makes of the evidence before take-off:
//!   the rested voltage (on the pack's open-circuit curve, as sure as a generic curve allows),
//!   else the vehicle's believed report (as sure as its kind, [`ReportKind`]), else a full pack
//!   with a wide band ([`ASSUMED_FULL_SD`]); started again whenever that evidence changes, until
//!   take-off. A stream that starts in the air starts at its first sample the same way.
//! - **In the air and after**: each sample counts the current since the last (the measured
//!   current, else the measured power over the voltage, else the energy used over the voltage)
//!   and reads the voltage through the circuit (only where the current is known: the sag is the
//!   circuit's to explain). The vehicle's reports are measurements, at most one every
//!   [`REPORT_INTERVAL_S`] and only while [`super::charge`] believes them; a report the autopilot
//!   derives from the voltage (PX4 without `BAT1_CAPACITY`) adds nothing to the voltage the filter
//!   reads itself and is not taken.

use std::collections::BTreeMap;

use aloft_packs::{Circuit, FilterTuning, ReportKind, SocEstimate, SocFilter};
use aloft_planner::battery::Pack;

/// The band of a full pack assumed at the start (one standard deviation): the voltage in the
/// air corrects it.
pub(crate) const ASSUMED_FULL_SD: f64 = 0.3;

/// How long a stream that starts in the air waits for a voltage or a report before it starts
/// from a full pack, s of flight.
pub(crate) const START_WAIT_S: f64 = 5.0;

/// Least time between two of the vehicle's reports taken as measurements, s (a report at 5 Hz
/// is one estimate repeated, not five).
pub(crate) const REPORT_INTERVAL_S: f64 = 10.0;

/// Longest gap over which the measured current is held to count the charge, s; over a longer
/// one (a silent link) the energy used is counted instead.
const MAX_CURRENT_GAP_S: f64 = 5.0;

/// What the state of charge starts from before take-off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Start {
    /// The rested voltage before take-off, V (the pack's open-circuit voltage).
    Rested(f64),
    /// The vehicle's believed report (0-1), less what was drawn since.
    Reported(f64),
    /// Nothing: a full pack.
    Full,
    /// The voltage under load of the first sample in the air.
    Loaded,
}

/// The band of a start from the voltage under load in the air (a stream that starts in the
/// air, nothing reported yet): the circuit's sag and the curve (one standard deviation).
pub(crate) const LOADED_START_SD: f64 = 0.15;

/// The filter and what it was last fed.
#[derive(Debug, Clone)]
pub(crate) struct PackState {
    circuit: Circuit,
    filter: Option<SocFilter>,
    /// Time of the last sample counted, s, and the energy used then, W h.
    last: Option<(f64, f64)>,
    /// Last voltage measured, V.
    voltage_v: Option<f64>,
    took_off: bool,
    start: Option<Start>,
    /// The vehicle's last report (0-1) and when it was last taken as a measurement, s.
    reported: Option<f64>,
    last_fused_s: f64,
    /// A voltage that is not this pack's (V): the vehicle file's pack is not the one flown,
    /// and the filter is not used.
    foreign_v: Option<f64>,
    /// Since when the voltages have been outside this pack's range, s (a glitch lasts less
    /// than [`FOREIGN_AFTER_S`]).
    outside_since_s: Option<f64>,
}

/// How long voltages outside the pack's range must last, once the pack's own voltage was seen,
/// before they are another pack's, s: a logged glitch (one 1 Hz record) is not.
pub(crate) const FOREIGN_AFTER_S: f64 = 5.0;

/// The voltages a pack may show under load, V per cell: below, or above, it is another pack
/// (other cells in series).
pub(crate) const PACK_CELL_V: (f64, f64) = (2.5, 4.35);

impl PackState {
    /// The state of a flight on `pack` (its open-circuit curve, cells, capacity and resistance;
    /// the default RC pair).
    pub(crate) fn new(pack: &Pack) -> Self {
        let mut circuit = Circuit::with_default_rc(
            pack.ocv_curve(),
            pack.cells_series(),
            pack.capacity_ah(),
            pack.resistance_ohm(),
        );
        // The pack file's RC pair where `aloft pack fit` identified one.
        if let Some((r, tau)) = pack.rc_pair() {
            circuit.rc_resistance_ohm = r;
            circuit.rc_time_constant_s = tau;
        }
        Self {
            circuit,
            filter: None,
            last: None,
            voltage_v: None,
            took_off: false,
            start: None,
            reported: None,
            last_fused_s: f64::NEG_INFINITY,
            foreign_v: None,
            outside_since_s: None,
        }
    }

    /// The estimate now and its band; `None` before anything started it, or where the voltage
    /// is not this pack's.
    pub(crate) fn estimate(&self) -> Option<SocEstimate> {
        if self.foreign_v.is_some() {
            return None;
        }
        self.filter.as_ref().map(SocFilter::band)
    }

    /// A voltage seen that is not this pack's, V.
    pub(crate) fn foreign_v(&self) -> Option<f64> {
        self.foreign_v
    }

    /// The filter itself (to fly the rest of the route on), where the voltage is this pack's.
    pub(crate) fn filter(&self) -> Option<&SocFilter> {
        self.filter.as_ref().filter(|_| self.foreign_v.is_none())
    }

    /// What the filter started from (`None`: not started).
    pub(crate) fn start(&self) -> Option<Start> {
        self.start
    }

    /// The vehicle's last report, 0-1.
    pub(crate) fn reported(&self) -> Option<f64> {
        self.reported
    }

    /// Before take-off (and at the first sample of a stream that starts in the air): start the
    /// filter from `start` where it changed. In the air with nothing but a full pack to start
    /// from, the voltage under load `loaded` (V, A) of the first sample is a better start: its
    /// open-circuit voltage `V + I R` on the curve, within [`LOADED_START_SD`].
    pub(crate) fn start_from(
        &mut self,
        start: Start,
        kind: ReportKind,
        loaded: Option<(f64, f64)>,
    ) {
        let start = match (start, loaded) {
            (Start::Full, Some((v, i)))
                if self.filter.is_none() || self.start == Some(Start::Full) =>
            {
                let ocv_v = v + i * self.circuit.resistance_ohm;
                let cells = f64::from(self.circuit.cells_series);
                let soc = self.circuit.ocv.soc_at(ocv_v / cells);
                let tuning = FilterTuning::default();
                if let Ok(f) = SocFilter::new(self.circuit.clone(), tuning, soc, LOADED_START_SD) {
                    self.filter = Some(f);
                    self.start = Some(Start::Loaded);
                }
                return;
            }
            _ => start,
        };
        if self.took_off && self.filter.is_some() {
            return;
        }
        if self.start == Some(start) && self.filter.is_some() {
            return;
        }
        let tuning = FilterTuning::default();
        let c = self.circuit.clone();
        let filter = match start {
            Start::Rested(v) => SocFilter::from_rested_voltage(c, tuning, v),
            Start::Reported(soc) => SocFilter::new(c, tuning, soc.clamp(0.0, 1.0), kind.sd()),
            Start::Full | Start::Loaded => SocFilter::new(c, tuning, 1.0, ASSUMED_FULL_SD),
        };
        // The circuit is the vehicle file's pack, checked when it was read: a start it refuses
        // keeps the filter it had.
        if let Ok(f) = filter {
            self.filter = Some(f);
            self.start = Some(start);
        }
    }

    /// `v` (V) at `time_s` where it is this pack's. Outside the pack's range it is not read: it
    /// is another pack's at once where the pack's own was never seen, else once it has lasted
    /// [`FOREIGN_AFTER_S`] (before that, a glitch).
    fn own_voltage(&mut self, time_s: f64, v: f64) -> Option<f64> {
        let cell_v = v / f64::from(self.circuit.cells_series);
        if (PACK_CELL_V.0..=PACK_CELL_V.1).contains(&cell_v) {
            self.outside_since_s = None;
            self.voltage_v = Some(v);
            return Some(v);
        }
        let since = *self.outside_since_s.get_or_insert(time_s);
        if self.voltage_v.is_none() || time_s - since >= FOREIGN_AFTER_S {
            self.foreign_v.get_or_insert(v);
        }
        None
    }

    /// The vehicle took off: from now on the filter runs on.
    pub(crate) fn in_air(&mut self) {
        self.took_off = true;
    }

    /// Whether the filter runs on (it started in the air or took off).
    pub(crate) fn running(&self) -> bool {
        self.took_off
    }

    /// A sample at `time_s`: its voltage (V), current (A) and power (W) where measured, and the
    /// energy used so far (W h, measured or the model's).
    pub(crate) fn sample(
        &mut self,
        time_s: f64,
        measured: (Option<f64>, Option<f64>, Option<f64>),
        energy_used_wh: f64,
    ) {
        let (voltage_v, current_a, power_w) = measured;
        let voltage_v = voltage_v
            .filter(|v| v.is_finite() && *v > 0.0)
            .and_then(|v| self.own_voltage(time_s, v));
        let current_a = current_a.filter(|i| i.is_finite()).or_else(|| {
            let v = self.voltage_v?;
            power_w.filter(|p| p.is_finite()).map(|p| p / v)
        });
        let last = self.last.replace((time_s, energy_used_wh));
        let Some(filter) = self.filter.as_mut().filter(|_| self.took_off) else {
            return;
        };
        let Some((t0, e0)) = last else {
            return;
        };
        let dt_s = time_s - t0;
        if dt_s.is_nan() || dt_s <= 0.0 {
            return;
        }
        match current_a {
            Some(i) if dt_s <= MAX_CURRENT_GAP_S => filter.predict(dt_s, i),
            _ => {
                // The charge of the energy used at the pack's voltage.
                let v = self.voltage_v.unwrap_or_else(|| self.circuit.ocv_v(0.5));
                let charge_as = 3600.0 * (energy_used_wh - e0).max(0.0) / v;
                filter.predict(dt_s, charge_as / dt_s);
            }
        }
        if let (Some(v), Some(i)) = (voltage_v, current_a) {
            filter.voltage(v, i);
        }
    }

    /// A state of charge `soc` (0-1) the vehicle reports at `time_s`, `believed` as
    /// [`super::charge`] judges it, of `kind`.
    pub(crate) fn report(&mut self, time_s: f64, soc: f64, believed: bool, kind: ReportKind) {
        if !(soc.is_finite() && (0.0..=1.0).contains(&soc)) {
            return;
        }
        self.reported = Some(soc);
        let Some(filter) = self.filter.as_mut().filter(|_| self.took_off) else {
            return;
        };
        let adds = kind != ReportKind::Voltage || self.voltage_v.is_none();
        if believed
            && adds
            && time_s - self.last_fused_s >= REPORT_INTERVAL_S
            && filter.report(soc, kind)
        {
            self.last_fused_s = time_s;
        }
    }
}

/// What kind of state of charge the vehicle reports, from its parameters: PX4 (`BAT1_*`, or the
/// older `BAT_*`) without a capacity (`BAT1_CAPACITY` unset: -1) estimates it from the voltage
/// under load (battery.cpp); PX4 with a capacity, ArduPilot (its monitors count from the
/// capacity) and a vehicle whose parameters are not known count the charge drawn.
pub(crate) fn report_kind(parameters: &BTreeMap<String, f64>) -> ReportKind {
    let capacity = parameters
        .get("BAT1_CAPACITY")
        .or_else(|| parameters.get("BAT_CAPACITY"));
    match capacity {
        Some(c) if c.is_nan() || *c <= 0.0 => ReportKind::Voltage,
        _ => ReportKind::Counted,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use aloft_planner::BatterySpec;

    /// A 12S pack of 10 A h on the generic curve.
    fn spec_12s() -> BatterySpec {
        BatterySpec {
            name: "12s".into(),
            cells_series: 12,
            capacity_mah: 10_000.0,
            nominal_v: Some(44.4),
            energy_wh: Some(444.0),
            mass_kg: Some(1.0),
            internal_resistance_ohm: Some(0.02),
            cutoff_cell_v: Some(3.0),
            ..BatterySpec::default()
        }
    }

    fn pack_12s() -> Pack {
        Pack::new(&spec_12s()).unwrap()
    }

    /// A state in the air from a loaded 12S voltage, fed `voltages` (V at 25 A) at 10 Hz.
    fn fed(voltages: &[f64]) -> PackState {
        let mut p = PackState::new(&pack_12s());
        p.start_from(Start::Full, ReportKind::Counted, Some((voltages[0], 25.0)));
        p.in_air();
        for (k, v) in voltages.iter().enumerate() {
            p.sample(0.1 * k as f64, (Some(*v), Some(25.0), None), 0.0);
        }
        p
    }

    /// One logged glitch (KAIST `2018-08-06.11_52_45`: one 1 Hz record of 90 V, repeated over
    /// ten 10 Hz rows, between 48 V records) is not another pack: the filter runs on.
    #[test]
    fn a_one_second_voltage_glitch_is_not_another_pack() {
        let mut v = vec![48.0; 100];
        v.extend([90.0; 10]);
        v.extend([48.0; 100]);
        let p = fed(&v);
        assert_eq!(p.foreign_v(), None);
        assert!(p.filter().is_some() && p.estimate().is_some());
    }

    /// A voltage that is another pack's from the first sample (a 4S pack's 16 V read as 12S),
    /// or for longer than [`FOREIGN_AFTER_S`], is another pack's.
    #[test]
    fn another_packs_voltage_is_said_at_once_or_when_it_lasts() {
        assert_eq!(fed(&[16.0; 20]).foreign_v(), Some(16.0));
        let mut v = vec![48.0; 10];
        v.extend([16.0; 80]);
        let p = fed(&v);
        assert_eq!(p.foreign_v(), Some(16.0));
        assert!(p.filter().is_none());
    }

    /// The pack file's RC pair is the circuit's (a pair `aloft pack fit` identified); without
    /// one, the filter's default; half a pair is refused naming the key given.
    #[test]
    fn the_pack_files_rc_pair_is_the_circuits() {
        let spec = |r: Option<f64>, tau: Option<f64>| BatterySpec {
            rc_resistance_ohm: r,
            rc_time_constant_s: tau,
            ..spec_12s()
        };
        let p = PackState::new(&Pack::new(&spec(Some(0.015), Some(12.0))).unwrap());
        let c = &p.circuit;
        assert_eq!(
            (c.rc_resistance_ohm, c.rc_time_constant_s).to_owned(),
            (0.015, 12.0)
        );
        let d = PackState::new(&pack_12s());
        let default = aloft_packs::soc_filter::DEFAULT_RC_TIME_CONSTANT_S;
        assert!((d.circuit.rc_time_constant_s - default).abs() < 1e-12);
        let e = Pack::new(&spec(Some(0.015), None)).unwrap_err().to_string();
        assert!(e.contains("rc_resistance_ohm"), "{e}");
        let e = Pack::new(&spec(Some(0.015), Some(-1.0)))
            .unwrap_err()
            .to_string();
        assert!(e.contains("rc_time_constant_s"), "{e}");
    }
}
