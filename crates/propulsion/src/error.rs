//! The one error type of the crate.

use thiserror::Error;

/// Everything that can go wrong when building or evaluating a propulsion model.
///
/// Every variant carries the offending value together with its unit, so that a caller can
/// print it without knowing the model.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum PropulsionError {
    /// A motor velocity constant that is zero, negative or not finite.
    #[error("motor Kv must be a positive finite number up to 1e5 rpm/V, got {} rpm/V", aloft_core::Num::of(.kv_rpm_per_v))]
    InvalidKv {
        /// The rejected value, rpm/V.
        kv_rpm_per_v: f64,
    },
    /// A mass that is zero, negative or not finite.
    #[error("{name} must be a positive finite mass up to 10000 kg, got {} kg", aloft_core::Num::of(.mass_kg))]
    InvalidMass {
        /// Which mass (e.g. `empty_mass_kg`).
        name: &'static str,
        /// The rejected value, kg.
        mass_kg: f64,
    },
    /// A voltage that is zero, negative or not finite.
    #[error("{name} must be a positive finite voltage up to 10000 V, got {} V", aloft_core::Num::of(.voltage_v))]
    InvalidVoltage {
        /// Which voltage.
        name: &'static str,
        /// The rejected value, V.
        voltage_v: f64,
    },
    /// A resistance that is negative or not finite.
    #[error(
        "{name} must be a non-negative finite resistance up to 1000 ohm, got {} ohm", aloft_core::Num::of(.resistance_ohm)
    )]
    InvalidResistance {
        /// Which resistance.
        name: &'static str,
        /// The rejected value, ohm.
        resistance_ohm: f64,
    },
    /// Any other parameter outside its valid range.
    #[error(transparent)]
    InvalidParameter(#[from] aloft_core::InvalidParameter),
    /// A count (rotors, packs, cells) that is zero or inconsistent.
    #[error("{name} = {count} is invalid: expected {expected}")]
    InvalidCount {
        /// Which count.
        name: &'static str,
        /// The rejected value.
        count: u32,
        /// What a valid count looks like.
        expected: &'static str,
    },
    /// The pack cannot deliver the requested power, whatever the current (eqs 29-30).
    #[error("a pack cannot deliver {} W: its maximum is {} W (full-charge voltage and internal resistance, eqs 29-30)", aloft_core::Fixed(*.power_w, 1), aloft_core::Fixed(*.max_power_w, 1))]
    PowerExceedsPack {
        /// Power asked of one pack, W.
        power_w: f64,
        /// Largest power the pack can deliver to its load, W.
        max_power_w: f64,
    },
    /// The pack current needed exceeds the pack's rated continuous current.
    #[error("pack current {} A exceeds the pack's rated {} A", aloft_core::Fixed(*.current_a, 1), aloft_core::Fixed(*.limit_a, 1))]
    PackCurrentLimit {
        /// Current required, A.
        current_a: f64,
        /// Rated limit, A.
        limit_a: f64,
    },
    /// The thrust asked of a rotor needs more motor current than the motor's rating.
    #[error("thrust {} N per rotor needs {} A of motor current, above the motor's {} A limit", aloft_core::Fixed(*.thrust_n, 2), aloft_core::Fixed(*.current_a, 1), aloft_core::Fixed(*.limit_a, 1))]
    CurrentLimitExceeded {
        /// Thrust asked of one rotor, N.
        thrust_n: f64,
        /// Motor current it needs, A.
        current_a: f64,
        /// Motor current limit, A.
        limit_a: f64,
    },
    /// A thrust that is negative or not finite.
    #[error("thrust must be a non-negative finite force, got {thrust_n} N")]
    InvalidThrust {
        /// The rejected value, N.
        thrust_n: f64,
    },
    /// Two data slices that should have the same length do not.
    #[error("data length mismatch for {what}: expected {expected} values, got {found}")]
    LengthMismatch {
        /// Which slice.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        found: usize,
    },
    /// Too few (usable) data points for a fit.
    #[error("fit of {model} needs at least {required} usable points, got {points}")]
    InsufficientData {
        /// Which model is being fitted.
        model: &'static str,
        /// Usable points.
        points: usize,
        /// Minimum needed.
        required: usize,
    },
    /// A data value that is not finite.
    #[error("data value {what}[{index}] = {value} is not finite")]
    NonFiniteData {
        /// Which slice.
        what: &'static str,
        /// Index of the value.
        index: usize,
        /// The value.
        value: f64,
    },
    /// The optimiser did not return a usable result.
    #[error("fit of {model} did not converge to a finite optimum")]
    FitDidNotConverge {
        /// Which model.
        model: &'static str,
    },
    /// An ESC protocol name that is not in the transient seed's Table 4.
    #[error("unknown ESC protocol {protocol:?}: expected dshot150, dshot300, oneshot42, oneshot125, multishot, pwm50 or pwm500")]
    UnknownProtocol {
        /// The rejected name.
        protocol: String,
    },
    /// Keys of a spec table that must not be given together, or of which one is required.
    #[error("in [{table}]: {problem}")]
    ConflictingKeys {
        /// The table (e.g. `propulsion.motor`).
        table: &'static str,
        /// What is wrong.
        problem: &'static str,
    },
    /// A simulated step response that never reached its band (simulation too short).
    #[error("step response did not settle within the simulated {duration_s} s")]
    NotSettled {
        /// Simulated duration, s.
        duration_s: f64,
    },
}

/// Largest magnitude of any parameter a constructor takes, in its own unit: far beyond any
/// propulsion system (a rotor of a kilometre, a million amperes), small enough that no product of
/// the model's formulas overflows. A value above it is a mistake (a unit slip), not a motor.
pub const MAX_PARAMETER: f64 = 1e6;

/// Largest mass, kg.
pub const MAX_MASS_KG: f64 = 1e4;

/// Largest voltage, V.
pub const MAX_VOLTAGE_V: f64 = 1e4;

/// Largest resistance, ohm.
pub const MAX_RESISTANCE_OHM: f64 = 1e3;

/// Largest velocity constant, rpm/V.
pub const MAX_KV_RPM_PER_V: f64 = 1e5;

/// Check that `value` is finite.
pub(crate) fn finite(
    name: &'static str,
    value: f64,
    unit: &'static str,
) -> Result<f64, PropulsionError> {
    let ok = value.is_finite() && value.abs() <= MAX_PARAMETER;
    Ok(aloft_core::parameter(
        name,
        value,
        unit,
        ok,
        "a finite number of at most 1e6 in magnitude",
    )?)
}

/// Check that `value` is finite and strictly positive.
pub(crate) fn positive(
    name: &'static str,
    value: f64,
    unit: &'static str,
) -> Result<f64, PropulsionError> {
    let ok = value.is_finite() && value > 0.0 && value <= MAX_PARAMETER;
    Ok(aloft_core::parameter(
        name,
        value,
        unit,
        ok,
        "a positive finite number up to 1e6",
    )?)
}

/// Check that `value` is finite and not negative.
pub(crate) fn non_negative(
    name: &'static str,
    value: f64,
    unit: &'static str,
) -> Result<f64, PropulsionError> {
    let ok = (0.0..=MAX_PARAMETER).contains(&value);
    Ok(aloft_core::parameter(
        name,
        value,
        unit,
        ok,
        "a non-negative finite number up to 1e6",
    )?)
}

/// Check a rated current limit: positive, infinity for none.
pub(crate) fn current_limit(name: &'static str, current_a: f64) -> Result<f64, PropulsionError> {
    let ok = !(current_a.is_nan() || current_a <= 0.0)
        && (current_a.is_infinite() || current_a <= MAX_PARAMETER);
    Ok(aloft_core::parameter(
        name,
        current_a,
        "A",
        ok,
        "a positive current (or infinity for no limit)",
    )?)
}

/// Check a fraction in `[0, 1)` (losses) or `(0, 1]` (coefficients).
pub(crate) fn fraction(
    name: &'static str,
    value: f64,
    allow_zero: bool,
    allow_one: bool,
) -> Result<f64, PropulsionError> {
    let lower_ok = if allow_zero {
        value >= 0.0
    } else {
        value > 0.0
    };
    let upper_ok = if allow_one { value <= 1.0 } else { value < 1.0 };
    if value.is_finite() && lower_ok && upper_ok {
        Ok(value)
    } else {
        Err(aloft_core::InvalidParameter {
            name,
            value,
            unit: "(fraction)",
            expected: "a fraction between 0 and 1",
        }
        .into())
    }
}

/// Check a mass.
pub(crate) fn mass(name: &'static str, mass_kg: f64) -> Result<f64, PropulsionError> {
    if mass_kg.is_finite() && mass_kg > 0.0 && mass_kg <= MAX_MASS_KG {
        Ok(mass_kg)
    } else {
        Err(PropulsionError::InvalidMass { name, mass_kg })
    }
}

/// Check a voltage.
pub(crate) fn voltage(name: &'static str, voltage_v: f64) -> Result<f64, PropulsionError> {
    if voltage_v.is_finite() && voltage_v > 0.0 && voltage_v <= MAX_VOLTAGE_V {
        Ok(voltage_v)
    } else {
        Err(PropulsionError::InvalidVoltage { name, voltage_v })
    }
}

/// Check a resistance (zero allowed).
pub(crate) fn resistance(name: &'static str, resistance_ohm: f64) -> Result<f64, PropulsionError> {
    if (0.0..=MAX_RESISTANCE_OHM).contains(&resistance_ohm) {
        Ok(resistance_ohm)
    } else {
        Err(PropulsionError::InvalidResistance {
            name,
            resistance_ohm,
        })
    }
}

/// Check a Kv.
pub(crate) fn kv(kv_rpm_per_v: f64) -> Result<f64, PropulsionError> {
    if kv_rpm_per_v.is_finite() && kv_rpm_per_v > 0.0 && kv_rpm_per_v <= MAX_KV_RPM_PER_V {
        Ok(kv_rpm_per_v)
    } else {
        Err(PropulsionError::InvalidKv { kv_rpm_per_v })
    }
}
