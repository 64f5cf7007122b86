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
//!    end is searched by bisection among the earlier segments.
//!
//! Each sortie's answer is its own flight: energy, end state of charge, duration.

use serde::{Deserialize, Serialize};

use aloft_planner::{Mission as Compiled, MissionReport, MissionSpec, SegmentSpec};

use super::flight::{first_speed, Flight};

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
pub(super) struct Sorties {
    /// Packs the route takes, when it can be split (the sorties' count).
    pub(super) batteries_required: Option<u32>,
    /// The sorties, when more than one.
    pub(super) sorties: Vec<SortieSummary>,
    /// Why the route was not split, when it was not.
    pub(super) note: Option<String>,
}

/// The sorties of `spec` (compiled as `compiled`), a mission one pack cannot fly; a route that
/// cannot be split says why (a sortie that cannot be compiled or flown is one that cannot be
/// flown).
pub(super) fn split(flight: &Flight<'_>, spec: &MissionSpec, compiled: &Compiled) -> Sorties {
    let route = match Route::of(spec, compiled) {
        Ok(r) => r,
        Err(why) => return unsplit(why),
    };
    let mut sorties = Vec::new();
    let mut start = route.first;
    loop {
        if sorties.len() == MAX_SORTIES {
            return unsplit(format!("the route takes more than {MAX_SORTIES} sorties"));
        }
        let rest = flight.trial(&route.sortie(flight, start, None), None);
        let rest = match rest {
            Ok(r) => r,
            Err(e) => return unsplit(format!("a sortie cannot be flown: {e}")),
        };
        if rest.feasible {
            sorties.push(route.summary(start, None, &rest));
            break;
        }
        let Some((end, report)) = sortie_end(flight, &route, start, &rest) else {
            let seg = &spec.segments[start];
            let name = match seg.item() {
                Some(i) => format!("item {i} ({})", seg.kind()),
                None => format!("segment {} ({})", start + 1, seg.kind()),
            };
            return unsplit(format!(
                "{name} cannot be flown from home and back with the reserve on one pack"
            ));
        };
        sorties.push(route.summary(start, Some(end), &report));
        start = end + 1;
    }
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

impl Sorties {
    /// The answer for a mission not split: one pack when it can fly it, else none known (a
    /// mission that ends in the air is not split).
    pub(super) fn one(feasible: bool) -> Self {
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

/// The end of the sortie that starts at segment `start` (see the module's steps 2 and 3) and its
/// flight; `None` when not even its first segment can be flown there and back.
fn sortie_end(
    flight: &Flight<'_>,
    route: &Route<'_>,
    start: usize,
    rest: &MissionReport,
) -> Option<(usize, MissionReport)> {
    // Without a point of no return (every straight return held, yet the mission's own way down
    // lands short), every segment of the route is a candidate.
    let limit_s = rest.point_of_no_return.map_or(f64::INFINITY, |p| p.time_s);
    let ends = route.ends_before(start, rest, limit_s);
    // A sortie that cannot be compiled (a transit beyond a limit) is one that cannot be flown.
    let try_end = |end: usize| {
        flight
            .trial(&route.sortie(flight, start, Some(end)), None)
            .ok()
            .filter(|r| r.feasible)
    };
    // The candidate first, then bisection among the earlier ends (fewer segments, less energy
    // before the return).
    let &candidate = ends.last()?;
    if let Some(r) = try_end(candidate) {
        return Some((candidate, r));
    }
    let (mut lo, mut hi) = (0usize, ends.len() - 1); // ends[hi] fails; find the last that holds
    let mut best = None;
    while lo < hi {
        let mid = (lo + hi) / 2;
        match try_end(ends[mid]) {
            Some(r) => {
                best = Some((ends[mid], r));
                lo = mid + 1;
            }
            None => hi = mid,
        }
    }
    best
}

/// The route of a mission and what its sorties need to know about it.
struct Route<'a> {
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
}

impl<'a> Route<'a> {
    /// The route of `spec`: its first segment must be a take-off and its last a landing.
    fn of(spec: &'a MissionSpec, compiled: &Compiled) -> Result<Self, String> {
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
        let mut end_m: Vec<Option<[f64; 3]>> = vec![None; n];
        let mut phase: Vec<Option<usize>> = vec![None; n];
        for p in compiled.pieces() {
            end_m[p.segment] = Some(p.end_m());
            phase[p.segment].get_or_insert(p.mass_phase);
        }
        let payloads = compiled.payloads_kg();
        let (mut last_end, mut last_phase) = (compiled.home_m(), 0);
        let mut ends = Vec::with_capacity(n);
        let mut payload_kg = Vec::with_capacity(n);
        for i in 0..n {
            last_end = end_m[i].unwrap_or(last_end);
            last_phase = phase[i].unwrap_or(last_phase);
            ends.push(last_end);
            payload_kg.push(payloads.get(last_phase).copied().unwrap_or(0.0));
        }
        Ok(Self {
            spec,
            first: 1,
            tail,
            end_m: ends,
            payload_kg,
            climb_rate_mps,
        })
    }

    /// The ends a sortie from `start` may have (segments of the route that end in the air)
    /// completed by mission time `limit_s` in `rest`, the flight of the rest of the route from
    /// `start`.
    fn ends_before(&self, start: usize, rest: &MissionReport, limit_s: f64) -> Vec<usize> {
        let prefix = self.prefix_len(start);
        let mut t = 0.0;
        let mut ends = Vec::new();
        for s in &rest.segments {
            t += s.duration_s;
            let Some(original) = (s.index - 1).checked_sub(prefix).map(|k| start + k) else {
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
    fn prefix_len(&self, start: usize) -> usize {
        if start == self.first {
            self.first
        } else {
            2
        }
    }

    /// The mission of the sortie from `start` to `end` (the route's end and the mission's way
    /// down when `None`).
    fn sortie(&self, flight: &Flight<'_>, start: usize, end: Option<usize>) -> MissionSpec {
        let spec = self.spec;
        let mut s = spec.clone();
        s.payload_kg = self.payload_kg[start];
        s.allow_end_in_air = false;
        let mut segments = Vec::new();
        if start == self.first {
            segments.extend_from_slice(&spec.segments[..start]);
        } else {
            let [east_m, north_m, up_m] = self.end_m[start - 1];
            segments.push(SegmentSpec::TakeOff {
                altitude_m: up_m,
                climb_rate_mps: self.climb_rate_mps,
                item: None,
            });
            segments.push(SegmentSpec::Leg {
                east_m: Some(east_m),
                north_m: Some(north_m),
                latitude_deg: None,
                longitude_deg: None,
                altitude_m: Some(up_m),
                ground_speed_mps: match spec.default_speed_mps {
                    Some(_) => None,
                    None => first_speed(&spec.segments[start..]),
                },
                payload_after_kg: None,
                acceptance_radius_m: None,
                item: None,
            });
        }
        match end {
            None => segments.extend_from_slice(&spec.segments[start..]),
            Some(e) => {
                segments.extend_from_slice(&spec.segments[start..=e]);
                segments.extend(flight.way_home(spec));
            }
        }
        s.segments = segments;
        s
    }

    /// The answer of the sortie from `start` to `end` (`None`: to the mission's end).
    fn summary(&self, start: usize, end: Option<usize>, report: &MissionReport) -> SortieSummary {
        let segments = &self.spec.segments;
        let first = if start == self.first { 0 } else { start };
        let last = end.unwrap_or(segments.len() - 1);
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
