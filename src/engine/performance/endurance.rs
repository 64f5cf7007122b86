//! Endurance and range of one vehicle in a steady wind: hover and orbit endurance, the
//! best-endurance and best-range speeds along a course ([`endurance`]), and the power curve
//! against airspeed ([`power_curve`]).

use serde::{Deserialize, Serialize};

use aloft_planner::{
    Aircraft, EnduranceQuery, EnduranceReport, Pack, Powered, SweepRow, Wind, WindSpec,
};
use aloft_power::AoaModel;

use crate::engine::basics::finite::finite;
use crate::engine::conditions::air::{vehicle_air, Air, AirInput};
use crate::engine::conditions::wind::{describe_wind_spec, steady};
use crate::engine::vehicles::vehicle::{TakeoffMass, Vehicle};
use crate::error::Error;

/// Options of [`endurance`] and [`power_curve`]: those of `aloft endurance` (JSON keys as the
/// field names; every key optional, unknown keys rejected).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EnduranceOptions {
    /// Pack by name (default: the vehicle's default pack).
    pub battery: Option<String>,
    /// Payload, kg (default 0).
    pub payload_kg: f64,
    /// Wind (a profile is evaluated at 10 m; no gusts). Default still air.
    pub wind: Option<WindSpec>,
    /// Course of the range query, degrees clockwise from north (default 0).
    pub course_deg: f64,
    /// Reserve kept, percent of the usable capacity (default 0).
    pub reserve_percent: f64,
    /// Orbit radius for the orbit-endurance query, m (with `orbit_speed_mps`).
    pub orbit_radius_m: Option<f64>,
    /// Orbit ground speed, m/s (with `orbit_radius_m`).
    pub orbit_speed_mps: Option<f64>,
    /// Angle-of-attack model (default geometric).
    pub aoa: AoaModel,
    /// The day's air (default: the vehicle file's density, ISA sea level unless it says
    /// otherwise).
    pub air: AirInput,
}

impl Default for EnduranceOptions {
    fn default() -> Self {
        Self {
            battery: None,
            payload_kg: 0.0,
            wind: None,
            course_deg: 0.0,
            reserve_percent: 0.0,
            orbit_radius_m: None,
            orbit_speed_mps: None,
            aoa: AoaModel::Geometric,
            air: AirInput::default(),
        }
    }
}

impl EnduranceOptions {
    /// Options from JSON text, e.g. `{"wind": {"speed_mps": 5, "from_deg": 0}, "course_deg": 90}`.
    ///
    /// # Errors
    /// [`Error::OptionsFormat`] for malformed JSON or unknown keys.
    pub fn from_json(text: &str) -> Result<Self, Error> {
        serde_json::from_str(text).map_err(|e| Error::OptionsFormat {
            what: "endurance options",
            message: e.to_string(),
        })
    }
}

/// The answers of [`endurance`]: the JSON of `aloft endurance --format json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EnduranceSummary {
    /// Vehicle name.
    pub vehicle: String,
    /// Pack name.
    pub battery: String,
    /// Take-off mass, kg.
    pub takeoff_mass_kg: f64,
    /// The air flown in (flattened: `air_density_kg_m3`, `density_source`, ...).
    #[serde(flatten)]
    pub air: Air,
    /// The queries' answers (flattened).
    #[serde(flatten)]
    pub report: EnduranceReport,
    /// What the answer was computed for, in words (not part of the JSON).
    #[serde(skip)]
    pub context: EnduranceContext,
}

/// The words and figures a reader wants beside the answers (not part of the JSON).
#[derive(Debug, Clone, PartialEq)]
pub struct EnduranceContext {
    /// The take-off mass and what it is made of.
    pub mass: TakeoffMass,
    /// The pack's rated energy, Wh.
    pub battery_energy_wh: f64,
    /// The wind in words.
    pub wind: String,
    /// Notes on how the vehicle is modelled.
    pub notes: Vec<String>,
}

impl EnduranceSummary {
    /// Pretty JSON, as the CLI prints it (without the CLI's trailing newline).
    ///
    /// # Errors
    /// [`Error::OptionsFormat`] if serialisation fails (it does not for finite numbers).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::engine::missions::summary::pretty_json(self, "endurance summary")
    }
}

/// The power curve of [`power_curve`]: rows of power, endurance and range against airspeed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(transparent)]
pub struct PowerCurve {
    /// One row per airspeed, from 0 to the vehicle's maximum speed.
    pub rows: Vec<SweepRow>,
    /// Vehicle, pack, mass and wind of the curve (not part of the JSON).
    #[serde(skip)]
    pub context: CurveContext,
}

/// What a power curve was computed for (not part of the JSON).
#[derive(Debug, Clone, PartialEq)]
pub struct CurveContext {
    /// Vehicle name.
    pub vehicle: String,
    /// Pack name.
    pub battery: String,
    /// The take-off mass and what it is made of.
    pub mass: TakeoffMass,
    /// The wind in words.
    pub wind: String,
    /// The air flown in.
    pub air: Air,
}

/// Hover and orbit endurance, best-endurance and best-range speeds along a course in a constant
/// wind, as `aloft endurance` answers them.
///
/// # Errors
/// A negative or non-finite payload, a take-off mass above the airframe's limit, a wind with
/// gusts, a reserve outside `[0, 100)`, only one of the orbit's radius and speed, no headway along
/// the course, and what the planner rejects.
pub fn endurance(vehicle: &Vehicle, options: &EnduranceOptions) -> Result<EnduranceSummary, Error> {
    let (vehicle, air) = vehicle_air(vehicle, &options.air)?;
    let vehicle = &vehicle;
    let setup = Setup::new(vehicle, options)?;
    let report = aloft_planner::endurance(&setup.powered, &setup.battery, &setup.query)?;
    finite(
        EnduranceSummary {
            vehicle: vehicle.name().to_string(),
            battery: setup.battery.name().to_string(),
            takeoff_mass_kg: setup.mass.total_kg,
            air,
            report,
            context: EnduranceContext {
                mass: setup.mass.clone(),
                battery_energy_wh: setup.battery.rated_energy_wh(),
                wind: setup.wind_text,
                notes: vehicle.notes(),
            },
        },
        "endurance",
        || format!("vehicle {} with {:?}", vehicle.name(), options),
    )
}

/// Power, endurance and range against airspeed in steps of `step_mps` up to the vehicle's
/// maximum speed, in the options' wind and along their course (`aloft endurance --sweep-speed`).
///
/// # Errors
/// As [`endurance`], and a step that is not positive and finite.
pub fn power_curve(
    vehicle: &Vehicle,
    options: &EnduranceOptions,
    step_mps: f64,
) -> Result<PowerCurve, Error> {
    let (vehicle, air) = vehicle_air(vehicle, &options.air)?;
    let vehicle = &vehicle;
    let setup = Setup::new(vehicle, options)?;
    let vmax = vehicle.aircraft()?.airframe().max_speed_mps();
    let rows =
        aloft_planner::sweep_speed(&setup.powered, &setup.battery, &setup.query, vmax, step_mps)?;
    finite(
        PowerCurve {
            rows,
            context: CurveContext {
                vehicle: vehicle.name().to_string(),
                battery: setup.battery.name().to_string(),
                mass: setup.mass,
                wind: setup.wind_text,
                air,
            },
        },
        "power curve",
        || {
            format!(
                "vehicle {} with {:?}, step {step_mps} m/s",
                vehicle.name(),
                options
            )
        },
    )
}

/// The vehicle at its take-off mass, its pack and the query of one set of options.
struct Setup<'a> {
    powered: Powered<'a>,
    battery: Pack,
    mass: TakeoffMass,
    query: EnduranceQuery,
    wind_text: String,
}

/// The queries' report for `aircraft` and `battery` in place of the vehicle's own (a scenario's,
/// scaled by its draws), with the options' payload and wind.
///
/// # Errors
/// As [`endurance`].
pub(in crate::engine) fn endurance_report(
    vehicle: &Vehicle,
    aircraft: &Aircraft,
    battery: &Pack,
    options: &EnduranceOptions,
) -> Result<EnduranceReport, Error> {
    let setup = Setup::with(vehicle, aircraft, battery.clone(), options)?;
    Ok(aloft_planner::endurance(
        &setup.powered,
        &setup.battery,
        &setup.query,
    )?)
}

impl<'a> Setup<'a> {
    fn new(vehicle: &'a Vehicle, options: &EnduranceOptions) -> Result<Self, Error> {
        let aircraft = vehicle.aircraft()?;
        let battery = vehicle.battery(options.battery.as_deref())?;
        Self::with(vehicle, aircraft, battery, options)
    }

    fn with(
        vehicle: &Vehicle,
        aircraft: &'a Aircraft,
        battery: Pack,
        options: &EnduranceOptions,
    ) -> Result<Self, Error> {
        let mass = vehicle.takeoff_mass_with(&battery, options.payload_kg)?;
        let powered = aircraft.at_mass(mass.total_kg, options.aoa)?;
        let (wind, wind_text) = steady_wind(options.wind.as_ref())?;
        check_reserve(options.reserve_percent)?;
        let query = EnduranceQuery {
            wind_mps: wind_at_10_m(&wind),
            course: course_unit(options.course_deg)?,
            start_soc: 1.0,
            reserve_fraction: options.reserve_percent / 100.0,
            orbit: orbit(options.orbit_radius_m, options.orbit_speed_mps)?,
        };
        Ok(Self {
            powered,
            battery,
            mass,
            query,
            wind_text,
        })
    }
}

/// The options' steady wind (no gusts) and its description; still air without one.
fn steady_wind(spec: Option<&WindSpec>) -> Result<(Wind, String), Error> {
    match spec {
        None => Ok((Wind::calm(), "still air".to_string())),
        Some(w) => {
            if let Some(g) = w.gust_std_mps {
                return Err(Error::InvalidInput {
                    name: "wind.gust_std_mps",
                    value: g,
                    unit: "m/s",
                    expected: "no gusts: the endurance queries take a steady wind",
                });
            }
            Ok((steady(w)?, describe_wind_spec(w)))
        }
    }
}

/// The horizontal wind at 10 m, which stands for the query's wind (a profile is evaluated there).
fn wind_at_10_m(wind: &Wind) -> [f64; 2] {
    let w = wind.mean_at([0.0, 0.0, 10.0]).unwrap_or([0.0; 3]);
    [w[0], w[1]]
}

fn check_reserve(reserve_percent: f64) -> Result<(), Error> {
    if (0.0..100.0).contains(&reserve_percent) {
        Ok(())
    } else {
        Err(Error::InvalidInput {
            name: "reserve_percent",
            value: reserve_percent,
            unit: "%",
            expected: "a percentage in [0, 100)",
        })
    }
}

/// The unit east-north vector of a course in degrees clockwise from north.
fn course_unit(course_deg: f64) -> Result<[f64; 2], Error> {
    if !course_deg.is_finite() {
        return Err(Error::InvalidInput {
            name: "course_deg",
            value: course_deg,
            unit: "deg",
            expected: "a finite course",
        });
    }
    let c = course_deg.to_radians();
    Ok([c.sin(), c.cos()])
}

/// The orbit of the orbit-endurance query: both radius and speed, or neither.
fn orbit(radius_m: Option<f64>, speed_mps: Option<f64>) -> Result<Option<(f64, f64)>, Error> {
    match (radius_m, speed_mps) {
        (Some(r), Some(v)) => Ok(Some((r, v))),
        (None, None) => Ok(None),
        (Some(r), None) => Err(Error::InvalidInput {
            name: "orbit_radius_m",
            value: r,
            unit: "m",
            expected: "orbit_speed_mps as well",
        }),
        (None, Some(v)) => Err(Error::InvalidInput {
            name: "orbit_speed_mps",
            value: v,
            unit: "m/s",
            expected: "orbit_radius_m as well",
        }),
    }
}
