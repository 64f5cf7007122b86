//! In flight: re-estimate the efficiency from measured power as the flight goes.

use aloft_core::Trapezoid;
use aloft_power::FlightState;

use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// Largest power a sample may carry, W (a gigawatt: beyond any multirotor; a larger number is a
/// unit slip, and the energy sums would overflow).
const MAX_POWER_W: f64 = 1e9;

/// In-flight re-estimate of the overall efficiency `eta` from measured electrical power.
///
/// Each sample pairs a time with the model's predicted electrical power at a reference efficiency
/// `eta_0` and the measured electrical power. Over the samples so far, by the trapezoid rule,
///
/// `eta = eta_0 * E_predicted / E_measured = E_aero / E_measured`,
///
/// the energy ratio: [`aloft_power::calibrate_efficiency`]'s `P_req / P_measured` (power seed
/// eqs 7 and 14) integrated over time, which weights each instant by the energy it costs and is the
/// re-estimate `aloft validate --calibrate-s` makes over a window.
///
/// | symbol | meaning | unit |
/// |---|---|---|
/// | `eta_0` | efficiency the predictions were made with | - |
/// | `E_predicted` | integral of the predicted electrical power | J |
/// | `E_measured` | integral of the measured electrical power | J |
/// | `E_aero` | `eta_0 E_predicted`, the model's aerodynamic energy | J |
///
/// Valid while the model's shape is right and only its scale is off (mass, air density and
/// drag errors are absorbed into `eta`, as in the paper's calibration).
#[derive(Debug, Clone, PartialEq)]
pub struct InFlightEstimator {
    reference_efficiency: f64,
    predicted_j: Trapezoid,
    measured_j: Trapezoid,
    samples: usize,
    predicted_w: Vec<f64>,
    measured_w: Vec<f64>,
}

impl InFlightEstimator {
    /// An estimator for predictions made with efficiency `reference_efficiency` in `(0, 1]`.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] for an efficiency outside `(0, 1]`.
    pub fn new(reference_efficiency: f64) -> Result<Self, Error> {
        if !(reference_efficiency > 0.0 && reference_efficiency <= 1.0) {
            return Err(Error::InvalidInput {
                name: "reference_efficiency",
                value: reference_efficiency,
                unit: "",
                expected: "an efficiency in (0, 1]",
            });
        }
        Ok(Self {
            reference_efficiency,
            predicted_j: Trapezoid::new(),
            measured_j: Trapezoid::new(),
            samples: 0,
            predicted_w: Vec::new(),
            measured_w: Vec::new(),
        })
    }

    /// An estimator for `vehicle`'s predictions (its model's efficiency).
    ///
    /// # Errors
    /// [`Error::MissingTable`] when the vehicle has no `[power]` table.
    pub fn for_vehicle(vehicle: &Vehicle) -> Result<Self, Error> {
        Self::new(vehicle.power_model()?.vehicle().efficiency())
    }

    /// Add a sample: `predicted_w` is the model's electrical power at the reference efficiency
    /// (e.g. the plan's `power_w` at that time), `measured_w` the pack's voltage times current.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] for a non-finite or non-increasing time, or a non-finite or negative
    /// power; the sample is then ignored.
    pub fn push(&mut self, time_s: f64, predicted_w: f64, measured_w: f64) -> Result<(), Error> {
        let in_range = time_s.is_finite() && time_s.abs() <= 1e9;
        if !in_range || self.measured_j.last().is_some_and(|(t, _)| time_s <= t) {
            return Err(Error::InvalidInput {
                name: "time_s",
                value: time_s,
                unit: "s",
                expected: "a finite time (within 1e9 s) after the previous sample's",
            });
        }
        for (name, value) in [("predicted_w", predicted_w), ("measured_w", measured_w)] {
            if !(0.0..=MAX_POWER_W).contains(&value) {
                return Err(Error::InvalidInput {
                    name,
                    value,
                    unit: "W",
                    expected: "a finite power, not negative, at most 1e9 W",
                });
            }
        }
        self.predicted_j.push(time_s, predicted_w);
        self.measured_j.push(time_s, measured_w);
        self.samples += 1;
        self.predicted_w.push(predicted_w);
        self.measured_w.push(measured_w);
        Ok(())
    }

    /// Add a sample with the prediction made here from a flight state: `vehicle`'s aerodynamic
    /// power at `state` over the reference efficiency.
    ///
    /// # Errors
    /// As [`Vehicle::power`] and [`InFlightEstimator::push`].
    pub fn push_state(
        &mut self,
        vehicle: &Vehicle,
        time_s: f64,
        state: &FlightState,
        measured_w: f64,
    ) -> Result<(), Error> {
        let aero_w = vehicle.power(state)?.aero_w.max(0.0);
        self.push(time_s, aero_w / self.reference_efficiency, measured_w)
    }

    /// Number of samples accepted.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Measured energy so far, Wh.
    pub fn measured_energy_wh(&self) -> f64 {
        self.measured_j.integral() / 3600.0
    }

    /// Predicted energy so far at the reference efficiency, Wh.
    pub fn predicted_energy_wh(&self) -> f64 {
        self.predicted_j.integral() / 3600.0
    }

    /// The re-estimated efficiency, `None` until two samples with energy have been added.
    ///
    /// # Errors
    /// [`Error::Power`] (out of range) when the measured energy is below the model's aerodynamic
    /// energy (`eta > 1`), as [`aloft_power::calibrate_efficiency`] refuses it.
    pub fn efficiency(&self) -> Result<Option<f64>, Error> {
        let (measured_j, predicted_j) = (self.measured_j.integral(), self.predicted_j.integral());
        if measured_j <= 0.0 || predicted_j <= 0.0 {
            return Ok(None);
        }
        let aero_j = self.reference_efficiency * predicted_j;
        let eta = aero_j / measured_j;
        if !(eta.is_finite() && eta <= 1.0) {
            return Err(aloft_power::PowerError::OutOfRange {
                name: "measured_energy_wh",
                value: measured_j / 3600.0,
                min: aero_j / 3600.0,
                max: f64::INFINITY,
            }
            .into());
        }
        Ok(Some(eta))
    }
}

impl InFlightEstimator {
    /// The re-estimated efficiency shrunk toward the reference efficiency by the uncertainty of
    /// each ([`crate::recalibration`]): `prior_relative_sd` is the vehicle file's
    /// `efficiency_relative_sd` (`None`: the estimate of [`Self::efficiency`] alone). `None`
    /// until two samples with energy have been added.
    ///
    /// # Errors
    /// As [`Self::efficiency`].
    pub fn shrunk_efficiency(&self, prior_relative_sd: Option<f64>) -> Result<Option<f64>, Error> {
        let Some(eta) = self.efficiency()? else {
            return Ok(None);
        };
        let ratio = self.reference_efficiency / eta;
        let shrunk = crate::recalibration::shrink(
            ratio,
            &self.measured_w,
            &self.predicted_w,
            prior_relative_sd,
        );
        Ok(Some(self.reference_efficiency / shrunk.ratio))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimator_recovers_a_scaled_efficiency() {
        let v = Vehicle::builtin("dji-m100").unwrap();
        let eta0 = v.efficiency().unwrap();
        let mut est = InFlightEstimator::for_vehicle(&v).unwrap();
        assert_eq!(est.efficiency().unwrap(), None);
        // The true vehicle draws 10 % more than predicted: eta = eta0 / 1.1.
        for k in 0..50 {
            let t = k as f64 * 0.5;
            let state = FlightState::new(0.2 * t, 0.0, -0.01 * t, 0.0);
            let predicted = v.power(&state).unwrap().electrical_w;
            est.push_state(&v, t, &state, 1.1 * predicted).unwrap();
        }
        let eta = est.efficiency().unwrap().unwrap();
        // Exact up to rounding: both energies use the same trapezoid.
        assert!((eta - eta0 / 1.1).abs() < 1e-12, "{eta} vs {}", eta0 / 1.1);
        // Without a prior spread the shrunk estimate is the window's; with noise-free data the
        // window is certain and outweighs even a tight prior.
        let alone = est.shrunk_efficiency(None).unwrap().unwrap();
        assert!((alone - eta).abs() < 1e-12, "{alone} vs {eta}");
        let sure = est.shrunk_efficiency(Some(1e-3)).unwrap().unwrap();
        assert!((sure - eta).abs() < 1e-12, "{sure} vs {eta}");
        let recal = v.with_efficiency(eta).unwrap();
        assert!((recal.efficiency().unwrap() - eta).abs() < 1e-15);
    }

    #[test]
    fn estimator_rejects_bad_samples_and_eta_above_one() {
        let mut est = InFlightEstimator::new(0.8).unwrap();
        est.push(0.0, 100.0, 50.0).unwrap();
        assert!(est.push(0.0, 100.0, 50.0).is_err());
        assert!(est.push(1.0, f64::NAN, 50.0).is_err());
        assert!(est.push(1.0, 100.0, -1.0).is_err());
        est.push(1.0, 100.0, 50.0).unwrap();
        assert_eq!(est.samples(), 2);
        // eta = 0.8 * 100 / 50 = 1.6: refused, as calibrate_efficiency refuses it.
        assert!(est.efficiency().is_err());
        assert!(InFlightEstimator::new(0.0).is_err());
        assert!(InFlightEstimator::new(f64::NAN).is_err());
    }
}
