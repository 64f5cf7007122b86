//! The route of a mission as its sorties see it: where a sortie may end ([`Cut`]), the mission a
//! sortie from one cut to another flies ([`Route::sortie`]), how far back the next one resumes
//! ([`Route::back_along`]), and the searches that find the farthest end a trial still holds
//! ([`last_that_holds`], [`farthest_fraction`]). Geometry and bookkeeping on a [`MissionSpec`]
//! and its compiled [`Mission`]; which sortie holds (a flight on a pack) is the caller's trial.
//!
//! The route is the mission between its first take-off and its final way down (a return, the
//! descents and the landing). A sortie after the first takes off at home to the height where the
//! last one left the route, flies straight there, flies on along the route and comes home by the
//! way home the caller gives (a return and a landing); the last sortie flies the mission's own way
//! down. A leg is straight from where the one before it ends to its waypoint, its height changing
//! evenly along it: a point a fraction of the way along is that fraction of the way in all three
//! coordinates.

use crate::mission::{Mission, MissionSpec, SegmentSpec};
use crate::plan::MissionReport;

/// The take-off height of a sortie that resumes at a point at or below home's height (a route
/// over a valley, flown over terrain), m.
pub const RESUME_TAKE_OFF_M: f64 = 10.0;

/// A point of the route where a sortie ends: the end of segment `segment` (`fraction` 1), or a
/// point `fraction` of the way along it (a leg).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cut {
    /// The segment, an index of the mission's segments.
    pub segment: usize,
    /// How far along it, 0 (exclusive) to 1.
    pub fraction: f64,
}

impl Cut {
    /// The end of segment `segment`.
    pub fn whole(segment: usize) -> Self {
        Self {
            segment,
            fraction: 1.0,
        }
    }

    /// Whether the cut is at the end of its segment.
    pub fn is_whole(self) -> bool {
        self.fraction >= 1.0
    }
}

/// Bisection on the fraction of a leg stops when the interval is shorter than this, m.
pub const CUT_RESOLUTION_M: f64 = 1.0;

/// The last of `n` candidates, in order, for which `trial` holds, by bisection: the candidates
/// are taken to hold up to some index and fail after it (a sortie that ends later draws more).
/// `None` when the first fails.
pub fn last_that_holds<T>(n: usize, mut trial: impl FnMut(usize) -> Option<T>) -> Option<T> {
    let (mut lo, mut hi) = (0usize, n);
    let mut best = None;
    while lo < hi {
        let mid = (lo + hi) / 2;
        match trial(mid) {
            Some(found) => {
                best = Some(found);
                lo = mid + 1;
            }
            None => hi = mid,
        }
    }
    best
}

/// The farthest fraction of a leg `length_m` long, above `from`, for which `trial` holds, by
/// bisection to [`CUT_RESOLUTION_M`] (at most 64 halvings); `None` when no fraction tried holds.
pub fn farthest_fraction<T>(
    from: f64,
    length_m: f64,
    mut trial: impl FnMut(f64) -> Option<T>,
) -> Option<T> {
    let (mut lo, mut hi) = (from, 1.0);
    let mut best = None;
    for _ in 0..64 {
        if (hi - lo) * length_m < CUT_RESOLUTION_M {
            break;
        }
        let mid = 0.5 * (lo + hi);
        match trial(mid) {
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
pub fn segment_ends_m(compiled: &Mission, n: usize) -> Vec<[f64; 3]> {
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

/// The first ground speed the segments set (a leg's, an orbit's or a return's), if any.
pub fn first_speed(segments: &[SegmentSpec]) -> Option<f64> {
    segments.iter().find_map(|s| match *s {
        SegmentSpec::Leg {
            ground_speed_mps, ..
        }
        | SegmentSpec::Orbit {
            ground_speed_mps, ..
        }
        | SegmentSpec::Return {
            ground_speed_mps, ..
        } => ground_speed_mps,
        _ => None,
    })
}

/// The route of a mission and what its sorties need to know about it.
#[derive(Debug, Clone)]
pub struct Route<'a> {
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
    /// The route of `spec` (compiled as `compiled`).
    ///
    /// # Errors
    /// Why it has none: its first segment is not a take-off, its last not a landing, or nothing
    /// lies between.
    pub fn of(spec: &'a MissionSpec, compiled: &Mission) -> Result<Self, String> {
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
        Ok(Self {
            spec,
            first: 1,
            tail,
            end_m: segment_ends_m(compiled, n),
            payload_kg,
            climb_rate_mps,
            home_m: compiled.home_m(),
        })
    }

    /// The mission the route is of.
    pub fn spec(&self) -> &'a MissionSpec {
        self.spec
    }

    /// The first segment of the way down (one past the route's last).
    pub fn tail(&self) -> usize {
        self.tail
    }

    /// Where segment `segment` ends, ENU m.
    pub fn end_m(&self, segment: usize) -> [f64; 3] {
        self.end_m[segment]
    }

    /// The first segment of the route a sortie from `start` flies (the remainder of a leg it
    /// resumes inside of, else the one after).
    pub fn resumes_at(&self, start: Option<Cut>) -> usize {
        match start {
            None => self.first,
            Some(c) if c.is_whole() => c.segment + 1,
            Some(c) => c.segment,
        }
    }

    /// The segments of the route a sortie from `start` may end with, in order (those that end
    /// in the air).
    pub fn ends_from(&self, start: Option<Cut>) -> Vec<usize> {
        (self.resumes_at(start)..self.tail)
            .filter(|&e| self.end_m[e][2] > 0.0)
            .collect()
    }

    /// The payload a sortie from `start` takes off with, kg.
    pub fn payload_at_kg(&self, start: Option<Cut>) -> f64 {
        self.payload_kg[self.resumes_at(start)]
    }

    /// Home's height, ENU m (the heights of a planner file are above it).
    pub fn home_up_m(&self) -> f64 {
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
    pub fn leg_length_m(&self, segment: usize) -> Option<f64> {
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
    pub fn point_m(&self, cut: Cut) -> [f64; 3] {
        let (a, b) = (self.start_m(cut.segment), self.end_m[cut.segment]);
        let f = cut.fraction.clamp(0.0, 1.0);
        [0, 1, 2].map(|k| a[k] + f * (b[k] - a[k]))
    }

    /// The point `overlap_m` back along the route's legs from `end`, no farther back than where
    /// the sortie from `start` began, nor across a segment that is not a leg.
    pub fn back_along(&self, end: Cut, overlap_m: f64, start: Option<Cut>) -> Cut {
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

    /// The segment of the route that ends farthest from home (horizontally), if any.
    pub fn farthest_segment(&self) -> Option<usize> {
        let home = self.home_m;
        let distance = |p: [f64; 3]| (p[0] - home[0]).hypot(p[1] - home[1]);
        (self.first..self.tail)
            .max_by(|&a, &b| distance(self.end_m[a]).total_cmp(&distance(self.end_m[b])))
    }

    /// A sortie that only flies to the end of segment `far` and back by `way_home`.
    pub fn there_and_back(&self, far: usize, way_home: [SegmentSpec; 2]) -> MissionSpec {
        let mut spec = self.spec.clone();
        spec.payload_kg = self.payload_kg[far];
        spec.allow_end_in_air = false;
        spec.segments = self.resume(Cut::whole(far), far + 1, None).to_vec();
        spec.segments.extend(way_home);
        spec
    }

    /// Why a pack that cannot fly [`Route::there_and_back`] to `far` cannot fly the route.
    pub fn out_of_reach(&self, far: usize) -> String {
        let home = self.home_m;
        let p = self.end_m[far];
        let seg = &self.spec.segments[far];
        let name = match seg.item() {
            Some(i) => format!("item {i}"),
            None => format!("segment {}", far + 1),
        };
        format!(
            "the route reaches {:.0} m from home at {name} ({}): a full pack cannot fly there and \
             back with the reserve",
            (p[0] - home[0]).hypot(p[1] - home[1]),
            seg.kind()
        )
    }

    /// Why no sortie from `start` can be flown.
    pub fn cannot_fly(&self, start: Option<Cut>) -> String {
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
    pub fn ends_before(
        &self,
        start: Option<Cut>,
        rest: &MissionReport,
        limit_s: f64,
    ) -> Vec<usize> {
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
    /// route's end and the mission's way down when `None`, else `way_home` after the cut).
    pub fn sortie(
        &self,
        start: Option<Cut>,
        end: Option<Cut>,
        way_home: [SegmentSpec; 2],
    ) -> MissionSpec {
        self.sortie_flying_out(start, end, way_home, None)
    }

    /// [`Route::sortie`] with its fly-out from home to `start` at `fly_out_mps` (else at the
    /// planning speed, or the first speed of the route from there).
    pub fn sortie_flying_out(
        &self,
        start: Option<Cut>,
        end: Option<Cut>,
        way_home: [SegmentSpec; 2],
        fly_out_mps: Option<f64>,
    ) -> MissionSpec {
        let spec = self.spec;
        let from = self.resumes_at(start);
        let mut s = spec.clone();
        s.payload_kg = self.payload_at_kg(start);
        s.allow_end_in_air = false;
        let mut segments = Vec::new();
        match start {
            None => segments.extend_from_slice(&spec.segments[..from]),
            Some(c) => segments.extend(self.resume(c, from, fly_out_mps)),
        }
        match end {
            None => segments.extend_from_slice(&spec.segments[from..]),
            Some(e) => {
                segments.extend_from_slice(&spec.segments[from..e.segment]);
                segments.push(self.to_cut(e));
                segments.extend(way_home);
            }
        }
        s.segments = segments;
        s
    }

    /// A take-off at home to the height of `cut` and a straight transit there, at `fly_out_mps`
    /// when given, else the planning speed (else the first speed of the route from `from`, else
    /// none).
    fn resume(&self, cut: Cut, from: usize, fly_out_mps: Option<f64>) -> [SegmentSpec; 2] {
        let spec = self.spec;
        let [east_m, north_m, up_m] = self.point_m(cut);
        [
            SegmentSpec::TakeOff {
                // A point below home's height (a route over a valley) is reached by a take-off to
                // RESUME_TAKE_OFF_M and the transit down to it.
                altitude_m: if up_m > 0.0 { up_m } else { RESUME_TAKE_OFF_M },
                climb_rate_mps: self.climb_rate_mps,
                item: None,
            },
            SegmentSpec::Leg {
                east_m: Some(east_m),
                north_m: Some(north_m),
                latitude_deg: None,
                longitude_deg: None,
                altitude_m: Some(up_m),
                ground_speed_mps: fly_out_mps.or(match spec.default_speed_mps {
                    Some(_) => None,
                    None => first_speed(&spec.segments[from..]),
                }),
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
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bisection finds the last index that holds when the trial holds up to 6 of 10, in at most
    /// ceil(log2(11)) = 4 trials; none when the first fails; the last when all hold.
    #[test]
    fn last_that_holds_finds_the_boundary_in_log_trials() {
        let mut trials = 0;
        let found = last_that_holds(10, |i| {
            trials += 1;
            (i <= 6).then_some(i)
        });
        assert_eq!(found, Some(6));
        assert!(trials <= 4, "{trials}");
        assert_eq!(last_that_holds(10, |i| (i > 99).then_some(i)), None);
        assert_eq!(last_that_holds(10, Some), Some(9));
        assert_eq!(last_that_holds(0, Some), None);
    }

    /// A 1000 m leg that holds up to 0.3071 of its length: the fraction found is within the 1 m
    /// resolution below it (0.3061 to 0.3071), from 0; from 0.5 nothing holds.
    #[test]
    fn farthest_fraction_stops_within_a_metre() {
        let f = farthest_fraction(0.0, 1000.0, |x| (x <= 0.3071).then_some(x)).unwrap();
        assert!((0.3061..=0.3071).contains(&f), "{f}");
        assert_eq!(
            farthest_fraction(0.5, 1000.0, |x| (x <= 0.3071).then_some(x)),
            None
        );
    }
}
