//! The vehicle a fit writes: the template completed into a vehicle that flies, from what the logs
//! record and what the owner states.
//!
//! - **Envelope** (`[airframe]`): the autopilot's own limits, read from each log's parameters
//!   ([`aloft_logs::battery_records::ENVELOPE_PARAMETERS`]): PX4 `MPC_TILTMAX_AIR`,
//!   `MPC_XY_VEL_MAX`, `MPC_XY_CRUISE`, `MPC_Z_VEL_MAX_UP`, `MPC_Z_VEL_MAX_DN`, `MPC_ACC_HOR`,
//!   `MPC_ACC_UP_MAX`, `MPC_YAWRAUTO_MAX`, `RTL_RETURN_ALT`; ArduPilot `ANGLE_MAX` (cdeg),
//!   `WPNAV_SPEED` (cm/s: the speed limit and the cruise speed), `WPNAV_SPEED_UP`,
//!   `WPNAV_SPEED_DN`, `WPNAV_ACCEL`, `WPNAV_ACCEL_Z`, `ATC_RATE_Y_MAX`, `RTL_ALT` (cm). Where the
//!   logs disagree the most cautious value is written (the smallest) and said. A limit no log
//!   sets keeps the template's.
//! - **Rotors**: PX4 `CA_ROTOR_COUNT`, else the template's; the diameter is `--rotor-diameter-m`.
//! - **Mass**: `--mass-kg` is the take-off mass of a flight without payload (airframe + pack);
//!   the airframe is that less the pack. A flight given as `FILE:payload_kg=KG` flew KG heavier.
//!   The maximum take-off mass is `--max-takeoff-mass-kg`, else the template's when it is the
//!   owner's, else 1.5 times the heaviest flight (a guess, said).
//! - **Pack** (`[[battery]]`): `aloft pack fit` on the same logs
//!   ([`crate::engine::packs::pack_fit::fit_pack`]): the measured resistance, the cells the logs give (else the
//!   highest voltage logged over 4.35 V a cell, rounded up), the capacity from the autopilot's
//!   parameter (PX4 `BAT1_CAPACITY`, ArduPilot `BATT_CAPACITY`) or `--battery-capacity-mah`,
//!   the mass from `--battery-mass-kg` or estimated at [`LIPO_WH_PER_KG`].
//!
//! A value neither the logs nor the flags give is asked for by the flag that gives it
//! ([`Error::MissingValue`]). The template is the owner's file (`--vehicle-template`), whose
//! values stand where logs and flags are silent; or the generic one (`aloft vehicles template`),
//! whose guesses never stand for the mass, the rotor size or the capacity.

use std::collections::BTreeMap;

use aloft_logs::{read_battery_log, OpenOptions, Profile};
use aloft_planner::{AirframeSpec, BatterySpec};

use crate::engine::basics::logs::FlightLogs;
use crate::engine::packs::pack_fit::{fit_pack, PackFitRequest};
use crate::error::Error;
use crate::vehicle::VehicleFile;

/// Specific energy of a LiPo pack used to estimate its mass when it is not given, W h/kg (the
/// middle of 130-180 W h/kg for hobby LiPo packs).
pub const LIPO_WH_PER_KG: f64 = 150.0;

/// The highest cell voltage a LiPo (or LiHV) cell reaches, V: a pack's cell count is at least its
/// highest logged voltage over this.
const MAX_CELL_V: f64 = 4.35;

/// What the owner states of a vehicle the logs do not record (`aloft fit`'s flags).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OwnVehicle {
    /// Take-off mass of the flights without payload (airframe + pack), kg.
    pub mass_kg: Option<f64>,
    /// Propeller diameter, m.
    pub rotor_diameter_m: Option<f64>,
    /// The pack's rated capacity, mA h (when the autopilot's parameter is unset).
    pub battery_capacity_mah: Option<f64>,
    /// The pack's mass, kg.
    pub battery_mass_kg: Option<f64>,
    /// The largest take-off mass, kg.
    pub max_takeoff_mass_kg: Option<f64>,
}

/// The completed vehicle file, and notes on where its values came from.
pub(crate) struct Completed {
    /// The vehicle file (its `[power]` the template's, with the mass and rotors set).
    pub file: VehicleFile,
    /// One line per value taken, guessed or chosen between logs.
    pub notes: Vec<String>,
}

/// One envelope key of `[airframe]`, the parameters that give it and their scale to the key's
/// unit, and how it is set.
struct EnvelopeKey {
    key: &'static str,
    sources: &'static [(&'static str, f64)],
    set: fn(&mut AirframeSpec, f64),
}

const ENVELOPE: [EnvelopeKey; 9] = [
    EnvelopeKey {
        key: "max_tilt_deg",
        sources: &[("MPC_TILTMAX_AIR", 1.0), ("ANGLE_MAX", 0.01)],
        set: |a, v| a.max_tilt_deg = v,
    },
    EnvelopeKey {
        key: "max_speed_mps",
        sources: &[("MPC_XY_VEL_MAX", 1.0), ("WPNAV_SPEED", 0.01)],
        set: |a, v| a.max_speed_mps = v,
    },
    EnvelopeKey {
        key: "cruise_speed_mps",
        sources: &[("MPC_XY_CRUISE", 1.0), ("WPNAV_SPEED", 0.01)],
        set: |a, v| a.cruise_speed_mps = Some(v),
    },
    EnvelopeKey {
        key: "max_climb_rate_mps",
        sources: &[("MPC_Z_VEL_MAX_UP", 1.0), ("WPNAV_SPEED_UP", 0.01)],
        set: |a, v| a.max_climb_rate_mps = v,
    },
    EnvelopeKey {
        key: "max_descent_rate_mps",
        sources: &[("MPC_Z_VEL_MAX_DN", 1.0), ("WPNAV_SPEED_DN", 0.01)],
        set: |a, v| a.max_descent_rate_mps = v,
    },
    EnvelopeKey {
        key: "acceleration_mps2",
        sources: &[("MPC_ACC_HOR", 1.0), ("WPNAV_ACCEL", 0.01)],
        set: |a, v| a.acceleration_mps2 = v,
    },
    EnvelopeKey {
        key: "vertical_acceleration_mps2",
        sources: &[("MPC_ACC_UP_MAX", 1.0), ("WPNAV_ACCEL_Z", 0.01)],
        set: |a, v| a.vertical_acceleration_mps2 = v,
    },
    EnvelopeKey {
        key: "yaw_rate_deg_s",
        sources: &[("MPC_YAWRAUTO_MAX", 1.0), ("ATC_RATE_Y_MAX", 1.0)],
        set: |a, v| a.yaw_rate_deg_s = v,
    },
    EnvelopeKey {
        key: "rtl_altitude_m",
        sources: &[("RTL_RETURN_ALT", 1.0), ("RTL_ALT", 0.01)],
        set: |a, v| a.rtl_altitude_m = Some(v),
    },
];

/// What one log says of its vehicle: its kept parameters and the highest pack voltage it
/// records, V (0 when none).
struct LogFacts {
    parameters: BTreeMap<String, f64>,
    max_voltage_v: f64,
}

/// Each log's [`LogFacts`] (the parameters those
/// [`aloft_logs::battery_records::is_kept_parameter`] keeps), read once; a log whose battery
/// records cannot be read gives none.
fn log_facts(logs: &FlightLogs) -> Result<Vec<LogFacts>, Error> {
    let profile = logs.profile.as_deref().map(Profile::resolve).transpose()?;
    let mut open = OpenOptions::default();
    open.binary.battery_instance = logs.battery_instance;
    Ok(logs
        .logs
        .iter()
        .filter_map(|path| {
            let log = read_battery_log(path, profile.as_ref(), &open).ok()?;
            let max_voltage_v = log
                .samples
                .iter()
                .map(|s| s.voltage_v)
                .filter(|v| v.is_finite() && *v > 0.0)
                .fold(0.0, f64::max);
            Some(LogFacts {
                parameters: log.parameters,
                max_voltage_v,
            })
        })
        .collect())
}

/// The value of one envelope key over the logs: each log's first source that is set (positive),
/// scaled; the smallest over the logs, with a note when they disagree.
fn envelope_value(key: &EnvelopeKey, params: &[LogFacts], notes: &mut Vec<String>) -> Option<f64> {
    let values: Vec<(f64, &'static str)> = params
        .iter()
        .filter_map(|f| {
            let p = &f.parameters;
            key.sources.iter().find_map(|(name, scale)| {
                let v = p.get(*name)? * scale;
                (v.is_finite() && v > 0.0).then_some((v, *name))
            })
        })
        .collect();
    let (min, name) = values.iter().copied().min_by(|a, b| a.0.total_cmp(&b.0))?;
    let max = values.iter().map(|v| v.0).fold(min, f64::max);
    if max > min {
        notes.push(format!(
            "the logs disagree on {name} ({min} to {max}): {} = {min} written, the most cautious",
            key.key
        ));
    }
    Some(min)
}

/// The template completed from the logs and the owner's flags (module docs). `generic`: the
/// template is `aloft vehicles template`, whose mass, rotor size and capacity are guesses that
/// never stand. An owner's template that cannot be completed (no capacity for a pack it lacks)
/// is written with its own tables, and a note says why.
///
/// # Errors
/// From the generic template, [`Error::MissingValue`] naming the flag of a value neither the logs
/// nor the flags give; values the vehicle file refuses.
pub(crate) fn complete_vehicle(
    template: &VehicleFile,
    generic: bool,
    own: &OwnVehicle,
    logs: &FlightLogs,
) -> Result<Completed, Error> {
    match completed(template, generic, own, logs) {
        // The owner's template stands as it is where a value is missing, said.
        Err(e @ Error::MissingValue { .. }) if !generic => Ok(Completed {
            file: template.clone(),
            notes: vec![format!(
                "the template's tables are written as they are, not completed from the logs: {e}"
            )],
        }),
        other => other,
    }
}

impl OwnVehicle {
    /// Each value given is in its range: a mass or diameter positive (a rotor at most 5 m, a
    /// mass at most 1000 kg), a capacity a pack has (10 to 1e7 mA h, the logs' own range).
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the flag.
    pub fn check(&self) -> Result<(), Error> {
        // A pack below 10 mA h is a unit slip: its own range, named.
        let (min_mah, max_mah) = aloft_core::BATTERY_CAPACITY_RANGE_MAH;
        if let Some(v) = self
            .battery_capacity_mah
            .filter(|v| !(min_mah..=max_mah).contains(v))
        {
            return Err(Error::InvalidInput {
                name: "--battery-capacity-mah",
                value: v,
                unit: "mAh",
                expected: "a pack's capacity, from 10 to 1e7 mA h",
            });
        }
        let checks: [(&'static str, Option<f64>, &'static str, f64); 4] = [
            ("--mass-kg", self.mass_kg, "kg", 1000.0),
            ("--rotor-diameter-m", self.rotor_diameter_m, "m", 5.0),
            ("--battery-mass-kg", self.battery_mass_kg, "kg", 1000.0),
            (
                "--max-takeoff-mass-kg",
                self.max_takeoff_mass_kg,
                "kg",
                1000.0,
            ),
        ];
        for (name, value, unit, max) in checks {
            if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0 && *v <= max)) {
                return Err(Error::InvalidInput {
                    name,
                    value: v,
                    unit,
                    expected: "a positive value within its physical range (a rotor up to 5 m, a mass up to 1000 kg)",
                });
            }
        }
        Ok(())
    }
}

/// [`complete_vehicle`], every missing value an error.
fn completed(
    template: &VehicleFile,
    generic: bool,
    own: &OwnVehicle,
    logs: &FlightLogs,
) -> Result<Completed, Error> {
    let mut notes = Vec::new();
    let mut file = template.clone();
    let params = log_facts(logs)?;
    let mut power = file.power.clone().ok_or(Error::MissingTable {
        vehicle: template.name.clone(),
        table: "power",
        needed_for: "the four-term power model",
    })?;
    set_rotors(&mut power, &params, own, generic)?;
    let template_pack = (!generic)
        .then(|| {
            file.batteries
                .iter()
                .find(|b| b.default)
                .or(file.batteries.first())
        })
        .flatten()
        .cloned();
    // The mass of a flight without payload (asked before the pack's capacity).
    let takeoff_kg = match own.mass_kg {
        Some(m) => m,
        None if generic => return Err(missing_mass()),
        None => match (&file.airframe, &template_pack) {
            (Some(a), Some(b)) => a.mass_kg + b.mass_kg.unwrap_or(0.0),
            _ => power.mass_kg,
        },
    };
    // The pack, from the same logs.
    let cells = cells_from_voltage(&params);
    let pack = own_pack(
        own,
        logs,
        cells,
        template,
        template_pack.as_ref(),
        &mut notes,
    )?;
    let pack_kg = pack.mass_kg.unwrap_or(0.0);
    if !(takeoff_kg.is_finite() && takeoff_kg > pack_kg) {
        return Err(Error::InvalidInput {
            name: "mass_kg",
            value: takeoff_kg,
            unit: "kg",
            expected: "a take-off mass above the pack's mass",
        });
    }
    power.mass_kg = takeoff_kg;
    let mut airframe = file.airframe.clone().unwrap_or_else(|| {
        let generic_file = crate::vehicle::VehicleFile::from_toml_str(
            crate::vehicle::VEHICLE_TEMPLATE,
            "the vehicle template",
        )
        .ok()
        .and_then(|f| f.airframe);
        generic_file.expect("the built-in vehicle template has an [airframe]")
    });
    if file.airframe.is_none() {
        notes.push(
            "the [airframe] keys no log parameter sets (rotor_height_m, and any limit below) are the generic template's: check them"
                .to_string(),
        );
    }
    airframe.mass_kg = round6(takeoff_kg - pack_kg);
    airframe.max_takeoff_mass_kg = max_takeoff_mass(
        &airframe, takeoff_kg, own, generic, template, logs, &mut notes,
    );
    for key in &ENVELOPE {
        if let Some(v) = envelope_value(key, &params, &mut notes) {
            (key.set)(&mut airframe, v);
        }
    }
    file.power = Some(power);
    file.airframe = Some(airframe);
    place_pack(&mut file, pack, template_pack.as_ref(), generic);
    Ok(Completed { file, notes })
}

/// The rotors: the autopilot's count (PX4 `CA_ROTOR_COUNT`), the owner's diameter.
fn set_rotors(
    power: &mut aloft_power::VehicleParams,
    params: &[LogFacts],
    own: &OwnVehicle,
    generic: bool,
) -> Result<(), Error> {
    if let Some(n) = params
        .iter()
        .find_map(|f| f.parameters.get("CA_ROTOR_COUNT").copied())
        .filter(|n| (1.0..=16.0).contains(n))
    {
        power.rotor_count = n as u32;
    }
    match own.rotor_diameter_m {
        Some(d) => power.rotor_radius_m = d / 2.0,
        None if generic => {
            return Err(Error::MissingValue {
                flag: "--rotor-diameter-m",
                hint: "logs do not record the propellers: give their diameter in metres (10 in = 0.254 m), or --vehicle-template FILE with your [power] rotor_radius_m",
            })
        }
        None => {}
    }
    Ok(())
}

/// The largest take-off mass: the owner's, else the owner's template's (at least the heaviest
/// flight), else 1.5 times the heaviest flight, said as a guess.
fn max_takeoff_mass(
    airframe: &AirframeSpec,
    takeoff_kg: f64,
    own: &OwnVehicle,
    generic: bool,
    template: &VehicleFile,
    logs: &FlightLogs,
    notes: &mut Vec<String>,
) -> f64 {
    let heaviest = takeoff_kg
        + (0..logs.logs.len())
            .map(|i| logs.payload_kg(i))
            .fold(0.0, f64::max);
    match own.max_takeoff_mass_kg {
        Some(m) => m,
        None if !generic && template.airframe.is_some() => {
            airframe.max_takeoff_mass_kg.max(heaviest)
        }
        None => {
            let guess = round6(1.5 * heaviest);
            notes.push(format!(
                "max_takeoff_mass_kg {guess:.3} kg is a guess, 1.5 times the heaviest flight ({heaviest:.3} kg): give --max-takeoff-mass-kg"
            ));
            guess
        }
    }
}

/// The fitted pack in place of the owner's template's default (its other packs kept), else
/// alone.
fn place_pack(
    file: &mut VehicleFile,
    pack: BatterySpec,
    template_pack: Option<&BatterySpec>,
    generic: bool,
) {
    let at = file
        .batteries
        .iter()
        .position(|b| Some(&b.name) == template_pack.map(|t| &t.name));
    match at {
        Some(i) if !generic => {
            for b in &mut file.batteries {
                b.default = false;
            }
            file.batteries[i] = pack;
        }
        _ => file.batteries = vec![pack],
    }
}

/// `x` to a millionth (a written value reads as it was meant: 11.1 V, not 11.100000000000001).
fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// The take-off mass, which no log records.
fn missing_mass() -> Error {
    Error::MissingValue {
        flag: "--mass-kg",
        hint: "logs do not weigh the vehicle: give the take-off mass of a flight without payload (with its pack), kg, or --vehicle-template FILE with your [airframe] and [[battery]]",
    }
}

/// The pack of the logs ([`fit_pack`]), its missing keys from the flags, else the template's
/// pack when the template is the owner's.
fn own_pack(
    own: &OwnVehicle,
    logs: &FlightLogs,
    cells_from_voltage: Option<u32>,
    template: &VehicleFile,
    template_pack: Option<&BatterySpec>,
    notes: &mut Vec<String>,
) -> Result<BatterySpec, Error> {
    let mass_kg = own
        .battery_mass_kg
        .or(template_pack.and_then(|b| b.mass_kg));
    let request = PackFitRequest {
        logs: logs.logs.clone(),
        profile: logs.profile.clone(),
        battery_instance: logs.battery_instance,
        capacity_mah: own
            .battery_capacity_mah
            .or(template_pack.map(|b| b.capacity_mah)),
        // The mass is set below (it may be estimated from the fitted energy).
        mass_kg: Some(mass_kg.unwrap_or(1.0)),
        name: template_pack.map(|b| b.name.clone()),
        ..PackFitRequest::default()
    };
    let answer = match fit_pack(&request) {
        // The logs do not say the cells: from the highest voltage they record.
        Err(Error::PackKeyMissing {
            key: "cells_series",
            ..
        }) => fit_pack(&PackFitRequest {
            cells_series: cells_from_voltage,
            ..request
        }),
        other => other,
    };
    let answer = match answer {
        Err(Error::PackKeyMissing {
            key: "capacity_mah",
            ..
        }) => {
            return Err(Error::MissingValue {
                flag: "--battery-capacity-mah",
                hint: "the autopilot's capacity parameter (PX4 BAT1_CAPACITY, ArduPilot BATT_CAPACITY) is unset in the logs: give the pack's rated capacity, mA h",
            })
        }
        other => other,
    };
    let answer = match answer {
        Ok(a) => a,
        Err(e) => return template_pack_as_is(template_pack, &e.to_string(), notes),
    };
    let Some(pack) = answer.pack else {
        return template_pack_as_is(template_pack, "no log has battery current", notes);
    };
    let mut spec = pack.battery;
    spec.mass_kg = Some(mass_kg.unwrap_or_else(|| {
        let energy = spec.energy_wh.unwrap_or(0.0);
        let mass = energy / LIPO_WH_PER_KG;
        notes.push(format!(
            "the pack's mass, {mass:.3} kg, is estimated from its {energy:.1} Wh at {LIPO_WH_PER_KG} Wh/kg: give --battery-mass-kg"
        ));
        mass
    }));
    spec.mass_kg = spec.mass_kg.map(round6);
    spec.nominal_v = spec.nominal_v.map(round6);
    spec.energy_wh = spec.energy_wh.map(round6);
    spec.default = true;
    if spec.name == "fitted" {
        spec.name = format!("{}-pack", template.name);
    }
    notes.extend(answer.notes);
    if let Some(r) = answer.internal_resistance_ohm {
        notes.push(format!(
            "pack resistance {:.4} ohm measured from {} over {} log(s) (aloft pack fit)",
            r,
            answer
                .internal_resistance_source
                .as_deref()
                .unwrap_or("the logs"),
            answer.logs.len()
        ));
    }
    Ok(spec)
}

/// What the logs cannot fit: the owner's pack stands, said; the generic template's never does.
fn template_pack_as_is(
    template_pack: Option<&BatterySpec>,
    reason: &str,
    notes: &mut Vec<String>,
) -> Result<BatterySpec, Error> {
    let Some(b) = template_pack else {
        return Err(Error::MissingValue {
            flag: "--vehicle-template",
            hint: "the logs cannot fit a pack (no battery current, or no current steps): give a vehicle file with your [[battery]]",
        });
    };
    notes.push(format!(
        "the pack is the template's {} as it is: {reason}",
        b.name
    ));
    Ok(b.clone())
}

/// Cells in series from the highest voltage any log records, when the logs' parameters do not
/// say: at least that voltage over [`MAX_CELL_V`], rounded up.
fn cells_from_voltage(logs: &[LogFacts]) -> Option<u32> {
    let max_v = logs.iter().map(|l| l.max_voltage_v).fold(0.0, f64::max);
    (max_v > 0.0).then(|| (max_v / MAX_CELL_V).ceil().max(1.0) as u32)
}
