//! The typed error of the power model.

use thiserror::Error;

/// Everything that can go wrong when building a vehicle or evaluating the power model.
///
/// Every variant carries the offending value with its unit, so a message can name it.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum PowerError {
    /// A parameter that must be a finite number is NaN or infinite.
    #[error("{name} must be a finite number, got {}", aloft_core::Num::of(.value))]
    NotFinite {
        /// Parameter name with its unit suffix, e.g. `airspeed_mps`.
        name: &'static str,
        /// The value received.
        value: f64,
    },
    /// A parameter that must be strictly positive is zero or negative.
    #[error("{name} must be greater than zero, got {}", aloft_core::Num::of(.value))]
    NotPositive {
        /// Parameter name with its unit suffix.
        name: &'static str,
        /// The value received.
        value: f64,
    },
    /// A parameter that must not be negative is negative.
    #[error("{name} must not be negative, got {}", aloft_core::Num::of(.value))]
    Negative {
        /// Parameter name with its unit suffix.
        name: &'static str,
        /// The value received.
        value: f64,
    },
    /// A parameter lies outside the range in which the model is defined or physical.
    #[error("{name} = {} is outside the accepted range {min} to {max}", aloft_core::Num::of(.value))]
    OutOfRange {
        /// Parameter name with its unit suffix.
        name: &'static str,
        /// The value received.
        value: f64,
        /// Smallest accepted value.
        min: f64,
        /// Largest accepted value.
        max: f64,
    },
    /// The vehicle has no rotor.
    #[error("rotor_count must be at least 1, got {rotor_count}")]
    NoRotor {
        /// The rotor count received.
        rotor_count: u32,
    },
    /// The cubic drag law of eq (6) gives a negative drag force at some airspeed in 0-60 m/s.
    #[error(
        "the drag coefficients mu1..mu3 give a negative drag force ({drag_n:.4} N) at {airspeed_mps:.2} m/s"
    )]
    NegativeDrag {
        /// Airspeed where the drag force is most negative, m/s.
        airspeed_mps: f64,
        /// The drag force there, N.
        drag_n: f64,
    },
    /// One body-axis drag key without the other (`mu2_x_n_s2_per_m2`, `mu2_y_n_s2_per_m2`).
    #[error("{given} is given without {missing}: body-axis drag needs both keys, or neither")]
    LoneBodyAxisDrag {
        /// The key given.
        given: &'static str,
        /// The key missing.
        missing: &'static str,
    },
    /// Roll and pitch tilt the thrust axis 90 degrees or more from vertical: the vehicle cannot hold altitude.
    #[error(
        "tilt of {tilt_deg:.2} deg (roll {roll_deg:.2} deg, pitch {pitch_deg:.2} deg) is 90 deg or more: thrust cannot balance weight"
    )]
    TiltTooLarge {
        /// Angle between the thrust axis and the vertical, degrees.
        tilt_deg: f64,
        /// Roll angle, degrees.
        roll_deg: f64,
        /// Pitch angle, degrees.
        pitch_deg: f64,
    },
    /// Momentum theory has no induced velocity continuous with hover for this inflow
    /// (the rotor is in the vortex-ring / windmill-brake region of a steep descent).
    #[error(
        "no induced velocity continuous with hover for axial inflow {normal_mps:.3} m/s and in-plane inflow {parallel_mps:.3} m/s (hover induced velocity {hover_mps:.3} m/s): momentum theory is invalid in this descent (vortex-ring state)"
    )]
    NoPhysicalInducedVelocity {
        /// Freestream component along the rotor axis, `Vn = v_inf sin(alpha)`, m/s.
        normal_mps: f64,
        /// Freestream component in the rotor plane, `Vp = v_inf cos(alpha)`, m/s.
        parallel_mps: f64,
        /// Hover induced velocity `vh`, m/s.
        hover_mps: f64,
    },
    /// A name that is not an angle-of-attack model ([`crate::AoaModel`]'s `FromStr`).
    #[error("unknown angle-of-attack model '{found}': expected paper or geometric")]
    UnknownAoaModel {
        /// The text received.
        found: String,
    },
    /// Two series that must be compared sample by sample have different lengths or are empty.
    #[error(
        "series lengths differ or are empty: {estimate_len} estimates, {measured_len} measurements"
    )]
    SeriesLength {
        /// Length of the estimate series.
        estimate_len: usize,
        /// Length of the measured series.
        measured_len: usize,
    },
    /// A normalised error is undefined because the normaliser is zero.
    #[error("cannot normalise the error: the measured {what} is {value}")]
    ZeroNormaliser {
        /// Which normaliser (mean or range).
        what: &'static str,
        /// Its value.
        value: f64,
    },
}

/// Errors of the parameter fit ([`crate::fit`]).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum FitError {
    /// Fewer usable samples than the fit needs.
    #[error(
        "{samples} usable samples: the fit of {parameters} parameters needs at least {required}"
    )]
    TooFewSamples {
        /// Usable samples.
        samples: usize,
        /// Free parameters.
        parameters: usize,
        /// Samples required.
        required: usize,
    },
    /// A sample whose state or measured power is invalid.
    #[error("sample {index}: {message}")]
    BadSample {
        /// 0-based index of the sample.
        index: usize,
        /// What is wrong, with the value.
        message: String,
    },
    /// The data has too little forward flight to identify a speed-dependent parameter.
    #[error(
        "{parameter} cannot be identified: only {above} of {total} samples fly faster than {airspeed_mps} m/s (need forward flight; fix it in the template and fit without it)"
    )]
    NoForwardFlight {
        /// The parameter.
        parameter: &'static str,
        /// Samples above the airspeed.
        above: usize,
        /// All samples.
        total: usize,
        /// The airspeed threshold, m/s.
        airspeed_mps: f64,
    },
    /// A drag constant asked of power data evaluated with the geometric angle of attack, where
    /// the drag work is already in the measured attitude.
    #[error(
        "{parameter} cannot be fitted from power: {geometric} of {total} samples use the geometric angle of attack, where the drag work is in the attitude (eq 8's T Vn), not in eq (11); fit drag from the force balance (aloft_power::fit::drag) or use the paper's angle of attack"
    )]
    DragNotInPower {
        /// The parameter.
        parameter: &'static str,
        /// Samples with the geometric angle of attack.
        geometric: usize,
        /// All samples.
        total: usize,
    },
    /// The data leaves a parameter undetermined: its standard error is too large or the
    /// information matrix is singular along it.
    #[error(
        "{parameter} cannot be identified from this data: fitted {value:.6e} {unit} with standard error {std_error:.3e} (fix it in the template and fit without it)"
    )]
    NotIdentifiable {
        /// The parameter.
        parameter: &'static str,
        /// Its fitted value.
        value: f64,
        /// Its standard error (infinite when the information matrix is singular).
        std_error: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// The fitted lumped constants give an efficiency above 1 with the template's mass.
    #[error(
        "the fit gives an efficiency of {efficiency:.3} (> 1) with the template's mass of {mass_kg} kg: the mass is too low for the measured power"
    )]
    EfficiencyAboveOne {
        /// The implied efficiency.
        efficiency: f64,
        /// The template's mass, kg.
        mass_kg: f64,
    },
    /// The optimiser failed.
    #[error("the least-squares solver failed: {message}")]
    Solver {
        /// The solver's message.
        message: String,
    },
}

/// Result type of this crate.
pub type Result<T, E = PowerError> = std::result::Result<T, E>;

/// Check that `value` is finite.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(PowerError::NotFinite { name, value })
    }
}

/// Check that `value` is finite and strictly positive.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    finite(name, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(PowerError::NotPositive { name, value })
    }
}

/// Check that `value` lies in `[min, max]` (NaN does not).
pub(crate) fn within(name: &'static str, value: f64, min: f64, max: f64) -> Result<f64> {
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(PowerError::OutOfRange {
            name,
            value,
            min,
            max,
        })
    }
}

/// Check that `value` is finite and not negative.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    finite(name, value)?;
    if value >= 0.0 {
        Ok(value)
    } else {
        Err(PowerError::Negative { name, value })
    }
}
