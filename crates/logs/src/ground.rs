//! On the ground or in the air: where in a flight log the vehicle flies.
//!
//! A log often starts minutes before take-off and holds several flights with idle time between.
//! [`GroundDetector`] splits a record into airborne spans and the ground time around them, one
//! point at a time (memory grows with the number of flights, not with the log):
//!
//! 1. **The log's own state** where it has one ([`Sample::landed`]: PX4
//!    `vehicle_land_detected.landed`, ArduPilot arming and landing events). It is taken as it is,
//!    at the time of the point that carries it: the autopilot's detector has its own hysteresis
//!    and sees the motors' commands, which a log reader does not.
//! 2. **Otherwise, detected** from the point's speed, its height above the ground it last stood
//!    on, and its measured power. A point is *ground-like* when all the evidence it has says so:
//!    - still: ground speed under [`GroundOptions::max_speed_mps`] (0.5 m/s: GPS and estimator
//!      velocity noise on the ground is about 0.1 m/s; any take-off or landing moves faster);
//!    - low: within [`GroundOptions::max_height_m`] (1 m) of the ground height when the log has
//!      no power (the height is then the only evidence that separates a hover from the ground,
//!      and barometric noise on the ground is a few tenths of a metre), within
//!      [`GroundOptions::max_height_powered_m`] (5 m) when it has (the power then separates
//!      them, and the height only guards against a glitch of the power sensor at altitude: 5 m
//!      allows for the drift of a barometric height over a flight);
//!    - idle: power under [`GroundOptions::idle_max_w`] when the log has power. The caller sets
//!      it to a fraction of the hover power ([`IDLE_FRACTION_OF_HOVER`]): with thrust
//!      `T ~ P^(2/3)` at a given rotor, 30 % of the hover power makes at most 45 % of the weight,
//!      so a vehicle drawing that little is not holding itself up.
//!
//!    A point with neither a height nor a power is never ground-like (nothing tells a hover
//!    from the ground). The ground height is the height of the last ground-like point on the
//!    ground (the take-off point), followed while the vehicle stands, so a slow drift of the
//!    barometer on the ground and a landing away from the take-off height are both handled.
//!
//! **Hysteresis.** The detected state changes only when the opposite evidence lasts: a landing
//! needs [`GroundOptions::min_ground_s`] (2 s) of ground-like points, a take-off
//! [`GroundOptions::min_air_s`] (1 s) of others; the change is dated at the first of them (the
//! spin-up at take-off, the touch-down at landing). A hover near the ground is not ground-like
//! when the log has power (it draws hover power); without power, a hover under 1 m that lasts 2 s
//! is called ground, since nothing in such a log tells the two apart.
//!
//! **Gaps.** A landing seen on the first point after a gap in the record (no point for longer
//! than [`GroundOptions::max_gap_s`], 5 s: logging stopped, as ArduPilot does while disarmed, or
//! a dropout) is dated at the start of the gap: the record cannot say when in the gap the
//! vehicle landed, and time it does not cover is not flown. A take-off after a gap is dated at
//! its first point, as always.

use serde::Serialize;

use crate::sample::Sample;

/// Power below which a vehicle is idle, as a fraction of its hover power (see the module docs).
pub const IDLE_FRACTION_OF_HOVER: f64 = 0.3;

/// Thresholds of the detection (see the module docs for the reasons of each default).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundOptions {
    /// Ground speed under which a point is still, m/s.
    pub max_speed_mps: f64,
    /// Height above the ground height within which a point is low when the log has no power, m.
    pub max_height_m: f64,
    /// The same when the point has a power, m.
    pub max_height_powered_m: f64,
    /// Power under which a point is idle, W (`None`: power is not used).
    pub idle_max_w: Option<f64>,
    /// Ground-like time that makes a landing, s.
    pub min_ground_s: f64,
    /// Time of other points that makes a take-off, s.
    pub min_air_s: f64,
    /// Longest interval between points that is not a gap, s.
    pub max_gap_s: f64,
}

impl Default for GroundOptions {
    fn default() -> Self {
        Self {
            max_speed_mps: 0.5,
            max_height_m: 1.0,
            max_height_powered_m: 5.0,
            idle_max_w: None,
            min_ground_s: 2.0,
            min_air_s: 1.0,
            max_gap_s: 5.0,
        }
    }
}

/// What the detector needs of one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GroundPoint {
    /// Time, s (increasing).
    pub time_s: f64,
    /// The log's own state.
    pub landed: Option<bool>,
    /// Height (up), m.
    pub up_m: Option<f64>,
    /// Ground speed, m/s.
    pub speed_mps: Option<f64>,
    /// Measured electrical power, W.
    pub power_w: Option<f64>,
}

impl From<&Sample> for GroundPoint {
    fn from(s: &Sample) -> Self {
        let finite = |x: f64| x.is_finite().then_some(x);
        Self {
            time_s: s.time_s,
            landed: s.landed,
            up_m: s.pos_enu_m.and_then(|p| finite(p[2])),
            speed_mps: s
                .vel_enu_mps
                .and_then(|v| finite((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt())),
            power_w: s.electrical_power_w().and_then(finite),
        }
    }
}

/// An airborne span, s.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Span {
    /// Take-off, s.
    pub start_s: f64,
    /// Landing (or the end of the record), s.
    pub end_s: f64,
}

/// The airborne spans of a record and where the state came from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GroundReport {
    /// Airborne spans in time order; the rest of `[first_s, last_s]` is ground time.
    pub airborne: Vec<Span>,
    /// Time of the first point, s.
    pub first_s: f64,
    /// Time of the last point, s.
    pub last_s: f64,
    /// Points whose state the log recorded.
    pub logged_points: u64,
    /// Points whose state was detected.
    pub detected_points: u64,
}

impl GroundReport {
    /// Whether `t` lies in an airborne span.
    pub fn airborne_at(&self, t: f64) -> bool {
        let i = self.airborne.partition_point(|s| s.start_s <= t);
        i > 0 && t < self.airborne[i - 1].end_s
    }
}

/// The streaming detector (see the module docs).
#[derive(Debug, Clone)]
pub struct GroundDetector {
    options: GroundOptions,
    report: GroundReport,
    started: bool,
    on_ground: bool,
    /// Start of the current airborne span.
    since_s: f64,
    /// First point of evidence against the current state, and the time of the point before it.
    candidate_s: Option<(f64, f64)>,
    /// Time of the last point.
    last_s: f64,
    /// Height of the ground the vehicle last stood on, m.
    ground_up_m: Option<f64>,
}

impl GroundDetector {
    /// A detector that has seen nothing.
    pub fn new(options: GroundOptions) -> Self {
        Self {
            options,
            report: GroundReport::default(),
            started: false,
            on_ground: true,
            since_s: 0.0,
            candidate_s: None,
            last_s: f64::NAN,
            ground_up_m: None,
        }
    }

    /// Whether `p` looks like the ground (see the module docs).
    fn ground_like(&self, p: &GroundPoint) -> bool {
        let o = &self.options;
        let still = p.speed_mps.is_none_or(|v| v < o.max_speed_mps);
        let idle = match (p.power_w, o.idle_max_w) {
            (Some(w), Some(max)) => Some(w < max),
            _ => None,
        };
        let max_h = if idle.is_some() {
            o.max_height_powered_m
        } else {
            o.max_height_m
        };
        let low = p
            .up_m
            .map(|h| self.ground_up_m.is_none_or(|g| (h - g).abs() < max_h));
        still && (idle.is_some() || low.is_some()) && idle != Some(false) && low != Some(false)
    }

    /// The state becomes `ground` at `t`, the point after one at `before_s` (a landing after a gap
    /// is dated at the start of the gap).
    fn set(&mut self, ground: bool, t: f64, before_s: f64) {
        if ground == self.on_ground {
            return;
        }
        if ground {
            let gap = t - before_s > self.options.max_gap_s;
            self.report.airborne.push(Span {
                start_s: self.since_s,
                end_s: if gap { before_s.max(self.since_s) } else { t },
            });
        } else {
            self.since_s = t;
        }
        self.on_ground = ground;
    }

    /// Feed the next point (times must increase; a point that is not later is ignored).
    pub fn push(&mut self, p: &GroundPoint) {
        let t = p.time_s;
        if !t.is_finite() || (self.started && t <= self.report.last_s) {
            return;
        }
        if !self.started {
            self.started = true;
            self.report.first_s = t;
            self.on_ground = p.landed.unwrap_or_else(|| self.ground_like(p));
            self.since_s = t;
        }
        self.report.last_s = t;
        let before_s = if self.last_s.is_nan() { t } else { self.last_s };
        self.last_s = t;
        if let Some(landed) = p.landed {
            self.report.logged_points += 1;
            self.candidate_s = None;
            self.set(landed, t, before_s);
        } else {
            self.report.detected_points += 1;
            self.detect(p, before_s);
        }
        if self.on_ground && self.candidate_s.is_none() {
            self.ground_up_m = p.up_m.or(self.ground_up_m);
        }
    }

    /// One step of the detection with hysteresis.
    fn detect(&mut self, p: &GroundPoint, before_s: f64) {
        if self.ground_like(p) == self.on_ground {
            self.candidate_s = None;
            return;
        }
        let (since, since_before) = *self.candidate_s.get_or_insert((p.time_s, before_s));
        let needed = if self.on_ground {
            self.options.min_air_s
        } else {
            self.options.min_ground_s
        };
        if p.time_s - since >= needed {
            self.candidate_s = None;
            self.set(!self.on_ground, since, since_before);
        }
    }

    /// The airborne spans (a flight still going at the end of the record ends there).
    pub fn finish(mut self) -> GroundReport {
        if self.started && !self.on_ground {
            let end = self.report.last_s;
            self.report.airborne.push(Span {
                start_s: self.since_s,
                end_s: end,
            });
        }
        self.report
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points at 10 Hz from `(t0, t1, up, speed, power)` stretches.
    fn points(parts: &[(f64, f64, f64, f64, Option<f64>)]) -> Vec<GroundPoint> {
        let mut out = Vec::new();
        for &(t0, t1, up, speed, power) in parts {
            let n = ((t1 - t0) * 10.0).round() as usize;
            for k in 0..n {
                out.push(GroundPoint {
                    time_s: t0 + k as f64 * 0.1,
                    landed: None,
                    up_m: Some(up),
                    speed_mps: Some(speed),
                    power_w: power,
                });
            }
        }
        out
    }

    fn run(options: GroundOptions, pts: &[GroundPoint]) -> GroundReport {
        let mut d = GroundDetector::new(options);
        for p in pts {
            d.push(p);
        }
        d.finish()
    }

    fn powered() -> GroundOptions {
        GroundOptions {
            idle_max_w: Some(60.0),
            ..GroundOptions::default()
        }
    }

    // Time comparisons below: points are 0.1 s apart, so 0.05 s separates "this point" from
    // its neighbours.

    /// The airborne spans of `r` are `want` (start, end), each end to 0.05 s.
    fn assert_spans(r: &GroundReport, want: &[(f64, f64)]) {
        let near = |s: &Span, &(a, b): &(f64, f64)| {
            (s.start_s - a).abs() < 0.05 && (s.end_s - b).abs() < 0.05
        };
        let all =
            r.airborne.len() == want.len() && r.airborne.iter().zip(want).all(|(s, w)| near(s, w));
        assert!(all, "{:?}, want {want:?}", r.airborne);
    }

    #[test]
    fn two_flights_with_ground_before_between_and_after() {
        // 10 s idle at 12 W, 20 s flight at 200 W, 8 s idle, 15 s flight, 5 s idle.
        let pts = points(&[
            (0.0, 10.0, 0.0, 0.0, Some(12.0)),
            (10.0, 30.0, 10.0, 3.0, Some(200.0)),
            (30.0, 38.0, 0.3, 0.0, Some(12.0)),
            (38.0, 53.0, 8.0, 2.0, Some(200.0)),
            (53.0, 58.0, 0.3, 0.0, Some(12.0)),
        ]);
        let r = run(powered(), &pts);
        assert_spans(&r, &[(10.0, 30.0), (38.0, 53.0)]);
        assert_eq!(r.detected_points, pts.len() as u64);
        assert!(r.airborne_at(20.0) && !r.airborne_at(35.0) && !r.airborne_at(5.0));
    }

    #[test]
    fn a_hover_near_the_ground_with_power_is_not_landed() {
        // A 10 s hover 0.3 m up at 180 W between two stretches of flight.
        let pts = points(&[
            (0.0, 5.0, 0.0, 0.0, Some(5.0)),
            (5.0, 15.0, 5.0, 2.0, Some(200.0)),
            (15.0, 25.0, 0.3, 0.0, Some(180.0)),
            (25.0, 30.0, 5.0, 2.0, Some(200.0)),
        ]);
        let r = run(powered(), &pts);
        // Flying to the end of the record.
        assert_spans(&r, &[(5.0, 29.9)]);
    }

    #[test]
    fn short_dips_do_not_land_and_short_hops_do_not_take_off() {
        // In flight: 1 s still at idle power (under the 2 s a landing needs). On the ground:
        // a 0.5 s burst of power (under the 1 s a take-off needs).
        let pts = points(&[
            (0.0, 5.0, 0.0, 0.0, Some(5.0)),
            (5.0, 5.5, 0.0, 0.0, Some(150.0)),
            (5.5, 10.0, 0.0, 0.0, Some(5.0)),
            (10.0, 20.0, 6.0, 3.0, Some(200.0)),
            (20.0, 21.0, 0.5, 0.0, Some(5.0)),
            (21.0, 30.0, 6.0, 3.0, Some(200.0)),
        ]);
        let r = run(powered(), &pts);
        assert_eq!(r.airborne.len(), 1, "{:?}", r.airborne);
        assert!((r.airborne[0].start_s - 10.0).abs() < 0.05);
    }

    #[test]
    fn without_power_the_height_decides() {
        // No power: 4 s on the ground, a flight at 20 m, a landing 0.6 m above the take-off
        // height (barometric drift), 3 s on the ground.
        let pts = points(&[
            (0.0, 4.0, 0.0, 0.0, None),
            (4.0, 14.0, 20.0, 4.0, None),
            (14.0, 17.0, 0.6, 0.0, None),
        ]);
        let r = run(GroundOptions::default(), &pts);
        assert_spans(&r, &[(4.0, 14.0)]);
        // A still hover at 3 m without power is in the air.
        let pts = points(&[(0.0, 4.0, 0.0, 0.0, None), (4.0, 14.0, 3.0, 0.0, None)]);
        let r = run(GroundOptions::default(), &pts);
        assert_eq!(r.airborne.len(), 1);
    }

    #[test]
    fn the_logs_state_is_taken_as_it_is() {
        // The log says airborne from 2 s to 6 s, whatever the other channels say.
        let pts: Vec<GroundPoint> = (0..100)
            .map(|k| {
                let t = k as f64 * 0.1;
                GroundPoint {
                    time_s: t,
                    landed: Some(!(2.0 - 0.05..6.0 - 0.05).contains(&t)),
                    up_m: Some(0.0),
                    speed_mps: Some(0.0),
                    power_w: Some(1.0),
                }
            })
            .collect();
        let r = run(powered(), &pts);
        assert_spans(&r, &[(2.0, 6.0)]);
        assert_eq!((r.logged_points, r.detected_points), (100, 0));
    }

    #[test]
    fn a_landing_after_a_gap_is_dated_at_its_start() {
        // Airborne (by the log) from 1 s; no point from 3 s to 60 s; landed from 60 s on.
        let mut pts = Vec::new();
        for k in 0..90 {
            let t = if k < 30 {
                k as f64 * 0.1
            } else {
                57.0 + k as f64 * 0.1
            };
            pts.push(GroundPoint {
                time_s: t,
                landed: Some(!(1.0 - 0.05..60.0 - 0.05).contains(&t)),
                ..GroundPoint::default()
            });
        }
        let r = run(GroundOptions::default(), &pts);
        // The last point before the gap is at 2.9 s.
        assert_spans(&r, &[(1.0, 2.9)]);
    }

    #[test]
    fn nothing_to_go_on_is_airborne() {
        // No height and no power: every point counts as flown.
        let pts: Vec<GroundPoint> = (0..50)
            .map(|k| GroundPoint {
                time_s: k as f64 * 0.1,
                speed_mps: Some(0.0),
                ..GroundPoint::default()
            })
            .collect();
        let r = run(powered(), &pts);
        assert_eq!(r.airborne.len(), 1);
        assert!((r.airborne[0].end_s - r.airborne[0].start_s - 4.9).abs() < 1e-9);
    }
}
