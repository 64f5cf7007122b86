//! The validation route of `aloft live` (`--route log`): a flight log replayed as if live, with
//! the rest of the logged path as the route ahead, so the prediction made at each time can be
//! checked against the energy the log measured from then to the end.
//!
//! At an update at time `t`:
//!
//! 1. the efficiency is re-estimated from the samples so far ([`super::estimate`]: the energy
//!    ratio shrunk toward the fitted model, its spread from the estimate and the drift);
//! 2. the energy ahead is the model's power along the rest of the path times the ratio:
//!    `E_ahead = r * integral_t^end P_predicted dt` (the p50), the ratio at least the fitted
//!    efficiency `eta_0` (the rest flown at an efficiency `eta_0 / r` of at most 1, as `aloft
//!    live` flies it: [`super::estimate::flown_efficiency`]);
//! 3. p5 and p95 are `E_ahead exp(-+1.645 s)` with `s` the ratio's spread on the log scale (the
//!    limit of a Monte-Carlo draw of the ratio);
//! 4. beside it, the naive rate: the mean measured power so far times the time left,
//!    `P_mean(t_0..t) (t_end - t)` (the rate behind PX4's remaining-time estimate).
//!
//! The samples are those of `aloft validate` ([`crate::identify::align_flight`]): the logged
//! motion and attitude paired with the measured power at the estimated lag, the idle samples on
//! the ground left out, so the truth is the measured energy of the rest of the flight.

use serde::Serialize;

use super::estimate::RatioEstimator;
use super::failsafes::LiveFailsafe;
use super::replay_failsafes::{Ahead, PackReplay};
pub use super::replay_failsafes::{FailsafeCheck, FailsafeCheckpoint};
use super::LiveUpdate;
use crate::engine::basics::finite::finite;
use crate::engine::basics::logs::FlightLogs;
use crate::engine::uncertainty::scenario_stats::Percentiles;
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;
use crate::identify::{predict, AlignedFlight};

/// The standard normal quantile of 95 %: p5 and p95 lie 1.645 standard deviations from p50.
const Z_95: f64 = 1.644_853_626_951_472_2;

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
    /// The day's air (default: the log's own density where it has one, else the vehicle
    /// file's).
    pub air: crate::engine::conditions::air::AirInput,
    /// The low-voltage failsafe, pack volts, judged on the voltage under load averaged over
    /// 5 s (`--low-voltage-v`): the time until it triggers is predicted at each update.
    pub low_voltage_v: Option<f64>,
    /// The critical-voltage failsafe, pack volts (`--critical-voltage-v`).
    pub critical_voltage_v: Option<f64>,
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
    /// The voltage failsafes of the flags (`--low-voltage-v`, `--critical-voltage-v`): when
    /// the log crossed each, and the predictions 300 s and 120 s before.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub failsafes: Vec<FailsafeCheck>,
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
    /// The naive rate's error, percent (left out where the naive rate has no figure: at the
    /// first update).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub naive_error_percent: Option<f64>,
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
    super::check_every(request.every_s)?;
    let mut flights = request.logs.load()?;
    let (flight, log) = flights.swap_remove(0);
    // The flight in its own air: the given day, else the log's, else the vehicle file's.
    let air =
        crate::engine::conditions::air::log_air(&request.air, flight.air_density_kg_m3, vehicle)?;
    let (model, _) = vehicle
        .in_air(air.air_density_kg_m3)?
        .power_model_with(request.battery.as_deref(), request.payload_kg)?;
    let predicted = predict(&model, &flight)?;
    let series = Series::new(&flight, predicted);
    let prior_sd = super::estimate::prior_sd(&model);
    let eta0 = model.vehicle().efficiency();
    let mut estimator = RatioEstimator::new(prior_sd);
    let thresholds = super::thresholds(
        [request.low_voltage_v, request.critical_voltage_v],
        [None, None],
    );
    let mut pack = PackReplay::new(vehicle, request.battery.as_deref(), &thresholds, &log)?;
    let mut judge = Judge::new(series.duration_s());
    let (mut t, mut next) = (series.t[0], 0);
    let end = series.t[series.t.len() - 1];
    while t < end {
        // The samples up to `t` so far.
        while next < series.t.len() && series.t[next] <= t {
            estimator.push(
                series.t[next],
                series.measured_w[next],
                series.predicted_w[next],
            );
            next += 1;
        }
        let k = next.max(1) - 1;
        let mut update = series.update_at(k, &estimator, eta0);
        if let Some(pack) = pack.as_mut() {
            update.failsafes = series.failsafes_at(k, flight.lag_s, &mut update, eta0, pack);
        }
        let update = finite(update, "live", || flight.source.clone())?;
        judge.add(&update, t - series.t[0]);
        emit(&update)?;
        t += request.every_s;
    }
    let mut check = judge.finish(flight.source.clone());
    check.failsafes = pack.map_or_else(Vec::new, PackReplay::finish);
    Ok(check)
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

    /// The answer at sample `k`: the samples up to it (in `estimator`) are "so far", the rest
    /// "ahead".
    fn update_at(&self, k: usize, estimator: &RatioEstimator, eta0: f64) -> LiveUpdate {
        let last = self.t.len() - 1;
        let so_far_m = self.measured_j[k];
        let ahead_p = self.predicted_j[last] - self.predicted_j[k];
        let ahead_m = self.measured_j[last] - so_far_m;
        let elapsed = self.t[k] - self.t[0];
        let time_left = self.t[last] - self.t[k];
        let r = estimator.ratio(time_left);
        // As `aloft live` flies the rest: at an efficiency of at most 1.
        let efficiency = super::estimate::flown_efficiency(eta0, r.ratio);
        let p50 = eta0 / efficiency * ahead_p / 3600.0;
        let spread = (Z_95 * r.log_sd).exp();
        LiveUpdate {
            time_s: self.t[k],
            in_air: true,
            energy_used_wh: so_far_m / 3600.0,
            power_w: Some(self.measured_w[k]),
            power_available: true,
            efficiency,
            note: (eta0 / r.ratio > 1.0).then(|| super::estimate::EFFICIENCY_HELD_NOTE.to_string()),
            remaining_wh: Some(Percentiles {
                p5: p50 / spread,
                p50,
                p95: p50 * spread,
            }),
            naive_remaining_wh: (elapsed > 0.0).then(|| so_far_m / elapsed * time_left / 3600.0),
            measured_remaining_wh: Some(ahead_m / 3600.0),
            ..LiveUpdate::default()
        }
    }
}

impl Series {
    /// The voltage failsafes at the update at sample `k` (`update`, whose pack state they fill
    /// in): the pack's records up to its power's time (`t + lag_s`), the rest flown at the power
    /// ratios of the energy ahead's band (`eta_0 / efficiency` at p50, scaled as p5 and p95
    /// are), then judged.
    fn failsafes_at(
        &self,
        k: usize,
        lag_s: f64,
        update: &mut LiveUpdate,
        eta0: f64,
        pack: &mut PackReplay,
    ) -> Vec<LiveFailsafe> {
        let now_s = self.t[k] + lag_s;
        pack.advance(now_s);
        let ratio = eta0 / update.efficiency;
        let (lo, hi) = match update.remaining_wh {
            Some(b) if b.p50 > 0.0 => (b.p5 / b.p50, b.p95 / b.p50),
            _ => (1.0, 1.0),
        };
        let ahead = Ahead {
            t: &self.t,
            predicted_w: &self.predicted_w,
            k,
            ratios: (ratio * lo, ratio, ratio * hi),
        };
        let failsafes = pack.predict(now_s, &ahead);
        pack.state_into(update);
        pack.judge(now_s, &failsafes);
        failsafes
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
        let Some(band) = u.remaining_wh else {
            return;
        };
        let inside = (band.p5..=band.p95).contains(&truth);
        self.judged += 1;
        self.in_band += usize::from(inside);
        while self.pending.first().is_some_and(|(_, at)| elapsed_s >= *at) {
            let (at, _) = self.pending.remove(0);
            let percent = |x: f64| 100.0 * (x - truth) / truth;
            self.checkpoints.push(LiveCheckpoint {
                at,
                time_s: u.time_s,
                error_percent: percent(band.p50),
                naive_error_percent: u.naive_remaining_wh.map(percent),
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
            failsafes: Vec::new(),
        }
    }
}
