//! From flight logs to the power model: time alignment of power with motion, fit samples, and
//! validation in the layout of the power seed's Table I.
//!
//! # Alignment
//! Logged power often lags the motion channels (in the KAIST logs by about 3 s). The lag is
//! estimated by cross-correlating measured power with the tilt of the thrust axis
//! (`acos(cos(roll) cos(pitch))`, which tracks thrust demand) on a common 0.1 s grid, searching
//! +-`max_lag_s` ([`aloft_logs::estimate_lag_s`]). Each motion sample at time `t` is then paired
//! with the measured power at `t + lag` (linear interpolation); samples whose partner falls outside
//! the log are left out.
//!
//! # Ground time
//! Logs that include take-off and landing have stretches on the ground with the motors idle or off.
//! Samples whose measured power is below `idle_power_fraction` (default 0.25) of the flight's median
//! are left out of a fit and counted ([`AlignedFlight::idle`]). `aloft validate` keeps them all
//! and compares over the log's airborne time instead ([`validate_flight`]: the seconds `aloft
//! mission --replay` books, so that one flight has one measured energy).
//!
//! # Flight state from a log
//! Air-relative velocity = ground velocity - wind when the log carries wind, otherwise the ground
//! velocity (no wind: an assumption, reported in docs/validation.md). Airspeed is its horizontal
//! norm (the paper's level-flight inputs), climb rate its vertical component, the angle of attack
//! the exact geometry with the air direction `course - yaw` from the nose.

use aloft_logs::sample::Attitude;
use aloft_logs::{Log, Sample};
use aloft_power::{
    fit::FitSample, metrics, AoaInput, FlightState, ModelOptions, PowerModel, Term, Terms,
};
use serde::Serialize;

use crate::error::Error;

/// Options of [`align_flight`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlignOptions {
    /// Search window of the lag estimate, s.
    pub max_lag_s: f64,
    /// Use this lag instead of estimating it, s.
    pub lag_s: Option<f64>,
    /// Samples whose measured power is below this fraction of the flight's median are taken as
    /// on the ground with the motors idle or off (logs that include take-off and landing) and
    /// left out: the model describes flight, not a vehicle standing on its legs.
    pub idle_power_fraction: f64,
}

impl Default for AlignOptions {
    fn default() -> Self {
        Self {
            max_lag_s: 10.0,
            lag_s: None,
            idle_power_fraction: 0.25,
        }
    }
}

/// A flight with power paired to motion.
#[derive(Debug, Clone)]
pub struct AlignedFlight {
    /// The log's source (file).
    pub source: String,
    /// Lag of power behind motion applied, s.
    pub lag_s: f64,
    /// Correlation of power with tilt at that lag (`None` when the lag was given).
    pub lag_correlation: Option<f64>,
    /// Motion time of each sample, s from the start of the log.
    pub times_s: Vec<f64>,
    /// Flight state and measured power at `t + lag`.
    pub samples: Vec<FitSample>,
    /// Motion samples left out (no velocity/attitude, tilt of 90 deg or more, no power partner).
    pub skipped: usize,
    /// Samples left out as on the ground (measured power below the idle fraction of the median).
    pub idle: usize,
    /// The log's own mean air density (PX4 `vehicle_air_data.rho`), kg/m^3, when it has one.
    pub air_density_kg_m3: Option<f64>,
}

fn interpolate(times: &[f64], values: &[f64], t: f64) -> Option<f64> {
    if times.is_empty() || t < times[0] || t > times[times.len() - 1] {
        return None;
    }
    let i = times.partition_point(|&x| x <= t);
    if i == 0 {
        return Some(values[0]);
    }
    if i >= times.len() {
        return Some(values[times.len() - 1]);
    }
    let (t0, t1) = (times[i - 1], times[i]);
    let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    Some(values[i - 1] + w * (values[i] - values[i - 1]))
}

fn motion(s: &Sample) -> Option<(FlightState, f64)> {
    let att = s.attitude?;
    let state = motion_state(s.vel_enu_mps?, &att, s.wind_enu_mps.unwrap_or([0.0; 3]))?;
    let tilt_cos = att.roll_rad.cos() * att.pitch_rad.cos();
    Some((state, tilt_cos.clamp(-1.0, 1.0).acos()))
}

/// The model's flight state from a ground velocity, attitude and wind (ENU, m/s): the air
/// velocity's horizontal speed and course against the heading, its vertical speed the climb.
/// `None` for a vehicle tilted 90 deg or more, or a speed that is not finite.
pub(crate) fn motion_state(vel: [f64; 3], att: &Attitude, wind: [f64; 3]) -> Option<FlightState> {
    let air = [vel[0] - wind[0], vel[1] - wind[1], vel[2] - wind[2]];
    let speed = air[0].hypot(air[1]);
    // Course over the air, clockwise from north (ENU: x east, y north).
    let course = air[0].atan2(air[1]);
    let state = FlightState {
        airspeed_mps: speed,
        roll_rad: att.roll_rad,
        pitch_rad: att.pitch_rad,
        climb_rate_mps: air[2],
        aoa: AoaInput::Geometric {
            air_direction_rad: course - att.yaw_rad,
        },
    };
    let tilt_cos = att.roll_rad.cos() * att.pitch_rad.cos();
    (tilt_cos > 1e-6 && state.airspeed_mps.is_finite()).then_some(state)
}

/// Pair power with motion in `log` (see the module docs): the power series, the motion series,
/// the lag between them (given or estimated), each motion sample paired with the power at its
/// time plus the lag, and the idle samples dropped.
pub fn align_flight(log: &Log, options: &AlignOptions) -> Result<AlignedFlight, Error> {
    let source = log.source.clone();
    let power = power_series(log)?;
    let (motion, mut skipped) = motion_series(log)?;
    let (lag_s, lag_correlation) = match options.lag_s {
        Some(l) => (l, None),
        None => {
            let est = estimate_lag(log, &power, &motion, options.max_lag_s)?;
            (est.lag_s, Some(est.correlation))
        }
    };
    let (times_s, samples, unpaired) = pair_with_power(&power, &motion, lag_s);
    skipped += unpaired;
    let (times_s, samples, idle) = drop_idle(times_s, samples, options.idle_power_fraction);
    Ok(AlignedFlight {
        source,
        lag_s,
        lag_correlation,
        idle,
        times_s,
        samples,
        skipped,
        air_density_kg_m3: None,
    })
}

/// Electrical power against time, where both are finite: (times, watts), at least two samples,
/// in time order.
struct PowerSeries {
    times_s: Vec<f64>,
    power_w: Vec<f64>,
}

/// Flight states against time, with the tilt of each (for the lag estimate).
struct MotionSeries {
    times_s: Vec<f64>,
    states: Vec<FlightState>,
    tilt_rad: Vec<f64>,
}

/// The times and electrical power (V x I) of the log's samples where both are logged and finite,
/// in the log's order.
pub(crate) fn power_samples(log: &Log) -> (Vec<f64>, Vec<f64>) {
    log.samples
        .iter()
        .filter_map(|s| s.electrical_power_w().map(|p| (s.time_s, p)))
        .filter(|(t, p)| t.is_finite() && p.is_finite())
        .unzip()
}

/// The log's electrical power series.
fn power_series(log: &Log) -> Result<PowerSeries, Error> {
    let (times_s, power_w) = power_samples(log);
    if times_s.len() < 2 {
        return Err(Error::NoPower {
            origin: log.source.clone(),
        });
    }
    if times_s.windows(2).any(|w| w[1] < w[0]) {
        return Err(Error::NotMonotonic {
            origin: log.source.clone(),
        });
    }
    Ok(PowerSeries { times_s, power_w })
}

/// The log's flight states, and how many samples gave none.
fn motion_series(log: &Log) -> Result<(MotionSeries, usize), Error> {
    let mut m = MotionSeries {
        times_s: Vec::new(),
        states: Vec::new(),
        tilt_rad: Vec::new(),
    };
    let mut skipped = 0;
    for s in &log.samples {
        match motion(s) {
            Some((state, tilt)) if s.time_s.is_finite() => {
                m.times_s.push(s.time_s);
                m.states.push(state);
                m.tilt_rad.push(tilt);
            }
            _ => skipped += 1,
        }
    }
    if m.times_s.len() < 2 {
        return Err(Error::NoMotion {
            origin: log.source.clone(),
        });
    }
    if m.times_s.windows(2).any(|w| w[1] < w[0]) {
        return Err(Error::NotMonotonic {
            origin: log.source.clone(),
        });
    }
    Ok((m, skipped))
}

/// The lag of power behind motion, from the cross-correlation of power and tilt on a common
/// 0.1 s grid over the overlap of the two channels.
fn estimate_lag(
    log: &Log,
    power: &PowerSeries,
    motion: &MotionSeries,
    max_lag_s: f64,
) -> Result<aloft_logs::LagEstimate, Error> {
    let (pt, mt) = (&power.times_s, &motion.times_s);
    let dt = 0.1;
    let start = pt[0].max(mt[0]);
    let end = pt[pt.len() - 1].min(mt[mt.len() - 1]);
    let n = ((end - start) / dt).floor().max(0.0);
    // The grid covers the overlap of the channels; one whose span is far longer than the
    // samples could fill (a time stamp off by years) is refused before it is built.
    let limit = 10.0 * (pt.len() + mt.len()) as f64 + 1e5;
    if n > limit {
        return Err(Error::SparseTime {
            origin: log.source.clone(),
            span_s: end - start,
            samples: pt.len().max(mt.len()),
        });
    }
    let grid: Vec<f64> = (0..n as usize).map(|i| start + i as f64 * dt).collect();
    let p: Vec<f64> = grid
        .iter()
        .filter_map(|&t| interpolate(pt, &power.power_w, t))
        .collect();
    let m: Vec<f64> = grid
        .iter()
        .filter_map(|&t| interpolate(mt, &motion.tilt_rad, t))
        .collect();
    aloft_logs::estimate_lag_s(&p, &m, dt, max_lag_s).map_err(|e| match e {
        // A window the series are too short for: said with the overlap, not as a bad setting.
        aloft_logs::LogError::InvalidArgument {
            name: "max_lag_s", ..
        } if max_lag_s.is_finite() && max_lag_s >= 0.0 => Error::TooShortForLag {
            origin: log.source.clone(),
            overlap_s: p.len() as f64 * dt,
            max_lag_s,
        },
        e => Error::Log {
            origin: log.source.clone(),
            source: Box::new(e),
        },
    })
}

/// Each flight state with the power at its time plus the lag, where there is one and it is not
/// negative (a motor stopped in the air draws 0 W, which is measured, not missing); and how many
/// states had none.
fn pair_with_power(
    power: &PowerSeries,
    motion: &MotionSeries,
    lag_s: f64,
) -> (Vec<f64>, Vec<FitSample>, usize) {
    let mut times_s = Vec::with_capacity(motion.times_s.len());
    let mut samples = Vec::with_capacity(motion.times_s.len());
    let mut unpaired = 0;
    for (&t, state) in motion.times_s.iter().zip(&motion.states) {
        match interpolate(&power.times_s, &power.power_w, t + lag_s) {
            Some(p) if p >= 0.0 => {
                times_s.push(t);
                samples.push(FitSample::new(*state, p));
            }
            _ => unpaired += 1,
        }
    }
    (times_s, samples, unpaired)
}

/// The samples at or above `idle_power_fraction` of the median power (and above 0 W), and how
/// many were below; a fraction of 0 keeps every sample (`aloft validate`, whose ground time is
/// the log's airborne spans).
fn drop_idle(
    times_s: Vec<f64>,
    samples: Vec<FitSample>,
    idle_power_fraction: f64,
) -> (Vec<f64>, Vec<FitSample>, usize) {
    // The median of the powers drawn (a stopped motor's 0 W is idle, not part of the flight's
    // power).
    let mut sorted: Vec<f64> = samples
        .iter()
        .map(|s| s.measured_power_w)
        .filter(|p| *p > 0.0)
        .collect();
    sorted.sort_by(f64::total_cmp);
    let threshold = idle_power_fraction * sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let keep = |p: f64| idle_power_fraction <= 0.0 || (p > 0.0 && p >= threshold);
    let before = samples.len();
    let (times_s, samples): (Vec<f64>, Vec<FitSample>) = times_s
        .into_iter()
        .zip(samples)
        .filter(|(_, s)| keep(s.measured_power_w))
        .unzip();
    let idle = before - samples.len();
    (times_s, samples, idle)
}

/// Force-balance samples of a log for [`aloft_power::fit_drag`]: air velocity (ground velocity
/// minus wind, when logged), acceleration and attitude, where all are present.
pub fn force_samples(log: &Log) -> Vec<aloft_power::ForceSample> {
    log.samples
        .iter()
        .filter_map(|s| {
            let vel = s.vel_enu_mps?;
            let acc = s.acc_enu_mps2?;
            let att = s.attitude?;
            let wind = s.wind_enu_mps.unwrap_or([0.0; 3]);
            Some(aloft_power::ForceSample {
                vel_air_enu_mps: [vel[0] - wind[0], vel[1] - wind[1], vel[2] - wind[2]],
                acc_enu_mps2: acc,
                roll_rad: att.roll_rad,
                pitch_rad: att.pitch_rad,
                yaw_rad: att.yaw_rad,
                mass_ratio: 1.0,
            })
        })
        .collect()
}

/// NRMSE of one model variant in one airspeed band.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BandNrmse {
    /// Airspeed band, m/s, as `"low-high"` (the last open: `"9-"`).
    pub airspeed_band_mps: &'static str,
    /// Samples in the band.
    pub samples: usize,
    /// NRMSE (normalised by the band's mean measured power), percent; omitted when empty.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nrmse_percent: Option<f64>,
}

/// One row of the Table I layout: the model with one term dropped (or none), its NRMSE over the
/// whole flight and per airspeed band `B`: one flight's [`BandNrmse`], or the mean over flights
/// of `aloft validate` ([`crate::engine::MeanBand`], in [`crate::engine::MeanRow`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AblationRow<B = BandNrmse> {
    /// The dropped term: `none`, `parasitic`, `profile`, `induced` or `climb`.
    pub dropped_term: &'static str,
    /// NRMSE over the whole flight (over flights: its mean), percent.
    pub nrmse_percent: f64,
    /// NRMSE per airspeed band.
    pub bands: Vec<B>,
}

/// The in-flight re-estimate of the efficiency from the start of the flight.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Calibration {
    /// Length of the calibration window, s.
    pub calibrate_s: f64,
    /// The efficiency applied after the window: the window's estimate shrunk toward the
    /// fitted efficiency by the uncertainty of each ([`crate::recalibration`]).
    pub efficiency: f64,
    /// The efficiency from the window alone (measured over predicted energy).
    pub window_efficiency: f64,
    /// Weight of the window's estimate (0: the fitted efficiency kept, 1: the window's taken
    /// alone, as without a prior spread in the vehicle file).
    pub window_weight: f64,
    /// Relative standard error of the window's estimate (effective sample size of the
    /// residuals' autocorrelation).
    pub window_relative_sd: f64,
    /// Measured energy after the window, Wh.
    pub measured_energy_wh: f64,
    /// Predicted energy after the window, Wh.
    pub predicted_energy_wh: f64,
    /// Energy error after the window, percent.
    pub energy_error_percent: f64,
    /// Instantaneous-power RMSE after the window, W.
    pub rmse_w: f64,
    /// RMSE of the best constant (the mean measured power after the window, which no forecast
    /// can know), W.
    pub best_constant_rmse_w: f64,
}

/// Longest stretch of a span without a validated sample that the comparison bridges, s: a
/// 10 Hz log's samples are 0.1 s apart, and at touch-down the motors stop (no power to pair)
/// a second or two before the autopilot's land detector says landed; a longer hole, where the
/// log has no velocity or attitude to pair with its power, is left out of the seconds compared.
pub const MAX_BRIDGE_S: f64 = 3.0;

/// Validation of the model on one flight.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlightValidation {
    /// The log file.
    pub file: String,
    /// The airborne time compared, s: the airborne time where the log has samples to compare
    /// (no hole longer than [`MAX_BRIDGE_S`]).
    pub duration_s: f64,
    /// The airborne time within the span where motion and power are logged, s (what `aloft
    /// mission --replay` books as `airborne_s`).
    pub airborne_s: f64,
    /// Lag of power behind motion used, s.
    pub lag_s: f64,
    /// Correlation of power with tilt at that lag (absent when the lag was given).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lag_correlation: Option<f64>,
    /// Measured energy over the airborne time compared (integral of V x I), Wh: the same as
    /// `aloft mission --replay`'s `measured_airborne_energy_wh`.
    pub measured_energy_wh: f64,
    /// Model energy over the same time (the model's power at the logged attitude of each sample,
    /// linear between samples), Wh.
    pub predicted_energy_wh: f64,
    /// `(predicted - measured) / measured`, percent.
    pub energy_error_percent: f64,
    /// NRMSE of the full model (normalised by the mean measured power), percent.
    pub nrmse_percent: f64,
    /// NRMSE of the flight's own mean power as the estimate, percent.
    pub baseline_nrmse_percent: f64,
    /// Samples used.
    pub samples: usize,
    /// Table I rows: full model and each term dropped, per airspeed band.
    pub table_i: Vec<AblationRow>,
    /// With a calibration window: the re-estimated efficiency and the errors after it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub calibration: Option<Calibration>,
    /// The density the model flew this flight in, kg/m^3 (the given air, else the log's own,
    /// else the vehicle file's).
    pub air_density_kg_m3: f64,
    /// Where it came from (`given`, `log`, `isa`, `vehicle_file`).
    pub density_source: crate::engine::AirSource,
    /// The verdict on this flight: `good`, `usable` or `poor` (the fit's rules, and `poor`
    /// where the model loses to a constant at the flight's mean power).
    pub quality: crate::engine::FitQuality,
    /// Why, one reason a line.
    pub quality_reasons: Vec<String>,
}

/// Airspeed bands of the Table I layout, centred on the paper's hover, 2, 4, 6, 8 m/s.
pub const AIRSPEED_BANDS: [(&str, f64, f64); 6] = [
    ("0-1", 0.0, 1.0),
    ("1-3", 1.0, 3.0),
    ("3-5", 3.0, 5.0),
    ("5-7", 5.0, 7.0),
    ("7-9", 7.0, 9.0),
    ("9-", 9.0, f64::INFINITY),
];

/// Energy of a power series, Wh (the planner's trapezoidal rule).
fn trapezoid_wh(times: &[f64], power: &[f64]) -> f64 {
    aloft_core::trapezoid(times, power) / 3600.0
}

fn nrmse_percent(est: &[f64], meas: &[f64]) -> Option<f64> {
    metrics::nrmse(est, meas, metrics::Normalisation::Mean)
        .ok()
        .map(|x| 100.0 * x)
}

/// Predicted electrical power of every sample; samples the model rejects are reported as errors.
pub fn predict(model: &PowerModel, flight: &AlignedFlight) -> Result<Vec<f64>, Error> {
    flight
        .samples
        .iter()
        .enumerate()
        .map(|(i, s)| {
            model
                .evaluate(&s.state)
                .map(|p| p.electrical_w)
                .map_err(|e| Error::BadRow {
                    origin: flight.source.clone(),
                    row: i + 1,
                    source: e,
                })
        })
        .collect()
}

/// The samples of `flight` inside `spans` (motion time).
fn within(flight: &AlignedFlight, spans: &[(f64, f64)]) -> AlignedFlight {
    let inside = |t: f64| spans.iter().any(|(a, b)| t >= *a && t <= *b);
    let (times_s, samples) = flight
        .times_s
        .iter()
        .zip(&flight.samples)
        .filter(|(t, _)| inside(**t))
        .map(|(t, s)| (*t, *s))
        .unzip();
    AlignedFlight {
        times_s,
        samples,
        source: flight.source.clone(),
        ..*flight
    }
}

/// The parts of `spans` that `times` (sorted) cover: each span cut to within
/// `MAX_BRIDGE_S / 2` of a sample, so that a hole longer than [`MAX_BRIDGE_S`] is left out.
fn covered(spans: &[(f64, f64)], times: &[f64]) -> Vec<(f64, f64)> {
    let h = 0.5 * MAX_BRIDGE_S;
    let mut out: Vec<(f64, f64)> = Vec::new();
    for &(a, b) in spans {
        let mut current: Option<(f64, f64)> = None;
        for &t in times.iter().filter(|t| **t >= a - h && **t <= b + h) {
            let (lo, hi) = ((t - h).max(a), (t + h).min(b));
            current = match current {
                Some((s, e)) if lo <= e => Some((s, e.max(hi))),
                Some(done) => {
                    out.push(done);
                    Some((lo, hi))
                }
                None => Some((lo, hi)),
            };
        }
        out.extend(current.filter(|(s, e)| e > s));
    }
    out
}

/// Integral of the piecewise-linear `values(times)` over `[a, b]`, each end value held beyond
/// the samples (a span may start a sample before the first with an attitude), J for W.
fn held_integral(times: &[f64], values: &[f64], a: f64, b: f64) -> f64 {
    let at = |t: f64| {
        interpolate(times, values, t).unwrap_or(if t < times[0] {
            values[0]
        } else {
            values[values.len() - 1]
        })
    };
    aloft_core::trapezoid_window(times, values, (a, b), at)
}

/// Validate `model` on `flight` over its airborne `spans` (motion time), where its samples
/// cover them ([`MAX_BRIDGE_S`]): the model's energy there against `measured_wh(a, b)`, the
/// energy measured from `a` to `b` (Wh); optionally re-estimating the efficiency from the
/// first `calibrate_first_s` seconds (as a ground station would in flight). The verdict is
/// left at `good` without reasons for the caller to judge ([`crate::engine::FitQuality`]).
pub fn validate_flight(
    model: &PowerModel,
    flight: &AlignedFlight,
    calibrate_first_s: Option<f64>,
    spans: &[(f64, f64)],
    measured_wh: &dyn Fn(f64, f64) -> f64,
) -> Result<FlightValidation, Error> {
    let flight = &within(flight, spans);
    let measured: Vec<f64> = flight.samples.iter().map(|s| s.measured_power_w).collect();
    if measured.len() < 2 {
        return Err(Error::NoMotion {
            origin: flight.source.clone(),
        });
    }
    let predicted = predict(model, flight)?;
    let t = &flight.times_s;
    let compared = covered(spans, t);
    let measured_energy_wh: f64 = compared.iter().map(|(a, b)| measured_wh(*a, *b)).sum();
    let predicted_energy_wh = compared
        .iter()
        .map(|(a, b)| held_integral(t, &predicted, *a, *b) / 3600.0)
        .sum::<f64>();
    let mean = measured.iter().sum::<f64>() / measured.len() as f64;
    let constant = vec![mean; measured.len()];
    let table_i = ablation_rows(model, flight, &measured)?;
    let calibration = match calibrate_first_s {
        None => None,
        Some(window) => Some(calibrate(model, flight, &measured, &predicted, window)?),
    };
    Ok(FlightValidation {
        file: flight.source.clone(),
        duration_s: compared.iter().map(|(a, b)| b - a).sum(),
        airborne_s: spans.iter().map(|(a, b)| b - a).sum(),
        lag_s: flight.lag_s,
        lag_correlation: flight.lag_correlation,
        measured_energy_wh,
        predicted_energy_wh,
        energy_error_percent: 100.0 * (predicted_energy_wh / measured_energy_wh - 1.0),
        nrmse_percent: nrmse_percent(&predicted, &measured).unwrap_or(f64::NAN),
        baseline_nrmse_percent: nrmse_percent(&constant, &measured).unwrap_or(f64::NAN),
        samples: measured.len(),
        table_i,
        calibration,
        air_density_kg_m3: model.vehicle().air_density_kg_m3(),
        density_source: crate::engine::AirSource::VehicleFile,
        quality: crate::engine::FitQuality::Good,
        quality_reasons: Vec::new(),
    })
}

/// The Table I rows: the full model and each term dropped, per airspeed band.
fn ablation_rows(
    model: &PowerModel,
    flight: &AlignedFlight,
    measured: &[f64],
) -> Result<Vec<AblationRow>, Error> {
    let mut table_i = Vec::new();
    for (name, term) in [
        ("none", None),
        ("parasitic", Some(Term::Parasitic)),
        ("profile", Some(Term::Profile)),
        ("induced", Some(Term::Induced)),
        ("climb", Some(Term::Climb)),
    ] {
        let variant = match term {
            None => model.clone(),
            Some(term) => PowerModel::with_options(
                model.vehicle().clone(),
                ModelOptions {
                    terms: Terms {
                        ..model.options().terms.without(term)
                    },
                    ..*model.options()
                },
            )?,
        };
        let est = predict(&variant, flight)?;
        let bands = AIRSPEED_BANDS
            .iter()
            .map(|&(label, lo, hi)| {
                let (e, m): (Vec<f64>, Vec<f64>) = flight
                    .samples
                    .iter()
                    .zip(est.iter().zip(measured))
                    .filter(|(s, _)| s.state.airspeed_mps >= lo && s.state.airspeed_mps < hi)
                    .map(|(_, (e, m))| (*e, *m))
                    .unzip();
                BandNrmse {
                    airspeed_band_mps: label,
                    samples: e.len(),
                    nrmse_percent: nrmse_percent(&e, &m),
                }
            })
            .collect();
        table_i.push(AblationRow {
            dropped_term: name,
            nrmse_percent: nrmse_percent(&est, measured).unwrap_or(f64::NAN),
            bands,
        });
    }
    Ok(table_i)
}

/// The efficiency re-estimated from the first `window` seconds and the errors over the rest.
fn calibrate(
    model: &PowerModel,
    flight: &AlignedFlight,
    measured: &[f64],
    predicted: &[f64],
    window: f64,
) -> Result<Calibration, Error> {
    let t = &flight.times_s;
    let split = t.partition_point(|&x| x < t[0] + window);
    if split < 2 || split + 2 > t.len() {
        return Err(Error::CalibrationWindow {
            origin: flight.source.clone(),
            window_s: window,
            duration_s: t[t.len() - 1] - t[0],
        });
    }
    // Electrical power is aero power / eta: rescaling by the ratio of energies over the
    // window is the least-biased re-estimate of eta from that window.
    let window_ratio = trapezoid_wh(&t[..split], &measured[..split])
        / trapezoid_wh(&t[..split], &predicted[..split]);
    // Shrunk toward the fitted model by the uncertainty of each (crate::recalibration).
    let prior = model.vehicle().params().efficiency_relative_sd;
    let shrunk =
        crate::recalibration::shrink(window_ratio, &measured[..split], &predicted[..split], prior);
    let scale = shrunk.ratio;
    let efficiency = model.vehicle().efficiency() / scale;
    let rest_pred: Vec<f64> = predicted[split..].iter().map(|p| p * scale).collect();
    let rest_meas = &measured[split..];
    let measured_energy_wh = trapezoid_wh(&t[split..], rest_meas);
    let predicted_energy_wh = trapezoid_wh(&t[split..], &rest_pred);
    let rest_mean = rest_meas.iter().sum::<f64>() / rest_meas.len() as f64;
    Ok(Calibration {
        calibrate_s: window,
        efficiency,
        window_efficiency: model.vehicle().efficiency() / window_ratio,
        window_weight: shrunk.window_weight,
        window_relative_sd: shrunk.window_relative_sd,
        measured_energy_wh,
        predicted_energy_wh,
        energy_error_percent: 100.0 * (predicted_energy_wh / measured_energy_wh - 1.0),
        rmse_w: metrics::rmse(&rest_pred, rest_meas)?,
        best_constant_rmse_w: metrics::rmse(&vec![rest_mean; rest_meas.len()], rest_meas)?,
    })
}
