//! The voltage failsafes of the validation route (`aloft live --route log` with
//! `--low-voltage-v` / `--critical-voltage-v`): at each update, when the loaded voltage averaged
//! over 5 s will first fall below each threshold, predicted from the pack's state so far, beside
//! the naive rate, and checked at the end against the time the log's own average crossed it.
//!
//! At an update at motion time `t` (the log's battery records up to `t + lag`, as the energy so
//! far counts the measured power at `t + lag`):
//!
//! 1. **The pack so far**: the records fed to the same state as `aloft live` keeps
//!    ([`PackState`]: the filter started from the first record's voltage under load, a flight
//!    replayed being in the air; the pack's own gauge, `remaining / capacity`, fused as a
//!    [`ReportKind::Gauge`] report) and to the failsafes' monitor ([`Watched`]).
//! 2. **The rest flown on it**: the model's power along the rest of the path times the ratio the
//!    energy ahead takes (at p50, and at the p5 and p95 ratios for the band), turned into the
//!    pack's current through the filter's circuit, `I = P / V(I)` (two fixed-point steps from
//!    the last current), stepped through [`SocFilter::predict_mean`] and a clone of the
//!    monitor: the first trigger of each failsafe, s from now. The highest power on the pack's
//!    state drawn 1.645 standard deviations emptier ([`SocFilter::drawn`]) gives `p5`, the
//!    lowest on one as much fuller `p95`.
//! 3. **The naive rate**: a least-squares line through the 5 s average over the last
//!    [`NAIVE_WINDOW_S`], extrapolated to the threshold (none where it does not fall).
//!
//! The truth is a monitor run over the whole log: the record at which the measured 5 s average
//! first fell below each threshold.

use std::collections::{BTreeMap, VecDeque};

use aloft_packs::{FailsafeMonitor, ReportKind, SocFilter, VoltageThreshold};
use serde::Serialize;

use super::failsafes::{LiveFailsafe, TimeBand, Watched};
use super::pack_state::{PackState, Start};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// z-score of the 5th and 95th percentiles of a Gaussian.
const Z_90: f64 = 1.644_853_626_951_472_2;

/// The span of the 5 s averages the naive rate fits its line to, s.
pub(crate) const NAIVE_WINDOW_S: f64 = 60.0;

/// The checkpoints of a failsafe's prediction: this many seconds before the measured crossing.
const BEFORE_S: [f64; 2] = [300.0, 120.0];

/// One battery record of the log: time s, voltage V, current A, the gauge's state of charge
/// (0-1).
#[derive(Debug, Clone, Copy)]
struct Record {
    time_s: f64,
    voltage_v: f64,
    current_a: Option<f64>,
    power_w: Option<f64>,
    gauge_soc: Option<f64>,
}

/// The rest of the logged path, as the failsafes' prediction flies it.
pub(crate) struct Ahead<'a> {
    /// Motion times, s.
    pub(crate) t: &'a [f64],
    /// The model's power at each, W.
    pub(crate) predicted_w: &'a [f64],
    /// The sample of the update ("now").
    pub(crate) k: usize,
    /// The power ratios of the band's ends and median: (p5, p50, p95).
    pub(crate) ratios: (f64, f64, f64),
}

/// The voltage failsafes followed along a replayed log.
pub(crate) struct PackReplay {
    records: Vec<Record>,
    next: usize,
    pack: PackState,
    watched: Watched,
    /// The 5 s averages of the last [`NAIVE_WINDOW_S`]: (time s, V).
    averages: VecDeque<(f64, f64)>,
    /// The last current measured, A.
    last_current_a: Option<f64>,
    /// The checks, one per failsafe, with the latest update before each of [`BEFORE_S`].
    checks: Vec<(FailsafeCheck, [Option<FailsafeCheckpoint>; 2])>,
}

/// How the prediction of one failsafe did on a replayed log.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailsafeCheck {
    /// `low` or `critical`.
    pub kind: &'static str,
    /// The flag its threshold comes from.
    pub source: String,
    /// The threshold, V.
    pub threshold: f64,
    /// When the log's voltage under load averaged over 5 s first fell below it, s of the log
    /// (left out where it never did).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crossed_s: Option<f64>,
    /// The predictions made at the last updates at least 300 s and 120 s before the crossing.
    pub checkpoints: Vec<FailsafeCheckpoint>,
}

/// The prediction of one failsafe at one update before the log's crossing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailsafeCheckpoint {
    /// `300 s` or `120 s` (before the crossing).
    pub before: String,
    /// Time of the update, s of the log (the battery records up to it were known).
    pub log_time_s: f64,
    /// The time from the update to the crossing, s.
    pub actual_s: f64,
    /// The prediction, s from the update.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted_s: Option<TimeBand>,
    /// `predicted p50 - actual`, s (left out where the p50 does not trigger).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_s: Option<f64>,
    /// The naive rate's time, s from the update.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub naive_s: Option<f64>,
    /// `naive - actual`, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub naive_error_s: Option<f64>,
    /// Whether p5-p95 holds the actual time (a p95 left out: later than the log).
    pub in_band: bool,
}

impl PackReplay {
    /// The failsafes of the flags' `low_voltage_v` and `critical_voltage_v` on `log` flown with
    /// `vehicle`'s pack `battery`; `None` where no threshold is given.
    ///
    /// # Errors
    /// A vehicle without that pack; a log without the pack's voltage.
    pub(crate) fn new(
        vehicle: &Vehicle,
        battery: Option<&str>,
        thresholds: &[VoltageThreshold],
        log: &aloft_logs::Log,
    ) -> Result<Option<Self>, Error> {
        if thresholds.is_empty() {
            return Ok(None);
        }
        let pack = vehicle.battery(battery)?;
        let records = records(log, pack.capacity_ah());
        let no_voltage = || Error::NoVoltage {
            origin: log.source.clone(),
            flags: thresholds
                .iter()
                .map(|t| t.source.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        };
        if records.is_empty() {
            return Err(no_voltage());
        }
        let built = Watched::new(&BTreeMap::new(), pack.cells_series(), thresholds);
        let Ok(Some(watched)) = built else {
            return Err(no_voltage());
        };
        let checks = crossings(&watched, &records);
        Ok(Some(Self {
            records,
            next: 0,
            pack: PackState::new(&pack),
            watched,
            averages: VecDeque::new(),
            last_current_a: None,
            checks,
        }))
    }

    /// Feed the records up to `now_s` (s of the log) to the pack's state and the monitor.
    pub(crate) fn advance(&mut self, now_s: f64) {
        while let Some(r) = self.records.get(self.next).copied() {
            if r.time_s > now_s {
                break;
            }
            self.next += 1;
            self.feed(r);
        }
    }

    fn feed(&mut self, r: Record) {
        if !self.pack.running() {
            // A replayed flight is in the air from its first record: the filter starts from
            // its voltage under load.
            let loaded = Some((r.voltage_v, r.current_a.unwrap_or(0.0)));
            self.pack.start_from(Start::Full, ReportKind::Gauge, loaded);
            self.pack.in_air();
        }
        // The charge is counted from the current, else the power over the voltage (the energy
        // used is the count of last resort, over a gap in both: none is kept here).
        let measured = (Some(r.voltage_v), r.current_a, r.power_w);
        self.pack.sample(r.time_s, measured, 0.0);
        if let Some(soc) = r.gauge_soc {
            self.pack.report(r.time_s, soc, true, ReportKind::Gauge);
        }
        self.watched
            .sample(r.time_s, r.voltage_v, r.current_a, None);
        if let Some(i) = r.current_a {
            self.last_current_a = Some(i);
        }
        if let Some(v) = self.watched.monitor().loaded_average_v() {
            self.averages.push_back((r.time_s, v));
        }
        while self
            .averages
            .front()
            .is_some_and(|(t, _)| r.time_s - t > NAIVE_WINDOW_S)
        {
            self.averages.pop_front();
        }
    }

    /// The pack so far into `update`: the filter's state of charge and band, the gauge's
    /// last report, the last voltage and current measured.
    pub(crate) fn state_into(&self, update: &mut super::LiveUpdate) {
        if let Some(e) = self.pack.estimate() {
            update.soc = Some(e.soc);
            update.soc_band = Some(super::SocBand {
                p5: e.p5,
                p95: e.p95,
            });
        }
        update.reported_soc = self.pack.reported();
        let last = self.next.checked_sub(1).and_then(|k| self.records.get(k));
        update.voltage_v = last.map(|r| r.voltage_v);
        update.current_a = last.and_then(|r| r.current_a);
    }

    /// Each failsafe at the update at `now_s` (s of the log), the rest flown along `ahead`.
    pub(crate) fn predict(&self, now_s: f64, ahead: &Ahead<'_>) -> Vec<LiveFailsafe> {
        let runs: Vec<Vec<f64>> = match self.pack.filter() {
            Some(filter) => {
                // The band's ends: the higher power on the pack's state drawn 1.645 sd emptier
                // (its charge, and the curve's offset and the RC pair with it), and the lower on
                // one as much fuller.
                let (lo, mid, hi) = ahead.ratios;
                [(hi, -Z_90), (mid, 0.0), (lo, Z_90)]
                    .iter()
                    .map(|(r, z)| self.fly(&filter.drawn(*z), ahead, *r))
                    .collect()
            }
            None => Vec::new(),
        };
        let mut answer = self.watched.answer(&runs);
        let monitor = self.watched.monitor();
        for (k, a) in answer.iter_mut().enumerate() {
            a.naive_time_s = if monitor.has_triggered(k) {
                Some(0.0)
            } else {
                naive_time_s(&self.averages, now_s, a.threshold)
            };
        }
        answer
    }

    /// The rest flown at `ratio` times the model's power: each failsafe's first trigger, s
    /// from now (infinite where it does not trigger before the log's end).
    fn fly(&self, filter: &SocFilter, ahead: &Ahead<'_>, ratio: f64) -> Vec<f64> {
        let mut filter = filter.clone();
        let mut monitor: FailsafeMonitor = self.watched.monitor().clone();
        let n = monitor.failsafes().len();
        let mut first = vec![f64::INFINITY; n];
        let (t, k) = (ahead.t, ahead.k);
        let mut current_a = self.last_current_a.unwrap_or(0.0);
        for j in k + 1..t.len() {
            let dt_s = t[j] - t[j - 1];
            let power_w = ratio * ahead.predicted_w[j];
            current_a = current_at(&filter, power_w, current_a);
            filter.predict_mean(dt_s, current_a);
            let v = filter.terminal_v(current_a);
            for index in monitor.step(dt_s, v, Some(current_a), None).indexes() {
                first[index] = first[index].min(t[j] - t[k]);
            }
            if first.iter().all(|f| f.is_finite()) {
                break;
            }
        }
        first
    }

    /// Judge the update at `now_s` (s of the log) against the log's crossings.
    pub(crate) fn judge(&mut self, now_s: f64, failsafes: &[LiveFailsafe]) {
        for ((check, slots), f) in self.checks.iter_mut().zip(failsafes) {
            let Some(crossed) = check.crossed_s else {
                continue;
            };
            let actual_s = crossed - now_s;
            for (slot, before_s) in slots.iter_mut().zip(BEFORE_S) {
                if actual_s >= before_s {
                    *slot = Some(checkpoint(before_s, now_s, actual_s, f));
                }
            }
        }
    }

    /// The checks, each checkpoint only where an update came early enough.
    pub(crate) fn finish(self) -> Vec<FailsafeCheck> {
        self.checks
            .into_iter()
            .map(|(mut c, slots)| {
                c.checkpoints = slots.into_iter().flatten().collect();
                c
            })
            .collect()
    }
}

/// The log's records with a voltage, in time order; the gauge's remaining charge as a share
/// of `capacity_ah`.
fn records(log: &aloft_logs::Log, capacity_ah: f64) -> Vec<Record> {
    let mut out: Vec<Record> = Vec::new();
    for s in &log.samples {
        let Some(v) = s.voltage_v.filter(|v| v.is_finite() && *v > 0.0) else {
            continue;
        };
        if !s.time_s.is_finite() || out.last().is_some_and(|r| s.time_s < r.time_s) {
            continue;
        }
        out.push(Record {
            time_s: s.time_s,
            voltage_v: v,
            current_a: s.current_a.filter(|i| i.is_finite()),
            power_w: s.power_w.filter(|p| p.is_finite()),
            gauge_soc: s
                .soc
                .or_else(|| s.charge_ah.map(|q| q / capacity_ah))
                .filter(|x| x.is_finite()),
        });
    }
    out
}

/// The log's crossings: a fresh monitor over every record, each failsafe's first trigger.
fn crossings(
    watched: &Watched,
    records: &[Record],
) -> Vec<(FailsafeCheck, [Option<FailsafeCheckpoint>; 2])> {
    let mut monitor = watched.monitor().clone();
    let failsafes = monitor.failsafes().to_vec();
    let mut crossed = vec![None; failsafes.len()];
    let mut last_s: Option<f64> = None;
    for r in records {
        let dt_s = last_s.map_or(0.0, |t| r.time_s - t);
        last_s = Some(r.time_s);
        for k in monitor.step(dt_s, r.voltage_v, r.current_a, None).indexes() {
            crossed[k] = Some(r.time_s);
        }
    }
    failsafes
        .iter()
        .zip(crossed)
        .map(|(f, crossed_s)| {
            let check = FailsafeCheck {
                kind: f.kind.as_str(),
                source: f.source.clone(),
                threshold: f.threshold,
                crossed_s,
                checkpoints: Vec::new(),
            };
            (check, [None, None])
        })
        .collect()
}

/// The prediction `f` made at `now_s`, `actual_s` before the crossing.
fn checkpoint(before_s: f64, now_s: f64, actual_s: f64, f: &LiveFailsafe) -> FailsafeCheckpoint {
    let band = f.time_s;
    let p50 = band.and_then(|b| b.p50);
    let in_band = band.is_some_and(|b| {
        b.p5.is_some_and(|lo| lo <= actual_s) && b.p95.is_none_or(|hi| actual_s <= hi)
    });
    FailsafeCheckpoint {
        before: format!("{before_s:.0} s"),
        log_time_s: now_s,
        actual_s,
        predicted_s: band,
        error_s: p50.map(|p| p - actual_s),
        naive_s: f.naive_time_s,
        naive_error_s: f.naive_time_s.map(|n| n - actual_s),
        in_band,
    }
}

/// The pack's current for `power_w` through the filter's circuit: `I = P / V(I)`, two
/// fixed-point steps from `guess_a` (the terminal voltage moves by `R dI`, a few per cent of
/// `V`, so two steps settle it well within the current's own noise).
fn current_at(filter: &SocFilter, power_w: f64, guess_a: f64) -> f64 {
    let mut i = guess_a;
    for _ in 0..2 {
        // A circuit driven below a volt is an empty pack: the current is bounded there.
        i = power_w / filter.terminal_v(i).max(1.0);
    }
    i
}

/// The naive rate: a least-squares line through `averages` (time s, V), where it falls, to
/// `threshold_v`, s from `now_s` (at least 0).
fn naive_time_s(averages: &VecDeque<(f64, f64)>, now_s: f64, threshold_v: f64) -> Option<f64> {
    let n = averages.len() as f64;
    if averages.len() < 2 {
        return None;
    }
    let mean_t = averages.iter().map(|a| a.0).sum::<f64>() / n;
    let mean_v = averages.iter().map(|a| a.1).sum::<f64>() / n;
    let (mut stt, mut stv) = (0.0, 0.0);
    for (t, v) in averages {
        stt += (t - mean_t) * (t - mean_t);
        stv += (t - mean_t) * (v - mean_v);
    }
    // A line needs two distinct times; it reaches the threshold only where it falls.
    let slope_v_s = Some(stv / stt).filter(|_| stt > 0.0)?;
    if slope_v_s.is_nan() || slope_v_s >= 0.0 {
        return None;
    }
    let v_now = mean_v + slope_v_s * (now_s - mean_t);
    Some(((threshold_v - v_now) / slope_v_s).max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The naive line through a voltage falling 1 V a minute reaches a threshold 2 V below the
    /// present value in 120 s; a flat or rising trend gives none.
    #[test]
    fn the_naive_rate_extrapolates_a_falling_line_only() {
        let falling: VecDeque<(f64, f64)> = (0..=60)
            .map(|k| (f64::from(k), 50.0 - f64::from(k) / 60.0))
            .collect();
        let t = naive_time_s(&falling, 60.0, 47.0).unwrap();
        // 49 V at 60 s, 1/60 V/s: 2 V in 120 s (rounding only).
        assert!((t - 120.0).abs() < 1e-9, "{t}");
        let flat: VecDeque<(f64, f64)> = (0..=60).map(|k| (f64::from(k), 50.0)).collect();
        assert_eq!(naive_time_s(&flat, 60.0, 47.0), None);
        assert_eq!(
            naive_time_s(&VecDeque::from([(0.0, 50.0)]), 0.0, 47.0),
            None
        );
    }
}
