//! Vehicles: load one (a built-in name, a vehicle file, TOML text), list the built-in ones.

use std::path::Path;

use serde::Serialize;

use aloft_planner::{Aircraft, Pack};
use aloft_power::{FlightState, ModelOptions, PowerBreakdown, PowerModel};

use crate::engine::basics::files::read_text_file;
use crate::error::Error;
use crate::vehicle::{builtin_names, VehicleFile, VehicleSource, BUILTIN_VEHICLES};

/// A loaded, validated vehicle: its file, the power model of its `[power]` table at its default
/// take-off mass (when it has one) and the aircraft the planner flies (when it has an
/// `[airframe]` and a model).
///
/// One vehicle, one mass: every command flies a vehicle with an `[airframe]` at its take-off mass,
/// airframe + pack + payload ([`Vehicle::takeoff_mass`]); the `[power]` table's own `mass_kg` is
/// the mass only of a vehicle without an airframe (a power model alone, such as the power seed's
/// validation case `dji-m100-paper`).
#[derive(Debug, Clone)]
pub struct Vehicle {
    file: VehicleFile,
    model: Option<PowerModel>,
    aircraft: Option<Aircraft>,
}

/// The mass a command flies a vehicle at, and what it is made of.
#[derive(Debug, Clone, PartialEq)]
pub struct TakeoffMass {
    /// The total, kg.
    pub total_kg: f64,
    /// What the total is made of.
    pub parts: MassParts,
}

/// What a [`TakeoffMass`] is made of.
#[derive(Debug, Clone, PartialEq)]
pub enum MassParts {
    /// A vehicle with an `[airframe]`: the airframe without battery, a pack, the payload.
    Airframe {
        /// The airframe's mass without battery, kg.
        airframe_kg: f64,
        /// The pack's name.
        battery: String,
        /// The pack's mass, kg.
        pack_kg: f64,
        /// The payload, kg.
        payload_kg: f64,
    },
    /// A vehicle without an `[airframe]` (a power model alone): the `[power]` table's mass (or the
    /// `[propulsion]` table's empty mass) and the payload.
    ModelTable {
        /// The table the mass comes from (`power` or `propulsion`).
        table: &'static str,
        /// The table's mass, kg.
        table_kg: f64,
        /// The payload, kg.
        payload_kg: f64,
    },
}

impl TakeoffMass {
    /// The pack in the mass, when the vehicle has an airframe.
    pub fn battery(&self) -> Option<&str> {
        match &self.parts {
            MassParts::Airframe { battery, .. } => Some(battery),
            MassParts::ModelTable { .. } => None,
        }
    }

    /// The payload in the mass, kg.
    pub fn payload_kg(&self) -> f64 {
        match self.parts {
            MassParts::Airframe { payload_kg, .. } | MassParts::ModelTable { payload_kg, .. } => {
                payload_kg
            }
        }
    }

    /// The mass and its parts in words, as the tables print it: `take-off mass 2.355 kg
    /// (airframe 1.755 kg + TB47D 0.600 kg + payload 0.000 kg)`.
    pub fn describe(&self) -> String {
        match &self.parts {
            MassParts::Airframe {
                airframe_kg,
                battery,
                pack_kg,
                payload_kg,
            } => format!(
                "take-off mass {:.3} kg (airframe {airframe_kg:.3} kg + {battery} {pack_kg:.3} kg + payload {payload_kg:.3} kg)",
                self.total_kg
            ),
            MassParts::ModelTable {
                table,
                table_kg,
                payload_kg,
            } => format!(
                "take-off mass {:.3} kg ([{table}] table {table_kg:.3} kg + payload {payload_kg:.3} kg; no [airframe])",
                self.total_kg
            ),
        }
    }
}

impl Vehicle {
    /// Parse and validate vehicle TOML text; `origin` names it in error messages.
    ///
    /// # Errors
    /// [`Error::VehicleFormat`] for text that is not a vehicle file, or a model error for a table
    /// whose values the model rejects.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, Error> {
        Self::from_file(VehicleFile::from_toml_str(text, origin)?)
    }

    /// A vehicle by built-in name (see [`list_vehicles`]) or, when no built-in vehicle has that
    /// name, from the vehicle file at that path.
    ///
    /// # Errors
    /// [`Error::UnknownVehicle`] for a bare name that is neither, [`Error::NoSuchVehicleFile`]
    /// for a path (with a directory or an extension) that does not exist; the file's read or
    /// format error otherwise.
    pub fn load(name_or_path: &str) -> Result<Self, Error> {
        if builtin_names().contains(&name_or_path) {
            return Self::builtin(name_or_path);
        }
        let path = Path::new(name_or_path);
        if !path.exists() {
            // A bare name is a misspelt built-in: list them. A path (a directory or an
            // extension in it) is a missing file: say so.
            if path.extension().is_some() || path.components().count() > 1 {
                return Err(Error::NoSuchVehicleFile {
                    path: name_or_path.to_string(),
                });
            }
            return Err(Error::UnknownVehicle {
                name: name_or_path.to_string(),
                known: builtin_names().join(", "),
            });
        }
        let text = read_text_file(path, "vehicle file")?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// A built-in vehicle (see [`list_vehicles`]).
    ///
    /// # Errors
    /// [`Error::UnknownVehicle`] for a name that is not built in.
    pub fn builtin(name: &str) -> Result<Self, Error> {
        Self::from_file(VehicleFile::builtin(name)?)
    }

    /// Wrap a parsed vehicle file.
    ///
    /// # Errors
    /// A model error when a table is present but invalid.
    pub fn from_file(file: VehicleFile) -> Result<Self, Error> {
        let model = match file.power {
            // At the default take-off mass; when that mass is refused (no pack, above the
            // airframe's limit), `power_model` says why when a power is asked for.
            Some(_) => {
                let table = file.power_vehicle()?;
                default_takeoff_mass(&file)
                    .ok()
                    .and_then(|m| table.with_mass(m.total_kg).ok())
                    .map(PowerModel::new)
            }
            None => None,
        };
        // A vehicle without an airframe (or without any model) can still answer power queries;
        // planning then reports the missing table (see `aircraft`).
        let aircraft = match file.aircraft(ModelOptions::default()) {
            Ok((a, _)) => Some(a),
            Err(Error::MissingTable { .. }) => None,
            Err(e) => return Err(e),
        };
        Ok(Self {
            file,
            model,
            aircraft,
        })
    }

    /// The vehicle's name.
    pub fn name(&self) -> &str {
        &self.file.name
    }

    /// The vehicle file it was built from.
    pub fn file(&self) -> &VehicleFile {
        &self.file
    }

    /// The overall efficiency `eta` of the four-term model, when the vehicle has one (whatever
    /// the mass it flies).
    pub fn efficiency(&self) -> Option<f64> {
        self.file.power.as_ref().map(|p| p.efficiency)
    }

    /// The four-term power model at the vehicle's default take-off mass: airframe + default pack
    /// for a vehicle with an `[airframe]`, else the `[power]` table's mass (no payload).
    ///
    /// # Errors
    /// [`Error::MissingTable`] when the vehicle has no `[power]` table (or an airframe without
    /// `[[battery]]`), [`Error::TooHeavy`] when airframe and default pack exceed the limit.
    pub fn power_model(&self) -> Result<&PowerModel, Error> {
        match &self.model {
            Some(m) => Ok(m),
            // Rebuild to get the precise error (which table, or which mass).
            None => {
                let table = self.file.power_vehicle()?;
                let mass = default_takeoff_mass(&self.file)?;
                table.with_mass(mass.total_kg)?;
                Err(Error::MissingTable {
                    vehicle: self.file.name.clone(),
                    table: "power",
                    needed_for: "the four-term power model",
                })
            }
        }
    }

    /// The four-term power model at `mass` (from [`Vehicle::takeoff_mass`]).
    ///
    /// # Errors
    /// No `[power]` table, or a mass the model rejects.
    pub fn power_model_at(&self, mass: &TakeoffMass) -> Result<PowerModel, Error> {
        let table = self.file.power_vehicle()?;
        Ok(PowerModel::new(table.with_mass(mass.total_kg)?))
    }

    /// The four-term power model at the take-off mass of `battery` and `payload_kg`, and that
    /// mass. A vehicle without a `[power]` table is refused for that first, whatever its mass.
    ///
    /// # Errors
    /// No `[power]` table, then as [`Vehicle::takeoff_mass`].
    pub fn power_model_with(
        &self,
        battery: Option<&str>,
        payload_kg: f64,
    ) -> Result<(PowerModel, TakeoffMass), Error> {
        self.file.power_vehicle()?;
        let mass = self.takeoff_mass(battery, payload_kg)?;
        Ok((self.power_model_at(&mass)?, mass))
    }

    /// The mass every command flies the vehicle at: airframe + pack (`battery` by name, else the
    /// default pack) + payload for a vehicle with an `[airframe]`, checked against its maximum
    /// take-off mass; else (a power model alone) the `[power]` table's mass (or the
    /// `[propulsion]` table's empty mass) + payload.
    ///
    /// # Errors
    /// A payload that is negative or not finite; an unknown pack; a pack named for a vehicle
    /// without an airframe; an airframe without `[[battery]]`; a mass above the airframe's limit.
    pub fn takeoff_mass(
        &self,
        battery: Option<&str>,
        payload_kg: f64,
    ) -> Result<TakeoffMass, Error> {
        takeoff_mass(&self.file, battery, payload_kg)
    }

    /// Airframe + `pack` + payload, checked against the airframe's limit (a scenario's pack,
    /// scaled by its draws, in place of the vehicle's own).
    ///
    /// # Errors
    /// As [`Vehicle::takeoff_mass`].
    pub(crate) fn takeoff_mass_with(
        &self,
        pack: &Pack,
        payload_kg: f64,
    ) -> Result<TakeoffMass, Error> {
        airframe_pack_payload(&self.file, pack, payload_kg)
    }

    /// Every term of the four-term model at `state` (power seed eqs 7-14), at the default
    /// take-off mass (see [`Vehicle::power_model`]).
    ///
    /// # Errors
    /// No `[power]` table, no default take-off mass, or a state the model rejects (NaN, negative
    /// airspeed, tilt beyond 90 deg).
    pub fn power(&self, state: &FlightState) -> Result<PowerBreakdown, Error> {
        Ok(self.power_model()?.evaluate(state)?)
    }

    /// The same vehicle with another efficiency `eta` in `(0, 1]` (an in-flight re-calibration):
    /// the power model and the aircraft the planner flies both use it.
    ///
    /// # Errors
    /// No `[power]` table, or an efficiency outside `(0, 1]`.
    pub fn with_efficiency(&self, efficiency: f64) -> Result<Self, Error> {
        let mut file = self.file.clone();
        let params = file.power.as_mut().ok_or_else(|| Error::MissingTable {
            vehicle: self.file.name.clone(),
            table: "power",
            needed_for: "an efficiency re-calibration",
        })?;
        params.efficiency = efficiency;
        Self::from_file(file)
    }

    /// The density the vehicle file's constants hold at, kg/m^3: its `[power]` table's
    /// `air_density_kg_m3`, else its `[propulsion]` table's, else ISA sea level.
    pub fn air_density_kg_m3(&self) -> f64 {
        self.file
            .power
            .as_ref()
            .map(|p| p.air_density_kg_m3)
            .or_else(|| self.file.propulsion.as_ref().map(|p| p.air_density_kg_m3))
            .unwrap_or(aloft_core::ISA_SEA_LEVEL_DENSITY_KG_M3)
    }

    /// The same vehicle in air of density `rho` (kg/m^3, decided by `crate::engine::conditions::air`): the four-term constants carried to its density term by term
    /// (`aloft_power::VehicleParams::in_air`: induced and `kappa1` profile power at fixed thrust
    /// `∝ rho^-1/2`, body drag `∝ rho`), the propulsion chain computing in it, and a stated
    /// `max_thrust_n` (a fixed-pitch rotor at its largest speed: thrust `∝ rho`) with the largest
    /// take-off mass falling in proportion in thinner air (never rising in denser). A vehicle
    /// that does not state its maximum thrust keeps its envelope: its default limit is a lower
    /// bound drawn from its take-off mass and tilt, not a measurement. Flying a vehicle in the
    /// air it is already in returns it unchanged.
    ///
    /// # Errors
    /// A density the model rejects (not positive, above 10 kg/m^3).
    pub fn in_air(&self, rho: f64) -> Result<Self, Error> {
        let s = rho / self.air_density_kg_m3();
        // Within 1e-12: the same air (a vehicle flown twice in it).
        if (s - 1.0).abs() < 1e-12 {
            return Ok(self.clone());
        }
        let mut file = self.file.clone();
        if let Some(power) = file.power.as_mut() {
            *power = power.in_air(rho);
        }
        if let Some(propulsion) = file.propulsion.as_mut() {
            propulsion.air_density_kg_m3 = rho;
        }
        if let Some(airframe) = file.airframe.as_mut() {
            if let Some(thrust) = airframe.max_thrust_n.as_mut() {
                *thrust *= s;
                airframe.max_takeoff_mass_kg *= s.min(1.0);
            }
        }
        Self::from_file(file)
    }

    /// Notes for the reader about how the vehicle is modelled (e.g. a propulsion chain without a
    /// drag law).
    pub fn notes(&self) -> Vec<String> {
        self.file
            .aircraft(ModelOptions::default())
            .map(|(_, notes)| notes)
            .unwrap_or_default()
    }

    /// A pack by name (case-insensitive), or the vehicle's default pack.
    ///
    /// # Errors
    /// No `[[battery]]` table, or no pack of that name (the message lists the packs).
    pub fn battery(&self, name: Option<&str>) -> Result<Pack, Error> {
        self.file.battery(name)
    }

    /// The vehicle's defaults for missions: its cruise speed and RTL altitude.
    pub(crate) fn flight_defaults(&self) -> FlightDefaults {
        let airframe = self.file.airframe.as_ref();
        FlightDefaults {
            cruise_speed_mps: airframe.and_then(|a| a.cruise_speed_mps),
            rtl_altitude_m: airframe.and_then(|a| a.rtl_altitude_m),
        }
    }

    /// The aircraft the planner flies, or the error that says which table is missing.
    pub(crate) fn aircraft(&self) -> Result<&Aircraft, Error> {
        match &self.aircraft {
            Some(a) => Ok(a),
            // Rebuild to get the precise error (which table, what for).
            None => Err(self
                .file
                .aircraft(ModelOptions::default())
                .err()
                .unwrap_or_else(|| Error::MissingTable {
                    vehicle: self.file.name.clone(),
                    table: "airframe",
                    needed_for: "the mission planner",
                })),
        }
    }
}

/// The take-off mass of [`Vehicle::takeoff_mass`] for a vehicle file.
fn takeoff_mass(
    file: &VehicleFile,
    battery: Option<&str>,
    payload_kg: f64,
) -> Result<TakeoffMass, Error> {
    check_payload(payload_kg)?;
    if file.airframe.is_some() {
        return airframe_pack_payload(file, &file.battery(battery)?, payload_kg);
    }
    if battery.is_some() {
        return Err(Error::MissingTable {
            vehicle: file.name.clone(),
            table: "airframe",
            needed_for: "a take-off mass with a chosen pack (airframe + pack + payload)",
        });
    }
    let (table, table_kg) = match (&file.power, &file.propulsion) {
        (Some(p), _) => ("power", p.mass_kg),
        (None, Some(p)) => ("propulsion", p.empty_mass_kg),
        (None, None) => {
            return Err(Error::MissingTable {
                vehicle: file.name.clone(),
                table: "airframe",
                needed_for: "a take-off mass (or a [power] table with its mass)",
            })
        }
    };
    Ok(TakeoffMass {
        total_kg: table_kg + payload_kg,
        parts: MassParts::ModelTable {
            table,
            table_kg,
            payload_kg,
        },
    })
}

/// The default take-off mass: the default pack, no payload.
fn default_takeoff_mass(file: &VehicleFile) -> Result<TakeoffMass, Error> {
    takeoff_mass(file, None, 0.0)
}

/// Airframe + `pack` + payload, checked against the airframe's maximum take-off mass.
fn airframe_pack_payload(
    file: &VehicleFile,
    pack: &Pack,
    payload_kg: f64,
) -> Result<TakeoffMass, Error> {
    check_payload(payload_kg)?;
    let airframe = file.airframe()?;
    let total_kg = airframe.mass_kg() + pack.mass_kg() + payload_kg;
    if total_kg > airframe.max_takeoff_mass_kg() {
        return Err(Error::TooHeavy {
            mass_kg: total_kg,
            max_kg: airframe.max_takeoff_mass_kg(),
            battery: pack.name().to_string(),
        });
    }
    Ok(TakeoffMass {
        total_kg,
        parts: MassParts::Airframe {
            airframe_kg: airframe.mass_kg(),
            battery: pack.name().to_string(),
            pack_kg: pack.mass_kg(),
            payload_kg,
        },
    })
}

/// A payload is a mass, finite and not negative.
fn check_payload(payload_kg: f64) -> Result<(), Error> {
    if payload_kg.is_finite() && payload_kg >= 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidInput {
            name: "payload_kg",
            value: payload_kg,
            unit: "kg",
            expected: "a mass, finite and not negative",
        })
    }
}

/// One vehicle as `aloft vehicles` lists it (and `aloft serve` lists the vehicles given to it
/// or dropped on its page: [`Vehicle::entry`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VehicleEntry {
    /// Name on the command line.
    pub name: String,
    /// One line about the vehicle and its source.
    pub description: String,
    /// The mass every command flies it at without payload, kg: airframe + default pack, or for
    /// a vehicle without an airframe its `[power]` table's mass.
    pub takeoff_mass_kg: f64,
    /// Models it has tables for (`power`, `propulsion`).
    pub models: Vec<&'static str>,
    /// Its battery options (`--battery`), the default first.
    pub batteries: Vec<String>,
    /// The published figures it was built from and where they were published.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub source: Option<VehicleSource>,
}

impl Vehicle {
    /// The vehicle as `aloft vehicles` lists one, under its own name.
    ///
    /// # Errors
    /// A vehicle without a default take-off mass (an airframe without `[[battery]]`, a default
    /// pack above the airframe's limit, no table that gives a mass): no command can fly it.
    pub fn entry(&self) -> Result<VehicleEntry, Error> {
        entry_of(&self.file)
    }
}

/// The entry of a vehicle file (see [`Vehicle::entry`]).
fn entry_of(f: &VehicleFile) -> Result<VehicleEntry, Error> {
    let mut models = Vec::new();
    if f.power.is_some() {
        models.push("power");
    }
    if f.propulsion.is_some() {
        models.push("propulsion");
    }
    Ok(VehicleEntry {
        name: f.name.clone(),
        takeoff_mass_kg: default_takeoff_mass(f)?.total_kg,
        batteries: f.battery_names().iter().map(|s| s.to_string()).collect(),
        source: f.source.clone(),
        description: f.description.clone(),
        models,
    })
}

/// The built-in vehicles, the default first.
///
/// # Errors
/// None in practice: the built-in files are checked by a unit test.
pub fn list_vehicles() -> Result<Vec<VehicleEntry>, Error> {
    BUILTIN_VEHICLES
        .iter()
        .map(|b| entry_of(&VehicleFile::builtin(b.name)?))
        .collect()
}

/// A vehicle's defaults for missions (the autopilot settings of its `[airframe]`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct FlightDefaults {
    /// Ground speed of a mission's legs that give none, m/s.
    pub(crate) cruise_speed_mps: Option<f64>,
    /// Lowest height of a return to home, m.
    pub(crate) rtl_altitude_m: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn takeoff_mass_is_airframe_pack_and_payload() {
        let m100 = Vehicle::builtin("dji-m100").unwrap();
        let m = m100.takeoff_mass(Some("tb48d"), 0.5).unwrap();
        // DJI: 1755 g airframe, 676 g TB48D.
        assert!((m.total_kg - (1.755 + 0.676 + 0.5)).abs() < 1e-12);
        assert_eq!(m.battery(), Some("TB48D"));
        assert!((m.payload_kg() - 0.5).abs() < 1e-15);
        assert_eq!(
            m.describe(),
            "take-off mass 2.931 kg (airframe 1.755 kg + TB48D 0.676 kg + payload 0.500 kg)"
        );
        // The default: the default pack, no payload; the cached model flies it.
        let d = m100.takeoff_mass(None, 0.0).unwrap();
        assert!((d.total_kg - 2.355).abs() < 1e-12);
        let model = m100.power_model().unwrap();
        assert!((model.vehicle().mass_kg() - d.total_kg).abs() < 1e-15);
    }

    #[test]
    fn refused_masses_name_the_reason() {
        let m100 = Vehicle::builtin("dji-m100").unwrap();
        let e = m100.takeoff_mass(None, -0.1).unwrap_err().to_string();
        assert!(e.contains("payload_kg") && e.contains("-0.1"), "{e}");
        let e = m100.takeoff_mass(None, f64::NAN).unwrap_err().to_string();
        assert!(e.contains("payload_kg"), "{e}");
        let e = m100.takeoff_mass(Some("2xTB48D"), 0.5).unwrap_err();
        assert!(matches!(e, Error::TooHeavy { .. }), "{e}");
        assert!(e.to_string().contains("3.767 kg") && e.to_string().contains("3.600 kg limit"));
        let paper = Vehicle::builtin("dji-m100-paper").unwrap();
        let m = paper.takeoff_mass(None, 0.25).unwrap();
        assert!((m.total_kg - 3.54).abs() < 1e-12 && m.battery().is_none());
        let e = paper
            .takeoff_mass(Some("TB47D"), 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("[airframe]"), "{e}");
    }

    /// A vehicle without a [power] table is refused for that, before its mass is looked at
    /// (this one has an airframe but no pack either).
    #[test]
    fn a_missing_power_table_is_named_before_the_mass() {
        let text = include_str!("../../../fixtures/vehicles/dji-m100.toml");
        let airframe = &text[text.find("[airframe]").unwrap()..text.find("[[battery]]").unwrap()];
        let v = Vehicle::from_toml(&format!("name = \"frame\"\n{airframe}"), "test").unwrap();
        for e in [
            v.power_model_with(None, 0.0).unwrap_err(),
            v.power_model().unwrap_err(),
        ] {
            assert!(e.to_string().contains("no [power] table"), "{e}");
        }
        let e = v.takeoff_mass(None, 0.0).unwrap_err().to_string();
        assert!(e.contains("[battery]"), "{e}");
    }

    #[test]
    fn every_builtin_has_a_default_takeoff_mass_within_its_limit() {
        for name in builtin_names() {
            let v = Vehicle::builtin(name).unwrap();
            let m = v.takeoff_mass(None, 0.0).unwrap();
            if let Some(power) = &v.file().power {
                let model = v.power_model().unwrap();
                assert!(
                    (model.vehicle().mass_kg() - m.total_kg).abs() < 1e-12,
                    "{name}"
                );
                // Only a power model alone flies its table's mass.
                if v.file().airframe.is_some() {
                    assert!(matches!(m.parts, MassParts::Airframe { .. }), "{name}");
                } else {
                    assert!((power.mass_kg - m.total_kg).abs() < 1e-15, "{name}");
                }
            }
        }
    }

    #[test]
    fn a_missing_path_is_no_such_file_and_a_wrong_name_lists_the_builtins() {
        for path in ["no/such/dir/quad.toml", "quad.toml"] {
            let e = Vehicle::load(path).unwrap_err();
            assert!(matches!(e, Error::NoSuchVehicleFile { .. }), "{e}");
            assert_eq!(e.to_string(), format!("vehicle file {path}: no such file"));
        }
        let e = Vehicle::load("dji-m300").unwrap_err();
        assert!(matches!(e, Error::UnknownVehicle { .. }), "{e}");
        assert!(e.to_string().contains("dji-m100-paper"), "{e}");
    }
}
