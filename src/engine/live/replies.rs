//! What `aloft live` sends back on a link after each update, so a stock ground station shows it:
//!
//! - NAMED_VALUE_FLOAT: the reserve at landing (`rsv_p50`, `rsv_p5`, percent), the seconds to the
//!   point of no return (`pnr_s`) and the energy to finish (`rem_wh`). Mission Planner shows them
//!   in its Quick tab; QGroundControl ignores them.
//! - BATTERY_STATUS of aloft's own battery (`--battery-id`, [`DEFAULT_BATTERY_ID`]) at every
//!   update: aloft's state of charge, the time to the first failsafe that comes before home (its
//!   p5, the conservative end), the voltage and current as measured, the autopilot's count of
//!   the charge drawn where it is believed, and a charge state from the advice and the
//!   failsafes ([`charge_state`]). QGroundControl shows each battery id it hears
//!   as a battery of its own.
//! - STATUSTEXT when the advice changes, at a severity that QGroundControl speaks for `return now`,
//!   `do not take off` (WARNING) and `land now` (CRITICAL) and not for `continue` (INFO: it
//!   speaks NOTICE and graver); and once per flight, when a failsafe first comes before home, a
//!   WARNING naming it and when it triggers.

use std::collections::BTreeSet;

use aloft_logs::telemetry::{BatteryReply, ChargeState, Reply, Severity};

use super::{LiveFailsafe, LiveUpdate};

/// The battery id aloft's battery is sent under unless `--battery-id` says otherwise: above
/// those autopilots use (ArduPilot sends each of its monitors' BATTERY_STATUS with the monitor's
/// instance as the id, 0-15 with its up to 16 monitors; PX4 its `battery_status.id - 1`, 0-3
/// with its up to 4 instances), so it never takes a battery's place in a ground station.
pub const DEFAULT_BATTERY_ID: u8 = 100;

/// The component of the vehicle's system aloft's replies are sent from unless
/// `--display-component-id` says otherwise: MAV_COMP_ID_ONBOARD_COMPUTER (see
/// `aloft_link::DISPLAY_COMPONENT_ID`).
pub const DEFAULT_DISPLAY_COMPONENT_ID: u8 = 191;

/// The longest STATUSTEXT a message holds in one chunk, characters.
const TEXT_MAX: usize = 50;

/// The replies of a followed flight, update after update (see the module docs).
#[derive(Debug, Clone)]
pub struct LiveReplies {
    battery_id: u8,
    /// The failsafes said to come before home in this flight: (kind, source).
    said: BTreeSet<(&'static str, String)>,
    /// Whether the last update was in the air (a landing ends the flight's texts).
    was_in_air: bool,
}

impl LiveReplies {
    /// Replies with aloft's battery under `battery_id`.
    pub fn new(battery_id: u8) -> Self {
        Self {
            battery_id,
            said: BTreeSet::new(),
            was_in_air: false,
        }
    }

    /// What to send after `update` (the one before it `previous`): the values, aloft's battery,
    /// a text where the advice changed, and a text for each failsafe that comes before home for
    /// the first time in this flight.
    pub fn replies(&mut self, previous: Option<&LiveUpdate>, update: &LiveUpdate) -> Vec<Reply> {
        if self.was_in_air && !update.in_air {
            self.said.clear();
        }
        self.was_in_air = update.in_air;
        let mut out = values(update);
        out.push(Reply::Battery(self.battery(update)));
        out.extend(advice_text(previous, update));
        for f in update.failsafes.iter().filter(|f| f.before_home) {
            if self.said.insert((f.kind, f.source.clone())) {
                out.push(Reply::Text {
                    text: failsafe_text(f),
                    severity: Severity::Warning,
                });
            }
        }
        out
    }

    /// aloft's battery after `update`.
    fn battery(&self, update: &LiveUpdate) -> BatteryReply {
        BatteryReply {
            id: self.battery_id,
            remaining_percent: update.soc.map(|s| 100.0 * s),
            time_remaining_s: first_failsafe_s(&update.failsafes),
            voltage_v: update.voltage_v,
            current_a: update.current_a,
            consumed_mah: update.charge_drawn_ah.map(|c| 1000.0 * c),
            charge_state: charge_state(update),
        }
    }
}

/// The NAMED_VALUE_FLOAT of an update: the reserve at landing (p50 and p5, percent), the seconds
/// to the point of no return and the energy to finish.
fn values(update: &LiveUpdate) -> Vec<Reply> {
    let mut out = Vec::new();
    if let Some(l) = update.landing_soc {
        out.push(Reply::Value {
            name: "rsv_p50",
            value: 100.0 * l.p50,
        });
        out.push(Reply::Value {
            name: "rsv_p5",
            value: 100.0 * l.p5,
        });
    }
    if let Some(pnr) = update.point_of_no_return_s {
        out.push(Reply::Value {
            name: "pnr_s",
            value: pnr,
        });
    }
    if let Some(r) = update.remaining_wh {
        out.push(Reply::Value {
            name: "rem_wh",
            value: r.p50,
        });
    }
    out
}

/// A STATUSTEXT where the advice changed, at its severity ([`advice_severity`]).
fn advice_text(previous: Option<&LiveUpdate>, update: &LiveUpdate) -> Option<Reply> {
    let before = previous.and_then(|p| p.advice);
    let advice = update.advice.filter(|a| Some(*a) != before)?;
    let landing = update.landing_soc.map_or_else(String::new, |l| {
        format!(", lands at {:.0}% (p5)", 100.0 * l.p5)
    });
    Some(Reply::Text {
        text: format!("aloft: {advice}{landing}"),
        severity: advice_severity(advice),
    })
}

/// `continue` is information (QGroundControl does not speak it); `return now` and `do not take
/// off` are warnings; `land now`, and any other advice, critical.
pub fn advice_severity(advice: &str) -> Severity {
    match advice {
        "continue" => Severity::Info,
        "return now" | "do not take off" => Severity::Warning,
        _ => Severity::Critical,
    }
}

/// The charge state aloft's battery is sent with: from the advice (`continue` OK, `return now`
/// and `do not take off` CRITICAL, "return or abort immediately"; `land now` EMERGENCY, "too
/// low for the ordinary abort sequence"), at least LOW ("warn and monitor closely") where a
/// failsafe comes before home; UNDEFINED without either.
pub fn charge_state(update: &LiveUpdate) -> ChargeState {
    let advised = match update.advice {
        None => ChargeState::Undefined,
        Some("continue") => ChargeState::Ok,
        Some("return now" | "do not take off") => ChargeState::Critical,
        Some(_) => ChargeState::Emergency,
    };
    let warned = if update.failsafes.iter().any(|f| f.before_home) {
        ChargeState::Low
    } else {
        ChargeState::Undefined
    };
    advised.max(warned)
}

/// Seconds to the first failsafe that comes before home, at its p5 (the conservative end).
fn first_failsafe_s(failsafes: &[LiveFailsafe]) -> Option<f64> {
    failsafes
        .iter()
        .filter(|f| f.before_home)
        .filter_map(|f| f.time_s?.p5)
        .reduce(f64::min)
}

/// `aloft: low failsafe (BAT_LOW_THR) in 3:10 (p5)`; without the source where that is longer
/// than a STATUSTEXT holds; `before home` where no time is known.
fn failsafe_text(f: &LiveFailsafe) -> String {
    let when = f.time_s.and_then(|t| t.p5).map_or_else(
        || "before home".to_string(),
        |s| format!("in {} (p5)", clock(s)),
    );
    let full = format!("aloft: {} failsafe ({}) {when}", f.kind, f.source);
    if full.chars().count() <= TEXT_MAX {
        return full;
    }
    format!("aloft: {} failsafe {when}", f.kind)
}

/// `m:ss`, or `h:mm:ss` from an hour, of a number of seconds (rounded; negative is 0).
pub(crate) fn clock(seconds: f64) -> String {
    let total = seconds.max(0.0).round() as u64;
    let (h, m, s) = (total / 3600, total / 60 % 60, total % 60);
    if h > 0 {
        format!("{h}:{m:02}:{s:02}")
    } else {
        format!("{m}:{s:02}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::live::TimeBand;
    use crate::engine::uncertainty::scenario_stats::Percentiles;

    fn update(advice: &'static str, landing_p5: f64) -> LiveUpdate {
        LiveUpdate {
            in_air: true,
            remaining_wh: Some(Percentiles {
                p5: 4.5,
                p50: 5.0,
                p95: 5.5,
            }),
            landing_soc: Some(Percentiles {
                p5: landing_p5,
                p50: landing_p5 + 0.02,
                p95: landing_p5 + 0.04,
            }),
            point_of_no_return_s: Some(42.0),
            advice: Some(advice),
            ..LiveUpdate::default()
        }
    }

    fn failsafe(kind: &'static str, source: &str, p5: Option<f64>, before: bool) -> LiveFailsafe {
        LiveFailsafe {
            kind,
            source: source.into(),
            threshold: 0.15,
            unit: "fraction",
            time_s: Some(TimeBand {
                p5,
                p50: p5.map(|t| t + 20.0),
                p95: None,
            }),
            before_home: before,
            naive_time_s: None,
        }
    }

    fn texts(r: &[Reply]) -> Vec<(String, Severity)> {
        r.iter()
            .filter_map(|r| match r {
                Reply::Text { text, severity } => Some((text.clone(), *severity)),
                _ => None,
            })
            .collect()
    }

    fn battery(r: &[Reply]) -> BatteryReply {
        let b = r.iter().find_map(|r| match r {
            Reply::Battery(b) => Some(*b),
            _ => None,
        });
        b.expect("a BATTERY_STATUS reply")
    }

    /// Every update sends the four values and the battery; a STATUSTEXT only when the advice
    /// changes: `continue` at INFO, `return now` at WARNING, `land now` at CRITICAL.
    #[test]
    fn replies_send_the_values_the_battery_and_the_advice_at_its_severity() {
        let mut replies = LiveReplies::new(DEFAULT_BATTERY_ID);
        let first = update("continue", 0.30);
        let r = replies.replies(None, &first);
        let values: Vec<(&str, f64)> = r
            .iter()
            .filter_map(|r| match r {
                Reply::Value { name, value } => Some((*name, *value)),
                _ => None,
            })
            .collect();
        assert_eq!(values.len(), 4);
        assert_eq!(values[0].0, "rsv_p50");
        assert!((values[0].1 - 32.0).abs() < 1e-9);
        assert_eq!(values[1].0, "rsv_p5");
        assert_eq!(values[2], ("pnr_s", 42.0));
        assert_eq!(values[3], ("rem_wh", 5.0));
        assert_eq!(
            texts(&r),
            [(
                "aloft: continue, lands at 30% (p5)".to_string(),
                Severity::Info
            )]
        );
        // The same advice again: values and the battery only.
        let again = replies.replies(Some(&first), &update("continue", 0.25));
        assert_eq!(again.len(), 5);
        assert!(texts(&again).is_empty());
        let turn = replies.replies(Some(&first), &update("return now", 0.12));
        assert_eq!(texts(&turn)[0].1, Severity::Warning);
        assert!(texts(&turn)[0].0.starts_with("aloft: return now"));
        let land = replies.replies(Some(&first), &update("land now", 0.01));
        assert_eq!(texts(&land)[0].1, Severity::Critical);
        assert_eq!(advice_severity("do not take off"), Severity::Warning);
    }

    /// The battery: aloft's estimate as a percentage, the time to the earliest p5 of the
    /// failsafes before home (not of one after home), measured voltage and current.
    #[test]
    fn the_battery_is_alofts_estimate_and_the_first_failsafe_before_home() {
        let mut replies = LiveReplies::new(7);
        let u = LiveUpdate {
            soc: Some(0.634),
            voltage_v: Some(11.42),
            current_a: Some(18.5),
            reported_soc: Some(0.40),
            failsafes: vec![
                failsafe("critical", "BAT_CRIT_THR", Some(260.0), true),
                failsafe("low", "BAT_LOW_THR", Some(190.0), true),
                failsafe("emergency", "BAT_EMERGEN_THR", Some(100.0), false),
            ],
            ..update("return now", 0.05)
        };
        let b = battery(&replies.replies(None, &u));
        assert_eq!(b.id, 7);
        assert!((b.remaining_percent.unwrap() - 63.4).abs() < 1e-9);
        assert_eq!(b.time_remaining_s, Some(190.0));
        assert_eq!(b.voltage_v, Some(11.42));
        assert_eq!(b.current_a, Some(18.5));
        assert_eq!(b.charge_state, ChargeState::Critical);
        // No failsafe before home: no time; nothing known: nothing sent for it.
        let plain = battery(&replies.replies(None, &LiveUpdate::default()));
        assert_eq!(plain.time_remaining_s, None);
        assert_eq!(plain.remaining_percent, None);
        assert_eq!(plain.charge_state, ChargeState::Undefined);
    }

    #[test]
    fn the_charge_state_follows_the_advice_and_the_failsafes() {
        let with = |advice: Option<&'static str>, before: bool| LiveUpdate {
            advice,
            failsafes: vec![failsafe("low", "BATT_LOW_VOLT", Some(60.0), before)],
            ..LiveUpdate::default()
        };
        assert_eq!(
            charge_state(&with(Some("continue"), false)),
            ChargeState::Ok
        );
        assert_eq!(
            charge_state(&with(Some("continue"), true)),
            ChargeState::Low
        );
        assert_eq!(charge_state(&with(None, true)), ChargeState::Low);
        assert_eq!(charge_state(&with(None, false)), ChargeState::Undefined);
        let critical = charge_state(&with(Some("do not take off"), true));
        assert_eq!(critical, ChargeState::Critical);
        let land = charge_state(&with(Some("land now"), true));
        assert_eq!(land, ChargeState::Emergency);
    }

    /// A failsafe that comes before home is said once, at WARNING, with its p5 time; not again
    /// while it stays so; again in the next flight (after a landing).
    #[test]
    fn a_failsafe_before_home_is_said_once_a_flight() {
        let mut replies = LiveReplies::new(DEFAULT_BATTERY_ID);
        let after = LiveUpdate {
            failsafes: vec![failsafe("low", "BAT_LOW_THR", Some(400.0), false)],
            ..update("continue", 0.2)
        };
        let before = LiveUpdate {
            failsafes: vec![failsafe("low", "BAT_LOW_THR", Some(190.4), true)],
            ..update("return now", 0.1)
        };
        replies.replies(None, &after);
        let first = texts(&replies.replies(Some(&after), &before));
        let said = (
            "aloft: low failsafe (BAT_LOW_THR) in 3:10 (p5)".to_string(),
            Severity::Warning,
        );
        assert_eq!(first.len(), 2, "{first:?}");
        assert_eq!(first[1], said);
        assert!(texts(&replies.replies(Some(&before), &before)).is_empty());
        // It goes away and comes back in the same flight: not said again.
        replies.replies(Some(&before), &after);
        let back = texts(&replies.replies(Some(&after), &before));
        assert!(back.iter().all(|t| t.0 != said.0), "{back:?}");
        // Landed, then another flight: said again.
        let landed = LiveUpdate {
            in_air: false,
            ..after.clone()
        };
        replies.replies(Some(&before), &landed);
        let next = texts(&replies.replies(Some(&landed), &before));
        assert!(next.contains(&said), "{next:?}");
    }

    /// At most 50 characters: a long source is left out; hours are shown; no time is "before
    /// home".
    #[test]
    fn failsafe_texts_fit_a_statustext() {
        let long = failsafe("critical", "--critical-voltage-v", Some(4000.0), true);
        let t = failsafe_text(&long);
        assert_eq!(t, "aloft: critical failsafe in 1:06:40 (p5)");
        let none = failsafe("low", "BATT_LOW_VOLT", None, true);
        assert_eq!(
            failsafe_text(&none),
            "aloft: low failsafe (BATT_LOW_VOLT) before home"
        );
        for f in [&long, &none] {
            assert!(failsafe_text(f).chars().count() <= TEXT_MAX);
        }
        assert_eq!(clock(59.6), "1:00");
        assert_eq!(clock(-3.0), "0:00");
    }
}
