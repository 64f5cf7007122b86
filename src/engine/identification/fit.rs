//! Identification: the power model of a vehicle fitted to flight logs (lag alignment,
//! Gauss-Newton on the lumped constants, drag from the force balance, pack resistance), written
//! as a vehicle file.

use std::path::PathBuf;
use std::sync::Arc;

use serde::Serialize;

use aloft_power::fit::{
    fit_body_axis_drag, fit_drag_bounded, fit_power_model_bounded, BodyAxisDragFit,
    BodyAxisRefusal, DragFit, FitParameter, ForceSample, KeptParameter, PowerFit,
};
use aloft_power::{FitOptions, FitSample};
use aloft_propulsion::fit::battery::{fit_pack_resistance, PackResistanceFit};

use crate::engine::basics::files::{check_output, escaped, write_output};
use crate::engine::basics::finite::finite;
use crate::engine::basics::logs::{FlightLogs, SkippedLog};
use crate::engine::identification::fit_quality::{judge_fit, Alignment, Envelope, FitQuality};
use crate::engine::identification::own_vehicle::{complete_vehicle, Completed, OwnVehicle};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;
use crate::identify::force_samples;
use crate::vehicle::VehicleFile;

/// A callback for long fits: Gauss-Newton iteration and residual norm (W).
pub type FitProgress = Arc<dyn Fn(u64, f64) + Send + Sync>;

/// A fit request (the options of `aloft fit`).
#[derive(Clone)]
pub struct FitRequest {
    /// The logs and how to align them.
    pub logs: FlightLogs,
    /// Lumped constants to fit (default: `k`, weight over efficiency).
    pub free: Vec<FitParameter>,
    /// Keep the template's drag instead of fitting it from the force balance.
    pub no_drag: bool,
    /// Where the fitted vehicle file is written (`None`: not written).
    pub output: Option<PathBuf>,
    /// Replace an existing `output` (a regular file or a link itself; never a device, a FIFO or
    /// a folder). Without it an existing file is kept and the fit refused before any log is read.
    pub force: bool,
    /// Called at each Gauss-Newton iteration.
    pub progress: Option<FitProgress>,
    /// What the owner states of the vehicle that the logs do not record.
    pub own: OwnVehicle,
    /// The template is the generic one (`aloft vehicles template`): its mass, rotor size and
    /// capacity are guesses that never stand in the written vehicle.
    pub generic_template: bool,
}

impl Default for FitRequest {
    fn default() -> Self {
        Self {
            logs: FlightLogs::default(),
            free: vec![FitParameter::WeightOverEfficiency],
            no_drag: false,
            output: None,
            force: false,
            progress: None,
            own: OwnVehicle::default(),
            generic_template: false,
        }
    }
}

/// A fit parameter by the name the command line uses: `k` (also `eta`, `efficiency`), `vh`,
/// `profile` (`kappa1`), `mu1`, `mu2`, `mu3`.
///
/// # Errors
/// [`Error::UnknownName`] for any other name.
pub fn fit_parameter(name: &str) -> Result<FitParameter, Error> {
    Ok(match name.trim().to_ascii_lowercase().as_str() {
        "k" | "eta" | "efficiency" => FitParameter::WeightOverEfficiency,
        "vh" => FitParameter::HoverInducedVelocity,
        "profile" | "kappa1" => FitParameter::Profile,
        "mu1" => FitParameter::Mu1,
        "mu2" => FitParameter::Mu2,
        "mu3" => FitParameter::Mu3,
        other => {
            return Err(Error::UnknownName {
                what: "--free parameter",
                name: other.to_string(),
                known: "k, vh, profile, mu1, mu2, mu3",
            })
        }
    })
}

/// One log of a fit: its alignment and pack.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogFitReport {
    /// The file.
    pub file: String,
    /// Lag of power behind motion applied, s.
    pub lag_s: f64,
    /// Correlation of power with tilt at that lag (absent when the lag was given).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lag_correlation: Option<f64>,
    /// Aligned samples.
    pub samples: usize,
    /// Motion samples left out.
    pub skipped: usize,
    /// Pack internal resistance from voltage and current, when logged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pack: Option<PackResistanceFit>,
}

/// The answer of [`fit_logs`]: the JSON of `aloft fit --format json`, and the vehicle file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitAnswer {
    /// The verdict: `good`, `usable` or `poor` (see [`crate::engine::identification::fit_quality`]).
    pub quality: FitQuality,
    /// Why, one reason a line.
    pub quality_reasons: Vec<String>,
    /// The logs left out, with their reasons.
    pub skipped_logs: Vec<SkippedLog>,
    /// Per log used.
    pub logs: Vec<LogFitReport>,
    /// The power-model fit.
    pub power: PowerFit,
    /// Drag from the force balance, when fitted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drag: Option<DragFit>,
    /// Body-axis quadratic drag (`mu2_x`, `mu2_y`) from the force balance, when the logs
    /// separate the two axes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drag_body_axes: Option<BodyAxisDragFit>,
    /// Relative standard deviation of the efficiency between the fitted logs (each log's
    /// measured energy against the fitted model's), when there are two logs or more: written to
    /// the vehicle file as `efficiency_relative_sd`, the prior of in-flight re-calibration.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub efficiency_relative_sd: Option<f64>,
    /// The constants fitted: the power fit's lumped constants and the force balance's drag
    /// coefficients.
    pub fitted_parameters: Vec<String>,
    /// The constants kept at the template's value or at a bound, with the reason: what the logs
    /// cannot identify, or what a free fit would have made unphysical (an efficiency above 1,
    /// negative drag).
    pub kept_parameters: Vec<KeptParameter>,
    /// Where the vehicle file was written (empty when it was not).
    pub output: String,
    /// The fitted vehicle file (TOML with the statistics in a comment header; not in the JSON).
    #[serde(skip)]
    pub vehicle_toml: String,
    /// Notes for the reader (e.g. why drag was not fitted; not in the JSON).
    #[serde(skip)]
    pub notes: Vec<String>,
}

/// Fit the power model of `template` to the request's logs: align each log, fit drag from the
/// force balance (unless asked not to, or asked of power), fit the free constants by
/// Gauss-Newton, fit each pack's resistance, and write the template with its `[power]` table
/// replaced.
///
/// A log that cannot be read or aligned is skipped with its reason ([`FitAnswer::skipped_logs`]);
/// the answer says how good the fit is ([`FitAnswer::quality`]).
///
/// # Errors
/// [`Error::NoUsableLog`] when no log can be used; a template without `[power]`, a fit the data
/// cannot identify, an output that cannot be written.
pub fn fit_logs(template: &Vehicle, request: &FitRequest) -> Result<FitAnswer, Error> {
    // A template without the model to fit is refused before any log is read.
    template.power_model()?;
    request.own.check()?;
    if let Some(path) = &request.output {
        check_output(path, request.force)?;
    }
    let (flights, skipped_logs) = request
        .logs
        .usable(crate::identify::AlignOptions::default().idle_power_fraction)?;
    let (used, completed) = starting_vehicle(template, request, &skipped_logs)?;
    let generic_name = request
        .generic_template
        .then(|| completed.file.name.clone());
    let template = Vehicle::from_file(completed.file)?;
    let template = &template;
    let mut vehicle = template.power_model()?.vehicle().clone();
    let mass_ratios: Vec<f64> = (0..used.logs.len())
        .map(|i| 1.0 + used.payload_kg(i) / vehicle.mass_kg())
        .collect();
    // The logs' own air: the constants are fitted in it and written for the template's density.
    let reference_density = vehicle.air_density_kg_m3();
    let (log_density, with_air) = logs_air(&flights);
    if let Some(rho) = log_density {
        vehicle = aloft_power::Vehicle::new(vehicle.params().in_air(rho))?;
    }
    let (logs, samples, forces) = fit_inputs(&flights, &mass_ratios);
    let mut notes = completed.notes;
    let mut kept = Vec::new();
    let (drag, mut drag_fitted) = drag_fit(request, &forces, &mut notes, &mut kept, &mut vehicle)?;
    let drag_body_axes = if drag.is_some() {
        body_axis_fit(&forces, &mut kept, &mut drag_fitted, &mut vehicle)?
    } else {
        None
    };
    let options = power_fit_options(request);
    let bounded = fit_power_model_bounded(&vehicle, &samples, &options)?;
    let mut power = bounded.fit;
    kept.extend(bounded.kept);
    let efficiency_relative_sd = efficiency_spread(&power, &flights, &mass_ratios)?;
    power.vehicle.efficiency_relative_sd = efficiency_relative_sd;
    if let Some(rho) = log_density {
        power.vehicle = power.vehicle.in_air(reference_density);
        notes.push(format!(
            "fitted in the logs' own air, {rho:.4} kg/m^3 (the mean of the logs' own, PX4 vehicle_air_data or ArduPilot BARO, over {} of {} logs), and written for {reference_density:.4} kg/m^3: kappa1 x {:.4}, drag x {:.4} (the fitted values above are the logs' air's)",
            with_air,
            flights.len(),
            (rho / reference_density).sqrt(),
            reference_density / rho
        ));
    }
    let mut fitted_parameters: Vec<String> = power
        .parameters
        .iter()
        .map(|p| p.name.to_string())
        .collect();
    fitted_parameters.extend(drag_fitted.iter().map(|n| n.to_string()));
    notes.extend(kept.iter().map(|k| {
        format!(
            "{} kept at {:.6e} {}: {}",
            k.name, k.value, k.unit, k.reason
        )
    }));
    let (quality, quality_reasons) = verdict(template, &power, &logs, &samples);
    let vehicle_toml = fitted_vehicle_toml(
        template.file(),
        generic_name.as_deref(),
        &power,
        drag.as_ref(),
        &logs,
        &vehicle,
        &notes,
    )?;
    if let Some(path) = &request.output {
        write_output(path, vehicle_toml.as_bytes(), request.force)?;
    }
    finite(
        FitAnswer {
            quality,
            quality_reasons,
            skipped_logs,
            logs,
            power,
            drag,
            drag_body_axes,
            efficiency_relative_sd,
            fitted_parameters,
            kept_parameters: kept,
            output: request
                .output
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_default(),
            vehicle_toml,
            notes,
        },
        "fit",
        || format!("logs {:?}", request.logs.logs),
    )
}

/// Each log's report, and the samples of every log for the power fit and the force balance,
/// each at its flight's mass ratio.
fn fit_inputs(
    flights: &[Flight],
    mass_ratios: &[f64],
) -> (Vec<LogFitReport>, Vec<FitSample>, Vec<ForceSample>) {
    let mut logs = Vec::new();
    let mut samples: Vec<FitSample> = Vec::new();
    let mut forces: Vec<ForceSample> = Vec::new();
    for ((flight, log), &mass_ratio) in flights.iter().zip(mass_ratios) {
        samples.extend(
            flight
                .samples
                .iter()
                .map(|s| FitSample { mass_ratio, ..*s }),
        );
        forces.extend(
            force_samples(log)
                .into_iter()
                .map(|f| ForceSample { mass_ratio, ..f }),
        );
        logs.push(LogFitReport {
            file: flight.source.clone(),
            lag_s: flight.lag_s,
            lag_correlation: flight.lag_correlation,
            samples: flight.samples.len(),
            skipped: flight.skipped,
            pack: pack_fit(log),
        });
    }
    (logs, samples, forces)
}

/// The power fit's options: known geometry, the request's free constants and progress.
fn power_fit_options(request: &FitRequest) -> FitOptions {
    let mut options = FitOptions::known_geometry();
    options.free = request.free.clone();
    if let Some(p) = &request.progress {
        let p = p.clone();
        options.progress = Some(Arc::new(move |i, cost| p(i, cost)));
    }
    options
}

/// How good the fit is ([`judge_fit`]), against the written vehicle's envelope.
fn verdict(
    vehicle: &Vehicle,
    power: &PowerFit,
    logs: &[LogFitReport],
    samples: &[FitSample],
) -> (FitQuality, Vec<String>) {
    let envelope = vehicle.file().airframe.as_ref().map(|a| Envelope {
        max_speed_mps: a.max_speed_mps,
        max_climb_rate_mps: a.max_climb_rate_mps,
    });
    let alignments: Vec<Alignment> = logs
        .iter()
        .map(|l| Alignment {
            file: &l.file,
            lag_s: l.lag_s,
            correlation: l.lag_correlation,
        })
        .collect();
    judge_fit(power.nrmse, &alignments, samples, envelope)
}

/// The vehicle the fit starts from and writes: the template completed from the usable logs'
/// parameters and pack and the owner's flags ([`complete_vehicle`]); from the generic template
/// it is named after its file (`-o quad.toml`: `quad`). And the usable logs.
fn starting_vehicle(
    template: &Vehicle,
    request: &FitRequest,
    skipped: &[SkippedLog],
) -> Result<(FlightLogs, Completed), Error> {
    let used = request.logs.without(skipped);
    let mut base = template.file().clone();
    if request.generic_template {
        base.name = request
            .output
            .as_ref()
            .and_then(|p| p.file_stem())
            .and_then(|s| s.to_str())
            .unwrap_or("my-quad")
            .to_string();
    }
    let completed = complete_vehicle(&base, request.generic_template, &request.own, &used)?;
    Ok((used, completed))
}

/// A log aligned for the fit, with its samples.
type Flight = (crate::identify::AlignedFlight, aloft_logs::Log);

/// The mean of the air densities the logs carry (PX4
/// `vehicle_air_data`, ArduPilot `BARO`), kg/m^3, and how many logs carry one. The constants are
/// fitted in that air and carried back to the template's density term by term
/// (`aloft_power::VehicleParams::in_air`).
fn logs_air(flights: &[Flight]) -> (Option<f64>, usize) {
    let densities: Vec<f64> = flights
        .iter()
        .filter_map(|(f, _)| f.air_density_kg_m3)
        .collect();
    let n = densities.len();
    ((n > 0).then(|| densities.iter().sum::<f64>() / n as f64), n)
}

/// Pack resistance of one log, when it has voltage and current.
fn pack_fit(log: &aloft_logs::Log) -> Option<PackResistanceFit> {
    let (mut t, mut i, mut v) = (Vec::new(), Vec::new(), Vec::new());
    for s in &log.samples {
        if let (Some(cur), Some(vol)) = (s.current_a, s.voltage_v) {
            t.push(s.time_s);
            i.push(cur);
            v.push(vol);
        }
    }
    fit_pack_resistance(&t, &i, &v).ok()
}

/// Drag from the force balance, unless asked not to or asked of power, kept physical and
/// limited to what the logs identify (`aloft_power::fit::bounded`); the fitted drag replaces
/// the vehicle's. The coefficients fitted, and the kept ones in `kept`.
fn drag_fit(
    request: &FitRequest,
    forces: &[ForceSample],
    notes: &mut Vec<String>,
    kept: &mut Vec<KeptParameter>,
    vehicle: &mut aloft_power::Vehicle,
) -> Result<(Option<DragFit>, Vec<&'static str>), Error> {
    let drag_in_free = request
        .free
        .iter()
        .any(|p| matches!(p, FitParameter::Mu1 | FitParameter::Mu2 | FitParameter::Mu3));
    if request.no_drag || drag_in_free {
        return Ok((None, Vec::new()));
    }
    if forces.is_empty() {
        notes.push(
            "the logs carry no acceleration: drag (mu1..mu3) kept from the template".to_string(),
        );
        return Ok((None, Vec::new()));
    }
    let bounded = with_drag_inputs(vehicle, forces, fit_drag_bounded);
    kept.extend(bounded.kept);
    let Some(d) = bounded.fit else {
        return Ok((None, bounded.fitted));
    };
    let mut p = vehicle.params().clone();
    [p.mu1_n_s_per_m, p.mu2_n_s2_per_m2, p.mu3_n_s3_per_m3] = d.mu_n;
    *vehicle = aloft_power::Vehicle::new(p)?;
    Ok((Some(d), bounded.fitted))
}

/// A fit of drag from the force balance: from the template's `mu` (N s/m, N s^2/m^2,
/// N s^3/m^3), mass (kg) and gravity (m/s^2) over force samples, with the lowest airspeed used
/// (m/s) and the outlier threshold (robust sigma).
type DragFitFn<T> = fn([f64; 3], f64, f64, &[ForceSample], f64, f64) -> T;

/// A drag fit from the force balance (`fit`: the scalar or the body-axis one) over `forces`,
/// started from the vehicle's drag with its mass and gravity, on the samples faster than 1 m/s,
/// outliers beyond 5 robust sigma dropped.
fn with_drag_inputs<T>(
    vehicle: &aloft_power::Vehicle,
    forces: &[ForceSample],
    fit: DragFitFn<T>,
) -> T {
    let (mu1, mu2, mu3) = vehicle.drag().coefficients();
    let (min_airspeed_mps, outlier_sigma) = (1.0, 5.0);
    fit(
        [mu1, mu2, mu3],
        vehicle.mass_kg(),
        vehicle.gravity_mps2(),
        forces,
        min_airspeed_mps,
        outlier_sigma,
    )
}

/// Relative change of the efficiency from one day to another that a fit cannot see in its own
/// logs: air density is not logged and enters the induced power as `rho^(-1/2)` (power seed
/// eq 10, `vh = sqrt(m g / (2 rho A))`); a 10 K change in air temperature between days at one
/// site (3.5 % in density) moves it by 1.7 %. Pack temperature and payload, also unlogged, add
/// to it; this is the floor.
pub const UNSEEN_DAY_RELATIVE_SD: f64 = 0.5 * 10.0 / 288.15;

/// Body-axis drag from the force balance with the vehicle's (fitted) `mu1`, `mu3`: written to
/// the vehicle when the logs separate the two axes, else the vehicle's own keys (the template's,
/// or none: the scalar law) are kept and said.
fn body_axis_fit(
    forces: &[ForceSample],
    kept: &mut Vec<KeptParameter>,
    fitted: &mut Vec<&'static str>,
    vehicle: &mut aloft_power::Vehicle,
) -> Result<Option<BodyAxisDragFit>, Error> {
    // What each axis keeps when the fit cannot tell them apart: the scalar mu2.
    let (_, mu2, _) = vehicle.drag().coefficients();
    let mut p = vehicle.params().clone();
    let answer = with_drag_inputs(vehicle, forces, fit_body_axis_drag);
    let fit = match answer {
        Ok(fit) => fit,
        Err(refusal) => {
            let reason = match refusal {
                BodyAxisRefusal::TooFewSamples { rows } => format!(
                    "too little flight along the body axes to tell them apart ({} samples forward, {} sideways faster than 1 m/s; {} each needed)",
                    rows[0], rows[1], aloft_power::fit::body_drag::MIN_AXIS_ROWS
                ),
                BodyAxisRefusal::NotSeparated { fit } => format!(
                    "the forward and sideways coefficients ({:.4} +/- {:.4}, {:.4} +/- {:.4} N s^2/m^2) do not differ by twice their uncertainty: the scalar law of eq (6)",
                    fit.mu2_n[0], fit.std_error[0], fit.mu2_n[1], fit.std_error[1]
                ),
            };
            // A template's body-axis keys that the new mu1, mu3 make unphysical are dropped.
            if aloft_power::Vehicle::new(p.clone()).is_err() {
                p.mu2_x_n_s2_per_m2 = None;
                p.mu2_y_n_s2_per_m2 = None;
                *vehicle = aloft_power::Vehicle::new(p.clone())?;
            }
            for (name, value) in [
                ("mu2_x_n_s2_per_m2", p.mu2_x_n_s2_per_m2),
                ("mu2_y_n_s2_per_m2", p.mu2_y_n_s2_per_m2),
            ] {
                kept.push(KeptParameter {
                    name,
                    value: value.unwrap_or(mu2),
                    unit: "N s^2/m^2",
                    reason: reason.clone(),
                });
            }
            return Ok(None);
        }
    };
    p.mu2_x_n_s2_per_m2 = Some(fit.mu2_n[0]);
    p.mu2_y_n_s2_per_m2 = Some(fit.mu2_n[1]);
    match aloft_power::Vehicle::new(p) {
        Ok(v) => {
            *vehicle = v;
            fitted.extend(["mu2_x_n_s2_per_m2", "mu2_y_n_s2_per_m2"]);
            Ok(Some(fit))
        }
        Err(e) => {
            for (name, value) in [
                ("mu2_x_n_s2_per_m2", fit.mu2_n[0]),
                ("mu2_y_n_s2_per_m2", fit.mu2_n[1]),
            ] {
                kept.push(KeptParameter {
                    name,
                    value,
                    unit: "N s^2/m^2",
                    reason: format!(
                        "not physical with the fitted mu1, mu3 ({e}): the scalar law of eq (6)"
                    ),
                });
            }
            Ok(None)
        }
    }
}

/// Relative uncertainty of the fitted efficiency for a flight on a day the fit has not seen.
///
/// Two parts, added in quadrature: the spread between the fitted logs of the efficiency each
/// implies against the fitted model (`eta_i = eta E_predicted,i / E_measured,i`, as
/// `sd(ln eta_i)`), and [`UNSEEN_DAY_RELATIVE_SD`], the day-to-day change that logs of one or two
/// days cannot show. `None` with fewer than two logs.
fn efficiency_spread(
    power: &PowerFit,
    flights: &[Flight],
    mass_ratios: &[f64],
) -> Result<Option<f64>, Error> {
    if flights.len() < 2 {
        return Ok(None);
    }
    let vehicle = aloft_power::Vehicle::new(power.vehicle.clone())?;
    let mut logs = Vec::with_capacity(flights.len());
    for ((f, _), r) in flights.iter().zip(mass_ratios) {
        // Each flight at its own mass.
        let model = aloft_power::PowerModel::new(vehicle.with_mass(vehicle.mass_kg() * r)?);
        let predicted = crate::identify::predict(&model, f)?;
        let measured: Vec<f64> = f.samples.iter().map(|s| s.measured_power_w).collect();
        let ratio = aloft_core::trapezoid(&f.times_s, &predicted)
            / aloft_core::trapezoid(&f.times_s, &measured);
        if ratio.is_finite() && ratio > 0.0 {
            logs.push(ratio.ln());
        }
    }
    if logs.len() < 2 {
        return Ok(None);
    }
    let n = logs.len() as f64;
    let mean = logs.iter().sum::<f64>() / n;
    let var = logs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    Ok(Some(var.sqrt().hypot(UNSEEN_DAY_RELATIVE_SD).min(1.0)))
}

/// The fitted vehicle file: the template with its `[power]` table replaced and the statistics in
/// a comment header.
fn fitted_vehicle_toml(
    template: &VehicleFile,
    generic_name: Option<&str>,
    fit: &PowerFit,
    drag: Option<&DragFit>,
    logs: &[LogFitReport],
    vehicle: &aloft_power::Vehicle,
    notes: &[String],
) -> Result<String, Error> {
    let mut fitted = template.clone();
    let fitted_by = format!(
        "fitted by aloft fit from {} log(s), RMSE {:.1} W, NRMSE {:.2} %",
        logs.len(),
        fit.rmse_w,
        100.0 * fit.nrmse
    );
    match generic_name {
        // The generic template's name and words are not the owner's vehicle.
        Some(name) => {
            fitted.name = name.to_string();
            fitted.description = format!("A multirotor {fitted_by}");
        }
        None => {
            fitted.name = format!("{}-fitted", template.name);
            fitted.description = format!("{} ({fitted_by})", template.description);
        }
    }
    fitted.power = Some(fit.vehicle.clone());
    let mut text = String::new();
    text.push_str(
        "# Written by `aloft fit`. Fitted constants (lumped; see aloft_power::fit::power):\n",
    );
    for p in &fit.parameters {
        text.push_str(&format!(
            "#   {} = {:.6e} +/- {:.2e} {}\n",
            p.name, p.value, p.std_error, p.unit
        ));
    }
    if let Some(d) = drag {
        text.push_str(&format!(
            "# Drag from the force balance ({} samples, mass {} kg): mu = {:.4}, {:.5}, {:.6} (+/- {:.2e}, {:.2e}, {:.2e})\n",
            d.samples_used, vehicle.mass_kg(), d.mu_n[0], d.mu_n[1], d.mu_n[2], d.std_error[0], d.std_error[1], d.std_error[2]
        ));
    }
    for l in logs {
        text.push_str(&format!(
            "# Log {}: lag {:.2} s, {} samples\n",
            escaped(&l.file),
            l.lag_s,
            l.samples
        ));
    }
    for n in notes {
        // A note may quote a file name: one comment line whatever it holds.
        text.push_str(&format!("# Note: {}\n", escaped(n)));
    }
    let body = toml::to_string(&fitted).map_err(|e| Error::VehicleFormat {
        origin: fitted.name.clone(),
        message: e.to_string(),
    })?;
    text.push_str(&body);
    Ok(text)
}
