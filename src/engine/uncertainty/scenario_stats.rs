//! The statistics of scenarios ([`crate::engine::uncertainty::scenarios::plan_scenarios`]): nearest-rank percentiles, the bands
//! of each segment's end state, and the state-of-charge fan over time, kept in bounded memory.

use serde::{Deserialize, Serialize};

use aloft_planner::{PlannerError, Sample, SampleSink};

pub use aloft_planner::percentiles::{nearest_rank, Percentiles};

/// The state of charge at the end of one segment over the completed scenarios.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SegmentBand {
    /// Segment number, from 1.
    pub index: usize,
    /// State of charge at its end.
    pub end_soc: Percentiles,
}

impl SegmentBand {
    /// The bands of the segments from each scenario's end states (all of one length; empty when
    /// they are not, or there are none).
    pub(in crate::engine) fn of<'a>(
        scenarios: impl Iterator<Item = &'a [f64]> + Clone,
    ) -> Vec<Self> {
        let mut lengths = scenarios.clone().map(<[f64]>::len);
        let Some(len) = lengths.next() else {
            return Vec::new();
        };
        if len == 0 || lengths.any(|l| l != len) {
            return Vec::new();
        }
        let mut column = Vec::new();
        (0..len)
            .filter_map(|k| {
                column.clear();
                column.extend(scenarios.clone().map(|s| s[k]));
                Percentiles::of(&mut column).map(|end_soc| SegmentBand {
                    index: k + 1,
                    end_soc,
                })
            })
            .collect()
    }
}

/// Bands of the state of charge over time across the scenarios flown to the end of the route: at
/// each time of a fixed grid, the 5th, 50th and 95th percentiles (a scenario that has landed
/// keeps its last state; one that ended early, its pack empty or a path it could not fly, is
/// left out). Resolution 0.1 % of state of charge. The map's `band` ([`crate::engine::front_door::maps::mission_map::MissionMap`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SocFan {
    /// Times of the grid, s.
    pub time_s: Vec<f64>,
    /// 5th percentile of the state of charge at each time.
    pub p5: Vec<f64>,
    /// Median.
    pub p50: Vec<f64>,
    /// 95th percentile.
    pub p95: Vec<f64>,
}

/// Points of the fan's time grid.
const FAN_POINTS: usize = 301;
/// Bins of the state of charge (0.1 % each).
const FAN_BINS: usize = 1000;

/// Counts of scenarios per grid time and state-of-charge bin: memory fixed (1.2 MB) whatever the
/// number of scenarios or the length of the flight; per thread, merged by adding counts (so the
/// fan does not depend on the threads).
#[derive(Debug, Clone)]
pub(in crate::engine) struct FanHistogram {
    span_s: f64,
    counts: Vec<u32>,
    /// Longest flight seen, s.
    longest_s: f64,
}

impl FanHistogram {
    /// An empty histogram over `[0, span_s]`.
    pub(in crate::engine) fn new(span_s: f64) -> Self {
        Self {
            span_s,
            counts: vec![0; FAN_POINTS * FAN_BINS],
            longest_s: 0.0,
        }
    }

    fn dt_s(&self) -> f64 {
        self.span_s / (FAN_POINTS - 1) as f64
    }

    fn add(&mut self, point: usize, soc: f64) {
        let bin = ((soc.clamp(0.0, 1.0) * FAN_BINS as f64) as usize).min(FAN_BINS - 1);
        self.counts[point * FAN_BINS + bin] += 1;
    }

    /// The sum of two histograms of one grid.
    pub(in crate::engine) fn merge(mut self, other: Self) -> Self {
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            *a += b;
        }
        self.longest_s = self.longest_s.max(other.longest_s);
        self
    }

    /// The bands up to the longest flight (within the grid); `None` when no scenario was flown.
    pub(in crate::engine) fn bands(&self) -> Option<SocFan> {
        let dt = self.dt_s();
        let points = ((self.longest_s / dt).ceil() as usize + 1).min(FAN_POINTS);
        let mut fan = SocFan {
            time_s: Vec::with_capacity(points),
            p5: Vec::with_capacity(points),
            p50: Vec::with_capacity(points),
            p95: Vec::with_capacity(points),
        };
        for k in 0..points {
            let row = &self.counts[k * FAN_BINS..(k + 1) * FAN_BINS];
            let total: u64 = row.iter().map(|&c| u64::from(c)).sum();
            if total == 0 {
                return None;
            }
            let at = |p: u64| {
                let rank = (p * total).div_ceil(100).max(1);
                let mut seen = 0;
                let bin = row
                    .iter()
                    .position(|&c| {
                        seen += u64::from(c);
                        seen >= rank
                    })
                    .unwrap_or(FAN_BINS - 1);
                (bin as f64 + 0.5) / FAN_BINS as f64
            };
            fan.time_s.push(k as f64 * dt);
            fan.p5.push(at(5));
            fan.p50.push(at(50));
            fan.p95.push(at(95));
        }
        Some(fan)
    }
}

/// The sink of one scenario's samples: its state of charge at each grid time, kept until the
/// flight ends and added to the histogram then ([`FanSink::finish`]). Every flight is in the fan,
/// one that ends early (its pack empty, a path it cannot fly) as one that lands: after its end it
/// keeps its last state of charge, so a band whose flights run out shows them running out
/// (it would otherwise have no flight to show at all).
pub(in crate::engine) struct FanSink<'h> {
    hist: &'h mut FanHistogram,
    /// State of charge at each grid time reached so far (at most the grid's points).
    at_grid: Vec<f64>,
    last_soc: Option<f64>,
    last_time_s: f64,
}

impl<'h> FanSink<'h> {
    pub(in crate::engine) fn new(hist: &'h mut FanHistogram) -> Self {
        Self {
            hist,
            at_grid: Vec::new(),
            last_soc: None,
            last_time_s: 0.0,
        }
    }

    /// After the flight: it goes into the histogram, the grid times after its end keeping its
    /// last state of charge (a flight without a sample adds nothing).
    pub(in crate::engine) fn finish(self) {
        let Some(soc) = self.last_soc else {
            return;
        };
        for (k, &s) in self.at_grid.iter().enumerate() {
            self.hist.add(k, s);
        }
        for k in self.at_grid.len()..FAN_POINTS {
            self.hist.add(k, soc);
        }
        self.hist.longest_s = self.hist.longest_s.max(self.last_time_s);
    }
}

impl SampleSink for FanSink<'_> {
    fn take(&mut self, s: &Sample) -> Result<(), PlannerError> {
        let dt = self.hist.dt_s();
        while self.at_grid.len() < FAN_POINTS && s.time_s >= self.at_grid.len() as f64 * dt {
            self.at_grid.push(s.soc);
        }
        self.last_soc = Some(s.soc);
        self.last_time_s = s.time_s;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_takes_the_ceiling_rank() {
        let v: Vec<f64> = (1..=1000).map(f64::from).collect();
        // ceil(5 x 1000 / 100) = 50: the 50th value.
        assert_eq!(nearest_rank(&v, 5).to_bits(), 50.0f64.to_bits());
        assert_eq!(nearest_rank(&v, 95).to_bits(), 950.0f64.to_bits());
        assert_eq!(nearest_rank(&[7.0], 5).to_bits(), 7.0f64.to_bits());
        let v = [1.0, 2.0, 3.0];
        // ceil(0.15) = 1, ceil(1.5) = 2, ceil(2.85) = 3
        assert_eq!(
            (
                nearest_rank(&v, 5),
                nearest_rank(&v, 50),
                nearest_rank(&v, 95)
            ),
            (1.0, 2.0, 3.0)
        );
    }

    #[test]
    fn fan_bands_follow_the_counts() {
        let mut h = FanHistogram::new(300.0);
        for k in 0..100 {
            let mut sink = FanSink::new(&mut h);
            // one sample per second from 0.9 down by 1e-3 per s, scenario k offset by k e-3
            for t in 0..200 {
                let s = Sample {
                    time_s: f64::from(t),
                    soc: 0.9 - 1e-3 * f64::from(t) - 1e-3 * f64::from(k),
                    ..test_sample()
                };
                sink.take(&s).unwrap();
            }
            sink.finish();
        }
        // Twenty flights that end early, at 0.3, keep 0.3 after their end: of 120 values the
        // 5th percentile is the 6th smallest, 0.3 at every time; the 95th is the 114th smallest,
        // the 94th of the 100 (k = 6): 0.9 - 6e-3 at t = 0.
        for _ in 0..20 {
            let mut sink = FanSink::new(&mut h);
            for t in 0..50 {
                let s = Sample {
                    time_s: f64::from(t),
                    soc: 0.3,
                    ..test_sample()
                };
                sink.take(&s).unwrap();
            }
            sink.finish();
        }
        let fan = h.bands().unwrap();
        // The grid stops at the longest flight (199 s), one grid step (1 s) beyond at most.
        assert!(*fan.time_s.last().unwrap() >= 199.0 && *fan.time_s.last().unwrap() < 201.0);
        // Within one bin (1e-3) of the value, by rounding.
        assert!(
            fan.p5.iter().all(|p| (p - 0.3).abs() <= 1e-3),
            "{:?}",
            fan.p5
        );
        assert!((fan.p95[0] - 0.894).abs() <= 1e-3, "{}", fan.p95[0]);
        assert!(fan.p5.iter().zip(&fan.p95).all(|(a, b)| a <= b));
    }

    fn test_sample() -> Sample {
        Sample {
            segment: 1,
            ..Sample::default()
        }
    }
}

/// When something happens in a flight (a failsafe triggers, the point of no return), s, over
/// scenarios: a percentile is left out where it falls on scenarios in which it does not happen
/// (before the landing: `p95` absent where in more than 5 % of them it never does).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct TimeBand {
    /// 5th percentile, s (of the point of no return: 95 % of the scenarios can still turn back
    /// until then).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p5: Option<f64>,
    /// Median, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p50: Option<f64>,
    /// 95th percentile, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p95: Option<f64>,
}

impl TimeBand {
    /// Whether no percentile is known (the key is then left out).
    pub fn is_empty(&self) -> bool {
        self.p5.is_none() && self.p50.is_none() && self.p95.is_none()
    }
}

/// The 5th, 50th and 95th percentiles ([`nearest_rank`]) of sorted times, infinite where it does
/// not happen, each left out where it falls on such a scenario; `None` where it happens in none.
pub(in crate::engine) fn time_band(sorted: &[f64]) -> Option<TimeBand> {
    if sorted.first().is_none_or(|t| !t.is_finite()) {
        return None;
    }
    let at = |p: usize| Some(nearest_rank(sorted, p)).filter(|t| t.is_finite());
    Some(TimeBand {
        p5: at(5),
        p50: at(50),
        p95: at(95),
    })
}
