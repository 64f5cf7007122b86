//! The one front door: requests in, answers out.
//!
//! Everything that reaches aloft from outside goes through this module: the `aloft` command line
//! (which only parses arguments into these requests and renders the answers), the C ABI of
//! `aloft-ffi`, embedding programs (a ground station in Rust), and the Python package. None of
//! them composes a pipeline of its own, so for the same request they give the same answer, bit
//! for bit. The answers serialise (serde) to the JSON of `aloft <command> --format json`.
//!
//! | concern | requests | answer | folder or file |
//! |---|---|---|---|
//! | vehicles | [`Vehicle::load`], [`Vehicle::builtin`], [`Vehicle::from_toml`]; [`Vehicle::takeoff_mass`] (the one mass every command flies) | [`Vehicle`], [`TakeoffMass`], [`list_vehicles`], one vehicle's entry of that list: [`Vehicle::entry`] | `vehicles/` |
//! | calibrate | [`SpecSheet`] → [`calibrate_spec`]; a vehicle file → [`calibrate_hover`] | [`SpecCalibration`], [`HoverCalibration`] | `vehicles/` |
//! | missions | [`Mission::load`] (aloft TOML or JSON, QGroundControl `.plan`, `.waypoints`, recognised from the content) + [`MissionOptions`] → [`plan_mission`] | [`Plan`] ([`MissionSummary`] with the [`RouteFigures`], samples, files) | `missions/` (the day it flies in: `missions/day.rs` over `conditions/`) |
//! | the day's conditions | [`AirInput`] → [`resolve_air`] (density from altitude, temperature, pressure and humidity, or given); a `[wind]` table or a gridded field ([`read_wind_field`]) | [`Air`], a wind and its words ([`describe_wind_spec`]) | `conditions/` |
//! | replay of a log | [`ReplayRequest`] → [`replay_log`] | [`ReplayAnswer`] | `identification/` |
//! | endurance | [`EnduranceOptions`] → [`endurance`], [`power_curve`]; + [`PayloadSweep`] → [`payload_sweep`] | [`EnduranceSummary`], [`PowerCurve`], [`PayloadCurve`] | `performance/` |
//! | power | [`PowerQuery`] → [`power_point`]; [`power_csv`] | [`PowerAnswer`] | `performance/` |
//! | propulsion | [`hover`], [`hover_sweep`], [`RotorRequest`] → [`rotor_response`] | [`HoverResult`], [`HoverSweep`], [`RotorAnswer`] | `performance/` |
//! | logs | [`LogReadOptions`] → [`log_info`], [`convert_log`] | [`LogInfo`], [`ConvertSummary`] | `basics/logs.rs` |
//! | identification | [`FitRequest`] → [`fit_logs`]; [`ValidateRequest`] → [`validate_logs`] | [`FitAnswer`], [`ValidateAnswer`] | `identification/` |
//! | packs | [`PackFitRequest`] → [`fit_pack`] (logs → a pack file); a `--battery` value → [`fly_with_battery`] (the command line: [`load_flying`]) (a pack name, or a [`PackFile`] flown, for every command that flies) | [`PackFitAnswer`], [`FlyingPack`] | `packs/` |
//! | in flight | [`InFlightEstimator`] | re-estimated efficiency | `live/` |
//! | how sure | [`ScenarioOptions`] → [`plan_scenarios`], [`endurance_scenarios`] | [`Uncertainty`], [`EnduranceUncertainty`] | `uncertainty/` |
//! | a flight followed live | [`LiveRequest`] and a [`LiveSource`] → [`follow_live`] (or event by event, [`LiveSession`]); [`LiveReplayRequest`] → [`replay_live`] | [`LiveUpdate`], [`LiveSummary`], [`LiveCheck`]; [`LiveReplies`] to the link | `live/` |
//! | the page's map (`aloft serve`) | a [`Plan`] → [`mission_map`] (with terrain, the route's [`TerrainProfile`] over the ground) | [`MissionMap`] | `front_door/maps/` |
//! | plans to fly (`aloft plan`) | a [`Mission`] + [`FlyPlanRequest`] → [`plan_to_fly`] (candidates, speeds for the wind, surveys turned, sorties cut inside legs, each file read back); [`FlyPlan::write`] | [`FlyPlan`] (its files' texts) | `plan_to_fly/` (sorties: `missions/sorties.rs`) |
//! | a plan to fly on the page's map | a [`FlyPlan`] → [`fly_plan_map`] | [`SortieMap`] per sortie | `front_door/maps/` |
//! | answers as the command line's JSON text (Python, `aloft serve`) | the option groups of [`flags`], or keywords ([`parse_keywords`]) → [`answers`] (with a vehicle already loaded: the `*_with` functions) | JSON text | `front_door/` |
//! | work a caller bounds (`aloft serve`) | [`WorkBounds`] in [`ScenarioOptions`] and [`FlyPlanRequest`]: the steps of a request's scenarios, a cancellation flag; a [`StepMeter`] in [`MissionOptions`]: the steps of every flight of a mission or a plan | [`crate::Error::TooMuchWork`], [`crate::Error::RequestTooLong`], [`crate::Error::Cancelled`] | `basics/step_meter.rs` |
//! | files a request names | [`read_text_file`] (regular files, at most [`MAX_INPUT_BYTES`]), [`file_keywords`] (the options that name one), [`read_wind_field`], [`check_profile`] | their text, or errors that quote none of it | `basics/files.rs`, `front_door/keywords.rs`, `conditions/`, `basics/logs.rs` |
//! | the ground (`aloft terrain`) | `--terrain DIR` or `ALOFT_TERRAIN` → [`terrain::from_flag_or_env`]; a [`terrain::Terrain`] and places → [`terrain::heights`] | [`terrain::Heights`] | `conditions/terrain.rs` |
//! | files written | [`write_output`], [`Output`], [`OutputSet`] (aloft's one way: exclusive temporary file, rename, nothing replaced without `force`, sets all or nothing), [`safe_stem`] (a name from an input's file name), [`abandon_outputs`] (interrupted) | the files, or [`crate::Error::Output`] | `basics/files.rs` (`aloft_core::output`) |
//!
//! The folders stand in layers, each importing only those below it: `basics/` (files, logs,
//! finite numbers, the step meter) at the ground, then `vehicles/` and `conditions/` (the air,
//! the wind, the ground), then `missions/`, then `performance/` and `packs/`, then
//! `uncertainty/` and `identification/`, then `plan_to_fly/` and `live/`; `front_door/` (the
//! flags, the keywords, the JSON answers, the page's maps) on top. This file only re-exports.
//! The physics and geometry live in the model crates; a folder keeps the steps of its requests.
//!
//! Defaults and precedences are decided here once: which wind a mission flies in (a gridded field,
//! else the options' wind, else the mission file's, else still air; gusts on top), the reserve
//! (the options', else the mission's, else 20 %), the time step (the options', else the
//! mission's, else 0.1 s).
//!
//! Frame and units: as the planner, east-north-up metres about the home point, SI units with the
//! unit in every name, degrees only in names ending in `_deg`.
//!
//! Every type here is `Send + Sync` (checked at compile time below), no function panics on bad
//! input, and every fallible function returns [`crate::Error`].
//!
//! ```
//! use aloft::engine::{plan_mission, Mission, MissionOptions, Vehicle};
//! let m100 = Vehicle::builtin("dji-m100")?;
//! let plan = plan_mission(&m100, &Mission::demo(), &MissionOptions::default())?;
//! assert!(plan.summary().feasible);
//! let json = plan.to_json()?; // identical to `aloft mission --format json`
//! assert!(json.contains("\"energy_wh\""));
//! # Ok::<(), aloft::Error>(())
//! ```

mod basics;
mod conditions;
mod front_door;
mod identification;
mod live;
mod missions;
mod packs;
mod performance;
mod plan_to_fly;
mod uncertainty;
mod vehicles;

// The public paths of the front door's modules and the ground, as before they had folders.
pub use conditions::terrain;
pub use front_door::{answers, flags};

pub use aloft_missions::{ItemCounts, RouteFigures, SourceFormat};
pub use basics::files::{
    abandon_outputs, check_output, escaped, read_text_file, safe_stem, shown_path, write_output,
    Output, OutputError, OutputSet, MAX_INPUT_BYTES,
};
pub use basics::logs::{
    check_profile, convert_log, log_info, ConvertSummary, FlightLogs, LagInfo, LogArg, LogChannel,
    LogInfo, LogReadOptions, LogTime, LogTopic, SkippedLog, TopicCount,
};
pub use basics::step_meter::{StepMeter, WorkBounds};
/// The route figures of a mission and the formats a mission file may be in (from the
/// `aloft-missions` importers), for the CLI and embedding programs.
pub use conditions::air::{resolve_air, Air, AirInput, AirSource};
pub use front_door::keywords::{file_keywords, keywords, parse_keywords, FlagGroup, Keyword};
pub use front_door::maps::mission_map::{
    mission_map, MapPoint, MissionMap, SegmentPath, SocLine, MAP_CHART_POINTS,
};
pub use front_door::maps::plan_map::{fly_plan_map, SortieMap};
pub use front_door::maps::profile::{ProfileLeast, TerrainProfile, PROFILE_POINTS};
pub use identification::fit::{
    fit_logs, fit_parameter, FitAnswer, FitProgress, FitRequest, LogFitReport,
};
pub use identification::fit_quality::FitQuality;
pub use identification::own_vehicle::{OwnVehicle, LIPO_WH_PER_KG};
pub use identification::replay::{
    replay_log, ReplayAcceleration, ReplayAnswer, ReplayContext, ReplayRequest,
};
pub use identification::validate::{
    validate_logs, MeanBand, MeanRow, PowerSeries, ValidateAnswer, ValidateReport, ValidateRequest,
};
pub use live::estimator::InFlightEstimator;
pub use live::{
    follow_live, replay_live, FailsafeCheck, FailsafeCheckpoint, LiveCheck, LiveCheckpoint,
    LiveFailsafe, LiveRecorder, LiveReplayRequest, LiveReplies, LiveRequest, LiveSession,
    LiveSource, LiveSummary, LiveUpdate, Position, SocBand, TimeBand, DEFAULT_BATTERY_ID,
    DEFAULT_DISPLAY_COMPONENT_ID, LIVE_SCENARIOS,
};
pub use missions::flown::PlanningSpeed;
pub use missions::ground::{GroundAt, HOME_DISAGREES_M};
pub use missions::loiter::LoiterSummary;
pub use missions::mission::{
    plan_mission, plan_mission_in, plan_mission_with, PackDescription, Plan, PlanContext, Remaining,
};
pub use missions::mission_file::{Mission, DEMO_MISSION, DEMO_ORIGIN};
pub use missions::mission_options::{GustSpec, MissionOptions, DEFAULT_MIN_CLEARANCE_M};
pub use missions::mission_outputs::{MissionOutputs, PLOT_SAMPLES};
pub use missions::sorties::{SortieSummary, MAX_SORTIES};
pub use missions::summary::{
    mission_summary, FailsafeTime, MissionSummary, PointOfNoReturnSummary, SegmentSummary,
};
pub use packs::pack_file::{
    fly_with_battery, is_pack_file, load_flying, Failsafe, FlyingPack, PackFile,
};
pub use packs::pack_fit::{
    fit_pack, PackFitAnswer, PackFitRequest, DEFAULT_CUTOFF_CELL_V, DEFAULT_NOMINAL_CELL_V,
};
pub use performance::endurance::{
    endurance, power_curve, CurveContext, EnduranceContext, EnduranceOptions, EnduranceSummary,
    PowerCurve,
};
pub use performance::payload_sweep::{
    payload_sweep, PayloadCurve, PayloadRow, PayloadSweep, SweptPack, MAX_PAYLOAD_POINTS,
};
pub use performance::power::{
    power_csv_file, power_model, power_point, FlightStateDeg, PowerAnswer, PowerContext,
    PowerGradientDeg, PowerModelQuery, PowerQuery,
};
pub use performance::power_batch::{power_csv, power_values, POWER_KEYS};
pub use performance::propulsion::{
    hover, hover_sweep, rotor_response, HoverRequest, HoverSweep, RotorAnswer, RotorOverrides,
    RotorRequest, SweepPoint, BUILTIN_ROTORS,
};
pub use plan_to_fly::fly_plan::{
    plan_to_fly, FlyPlan, FlyPlanRequest, FlySortie, PlanChanges, PlanConfidence, PlanFigures,
    PlanScenarios, SpeedChange, SpeedChoice, DEFAULT_CAMERA_INTERVAL_S,
    DEFAULT_CAPACITY_SD_PERCENT, DEFAULT_CONFIDENCE, DEFAULT_OVERLAP_M, DEFAULT_PLAN_SCENARIOS,
    DEFAULT_WIND_FROM_SD_DEG, MIN_WIND_SPEED_SD_MPS, WIND_SPEED_SD_SHARE,
};
pub use plan_to_fly::survey_angle::{AngleChange, AngleKept, ANGLE_STEP_DEG};
pub use uncertainty::scenario_stats::{Percentiles, SegmentBand};
pub use uncertainty::scenarios::{
    endurance_scenarios, options_from_json, plan_scenarios, EnduranceUncertainty,
    EnduranceWithUncertainty, MissionWithUncertainty, ScenarioOptions, SocFan, Spreads,
    Uncertainty, WithUncertainty, DEFAULT_POWER_SD_PERCENT, DEFAULT_SCENARIOS, MAX_SCENARIOS,
};
pub use vehicles::calibrate::{
    calibrate_hover, calibrate_spec, calibrate_spec_file, HoverCalibration, PublishedHover,
    SpecBattery, SpecCalibration, SpecDrag, SpecSheet,
};
pub use vehicles::vehicle::{list_vehicles, MassParts, TakeoffMass, Vehicle, VehicleEntry};

/// A parser's message on one line, and an error with its causes on one line (the CLI prints
/// every error on one line).
pub use aloft_core::{error_line, one_line};

/// The error of every engine function, and what is wrong with a payload sweep (so callers match
/// on them through this module alone).
pub use crate::error::{Error, SweepProblem};

/// The vehicle every command uses when none is named.
pub use crate::vehicle::{builtin_names, DEFAULT_VEHICLE, VEHICLE_TEMPLATE};
pub use conditions::wind::{describe_wind_spec, read_wind_field};

/// Model types that appear in requests and answers, re-exported so callers of the engine (the
/// command line among them) need no model crate.
pub use aloft_logs::{sample::Gap, sample::NonMonotonic, Channel, DroppedValue, LogFormat};
pub use aloft_planner::{
    CornerMode, EnduranceReport, MissionReport, PointOfNoReturn, Sample, SegmentReport, Shortfall,
    SweepRow, Wind, WindProfileKind, WindSpec,
};
pub use aloft_power::fit::{DragFit, FitParameter, KeptParameter, PowerFit};
pub use aloft_power::{AoaModel, FlightState, PowerBreakdown, Term, Terms};
pub use aloft_propulsion::fit::battery::PackResistanceFit;
pub use aloft_propulsion::{EscProtocol, HoverResult, RotorSpec, RotorTransientResult};

// Everything a ground station shares between threads is Send + Sync.
const _: () = {
    const fn send_sync<T: Send + Sync>() {}
    send_sync::<Vehicle>();
    send_sync::<Mission>();
    send_sync::<MissionOptions>();
    send_sync::<Plan>();
    send_sync::<MissionSummary>();
    send_sync::<EnduranceOptions>();
    send_sync::<EnduranceSummary>();
    send_sync::<PayloadSweep>();
    send_sync::<PayloadCurve>();
    send_sync::<InFlightEstimator>();
    send_sync::<PowerQuery>();
    send_sync::<PowerAnswer>();
    send_sync::<ScenarioOptions>();
    send_sync::<Uncertainty>();
    send_sync::<crate::Error>();
    send_sync::<terrain::Terrain>();
};
