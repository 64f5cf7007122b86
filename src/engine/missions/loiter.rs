//! Loiter until the reserve: how long the vehicle can hover where a route ends in an open-ended
//! loiter (QGroundControl's and Mission Planner's LOITER_UNLIM) before it must fly home and land
//! with the reserve.
//!
//! The loiter is found by flying the whole mission: the route, a hover of `h` seconds, the way
//! home (a return at the planning speed and the RTL altitude, a landing), and bisecting `h` on
//! whether it lands with the reserve (which only gets worse as `h` grows). The answer is what the
//! mission flies, not an estimate beside it: the plan that is reported is the one with the loiter
//! found, to the second below.

use serde::{Deserialize, Serialize};

use aloft_planner::{MissionSpec, PlannerError, SegmentSpec};

use crate::engine::missions::flight::Flight;

/// How finely the loiter time is found, s.
const RESOLUTION_S: f64 = 1.0;

/// First loiter tried, s; doubled while it still returns with the reserve.
const FIRST_GUESS_S: f64 = 1800.0;

/// Longest loiter looked for, s (27.8 hours): a vehicle that can loiter longer is told "at least".
const LONGEST_S: f64 = 100_000.0;

/// The loiter of a route that ends in one (in the answer as `loiter`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoiterSummary {
    /// The loiter's mission item number (from a planner file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub item: Option<u32>,
    /// The loiter's segment in the answer's `segments` (a hover), from 1.
    pub segment: usize,
    /// Mission time at which the loiter begins, s.
    pub start_s: f64,
    /// How long the vehicle can loiter before it must fly home to land with the reserve, s
    /// (whole seconds, rounded down; 0 when it cannot loiter at all).
    pub duration_s: f64,
    /// The search stopped at its longest loiter (27.8 hours): the vehicle can loiter at least
    /// this long.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub at_least: bool,
}

/// When `spec` ends in a loiter until the reserve: the mission that flies it (the route, the
/// longest hover that still lands with the reserve, the way home) and the loiter; `None` for any
/// other mission. `payload_kg` overrides the take-off payload.
///
/// # Errors
/// What compiling or flying the mission returns.
pub(in crate::engine) fn resolve_loiter(
    flight: &Flight<'_>,
    spec: &MissionSpec,
    payload_kg: Option<f64>,
) -> Result<Option<(MissionSpec, LoiterSummary)>, PlannerError> {
    let Some(&SegmentSpec::LoiterUntilReserve { item }) = spec.segments.last() else {
        return Ok(None);
    };
    let route = &spec.segments[..spec.segments.len() - 1];
    let with_hover = |hover_s: f64| {
        let mut s = spec.clone();
        s.segments = route.to_vec();
        if hover_s > 0.0 {
            s.segments.push(SegmentSpec::Hover {
                duration_s: hover_s,
                payload_after_kg: None,
                item,
            });
        }
        s.segments.extend(flight.way_home(spec));
        s
    };
    let lands_with_reserve = |hover_s: f64| -> Result<bool, PlannerError> {
        Ok(flight.trial(&with_hover(hover_s), payload_kg)?.feasible)
    };
    let (duration_s, at_least) = longest_loiter(lands_with_reserve)?;
    let flown = with_hover(duration_s);
    let compiled = flight.compile(&flown, payload_kg)?;
    let start_s = compiled
        .pieces()
        .iter()
        .take_while(|p| p.segment < route.len())
        .map(|p| p.duration_s())
        .sum();
    Ok(Some((
        flown,
        LoiterSummary {
            item,
            segment: route.len() + 1,
            start_s,
            duration_s,
            at_least,
        },
    )))
}

/// The longest hover (whole seconds) for which `ok` holds, given that it holds for every shorter
/// one: 0 when it fails at one second; `(LONGEST_S, true)` when it holds there.
fn longest_loiter(
    mut ok: impl FnMut(f64) -> Result<bool, PlannerError>,
) -> Result<(f64, bool), PlannerError> {
    if !ok(RESOLUTION_S)? {
        return Ok((0.0, false));
    }
    let (mut lo, mut hi) = (RESOLUTION_S, FIRST_GUESS_S);
    while ok(hi)? {
        if hi >= LONGEST_S {
            return Ok((LONGEST_S, true));
        }
        lo = hi;
        hi = (hi * 2.0).min(LONGEST_S);
    }
    while hi - lo > RESOLUTION_S {
        let mid = ((lo + hi) / 2.0).floor();
        if ok(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok((lo.floor(), false))
}

#[cfg(test)]
mod tests {
    use super::*;

    // Whole seconds below 2^53 are exact in f64: the search's answers compare exactly.
    #[allow(clippy::float_cmp)]
    #[test]
    fn the_search_finds_the_last_second_that_holds() {
        for limit in [0.5, 1.0, 7.0, 1799.0, 1800.0, 1800.5, 5000.0, 99_999.0] {
            let (found, at_least) = longest_loiter(|h| Ok(h <= limit)).unwrap();
            assert_eq!(found, limit.floor(), "limit {limit}");
            assert!(!at_least);
        }
        assert_eq!(longest_loiter(|_| Ok(true)).unwrap(), (LONGEST_S, true));
        assert_eq!(longest_loiter(|_| Ok(false)).unwrap(), (0.0, false));
    }
}
