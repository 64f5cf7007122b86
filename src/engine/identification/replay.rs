//! Replay: the energy of a recorded flight predicted from its trajectory alone (velocities, and
//! accelerations differentiated from them or taken from the log, through the planner's force
//! balance and power model; no power data used), next to the measured energy (V x I over the
//! same span, shifted by the lag of power behind motion).
//!
//! Ground time is not flown: a record that starts before take-off, holds several flights or goes
//! on after landing has its ground time found ([`aloft_logs::ground`]: the log's own landed state
//! where it has one, else detected from height, speed and power) and priced at the measured idle
//! power of each ground stretch (0 W when the log has no power), so the prediction is the
//! model's only where the vehicle flies. Airborne and ground time and energy are reported apart.

use std::path::PathBuf;

use serde::Serialize;

use aloft_core::trapezoid_window;
use aloft_logs::{GroundReport, Log};
use aloft_planner::{differentiate_velocity, power_only_aircraft, replay, ReplayPoint};
use aloft_power::{AoaModel, ModelOptions};

use crate::engine::basics::finite::finite;
use crate::engine::basics::logs::ground_time;
use crate::engine::conditions::air::{log_air, Air, AirInput};
use crate::engine::conditions::wind::{describe_wind_spec, steady};
use crate::engine::vehicles::vehicle::{MassParts, Vehicle};
use crate::error::Error;
use crate::identify::{align_flight, power_samples, AlignOptions};

/// Where the replay takes the acceleration from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ReplayAcceleration {
    /// Centred difference of the logged velocity over a window (default, 1 s).
    Velocity {
        /// Window of the difference, s.
        window_s: f64,
    },
    /// The log's acceleration channel.
    Log,
}

impl Default for ReplayAcceleration {
    fn default() -> Self {
        Self::Velocity { window_s: 1.0 }
    }
}

/// A replay request (the options of `aloft mission --replay`).
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayRequest {
    /// The flight log.
    pub log: PathBuf,
    /// CSV profile: `kaist`, `px4` or a column-map TOML; `None`: recognised from the file.
    pub profile: Option<String>,
    /// Payload added to the vehicle's mass, kg.
    pub payload_kg: f64,
    /// Lag of the logged power behind the motion, s (`None`: estimated).
    pub lag_s: Option<f64>,
    /// Where the acceleration comes from.
    pub acceleration: ReplayAcceleration,
    /// Angle-of-attack model of the power model.
    pub aoa: AoaModel,
    /// Wind where the log has none (default still air).
    pub wind: Option<aloft_planner::WindSpec>,
    /// The pack flown, by name (`None`: the vehicle's default pack); its mass is part of the
    /// mass flown.
    pub battery: Option<String>,
    /// The day's air (default: the log's own density where it has one, else the vehicle
    /// file's).
    pub air: AirInput,
}

impl Default for ReplayRequest {
    fn default() -> Self {
        Self {
            log: PathBuf::new(),
            profile: None,
            payload_kg: 0.0,
            lag_s: None,
            acceleration: ReplayAcceleration::default(),
            aoa: AoaModel::Geometric,
            wind: None,
            battery: None,
            air: AirInput::default(),
        }
    }
}

/// The answer of [`replay_log`] (the JSON of `aloft mission --replay --format json`).
///
/// The span compared is split into airborne time, flown through the power model, and ground time
/// (before, between and after flights), priced at the measured idle power; the energies of the
/// two parts add up to the totals.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReplayAnswer {
    /// The log.
    pub file: String,
    /// Vehicle name.
    pub vehicle: String,
    /// The pack flown (its mass is part of `mass_kg`); absent for a `[power]`-only vehicle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub battery: Option<String>,
    /// Mass flown, kg.
    pub mass_kg: f64,
    /// The air flown in (flattened: `air_density_kg_m3`, `density_source`, ...): the given
    /// day's, else the log's own (`log`), else the vehicle file's.
    #[serde(flatten)]
    pub air: Air,
    /// Trajectory points replayed.
    pub points: usize,
    /// Span compared, s.
    pub duration_s: f64,
    /// `velocity` or `log`.
    pub acceleration: &'static str,
    /// Lag of power behind motion applied, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lag_s: Option<f64>,
    /// Predicted energy over the span, Wh: airborne from the trajectory, ground at idle.
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
    /// Flights (airborne spans) in the span.
    pub flights: usize,
    /// Airborne time in the span, s.
    pub airborne_s: f64,
    /// Ground time in the span (before, between and after flights), s.
    pub ground_s: f64,
    /// Where the ground time comes from: `log` (the log's landed state), `detected` (height,
    /// speed and power) or `log_and_detected` (the log's state where it has one).
    pub ground_source: &'static str,
    /// Mean measured power on the ground over the record, W, over the ground time's own span
    /// (not shifted by the lag); absent without power or ground time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub idle_power_w: Option<f64>,
    /// Predicted energy of the airborne time, Wh (from the trajectory alone).
    pub predicted_airborne_energy_wh: f64,
    /// Predicted energy of the ground time, Wh: each ground stretch at its own mean measured
    /// power (the record's where the power does not cover it), 0 without power.
    pub predicted_ground_energy_wh: f64,
    /// Measured energy of the airborne time, Wh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_airborne_energy_wh: Option<f64>,
    /// Measured energy of the ground time, Wh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_ground_energy_wh: Option<f64>,
    /// `(predicted - measured) / measured` of the airborne time, percent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub airborne_energy_error_percent: Option<f64>,
    /// The airborne spans, s from the start of the log.
    pub airborne_spans: Vec<aloft_logs::Span>,
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

/// The aircraft flown and its take-off mass ([`Vehicle::takeoff_mass`]).
struct Flown {
    aircraft: aloft_planner::Aircraft,
    mass_kg: f64,
    battery: Option<String>,
    /// The take-off mass and what it is made of, in words.
    described: String,
}

/// Replay the flight of `request.log` with `vehicle` (see the module docs). A vehicle with an
/// airframe flies at airframe + pack (`request.battery`, else its default) + payload; one with
/// only a `[power]` table (a fit) at that table's mass + payload.
///
/// Steps: the aircraft at its mass, the log, the trajectory, the model's power along it, the
/// ground time, the measured power, the span both cover, the books of air and ground.
///
/// # Errors
/// An invalid payload, window or wind, an unknown pack (or a pack for a vehicle without an
/// airframe), an unreadable log, a log with fewer than two velocity samples, no acceleration in
/// the log when asked for it, a power channel that does not overlap the trajectory.
pub fn replay_log(vehicle: &Vehicle, request: &ReplayRequest) -> Result<ReplayAnswer, Error> {
    let (log, log_density) = read_replay_log(request)?;
    // The flight in its own air: the given day, else the log's, else the vehicle file's.
    let air = log_air(&request.air, log_density, vehicle)?;
    let vehicle = &vehicle.in_air(air.air_density_kg_m3)?;
    let flown = replay_aircraft(vehicle, request.battery.as_deref(), request.payload_kg)?;
    let powered = flown.aircraft.at_mass(flown.mass_kg, request.aoa)?;
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
    let ground = ground_time(&log, hover_power_w(&powered));
    let mut notes = Vec::new();
    let measured = measured_series(&log, request, &mut notes)?;
    let window = compared_window(&trajectory.times, measured.as_ref(), &path)?;
    let books = book(
        &stretches(&ground, window),
        (&trajectory.times, &report.power_w),
        measured.as_ref(),
    );
    let logged_wind = trajectory.points.iter().any(|p| p.wind_enu_mps.is_some());
    let context = ReplayContext {
        mass: flown.described.clone(),
        acceleration: match request.acceleration {
            ReplayAcceleration::Velocity { window_s } => {
                format!("differentiated velocity over {window_s} s")
            }
            ReplayAcceleration::Log => "the log's".to_string(),
        },
        wind: if logged_wind {
            "from the log".to_string()
        } else {
            wind_text
        },
        notes,
    };
    let mut answer = answer(
        vehicle,
        request,
        flown,
        (trajectory.points.len(), measured.map(|m| m.lag_s)),
        (&ground, books, window),
        context,
    );
    answer.air = air;
    finite(answer, "replay", || request.log.display().to_string())
}

/// The answer from its parts (the keys documented on [`ReplayAnswer`]).
fn answer(
    vehicle: &Vehicle,
    request: &ReplayRequest,
    flown: Flown,
    (points, lag_s): (usize, Option<f64>),
    (ground, books, (a, b)): (&GroundReport, Books, (f64, f64)),
    context: ReplayContext,
) -> ReplayAnswer {
    let span_s = b - a;
    let predicted_wh = books.predicted_air_wh + books.predicted_ground_wh;
    let measured_wh = books.measured.map(|m| m.air_wh + m.ground_wh);
    let percent = |p: f64, m: f64| (m > 0.0).then(|| 100.0 * (p - m) / m);
    ReplayAnswer {
        file: request.log.display().to_string(),
        vehicle: vehicle.name().to_string(),
        battery: flown.battery,
        mass_kg: flown.mass_kg,
        air: Air::sea_level(),
        points,
        duration_s: span_s,
        acceleration: match request.acceleration {
            ReplayAcceleration::Velocity { .. } => "velocity",
            ReplayAcceleration::Log => "log",
        },
        lag_s,
        predicted_energy_wh: predicted_wh,
        predicted_mean_power_w: predicted_wh * 3600.0 / span_s,
        measured_energy_wh: measured_wh,
        measured_mean_power_w: measured_wh.map(|m| m * 3600.0 / span_s),
        energy_error_percent: measured_wh.and_then(|m| percent(predicted_wh, m)),
        flights: books.spans.len(),
        airborne_s: books.airborne_s,
        ground_s: books.ground_s,
        ground_source: match (ground.logged_points, ground.detected_points) {
            (_, 0) => "log",
            (0, _) => "detected",
            _ => "log_and_detected",
        },
        idle_power_w: books.idle_w.filter(|_| books.ground_s > 0.0),
        predicted_airborne_energy_wh: books.predicted_air_wh,
        predicted_ground_energy_wh: books.predicted_ground_wh,
        measured_airborne_energy_wh: books.measured.map(|m| m.air_wh),
        measured_ground_energy_wh: books.measured.map(|m| m.ground_wh),
        airborne_energy_error_percent: books
            .measured
            .and_then(|m| percent(books.predicted_air_wh, m.air_wh)),
        airborne_spans: books.spans,
        context,
    }
}

/// The aircraft at its replay mass: airframe + pack (the one named, else the default) +
/// payload, as a planned mission flies, or a `[power]`-only vehicle at its table's mass + payload
/// (that mass already is the whole vehicle: naming a pack for it is an error).
fn replay_aircraft(
    vehicle: &Vehicle,
    battery: Option<&str>,
    payload_kg: f64,
) -> Result<Flown, Error> {
    let mass = vehicle.takeoff_mass(battery, payload_kg)?;
    let aircraft = if vehicle.file().airframe.is_some() {
        vehicle.aircraft()?.clone()
    } else {
        let power = vehicle.power_model_at(&mass)?.vehicle().clone();
        power_only_aircraft(power, ModelOptions::default())?
    };
    let battery = match &mass.parts {
        MassParts::Airframe { battery, .. } => Some(battery.clone()),
        MassParts::ModelTable { .. } => None,
    };
    Ok(Flown {
        aircraft,
        mass_kg: mass.total_kg,
        battery,
        described: mass.describe(),
    })
}

/// The log, read whole (the replay needs every sample twice: the trajectory and the power),
/// and its own mean air density when it logs one (PX4 `vehicle_air_data.rho`, ArduPilot `BARO`), kg/m^3.
fn read_replay_log(request: &ReplayRequest) -> Result<(Log, Option<f64>), Error> {
    let profile = request
        .profile
        .as_deref()
        .map(aloft_logs::Profile::resolve)
        .transpose()?;
    let mut reader =
        aloft_logs::open_log_with(&request.log, profile.as_ref(), &Default::default())?;
    let log = reader.read_rest(&request.log.display().to_string())?;
    let density = reader
        .binary_summary()
        .and_then(|b| b.air_density_kg_m3)
        .filter(|rho| rho.is_finite() && (0.3..=1.6).contains(rho));
    Ok((log, density))
}

/// The samples with a velocity, strictly increasing in time, with their accelerations.
fn trajectory(log: &Log, request: &ReplayRequest, path: &str) -> Result<Trajectory, Error> {
    let rows = trajectory_rows(log);
    let times: Vec<f64> = rows.iter().map(|s| s.time_s).collect();
    let vels: Vec<[f64; 3]> = rows.iter().filter_map(|s| s.vel_enu_mps).collect();
    if times.len() < 2 {
        return Err(Error::NothingToReplay {
            origin: path.to_string(),
        });
    }
    let accs: Vec<[f64; 3]> = match request.acceleration {
        ReplayAcceleration::Velocity { window_s } => {
            differentiate_velocity(&times, &vels, window_s)?
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

/// The samples of a log a trajectory is made of: those with a velocity, strictly increasing in
/// time.
fn trajectory_rows(log: &Log) -> Vec<&aloft_logs::Sample> {
    let mut rows: Vec<&aloft_logs::Sample> = Vec::new();
    for s in &log.samples {
        if s.vel_enu_mps.is_none()
            || !s.time_s.is_finite()
            || rows.last().is_some_and(|r| s.time_s <= r.time_s)
        {
            continue;
        }
        rows.push(s);
    }
    rows
}

/// The power of `powered` in a hover, W, the scale of the idle threshold of the ground time
/// ([`ground_time`]); `None` for a vehicle that cannot hover at its mass (power is then not
/// used to tell the ground).
fn hover_power_w(powered: &aloft_planner::Powered<'_>) -> Option<f64> {
    powered.level_power_w([0.0; 2], [0.0, 1.0]).ok()
}

/// The airborne seconds of a logged flight that `aloft mission --replay` books and `aloft
/// validate` compares, and the energy measured over them: the airborne spans of the ground time
/// (the log's landed state, else detected with the idle threshold of `vehicle`'s hover power at
/// the take-off mass of `battery` and `payload_kg`), within the span where the log has a
/// velocity and a power `lag_s` later; the measured energy is the power's integral over each
/// span shifted by the lag. One function for both commands, so that one flight has one measured
/// energy.
///
/// # Errors
/// A pack the vehicle does not have, a log without a trajectory or a power that overlaps it.
pub(crate) fn compared_airborne(
    vehicle: &Vehicle,
    (battery, payload_kg, aoa): (Option<&str>, f64, AoaModel),
    log: &Log,
    lag_s: f64,
) -> Result<AirborneTime, Error> {
    let flown = replay_aircraft(vehicle, battery, payload_kg)?;
    let powered = flown.aircraft.at_mass(flown.mass_kg, aoa)?;
    let times: Vec<f64> = trajectory_rows(log).iter().map(|s| s.time_s).collect();
    if times.len() < 2 {
        return Err(Error::NothingToReplay {
            origin: log.source.clone(),
        });
    }
    let (ptimes, power_w) = power_samples(log);
    let measured = Measured {
        times: ptimes,
        power_w,
        lag_s,
    };
    let window = compared_window(&times, Some(&measured), &log.source)?;
    let ground = ground_time(log, hover_power_w(&powered));
    let spans: Vec<(f64, f64)> = stretches(&ground, window)
        .into_iter()
        .filter(|st| st.airborne)
        .map(|st| (st.start_s, st.end_s))
        .collect();
    Ok(AirborneTime { spans, measured })
}

/// The airborne time of a logged flight ([`compared_airborne`]) and its measured power.
pub(crate) struct AirborneTime {
    /// Airborne spans within the span where motion and power are both logged, s (motion time).
    pub spans: Vec<(f64, f64)>,
    measured: Measured,
}

impl AirborneTime {
    /// The measured energy from `a` to `b` (motion time, within the spans), Wh: the integral
    /// `aloft mission --replay` books.
    pub fn measured_wh(&self, a: f64, b: f64) -> f64 {
        measured_wh(&self.measured, a, b)
    }
}

/// The measured energy from `a` to `b` (trajectory time; the power `lag_s` later), Wh.
fn measured_wh(m: &Measured, a: f64, b: f64) -> f64 {
    window_integral(&m.times, &m.power_w, a + m.lag_s, b + m.lag_s) / 3600.0
}

/// The measured power (V x I) and the lag of power behind motion.
struct Measured {
    times: Vec<f64>,
    power_w: Vec<f64>,
    lag_s: f64,
}

/// The log's measured power and its lag; `None` when the log has no usable power channel.
fn measured_series(
    log: &Log,
    request: &ReplayRequest,
    notes: &mut Vec<String>,
) -> Result<Option<Measured>, Error> {
    let (times, power_w) = power_samples(log);
    let monotonic = times.windows(2).all(|w| w[1] >= w[0]);
    if times.len() < 2 || !monotonic {
        return Ok(None);
    }
    let lag_s = match request.lag_s {
        Some(l) => l,
        None => match align_flight(log, &AlignOptions::default()) {
            Ok(a) => a.lag_s,
            Err(e) => {
                notes.push(format!("no lag estimate ({e}); using 0 s"));
                0.0
            }
        },
    };
    Ok(Some(Measured {
        times,
        power_w,
        lag_s,
    }))
}

/// The span compared, in trajectory time: the trajectory, within the measured power shifted by
/// the lag when there is power.
fn compared_window(
    times: &[f64],
    measured: Option<&Measured>,
    path: &str,
) -> Result<(f64, f64), Error> {
    let (mut a, mut b) = (times[0], times[times.len() - 1]);
    if let Some(m) = measured {
        a = a.max(m.times[0] - m.lag_s);
        b = b.min(m.times[m.times.len() - 1] - m.lag_s);
        if b <= a {
            return Err(Error::NoOverlap {
                origin: path.to_string(),
                lag_s: m.lag_s,
            });
        }
    }
    Ok((a, b))
}

/// One part of the span: airborne or on the ground.
struct Stretch {
    start_s: f64,
    end_s: f64,
    airborne: bool,
}

/// The span `[a, b]` cut into airborne and ground stretches (each longer than zero).
fn stretches(ground: &GroundReport, (a, b): (f64, f64)) -> Vec<Stretch> {
    let mut out = Vec::new();
    let mut at = a;
    for span in &ground.airborne {
        let (s, e) = (span.start_s.max(a), span.end_s.min(b));
        if e <= s {
            continue;
        }
        if s > at {
            out.push(Stretch {
                start_s: at,
                end_s: s,
                airborne: false,
            });
        }
        out.push(Stretch {
            start_s: s,
            end_s: e,
            airborne: true,
        });
        at = e;
    }
    if b > at {
        out.push(Stretch {
            start_s: at,
            end_s: b,
            airborne: false,
        });
    }
    out
}

/// Measured energy of the airborne and ground time, Wh.
#[derive(Debug, Clone, Copy)]
struct MeasuredBooks {
    air_wh: f64,
    ground_wh: f64,
}

/// The energy books of a replay: airborne time through the model, ground time at idle.
struct Books {
    airborne_s: f64,
    ground_s: f64,
    predicted_air_wh: f64,
    predicted_ground_wh: f64,
    /// Mean measured power on the ground over the record, W.
    idle_w: Option<f64>,
    measured: Option<MeasuredBooks>,
    spans: Vec<aloft_logs::Span>,
}

/// The idle power of each stretch (`None` for airborne ones and for ground ones the power does
/// not cover) and of the record: the mean measured power over the stretch's own time (not
/// shifted by the lag, which relates power to motion, and at rest there is no motion).
fn idle_powers(stretches: &[Stretch], m: &Measured) -> (Vec<Option<f64>>, Option<f64>) {
    let (t0, t1) = (m.times[0], m.times[m.times.len() - 1]);
    let (mut joules, mut seconds) = (0.0, 0.0);
    let each = stretches
        .iter()
        .map(|st| {
            let (s, e) = (st.start_s.max(t0), st.end_s.min(t1));
            if st.airborne || e <= s {
                return None;
            }
            let j = window_integral(&m.times, &m.power_w, s, e);
            joules += j;
            seconds += e - s;
            Some(j / (e - s))
        })
        .collect();
    (each, (seconds > 0.0).then(|| joules / seconds))
}

/// Price each stretch: airborne at the model's power along the trajectory, ground at the idle
/// power of that stretch (of the record when the power does not cover the stretch; 0 W without
/// power). The measured energies are over the same stretches shifted by the lag.
fn book(
    stretches: &[Stretch],
    (times, predicted_w): (&[f64], &[f64]),
    measured: Option<&Measured>,
) -> Books {
    let (idle, idle_w) = measured.map_or((vec![None; stretches.len()], None), |m| {
        idle_powers(stretches, m)
    });
    let mut books = Books {
        airborne_s: 0.0,
        ground_s: 0.0,
        predicted_air_wh: 0.0,
        predicted_ground_wh: 0.0,
        idle_w,
        measured: measured.map(|_| MeasuredBooks {
            air_wh: 0.0,
            ground_wh: 0.0,
        }),
        spans: Vec::new(),
    };
    for (st, idle) in stretches.iter().zip(idle) {
        let (s, e) = (st.start_s, st.end_s);
        if st.airborne {
            books.airborne_s += e - s;
            books.predicted_air_wh += window_integral(times, predicted_w, s, e) / 3600.0;
            books.spans.push(aloft_logs::Span {
                start_s: s,
                end_s: e,
            });
        } else {
            books.ground_s += e - s;
            books.predicted_ground_wh += idle.or(idle_w).unwrap_or(0.0) * (e - s) / 3600.0;
        }
        if let (Some(mb), Some(m)) = (books.measured.as_mut(), measured) {
            let wh = measured_wh(m, s, e);
            if st.airborne {
                mb.air_wh += wh;
            } else {
                mb.ground_wh += wh;
            }
        }
    }
    books
}

/// Integral of the piecewise-linear `values(times)` over `[a, b]` (inside the data).
fn window_integral(times: &[f64], values: &[f64], a: f64, b: f64) -> f64 {
    let interp = |t: f64| {
        let i = times.partition_point(|&x| x <= t).clamp(1, times.len() - 1);
        let (t0, t1) = (times[i - 1], times[i]);
        let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
        values[i - 1] + w * (values[i] - values[i - 1])
    };
    trapezoid_window(times, values, (a, b), interp)
}
