//! The autopilot's failsafes ahead of a flight followed live: for each one the vehicle watches,
//! when it triggers on the rest of the route.

use std::collections::BTreeMap;

use aloft_packs::{FailsafeAction, FailsafeMonitor, SocFilter, VehicleFailsafes, VoltageThreshold};
use serde::Serialize;

use crate::engine::uncertainty::scenario_stats::time_band;
pub use crate::engine::uncertainty::scenario_stats::TimeBand;
use crate::engine::uncertainty::scenarios::{Draws, ScenarioWatch, WatchRun};

/// One failsafe the vehicle watches, and when it triggers on the rest of the route.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveFailsafe {
    /// `low`, `critical` or `emergency`.
    pub kind: &'static str,
    /// Where its threshold comes from: the flag (`--low-voltage-v`), the pack file
    /// (`[failsafe]`) or the vehicle's parameter (`BATT_LOW_VOLT`, `BAT_LOW_THR`, ...).
    pub source: String,
    /// The threshold, in `unit`.
    pub threshold: f64,
    /// What the threshold is in: `V` (the pack's voltage under load), `fraction` (PX4's own
    /// estimate of the state of charge) or `mAh` (the charge drawn).
    pub unit: &'static str,
    /// When it triggers, s from now, over the scenarios (a percentile left out where it falls
    /// on scenarios in which it does not trigger before the landing; the whole left out where
    /// it triggers in none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_s: Option<TimeBand>,
    /// Whether it triggers before the route's landing (in at least 5 % of the scenarios).
    pub before_home: bool,
    /// The naive rate's time, s from now (`--route log` only): the voltage under load averaged
    /// over 5 s, its linear trend over the last 60 s extrapolated to the threshold (left out
    /// where the trend does not fall).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub naive_time_s: Option<f64>,
}

/// The failsafes a followed flight watches and their monitor, fed the measured samples so its
/// filters and timers stand where the autopilot's stand now ([`aloft_packs::FailsafeMonitor`]).
#[derive(Debug, Clone)]
pub(crate) struct Watched {
    vehicle: VehicleFailsafes,
    monitor: FailsafeMonitor,
    /// The parameters it was built from (a change rebuilds it).
    parameters: BTreeMap<String, f64>,
    last_time_s: Option<f64>,
}

impl Watched {
    /// The failsafes of `parameters` (the vehicle's, as heard), the pack's `cells` and the
    /// flags' `thresholds`; `None` where there is none to watch or the parameters are not a
    /// vehicle's (the reason, for the note).
    pub(crate) fn new(
        parameters: &BTreeMap<String, f64>,
        cells: u32,
        thresholds: &[VoltageThreshold],
    ) -> Result<Option<Self>, String> {
        let vehicle = VehicleFailsafes::from_parameters(parameters, Some(cells), thresholds)
            .map_err(|e| format!("the vehicle's failsafes are not watched: {e}"))?;
        if vehicle.failsafes.is_empty() {
            return Ok(None);
        }
        Ok(Some(Self {
            monitor: vehicle.monitor(),
            vehicle,
            parameters: parameters.clone(),
            last_time_s: None,
        }))
    }

    /// The monitor as it stands after the samples fed so far.
    pub(crate) fn monitor(&self) -> &FailsafeMonitor {
        &self.monitor
    }

    /// Whether it was built from `parameters`.
    pub(crate) fn is_of(&self, parameters: &BTreeMap<String, f64>) -> bool {
        &self.parameters == parameters
    }

    /// A measured sample at `time_s`: the pack's voltage (V), current (A) and the autopilot's
    /// count of the charge drawn (mA h), where known.
    pub(crate) fn sample(
        &mut self,
        time_s: f64,
        voltage_v: f64,
        current_a: Option<f64>,
        drawn_mah: Option<f64>,
    ) {
        let dt_s = self.last_time_s.map_or(0.0, |t| (time_s - t).max(0.0));
        self.last_time_s = Some(time_s);
        self.monitor.step(dt_s, voltage_v, current_a, drawn_mah);
    }

    /// The failsafes that end the flight when they trigger (an action, or one not known: a
    /// flag's), by index: a warning alone does not.
    pub(crate) fn acting(&self) -> Vec<bool> {
        self.vehicle
            .failsafes
            .iter()
            .map(|f| f.action != FailsafeAction::WarnOnly)
            .collect()
    }

    /// PX4's own estimate now, as the monitor emulates it (0-1), on a PX4.
    pub(crate) fn px4_remaining(&self) -> Option<f64> {
        self.monitor.px4_estimate().map(|e| e.remaining)
    }

    /// Whether a failsafe that acts has triggered already.
    pub(crate) fn acted(&self) -> bool {
        self.acting()
            .iter()
            .enumerate()
            .any(|(i, acts)| *acts && self.monitor.has_triggered(i))
    }

    /// The watch of the route ahead's scenarios, from the pack's state `filter` (its draws
    /// under `seed`).
    pub(crate) fn ahead<'a>(&'a self, filter: &'a SocFilter, seed: u64) -> AheadWatch<'a> {
        AheadWatch {
            watched: self,
            filter,
            seed,
        }
    }

    /// Each failsafe as the update says it, from the scenarios' runs (`runs`: each scenario's
    /// first trigger time per failsafe, s from now, infinite where it does not trigger).
    pub(crate) fn answer(&self, runs: &[Vec<f64>]) -> Vec<LiveFailsafe> {
        let n = runs.len();
        self.vehicle
            .failsafes
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let (time_s, share) = if self.monitor.has_triggered(i) {
                    let now = Some(0.0);
                    let band = TimeBand {
                        p5: now,
                        p50: now,
                        p95: now,
                    };
                    (Some(band), 1.0)
                } else {
                    let mut t: Vec<f64> = runs
                        .iter()
                        .map(|r| r.get(i).copied().unwrap_or(f64::INFINITY))
                        .collect();
                    t.sort_by(f64::total_cmp);
                    let share = t.iter().filter(|x| x.is_finite()).count() as f64 / n.max(1) as f64;
                    (time_band(&t), share)
                };
                LiveFailsafe {
                    kind: f.kind.as_str(),
                    source: f.source.clone(),
                    threshold: f.threshold,
                    unit: f.unit.as_str(),
                    time_s,
                    before_home: share >= BEFORE_HOME_SHARE,
                    naive_time_s: None,
                }
            })
            .collect()
    }
}

/// Share of the scenarios in which a failsafe must trigger before the landing for the update
/// to say it comes before home (the band's p5).
pub(crate) const BEFORE_HOME_SHARE: f64 = 0.05;

/// The route ahead's scenarios followed on the pack: each from a draw of the pack's state now,
/// the filter's circuit giving the voltage under the planned current, the failsafes' monitor
/// (as it stands now) judging it.
pub(crate) struct AheadWatch<'a> {
    watched: &'a Watched,
    filter: &'a SocFilter,
    seed: u64,
}

impl ScenarioWatch for AheadWatch<'_> {
    fn start(&self, index: usize) -> (Option<f64>, Box<dyn WatchRun>) {
        let z = Draws::of(self.seed, index).pack_state;
        let filter = self.filter.drawn(z);
        let n = self.watched.vehicle.failsafes.len();
        let run = AheadRun {
            soc0: filter.soc(),
            filter,
            monitor: self.watched.monitor.clone(),
            last_time_s: 0.0,
            first_s: vec![f64::INFINITY; n],
            least_v: f64::INFINITY,
        };
        (Some(run.soc0.clamp(0.0, 1.0)), Box::new(run))
    }
}

/// One scenario of the route ahead on the pack.
struct AheadRun {
    soc0: f64,
    filter: SocFilter,
    monitor: FailsafeMonitor,
    last_time_s: f64,
    first_s: Vec<f64>,
    least_v: f64,
}

impl WatchRun for AheadRun {
    fn take(&mut self, sample: &aloft_planner::Sample) {
        let dt_s = (sample.time_s - self.last_time_s).max(0.0);
        self.last_time_s = sample.time_s;
        let i = sample.current_a;
        self.filter.predict_mean(dt_s, i);
        let v = self.filter.terminal_v(i);
        self.least_v = self.least_v.min(v);
        for k in self.monitor.step(dt_s, v, Some(i), None).indexes() {
            if let Some(t) = self.first_s.get_mut(k) {
                *t = t.min(sample.time_s);
            }
        }
    }

    /// The first trigger time of each failsafe, then the least voltage under load.
    fn finish(&mut self) -> Vec<f64> {
        let mut out = self.first_s.clone();
        out.push(self.least_v);
        out
    }
}
