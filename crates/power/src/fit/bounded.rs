//! Fits that always give a physical vehicle.
//!
//! A short log cannot identify every constant: a minute of hover and climb says nothing of
//! drag, and the lumped `K = W / eta` of a template whose mass is too low gives an efficiency
//! above 1. The fits here know it: each constant is fitted where the data identifies it and
//! stays in its physical range, and the answer says which constants were fitted and which were
//! kept, with the reason.
//!
//! **Power** ([`fit_power_model_bounded`]): [`fit_power_model`] with the requested constants;
//! then, one at a time, until the fit is physical and identified:
//!
//! | the fit says | what is kept |
//! |---|---|
//! | a constant's standard error is above `max_relative_std_error` times its value, or the information matrix is singular along it | that constant, at the template's value |
//! | too little forward flight for a speed-dependent constant (drag, `vh`) | that constant, at the template's value |
//! | a drag constant asked of geometric-angle-of-attack power | that constant, at the template's value |
//! | an efficiency above 1 (`K < W`) | the efficiency at its bound, 1 (`K = W`) |
//! | a negative profile constant, or drag that is negative somewhere in 0-60 m/s | that constant, at the template's value |
//! | the solver fails (a singular step) with several constants free | the least identifiable of them: drag, then `vh`, then profile |
//!
//! When nothing is left to fit, the answer is the template's own prediction of the samples.
//! A fit that is physical and identified from the start is exactly [`fit_power_model`]'s.
//!
//! **Drag** ([`fit_drag_bounded`]): the force balance's free cubic ([`fit_drag`]) when its drag
//! is non-negative over 0-60 m/s and every coefficient is identified (standard error at most its
//! magnitude); else the best fit with non-negative coefficients (non-negative least squares over
//! the subsets of `v, v^2, v^3`, each coefficient identified; non-negative coefficients give
//! non-negative drag at every speed); else the template's drag. Too few samples in forward
//! flight (30 above the airspeed threshold) or too narrow a speed range (under 3 m/s between the
//! 5th and 95th percentiles) keep the template's drag: a cubic through a narrow band of speeds
//! extrapolates anywhere.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::drag::{fit_drag, force_rows, DragFit, ForceSample, MIN_FORWARD_ROWS};
use super::power::{fit_power_model, FitOptions, FitParameter, FitSample, PowerFit};
use crate::error::FitError;
use crate::four_term::PowerModel;
use crate::vehicle::Vehicle;

/// Narrowest band of airspeeds (5th to 95th percentile) from which drag is fitted, m/s.
pub const MIN_DRAG_SPEED_SPAN_MPS: f64 = 3.0;

/// A constant the fit kept instead of fitting it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KeptParameter {
    /// Name (as [`FitParameter::name`], or `mu1_n_s_per_m` and so on for the force balance).
    pub name: &'static str,
    /// The value kept, in `unit`.
    pub value: f64,
    /// Unit.
    pub unit: &'static str,
    /// Why it was kept.
    pub reason: String,
}

/// The answer of [`fit_power_model_bounded`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoundedPowerFit {
    /// The fit of the constants that were fitted (its `parameters`); the vehicle holds the kept
    /// ones at the template's values or their bounds.
    pub fit: PowerFit,
    /// The constants kept, with the reason.
    pub kept: Vec<KeptParameter>,
}

/// [`fit_power_model`] kept physical and identified (see the module docs).
///
/// # Errors
/// Samples that are invalid or too few for even one constant; a solver failure.
pub fn fit_power_model_bounded(
    template: &Vehicle,
    samples: &[FitSample],
    options: &FitOptions,
) -> Result<BoundedPowerFit, FitError> {
    let mut template = template.clone();
    let mut options = options.clone();
    let mut kept = Vec::new();
    // Each pass fits or keeps one more constant (six, and the efficiency bound): a bounded loop.
    for _ in 0..=FitParameter::ALL.len() + 1 {
        if options.free.is_empty() {
            let fit = template_prediction(&template, samples)?;
            return Ok(BoundedPowerFit { fit, kept });
        }
        let keep = match fit_power_model(&template, samples, &options) {
            Ok(fit) => match unphysical(&fit, &options.free) {
                None => return Ok(BoundedPowerFit { fit, kept }),
                Some(why) => why,
            },
            Err(e) => match refusal(&e).or_else(|| solver_fallback(&e, &options.free)) {
                Some(why) => why,
                None => return Err(e),
            },
        };
        if let Keep::EfficiencyBound { efficiency } = keep {
            template = template
                .with_efficiency(1.0)
                .map_err(|e| FitError::Solver {
                    message: e.to_string(),
                })?;
            kept.push(KeptParameter {
                name: FitParameter::WeightOverEfficiency.name(),
                value: template.weight_n(),
                unit: FitParameter::WeightOverEfficiency.unit(),
                reason: format!(
                    "the fit's efficiency {efficiency:.3} is above 1 with the template's mass of {} kg: held at 1 (the mass or the disk-area convention of the template is probably off)",
                    template.mass_kg()
                ),
            });
            options
                .free
                .retain(|&p| p != FitParameter::WeightOverEfficiency);
            continue;
        }
        let Keep::Parameter { parameter, reason } = keep else {
            continue;
        };
        kept.push(KeptParameter {
            name: parameter.name(),
            value: template_lumped(&template, parameter),
            unit: parameter.unit(),
            reason,
        });
        options.free.retain(|&p| p != parameter);
    }
    Err(FitError::Solver {
        message: "the bounded fit did not settle".to_string(),
    })
}

/// What one pass of the bounded fit keeps.
enum Keep {
    /// A constant at the template's value.
    Parameter {
        parameter: FitParameter,
        reason: String,
    },
    /// The efficiency at its bound 1.
    EfficiencyBound { efficiency: f64 },
}

/// The constant an error of the fit says the data cannot identify, or the efficiency bound.
fn refusal(e: &FitError) -> Option<Keep> {
    let by_name = |name: &str| FitParameter::ALL.into_iter().find(|p| p.name() == name);
    match e {
        FitError::NotIdentifiable { parameter, .. }
        | FitError::NoForwardFlight { parameter, .. }
        | FitError::DragNotInPower { parameter, .. } => Some(Keep::Parameter {
            parameter: by_name(parameter)?,
            reason: format!("not identified by these logs: {e}"),
        }),
        FitError::EfficiencyAboveOne { efficiency, .. } => Some(Keep::EfficiencyBound {
            efficiency: *efficiency,
        }),
        _ => None,
    }
}

/// When the solver fails with more than one constant free (a singular step: the data does not
/// separate them), the least identifiable of them is kept: drag first (`mu3`, `mu2`, `mu1`),
/// then `vh`, then the profile constant.
fn solver_fallback(e: &FitError, free: &[FitParameter]) -> Option<Keep> {
    if !matches!(e, FitError::Solver { .. }) || free.len() < 2 {
        return None;
    }
    let order = [
        FitParameter::Mu3,
        FitParameter::Mu2,
        FitParameter::Mu1,
        FitParameter::HoverInducedVelocity,
        FitParameter::Profile,
    ];
    let parameter = order.into_iter().find(|p| free.contains(p))?;
    Some(Keep::Parameter {
        parameter,
        reason: format!("the fit does not converge with it free ({e})"),
    })
}

/// A free constant whose fitted value makes the vehicle unphysical: a negative profile constant,
/// or drag that is negative somewhere (the first free drag constant is kept, then the next).
fn unphysical(fit: &PowerFit, free: &[FitParameter]) -> Option<Keep> {
    let kappa1 = fit.vehicle.kappa1_w_per_n1_5;
    if free.contains(&FitParameter::Profile) && kappa1 < 0.0 {
        return Some(Keep::Parameter {
            parameter: FitParameter::Profile,
            reason: format!("the fit's profile constant kappa1 {kappa1:.4} is negative"),
        });
    }
    if let Err(e) = Vehicle::new(fit.vehicle.clone()) {
        let drag = [FitParameter::Mu1, FitParameter::Mu2, FitParameter::Mu3];
        let parameter = drag.into_iter().find(|p| free.contains(p))?;
        return Some(Keep::Parameter {
            parameter,
            reason: format!("the fitted vehicle is not physical: {e}"),
        });
    }
    None
}

/// The template's lumped value of `parameter` (see [`super::power`]).
fn template_lumped(template: &Vehicle, parameter: FitParameter) -> f64 {
    let (eta, w) = (template.efficiency(), template.weight_n());
    let (mu1, mu2, mu3) = template.drag().coefficients();
    match parameter {
        FitParameter::WeightOverEfficiency => w / eta,
        FitParameter::HoverInducedVelocity => template.hover_induced_velocity_mps(),
        FitParameter::Profile => template.kappa1() * w.powf(1.5) / eta,
        FitParameter::Mu1 => mu1 / eta,
        FitParameter::Mu2 => mu2 / eta,
        FitParameter::Mu3 => mu3 / eta,
    }
}

/// The template's own prediction of the samples, as a fit of nothing: its RMSE over all of them.
fn template_prediction(template: &Vehicle, samples: &[FitSample]) -> Result<PowerFit, FitError> {
    let model = PowerModel::new(template.clone());
    let (mut ssr, mut sum) = (0.0, 0.0);
    for (index, s) in samples.iter().enumerate() {
        let p = model
            .evaluate(&s.state)
            .map_err(|e| FitError::BadSample {
                index,
                message: e.to_string(),
            })?
            .electrical_w;
        ssr += (p - s.measured_power_w).powi(2);
        sum += s.measured_power_w;
    }
    let n = samples.len().max(1) as f64;
    let rmse_w = (ssr / n).sqrt();
    Ok(PowerFit {
        vehicle: template.params().clone(),
        parameters: Vec::new(),
        rmse_w,
        nrmse: if sum > 0.0 { rmse_w * n / sum } else { 0.0 },
        samples_used: samples.len(),
        outliers_rejected: 0,
        iterations: 0,
    })
}

/// The answer of [`fit_drag_bounded`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoundedDragFit {
    /// The drag fitted from the force balance (`mu_n` holds every coefficient, the kept ones at
    /// the template's value or 0); none when the template's drag is kept whole.
    pub fit: Option<DragFit>,
    /// The coefficients fitted.
    pub fitted: Vec<&'static str>,
    /// The coefficients kept, with the reason.
    pub kept: Vec<KeptParameter>,
}

/// Names and units of `mu1..mu3`.
const MU: [(&str, &str); 3] = [
    ("mu1_n_s_per_m", "N s/m"),
    ("mu2_n_s2_per_m2", "N s^2/m^2"),
    ("mu3_n_s3_per_m3", "N s^3/m^3"),
];

/// Drag from the force balance kept physical and identified (see the module docs);
/// `template_mu` is the drag kept when the data cannot tell.
pub fn fit_drag_bounded(
    template_mu: [f64; 3],
    mass_kg: f64,
    gravity_mps2: f64,
    samples: &[ForceSample],
    min_airspeed_mps: f64,
    outlier_sigma: f64,
) -> BoundedDragFit {
    let rows = force_rows(gravity_mps2, samples, min_airspeed_mps);
    if let Some(why) = too_little_speed(&rows, samples.len(), min_airspeed_mps) {
        return keep_template(template_mu, &why);
    }
    if let Ok(free) = fit_drag(
        mass_kg,
        gravity_mps2,
        samples,
        min_airspeed_mps,
        outlier_sigma,
    ) {
        if physical(free.mu_n) && identified(&free.mu_n, &free.std_error) {
            return BoundedDragFit {
                fit: Some(free),
                fitted: MU.iter().map(|m| m.0).collect(),
                kept: Vec::new(),
            };
        }
    }
    match non_negative_fit(mass_kg, &rows) {
        Some((fit, basis)) => {
            let mut fitted = Vec::new();
            let mut kept = Vec::new();
            for (k, (name, unit)) in MU.into_iter().enumerate() {
                if basis[k] {
                    fitted.push(name);
                } else {
                    kept.push(KeptParameter {
                        name,
                        value: 0.0,
                        unit,
                        reason: "held at 0: the free cubic was not physical (negative drag) or not identified, and the best fit with non-negative coefficients leaves it out".to_string(),
                    });
                }
            }
            BoundedDragFit {
                fit: Some(fit),
                fitted,
                kept,
            }
        }
        None => keep_template(
            template_mu,
            "no fit with non-negative, identified coefficients: the force balance does not determine the drag",
        ),
    }
}

/// Why the rows cannot identify drag: too few in forward flight, or too narrow a speed band.
fn too_little_speed(rows: &[(f64, f64)], total: usize, min_airspeed_mps: f64) -> Option<String> {
    if rows.len() < MIN_FORWARD_ROWS {
        return Some(format!(
            "only {} of {total} samples fly faster than {min_airspeed_mps} m/s (at least {MIN_FORWARD_ROWS} needed)",
            rows.len()
        ));
    }
    let mut speeds: Vec<f64> = rows.iter().map(|r| r.0).collect();
    speeds.sort_by(f64::total_cmp);
    let at = |q: f64| speeds[((speeds.len() - 1) as f64 * q).round() as usize];
    let (lo, hi) = (at(0.05), at(0.95));
    (hi - lo < MIN_DRAG_SPEED_SPAN_MPS).then(|| {
        format!(
            "the airspeeds span {lo:.1}-{hi:.1} m/s (5th-95th percentile), under {MIN_DRAG_SPEED_SPAN_MPS} m/s: too narrow to tell the drag law"
        )
    })
}

/// The template's drag, every coefficient kept for `why`.
fn keep_template(template_mu: [f64; 3], why: &str) -> BoundedDragFit {
    BoundedDragFit {
        fit: None,
        fitted: Vec::new(),
        kept: MU
            .into_iter()
            .zip(template_mu)
            .map(|((name, unit), value)| KeptParameter {
                name,
                value,
                unit,
                reason: format!("kept from the template: {why}"),
            })
            .collect(),
    }
}

/// Drag non-negative over 0-60 m/s (the check of [`crate::drag::CubicDrag::new`]).
fn physical(mu: [f64; 3]) -> bool {
    crate::drag::CubicDrag::new(mu[0], mu[1], mu[2]).is_ok()
}

/// Every coefficient's standard error at most its magnitude.
fn identified(mu: &[f64], std_error: &[f64]) -> bool {
    mu.iter()
        .zip(std_error)
        .all(|(m, se)| se.is_finite() && *se <= m.abs())
}

/// The best least-squares fit of drag per unit mass on a subset of `v, v^2, v^3` with every
/// coefficient positive and identified (the lowest residual over the seven subsets), as `mu`
/// for `mass_kg`; none when no subset qualifies.
fn non_negative_fit(mass_kg: f64, rows: &[(f64, f64)]) -> Option<(DragFit, [bool; 3])> {
    let mut best: Option<(f64, DragFit, [bool; 3])> = None;
    for mask in 1u8..8 {
        let basis = [mask & 1 != 0, mask & 2 != 0, mask & 4 != 0];
        let Some((fit, ssr)) = subset_fit(mass_kg, rows, basis) else {
            continue;
        };
        let used: Vec<usize> = (0..3).filter(|&k| basis[k]).collect();
        let ok = used
            .iter()
            .all(|&k| fit.mu_n[k] > 0.0 && fit.std_error[k] <= fit.mu_n[k]);
        if ok && best.as_ref().is_none_or(|b| ssr < b.0) {
            best = Some((ssr, fit, basis));
        }
    }
    best.map(|(_, fit, basis)| (fit, basis))
}

/// Least squares of drag per unit mass on the powers of `v` in `basis` (no outlier pass):
/// the fit as `mu` for `mass_kg` (0 outside the basis) and its sum of squared residuals.
fn subset_fit(mass_kg: f64, rows: &[(f64, f64)], basis: [bool; 3]) -> Option<(DragFit, f64)> {
    let powers: Vec<i32> = (0..3usize)
        .filter(|&k| basis[k])
        .map(|k| k as i32 + 1)
        .collect();
    let x = DMatrix::from_fn(rows.len(), powers.len(), |i, j| rows[i].0.powi(powers[j]));
    let y = DVector::from_iterator(rows.len(), rows.iter().map(|r| r.1));
    let xtx = x.transpose() * &x;
    let inv = xtx.try_inverse()?;
    let c = &inv * x.transpose() * &y;
    let ssr = (&x * &c - &y).norm_squared();
    let dof = rows.len().saturating_sub(powers.len()).max(1) as f64;
    let (mut mu_n, mut std_error) = ([0.0; 3], [0.0; 3]);
    for (j, &p) in powers.iter().enumerate() {
        let k = (p - 1) as usize;
        mu_n[k] = mass_kg * c[j];
        std_error[k] = mass_kg * (ssr / dof * inv[(j, j)]).max(0.0).sqrt();
    }
    let n = rows.len();
    Some((
        DragFit {
            mu_n,
            std_error,
            rmse_n: mass_kg * (ssr / n as f64).sqrt(),
            samples_used: n,
            outliers_rejected: 0,
        },
        ssr,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::four_term::FlightState;
    use crate::vehicle::{DiskArea, VehicleParams};

    fn template(efficiency: f64) -> Vehicle {
        Vehicle::new(VehicleParams {
            mass_kg: 1.2,
            gravity_mps2: 9.80665,
            air_density_kg_m3: 1.225,
            rotor_count: 4,
            rotor_radius_m: 0.127,
            disk_area: DiskArea::OneRotor,
            mu1_n_s_per_m: 0.1,
            mu2_n_s2_per_m2: 0.0,
            mu3_n_s3_per_m3: 0.002,
            kappa1_w_per_n1_5: 0.1,
            kappa2_w_s2_per_m2_n0_5: 0.0,
            efficiency,
            mu2_x_n_s2_per_m2: None,
            mu2_y_n_s2_per_m2: None,
            efficiency_relative_sd: None,
        })
        .unwrap()
    }

    /// Hover and gentle manoeuvres at 0-2 m/s: power from a vehicle of efficiency `eta`.
    fn hover_samples(truth: &Vehicle) -> Vec<FitSample> {
        let model = PowerModel::new(truth.clone());
        (0..400)
            .map(|i| {
                let t = f64::from(i) * 0.1;
                let state = FlightState::new(
                    1.0 + (0.3 * t).sin(),
                    0.05 * (0.7 * t).sin(),
                    0.04 * (0.5 * t).cos(),
                    0.5 * (0.2 * t).sin(),
                );
                let p = model.evaluate(&state).unwrap().electrical_w;
                FitSample::new(state, p * (1.0 + 0.01 * (1.7 * t).sin()))
            })
            .collect()
    }

    #[test]
    fn an_efficiency_above_one_is_held_at_its_bound_and_said() {
        // The log's vehicle needs less power than any efficiency <= 1 allows the template's mass.
        let truth = template(1.0).with_mass(1.0).unwrap();
        let samples = hover_samples(&truth);
        let unbounded = fit_power_model(&template(0.6), &samples, &FitOptions::known_geometry());
        assert!(
            matches!(
                unbounded,
                Err(FitError::EfficiencyAboveOne { .. }) | Err(FitError::NoForwardFlight { .. })
            ),
            "{unbounded:?}"
        );
        let b = fit_power_model_bounded(&template(0.6), &samples, &FitOptions::known_geometry())
            .unwrap();
        assert!(b.fit.vehicle.efficiency <= 1.0, "{:?}", b.fit.vehicle);
        assert!(Vehicle::new(b.fit.vehicle.clone()).is_ok());
        let names: Vec<_> = b.kept.iter().map(|k| k.name).collect();
        assert!(names.contains(&"weight_over_efficiency_n"), "{names:?}");
        // Drag and vh need forward flight these samples do not have: kept, with the reason.
        assert!(names.contains(&"mu1_over_eta_n_s_per_m"), "{names:?}");
        assert!(b.kept.iter().all(|k| !k.reason.is_empty()));
    }

    #[test]
    fn a_physical_identified_fit_is_the_unbounded_one() {
        let truth = template(0.7);
        let samples = hover_samples(&truth);
        let options = FitOptions::known_geometry()
            .without(FitParameter::Mu1)
            .without(FitParameter::Mu2)
            .without(FitParameter::Mu3);
        let free = fit_power_model(&template(0.6), &samples, &options).unwrap();
        let b = fit_power_model_bounded(&template(0.6), &samples, &options).unwrap();
        assert_eq!(b.fit, free);
        assert!(b.kept.is_empty());
    }

    #[test]
    fn nothing_left_to_fit_is_the_templates_prediction() {
        let t = template(0.6);
        let samples = hover_samples(&t);
        let mut options = FitOptions::known_geometry();
        options.free.clear();
        let b = fit_power_model_bounded(&t, &samples, &options).unwrap();
        // The samples are the template's power with a 1 % ripple: RMSE about 0.7 % of the mean.
        assert!(b.fit.nrmse > 0.003 && b.fit.nrmse < 0.01, "{}", b.fit.nrmse);
        assert_eq!(b.fit.vehicle, *t.params());
    }

    /// Force-balance rows with drag per unit mass `d(v)` at speeds `lo..hi`.
    fn force_samples(lo: f64, hi: f64, d: impl Fn(f64) -> f64) -> Vec<ForceSample> {
        (0..300)
            .map(|i| {
                let v = lo + (hi - lo) * f64::from(i % 100) / 99.0;
                // Level, unaccelerated flight east: tan(pitch) = D / (m g) with the nose east.
                let pitch = -(d(v) / 9.80665).atan();
                ForceSample {
                    vel_air_enu_mps: [v, 0.0, 0.0],
                    acc_enu_mps2: [0.0; 3],
                    roll_rad: 0.0,
                    pitch_rad: pitch,
                    yaw_rad: std::f64::consts::FRAC_PI_2,
                    mass_ratio: 1.0,
                }
            })
            .collect()
    }

    #[test]
    fn drag_with_a_negative_free_cubic_falls_back_to_non_negative_coefficients() {
        // Quadratic drag with a dip the cubic follows into negative values at low speed.
        let d = |v: f64| 0.02 * v * v - 0.015 * v + 0.001 * (v * 3.0).sin();
        let s = force_samples(1.5, 9.0, d);
        let free = fit_drag(1.0, 9.80665, &s, 1.0, 5.0).unwrap();
        assert!(!physical(free.mu_n), "{free:?}");
        let b = fit_drag_bounded([0.1, 0.0, 0.002], 1.0, 9.80665, &s, 1.0, 5.0);
        let fit = b.fit.unwrap();
        assert!(
            physical(fit.mu_n) && fit.mu_n.iter().all(|&m| m >= 0.0),
            "{fit:?}"
        );
        assert_eq!(b.fitted.len() + b.kept.len(), 3);
    }

    #[test]
    fn drag_from_a_narrow_speed_band_keeps_the_template() {
        let s = force_samples(2.0, 3.5, |v| 0.03 * v * v);
        let b = fit_drag_bounded([0.1, 0.0, 0.002], 1.0, 9.80665, &s, 1.0, 5.0);
        assert!(b.fit.is_none() && b.fitted.is_empty());
        assert_eq!(b.kept.len(), 3);
        assert!(b.kept[0].reason.contains("span"), "{}", b.kept[0].reason);
        // Hover: nothing above 1 m/s.
        let b = fit_drag_bounded(
            [0.1, 0.0, 0.002],
            1.0,
            9.80665,
            &force_samples(0.1, 0.9, |_| 0.0),
            1.0,
            5.0,
        );
        assert!(b.fit.is_none() && b.kept[0].reason.contains("faster than"));
    }

    #[test]
    fn a_physical_free_drag_fit_is_kept_whole() {
        let mu = [0.05, 0.01, 0.001];
        let s = force_samples(1.5, 14.0, |v| v * (mu[0] + v * (mu[1] + v * mu[2])));
        let b = fit_drag_bounded([0.1, 0.0, 0.002], 1.0, 9.80665, &s, 1.0, 5.0);
        let fit = b.fit.unwrap();
        for (got, want) in fit.mu_n.iter().zip(mu) {
            assert!((got - want).abs() < 1e-9, "{fit:?}");
        }
        assert_eq!(b.fitted.len(), 3);
    }
}
