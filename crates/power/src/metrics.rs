//! Error metrics for comparing a power estimate with measurements.
//!
//! `RMSE = sqrt(mean((estimate - measured)^2))`, in the unit of the data.
//!
//! `NRMSE = RMSE / N`, as a fraction (multiply by 100 for percent), with the normaliser `N`:
//! - [`Normalisation::Mean`] (the default): the mean of the measured values. This is the reading
//!   used throughout aloft for power, where the measured mean is far from zero and the range of a
//!   steady hover is tiny; it is also what makes "the flight's own mean power" a baseline with an
//!   NRMSE equal to the coefficient of variation of the measurement.
//! - [`Normalisation::Range`]: `max - min` of the measured values.
//!
//! The power seed does not define its NRMSE; aloft's comparison with its Table I assumes the mean.

use crate::error::{finite, PowerError, Result};

/// The normaliser of [`nrmse`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Normalisation {
    /// The mean of the measured values.
    #[default]
    Mean,
    /// The range (max - min) of the measured values.
    Range,
}

fn check_lengths(estimate: &[f64], measured: &[f64]) -> Result<()> {
    if estimate.len() != measured.len() || estimate.is_empty() {
        return Err(PowerError::SeriesLength {
            estimate_len: estimate.len(),
            measured_len: measured.len(),
        });
    }
    for (&e, &m) in estimate.iter().zip(measured) {
        finite("estimate", e)?;
        finite("measured", m)?;
    }
    Ok(())
}

/// Root-mean-square error of `estimate` against `measured` (same length, not empty, finite).
pub fn rmse(estimate: &[f64], measured: &[f64]) -> Result<f64> {
    check_lengths(estimate, measured)?;
    let sum: f64 = estimate
        .iter()
        .zip(measured)
        .map(|(e, m)| (e - m) * (e - m))
        .sum();
    Ok((sum / estimate.len() as f64).sqrt())
}

/// Normalised root-mean-square error, a fraction: `rmse / normaliser` (see the module docs).
pub fn nrmse(estimate: &[f64], measured: &[f64], normalisation: Normalisation) -> Result<f64> {
    let r = rmse(estimate, measured)?;
    let (what, norm) = match normalisation {
        Normalisation::Mean => ("mean", measured.iter().sum::<f64>() / measured.len() as f64),
        Normalisation::Range => {
            let max = measured.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let min = measured.iter().copied().fold(f64::INFINITY, f64::min);
            ("range", max - min)
        }
    };
    if norm.abs() < f64::MIN_POSITIVE {
        return Err(PowerError::ZeroNormaliser { what, value: norm });
    }
    Ok(r / norm.abs())
}

#[cfg(test)]
// Exact comparisons here check values that are exact by construction (zeros of removed terms and
// of zero airspeed, bit-identical results of the same arithmetic).
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn rmse_by_hand() {
        // Errors 1, -1, 2, 0: mean square (1 + 1 + 4 + 0) / 4 = 1.5.
        let r = rmse(&[2.0, 1.0, 5.0, 4.0], &[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert!((r - 1.5f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn nrmse_normalisations() {
        let est = [2.0, 1.0, 5.0, 4.0];
        let meas = [1.0, 2.0, 3.0, 4.0];
        let mean = nrmse(&est, &meas, Normalisation::Mean).unwrap();
        let range = nrmse(&est, &meas, Normalisation::Range).unwrap();
        assert!((mean - 1.5f64.sqrt() / 2.5).abs() < 1e-15);
        assert!((range - 1.5f64.sqrt() / 3.0).abs() < 1e-15);
    }

    #[test]
    fn a_perfect_estimate_scores_zero_and_bad_series_are_errors() {
        assert_eq!(rmse(&[3.0, 4.0], &[3.0, 4.0]).unwrap(), 0.0);
        assert!(rmse(&[], &[]).is_err());
        assert!(rmse(&[1.0], &[1.0, 2.0]).is_err());
        assert!(rmse(&[f64::NAN], &[1.0]).is_err());
        assert!(nrmse(&[1.0, 1.0], &[2.0, 2.0], Normalisation::Range).is_err());
    }
}
