//! The autopilot's failsafes ahead of a flight followed live: for each one the vehicle watches,
//! when it triggers on the rest of the route.

use serde::Serialize;

/// When a failsafe triggers, s from now, over the scenarios of the route ahead: a percentile is
/// left out where it falls on scenarios in which the failsafe does not trigger before the
/// landing (`p95` absent: in more than 5 % of them it never does).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct TimeBand {
    /// 5th percentile, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p5: Option<f64>,
    /// Median, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p50: Option<f64>,
    /// 95th percentile, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p95: Option<f64>,
}

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
    /// When it triggers, s from now (left out where it does not trigger before the landing in
    /// any scenario).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_s: Option<TimeBand>,
    /// Whether it triggers before the route's landing (in at least 5 % of the scenarios).
    pub before_home: bool,
}
