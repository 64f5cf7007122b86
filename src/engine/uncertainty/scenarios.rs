//! How sure is the answer: Monte-Carlo scenarios of a mission ([`plan_scenarios`]) and of the
//! endurance queries ([`endurance_scenarios`]).
//!
//! A request's answer is computed as if the wind, the payload, the pack and the model were exact.
//! Scenarios draw each of them from a distribution around the request's value, fly the same
//! route once per scenario, and report how often the mission lands with the reserve
//! (`p_feasible`) and percentiles of what it costs.
//!
//! # What is drawn (scenario `i`, standard normal draws `z`)
//!
//! | source | draw | option | default |
//! |---|---|---|---|
//! | wind speed | `max(0, S + sd z1)`, held at most 100 m/s (the planner's limit) | [`ScenarioOptions::wind_speed_sd_mps`] | 0 |
//! | wind direction | `D + sd z2`, degrees | [`ScenarioOptions::wind_from_sd_deg`] | 0 |
//! | payload at take-off | `max(0, m + sd z3)` | [`ScenarioOptions::payload_sd_kg`] | 0 |
//! | pack capacity (health) | factor `max(0.01, 1 + sd z4 / 100)` on capacity and rated energy | [`ScenarioOptions::capacity_sd_percent`] | 0 |
//! | model error | factor `max(0.01, 1 + sd z5 / 100)` on the electrical power | [`ScenarioOptions::power_sd_percent`] | [`DEFAULT_POWER_SD_PERCENT`] |
//! | gusts (when the request has gusts) | a new gust seed per scenario | - | - |
//!
//! The wind is drawn around the steady wind the mission flies in (the options', else the mission
//! file's, else still air: speed 0 from north); its profile with height is kept. A gridded wind
//! field has no single speed and direction, so wind spreads with a field are refused. Only the
//! take-off payload is drawn; payload changes along the route keep their values. A value below
//! zero is set to zero ("clipped"), so the distribution keeps its normal shape above zero.
//!
//! The model error is one factor on the electrical power for the whole flight of a scenario (a
//! vehicle whose model is off by a few percent is off for the whole flight). For the four-term
//! model it is exactly the efficiency `eta / s` for every term (see
//! `aloft_power::Vehicle::with_power_scale`); for a propulsion chain, the summed supply and climb
//! power is scaled. Its default, 3 %, is aloft's own validation: whole-flight energy errors of
//! +2.1 to +4.7 % on the five KAIST validation flights (`aloft validate`, docs/validation.md
//! "Real flights"), +1.2 to +3.7 % when those flights are replayed from their trajectories, and
//! the M100 hover table's -2.6 to +2.2 % (docs/validation.md "Published figures").
//!
//! # Reproducible
//! Scenario `i` draws from its own counter-based stream (splitmix64 of the seed and `i`), so its
//! draws do not depend on the thread that flies it: the same seed gives the same answer whatever
//! [`ScenarioOptions::threads`]. With every spread zero and no gusts, every scenario is the
//! deterministic plan, bit for bit.
//!
//! # What is counted
//! Every scenario flies by the same rules as the plan: where its wind asks more than the
//! vehicle's envelope allows, it flies slower at the limit (and takes longer and costs more);
//! where it cannot make headway or hold its position at all, its flight ends there, infeasible.
//!
//! - `p_feasible`: scenarios that land with the reserve, over all scenarios. A scenario the
//!   vehicle cannot fly (the take-off mass beyond the airframe's limit, a path it cannot make
//!   headway along or hold its position on in that wind, a propulsion chain beyond its operating
//!   range) is infeasible, not an error, and is counted in `cannot_fly_scenarios`; inputs that are
//!   wrong whatever is drawn are still errors.
//! - Percentiles of `energy_wh`, `end_soc`, `duration_s` and of each segment's end state of
//!   charge: over the scenarios flown to the end of the route (feasible, or landing short of the
//!   reserve: `completed_scenarios`). A scenario that ends early (its pack empty or below its
//!   cut-off, or a path it cannot fly) has no such figures: its energy up to where it stopped is
//!   not the mission's, and counting it would pull the percentiles down. The state-of-charge fan
//!   ([`Uncertainty::soc_fan`]) is of every scenario: one that ends early keeps its last state of
//!   charge after its end, so the fan shows the packs that run out. Nearest rank: the `p`-th percentile of
//!   `n` values is the `ceil(p n / 100)`-th smallest, always a value some scenario gave.
//! - `point_of_no_return_s`: over all scenarios, a scenario without a point of no return (safe to
//!   turn back everywhere) counting as later than any time, a scenario that cannot be flown at
//!   all as a point of no return at take-off (0 s), and one that cannot fly on somewhere as one
//!   where it stops (if none came earlier). So `p5` is the time up to which 95 % of the
//!   scenarios can still turn back: the point of no return with 95 % confidence. A percentile
//!   that falls among the scenarios without one is omitted.

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

use aloft_planner::{
    Aircraft, Gusts, MissionReport, MissionSpec, NoSamples, Pack, PlannerError, Shortfall, Wind,
    WindSpec,
};

use crate::engine::basics::finite::finite;
use crate::engine::basics::step_meter::WorkBounds;
use crate::engine::missions::day::mission_wind;
use crate::engine::missions::flight::Flight;
use crate::engine::missions::flown::flown_spec;
use crate::engine::missions::loiter::resolve_loiter;
use crate::engine::missions::mission::{check_options, planner_options};
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_options::MissionOptions;
use crate::engine::missions::summary::reason;
use crate::engine::missions::summary::MissionSummary;
use crate::engine::performance::endurance::EnduranceOptions;
use crate::engine::uncertainty::scenario_stats::{time_band, TimeBand};
use crate::engine::uncertainty::scenario_stats::{FanHistogram, FanSink, Percentiles, SegmentBand};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

pub use crate::engine::uncertainty::scenario_stats::SocFan;

/// Most scenarios one request may draw.
pub const MAX_SCENARIOS: u32 = 100_000;

/// The default spread of the model error, percent of the electrical power (one standard
/// deviation): aloft's own whole-flight energy errors (see the module docs).
pub const DEFAULT_POWER_SD_PERCENT: f64 = 3.0;

/// Scenarios drawn when a request asks for scenarios without saying how many.
pub const DEFAULT_SCENARIOS: u32 = 1000;

/// Largest wind the planner takes, m/s: a drawn speed is held at it.
const MAX_WIND_MPS: f64 = 100.0;

/// How many scenarios to draw, from what seed, with which spreads (one standard deviation each),
/// on how many threads. JSON keys as the field names (the C ABI's `scenarios` object); every key
/// optional, unknown keys rejected.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ScenarioOptions {
    /// Scenarios to draw, 1 to [`MAX_SCENARIOS`] (default [`DEFAULT_SCENARIOS`]).
    pub samples: u32,
    /// Seed of the draws (default 1).
    pub seed: u64,
    /// Wind speed, m/s (0 to 50; default 0).
    pub wind_speed_sd_mps: f64,
    /// Wind direction, degrees (0 to 180; default 0).
    pub wind_from_sd_deg: f64,
    /// Payload at take-off, kg (0 to 1000; default 0).
    pub payload_sd_kg: f64,
    /// Pack capacity, percent of the rated capacity (0 to 50; default 0).
    pub capacity_sd_percent: f64,
    /// Electrical power (model error), percent (0 to 50; default [`DEFAULT_POWER_SD_PERCENT`]).
    pub power_sd_percent: f64,
    /// Threads to fly them on (0, the default: one per core). The answer does not depend on it.
    pub threads: usize,
    /// Also follow the state of charge of every scenario on a time grid for
    /// [`Uncertainty::soc_fan`] (a chart's bands; not in the JSON; default false).
    #[serde(skip)]
    pub soc_fan: bool,
    /// What the request may spend, and whether its caller still wants the answer (not in the
    /// JSON; default: no bound, never cancelled).
    #[serde(skip)]
    pub bounds: WorkBounds,
}

impl Default for ScenarioOptions {
    fn default() -> Self {
        Self {
            samples: DEFAULT_SCENARIOS,
            seed: 1,
            wind_speed_sd_mps: 0.0,
            wind_from_sd_deg: 0.0,
            payload_sd_kg: 0.0,
            capacity_sd_percent: 0.0,
            power_sd_percent: DEFAULT_POWER_SD_PERCENT,
            threads: 0,
            soc_fan: false,
            bounds: WorkBounds::default(),
        }
    }
}

/// The spreads a set of scenarios was drawn with (in the answer, keys as
/// [`ScenarioOptions`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Spreads {
    /// Wind speed, m/s.
    pub wind_speed_sd_mps: f64,
    /// Wind direction, deg.
    pub wind_from_sd_deg: f64,
    /// Payload, kg.
    pub payload_sd_kg: f64,
    /// Pack capacity, percent.
    pub capacity_sd_percent: f64,
    /// Electrical power, percent.
    pub power_sd_percent: f64,
}

impl ScenarioOptions {
    /// Check every value (the C ABI's JSON and the library's callers come here unchecked).
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the field: samples outside 1 to [`MAX_SCENARIOS`], a spread
    /// that is negative, not finite or beyond its limit, more than 1024 threads.
    pub fn check(&self) -> Result<(), Error> {
        if !(1..=MAX_SCENARIOS).contains(&self.samples) {
            return Err(Error::InvalidInput {
                name: "samples",
                value: f64::from(self.samples),
                unit: "",
                expected: "from 1 to 100000 scenarios",
            });
        }
        let spread = |name, value: f64, max: f64, unit, expected| {
            if value.is_finite() && (0.0..=max).contains(&value) {
                Ok(())
            } else {
                Err(Error::InvalidInput {
                    name,
                    value,
                    unit,
                    expected,
                })
            }
        };
        let s = self.spreads();
        spread(
            "wind_speed_sd_mps",
            s.wind_speed_sd_mps,
            50.0,
            "m/s",
            "a standard deviation from 0 to 50 m/s",
        )?;
        spread(
            "wind_from_sd_deg",
            s.wind_from_sd_deg,
            180.0,
            "deg",
            "a standard deviation from 0 to 180 deg",
        )?;
        spread(
            "payload_sd_kg",
            s.payload_sd_kg,
            1000.0,
            "kg",
            "a standard deviation from 0 to 1000 kg",
        )?;
        spread(
            "capacity_sd_percent",
            s.capacity_sd_percent,
            50.0,
            "%",
            "a standard deviation from 0 to 50 %",
        )?;
        spread(
            "power_sd_percent",
            s.power_sd_percent,
            50.0,
            "%",
            "a standard deviation from 0 to 50 %",
        )?;
        if self.threads > 1024 {
            return Err(Error::InvalidInput {
                name: "threads",
                value: self.threads as f64,
                unit: "",
                expected: "0 (one per core) to 1024 threads",
            });
        }
        Ok(())
    }

    /// The spreads, as the answer reports them.
    pub fn spreads(&self) -> Spreads {
        Spreads {
            wind_speed_sd_mps: self.wind_speed_sd_mps,
            wind_from_sd_deg: self.wind_from_sd_deg,
            payload_sd_kg: self.payload_sd_kg,
            capacity_sd_percent: self.capacity_sd_percent,
            power_sd_percent: self.power_sd_percent,
        }
    }

    /// Whether the wind's speed or direction is drawn.
    fn draws_wind(&self) -> bool {
        self.wind_speed_sd_mps > 0.0 || self.wind_from_sd_deg > 0.0
    }

    /// Threads to use for `n` scenarios.
    pub(super) fn thread_count(&self, n: usize) -> usize {
        let t = match self.threads {
            0 => std::thread::available_parallelism().map_or(1, |c| c.get()),
            t => t,
        };
        t.clamp(1, n.max(1))
    }
}

/// The answer of [`plan_scenarios`]: the `uncertainty` object of `aloft mission --samples N
/// --format json` (keys in docs/guide.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Uncertainty {
    /// Scenarios drawn.
    pub samples: u32,
    /// Seed of the draws.
    pub seed: u64,
    /// Fraction of the scenarios that land with the reserve.
    pub p_feasible: f64,
    /// Scenarios that land with the reserve.
    pub feasible_scenarios: u32,
    /// Scenarios flown to the end of the route (feasible or short of the reserve): those the
    /// percentiles of energy, state of charge and duration are over.
    pub completed_scenarios: u32,
    /// Scenarios the vehicle cannot fly (a path it cannot make headway along or hold its
    /// position on within its envelope, a take-off mass beyond its limit, its propulsion chain's
    /// range): infeasible, and not flown to the end.
    pub cannot_fly_scenarios: u32,
    /// Why, in the first such scenario (by index).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cannot_fly_reason: Option<String>,
    /// The spreads drawn with.
    pub spreads: Spreads,
    /// Electrical energy, Wh (absent when no scenario completes the route).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub energy_wh: Option<Percentiles>,
    /// State of charge at the end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end_soc: Option<Percentiles>,
    /// Flight time, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<Percentiles>,
    /// Fraction of the scenarios that have a point of no return (including those that cannot be
    /// flown at all).
    pub p_point_of_no_return: f64,
    /// Time of the point of no return, s (see the module docs for how scenarios without one
    /// count); absent when fewer than 5 % of the scenarios have one.
    #[serde(default, skip_serializing_if = "TimeBand::is_empty")]
    pub point_of_no_return_s: TimeBand,
    /// State of charge at the end of each segment, over the completed scenarios (absent when
    /// none completes, or when scenarios x segments exceed ten million).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub segments: Vec<SegmentBand>,
    /// Percentile bands of the state of charge over time (with [`ScenarioOptions::soc_fan`];
    /// not in the JSON).
    #[serde(skip)]
    pub soc_fan: Option<SocFan>,
    /// The voltage failsafes watched (`--low-voltage-v`, `--critical-voltage-v`, a pack file's
    /// `[failsafe]`) and when each triggers over the scenarios: the first time the predicted
    /// voltage under load falls below it, as the mission's `failsafes` say it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failsafes: Vec<FailsafeBand>,
}

/// When a voltage failsafe triggers over a mission's scenarios.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailsafeBand {
    /// `low` or `critical`.
    pub kind: String,
    /// The threshold, pack volts.
    pub voltage_v: f64,
    /// Share of the scenarios in which it triggers.
    pub p_triggers: f64,
    /// When, s from take-off (percentiles left out where they fall on scenarios in which it
    /// does not trigger; the whole left out where it triggers in none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_s: Option<TimeBand>,
}

/// The first time the voltage under load falls below each threshold, in each scenario.
struct Crossings {
    thresholds_v: Vec<f64>,
}

impl ScenarioWatch for Crossings {
    fn start(&self, _index: usize) -> (Option<f64>, Box<dyn WatchRun>) {
        let run = CrossingRun {
            thresholds_v: self.thresholds_v.clone(),
            first_s: vec![f64::INFINITY; self.thresholds_v.len()],
        };
        (None, Box::new(run))
    }
}

/// One scenario's [`Crossings`].
struct CrossingRun {
    thresholds_v: Vec<f64>,
    first_s: Vec<f64>,
}

impl WatchRun for CrossingRun {
    fn take(&mut self, sample: &aloft_planner::Sample) {
        for (first, th) in self.first_s.iter_mut().zip(&self.thresholds_v) {
            if sample.voltage_v < *th && first.is_infinite() {
                *first = sample.time_s;
            }
        }
    }

    fn finish(&mut self) -> Vec<f64> {
        self.first_s.clone()
    }
}

/// A deterministic answer with its `uncertainty` over scenarios: the answer's keys, then
/// `uncertainty` ([`MissionWithUncertainty`], [`EnduranceWithUncertainty`]).
#[derive(Debug, Clone, Serialize)]
pub struct WithUncertainty<'a, A, U> {
    /// The deterministic answer.
    #[serde(flatten)]
    pub summary: &'a A,
    /// How sure it is.
    pub uncertainty: &'a U,
}

/// A mission's summary with its `uncertainty`: the JSON of `aloft mission --samples N --format
/// json` (the C ABI's `aloft_mission_json` with a `scenarios` object gives the same bytes).
pub type MissionWithUncertainty<'a> = WithUncertainty<'a, MissionSummary, Uncertainty>;

impl MissionWithUncertainty<'_> {
    /// Pretty JSON, as the CLI prints it (without the CLI's trailing newline).
    ///
    /// # Errors
    /// [`Error::OptionsFormat`] if serialisation fails (it does not for finite numbers).
    pub fn to_json(&self) -> Result<String, Error> {
        crate::engine::missions::summary::pretty_json(self, "mission summary")
    }
}

/// Mission options with an optional `scenarios` object (the C ABI's options JSON):
/// `{"payload_kg": 0.5, "scenarios": {"samples": 1000, "payload_sd_kg": 0.1}}`.
///
/// # Errors
/// [`Error::OptionsFormat`] for malformed JSON or unknown keys.
pub fn options_from_json(text: &str) -> Result<(MissionOptions, Option<ScenarioOptions>), Error> {
    let bad = |e: serde_json::Error| Error::OptionsFormat {
        what: "mission options",
        message: e.to_string(),
    };
    let mut value: serde_json::Value = serde_json::from_str(text).map_err(bad)?;
    let scenarios = match value.as_object_mut().and_then(|m| m.remove("scenarios")) {
        Some(s) => Some(serde_json::from_value(s).map_err(|e| Error::OptionsFormat {
            what: "scenario options",
            message: e.to_string(),
        })?),
        None => None,
    };
    Ok((serde_json::from_value(value).map_err(bad)?, scenarios))
}

// ---------------------------------------------------------------------------------------------
// Draws.

/// The golden-ratio increment of splitmix64.
const GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// The output function of splitmix64 (Steele, Lea and Flood 2014): a bijection of 64-bit words
/// that mixes every input bit into every output bit.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Scenario `index`'s own stream of draws: splitmix64 from a state that mixes the seed and the
/// index, so the draws of a scenario depend on nothing else.
struct Stream {
    state: u64,
}

impl Stream {
    fn of(seed: u64, index: u64) -> Self {
        Self {
            state: mix64(seed.wrapping_add(GAMMA))
                ^ mix64(index.wrapping_mul(GAMMA) ^ 0x5851_f42d_4c95_7f2d),
        }
    }

    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GAMMA);
        mix64(self.state)
    }

    /// Uniform in `[0, 1)` with 53 random bits.
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal by Box-Muller (the cosine branch; two uniforms per draw).
    fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform(); // (0, 1]: the logarithm is finite
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// The standard normal draws of one scenario and its gust seed. Every source is drawn whether
/// its spread is zero or not, so a source's draws do not depend on which others are on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::engine) struct Draws {
    pub(in crate::engine) wind_speed: f64,
    pub(in crate::engine) wind_from: f64,
    pub(in crate::engine) payload: f64,
    pub(in crate::engine) capacity: f64,
    pub(in crate::engine) power: f64,
    pub(in crate::engine) gust_seed: u64,
    /// The pack's state now (`aloft live`: its state of charge's draw), drawn last so that
    /// the other draws are what they were before it.
    pub(in crate::engine) pack_state: f64,
}

impl Draws {
    /// The draws of scenario `index` under `seed`.
    pub(in crate::engine) fn of(seed: u64, index: usize) -> Self {
        let mut s = Stream::of(seed, index as u64);
        Self {
            wind_speed: s.normal(),
            wind_from: s.normal(),
            payload: s.normal(),
            capacity: s.normal(),
            power: s.normal(),
            gust_seed: s.next_u64(),
            pack_state: s.normal(),
        }
    }
}

/// A factor `1 + sd z / 100`, at least 0.01.
fn factor(sd_percent: f64, z: f64) -> f64 {
    (1.0 + sd_percent * z / 100.0).max(0.01)
}

/// `value` scaled by `factor(sd_percent, z)` through `scale` when the spread is on, else
/// borrowed as it is.
fn scaled<'a, T: Clone, E>(
    value: &'a T,
    sd_percent: f64,
    z: f64,
    scale: impl FnOnce(&T, f64) -> Result<T, E>,
) -> Result<Cow<'a, T>, E> {
    Ok(if sd_percent > 0.0 {
        Cow::Owned(scale(value, factor(sd_percent, z))?)
    } else {
        Cow::Borrowed(value)
    })
}

/// The aircraft and pack of a scenario: the aircraft scaled by its model error and the pack's
/// capacity drawn, each when its spread is on.
pub(super) fn scaled_models<'a>(
    aircraft: &'a Aircraft,
    pack: &'a Pack,
    sc: &ScenarioOptions,
    d: &Draws,
) -> Result<(Cow<'a, Aircraft>, Cow<'a, Pack>), Error> {
    let aircraft = scaled(aircraft, sc.power_sd_percent, d.power, |a, f| {
        a.with_power_scale(f)
    })?;
    let pack = scaled(pack, sc.capacity_sd_percent, d.capacity, |p, f| {
        p.with_capacity_factor(f)
    })?;
    Ok((aircraft, pack))
}

/// Still air, as a wind table: what scenarios draw around when the request names no wind.
fn calm_spec() -> WindSpec {
    WindSpec::uniform(0.0, 0.0)
}

/// A steady wind drawn around `spec` (gusts left out: they are added by the caller).
fn drawn_wind_spec(spec: &WindSpec, sc: &ScenarioOptions, d: &Draws) -> WindSpec {
    WindSpec {
        speed_mps: (spec.speed_mps + sc.wind_speed_sd_mps * d.wind_speed).clamp(0.0, MAX_WIND_MPS),
        from_deg: spec.from_deg + sc.wind_from_sd_deg * d.wind_from,
        gust_std_mps: None,
        gust_seed: None,
        ..spec.clone()
    }
}

/// Whether a planner error says that the vehicle cannot fly this scenario (its limits), rather
/// than that the request is wrong.
pub(super) fn cannot_fly(e: &PlannerError) -> bool {
    match e {
        PlannerError::Propulsion(_) | PlannerError::NoHeadway { .. } => true,
        PlannerError::Unreachable { name, .. } => name.starts_with("take-off mass"),
        _ => false,
    }
}

// ---------------------------------------------------------------------------------------------
// Missions.

/// The winds of a mission's scenarios: what is decided once, and how scenario `i`'s is drawn.
pub(super) struct Winds {
    /// The wind of the deterministic plan.
    nominal: Wind,
    /// The wind without the request's gusts (a scenario's gusts replace whatever it carries).
    base: Wind,
    /// The steady wind drawn around (absent with a gridded field).
    spec: Option<WindSpec>,
    /// The gusts' standard deviation, when the mission flies with gusts.
    gust_std_mps: Option<f64>,
}

impl Winds {
    pub(super) fn new(
        vehicle: &Vehicle,
        mission: &Mission,
        options: &MissionOptions,
        sc: &ScenarioOptions,
    ) -> Result<Self, Error> {
        let (nominal, _) = mission_wind(options, mission, vehicle)?;
        let base = match options.gusts {
            Some(_) => {
                let plain = MissionOptions {
                    gusts: None,
                    ..options.clone()
                };
                mission_wind(&plain, mission, vehicle)?.0
            }
            None => nominal.clone(),
        };
        let spec = match &options.wind_field {
            Some(_) if sc.draws_wind() => {
                return Err(Error::Contradiction {
                    message: "wind_speed_sd_mps and wind_from_sd_deg draw around a steady wind: a gridded wind field has no single speed and direction".to_string(),
                })
            }
            Some(_) => None,
            None => Some(options.wind.clone().or_else(|| mission.spec().wind.clone()).unwrap_or_else(calm_spec)),
        };
        let gust_std_mps = options
            .gusts
            .map(|g| g.std_mps)
            .or_else(|| spec.as_ref().and_then(|s| s.gust_std_mps));
        Ok(Self {
            nominal,
            base,
            spec,
            gust_std_mps,
        })
    }

    /// The wind of a scenario: the plan's when nothing about it is drawn.
    pub(super) fn of(&self, sc: &ScenarioOptions, d: &Draws) -> Result<Cow<'_, Wind>, Error> {
        let wind_error = |e| Error::Wind {
            origin: "scenario wind".to_string(),
            source: Box::new(e),
        };
        let mean = match (&self.spec, sc.draws_wind()) {
            (Some(spec), true) => drawn_wind_spec(spec, sc, d).to_wind().map_err(wind_error)?,
            _ if self.gust_std_mps.is_none() => return Ok(Cow::Borrowed(&self.nominal)),
            _ => self.base.clone(),
        };
        Ok(Cow::Owned(match self.gust_std_mps {
            Some(std) => mean.with_gusts(Gusts::new(std, d.gust_seed).map_err(wind_error)?),
            None => mean,
        }))
    }
}

/// What every scenario of a mission shares: decided once.
struct MissionScenarios<'a> {
    aircraft: &'a Aircraft,
    pack: Pack,
    options: aloft_planner::PlanOptions,
    spec: MissionSpec,
    payload_kg: Option<f64>,
    base_payload_kg: f64,
    winds: Winds,
    origin: &'a str,
    vehicle: &'a str,
}

/// What one scenario gave.
#[derive(Debug, Clone, PartialEq)]
struct Record {
    feasible: bool,
    /// Flown to the end of the route.
    completed: bool,
    energy_wh: f64,
    end_soc: f64,
    duration_s: f64,
    /// Point of no return, s: infinity when there is none, 0 when it cannot be flown.
    pnr_s: f64,
    segment_end_soc: Vec<f64>,
    /// Why the vehicle cannot fly it, when it cannot.
    cannot_fly: Option<String>,
    /// What a [`ScenarioWatch`] saw of it.
    watched: Vec<f64>,
}

impl Record {
    fn cannot_fly(e: &PlannerError) -> Self {
        Record {
            feasible: false,
            completed: false,
            energy_wh: 0.0,
            end_soc: 0.0,
            duration_s: 0.0,
            pnr_s: 0.0,
            segment_end_soc: Vec::new(),
            cannot_fly: Some(e.to_string()),
            watched: Vec::new(),
        }
    }

    fn of(r: &MissionReport, keep_segments: bool, vehicle: &str) -> Self {
        // A path it cannot fly (no headway against the wind, no hover): the flight ends there;
        // it could turn back until then at the latest.
        let stuck = matches!(r.shortfall, Some(Shortfall::NoProgress(_)));
        let no_pnr = if stuck { r.duration_s } else { f64::INFINITY };
        Self {
            feasible: r.feasible,
            completed: matches!(r.shortfall, None | Some(Shortfall::Reserve { .. })),
            energy_wh: r.energy_wh,
            end_soc: r.end_soc,
            duration_s: r.duration_s,
            pnr_s: r.point_of_no_return.map_or(no_pnr, |p| p.time_s),
            segment_end_soc: if keep_segments {
                r.segments.iter().map(|s| s.end_soc).collect()
            } else {
                Vec::new()
            },
            cannot_fly: r
                .shortfall
                .as_ref()
                .filter(|_| stuck)
                .map(|why| reason(why, &r.segments, vehicle)),
            watched: Vec::new(),
        }
    }
}

impl<'a> MissionScenarios<'a> {
    fn new(
        vehicle: &'a Vehicle,
        mission: &'a Mission,
        options: &MissionOptions,
        sc: &ScenarioOptions,
    ) -> Result<Self, Error> {
        // The aircraft first: a vehicle without an airframe is told so, before its packs.
        let aircraft = vehicle.aircraft()?;
        let pack = vehicle.battery(options.battery.as_deref())?;
        check_options(options)?;
        let winds = Winds::new(vehicle, mission, options, sc)?;
        let plan_options = aloft_planner::PlanOptions {
            // Scenarios run on every core already: one thread per flight.
            second_thread: false,
            ..planner_options(options, mission.spec(), &pack)?
        };
        let (spec, _) = flown_spec(mission, vehicle, options);
        let flight = Flight {
            aircraft,
            pack: &pack,
            wind: &winds.nominal,
            options: plan_options,
            // The scenarios are bounded before they fly (`WorkBounds`).
            meter: None,
        };
        // A loiter until the reserve is resolved once, in the plan's conditions: the scenarios
        // fly the loiter the operator is told to fly.
        let spec = match resolve_loiter(&flight, &spec, options.payload_kg) {
            Ok(Some((flown, _))) => flown,
            Ok(None) => spec,
            Err(e) => return Err(mission_error(mission.origin(), vehicle.name(), e)),
        };
        // A mission that ends in the air flies home as the plan does.
        let (spec, _) = flight.home_at_mission_end(spec);
        Ok(Self {
            aircraft,
            base_payload_kg: options.payload_kg.unwrap_or(spec.payload_kg),
            pack,
            options: plan_options,
            spec,
            payload_kg: options.payload_kg,
            winds,
            origin: mission.origin(),
            vehicle: vehicle.name(),
        })
    }

    /// The duration of the plan's flight, s: as compiled, or as flown where the envelope slows it
    /// beyond its planned time.
    fn nominal_duration_s(&self) -> Result<f64, Error> {
        let plan = Flight {
            aircraft: self.aircraft,
            pack: &self.pack,
            wind: &self.winds.nominal,
            options: self.options,
            meter: None,
        };
        let compiled = plan
            .compile(&self.spec, self.payload_kg)
            .map_err(|e| mission_error(self.origin, self.vehicle, e))?;
        let planned: f64 = compiled.pieces().iter().map(|p| p.duration_s()).sum();
        let flown = plan
            .fly_into(&compiled, &mut NoSamples)
            .map_or(0.0, |r| r.duration_s);
        Ok(planned.max(flown))
    }

    /// Fly scenario `index`, its samples into `sink` (the state-of-charge fan) when given, and
    /// into `watch`'s run of it when given.
    fn fly(
        &self,
        sc: &ScenarioOptions,
        index: usize,
        keep_segments: bool,
        (fan, watch): (Option<&mut FanHistogram>, Option<&dyn ScenarioWatch>),
    ) -> Result<Record, Error> {
        let d = Draws::of(sc.seed, index);
        let (aircraft, pack) = scaled_models(self.aircraft, &self.pack, sc, &d)?;
        let wind = self.winds.of(sc, &d)?;
        let payload_kg = if sc.payload_sd_kg > 0.0 {
            Some((self.base_payload_kg + sc.payload_sd_kg * d.payload).max(0.0))
        } else {
            self.payload_kg
        };
        let (start_soc, mut run) = match watch {
            Some(w) => {
                let (s, r) = w.start(index);
                (s, Some(r))
            }
            None => (None, None),
        };
        let mut options = self.options;
        if let Some(s) = start_soc {
            options.start_soc = s;
        }
        let flight = Flight {
            aircraft: &aircraft,
            pack: &pack,
            wind: &wind,
            options,
            meter: None,
        };
        let report = match flight.compile(&self.spec, payload_kg) {
            Ok(c) => {
                let mut sink = Sinks {
                    fan: fan.map(FanSink::new),
                    watch: run.as_deref_mut(),
                };
                let r = match sink.wants() {
                    true => flight.fly_into(&c, &mut sink),
                    false => flight.fly_into(&c, &mut NoSamples),
                };
                if let Some(f) = sink.fan {
                    f.finish();
                }
                r
            }
            Err(e) => Err(e),
        };
        let watched = run.map_or_else(Vec::new, |mut r| r.finish());
        match report {
            Ok(r) => Ok(Record {
                watched,
                ..Record::of(&r, keep_segments, self.vehicle)
            }),
            Err(e) if cannot_fly(&e) => Ok(Record::cannot_fly(&e)),
            Err(e) => Err(mission_error(self.origin, self.vehicle, e)),
        }
    }
}

/// What a [`ScenarioWatch`] saw of one scenario: whether it landed with the reserve, and the
/// run's own figures.
pub(in crate::engine) type Watched = (bool, Vec<f64>);

/// Something that follows each scenario's flight sample by sample, beside what every scenario
/// gives (`aloft live`: the autopilot's failsafes on the pack flown).
pub(in crate::engine) trait ScenarioWatch: Sync {
    /// The state of charge scenario `index` starts from (`None`: the options'), and its run.
    fn start(&self, index: usize) -> (Option<f64>, Box<dyn WatchRun>);
}

/// A [`ScenarioWatch`]'s run of one scenario.
pub(in crate::engine) trait WatchRun: Send {
    /// The next sample of the flight.
    fn take(&mut self, sample: &aloft_planner::Sample);
    /// What it saw, once the flight is over.
    fn finish(&mut self) -> Vec<f64>;
}

/// The state-of-charge fan's sink and a watch's run, either or both.
struct Sinks<'h, 'w> {
    fan: Option<FanSink<'h>>,
    watch: Option<&'w mut (dyn WatchRun + 'static)>,
}

impl Sinks<'_, '_> {
    fn wants(&self) -> bool {
        self.fan.is_some() || self.watch.is_some()
    }
}

impl aloft_planner::SampleSink for Sinks<'_, '_> {
    fn take(&mut self, sample: &aloft_planner::Sample) -> Result<(), PlannerError> {
        if let Some(f) = self.fan.as_mut() {
            f.take(sample)?;
        }
        if let Some(w) = self.watch.as_mut() {
            w.take(sample);
        }
        Ok(())
    }
}

fn mission_error(origin: &str, vehicle: &str, e: PlannerError) -> Error {
    Error::Mission {
        origin: origin.to_string(),
        vehicle: vehicle.to_string(),
        source: Box::new(e),
    }
}

/// Most values of segment end states kept for the segment bands (scenarios x segments).
const MAX_SEGMENT_VALUES: usize = 10_000_000;

/// Draw `sc.samples` scenarios around the request of [`crate::engine::missions::mission::plan_mission`] and fly each: how
/// often the mission lands with the reserve and percentiles of what it costs (the module docs
/// say what is drawn and how each figure counts).
///
/// # Errors
/// Invalid scenario options, wind spreads with a gridded wind field, and whatever makes the
/// request itself wrong (as [`crate::engine::missions::mission::plan_mission`]); a scenario the vehicle cannot fly is not an
/// error.
pub fn plan_scenarios(
    vehicle: &Vehicle,
    mission: &Mission,
    options: &MissionOptions,
    sc: &ScenarioOptions,
) -> Result<Uncertainty, Error> {
    let watched = crate::engine::missions::mission::failsafe_thresholds(options)?;
    let crossings = Crossings {
        thresholds_v: watched.iter().map(|w| w.1).collect(),
    };
    let watch = (!watched.is_empty()).then_some(&crossings as &dyn ScenarioWatch);
    let (mut u, seen) = plan_scenarios_watched(vehicle, mission, options, sc, watch)?;
    u.failsafes = watched
        .iter()
        .enumerate()
        .map(|(i, (kind, voltage_v))| {
            // A scenario the vehicle cannot fly has no voltage: it does not trigger.
            let mut t: Vec<f64> = seen
                .iter()
                .map(|(_, run)| run.get(i).copied().unwrap_or(f64::INFINITY))
                .collect();
            t.sort_by(f64::total_cmp);
            let n = t.len().max(1) as f64;
            FailsafeBand {
                kind: kind.to_string(),
                voltage_v: *voltage_v,
                p_triggers: t.iter().filter(|x| x.is_finite()).count() as f64 / n,
                time_s: time_band(&t),
            }
        })
        .collect();
    Ok(u)
}

/// [`plan_scenarios`], each scenario followed by `watch` where given: whether each scenario
/// landed with the reserve and what the watch saw of it, in index order, beside the answer
/// (nothing seen of a scenario the vehicle cannot fly).
///
/// # Errors
/// As [`plan_scenarios`].
pub(in crate::engine) fn plan_scenarios_watched(
    vehicle: &Vehicle,
    mission: &Mission,
    options: &MissionOptions,
    sc: &ScenarioOptions,
    watch: Option<&dyn ScenarioWatch>,
) -> Result<(Uncertainty, Vec<Watched>), Error> {
    sc.check()?;
    // Over terrain, the scenarios fly the mission over the ground as the plan does.
    let over = crate::engine::missions::mission::over_terrain(mission, options)?;
    let mission = over.as_ref().map_or(mission, |(m, _)| m);
    let (vehicle, _air) =
        crate::engine::missions::day::mission_air(vehicle, mission, &options.air)?;
    let vehicle = &vehicle;
    let setup = MissionScenarios::new(vehicle, mission, options, sc)?;
    let n = sc.samples as usize;
    let keep_segments = n.saturating_mul(setup.spec.segments.len().max(1)) <= MAX_SEGMENT_VALUES;
    let nominal_s = match sc.soc_fan || sc.bounds.max_steps.is_some() {
        true => Some(setup.nominal_duration_s()?),
        false => None,
    };
    if let Some(d) = nominal_s {
        let steps = (d / setup.options.time_step_s).ceil();
        sc.bounds.check(sc.samples, steps as u64)?;
    }
    // The fan's grid spans 1.5 times the plan's flight: a scenario's flight beyond it is cut.
    let fan_grid = nominal_s.filter(|_| sc.soc_fan).map(|d| 1.5 * d.max(1.0));
    let (records, fans) = run_indexed(
        n,
        (sc.thread_count(n), &sc.bounds),
        || fan_grid.map(FanHistogram::new),
        |i, fan| setup.fly(sc, i, keep_segments, (fan.as_mut(), watch)),
    )?;
    let soc_fan = fans
        .into_iter()
        .flatten()
        .reduce(FanHistogram::merge)
        .and_then(|h| h.bands());
    let u = summarise(sc, &records, soc_fan);
    let u = finite(u, "uncertainty", || {
        format!(
            "scenarios of mission {} with {}",
            mission.origin(),
            vehicle.name()
        )
    })?;
    Ok((
        u,
        records
            .into_iter()
            .map(|r| (r.feasible, r.watched))
            .collect(),
    ))
}

/// The answer from the records of every scenario, in index order.
fn summarise(sc: &ScenarioOptions, records: &[Record], soc_fan: Option<SocFan>) -> Uncertainty {
    let n = records.len();
    let feasible = records.iter().filter(|r| r.feasible).count();
    let completed: Vec<&Record> = records.iter().filter(|r| r.completed).collect();
    let of = |f: fn(&Record) -> f64| {
        let mut v: Vec<f64> = completed.iter().map(|r| f(r)).collect();
        Percentiles::of(&mut v)
    };
    let mut pnr: Vec<f64> = records.iter().map(|r| r.pnr_s).collect();
    pnr.sort_by(f64::total_cmp);
    let with_pnr = pnr.iter().filter(|t| t.is_finite()).count();
    Uncertainty {
        samples: sc.samples,
        seed: sc.seed,
        p_feasible: feasible as f64 / n as f64,
        feasible_scenarios: u32::try_from(feasible).unwrap_or(u32::MAX),
        completed_scenarios: u32::try_from(completed.len()).unwrap_or(u32::MAX),
        cannot_fly_scenarios: u32::try_from(
            records.iter().filter(|r| r.cannot_fly.is_some()).count(),
        )
        .unwrap_or(u32::MAX),
        cannot_fly_reason: records.iter().find_map(|r| r.cannot_fly.clone()),
        spreads: sc.spreads(),
        energy_wh: of(|r| r.energy_wh),
        end_soc: of(|r| r.end_soc),
        duration_s: of(|r| r.duration_s),
        p_point_of_no_return: with_pnr as f64 / n as f64,
        point_of_no_return_s: time_band(&pnr).unwrap_or_default(),
        segments: SegmentBand::of(completed.iter().map(|r| r.segment_end_soc.as_slice())),
        soc_fan,
        failsafes: Vec::new(),
    }
}

/// Run `fly` for every index below `n` on `threads` scoped threads (thread `t` takes indices `t,
/// t + threads, ...`), each with its own state from `state`, until `bounds` is cancelled: the
/// results in index order and the states. The first error by index is returned, whatever thread
/// met it ([`Error::Cancelled`] once cancelled).
pub(super) fn run_indexed<R: Send, S: Send>(
    n: usize,
    (threads, bounds): (usize, &WorkBounds),
    state: impl Fn() -> S + Sync,
    fly: impl Fn(usize, &mut S) -> Result<R, Error> + Sync,
) -> Result<(Vec<R>, Vec<S>), Error> {
    type Part<R, S> = Result<(Vec<(usize, R)>, S), (usize, Error)>;
    let run = |t: usize| -> Part<R, S> {
        let mut st = state();
        let mut out = Vec::with_capacity(n / threads + 1);
        for i in (t..n).step_by(threads) {
            if bounds.cancelled() {
                return Err((i, Error::Cancelled));
            }
            match fly(i, &mut st) {
                Ok(r) => out.push((i, r)),
                Err(e) => return Err((i, e)),
            }
        }
        Ok((out, st))
    };
    let parts: Vec<Part<R, S>> = if threads <= 1 {
        vec![run(0)]
    } else {
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..threads).map(|t| s.spawn(move || run(t))).collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
                .collect()
        })
    };
    let mut slots: Vec<Option<R>> = (0..n).map(|_| None).collect();
    let mut states = Vec::with_capacity(parts.len());
    let mut first_error: Option<(usize, Error)> = None;
    for part in parts {
        match part {
            Ok((out, st)) => {
                for (i, r) in out {
                    slots[i] = Some(r);
                }
                states.push(st);
            }
            Err((i, e)) => {
                if first_error.as_ref().is_none_or(|(j, _)| i < *j) {
                    first_error = Some((i, e));
                }
            }
        }
    }
    if let Some((_, e)) = first_error {
        return Err(e);
    }
    Ok((slots.into_iter().flatten().collect(), states))
}

// ---------------------------------------------------------------------------------------------
// Endurance.

/// The answer of [`endurance_scenarios`]: the `uncertainty` object of `aloft endurance --samples
/// N --format json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnduranceUncertainty {
    /// Scenarios drawn.
    pub samples: u32,
    /// Seed of the draws.
    pub seed: u64,
    /// Fraction of the scenarios the vehicle can fly: take-off mass within its limit, the hover
    /// and the flight along the course within its thrust and tilt, headway along the course.
    pub p_feasible: f64,
    /// The spreads drawn with.
    pub spreads: Spreads,
    /// Hover endurance, s (over the scenarios that can be flown; absent when none can).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hover_endurance_s: Option<Percentiles>,
    /// Endurance at the best-endurance speed, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_endurance_s: Option<Percentiles>,
    /// Range along the course at the best-range speed, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_range_m: Option<Percentiles>,
    /// Orbit endurance, s (with an orbit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbit_endurance_s: Option<Percentiles>,
}

/// An endurance answer with its `uncertainty` (the JSON of `aloft endurance --samples N`).
pub type EnduranceWithUncertainty<'a> = WithUncertainty<
    'a,
    crate::engine::performance::endurance::EnduranceSummary,
    EnduranceUncertainty,
>;

/// Draw `sc.samples` scenarios around the request of [`crate::engine::performance::endurance`] (wind speed and
/// direction, payload, pack capacity, model error; no gusts) and answer the queries in each:
/// percentiles of hover endurance, best endurance, best range and orbit endurance.
///
/// # Errors
/// Invalid scenario options, and whatever makes the request itself wrong (as
/// [`crate::engine::performance::endurance`]); a scenario the vehicle cannot fly is not an error.
pub fn endurance_scenarios(
    vehicle: &Vehicle,
    options: &EnduranceOptions,
    sc: &ScenarioOptions,
) -> Result<EnduranceUncertainty, Error> {
    sc.check()?;
    let (vehicle, _air) = crate::engine::conditions::air::vehicle_air(vehicle, &options.air)?;
    let vehicle = &vehicle;
    let aircraft = vehicle.aircraft()?;
    let pack = vehicle.battery(options.battery.as_deref())?;
    let n = sc.samples as usize;
    let base_wind = options.wind.clone().unwrap_or_else(calm_spec);
    let (reports, _) = run_indexed(
        n,
        (sc.thread_count(n), &sc.bounds),
        || (),
        |i, ()| {
            let d = Draws::of(sc.seed, i);
            let mut o = options.clone();
            if sc.payload_sd_kg > 0.0 {
                o.payload_kg = (options.payload_kg + sc.payload_sd_kg * d.payload).max(0.0);
            }
            if sc.draws_wind() {
                o.wind = Some(drawn_wind_spec(&base_wind, sc, &d));
            }
            let (a, p) = scaled_models(aircraft, &pack, sc, &d)?;
            match crate::engine::performance::endurance::endurance_report(vehicle, &a, &p, &o) {
                Ok(r) => Ok(Some(r)),
                Err(Error::TooHeavy { .. }) => Ok(None),
                Err(Error::Planner(e)) if cannot_fly(&e) => Ok(None),
                Err(e) => Err(e),
            }
        },
    )?;
    let flown: Vec<_> = reports.iter().flatten().collect();
    let of = |f: &dyn Fn(&aloft_planner::EnduranceReport) -> Option<f64>| {
        let mut v: Vec<f64> = flown.iter().filter_map(|r| f(r)).collect();
        Percentiles::of(&mut v)
    };
    let u = EnduranceUncertainty {
        samples: sc.samples,
        seed: sc.seed,
        p_feasible: flown.len() as f64 / n as f64,
        spreads: sc.spreads(),
        hover_endurance_s: of(&|r| Some(r.hover_endurance_s)),
        max_endurance_s: of(&|r| Some(r.max_endurance_s)),
        max_range_m: of(&|r| Some(r.max_range_m)),
        orbit_endurance_s: of(&|r| r.orbit_endurance_s),
    };
    finite(u, "endurance uncertainty", || {
        format!("scenarios of the endurance of {}", vehicle.name())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_are_standard_normal_and_independent_of_each_other() {
        let n = 100_000;
        let d: Vec<Draws> = (0..n).map(|i| Draws::of(5, i)).collect();
        let nf = n as f64;
        for (name, z) in [
            (
                "wind_speed",
                d.iter().map(|x| x.wind_speed).collect::<Vec<_>>(),
            ),
            ("payload", d.iter().map(|x| x.payload).collect()),
            ("power", d.iter().map(|x| x.power).collect()),
        ] {
            let mean = z.iter().sum::<f64>() / nf;
            let var = z.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (nf - 1.0);
            let below = z.iter().filter(|&&x| x < 0.5).count() as f64 / nf;
            // Four standard errors: of the mean 1/sqrt(n) = 0.0032, of the variance
            // sqrt(2/n) = 0.0045, of a fraction near 0.69 sqrt(p(1-p)/n) = 0.0015.
            assert!(mean.abs() < 4.0 * (1.0 / nf).sqrt(), "{name} mean {mean}");
            assert!(
                (var - 1.0).abs() < 4.0 * (2.0 / nf).sqrt(),
                "{name} var {var}"
            );
            let phi = 0.691_462_461_274_013;
            assert!(
                (below - phi).abs() < 4.0 * (phi * (1.0 - phi) / nf).sqrt(),
                "{name} {below}"
            );
        }
        // Two sources of one scenario are uncorrelated (|r| < 4 / sqrt(n)).
        let r = d.iter().map(|x| x.payload * x.power).sum::<f64>() / nf;
        assert!(r.abs() < 4.0 / nf.sqrt(), "{r}");
        // A scenario's draws depend on its seed and index only.
        assert_eq!(Draws::of(5, 123), d[123]);
        assert_ne!(Draws::of(6, 123), d[123]);
    }

    #[test]
    fn options_json_takes_a_scenarios_object_and_rejects_unknown_keys() {
        let (o, s) = options_from_json(
            r#"{"payload_kg": 0.5, "scenarios": {"samples": 10, "payload_sd_kg": 0.1}}"#,
        )
        .unwrap();
        assert_eq!(o.payload_kg, Some(0.5));
        let s = s.unwrap();
        assert_eq!((s.samples, s.payload_sd_kg, s.seed), (10, 0.1, 1));
        assert_eq!(
            s.power_sd_percent.to_bits(),
            DEFAULT_POWER_SD_PERCENT.to_bits()
        );
        assert!(options_from_json(r#"{"scenarios": {"sample": 10}}"#).is_err());
        assert!(options_from_json(r#"{"bogus": 1}"#).is_err());
        assert_eq!(options_from_json("{}").unwrap().1, None);
    }
}
