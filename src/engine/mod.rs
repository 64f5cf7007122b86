//! The one front door: requests in, answers out.
//!
//! Everything that reaches aloft from outside goes through this module: the `aloft` command line
//! (which only parses arguments into these requests and renders the answers), the C ABI of
//! `aloft-ffi`, embedding programs (a ground station in Rust), and the Python package. None of
//! them composes a pipeline of its own, so for the same request they give the same answer, bit
//! for bit. The answers serialise (serde) to the JSON of `aloft <command> --format json`.
//!
//! | concern | requests | answer | file |
//! |---|---|---|---|
//! | vehicles | [`Vehicle::load`], [`Vehicle::builtin`], [`Vehicle::from_toml`]; [`Vehicle::takeoff_mass`] (the one mass every command flies) | [`Vehicle`], [`TakeoffMass`], [`list_vehicles`], one vehicle's entry of that list: [`Vehicle::entry`] | `vehicles.rs` |
//! | calibrate | [`SpecSheet`] → [`calibrate_spec`]; a vehicle file → [`calibrate_hover`] | [`SpecCalibration`], [`HoverCalibration`] | `calibrate.rs` |
//! | missions | [`Mission::load`] (aloft TOML or JSON, QGroundControl `.plan`, `.waypoints`, recognised from the content) + [`MissionOptions`] → [`plan_mission`] | [`Plan`] ([`MissionSummary`] with the [`RouteFigures`], samples, files) | `mission.rs`, `summary.rs`, `mission_outputs.rs`, `wind.rs` |
//! | replay of a log | [`ReplayRequest`] → [`replay_log`] | [`ReplayAnswer`] | `replay.rs` |
//! | endurance | [`EnduranceOptions`] → [`endurance`], [`power_curve`]; + [`PayloadSweep`] → [`payload_sweep`] | [`EnduranceSummary`], [`PowerCurve`], [`PayloadCurve`] | `endurance.rs`, `payload_sweep.rs` |
//! | power | [`PowerQuery`] → [`power_point`]; [`power_csv`] | [`PowerAnswer`] | `power.rs`, `power_batch.rs` |
//! | propulsion | [`hover`], [`hover_sweep`], [`RotorRequest`] → [`rotor_response`] | [`HoverResult`], [`HoverSweep`], [`RotorAnswer`] | `propulsion.rs` |
//! | logs | [`LogReadOptions`] → [`log_info`], [`convert_log`] | [`LogInfo`], [`ConvertSummary`] | `logs.rs` |
//! | identification | [`FitRequest`] → [`fit_logs`]; [`ValidateRequest`] → [`validate_logs`] | [`FitAnswer`], [`ValidateAnswer`] | `fit.rs`, `validate.rs` |
//! | packs | [`PackFitRequest`] → [`fit_pack`] (logs → a pack file); a `--battery` value → [`fly_with_battery`] (the command line: [`load_flying`]) (a pack name, or a [`PackFile`] flown, for every command that flies) | [`PackFitAnswer`], [`FlyingPack`] | `pack_fit.rs`, `pack_file.rs` |
//! | in flight | [`InFlightEstimator`] | re-estimated efficiency | `estimator.rs` |
//! | how sure | [`ScenarioOptions`] → [`plan_scenarios`], [`endurance_scenarios`] | [`Uncertainty`], [`EnduranceUncertainty`] | `scenarios.rs`, `scenario_stats.rs` |
//! | a flight followed live | [`LiveRequest`] and a [`LiveSource`] → [`follow_live`] (or event by event, [`LiveSession`]); [`LiveReplayRequest`] → [`replay_live`] | [`LiveUpdate`], [`LiveSummary`], [`LiveCheck`]; [`replies`] to the link | `live/` |
//! | the page's map (`aloft serve`) | a [`Plan`] → [`mission_map`] | [`MissionMap`] | `mission_map.rs` |
//! | plans to fly (`aloft plan`) | a [`Mission`] + [`FlyPlanRequest`] → [`plan_to_fly`] (candidates, speeds for the wind, surveys turned, sorties cut inside legs, each file read back); [`FlyPlan::write`] | [`FlyPlan`] (its files' texts) | `fly_plan.rs`, `sorties.rs`, `plan_files.rs`, `survey_angle.rs` |
//! | a plan to fly on the page's map | a [`FlyPlan`] → [`fly_plan_map`] | [`SortieMap`] per sortie | `plan_map.rs` |
//! | answers as the command line's JSON text (Python, `aloft serve`) | the option groups of [`flags`], or keywords ([`parse_keywords`]) → [`answers`] (with a vehicle already loaded: the `*_with` functions) | JSON text | `answers.rs`, `flags.rs`, `keywords.rs` |
//! | work a caller bounds (`aloft serve`) | [`WorkBounds`] in [`ScenarioOptions`] and [`FlyPlanRequest`]: the steps of a request's scenarios, a cancellation flag; a [`StepMeter`] in [`MissionOptions`]: the steps of every flight of a mission or a plan | [`crate::Error::TooMuchWork`], [`crate::Error::RequestTooLong`], [`crate::Error::Cancelled`] | `step_meter.rs` |
//! | files a request names | [`read_text_file`] (regular files, at most [`MAX_INPUT_BYTES`]), [`file_keywords`] (the options that name one), [`read_wind_field`], [`check_profile`] | their text, or errors that quote none of it | `files.rs`, `keywords.rs`, `wind.rs`, `logs.rs` |
//! | files written | [`write_output`], [`Output`], [`OutputSet`] (aloft's one way: exclusive temporary file, rename, nothing replaced without `force`, sets all or nothing), [`safe_stem`] (a name from an input's file name), [`abandon_outputs`] (interrupted) | the files, or [`crate::Error::Output`] | `files.rs` (`aloft_core::output`) |
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

mod air;
pub mod answers;
mod calibrate;
mod endurance;
mod estimator;
mod files;
mod finite;
mod fit;
mod fit_quality;
pub mod flags;
mod flight;
mod flown;
mod fly_plan;
mod keywords;
mod live;
mod logs;
mod loiter;
mod mission;
mod mission_file;
mod mission_map;
mod mission_options;
mod mission_outputs;
mod own_vehicle;
mod pack_file;
mod pack_fit;
mod payload_sweep;
mod plan_files;
mod plan_map;
mod power;
mod power_batch;
mod propulsion;
mod replay;
mod scenario_stats;
mod scenarios;
mod sorties;
mod step_meter;
mod summary;
mod survey_angle;
mod validate;
mod vehicles;
mod wind;

/// The route figures of a mission and the formats a mission file may be in (from the
/// `aloft-missions` importers), for the CLI and embedding programs.
pub use air::{resolve_air, Air, AirInput, AirSource};
pub use aloft_missions::{ItemCounts, RouteFigures, SourceFormat};
pub use calibrate::{
    calibrate_hover, calibrate_spec, calibrate_spec_file, HoverCalibration, PublishedHover,
    SpecBattery, SpecCalibration, SpecDrag, SpecSheet,
};
pub use endurance::{
    endurance, power_curve, CurveContext, EnduranceContext, EnduranceOptions, EnduranceSummary,
    PowerCurve,
};
pub use estimator::InFlightEstimator;
pub use files::{
    abandon_outputs, check_output, escaped, read_text_file, safe_stem, shown_path, write_output,
    Output, OutputError, OutputSet, MAX_INPUT_BYTES,
};
pub use fit::{fit_logs, fit_parameter, FitAnswer, FitProgress, FitRequest, LogFitReport};
pub use fit_quality::FitQuality;
pub use flown::PlanningSpeed;
pub use fly_plan::{
    plan_to_fly, FlyPlan, FlyPlanRequest, FlySortie, PlanChanges, PlanFigures, SpeedChange,
    SpeedChoice, DEFAULT_CAMERA_INTERVAL_S, DEFAULT_OVERLAP_M,
};
pub use keywords::{file_keywords, keywords, parse_keywords, FlagGroup, Keyword};
pub use live::{
    follow_live, replay_live, replies, LiveCheck, LiveCheckpoint, LiveRecorder, LiveReplayRequest,
    LiveRequest, LiveSession, LiveSource, LiveSummary, LiveUpdate, Position, LIVE_SCENARIOS,
};
pub use logs::{
    check_profile, convert_log, log_info, ConvertSummary, FlightLogs, LagInfo, LogArg, LogChannel,
    LogInfo, LogReadOptions, LogTime, LogTopic, SkippedLog, TopicCount,
};
pub use loiter::LoiterSummary;
pub use mission::{
    plan_mission, plan_mission_in, plan_mission_with, PackDescription, Plan, PlanContext, Remaining,
};
pub use mission_file::{Mission, DEMO_MISSION, DEMO_ORIGIN};
pub use mission_map::{
    mission_map, GeoPoint, MapPoint, MissionMap, SegmentPath, SocLine, MAP_CHART_POINTS,
};
pub use mission_options::{GustSpec, MissionOptions};
pub use mission_outputs::{MissionOutputs, PLOT_SAMPLES};
pub use own_vehicle::{OwnVehicle, LIPO_WH_PER_KG};
pub use pack_file::{fly_with_battery, is_pack_file, load_flying, Failsafe, FlyingPack, PackFile};
pub use pack_fit::{
    fit_pack, PackFitAnswer, PackFitRequest, DEFAULT_CUTOFF_CELL_V, DEFAULT_NOMINAL_CELL_V,
};
pub use payload_sweep::{
    payload_sweep, PayloadCurve, PayloadRow, PayloadSweep, SweptPack, MAX_PAYLOAD_POINTS,
};
pub use plan_map::{fly_plan_map, SortieMap};
pub use power::{
    power_csv_file, power_model, power_point, FlightStateDeg, PowerAnswer, PowerContext,
    PowerGradientDeg, PowerModelQuery, PowerQuery,
};
pub use power_batch::{power_csv, power_values, POWER_KEYS};
pub use propulsion::{
    hover, hover_sweep, rotor_response, HoverRequest, HoverSweep, RotorAnswer, RotorOverrides,
    RotorRequest, SweepPoint, BUILTIN_ROTORS,
};
pub use replay::{replay_log, ReplayAcceleration, ReplayAnswer, ReplayContext, ReplayRequest};
pub use scenario_stats::{Percentiles, PointOfNoReturnPercentiles, SegmentBand};
pub use scenarios::{
    endurance_scenarios, options_from_json, plan_scenarios, EnduranceUncertainty,
    EnduranceWithUncertainty, MissionWithUncertainty, ScenarioOptions, SocFan, Spreads,
    Uncertainty, WithUncertainty, DEFAULT_POWER_SD_PERCENT, DEFAULT_SCENARIOS, MAX_SCENARIOS,
};
pub use sorties::{SortieSummary, MAX_SORTIES};
pub use step_meter::{StepMeter, WorkBounds};
pub use summary::{
    mission_summary, FailsafeTime, MissionSummary, PointOfNoReturnSummary, SegmentSummary,
};
pub use survey_angle::{AngleChange, ANGLE_STEP_DEG};
pub use validate::{
    validate_logs, MeanBand, MeanRow, PowerSeries, ValidateAnswer, ValidateReport, ValidateRequest,
};
pub use vehicles::{list_vehicles, MassParts, TakeoffMass, Vehicle, VehicleEntry};

/// A parser's message on one line, and an error with its causes on one line (the CLI prints
/// every error on one line).
pub use aloft_core::{error_line, one_line};

/// The error of every engine function, and what is wrong with a payload sweep (so callers match
/// on them through this module alone).
pub use crate::error::{Error, SweepProblem};

/// The vehicle every command uses when none is named.
pub use crate::vehicle::{builtin_names, DEFAULT_VEHICLE, VEHICLE_TEMPLATE};
pub use wind::{describe_wind_spec, read_wind_field};

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
};
