//! Arguments several subcommands share, and the parsers that turn their words into the engine's
//! types (one name per concept: the CLI has no enums of its own for them).

use std::path::PathBuf;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::Args;

use aloft::engine::{AoaModel, CornerMode, GustSpec, WindProfileKind, WindSpec};

/// Every numeric flag: a finite number (`nan`, `inf` and overflowing text like `1e999` are
/// refused here with the flag's name; the engine checks each value's physical range and unit).
pub fn finite() -> impl TypedValueParser<Value = f64> {
    clap::builder::StringValueParser::new().try_map(|text: String| {
        match text.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err("not a finite number".to_string()),
            Err(_) => Err("not a number".to_string()),
        }
    })
}

/// `--aoa geometric|paper`, parsed into the engine's [`AoaModel`].
pub fn aoa_parser() -> impl TypedValueParser<Value = AoaModel> {
    PossibleValuesParser::new([
        PossibleValue::new("geometric")
            .help("Exact angle between the air-relative velocity and the rotor plane"),
        PossibleValue::new("paper").help("The power seed's eqs (3)-(4) from roll and pitch"),
    ])
    .map(|s| match s.as_str() {
        "paper" => AoaModel::Paper,
        _ => AoaModel::Geometric,
    })
}

/// `--corners pass|stop`, parsed into the engine's [`CornerMode`].
pub fn corners_parser() -> impl TypedValueParser<Value = CornerMode> {
    PossibleValuesParser::new([
        PossibleValue::new("pass").help(
            "Through waypoints without a hold at the speed the turn allows (as autopilots fly)",
        ),
        PossibleValue::new("stop").help("Stop at every waypoint, yaw, go on"),
    ])
    .map(|s| match s.as_str() {
        "stop" => CornerMode::Stop,
        _ => CornerMode::Pass,
    })
}

/// `--wind-profile uniform|power-law|log`, parsed into the engine's [`WindProfileKind`].
fn profile_parser() -> impl TypedValueParser<Value = WindProfileKind> {
    PossibleValuesParser::new([
        PossibleValue::new("uniform").help("The same speed at every height"),
        PossibleValue::new("power-law").help("S (z / z_ref)^exponent"),
        PossibleValue::new("log").help("S ln(z / z0) / ln(z_ref / z0)"),
    ])
    .map(|s| match s.as_str() {
        "power-law" => WindProfileKind::PowerLaw,
        "log" => WindProfileKind::Log,
        _ => WindProfileKind::Uniform,
    })
}

/// A steady wind: speed, direction and how it varies with height.
#[derive(Debug, Args)]
pub struct SteadyWindArgs {
    /// Wind speed in m/s (at the reference height when a profile is given).
    #[arg(value_parser = finite(), long, value_name = "M/S", requires = "wind_from")]
    pub wind_speed: Option<f64>,
    /// Direction the wind blows FROM, degrees clockwise from north (270 = a westerly).
    #[arg(value_parser = finite(),
        long,
        value_name = "DEG",
        allow_negative_numbers = true,
        requires = "wind_speed"
    )]
    pub wind_from: Option<f64>,
    /// Variation of the wind with height (needs --wind-speed).
    #[arg(long, value_parser = profile_parser(), requires = "wind_speed")]
    pub wind_profile: Option<WindProfileKind>,
    /// Reference height of the profile, m.
    #[arg(value_parser = finite(), long, default_value_t = 10.0, value_name = "M")]
    pub wind_reference_height: f64,
    /// Power-law exponent.
    #[arg(value_parser = finite(), long, default_value_t = 1.0 / 7.0)]
    pub wind_exponent: f64,
    /// Roughness length of the log profile, m (0.03 open grass, 0.1-0.25 crops and hedges).
    #[arg(value_parser = finite(), long, default_value_t = 0.03, value_name = "M")]
    pub wind_roughness: f64,
}

impl SteadyWindArgs {
    /// The wind as the engine's `[wind]` table, when a speed and direction were given.
    pub fn spec(&self) -> Option<WindSpec> {
        let (speed_mps, from_deg) = self.wind_speed.zip(self.wind_from)?;
        let profile = self.wind_profile.unwrap_or_default();
        let uses = |p: WindProfileKind| profile == p;
        let profiled = !uses(WindProfileKind::Uniform);
        Some(WindSpec {
            speed_mps,
            from_deg,
            profile,
            reference_height_m: profiled.then_some(self.wind_reference_height),
            exponent: uses(WindProfileKind::PowerLaw).then_some(self.wind_exponent),
            roughness_m: uses(WindProfileKind::Log).then_some(self.wind_roughness),
            gust_std_mps: None,
            gust_seed: None,
        })
    }
}

/// The wind of a mission: a steady wind, or a gridded field, with gusts on top.
#[derive(Debug, Args)]
pub struct MissionWindArgs {
    #[command(flatten)]
    pub steady: SteadyWindArgs,
    /// Gridded wind field: CSV with columns x_m,y_m,z_m,u_mps,v_mps,w_mps (east, north, up),
    /// interpolated trilinearly; the route must stay inside it.
    #[arg(long, value_name = "CSV", conflicts_with_all = ["wind_speed", "wind_profile"])]
    pub wind_field: Option<PathBuf>,
    /// Add seeded gusts with this standard deviation per horizontal axis, m/s.
    #[arg(value_parser = finite(), long, value_name = "M/S")]
    pub gust_std: Option<f64>,
    /// Seed of the gusts.
    #[arg(long, default_value_t = 1)]
    pub gust_seed: u64,
}

impl MissionWindArgs {
    /// The gusts asked for.
    pub fn gusts(&self) -> Option<GustSpec> {
        self.gust_std.map(|std_mps| GustSpec {
            std_mps,
            seed: self.gust_seed,
        })
    }
}
