//! The pack's state of charge in flight: an extended Kalman filter over an equivalent circuit.
//!
//! The circuit ([`Circuit`]) is the pack's open-circuit curve `V_oc(s)` in series with a
//! resistance `R_0` and one RC pair (`R_1`, time constant `tau = R_1 C_1`), the usual one-pair
//! trade-off for drone packs (Bauersfeld & Scaramuzza, RA-L 2022, arXiv 2109.04741: one time
//! constant, cell voltage within 1.3 % under non-constant discharge). The terminal voltage is
//!
//! `V = V_oc(s) + b - R_0 I - v_1`
//!
//! where `v_1` is the RC pair's voltage and `b` the open-circuit curve's offset for this pack (a
//! generic curve is not the pack's own). The filter ([`SocFilter`]) is Plett's extended Kalman
//! filter for battery management (G. L. Plett, "Extended Kalman filtering for battery management
//! systems of LiPB-based HEV battery packs", J. Power Sources 134 (2004), parts 1-3: state =
//! state of charge and RC voltages, process = coulomb counting, measurement = the circuit's
//! voltage), with two states added, as Plett's part 3 adds the parameters it cannot trust: the
//! series resistance and the curve's offset. State `x = [s, v_1, R_0, b]`:
//!
//! - **predict** over `dt` at current `I` (A, positive discharging): `s -= I dt / (3600 Q)`,
//!   `v_1 = a v_1 + R_1 (1 - a) I` with `a = exp(-dt / tau)`; `R_0` held with a slow random
//!   walk (temperature), `b` with one that grows with the charge drawn (the generic curve's
//!   shape is not the pack's either, [`FilterTuning::curve_shape_sd_cell_v`]: without it the
//!   filter reads the charge from the kinks of a curve that is not the pack's, and is sure of
//!   it). The charge counted is uncertain by the capacity (a systematic error of
//!   [`FilterTuning::capacity_sd`] of what was drawn) and the current sensor's offset
//!   ([`FilterTuning::current_offset_sd_a`] over the time flown): their variance is added as it
//!   grows, so that over a flight it sums to that of a systematic error, not of white noise.
//! - **voltage update**: the measured terminal voltage against the circuit's, Jacobian
//!   `H = [V_oc'(s), -1, -I, 1]`. Sag under load is explained by `R_0 I + v_1` (and `R_0` is
//!   learned where the current steps), so it is never read as charge drawn.
//! - **report update** ([`SocFilter::report`]): a state of charge another estimator gives (the
//!   autopilot's), `H = [1, 0, 0, 0]`, with the variance its kind deserves ([`ReportKind`]).
//!
//! Its band ([`SocFilter::band`]) is `s ± 1.645 sqrt(P_ss)`, the 5th and 95th percentiles of the
//! filter's Gaussian, clamped to 0-1.
//!
//! Defaults, where the pack file and its logs give nothing ([`Circuit::with_default_rc`]): the RC
//! pair `R_1 = R_0`, `tau = 30 s` (aloft's choice: LiPo packs' diffusion time constants of
//! 10-60 s; the filter learns the series resistance, which carries most of the sag).

use aloft_propulsion::OcvCurve;
use nalgebra::{SMatrix, SVector};

/// The state's size.
const N: usize = 5;
type Mat = SMatrix<f64, N, N>;
type Vect = SVector<f64, N>;
type Row = SMatrix<f64, 1, N>;

use crate::PackError;

/// z-score of the 5th and 95th percentiles of a Gaussian.
const Z_90: f64 = 1.644_853_626_951_472_2;

/// A value out of its range, named.
fn invalid(
    name: &'static str,
    value: f64,
    unit: &'static str,
    expected: &'static str,
) -> PackError {
    PackError::InvalidValue {
        name,
        value,
        unit,
        expected,
    }
}

/// The RC pair's time constant where none was fitted, s.
pub const DEFAULT_RC_TIME_CONSTANT_S: f64 = 30.0;

/// The RC pair's resistance where none was fitted, as a multiple of the series resistance.
pub const DEFAULT_RC_RESISTANCE_RATIO: f64 = 1.0;

/// The pack as an equivalent circuit.
#[derive(Debug, Clone, PartialEq)]
pub struct Circuit {
    /// The cell's open-circuit (rested) voltage against the state of charge.
    pub ocv: OcvCurve,
    /// Cells in series.
    pub cells_series: u32,
    /// Capacity, A h.
    pub capacity_ah: f64,
    /// Series resistance of the whole pack, ohm.
    pub resistance_ohm: f64,
    /// The RC pair's resistance, ohm.
    pub rc_resistance_ohm: f64,
    /// The RC pair's time constant, s.
    pub rc_time_constant_s: f64,
}

impl Circuit {
    /// A circuit with the default RC pair ([`DEFAULT_RC_RESISTANCE_RATIO`],
    /// [`DEFAULT_RC_TIME_CONSTANT_S`]).
    pub fn with_default_rc(
        ocv: OcvCurve,
        cells_series: u32,
        capacity_ah: f64,
        resistance_ohm: f64,
    ) -> Self {
        Self {
            ocv,
            cells_series,
            capacity_ah,
            resistance_ohm,
            rc_resistance_ohm: DEFAULT_RC_RESISTANCE_RATIO * resistance_ohm,
            rc_time_constant_s: DEFAULT_RC_TIME_CONSTANT_S,
        }
    }

    /// Each value in its range.
    ///
    /// # Errors
    /// [`PackError::InvalidValue`] naming the first value out of its range.
    pub fn check(&self) -> Result<(), PackError> {
        let bad = |name, value, unit, expected| Err(invalid(name, value, unit, expected));
        if self.cells_series == 0 {
            return bad("cells_series", 0.0, "", "at least one cell");
        }
        if !(self.capacity_ah.is_finite() && self.capacity_ah > 0.0) {
            return bad(
                "capacity_ah",
                self.capacity_ah,
                "A h",
                "positive and finite",
            );
        }
        for (name, v) in [
            ("resistance_ohm", self.resistance_ohm),
            ("rc_resistance_ohm", self.rc_resistance_ohm),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v, "ohm", "zero or positive, finite");
            }
        }
        let tau = self.rc_time_constant_s;
        if !(tau.is_finite() && tau > 0.0) {
            return bad("rc_time_constant_s", tau, "s", "positive and finite");
        }
        Ok(())
    }

    /// The pack's open-circuit voltage at `soc`, V.
    pub fn ocv_v(&self, soc: f64) -> f64 {
        self.ocv.pack_v(soc, self.cells_series)
    }

    /// The slope of the pack's open-circuit voltage at `soc`, V per unit of charge (a central
    /// difference over one per cent, one-sided at the ends).
    pub fn ocv_slope_v(&self, soc: f64) -> f64 {
        let h = 0.005;
        let (a, b) = ((soc - h).max(0.0), (soc + h).min(1.0));
        if b <= a {
            return 0.0;
        }
        (self.ocv_v(b) - self.ocv_v(a)) / (b - a)
    }
}

/// How sure the filter is of what it is told: standard deviations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterTuning {
    /// The voltage's error against the circuit (the sensor's noise and what the circuit does
    /// not hold), V per cell.
    pub voltage_sd_cell_v: f64,
    /// Least time between two voltage updates, s: the circuit's errors last, and readings
    /// closer than this are not independent evidence.
    pub voltage_interval_s: f64,
    /// The open-circuit curve's offset for this pack, V per cell (prior).
    pub curve_offset_sd_cell_v: f64,
    /// How far the curve's offset wanders as the charge moves (its shape is not the pack's
    /// either), V per cell per 10 % of charge drawn.
    pub curve_shape_sd_cell_v: f64,
    /// The series resistance (prior), as a fraction of it.
    pub resistance_sd: f64,
    /// The RC pair's resistance (prior), as a fraction of it.
    pub rc_resistance_sd: f64,
    /// The series resistance's drift (temperature), fraction per square root of a minute.
    pub resistance_drift: f64,
    /// The capacity, as a fraction: the error of the charge counted is this much of what was
    /// drawn.
    pub capacity_sd: f64,
    /// The current sensor's offset, A.
    pub current_offset_sd_a: f64,
    /// The RC pair's voltage (prior at the start), V per cell.
    pub rc_sd_cell_v: f64,
    /// How far the RC pair's voltage wanders from the model's (what one pair does not hold:
    /// slower diffusion, a pair that is a default), V per cell per square root of a second.
    pub rc_drift_cell_v: f64,
}

impl Default for FilterTuning {
    /// 80 mV a cell between the voltage and the circuit, at most every 2 s (a pack sensor's
    /// readings scatter by 0.1 V at rest on the shared 3S PX4 flights, and one RC pair's sag errs
    /// by more: with 50 mV once a second the band held simulated packs drawn from these priors
    /// 80 % of the time, with these 88 %), 30 mV a cell for a generic curve's offset and 20 mV a cell per
    /// 10 % of charge for its shape, the resistance within 60 %, drifting 2 % a minute, the RC
    /// pair's within 80 % and its voltage wandering 50 mV a cell per square root of a second,
    /// the capacity within 3 %, the current sensor within 0.3 A.
    ///
    /// The drift of the RC pair's voltage is what the flights asked: one pair of 30 s does not
    /// hold a LiPo's polarisation over a flight, and where its voltage may not wander the filter
    /// reads the rest of the sag as charge drawn. On the five shared PX4 flights, started from
    /// their rested voltage, the worst error in the air against that voltage less the charge
    /// counted (docs/validation.md) was 0.3-3.9 points with 10 mV and a resistance within 30 %,
    /// 0.1-1.2 points with these; the simulated packs of the tests hold either.
    fn default() -> Self {
        Self {
            voltage_sd_cell_v: 0.08,
            voltage_interval_s: 2.0,
            curve_offset_sd_cell_v: 0.03,
            curve_shape_sd_cell_v: 0.03,
            resistance_sd: 0.6,
            rc_resistance_sd: 0.8,
            resistance_drift: 0.02,
            capacity_sd: 0.03,
            current_offset_sd_a: 0.3,
            rc_sd_cell_v: 0.02,
            rc_drift_cell_v: 0.05,
        }
    }
}

/// What kind of state of charge another estimator reports, and so how much it is believed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReportKind {
    /// A smart pack's own gauge (coulomb counting from its own full charge): 3 % (one sd).
    Gauge,
    /// An autopilot's count of the charge drawn from a pack assumed full, or a report whose
    /// origin is not known: 10 %.
    Counted,
    /// Derived from the voltage (PX4 without a capacity, ArduPilot's voltage-only monitors):
    /// the voltage the filter already reads through the circuit, so it adds nothing where the
    /// filter has a voltage; without one, 20 %.
    Voltage,
}

impl ReportKind {
    /// The report's standard deviation, state of charge (0-1).
    pub fn sd(self) -> f64 {
        match self {
            ReportKind::Gauge => 0.03,
            ReportKind::Counted => 0.10,
            ReportKind::Voltage => 0.20,
        }
    }
}

/// The state of charge's band: the 5th and 95th percentiles, 0-1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SocEstimate {
    /// The estimate (the filter's mean, clamped to 0-1).
    pub soc: f64,
    /// 5th percentile.
    pub p5: f64,
    /// 95th percentile.
    pub p95: f64,
}

/// The extended Kalman filter over `[s, v_1, R_0, b]` (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SocFilter {
    circuit: Circuit,
    tuning: FilterTuning,
    x: Vect,
    p: Mat,
    /// Charge drawn since the start, fraction of the capacity, and time counted, s: the
    /// systematic errors' scale.
    drawn: f64,
    counted_s: f64,
    /// Time since the last voltage update, s.
    since_voltage_s: f64,
}

/// A rested voltage's error, V per cell: the median of a pack sensor's readings over seconds at
/// rest (they scatter by 0.1 V on a 3S pack, and the median of 50 of them by a tenth of that).
pub const REST_VOLTAGE_SD_CELL_V: f64 = 0.01;

/// A report further from the estimate than this many standard deviations of their difference
/// is not taken (innovation gating: a glitch, or another pack's estimate).
pub const REPORT_GATE_SD: f64 = 4.0;

/// A voltage further from the circuit's than this many standard deviations is not taken (a
/// damaged record: a KAIST flight logs one 90 V sample on a 49 V pack).
pub const VOLTAGE_GATE_SD: f64 = 6.0;

/// Relinearisations of a voltage update (the iterated extended Kalman filter).
const VOLTAGE_ITERATIONS: usize = 3;

/// Indices of the state.
const S: usize = 0;
const V1: usize = 1;
const R0: usize = 2;
const B: usize = 3;
const R1: usize = 4;

impl SocFilter {
    /// A filter on `circuit`, started at `soc` with standard deviation `soc_sd` (0-1), the RC
    /// pair at rest.
    ///
    /// # Errors
    /// The circuit's values out of range, a start outside 0-1 or a negative or non-finite
    /// standard deviation.
    pub fn new(
        circuit: Circuit,
        tuning: FilterTuning,
        soc: f64,
        soc_sd: f64,
    ) -> Result<Self, PackError> {
        circuit.check()?;
        if !(soc.is_finite() && (0.0..=1.0).contains(&soc)) {
            return Err(invalid("soc", soc, "", "a state of charge from 0 to 1"));
        }
        if !(soc_sd.is_finite() && soc_sd >= 0.0) {
            return Err(invalid("soc_sd", soc_sd, "", "zero or positive, finite"));
        }
        let cells = f64::from(circuit.cells_series);
        let x = Vect::from([
            soc,
            0.0,
            circuit.resistance_ohm,
            0.0,
            circuit.rc_resistance_ohm,
        ]);
        let r_sd = tuning.resistance_sd * circuit.resistance_ohm.max(1e-4);
        let r1_sd = tuning.rc_resistance_sd * circuit.rc_resistance_ohm.max(1e-4);
        let p = Mat::from_diagonal(&Vect::from([
            soc_sd.powi(2),
            (tuning.rc_sd_cell_v * cells).powi(2),
            r_sd.powi(2),
            (tuning.curve_offset_sd_cell_v * cells).powi(2),
            r1_sd.powi(2),
        ]));
        Ok(Self {
            circuit,
            tuning,
            x,
            p,
            drawn: 0.0,
            counted_s: 0.0,
            since_voltage_s: f64::INFINITY,
        })
    }

    /// A filter started from a rested voltage `rested_v` (V, the pack at no load): the state
    /// of charge the open-circuit curve gives it, as sure as the curve's offset allows.
    ///
    /// # Errors
    /// As [`Self::new`]; a rested voltage that is not finite and positive.
    pub fn from_rested_voltage(
        circuit: Circuit,
        tuning: FilterTuning,
        rested_v: f64,
    ) -> Result<Self, PackError> {
        if !(rested_v.is_finite() && rested_v > 0.0) {
            return Err(invalid("rested_v", rested_v, "V", "a positive voltage"));
        }
        let cells = f64::from(circuit.cells_series);
        let soc = circuit.ocv.soc_at(rested_v / cells);
        // The rested voltage is as sure as the curve (its offset) and the sensor: in charge,
        // through the curve's slope there (at least 0.1 V a cell per unit, the plateau).
        let v_sd =
            (tuning.curve_offset_sd_cell_v.powi(2) + REST_VOLTAGE_SD_CELL_V.powi(2)).sqrt() * cells;
        let slope = circuit.ocv_slope_v(soc).max(0.1 * cells);
        let mut f = Self::new(circuit, tuning, soc, (v_sd / slope).min(0.5))?;
        // The start and the curve's offset are one uncertainty at rest: `s = V_oc^-1(V - b)`,
        // so their covariance is `-var(b) / slope`, and the circuit gives the rested voltage
        // back whatever the offset.
        let cov = -f.p[(B, B)] / slope;
        f.p[(S, B)] = cov;
        f.p[(B, S)] = cov;
        Ok(f)
    }

    /// The circuit.
    pub fn circuit(&self) -> &Circuit {
        &self.circuit
    }

    /// The estimate now and its band.
    pub fn band(&self) -> SocEstimate {
        let s = self.x[S];
        let sd = self.p[(S, S)].max(0.0).sqrt();
        SocEstimate {
            soc: s.clamp(0.0, 1.0),
            p5: (s - Z_90 * sd).clamp(0.0, 1.0),
            p95: (s + Z_90 * sd).clamp(0.0, 1.0),
        }
    }

    /// The state of charge's standard deviation.
    pub fn soc_sd(&self) -> f64 {
        self.p[(S, S)].max(0.0).sqrt()
    }

    /// The filter with its state of charge moved `z` standard deviations, and every other state
    /// with it by its covariance (the conditional mean): one draw of the present state, for a
    /// Monte-Carlo flight of the rest on it. A `z` that is not finite changes nothing.
    pub fn drawn(&self, z: f64) -> Self {
        let mut f = self.clone();
        let sd = self.soc_sd();
        if !(z.is_finite() && sd > 0.0) {
            return f;
        }
        f.x += self.p.column(S) * (z / sd);
        f.x[S] = f.x[S].clamp(0.0, 1.0);
        f.keep_resistance_positive();
        f
    }

    /// The state of charge the filter holds (its mean, not clamped).
    pub fn soc(&self) -> f64 {
        self.x[S]
    }

    /// The series resistance the filter has learned, ohm.
    pub fn resistance_ohm(&self) -> f64 {
        self.x[R0]
    }

    /// The RC pair's voltage now, V.
    pub fn rc_voltage_v(&self) -> f64 {
        self.x[V1]
    }

    /// The terminal voltage the circuit gives at current `current_a` (A) now, V.
    pub fn terminal_v(&self, current_a: f64) -> f64 {
        self.circuit.ocv_v(self.x[S]) + self.x[B] - self.x[R0] * current_a - self.x[V1]
    }

    /// Count `current_a` (A, positive discharging) over `dt_s` seconds (ignored where either is
    /// not finite or `dt_s` is not positive).
    pub fn predict(&mut self, dt_s: f64, current_a: f64) {
        if !(dt_s.is_finite() && dt_s > 0.0 && current_a.is_finite()) {
            return;
        }
        let c = &self.circuit;
        let q_as = 3600.0 * c.capacity_ah;
        let a = (-dt_s / c.rc_time_constant_s).exp();
        let ds = current_a * dt_s / q_as;
        self.x[S] -= ds;
        self.x[V1] = a * self.x[V1] + self.x[R1] * (1.0 - a) * current_a;
        let mut f = Mat::identity();
        f[(V1, V1)] = a;
        f[(V1, R1)] = (1.0 - a) * current_a;
        // The systematic errors of the count: variance as it grows.
        let t = &self.tuning;
        let var = |drawn: f64, time_s: f64| {
            (t.capacity_sd * drawn).powi(2) + (t.current_offset_sd_a * time_s / q_as).powi(2)
        };
        let before = var(self.drawn, self.counted_s);
        self.drawn += ds.abs();
        self.counted_s += dt_s;
        self.since_voltage_s += dt_s;
        let q_s = (var(self.drawn, self.counted_s) - before).max(0.0);
        let cells = f64::from(c.cells_series);
        // The RC pair is a default or a fit: its voltage wanders from the model's by up to
        // half of what the pair holds.
        let q_v1 = (t.rc_drift_cell_v * cells).powi(2) * dt_s;
        let q_r = (t.resistance_drift * c.resistance_ohm.max(1e-4)).powi(2) * dt_s / 60.0;
        // The curve's offset wanders as the charge moves along a shape that is not the pack's.
        let q_b = (t.curve_shape_sd_cell_v * cells).powi(2) * ds.abs() / 0.1;
        let q = Mat::from_diagonal(&Vect::from([q_s, q_v1, q_r, q_b, 0.0]));
        self.p = f * self.p * f.transpose() + q;
        self.keep_resistance_positive();
    }

    /// [`Self::predict`] of the state alone, not its covariance: what a flight of the rest on a
    /// draw of the state needs ([`Self::drawn`]), at a fifth of the cost.
    pub fn predict_mean(&mut self, dt_s: f64, current_a: f64) {
        if !(dt_s.is_finite() && dt_s > 0.0 && current_a.is_finite()) {
            return;
        }
        let c = &self.circuit;
        let a = (-dt_s / c.rc_time_constant_s).exp();
        self.x[S] -= current_a * dt_s / (3600.0 * c.capacity_ah);
        self.x[V1] = a * self.x[V1] + self.x[R1] * (1.0 - a) * current_a;
    }

    /// A measured terminal voltage `voltage_v` (V) at current `current_a` (A); ignored where
    /// either is not finite or the voltage is not positive, and within
    /// [`FilterTuning::voltage_interval_s`] of the last one taken.
    pub fn voltage(&mut self, voltage_v: f64, current_a: f64) {
        if !(voltage_v.is_finite() && voltage_v > 0.0 && current_a.is_finite())
            || self.since_voltage_s < self.tuning.voltage_interval_s
        {
            return;
        }
        self.since_voltage_s = 0.0;
        // Iterated: the curve is relinearised at the updated state (an open-circuit curve bends,
        // and a start far off is pulled along the slope where it is, not where it started).
        let sd = self.tuning.voltage_sd_cell_v * f64::from(self.circuit.cells_series);
        let r = sd * sd;
        let x0 = self.x;
        {
            let s = x0[S].clamp(0.0, 1.0);
            let h = Row::from_row_slice(&[self.circuit.ocv_slope_v(s), -1.0, -current_a, 1.0, 0.0]);
            let y = voltage_v - self.terminal_v(current_a);
            if y * y > VOLTAGE_GATE_SD.powi(2) * ((h * self.p * h.transpose())[(0, 0)] + r) {
                return;
            }
        }
        let mut xi = x0;
        let mut gain = None;
        for _ in 0..VOLTAGE_ITERATIONS {
            let s = xi[S].clamp(0.0, 1.0);
            let h = Row::from_row_slice(&[self.circuit.ocv_slope_v(s), -1.0, -current_a, 1.0, 0.0]);
            let predicted = self.circuit.ocv_v(xi[S]) + xi[B] - xi[R0] * current_a - xi[V1];
            let y = voltage_v - predicted - (h * (x0 - xi))[(0, 0)];
            let ph = self.p * h.transpose();
            let sv = (h * ph)[(0, 0)] + r;
            if !(sv.is_finite() && sv > 0.0) {
                return;
            }
            let k = ph / sv;
            xi = x0 + k * y;
            gain = Some((k, h));
        }
        let Some((k, h)) = gain else { return };
        self.take(xi, k, h, r);
    }

    /// A state of charge `soc` (0-1) another estimator reports, believed as `kind` says; not
    /// taken (`false`) where it lies more than [`REPORT_GATE_SD`] standard deviations of the
    /// difference from the estimate, or is not a state of charge.
    pub fn report(&mut self, soc: f64, kind: ReportKind) -> bool {
        if !(soc.is_finite() && (0.0..=1.0).contains(&soc)) {
            return false;
        }
        let r = kind.sd().powi(2);
        let y = soc - self.x[S];
        if y * y > REPORT_GATE_SD.powi(2) * (self.p[(S, S)] + r) {
            return false;
        }
        let h = Row::from_row_slice(&[1.0, 0.0, 0.0, 0.0, 0.0]);
        self.measure(h, y, r);
        true
    }

    /// The Kalman update for a scalar measurement with Jacobian `h`, innovation `y` and
    /// variance `r` (Joseph form, which keeps the covariance symmetric and positive).
    fn measure(&mut self, h: Row, y: f64, r: f64) {
        let ph = self.p * h.transpose();
        let s = (h * ph)[(0, 0)] + r;
        if !(s.is_finite() && s > 0.0) {
            return;
        }
        let k = ph / s;
        self.take(self.x + k * y, k, h, r);
    }

    /// The updated state `x` of a measurement with Jacobian `h` and variance `r` taken with
    /// gain `k`, and its covariance in Joseph form (symmetrised), both where every value is
    /// finite.
    fn take(&mut self, x: Vect, k: Vect, h: Row, r: f64) {
        let i_kh = Mat::identity() - k * h;
        let p = i_kh * self.p * i_kh.transpose() + k * k.transpose() * r;
        if x.iter().chain(p.iter()).all(|v| v.is_finite()) {
            self.x = x;
            self.p = 0.5 * (p + p.transpose());
            self.keep_resistance_positive();
        }
    }

    /// The state within its physical range: the charge within 0-1 (the curve ends there), the
    /// resistances not negative.
    fn keep_resistance_positive(&mut self) {
        self.x[S] = self.x[S].clamp(0.0, 1.0);
        self.x[R0] = self.x[R0].max(0.0);
        self.x[R1] = self.x[R1].max(0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift64*) and Box-Muller normals, for the simulated
    /// pack's noise.
    struct Noise(u64);

    impl Noise {
        fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let r = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
            ((r >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }

        fn normal(&mut self) -> f64 {
            let (u, v) = (self.uniform(), self.uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    /// The simulated pack: 3S, 5 A h, its own resistances, RC time constant and offset from the
    /// generic curve (the filter is given the generic curve, 0.05 ohm and the default RC pair).
    #[derive(Clone, Copy)]
    struct TruePack {
        s: f64,
        v1: f64,
        r0: f64,
        r1: f64,
        tau: f64,
        offset_cell_v: f64,
    }

    const CELLS: u32 = 3;
    const CAP_AH: f64 = 5.0;

    impl TruePack {
        /// 0.04 ohm, an RC pair of 0.03 ohm and 20 s, 30 mV a cell above the generic curve.
        fn mismatched(s: f64) -> Self {
            Self {
                s,
                v1: 0.0,
                r0: 0.04,
                r1: 0.03,
                tau: 20.0,
                offset_cell_v: 0.03,
            }
        }

        /// A pack drawn from the filter's own priors (its default tuning): the resistances
        /// within 30 % and 80 % of the filter's, the time constant 10-60 s, the curve's offset
        /// within 30 mV a cell (one sd), the start within `start_sd` of the filter's.
        fn drawn(noise: &mut Noise, s: f64) -> Self {
            let t = FilterTuning::default();
            Self {
                s,
                v1: 0.0,
                r0: 0.05 * (1.0 + t.resistance_sd * noise.normal()).max(0.2),
                r1: 0.05 * (1.0 + t.rc_resistance_sd * noise.normal()).max(0.05),
                tau: 10.0 + 50.0 * noise.uniform(),
                offset_cell_v: t.curve_offset_sd_cell_v * noise.normal(),
            }
        }

        fn step(&mut self, dt: f64, i: f64) {
            let a = (-dt / self.tau).exp();
            self.s -= i * dt / (3600.0 * CAP_AH);
            self.v1 = a * self.v1 + self.r1 * (1.0 - a) * i;
        }

        fn terminal_v(&self, i: f64) -> f64 {
            let ocv = OcvCurve::typical_lipo();
            ocv.pack_v(self.s, CELLS) + self.offset_cell_v * f64::from(CELLS)
                - self.r0 * i
                - self.v1
        }
    }

    fn circuit() -> Circuit {
        Circuit::with_default_rc(OcvCurve::typical_lipo(), CELLS, CAP_AH, 0.05)
    }

    /// A flight of load steps: hover at 20 A with steps to 35 A and 10 A every 20 s.
    fn load(t: f64) -> f64 {
        match (t / 20.0) as u64 % 4 {
            1 => 35.0,
            3 => 10.0,
            _ => 20.0,
        }
    }

    /// Fly `truth` with the filter started at `start` (sd `start_sd`), 10 Hz, noisy current
    /// (an offset of 0.2 A sd and 0.3 A of noise) and voltage (20 mV a cell), for `seconds`;
    /// the truth and the estimate every second.
    fn fly(
        mut truth: TruePack,
        start: f64,
        start_sd: f64,
        seconds: f64,
        noise: &mut Noise,
    ) -> Vec<(f64, SocEstimate)> {
        let mut f = SocFilter::new(circuit(), FilterTuning::default(), start, start_sd).unwrap();
        let dt = 0.1;
        let mut out = Vec::new();
        let offset_a = 0.2 * noise.normal();
        for k in 0..(seconds / dt) as usize {
            let i = load(k as f64 * dt);
            truth.step(dt, i);
            let i_meas = i + offset_a + 0.3 * noise.normal();
            f.predict(dt, i_meas);
            let v_meas = truth.terminal_v(i) + 0.02 * f64::from(CELLS) * noise.normal();
            f.voltage(v_meas, i_meas);
            if k % 10 == 9 {
                out.push((truth.s, f.band()));
            }
        }
        out
    }

    #[test]
    fn it_converges_from_a_wrong_start() {
        // A pack on the generic curve with the mismatched resistances, the filter started 30
        // points high with a wide band: within 6 points after 3 minutes, and the truth in the
        // band from then on.
        let truth = TruePack {
            offset_cell_v: 0.0,
            ..TruePack::mismatched(0.7)
        };
        let run = fly(truth, 1.0, 0.3, 300.0, &mut Noise(1));
        for (s, e) in &run[180..] {
            assert!((e.soc - s).abs() < 0.06, "truth {s}, estimate {}", e.soc);
            assert!(e.p5 <= *s && *s <= e.p95, "truth {s}, band {e:?}");
        }
    }

    #[test]
    fn load_steps_are_not_read_as_charge_drawn() {
        // Started right on a pack unlike the filter's (resistances, time constant, curve): the
        // estimate stays within 4 points of the truth while the load steps between 10 and
        // 35 A (a sag of 1.5 V on a 12 V pack), for ten minutes.
        let run = fly(TruePack::mismatched(0.8), 0.8, 0.03, 600.0, &mut Noise(2));
        let worst = run
            .iter()
            .map(|(s, e)| (e.soc - s).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.04, "worst {worst}");
    }

    #[test]
    fn the_band_covers_the_truth_nine_times_in_ten() {
        // 40 packs drawn from the filter's priors, started within 10 points (sd) of the truth:
        // every second of their flights.
        let (mut inside, mut all) = (0usize, 0usize);
        let mut noise = Noise(7);
        for k in 0..40 {
            let s0 = 0.55 + 0.01 * f64::from(k);
            let start = (s0 + 0.1 * noise.normal()).clamp(0.0, 1.0);
            let truth = TruePack::drawn(&mut noise, s0);
            for (s, e) in fly(truth, start, 0.1, 400.0, &mut noise) {
                all += 1;
                inside += usize::from(e.p5 <= s && s <= e.p95);
            }
        }
        let share = inside as f64 / all as f64;
        assert!((0.85..=0.97).contains(&share), "covered {share}");
    }

    #[test]
    fn coulomb_counting_alone_matches_the_closed_form() {
        // No voltage: 10 A for 900 s from 90 % on a 5 A h pack is 90 - 50 = 40 %.
        let mut f = SocFilter::new(circuit(), FilterTuning::default(), 0.9, 0.01).unwrap();
        for _ in 0..9000 {
            f.predict(0.1, 10.0);
        }
        assert!((f.band().soc - 0.4).abs() < 1e-9);
        // The count's systematic error: 3 % of the half drawn and 0.3 A over 900 s, with the
        // start's 1 %, in quadrature.
        let sd =
            (0.01f64.powi(2) + (0.03 * 0.5f64).powi(2) + (0.3 * 900.0 / 18000.0f64).powi(2)).sqrt();
        assert!(
            (f.soc_sd() - sd).abs() < 1e-9,
            "{} against {sd}",
            f.soc_sd()
        );
    }

    #[test]
    fn a_rested_voltage_starts_the_filter_on_the_curve() {
        let c = circuit();
        let v = c.ocv_v(0.6);
        let f = SocFilter::from_rested_voltage(c, FilterTuning::default(), v).unwrap();
        assert!((f.band().soc - 0.6).abs() < 1e-9);
        assert!(f.band().p5 < 0.6 && f.band().p95 > 0.6);
        // The circuit at rest gives the rested voltage back.
        assert!((f.terminal_v(0.0) - v).abs() < 1e-9);
    }

    #[test]
    fn the_mean_alone_is_predicted_as_with_the_covariance() {
        let mut a = SocFilter::new(circuit(), FilterTuning::default(), 0.8, 0.05).unwrap();
        let mut b = a.clone();
        for k in 0..100 {
            let i = load(f64::from(k));
            a.predict(0.5, i);
            b.predict_mean(0.5, i);
        }
        assert_eq!(a.x, b.x);
    }

    #[test]
    fn a_draw_moves_the_offset_with_the_charge() {
        // Started from a rested voltage, the charge and the curve's offset are one uncertainty:
        // a draw of the charge moves the offset so that the circuit still gives the rested
        // voltage.
        let c = circuit();
        let v = c.ocv_v(0.8);
        let f = SocFilter::from_rested_voltage(c, FilterTuning::default(), v).unwrap();
        let d = f.drawn(1.0);
        assert!((d.soc() - (0.8 + f.soc_sd())).abs() < 1e-12);
        // Within the curve's bend over the draw (its slope is 0.8 and 1.2 V a cell per unit
        // either side of 80 %): the offset alone moves the voltage by 84 mV.
        assert!(
            (d.terminal_v(0.0) - v).abs() < 0.05,
            "{}",
            d.terminal_v(0.0)
        );
        assert_eq!(f.drawn(f64::NAN), f);
    }

    #[test]
    fn bad_values_are_named() {
        let mut c = circuit();
        c.capacity_ah = -1.0;
        let e = SocFilter::new(c, FilterTuning::default(), 0.5, 0.1).unwrap_err();
        assert!(e.to_string().contains("capacity_ah"), "{e}");
        let e = SocFilter::new(circuit(), FilterTuning::default(), 1.5, 0.1).unwrap_err();
        assert!(e.to_string().contains("soc"), "{e}");
        let e = SocFilter::from_rested_voltage(circuit(), FilterTuning::default(), f64::NAN)
            .unwrap_err();
        assert!(e.to_string().contains("rested_v"), "{e}");
        // Readings that are not numbers change nothing.
        let mut f = SocFilter::new(circuit(), FilterTuning::default(), 0.5, 0.1).unwrap();
        let before = f.clone();
        f.predict(f64::NAN, 10.0);
        f.voltage(f64::INFINITY, 1.0);
        assert!(!f.report(f64::NAN, ReportKind::Gauge));
        assert_eq!(f, before);
        // A report 50 points off a filter sure within 2 points is not taken (beyond 4 sd of
        // their difference, 0.41); one 5 points off is.
        let mut f = SocFilter::new(circuit(), FilterTuning::default(), 0.8, 0.02).unwrap();
        assert!(!f.report(0.3, ReportKind::Counted));
        assert!((f.band().soc - 0.8).abs() < 1e-15);
        assert!(f.report(0.75, ReportKind::Counted));
        assert!(f.band().soc < 0.8);
    }
}
