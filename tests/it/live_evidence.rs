//! `aloft live` believes only physical evidence (issue 41, item 3), event by event through
//! [`LiveSession`] with synthetic telemetry: an M100 (TB47D, 4.5 A h, 99.9 W h) hovering in
//! `LOITER` 20 m above home, armed and in the air, drawing 12 A at 22.8 V (273.6 W), its
//! battery reported once a second.
//!
//! - The autopilot's count of the charge drawn (BATTERY_STATUS `current_consumed`) that jumps to
//!   `INT32_MAX` mA h, goes back (a wrap) or is negative is not believed, the note says so once,
//!   and the state of charge goes on from the evidence believed (the reports, or the energy).
//!   Before the fix each gave a state of charge of 0 and `land now` while the vehicle reported
//!   70 %.
//! - 20 s of a reported 0 % gave `land now` to the end of the flight after the report returned:
//!   the advice follows the evidence back to `continue`, within the hold time the docs state.
//! - The advice does not flap with a report that alternates across the line between two
//!   advices: it turns at once to the graver one and back only after the milder one has held.

use aloft::engine::{LiveRequest, LiveSession, LiveUpdate, Vehicle};
use aloft_logs::sample::{Attitude, Sample};
use aloft_logs::telemetry::{BatteryState, Event, Heartbeat, Telemetry};

/// The hover's current, A, and voltage, V.
const CURRENT_A: f64 = 12.0;
const VOLTAGE_V: f64 = 22.8;

/// The TB47D's capacity, A h, and rated energy, W h (`fixtures/vehicles/dji-m100.toml`).
const CAPACITY_AH: f64 = 4.5;
const RATED_WH: f64 = 99.9;

/// How long a milder advice must hold before it is given, s (docs/guide.md, "the advice"):
/// the hold time the tests allow, plus one update.
const HOLD_S: f64 = 5.0;

/// The charge the hover draws in `t_s` seconds, A h.
fn drawn_ah(t_s: f64) -> f64 {
    CURRENT_A * t_s / 3600.0
}

/// `INT32_MAX` mA h in A h, the count a corrupted BATTERY_STATUS carries.
const INT32_MAX_AH: f64 = 2_147_483.647;

/// What the battery says at second `t` (reported state of charge, the autopilot's count), or
/// `None` for nothing.
type BatteryAt = dyn Fn(u32) -> (Option<f64>, Option<f64>);

/// A session over `seconds` of the hover, an update every second after the battery's message;
/// `reserve_percent` the reserve asked (default 20).
fn fly(seconds: u32, reserve_percent: Option<f64>, battery: &BatteryAt) -> Vec<LiveUpdate> {
    let vehicle = Vehicle::builtin("dji-m100").expect("built-in vehicle");
    let request = LiveRequest {
        scenarios: 20,
        reserve_percent,
        ..LiveRequest::new()
    };
    let mut session = LiveSession::new(&vehicle, &request).expect("session");
    session.apply(&at(0.0, Event::Home([0.0, 0.0, 0.0])));
    let mut updates = Vec::new();
    for s in 0..=seconds {
        for k in 0..5 {
            let t = f64::from(s) + 0.2 * f64::from(k);
            if k == 0 {
                let heartbeat = Heartbeat {
                    armed: true,
                    mode: "LOITER".to_string(),
                    vehicle_type: 2,
                };
                session.apply(&at(t, Event::Heartbeat(heartbeat)));
            }
            let motion = Sample {
                time_s: t,
                pos_enu_m: Some([0.0, 0.0, 20.0]),
                vel_enu_mps: Some([0.0; 3]),
                attitude: Some(Attitude::default()),
                landed: Some(false),
                ..Sample::default()
            };
            session.apply(&at(t, Event::Sample(motion)));
            let power = Sample {
                time_s: t,
                voltage_v: Some(VOLTAGE_V),
                current_a: Some(CURRENT_A),
                ..Sample::default()
            };
            session.apply(&at(t, Event::Sample(power)));
        }
        let t = f64::from(s) + 0.8;
        let (soc, consumed_ah) = battery(s);
        if soc.is_some() || consumed_ah.is_some() {
            let state = BatteryState { soc, consumed_ah };
            session.apply(&at(t, Event::Battery(state)));
        }
        updates.push(session.update());
    }
    updates
}

fn at(time_s: f64, event: Event) -> Telemetry {
    Telemetry { time_s, event }
}

/// The report of a pack at `from` (0-1) drawn at the hover's current for `t_s` seconds, in
/// MAVLink's whole percent.
fn reported(from: f64, t_s: f64) -> f64 {
    ((from - drawn_ah(t_s) / CAPACITY_AH) * 100.0).round() / 100.0
}

/// The count of a pack counted from 0.5 A h at second 0, A h, in MAVLink's whole mA h.
fn counted(t_s: f64) -> f64 {
    ((0.5 + drawn_ah(t_s)) * 1000.0).round() / 1000.0
}

fn soc(u: &LiveUpdate) -> f64 {
    u.soc.expect("a state of charge in the air")
}

fn notes(updates: &[LiveUpdate], word: &str) -> Vec<(f64, String)> {
    updates
        .iter()
        .filter_map(|u| u.note.as_ref().map(|n| (u.time_s, n.clone())))
        .filter(|(_, n)| n.contains(word))
        .collect()
}

/// Every update in the air says `continue` and follows the reports within 1.5 % (MAVLink's whole
/// percent, and up to a second of drawing between the report and the update).
fn follows_the_reports(updates: &[LiveUpdate], from: f64) {
    for u in updates {
        assert!(u.in_air, "{u:?}");
        assert_eq!(u.advice, Some("continue"), "{u:?}");
        let want = from - drawn_ah(u.time_s) / CAPACITY_AH;
        assert!((soc(u) - want).abs() < 0.015, "{} vs {want}: {u:?}", soc(u));
    }
}

/// The count says exactly one note about it over the stream (said once, not every update).
fn said_once(updates: &[LiveUpdate], what: &str) {
    let said = notes(updates, "current_consumed");
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(
        said[0].1.contains(what) && said[0].1.contains("not believed"),
        "{said:?}"
    );
}

/// A count that jumps to `INT32_MAX` mA h at 10 s while the vehicle reports 70 %: the count is
/// not believed (the note says so once), the state of charge follows the reports, `continue`
/// throughout. Before: 0 % and `land now` from 10 s on.
#[test]
fn a_charge_count_that_jumps_to_int32_max_is_not_believed() {
    let updates = fly(30, None, &|s| {
        let t = f64::from(s) + 0.8;
        let count = if s < 10 { counted(t) } else { INT32_MAX_AH };
        (Some(reported(0.70, t)), Some(count))
    });
    follows_the_reports(&updates, 0.70);
    said_once(&updates, "more than the");
}

/// A count that goes back (a reset or a wrap: from 0.54 A h to 0.002 A h at 10 s, counting on
/// from there) and after 5 s comes back to its own track: not believed while it is back, said
/// once, the reports followed, `continue`. Before: the count's return took 0.5 A h (11 % of
/// the pack) off at once.
#[test]
fn a_charge_count_that_goes_back_is_not_believed() {
    let updates = fly(30, None, &|s| {
        let t = f64::from(s) + 0.8;
        let count = match (10..15).contains(&s) {
            false => counted(t),
            true => counted(t) - 0.5 + 0.002,
        };
        (Some(reported(0.70, t)), Some(count))
    });
    follows_the_reports(&updates, 0.70);
    said_once(&updates, "went back");
}

/// A negative count (a 32-bit wrap: `INT32_MIN` mA h, counting on) from 10 s to 15 s, then the
/// count of before: not believed while negative, said once, the reports followed, `continue`.
/// Before: the count's return from `INT32_MIN` drew the pack to 0 % and `land now`.
#[test]
fn a_negative_charge_count_is_not_believed() {
    let updates = fly(30, None, &|s| {
        let t = f64::from(s) + 0.8;
        let count = match (10..15).contains(&s) {
            false => counted(t),
            true => -2_147_483.648 + drawn_ah(t),
        };
        (Some(reported(0.70, t)), Some(count))
    });
    follows_the_reports(&updates, 0.70);
    said_once(&updates, "negative");
}

/// Without reports, the count is the evidence until it jumps (at 20 s, by 1 A h in a second
/// at 12 A, which draws 3.3 mA h a second); from then on the charge drawn is the energy used
/// over the pack's rated energy, from the start (a full pack at the autopilot's boot, the count
/// at 0). Before: 1 A h taken off at once (22 % of the pack).
#[test]
fn without_reports_a_jumping_count_gives_way_to_the_energy_used() {
    let updates = fly(40, None, &|s| {
        let t = f64::from(s) + 0.8;
        let count = drawn_ah(t) + if s < 20 { 0.0 } else { 1.0 };
        (None, Some((count * 1000.0).round() / 1000.0))
    });
    for u in &updates {
        let t = u.time_s;
        let want = match t < 20.5 {
            // The count believed: full at boot less the count (to a mA h).
            true => 1.0 - drawn_ah(t) / CAPACITY_AH,
            // The energy measured since the first power sample (at 0 s).
            false => 1.0 - VOLTAGE_V * CURRENT_A * t / 3600.0 / RATED_WH,
        };
        assert!(
            (soc(u) - want).abs() < 0.002,
            "at {t} s: {} vs {want}",
            soc(u)
        );
    }
    said_once(&updates, "rose from");
}

/// 20 s of a reported 0 % (from 10 s to 30 s) between reports of a pack drawn from 90 %: the
/// 0 % is believed once it has lasted (a fall that lasts is a new estimate), and the advice
/// turns to `land now`; when the reports come back to the pack's track, so does the state of
/// charge at once, and the advice returns to `continue` within the hold time. Before: `land
/// now` to the end of the flight.
#[test]
fn the_advice_follows_a_report_that_returns_after_20_s_at_zero() {
    let updates = fly(60, None, &|s| {
        let t = f64::from(s) + 0.8;
        let soc = if (10..30).contains(&s) {
            0.0
        } else {
            reported(0.90, t)
        };
        (Some(soc), None)
    });
    for u in &updates {
        println!("{:5.1} s  {:.3}  {:?}", u.time_s, soc(u), u.advice);
    }
    assert!(
        updates
            .iter()
            .any(|u| u.time_s < 30.0 && u.advice == Some("land now")),
        "{updates:?}"
    );
    for u in updates.iter().filter(|u| u.time_s >= 30.0) {
        let want = 0.90 - drawn_ah(u.time_s) / CAPACITY_AH;
        assert!((soc(u) - want).abs() < 0.015, "{} vs {want}: {u:?}", soc(u));
    }
    for u in updates.iter().filter(|u| u.time_s >= 30.0 + HOLD_S + 1.0) {
        assert_eq!(u.advice, Some("continue"), "{u:?}");
    }
}

/// A report that alternates every second between a level where the reserve holds and one
/// where it does not (34 % and 22 % with a 20 % reserve, within 15 % of each other: each is
/// believed): `land now` at the first low report, and it holds while the reports alternate;
/// `continue` only after the high level has held for the hold time. Each level alone gives its
/// own advice (checked first), so the line lies between them.
#[test]
fn the_advice_does_not_flap_with_a_report_across_the_line() {
    let (high, low) = (0.34, 0.22);
    let steady = |level: f64| fly(8, Some(20.0), &move |_| (Some(level), None));
    assert!(steady(high).iter().all(|u| u.advice == Some("continue")));
    assert!(steady(low).iter().all(|u| u.advice == Some("land now")));
    // High to 10 s, alternating to 30 s, high again.
    let updates = fly(50, Some(20.0), &move |s| {
        let level = match (10..30).contains(&s) && s % 2 == 0 {
            true => low,
            false => high,
        };
        (Some(level), None)
    });
    let advice = |from: f64, to: f64| {
        updates
            .iter()
            .filter(move |u| (from..to).contains(&u.time_s))
            .map(|u| u.advice.expect("advice"))
            .collect::<Vec<_>>()
    };
    assert!(advice(0.0, 10.0).iter().all(|a| *a == "continue"));
    let alternating = advice(10.0, 30.0);
    assert!(
        alternating.iter().all(|a| *a == "land now"),
        "{alternating:?}"
    );
    let after = advice(30.0 + HOLD_S + 1.0, 51.0);
    assert!(after.iter().all(|a| *a == "continue"), "{after:?}");
}
