//! `aloft live` stopped by Ctrl-C (SIGINT) or SIGTERM ends as a flight ends: it stops
//! following, prints its summary line and exits 0. A live link has no end of its own, so this is
//! how every `aloft live --connect` ends.
//!
//! The vehicle is a UDP socket of the test on 127.0.0.1 sending, with the `mavlink` crate, an
//! armed quadrotor's HEARTBEAT, GLOBAL_POSITION_INT and SYS_STATUS at 5 Hz; the signal is sent
//! with `kill`, as a shell's Ctrl-C or a service manager's stop would.
#![cfg(all(feature = "live", unix))]

use crate::common;

use std::net::UdpSocket;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use aloft_link::mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavMessage, MavModeFlag, MavState, MavType, GLOBAL_POSITION_INT_DATA,
    HEARTBEAT_DATA, SYS_STATUS_DATA,
};
use aloft_link::mavlink::{write_v2_msg, MavHeader};
use serde_json::Value;

/// What the vehicle sends every 0.2 s.
fn telemetry(boot_ms: u32) -> Vec<u8> {
    let messages = [
        MavMessage::HEARTBEAT(HEARTBEAT_DATA {
            custom_mode: 5,
            mavtype: MavType::MAV_TYPE_QUADROTOR,
            autopilot: MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA,
            base_mode: MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED,
            system_status: MavState::MAV_STATE_ACTIVE,
            mavlink_version: 3,
        }),
        MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
            time_boot_ms: boot_ms,
            lat: 473_977_000,
            lon: 85_456_000,
            alt: 508_000,
            relative_alt: 20_000,
            ..GLOBAL_POSITION_INT_DATA::default()
        }),
        MavMessage::SYS_STATUS(SYS_STATUS_DATA {
            voltage_battery: 22_800,
            current_battery: 1_400,
            battery_remaining: 80,
            ..SYS_STATUS_DATA::default()
        }),
    ];
    let header = MavHeader {
        system_id: 1,
        component_id: 1,
        sequence: 0,
    };
    let mut out = Vec::new();
    for m in &messages {
        write_v2_msg(&mut out, header, m).expect("frame");
    }
    out
}

/// `aloft live --connect udpin:127.0.0.1:PORT` in `format`, fed for `feed`.
fn follow_link(format: &str, feed: Duration) -> Child {
    let port = {
        let probe = UdpSocket::bind("127.0.0.1:0").expect("bind");
        probe.local_addr().expect("address").port()
    };
    let child = Command::new(env!("CARGO_BIN_EXE_aloft"))
        .args(["live", "--connect", &format!("udpin:127.0.0.1:{port}")])
        .args([
            "--vehicle",
            "dji-m100",
            "--format",
            format,
            "--every",
            "0.5",
        ])
        .args(["--scenarios", "20"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("aloft starts");
    let vehicle = UdpSocket::bind("127.0.0.1:0").expect("bind");
    std::thread::sleep(Duration::from_millis(500));
    let start = Instant::now();
    let mut k = 0;
    while start.elapsed() < feed {
        let _ = vehicle.send_to(&telemetry(10_000 + 200 * k), ("127.0.0.1", port));
        k += 1;
        std::thread::sleep(Duration::from_millis(200));
    }
    child
}

/// Sends `signal` to `child` with `kill`, and its output once it ended (killed, and the test
/// failed, if it has not within 10 s).
fn stop(mut child: Child, signal: &str) -> Output {
    let sent = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(sent.success());
    if common::wait_within(&mut child, Duration::from_secs(10)).is_none() {
        panic!("aloft live still running 10 s after SIG{signal}");
    }
    child.wait_with_output().expect("output")
}

/// Ctrl-C: exit 0, the updates, then `{"summary": ...}` counting them.
#[test]
fn live_connect_on_sigint_prints_its_summary_and_exits_0() {
    let out = stop(follow_link("json", Duration::from_secs(3)), "INT");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{:?}: {stderr}", out.status);
    let lines: Vec<Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect();
    let (summary, updates) = lines.split_last().expect("lines");
    let summary = &summary["summary"];
    assert!(summary.is_object(), "{summary}");
    // 3 s of telemetry at an update every 0.5 s: 6 updates, less the debug build's slowness.
    assert!(updates.len() >= 2, "{updates:?}");
    assert_eq!(summary["updates"].as_u64(), Some(updates.len() as u64));
    let duration_s = summary["duration_s"].as_f64().unwrap();
    assert!((1.0..=15.0).contains(&duration_s), "{summary}");
}

/// SIGTERM, as a service manager stops it: exit 0, the table's summary line last.
#[test]
fn live_connect_on_sigterm_prints_its_summary_and_exits_0() {
    let out = stop(follow_link("table", Duration::from_secs(2)), "TERM");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{:?}: {stderr}", out.status);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout.lines().last().unwrap_or_default();
    assert!(
        last.contains(" updates over ") && last.contains("restart(s) of the vehicle"),
        "{stdout}"
    );
}

/// A telemetry log played in its own time stops as promptly: the summary of what was played.
#[test]
fn live_tlog_on_sigint_prints_its_summary_and_exits_0() {
    let tlog = common::data_dir().join("telemetry/ayoub_auto_mission_sitl.tlog");
    let child = Command::new(env!("CARGO_BIN_EXE_aloft"))
        .args(["live", "--tlog", tlog.to_str().unwrap(), "--speed", "1"])
        .args([
            "--vehicle",
            "dji-m100",
            "--format",
            "json",
            "--scenarios",
            "20",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("aloft starts");
    std::thread::sleep(Duration::from_secs(2));
    let out = stop(child, "INT");
    assert_eq!(out.status.code(), Some(0), "{:?}", out.status);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last: Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    // 2 s of a 271 s log: far from its end.
    let duration_s = last["summary"]["duration_s"].as_f64().unwrap();
    assert!(duration_s < 30.0, "{last}");
}
