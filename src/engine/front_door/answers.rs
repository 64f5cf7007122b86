//! The command line's `--format json` answers as text, one request of flags in: what the JSON
//! front ends give (the Python package; the page's API of `aloft serve` to come), so that none
//! of them composes a pipeline of its own and each answers exactly as `aloft ... --format json`
//! (the Python tests hold every answer equal to the command line's).
//!
//! Each function is the steps of its command: the vehicle, the request of the flags, the engine
//! call, the JSON text (pretty, as the command line prints it, without its final line break).

use std::path::Path;

use serde::Serialize;

use crate::engine::basics::logs::log_info;
use crate::engine::front_door::flags::{
    EnduranceFlags, FitFlags, LiveFlags, LiveTask, LogInfoFlags, MissionScenarioFlags, PlanFlags,
    ValidateFlags,
};
use crate::engine::front_door::maps::mission_map::mission_map;
use crate::engine::front_door::maps::plan_map::{fly_plan_map, SortieMap};
use crate::engine::front_door::maps::profile::route_profile;
use crate::engine::identification::fit::fit_logs;
use crate::engine::identification::validate::validate_logs;
use crate::engine::live::{follow_live, replay_live, LiveUpdate};
use crate::engine::missions::mission::{plan_mission, plan_mission_with};
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_outputs::MissionOutputs;
use crate::engine::performance::endurance::{endurance, power_curve};
use crate::engine::performance::payload_sweep::payload_sweep;
use crate::engine::plan_to_fly::fly_plan::{plan_to_fly, FlyPlan};
use crate::engine::uncertainty::scenarios::{
    endurance_scenarios, plan_scenarios, EnduranceWithUncertainty, MissionWithUncertainty,
};
use crate::engine::vehicles::calibrate::calibrate_spec_file;
use crate::engine::vehicles::vehicle::{list_vehicles, Vehicle, VehicleEntry};
use crate::error::Error;

/// A value as the command line's JSON text.
pub fn json_text(value: &impl serde::Serialize) -> Result<String, Error> {
    serde_json::to_string_pretty(value).map_err(|e| Error::OptionsFormat {
        what: "answer",
        message: e.to_string(),
    })
}

/// `aloft mission [PATH] --format json` (`None`: the built-in demo), with its uncertainty when
/// the flags ask for scenarios.
///
/// # Errors
/// As [`plan_mission`] and [`plan_scenarios`].
pub fn mission_answer(path: Option<&Path>, flags: &MissionScenarioFlags) -> Result<String, Error> {
    mission_answer_for(&Mission::load(path)?, flags)
}

/// [`mission_answer`] of a mission already read (a file's text sent to the page's API).
///
/// # Errors
/// As [`plan_mission`] and [`plan_scenarios`].
pub fn mission_answer_for(m: &Mission, flags: &MissionScenarioFlags) -> Result<String, Error> {
    mission_answer_with(&Vehicle::load(&flags.mission.vehicle)?, m, flags)
}

/// [`mission_answer_for`] of a vehicle already loaded (`aloft serve`'s, read at its start or
/// sent to it), in place of the flags' `vehicle`.
///
/// # Errors
/// As [`plan_mission`] and [`plan_scenarios`].
pub fn mission_answer_with(
    v: &Vehicle,
    m: &Mission,
    flags: &MissionScenarioFlags,
) -> Result<String, Error> {
    let opts = flags.mission.options();
    let plan = plan_mission(v, m, &opts)?;
    match flags.scenarios.options(false) {
        None => plan.to_json(),
        Some(sc) => MissionWithUncertainty {
            summary: plan.summary(),
            uncertainty: &plan_scenarios(v, m, &opts, &sc)?,
        }
        .to_json(),
    }
}

/// The page's map of the mission file at `path` (`None`: the built-in demo): see
/// [`mission_map_answer_for`].
///
/// # Errors
/// As [`plan_mission`] and [`plan_scenarios`].
pub fn mission_map_answer(
    path: Option<&Path>,
    flags: &MissionScenarioFlags,
) -> Result<String, Error> {
    mission_map_answer_for(&Mission::load(path)?, flags)
}

/// The page's map of a mission already read ([`MissionMap`](crate::engine::MissionMap)): the route
/// per segment, the point of no return, the state of charge over time, when the flags ask
/// for scenarios its band, and with terrain the route's profile over the ground, as compact JSON. Planned with the same flags as [`mission_answer_for`], so the two
/// answers describe one flight.
///
/// # Errors
/// As [`plan_mission`] and [`plan_scenarios`].
pub fn mission_map_answer_for(m: &Mission, flags: &MissionScenarioFlags) -> Result<String, Error> {
    mission_map_answer_with(&Vehicle::load(&flags.mission.vehicle)?, m, flags)
}

/// [`mission_map_answer_for`] of a vehicle already loaded, in place of the flags' `vehicle`.
///
/// # Errors
/// As [`plan_mission`] and [`plan_scenarios`].
pub fn mission_map_answer_with(
    v: &Vehicle,
    m: &Mission,
    flags: &MissionScenarioFlags,
) -> Result<String, Error> {
    let opts = flags.mission.options();
    let outputs = MissionOutputs {
        plot: true,
        ..MissionOutputs::default()
    };
    let plan = plan_mission_with(v, m, &opts, &outputs)?;
    let fan = match flags.scenarios.options(true) {
        None => None,
        Some(sc) => plan_scenarios(v, m, &opts, &sc)?.soc_fan,
    };
    let mut map = mission_map(&plan, m, fan);
    map.profile = route_profile(&plan, m, opts.terrain.as_deref())?;
    // Compact: the page's, not a reader's (a long route is thousands of points).
    serde_json::to_string(&map).map_err(|e| Error::OptionsFormat {
        what: "answer",
        message: e.to_string(),
    })
}

/// `aloft plan MISSION --format json` of a mission already read, with what the page needs that
/// the command line writes to files instead: each file's text (`texts`, in flight order, as
/// `{"file", "text"}`) and each sortie's flown path (`maps`: [`fly_plan_map`]). No file is
/// written. When no plan keeps the reserve, the command line's answer of that
/// ([`no_plan_answer`]). Compact, as the page's map.
///
/// # Errors
/// As [`plan_to_fly`] (but [`Error::NoPlan`], which is an answer) and [`PlanFlags::request`].
pub fn plan_answer_for(m: &Mission, flags: &PlanFlags) -> Result<String, Error> {
    plan_answer_with(&Vehicle::load(&flags.mission.vehicle)?, m, flags)
}

/// [`plan_answer_for`] of a vehicle already loaded, in place of the flags' `vehicle`.
///
/// # Errors
/// As [`plan_answer_for`].
pub fn plan_answer_with(v: &Vehicle, m: &Mission, flags: &PlanFlags) -> Result<String, Error> {
    let request = flags.request()?;
    let plan = match plan_to_fly(v, m, &request) {
        Ok(plan) => plan,
        Err(Error::NoPlan { reason }) => return Ok(no_plan_answer(&reason)),
        Err(e) => return Err(e),
    };
    let answer = PlanAnswer {
        texts: plan
            .sorties
            .iter()
            .zip(&plan.texts)
            .map(|(s, text)| PlanText {
                file: &s.file,
                text,
            })
            .collect(),
        maps: fly_plan_map(v, &plan, &request)?,
        plan: &plan,
    };
    serde_json::to_string(&answer).map_err(|e| Error::OptionsFormat {
        what: "answer",
        message: e.to_string(),
    })
}

/// `aloft plan --format json` when no plan keeps the reserve (exit 1 on the command line): the
/// answer of an infeasible mission, `{"feasible":false,"reason":...}`.
pub fn no_plan_answer(reason: &str) -> String {
    serde_json::json!({ "feasible": false, "reason": reason }).to_string()
}

/// The answer of [`plan_answer_for`]: the plan's JSON, its files' texts and its sorties' maps.
#[derive(Serialize)]
struct PlanAnswer<'a> {
    #[serde(flatten)]
    plan: &'a FlyPlan,
    texts: Vec<PlanText<'a>>,
    maps: Vec<SortieMap>,
}

/// A file of a plan and its text.
#[derive(Serialize)]
struct PlanText<'a> {
    file: &'a str,
    text: &'a str,
}

/// The answer of `aloft plan` as the command line gives it: its `--format json` text and the
/// texts of the files it writes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlanWithTexts {
    /// `aloft plan ... --format json`: the plan (`files`, `batteries`, `energy_wh`,
    /// `duration_s`, `sorties`, `as_given`, `changes`), or [`no_plan_answer`] when no plan keeps
    /// the reserve (the command's exit 1; no file written).
    pub json: String,
    /// The files' texts, in flight order (none without a plan).
    pub texts: Vec<String>,
}

/// `aloft plan [PATH] -o DIR --format json` (`None`: the built-in demo): the missions to fly,
/// one per battery. With `output` (the folder, and whether to overwrite files that exist) the
/// files are written there by [`FlyPlan::write`] and the answer's `files` are their paths, as
/// the command's; without it nothing is written and `files` are the names they would have.
///
/// # Errors
/// As [`plan_to_fly`] (but for [`Error::NoPlan`], an answer) and [`PlanFlags::request`]; an
/// existing file without `force` ([`Error::FileExists`]).
pub fn plan_answer(
    path: Option<&Path>,
    flags: &PlanFlags,
    output: Option<(&Path, bool)>,
) -> Result<PlanWithTexts, Error> {
    // In the command's order: the vehicle, the mission, the request.
    let v = Vehicle::load(&flags.mission.vehicle)?;
    let m = Mission::load(path)?;
    let request = flags.request()?;
    let mut plan = match plan_to_fly(&v, &m, &request) {
        Ok(plan) => plan,
        Err(Error::NoPlan { reason }) => {
            return Ok(PlanWithTexts {
                json: no_plan_answer(&reason),
                texts: Vec::new(),
            })
        }
        Err(e) => return Err(e),
    };
    if let Some((dir, force)) = output {
        plan.write(dir, force)?;
    }
    Ok(PlanWithTexts {
        json: json_text(&plan)?,
        texts: std::mem::take(&mut plan.texts),
    })
}

/// `aloft endurance --format json`: the power curve with `--sweep-speed`, endurance against
/// payload with `--payload-sweep`, with its uncertainty when the flags ask for scenarios.
///
/// # Errors
/// As [`endurance`] and the sweeps.
pub fn endurance_answer(flags: &EnduranceFlags) -> Result<String, Error> {
    endurance_answer_with(&Vehicle::load(&flags.vehicle)?, flags)
}

/// [`endurance_answer`] of a vehicle already loaded, in place of the flags' `vehicle`.
///
/// # Errors
/// As [`endurance`] and the sweeps.
pub fn endurance_answer_with(v: &Vehicle, flags: &EnduranceFlags) -> Result<String, Error> {
    let opts = flags.options();
    if let Some(sweep) = &flags.payload_sweep {
        return json_text(&payload_sweep(v, &opts, sweep)?);
    }
    if let Some(step) = flags.sweep_speed {
        return json_text(&power_curve(v, &opts, step)?);
    }
    let summary = endurance(v, &opts)?;
    match flags.scenarios.options(false) {
        None => summary.to_json(),
        Some(sc) => json_text(&EnduranceWithUncertainty {
            summary: &summary,
            uncertainty: &endurance_scenarios(v, &opts, &sc)?,
        }),
    }
}

/// `aloft vehicles --format json`: the built-in vehicles with their packs and sources.
///
/// # Errors
/// A built-in vehicle file that does not read (a defect, tested against).
pub fn vehicles_answer() -> Result<String, Error> {
    vehicles_answer_of(&list_vehicles()?)
}

/// `aloft vehicles --format json` of a list of entries ([`list_vehicles`] and the vehicles
/// `aloft serve` was given or sent: [`Vehicle::entry`]).
///
/// # Errors
/// None in practice (finite numbers serialise).
pub fn vehicles_answer_of(entries: &[VehicleEntry]) -> Result<String, Error> {
    json_text(&entries)
}

/// One vehicle's entry as `aloft vehicles --format json` lists it ([`Vehicle::entry`]), listed
/// under `name`.
///
/// # Errors
/// As [`Vehicle::entry`].
pub fn vehicle_answer(v: &Vehicle, name: &str) -> Result<String, Error> {
    let mut entry = v.entry()?;
    entry.name = name.to_string();
    json_text(&entry)
}

/// `aloft vehicles calibrate SPEC -o OUTPUT [--force] --format json`: the vehicle file of a
/// spec sheet, written to `output` (an existing file replaced only with `force`).
///
/// # Errors
/// As [`calibrate_spec_file`], and an `output` that exists (without `force`) or cannot be
/// written.
pub fn calibrate_vehicle_answer(spec: &Path, output: &Path, force: bool) -> Result<String, Error> {
    let c = calibrate_spec_file(spec)?;
    c.write_vehicle_file(output, force)?;
    json_text(&c)
}

/// `aloft log info PATH --format json`.
///
/// # Errors
/// As [`log_info`].
pub fn log_info_answer(path: &Path, flags: &LogInfoFlags) -> Result<String, Error> {
    log_info_answer_as(path, &path.display().to_string(), flags)
}

/// [`log_info_answer`] of the log at `path` as `aloft log info NAME` answers it: the page's
/// upload, kept in a temporary file, named as it was sent.
///
/// # Errors
/// As [`log_info`].
pub fn log_info_answer_as(path: &Path, name: &str, flags: &LogInfoFlags) -> Result<String, Error> {
    let mut info = log_info(path, &flags.read.options(), flags.max_lag)?;
    info.file = name.to_string();
    json_text(&info)
}

/// `aloft fit --format json` (the vehicle file written only when the flags give `-o`).
///
/// # Errors
/// As [`fit_logs`].
pub fn fit_answer(flags: &FitFlags) -> Result<String, Error> {
    let template = flags.template()?;
    json_text(&fit_logs(&template, &flags.request()?)?)
}

/// `aloft validate --format json`.
///
/// # Errors
/// As [`validate_logs`].
pub fn validate_answer(flags: &ValidateFlags) -> Result<String, Error> {
    let v = Vehicle::load(&flags.vehicle)?;
    json_text(&validate_logs(&v, &flags.request(false))?.report)
}

/// `aloft live --format json` as one JSON text: `{"updates": [...], "check": ...}` for the
/// validation replay (`--route log`), else `{"updates": [...], "summary": ...}`.
///
/// # Errors
/// As [`replay_live`] and [`follow_live`].
pub fn live_answer(flags: &LiveFlags) -> Result<String, Error> {
    let v = Vehicle::load(&flags.vehicle)?;
    let mut updates: Vec<LiveUpdate> = Vec::new();
    let mut keep = |u: &LiveUpdate| -> Result<(), Error> {
        updates.push(u.clone());
        Ok(())
    };
    let end = match flags.request()? {
        LiveTask::Validate(request) => {
            serde_json::json!({ "check": replay_live(&v, &request, &mut keep)? })
        }
        LiveTask::Follow { source, request } => {
            let mut source = source.open()?;
            serde_json::json!({ "summary": follow_live(&v, &request, &mut source, &mut keep)? })
        }
    };
    let mut answer = serde_json::json!({ "updates": updates });
    if let (Some(a), serde_json::Value::Object(e)) = (answer.as_object_mut(), end) {
        a.extend(e);
    }
    json_text(&answer)
}
