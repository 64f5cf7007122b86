//! Vehicle files and the built-in vehicles.
//!
//! A vehicle file is TOML with the units in the key names and unknown keys rejected:
//!
//! ```toml
//! name = "dji-m100"
//! description = "..."
//!
//! [power]        # four-term power model parameters: aloft_power::VehicleParams
//! mass_kg = 3.29
//! # ...
//!
//! [propulsion]   # propulsion chain: aloft_propulsion::PropulsionSpec
//! empty_mass_kg = 7.484
//! # ... with [propulsion.propeller], [propulsion.motor], [propulsion.esc], [propulsion.battery]
//! ```
//!
//! Tables are optional, so a vehicle can describe only the models it has data for; asking for a
//! model whose table is missing is an [`Error::MissingTable`].
//! Built-in vehicles are compiled into the binary from `fixtures/vehicles/`.

use serde::{Deserialize, Serialize};

use crate::error::Error;

/// A built-in vehicle: its name and the TOML text it is built from.
#[derive(Debug, Clone, Copy)]
pub struct BuiltinVehicle {
    /// Name used on the command line.
    pub name: &'static str,
    /// The vehicle file text (identical to `fixtures/vehicles/<name>.toml`).
    pub toml: &'static str,
}

/// The built-in vehicles, the default first.
pub const BUILTIN_VEHICLES: &[BuiltinVehicle] = &[
    BuiltinVehicle {
        name: "dji-m100",
        toml: include_str!("../fixtures/vehicles/dji-m100.toml"),
    },
    BuiltinVehicle {
        name: "aec-quadrotor",
        toml: include_str!("../fixtures/vehicles/aec-quadrotor.toml"),
    },
];

/// Name of the default vehicle.
pub const DEFAULT_VEHICLE: &str = "dji-m100";

/// A parsed vehicle file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleFile {
    /// Short name.
    pub name: String,
    /// One line about the vehicle and its source.
    #[serde(default)]
    pub description: String,
    /// Four-term power model parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub power: Option<aloft_power::VehicleParams>,
    /// Propulsion chain: propeller, motor, ESC, battery packs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub propulsion: Option<aloft_propulsion::PropulsionSpec>,
}

impl VehicleFile {
    /// Parse vehicle TOML text; `origin` names the text in error messages (a path or a name).
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, Error> {
        let file: Self = toml::from_str(text).map_err(|e| Error::VehicleFormat {
            origin: origin.to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        // Validate every table that is present, so a file that loads is usable.
        if let Some(p) = &file.power {
            aloft_power::Vehicle::new(p.clone())?;
        }
        if let Some(p) = &file.propulsion {
            p.clone().into_model()?;
        }
        Ok(file)
    }

    /// A built-in vehicle by name.
    pub fn builtin(name: &str) -> Result<Self, Error> {
        let b = BUILTIN_VEHICLES
            .iter()
            .find(|b| b.name == name)
            .ok_or_else(|| Error::UnknownVehicle {
                name: name.to_string(),
                known: builtin_names().join(", "),
            })?;
        Self::from_toml_str(b.toml, &format!("built-in '{}'", b.name))
    }

    /// The validated propulsion chain of the `[propulsion]` table.
    pub fn propulsion_system(&self) -> Result<aloft_propulsion::PropulsionSystem, Error> {
        let spec = self.propulsion.clone().ok_or_else(|| Error::MissingTable {
            vehicle: self.name.clone(),
            table: "propulsion",
            needed_for: "the propulsion chain",
        })?;
        Ok(spec.into_model()?)
    }

    /// The validated power-model vehicle of the `[power]` table.
    pub fn power_vehicle(&self) -> Result<aloft_power::Vehicle, Error> {
        let params = self.power.clone().ok_or_else(|| Error::MissingTable {
            vehicle: self.name.clone(),
            table: "power",
            needed_for: "the four-term power model",
        })?;
        Ok(aloft_power::Vehicle::new(params)?)
    }
}

/// Names of the built-in vehicles.
pub fn builtin_names() -> Vec<&'static str> {
    BUILTIN_VEHICLES.iter().map(|b| b.name).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_parses_and_validates() {
        for b in BUILTIN_VEHICLES {
            let f = VehicleFile::builtin(b.name).unwrap();
            assert_eq!(f.name, b.name);
        }
    }

    #[test]
    fn unknown_keys_and_names_are_errors() {
        let text = "name = \"x\"\nwingspan_m = 3.0\n";
        let e = VehicleFile::from_toml_str(text, "test")
            .unwrap_err()
            .to_string();
        assert!(e.contains("wingspan_m"), "{e}");
        let e = VehicleFile::builtin("dji-m200").unwrap_err().to_string();
        assert!(e.contains("dji-m200") && e.contains("dji-m100"), "{e}");
    }

    #[test]
    fn a_missing_power_table_is_named() {
        let f = VehicleFile::from_toml_str("name = \"bare\"\n", "test").unwrap();
        let e = f.power_vehicle().unwrap_err().to_string();
        assert!(e.contains("[power]"), "{e}");
    }

    #[test]
    fn invalid_values_in_a_file_are_rejected_on_load() {
        let text = VehicleFile::builtin("dji-m100").unwrap();
        let mut p = text.power.unwrap();
        p.mass_kg = -3.0;
        let bad = toml::to_string(&VehicleFile {
            name: "bad".into(),
            description: String::new(),
            power: Some(p),
            propulsion: None,
        })
        .unwrap();
        let e = VehicleFile::from_toml_str(&bad, "test")
            .unwrap_err()
            .to_string();
        assert!(e.contains("mass_kg") && e.contains("-3"), "{e}");
    }
}
