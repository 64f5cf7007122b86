//! The day a mission flies in, decided in one place: its air (the request's, with the mission's
//! home altitude) and its wind, by precedence: a gridded field
//! ([`MissionOptions::wind_field`]), else the options' wind ([`MissionOptions::wind`]), else the
//! mission file's `[wind]`, else still air. Gusts ([`MissionOptions::gusts`]) are added on top
//! of whichever it is (replacing gusts the chosen wind carries).

use aloft_planner::{Gusts, Wind};

use crate::engine::conditions::air::{resolve_air, Air, AirInput};
use crate::engine::conditions::wind::{describe_wind_spec, field, steady};
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_options::MissionOptions;
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// A mission's air ([`resolve_air`] with the mission's home altitude) and the vehicle in it.
///
/// # Errors
/// As [`resolve_air`] and [`Vehicle::in_air`].
pub(crate) fn mission_air(
    vehicle: &Vehicle,
    mission: &Mission,
    input: &AirInput,
) -> Result<(Vehicle, Air), Error> {
    let air = resolve_air(input, mission.spec().home.altitude_amsl_m, vehicle)?;
    Ok((vehicle.in_air(air.air_density_kg_m3)?, air))
}

/// The wind of a mission request and its description (see the module docs for the precedence).
///
/// # Errors
/// An unreadable or invalid wind field, an invalid wind in the options or the mission file, an
/// invalid gust spread.
pub(crate) fn mission_wind(
    options: &MissionOptions,
    mission: &Mission,
    vehicle: &Vehicle,
) -> Result<(Wind, String), Error> {
    let (wind, text) = if let Some(path) = &options.wind_field {
        field(path)?
    } else if let Some(w) = &options.wind {
        (steady(w)?, describe_wind_spec(w))
    } else if let Some(w) = &mission.spec().wind {
        let wind = w.to_wind().map_err(|e| Error::Mission {
            origin: format!("{}: [wind]", mission.origin()),
            vehicle: vehicle.name().to_string(),
            source: Box::new(e),
        })?;
        (
            wind,
            format!("{} (from the mission file)", describe_wind_spec(w)),
        )
    } else {
        (Wind::calm(), "still air".to_string())
    };
    match options.gusts {
        None => Ok((wind, text)),
        Some(g) => {
            let gusts = Gusts::new(g.std_mps, g.seed).map_err(|e| Error::Wind {
                origin: "gusts".to_string(),
                source: Box::new(e),
            })?;
            Ok((
                wind.with_gusts(gusts),
                format!("{text}, gusts {:.1} m/s std (seed {})", g.std_mps, g.seed),
            ))
        }
    }
}
