//! `aloft live`: following a flight as it flies and answering, at every update, what the rest of
//! it costs and whether it can be flown.
//!
//! This module holds the answer of one update ([`LiveUpdate`], one JSON line) and the validation
//! route (`--route log`): a flight log replayed as if live, with the rest of the logged path as
//! the route ahead, so the prediction made at each time can be checked against the energy the
//! log measured from then to the end.
//!
//! At an update at time `t` of a replayed flight:
//!
//! 1. the efficiency is re-estimated from the samples so far: the energy ratio
//!    `r_d = E_measured / E_predicted` over `[t_0, t]` shrunk toward the fitted model by the
//!    uncertainty of each ([`crate::recalibration`]; power seed eqs 7 and 14), `r = exp(w ln r_d)`;
//! 2. the energy ahead is the model's power along the rest of the path times the ratio:
//!    `E_ahead = r * integral_t^end P_predicted dt` (the p50);
//! 3. its spread is that of the ratio of the rest, on the log scale the sum of two variances:
//!    the estimate's, `s^2 = s_p^2 s_d^2 / (s_p^2 + s_d^2)` (the fit's spread `s_p` between
//!    flights, or the scenarios' 3 % model error for a vehicle without one, combined with the
//!    window's standard error `s_d`), and the drift of the ratio along the flight, the variance
//!    of the log ratios of the 60 s blocks so far over the number of blocks ahead. p5 and p95 are
//!    `E_ahead exp(-+1.645 s_total)` (the limit of a Monte-Carlo draw of the ratio);
//! 4. beside it, the naive rate: the mean measured power so far times the time left,
//!    `P_mean(t_0..t) (t_end - t)` (the rate behind PX4's remaining-time estimate).
//!
//! The samples are those of `aloft validate` ([`crate::identify::align_flight`]): the logged
//! motion and attitude paired with the measured power at the estimated lag, the idle samples on
//! the ground left out, so the truth is the measured energy of the rest of the flight.

use serde::Serialize;

use super::finite::finite;
use super::logs::FlightLogs;
use super::scenario_stats::Percentiles;
use super::scenarios::DEFAULT_POWER_SD_PERCENT;
use super::vehicles::Vehicle;
use crate::error::Error;
use crate::identify::{predict, AlignedFlight};

/// The standard normal quantile of 95 %: p5 and p95 lie 1.645 standard deviations from p50.
const Z_95: f64 = 1.644_853_626_951_472_2;

/// Shortest window the efficiency is re-estimated from, s: before it an update answers with the
/// fitted model alone.
const MIN_WINDOW_S: f64 = 10.0;

/// Length of the blocks whose ratios measure how the ratio drifts along a flight, s.
const DRIFT_BLOCK_S: f64 = 60.0;

/// A replayed flight followed as if live, with the rest of the log as the route ahead.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveReplayRequest {
    /// The flight log (one file) and how to read it.
    pub logs: FlightLogs,
    /// Pack flown (default: the vehicle's).
    pub battery: Option<String>,
    /// Payload, kg.
    pub payload_kg: f64,
    /// An update every this many seconds of flight time.
    pub every_s: f64,
}

/// One update: a line of `aloft live --format json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveUpdate {
    /// Time since the start of the stream, s.
    pub time_s: f64,
    /// In the air.
    pub in_air: bool,
    /// Measured electrical energy so far, Wh.
    pub energy_used_wh: f64,
    /// Measured electrical power now, W.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power_w: Option<f64>,
    /// Whether the source measures power (without it the prediction is the model's alone).
    pub power_available: bool,
    /// The efficiency the rest is predicted with (re-estimated in flight).
    pub efficiency: f64,
    /// Energy to finish the route and land, Wh.
    pub remaining_wh: Percentiles,
    /// The naive rate: mean measured power so far times the route's remaining time, Wh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub naive_remaining_wh: Option<f64>,
    /// Validation mode: the energy the log measured from now to the end, Wh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_remaining_wh: Option<f64>,
    /// What to do: `continue`, `return now` or `land now`; absent where the pack's capacity or
    /// state is not known (a vehicle with a power table only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub advice: Option<&'static str>,
}

/// The end of a validation replay: how the predictions did against the measured rest.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveCheck {
    /// The log.
    pub file: String,
    /// Updates made.
    pub updates: usize,
    /// Span of the flight followed, s.
    pub duration_s: f64,
    /// Error of `remaining_wh.p50` against the measured rest at the checkpoints, percent.
    pub checkpoints: Vec<LiveCheckpoint>,
    /// Fraction of the updates whose p5-p95 band holds the measured rest.
    pub band_coverage: f64,
}

/// The prediction at one checkpoint of a validation replay.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveCheckpoint {
    /// `120 s`, `40 %`, `60 %` or `80 %` of the flight.
    pub at: String,
    /// Time of the update, s.
    pub time_s: f64,
    /// `(p50 - measured) / measured`, percent.
    pub error_percent: f64,
    /// The naive rate's error, percent.
    pub naive_error_percent: f64,
    /// Whether p5-p95 holds the measured rest.
    pub in_band: bool,
}

/// Replay `request`'s log as if live with the rest of the logged path as the route ahead: one
/// [`LiveUpdate`] every `every_s` seconds to `emit`, then the check of the predictions.
///
/// Steps: the model at the flown mass, the aligned flight, the model's power along it, then at
/// each update the re-estimate, the energy ahead and its spread.
///
/// # Errors
/// An unreadable log or one without power and motion (as `aloft validate`), an update interval
/// that is not positive, and `emit`'s own error.
pub fn replay_live(
    vehicle: &Vehicle,
    request: &LiveReplayRequest,
    emit: &mut dyn FnMut(&LiveUpdate) -> Result<(), Error>,
) -> Result<LiveCheck, Error> {
    if !(request.every_s.is_finite() && request.every_s > 0.0) {
        return Err(Error::InvalidInput {
            name: "every",
            value: request.every_s,
            unit: "s",
            expected: "a positive number of seconds",
        });
    }
    let (model, _) = vehicle.power_model_with(request.battery.as_deref(), request.payload_kg)?;
    let mut flights = request.logs.load()?;
    let (flight, _) = flights.swap_remove(0);
    let predicted = predict(&model, &flight)?;
    let series = Series::new(&flight, predicted);
    // Without a spread from a fit, the model error the scenarios assume.
    let prior_sd = Some(
        model
            .vehicle()
            .params()
            .efficiency_relative_sd
            .unwrap_or(DEFAULT_POWER_SD_PERCENT / 100.0),
    );
    let eta0 = model.vehicle().efficiency();
    let mut judge = Judge::new(series.duration_s());
    let mut t = series.t[0];
    let end = series.t[series.t.len() - 1];
    while t < end {
        let update = series.update_at(t, eta0, prior_sd);
        let update = finite(update, "live", || flight.source.clone())?;
        judge.add(&update, t - series.t[0]);
        emit(&update)?;
        t += request.every_s;
    }
    Ok(judge.finish(flight.source.clone()))
}

/// A flight's measured and predicted power, with their running energies.
struct Series {
    t: Vec<f64>,
    measured_w: Vec<f64>,
    predicted_w: Vec<f64>,
    /// Measured energy from the start to each sample, J.
    measured_j: Vec<f64>,
    /// Predicted energy from the start to each sample, J.
    predicted_j: Vec<f64>,
}

impl Series {
    fn new(flight: &AlignedFlight, predicted_w: Vec<f64>) -> Self {
        let measured_w: Vec<f64> = flight.samples.iter().map(|s| s.measured_power_w).collect();
        let t = flight.times_s.clone();
        let running = |p: &[f64]| {
            let mut acc = aloft_core::Trapezoid::new();
            t.iter()
                .zip(p)
                .map(|(&ti, &pi)| {
                    acc.push(ti, pi);
                    acc.integral()
                })
                .collect::<Vec<f64>>()
        };
        let (measured_j, predicted_j) = (running(&measured_w), running(&predicted_w));
        Self {
            t,
            measured_w,
            predicted_w,
            measured_j,
            predicted_j,
        }
    }

    fn duration_s(&self) -> f64 {
        self.t[self.t.len() - 1] - self.t[0]
    }

    /// The answer at time `t`: the samples up to it are "so far", the rest "ahead".
    fn update_at(&self, t: f64, eta0: f64, prior_sd: Option<f64>) -> LiveUpdate {
        let k = self.t.partition_point(|&x| x <= t).max(1) - 1;
        let last = self.t.len() - 1;
        let (so_far_m, so_far_p) = (self.measured_j[k], self.predicted_j[k]);
        let ahead_p = self.predicted_j[last] - so_far_p;
        let ahead_m = self.measured_j[last] - so_far_m;
        let elapsed = self.t[k] - self.t[0];
        let (ratio, sd) = if elapsed >= MIN_WINDOW_S && so_far_p > 0.0 && k >= 2 {
            let shrunk = crate::recalibration::shrink(
                so_far_m / so_far_p,
                &self.measured_w[..=k],
                &self.predicted_w[..=k],
                prior_sd,
            );
            // The shrunk estimate's variance is the window's times its weight: `w s_d^2 =
            // s_p^2 s_d^2 / (s_p^2 + s_d^2)`; without a finite window spread, the prior's.
            let estimate_sd = match shrunk.window_relative_sd {
                sd if sd.is_finite() => shrunk.window_weight.sqrt() * sd,
                _ => prior_sd.unwrap_or(0.0),
            };
            let drift_sd = self.drift_sd(k, self.t[last] - self.t[k]);
            (shrunk.ratio, estimate_sd.hypot(drift_sd))
        } else {
            (1.0, prior_sd.unwrap_or(0.0))
        };
        let p50 = ratio * ahead_p / 3600.0;
        let spread = (Z_95 * sd).exp();
        let time_left = self.t[last] - self.t[k];
        LiveUpdate {
            time_s: self.t[k],
            in_air: true,
            energy_used_wh: so_far_m / 3600.0,
            power_w: Some(self.measured_w[k]),
            power_available: true,
            efficiency: eta0 / ratio,
            remaining_wh: Percentiles {
                p5: p50 / spread,
                p50,
                p95: p50 * spread,
            },
            naive_remaining_wh: (elapsed > 0.0).then(|| so_far_m / elapsed * time_left / 3600.0),
            measured_remaining_wh: Some(ahead_m / 3600.0),
            advice: None,
        }
    }
}

impl Series {
    /// How far the ratio of the rest may drift from the flight's so far: the spread of the log
    /// ratios of the [`DRIFT_BLOCK_S`] blocks so far, over the square root of the blocks the rest
    /// holds (at least one); 0 with fewer than three blocks so far.
    fn drift_sd(&self, k: usize, rest_s: f64) -> f64 {
        let mut logs = Vec::new();
        let mut from = 0;
        for j in 1..=k {
            if self.t[j] - self.t[from] >= DRIFT_BLOCK_S {
                let m = self.measured_j[j] - self.measured_j[from];
                let p = self.predicted_j[j] - self.predicted_j[from];
                if m > 0.0 && p > 0.0 {
                    logs.push((m / p).ln());
                }
                from = j;
            }
        }
        if logs.len() < 3 {
            return 0.0;
        }
        let n = logs.len() as f64;
        let mean = logs.iter().sum::<f64>() / n;
        let var = logs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
        (var / (rest_s / DRIFT_BLOCK_S).max(1.0)).sqrt()
    }
}

/// The running check of a validation replay.
struct Judge {
    duration_s: f64,
    updates: usize,
    in_band: usize,
    judged: usize,
    /// The checkpoints not reached yet: (label, elapsed time).
    pending: Vec<(String, f64)>,
    checkpoints: Vec<LiveCheckpoint>,
}

impl Judge {
    fn new(duration_s: f64) -> Self {
        let mut pending = vec![("120 s".to_string(), 120.0)];
        for f in [40, 60, 80] {
            pending.push((format!("{f} %"), duration_s * f64::from(f) / 100.0));
        }
        pending.sort_by(|a, b| a.1.total_cmp(&b.1));
        Self {
            duration_s,
            updates: 0,
            in_band: 0,
            judged: 0,
            pending,
            checkpoints: Vec::new(),
        }
    }

    fn add(&mut self, u: &LiveUpdate, elapsed_s: f64) {
        self.updates += 1;
        let Some(truth) = u.measured_remaining_wh.filter(|m| *m > 0.0) else {
            return;
        };
        let inside = (u.remaining_wh.p5..=u.remaining_wh.p95).contains(&truth);
        self.judged += 1;
        self.in_band += usize::from(inside);
        while self.pending.first().is_some_and(|(_, at)| elapsed_s >= *at) {
            let (at, _) = self.pending.remove(0);
            let percent = |x: f64| 100.0 * (x - truth) / truth;
            self.checkpoints.push(LiveCheckpoint {
                at,
                time_s: u.time_s,
                error_percent: percent(u.remaining_wh.p50),
                naive_error_percent: u.naive_remaining_wh.map_or(f64::NAN, percent),
                in_band: inside,
            });
        }
    }

    fn finish(self, file: String) -> LiveCheck {
        LiveCheck {
            file,
            updates: self.updates,
            duration_s: self.duration_s,
            checkpoints: self.checkpoints,
            band_coverage: self.in_band as f64 / self.judged.max(1) as f64,
        }
    }
}
