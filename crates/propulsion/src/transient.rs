//! Rotor transients: first-order rotor dynamics driven by the motor voltage, from the transient
//! seed (`rotor-transient-response.txt`), eqs (1)-(10) and Table 4.
//!
//! Equation of motion, eq (2), with the load torque of eq (1):
//!
//! ```text
//! J_r dw/dt = K_T / R (V - K_E w) - c w^2,        J_r = J_m + J_p   (eq 4)
//! K_T = K_E = (V0 - I0 R) / (K_V V0)                                (eq 3, K_V in rad/(V s))
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `w` | rotor speed | rad/s |
//! | `V` | motor voltage (ESC output), `V0` the supply (nominal) voltage | V |
//! | `R` | motor resistance | ohm |
//! | `I0` | no-load current | A |
//! | `K_T`, `K_E` | torque and back-emf constants | N m/A = V s/rad |
//! | `c` | load-torque coefficient, `tau_l = c w^2` (eq 1) | N m s^2 |
//! | `J_m`, `J_p` | motor and propeller inertia | kg m^2 |
//!
//! Time constants: the seed's eq (7) `tau = J R / (K_T^2 + c R w)`; linearising eq (2) about a
//! steady speed `w` gives `tau_lin = J R / (K_T^2 + 2 c R w)` (the derivative of `c w^2` is
//! `2 c w`). Eq (8) gives the rise time `2.2 tau`. The seed's eq (7) has `c w` where the
//! linearisation has `2 c w`, so it over-estimates the time constant when the propeller load is
//! significant; the truth for rise and settling time here is the fixed-step RK4 simulation of
//! eq (2) ([`RotorTransient::simulate_step`]), with the time constants reported beside it.
//!
//! Current, eq (5): `I = (V / V_in) (tau K_V V0 / (V0 - I0 R) + I0) = (V / V_in)(tau / K_T + I0)`,
//! the supply-side current when the ESC applies `V` out of `V_in`.
//!
//! # Deviation
//! Eq (5) is written with the load torque; during a transient this crate uses the motor's
//! electromagnetic torque `K_T (V - K_E w) / R` from eq (2), which equals the load torque
//! `c w^2` at steady state (where the seed validates it).
//!
//! ESC protocols (Table 4) are modelled as a pure delay added before the voltage step, equal to
//! the protocol's mean settling time (mean over the table's three steps) minus that of the fastest
//! protocol, dshot150. The seed itself assumes the ESC "only provides a time delay at the start of
//! the response" (section 4.2).

use crate::error::{kv, mass, non_negative, positive, resistance, voltage, PropulsionError};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Eq (9) constants `A1, A2, A3` (transient seed, section 4.2).
pub const EQ9_A: [f64; 3] = [1.77e-5, -0.098, 2.71];
/// Eq (10) constants `B1, B2` (transient seed, section 4.2).
pub const EQ10_B: [f64; 2] = [0.135, 0.012];
/// Unit factor applied to eq (9): see [`motor_inertia_kgm2`].
pub const EQ9_TO_KGM2: f64 = 1e-3;
/// Settling band used for the settling time: 2 % of the step size.
pub const SETTLING_BAND: f64 = 0.02;

/// Eq (3): `K_T = K_E = (V0 - I0 R) / (K_V V0)` with `K_V` converted from rpm/V to rad/(V s).
///
/// # Errors
/// Invalid Kv, voltage, resistance or current, or `I0 R >= V0`.
pub fn kt_from_kv(
    kv_rpm_per_v: f64,
    nominal_voltage_v: f64,
    no_load_current_a: f64,
    resistance_ohm: f64,
) -> Result<f64, PropulsionError> {
    let kv_rpm_per_v = kv(kv_rpm_per_v)?;
    let v0 = voltage("voltage_v", nominal_voltage_v)?;
    let i0 = non_negative("no_load_current_a", no_load_current_a, "A")?;
    let r = resistance("motor_resistance_ohm", resistance_ohm)?;
    if i0 * r >= v0 {
        return Err(aloft_core::InvalidParameter {
            name: "no_load_current_a",
            value: i0,
            unit: "A",
            expected: "I0 R below the nominal voltage (eq 3)",
        }
        .into());
    }
    let kv_si = kv_rpm_per_v * 2.0 * PI / 60.0;
    Ok((v0 - i0 * r) / (kv_si * v0))
}

/// Motor inertia from mass and outer diameter, eq (9): `J_m = A1 + A2 m d^2 + A3 m d`.
///
/// # Unit reading
/// With `m` in kg and `d` in m, eq (9) returns about `1.1e-3` for the 18 g, 23 mm MN1806. Read as
/// kg m^2 that is ~480 times the thin-ring upper bound `m (d/2)^2 = 2.4e-6 kg m^2` (no part of a
/// motor can be farther out than its case), so that reading is unphysical. Reading the result in
/// g m^2 (i.e. multiplying by 1e-3, [`EQ9_TO_KGM2`]) gives `1.1e-6 kg m^2`, 0.29-0.48 of the ring
/// bound for every motor of the seed's Table 2, which is what an outrunner whose rotating bell
/// and magnets are a third to a half of its mass should give. Other readings (grams, millimetres,
/// kg cm^2) give either negative values, values above the bound, or under a tenth of it.
///
/// | symbol | meaning | unit here |
/// |---|---|---|
/// | `m` | motor mass | kg |
/// | `d` | motor outer diameter | m |
///
/// # Errors
/// Non-positive mass or diameter, or a non-positive result (outside the fit's range).
pub fn motor_inertia_kgm2(mass_kg: f64, diameter_m: f64) -> Result<f64, PropulsionError> {
    let m = mass("motor_mass", mass_kg)?;
    let d = positive("motor_diameter", diameter_m, "m")?;
    let j = EQ9_TO_KGM2 * (EQ9_A[0] + EQ9_A[1] * m * d * d + EQ9_A[2] * m * d);
    let expected = "a motor within the range of the eq (9) fit (positive inertia)";
    aloft_core::parameter("motor_diameter", diameter_m, "m", j > 0.0, expected)?;
    Ok(j)
}

/// Propeller inertia from mass and diameter, eq (10): `J_p = B1 m d^2 - B2 m d`, SI (kg, m,
/// kg m^2), consistent as printed.
///
/// The fit is positive only for `d > B2 / B1 = 0.089 m` (3.5 in); smaller propellers are outside
/// the fit's range (the seed's smallest is 4 in).
///
/// # Errors
/// Non-positive mass or diameter, or a diameter below 0.089 m.
pub fn prop_inertia_kgm2(mass_kg: f64, diameter_m: f64) -> Result<f64, PropulsionError> {
    let m = mass("prop_mass", mass_kg)?;
    let d = positive("prop_diameter", diameter_m, "m")?;
    let j = EQ10_B[0] * m * d * d - EQ10_B[1] * m * d;
    let expected = "a propeller larger than 0.089 m (3.5 in), the range of the eq (10) fit";
    aloft_core::parameter("prop_diameter", diameter_m, "m", j > 0.0, expected)?;
    Ok(j)
}

/// ESC command protocols of the transient seed's Table 4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EscProtocol {
    /// DShot150.
    Dshot150,
    /// DShot300.
    Dshot300,
    /// OneShot42.
    Oneshot42,
    /// OneShot125.
    Oneshot125,
    /// MultiShot.
    Multishot,
    /// PWM at 50 Hz.
    Pwm50,
    /// PWM at 500 Hz.
    Pwm500,
}

impl EscProtocol {
    /// All protocols of Table 4.
    pub const ALL: [EscProtocol; 7] = [
        EscProtocol::Dshot150,
        EscProtocol::Dshot300,
        EscProtocol::Oneshot42,
        EscProtocol::Oneshot125,
        EscProtocol::Multishot,
        EscProtocol::Pwm50,
        EscProtocol::Pwm500,
    ];

    /// Table 4: mean settling time of the MN1806 + T-Motor 6x2 rotor for steps 1-3, ms.
    pub fn table4_settling_ms(self) -> [f64; 3] {
        match self {
            EscProtocol::Dshot150 => [101.0, 98.8, 98.0],
            EscProtocol::Dshot300 => [105.0, 103.0, 99.8],
            EscProtocol::Oneshot42 => [103.0, 101.0, 104.0],
            EscProtocol::Oneshot125 => [104.0, 99.0, 99.4],
            EscProtocol::Multishot => [104.0, 102.0, 100.0],
            EscProtocol::Pwm50 => [114.0, 113.0, 112.0],
            EscProtocol::Pwm500 => [108.0, 102.0, 100.0],
        }
    }

    fn mean_ms(self) -> f64 {
        self.table4_settling_ms().iter().sum::<f64>() / 3.0
    }

    /// Added delay, s: the protocol's Table 4 mean settling time minus dshot150's (the fastest).
    /// dshot150 itself is 0; PWM 50 Hz is 13.7 ms.
    pub fn added_delay_s(self) -> f64 {
        let fastest = EscProtocol::ALL
            .iter()
            .map(|p| p.mean_ms())
            .fold(f64::INFINITY, f64::min);
        (self.mean_ms() - fastest) * 1e-3
    }

    /// The lowercase name (`dshot300`, `pwm50`, ...).
    pub fn name(self) -> &'static str {
        match self {
            EscProtocol::Dshot150 => "dshot150",
            EscProtocol::Dshot300 => "dshot300",
            EscProtocol::Oneshot42 => "oneshot42",
            EscProtocol::Oneshot125 => "oneshot125",
            EscProtocol::Multishot => "multishot",
            EscProtocol::Pwm50 => "pwm50",
            EscProtocol::Pwm500 => "pwm500",
        }
    }
}

impl std::str::FromStr for EscProtocol {
    type Err = PropulsionError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.to_ascii_lowercase().replace(['_', '-', ' '], "");
        let t = t.strip_suffix("hz").unwrap_or(&t);
        EscProtocol::ALL
            .iter()
            .copied()
            .find(|p| p.name() == t)
            .ok_or_else(|| PropulsionError::UnknownProtocol {
                protocol: s.to_string(),
            })
    }
}

impl std::fmt::Display for EscProtocol {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A rotor (motor + propeller + ESC) for transient analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotorTransient {
    c: RotorConstants,
}

/// The constants of a rotor for transient analysis, as [`RotorTransient::new`] checks them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotorConstants {
    /// Torque constant `K_T = K_E`, eq (3), N m/A.
    pub kt_nm_per_a: f64,
    /// Motor resistance `R`, ohm (positive: eq 2 divides by it).
    pub resistance_ohm: f64,
    /// No-load current `I0`, A.
    pub no_load_current_a: f64,
    /// Supply voltage, V.
    pub supply_voltage_v: f64,
    /// Motor inertia `J_m`, kg m^2.
    pub motor_inertia_kgm2: f64,
    /// Propeller inertia `J_p`, kg m^2.
    pub prop_inertia_kgm2: f64,
    /// Load-torque coefficient `c` of `tau = c w^2`, N m s^2.
    pub torque_coefficient_nms2: f64,
    /// Delay of the ESC protocol, s.
    pub delay_s: f64,
}

/// Metrics of a simulated step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepMetrics {
    /// 10-90 % rise time, s (from the simulation, delay excluded).
    pub rise_time_s: f64,
    /// Time from the command until the speed stays within 2 % of the step of its final value, s
    /// (ESC delay included).
    pub settling_time_s: f64,
    /// Largest speed overshoot beyond the final value, rad/s (0 for a first-order system).
    pub overshoot_radps: f64,
}

/// A simulated step response, sampled at every RK4 step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepResponse {
    /// Time since the command, s.
    pub time_s: Vec<f64>,
    /// Rotor speed, rad/s.
    pub speed_radps: Vec<f64>,
    /// Supply-side current, eq (5), A.
    pub current_a: Vec<f64>,
    /// Metrics of the response.
    pub metrics: StepMetrics,
}

/// Summary of a rotor's transient behaviour (the JSON contract of `aloft rotor`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RotorTransientResult {
    /// Motor inertia, eq (9) in the unit reading documented at [`motor_inertia_kgm2`], kg m^2.
    pub motor_inertia_kgm2: f64,
    /// Propeller inertia, eq (10), kg m^2.
    pub prop_inertia_kgm2: f64,
    /// Seed's time constant, eq (7), at the final speed, s.
    pub time_constant_s: f64,
    /// 10-90 % rise time from the RK4 simulation, s.
    pub rise_time_s: f64,
    /// 2 % settling time from the RK4 simulation, including the protocol delay, s.
    pub settling_time_s: f64,
    /// Steady supply current at the final speed, eq (5), A.
    pub steady_current_a: f64,
    /// Linearised time constant `J R / (K_T^2 + 2 c R w)` at the final speed, s.
    pub linearised_time_constant_s: f64,
    /// Rise time from eq (8), `2.2 tau` with the seed's eq (7) time constant, s.
    pub rise_time_eq8_s: f64,
    /// Delay added for the ESC protocol, s.
    pub protocol_delay_s: f64,
    /// `K_T = K_E`, eq (3), N m/A.
    pub kt_nm_per_a: f64,
    /// Speed before the step, rad/s.
    pub step_from_radps: f64,
    /// Speed after the step, rad/s.
    pub step_to_radps: f64,
    /// Motor voltage before the step, V.
    pub step_from_voltage_v: f64,
    /// Motor voltage after the step, V.
    pub step_to_voltage_v: f64,
    /// Settling band as a fraction of the step (0.02).
    pub settling_band_fraction: f64,
}

impl RotorTransient {
    /// A rotor from its constants.
    ///
    /// # Errors
    /// Non-finite or non-positive constants (zero resistance is rejected: eq 2 divides by `R`),
    /// a negative load coefficient or delay.
    pub fn new(c: RotorConstants) -> Result<Self, PropulsionError> {
        let resistance_ohm = resistance("motor_resistance_ohm", c.resistance_ohm)?;
        if resistance_ohm <= 0.0 {
            return Err(PropulsionError::InvalidResistance {
                name: "motor_resistance_ohm (eq 2 needs R > 0)",
                resistance_ohm,
            });
        }
        let c = RotorConstants {
            kt_nm_per_a: positive("kt_nm_per_a", c.kt_nm_per_a, "N m/A")?,
            resistance_ohm,
            no_load_current_a: non_negative("no_load_current_a", c.no_load_current_a, "A")?,
            supply_voltage_v: voltage("voltage_v", c.supply_voltage_v)?,
            motor_inertia_kgm2: positive("motor_inertia_kgm2", c.motor_inertia_kgm2, "kg m^2")?,
            prop_inertia_kgm2: non_negative("prop_inertia_kgm2", c.prop_inertia_kgm2, "kg m^2")?,
            torque_coefficient_nms2: non_negative(
                "torque_coefficient_nms2",
                c.torque_coefficient_nms2,
                "N m s^2",
            )?,
            delay_s: non_negative("protocol delay_s", c.delay_s, "s")?,
        };
        Ok(Self { c })
    }

    /// Total inertia `J_m + J_p` (eq 4), kg m^2.
    pub fn inertia_kgm2(&self) -> f64 {
        self.c.motor_inertia_kgm2 + self.c.prop_inertia_kgm2
    }

    /// Returns a copy with another total-inertia split (used by the inertia fit): the propeller
    /// share is set to `prop_inertia_kgm2`.
    pub fn with_prop_inertia(mut self, prop_inertia_kgm2: f64) -> Self {
        self.c.prop_inertia_kgm2 = prop_inertia_kgm2.max(0.0);
        self
    }

    /// Returns a copy with total inertia `inertia_kgm2`, keeping the motor/propeller ratio
    /// (used by the inertia fit).
    pub fn with_total_inertia(mut self, inertia_kgm2: f64) -> Self {
        let scale = inertia_kgm2 / self.inertia_kgm2();
        if scale.is_finite() && scale > 0.0 {
            self.c.motor_inertia_kgm2 *= scale;
            self.c.prop_inertia_kgm2 *= scale;
        }
        self
    }

    /// Motor resistance `R`, ohm.
    pub fn resistance_ohm(&self) -> f64 {
        self.c.resistance_ohm
    }

    /// Load-torque coefficient `c`, N m s^2.
    pub fn torque_coefficient_nms2(&self) -> f64 {
        self.c.torque_coefficient_nms2
    }

    /// Returns a copy with another ESC delay, s.
    pub fn with_delay(mut self, delay_s: f64) -> Self {
        self.c.delay_s = delay_s.max(0.0);
        self
    }

    /// `K_T = K_E`, N m/A.
    pub fn kt_nm_per_a(&self) -> f64 {
        self.c.kt_nm_per_a
    }

    /// Motor inertia, kg m^2.
    pub fn motor_inertia_kgm2(&self) -> f64 {
        self.c.motor_inertia_kgm2
    }

    /// Propeller inertia, kg m^2.
    pub fn prop_inertia_kgm2(&self) -> f64 {
        self.c.prop_inertia_kgm2
    }

    /// ESC delay, s.
    pub fn delay_s(&self) -> f64 {
        self.c.delay_s
    }

    /// Seed eq (7): `J R / (K_T^2 + c R w)`, s.
    pub fn time_constant_eq7_s(&self, speed_radps: f64) -> f64 {
        self.inertia_kgm2() * self.c.resistance_ohm
            / (self.c.kt_nm_per_a.powi(2)
                + self.c.torque_coefficient_nms2 * self.c.resistance_ohm * speed_radps)
    }

    /// Linearised eq (2): `J R / (K_T^2 + 2 c R w)`, s.
    pub fn time_constant_linearised_s(&self, speed_radps: f64) -> f64 {
        self.inertia_kgm2() * self.c.resistance_ohm
            / (self.c.kt_nm_per_a.powi(2)
                + 2.0 * self.c.torque_coefficient_nms2 * self.c.resistance_ohm * speed_radps)
    }

    /// Motor voltage that holds `speed_radps` steady: `K_E w + c w^2 R / K_T`, V.
    pub fn equilibrium_voltage_v(&self, speed_radps: f64) -> f64 {
        self.c.kt_nm_per_a * speed_radps
            + self.c.torque_coefficient_nms2 * speed_radps * speed_radps * self.c.resistance_ohm
                / self.c.kt_nm_per_a
    }

    /// Steady speed at motor voltage `voltage_v`, rad/s (positive root of eq 2 at rest).
    pub fn steady_speed_radps(&self, voltage_v: f64) -> f64 {
        let k = self.c.kt_nm_per_a;
        let r = self.c.resistance_ohm;
        let c = self.c.torque_coefficient_nms2;
        if c <= 0.0 {
            return voltage_v / k;
        }
        let b = k * k / r;
        let q = k * voltage_v / r;
        // c w^2 + b w - q = 0, stable form of the positive root
        2.0 * q / (b + (b * b + 4.0 * c * q).sqrt())
    }

    /// Supply-side current at motor voltage `voltage_v` and speed `w`, eq (5) with the
    /// electromagnetic torque (see the module's Deviation), A.
    pub fn current_a(&self, voltage_v: f64, w: f64) -> f64 {
        let torque =
            self.c.kt_nm_per_a / self.c.resistance_ohm * (voltage_v - self.c.kt_nm_per_a * w);
        voltage_v / self.c.supply_voltage_v
            * (torque / self.c.kt_nm_per_a + self.c.no_load_current_a)
    }

    /// Steady supply current at speed `w`, eq (5) with `tau_l = c w^2`, A.
    pub fn steady_current_a(&self, w: f64) -> f64 {
        let v = self.equilibrium_voltage_v(w);
        v / self.c.supply_voltage_v
            * (self.c.torque_coefficient_nms2 * w * w / self.c.kt_nm_per_a
                + self.c.no_load_current_a)
    }

    fn check_step(&self, from_radps: f64, to_radps: f64) -> Result<(f64, f64), PropulsionError> {
        let from = non_negative("step_from_radps", from_radps, "rad/s")?;
        let to = non_negative("step_to_radps", to_radps, "rad/s")?;
        let w_max = self.steady_speed_radps(self.c.supply_voltage_v);
        for (name, w) in [("step_from_radps", from), ("step_to_radps", to)] {
            if w > w_max {
                return Err(aloft_core::InvalidParameter {
                    name,
                    value: w,
                    unit: "rad/s",
                    expected: "a speed the supply voltage can hold (at most the full-voltage steady speed)",
                }.into());
            }
        }
        // Steps smaller than 1e-6 of the top speed have no meaningful rise time.
        if (to - from).abs() <= 1e-6 * w_max {
            return Err(aloft_core::InvalidParameter {
                name: "step_to_radps",
                value: to,
                unit: "rad/s",
                expected: "a speed different from step_from_radps",
            }
            .into());
        }
        Ok((from, to))
    }

    /// Fixed-step RK4 simulation of eq (2) for a voltage step from the voltage that holds
    /// `from_radps` to the one that holds `to_radps`, applied after the ESC delay; metrics only
    /// (no allocation). This is the benched `propulsion/step_response` path.
    ///
    /// # Errors
    /// Invalid or unreachable speeds, non-positive duration or step, a response that has not
    /// settled by the end of the simulation.
    pub fn simulate_step_metrics(
        &self,
        from_radps: f64,
        to_radps: f64,
        duration_s: f64,
        dt_s: f64,
    ) -> Result<StepMetrics, PropulsionError> {
        self.run(from_radps, to_radps, duration_s, dt_s, |_, _, _| {})
    }

    /// As [`Self::simulate_step_metrics`], also returning the sampled speed and current.
    ///
    /// # Errors
    /// As [`Self::simulate_step_metrics`].
    pub fn simulate_step(
        &self,
        from_radps: f64,
        to_radps: f64,
        duration_s: f64,
        dt_s: f64,
    ) -> Result<StepResponse, PropulsionError> {
        let mut time_s = Vec::new();
        let mut speed_radps = Vec::new();
        let mut current_a = Vec::new();
        let metrics = self.run(from_radps, to_radps, duration_s, dt_s, |t, w, i| {
            time_s.push(t);
            speed_radps.push(w);
            current_a.push(i);
        })?;
        Ok(StepResponse {
            time_s,
            speed_radps,
            current_a,
            metrics,
        })
    }

    fn run(
        &self,
        from_radps: f64,
        to_radps: f64,
        duration_s: f64,
        dt_s: f64,
        mut sample: impl FnMut(f64, f64, f64),
    ) -> Result<StepMetrics, PropulsionError> {
        let (from, to) = self.check_step(from_radps, to_radps)?;
        let duration_s = positive("duration_s", duration_s, "s")?;
        let dt_s = positive("dt_s", dt_s, "s")?;
        let steps = (duration_s / dt_s).ceil();
        // `steps` is positive (NaN cannot reach here): `<=` is the negation of `>`.
        let expected = "at most 1e8 steps per simulation";
        aloft_core::parameter("dt_s", dt_s, "s", steps <= 1e8, expected)?;
        let steps = steps as usize;
        let v0 = self.equilibrium_voltage_v(from);
        let v1 = self.equilibrium_voltage_v(to);
        let dw = to - from;
        let band = SETTLING_BAND * dw.abs();
        let (w10, w90) = (from + 0.1 * dw, from + 0.9 * dw);
        let sign = dw.signum();
        let j = self.inertia_kgm2();
        let ka = self.c.kt_nm_per_a / (self.c.resistance_ohm * j);
        let kb = self.c.kt_nm_per_a * self.c.kt_nm_per_a / (self.c.resistance_ohm * j);
        let kg = self.c.torque_coefficient_nms2 / j;
        let mut w = from;
        let mut t = 0.0;
        let mut t10 = f64::NAN;
        let mut t90 = f64::NAN;
        let mut last_outside = 0.0;
        let mut overshoot: f64 = 0.0;
        sample(t, w, self.current_a(v0, w));
        for k in 0..steps {
            let t_next = (k + 1) as f64 * dt_s;
            // Voltage is piecewise constant; the switch is placed on the step grid.
            let v = if t + 0.5 * dt_s >= self.c.delay_s {
                v1
            } else {
                v0
            };
            let h = dt_s;
            // eq (2) divided by J: dw/dt = a V - b w - g w^2 (constants hoisted out of the loop)
            let av = ka * v;
            let f = |w: f64| av - kb * w - kg * w * w;
            let k1 = f(w);
            let k2 = f(w + 0.5 * h * k1);
            let k3 = f(w + 0.5 * h * k2);
            let k4 = f(w + h * k3);
            let w_next = w + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            // Interpolated threshold crossings.
            if t10.is_nan() && sign * (w_next - w10) >= 0.0 {
                t10 = t + h * (w10 - w) / (w_next - w);
            }
            if t90.is_nan() && sign * (w_next - w90) >= 0.0 {
                t90 = t + h * (w90 - w) / (w_next - w);
            }
            if (w_next - to).abs() > band {
                last_outside = t_next;
            }
            overshoot = overshoot.max(sign * (w_next - to));
            w = w_next;
            t = t_next;
            sample(t, w, self.current_a(v, w));
        }
        if t90.is_nan() || last_outside >= t {
            return Err(PropulsionError::NotSettled { duration_s: t });
        }
        Ok(StepMetrics {
            rise_time_s: t90 - t10,
            settling_time_s: last_outside,
            overshoot_radps: overshoot,
        })
    }

    /// Full summary for a step: inertias, time constants, simulated rise and settling time,
    /// steady current. Simulates `max(0.5 s, delay + 20 tau)` at `min(0.1 ms, tau / 50)` steps.
    ///
    /// # Errors
    /// As [`Self::simulate_step_metrics`].
    pub fn summary(
        &self,
        from_radps: f64,
        to_radps: f64,
    ) -> Result<RotorTransientResult, PropulsionError> {
        let (from, to) = self.check_step(from_radps, to_radps)?;
        let tau = self
            .time_constant_eq7_s(to)
            .max(self.time_constant_eq7_s(from))
            .max(self.time_constant_linearised_s(from.min(to)));
        let duration = (self.c.delay_s + 20.0 * tau).max(0.5);
        let dt = (tau / 50.0).min(1e-4);
        let m = self.simulate_step_metrics(from, to, duration, dt)?;
        let tau7 = self.time_constant_eq7_s(to);
        Ok(RotorTransientResult {
            motor_inertia_kgm2: self.c.motor_inertia_kgm2,
            prop_inertia_kgm2: self.c.prop_inertia_kgm2,
            time_constant_s: tau7,
            rise_time_s: m.rise_time_s,
            settling_time_s: m.settling_time_s,
            steady_current_a: self.steady_current_a(to),
            linearised_time_constant_s: self.time_constant_linearised_s(to),
            rise_time_eq8_s: 2.2 * tau7,
            protocol_delay_s: self.c.delay_s,
            kt_nm_per_a: self.c.kt_nm_per_a,
            step_from_radps: from,
            step_to_radps: to,
            step_from_voltage_v: self.equilibrium_voltage_v(from),
            step_to_voltage_v: self.equilibrium_voltage_v(to),
            settling_band_fraction: SETTLING_BAND,
        })
    }

    /// Steady speed at the full supply voltage, rad/s.
    pub fn full_voltage_speed_radps(&self) -> f64 {
        self.steady_speed_radps(self.c.supply_voltage_v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rotor(c: f64) -> RotorTransient {
        RotorTransient::new(RotorConstants {
            kt_nm_per_a: 4e-3,
            resistance_ohm: 0.1,
            no_load_current_a: 0.4,
            supply_voltage_v: 11.1,
            motor_inertia_kgm2: 1e-6,
            prop_inertia_kgm2: 2e-6,
            torque_coefficient_nms2: c,
            delay_s: 0.0,
        })
        .unwrap()
    }

    #[test]
    fn rk4_matches_the_exact_first_order_response_without_load() {
        // With c = 0, eq (2) is linear: w(t) = to + (from - to) exp(-t/tau), tau = J R / K_T^2.
        // 10-90 % rise time ln(9) tau, 2 % settling time ln(50) tau.
        let r = rotor(0.0);
        let tau = r.time_constant_eq7_s(0.0);
        let m = r.simulate_step_metrics(200.0, 1200.0, 0.5, 1e-5).unwrap();
        // RK4 at dt = tau/1875 plus linear interpolation of crossings: error << 0.1 %; the
        // settling time is quantised to one step (1e-5 s of ~0.074 s).
        assert!((m.rise_time_s / (9f64.ln() * tau) - 1.0).abs() < 1e-3);
        assert!((m.settling_time_s - 50f64.ln() * tau).abs() < 2e-5);
        assert!(m.overshoot_radps < 1e-6);
    }

    #[test]
    fn linearised_time_constant_governs_small_steps() {
        // For a small step about w, the response is first order with the linearised constant
        // (2 c w), not the seed's eq (7) (c w).
        let r = rotor(2e-8);
        let w = 1500.0;
        let m = r.simulate_step_metrics(w - 5.0, w, 0.5, 1e-5).unwrap();
        let tau_lin = r.time_constant_linearised_s(w);
        let tau7 = r.time_constant_eq7_s(w);
        // a 5 rad/s step changes 2 c w by 0.3 %: 1 % tolerance
        assert!((m.rise_time_s / (9f64.ln() * tau_lin) - 1.0).abs() < 0.01);
        assert!((m.rise_time_s / (9f64.ln() * tau7) - 1.0).abs() > 0.05);
    }

    #[test]
    fn steady_state_is_consistent() {
        let r = rotor(2e-8);
        let w = r.steady_speed_radps(8.0);
        assert!((r.equilibrium_voltage_v(w) - 8.0).abs() < 1e-9);
        assert!((r.current_a(8.0, w) - r.steady_current_a(w)).abs() < 1e-9);
    }

    #[test]
    fn eq3_reduces_to_si_kt_without_losses() {
        let kt = kt_from_kv(1000.0, 10.0, 0.0, 0.1).unwrap();
        assert!((kt - 60.0 / (2.0 * PI * 1000.0)).abs() < 1e-15);
        assert!(matches!(
            kt_from_kv(0.0, 10.0, 0.0, 0.1),
            Err(PropulsionError::InvalidKv { .. })
        ));
        assert!(matches!(
            kt_from_kv(1000.0, -1.0, 0.0, 0.1),
            Err(PropulsionError::InvalidVoltage { .. })
        ));
        assert!(kt_from_kv(1000.0, 1.0, 20.0, 0.1).is_err());
    }

    #[test]
    fn protocols_parse_and_delay() {
        assert_eq!(
            "dshot300".parse::<EscProtocol>().unwrap(),
            EscProtocol::Dshot300
        );
        assert_eq!(
            "PWM50Hz".parse::<EscProtocol>().unwrap(),
            EscProtocol::Pwm50
        );
        assert!("dshot1200".parse::<EscProtocol>().is_err());
        assert!(EscProtocol::Dshot150.added_delay_s().abs() < 1e-15);
        // (114 + 113 + 112)/3 - (101 + 98.8 + 98)/3 = 13.73 ms
        assert!((EscProtocol::Pwm50.added_delay_s() - 0.013_733).abs() < 1e-6);
    }

    #[test]
    fn unreachable_or_bad_steps_are_errors() {
        let r = rotor(2e-8);
        let top = r.full_voltage_speed_radps();
        assert!(r.summary(0.0, top * 1.01).is_err());
        assert!(r.summary(100.0, 100.0).is_err());
        assert!(r.summary(-1.0, 100.0).is_err());
        assert!(matches!(
            r.simulate_step_metrics(0.0, top * 0.9, 0.001, 1e-4),
            Err(PropulsionError::NotSettled { .. })
        ));
    }
}
