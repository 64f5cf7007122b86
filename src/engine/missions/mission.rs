//! Missions: load one (a file, text, the built-in demo), plan it with a vehicle, and what the
//! plan answers (summary, samples, what is left after a time, files for other tools).

use std::borrow::Cow;

use aloft_core::Trapezoid;
use serde::Serialize;

use aloft_planner::{MissionReport, MissionSpec, Pack, PlanOptions, Sample, Shortfall, Wind};
use aloft_power::AoaModel;

use crate::engine::basics::finite::finite;
use crate::engine::conditions::air::Air;
use crate::engine::missions::day::{mission_air, mission_wind};
use crate::engine::missions::flight::Flight;
use crate::engine::missions::flown::flown_spec;
use crate::engine::missions::ground::Ground;
use crate::engine::missions::loiter::resolve_loiter;
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_options::{MissionOptions, DEFAULT_MIN_CLEARANCE_M};
use crate::engine::missions::mission_outputs::{path_points, MissionOutputs, OutputSink};
use crate::engine::missions::sorties::{split, Sorties};
use crate::engine::missions::summary::{
    edge_warnings, mission_summary, FailsafeTime, MissionSummary,
};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// A planned mission: the planner's report, its summary and what it was planned for.
#[derive(Debug, Clone)]
pub struct Plan {
    report: MissionReport,
    summary: MissionSummary,
    context: PlanContext,
    compiled: aloft_planner::Mission,
    plot_samples: Vec<Sample>,
}

/// What a plan was computed for, in the words and figures a reader wants beside the answer
/// (the table's header and notes; not part of the JSON).
#[derive(Debug, Clone, PartialEq)]
pub struct PlanContext {
    /// Where the mission came from (a path, `built-in demo`).
    pub origin: String,
    /// The mission file's one-line description.
    pub description: String,
    /// The pack flown.
    pub battery: PackDescription,
    /// The wind in words (and where it came from).
    pub wind: String,
    /// Notes on how the vehicle is modelled.
    pub notes: Vec<String>,
    /// Where the electrical power comes from, in words.
    pub power_model: &'static str,
    /// Angle-of-attack model of the power model.
    pub aoa: AoaModel,
    /// Whether ground effect was applied near the ground.
    pub ground_effect: bool,
}

/// The figures of a pack a reader sees: name, cells, capacity, energy, resistance.
#[derive(Debug, Clone, PartialEq)]
pub struct PackDescription {
    /// Pack name.
    pub name: String,
    /// Cells in series.
    pub cells_series: u32,
    /// Rated capacity, mAh.
    pub capacity_mah: f64,
    /// Rated energy, Wh.
    pub energy_wh: f64,
    /// Internal resistance, ohm.
    pub resistance_ohm: f64,
}

impl PackDescription {
    fn of(b: &Pack) -> Self {
        Self {
            name: b.name().to_string(),
            cells_series: b.cells_series(),
            capacity_mah: b.capacity_ah() * 1000.0,
            energy_wh: b.rated_energy_wh(),
            resistance_ohm: b.resistance_ohm(),
        }
    }
}

/// What is left of a planned mission after a given time (see [`Plan::remaining`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Remaining {
    /// Flight time left, s.
    pub duration_s: f64,
    /// Electrical energy the rest of the mission draws, Wh.
    pub energy_wh: f64,
    /// State of charge the rest of the mission uses, fraction of the capacity.
    pub soc_used: f64,
}

impl Plan {
    /// What the plan was computed for (header and notes of the table).
    pub fn context(&self) -> &PlanContext {
        &self.context
    }

    /// Home, east-north-up metres.
    pub fn home_m(&self) -> [f64; 3] {
        self.compiled.home_m()
    }

    /// The mission as compiled and flown (the options applied, the way home added).
    pub fn compiled(&self) -> &aloft_planner::Mission {
        &self.compiled
    }

    /// The samples kept for a chart ([`MissionOutputs::plot`]): all of a short flight, an evenly
    /// decimated selection of a long one (at most [`PLOT_SAMPLES`](crate::engine::missions::mission_outputs::PLOT_SAMPLES)).
    pub fn plot_samples(&self) -> &[Sample] {
        &self.plot_samples
    }

    /// The summary (the CLI's JSON).
    pub fn summary(&self) -> &MissionSummary {
        &self.summary
    }

    /// The planner's full report (samples only with [`MissionOptions::record_samples`]).
    pub fn report(&self) -> &MissionReport {
        &self.report
    }

    /// Electrical energy of the whole mission, Wh.
    pub fn energy_wh(&self) -> f64 {
        self.report.energy_wh
    }

    /// The summary as pretty JSON, identical to `aloft mission --format json` without its final
    /// newline.
    ///
    /// # Errors
    /// As [`MissionSummary::to_json`].
    pub fn to_json(&self) -> Result<String, Error> {
        self.summary.to_json()
    }

    /// What the mission still costs after `time_s` into the flight: the samples after it,
    /// integrated by the trapezoid rule, the sample at `time_s` interpolated linearly. A ground
    /// station adds it to what it has measured so far; the state of charge used is the plan's
    /// (charge counting at the plan's voltages), a first-order estimate of the measured pack's.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] when the plan holds no samples (plan with
    /// [`MissionOptions::record_samples`]) or `time_s` is not finite or negative.
    pub fn remaining(&self, time_s: f64) -> Result<Remaining, Error> {
        let s = &self.report.samples;
        if s.len() < 2 {
            return Err(Error::InvalidInput {
                name: "samples",
                value: s.len() as f64,
                unit: "",
                expected: "a plan with recorded samples (MissionOptions::record_samples)",
            });
        }
        if !(time_s.is_finite() && time_s >= 0.0) {
            return Err(Error::InvalidInput {
                name: "time_s",
                value: time_s,
                unit: "s",
                expected: "a finite time since take-off, not negative",
            });
        }
        let end = &s[s.len() - 1];
        if time_s >= end.time_s {
            return Ok(Remaining {
                duration_s: 0.0,
                energy_wh: 0.0,
                soc_used: 0.0,
            });
        }
        let k = s.partition_point(|x| x.time_s <= time_s);
        // Values at `time_s`: before the first sample, the first sample's.
        let (p0, soc0) = if k == 0 {
            (s[0].power_w, s[0].soc)
        } else {
            let (a, b) = (&s[k - 1], &s[k]);
            let f = (time_s - a.time_s) / (b.time_s - a.time_s);
            (
                a.power_w + f * (b.power_w - a.power_w),
                a.soc + f * (b.soc - a.soc),
            )
        };
        let mut energy_j = Trapezoid::new();
        energy_j.push(time_s.max(s[0].time_s), p0);
        for x in &s[k..] {
            energy_j.push(x.time_s, x.power_w);
        }
        Ok(Remaining {
            duration_s: (self.report.duration_s - time_s).max(0.0),
            energy_wh: energy_j.integral() / 3600.0,
            soc_used: (soc0 - end.soc).max(0.0),
        })
    }
}

/// Plan `mission` with `vehicle` as `aloft mission` does, in the wind the options and the
/// mission decide (see the wind precedence in the engine's docs).
///
/// # Errors
/// An unknown pack, a mission the vehicle cannot fly (speed or mass beyond its limits, segments
/// out of order), invalid options (reserve outside `[0, 100)` percent, start outside `(0, 100]`),
/// an invalid or unreadable wind. An infeasible mission (reserve not held) is not an error: the
/// summary says so.
pub fn plan_mission(
    vehicle: &Vehicle,
    mission: &Mission,
    options: &MissionOptions,
) -> Result<Plan, Error> {
    plan_mission_with(vehicle, mission, options, &MissionOutputs::default())
}

/// [`plan_mission`], writing the files of `outputs` (time series, MCAP) and keeping a chart's
/// samples as the flight is flown, so that memory does not grow with the flight. After a failed
/// run the files it created are removed.
///
/// # Errors
/// As [`plan_mission`], and files that cannot be created or written.
pub fn plan_mission_with(
    vehicle: &Vehicle,
    mission: &Mission,
    options: &MissionOptions,
    outputs: &MissionOutputs,
) -> Result<Plan, Error> {
    plan_over(vehicle, mission, options, None, outputs)
}

/// [`plan_mission`] in a wind built by the caller, which replaces the options' and the mission
/// file's.
///
/// # Errors
/// As [`plan_mission`].
pub fn plan_mission_in(
    vehicle: &Vehicle,
    mission: &Mission,
    options: &MissionOptions,
    wind: &Wind,
) -> Result<Plan, Error> {
    plan_over(
        vehicle,
        mission,
        options,
        Some(wind),
        &MissionOutputs::default(),
    )
}

/// The day of a plan, then [`plan_in`]: over terrain, the mission flown over the ground (its
/// terrain-frame legs followed), in the air of home's ground; in the wind `given`, else the one
/// the options and the mission decide.
fn plan_over(
    vehicle: &Vehicle,
    mission: &Mission,
    options: &MissionOptions,
    given: Option<&Wind>,
    outputs: &MissionOutputs,
) -> Result<Plan, Error> {
    let over = over_terrain(mission, options)?;
    let (mission, terrain) = match &over {
        Some((m, t)) => (m, Some(t)),
        None => (mission, None),
    };
    let (vehicle, air) = mission_air(vehicle, mission, &options.air)?;
    let (wind, wind_text) = match given {
        Some(wind) => (Cow::Borrowed(wind), "given by the caller".to_string()),
        None => {
            let (wind, text) = mission_wind(options, mission, &vehicle)?;
            (Cow::Owned(wind), text)
        }
    };
    plan_in(
        &vehicle,
        (mission, terrain),
        options,
        (&wind, wind_text, air),
        outputs,
    )
}

/// The steps of a plan: the pack and the flight's fixed parts, the spec flown (the options
/// applied), a loiter until the reserve resolved, the compiled mission, the flight (into the
/// outputs), the sorties when one pack is not enough, the summary.
fn plan_in(
    vehicle: &Vehicle,
    (mission, terrain): (&Mission, Option<&aloft_terrain::Terrain>),
    options: &MissionOptions,
    (wind, wind_text, air): (&Wind, String, Air),
    outputs: &MissionOutputs,
) -> Result<Plan, Error> {
    // The aircraft first: a vehicle without an airframe is told so, before its packs.
    let aircraft = vehicle.aircraft()?;
    let battery = vehicle.battery(options.battery.as_deref())?;
    let in_mission = |e| Error::Mission {
        origin: mission.origin().to_string(),
        vehicle: vehicle.name().to_string(),
        source: Box::new(e),
    };
    let Prepared {
        flight,
        spec,
        compiled,
        planning_speed,
        loiter,
        way_home_note,
    } = prepare(vehicle, mission, options, (aircraft, &battery, wind))?;
    let watched = failsafe_thresholds(options)?;
    let thresholds: Vec<f64> = watched.iter().map(|w| w.1).collect();
    let (report, plot_samples, crossings) =
        fly_into_outputs(&flight, &compiled, (outputs, &thresholds), in_mission)?;
    // A vehicle that cannot make progress somewhere cannot fly that part on any pack.
    let stuck = matches!(report.shortfall, Some(Shortfall::NoProgress(_)));
    let sorties = if report.feasible || compiled.ends_in_air() || stuck {
        Sorties::one(report.feasible)
    } else {
        let mut flat = spec.clone();
        flat.payload_kg = compiled.payloads_kg().first().copied().unwrap_or(0.0);
        split(&flight, &flat, &compiled)
    };
    let payload = compiled.payloads_kg().first().copied().unwrap_or(0.0);
    let mut summary = mission_summary(
        &report,
        mission.display_name(),
        vehicle.name(),
        battery.name(),
        payload,
    );
    summary.air = air;
    summary.route = mission.route().clone();
    summary.planning_speed = planning_speed;
    summary.loiter = loiter;
    summary.batteries_required = sorties.batteries_required;
    summary.sorties = sorties.sorties;
    summary.failsafes = watched
        .iter()
        .zip(crossings)
        .map(|((kind, voltage_v), at)| FailsafeTime {
            kind: kind.to_string(),
            voltage_v: *voltage_v,
            time_s: at.map(|a| a.0),
            segment: at.map(|a| a.1),
            item: at.and_then(|a| summary.segments.get(a.1.wrapping_sub(1))?.item),
        })
        .collect();
    summary.warnings = compiled.warnings().to_vec();
    summary.warnings.extend(way_home_note);
    summary
        .warnings
        .extend(edge_warnings(&report, vehicle.name()));
    summary
        .warnings
        .extend(sorties.note.map(|n| format!("not split into sorties: {n}")));
    if let Some(t) = terrain {
        let least_m = options.min_clearance_m.unwrap_or(DEFAULT_MIN_CLEARANCE_M);
        judge_clearances(
            &mut summary,
            &Ground::at_home(t, mission.spec())?,
            &compiled,
            least_m,
        )?;
    }
    let summary = finite(summary, "mission", || {
        format!("mission {} with {}", mission.origin(), vehicle.name())
    })?;
    let context = PlanContext {
        origin: mission.origin().to_string(),
        description: mission.spec().description.clone(),
        battery: PackDescription::of(&battery),
        wind: wind_text,
        notes: vehicle.notes(),
        power_model: match aircraft.source() {
            aloft_planner::PowerSource::FourTerm { .. } => "four-term power model (power seed)",
            aloft_planner::PowerSource::Chain(_) => {
                "propulsion chain (propulsion seed: propeller, motor, ESC and pack per rotor)"
            }
        },
        aoa: options.aoa,
        ground_effect: options.ground_effect,
    };
    Ok(Plan {
        report,
        summary,
        context,
        compiled,
        plot_samples,
    })
}

/// The mission of a request flown over the ground of its options' terrain
/// ([`Mission::over_ground`]), with the tiles; none without terrain.
///
/// # Errors
/// A directory that cannot be read or holds no tile, no ground under the route, a mission placed
/// in metres; `min_clearance_m` not finite or negative.
pub(in crate::engine) fn over_terrain(
    mission: &Mission,
    options: &MissionOptions,
) -> Result<Option<(Mission, aloft_terrain::Terrain)>, Error> {
    if let Some(m) = options.min_clearance_m {
        if !(m.is_finite() && (0.0..=aloft_planner::mission::MAX_MISSION_VALUE).contains(&m)) {
            return Err(Error::InvalidInput {
                name: "min_clearance_m",
                value: m,
                unit: "m",
                expected: "a height above the ground, 0 or more, at most 1e7",
            });
        }
    }
    let Some(dir) = &options.terrain else {
        return Ok(None);
    };
    let terrain = aloft_terrain::Terrain::open(dir)?;
    let over = over_these_tiles(mission, options, &terrain)?;
    Ok(Some((over, terrain)))
}

/// As [`over_terrain`] with tiles already open (a caller that flies many versions of a mission,
/// as `aloft plan` its sorties, opens them once).
///
/// # Errors
/// No ground under the route, a mission placed in metres.
pub(in crate::engine) fn over_these_tiles(
    mission: &Mission,
    options: &MissionOptions,
    terrain: &aloft_terrain::Terrain,
) -> Result<Mission, Error> {
    let ground = Ground::at_home(terrain, mission.spec())?;
    mission.over_ground(&ground, options.rtl_altitude_m)
}

/// A request's flight and the mission it flies: the spec with the options applied, a loiter
/// until the reserve resolved and the way home of a mission that ends in the air added, compiled.
pub(in crate::engine) struct Prepared<'a> {
    /// What every flight of the request shares.
    pub(in crate::engine) flight: Flight<'a>,
    /// The mission flown.
    pub(in crate::engine) spec: MissionSpec,
    /// It compiled.
    pub(in crate::engine) compiled: aloft_planner::Mission,
    /// The planning speed applied, when the options or the vehicle gave one.
    pub(in crate::engine) planning_speed: Option<crate::engine::missions::flown::PlanningSpeed>,
    /// The loiter until the reserve, when the mission ends in one.
    pub(in crate::engine) loiter: Option<crate::engine::missions::loiter::LoiterSummary>,
    /// Why a way home was added, when it was.
    pub(in crate::engine) way_home_note: Option<String>,
}

/// The steps before a request's flight (see [`Prepared`]), with the aircraft, pack and wind it
/// flies.
///
/// # Errors
/// Invalid options, and a mission the planner refuses.
pub(in crate::engine) fn prepare<'a>(
    vehicle: &Vehicle,
    mission: &Mission,
    options: &MissionOptions,
    (aircraft, pack, wind): (&'a aloft_planner::Aircraft, &'a Pack, &'a Wind),
) -> Result<Prepared<'a>, Error> {
    let in_mission = |e| Error::Mission {
        origin: mission.origin().to_string(),
        vehicle: vehicle.name().to_string(),
        source: Box::new(e),
    };
    check_options(options)?;
    let flight = Flight {
        aircraft,
        pack,
        wind,
        options: planner_options(options, mission.spec(), pack)?,
        meter: options.meter.clone(),
    };
    let flown = flown_mission(&flight, mission, vehicle, (options, options.payload_kg))
        .map_err(in_mission)?;
    let compiled = flight
        .compile(&flown.spec, options.payload_kg)
        .map_err(in_mission)?;
    Ok(Prepared {
        flight,
        spec: flown.spec,
        compiled,
        planning_speed: flown.planning_speed,
        loiter: flown.loiter,
        way_home_note: flown.way_home_note,
    })
}

/// The mission a request flies, before it is compiled (see [`Prepared`]).
pub(in crate::engine) struct FlownMission {
    /// The spec flown.
    pub(in crate::engine) spec: MissionSpec,
    /// The planning speed applied, when the options or the vehicle gave one.
    pub(in crate::engine) planning_speed: Option<crate::engine::missions::flown::PlanningSpeed>,
    /// The loiter until the reserve, when the mission ends in one.
    pub(in crate::engine) loiter: Option<crate::engine::missions::loiter::LoiterSummary>,
    /// Why a way home was added, when it was.
    pub(in crate::engine) way_home_note: Option<String>,
}

/// The spec `mission` is flown as: the options applied, a loiter until the reserve resolved
/// (taking off with `payload_kg`, else the mission's payload) and the way home of a mission that
/// ends in the air added. `aloft plan` flies each file it writes so, as `aloft mission` reads it.
///
/// # Errors
/// A loiter the planner cannot fly.
pub(in crate::engine) fn flown_mission(
    flight: &Flight<'_>,
    mission: &Mission,
    vehicle: &Vehicle,
    (options, payload_kg): (&MissionOptions, Option<f64>),
) -> Result<FlownMission, aloft_planner::PlannerError> {
    let (spec, planning_speed) = flown_spec(mission, vehicle, options);
    let (spec, loiter) = match resolve_loiter(flight, &spec, payload_kg)? {
        Some((flown, loiter)) => (flown, Some(loiter)),
        None => (spec, None),
    };
    let (spec, way_home_note) = flight.home_at_mission_end(spec);
    Ok(FlownMission {
        spec,
        planning_speed,
        loiter,
        way_home_note,
    })
}

/// Fly the compiled mission, writing the files of `outputs` (removed again after a failed run)
/// and keeping a chart's samples; without outputs, the planner's report alone (with every sample
/// when the options ask).
#[allow(clippy::type_complexity)]
fn fly_into_outputs(
    flight: &Flight<'_>,
    compiled: &aloft_planner::Mission,
    (outputs, thresholds_v): (&MissionOutputs, &[f64]),
    in_mission: impl Fn(aloft_planner::PlannerError) -> Error,
) -> Result<(MissionReport, Vec<Sample>, Vec<Option<(f64, usize)>>), Error> {
    if !outputs.any() && thresholds_v.is_empty() {
        let report = flight.fly(compiled).map_err(in_mission)?;
        return Ok((report, Vec::new(), Vec::new()));
    }
    let keep_all = flight.options.record_samples;
    let mut sink = OutputSink::create(outputs, path_points(compiled), keep_all)?;
    sink.watch_voltage(thresholds_v);
    match flight.fly_into(compiled, &mut sink) {
        Ok(mut report) => {
            let crossings = sink.crossings();
            let (plot, all) = sink.finish()?;
            report.samples = all;
            Ok((report, plot, crossings))
        }
        Err(e) => {
            sink.discard();
            Err(sink.take_failure().unwrap_or_else(|| in_mission(e)))
        }
    }
}

/// The voltage failsafes a mission watches: (`low` / `critical`, pack volts), each positive and
/// finite.
pub(in crate::engine) fn failsafe_thresholds(
    options: &MissionOptions,
) -> Result<Vec<(&'static str, f64)>, Error> {
    let mut out = Vec::new();
    for (kind, name, v) in [
        ("low", "low_voltage_v", options.low_voltage_v),
        ("critical", "critical_voltage_v", options.critical_voltage_v),
    ] {
        let Some(v) = v else { continue };
        if !(v.is_finite() && v > 0.0 && v <= 1e4) {
            return Err(Error::InvalidInput {
                name,
                value: v,
                unit: "V",
                expected: "a positive pack voltage up to 10000 V",
            });
        }
        out.push((kind, v));
    }
    Ok(out)
}

/// The options' own values, before anything is flown: a planning speed and an RTL altitude are
/// positive and finite.
pub(in crate::engine) fn check_options(options: &MissionOptions) -> Result<(), Error> {
    let positive = |name: &'static str, value: Option<f64>, unit: &'static str| match value {
        Some(v)
            if !(v.is_finite() && v > 0.0 && v <= aloft_planner::mission::MAX_MISSION_VALUE) =>
        {
            Err(Error::InvalidInput {
                name,
                value: v,
                unit,
                expected: "positive and finite, at most 1e7",
            })
        }
        _ => Ok(()),
    };
    positive("speed_mps", options.speed_mps, "m/s")?;
    positive("rtl_altitude_m", options.rtl_altitude_m, "m")?;
    let start = options.start_percent;
    if !(start.is_finite() && start > 0.0 && start <= 100.0) {
        return Err(Error::InvalidInput {
            name: "start_percent",
            value: start,
            unit: "%",
            expected: "a state of charge above 0 and at most 100 %",
        });
    }
    match options.payload_kg {
        Some(p)
            if !(p.is_finite()
                && (0.0..=aloft_planner::mission::MAX_MISSION_VALUE).contains(&p)) =>
        {
            Err(Error::InvalidInput {
                name: "payload_kg",
                value: p,
                unit: "kg",
                expected: "from 0 to 1e7 kg",
            })
        }
        _ => Ok(()),
    }
}

/// The planner's options: the request's, else the mission file's, else the defaults (reserve
/// 20 %, time step 0.1 s).
pub(in crate::engine) fn planner_options(
    options: &MissionOptions,
    spec: &MissionSpec,
    pack: &Pack,
) -> Result<PlanOptions, Error> {
    let reserve_percent = options
        .reserve_percent
        .or(spec.reserve_percent)
        .unwrap_or(20.0);
    if !(0.0..100.0).contains(&reserve_percent) {
        return Err(Error::InvalidInput {
            name: "reserve_percent",
            value: reserve_percent,
            unit: "%",
            expected: "a percentage in [0, 100)",
        });
    }
    Ok(PlanOptions {
        time_step_s: options.time_step_s.or(spec.time_step_s).unwrap_or(0.1),
        aoa: options.aoa,
        ground_effect: options.ground_effect,
        reserve_fraction: reserve_percent / 100.0,
        start_soc: start_soc(options, pack)?,
        record_samples: options.record_samples,
        ..PlanOptions::default()
    })
}

/// How far a rested cell voltage may lie outside the pack's open-circuit curve and still be
/// this pack's, V (a cell just off the charger, a sensor's calibration).
const REST_MARGIN_CELL_V: f64 = 0.05;

/// The state of charge at take-off: `start_voltage_v` on the pack's open-circuit curve where
/// given, else `start_percent`.
///
/// # Errors
/// A rested voltage that is not this pack's (outside its curve by more than
/// [`REST_MARGIN_CELL_V`] a cell), or given with a `start_percent` other than 100.
pub(in crate::engine) fn start_soc(options: &MissionOptions, pack: &Pack) -> Result<f64, Error> {
    let Some(v) = options.start_voltage_v else {
        return Ok(options.start_percent / 100.0);
    };
    if (options.start_percent - 100.0).abs() > 1e-9 {
        return Err(Error::InvalidInput {
            name: "start_voltage_v",
            value: v,
            unit: "V",
            expected: "either a rested voltage or a start percent, not both",
        });
    }
    let margin_v = REST_MARGIN_CELL_V * f64::from(pack.cells_series());
    let (empty_v, full_v) = (pack.ocv_v(0.0) - margin_v, pack.ocv_v(1.0) + margin_v);
    if !(v.is_finite() && (empty_v..=full_v).contains(&v)) {
        return Err(Error::InvalidInput {
            name: "start_voltage_v",
            value: v,
            unit: "V",
            expected: "a rested voltage of the pack flown, on its open-circuit curve",
        });
    }
    // At least a tenth of a per cent: the planner starts from a charge.
    Ok(pack.soc_at_ocv_v(v).max(0.001))
}

/// The clearances of `compiled` written into `summary`: each segment's least height above the
/// ground and where, the mission's least over the segments judged, and an infeasible answer
/// naming the first judged segment closer to the ground than `min_clearance_m`.
///
/// # Errors
/// The tiles' (no tile or a void under the route).
fn judge_clearances(
    summary: &mut MissionSummary,
    ground: &Ground<'_>,
    compiled: &aloft_planner::Mission,
    min_clearance_m: f64,
) -> Result<(), Error> {
    // The whole planned route is judged, also past where a pack that falls short stops (the
    // answer's segments end there).
    let kinds = compiled.segment_kinds();
    let items = compiled.segment_items();
    let paths = crate::engine::missions::mission_outputs::segment_paths(compiled);
    let clearances = ground.clearances(&paths, compiled.home_m(), kinds.len())?;
    let mut least: Option<f64> = None;
    let mut first_too_close = None;
    for (k, c) in clearances.into_iter().enumerate() {
        let Some(c) = c else { continue };
        if let Some(s) = summary.segments.iter_mut().find(|s| s.index == k + 1) {
            s.min_clearance_m = Some(c.clearance_m);
            s.min_clearance_at = Some(c.at);
        }
        let kind = kinds.get(k).copied().unwrap_or("segment");
        if !crate::engine::missions::ground::judged(kind, kinds.get(k + 1).copied()) {
            continue;
        }
        least = Some(least.map_or(c.clearance_m, |l: f64| l.min(c.clearance_m)));
        if c.clearance_m < min_clearance_m && first_too_close.is_none() {
            let item = items.get(k).copied().flatten();
            first_too_close = Some((k + 1, item, kind.to_string(), c));
        }
    }
    summary.min_clearance_m = least;
    if let Some((index, item, kind, c)) = first_too_close {
        let name = match item {
            Some(i) => format!("segment {index} (item {i}, {kind})"),
            None => format!("segment {index} ({kind})"),
        };
        let why = format!(
            "{name} passes {:.1} m above the ground at {:.5}, {:.5}: closer than the least \
             clearance of {min_clearance_m} m",
            c.clearance_m, c.at.latitude_deg, c.at.longitude_deg
        );
        summary.reason = Some(match summary.reason.take() {
            Some(energy) => format!("{why}; and {energy}"),
            None => why,
        });
        summary.feasible = false;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{endurance, EnduranceOptions, FlightState, SourceFormat};
    use crate::engine::{DEMO_MISSION, DEMO_ORIGIN};

    #[test]
    fn demo_mission_parses() {
        let m = MissionSpec::from_toml_str(DEMO_MISSION).unwrap();
        assert!(!m.segments.is_empty());
        assert_eq!(Mission::demo().display_name(), "demo-survey");
    }

    #[test]
    fn mission_json_round_trips_to_the_same_plan() {
        let v = Vehicle::builtin("dji-m100").unwrap();
        let demo = Mission::demo();
        let again = Mission::from_text(&demo.to_json().unwrap(), DEMO_ORIGIN).unwrap();
        assert_eq!(demo.spec(), again.spec());
        assert_eq!(again.route().source_format, SourceFormat::AloftJson);
        let a = plan_mission(&v, &demo, &MissionOptions::default()).unwrap();
        let b = plan_mission(&v, &again, &MissionOptions::default()).unwrap();
        // The same answer but for the format the route was read from.
        let mut read_back = b.summary().clone();
        read_back.route.source_format = SourceFormat::AloftToml;
        assert_eq!(a.summary(), &read_back);
    }

    #[test]
    fn summary_json_reads_back() {
        let v = Vehicle::builtin("dji-m100").unwrap();
        let p = plan_mission(&v, &Mission::demo(), &MissionOptions::default()).unwrap();
        let back: MissionSummary = serde_json::from_str(&p.to_json().unwrap()).unwrap();
        assert_eq!(&back, p.summary());
    }

    #[test]
    fn remaining_is_the_whole_mission_at_zero_and_nothing_at_the_end() {
        let v = Vehicle::builtin("dji-m100").unwrap();
        let opts = MissionOptions {
            record_samples: true,
            ..MissionOptions::default()
        };
        let p = plan_mission(&v, &Mission::demo(), &opts).unwrap();
        let all = p.remaining(0.0).unwrap();
        // Trapezoid over 0.1 s samples against the planner's own integration: 0.5 % covers the
        // first half-step and the quadrature difference.
        assert!(
            (all.energy_wh / p.energy_wh() - 1.0).abs() < 5e-3,
            "{all:?}"
        );
        let s = &p.report().start_soc;
        assert!((all.soc_used - (s - p.summary().end_soc)).abs() < 5e-3);
        let half = p.remaining(p.summary().duration_s / 2.0).unwrap();
        assert!(half.energy_wh > 0.2 * all.energy_wh && half.energy_wh < 0.8 * all.energy_wh);
        let none = p.remaining(1e9).unwrap();
        assert!(none.energy_wh.abs() < 1e-12);
        assert!(p.remaining(f64::NAN).is_err());
        let unrecorded = plan_mission(&v, &Mission::demo(), &MissionOptions::default()).unwrap();
        assert!(unrecorded.remaining(1.0).is_err());
    }

    #[test]
    fn bad_inputs_are_errors() {
        assert!(matches!(
            Vehicle::builtin("nope"),
            Err(Error::UnknownVehicle { .. })
        ));
        assert!(matches!(
            Vehicle::from_toml("name = ", "t"),
            Err(Error::VehicleFormat { .. })
        ));
        assert!(matches!(
            Mission::from_text("{\"segment\": 3}", "t"),
            Err(Error::MissionFormat { .. })
        ));
        assert!(matches!(
            Mission::from_text("[[segment]]\nkind = 1", "t"),
            Err(Error::MissionFormat { .. })
        ));
        assert!(MissionOptions::from_json("{\"bogus\": 1}").is_err());
        let v = Vehicle::builtin("dji-m100").unwrap();
        let bad = MissionOptions {
            reserve_percent: Some(120.0),
            ..Default::default()
        };
        assert!(plan_mission(&v, &Mission::demo(), &bad).is_err());
        let heavy = MissionOptions {
            payload_kg: Some(50.0),
            ..Default::default()
        };
        assert!(matches!(
            plan_mission(&v, &Mission::demo(), &heavy),
            Err(Error::Mission { .. })
        ));
        let e = EnduranceOptions {
            payload_kg: f64::NAN,
            ..Default::default()
        };
        assert!(endurance(&v, &e).is_err());
        assert!(v.power(&FlightState::new(f64::NAN, 0.0, 0.0, 0.0)).is_err());
    }
}
