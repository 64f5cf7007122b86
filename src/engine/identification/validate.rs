//! Validation: a vehicle's power model against measured power, per flight and per airspeed band
//! in the layout of the power seed's Table I, with the whole-flight energy error and, optionally,
//! an in-flight re-calibration of the efficiency.

use serde::Serialize;

use crate::engine::basics::finite::finite;
use crate::engine::basics::logs::{FlightLogs, SkippedLog};
use crate::engine::conditions::air::{log_air, AirInput};
use crate::engine::identification::fit_quality::{
    judge_flight, Alignment, FitQuality, FlightJudged,
};
use crate::engine::identification::replay::compared_airborne;
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;
use crate::identify::{
    predict, validate_flight, AblationRow, AlignedFlight, FlightValidation, AIRSPEED_BANDS,
};

/// A validation request (the options of `aloft validate`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ValidateRequest {
    /// The logs and how to align them.
    pub logs: FlightLogs,
    /// The pack the flights carried, part of the take-off mass (default: the vehicle's default
    /// pack).
    pub battery: Option<String>,
    /// The payload the flights carried, kg, part of the take-off mass.
    pub payload_kg: f64,
    /// Re-estimate the efficiency from the first this many seconds of each flight, s.
    pub calibrate_first_s: Option<f64>,
    /// Also return the measured and predicted power of every flight (for a plot).
    pub series: bool,
    /// The day's air for every flight (default: each log's own density where it has one, else
    /// the vehicle file's).
    pub air: AirInput,
}

/// Mean over flights of one Table I cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeanBand {
    /// Airspeed band, m/s.
    pub airspeed_band_mps: &'static str,
    /// Flights with samples in the band.
    pub flights: usize,
    /// Mean NRMSE, percent (absent when no flight has samples there).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nrmse_percent: Option<f64>,
}

/// Mean over flights of one Table I row.
pub type MeanRow = AblationRow<MeanBand>;

/// The JSON of `aloft validate --format json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ValidateReport {
    /// Vehicle name.
    pub vehicle: String,
    /// The take-off mass the model flew, kg (airframe + pack + payload, or a fitted vehicle's
    /// `[power]` mass + payload).
    pub takeoff_mass_kg: f64,
    /// That mass and what it is made of, in words (not part of the JSON).
    #[serde(skip)]
    pub mass: String,
    /// The verdict on the whole: its worst flight's (`good`, `usable`, `poor`).
    pub quality: FitQuality,
    /// Why: each flight's reasons after its file name.
    pub quality_reasons: Vec<String>,
    /// The logs left out (one that never flew, one too short to align, ...), with their
    /// reasons: the rule of `aloft fit`.
    pub skipped_logs: Vec<SkippedLog>,
    /// Per flight.
    pub flights: Vec<FlightValidation>,
    /// Mean NRMSE over the flights, per dropped term and airspeed band (Table I layout).
    pub table_i: Vec<MeanRow>,
}

/// Measured and predicted power of one flight: name, times (s), measured (W), predicted (W).
pub type PowerSeries = (String, Vec<f64>, Vec<f64>, Vec<f64>);

/// The answer of [`validate_logs`]: the report and, when asked, the power series.
#[derive(Debug, Clone, PartialEq)]
pub struct ValidateAnswer {
    /// The report (the JSON).
    pub report: ValidateReport,
    /// Per flight, when [`ValidateRequest::series`] is set.
    pub series: Vec<PowerSeries>,
}

/// Validate `vehicle`'s power model, at the take-off mass of the request's pack and payload
/// ([`Vehicle::takeoff_mass`]), on the request's logs: each over its airborne time, the seconds
/// `aloft mission --replay` books ([`compared_airborne`]), with a verdict per flight and on the
/// whole ([`judge_flight`]). A log that cannot be used (one that never flew, one too short to
/// align) is left out with its reason, as `aloft fit` does ([`FlightLogs::usable`]).
///
/// # Errors
/// [`Error::NoUsableLog`] when no log can be used; a vehicle without `[power]`, a take-off mass
/// the vehicle refuses, a calibration window that does not fit a flight.
pub fn validate_logs(
    vehicle: &Vehicle,
    request: &ValidateRequest,
) -> Result<ValidateAnswer, Error> {
    let (_, mass) = vehicle.power_model_with(request.battery.as_deref(), request.payload_kg)?;
    // Every paired sample is kept: the airborne spans are the flight's ground time here, not
    // the idle power the fit leaves out.
    let (flights, mut skipped_logs) = request.logs.usable(0.0)?;
    let used = request.logs.without(&skipped_logs);
    let mut results = Vec::with_capacity(flights.len());
    let mut series = Vec::new();
    for (i, (f, log)) in flights.iter().enumerate() {
        let payload_kg = request.payload_kg + used.payload_kg(i);
        let Some(result) = validate_one(vehicle, request, (f, log), payload_kg)? else {
            skipped_logs.push(SkippedLog {
                file: f.source.clone(),
                reason: Error::NoAirborneTime {
                    origin: f.source.clone(),
                }
                .to_string(),
            });
            continue;
        };
        if request.series {
            series.push(power_series(vehicle, request, f, payload_kg)?);
        }
        results.push(result);
    }
    if results.is_empty() {
        let reasons: Vec<&str> = skipped_logs.iter().map(|s| s.reason.as_str()).collect();
        return Err(Error::NoUsableLog {
            reasons: reasons.join("; "),
        });
    }
    let table_i = mean_table_i(&results);
    let (quality, quality_reasons) = overall(&results);
    let report = ValidateReport {
        vehicle: vehicle.name().to_string(),
        takeoff_mass_kg: mass.total_kg,
        mass: mass.describe(),
        quality,
        quality_reasons,
        skipped_logs,
        flights: results,
        table_i,
    };
    let report = finite(report, "validate", || {
        format!("logs {:?}", request.logs.logs)
    })?;
    Ok(ValidateAnswer { report, series })
}

/// One flight validated in its own air (the given day, else the log's, else the vehicle
/// file's) and at its own mass (the request's payload and the log's own,
/// `FILE:payload_kg=KG`), over its airborne time, with its verdict; `None` when it has no
/// airborne time where motion and power are logged.
fn validate_one(
    vehicle: &Vehicle,
    request: &ValidateRequest,
    (f, log): (&AlignedFlight, &aloft_logs::Log),
    payload_kg: f64,
) -> Result<Option<FlightValidation>, Error> {
    let air = log_air(&request.air, f.air_density_kg_m3, vehicle)?;
    let in_air = vehicle.in_air(air.air_density_kg_m3)?;
    let (model, _) = in_air.power_model_with(request.battery.as_deref(), payload_kg)?;
    let flown = (request.battery.as_deref(), payload_kg, request.logs.aoa);
    let airborne = compared_airborne(&in_air, flown, log, f.lag_s)?;
    if airborne.spans.is_empty() {
        return Ok(None);
    }
    let measured_wh = |a: f64, b: f64| airborne.measured_wh(a, b);
    let mut result = validate_flight(
        &model,
        f,
        request.calibrate_first_s,
        &airborne.spans,
        &measured_wh,
    )?;
    result.density_source = air.density_source;
    (result.quality, result.quality_reasons) = judge_flight(&FlightJudged {
        alignment: Alignment {
            file: &result.file,
            lag_s: result.lag_s,
            correlation: result.lag_correlation,
        },
        nrmse_percent: result.nrmse_percent,
        constant_nrmse_percent: result.baseline_nrmse_percent,
        samples: result.samples,
        compared_s: result.duration_s,
        airborne_s: result.airborne_s,
    });
    Ok(Some(result))
}

/// The measured and predicted power of a flight, for the plot.
fn power_series(
    vehicle: &Vehicle,
    request: &ValidateRequest,
    f: &AlignedFlight,
    payload_kg: f64,
) -> Result<PowerSeries, Error> {
    let air = log_air(&request.air, f.air_density_kg_m3, vehicle)?;
    let (model, _) = vehicle
        .in_air(air.air_density_kg_m3)?
        .power_model_with(request.battery.as_deref(), payload_kg)?;
    let predicted = predict(&model, f)?;
    let measured = f.samples.iter().map(|s| s.measured_power_w).collect();
    Ok((f.source.clone(), f.times_s.clone(), measured, predicted))
}

/// The verdict on the whole: the worst flight's, and every flight's reasons after its name.
fn overall(results: &[FlightValidation]) -> (FitQuality, Vec<String>) {
    let quality = results
        .iter()
        .map(|f| f.quality)
        .max()
        .unwrap_or(FitQuality::Good);
    let mut reasons = Vec::new();
    for f in results {
        let name = f.file.rsplit('/').next().unwrap_or(&f.file);
        for r in &f.quality_reasons {
            // The alignment's reasons already start with the file's name.
            if r.starts_with(&format!("{name}: ")) {
                reasons.push(r.clone());
            } else {
                reasons.push(format!("{name}: {r}"));
            }
        }
    }
    (quality, reasons)
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// The Table I cells averaged over the flights.
fn mean_table_i(results: &[FlightValidation]) -> Vec<MeanRow> {
    let Some(first) = results.first() else {
        return Vec::new();
    };
    first
        .table_i
        .iter()
        .enumerate()
        .map(|(row, r)| MeanRow {
            dropped_term: r.dropped_term,
            nrmse_percent: mean(results.iter().map(|f| f.table_i[row].nrmse_percent))
                .unwrap_or(f64::NAN),
            bands: AIRSPEED_BANDS
                .iter()
                .enumerate()
                .map(|(b, &(label, _, _))| {
                    let cells: Vec<f64> = results
                        .iter()
                        .filter_map(|f| f.table_i[row].bands[b].nrmse_percent)
                        .collect();
                    MeanBand {
                        airspeed_band_mps: label,
                        flights: cells.len(),
                        nrmse_percent: mean(cells.into_iter()),
                    }
                })
                .collect(),
        })
        .collect()
}
