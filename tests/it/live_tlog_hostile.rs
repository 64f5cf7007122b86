//! `aloft live --tlog` on telemetry logs built here to carry what a security review found: positions
//! off the Earth or out of any multirotor's reach (believed, they turned the advice to `land
//! now`), a bad first fix (it became the origin, and home with it), and clock steps in the log's
//! timestamps (11.6 days flown as time, 100 s of updates silenced, a file with no usable timestamp
//! read as an empty flight with exit 0).
//!
//! The flight: an armed quadrotor in LOITER, hovering 20 m above its home at 47.3977 N,
//! 8.5456 E with 80 % of its charge, for 40 s: GLOBAL_POSITION_INT and ATTITUDE at 5 Hz,
//! HEARTBEAT, SYS_STATUS, EXTENDED_SYS_STATE (in the air) and HOME_POSITION at 1 Hz. What is
//! expected is what the test wrote: the vehicle never leaves home, and a vehicle 20 m above its
//! home with 80 % of an M100's pack has no reason to do anything but continue.
#![cfg(feature = "live")]

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use aloft_link::mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavLandedState, MavMessage, MavModeFlag, MavState, MavType, ATTITUDE_DATA,
    EXTENDED_SYS_STATE_DATA, GLOBAL_POSITION_INT_DATA, HEARTBEAT_DATA, HOME_POSITION_DATA,
    SYS_STATUS_DATA,
};
use aloft_link::mavlink::{write_v2_msg, MavHeader};
use common::{aloft, scratch, stderr};
use serde_json::Value;

/// The first timestamp of the logs, µs since the Unix epoch (2023-11-14).
const T0_US: u64 = 1_700_000_000_000_000;
/// Home: 47.3977 N, 8.5456 E (1e-7 deg), 488 m above sea level (mm).
const HOME: (i32, i32, i32) = (473_977_000, 85_456_000, 488_000);
/// Height of the hover above home, mm.
const UP_MM: i32 = 20_000;
/// Length of the flight, s.
const FLIGHT_S: f64 = 40.0;

/// A telemetry log being written: each frame after its big-endian µs timestamp.
#[derive(Default)]
struct Tlog {
    bytes: Vec<u8>,
    sequence: u8,
}

impl Tlog {
    fn push(&mut self, stamp_us: u64, msg: &MavMessage) {
        let header = MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: self.sequence,
        };
        self.sequence = self.sequence.wrapping_add(1);
        self.bytes.extend(stamp_us.to_be_bytes());
        write_v2_msg(&mut self.bytes, header, msg).expect("frame");
    }

    fn write(&self, name: &str) -> PathBuf {
        let path = scratch("live-tlog-hostile", name);
        std::fs::write(&path, &self.bytes).expect("write the tlog");
        path
    }
}

fn heartbeat() -> MavMessage {
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 5, // LOITER
        mavtype: MavType::MAV_TYPE_QUADROTOR,
        autopilot: MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA,
        base_mode: MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED
            | MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
        system_status: MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    })
}

fn position(boot_ms: u32, lat: i32, lon: i32) -> MavMessage {
    MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
        time_boot_ms: boot_ms,
        lat,
        lon,
        alt: HOME.2 + UP_MM,
        relative_alt: UP_MM,
        ..GLOBAL_POSITION_INT_DATA::default()
    })
}

fn home(lat: i32, lon: i32) -> MavMessage {
    MavMessage::HOME_POSITION(HOME_POSITION_DATA {
        latitude: lat,
        longitude: lon,
        altitude: HOME.2,
        ..HOME_POSITION_DATA::default()
    })
}

fn once_a_second() -> [MavMessage; 3] {
    [
        heartbeat(),
        // 22.8 V, 14 A (319 W, an M100's hover), 80 % left.
        MavMessage::SYS_STATUS(SYS_STATUS_DATA {
            voltage_battery: 22_800,
            current_battery: 1_400,
            battery_remaining: 80,
            ..SYS_STATUS_DATA::default()
        }),
        MavMessage::EXTENDED_SYS_STATE(EXTENDED_SYS_STATE_DATA {
            landed_state: MavLandedState::MAV_LANDED_STATE_IN_AIR,
            ..EXTENDED_SYS_STATE_DATA::default()
        }),
    ]
}

/// The hover: at flight time `t` s (5 Hz) the frame's timestamp is `stamp(t)`, the fix
/// `fix(t)` (latitude, longitude in 1e-7 deg), home `home_at(t)` once a second (none where it is
/// `None`).
fn hover(
    stamp: impl Fn(f64) -> u64,
    fix: impl Fn(f64) -> (i32, i32),
    home_at: impl Fn(f64) -> Option<(i32, i32)>,
) -> Tlog {
    let mut log = Tlog::default();
    for k in 0..(FLIGHT_S * 5.0) as u32 {
        let t = f64::from(k) * 0.2;
        let boot_ms = 60_000 + k * 200;
        if k % 5 == 0 {
            for m in once_a_second() {
                log.push(stamp(t), &m);
            }
            if let Some((lat, lon)) = home_at(t) {
                log.push(stamp(t), &home(lat, lon));
            }
        }
        let (lat, lon) = fix(t);
        log.push(stamp(t), &position(boot_ms, lat, lon));
        let level = MavMessage::ATTITUDE(ATTITUDE_DATA {
            time_boot_ms: boot_ms,
            ..ATTITUDE_DATA::default()
        });
        log.push(stamp(t), &level);
    }
    log
}

fn steady(t: f64) -> u64 {
    T0_US + (t * 1e6).round() as u64
}

fn at_home(_: f64) -> (i32, i32) {
    (HOME.0, HOME.1)
}

fn home_at_home(_: f64) -> Option<(i32, i32)> {
    Some((HOME.0, HOME.1))
}

/// `aloft live --tlog` of `path` with `extra` options, in JSON: the exit code, the updates, the
/// summary (or `Null`), stderr; killed after `limit` (the test fails then).
fn live(path: &Path, extra: &[&str], limit: Duration) -> (Option<i32>, Vec<Value>, Value, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_aloft"))
        .args([
            "live",
            "--tlog",
            path.to_str().unwrap(),
            "--vehicle",
            "dji-m100",
        ])
        .args(["--format", "json", "--scenarios", "20"])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("aloft starts");
    if common::wait_within(&mut child, limit).is_none() {
        panic!("aloft live {extra:?} still running after {limit:?}");
    }
    let out = child.wait_with_output().expect("output");
    let text = String::from_utf8(out.stdout).expect("UTF-8");
    for bad in ["null", "NaN", "inf"] {
        assert!(!text.contains(bad), "{bad} in {text}");
    }
    let mut lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect();
    let summary = match lines.last() {
        Some(l) if l.get("summary").is_some() => lines.pop().unwrap()["summary"].clone(),
        _ => Value::Null,
    };
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (out.status.code(), lines, summary, err)
}

const MINUTE: Duration = Duration::from_secs(60);

/// The updates with a position: all but the first (which comes with the first message, before
/// any fix), and at least 15.
fn placed(updates: &[Value]) -> Vec<&Value> {
    let placed: Vec<&Value> = updates
        .iter()
        .filter(|u| u.get("position").is_some())
        .collect();
    assert!(
        placed.len() + 1 >= updates.len() && placed.len() >= 15,
        "{updates:?}"
    );
    placed
}

/// Every update from the first fix on: the vehicle where it hovers (at home, 20 m up, at home's
/// latitude and longitude), in the air, and the advice `continue`. Every update that is not is
/// listed in the failure.
fn at_home_and_continuing(updates: &[Value]) {
    let wrong: Vec<String> = placed(updates)
        .into_iter()
        .filter(|u| {
            let p = &u["position"];
            let (east, north, up) = (
                p["east_m"].as_f64().unwrap(),
                p["north_m"].as_f64().unwrap(),
                p["up_m"].as_f64().unwrap(),
            );
            let lat = p["latitude_deg"].as_f64().unwrap();
            // The fixes the test wrote are home's to the 1e-7 deg: 1 m covers the arithmetic.
            let at_home = east.hypot(north) < 1.0 && (up - 20.0).abs() < 1e-6;
            let right = at_home && (lat - 47.3977).abs() < 1e-6;
            !(right && u["in_air"] == true && u["advice"] == "continue")
        })
        .map(|u| {
            let p = &u["position"];
            format!(
                "t {} s: {} m north, {} m east, advice {}",
                u["time_s"], p["north_m"], p["east_m"], u["advice"]
            )
        })
        .collect();
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// One second of latitude 214.7 deg (`i32::MAX`), one second 1 deg north (111 km), one second
/// 1 km east (over 150 m/s from the last fix believed), and homes at 214.7 deg and 5 deg away:
/// none is believed, none moves the vehicle or turns the advice.
#[test]
fn live_tlog_positions_off_the_earth_or_out_of_reach_are_not_believed() {
    let fix = |t: f64| match t {
        // Each a second long across an update (one a second, at the HEARTBEAT).
        t if (9.5..10.5).contains(&t) => (i32::MAX, HOME.1),
        t if (17.5..18.5).contains(&t) => (HOME.0 + 10_000_000, HOME.1),
        // 0.0132 deg of longitude at 47.4 deg: about 1 km.
        t if (25.5..26.5).contains(&t) => (HOME.0, HOME.1 + 132_000),
        _ => (HOME.0, HOME.1),
    };
    // Each held until the next HOME_POSITION, a second later, after the next update.
    let home_at = |t: f64| match t as u32 {
        14 => Some((i32::MAX, HOME.1)),
        22 => Some((HOME.0 + 50_000_000, HOME.1)),
        _ => Some((HOME.0, HOME.1)),
    };
    let path = hover(steady, fix, home_at).write("glitches.tlog");
    let (code, updates, summary, err) = live(&path, &["--speed", "max", "--every", "1"], MINUTE);
    assert_eq!(code, Some(0), "{err}");
    at_home_and_continuing(&updates);
    // Said at the end: the fixes and homes not believed.
    let skipped = summary["skipped"].as_str().unwrap();
    assert!(skipped.contains("positions"), "{summary}");
}

/// The first fix 0.5 deg (56 km) north of where the vehicle is, every later one right: the bad
/// one does not become the origin (nor home before the vehicle sends one).
#[test]
fn live_tlog_a_bad_first_fix_is_not_the_origin() {
    let fix = |t: f64| match t {
        0.0 => (HOME.0 + 5_000_000, HOME.1),
        _ => (HOME.0, HOME.1),
    };
    // No HOME_POSITION: home is the origin.
    let path = hover(steady, fix, |_| None).write("first-fix.tlog");
    let (code, updates, _, err) = live(&path, &["--speed", "max", "--every", "2"], MINUTE);
    assert_eq!(code, Some(0), "{err}");
    // Without a home the origin's height is the ground: the vehicle is at 0 m "above home", in
    // the air by its landed state.
    for u in placed(&updates) {
        let p = &u["position"];
        let horizontal = p["east_m"]
            .as_f64()
            .unwrap()
            .hypot(p["north_m"].as_f64().unwrap());
        assert!(horizontal < 1.0, "{u}");
        assert!(
            (p["latitude_deg"].as_f64().unwrap() - 47.3977).abs() < 1e-6,
            "{u}"
        );
        assert_eq!(u["advice"], "continue", "{u}");
    }
}

/// A forward step of 1,000,000 s (11.6 days) in the middle of the log: a lost link, not time.
/// Played as fast as it goes, the flight lasts its 40 s, not 11.6 days; played at 100 times its
/// time it takes 0.4 s of pacing, not 2.8 hours.
#[test]
fn live_tlog_a_forward_clock_step_is_a_lost_link_not_time() {
    let jump = |t: f64| steady(t) + if t >= 20.0 { 1_000_000_000_000 } else { 0 };
    let path = hover(jump, at_home, home_at_home).write("forward.tlog");
    let (code, updates, summary, err) = live(&path, &["--speed", "max", "--every", "1"], MINUTE);
    assert_eq!(code, Some(0), "{err}");
    let duration_s = summary["duration_s"].as_f64().unwrap();
    // 40 s of frames; the first update comes with the first frame: 39.8 s from it to the last.
    assert!((39.0..=40.0).contains(&duration_s), "{summary}");
    let lost: Vec<&Value> = updates.iter().filter(|u| u["link_lost"] == true).collect();
    assert_eq!(lost.len(), 1, "{updates:?}");
    // The updates go on after it, one a second of the flight.
    assert!(updates.len() >= 39, "{} updates", updates.len());
    let start = Instant::now();
    let (code, _, summary, err) = live(&path, &["--speed", "100", "--every", "5"], MINUTE);
    assert_eq!(code, Some(0), "{err}");
    assert!(summary.is_object(), "{err}");
    // 0.4 s of pacing; 30 s leaves the debug build's planning and a busy machine room.
    assert!(
        start.elapsed() < Duration::from_secs(30),
        "{:?}",
        start.elapsed()
    );
}

/// A step back of 100 s in the middle of the log: said in a note, and the updates go on, one a
/// second of the flight, instead of falling silent until the clock catches up.
#[test]
fn live_tlog_a_backward_clock_step_is_said_and_updates_go_on() {
    let back = |t: f64| steady(t) - if t >= 20.0 { 100_000_000 } else { 0 };
    let path = hover(back, at_home, home_at_home).write("backward.tlog");
    let (code, updates, summary, err) = live(&path, &["--speed", "max", "--every", "1"], MINUTE);
    assert_eq!(code, Some(0), "{err}");
    // One update a second over the 40 s: 40 (39 from the first to the last frame, and the first).
    assert!(
        updates.len() >= 39,
        "{} updates: {updates:?}",
        updates.len()
    );
    let after: Vec<f64> = updates
        .iter()
        .map(|u| u["time_s"].as_f64().unwrap())
        .filter(|t| *t > 20.0)
        .collect();
    assert!(after.len() >= 18, "{after:?}");
    let notes: Vec<&str> = updates.iter().filter_map(|u| u["note"].as_str()).collect();
    assert!(
        notes
            .iter()
            .any(|n| n.contains("clock") && n.contains("100 s")),
        "{notes:?}"
    );
    assert!(
        (39.0..=40.0).contains(&summary["duration_s"].as_f64().unwrap()),
        "{summary}"
    );
}

/// Nothing readable: timestamps all 0 (every frame whole and CRC-valid), no bytes, bytes that are
/// not MAVLink. Bad input: exit 2, one line on stderr naming the file.
#[test]
fn live_tlog_with_nothing_readable_is_bad_input() {
    let zero = hover(|_| 0, at_home, home_at_home).write("zero-time.tlog");
    let empty = scratch("live-tlog-hostile", "empty.tlog");
    std::fs::write(&empty, b"").unwrap();
    let text = scratch("live-tlog-hostile", "text.tlog");
    std::fs::write(&text, "time,lat,lon\n0,47.3977,8.5456\n".repeat(100)).unwrap();
    for path in [zero, empty, text] {
        let out = aloft(&["live", "--tlog", path.to_str().unwrap(), "--speed", "max"]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{}: {err}", path.display());
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(path.to_str().unwrap()), "{err}");
        assert!(
            out.stdout.is_empty(),
            "{}",
            String::from_utf8_lossy(&out.stdout)
        );
    }
}
