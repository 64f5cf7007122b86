//! The streaming join of binary logs' topics onto one time base, and what is known about their
//! battery records.
//!
//! A binary log (PX4 ULog, ArduPilot DataFlash) interleaves its topics in one stream, only
//! roughly in time order. The decoders turn each record they keep into an [`Event`]: an absolute
//! time and a partial [`Sample`] of one [`Stream`]. The [`Joiner`] makes one sample per record of
//! the base stream (the motion topic) and fills the other streams' channels by the same linear
//! interpolation as the PX4 CSV join ([`crate::px4::lerp_sample`]): between the two neighbouring
//! records of that stream, never across an interval longer than the bracket, never extrapolated.
//!
//! # Memory
//! A base record waits until every other stream (the landed state too, once it has a record) has
//! a record at or after its time, or until the
//! base stream has moved [`Joiner::SETTLE_S`] past it (a record that late could only bracket an
//! interval longer than the bracket), or until [`Joiner::MAX_PENDING`] records wait. Other
//! streams keep only the records a waiting base record can still use. Memory is bounded by the
//! rates of the kept topics, not by the length of the log.

use std::collections::VecDeque;

use serde::Serialize;

use crate::px4::lerp_sample;
use crate::sample::Sample;

/// Which part of the joined sample a record feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// The time base: the sample's position, velocity, acceleration (and attitude when the base
    /// record carries it).
    Base,
    /// Attitude.
    Attitude,
    /// Position (when not in the base).
    Position,
    /// Ground velocity (when not in the base).
    Velocity,
    /// Wind.
    Wind,
    /// Battery voltage and current, and the state of charge the autopilot reports.
    Battery,
    /// The landed state ([`Sample::landed`]), held from one record to the next. A record
    /// without a state declares that the log has the stream.
    Landed,
}

const SECONDARY: [Stream; 5] = [
    Stream::Attitude,
    Stream::Position,
    Stream::Velocity,
    Stream::Wind,
    Stream::Battery,
];

/// One decoded record: its absolute time (s, in the log's clock) and the channels it carries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    /// Absolute time, s.
    pub time_s: f64,
    /// The stream it feeds.
    pub stream: Stream,
    /// Its channels (the other fields `None`).
    pub sample: Sample,
}

/// The records of one secondary stream that waiting base records may still need, in time order.
#[derive(Default)]
struct Track {
    records: VecDeque<(f64, Sample)>,
    seen: bool,
}

impl Track {
    fn insert(&mut self, t: f64, s: Sample) {
        self.seen = true;
        // Roughly ordered input: find the place from the back.
        let at = self
            .records
            .iter()
            .rposition(|(u, _)| *u <= t)
            .map_or(0, |i| i + 1);
        self.records.insert(at, (t, s));
    }

    fn covers(&self, t: f64) -> bool {
        self.records.back().is_some_and(|(u, _)| *u >= t)
    }

    /// The stream's value at `t`, interpolated between neighbours at most `max_s` apart.
    fn at(&self, t: f64, max_s: f64) -> Option<Sample> {
        let i = self.records.iter().position(|(u, _)| *u >= t)?;
        let (tb, b) = &self.records[i];
        // 1e-9 s: time stamps are whole microseconds, so equal stamps compare equal.
        if (tb - t).abs() < 1e-9 {
            return Some(*b);
        }
        let (ta, a) = self.records.get(i.checked_sub(1)?)?;
        if tb - ta > max_s {
            return None;
        }
        Some(lerp_sample(a, b, (t - ta) / (tb - ta)))
    }

    /// Drop records before the one just before `t` (no later base record needs them).
    fn prune(&mut self, t: f64) {
        while self.records.len() > 2 && self.records[1].0 <= t {
            self.records.pop_front();
        }
    }
}

/// The streaming join (see the module docs).
pub struct Joiner {
    max_bracket_s: f64,
    pending: VecDeque<(f64, Sample)>,
    tracks: [Track; 5],
    /// Landed-state records a waiting base record may still need, in time order.
    landed: VecDeque<(f64, bool)>,
    landed_seen: bool,
    base_latest_s: f64,
    ready: VecDeque<(f64, Sample)>,
}

impl Joiner {
    /// How far the base stream must move past a waiting record before it is emitted without
    /// waiting for the other streams, beyond the bracket, s (covers the disorder of the topics).
    pub const SETTLE_S: f64 = 2.0;
    /// Most base records that wait.
    pub const MAX_PENDING: usize = 4096;

    /// A join that interpolates across intervals of at most `max_bracket_s`.
    pub fn new(max_bracket_s: f64) -> Self {
        Self {
            max_bracket_s,
            pending: VecDeque::new(),
            tracks: Default::default(),
            landed: VecDeque::new(),
            landed_seen: false,
            base_latest_s: f64::NEG_INFINITY,
            ready: VecDeque::new(),
        }
    }

    fn track(&mut self, s: Stream) -> Option<&mut Track> {
        let i = SECONDARY.iter().position(|x| *x == s)?;
        Some(&mut self.tracks[i])
    }

    /// Add a record.
    pub fn push(&mut self, e: Event) {
        if !e.time_s.is_finite() {
            return;
        }
        if e.stream == Stream::Base {
            let at = self
                .pending
                .iter()
                .rposition(|(u, _)| *u <= e.time_s)
                .map_or(0, |i| i + 1);
            self.pending.insert(at, (e.time_s, e.sample));
            self.base_latest_s = self.base_latest_s.max(e.time_s);
        } else if e.stream == Stream::Landed {
            // A record without a state declares the stream: base records wait for it from now.
            self.landed_seen = true;
            if let Some(l) = e.sample.landed {
                let at = self
                    .landed
                    .iter()
                    .rposition(|(u, _)| *u <= e.time_s)
                    .map_or(0, |i| i + 1);
                self.landed.insert(at, (e.time_s, l));
            }
        } else if let Some(t) = self.track(e.stream) {
            t.insert(e.time_s, e.sample);
        }
        self.settle(false);
    }

    /// No more records: every waiting base record is joined.
    pub fn finish(&mut self) {
        self.settle(true);
    }

    /// The next joined sample, with its absolute time.
    pub fn pop(&mut self) -> Option<(f64, Sample)> {
        self.ready.pop_front()
    }

    fn settle(&mut self, all: bool) {
        while let Some(&(t, _)) = self.pending.front() {
            let waited_out = self.base_latest_s >= t + self.max_bracket_s + Self::SETTLE_S
                || self.pending.len() > Self::MAX_PENDING;
            // A state record at or after `t` settles the state at `t` (sparse events wait out).
            let covered = self.tracks.iter().all(|k| !k.seen || k.covers(t))
                && (!self.landed_seen || self.landed.back().is_some_and(|(u, _)| *u >= t));
            if !(all || waited_out || covered) {
                return;
            }
            let (t, s) = self.pending.pop_front().expect("front exists");
            let joined = self.fill(t, s);
            self.ready.push_back((t, joined));
            for k in &mut self.tracks {
                k.prune(t);
            }
            // Keep the last state at or before `t`: later base records may still need it.
            while self.landed.get(1).is_some_and(|(u, _)| *u <= t) {
                self.landed.pop_front();
            }
        }
    }

    fn fill(&self, t: f64, mut s: Sample) -> Sample {
        let max = self.max_bracket_s;
        // 1e-9 s: time stamps are whole microseconds, so a record at `t` is at or before it.
        s.landed = self
            .landed
            .iter()
            .take_while(|(u, _)| *u <= t + 1e-9)
            .last()
            .map(|(_, l)| *l);
        for (k, stream) in self.tracks.iter().zip(SECONDARY) {
            let Some(v) = k.at(t, max) else { continue };
            match stream {
                Stream::Attitude => s.attitude = s.attitude.or(v.attitude),
                Stream::Position => s.pos_enu_m = s.pos_enu_m.or(v.pos_enu_m),
                Stream::Velocity => s.vel_enu_mps = s.vel_enu_mps.or(v.vel_enu_mps),
                Stream::Wind => s.wind_enu_mps = v.wind_enu_mps,
                Stream::Battery => {
                    s.voltage_v = v.voltage_v;
                    s.current_a = v.current_a;
                    s.soc = v.soc;
                }
                Stream::Base | Stream::Landed => {}
            }
        }
        s
    }
}

/// The battery records of a binary log: count, span, energy, and what was left out.
///
/// Energy is the trapezoid of V x I over consecutive valid records in file order (the rule of
/// the independent figures in `flight_logs/README.md`): a step whose time does not increase is
/// skipped.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct BatterySummary {
    /// Battery records of the chosen instance.
    pub records: u64,
    /// Records used (valid voltage and current).
    pub valid: u64,
    /// Records left out because the current was negative (PX4: unknown).
    pub unknown_current: u64,
    /// Records left out because the voltage was not positive (no sensor).
    pub no_voltage: u64,
    /// Absolute time of the first and last valid record, s.
    pub first_s: Option<f64>,
    /// Absolute time of the last valid record, s.
    pub last_s: Option<f64>,
    /// Integrated energy, J.
    pub energy_j: f64,
    #[serde(skip)]
    last: Option<(f64, f64)>,
}

impl BatterySummary {
    /// A battery record: `valid` says whether it counts (the caller applies the format's rule).
    pub fn push(&mut self, t: f64, v: f64, i: f64) {
        self.valid += 1;
        self.first_s.get_or_insert(t);
        self.last_s = Some(self.last_s.map_or(t, |l| l.max(t)));
        let p = v * i;
        if let Some((t0, p0)) = self.last {
            if t > t0 {
                self.energy_j += 0.5 * (p0 + p) * (t - t0);
            }
        }
        self.last = Some((t, p));
    }

    /// Span of the valid records, s.
    pub fn span_s(&self) -> f64 {
        match (self.first_s, self.last_s) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base(t: f64) -> Event {
        Event {
            time_s: t,
            stream: Stream::Base,
            sample: Sample {
                vel_enu_mps: Some([t, 0.0, 0.0]),
                ..Sample::default()
            },
        }
    }

    fn battery(t: f64, v: f64) -> Event {
        Event {
            time_s: t,
            stream: Stream::Battery,
            sample: Sample {
                voltage_v: Some(v),
                current_a: Some(1.0),
                ..Sample::default()
            },
        }
    }

    #[test]
    fn battery_is_interpolated_onto_the_base_out_of_order() {
        let mut j = Joiner::new(1.0);
        j.push(battery(0.0, 10.0));
        j.push(base(0.5));
        j.push(base(0.25));
        j.push(battery(1.0, 12.0));
        j.push(base(3.0));
        j.finish();
        let out: Vec<_> = std::iter::from_fn(|| j.pop()).collect();
        assert_eq!(out.len(), 3);
        // Linear between 10 V at 0 s and 12 V at 1 s; 1e-12 covers rounding.
        assert!((out[0].1.voltage_v.unwrap() - 10.5).abs() < 1e-12);
        assert!((out[1].1.voltage_v.unwrap() - 11.0).abs() < 1e-12);
        // 3 s is past the last battery record: not extrapolated.
        assert_eq!(out[2].1.voltage_v, None);
    }

    fn landed(t: f64, l: bool) -> Event {
        Event {
            time_s: t,
            stream: Stream::Landed,
            sample: Sample {
                landed: Some(l),
                ..Sample::default()
            },
        }
    }

    #[test]
    fn the_landed_state_holds_from_one_record_to_the_next() {
        // Events 10 s apart (far beyond the 1 s bracket): each holds until the next.
        let mut j = Joiner::new(1.0);
        j.push(base(0.0));
        j.push(landed(0.5, true));
        for k in 1..40 {
            j.push(base(k as f64 * 0.5));
            if k == 10 {
                j.push(landed(5.0, false));
            }
            if k == 30 {
                j.push(landed(15.0, true));
            }
        }
        j.finish();
        let out: Vec<_> = std::iter::from_fn(|| j.pop()).collect();
        assert_eq!(out.len(), 40);
        for (t, s) in &out {
            let want = if *t < 0.5 {
                None
            } else {
                Some(!(5.0..15.0).contains(t))
            };
            assert_eq!(s.landed, want, "at {t} s");
        }
    }

    #[test]
    fn memory_stays_bounded_without_the_other_streams() {
        let mut j = Joiner::new(1.0);
        j.push(battery(0.0, 10.0));
        for i in 0..100_000 {
            j.push(base(i as f64 * 0.01));
            while j.pop().is_some() {}
            assert!(j.pending.len() <= Joiner::MAX_PENDING + 1);
        }
    }

    #[test]
    fn battery_energy_is_the_trapezoid() {
        let mut b = BatterySummary::default();
        b.push(0.0, 10.0, 1.0);
        b.push(3600.0, 10.0, 3.0);
        // (10 + 30) / 2 W for one hour = 20 W h; 1e-9 covers rounding.
        assert!((b.energy_j / 3600.0 - 20.0).abs() < 1e-9);
    }
}
