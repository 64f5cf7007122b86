//! Requests from flags: the one description of the options a user names, shared by every front
//! end that takes options by name.
//!
//! Each group below is a [`clap::Args`] description (names, defaults, ranges, the options that
//! need or exclude each other) and the mapping from what was given to the engine's request
//! (precedence included). The `aloft` command line flattens these groups into its subcommands;
//! the Python package parses its keyword arguments with the very same groups
//! ([`crate::engine::front_door::keywords`]), so an option's name, default and range are written once. Python's
//! keyword is the flag's long name in snake_case (`--payload-kg` is `payload_kg=`).
//!
//! What only one front end has (output formats, files to write, progress) stays with it.

use std::path::PathBuf;

use clap::builder::{PossibleValue, PossibleValuesParser, StringValueParser, TypedValueParser};
use clap::Args;

use aloft_planner::{CornerMode, WindProfileKind, WindSpec};
use aloft_power::{AoaModel, Term};

use crate::engine::basics::logs::{FlightLogs, LogArg, LogReadOptions};
use crate::engine::basics::step_meter::StepMeter;
use crate::engine::basics::step_meter::WorkBounds;
use crate::engine::conditions::air::AirInput;
use crate::engine::identification::fit::{fit_parameter, FitRequest};
use crate::engine::identification::own_vehicle::OwnVehicle;
use crate::engine::identification::validate::ValidateRequest;
use crate::engine::live::{LiveReplayRequest, LiveRequest, LiveSource};
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_options::{GustSpec, MissionOptions, DEFAULT_MIN_CLEARANCE_M};
use crate::engine::performance::endurance::EnduranceOptions;
use crate::engine::performance::payload_sweep::PayloadSweep;
use crate::engine::performance::power::PowerModelQuery;
use crate::engine::plan_to_fly::fly_plan::{
    FlyPlanRequest, PlanConfidence, SpeedChoice, DEFAULT_CAPACITY_SD_PERCENT, DEFAULT_CONFIDENCE,
    DEFAULT_LOITER_UNLIMITED_S, DEFAULT_OVERLAP_M, DEFAULT_PLAN_SCENARIOS,
    DEFAULT_WIND_FROM_SD_DEG,
};
use crate::engine::uncertainty::scenarios::{
    ScenarioOptions, DEFAULT_POWER_SD_PERCENT, MAX_SCENARIOS,
};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;
use crate::vehicle::DEFAULT_VEHICLE;

/// Every numeric option: a finite number (`nan`, `inf` and overflowing text like `1e999` are
/// refused with the option's name; the engine checks each value's physical range and unit).
pub fn finite() -> impl TypedValueParser<Value = f64> {
    StringValueParser::new().try_map(|text: String| match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err("not a finite number".to_string()),
        Err(_) => Err("not a number".to_string()),
    })
}

/// A flight log as `--log` takes it: `FILE`, or `FILE:payload_kg=KG` for the payload that flight
/// carried beyond the request's (a file whose whole name exists is that file).
fn log_arg() -> impl TypedValueParser<Value = LogArg> {
    StringValueParser::new().try_map(|text: String| LogArg::parse(&text))
}

/// A spread: a finite number from 0 to `max`.
fn spread(max: f64) -> impl TypedValueParser<Value = f64> {
    finite().try_map(move |v: f64| {
        if (0.0..=max).contains(&v) {
            Ok(v)
        } else {
            Err(format!("a standard deviation from 0 to {max}"))
        }
    })
}

/// One of a few words, each with its help and the engine's value it stands for.
fn words<T: Clone + Send + Sync + 'static, const N: usize>(
    choices: [(&'static str, &'static str, T); N],
) -> impl TypedValueParser<Value = T> {
    let values: Vec<(&'static str, T)> = choices.iter().map(|(w, _, v)| (*w, v.clone())).collect();
    PossibleValuesParser::new(choices.map(|(word, help, _)| PossibleValue::new(word).help(help)))
        .try_map(move |s: String| {
            values
                .iter()
                .find(|(w, _)| *w == s)
                .map(|(_, v)| v.clone())
                .ok_or("not one of the words")
        })
}

/// `geometric|paper`, parsed into the engine's [`AoaModel`].
pub fn aoa_parser() -> impl TypedValueParser<Value = AoaModel> {
    words([
        (
            "geometric",
            "Exact angle between the air-relative velocity and the rotor plane",
            AoaModel::Geometric,
        ),
        (
            "paper",
            "The power seed's eqs (3)-(4) from roll and pitch",
            AoaModel::Paper,
        ),
    ])
}

/// `pass|stop`, parsed into the engine's [`CornerMode`].
fn corners_parser() -> impl TypedValueParser<Value = CornerMode> {
    words([
        (
            "pass",
            "Through waypoints without a hold at the speed the turn allows (as autopilots fly)",
            CornerMode::Pass,
        ),
        (
            "stop",
            "Stop at every waypoint, yaw, go on",
            CornerMode::Stop,
        ),
    ])
}

/// `uniform|power-law|log`, parsed into the engine's [`WindProfileKind`].
fn profile_parser() -> impl TypedValueParser<Value = WindProfileKind> {
    words([
        (
            "uniform",
            "The same speed at every height",
            WindProfileKind::Uniform,
        ),
        (
            "power-law",
            "S (z / z_ref)^exponent",
            WindProfileKind::PowerLaw,
        ),
        ("log", "S ln(z / z0) / ln(z_ref / z0)", WindProfileKind::Log),
    ])
}

/// `START:STOP:STEP`, parsed and checked by [`PayloadSweep::parse`] (the option is named in the
/// message).
fn payload_sweep_parser() -> impl TypedValueParser<Value = PayloadSweep> {
    StringValueParser::new().try_map(|text: String| {
        PayloadSweep::parse(&text).map_err(|e| match e {
            Error::PayloadSweep { problem, .. } => problem.to_string(),
            other => other.to_string(),
        })
    })
}

/// A steady wind: speed, direction and how it varies with height.
#[derive(Debug, Clone, Args)]
pub struct WindFlags {
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

impl WindFlags {
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

/// The day's air: elevation, temperature, humidity, QNH. Each unset value has its default
/// ([`AirInput`]): the mission's home altitude, ISA's temperature there, dry air, 1013.25 hPa;
/// with none set and no home altitude, the vehicle file's density.
#[derive(Debug, Clone, Copy, Args)]
pub struct AirFlags {
    /// Elevation of the flight above mean sea level, m (-430 to 11000; default: the mission's
    /// home altitude, else sea level).
    #[arg(value_parser = finite(), long, value_name = "M", allow_negative_numbers = true)]
    pub elevation_m: Option<f64>,
    /// Air temperature, C (-60 to 60; default: ISA's at the elevation).
    #[arg(value_parser = finite(), long, value_name = "C", allow_negative_numbers = true)]
    pub temperature_c: Option<f64>,
    /// Relative humidity, percent (0 to 100; default 0, dry air).
    #[arg(value_parser = finite(), long, value_name = "PERCENT")]
    pub humidity_percent: Option<f64>,
    /// The day's QNH (altimeter setting), hPa (850 to 1100; default ISA's 1013.25).
    #[arg(value_parser = finite(), long, value_name = "HPA")]
    pub qnh_hpa: Option<f64>,
}

impl AirFlags {
    /// The engine's air input of these flags.
    pub fn input(&self) -> AirInput {
        AirInput {
            elevation_m: self.elevation_m,
            temperature_c: self.temperature_c,
            humidity_percent: self.humidity_percent,
            qnh_hpa: self.qnh_hpa,
            air_density_kg_m3: None,
        }
    }
}

/// The options of `aloft mission` (and of Python's `aloft.mission`, `aloft.timeseries`).
#[derive(Debug, Clone, Args)]
pub struct MissionFlags {
    /// Vehicle: a built-in name (see `aloft vehicles`) or a vehicle TOML file.
    #[arg(long, default_value = DEFAULT_VEHICLE, value_name = "NAME|FILE")]
    pub vehicle: String,
    /// Battery pack by name (default: the vehicle's default pack). With --replay, the pack flown
    /// in the log: its mass is part of the mass flown (airframe + pack + payload).
    #[arg(long)]
    pub battery: Option<String>,
    /// Payload at take-off, kg (overrides the mission file).
    #[arg(value_parser = finite(), long, value_name = "KG")]
    pub payload_kg: Option<f64>,
    /// The steady wind.
    #[command(flatten)]
    pub wind: WindFlags,
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
    /// Reserve required at landing, percent of the usable capacity (default: the mission's, else 20).
    #[arg(value_parser = finite(), long, value_name = "PERCENT")]
    pub reserve_percent: Option<f64>,
    /// State of charge at take-off, percent.
    #[arg(value_parser = finite(), long, default_value_t = 100.0, value_name = "PERCENT", conflicts_with = "start_voltage_v")]
    pub start_percent: f64,
    /// The pack's rested voltage before take-off, V: the state of charge at take-off is read on
    /// the pack's open-circuit curve (in place of --start-percent).
    #[arg(value_parser = finite(), long, value_name = "V")]
    pub start_voltage_v: Option<f64>,
    /// Sampling step, s (default: the mission's, else 0.1).
    #[arg(value_parser = finite(), long, value_name = "S")]
    pub time_step: Option<f64>,
    /// Planning speed, m/s: the ground speed of legs without one of their own (overrides the
    /// vehicle's cruise_speed_mps and the file's, e.g. a .plan's hoverSpeed).
    #[arg(value_parser = finite(), long, value_name = "M/S")]
    pub speed: Option<f64>,
    /// Lowest height of a return to launch, m (overrides the vehicle's rtl_altitude_m and the
    /// mission's): a return below it climbs first.
    #[arg(value_parser = finite(), long, value_name = "M")]
    pub rtl_altitude_m: Option<f64>,
    /// How waypoints without a hold are flown (default: the mission's, else pass).
    #[arg(long, value_parser = corners_parser(), value_name = "MODE")]
    pub corners: Option<CornerMode>,
    /// Angle-of-attack model of the power model.
    #[arg(long, value_parser = aoa_parser(), default_value = "geometric")]
    pub aoa: AoaModel,
    /// Leave out ground effect (survey eq 35) near the ground.
    #[arg(long)]
    pub no_ground_effect: bool,
    /// The day's air.
    #[command(flatten)]
    pub air: AirFlags,
    /// The autopilot's low-voltage failsafe, pack volts (ArduPilot BATT_LOW_VOLT): the answer
    /// says when the predicted voltage under load first falls below it (default: the pack
    /// file's [failsafe]).
    #[arg(value_parser = finite(), long, value_name = "V")]
    pub low_voltage_v: Option<f64>,
    /// The autopilot's critical-voltage failsafe, pack volts (ArduPilot BATT_CRT_VOLT).
    #[arg(value_parser = finite(), long, value_name = "V")]
    pub critical_voltage_v: Option<f64>,
    /// Elevation tiles, offline: a directory of SRTM .hgt (.hgt.zip) and WGS84 GeoTIFF files.
    /// Each segment's least height above the ground is given, terrain-frame items are flown
    /// over the ground (default: the ALOFT_TERRAIN environment variable; none: a flat Earth).
    #[arg(long, value_name = "DIR", env = "ALOFT_TERRAIN")]
    pub terrain: Option<PathBuf>,
    /// With --terrain: a segment in the air (take-off and landing excepted) that passes closer
    /// to the ground than this makes the mission infeasible (exit 1), m.
    #[arg(value_parser = finite(), long, value_name = "M", default_value_t = DEFAULT_MIN_CLEARANCE_M)]
    pub min_clearance_m: f64,
    /// The request's budget of planner steps, set by a caller that serves others (no flag).
    #[arg(skip)]
    pub meter: Option<StepMeter>,
}

impl MissionFlags {
    /// The engine's mission options of these flags.
    pub fn options(&self) -> MissionOptions {
        MissionOptions {
            battery: self.battery.clone(),
            payload_kg: self.payload_kg,
            wind: self.wind.spec(),
            wind_field: self.wind_field.clone(),
            gusts: self.gust_std.map(|std_mps| GustSpec {
                std_mps,
                seed: self.gust_seed,
            }),
            reserve_percent: self.reserve_percent,
            start_percent: self.start_percent,
            start_voltage_v: self.start_voltage_v,
            time_step_s: self.time_step,
            aoa: self.aoa,
            ground_effect: !self.no_ground_effect,
            record_samples: false,
            speed_mps: self.speed,
            rtl_altitude_m: self.rtl_altitude_m,
            corners: self.corners,
            air: self.air.input(),
            low_voltage_v: self.low_voltage_v,
            critical_voltage_v: self.critical_voltage_v,
            terrain: self.terrain.clone(),
            min_clearance_m: Some(self.min_clearance_m),
            meter: self.meter.clone(),
        }
    }
}

/// Monte-Carlo scenarios: how many, from what seed, and the spread (one standard deviation) of
/// each source drawn.
#[derive(Debug, Clone, Args)]
pub struct ScenarioFlags {
    /// Draw and fly this many scenarios (1 to 100000): p_feasible and percentiles of energy,
    /// battery, time and point of no return (docs/guide.md, "How sure is the answer").
    #[arg(long, value_name = "N",
        value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SCENARIOS)))]
    pub samples: Option<u32>,
    /// Seed of the scenarios' draws (the same seed gives the same answer).
    #[arg(long, requires = "samples", default_value_t = 1)]
    pub seed: u64,
    /// Spread of the wind speed, m/s (normal, clipped at 0).
    #[arg(long, requires = "samples", value_parser = spread(50.0), default_value_t = 0.0,
        value_name = "M/S", allow_negative_numbers = true)]
    pub wind_speed_sd: f64,
    /// Spread of the wind direction, degrees (normal).
    #[arg(long, requires = "samples", value_parser = spread(180.0), default_value_t = 0.0,
        value_name = "DEG", allow_negative_numbers = true)]
    pub wind_from_sd: f64,
    /// Spread of the take-off payload, kg (normal, clipped at 0).
    #[arg(long, requires = "samples", value_parser = spread(1000.0), default_value_t = 0.0,
        value_name = "KG", allow_negative_numbers = true)]
    pub payload_sd_kg: f64,
    /// Spread of the pack's capacity (health), percent of its rating (normal).
    #[arg(long, requires = "samples", value_parser = spread(50.0), default_value_t = 0.0,
        value_name = "PERCENT", allow_negative_numbers = true)]
    pub capacity_sd_percent: f64,
    /// Spread of the model's electrical power, percent (normal; default 3, aloft's own
    /// whole-flight energy errors).
    #[arg(long, requires = "samples", value_parser = spread(50.0),
        default_value_t = DEFAULT_POWER_SD_PERCENT, value_name = "PERCENT",
        allow_negative_numbers = true)]
    pub power_sd_percent: f64,
    /// Threads for the scenarios (0: one per core); the answer does not depend on it.
    #[arg(long, requires = "samples", default_value_t = 0, value_name = "N",
        value_parser = clap::value_parser!(u16).range(0..=1024))]
    pub threads: u16,
    /// What the request may spend (set by a caller that serves others; no flag).
    #[arg(skip)]
    pub bounds: WorkBounds,
}

impl ScenarioFlags {
    /// The engine's scenario options, when `--samples` was given (`fan`: follow the state of
    /// charge for a chart).
    pub fn options(&self, fan: bool) -> Option<ScenarioOptions> {
        Some(ScenarioOptions {
            samples: self.samples?,
            seed: self.seed,
            wind_speed_sd_mps: self.wind_speed_sd,
            wind_from_sd_deg: self.wind_from_sd,
            payload_sd_kg: self.payload_sd_kg,
            capacity_sd_percent: self.capacity_sd_percent,
            power_sd_percent: self.power_sd_percent,
            threads: usize::from(self.threads),
            soc_fan: fan,
            bounds: self.bounds.clone(),
        })
    }
}

/// The options of `aloft endurance`: the queries at one payload, the power curve
/// (`--sweep-speed`) or endurance against payload (`--payload-sweep`), with its scenarios.
#[derive(Debug, Clone, Args)]
pub struct EnduranceFlags {
    /// Vehicle: a built-in name (see `aloft vehicles`) or a vehicle TOML file.
    #[arg(long, default_value = DEFAULT_VEHICLE, value_name = "NAME|FILE")]
    pub vehicle: String,
    /// Battery pack by name (default: the vehicle's default pack).
    #[arg(long)]
    pub battery: Option<String>,
    /// Payload, kg.
    #[arg(value_parser = finite(), long, default_value_t = 0.0, value_name = "KG")]
    pub payload_kg: f64,
    /// The steady wind.
    #[command(flatten)]
    pub wind: WindFlags,
    /// Course of the range query, degrees clockwise from north.
    #[arg(value_parser = finite(),
        long,
        default_value_t = 0.0,
        value_name = "DEG",
        allow_negative_numbers = true
    )]
    pub course: f64,
    /// Reserve kept, percent of the usable capacity.
    #[arg(value_parser = finite(), long, default_value_t = 0.0, value_name = "PERCENT")]
    pub reserve_percent: f64,
    /// Orbit radius for the orbit-endurance query, m.
    #[arg(value_parser = finite(), long, value_name = "M", requires = "orbit_speed")]
    pub orbit_radius: Option<f64>,
    /// Orbit ground speed, m/s.
    #[arg(value_parser = finite(), long, value_name = "M/S", requires = "orbit_radius")]
    pub orbit_speed: Option<f64>,
    /// Angle-of-attack model of the power model.
    #[arg(long, value_parser = aoa_parser(), default_value = "geometric")]
    pub aoa: AoaModel,
    /// The power curve instead: power, endurance and range against airspeed, in steps of this
    /// many m/s up to the vehicle's maximum speed (scenarios are drawn around the queries, not a
    /// curve).
    #[arg(value_parser = finite(), long, value_name = "STEP_M/S", conflicts_with = "samples")]
    pub sweep_speed: Option<f64>,
    /// Endurance against payload instead, one curve per pack (every pack of the vehicle unless
    /// --battery names one): hover endurance, best endurance and best range at payloads from
    /// START to STOP kg in steps of STEP kg (e.g. 0:1:0.25; at most 1000 payloads). A pack's
    /// curve stops at the maximum take-off mass.
    #[arg(long, value_name = "START:STOP:STEP", value_parser = payload_sweep_parser(),
        allow_hyphen_values = true,
        conflicts_with_all = ["payload_kg", "sweep_speed", "samples"])]
    pub payload_sweep: Option<PayloadSweep>,
    /// Monte-Carlo scenarios (--samples N and the spreads; no gusts).
    #[command(flatten)]
    pub scenarios: ScenarioFlags,
    /// The day's air.
    #[command(flatten)]
    pub air: AirFlags,
}

impl EnduranceFlags {
    /// The engine's endurance options of these flags.
    pub fn options(&self) -> EnduranceOptions {
        EnduranceOptions {
            battery: self.battery.clone(),
            payload_kg: self.payload_kg,
            wind: self.wind.spec(),
            course_deg: self.course,
            reserve_percent: self.reserve_percent,
            orbit_radius_m: self.orbit_radius,
            orbit_speed_mps: self.orbit_speed,
            aoa: self.aoa,
            air: self.air.input(),
        }
    }
}

/// How a log is read: its layout and, for MCAP, ULog and DataFlash, what to take from it.
#[derive(Debug, Clone, Args)]
pub struct LogReadFlags {
    /// CSV profile: kaist, px4, or a column-map TOML file. Default: recognised from the file
    /// (MCAP by magic, KAIST by header, PX4 by table name).
    #[arg(long, value_name = "PROFILE")]
    pub profile: Option<String>,
    /// MCAP: decode only these topics (repeatable or comma-separated); default: chosen by
    /// message type.
    #[arg(
        long,
        visible_alias = "topic",
        value_delimiter = ',',
        value_name = "TOPIC"
    )]
    pub topics: Vec<String>,
    /// MCAP: use the header stamps instead of the recording's log time.
    #[arg(long)]
    pub header_time: bool,
    /// MCAP: take sensor_msgs/BatteryState current as positive while discharging (the message
    /// definition says negative; some drivers publish the opposite).
    #[arg(long)]
    pub battery_current_positive: bool,
    /// PX4 ULog / ArduPilot DataFlash: the battery instance to read (0: the first).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub battery_instance: u8,
}

impl LogReadFlags {
    /// The engine's read options of these flags.
    pub fn options(&self) -> LogReadOptions {
        LogReadOptions {
            profile: self.profile.clone(),
            topics: self.topics.clone(),
            header_time: self.header_time,
            battery_current_positive: self.battery_current_positive,
            battery_instance: self.battery_instance,
        }
    }
}

/// The options of `aloft log info`.
#[derive(Debug, Clone, Args)]
pub struct LogInfoFlags {
    /// How the log is read.
    #[command(flatten)]
    pub read: LogReadFlags,
    /// Also estimate the lag of power behind ground speed by cross-correlation, searched within
    /// +-MAX_S seconds.
    #[arg(value_parser = finite(), long, value_name = "MAX_S")]
    pub max_lag: Option<f64>,
}

/// The flight logs of `aloft fit` and `aloft validate` and how to align power with motion in
/// them.
#[derive(Debug, Clone, Args)]
pub struct FlightLogFlags {
    /// Flight logs (CSV, MCAP, PX4 ULog or ArduPilot DataFlash); `FILE:payload_kg=KG` for a
    /// flight that carried a payload beyond the others (its take-off mass is the vehicle's plus
    /// KG).
    #[arg(long, required = true, num_args = 1.., value_name = "FILE[:payload_kg=KG]",
        value_parser = log_arg())]
    pub log: Vec<LogArg>,
    /// Log layout: kaist, px4 or a column-map TOML (default: detected).
    #[arg(long, value_name = "PROFILE")]
    pub profile: Option<String>,
    /// Angle-of-attack model for the logged states: geometric (drag work is in the attitude;
    /// drag is fitted from the force balance) or paper (drag can be fitted from power).
    #[arg(long, value_parser = aoa_parser(), default_value = "geometric")]
    pub aoa: AoaModel,
    /// Use this lag of power behind motion (s) instead of estimating it.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true, value_name = "S")]
    pub lag: Option<f64>,
    /// Search window of the lag estimate, s.
    #[arg(value_parser = finite(), long, default_value_t = 10.0, value_name = "S")]
    pub max_lag: f64,
    /// PX4 ULog / ArduPilot DataFlash: the battery instance to read (0: the first).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub battery_instance: u8,
}

impl FlightLogFlags {
    /// The engine's description of the logs.
    pub fn logs(&self) -> FlightLogs {
        FlightLogs {
            logs: self.log.iter().map(|l| l.path.clone()).collect(),
            payloads_kg: self.log.iter().map(|l| l.payload_kg).collect(),
            profile: self.profile.clone(),
            aoa: self.aoa,
            lag_s: self.lag,
            max_lag_s: self.max_lag,
            battery_instance: self.battery_instance,
        }
    }
}

/// The options of `aloft fit`.
#[derive(Debug, Clone, Args)]
pub struct FitFlags {
    /// The flight logs.
    #[command(flatten)]
    pub logs: FlightLogFlags,
    /// Vehicle to start from: built-in name or TOML file (default: the generic template of
    /// `aloft vehicles template`; then --mass-kg and --rotor-diameter-m are needed).
    #[arg(long, value_name = "NAME|FILE")]
    pub vehicle_template: Option<String>,
    /// Take-off mass of the flights without payload (airframe and pack), kg.
    #[arg(value_parser = finite(), long, value_name = "KG")]
    pub mass_kg: Option<f64>,
    /// Propeller diameter, m (10 in = 0.254 m).
    #[arg(value_parser = finite(), long, value_name = "M")]
    pub rotor_diameter_m: Option<f64>,
    /// The pack's rated capacity, mA h (when the logs' BAT1_CAPACITY / BATT_CAPACITY is unset).
    #[arg(value_parser = finite(), long, value_name = "MAH")]
    pub battery_capacity_mah: Option<f64>,
    /// The pack's mass, kg (default: estimated from its energy at 150 Wh/kg).
    #[arg(value_parser = finite(), long, value_name = "KG")]
    pub battery_mass_kg: Option<f64>,
    /// Largest take-off mass, kg (default: the template's, else 1.5 times the heaviest flight).
    #[arg(value_parser = finite(), long, value_name = "KG")]
    pub max_takeoff_mass_kg: Option<f64>,
    /// Where to write the fitted vehicle TOML.
    #[arg(short = 'o', long, value_name = "TOML")]
    pub output: Option<PathBuf>,
    /// Replace an existing output (a regular file, or a link itself, never what it points to;
    /// never a device, a FIFO or a folder). Without it an existing output is kept (exit 2).
    #[arg(long)]
    pub force: bool,
    /// Lumped constants to fit: k (= m g / eta), vh, profile, mu1, mu2, mu3 (comma-separated).
    /// Default: k. Drag (mu1..mu3) is fitted from the force balance when the logs carry
    /// acceleration, unless --aoa paper and mu* are listed here.
    #[arg(long, value_delimiter = ',', default_value = "k")]
    pub free: Vec<String>,
    /// Do not fit drag from the force balance (keep the template's mu1..mu3).
    #[arg(long)]
    pub no_drag: bool,
}

impl FitFlags {
    /// The engine's fit request of these flags (without progress reports).
    ///
    /// # Errors
    /// [`Error::UnknownParameter`]-style errors of [`fit_parameter`] for a name in `free` that
    /// is not a constant of the model.
    pub fn request(&self) -> Result<FitRequest, Error> {
        Ok(FitRequest {
            logs: self.logs.logs(),
            free: self
                .free
                .iter()
                .map(|n| fit_parameter(n))
                .collect::<Result<Vec<_>, _>>()?,
            no_drag: self.no_drag,
            output: self.output.clone(),
            force: self.force,
            progress: None,
            own: OwnVehicle {
                mass_kg: self.mass_kg,
                rotor_diameter_m: self.rotor_diameter_m,
                battery_capacity_mah: self.battery_capacity_mah,
                battery_mass_kg: self.battery_mass_kg,
                max_takeoff_mass_kg: self.max_takeoff_mass_kg,
            },
            generic_template: self.vehicle_template.is_none(),
        })
    }

    /// The vehicle the fit starts from: `--vehicle-template`, else the generic template.
    ///
    /// # Errors
    /// A template that cannot be loaded.
    pub fn template(&self) -> Result<Vehicle, Error> {
        match &self.vehicle_template {
            Some(name) => Vehicle::load(name),
            None => Vehicle::from_toml(crate::vehicle::VEHICLE_TEMPLATE, "the vehicle template"),
        }
    }
}

/// The options of `aloft validate`.
#[derive(Debug, Clone, Args)]
pub struct ValidateFlags {
    /// The flight logs.
    #[command(flatten)]
    pub logs: FlightLogFlags,
    /// Vehicle with a [power] table (e.g. from `aloft fit`): built-in name or TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    pub vehicle: String,
    /// Battery pack the flights carried, part of the take-off mass (default: the vehicle's
    /// default pack; a vehicle without an airframe flies its [power] mass).
    #[arg(long)]
    pub battery: Option<String>,
    /// Payload the flights carried, kg, part of the take-off mass.
    #[arg(value_parser = finite(), long, default_value_t = 0.0, value_name = "KG")]
    pub payload_kg: f64,
    /// Re-estimate only the efficiency from the first S seconds of each flight, as a ground
    /// station would in flight, and report the errors over the rest.
    #[arg(value_parser = finite(), long, value_name = "S")]
    pub calibrate_first: Option<f64>,
    /// The day's air of every flight (default: each log's own, PX4 vehicle_air_data or ArduPilot BARO).
    #[command(flatten)]
    pub air: AirFlags,
}

impl ValidateFlags {
    /// The engine's validation request of these flags (`series`: keep the power series for a
    /// chart).
    pub fn request(&self, series: bool) -> ValidateRequest {
        ValidateRequest {
            logs: self.logs.logs(),
            battery: self.battery.clone(),
            payload_kg: self.payload_kg,
            calibrate_first_s: self.calibrate_first,
            series,
            air: self.air.input(),
        }
    }
}

/// The model options of `aloft power` (the flight state and the output are the caller's).
#[derive(Debug, Clone, Args)]
pub struct PowerModelFlags {
    /// Vehicle: a built-in name (see `aloft vehicles`) or a vehicle TOML file.
    #[arg(long, default_value = DEFAULT_VEHICLE, value_name = "NAME|FILE")]
    pub vehicle: String,
    /// Battery pack by name (default: the vehicle's default pack); its mass is part of the
    /// take-off mass the model flies (airframe + pack + payload).
    #[arg(long)]
    pub battery: Option<String>,
    /// Payload, kg, part of the take-off mass.
    #[arg(value_parser = finite(), long, default_value_t = 0.0, value_name = "KG",
        allow_negative_numbers = true)]
    pub payload_kg: f64,
    /// Remove terms from the model (the ablation rows of the paper's Table I), comma-separated:
    /// induced, parasitic, profile, climb.
    #[arg(long, value_delimiter = ',', value_name = "TERMS")]
    pub without: Vec<Term>,
    /// Hybrid model: drop the profile term above this airspeed, m/s (the paper's conclusion).
    #[arg(value_parser = finite(), long, value_name = "M/S")]
    pub profile_cutoff: Option<f64>,
    /// Angle-of-attack model. Default: paper, or geometric when --air-direction-deg is given.
    #[arg(long, value_parser = aoa_parser())]
    pub aoa: Option<AoaModel>,
    /// The day's air.
    #[command(flatten)]
    pub air: AirFlags,
}

impl PowerModelFlags {
    /// The engine's power model of these options (the caller gives the state).
    pub fn query(&self) -> PowerModelQuery {
        PowerModelQuery {
            battery: self.battery.clone(),
            payload_kg: self.payload_kg,
            without: self.without.clone(),
            profile_cutoff_mps: self.profile_cutoff,
            aoa: self.aoa,
            air: self.air.input(),
        }
    }
}

/// The options of a mission with its scenarios, in one group (for callers that take them in
/// one call, as Python's `aloft.mission`).
#[derive(Debug, Clone, Args)]
pub struct MissionScenarioFlags {
    /// The mission's options.
    #[command(flatten)]
    pub mission: MissionFlags,
    /// Its scenarios.
    #[command(flatten)]
    pub scenarios: ScenarioFlags,
}

/// `wind|energy|keep`, parsed into the engine's [`SpeedChoice`].
fn speeds_parser() -> impl TypedValueParser<Value = SpeedChoice> {
    words([
        (
            "wind",
            "Legs without a speed of their own at the speed of least energy in their wind",
            SpeedChoice::Wind,
        ),
        (
            "energy",
            "Every leg at the speed of least energy in its wind, the operator's speeds too",
            SpeedChoice::Energy,
        ),
        ("keep", "Every speed as it is", SpeedChoice::Keep),
    ])
}

/// How sure a plan's sorties must be: the confidence and the scenarios it is judged in (as
/// `aloft mission`'s scenario flags, with a plan's defaults: the forecast's error and the
/// models').
#[derive(Debug, Clone, Args)]
pub struct PlanConfidenceFlags {
    /// Share of the day's scenarios each sortie must land with the reserve in, 0.5 to 0.999
    /// (0.5: cut for the forecast alone, today's nominal cut).
    #[arg(long, value_parser = finite(), default_value_t = DEFAULT_CONFIDENCE, value_name = "P",
        allow_negative_numbers = true)]
    pub confidence: f64,
    /// Scenarios drawn to judge each sortie (1 to 100000).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_PLAN_SCENARIOS,
        value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SCENARIOS)))]
    pub samples: u32,
    /// Seed of the scenarios' draws (the same seed gives the same plan).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Spread of the wind speed, m/s (normal, clipped at 0; default: 25 % of the forecast
    /// speed and at least 1.5 m/s).
    #[arg(long, value_parser = spread(50.0), value_name = "M/S", allow_negative_numbers = true)]
    pub wind_speed_sd: Option<f64>,
    /// Spread of the wind direction, degrees (normal).
    #[arg(long, value_parser = spread(180.0), default_value_t = DEFAULT_WIND_FROM_SD_DEG,
        value_name = "DEG", allow_negative_numbers = true)]
    pub wind_from_sd: f64,
    /// Spread of the take-off payload, kg (normal, clipped at 0).
    #[arg(long, value_parser = spread(1000.0), default_value_t = 0.0, value_name = "KG",
        allow_negative_numbers = true)]
    pub payload_sd_kg: f64,
    /// Spread of the pack's capacity (health), percent of its rating (normal).
    #[arg(long, value_parser = spread(50.0), default_value_t = DEFAULT_CAPACITY_SD_PERCENT,
        value_name = "PERCENT", allow_negative_numbers = true)]
    pub capacity_sd_percent: f64,
    /// Spread of the model's electrical power, percent (normal; aloft's own whole-flight
    /// energy errors).
    #[arg(long, value_parser = spread(50.0), default_value_t = DEFAULT_POWER_SD_PERCENT,
        value_name = "PERCENT", allow_negative_numbers = true)]
    pub power_sd_percent: f64,
    /// Threads for the scenarios (0: one per core); the plan does not depend on it.
    #[arg(long, default_value_t = 0, value_name = "N",
        value_parser = clap::value_parser!(u16).range(0..=1024))]
    pub threads: u16,
}

impl PlanConfidenceFlags {
    /// The engine's confidence of these flags.
    pub fn confidence(&self) -> PlanConfidence {
        PlanConfidence {
            confidence: self.confidence,
            samples: self.samples,
            seed: self.seed,
            wind_speed_sd_mps: self.wind_speed_sd,
            wind_from_sd_deg: self.wind_from_sd,
            payload_sd_kg: self.payload_sd_kg,
            capacity_sd_percent: self.capacity_sd_percent,
            power_sd_percent: self.power_sd_percent,
            threads: usize::from(self.threads),
        }
    }
}

/// The options of `aloft plan` (the mission's, and how the plan is made).
#[derive(Debug, Clone, Args)]
pub struct PlanFlags {
    /// The mission's options.
    #[command(flatten)]
    pub mission: MissionFlags,
    /// How far back along the route a sortie resumes, m: it re-flies that much of where the
    /// last one turned home (for a survey's image overlap).
    #[arg(value_parser = finite(), long, default_value_t = DEFAULT_OVERLAP_M, value_name = "M",
        allow_negative_numbers = true)]
    pub overlap_m: f64,
    /// Which legs are given the ground speed that costs least energy per metre in their wind.
    #[arg(long, value_parser = speeds_parser(), default_value = "wind", value_name = "WHICH")]
    pub speeds: SpeedChoice,
    /// Highest ground speed a leg is given, m/s (the vehicle's limits apply anyway).
    #[arg(value_parser = finite(), long, value_name = "M/S", allow_negative_numbers = true)]
    pub max_speed: Option<f64>,
    /// The camera's shortest time between photos, s: a leg flown with the camera triggering
    /// every D m is given at most D / this (default: a survey's `CameraCalc.MinTriggerInterval`
    /// in a .plan, else 2 s).
    #[arg(value_parser = finite(), long, value_name = "S", allow_negative_numbers = true)]
    pub camera_interval_s: Option<f64>,
    /// Keep every survey's grid angle (else each QGroundControl survey is turned to the wind
    /// where that saves energy, its transects drawn again as QGroundControl draws them).
    #[arg(long)]
    pub keep_angle: bool,
    /// How sure each sortie must be.
    #[command(flatten)]
    pub sure: PlanConfidenceFlags,
    /// How long an unlimited loiter (NAV_LOITER_UNLIM) is flown, s, before the operator
    /// continues the mission with the items after it (each sortie keeps them and the
    /// mission's own landing).
    #[arg(value_parser = finite(), long, default_value_t = DEFAULT_LOITER_UNLIMITED_S,
        value_name = "S", allow_negative_numbers = true)]
    pub loiter_unlimited_s: f64,
    /// Write the mission to keep this height above the ground, m (with --terrain): each
    /// waypoint and loiter relative to home, for the autopilot of --autopilot.
    #[arg(value_parser = finite(), long, value_name = "M", allow_negative_numbers = true)]
    pub follow_terrain: Option<f64>,
    /// The autopilot a terrain-following plan is written for: px4 (above mean sea level, a
    /// waypoint at every terrain sample where the height changes, as QGroundControl writes it)
    /// or ardupilot (the terrain frame, which ArduPilot follows itself).
    #[arg(long, value_enum, default_value_t = AutopilotFlag::Px4, requires = "follow_terrain")]
    pub autopilot: AutopilotFlag,
    /// What the request may spend (set by a caller that serves others: its cancellation; no
    /// flag).
    #[arg(skip)]
    pub bounds: WorkBounds,
}

/// The autopilot a terrain-following plan is written for (`--autopilot`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum AutopilotFlag {
    /// PX4: altitudes above mean sea level.
    #[default]
    Px4,
    /// ArduPilot: the terrain frame.
    Ardupilot,
}

impl PlanFlags {
    /// The engine's plan request of these flags.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] for an overlap or a top speed out of range.
    pub fn request(&self) -> Result<FlyPlanRequest, Error> {
        if !(0.0..=1000.0).contains(&self.overlap_m) {
            return Err(Error::InvalidInput {
                name: "overlap_m",
                value: self.overlap_m,
                unit: "m",
                expected: "from 0 to 1000 m",
            });
        }
        // A subnormal speed (1e-310 m/s) is above 0 but no speed: refused as one.
        if let Some(v) = self
            .max_speed
            .filter(|v| !(v.is_normal() && *v > 0.0 && *v <= 100.0))
        {
            return Err(Error::InvalidInput {
                name: "max_speed",
                value: v,
                unit: "m/s",
                expected: "a ground speed above 0 and at most 100 m/s (not subnormal)",
            });
        }
        if let Some(v) = self
            .camera_interval_s
            .filter(|v| !(*v > 0.0 && *v <= 3600.0))
        {
            return Err(Error::InvalidInput {
                name: "camera_interval_s",
                value: v,
                unit: "s",
                expected: "a time above 0 and at most 3600 s",
            });
        }
        if !(0.0..=86_400.0).contains(&self.loiter_unlimited_s) {
            return Err(Error::InvalidInput {
                name: "loiter_unlimited_s",
                value: self.loiter_unlimited_s,
                unit: "s",
                expected: "from 0 to 86400 s",
            });
        }
        Ok(FlyPlanRequest {
            options: self.mission.options(),
            overlap_m: self.overlap_m,
            loiter_unlimited_s: self.loiter_unlimited_s,
            speeds: self.speeds,
            max_speed_mps: self.max_speed,
            camera_interval_s: self.camera_interval_s,
            confidence: self.sure.confidence(),
            scenarios: None,
            keep_angle: self.keep_angle,
            follow_terrain_m: self.follow_terrain,
            follow_frames: match self.autopilot {
                AutopilotFlag::Px4 => aloft_missions::follow_terrain::FollowFrames::Amsl,
                AutopilotFlag::Ardupilot => aloft_missions::follow_terrain::FollowFrames::Terrain,
            },
            bounds: self.bounds.clone(),
        })
    }
}

/// The route ahead of `aloft live` (`--route`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum RouteFlag {
    /// From where the vehicle is through the rest of the mission (`--mission`, else the one on
    /// the link) to home and the landing; without a mission, home and the landing.
    #[default]
    Mission,
    /// The rest of the logged path (a replay): the prediction at each time is checked against
    /// the energy the log measured from then to the end.
    Log,
}

/// The options of `aloft live`.
#[derive(Debug, Clone, Args)]
#[command(group(clap::ArgGroup::new("live_source").required(true).args(["replay", "tlog", "connect"])))]
pub struct LiveFlags {
    /// Follow a flight log (CSV, MCAP, PX4 ULog or ArduPilot DataFlash) as if live.
    #[arg(long, value_name = "LOG")]
    pub replay: Option<PathBuf>,
    /// Log layout of `--replay`: kaist, px4 or a column-map TOML (default: detected).
    #[arg(long, requires = "replay", value_name = "PROFILE")]
    pub profile: Option<String>,
    /// Follow a telemetry log (Mission Planner / QGroundControl `.tlog`).
    #[arg(long, value_name = "FILE")]
    pub tlog: Option<PathBuf>,
    /// Follow a live MAVLink link: `udpin:0.0.0.0:14550`, `udpout:HOST:PORT`,
    /// `tcpout:HOST:PORT` or `serial:/dev/ttyUSB0:57600`.
    #[arg(long, value_name = "URL")]
    pub connect: Option<String>,
    /// Pace of `--tlog` and `--replay`: X times their own time, or `max` (default: 1 for a tlog,
    /// max for a replay).
    #[arg(long, value_name = "X|max", conflicts_with = "connect", value_parser = playback_speed)]
    pub speed: Option<PlaybackSpeed>,
    /// The route ahead.
    #[arg(long, value_enum, default_value_t = RouteFlag::Mission)]
    pub route: RouteFlag,
    /// The mission flown (any format aloft reads), where the link does not carry it.
    #[arg(long, value_name = "FILE", conflicts_with = "route")]
    pub mission: Option<PathBuf>,
    /// Vehicle with a power model: built-in name or TOML file (e.g. from `aloft fit`).
    #[arg(long, default_value = DEFAULT_VEHICLE, value_name = "NAME|FILE")]
    pub vehicle: String,
    /// Battery pack flown (default: the vehicle's default pack).
    #[arg(long)]
    pub battery: Option<String>,
    /// Payload flown, kg.
    #[arg(value_parser = finite(), long, default_value_t = 0.0, value_name = "KG")]
    pub payload_kg: f64,
    /// An update every S seconds of flight time.
    #[arg(value_parser = finite(), long, default_value_t = 1.0, value_name = "S")]
    pub every: f64,
    /// Reserve required at landing, percent of the usable capacity (default: the mission's,
    /// else 20).
    #[arg(value_parser = finite(), long, value_name = "PERCENT")]
    pub reserve_percent: Option<f64>,
    /// The autopilot's low-voltage failsafe, pack volts, judged on the voltage under load
    /// averaged over 5 s (in place of the vehicle's own BATT_LOW_VOLT). With --route log the
    /// time until it triggers is predicted at each update and checked against the log's.
    #[arg(value_parser = finite(), long, value_name = "V")]
    pub low_voltage_v: Option<f64>,
    /// The autopilot's critical-voltage failsafe, pack volts (in place of BATT_CRT_VOLT).
    #[arg(value_parser = finite(), long, value_name = "V")]
    pub critical_voltage_v: Option<f64>,
    /// The pack's rested voltage before take-off, V: the state of charge starts from it on the
    /// pack's open-circuit curve (where the stream starts after it, or says nothing of it).
    #[arg(value_parser = finite(), long, value_name = "V")]
    pub start_voltage_v: Option<f64>,
    /// Monte-Carlo scenarios of the route ahead per update.
    #[arg(long, default_value_t = crate::engine::live::LIVE_SCENARIOS, value_parser = clap::value_parser!(u32).range(1..=10_000), value_name = "N")]
    pub scenarios: u32,
    /// aloft's MAVLink system id on the link (a ground station's).
    #[arg(long, default_value_t = 255, value_name = "ID")]
    pub system_id: u8,
    /// aloft's MAVLink component id (190: MAV_COMP_ID_MISSIONPLANNER), for its requests and
    /// heartbeat.
    #[arg(long, default_value_t = 190, value_name = "ID")]
    pub component_id: u8,
    /// The component of the vehicle's own system aloft's battery, texts and values are sent
    /// from, 1-255 (191: MAV_COMP_ID_ONBOARD_COMPUTER), so a ground station shows them beside
    /// the autopilot's.
    #[arg(long, default_value_t = crate::engine::live::DEFAULT_DISPLAY_COMPONENT_ID, value_parser = clap::value_parser!(u8).range(1..), value_name = "ID", allow_negative_numbers = true)]
    pub display_component_id: u8,
    /// The BATTERY_STATUS id aloft's own estimate of the pack is sent under, 0-255 (100: above
    /// ArduPilot's 0-15 and PX4's 0-3, so no autopilot battery's).
    #[arg(long, default_value_t = crate::engine::live::DEFAULT_BATTERY_ID, value_name = "ID", allow_negative_numbers = true)]
    pub battery_id: u8,
    /// Silence of the vehicle after which the link is said lost, s (in a telemetry log: a
    /// forward step of its clock longer than this, not waited through nor counted as time).
    #[arg(value_parser = finite(), long, default_value_t = 5.0, value_name = "S")]
    pub link_timeout: f64,
    /// The day's air (default: with --route log the log's own; else the mission's home
    /// altitude, else the vehicle file's density).
    #[command(flatten)]
    pub air: AirFlags,
}

/// The pace of a replayed source (`--speed`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlaybackSpeed {
    /// As fast as it goes.
    Max,
    /// Times its own time.
    Times(f64),
}

/// `max` or a positive, finite number.
fn playback_speed(text: &str) -> Result<PlaybackSpeed, String> {
    if text.eq_ignore_ascii_case("max") {
        return Ok(PlaybackSpeed::Max);
    }
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(PlaybackSpeed::Times(x)),
        _ => Err("expected `max` or a positive number (times the log's own time)".to_string()),
    }
}

/// What `aloft live` is asked: the validation replay, or a source followed.
#[derive(Debug, Clone, PartialEq)]
pub enum LiveTask {
    /// `--route log`.
    Validate(LiveReplayRequest),
    /// A source followed on the mission's route.
    Follow {
        /// Where the flight comes from.
        source: LiveSource,
        /// How it is answered.
        request: Box<LiveRequest>,
    },
}

impl LiveFlags {
    /// The engine's task of these flags.
    ///
    /// # Errors
    /// A voltage threshold (`--low-voltage-v`, `--critical-voltage-v`) that is not positive,
    /// on either route; `--route log` without `--replay`, a `--speed` that is neither `max` nor
    /// a positive number, a link timeout that is not positive, and a `--mission` that cannot be
    /// read.
    pub fn request(&self) -> Result<LiveTask, Error> {
        let logs = |path: &PathBuf| FlightLogs {
            logs: vec![path.clone()],
            profile: self.profile.clone(),
            ..FlightLogs::default()
        };
        for (name, v) in [
            ("low-voltage-v", self.low_voltage_v),
            ("critical-voltage-v", self.critical_voltage_v),
        ] {
            if v.is_some_and(|v| !(v > 0.0 && v <= 1e4)) {
                return Err(Error::InvalidInput {
                    name,
                    value: v.unwrap_or(f64::NAN),
                    unit: "V",
                    expected: "a positive pack voltage up to 10000 V",
                });
            }
        }
        if self.route == RouteFlag::Log {
            let path = self.replay.as_ref().ok_or(Error::MissingValue {
                flag: "--replay",
                hint: "--route log checks the predictions against the rest of a logged path, which only a replayed log has",
            })?;
            return Ok(LiveTask::Validate(LiveReplayRequest {
                logs: logs(path),
                battery: self.battery.clone(),
                payload_kg: self.payload_kg,
                every_s: self.every,
                air: self.air.input(),
                low_voltage_v: self.low_voltage_v,
                critical_voltage_v: self.critical_voltage_v,
            }));
        }
        let speed = match self.speed {
            None if self.tlog.is_some() => Some(1.0),
            None | Some(PlaybackSpeed::Max) => None,
            Some(PlaybackSpeed::Times(x)) => Some(x),
        };
        // At most 1e9 s (31 years): any longer is no timeout, and too long for a duration.
        if !(self.link_timeout > 0.0 && self.link_timeout <= 1e9) {
            return Err(Error::InvalidInput {
                name: "link-timeout",
                value: self.link_timeout,
                unit: "s",
                expected: "a positive number of seconds, at most 1e9",
            });
        }
        let source = match (&self.replay, &self.tlog, &self.connect) {
            (Some(path), _, _) => LiveSource::Replay {
                logs: logs(path),
                speed,
            },
            (_, Some(path), _) => LiveSource::Tlog {
                path: path.clone(),
                speed,
                timeout_s: self.link_timeout,
            },
            (_, _, url) => LiveSource::Connect {
                url: url.clone().unwrap_or_default(),
                system_id: self.system_id,
                component_id: self.component_id,
                display_component_id: self.display_component_id,
                timeout_s: self.link_timeout,
            },
        };
        let mission = self
            .mission
            .as_deref()
            .map(|p| Mission::load(Some(p)))
            .transpose()?;
        Ok(LiveTask::Follow {
            source,
            request: Box::new(LiveRequest {
                battery: self.battery.clone(),
                payload_kg: self.payload_kg,
                every_s: self.every,
                mission,
                reserve_percent: self.reserve_percent,
                speed_mps: None,
                scenarios: self.scenarios,
                low_voltage_v: self.low_voltage_v,
                critical_voltage_v: self.critical_voltage_v,
                pack_failsafe_v: [None, None],
                start_voltage_v: self.start_voltage_v,
                air: self.air.input(),
                battery_id: self.battery_id,
            }),
        })
    }
}
