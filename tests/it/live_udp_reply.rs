//! `aloft live --connect udpin:...` answers the vehicle, whoever else sends to its port.
//!
//! The vehicle is pymavlink (`tests/python/mavlink_vehicle.py`, the independent MAVLink
//! implementation), an armed quadrotor hovering in LOITER that sends telemetry at 5 Hz from its
//! own port of 127.0.0.1 and answers aloft's mission download. A stray sender on another port
//! sends a datagram every 50 ms, four times as often as the vehicle: bytes that are not MAVLink,
//! and a ground station's HEARTBEAT (system 254). A listener that answers the last sender (the
//! `mavlink` crate's `udpin`) sent most of aloft's messages to the stray; aloft must send every
//! one to the vehicle, and none to the stray.
//!
//! The same vehicle reporting 70 % left with a count of the charge drawn (BATTERY_STATUS
//! `current_consumed`) that jumps to `INT32_MAX`, wraps to `INT32_MIN` and goes back (issue 41):
//! no `land now` reaches it, and the updates say the count was not believed.
//!
//! aloft's battery, texts and values come from the vehicle's system and aloft's display
//! component (1, 191), and a QGroundControl-like filter (only the vehicle's system id) takes
//! them; its requests and heartbeat still come from its own ids (255, 190).
//!
//! It needs python3 with pymavlink (`.ci/run` installs it). Without it the test says so and
//! passes, unless `ALOFT_PYMAVLINK_TESTS=require` or `CI` is set, where it fails.
#![cfg(feature = "live")]

use std::net::UdpSocket;
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use aloft_link::mavlink::{write_v2_msg, MavHeader};
use serde_json::Value;

/// Seconds the vehicle sends for.
const VEHICLE_S: u32 = 8;

/// Whether pymavlink can be imported; without it the test fails where it is required.
fn pymavlink_ready() -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import pymavlink"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        let required = std::env::var("ALOFT_PYMAVLINK_TESTS").is_ok_and(|v| v == "require")
            || std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false");
        assert!(
            !required,
            "ALOFT_PYMAVLINK_TESTS=require or CI is set, but python3 cannot import pymavlink \
             (python3 -m pip install pymavlink==2.4.50)"
        );
        eprintln!("skipped: this test needs python3 with pymavlink 2.4.50");
    }
    ok
}

/// The stray: a datagram every 50 ms to `port` until `stop`, alternately bytes that are not
/// MAVLink (with magic bytes in them) and a ground station's HEARTBEAT; what it sent and the
/// datagrams it received.
fn stray(port: u16, stop: &AtomicBool) -> (u32, u32) {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("bind");
    socket
        .set_read_timeout(Some(Duration::from_millis(50)))
        .expect("timeout");
    // Another ground station's: the one aloft itself sends.
    let gcs = aloft_link::gcs_heartbeat();
    let mut heartbeat = Vec::new();
    let header = MavHeader {
        system_id: 254,
        component_id: 190,
        sequence: 0,
    };
    write_v2_msg(&mut heartbeat, header, &gcs).expect("frame");
    let junk: Vec<u8> = (0u8..40).map(|k| k.wrapping_mul(37) ^ 0xFD).collect();
    let (mut sent, mut received) = (0, 0);
    let mut buf = [0u8; 2048];
    while !stop.load(Ordering::Relaxed) {
        let datagram: &[u8] = if sent % 2 == 0 { &junk } else { &heartbeat };
        if socket.send_to(datagram, ("127.0.0.1", port)).is_ok() {
            sent += 1;
        }
        if socket.recv(&mut buf).is_ok() {
            received += 1;
        }
    }
    (sent, received)
}

/// `aloft live --connect udpin:127.0.0.1:PORT`, JSON, an update every 0.5 s.
fn aloft_live(port: u16) -> Child {
    aloft_live_with(port, &[])
}

/// The same with more flags.
fn aloft_live_with(port: u16, more: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_aloft"))
        .args(["live", "--connect", &format!("udpin:127.0.0.1:{port}")])
        .args([
            "--vehicle",
            "dji-m100",
            "--format",
            "json",
            "--every",
            "0.5",
        ])
        .args(["--scenarios", "20", "--link-timeout", "30"])
        .args(more)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("aloft starts")
}

/// A free UDP port of 127.0.0.1 (bound, then let go).
fn free_port() -> u16 {
    let probe = UdpSocket::bind("127.0.0.1:0").expect("bind");
    probe.local_addr().expect("address").port()
}

/// The pymavlink vehicle (`tests/python/mavlink_vehicle.py PORT ARGS...`), run to its end.
fn vehicle_run(port: u16, args: &[String]) -> Output {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/mavlink_vehicle.py");
    Command::new("python3")
        .arg(&script)
        .arg(port.to_string())
        .args(args)
        .output()
        .expect("python3 runs")
}

/// aloft stopped after the vehicle's run (which must have succeeded): what the vehicle got (its
/// JSON line), aloft's updates (a JSON line each) and aloft's stderr.
fn after_the_run(mut aloft: Child, vehicle: &Output) -> (Value, Vec<Value>, String) {
    let _ = aloft.kill();
    let out = aloft.wait_with_output().expect("aloft's output");
    assert!(
        vehicle.status.success(),
        "{}",
        String::from_utf8_lossy(&vehicle.stderr)
    );
    let got: Value = serde_json::from_slice(&vehicle.stdout).expect("the vehicle's JSON line");
    let updates: Vec<Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect();
    (
        got,
        updates,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The senders of the messages of type `t` the vehicle got, `[[system, component], ...]`.
fn senders<'a>(got: &'a Value, t: &str) -> &'a Value {
    &got["senders"][t]
}

/// What a ground station shows, aloft's own ids: the battery, texts and values from the
/// vehicle's system (1) and the display component (191), and nothing else; the requests and
/// the heartbeat from (255, 190).
fn check_senders(got: &Value) {
    let display = serde_json::json!([[1, 191]]);
    let own = serde_json::json!([[255, 190]]);
    for (t, ids) in [
        ("NAMED_VALUE_FLOAT", &display),
        ("STATUSTEXT", &display),
        ("BATTERY_STATUS", &display),
        ("HEARTBEAT", &own),
        ("PARAM_REQUEST_READ", &own),
        ("MISSION_REQUEST_LIST", &own),
        ("MISSION_REQUEST_INT", &own),
        ("MISSION_ACK", &own),
    ] {
        let s = senders(got, t);
        assert!(s.is_null() || s == ids, "{t} from {s}, not {ids}");
    }
    // The QGroundControl-like filter takes every displayed message and only those.
    for (t, n) in got["shown"].as_object().expect("shown") {
        assert!(
            ["NAMED_VALUE_FLOAT", "STATUSTEXT", "BATTERY_STATUS"].contains(&t.as_str()),
            "{t}"
        );
        assert_eq!(n, &got["counts"][t], "{t}");
    }
}

/// The NAMED_VALUE_FLOAT and STATUSTEXT aloft sent with its updates: four values an update
/// with a band (two reserves, the point of no return where there is one, the energy left), and
/// a text where the advice changed.
fn replies_of(updates: &[Value]) -> (u64, u64) {
    let mut values = 0;
    let mut texts = 0;
    let mut advice = None;
    for u in updates {
        values += 2 * u64::from(u.get("landing_soc").is_some())
            + u64::from(u.get("point_of_no_return_s").is_some())
            + u64::from(u.get("remaining_wh").is_some());
        let a = u.get("advice").and_then(Value::as_str);
        if a.is_some() && a != advice {
            texts += 1;
        }
        advice = a.or(advice);
    }
    (values, texts)
}

#[test]
fn live_udpin_answers_the_vehicle_not_a_stray_sender() {
    if !pymavlink_ready() {
        return;
    }
    let port = free_port();
    let aloft = aloft_live(port);
    std::thread::sleep(Duration::from_millis(500));
    let stop = Arc::new(AtomicBool::new(false));
    let stray = {
        let stop = stop.clone();
        std::thread::spawn(move || stray(port, &stop))
    };
    std::thread::sleep(Duration::from_millis(300));
    let start = Instant::now();
    let vehicle = vehicle_run(port, &[VEHICLE_S.to_string()]);
    stop.store(true, Ordering::Relaxed);
    let (stray_sent, stray_received) = stray.join().expect("stray thread");
    let (got, updates, stderr) = after_the_run(aloft, &vehicle);
    assert!(start.elapsed() < Duration::from_secs(60));
    let (values, texts) = replies_of(&updates);
    let count = |t: &str| got["counts"][t].as_u64().unwrap_or(0);
    eprintln!(
        "aloft printed {} updates ({values} values, {texts} texts to send); the vehicle got {}; \
         the stray sent {stray_sent} datagrams and got {stray_received}",
        updates.len(),
        got
    );
    assert_eq!(stray_received, 0, "aloft answered the stray");
    assert!(stray_sent > 4 * VEHICLE_S, "{stray_sent}");
    assert!(values >= 10, "{} updates: {updates:?}", updates.len());
    assert_eq!(count("NAMED_VALUE_FLOAT"), values, "{got}");
    assert_eq!(count("STATUSTEXT"), texts, "{got}");
    assert!(
        got["texts"][0]
            .as_str()
            .unwrap()
            .starts_with("aloft: continue"),
        "{got}"
    );
    // A heartbeat a second from the vehicle's first message on (the first second may be lost to
    // the start).
    assert!(count("HEARTBEAT") >= u64::from(VEHICLE_S) - 1, "{got}");
    // The mission download ran to its end: asked, both items, acknowledged.
    assert_eq!(count("MISSION_REQUEST_INT"), 2, "{got}");
    assert_eq!(count("MISSION_ACK"), 1, "{got}");
    assert_eq!(got["others"], serde_json::json!({}), "{got}");
    check_senders(&got);
    assert_eq!(got["shown"]["STATUSTEXT"], texts, "{got}");
    assert!(stderr.trim().is_empty(), "{stderr}");
}

/// The vehicle (`wrapped-count`) reports 70 % left while its count of the charge drawn counts
/// 14 A from 500 mA h, jumps to `INT32_MAX` mA h at 3 s, wraps to `INT32_MIN` at 5 s and goes
/// back to 10 mA h at 7 s. Before the fix the jump made the state of charge 0 and sent the
/// vehicle `aloft: land now`; now every update says `continue` at about 70 %, the only text the
/// vehicle gets is `aloft: continue`, and the notes say, once each, why the count is not
/// believed.
#[test]
fn live_udp_a_jumping_and_wrapping_charge_count_is_not_land_now() {
    if !pymavlink_ready() {
        return;
    }
    const SECONDS: u32 = 10;
    let port = free_port();
    let aloft = aloft_live(port);
    std::thread::sleep(Duration::from_millis(500));
    let vehicle = vehicle_run(port, &[SECONDS.to_string(), "wrapped-count".into()]);
    let (got, updates, _) = after_the_run(aloft, &vehicle);
    eprintln!("the vehicle got {got}");
    let texts: Vec<&str> = got["texts"]
        .as_array()
        .expect("texts")
        .iter()
        .filter_map(Value::as_str)
        .collect();
    assert!(!texts.is_empty(), "{got}");
    assert!(
        texts.iter().all(|t| t.starts_with("aloft: continue")),
        "{texts:?}"
    );
    let advised = updates.iter().filter(|u| u.get("advice").is_some()).count();
    assert!(advised >= 2 * SECONDS as usize - 4, "{updates:?}");
    for u in &updates {
        if let Some(advice) = u.get("advice") {
            assert_eq!(advice, "continue", "{u}");
        }
        if let Some(soc) = u["soc"].as_f64() {
            assert!(soc >= 0.68, "{u}");
        }
    }
    let notes: Vec<&str> = updates
        .iter()
        .filter_map(|u| u["note"].as_str())
        .filter(|n| n.contains("current_consumed"))
        .collect();
    eprintln!("notes: {notes:#?}");
    for why in ["is more than the", "is negative", "went back from"] {
        let said = notes.iter().filter(|n| n.contains(why)).count();
        assert_eq!(said, 1, "{why}: {notes:?}");
    }
    assert!(
        notes.iter().all(|n| n.contains("not believed")),
        "{notes:?}"
    );
}

/// aloft's battery and its texts as a stock ground station decodes them (pymavlink 2.4.50's
/// BATTERY_STATUS and STATUSTEXT), and the failsafe parameters it asked the vehicle for.
///
/// The vehicle hovers at 22.8 V and 14 A reporting 80 % left (SYS_STATUS); aloft runs with
/// `--battery-id 42`. Every update is a BATTERY_STATUS of id 42 from the vehicle's system and
/// aloft's display component (1, 191), which a QGroundControl-like filter takes:
/// `voltages[0]` 22,800 mV and the others UINT16_MAX (cells not known), `current_battery`
/// 1,400 cA, `battery_remaining` aloft's `soc` of an update in percent, no time (0: no failsafe
/// ahead yet), charge OK (1) under `continue`, function ALL (1), type LIPO (1), temperature
/// INT16_MAX, consumed and energy -1. `aloft: continue` comes at INFO (6), which QGroundControl
/// does not speak. ArduPilot's nine failsafe parameters are each asked by name (index -1) of
/// the vehicle (1, 1).
#[test]
fn live_udp_alofts_battery_and_text_severities_reach_the_ground_station() {
    if !pymavlink_ready() {
        return;
    }
    let port = free_port();
    let aloft = aloft_live_with(port, &["--battery-id", "42"]);
    std::thread::sleep(Duration::from_millis(500));
    let vehicle = vehicle_run(port, &["6".to_string()]);
    let (got, updates, stderr) = after_the_run(aloft, &vehicle);
    assert!(stderr.trim().is_empty(), "{stderr}");
    let batteries = got["batteries"].as_array().expect("batteries");
    let with_soc: Vec<i64> = updates
        .iter()
        .filter_map(|u| u["soc"].as_f64())
        .map(|s| (100.0 * s).round() as i64)
        .collect();
    eprintln!(
        "{} BATTERY_STATUS; soc of the updates {with_soc:?}",
        batteries.len()
    );
    assert!(batteries.len() >= 8, "{got}");
    assert_eq!(
        batteries.len() as u64,
        got["counts"]["BATTERY_STATUS"].as_u64().unwrap()
    );
    let mut cells = vec![serde_json::json!(22_800)];
    cells.extend(std::iter::repeat_n(serde_json::json!(65_535), 9));
    let cells = Value::Array(cells);
    let unknown = Value::Array(vec![serde_json::json!(65_535); 10]);
    for b in batteries {
        assert_eq!(b["id"], 42, "{b}");
        assert_eq!(
            (&b["system"], &b["component"]),
            (&1.into(), &191.into()),
            "{b}"
        );
        // Before the vehicle's first SYS_STATUS, not known.
        let measured = b["current_battery"] != -1;
        assert_eq!(
            &b["voltages"],
            if measured { &cells } else { &unknown },
            "{b}"
        );
        assert!(!measured || b["current_battery"] == 1_400, "{b}");
        assert_eq!(b["time_remaining"], 0, "{b}");
        assert_eq!(b["temperature"], i64::from(i16::MAX), "{b}");
        assert_eq!(b["current_consumed"], -1, "{b}");
        assert_eq!(b["energy_consumed"], -1, "{b}");
        assert_eq!(
            (&b["battery_function"], &b["type"]),
            (&1.into(), &1.into()),
            "{b}"
        );
        let remaining = b["battery_remaining"].as_i64().unwrap();
        assert!(
            remaining == -1 || with_soc.contains(&remaining),
            "{remaining} not an update's soc {with_soc:?}"
        );
    }
    // The vehicle's 80 % less a few seconds at 14 A, once aloft has it.
    let last = batteries.last().unwrap();
    let remaining = last["battery_remaining"].as_i64().unwrap();
    assert!((75..=80).contains(&remaining), "{last}");
    assert_eq!(last["voltages"], cells, "{last}");
    assert_eq!(last["current_battery"], 1_400, "{last}");
    assert_eq!(last["charge_state"], 1, "{last}");
    check_senders(&got);
    assert_eq!(got["shown"]["BATTERY_STATUS"], batteries.len(), "{got}");
    let severities = got["severities"].as_array().expect("severities");
    assert!(!severities.is_empty(), "{got}");
    assert_eq!(got["shown"]["STATUSTEXT"], severities.len(), "{got}");
    for t in severities {
        assert!(t[0].as_str().unwrap().starts_with("aloft: continue"), "{t}");
        assert_eq!(t[1], 6, "{t}");
    }
    let asked: std::collections::BTreeSet<&str> = got["asked"]
        .as_array()
        .expect("asked")
        .iter()
        .map(|a| {
            assert_eq!(
                (&a[1], &a[2], &a[3]),
                (&(-1).into(), &1.into(), &1.into()),
                "{a}"
            );
            a[0].as_str().unwrap()
        })
        .collect();
    let want = [
        "BATT_CAPACITY",
        "BATT_CRT_MAH",
        "BATT_CRT_VOLT",
        "BATT_FS_CRT_ACT",
        "BATT_FS_LOW_ACT",
        "BATT_FS_VOLTSRC",
        "BATT_LOW_MAH",
        "BATT_LOW_TIMER",
        "BATT_LOW_VOLT",
    ];
    assert_eq!(asked, want.into_iter().collect());
}

/// The vehicle's failsafe parameters reach aloft's events as each autopilot encodes them, the
/// PARAM_VALUE made by pymavlink: ArduPilot's cast (BATT_LOW_VOLT 10.5, BATT_FS_LOW_ACT INT8 2)
/// and PX4's bytewise copy (BAT1_N_CELLS INT32 3 sent as the float of bits 3; BAT_LOW_THR 0.15),
/// asked by aloft's link on its own.
#[test]
fn live_udp_the_vehicles_failsafe_parameters_arrive_as_events() {
    if !pymavlink_ready() {
        return;
    }
    /// The vehicle's flags, and the parameters it answers with their values.
    type Case<'a> = (&'a [&'a str], [(&'a str, f64); 2]);
    let cases: [Case; 2] = [
        (&[], [("BATT_LOW_VOLT", 10.5), ("BATT_FS_LOW_ACT", 2.0)]),
        (&["px4"], [("BAT1_N_CELLS", 3.0), ("BAT_LOW_THR", 0.15)]),
    ];
    for (flags, want) in cases {
        let port = free_port();
        let options = aloft_link::LinkOptions {
            request_mission: false,
            ..aloft_link::LinkOptions::default()
        };
        let mut link =
            aloft_link::LinkSource::connect(&format!("udpin:127.0.0.1:{port}"), options).unwrap();
        let mut args = vec!["3".to_string()];
        args.extend(flags.iter().map(|f| f.to_string()));
        let vehicle = std::thread::spawn(move || vehicle_run(port, &args));
        let mut heard = std::collections::BTreeMap::new();
        let deadline = Instant::now() + Duration::from_secs(20);
        while heard.len() < 2 && Instant::now() < deadline {
            let Some(t) = link.next_telemetry().expect("link up") else {
                break;
            };
            if let aloft_link::Event::Parameter { name, value } = t.event {
                heard.insert(name, value);
            }
        }
        let out = vehicle.join().expect("vehicle");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        for (name, value) in want {
            let got = heard.get(name).copied();
            // 0.15 travels as an f32: within its half-ulp.
            assert!(
                got.is_some_and(|g| (g - value).abs() < 1e-7),
                "{flags:?} {name}: {got:?} in {heard:?}"
            );
        }
    }
}
