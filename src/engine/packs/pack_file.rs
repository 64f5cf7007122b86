//! Pack files: one battery pack in a TOML file of its own, as `aloft pack fit` writes it and
//! `--battery pack.toml` flies it.
//!
//! ```toml
//! [battery]            # exactly the keys of a vehicle file's [[battery]] (aloft_propulsion::BatterySpec)
//! name = "pack-7"
//! cells_series = 6
//! capacity_mah = 5200.0
//! # nominal_v, energy_wh, mass_kg, internal_resistance_ohm, cutoff_cell_v, usable_fraction ...
//!
//! [failsafe]           # optional: the autopilot's voltage failsafes, pack volts
//! low_voltage_v = 21.0       # ArduPilot BATT_LOW_VOLT
//! critical_voltage_v = 20.4  # ArduPilot BATT_CRT_VOLT
//!
//! [fitted]             # optional: how the pack was fitted (read and ignored when flying)
//! ```
//!
//! A value of `--battery` that names an existing file ending `.toml` is a pack file
//! ([`is_pack_file`]); [`fly_with_battery`] is the one function every command that flies
//! (mission, plan, endurance, power, validate, live, replay) resolves `--battery` with. The
//! engine's keyword entry points (`aloft serve`, Python) do not call it: over `aloft serve` a
//! request names no file of the server's, so there a `.toml` value is only a pack name.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::engine::basics::files::read_text_file;
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// The autopilot's voltage failsafes of a pack, pack volts.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Failsafe {
    /// The low-voltage failsafe (ArduPilot `BATT_LOW_VOLT`), V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub low_voltage_v: Option<f64>,
    /// The critical-voltage failsafe (ArduPilot `BATT_CRT_VOLT`), V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub critical_voltage_v: Option<f64>,
}

/// A pack file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PackFile {
    /// The pack, with the keys of a vehicle file's `[[battery]]`.
    pub battery: aloft_planner::BatterySpec,
    /// The autopilot's voltage failsafes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failsafe: Option<Failsafe>,
    /// How the pack was fitted (logs, steps, the autopilot's figures): kept, not read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fitted: Option<toml::Table>,
}

/// Whether a `--battery` value names a pack file: an existing file whose name ends `.toml`.
pub fn is_pack_file(battery: &str) -> bool {
    battery.to_ascii_lowercase().ends_with(".toml") && Path::new(battery).is_file()
}

impl PackFile {
    /// Parse and check a pack file's text; `origin` names it in errors.
    ///
    /// # Errors
    /// [`Error::PackFile`] naming the key, its value and its range (a capacity of 0, a missing
    /// key, an unknown key).
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, Error> {
        let bad = |message: String| Error::PackFile {
            path: origin.to_string(),
            message,
        };
        aloft_core::check_value_count(text).map_err(|c| bad(aloft_core::too_many_values(c)))?;
        let file: Self =
            toml::from_str(text).map_err(|e| bad(aloft_core::file_message(&e.to_string())))?;
        aloft_planner::Pack::new(&file.battery).map_err(|e| bad(e.to_string()))?;
        if let Some(f) = &file.failsafe {
            for (key, v) in [
                ("low_voltage_v", f.low_voltage_v),
                ("critical_voltage_v", f.critical_voltage_v),
            ] {
                if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0 && *v <= 1e4)) {
                    return Err(bad(format!(
                        "[failsafe] {key} = {v} is invalid: a positive voltage up to 10000 V"
                    )));
                }
            }
        }
        Ok(file)
    }

    /// Read a pack file.
    ///
    /// # Errors
    /// [`Error::Io`] when it cannot be read; as [`PackFile::from_toml_str`].
    pub fn load(path: &Path) -> Result<Self, Error> {
        let text = read_text_file(path, "pack file")?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// The file's TOML text.
    ///
    /// # Errors
    /// [`Error::PackFile`] when a value cannot be written (not finite).
    pub fn to_toml(&self) -> Result<String, Error> {
        toml::to_string(self).map_err(|e| Error::PackFile {
            path: self.battery.name.clone(),
            message: e.to_string(),
        })
    }
}

/// A vehicle with the pack a command flies.
#[derive(Debug, Clone)]
pub struct FlyingPack {
    /// The vehicle, with the pack file's pack among its packs when one was given.
    pub vehicle: Vehicle,
    /// The pack to select by name (`None`: the vehicle's default).
    pub battery: Option<String>,
    /// The pack file's failsafes.
    pub failsafe: Option<Failsafe>,
}

impl FlyingPack {
    /// `options` with the pack file's failsafes where the options give none (the options' own
    /// thresholds, from the flags, come first).
    pub fn with_failsafes(
        &self,
        mut options: crate::engine::missions::mission_options::MissionOptions,
    ) -> crate::engine::missions::mission_options::MissionOptions {
        if let Some(f) = &self.failsafe {
            options.low_voltage_v = options.low_voltage_v.or(f.low_voltage_v);
            options.critical_voltage_v = options.critical_voltage_v.or(f.critical_voltage_v);
        }
        options
    }
}

/// The vehicle and the pack a command flies: `battery` as given when it is a pack name (or
/// none); when it names a pack file ([`is_pack_file`]), that pack added to the vehicle's packs
/// (replacing one of the same name) and selected, with its failsafes.
///
/// # Errors
/// As [`PackFile::load`], or a vehicle that does not accept the pack.
pub fn fly_with_battery(vehicle: Vehicle, battery: Option<&str>) -> Result<FlyingPack, Error> {
    fly_pack(vehicle, battery)
}

/// The command line's `--vehicle NAME|FILE` and `--battery NAME|pack.toml`: the vehicle loaded
/// and flown with the pack ([`fly_with_battery`]), and `battery` set to the pack's name.
///
/// # Errors
/// As [`Vehicle::load`] and [`fly_with_battery`].
pub fn load_flying(vehicle: &str, battery: &mut Option<String>) -> Result<FlyingPack, Error> {
    let flying = fly_pack(Vehicle::load(vehicle)?, battery.as_deref())?;
    battery.clone_from(&flying.battery);
    Ok(flying)
}

fn fly_pack(vehicle: Vehicle, battery: Option<&str>) -> Result<FlyingPack, Error> {
    let Some(path) = battery.filter(|b| is_pack_file(b)) else {
        return Ok(FlyingPack {
            vehicle,
            battery: battery.map(str::to_string),
            failsafe: None,
        });
    };
    let pack = PackFile::load(Path::new(path))?;
    let mut file = vehicle.file().clone();
    let mut spec = pack.battery.clone();
    if spec.name.is_empty() {
        spec.name = Path::new(path)
            .file_stem()
            .map_or_else(|| "pack".to_string(), |s| s.to_string_lossy().into_owned());
    }
    spec.default = false;
    file.batteries
        .retain(|b| !b.name.eq_ignore_ascii_case(&spec.name));
    let name = spec.name.clone();
    file.batteries.push(spec);
    Ok(FlyingPack {
        vehicle: Vehicle::from_file(file)?,
        battery: Some(name),
        failsafe: pack.failsafe,
    })
}
