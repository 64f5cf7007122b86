//! Batteries and sorties: a route that one pack cannot fly is split into sorties, each flown on a
//! fresh pack from home and back with the reserve (a battery swap at home), as QGroundControl's
//! "batteries required", but from the energy of each sortie in the wind rather than a constant
//! current.
//!
//! The route is the mission between its first take-off and its final way down (a return, the
//! descents and the landing). A sortie after the first takes off at home to the height where the
//! last one left the route, flies straight there, flies on along the route and comes home (a
//! return at the planning speed and RTL altitude, a landing); the last sortie flies the mission's
//! own way down. The sorties are found greedily, each as long as it can be:
//!
//! 1. fly the rest of the route from the sortie's start to the mission's end; when it lands with
//!    the reserve, it is the last sortie;
//! 2. otherwise its point of no return (the last point from which a straight return lands with the
//!    reserve) bounds the sortie: the candidate end is the last segment completed before it, in
//!    the air;
//! 3. the sortie to that end, with its way home, is flown; while it does not land with the
//!    reserve (its return is the mission's, not the point of no return's best-range one), the
//!    end is searched by bisection among the earlier segments;
//! 4. with [`SplitOptions::inside_legs`] (`aloft plan`), the sortie then goes on into the next
//!    segment when it is a leg: the farthest point along it from which the sortie still lands
//!    with the reserve, found by bisection to a metre, ends it (a waypoint is added there), so
//!    that a pack is used to the reserve rather than to the last whole item;
//! 5. with [`SplitOptions::overlap_m`], the next sortie resumes that far back along the route's
//!    legs (it re-flies the stretch, as an operator resuming a survey a few waypoints back does
//!    for the images' overlap), never before where the sortie it follows began.
//!
//! The route's geometry (where a sortie may end, the mission a sortie flies, how far back the
//! next resumes) and the searches are [`aloft_planner::sorties`]'s; here are the steps, each trial a
//! flight on the pack. Each sortie's answer is its own flight: energy, end state of charge,
//! duration.

use serde::{Deserialize, Serialize};

use aloft_planner::sorties::{farthest_fraction, last_that_holds};
pub(in crate::engine) use aloft_planner::sorties::{segment_ends_m, Cut, Route};
use aloft_planner::{Mission as Compiled, MissionReport, MissionSpec, Percentiles, SegmentSpec};

use crate::engine::missions::flight::Flight;

/// Most sorties aloft splits a route into: beyond it, the answer says the route needs more. A
/// route of more than 200 packs is a campaign, not a mission, and the bound keeps the search
/// (two to a dozen trial flights of one pack each per sortie) near a second of CPU for the
/// longest routes aloft reads (20,000 flown items; the fuzz harness found a 585-byte `.waypoints`
/// whose jump repeats a climb 2,000 times, 501 sorties at 1,000 repeats, taking 3.2 s with the
/// earlier bound of 1,000).
pub const MAX_SORTIES: usize = 200;

/// One sortie of a route flown on several packs (in the answer's `sorties`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SortieSummary {
    /// The first mission item of the route it flies (from a planner file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_item: Option<u32>,
    /// The last mission item of the route it flies (from a planner file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub last_item: Option<u32>,
    /// The first segment of the mission it flies, from 1.
    pub first_segment: usize,
    /// The last segment of the mission it flies, from 1.
    pub last_segment: usize,
    /// Flight time, take-off to landing, s.
    pub duration_s: f64,
    /// Electrical energy drawn from its pack, Wh.
    pub energy_wh: f64,
    /// State of charge of its pack at landing.
    pub end_soc: f64,
}

/// How many packs a route takes and its sorties.
#[derive(Debug, Clone, PartialEq, Default)]
pub(in crate::engine) struct Sorties {
    /// Packs the route takes, when it can be split (the sorties' count).
    pub(in crate::engine) batteries_required: Option<u32>,
    /// The sorties, when more than one.
    pub(in crate::engine) sorties: Vec<SortieSummary>,
    /// Why the route was not split, when it was not.
    pub(in crate::engine) note: Option<String>,
}

/// How sorties are cut: at whole segments (`aloft mission`), or inside legs with an overlap
/// (`aloft plan`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(in crate::engine) struct SplitOptions {
    /// End a sortie inside a leg when the pack allows part of it (module step 4).
    pub(in crate::engine) inside_legs: bool,
    /// How far back along the route's legs the next sortie resumes, m (module step 5).
    pub(in crate::engine) overlap_m: f64,
}

/// One sortie: where it resumes the route (`None`: the mission's own start), where it leaves it
/// (`None`: the mission's own end), its mission and its flight.
#[derive(Debug, Clone)]
pub(in crate::engine) struct SortiePlan {
    /// The point it flies to after its take-off (the last one's end, less the overlap).
    pub(in crate::engine) start: Option<Cut>,
    /// The point it turns home at.
    pub(in crate::engine) end: Option<Cut>,
    /// Its mission: take-off, transit, route, way home.
    pub(in crate::engine) spec: MissionSpec,
    /// Its flight.
    pub(in crate::engine) report: MissionReport,
    /// The mission's segments it flies, whole or in part (the first sortie's take-off and the
    /// last one's way down included).
    pub(in crate::engine) route: std::ops::Range<usize>,
    /// How it lands in the scenarios of the day, when a [`SortieCheck`] cut it.
    pub(in crate::engine) band: Option<LandingBand>,
    /// The margin it was cut with above the reserve, a share of the usable capacity.
    pub(in crate::engine) margin: f64,
}

/// How a sortie lands in the scenarios of the day (`aloft plan --confidence`).
#[derive(Debug, Clone, PartialEq)]
pub(in crate::engine) struct LandingBand {
    /// Its pack's state of charge at landing over the scenarios flown to the end (absent when
    /// none was).
    pub(in crate::engine) landing_soc: Option<Percentiles>,
    /// The share of the scenarios that land with the reserve.
    pub(in crate::engine) p_reserve: f64,
    /// The reserve's margin that the share [`SortieCheck::confidence`] of the scenarios reach
    /// or exceed, a fraction of the capacity (the charge left above the reserve at landing; a
    /// scenario that does not finish counts as far below): at or above 0 the sortie holds.
    pub(in crate::engine) margin_reached: f64,
    /// The share of the scenarios the vehicle cannot fly at all (beyond its envelope, its pack's
    /// power), which no margin of charge makes up for.
    pub(in crate::engine) cannot_fly: f64,
}

/// What cuts sorties at a confidence: the band of a sortie's mission over the day's scenarios.
pub(in crate::engine) trait SortieCheck: Sync {
    /// The share of the scenarios that must land with the reserve (0.5 or less: the nominal cut,
    /// the bands only reported).
    fn confidence(&self) -> f64;

    /// The band of `spec` flown in every scenario.
    ///
    /// # Errors
    /// Why the scenarios cannot be flown (a request wrong whatever is drawn).
    fn band(&self, spec: &MissionSpec) -> Result<LandingBand, String>;
}

/// Most times one sortie is cut again with a new margin before the plan says it cannot reach its
/// confidence: the margin a cut needs changes little with where it ends (the same legs, the
/// same wind), so the second or third cut holds.
const MAX_MARGIN_ROUNDS: usize = 6;

/// A margin this far above what the confidence asks is taken back (the cut moved on): the
/// sorties are cut to within this much of the band's edge, a fraction of the capacity.
const MARGIN_TOLERANCE: f64 = 0.01;

/// Added to each raise of the margin, a fraction of the capacity: the next cut lands a little
/// above the band's edge rather than on it.
const MARGIN_STEP: f64 = 0.002;

/// The sorties of `spec` (compiled as `compiled`), a mission one pack cannot fly; a route that
/// cannot be split says why (a sortie that cannot be compiled or flown is one that cannot be
/// flown).
pub(in crate::engine) fn split(
    flight: &Flight<'_>,
    spec: &MissionSpec,
    compiled: &Compiled,
) -> Sorties {
    let route = match Route::of(spec, compiled) {
        Ok(r) => r,
        Err(why) => return unsplit(why),
    };
    let maker = SpecSorties {
        route: &route,
        flight,
        fly_out: None,
    };
    match sortie_plans(flight, &route, SplitOptions::default(), &maker) {
        Ok(plans) => {
            let mut sorties: Vec<SortieSummary> =
                plans.iter().map(|p| summary(&route, p)).collect();
            let batteries_required = u32::try_from(sorties.len()).ok();
            if sorties.len() == 1 {
                sorties.clear();
            }
            Sorties {
                batteries_required,
                sorties,
                note: None,
            }
        }
        Err(why) => unsplit(why),
    }
}

/// What a sortie's mission is, from where it resumes the route to where it leaves it: aloft's
/// own segments ([`Route::sortie`]), or the items of a planner file as `aloft mission` reads them
/// back. The route is cut the same way whatever the maker.
pub(in crate::engine) trait SortieMaker {
    /// The mission flown from `start` (`None`: the mission's own start) to `end` (`None`: its
    /// own end and way down).
    ///
    /// # Errors
    /// Why that sortie cannot be made (a file it cannot write or read back).
    fn sortie(&self, start: Option<Cut>, end: Option<Cut>) -> Result<MissionSpec, String>;
}

/// The ground speed of a sortie's fly-out from home to where it resumes the route (`aloft
/// plan`: the speed of least energy in its wind); `None` flies it at the planning speed.
pub(in crate::engine) trait FlyOutSpeed: Sync {
    /// The fly-out's ground speed to `point_m` (ENU m, home's frame), m/s.
    fn speed_mps(&self, point_m: [f64; 3]) -> Option<f64>;
}

/// The sorties' missions as aloft's own segments.
pub(in crate::engine) struct SpecSorties<'r, 'f> {
    /// The route cut.
    pub(in crate::engine) route: &'r Route<'r>,
    /// What every flight shares (the way home's speed and landing).
    pub(in crate::engine) flight: &'r Flight<'f>,
    /// The fly-out's speed, when aloft chooses it.
    pub(in crate::engine) fly_out: Option<&'r dyn FlyOutSpeed>,
}

impl SortieMaker for SpecSorties<'_, '_> {
    fn sortie(&self, start: Option<Cut>, end: Option<Cut>) -> Result<MissionSpec, String> {
        let way_home = self.flight.way_home(self.route.spec());
        let fly_out_mps = start
            .zip(self.fly_out)
            .and_then(|(c, f)| f.speed_mps(self.route.point_m(c)));
        Ok(self
            .route
            .sortie_flying_out(start, end, way_home, fly_out_mps))
    }
}

/// The sorties of `route` cut as `options` say, each with its mission (made by `maker`) and its
/// flight; or why the route cannot be split.
pub(in crate::engine) fn sortie_plans(
    flight: &Flight<'_>,
    route: &Route<'_>,
    options: SplitOptions,
    maker: &dyn SortieMaker,
) -> Result<Vec<SortiePlan>, String> {
    confident_sortie_plans(flight, route, options, maker, (None, Margins::Nominal))
}

/// How the margins of [`confident_sortie_plans`] are set: the reserve each sortie is cut with
/// is the request's plus its margin (a share of the usable capacity).
#[derive(Debug, Clone, Copy)]
pub(in crate::engine) enum Margins<'a> {
    /// None: the nominal cut (the bands reported when there is a check).
    Nominal,
    /// Searched for each sortie until the check's confidence holds.
    Searched,
    /// Given for each sortie in order but the last, whose margin is searched, each sortie
    /// checked: a route that takes more sorties than given, or a sortie that does not hold, is
    /// refused.
    Given(&'a [f64]),
}

/// The sorties of `route` as [`sortie_plans`] cuts them with the reserve raised by a margin
/// (`margins`), each sortie's landing band from `check` when given (module step 6).
///
/// [`Margins::Searched`]: a sortie is cut with a margin (the last sortie's to begin with), its
/// band taken, and the margin raised by what the band lacks (or lowered by what it holds beyond
/// [`MARGIN_TOLERANCE`]) until the share [`SortieCheck::confidence`] of the scenarios lands it
/// with the reserve: the margin a cut needs changes little with where it ends, so the second or
/// third cut holds; where a cut crosses a turn and the band jumps, the margin is halved between
/// the highest that failed and the lowest that held. The sortie that holds with the least margin
/// is kept.
///
/// # Errors
/// Why the route cannot be split, or not at that confidence (or with the margins given).
pub(in crate::engine) fn confident_sortie_plans(
    flight: &Flight<'_>,
    route: &Route<'_>,
    options: SplitOptions,
    maker: &dyn SortieMaker,
    (check, margins): (Option<&dyn SortieCheck>, Margins<'_>),
) -> Result<Vec<SortiePlan>, String> {
    if options.inside_legs {
        within_reach(flight, route)?;
    }
    let mut plans: Vec<SortiePlan> = Vec::new();
    let mut start: Option<Cut> = None;
    let mut margin = 0.0;
    loop {
        if plans.len() == MAX_SORTIES {
            return Err(format!("the route takes more than {MAX_SORTIES} sorties"));
        }
        let trials = Trials {
            flight,
            route,
            options,
            maker,
            start,
        };
        let plan = match (check, margins) {
            (Some(check), Margins::Searched) if check.confidence() > 0.5 => {
                let plan = trials.searched(check, margin)?;
                margin = plan.margin;
                plan
            }
            (_, Margins::Given(given)) if plans.len() >= given.len() => {
                return Err(format!("the route takes more than {} sorties", given.len()));
            }
            // The last sortie given flies the rest of the route when that holds: its margin is
            // searched, as its band is narrower than the others' (a shorter flight).
            (Some(check), Margins::Given(given)) if plans.len() + 1 == given.len() => {
                trials.searched(check, 0.0)?
            }
            (_, Margins::Given(given)) => {
                let plan = trials.cut(given[plans.len()], check)?;
                if plan.band.as_ref().is_some_and(|b| b.margin_reached < 0.0) {
                    return Err(format!("sortie {} does not hold", plans.len() + 1));
                }
                plan
            }
            (check, _) => trials.cut(0.0, check)?,
        };
        let end = plan.end;
        plans.push(plan);
        match end {
            None => return Ok(plans),
            Some(end) => start = Some(route.back_along(end, options.overlap_m, start)),
        }
    }
}

/// The trials of one sortie from `start`.
struct Trials<'t, 'f> {
    flight: &'t Flight<'f>,
    route: &'t Route<'t>,
    options: SplitOptions,
    maker: &'t dyn SortieMaker,
    start: Option<Cut>,
}

impl Trials<'_, '_> {
    /// The sortie cut with the reserve raised by `margin`, with its band when there is a check.
    fn cut(&self, margin: f64, check: Option<&dyn SortieCheck>) -> Result<SortiePlan, String> {
        let raised = self
            .flight
            .with_reserve(self.flight.options.reserve_fraction + margin);
        let mut plan = next_sortie(&raised, self.route, self.options, self.maker, self.start)?;
        plan.margin = margin;
        if let Some(check) = check {
            plan.band = Some(check.band(&plan.spec)?);
        }
        Ok(plan)
    }

    /// The sortie cut with the least margin found that holds at `check`'s confidence, the search
    /// starting from `margin` ([`Margins::Searched`]).
    fn searched(&self, check: &dyn SortieCheck, mut margin: f64) -> Result<SortiePlan, String> {
        let reserve = self.flight.options.reserve_fraction;
        // The highest margin that failed, and the sortie that held with the least.
        let mut failed: Option<f64> = None;
        let mut held: Option<SortiePlan> = None;
        // The margin the last band asked for, and the share it could not fly at all.
        let mut asked = margin;
        let mut cannot_fly = 0.0;
        for _ in 0..MAX_MARGIN_ROUNDS {
            // No end lands with the reserve raised so far: the one that held is kept, if any.
            let Ok(plan) = self.cut(margin, Some(check)) else {
                break;
            };
            let reached = plan.band.as_ref().map_or(-1.0, |b| b.margin_reached);
            asked = margin - reached;
            cannot_fly = plan.band.as_ref().map_or(0.0, |b| b.cannot_fly);
            let holds = reached >= 0.0;
            // The last sortie is not cut: any margin it lands with is kept.
            let done = holds && (plan.end.is_none() || reached <= MARGIN_TOLERANCE);
            match holds {
                true if held.as_ref().is_none_or(|h| margin < h.margin) => held = Some(plan),
                true => {}
                false => failed = Some(failed.map_or(margin, |f| f.max(margin))),
            }
            if done {
                break;
            }
            // What the band lacks (or holds beyond what it asks), kept between the margins
            // tried when it would leave them.
            let mut next = (margin - reached + MARGIN_STEP).max(0.0);
            if let (Some(lo), Some(hi)) = (failed, held.as_ref().map(|h| h.margin)) {
                if hi - lo < MARGIN_STEP {
                    break;
                }
                if !(lo < next && next < hi) {
                    next = 0.5 * (lo + hi);
                }
            }
            if reserve + next >= MAX_RESERVE {
                break;
            }
            margin = next;
        }
        held.ok_or_else(|| {
            let c = check.confidence();
            if cannot_fly > 1.0 - c {
                return format!(
                    "{} at a confidence of {} %: in {:.1} % of the day's scenarios the vehicle \
                     cannot fly it at all (a wind beyond its envelope, a power beyond its pack), \
                     which no margin of charge makes up for",
                    self.route.cannot_fly(self.start),
                    100.0 * c,
                    100.0 * cannot_fly
                );
            }
            format!(
                "{} at a confidence of {} %: in the day's scenarios it needs a margin of {:.0} % \
                 of the usable capacity above the {:.0} % reserve (a lower --confidence, narrower \
                 spreads or a lower reserve ask less)",
                self.route.cannot_fly(self.start),
                100.0 * check.confidence(),
                100.0 * asked,
                100.0 * reserve
            )
        })
    }
}

/// The highest reserve a margin raises the cut to, a fraction of the capacity: beyond it no
/// sortie is worth flying.
const MAX_RESERVE: f64 = 0.95;

/// The sortie from `start` as the greedy cut finds it (the module's steps 1-4) with `flight`'s
/// reserve: the rest of the route when it lands with the reserve, else the farthest end.
fn next_sortie(
    flight: &Flight<'_>,
    route: &Route<'_>,
    options: SplitOptions,
    maker: &dyn SortieMaker,
    start: Option<Cut>,
) -> Result<SortiePlan, String> {
    let spec = maker.sortie(start, None)?;
    let rest = flight
        .trial(&spec, None)
        .map_err(|e| format!("a sortie cannot be flown: {e}"))?;
    let from = start.map_or(0, |_| route.resumes_at(start));
    if rest.feasible {
        return Ok(SortiePlan {
            start,
            end: None,
            spec,
            report: rest,
            route: from..route.spec().segments.len(),
            band: None,
            margin: 0.0,
        });
    }
    let found = match options.inside_legs {
        true => farthest_end(flight, route, maker, start),
        false => whole_end(flight, route, maker, (start, &rest)),
    };
    let Some((end, spec, report)) = found else {
        return Err(route.cannot_fly(start));
    };
    Ok(SortiePlan {
        start,
        end: Some(end),
        spec,
        report,
        route: from..end.segment + 1,
        band: None,
        margin: 0.0,
    })
}

impl Sorties {
    /// The answer for a mission not split: one pack when it can fly it, else none known (a
    /// mission that ends in the air is not split).
    pub(in crate::engine) fn one(feasible: bool) -> Self {
        Self {
            batteries_required: feasible.then_some(1),
            ..Self::default()
        }
    }
}

fn unsplit(why: String) -> Sorties {
    Sorties {
        batteries_required: None,
        sorties: Vec::new(),
        note: Some(why),
    }
}

/// A sortie's end, its mission and its flight.
type Ending = (Cut, MissionSpec, MissionReport);

/// The farthest point a sortie from `start` can turn home at (module step 4): the last whole
/// segment of the route it can end with, by bisection, then the farthest point along the next
/// one when it is a leg; with its mission and its flight.
fn farthest_end(
    flight: &Flight<'_>,
    route: &Route<'_>,
    maker: &dyn SortieMaker,
    start: Option<Cut>,
) -> Option<Ending> {
    let try_end = |cut: Cut| {
        let spec = maker.sortie(start, Some(cut)).ok()?;
        let report = flight.trial(&spec, None).ok().filter(|r| r.feasible)?;
        Some((cut, spec, report))
    };
    let ends = route.ends_from(start);
    let best = last_that_holds(ends.len(), |k| try_end(Cut::whole(ends[k])));
    let next = best
        .as_ref()
        .map_or(route.resumes_at(start), |(c, _, _)| c.segment + 1);
    let length_m = route.leg_length_m(next);
    let from = match start {
        Some(c) if c.segment == next => c.fraction,
        _ => 0.0,
    };
    let partial = length_m.and_then(|length_m| {
        farthest_fraction(from, length_m, |fraction| {
            try_end(Cut {
                segment: next,
                fraction,
            })
        })
    });
    partial.or(best)
}

/// The last whole segment a sortie from `start` can end with (module steps 2 and 3).
fn whole_end(
    flight: &Flight<'_>,
    route: &Route<'_>,
    maker: &dyn SortieMaker,
    (start, rest): (Option<Cut>, &MissionReport),
) -> Option<Ending> {
    // Without a point of no return (every straight return held, yet the mission's own way down
    // lands short), every segment of the route is a candidate.
    let limit_s = rest.point_of_no_return.map_or(f64::INFINITY, |p| p.time_s);
    let ends = route.ends_before(start, rest, limit_s);
    // A sortie that cannot be compiled (a transit beyond a limit) is one that cannot be flown.
    let try_end = |end: usize| {
        let cut = Cut::whole(end);
        let spec = maker.sortie(start, Some(cut)).ok()?;
        let report = flight.trial(&spec, None).ok().filter(|r| r.feasible)?;
        Some((cut, spec, report))
    };
    // The candidate first, then bisection among the earlier ends (fewer segments, less energy
    // before the return); the candidate, ends[n - 1], fails.
    let &candidate = ends.last()?;
    try_end(candidate).or_else(|| last_that_holds(ends.len() - 1, |k| try_end(ends[k])))
}

/// Whether a pack can fly to the route's farthest point from home and back (a sortie that only
/// goes there): when it cannot, no way of cutting the route keeps the reserve, and the sorties
/// cut inside legs would otherwise creep toward that point by ever shorter steps.
///
/// # Errors
/// The farthest point and its item (or segment), when it is out of reach.
fn within_reach(flight: &Flight<'_>, route: &Route<'_>) -> Result<(), String> {
    let Some(far) = route.farthest_segment() else {
        return Ok(());
    };
    let spec = route.there_and_back(far, flight.way_home(route.spec()));
    match flight.trial(&spec, None).is_ok_and(|r| r.feasible) {
        true => Ok(()),
        false => Err(route.out_of_reach(far)),
    }
}

/// The answer of a sortie of `route`.
fn summary(route: &Route<'_>, plan: &SortiePlan) -> SortieSummary {
    let segments = &route.spec().segments;
    let first = match plan.start {
        None => 0,
        Some(_) => route.resumes_at(plan.start),
    };
    let last = plan.end.map_or(segments.len() - 1, |c| c.segment);
    let report = &plan.report;
    SortieSummary {
        first_item: segments[first..=last].iter().find_map(SegmentSpec::item),
        last_item: segments[first..=last]
            .iter()
            .rev()
            .find_map(SegmentSpec::item),
        first_segment: first + 1,
        last_segment: last + 1,
        duration_s: report.duration_s,
        energy_wh: report.energy_wh,
        end_soc: report.end_soc,
    }
}
