//! `aloft live --connect` on the loopback interface: the test plays a real telemetry log (the
//! simulator's AUTO mission with battery, `$ALOFT_DATA_DIR/telemetry`) as the vehicle, frame by
//! frame over UDP at 40 times its own time, into `aloft live --connect udpin:127.0.0.1:PORT`,
//! reads what aloft sends back (NAMED_VALUE_FLOAT, STATUSTEXT), then falls silent: aloft says the
//! link is lost and keeps the last estimate.
#![cfg(feature = "live")]

use crate::common;

use std::io::Read;
use std::net::UdpSocket;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use aloft_link::mavlink::dialects::ardupilotmega::MavMessage;
use aloft_link::mavlink::{write_versioned_msg, MavlinkReader, Message};
use aloft_link::TlogReader;
use common::data_dir;

/// Play speed, times the log's own time.
const SPEED: f64 = 40.0;

/// A MAVLink text, or what is wrong with it.
fn text(s: Result<&str, std::str::Utf8Error>) -> String {
    s.map_or_else(|e| e.to_string(), str::to_string)
}

/// What the vehicle received from aloft: (NAMED_VALUE_FLOAT names, STATUSTEXT texts with their
/// severity).
fn received(socket: &UdpSocket, names: &mut Vec<String>, texts: &mut Vec<(String, String)>) {
    let mut buf = [0u8; 2048];
    while let Ok(n) = socket.recv(&mut buf) {
        let mut reader = MavlinkReader::new(&buf[..n]);
        while let Ok(raw) = reader.read_any_raw_message::<MavMessage>() {
            match MavMessage::parse(raw.version(), raw.message_id(), raw.payload()) {
                Ok(MavMessage::NAMED_VALUE_FLOAT(v)) => names.push(text(v.name.to_str())),
                Ok(MavMessage::STATUSTEXT(t)) => {
                    texts.push((text(t.text.to_str()), format!("{:?}", t.severity)));
                }
                _ => {}
            }
        }
    }
}

#[test]
fn data_val_live_connect_on_loopback_answers_the_vehicle_and_reports_silence() {
    let port = {
        let probe = UdpSocket::bind("127.0.0.1:0").expect("bind");
        probe.local_addr().expect("address").port()
    };
    let url = format!("udpin:127.0.0.1:{port}");
    let mut child = Command::new(env!("CARGO_BIN_EXE_aloft"))
        .args([
            "live",
            "--connect",
            &url,
            "--vehicle",
            "dji-m100",
            "--format",
            "json",
        ])
        .args(["--every", "1", "--link-timeout", "2", "--scenarios", "50"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("aloft starts");
    let vehicle = UdpSocket::bind("127.0.0.1:0").expect("bind");
    vehicle.connect(("127.0.0.1", port)).expect("connect");
    vehicle
        .set_read_timeout(Some(Duration::from_millis(1)))
        .expect("timeout");
    // Let aloft bind its socket.
    std::thread::sleep(Duration::from_millis(500));

    let path = data_dir()
        .join("telemetry")
        .join("ayoub_auto_mission_sitl.tlog");
    let file = std::fs::File::open(&path).expect("shared telemetry log");
    let mut tlog = TlogReader::new(std::io::BufReader::new(file), path.display().to_string());
    let (mut names, mut texts) = (Vec::new(), Vec::new());
    let start = Instant::now();
    let mut first_us = None;
    while let Some(frame) = tlog.next_frame().expect("readable") {
        let first = *first_us.get_or_insert(frame.timestamp_us);
        let due = (frame.timestamp_us.saturating_sub(first)) as f64 * 1e-6 / SPEED;
        while start.elapsed().as_secs_f64() < due {
            received(&vehicle, &mut names, &mut texts);
        }
        let mut bytes = Vec::new();
        write_versioned_msg(&mut bytes, frame.version, frame.header, &frame.message)
            .expect("frame");
        let _ = vehicle.send(&bytes);
    }
    // Silence: aloft says the link is lost after 2 s.
    let quiet = Instant::now();
    while quiet.elapsed() < Duration::from_secs(4) {
        received(&vehicle, &mut names, &mut texts);
    }
    let _ = child.kill();
    let mut stdout = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut stdout)
        .expect("stdout");
    let _ = child.wait();

    for name in ["rsv_p50", "rsv_p5", "rem_wh"] {
        assert!(
            names.iter().any(|n| n == name),
            "{name} not received: {names:?}"
        );
    }
    let advice = texts.iter().find(|(t, _)| t.starts_with("aloft: continue"));
    assert!(advice.is_some(), "{texts:?}");
    let updates: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON line"))
        .collect();
    assert!(
        updates
            .iter()
            .any(|u| u["in_air"] == true && u["mission_item"].as_u64() >= Some(2)),
        "{stdout}"
    );
    let last = updates.last().expect("updates");
    assert_eq!(last["link_lost"], true, "{last}");
    assert!(
        last["remaining_wh"]["p50"].as_f64().is_some(),
        "the last estimate is kept: {last}"
    );
}
