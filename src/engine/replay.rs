//! Replay: the energy of a recorded flight predicted from its trajectory alone (velocities, and
//! accelerations differentiated from them or taken from the log, through the planner's force
//! balance and power model; no power data used), next to the measured energy (V x I over the
//! same span, shifted by the lag of power behind motion).

use std::path::PathBuf;

use serde::Serialize;

use aloft_core::trapezoid;
use aloft_logs::Log;
use aloft_planner::{differentiate_velocity, power_only_aircraft, replay, ReplayPoint};
use aloft_power::{AoaModel, ModelOptions};

use super::finite::finite;
use super::vehicles::{TakeoffMass, Vehicle};
use super::wind::{describe_wind_spec, steady};
use crate::error::Error;
use crate::identify::{align_flight, AlignOptions};

/// Where the replay takes the acceleration from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReplayAcceleration {
    /// Centred difference of the logged velocity over a window (default).
    #[default]
    Velocity,
    /// The log's acceleration channel.
    Log,
}

/// A replay request (the options of `aloft mission --replay`).
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayRequest {
    /// The flight log.
    pub log: PathBuf,
    /// CSV profile: `kaist`, `px4` or a column-map TOML; `None`: recognised from the file.
    pub profile: Option<String>,
    /// Pack by name (default: the vehicle's default pack), part of the take-off mass.
    pub battery: Option<String>,
    /// Payload, kg, part of the take-off mass.
    pub payload_kg: f64,
    /// Lag of the logged power behind the motion, s (`None`: estimated).
    pub lag_s: Option<f64>,
    /// Where the acceleration comes from.
    pub acceleration: ReplayAcceleration,
    /// Window of the velocity difference, s.
    pub acceleration_window_s: f64,
    /// Angle-of-attack model of the power model.
    pub aoa: AoaModel,
    /// Wind where the log has none (default still air).
    pub wind: Option<aloft_planner::WindSpec>,
}

impl Default for ReplayRequest {
    fn default() -> Self {
        Self {
            log: PathBuf::new(),
            profile: None,
            battery: None,
            payload_kg: 0.0,
            lag_s: None,
            acceleration: ReplayAcceleration::Velocity,
            acceleration_window_s: 1.0,
            aoa: AoaModel::Geometric,
            wind: None,
        }
    }
}

/// The answer of [`replay_log`] (the JSON of `aloft mission --replay --format json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReplayAnswer {
    /// The log.
    pub file: String,
    /// Vehicle name.
    pub vehicle: String,
    /// Mass flown, kg.
    pub mass_kg: f64,
    /// Trajectory points replayed.
    pub points: usize,
    /// Span compared, s.
    pub duration_s: f64,
    /// `velocity` or `log`.
    pub acceleration: &'static str,
    /// Lag of power behind motion applied, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lag_s: Option<f64>,
    /// Predicted energy over the span, Wh.
    pub predicted_energy_wh: f64,
    /// Predicted mean power, W.
    pub predicted_mean_power_w: f64,
    /// Measured energy over the span, Wh (absent without power in the log).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_energy_wh: Option<f64>,
    /// Measured mean power, W.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_mean_power_w: Option<f64>,
    /// `(predicted - measured) / measured`, percent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_error_percent: Option<f64>,
    /// The acceleration source and the wind, in words (not part of the JSON).
    #[serde(skip)]
    pub context: ReplayContext,
}

/// What a replay used, in words (not part of the JSON).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReplayContext {
    /// The take-off mass and what it is made of.
    pub mass: String,
    /// The acceleration source.
    pub acceleration: String,
    /// The wind.
    pub wind: String,
    /// Notes for the reader (e.g. why no lag was estimated).
    pub notes: Vec<String>,
}

/// The trajectory of a log: samples with a velocity, strictly increasing in time.
struct Trajectory {
    times: Vec<f64>,
    points: Vec<ReplayPoint>,
}

/// Replay the flight of `request.log` with `vehicle` (see the module docs) at its take-off mass
/// ([`Vehicle::takeoff_mass`]): airframe + pack + payload for a vehicle with an airframe; one with
/// only a `[power]` table (a fit) at that table's mass + payload.
///
/// # Errors
/// An invalid payload, window or wind, an unreadable log, a log with fewer than two velocity
/// samples, no acceleration in the log when asked for it, a power channel that does not overlap
/// the trajectory.
pub fn replay_log(vehicle: &Vehicle, request: &ReplayRequest) -> Result<ReplayAnswer, Error> {
    let (aircraft, mass) = replay_aircraft(vehicle, request)?;
    let powered = aircraft.at_mass(mass.total_kg, request.aoa)?;
    let profile = request
        .profile
        .as_deref()
        .map(aloft_logs::Profile::resolve)
        .transpose()?;
    let log = aloft_logs::read_log(&request.log, profile.as_ref(), &Default::default())?;
    let path = request.log.display().to_string();
    let trajectory = trajectory(&log, request, &path)?;
    let (wind, wind_text) = match &request.wind {
        Some(w) => (steady(w)?, describe_wind_spec(w)),
        None => (aloft_planner::Wind::calm(), "still air".to_string()),
    };
    let report = replay(&powered, &trajectory.points, &wind).map_err(|e| Error::Replay {
        origin: path.clone(),
        source: Box::new(e),
    })?;
    let mut notes = Vec::new();
    let measured = measured_span(
        &log,
        request,
        &trajectory.times,
        &report.power_w,
        &mut notes,
        &path,
    )?;
    let (lag_s, measured_wh, predicted_wh, span_s) = match measured {
        Some(m) => (Some(m.lag_s), Some(m.measured_wh), m.predicted_wh, m.span_s),
        None => (None, None, report.energy_wh, report.duration_s),
    };
    let error = measured_wh.map(|m| 100.0 * (predicted_wh - m) / m);
    let logged_wind = trajectory.points.iter().any(|p| p.wind_enu_mps.is_some());
    let answer = ReplayAnswer {
        file: path,
        vehicle: vehicle.name().to_string(),
        mass_kg: mass.total_kg,
        points: trajectory.points.len(),
        duration_s: span_s,
        acceleration: match request.acceleration {
            ReplayAcceleration::Velocity => "velocity",
            ReplayAcceleration::Log => "log",
        },
        lag_s,
        predicted_energy_wh: predicted_wh,
        predicted_mean_power_w: predicted_wh * 3600.0 / span_s,
        measured_energy_wh: measured_wh,
        measured_mean_power_w: measured_wh.map(|m| m * 3600.0 / span_s),
        energy_error_percent: error,
        context: ReplayContext {
            mass: mass.describe(),
            acceleration: match request.acceleration {
                ReplayAcceleration::Velocity => format!(
                    "differentiated velocity over {} s",
                    request.acceleration_window_s
                ),
                ReplayAcceleration::Log => "the log's".to_string(),
            },
            wind: if logged_wind {
                "from the log".to_string()
            } else {
                wind_text
            },
            notes,
        },
    };
    finite(answer, "replay", || request.log.display().to_string())
}

/// The aircraft at its take-off mass ([`Vehicle::takeoff_mass`]); a vehicle without an airframe
/// flies its `[power]` table alone.
fn replay_aircraft(
    vehicle: &Vehicle,
    request: &ReplayRequest,
) -> Result<(aloft_planner::Aircraft, TakeoffMass), Error> {
    let mass = vehicle.takeoff_mass(request.battery.as_deref(), request.payload_kg)?;
    let aircraft = if vehicle.file().airframe.is_some() {
        vehicle.aircraft()?.clone()
    } else {
        let power = vehicle.power_model_at(&mass)?.vehicle().clone();
        power_only_aircraft(power, ModelOptions::default())?
    };
    Ok((aircraft, mass))
}

/// The samples with a velocity, strictly increasing in time, with their accelerations.
fn trajectory(log: &Log, request: &ReplayRequest, path: &str) -> Result<Trajectory, Error> {
    let mut times = Vec::new();
    let mut vels = Vec::new();
    let mut rows = Vec::new();
    for s in &log.samples {
        let Some(v) = s.vel_enu_mps else { continue };
        if !s.time_s.is_finite() || times.last().is_some_and(|&t| s.time_s <= t) {
            continue;
        }
        times.push(s.time_s);
        vels.push(v);
        rows.push(s);
    }
    if times.len() < 2 {
        return Err(Error::NothingToReplay {
            origin: path.to_string(),
        });
    }
    let accs: Vec<[f64; 3]> = match request.acceleration {
        ReplayAcceleration::Velocity => {
            differentiate_velocity(&times, &vels, request.acceleration_window_s)?
        }
        ReplayAcceleration::Log => rows
            .iter()
            .map(|s| s.acc_enu_mps2)
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| Error::MissingChannel {
                origin: path.to_string(),
                needed_for: "--acceleration log",
                channel: "acceleration on every velocity sample (use --acceleration velocity)",
            })?,
    };
    let points = rows
        .iter()
        .zip(&accs)
        .map(|(s, a)| ReplayPoint {
            time_s: s.time_s,
            vel_enu_mps: s.vel_enu_mps.unwrap_or([0.0; 3]),
            acc_enu_mps2: *a,
            pos_enu_m: s.pos_enu_m.unwrap_or([0.0; 3]),
            height_above_ground_m: None,
            wind_enu_mps: s.wind_enu_mps,
            yaw_rad: s.attitude.map(|a| a.yaw_rad),
        })
        .collect();
    Ok(Trajectory { times, points })
}

/// The measured and predicted energy over the span both cover.
struct MeasuredSpan {
    lag_s: f64,
    measured_wh: f64,
    predicted_wh: f64,
    span_s: f64,
}

/// Measured energy (V x I) over the trajectory's span shifted by the lag, and the predicted
/// energy over the same span; `None` when the log has no usable power channel.
fn measured_span(
    log: &Log,
    request: &ReplayRequest,
    times: &[f64],
    predicted_w: &[f64],
    notes: &mut Vec<String>,
    path: &str,
) -> Result<Option<MeasuredSpan>, Error> {
    let (pt, pp): (Vec<f64>, Vec<f64>) = log
        .samples
        .iter()
        .filter_map(|s| s.electrical_power_w().map(|p| (s.time_s, p)))
        .filter(|(t, p)| t.is_finite() && p.is_finite())
        .unzip();
    let monotonic = pt.windows(2).all(|w| w[1] >= w[0]);
    if pt.len() < 2 || !monotonic {
        return Ok(None);
    }
    let lag = match request.lag_s {
        Some(l) => l,
        None => match align_flight(log, &AlignOptions::default()) {
            Ok(a) => a.lag_s,
            Err(e) => {
                notes.push(format!("no lag estimate ({e}); using 0 s"));
                0.0
            }
        },
    };
    let a = times[0].max(pt[0] - lag);
    let b = times[times.len() - 1].min(pt[pt.len() - 1] - lag);
    if b <= a {
        return Err(Error::NoOverlap {
            origin: path.to_string(),
            lag_s: lag,
        });
    }
    Ok(Some(MeasuredSpan {
        lag_s: lag,
        measured_wh: window_integral(&pt, &pp, a + lag, b + lag) / 3600.0,
        predicted_wh: window_integral(times, predicted_w, a, b) / 3600.0,
        span_s: b - a,
    }))
}

/// Integral of the piecewise-linear `values(times)` over `[a, b]` (inside the data).
fn window_integral(times: &[f64], values: &[f64], a: f64, b: f64) -> f64 {
    let interp = |t: f64| {
        let i = times.partition_point(|&x| x <= t).clamp(1, times.len() - 1);
        let (t0, t1) = (times[i - 1], times[i]);
        let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
        values[i - 1] + w * (values[i] - values[i - 1])
    };
    let (mut ts, mut vs) = (vec![a], vec![interp(a)]);
    for (&t, &v) in times.iter().zip(values) {
        if t > a && t < b {
            ts.push(t);
            vs.push(v);
        }
    }
    ts.push(b);
    vs.push(interp(b));
    trapezoid(&ts, &vs)
}
