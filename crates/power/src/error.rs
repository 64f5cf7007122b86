//! The typed error of the power model.

use thiserror::Error;

/// Everything that can go wrong when building a vehicle or evaluating the power model.
///
/// Every variant carries the offending value with its unit, so a message can name it.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum PowerError {
    /// A parameter that must be a finite number is NaN or infinite.
    #[error("{name} must be a finite number, got {value}")]
    NotFinite {
        /// Parameter name with its unit suffix, e.g. `airspeed_mps`.
        name: &'static str,
        /// The value received.
        value: f64,
    },
    /// A parameter that must be strictly positive is zero or negative.
    #[error("{name} must be greater than zero, got {value}")]
    NotPositive {
        /// Parameter name with its unit suffix.
        name: &'static str,
        /// The value received.
        value: f64,
    },
    /// A parameter that must not be negative is negative.
    #[error("{name} must not be negative, got {value}")]
    Negative {
        /// Parameter name with its unit suffix.
        name: &'static str,
        /// The value received.
        value: f64,
    },
    /// A parameter lies outside the range in which the model is defined or physical.
    #[error("{name} = {value} is outside the accepted range {min} to {max}")]
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

/// Check that `value` is finite and not negative.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    finite(name, value)?;
    if value >= 0.0 {
        Ok(value)
    } else {
        Err(PowerError::Negative { name, value })
    }
}
