//! Vehicle files and the built-in vehicles.
//!
//! A vehicle file is TOML with the units in the key names and unknown keys rejected:
//!
//! ```toml
//! name = "dji-m100"
//! description = "..."
//!
//! [power]        # four-term power model parameters: aloft_power::VehicleParams
//! mass_kg = 2.355  # the mass only of a vehicle without [airframe]
//! # ...
//!
//! [propulsion]   # propulsion chain: aloft_propulsion::PropulsionSpec
//! empty_mass_kg = 7.484
//! # ... with [propulsion.propeller], [propulsion.motor], [propulsion.esc], [propulsion.battery]
//!
//! [airframe]     # mass without battery, limits: aloft_planner::AirframeSpec
//! mass_kg = 1.755
//! # ...
//!
//! [[battery]]    # packs for missions, one table each: aloft_propulsion::BatterySpec, the same
//!                # description [propulsion.battery] uses
//! name = "TB47D"
//! default = true
//! # ...
//! ```
//!
//! Tables are optional, so a vehicle can describe only the models it has data for; asking for a
//! model whose table is missing is an [`Error::MissingTable`].
//!
//! One vehicle, one mass: a vehicle with an `[airframe]` flies at airframe + pack + payload in
//! every command (`crate::engine::Vehicle::takeoff_mass`); the `[power]` table's `mass_kg` is the
//! mass only of a vehicle without an airframe (a power model alone, e.g. `dji-m100-paper`).
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

/// A built-in vehicle: its name and the text of `fixtures/vehicles/<name>.toml`.
macro_rules! builtin {
    ($name:literal) => {
        BuiltinVehicle {
            name: $name,
            toml: include_str!(concat!("../fixtures/vehicles/", $name, ".toml")),
        }
    };
}

/// A commented vehicle file for one's own multirotor (`aloft vehicles template`): every value a
/// mission needs, the ones to change marked, loadable as it is (a 1.2 kg 3S quadrotor). Every key
/// is documented in docs/vehicle-file.md.
pub const VEHICLE_TEMPLATE: &str = include_str!("vehicle_template.toml");

/// The built-in vehicles, the default first.
pub const BUILTIN_VEHICLES: &[BuiltinVehicle] = &[
    builtin!("dji-m100"),
    builtin!("dji-m600"),
    builtin!("dji-inspire1"),
    builtin!("dji-inspire1-pro"),
    builtin!("aec-quadrotor"),
    builtin!("dji-m100-paper"),
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
    /// The published figures the vehicle was built from and where they were published.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<VehicleSource>,
    /// Four-term power model parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub power: Option<aloft_power::VehicleParams>,
    /// Propulsion chain: propeller, motor, ESC, battery packs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub propulsion: Option<aloft_propulsion::PropulsionSpec>,
    /// Airframe mass without battery and the flight envelope (missions and endurance queries).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub airframe: Option<aloft_planner::AirframeSpec>,
    /// Battery packs for missions (`[[battery]]` tables).
    #[serde(default, rename = "battery", skip_serializing_if = "Vec::is_empty")]
    pub batteries: Vec<aloft_planner::BatterySpec>,
}

/// Where a vehicle's numbers come from (`[source]`): shown by `aloft vehicles`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleSource {
    /// The published figures the vehicle was built from, in words with units.
    pub figures: String,
    /// The one figure the efficiency was calibrated on.
    pub calibrated_on: String,
    /// Where the figures were published.
    pub published: String,
}

impl VehicleFile {
    /// Parse vehicle TOML text; `origin` names the text in error messages (a path or a name).
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, Error> {
        aloft_core::check_value_count(text).map_err(|count| Error::VehicleFormat {
            origin: origin.to_string(),
            message: aloft_core::too_many_values(count),
        })?;
        let file: Self = toml::from_str(text).map_err(|e| Error::VehicleFormat {
            origin: origin.to_string(),
            message: aloft_core::file_message(&e.to_string()),
        })?;
        // Validate every table that is present, so a file that loads is usable.
        if let Some(p) = &file.power {
            aloft_power::Vehicle::new(p.clone())?;
        }
        if let Some(p) = &file.propulsion {
            p.clone().into_model()?;
        }
        let planner_error = |e: aloft_planner::PlannerError| Error::VehicleFormat {
            origin: origin.to_string(),
            message: e.to_string(),
        };
        if let Some(a) = &file.airframe {
            aloft_planner::Airframe::new(a.clone()).map_err(planner_error)?;
        }
        for (k, b) in file.batteries.iter().enumerate() {
            aloft_planner::Pack::new(b).map_err(planner_error)?;
            if file.batteries[..k].iter().any(|o| o.name == b.name) {
                return Err(Error::VehicleFormat {
                    origin: origin.to_string(),
                    message: format!("battery name '{}' appears twice", b.name),
                });
            }
        }
        if file.batteries.iter().filter(|b| b.default).count() > 1 {
            return Err(Error::VehicleFormat {
                origin: origin.to_string(),
                message: "more than one [[battery]] has default = true".to_string(),
            });
        }
        Ok(file)
    }

    /// The validated `[airframe]` table.
    pub fn airframe(&self) -> Result<aloft_planner::Airframe, Error> {
        let spec = self.airframe.clone().ok_or_else(|| Error::MissingTable {
            vehicle: self.name.clone(),
            table: "airframe",
            needed_for: "the mission planner (airframe mass and limits)",
        })?;
        aloft_planner::Airframe::new(spec).map_err(|e| Error::VehicleFormat {
            origin: self.name.clone(),
            message: e.to_string(),
        })
    }

    /// Names of the packs, the default first.
    pub fn battery_names(&self) -> Vec<&str> {
        let mut names: Vec<&str> = self.batteries.iter().map(|b| b.name.as_str()).collect();
        if let Some(d) = self.batteries.iter().position(|b| b.default) {
            names.swap(0, d);
        }
        names
    }

    /// A pack by name (case-insensitive), or the default pack (the one marked `default`, else the
    /// first).
    pub fn battery(&self, name: Option<&str>) -> Result<aloft_planner::Pack, Error> {
        if self.batteries.is_empty() {
            return Err(Error::MissingTable {
                vehicle: self.name.clone(),
                table: "[battery]",
                needed_for: "the mission planner (the pack)",
            });
        }
        let spec = match name {
            Some(n) => self
                .batteries
                .iter()
                .find(|b| b.name.eq_ignore_ascii_case(n))
                .ok_or_else(|| Error::VehicleFormat {
                    origin: self.name.clone(),
                    message: format!(
                        "no battery '{n}' on this vehicle: its packs are {}",
                        self.battery_names().join(", ")
                    ),
                })?,
            None => self
                .batteries
                .iter()
                .find(|b| b.default)
                .unwrap_or(&self.batteries[0]),
        };
        aloft_planner::Pack::new(spec).map_err(|e| Error::VehicleFormat {
            origin: self.name.clone(),
            message: e.to_string(),
        })
    }

    /// The aircraft the planner flies: the four-term model of `[power]` when present (its drag
    /// and rotor radius), else the propulsion chain of `[propulsion]` with no drag (the chain
    /// carries no drag law; a note says so). Returns the aircraft and notes for the reader.
    pub fn aircraft(
        &self,
        options: aloft_power::ModelOptions,
    ) -> Result<(aloft_planner::Aircraft, Vec<String>), Error> {
        let airframe = self.airframe()?;
        if self.power.is_some() {
            let vehicle = self.power_vehicle()?;
            return Ok((
                aloft_planner::Aircraft::four_term(airframe, vehicle, options),
                vec![],
            ));
        }
        if self.propulsion.is_some() {
            let system = self.propulsion_system()?;
            let radius = system.propeller.diameter_m() / 2.0;
            let drag = aloft_power::CubicDrag::new(0.0, 0.0, 0.0)?;
            let aircraft = aloft_planner::Aircraft::propulsion_chain(
                airframe, system, drag, radius,
            )
            .map_err(|e| Error::VehicleFormat {
                origin: self.name.clone(),
                message: e.to_string(),
            })?;
            return Ok((
                aircraft,
                vec!["propulsion chain without a drag law: drag is taken as zero".to_string()],
            ));
        }
        Err(Error::MissingTable {
            vehicle: self.name.clone(),
            table: "power",
            needed_for: "the mission planner (or a [propulsion] table)",
        })
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
        // Named by its place (a file named as a vehicle may be any file: its text is not
        // quoted), with the nearest known key.
        let text = "name = \"x\"\nwingspan_m = 3.0\n";
        let e = VehicleFile::from_toml_str(text, "test")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains("unknown field"), "{e}");
        assert!(!e.contains("wingspan_m"), "{e}");
        let e = VehicleFile::from_toml_str("nmae = \"x\"\n", "test")
            .unwrap_err()
            .to_string();
        assert!(e.contains("did you mean `name`?"), "{e}");
        let e = VehicleFile::builtin("dji-m200").unwrap_err().to_string();
        assert!(e.contains("dji-m200") && e.contains("dji-m100"), "{e}");
    }

    /// The paper-validation case is the M100's [power] table at the seed's 3.29 kg (section V):
    /// the two files cannot drift apart.
    #[test]
    fn m100_paper_is_the_m100_power_table_at_3_29_kg() {
        let paper = VehicleFile::builtin("dji-m100-paper").unwrap();
        let m100 = VehicleFile::builtin("dji-m100").unwrap();
        let mut p = paper.power.clone().unwrap();
        assert_eq!(p.mass_kg.to_bits(), 3.29f64.to_bits());
        p.mass_kg = m100.power.as_ref().unwrap().mass_kg;
        assert_eq!(&p, m100.power.as_ref().unwrap());
        assert!(paper.airframe.is_none() && paper.batteries.is_empty());
        assert!(paper.propulsion.is_none());
    }

    /// The propulsion seed's 16.5 lb (S4) is the airframe's 9.5 lb plus four 1.75 lb packs (S5),
    /// so `aloft propulsion` and the planner fly the same take-off mass.
    #[test]
    fn aec_empty_mass_is_airframe_plus_its_packs() {
        let f = VehicleFile::builtin("aec-quadrotor").unwrap();
        let lb = 0.45359237;
        let airframe = f.airframe().unwrap().mass_kg();
        let pack = f.battery(None).unwrap().mass_kg();
        assert!((airframe - 9.5 * lb).abs() < 1e-9, "{airframe}");
        assert!((pack - 4.0 * 1.75 * lb).abs() < 1e-9, "{pack}");
        let empty = f.propulsion.as_ref().unwrap().empty_mass_kg;
        assert!((empty - 16.5 * lb).abs() < 1e-9, "{empty}");
        assert!((airframe + pack - empty).abs() < 1e-9);
        // The worked example (S3: 26.5 lb) is within the largest mass flown (S6: 27.1 lb).
        let max = f.airframe().unwrap().max_takeoff_mass_kg();
        assert!((max - 27.1 * lb).abs() < 1e-9 && 26.5 * lb < max);
    }

    #[test]
    fn m100_has_its_packs_and_airframe() {
        let f = VehicleFile::builtin("dji-m100").unwrap();
        assert_eq!(f.battery_names(), ["TB47D", "TB48D", "2xTB47D", "2xTB48D"]);
        let b = f.battery(None).unwrap();
        assert_eq!(b.name(), "TB47D");
        // DJI: 2355 g with the TB47D
        let a = f.airframe().unwrap();
        assert!((a.mass_kg() + b.mass_kg() - 2.355).abs() < 1e-12);
        assert!(f.battery(Some("tb48d")).is_ok());
        let e = f.battery(Some("TB55")).unwrap_err().to_string();
        assert!(e.contains("TB55") && e.contains("TB47D"), "{e}");
    }

    #[test]
    fn invalid_airframe_and_battery_values_are_rejected_on_load() {
        let text = include_str!("../fixtures/vehicles/dji-m100.toml");
        let bad = text.replace("max_tilt_deg = 35.0", "max_tilt_deg = 95.0");
        let e = VehicleFile::from_toml_str(&bad, "test")
            .unwrap_err()
            .to_string();
        assert!(e.contains("max_tilt_deg") && e.contains("95"), "{e}");
        let bad = text.replace("energy_wh = 99.9", "energy_wh = 150.0");
        let e = VehicleFile::from_toml_str(&bad, "test")
            .unwrap_err()
            .to_string();
        assert!(e.contains("energy_wh") && e.contains("150"), "{e}");
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
            source: None,
            power: Some(p),
            propulsion: None,
            airframe: None,
            batteries: vec![],
        })
        .unwrap();
        let e = VehicleFile::from_toml_str(&bad, "test")
            .unwrap_err()
            .to_string();
        assert!(e.contains("mass_kg") && e.contains("-3"), "{e}");
    }
}
