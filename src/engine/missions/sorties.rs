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
//! A leg is straight from where the one before it ends to its waypoint, its height changing
//! evenly along it: a point a fraction of the way along is that fraction of the way in all three
//! coordinates. Each sortie's answer is its own flight: energy, end state of charge, duration.

use serde::{Deserialize, Serialize};

use aloft_planner::{Mission as Compiled, MissionReport, MissionSpec, SegmentSpec};

use crate::engine::missions::flight::{first_speed, Flight};

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

/// A point of the route where a sortie ends: the end of segment `segment` (`fraction` 1), or a
/// point `fraction` of the way along it (a leg).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::engine) struct Cut {
    /// The segment, an index of the mission's segments.
    pub(in crate::engine) segment: usize,
    /// How far along it, 0 (exclusive) to 1.
    pub(in crate::engine) fraction: f64,
}

impl Cut {
    fn whole(segment: usize) -> Self {
        Self {
            segment,
            fraction: 1.0,
        }
    }

    fn is_whole(self) -> bool {
        self.fraction >= 1.0
    }
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
}

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
    };
    match sortie_plans(flight, &route, SplitOptions::default(), &maker) {
        Ok(plans) => {
            let mut sorties: Vec<SortieSummary> = plans.iter().map(|p| route.summary(p)).collect();
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

/// The sorties' missions as aloft's own segments.
pub(in crate::engine) struct SpecSorties<'r, 'f> {
    /// The route cut.
    pub(in crate::engine) route: &'r Route<'r>,
    /// What every flight shares (the way home's speed and landing).
    pub(in crate::engine) flight: &'r Flight<'f>,
}

impl SortieMaker for SpecSorties<'_, '_> {
    fn sortie(&self, start: Option<Cut>, end: Option<Cut>) -> Result<MissionSpec, String> {
        Ok(self.route.sortie(self.flight, start, end))
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
    if options.inside_legs {
        route.within_reach(flight)?;
    }
    let mut plans: Vec<SortiePlan> = Vec::new();
    let mut start: Option<Cut> = None;
    loop {
        if plans.len() == MAX_SORTIES {
            return Err(format!("the route takes more than {MAX_SORTIES} sorties"));
        }
        let spec = maker.sortie(start, None)?;
        let rest = flight
            .trial(&spec, None)
            .map_err(|e| format!("a sortie cannot be flown: {e}"))?;
        let from = start.map_or(0, |_| route.resumes_at(start));
        if rest.feasible {
            plans.push(SortiePlan {
                start,
                end: None,
                spec,
                report: rest,
                route: from..route.spec.segments.len(),
            });
            return Ok(plans);
        }
        let found = match options.inside_legs {
            true => farthest_end(flight, route, maker, start),
            false => whole_end(flight, route, maker, (start, &rest)),
        };
        let Some((end, spec, report)) = found else {
            return Err(route.cannot_fly(start));
        };
        plans.push(SortiePlan {
            start,
            end: Some(end),
            spec,
            report,
            route: from..end.segment + 1,
        });
        start = Some(route.back_along(end, options.overlap_m, start));
    }
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
    let from = route.resumes_at(start);
    let ends: Vec<usize> = (from..route.tail)
        .filter(|&e| route.end_m[e][2] > 0.0)
        .collect();
    let (mut lo, mut hi) = (0usize, ends.len());
    let mut best = None;
    while lo < hi {
        let mid = (lo + hi) / 2;
        match try_end(Cut::whole(ends[mid])) {
            Some(found) => {
                best = Some(found);
                lo = mid + 1;
            }
            None => hi = mid,
        }
    }
    let next = best.as_ref().map_or(from, |(c, _, _)| c.segment + 1);
    partial_end(route, start, next, &try_end).or(best)
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
    // before the return).
    let &candidate = ends.last()?;
    if let Some(found) = try_end(candidate) {
        return Some(found);
    }
    let (mut lo, mut hi) = (0usize, ends.len() - 1); // ends[hi] fails; find the last that holds
    let mut best = None;
    while lo < hi {
        let mid = (lo + hi) / 2;
        match try_end(ends[mid]) {
            Some(found) => {
                best = Some(found);
                lo = mid + 1;
            }
            None => hi = mid,
        }
    }
    best
}

/// Bisection on the fraction of a leg stops when the interval is shorter than this, m.
const CUT_RESOLUTION_M: f64 = 1.0;

/// The farthest point of leg `segment` a sortie from `start` can end at (module step 4), when
/// the segment is a leg of the route beyond `start`.
fn partial_end(
    route: &Route<'_>,
    start: Option<Cut>,
    segment: usize,
    try_end: &dyn Fn(Cut) -> Option<Ending>,
) -> Option<Ending> {
    let length_m = route.leg_length_m(segment)?;
    let mut lo = match start {
        Some(c) if c.segment == segment => c.fraction,
        _ => 0.0,
    };
    let mut hi = 1.0;
    let mut best = None;
    // Each step halves the interval; 64 steps reach any leg's metre.
    for _ in 0..64 {
        if (hi - lo) * length_m < CUT_RESOLUTION_M {
            break;
        }
        let mid = 0.5 * (lo + hi);
        match try_end(Cut {
            segment,
            fraction: mid,
        }) {
            Some(found) => {
                best = Some(found);
                lo = mid;
            }
            None => hi = mid,
        }
    }
    best
}

/// Where each of the `n` segments of `compiled` ends, ENU m (a segment without a piece where the
/// one before it ended, home before the first).
pub(in crate::engine) fn segment_ends_m(compiled: &Compiled, n: usize) -> Vec<[f64; 3]> {
    let mut end_m: Vec<Option<[f64; 3]>> = vec![None; n];
    for p in compiled.pieces() {
        if let Some(slot) = end_m.get_mut(p.segment) {
            *slot = Some(p.end_m());
        }
    }
    let mut last = compiled.home_m();
    end_m
        .into_iter()
        .map(|e| {
            last = e.unwrap_or(last);
            last
        })
        .collect()
}

/// The route of a mission and what its sorties need to know about it.
pub(in crate::engine) struct Route<'a> {
    spec: &'a MissionSpec,
    /// First segment after the take-off.
    first: usize,
    /// First segment of the way down (the tail every last sortie flies).
    tail: usize,
    /// Where each segment ends, ENU m.
    end_m: Vec<[f64; 3]>,
    /// The payload at the start of each segment, kg.
    payload_kg: Vec<f64>,
    /// The take-off's climb rate, m/s.
    climb_rate_mps: f64,
    /// Home, ENU m.
    home_m: [f64; 3],
}

impl<'a> Route<'a> {
    /// The route of `spec`: its first segment must be a take-off and its last a landing.
    pub(in crate::engine) fn of(
        spec: &'a MissionSpec,
        compiled: &Compiled,
    ) -> Result<Self, String> {
        let segments = &spec.segments;
        let Some(&SegmentSpec::TakeOff { climb_rate_mps, .. }) = segments.first() else {
            return Err("the mission does not begin with a take-off".to_string());
        };
        if !matches!(segments.last(), Some(SegmentSpec::Landing { .. })) {
            return Err("the mission does not end with a landing".to_string());
        }
        let tail = segments
            .iter()
            .rposition(|s| {
                !matches!(
                    s,
                    SegmentSpec::Landing { .. }
                        | SegmentSpec::Descent { .. }
                        | SegmentSpec::Return { .. }
                )
            })
            .map_or(segments.len(), |i| i + 1);
        if tail <= 1 {
            return Err("the mission has no route between its take-off and landing".to_string());
        }
        let n = segments.len();
        let mut phase: Vec<Option<usize>> = vec![None; n];
        for p in compiled.pieces() {
            phase[p.segment].get_or_insert(p.mass_phase);
        }
        let payloads = compiled.payloads_kg();
        let mut last_phase = 0;
        let mut payload_kg = Vec::with_capacity(n);
        for p in phase {
            last_phase = p.unwrap_or(last_phase);
            payload_kg.push(payloads.get(last_phase).copied().unwrap_or(0.0));
        }
        let ends = segment_ends_m(compiled, n);
        Ok(Self {
            spec,
            first: 1,
            tail,
            end_m: ends,
            payload_kg,
            climb_rate_mps,
            home_m: compiled.home_m(),
        })
    }

    /// The first segment of the route a sortie from `start` flies (the remainder of a leg it
    /// resumes inside of, else the one after).
    pub(in crate::engine) fn resumes_at(&self, start: Option<Cut>) -> usize {
        match start {
            None => self.first,
            Some(c) if c.is_whole() => c.segment + 1,
            Some(c) => c.segment,
        }
    }

    /// The payload a sortie from `start` takes off with, kg.
    pub(in crate::engine) fn payload_at_kg(&self, start: Option<Cut>) -> f64 {
        self.payload_kg[self.resumes_at(start)]
    }

    /// Home's height, ENU m (the heights of a planner file are above it).
    pub(in crate::engine) fn home_up_m(&self) -> f64 {
        self.home_m[2]
    }

    /// Where segment `segment` begins, ENU m.
    fn start_m(&self, segment: usize) -> [f64; 3] {
        match segment.checked_sub(1) {
            Some(previous) => self.end_m[previous],
            None => self.home_m,
        }
    }

    /// The length of segment `segment` when it is a leg of the route (before its way down), m.
    fn leg_length_m(&self, segment: usize) -> Option<f64> {
        let is_leg = matches!(
            self.spec.segments.get(segment),
            Some(SegmentSpec::Leg { .. })
        );
        if !is_leg || segment < self.first || segment >= self.tail {
            return None;
        }
        let (a, b) = (self.start_m(segment), self.end_m[segment]);
        Some((b[0] - a[0]).hypot(b[1] - a[1]).hypot(b[2] - a[2]))
    }

    /// The point of the route at `cut`, ENU m.
    pub(in crate::engine) fn point_m(&self, cut: Cut) -> [f64; 3] {
        let (a, b) = (self.start_m(cut.segment), self.end_m[cut.segment]);
        let f = cut.fraction.clamp(0.0, 1.0);
        [0, 1, 2].map(|k| a[k] + f * (b[k] - a[k]))
    }

    /// The point `overlap_m` back along the route's legs from `end` (module step 5), no farther
    /// back than where the sortie from `start` began, nor across a segment that is not a leg.
    fn back_along(&self, end: Cut, overlap_m: f64, start: Option<Cut>) -> Cut {
        let floor = start.map_or((self.first, 0.0), |c| match c.is_whole() {
            true => (c.segment + 1, 0.0),
            false => (c.segment, c.fraction),
        });
        let (mut segment, mut fraction, mut left_m) = (end.segment, end.fraction, overlap_m);
        while left_m > 0.0 {
            let Some(length_m) = self.leg_length_m(segment).filter(|l| *l > 0.0) else {
                break;
            };
            let lowest = if segment == floor.0 { floor.1 } else { 0.0 };
            let available_m = (fraction - lowest) * length_m;
            if available_m >= left_m {
                fraction -= left_m / length_m;
                break;
            }
            left_m -= available_m;
            fraction = lowest;
            if segment <= floor.0 || lowest > 0.0 {
                break;
            }
            segment -= 1;
            fraction = 1.0;
        }
        match fraction > 0.0 {
            true => Cut { segment, fraction },
            // At a leg's start: the end of the segment before it.
            false => Cut::whole(segment - 1),
        }
    }

    /// Whether a pack can fly to the route's farthest point from home and back (a sortie that
    /// only goes there): when it cannot, no way of cutting the route keeps the reserve, and the
    /// sorties cut inside legs would otherwise creep toward that point by ever shorter steps.
    ///
    /// # Errors
    /// The farthest point and its item (or segment), when it is out of reach.
    fn within_reach(&self, flight: &Flight<'_>) -> Result<(), String> {
        let home = self.home_m;
        let distance = |p: [f64; 3]| (p[0] - home[0]).hypot(p[1] - home[1]);
        let Some(far) = (self.first..self.tail)
            .max_by(|&a, &b| distance(self.end_m[a]).total_cmp(&distance(self.end_m[b])))
        else {
            return Ok(());
        };
        let cut = Cut::whole(far);
        let mut spec = self.spec.clone();
        spec.payload_kg = self.payload_kg[far];
        spec.allow_end_in_air = false;
        spec.segments = self.resume(cut, far + 1).to_vec();
        spec.segments.extend(flight.way_home(self.spec));
        if flight.trial(&spec, None).is_ok_and(|r| r.feasible) {
            return Ok(());
        }
        let seg = &self.spec.segments[far];
        let name = match seg.item() {
            Some(i) => format!("item {i}"),
            None => format!("segment {}", far + 1),
        };
        Err(format!(
            "the route reaches {:.0} m from home at {name} ({}): a full pack cannot fly there and \
             back with the reserve",
            distance(self.end_m[far]),
            seg.kind()
        ))
    }

    /// Why no sortie from `start` can be flown.
    fn cannot_fly(&self, start: Option<Cut>) -> String {
        let at = self.resumes_at(start);
        let seg = &self.spec.segments[at.min(self.spec.segments.len() - 1)];
        let name = match seg.item() {
            Some(i) => format!("item {i} ({})", seg.kind()),
            None => format!("segment {} ({})", at + 1, seg.kind()),
        };
        format!("{name} cannot be flown from home and back with the reserve on one pack")
    }

    /// The ends a sortie from `start` may have (segments of the route that end in the air)
    /// completed by mission time `limit_s` in `rest`, the flight of the rest of the route from
    /// `start`.
    fn ends_before(&self, start: Option<Cut>, rest: &MissionReport, limit_s: f64) -> Vec<usize> {
        let prefix = self.prefix_len(start);
        let from = self.resumes_at(start);
        let mut t = 0.0;
        let mut ends = Vec::new();
        for s in &rest.segments {
            t += s.duration_s;
            let Some(original) = (s.index - 1).checked_sub(prefix).map(|k| from + k) else {
                continue;
            };
            if original >= self.tail || t > limit_s {
                break;
            }
            if self.end_m[original][2] > 0.0 {
                ends.push(original);
            }
        }
        ends
    }

    /// Segments a sortie from `start` flies before the route: the first sortie flies the
    /// mission's own take-off (segment 0); the others a take-off and a transit.
    fn prefix_len(&self, start: Option<Cut>) -> usize {
        match start {
            None => self.first,
            Some(_) => 2,
        }
    }

    /// The mission of the sortie from `start` (`None`: the mission's own start) to `end` (the
    /// route's end and the mission's way down when `None`).
    fn sortie(&self, flight: &Flight<'_>, start: Option<Cut>, end: Option<Cut>) -> MissionSpec {
        let spec = self.spec;
        let from = self.resumes_at(start);
        let mut s = spec.clone();
        s.payload_kg = self.payload_at_kg(start);
        s.allow_end_in_air = false;
        let mut segments = Vec::new();
        match start {
            None => segments.extend_from_slice(&spec.segments[..from]),
            Some(c) => segments.extend(self.resume(c, from)),
        }
        match end {
            None => segments.extend_from_slice(&spec.segments[from..]),
            Some(e) => {
                segments.extend_from_slice(&spec.segments[from..e.segment]);
                segments.push(self.to_cut(e));
                segments.extend(flight.way_home(spec));
            }
        }
        s.segments = segments;
        s
    }

    /// A take-off at home to the height of `cut` and a straight transit there, at the planning
    /// speed (else the first speed of the route from `from`, else none).
    fn resume(&self, cut: Cut, from: usize) -> [SegmentSpec; 2] {
        let spec = self.spec;
        let [east_m, north_m, up_m] = self.point_m(cut);
        [
            SegmentSpec::TakeOff {
                altitude_m: up_m,
                climb_rate_mps: self.climb_rate_mps,
                item: None,
            },
            SegmentSpec::Leg {
                east_m: Some(east_m),
                north_m: Some(north_m),
                latitude_deg: None,
                longitude_deg: None,
                altitude_m: Some(up_m),
                ground_speed_mps: match spec.default_speed_mps {
                    Some(_) => None,
                    None => first_speed(&spec.segments[from..]),
                },
                payload_after_kg: None,
                acceptance_radius_m: None,
                item: None,
            },
        ]
    }

    /// The segment that ends the route at `cut`: the segment itself when whole, else its leg
    /// to the point (the item's speed and number kept, its payload change not reached).
    fn to_cut(&self, cut: Cut) -> SegmentSpec {
        let segment = self.spec.segments[cut.segment].clone();
        if cut.is_whole() {
            return segment;
        }
        let [east, north, up] = self.point_m(cut);
        match segment {
            SegmentSpec::Leg {
                ground_speed_mps,
                acceptance_radius_m,
                item,
                ..
            } => SegmentSpec::Leg {
                east_m: Some(east),
                north_m: Some(north),
                latitude_deg: None,
                longitude_deg: None,
                altitude_m: Some(up),
                ground_speed_mps,
                payload_after_kg: None,
                acceptance_radius_m,
                item,
            },
            other => other,
        }
    }

    /// The answer of a sortie.
    fn summary(&self, plan: &SortiePlan) -> SortieSummary {
        let segments = &self.spec.segments;
        let first = match plan.start {
            None => 0,
            Some(_) => self.resumes_at(plan.start),
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
}
