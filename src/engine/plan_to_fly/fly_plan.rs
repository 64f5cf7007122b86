//! Plans to fly (`aloft plan`): the missions aloft would fly for an operator's mission, one per
//! battery, at the speeds the wind favours.
//!
//! The steps, each candidate flown by the planner that answers `aloft mission`:
//!
//! 0. **The operator's whole mission**: an unlimited loiter (NAV_LOITER_UNLIM) is flown for
//!    [`FlyPlanRequest::loiter_unlimited_s`] and the items after it, with the mission's own
//!    landing, are planned and written (`aloft mission` ends the route there with a loiter until
//!    the reserve); the answer's `notes` say what was assumed.
//!
//! 1. **As given**: the mission with its own speeds, split into sorties at whole items as
//!    `aloft mission` splits it, flown from the files that split gives (each ending with a return
//!    to launch, as every file does: a mission that ends in the air is priced with its autopilot's
//!    return rather than `aloft mission`'s generic way home). `as_given` in the answer; where
//!    that split has no files that keep the reserve, the figures of `aloft mission`.
//! 2. **Speeds for the wind** ([`SpeedChoice`]): each leg at the ground speed that costs least
//!    energy per metre along its course in the wind at its height
//!    ([`aloft_planner::best_range_within_limits`]: within the vehicle's speed and its steady
//!    envelope), at most `max_speed_mps`, rounded to 0.1 m/s. A speed the operator set on a leg
//!    is kept unless [`SpeedChoice::Energy`]; [`SpeedChoice::Keep`] changes none. With
//!    [`SpeedChoice::Wind`] and no `max_speed_mps`, no leg is given more than the operator's
//!    fastest planned speed (the planning speed, a `.plan`'s `hoverSpeed`, and every speed the
//!    items set), but a survey leg where the camera triggers every D m, which may go up to D per
//!    camera interval: a mission planned slow and low is not written fast.
//! 3. **Sorties cut inside legs** ([`crate::engine::missions::sorties`], steps 4 and 5): each pack used to the
//!    reserve, the next sortie resuming `overlap_m` back along the route.
//! 4. **The best**: of the candidates (the mission's own speeds and the wind's, each cut inside
//!    legs, and the as-given split), the one with the fewest batteries, then the least energy; so
//!    the plan never needs more batteries or energy than the mission as given.
//! 5. **Files**, one per sortie in the input's format ([`FlyPlan::files`]), each a complete
//!    mission that `aloft mission` flies in the same conditions to the sortie's answer, and whose
//!    whole path stays inside the operator's inclusion fences and out of the exclusion ones (a
//!    `.plan`'s geofence, written into every file with its rally points).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use aloft_missions::SourceFormat;
use aloft_planner::geodesy::LocalFrame;
use aloft_planner::{best_range_within_limits, MissionSpec, SegmentSpec, Wind};

use crate::engine::basics::files::{safe_stem, shown_path, OutputSet};
use crate::engine::basics::finite::finite;
use crate::engine::basics::step_meter::WorkBounds;
use crate::engine::missions::day::mission_wind;
use crate::engine::missions::mission::{plan_mission, prepare, Prepared};
use crate::engine::missions::mission_file::{Mission, DEMO_FILE_STEM, DEMO_ORIGIN};
use crate::engine::missions::mission_options::MissionOptions;
use crate::engine::missions::mission_outputs::segment_paths;
use crate::engine::missions::sorties::{
    confident_sortie_plans, segment_ends_m, FlyOutSpeed, Margins, Route, SortieCheck, SortieMaker,
    SortiePlan, SpecSorties, SplitOptions,
};
use crate::engine::plan_to_fly::plan_files::PlannerSorties;
use crate::engine::plan_to_fly::survey_angle::{
    turned_to_wind, unturnable, AngleChange, AngleKept,
};
use crate::engine::uncertainty::scenarios::{ScenarioOptions, Spreads};
use crate::engine::uncertainty::sortie_bands::SortieScenarios;
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;
use aloft_planner::Percentiles;

/// How far back along the route a sortie resumes by default, m: a frame of a survey camera at
/// the usual 10-30 m trigger distance, so that the last images of one sortie and the first of the
/// next overlap (QGroundControl issue #4254 asks for a few waypoints back).
pub const DEFAULT_OVERLAP_M: f64 = 10.0;

/// How long an unlimited loiter (NAV_LOITER_UNLIM) is planned to last by default, s: the
/// autopilot loiters there until the operator continues the mission, which no file says; a
/// minute is a short wait for an operator's go (a delivery confirmed, a check), and the plan
/// says what it assumed so that an operator who waits longer sets `--loiter-unlimited-s`.
pub const DEFAULT_LOITER_UNLIMITED_S: f64 = 60.0;

/// The camera's shortest time between photos when neither the request nor the file gives one,
/// s: a conservative interval for a survey camera that does not state its own (give
/// `--camera-interval-s` for yours), so that no photo is skipped.
pub const DEFAULT_CAMERA_INTERVAL_S: f64 = 2.0;

/// The share of the day's scenarios each sortie lands with the reserve in by default: the 5th
/// percentile of its landing charge at the reserve or above.
pub const DEFAULT_CONFIDENCE: f64 = 0.95;

/// Scenarios a plan draws by default: the 5th percentile of 400 draws is the 20th smallest, and
/// the share that holds is known to about 1.1 percentage points (one standard error,
/// `sqrt(0.95 x 0.05 / 400)`).
pub const DEFAULT_PLAN_SCENARIOS: u32 = 400;

/// The wind speed's spread a plan draws by default, a share of the forecast speed (one standard
/// deviation), and at least [`MIN_WIND_SPEED_SD_MPS`] (see [`PlanConfidence`]).
pub const WIND_SPEED_SD_SHARE: f64 = 0.25;

/// The least wind speed spread a plan draws by default, m/s.
pub const MIN_WIND_SPEED_SD_MPS: f64 = 1.5;

/// The wind direction's spread a plan draws by default, degrees.
pub const DEFAULT_WIND_FROM_SD_DEG: f64 = 25.0;

/// The pack capacity's spread a plan draws by default, percent: packs of one model and age
/// differ by a few percent (the KAIST packs' counted charge is 0.88 to 0.96 of what their
/// management system reports, ../shared/research/air-packs.md).
pub const DEFAULT_CAPACITY_SD_PERCENT: f64 = 3.0;

/// How sure a plan must be, and of what: each sortie is cut where the share `confidence` of the
/// scenarios (`samples` draws from `seed`) still lands it with the reserve. The spreads are the
/// forecast's error and the models' (one standard deviation each); a weather forecast's 10 m
/// wind is off by about 1.5 to 2.5 m/s (root mean square) and 20 to 40 degrees a day ahead, so
/// the defaults draw the speed with a spread of [`WIND_SPEED_SD_SHARE`] of the forecast and at
/// least [`MIN_WIND_SPEED_SD_MPS`], the direction with [`DEFAULT_WIND_FROM_SD_DEG`], the pack's
/// capacity with [`DEFAULT_CAPACITY_SD_PERCENT`], the model's power with aloft's own 3 %
/// ([`crate::engine::DEFAULT_POWER_SD_PERCENT`]), and no payload spread (an operator weighs
/// it). docs/guide.md, "Plans that hold", says where these come from.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanConfidence {
    /// The share of the scenarios each sortie must land with the reserve in, 0.5 to 0.999 (0.5:
    /// the nominal cut, the bands still reported).
    pub confidence: f64,
    /// Scenarios drawn (1 to 100,000).
    pub samples: u32,
    /// Seed of the draws.
    pub seed: u64,
    /// Wind speed spread, m/s (default: a share of the forecast, see above).
    pub wind_speed_sd_mps: Option<f64>,
    /// Wind direction spread, degrees.
    pub wind_from_sd_deg: f64,
    /// Payload spread, kg.
    pub payload_sd_kg: f64,
    /// Pack capacity spread, percent.
    pub capacity_sd_percent: f64,
    /// Electrical power spread (the model's error), percent.
    pub power_sd_percent: f64,
    /// Threads for the scenarios (0: one per core); the answer does not depend on it.
    pub threads: usize,
}

impl Default for PlanConfidence {
    fn default() -> Self {
        Self {
            confidence: DEFAULT_CONFIDENCE,
            samples: DEFAULT_PLAN_SCENARIOS,
            seed: 1,
            wind_speed_sd_mps: None,
            wind_from_sd_deg: DEFAULT_WIND_FROM_SD_DEG,
            payload_sd_kg: 0.0,
            capacity_sd_percent: DEFAULT_CAPACITY_SD_PERCENT,
            power_sd_percent: crate::engine::uncertainty::scenarios::DEFAULT_POWER_SD_PERCENT,
            threads: 0,
        }
    }
}

impl PlanConfidence {
    /// The scenario options for a forecast of `forecast_mps` (the wind's speed at its reference
    /// height; `None` for a gridded field, whose wind is not drawn unless a spread is given).
    fn scenarios(&self, forecast_mps: Option<f64>, bounds: &WorkBounds) -> ScenarioOptions {
        let speed_sd = self.wind_speed_sd_mps.unwrap_or(match forecast_mps {
            Some(v) => (WIND_SPEED_SD_SHARE * v).max(MIN_WIND_SPEED_SD_MPS),
            None => 0.0,
        });
        let from_sd = match forecast_mps {
            Some(_) => self.wind_from_sd_deg,
            None if self.wind_speed_sd_mps.is_some() => self.wind_from_sd_deg,
            None => 0.0,
        };
        ScenarioOptions {
            samples: self.samples,
            seed: self.seed,
            wind_speed_sd_mps: speed_sd,
            wind_from_sd_deg: from_sd,
            payload_sd_kg: self.payload_sd_kg,
            capacity_sd_percent: self.capacity_sd_percent,
            power_sd_percent: self.power_sd_percent,
            threads: self.threads,
            soc_fan: false,
            bounds: bounds.clone(),
        }
    }
}

/// The scenarios a plan's sorties were checked in (the answer's `scenarios`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanScenarios {
    /// Scenarios drawn.
    pub samples: u32,
    /// Seed of the draws.
    pub seed: u64,
    /// The spreads drawn (one standard deviation each).
    pub spreads: Spreads,
}

/// Which legs get the wind's speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpeedChoice {
    /// Legs without a speed of their own (they fly the planning speed, which is no per-leg
    /// choice); a speed the operator set is kept.
    #[default]
    Wind,
    /// Every leg, the operator's speeds too.
    Energy,
    /// No leg: every speed as it is.
    Keep,
}

/// What `aloft plan` is asked.
#[derive(Debug, Clone, PartialEq)]
pub struct FlyPlanRequest {
    /// The mission's options (as `aloft mission`'s).
    pub options: MissionOptions,
    /// How far back along the route a sortie resumes, m.
    pub overlap_m: f64,
    /// How long an unlimited loiter is flown before the items after it, s.
    pub loiter_unlimited_s: f64,
    /// Which legs get the wind's speed.
    pub speeds: SpeedChoice,
    /// Highest ground speed a leg is given, m/s (the vehicle's own limits apply anyway).
    pub max_speed_mps: Option<f64>,
    /// The camera's shortest time between photos, s (default: a `.plan` survey's
    /// `CameraCalc.MinTriggerInterval`, else [`DEFAULT_CAMERA_INTERVAL_S`]).
    pub camera_interval_s: Option<f64>,
    /// How sure each sortie must be to land with the reserve.
    pub confidence: PlanConfidence,
    /// The scenarios of [`FlyPlanRequest::confidence`] once resolved for the forecast (set by
    /// [`plan_to_fly`]; a caller leaves it `None`).
    pub scenarios: Option<ScenarioOptions>,
    /// Keep the grid angle of every survey (else each QGroundControl survey is turned to the
    /// wind where that saves energy and covers its polygon as before, its transects drawn again
    /// at every [`ANGLE_STEP_DEG`](crate::engine::plan_to_fly::survey_angle::ANGLE_STEP_DEG) degrees and along and across the wind).
    pub keep_angle: bool,
    /// Write the mission to keep this height above the ground, m (with the options' terrain; a
    /// planner file's waypoints and loiters relative to home): `--follow-terrain`.
    pub follow_terrain_m: Option<f64>,
    /// How a mission that follows the ground is written: above mean sea level with a waypoint at
    /// every terrain sample kept (PX4, the default), or in the terrain frame (ArduPilot).
    pub follow_frames: aloft_missions::follow_terrain::FollowFrames,
    /// What the request may spend: a plan stops with [`Error::Cancelled`] before its next
    /// candidate, angle or sortie once cancelled (its steps, and its flights once cancelled, are
    /// bounded by the options' [`StepMeter`](crate::engine::basics::step_meter::StepMeter) when the caller gives one).
    pub bounds: WorkBounds,
}

impl Default for FlyPlanRequest {
    fn default() -> Self {
        Self {
            options: MissionOptions::default(),
            overlap_m: DEFAULT_OVERLAP_M,
            loiter_unlimited_s: DEFAULT_LOITER_UNLIMITED_S,
            speeds: SpeedChoice::default(),
            max_speed_mps: None,
            camera_interval_s: None,
            confidence: PlanConfidence::default(),
            scenarios: None,
            keep_angle: false,
            follow_terrain_m: None,
            follow_frames: aloft_missions::follow_terrain::FollowFrames::Amsl,
            bounds: WorkBounds::default(),
        }
    }
}

/// The figures of a way of flying the mission.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlanFigures {
    /// Packs it takes.
    pub batteries: u32,
    /// Energy of all its flights, Wh.
    pub energy_wh: f64,
    /// Flight time of all its flights, s.
    pub duration_s: f64,
}

/// One sortie of the plan: one file, one pack.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlySortie {
    /// Its file's name.
    pub file: String,
    /// The first item of the input it flies (from a planner file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_item: Option<u32>,
    /// The last item of the input it flies, whole or in part.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub last_item: Option<u32>,
    /// Where it turns home inside a leg: the fraction of that leg flown (absent: at an item).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ends_inside_leg_fraction: Option<f64>,
    /// Electrical energy drawn from its pack, Wh.
    pub energy_wh: f64,
    /// Flight time, take-off to landing, s.
    pub duration_s: f64,
    /// State of charge of its pack at landing.
    pub end_soc: f64,
    /// Its point of no return, s after take-off (absent: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point_of_no_return_s: Option<f64>,
    /// Its pack's state of charge at landing over the day's scenarios (those that land).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub landing_soc: Option<Percentiles>,
    /// The share of the day's scenarios in which it lands with the reserve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p_reserve: Option<f64>,
}

/// A leg given another speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpeedChange {
    /// The leg's item (from a planner file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub item: Option<u32>,
    /// The leg, from 1.
    pub segment: usize,
    /// Its ground speed as given (absent: the planning speed), m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from_mps: Option<f64>,
    /// Its ground speed in the plan, m/s.
    pub to_mps: f64,
}

/// What changed from the mission as given.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PlanChanges {
    /// Legs given another speed.
    pub speeds: Vec<SpeedChange>,
    /// Whether the sorties end inside legs (else at items, as given).
    pub cut_inside_legs: bool,
    /// Surveys given another grid angle.
    #[serde(default)]
    pub angles: Vec<AngleChange>,
    /// Surveys kept at their grid angle, with why (the angle tried, what it would have cost or
    /// covered).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub angles_kept: Vec<AngleKept>,
}

/// The answer of `aloft plan`: the plan beside the mission as given, its sorties and files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlyPlan {
    /// The files, in flight order (their paths once written, else their names).
    pub files: Vec<String>,
    /// Packs the plan takes.
    pub batteries: u32,
    /// Energy of all its flights, Wh.
    pub energy_wh: f64,
    /// Flight time of all its flights, s.
    pub duration_s: f64,
    /// The share of the day's scenarios each sortie was cut to land with the reserve in.
    pub confidence: f64,
    /// The scenarios drawn.
    pub scenarios: PlanScenarios,
    /// The air flown in (flattened: `air_density_kg_m3`, `density_source`, ...).
    #[serde(flatten)]
    pub air: crate::engine::conditions::air::Air,
    /// The sorties, one per file.
    pub sorties: Vec<FlySortie>,
    /// The mission as given, split at whole items as `aloft mission` splits it and flown from
    /// the files of that split (module step 1; absent when it cannot be split so).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub as_given: Option<PlanFigures>,
    /// What changed.
    pub changes: PlanChanges,
    /// What the plan could not do, and why (a survey it could not draw again).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// The files' texts, in flight order (not in the JSON: written by [`FlyPlan::write`]).
    #[serde(skip)]
    pub texts: Vec<String>,
}

/// [`Error::NoPlan`] when the mission as given (over the options' terrain) passes closer to the
/// ground than the options' least clearance, naming the segment and the place.
///
/// # Errors
/// As [`plan_mission`], and that.
fn too_close_to_the_ground(
    vehicle: &Vehicle,
    mission: &Mission,
    options: &MissionOptions,
) -> Result<(), Error> {
    let whole = plan_mission(vehicle, mission, options)?;
    let s = whole.summary();
    let least_m = options
        .min_clearance_m
        .unwrap_or(crate::engine::missions::mission_options::DEFAULT_MIN_CLEARANCE_M);
    match s.min_clearance_m {
        Some(c) if c < least_m => Err(Error::NoPlan {
            reason: s
                .reason
                .as_deref()
                .and_then(|r| r.split("; and ").next())
                .unwrap_or("the route passes too close to the ground")
                .to_string(),
        }),
        _ => Ok(()),
    }
}

/// Plan the missions to fly for `mission` with `vehicle` (module steps 1-5).
///
/// # Errors
/// As [`plan_mission`]; [`Error::NoPlan`] when no way of cutting the route keeps the reserve (a
/// leg a full pack cannot fly out and back); a mission format aloft cannot write yet.
pub fn plan_to_fly(
    vehicle: &Vehicle,
    mission: &Mission,
    request: &FlyPlanRequest,
) -> Result<FlyPlan, Error> {
    let options = &request.options;
    // An unlimited loiter lasts a stated time, and the items after it are flown (module step 0).
    let mission = &mission.read_with(aloft_missions::ReadOptions {
        loiter_unlimited_s: Some(request.loiter_unlimited_s),
        ..mission.read_options()
    })?;
    // Written again to follow the ground, when asked (its files carry those frames).
    let followed = match request.follow_terrain_m {
        Some(h) => Some(crate::engine::plan_to_fly::follow::follow_terrain(
            mission,
            options,
            h,
            request.follow_frames,
        )?),
        None => None,
    };
    let mission = followed.as_ref().unwrap_or(mission);
    // Over terrain: the mission flown over the ground (its terrain-frame legs followed).
    let over = crate::engine::missions::mission::over_terrain(mission, options)?;
    let mission = over.as_ref().map_or(mission, |(m, _)| m);
    // The air once: every candidate flies the vehicle in it (and finds it so when it decides
    // the air again from its own file).
    let (vehicle, air) = crate::engine::missions::day::mission_air(vehicle, mission, &options.air)?;
    let vehicle = &vehicle;
    let request = &FlyPlanRequest {
        options: MissionOptions {
            air: crate::engine::conditions::air::AirInput::of_density(air.air_density_kg_m3),
            ..options.clone()
        },
        ..request.clone()
    };
    let options = &request.options;
    // Over terrain, a route that passes too close to the ground has no plan: no cut or speed
    // changes the path (the return's height is `--rtl-altitude-m`).
    if options.terrain.is_some() {
        too_close_to_the_ground(vehicle, mission, options)?;
    }
    let (wind, _) = mission_wind(options, mission, vehicle)?;
    let scenarios = plan_scenarios(mission, request)?;
    let request = &FlyPlanRequest {
        scenarios: Some(scenarios.clone()),
        ..request.clone()
    };
    // The mission as given is planned while its surveys are turned (two threads).
    let (planned, turned) = std::thread::scope(|scope| {
        let planned = scope.spawn(|| plan_for(vehicle, mission, request, &wind, None));
        let turned = match request.keep_angle {
            true => Ok((None, Vec::new())),
            false => turned_to_wind(
                mission,
                &wind,
                &|m| energy_wh(vehicle, m, request, &wind),
                &request.bounds,
            ),
        };
        let planned = planned.join().unwrap_or_else(|_| {
            Err(Error::NoPlan {
                reason: "the plan's flight failed".into(),
            })
        });
        (planned, turned)
    });
    let (best, given) = planned?;
    let turned = turned?;
    // The surveys turned to the wind, when that needs fewer batteries or less energy.
    let (turned, mut kept) = turned;
    let (best, angles, turned) = match turned {
        Some((turned, angles)) => match plan_for(vehicle, &turned, request, &wind, None) {
            Ok((t, _))
                if (t.figures.batteries, t.figures.energy_wh)
                    < (best.figures.batteries, best.figures.energy_wh) =>
            {
                (t, angles, Some(turned))
            }
            // The turned survey saves energy flown whole, but not once cut into sorties.
            planned => {
                kept.extend(
                    angles
                        .iter()
                        .map(|a| turn_not_kept(a, &best, planned.as_ref().ok())),
                );
                (best, Vec::new(), None)
            }
        },
        None => (best, Vec::new(), None),
    };
    // The best way of flying it, cut again at the confidence with its margins balanced (module
    // step 4): the same candidate of the same mission, each sortie judged in the day's scenarios.
    // Cut for the forecast alone (0.5), the sorties are the nominal phase's: their bands only.
    let chosen = turned.as_ref().unwrap_or(mission);
    let best = match request.confidence.confidence > 0.5 {
        true => plan_for(vehicle, chosen, request, &wind, Some(best.candidate.kind))?.0,
        false => with_bands(vehicle, chosen, request, &wind, best)?,
    };
    let as_given = match given {
        Some(figures) => Some(figures),
        None => as_given_figures(vehicle, mission, options)?,
    };
    let mut plan = answer(mission, &best, as_given)?;
    plan.air = air;
    plan.confidence = request.confidence.confidence;
    plan.scenarios = PlanScenarios {
        samples: scenarios.samples,
        seed: scenarios.seed,
        spreads: scenarios.spreads(),
    };
    plan.changes.angles = angles;
    plan.changes.angles_kept = kept;
    if !request.keep_angle {
        plan.notes = unturnable(mission);
    }
    plan.notes.extend(loiters_assumed(mission));
    finite(plan, "plan", || {
        format!(
            "plan of mission {} with {}",
            mission.origin(),
            vehicle.name()
        )
    })
}

/// The scenarios of `request` around the forecast the mission flies in (its options' wind, else
/// the mission's, else still air; none drawn around a gridded field unless asked).
///
/// # Errors
/// A confidence outside 0.5 to 0.999; invalid scenario options.
fn plan_scenarios(mission: &Mission, request: &FlyPlanRequest) -> Result<ScenarioOptions, Error> {
    let c = &request.confidence;
    if !(0.5..=0.999).contains(&c.confidence) {
        return Err(Error::InvalidInput {
            name: "confidence",
            value: c.confidence,
            unit: "",
            expected: "a share of the scenarios from 0.5 (the nominal cut) to 0.999",
        });
    }
    let options = &request.options;
    let forecast_mps = match options.wind_field {
        Some(_) => None,
        None => Some(
            options
                .wind
                .as_ref()
                .or(mission.spec().wind.as_ref())
                .map_or(0.0, |w| w.speed_mps),
        ),
    };
    let sc = c.scenarios(forecast_mps, &request.bounds);
    sc.check()?;
    Ok(sc)
}

/// Why the survey turn `a` is not kept: the plan of the turned mission (`planned`, when it has
/// one) needs more packs or energy than `best`'s.
fn turn_not_kept(
    a: &AngleChange,
    best: &Flown,
    planned: Option<&(Flown, Option<PlanFigures>)>,
) -> AngleKept {
    let b = &best.figures;
    let why =
        match planned {
            Some((t, _)) => format!(
            "turned to {:.1}\u{b0} it saves energy flown whole, but cut into sorties it takes {} \
             packs and {:.1} Wh against {} and {:.1} Wh at {:.1}\u{b0}",
            a.to_deg, t.figures.batteries, t.figures.energy_wh, b.batteries, b.energy_wh, a.from_deg
        ),
            None => format!(
            "turned to {:.1}\u{b0} it saves energy flown whole, but cannot be cut into sorties \
             that keep the reserve",
            a.to_deg
        ),
        };
    AngleKept {
        item: a.item,
        angle_deg: a.from_deg,
        tried_deg: Some(a.to_deg),
        why,
    }
}

/// What the plan assumed of the unlimited loiters (the reader's words for each).
fn loiters_assumed(mission: &Mission) -> Vec<String> {
    mission
        .route()
        .warnings
        .iter()
        .filter(|w| w.contains("LOITER_UNLIM: flown as a loiter of"))
        .cloned()
        .collect()
}

/// The best candidate of `mission` (module steps 2-4) and the figures of the mission as given,
/// flown from its files, when it has them.
fn plan_for(
    vehicle: &Vehicle,
    mission: &Mission,
    request: &FlyPlanRequest,
    wind: &Wind,
    sure: Option<usize>,
) -> Result<(Flown, Option<PlanFigures>), Error> {
    let options = &request.options;
    let aircraft = vehicle.aircraft()?;
    let battery = vehicle.battery(options.battery.as_deref())?;
    let mut prepared = prepare(vehicle, mission, options, (aircraft, &battery, wind))?;
    // The take-off payload the request gives is the candidates' own (each is compiled again).
    if let Some(payload_kg) = options.payload_kg {
        prepared.spec.payload_kg = payload_kg;
    }
    let mut candidates = candidates((vehicle, mission), &prepared, wind, request)?;
    if let Some(kind) = sure {
        candidates.retain(|c| c.kind == kind);
    }
    let check = day_scenarios((vehicle, mission), request, &prepared)?;
    let fly_out = FlyOut::of(vehicle, &prepared, request, wind)?;
    let terrain = match &options.terrain {
        Some(dir) => Some(aloft_terrain::Terrain::open(dir)?),
        None => None,
    };
    let cx = Context {
        vehicle,
        mission,
        options,
        prepared: &prepared,
        bounds: &request.bounds,
        check: sure.map(|_| &check),
        fly_out: fly_out.as_ref(),
        terrain: terrain.as_ref(),
    };
    best_candidate(&cx, candidates)
}

/// The day's scenarios of `request` that the sorties of `mission` (as `prepared`) are judged in.
///
/// # Errors
/// Invalid scenario options; wind spreads with a gridded wind field.
fn day_scenarios<'a>(
    (vehicle, mission): (&Vehicle, &Mission),
    request: &FlyPlanRequest,
    prepared: &Prepared<'a>,
) -> Result<SortieScenarios<'a>, Error> {
    let scenarios = request
        .scenarios
        .clone()
        .unwrap_or_else(|| request.confidence.scenarios(Some(0.0), &request.bounds));
    SortieScenarios::new(
        (vehicle, mission, &request.options),
        &prepared.flight,
        &scenarios,
        request.confidence.confidence,
    )
}

/// `flown`'s sorties (of `mission`), each with its landing band in the day's scenarios.
///
/// # Errors
/// As [`plan_for`].
fn with_bands(
    vehicle: &Vehicle,
    mission: &Mission,
    request: &FlyPlanRequest,
    wind: &Wind,
    mut flown: Flown,
) -> Result<Flown, Error> {
    let options = &request.options;
    let aircraft = vehicle.aircraft()?;
    let battery = vehicle.battery(options.battery.as_deref())?;
    let prepared = prepare(vehicle, mission, options, (aircraft, &battery, wind))?;
    let check = day_scenarios((vehicle, mission), request, &prepared)?;
    for plan in &mut flown.plans {
        let band = check
            .band(&plan.spec)
            .map_err(|reason| Error::NoPlan { reason })?;
        plan.band = Some(band);
    }
    Ok(flown)
}

/// The mission as given: its batteries and the energy and time of its sorties (or its one
/// flight).
fn as_given_figures(
    vehicle: &Vehicle,
    mission: &Mission,
    options: &MissionOptions,
) -> Result<Option<PlanFigures>, Error> {
    let plan = plan_mission(vehicle, mission, options)?;
    let summary = plan.summary();
    let Some(batteries) = summary.batteries_required else {
        return Ok(None);
    };
    let (energy_wh, duration_s) = match summary.sorties.is_empty() {
        true => (summary.energy_wh, summary.duration_s),
        false => summary
            .sorties
            .iter()
            .fold((0.0, 0.0), |(e, t), s| (e + s.energy_wh, t + s.duration_s)),
    };
    Ok(Some(PlanFigures {
        batteries,
        energy_wh,
        duration_s,
    }))
}

/// A way of flying the mission: its spec, how it is cut and the speeds changed; `as_given` for
/// the mission as given split at whole items.
struct Candidate {
    /// Which of [`candidates`] it is (its place in their order).
    kind: usize,
    spec: MissionSpec,
    split: SplitOptions,
    speeds: Vec<SpeedChange>,
    as_given: bool,
}

/// The candidates of module step 4.
fn candidates(
    (vehicle, mission): (&Vehicle, &Mission),
    prepared: &Prepared<'_>,
    wind: &Wind,
    request: &FlyPlanRequest,
) -> Result<Vec<Candidate>, Error> {
    let inside = SplitOptions {
        inside_legs: true,
        overlap_m: request.overlap_m,
    };
    let mut out = vec![
        Candidate {
            kind: 0,
            spec: prepared.spec.clone(),
            split: inside,
            speeds: Vec::new(),
            as_given: false,
        },
        Candidate {
            kind: 1,
            spec: prepared.spec.clone(),
            split: SplitOptions::default(),
            speeds: Vec::new(),
            as_given: true,
        },
    ];
    if request.speeds != SpeedChoice::Keep {
        let (spec, speeds) = speeds_for_wind((vehicle, mission), prepared, wind, request)?;
        if !speeds.is_empty() {
            out.push(Candidate {
                kind: 2,
                spec,
                split: inside,
                speeds,
                as_given: false,
            });
        }
    }
    Ok(out)
}

/// The spec with its legs at the wind's speeds (module step 2), and the legs changed.
pub(in crate::engine) fn speeds_for_wind(
    (vehicle, mission): (&Vehicle, &Mission),
    prepared: &Prepared<'_>,
    wind: &Wind,
    request: &FlyPlanRequest,
) -> Result<(MissionSpec, Vec<SpeedChange>), Error> {
    let SpeedLimits {
        powered,
        max_mps,
        operators_mps,
    } = speed_limits(vehicle, prepared, request)?;
    let mut spec = prepared.spec.clone();
    let planning_mps = spec.default_speed_mps;
    let ends = segment_ends_m(&prepared.compiled, spec.segments.len());
    let triggers = camera_triggers_m(mission);
    let interval_s = camera_interval_s(mission, request);
    let mut changes = Vec::new();
    for (i, segment) in spec.segments.iter_mut().enumerate() {
        let SegmentSpec::Leg {
            ground_speed_mps,
            item,
            ..
        } = segment
        else {
            continue;
        };
        if request.speeds == SpeedChoice::Wind && ground_speed_mps.is_some() {
            continue;
        }
        let start = if i == 0 {
            prepared.compiled.home_m()
        } else {
            ends[i - 1]
        };
        // A leg flown with the camera triggering every D m: at most D per camera interval (the
        // operator's survey legs may go that fast); any other at most the operator's fastest.
        let camera_mps = triggers
            .get(i)
            .filter(|d| **d > 0.0)
            .map(|d| d / interval_s);
        let cap_mps = camera_mps.or(operators_mps);
        let max_mps = match (max_mps, cap_mps) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let Some(v) = leg_speed_mps(&powered, wind, (start, ends[i]), max_mps) else {
            continue;
        };
        // A leg that flies that speed already (its own, or the planning speed) is not changed.
        if ground_speed_mps
            .or(planning_mps)
            .is_some_and(|g| (g - v).abs() < 0.05)
        {
            continue;
        }
        changes.push(SpeedChange {
            item: *item,
            segment: i + 1,
            from_mps: *ground_speed_mps,
            to_mps: v,
        });
        *ground_speed_mps = Some(v);
    }
    Ok((spec, changes))
}

/// What bounds the speeds aloft gives: the vehicle at its take-off mass, the highest speed
/// anywhere (`--max-speed`, the tilt limit of a planner file's speeds), and the operator's
/// fastest planned speed where that bounds them too.
pub(in crate::engine) struct SpeedLimits<'a> {
    /// The vehicle at its take-off mass.
    pub(in crate::engine) powered: aloft_planner::Powered<'a>,
    /// At most anywhere, m/s.
    pub(in crate::engine) max_mps: Option<f64>,
    /// At most, for legs that are not a survey's camera legs (and below the RTL altitude for
    /// aloft's own), m/s: the operator's fastest planned speed with `--speeds wind` and no
    /// `--max-speed`.
    pub(in crate::engine) operators_mps: Option<f64>,
}

/// The [`SpeedLimits`] of `prepared` for `request`.
///
/// # Errors
/// A take-off mass or a model the vehicle refuses.
pub(in crate::engine) fn speed_limits<'a>(
    vehicle: &Vehicle,
    prepared: &Prepared<'a>,
    request: &FlyPlanRequest,
) -> Result<SpeedLimits<'a>, Error> {
    let flight = &prepared.flight;
    let payload = prepared
        .compiled
        .payloads_kg()
        .first()
        .copied()
        .unwrap_or(0.0);
    let mass = vehicle.takeoff_mass_with(flight.pack, payload)?;
    let powered = flight
        .aircraft
        .at_mass(mass.total_kg, request.options.aoa)?;
    // A planner file's speeds are flown at most at what the vehicle holds within its tilt limit
    // in still air (as `aloft mission` flies them): a faster choice would be written and not flown.
    let tilt_mps = prepared
        .spec
        .clamp_speeds
        .then(|| flight.aircraft.tilt_limited_speed_mps(mass.total_kg));
    let max_mps = match (request.max_speed_mps, tilt_mps) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    };
    // No leg faster than the operator planned any (module step 2) unless asked.
    let operators_mps = match (request.speeds, request.max_speed_mps) {
        (SpeedChoice::Wind, None) => highest_planned_mps(&prepared.spec),
        _ => None,
    };
    Ok(SpeedLimits {
        powered,
        max_mps,
        operators_mps,
    })
}

/// A resumed sortie's fly-out from home to where it resumes, at the ground speed of least energy
/// per metre along its course in the wind at its height (within the vehicle's speed and
/// envelope, `--max-speed`), no faster than the operator's planned speeds unless it flies at or
/// above the RTL altitude (module step 3).
pub(in crate::engine) struct FlyOut<'a> {
    limits: SpeedLimits<'a>,
    wind: &'a Wind,
    home_m: [f64; 3],
    rtl_altitude_m: Option<f64>,
}

impl<'a> FlyOut<'a> {
    /// The fly-outs of `prepared` for `request` in `wind`; `None` with `--speeds keep`.
    ///
    /// # Errors
    /// As [`speed_limits`].
    pub(in crate::engine) fn of(
        vehicle: &Vehicle,
        prepared: &Prepared<'a>,
        request: &FlyPlanRequest,
        wind: &'a Wind,
    ) -> Result<Option<Self>, Error> {
        if request.speeds == SpeedChoice::Keep {
            return Ok(None);
        }
        Ok(Some(Self {
            limits: speed_limits(vehicle, prepared, request)?,
            wind,
            home_m: prepared.compiled.home_m(),
            rtl_altitude_m: prepared.spec.rtl_altitude_m,
        }))
    }
}

impl FlyOutSpeed for FlyOut<'_> {
    fn speed_mps(&self, point_m: [f64; 3]) -> Option<f64> {
        let height_m = point_m[2] - self.home_m[2];
        let high = self.rtl_altitude_m.is_some_and(|r| height_m >= r - 1e-6);
        let cap = match (high, self.limits.max_mps, self.limits.operators_mps) {
            (false, Some(a), Some(b)) => Some(a.min(b)),
            (false, a, b) => a.or(b),
            (true, a, _) => a,
        };
        let from = [self.home_m[0], self.home_m[1], point_m[2]];
        leg_speed_mps(&self.limits.powered, self.wind, (from, point_m), cap)
    }
}

/// The highest ground speed the operator planned any leg of `spec` at, m/s: each leg's and
/// orbit's own speed (a DO_CHANGE_SPEED in force), else the planning speed (a `.plan`'s
/// `hoverSpeed`, a `.waypoints` file's autopilot default, `--speed`); `None` when none is known.
fn highest_planned_mps(spec: &MissionSpec) -> Option<f64> {
    spec.segments
        .iter()
        .filter_map(|s| match *s {
            SegmentSpec::Leg {
                ground_speed_mps, ..
            }
            | SegmentSpec::Orbit {
                ground_speed_mps, ..
            } => ground_speed_mps.or(spec.default_speed_mps),
            _ => None,
        })
        .filter(|v| v.is_finite() && *v > 0.0)
        .reduce(f64::max)
}

/// The camera trigger distance in force on each segment of a planner file's mission, m (0: the
/// camera off; empty for aloft's own formats): the last DO_SET_CAM_TRIGG_DIST (206) flown before
/// the item that made the segment.
fn camera_triggers_m(mission: &Mission) -> Vec<f64> {
    let Some(imported) = mission.kept() else {
        return Vec::new();
    };
    let mut out = vec![0.0; imported.spec.segments.len()];
    let mut in_force = 0.0;
    for f in &imported.flown {
        for s in f.segments.clone() {
            if let Some(slot) = out.get_mut(s) {
                *slot = in_force;
            }
        }
        let item = &imported.items[f.item];
        if item.command == 206 && item.params[0].is_finite() {
            in_force = item.params[0].max(0.0);
        }
    }
    out
}

/// The camera's shortest time between photos, s: the request's, else the longest
/// `CameraCalc.MinTriggerInterval` of a `.plan`'s surveys, else [`DEFAULT_CAMERA_INTERVAL_S`].
fn camera_interval_s(mission: &Mission, request: &FlyPlanRequest) -> f64 {
    let of_file = mission.kept().and_then(|k| {
        k.surveys
            .iter()
            .filter_map(|s| s.survey.as_ref().ok()?.params().min_trigger_interval_s)
            .filter(|t| *t > 0.0)
            .reduce(f64::max)
    });
    request
        .camera_interval_s
        .or(of_file)
        .unwrap_or(DEFAULT_CAMERA_INTERVAL_S)
}

/// The ground speed of least energy per metre along the leg from `a` to `b` in the wind at its
/// middle, at most the vehicle's speed and `max_mps`, rounded down to 0.1 m/s; `None` for a leg without a horizontal course
/// (shorter than 1 m) or without headway.
fn leg_speed_mps(
    powered: &aloft_planner::Powered<'_>,
    wind: &Wind,
    (a, b): ([f64; 3], [f64; 3]),
    max_mps: Option<f64>,
) -> Option<f64> {
    let (de, dn) = (b[0] - a[0], b[1] - a[1]);
    let length_m = de.hypot(dn);
    if length_m < 1.0 {
        return None;
    }
    let course = [de / length_m, dn / length_m];
    let middle = [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
    let w = wind.mean_at(middle)?;
    let best = best_range_within_limits(powered, course, [w[0], w[1]]).ok()?;
    // The vehicle's speed bounds its ground speed too (the planner holds a leg's ground speed at
    // it), whatever a tail wind would allow.
    let vehicle_mps = powered.aircraft().airframe().max_speed_mps();
    let v = best
        .ground_speed_mps
        .min(vehicle_mps)
        .min(max_mps.unwrap_or(f64::INFINITY));
    let rounded = (v * 10.0).floor() / 10.0;
    (rounded > 0.0).then_some(rounded)
}

/// A candidate cut into sorties, with its figures and its files' texts.
struct Flown {
    candidate: Candidate,
    plans: Vec<SortiePlan>,
    figures: PlanFigures,
    texts: Vec<String>,
}

/// What the candidates are flown for.
struct Context<'a> {
    vehicle: &'a Vehicle,
    mission: &'a Mission,
    options: &'a MissionOptions,
    prepared: &'a Prepared<'a>,
    bounds: &'a WorkBounds,
    /// The day's scenarios each sortie is checked in (none: the nominal cut, to choose the
    /// candidate).
    check: Option<&'a SortieScenarios<'a>>,
    /// The speed of a resumed sortie's fly-out.
    fly_out: Option<&'a FlyOut<'a>>,
    /// The request's terrain tiles, open once for every sortie tried.
    terrain: Option<&'a aloft_terrain::Terrain>,
}

/// The best candidate (module step 4), and the figures of the mission as given split at whole
/// items, flown from its files, when it has them.
///
/// # Errors
/// [`Error::NoPlan`] when none can be cut into sorties that keep the reserve.
fn best_candidate(
    cx: &Context<'_>,
    candidates: Vec<Candidate>,
) -> Result<(Flown, Option<PlanFigures>), Error> {
    let mut best: Option<Flown> = None;
    let mut given: Option<PlanFigures> = None;
    // Why the first candidate (the route cut inside legs, as given) has no plan.
    let mut why: Option<String> = None;
    if cx.bounds.cancelled() {
        return Err(Error::Cancelled);
    }
    // The candidates fly at once, one thread each (a handful); the answer is taken in their
    // order, so it does not depend on which finishes first.
    let flown: Vec<Result<Flown, String>> = std::thread::scope(|scope| {
        let running: Vec<_> = candidates
            .into_iter()
            .map(|c| scope.spawn(move || fly_candidate(cx, c)))
            .collect();
        running
            .into_iter()
            .map(|r| {
                r.join()
                    .unwrap_or_else(|_| Err("a candidate's flight failed".to_string()))
            })
            .collect()
    });
    if cx.bounds.cancelled() {
        return Err(Error::Cancelled);
    }
    for result in flown {
        match result {
            Ok(flown) => {
                if flown.candidate.as_given {
                    given = Some(flown.figures);
                }
                let better = best.as_ref().is_none_or(|b| {
                    (flown.figures.batteries, flown.figures.energy_wh)
                        < (b.figures.batteries, b.figures.energy_wh)
                });
                if better {
                    best = Some(flown);
                }
            }
            Err(e) => {
                why.get_or_insert(e);
            }
        }
    }
    let best = best.ok_or_else(|| Error::NoPlan {
        reason: why.unwrap_or_default(),
    })?;
    Ok((best, given))
}

/// A candidate cut into sorties, each flown from its own file's mission (the file aloft writes,
/// read back as `aloft mission` reads it), and the files' texts.
fn fly_candidate(cx: &Context<'_>, candidate: Candidate) -> Result<Flown, String> {
    let flight = &cx.prepared.flight;
    let compiled = flight
        .compile(&candidate.spec, None)
        .map_err(|e| e.to_string())?;
    let route = Route::of(&candidate.spec, &compiled)?;
    let maker = Maker::of(cx, &route, &candidate);
    let mut plans = balanced_sortie_plans(cx, &route, candidate.split, maker.as_dyn())?;
    let n = plans.len();
    let mut texts = Vec::with_capacity(n);
    for (k, plan) in plans.iter_mut().enumerate() {
        plan.spec = maker.as_dyn().sortie(plan.start, plan.end)?;
        plan.report = flight
            .trial(&plan.spec, None)
            .map_err(|e| format!("a sortie cannot be flown: {e}"))?;
        if !plan.report.feasible {
            return Err(format!(
                "sortie {} of {n} misses the reserve once written",
                k + 1
            ));
        }
        within_fence(cx, plan, (k + 1, n))?;
        texts.push(maker.text(cx.mission, plan, (k + 1, n))?);
    }
    Ok(Flown {
        figures: figures(&plans),
        candidate,
        plans,
        texts,
    })
}

/// The sorties of `route` cut at the plan's confidence (module step 3), their margins balanced:
/// with the fewest packs that reach the confidence, the slack the last sortie would land with is
/// shared out, every sortie but the last cut again with its margin raised by the same share of
/// the capacity (a little under the last one's slack over the sorties' count) and checked: up
/// to [`BALANCE_PASSES`] cuts while the last keeps more than [`BALANCE_FROM`], the share halved
/// after a cut that needs more packs or does not hold, the unbalanced cut kept when none does.
fn balanced_sortie_plans(
    cx: &Context<'_>,
    route: &Route<'_>,
    split: SplitOptions,
    maker: &dyn SortieMaker,
) -> Result<Vec<SortiePlan>, String> {
    let flight = &cx.prepared.flight;
    let Some(check) = cx.check else {
        return confident_sortie_plans(flight, route, split, maker, (None, Margins::Nominal));
    };
    let check: &dyn SortieCheck = check;
    let mut best = confident_sortie_plans(
        flight,
        route,
        split,
        maker,
        (Some(check), Margins::Searched),
    )?;
    let n = best.len();
    if n < 2 || check.confidence() <= 0.5 {
        return Ok(best);
    }
    let searched: Vec<f64> = best.iter().map(|p| p.margin).collect();
    // The share added to every margin so far, and the next step of it.
    let mut extra = 0.0;
    let mut step = BALANCE_SHARE * last_slack(&best) / n as f64;
    for _ in 0..BALANCE_PASSES {
        if step <= BALANCE_FROM / n as f64 || cx.bounds.cancelled() {
            break;
        }
        let mut margins: Vec<f64> = searched.iter().map(|m| m + extra + step).collect();
        margins[n - 1] = searched[n - 1];
        let given = Margins::Given(&margins);
        match confident_sortie_plans(flight, route, split, maker, (Some(check), given)) {
            Ok(plans) => {
                extra += step;
                best = plans;
                step = BALANCE_SHARE * last_slack(&best) / n as f64;
            }
            Err(_) => step *= 0.5,
        }
    }
    Ok(best)
}

/// What the last of `plans` lands with beyond what the confidence asks, a share of the usable
/// capacity.
fn last_slack(plans: &[SortiePlan]) -> f64 {
    plans
        .last()
        .and_then(|p| p.band.as_ref())
        .map_or(0.0, |b| b.margin_reached)
}

/// How many times the sorties are cut again to share the margins out.
const BALANCE_PASSES: usize = 2;

/// The last sortie's slack over the confidence below which the sorties are not balanced, a
/// fraction of the capacity.
const BALANCE_FROM: f64 = 0.02;

/// The share of the even split of the last sortie's slack each sortie is cut to keep: a little
/// under all of it, since cutting a sortie earlier moves its fly-out's and way home's energy,
/// not only the route's, onto the next.
const BALANCE_SHARE: f64 = 0.8;

/// Whether sortie `k` of `n` (its file read back, `plan.spec`) stays inside the operator's
/// inclusion fences and out of the exclusion ones the whole way (take-off, fly-out, route, way
/// home), horizontally ([`aloft_missions::LocalFence`]; an orbit as its chords).
///
/// # Errors
/// The sortie, the fence, the item (or the segment aloft added) and where it first breaches.
fn within_fence(cx: &Context<'_>, plan: &SortiePlan, (k, n): (usize, usize)) -> Result<(), String> {
    let Some(airspace) = cx
        .mission
        .kept()
        .and_then(|i| i.plan.as_ref())
        .map(|p| &p.airspace)
    else {
        return Ok(());
    };
    let home = &plan.spec.home;
    let (Some(latitude_deg), Some(longitude_deg)) = (home.latitude_deg, home.longitude_deg) else {
        return Ok(());
    };
    let frame = LocalFrame::new(latitude_deg, longitude_deg);
    let fence = airspace.local(&frame);
    if fence.is_empty() {
        return Ok(());
    }
    let compiled = cx
        .prepared
        .flight
        .compile(&plan.spec, None)
        .map_err(|e| e.to_string())?;
    let origin = compiled.home_m();
    let local = |p: [f64; 3]| [p[0] - origin[0], p[1] - origin[1]];
    for (segment, points) in segment_paths(&compiled) {
        let breach = points
            .windows(2)
            .find_map(|w| fence.first_breach(local(w[0]), local(w[1])));
        let Some(breach) = breach else {
            continue;
        };
        let seg = &plan.spec.segments[segment];
        let what = match seg.item() {
            Some(i) => format!("item {i} ({})", seg.kind()),
            None => format!("segment {} ({}, aloft's own)", segment + 1, seg.kind()),
        };
        let [la, lo] = frame.to_lat_lon_deg(breach.at_m[0], breach.at_m[1]);
        let verb = match breach.leaves {
            true => "leaves",
            false => "enters",
        };
        return Err(format!(
            "sortie {k} of {n} {verb} the fence's {} at {what}, at {la:.6}, {lo:.6}",
            breach.fence
        ));
    }
    Ok(())
}

/// Who makes the sorties' missions and files: aloft's own segments (TOML, JSON) or the items of a
/// planner file.
enum Maker<'a> {
    Spec(SpecSorties<'a, 'a>),
    Planner(PlannerSorties<'a>),
}

impl<'a> Maker<'a> {
    fn of(cx: &'a Context<'a>, route: &'a Route<'a>, candidate: &'a Candidate) -> Self {
        match cx.mission.kept() {
            Some(kept) => Maker::Planner(PlannerSorties {
                route,
                kept,
                spec: &candidate.spec,
                speeds_changed: !candidate.speeds.is_empty(),
                vehicle: cx.vehicle,
                options: cx.options,
                flight: &cx.prepared.flight,
                read: cx.mission.read_options(),
                fly_out: cx.fly_out.map(|f| f as &dyn FlyOutSpeed),
                terrain: cx.terrain,
            }),
            None => Maker::Spec(SpecSorties {
                route,
                flight: &cx.prepared.flight,
                fly_out: cx.fly_out.map(|f| f as &dyn FlyOutSpeed),
            }),
        }
    }

    fn as_dyn(&self) -> &dyn SortieMaker {
        match self {
            Maker::Spec(m) => m,
            Maker::Planner(m) => m,
        }
    }

    /// The file of sortie `k` of `n`.
    fn text(
        &self,
        mission: &Mission,
        plan: &SortiePlan,
        (k, n): (usize, usize),
    ) -> Result<String, String> {
        match self {
            Maker::Spec(_) => sortie_text(mission, plan, k, n).map_err(|e| e.to_string()),
            Maker::Planner(m) => m.text(plan.start, plan.end),
        }
    }
}

/// The figures of a set of sorties.
fn figures(plans: &[SortiePlan]) -> PlanFigures {
    PlanFigures {
        batteries: u32::try_from(plans.len()).unwrap_or(u32::MAX),
        energy_wh: plans.iter().map(|p| p.report.energy_wh).sum(),
        duration_s: plans.iter().map(|p| p.report.duration_s).sum(),
    }
}

/// The answer of the best candidate: its sorties named as files in the input's format.
fn answer(
    mission: &Mission,
    best: &Flown,
    as_given: Option<PlanFigures>,
) -> Result<FlyPlan, Error> {
    let (stem, extension) = file_stem_and_extension(mission)?;
    let n = best.plans.len();
    let mut files = Vec::with_capacity(n);
    let mut texts = Vec::with_capacity(n);
    let mut sorties = Vec::with_capacity(n);
    for (k, plan) in best.plans.iter().enumerate() {
        let file = format!("{stem}-{}-of-{n}.{extension}", k + 1);
        sorties.push(sortie_answer(&file, plan, &best.candidate.spec));
        files.push(file);
    }
    texts.extend(best.texts.iter().cloned());
    Ok(FlyPlan {
        files,
        batteries: best.figures.batteries,
        energy_wh: best.figures.energy_wh,
        duration_s: best.figures.duration_s,
        confidence: DEFAULT_CONFIDENCE,
        scenarios: PlanScenarios {
            samples: 0,
            seed: 0,
            spreads: ScenarioOptions::default().spreads(),
        },
        air: crate::engine::conditions::air::Air::sea_level(),
        sorties,
        as_given,
        changes: PlanChanges {
            speeds: best.candidate.speeds.clone(),
            angles: Vec::new(),
            angles_kept: Vec::new(),
            cut_inside_legs: best.candidate.split.inside_legs
                && best
                    .plans
                    .iter()
                    .any(|p| p.end.is_some_and(|c| c.fraction < 1.0)),
        },
        notes: Vec::new(),
        texts,
    })
}

/// One sortie's answer.
fn sortie_answer(file: &str, plan: &SortiePlan, spec: &MissionSpec) -> FlySortie {
    let items = || {
        spec.segments[plan.route.clone()]
            .iter()
            .filter_map(SegmentSpec::item)
    };
    FlySortie {
        file: file.to_string(),
        first_item: items().next(),
        last_item: items().next_back(),
        ends_inside_leg_fraction: plan.end.filter(|c| c.fraction < 1.0).map(|c| c.fraction),
        energy_wh: plan.report.energy_wh,
        duration_s: plan.report.duration_s,
        end_soc: plan.report.end_soc,
        point_of_no_return_s: plan.report.point_of_no_return.map(|p| p.time_s),
        landing_soc: plan.band.as_ref().and_then(|b| b.landing_soc),
        p_reserve: plan.band.as_ref().map(|b| b.p_reserve),
    }
}

/// The name a plan's files are given and their extension: the input's file name, made safe
/// ([`safe_stem`]: never a path, never the mission's own `name`), `mission` when nothing is left
/// of it; the built-in demo's is its fixture's, `demo-survey`.
fn file_stem_and_extension(mission: &Mission) -> Result<(String, &'static str), Error> {
    let extension = match mission.route().source_format {
        SourceFormat::AloftToml => "toml",
        SourceFormat::AloftJson => "json",
        SourceFormat::QgcPlan => "plan",
        SourceFormat::QgcWpl | SourceFormat::MavlinkItems => "waypoints",
    };
    let stem = if mission.origin() == DEMO_ORIGIN {
        DEMO_FILE_STEM.to_string()
    } else {
        safe_stem(Path::new(mission.origin())).unwrap_or_else(|| "mission".to_string())
    };
    Ok((stem, extension))
}

/// The text of sortie `k` of `n`: its mission in the input's format, named so.
fn sortie_text(mission: &Mission, plan: &SortiePlan, k: usize, n: usize) -> Result<String, Error> {
    let mut spec = plan.spec.clone();
    spec.name = format!("{} ({k} of {n})", mission.display_name());
    let text = match mission.route().source_format {
        SourceFormat::AloftJson => serde_json::to_string_pretty(&spec).map_err(|e| e.to_string()),
        _ => toml::to_string(&spec).map_err(|e| e.to_string()),
    };
    text.map_err(|message| Error::OptionsFormat {
        what: "plan file",
        message,
    })
}

impl FlyPlan {
    /// Write the files into `dir` (created if missing) as one set, all or nothing
    /// ([`OutputSet`]): each to an exclusive temporary file with a random name there, then all
    /// renamed into place; an existing file is kept unless `force` (which replaces a regular file
    /// or a link itself, never a device or a FIFO); an error (or an interrupted program) at any
    /// file leaves none of the set. The answer's `files` become their paths.
    ///
    /// # Errors
    /// [`Error::Io`] naming the folder; [`Error::Output`] naming the file.
    pub fn write(&mut self, dir: &Path, force: bool) -> Result<(), Error> {
        std::fs::create_dir_all(dir).map_err(|source| Error::Io {
            origin: format!("cannot create {}", shown_path(dir)),
            source,
        })?;
        let paths: Vec<PathBuf> = self.files.iter().map(|f| dir.join(f)).collect();
        let mut set = OutputSet::new();
        for (path, text) in paths.iter().zip(&self.texts) {
            set.add(path, text.as_bytes(), force)?;
        }
        set.commit()?;
        self.files = paths.iter().map(|p| p.display().to_string()).collect();
        for (sortie, file) in self.sorties.iter_mut().zip(&self.files) {
            sortie.file.clone_from(file);
        }
        Ok(())
    }
}

/// The energy of `mission` flown whole with the legs' speeds for the wind, on a pack as large as
/// the route needs, Wh; `None` when it cannot be flown.
fn energy_wh(
    vehicle: &Vehicle,
    mission: &Mission,
    request: &FlyPlanRequest,
    wind: &Wind,
) -> Option<f64> {
    let options = &request.options;
    let aircraft = vehicle.aircraft().ok()?;
    let battery = vehicle.battery(options.battery.as_deref()).ok()?;
    let mut prepared = prepare(vehicle, mission, options, (aircraft, &battery, wind)).ok()?;
    if let Some(payload_kg) = options.payload_kg {
        prepared.spec.payload_kg = payload_kg;
    }
    let spec = match request.speeds {
        SpeedChoice::Keep => prepared.spec.clone(),
        _ => {
            speeds_for_wind((vehicle, mission), &prepared, wind, request)
                .ok()?
                .0
        }
    };
    // The whole route, however many packs it takes: on one pack a route beyond it stops where
    // the pack is empty, and every angle would cost that pack.
    let whole = battery.with_capacity_factor(WHOLE_ROUTE_PACKS).ok()?;
    let flight = crate::engine::missions::flight::Flight {
        pack: &whole,
        options: aloft_planner::PlanOptions {
            point_of_no_return: false,
            ..prepared.flight.options
        },
        ..prepared
            .flight
            .with_reserve(prepared.flight.options.reserve_fraction)
    };
    let report = flight.trial(&spec, None).ok()?;
    Some(report.energy_wh)
}

/// The packs' worth of charge a survey's angle is judged with ([`energy_wh`]): the most sorties
/// a route is cut into.
const WHOLE_ROUTE_PACKS: f64 = crate::engine::missions::sorties::MAX_SORTIES as f64;
