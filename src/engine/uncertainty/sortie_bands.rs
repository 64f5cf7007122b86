//! How a plan's sorties land in the day's scenarios (`aloft plan --confidence`): each sortie's
//! mission flown in the scenarios of [`crate::engine::uncertainty::scenarios`] (the wind's speed
//! and direction drawn around the forecast, the model's power error, the pack's capacity, the
//! payload), its landing charge's percentiles and the share that lands with the reserve.
//!
//! Every sortie of a plan is flown in the same draws (scenario `i` is the same day for each: a
//! forecast that is off is off for the whole campaign), so that the cut of one sortie does not
//! change another's draws. The point of no return is not computed in the scenarios (only the
//! landing counts), which makes each flight about a third cheaper than the plan's own.

use std::borrow::Cow;

use aloft_planner::percentiles::reached_by;
use aloft_planner::{Aircraft, MissionSpec, NoSamples, Pack, Percentiles, PlanOptions, Shortfall};

use crate::engine::missions::flight::Flight;
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_options::MissionOptions;
use crate::engine::missions::sorties::{LandingBand, SortieCheck};
use crate::engine::uncertainty::scenarios::{
    cannot_fly, run_indexed, scaled_models, Draws, ScenarioOptions, Winds,
};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// The largest sampling step of the scenarios' flights, s (the plan's own when it is longer): on
/// the cut sorties of a 38 km survey the landing charge at 0.5 s differs from the one at the
/// plan's 0.1 s by 2e-5 of the capacity in the median and 1.4e-4 at the 5th percentile, for a
/// fifth of the steps.
const SCENARIO_TIME_STEP_S: f64 = 0.5;

/// The margin a scenario the vehicle cannot fly counts as (a take-off mass beyond its limit, a
/// wind it cannot make headway in, a power its pack cannot give), a fraction of the capacity:
/// below any other, and no margin of charge makes up for it.
const CANNOT_FLY: f64 = -1.0;

/// The scenarios of a plan's sorties and the confidence they are cut at.
pub(in crate::engine) struct SortieScenarios<'a> {
    aircraft: &'a Aircraft,
    pack: &'a Pack,
    options: PlanOptions,
    winds: Winds,
    scenarios: ScenarioOptions,
    confidence: f64,
}

impl<'a> SortieScenarios<'a> {
    /// The scenarios of `scenarios` around the request's conditions (`options`, the mission's
    /// wind where they give none), flown by `flight`'s aircraft and pack with its options.
    ///
    /// # Errors
    /// Invalid scenario options; wind spreads with a gridded wind field.
    pub(in crate::engine) fn new(
        (vehicle, mission, options): (&Vehicle, &Mission, &MissionOptions),
        flight: &Flight<'a>,
        scenarios: &ScenarioOptions,
        confidence: f64,
    ) -> Result<Self, Error> {
        scenarios.check()?;
        let winds = Winds::new(vehicle, mission, options, scenarios)?;
        Ok(Self {
            aircraft: flight.aircraft,
            pack: flight.pack,
            options: PlanOptions {
                point_of_no_return: false,
                second_thread: false,
                time_step_s: flight.options.time_step_s.max(SCENARIO_TIME_STEP_S),
                ..flight.options
            },
            winds,
            scenarios: scenarios.clone(),
            confidence,
        })
    }

    /// Scenario `index` of `spec`: whether it lands with the reserve, its landing charge when it
    /// lands, and its margin over the reserve (a fraction of the usable capacity: the charge left
    /// above the reserve, negative below; a flight that runs its pack empty counts as landing
    /// empty, less than the charge it lacked; [`CANNOT_FLY`] when it cannot be flown).
    fn fly(&self, spec: &MissionSpec, index: usize) -> Result<(bool, Option<f64>, f64), Error> {
        let sc = &self.scenarios;
        let d = Draws::of(sc.seed, index);
        let (aircraft, pack): (Cow<'_, Aircraft>, Cow<'_, Pack>) =
            scaled_models(self.aircraft, self.pack, sc, &d)?;
        let wind = self.winds.of(sc, &d)?;
        let payload_kg = (sc.payload_sd_kg > 0.0)
            .then(|| (spec.payload_kg + sc.payload_sd_kg * d.payload).max(0.0));
        let flight = Flight {
            aircraft: &aircraft,
            pack: &pack,
            wind: &wind,
            options: self.options,
            meter: None,
        };
        let flown = flight
            .compile(spec, payload_kg)
            .and_then(|c| flight.fly_into(&c, &mut NoSamples));
        match flown {
            Ok(r) => {
                let landed = matches!(r.shortfall, None | Some(Shortfall::Reserve { .. }));
                let usable = (1.0 - r.empty_soc).max(f64::MIN_POSITIVE);
                // A flight that stops where it cannot make headway, or whose pack cannot give
                // the power, did not land whatever charge it kept.
                let margin = match r.shortfall {
                    Some(Shortfall::NoProgress(_) | Shortfall::PackLimit { .. }) => CANNOT_FLY,
                    _ => (r.reserve_soc.max(0.0) - r.required_reserve_soc) / usable,
                };
                Ok((r.feasible, landed.then_some(r.end_soc), margin))
            }
            Err(e) if cannot_fly(&e) => Ok((false, None, CANNOT_FLY)),
            Err(e) => Err(Error::NoPlan {
                reason: format!("a sortie's scenarios cannot be flown: {e}"),
            }),
        }
    }
}

impl SortieCheck for SortieScenarios<'_> {
    fn confidence(&self) -> f64 {
        self.confidence
    }

    fn band(&self, spec: &MissionSpec) -> Result<LandingBand, String> {
        let sc = &self.scenarios;
        let n = sc.samples as usize;
        let (records, _) = run_indexed(
            n,
            (sc.thread_count(n), &sc.bounds),
            || (),
            |i, _| self.fly(spec, i),
        )
        .map_err(|e| e.to_string())?;
        let held = records.iter().filter(|r| r.0).count();
        let stuck = records.iter().filter(|r| r.2 == CANNOT_FLY).count();
        let mut landed: Vec<f64> = records.iter().filter_map(|r| r.1).collect();
        let mut margins: Vec<f64> = records.iter().map(|r| r.2).collect();
        margins.sort_by(f64::total_cmp);
        Ok(LandingBand {
            landing_soc: Percentiles::of(&mut landed),
            p_reserve: held as f64 / n.max(1) as f64,
            margin_reached: reached_by(&margins, self.confidence.max(0.5)),
            cannot_fly: stuck as f64 / n.max(1) as f64,
        })
    }
}
