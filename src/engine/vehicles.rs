//! Vehicles: load one (a built-in name, a vehicle file, TOML text), list the built-in ones.

use std::path::Path;

use serde::Serialize;

use aloft_planner::{Aircraft, Pack};
use aloft_power::{FlightState, ModelOptions, PowerBreakdown, PowerModel};

use super::files::read_text_file;
use crate::error::Error;
use crate::vehicle::{builtin_names, VehicleFile, VehicleSource, BUILTIN_VEHICLES};

/// A loaded, validated vehicle: its file, the power model of its `[power]` table (when present)
/// and the aircraft the planner flies (when it has an `[airframe]` and a model).
#[derive(Debug, Clone)]
pub struct Vehicle {
    file: VehicleFile,
    model: Option<PowerModel>,
    aircraft: Option<Aircraft>,
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
    /// [`Error::UnknownVehicle`] when it is neither; the file's read or format error otherwise.
    pub fn load(name_or_path: &str) -> Result<Self, Error> {
        if builtin_names().contains(&name_or_path) {
            return Self::builtin(name_or_path);
        }
        let path = Path::new(name_or_path);
        if !path.exists() {
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
            Some(_) => Some(PowerModel::new(file.power_vehicle()?)),
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

    /// The overall efficiency `eta` of the four-term model, when the vehicle has one.
    pub fn efficiency(&self) -> Option<f64> {
        self.model.as_ref().map(|m| m.vehicle().efficiency())
    }

    /// The four-term power model (at the `[power]` table's mass).
    ///
    /// # Errors
    /// [`Error::MissingTable`] when the vehicle has no `[power]` table.
    pub fn power_model(&self) -> Result<&PowerModel, Error> {
        self.model.as_ref().ok_or_else(|| Error::MissingTable {
            vehicle: self.file.name.clone(),
            table: "power",
            needed_for: "the four-term power model",
        })
    }

    /// Every term of the four-term model at `state` (power seed eqs 7-14).
    ///
    /// # Errors
    /// No `[power]` table, or a state the model rejects (NaN, negative airspeed, tilt beyond 90 deg).
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
    pub(crate) fn flight_defaults(&self) -> super::flown::FlightDefaults {
        let airframe = self.file.airframe.as_ref();
        super::flown::FlightDefaults {
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

/// One built-in vehicle as `aloft vehicles` lists it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VehicleEntry {
    /// Name on the command line.
    pub name: &'static str,
    /// One line about the vehicle and its source.
    pub description: String,
    /// Mass of the `[power]` table, else the empty mass of the `[propulsion]` table, kg.
    pub mass_kg: Option<f64>,
    /// Models it has tables for (`power`, `propulsion`).
    pub models: Vec<&'static str>,
    /// Its battery options (`--battery`), the default first.
    pub batteries: Vec<String>,
    /// The published figures it was built from and where they were published.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub source: Option<VehicleSource>,
}

/// The built-in vehicles, the default first.
///
/// # Errors
/// None in practice: the built-in files are checked by a unit test.
pub fn list_vehicles() -> Result<Vec<VehicleEntry>, Error> {
    BUILTIN_VEHICLES
        .iter()
        .map(|b| {
            let f = VehicleFile::builtin(b.name)?;
            let mut models = Vec::new();
            if f.power.is_some() {
                models.push("power");
            }
            if f.propulsion.is_some() {
                models.push("propulsion");
            }
            Ok(VehicleEntry {
                name: b.name,
                mass_kg: f
                    .power
                    .as_ref()
                    .map(|p| p.mass_kg)
                    .or(f.propulsion.as_ref().map(|p| p.empty_mass_kg)),
                batteries: f.battery_names().iter().map(|s| s.to_string()).collect(),
                source: f.source.clone(),
                description: f.description,
                models,
            })
        })
        .collect()
}
