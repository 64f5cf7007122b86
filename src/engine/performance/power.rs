//! Power of one flight state from the four-term model ([`power_point`]), with the ablation and
//! hybrid options of the power seed, the angle-of-attack choice and the gradient; and the same
//! for a CSV of states streamed from a file ([`power_csv_file`]).

use std::io::{BufReader, BufWriter};
use std::path::Path;

use aloft_core::Num;
use serde::Serialize;

use aloft_power::{AoaInput, AoaModel, FlightState, ModelOptions, PowerBreakdown, PowerModel};
use aloft_power::{Term, Terms};

use crate::engine::basics::files::{open_input_file, shown_path, Output};
use crate::engine::basics::finite::finite;
use crate::engine::conditions::air::{vehicle_air, Air, AirInput};
use crate::engine::performance::power_batch::power_csv;
use crate::engine::vehicles::vehicle::{TakeoffMass, Vehicle};
use crate::error::Error;

/// A point query of the power model (the options of `aloft power`): the model and the flight
/// state, angles in degrees.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PowerQuery {
    /// The model: take-off mass, terms, angle of attack.
    pub model: PowerModelQuery,
    /// The flight state.
    pub state: FlightStateDeg,
    /// Also compute the gradient of electrical power.
    pub gradient: bool,
}

/// The model a power query flies.
///
/// The model flies the vehicle's take-off mass ([`Vehicle::takeoff_mass`]): airframe + pack
/// (`battery`, default the vehicle's default pack) + `payload_kg`, as `aloft endurance` and
/// `aloft mission` do.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PowerModelQuery {
    /// Pack by name (default: the vehicle's default pack).
    pub battery: Option<String>,
    /// Payload, kg (default 0).
    pub payload_kg: f64,
    /// Terms removed (the ablation rows of the paper's Table I).
    pub without: Vec<Term>,
    /// Hybrid model: drop the profile term above this airspeed, m/s.
    pub profile_cutoff_mps: Option<f64>,
    /// Angle-of-attack model; default the paper's, or geometric when the state's
    /// `air_direction_deg` is given.
    pub aoa: Option<AoaModel>,
    /// The day's air (default: the vehicle file's density).
    pub air: AirInput,
}

/// The flight state of a point query, angles in degrees (the power model's [`FlightState`] in
/// the units of `aloft power`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FlightStateDeg {
    /// Airspeed, m/s (horizontal, as the paper assumes).
    pub airspeed_mps: f64,
    /// Roll, deg (positive right side down).
    pub roll_deg: f64,
    /// Pitch, deg (positive nose up).
    pub pitch_deg: f64,
    /// Vertical speed, m/s, positive up.
    pub climb_rate_mps: f64,
    /// Direction of the air-relative velocity from the nose, deg (selects the geometric model).
    pub air_direction_deg: Option<f64>,
}

/// The gradient of electrical power with respect to airspeed, roll and pitch (per degree).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PowerGradientDeg {
    /// dP/d airspeed, W per m/s.
    pub d_airspeed_w_per_mps: f64,
    /// dP/d roll, W per degree.
    pub d_roll_w_per_deg: f64,
    /// dP/d pitch, W per degree.
    pub d_pitch_w_per_deg: f64,
}

/// The answer of [`power_point`]: every term, and the gradient when asked (the JSON of
/// `aloft power --format json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PowerAnswer {
    /// The take-off mass the model flew, kg (airframe + pack + payload).
    pub takeoff_mass_kg: f64,
    /// The pack in that mass (absent for a vehicle without an airframe).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub battery: Option<String>,
    /// The payload in that mass, kg.
    pub payload_kg: f64,
    /// The air the model flew in (flattened: `air_density_kg_m3`, `density_source`, ...).
    #[serde(flatten)]
    pub air: Air,
    /// Every term of the model.
    #[serde(flatten)]
    pub power: PowerBreakdown,
    /// The gradient, when asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub electrical_gradient: Option<PowerGradientDeg>,
    /// What was evaluated, in words (not part of the JSON).
    #[serde(skip)]
    pub context: PowerContext,
}

/// What a power answer was computed for (not part of the JSON).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PowerContext {
    /// Vehicle name.
    pub vehicle: String,
    /// The take-off mass and what it is made of, in words.
    pub mass: String,
    /// The model's efficiency `eta`.
    pub efficiency: f64,
    /// The angle-of-attack model in words.
    pub aoa: String,
    /// Names of the removed terms.
    pub removed: Vec<&'static str>,
}

/// The four-term model of `vehicle` at the query's take-off mass (its `battery` and
/// `payload_kg`), with its terms removed and its profile cutoff.
///
/// # Errors
/// No `[power]` table, a take-off mass [`Vehicle::takeoff_mass`] refuses, or an invalid cutoff.
pub fn power_model(vehicle: &Vehicle, query: &PowerModelQuery) -> Result<PowerModel, Error> {
    Ok(model_and_mass(vehicle, query)?.0)
}

/// The four-term model in the query's air at its take-off mass with its terms and cutoff, that
/// mass and that air.
fn model_and_mass(
    vehicle: &Vehicle,
    query: &PowerModelQuery,
) -> Result<(PowerModel, TakeoffMass, Air), Error> {
    let (vehicle, air) = vehicle_air(vehicle, &query.air)?;
    let (model, mass) = vehicle.power_model_with(query.battery.as_deref(), query.payload_kg)?;
    let options = ModelOptions {
        terms: Terms::all_but(&query.without),
        profile_cutoff_mps: query.profile_cutoff_mps,
    };
    let model = PowerModel::with_options(model.vehicle().clone(), options)?;
    Ok((model, mass, air))
}

/// Every term of the four-term model (power seed eqs 3-14) at one flight state, at the
/// vehicle's take-off mass.
///
/// # Errors
/// No `[power]` table; a take-off mass [`Vehicle::takeoff_mass`] refuses; a contradictory
/// angle-of-attack choice (geometric without a direction, the paper's with one); a state the
/// model rejects (negative airspeed, tilt of 90 deg or more).
pub fn power_point(vehicle: &Vehicle, query: &PowerQuery) -> Result<PowerAnswer, Error> {
    let (model, mass, air) = model_and_mass(vehicle, &query.model)?;
    let s = &query.state;
    let aoa = aoa_input(query.model.aoa, s.air_direction_deg)?;
    let state = FlightState {
        airspeed_mps: s.airspeed_mps,
        roll_rad: s.roll_deg.to_radians(),
        pitch_rad: s.pitch_deg.to_radians(),
        climb_rate_mps: s.climb_rate_mps,
        aoa,
    };
    let invalid = |source| Error::FlightState {
        state: format!(
            "airspeed_mps {}, roll_deg {}, pitch_deg {}, climb_rate_mps {}",
            Num(s.airspeed_mps),
            Num(s.roll_deg),
            Num(s.pitch_deg),
            Num(s.climb_rate_mps)
        ),
        source,
    };
    let power = model.evaluate(&state).map_err(invalid)?;
    let electrical_gradient = if query.gradient {
        let g = model.electrical_gradient(&state).map_err(invalid)?;
        Some(PowerGradientDeg {
            d_airspeed_w_per_mps: g.d_airspeed_w_per_mps,
            d_roll_w_per_deg: g.d_roll_w_per_rad.to_radians(),
            d_pitch_w_per_deg: g.d_pitch_w_per_rad.to_radians(),
        })
    } else {
        None
    };
    finite(
        PowerAnswer {
            takeoff_mass_kg: mass.total_kg,
            battery: mass.battery().map(str::to_string),
            payload_kg: mass.payload_kg(),
            air,
            power,
            electrical_gradient,
            context: PowerContext {
                vehicle: vehicle.name().to_string(),
                mass: mass.describe(),
                efficiency: model.vehicle().efficiency(),
                aoa: match aoa {
                    AoaInput::Paper => "paper eqs 3-4".to_string(),
                    AoaInput::Geometric { .. } => format!(
                        "geometric, air from {:.1} deg off the nose",
                        s.air_direction_deg.unwrap_or_default()
                    ),
                },
                removed: query.model.without.iter().map(|t| t.name()).collect(),
            },
        },
        "power",
        || format!("{query:?}"),
    )
}

/// The angle of attack of a point query: the paper's unless a direction of the air-relative
/// velocity is given (a point query has no such direction otherwise).
fn aoa_input(aoa: Option<AoaModel>, air_direction_deg: Option<f64>) -> Result<AoaInput, Error> {
    match (aoa, air_direction_deg) {
        (Some(AoaModel::Geometric), None) => Err(Error::Contradiction {
            message: "--aoa geometric needs --air-direction-deg: a point query has no air-velocity direction otherwise".to_string(),
        }),
        (Some(AoaModel::Paper), Some(d)) => Err(Error::Contradiction {
            message: format!("--air-direction-deg {d} selects the geometric angle of attack; it contradicts --aoa paper"),
        }),
        (_, Some(d)) => Ok(AoaInput::Geometric {
            air_direction_rad: d.to_radians(),
        }),
        (_, None) => Ok(AoaInput::Paper),
    }
}

/// Stream the CSV of states at `input` through the model of `vehicle` at the query's take-off
/// mass, terms and cutoff ([`power_model`]; the states come from the rows) into `output`, or
/// standard output when `None`, one row at a time (see [`power_csv`]). Returns the number of
/// rows. The output file is written in aloft's one way ([`crate::engine::basics::files::write_output`]): placed when
/// every row is written (an error leaves nothing), an existing file replaced only with `force`.
///
/// # Errors
/// As [`power_model`] and [`power_csv`], an input that cannot be opened, an output that exists
/// (without `force`) or cannot be written.
pub fn power_csv_file(
    vehicle: &Vehicle,
    query: &PowerModelQuery,
    input: &Path,
    output: Option<(&Path, bool)>,
) -> Result<u64, Error> {
    let model = power_model(vehicle, query)?;
    let file = open_input_file(input, "CSV of states")?;
    let reader = BufReader::with_capacity(1 << 16, file);
    let origin = input.display().to_string();
    match output {
        Some((p, force)) => {
            let mut sink = BufWriter::with_capacity(1 << 16, Output::create(p, force)?);
            let rows = power_csv(&model, reader, &mut sink, &origin)?;
            let out = sink.into_inner().map_err(|e| Error::Io {
                origin: format!("cannot write {}", shown_path(p)),
                source: e.into_error(),
            })?;
            out.commit()?;
            Ok(rows)
        }
        None => {
            let stdout = std::io::stdout();
            let sink = BufWriter::with_capacity(1 << 16, stdout.lock());
            power_csv(&model, reader, sink, &origin)
        }
    }
}
