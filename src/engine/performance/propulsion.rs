//! The propulsion chain at hover ([`hover`], [`hover_sweep`]: the propulsion seed) and the
//! rotor's transient response ([`rotor_response`]: the rotor-transient seed).

use std::path::Path;

use serde::Serialize;

use aloft_propulsion::{
    mass_range_kg, rotor_step_response, EscProtocol, HoverResult, RotorSpec, RotorTransientResult,
};

use crate::engine::basics::files::read_text_file;
use crate::engine::basics::finite::finite;
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// What hover to compute: a payload on the vehicle's empty mass, or a take-off mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HoverRequest {
    /// Payload added to the empty mass, kg.
    Payload(f64),
    /// Take-off mass, kg.
    TakeoffMass(f64),
}

/// The propulsion chain of `vehicle` at hover: rotor speed, currents, pack heat, flight time.
///
/// # Errors
/// No `[propulsion]` table, or a mass the chain cannot hover (named with the request).
pub fn hover(vehicle: &Vehicle, request: HoverRequest) -> Result<HoverResult, Error> {
    let system = vehicle.file().propulsion_system()?;
    let (result, what) = match request {
        HoverRequest::Payload(kg) => (system.hover_with_payload(kg), format!("payload_kg {kg}")),
        HoverRequest::TakeoffMass(kg) => (
            system.hover_at_takeoff_mass(kg),
            format!("takeoff_mass_kg {kg}"),
        ),
    };
    let hover = result.map_err(|source| Error::Hover {
        request: what.clone(),
        source,
    })?;
    finite(hover, "hover", || what)
}

/// One point of a sweep over take-off mass: the hover, or why that mass cannot hover.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepPoint {
    /// Take-off mass, kg.
    pub takeoff_mass_kg: f64,
    /// The hover at that mass.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub result: Option<HoverResult>,
    /// Why that mass cannot hover.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The hover across take-off mass (the propulsion seed's Fig. 13).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(transparent)]
pub struct HoverSweep {
    /// One point per mass.
    pub points: Vec<SweepPoint>,
}

/// The hover of `vehicle` at take-off masses from `from_kg` to `to_kg` in steps of `step_kg`; a
/// mass that cannot hover is a point with an error, not a failure of the sweep.
///
/// # Errors
/// No `[propulsion]` table, or an invalid range.
pub fn hover_sweep(
    vehicle: &Vehicle,
    from_kg: f64,
    to_kg: f64,
    step_kg: f64,
) -> Result<HoverSweep, Error> {
    let system = vehicle.file().propulsion_system()?;
    let masses = mass_range_kg(from_kg, to_kg, step_kg)?;
    let points = system
        .sweep_takeoff_mass(&masses)
        .into_iter()
        .zip(&masses)
        .map(|(r, &m)| match r {
            Ok(h) => SweepPoint {
                takeoff_mass_kg: m,
                result: Some(h),
                error: None,
            },
            Err(e) => SweepPoint {
                takeoff_mass_kg: m,
                result: None,
                error: Some(e.to_string()),
            },
        })
        .collect();
    finite(HoverSweep { points }, "hover sweep", || {
        format!("take-off mass {from_kg}..{to_kg} kg in steps of {step_kg} kg")
    })
}

/// Built-in rotors: name and TOML text (identical to `fixtures/rotors/<name>.toml`).
pub const BUILTIN_ROTORS: &[(&str, &str)] = &[(
    "mn1806-6x2",
    include_str!("../../../fixtures/rotors/mn1806-6x2.toml"),
)];

/// Values of a rotor given one by one; each replaces the rotor file's.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RotorOverrides {
    /// Motor speed constant, rpm/V.
    pub motor_kv_rpm_per_v: Option<f64>,
    /// Motor (armature + ESC) resistance, ohm.
    pub motor_resistance_ohm: Option<f64>,
    /// No-load current, A.
    pub no_load_current_a: Option<f64>,
    /// Supply voltage, V.
    pub voltage_v: Option<f64>,
    /// Motor mass, g.
    pub motor_mass_g: Option<f64>,
    /// Motor outer diameter, mm.
    pub motor_diameter_mm: Option<f64>,
    /// Propeller mass, g.
    pub prop_mass_g: Option<f64>,
    /// Propeller diameter, in.
    pub prop_diameter_in: Option<f64>,
    /// Load-torque coefficient of `tau = c omega^2`, N m s^2.
    pub torque_coefficient_nms2: Option<f64>,
    /// ESC protocol whose latency is added.
    pub protocol: Option<EscProtocol>,
    /// Step start speed, rad/s.
    pub step_from_radps: Option<f64>,
    /// Step end speed, rad/s.
    pub step_to_radps: Option<f64>,
}

/// A rotor step-response request: a rotor (built-in name or rotor TOML file) and values that
/// replace its own, or only values.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RotorRequest {
    /// A built-in rotor name or a rotor TOML file.
    pub rotor: Option<String>,
    /// Values given one by one.
    pub overrides: RotorOverrides,
}

/// The answer of [`rotor_response`] (the JSON of `aloft rotor --format json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(transparent)]
pub struct RotorAnswer {
    /// Inertias, time constants, rise and settling times, steady current.
    pub result: RotorTransientResult,
    /// The rotor the answer is for (not part of the JSON).
    #[serde(skip)]
    pub spec: RotorSpec,
}

/// Inertias, time constants and the simulated step response of a rotor.
///
/// # Errors
/// An unknown rotor, an unreadable or invalid rotor file, a value given neither way, values the
/// model rejects.
pub fn rotor_response(request: &RotorRequest) -> Result<RotorAnswer, Error> {
    let base = request.rotor.as_deref().map(base_rotor).transpose()?;
    let spec = merged_spec(base.as_ref(), &request.overrides)?;
    let result = rotor_step_response(&spec).map_err(|source| Error::Rotor { source })?;
    finite(RotorAnswer { result, spec }, "rotor", || {
        format!("{request:?}")
    })
}

/// A built-in rotor by name, else the rotor file at that path.
fn base_rotor(rotor: &str) -> Result<RotorSpec, Error> {
    let (text, origin) = match BUILTIN_ROTORS.iter().find(|(n, _)| *n == rotor) {
        Some((_, t)) => (t.to_string(), format!("built-in rotor '{rotor}'")),
        None if Path::new(rotor).exists() => (
            read_text_file(Path::new(rotor), "rotor file")?,
            rotor.to_string(),
        ),
        None => {
            return Err(Error::UnknownRotor {
                name: rotor.to_string(),
                known: BUILTIN_ROTORS
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", "),
            })
        }
    };
    toml::from_str(&text).map_err(|e| Error::RotorFormat {
        origin,
        message: aloft_core::file_message(&e.to_string()),
    })
}

/// The rotor of the base file with the overrides applied; every required value must come from
/// one of them.
fn merged_spec(b: Option<&RotorSpec>, o: &RotorOverrides) -> Result<RotorSpec, Error> {
    let need = |v: Option<f64>, base: Option<f64>, flag: &'static str| {
        v.or(base).ok_or(Error::MissingValue {
            flag,
            hint: "give it, or a rotor file with --rotor (e.g. --rotor mn1806-6x2)",
        })
    };
    // A field of the overrides, else of the base file, else an error naming its flag (a field by
    // name, so a macro).
    macro_rules! need {
        ($field:ident, $flag:literal) => {
            need(o.$field, b.map(|s| s.$field), $flag)?
        };
    }
    Ok(RotorSpec {
        motor_kv_rpm_per_v: need!(motor_kv_rpm_per_v, "--motor-kv"),
        motor_resistance_ohm: need!(motor_resistance_ohm, "--motor-resistance"),
        no_load_current_a: need!(no_load_current_a, "--no-load-current"),
        voltage_v: need!(voltage_v, "--voltage"),
        motor_mass_g: need!(motor_mass_g, "--motor-mass"),
        motor_diameter_mm: need!(motor_diameter_mm, "--motor-diameter"),
        prop_mass_g: need!(prop_mass_g, "--prop-mass"),
        prop_diameter_in: need!(prop_diameter_in, "--prop-diameter"),
        torque_coefficient_nms2: need!(torque_coefficient_nms2, "--torque-coefficient"),
        protocol: o.protocol.or(b.and_then(|s| s.protocol)),
        step_from_radps: o.step_from_radps.or(b.and_then(|s| s.step_from_radps)),
        step_to_radps: o.step_to_radps.or(b.and_then(|s| s.step_to_radps)),
    })
}
