//! The air a flight flies in: what the caller says of the day (elevation, temperature,
//! humidity, QNH), decided once with its defaults into a density, and the vehicle carried into
//! that air.
//!
//! Precedence, for each quantity on its own:
//! - **elevation**: the flag; else the mission's home altitude above mean sea level (a `.plan`'s
//!   `plannedHomePosition` altitude, a `.waypoints` home row's altitude, a TOML mission's
//!   `[home] altitude_amsl_m`); else sea level;
//! - **temperature**: the flag; else ISA's at the elevation;
//! - **pressure**: ISA's at the elevation, from the QNH when one is given instead of 1013.25 hPa;
//! - **humidity**: the flag; else dry air.
//!
//! When nothing of the day is known (no flag, no home altitude) the flight flies in the vehicle
//! file's density (`air_density_kg_m3` of its `[power]` or `[propulsion]` table), which is ISA
//! sea level unless the file says otherwise. The answer carries the density, the elevation and
//! the temperature and where each came from ([`Air`]).
//!
//! The vehicle's constants hold at its file's density; [`Vehicle::in_air`] carries them to the
//! flight's air term by term (`aloft_power::VehicleParams::in_air`), the propulsion chain
//! computes in the new density directly, and a stated thrust limit falls with it.

use serde::{Deserialize, Serialize};

use aloft_core::atmosphere::{
    isa_temperature_k, rounded_density_altitude_m, Day, DayAir, ImpossibleAir, ELEVATION_RANGE_M,
    ISA_SEA_LEVEL_PRESSURE_PA, QNH_RANGE_HPA, TEMPERATURE_RANGE_C, ZERO_CELSIUS_K,
};
use aloft_core::ISA_SEA_LEVEL_DENSITY_KG_M3;

use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// What the caller says of the day's air (every field optional; JSON keys as the field names).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AirInput {
    /// Elevation of the flight above mean sea level, m (-430 to 11,000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elevation_m: Option<f64>,
    /// Air temperature, C (-60 to 60; default ISA's at the elevation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<f64>,
    /// Relative humidity, percent (0 to 100; default 0, dry air).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub humidity_percent: Option<f64>,
    /// The day's QNH (altimeter setting), hPa (850 to 1100; default ISA's 1013.25).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub qnh_hpa: Option<f64>,
    /// A density known outright, kg/m^3 (0.3 to 2): it overrides everything above (a caller
    /// that decided the air once and flies again in it, as `aloft live` planning the route
    /// ahead). No command-line flag.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub air_density_kg_m3: Option<f64>,
}

impl AirInput {
    /// The air of a density known outright.
    pub fn of_density(air_density_kg_m3: f64) -> Self {
        Self {
            air_density_kg_m3: Some(air_density_kg_m3),
            ..Self::default()
        }
    }

    /// Whether the caller said anything of the day.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// Each given value within its range, or the error that names it and the range.
    ///
    /// # Errors
    /// [`Error::Air`] naming the value, its unit and its range.
    pub fn check(&self) -> Result<(), Error> {
        let checks = [
            (
                "elevation_m",
                self.elevation_m,
                ELEVATION_RANGE_M,
                "m",
                "from -430 m (the Dead Sea's shore) to 11000 m (the top of the ISA troposphere)",
            ),
            (
                "temperature_c",
                self.temperature_c,
                TEMPERATURE_RANGE_C,
                "C",
                "from -60 to 60 C",
            ),
            (
                "humidity_percent",
                self.humidity_percent,
                (0.0, 100.0),
                "%",
                "from 0 to 100 %",
            ),
            (
                "qnh_hpa",
                self.qnh_hpa,
                QNH_RANGE_HPA,
                "hPa",
                "from 850 to 1100 hPa",
            ),
            (
                "air_density_kg_m3",
                self.air_density_kg_m3,
                (0.3, 2.0),
                "kg/m^3",
                "from 0.3 to 2 kg/m^3",
            ),
        ];
        for (name, value, (lo, hi), unit, expected) in checks {
            if let Some(v) = value {
                // `contains` is false for NaN.
                if !(lo..=hi).contains(&v) {
                    return Err(Error::Air {
                        name,
                        value: v,
                        unit,
                        expected,
                    });
                }
            }
        }
        Ok(())
    }
}

/// Where a figure of the air came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AirSource {
    /// The caller's option (`--elevation-m`, `--temperature-c`, ...).
    Given,
    /// The mission file's home altitude above mean sea level.
    MissionHome,
    /// The International Standard Atmosphere at the elevation (or at sea level).
    Isa,
    /// The vehicle file's `air_density_kg_m3`.
    VehicleFile,
    /// The flight log's own air (barometer pressure and temperature, or the autopilot's density).
    Log,
}

impl AirSource {
    /// The source in words, as the tables print it.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Given => "given",
            Self::MissionHome => "the mission's home altitude",
            Self::Isa => "ISA",
            Self::VehicleFile => "the vehicle file",
            Self::Log => "the log",
        }
    }
}

/// The air a flight flies in, as every answer reports it (JSON keys as the field names).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Air {
    /// Density, kg/m^3.
    pub air_density_kg_m3: f64,
    /// Where the density came from: computed from the elevation and the day
    /// (`given`/`mission_home`/`isa`), the vehicle file's, or the log's.
    pub density_source: AirSource,
    /// Elevation above mean sea level, m, when the density was computed from one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elevation_m: Option<f64>,
    /// Where the elevation came from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elevation_source: Option<AirSource>,
    /// Air temperature, C, when the density was computed from one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<f64>,
    /// Where the temperature came from (given, or ISA's at the elevation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_source: Option<AirSource>,
    /// Static pressure, Pa, when the density was computed from one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure_pa: Option<f64>,
    /// Relative humidity, percent, when the density was computed from the day.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub humidity_percent: Option<f64>,
    /// The ISA elevation of the same density, m (the density altitude).
    pub density_altitude_m: f64,
}

impl Air {
    /// ISA sea level: 1.225 kg/m^3.
    pub fn sea_level() -> Self {
        Self::of_density(ISA_SEA_LEVEL_DENSITY_KG_M3, AirSource::Isa)
    }

    /// A density known by itself (a vehicle file's, a log's).
    pub fn of_density(air_density_kg_m3: f64, source: AirSource) -> Self {
        Self {
            air_density_kg_m3,
            density_source: source,
            elevation_m: None,
            elevation_source: None,
            temperature_c: None,
            temperature_source: None,
            pressure_pa: None,
            humidity_percent: None,
            density_altitude_m: rounded_density_altitude_m(air_density_kg_m3),
        }
    }

    /// The air in one line, as the tables print it after `Air: `: `1.007 kg/m^3 (elevation
    /// 2000 m, the mission's home altitude; 2.0 C, ISA; density altitude 2000 m)`.
    pub fn describe(&self) -> String {
        let mut parts = Vec::new();
        if let (Some(h), Some(src)) = (self.elevation_m, self.elevation_source) {
            parts.push(format!("elevation {h:.0} m, {}", src.describe()));
        }
        if let (Some(t), Some(src)) = (self.temperature_c, self.temperature_source) {
            parts.push(format!("{t:.1} C, {}", src.describe()));
        }
        if let Some(rh) = self.humidity_percent.filter(|rh| *rh > 0.0) {
            parts.push(format!("humidity {rh:.0} %"));
        }
        if parts.is_empty() {
            parts.push(self.density_source.describe().to_string());
        }
        parts.push(format!("density altitude {:.0} m", self.density_altitude_m));
        format!(
            "{:.3} kg/m^3 ({})",
            self.air_density_kg_m3,
            parts.join("; ")
        )
    }
}

/// The air of a flight: the caller's day, else the mission's home altitude in ISA air, else the
/// vehicle file's density (see the module docs for the precedence).
///
/// # Errors
/// [`Error::Air`] for a given value outside its range.
pub fn resolve_air(
    input: &AirInput,
    home_amsl_m: Option<f64>,
    vehicle: &Vehicle,
) -> Result<Air, Error> {
    input.check()?;
    if let Some(rho) = input.air_density_kg_m3 {
        return Ok(Air::of_density(rho, AirSource::Given));
    }
    if input.is_empty() && home_amsl_m.is_none() {
        let rho = vehicle.air_density_kg_m3();
        // Within 1e-9 of 1.225 is the default the file did not state.
        let source = if (rho - ISA_SEA_LEVEL_DENSITY_KG_M3).abs() < 1e-9 {
            AirSource::Isa
        } else {
            AirSource::VehicleFile
        };
        return Ok(Air::of_density(rho, source));
    }
    let (elevation_m, elevation_source) = match (input.elevation_m, home_amsl_m) {
        (Some(h), _) => (h, AirSource::Given),
        (None, Some(h)) => (h, AirSource::MissionHome),
        (None, None) => (0.0, AirSource::Isa),
    };
    let (temperature_k, temperature_source) = match input.temperature_c {
        Some(t) => (t + ZERO_CELSIUS_K, AirSource::Given),
        None => (isa_temperature_k(elevation_m), AirSource::Isa),
    };
    let sea_level_pa = input
        .qnh_hpa
        .map_or(ISA_SEA_LEVEL_PRESSURE_PA, |q| q * 100.0);
    let day = Day {
        elevation_m,
        temperature_k,
        humidity_percent: input.humidity_percent.unwrap_or(0.0),
        sea_level_pa,
    };
    let DayAir {
        pressure_pa,
        density_kg_m3: rho,
    } = day.air().map_err(|e| impossible(&day, e))?;
    let density_source = if input.is_empty() {
        AirSource::MissionHome
    } else {
        AirSource::Given
    };
    Ok(Air {
        air_density_kg_m3: rho,
        density_source,
        elevation_m: Some(elevation_m),
        elevation_source: Some(elevation_source),
        temperature_c: Some(temperature_k - ZERO_CELSIUS_K),
        temperature_source: Some(temperature_source),
        pressure_pa: Some(pressure_pa),
        humidity_percent: Some(day.humidity_percent),
        density_altitude_m: rounded_density_altitude_m(rho),
    })
}

/// A day whose figures are each in range that combines into air that cannot exist
/// ([`Day::air`]), as the error that names the combination.
fn impossible(day: &Day, why: ImpossibleAir) -> Error {
    let (elevation_m, temperature_c) = (day.elevation_m, day.temperature_k - ZERO_CELSIUS_K);
    let (humidity_percent, qnh_hpa) = (day.humidity_percent, day.sea_level_pa / 100.0);
    match why {
        ImpossibleAir::Vapour {
            vapour_pa,
            pressure_pa,
        } => Error::AirVapour {
            elevation_m,
            temperature_c,
            humidity_percent,
            qnh_hpa,
            vapour_pa,
            pressure_pa,
        },
        ImpossibleAir::TooThin {
            density_kg_m3,
            min_density_kg_m3,
        } => Error::AirTooThin {
            elevation_m,
            temperature_c,
            humidity_percent,
            qnh_hpa,
            density_kg_m3,
            min_density_kg_m3,
        },
    }
}

/// The air of a flight without a mission (endurance, power): [`resolve_air`] without a home
/// altitude, and the vehicle in it.
///
/// # Errors
/// As [`resolve_air`] and [`Vehicle::in_air`].
pub(crate) fn vehicle_air(vehicle: &Vehicle, input: &AirInput) -> Result<(Vehicle, Air), Error> {
    let air = resolve_air(input, None, vehicle)?;
    Ok((vehicle.in_air(air.air_density_kg_m3)?, air))
}

/// The air of a logged flight: the caller's day when given (without a mission, so from the
/// elevation), else the log's own density, else the vehicle file's.
///
/// # Errors
/// As [`resolve_air`].
pub(crate) fn log_air(
    input: &AirInput,
    log_density_kg_m3: Option<f64>,
    vehicle: &Vehicle,
) -> Result<Air, Error> {
    match log_density_kg_m3 {
        Some(rho) if input.is_empty() => Ok(Air::of_density(rho, AirSource::Log)),
        _ => resolve_air(input, None, vehicle),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m100() -> Vehicle {
        Vehicle::builtin("dji-m100").unwrap()
    }

    /// The precedence, quantity by quantity: flags over the mission's home, the home over the
    /// vehicle file, ISA sea level last; an unknown temperature is ISA's at the elevation.
    #[test]
    fn precedence_flags_then_home_then_vehicle_file_then_isa() {
        let v = m100();
        let none = resolve_air(&AirInput::default(), None, &v).unwrap();
        assert_eq!(none.density_source, AirSource::Isa);
        assert!((none.air_density_kg_m3 - 1.225).abs() < 1e-12);
        let home = resolve_air(&AirInput::default(), Some(3000.0), &v).unwrap();
        assert_eq!(home.elevation_source, Some(AirSource::MissionHome));
        assert_eq!(home.temperature_source, Some(AirSource::Isa));
        assert!((home.air_density_kg_m3 - 0.9091).abs() < 0.001);
        let flags = AirInput {
            elevation_m: Some(1000.0),
            temperature_c: Some(30.0),
            ..AirInput::default()
        };
        let given = resolve_air(&flags, Some(3000.0), &v).unwrap();
        assert_eq!(given.elevation_source, Some(AirSource::Given));
        assert!((given.air_density_kg_m3 - 1.0328).abs() < 0.001);
        // A temperature alone keeps the home's elevation.
        let hot = AirInput {
            temperature_c: Some(25.0),
            ..AirInput::default()
        };
        let hot_home = resolve_air(&hot, Some(2000.0), &v).unwrap();
        assert_eq!(hot_home.elevation_source, Some(AirSource::MissionHome));
        assert!((hot_home.air_density_kg_m3 - 0.9288).abs() < 0.001);
        // A vehicle file that states its density flies in it when nothing else is known.
        let mut file = v.file().clone();
        file.power.as_mut().unwrap().air_density_kg_m3 = 1.1;
        let thin = Vehicle::from_file(file).unwrap();
        let own = resolve_air(&AirInput::default(), None, &thin).unwrap();
        assert_eq!(own.density_source, AirSource::VehicleFile);
        assert!((own.air_density_kg_m3 - 1.1).abs() < 1e-12);
    }

    /// Issue 41: values each in range that combine into air that cannot exist are refused
    /// naming the combination; ISA's own 11 km is flown.
    #[test]
    fn air_that_cannot_exist_is_refused_naming_the_combination() {
        let day = |h: f64, t: Option<f64>, rh: Option<f64>, qnh: Option<f64>| AirInput {
            elevation_m: Some(h),
            temperature_c: t,
            humidity_percent: rh,
            qnh_hpa: qnh,
            air_density_kg_m3: None,
        };
        let steam = resolve_air(
            &day(11_000.0, Some(60.0), Some(100.0), Some(850.0)),
            None,
            &m100(),
        );
        assert!(matches!(steam, Err(Error::AirVapour { .. })), "{steam:?}");
        let thin = resolve_air(&day(11_000.0, Some(60.0), None, None), None, &m100());
        assert!(matches!(thin, Err(Error::AirTooThin { .. })), "{thin:?}");
        let e = thin.unwrap_err().to_string();
        assert!(
            e.contains("11000 m, 60 C, 0 % humidity and QNH 1013.25 hPa"),
            "{e}"
        );
        let top = resolve_air(&day(11_000.0, None, None, None), None, &m100()).unwrap();
        assert!((top.air_density_kg_m3 - 0.3639).abs() < 1e-4);
    }

    /// Out-of-range values are refused naming the value and its range.
    #[test]
    fn absurd_air_is_refused_with_its_name_and_range() {
        // The air given with one value, the one named.
        let given = |name: &str, value: f64| {
            let mut input = AirInput::default();
            let field = match name {
                "elevation_m" => &mut input.elevation_m,
                "temperature_c" => &mut input.temperature_c,
                "humidity_percent" => &mut input.humidity_percent,
                "qnh_hpa" => &mut input.qnh_hpa,
                other => panic!("no air value {other}"),
            };
            *field = Some(value);
            input
        };
        let cases = [
            ("elevation_m", -500.0),
            ("elevation_m", 12_000.0),
            ("temperature_c", 300.0),
            ("temperature_c", -273.0),
            ("humidity_percent", 101.0),
            ("qnh_hpa", 29.92),
        ];
        for (name, value) in cases {
            let input = given(name, value);
            let e = resolve_air(&input, None, &m100()).unwrap_err().to_string();
            assert!(e.contains(name) && e.contains("from "), "{e}");
        }
    }
}
