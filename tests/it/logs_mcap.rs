//! MCAP reading (ROS 2 CDR and JSON), writing, round trips, bad files, and the independent check
//! of what aloft writes with the Python `mcap` package (`tests/python/check_mcap.py`).

use crate::common;
use common::ros2::{battery_state, message_header, pose_stamped, ros2_channel};

use std::io::Cursor;
use std::path::{Path, PathBuf};

use aloft_logs::cdr::CdrWriter;
use aloft_logs::{
    read_log, write_log_mcap, write_mission_mcap, Attitude, BatteryPoint, Channel, InfoAccumulator,
    LogError, McapOptions, McapSamples, MissionSample, PathPoint, PowerTerms, Profile, Sample,
};

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("logs_mcap-{}-{name}", std::process::id()))
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/logs")
        .join(name)
}

// Values pass through decimal JSON (shortest round-trip f64 formatting) or binary CDR unchanged;
// quaternion <-> Euler conversions cost a few ulps: 1e-9.
const TOL: f64 = 1e-9;

/// A pose at (x, 2, 3) m in `map`, level and facing east.
fn pose_cdr(sec: i32, x: f64) -> Vec<u8> {
    pose_stamped(sec, 0, "map", [x, 2.0, 3.0], [0.0, 0.0, 0.0, 1.0])
}

/// A pack at `v` volts drawing `i` amperes (negative: discharging), 80 % full.
fn battery_cdr(sec: i32, v: f32, i: f32) -> Vec<u8> {
    let nan = f32::NAN;
    battery_state(sec, [v, nan, i, nan, nan, 5.0, 0.8], &[])
}

fn twist_cdr(sec: i32, frame: &str) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.header(sec, 0, frame);
    for v in [1.0, -2.0, 0.5, 0.0, 0.0, 0.0] {
        w.f64(v);
    }
    w.finish()
}

/// An MCAP with two pose topics, a battery, a twist and an unsupported topic, 10 messages each.
fn ros2_file(path: &Path) {
    let f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::Writer::new(f).unwrap();
    let pose = "geometry_msgs/msg/PoseStamped";
    let c_pose = ros2_channel(&mut w, pose, "/vehicle/pose");
    let c_pose2 = ros2_channel(&mut w, pose, "/mocap/pose");
    let c_bat = ros2_channel(&mut w, "sensor_msgs/msg/BatteryState", "/battery");
    let c_tw = ros2_channel(
        &mut w,
        "geometry_msgs/msg/TwistStamped",
        "/vehicle/velocity",
    );
    let c_other = ros2_channel(&mut w, "std_msgs/msg/String", "/status");
    for k in 0..10u32 {
        let ns = 1_000_000_000 + u64::from(k) * 100_000_000;
        let hdr = |ch: u16| message_header(ch, k, ns);
        w.write_to_known_channel(&hdr(c_pose), &pose_cdr(1, f64::from(k)))
            .unwrap();
        w.write_to_known_channel(&hdr(c_pose2), &pose_cdr(1, 100.0))
            .unwrap();
        w.write_to_known_channel(&hdr(c_bat), &battery_cdr(1, 12.0, -10.0))
            .unwrap();
        w.write_to_known_channel(&hdr(c_tw), &twist_cdr(1, "map"))
            .unwrap();
        w.write_to_known_channel(&hdr(c_other), &[0, 1, 0, 0, 1, 0, 0, 0, 0])
            .unwrap();
    }
    w.finish().unwrap();
}

/// An MCAP at `path` of the one ROS 2 topic `topic` of `message_type`: each of `messages` is
/// its log time (ns) and its CDR bytes, in sequence from 0.
fn one_topic_file(path: &Path, message_type: &str, topic: &str, messages: &[(u64, &[u8])]) {
    let f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::Writer::new(f).unwrap();
    let c = ros2_channel(&mut w, message_type, topic);
    for (k, (ns, data)) in (0u32..).zip(messages) {
        w.write_to_known_channel(&message_header(c, k, *ns), data)
            .unwrap();
    }
    w.finish().unwrap();
}

/// The log of the MCAP at `path` read from the named `topics` only.
fn read_topics(path: &Path, topics: &[&str]) -> Result<aloft_logs::Log, LogError> {
    let o = McapOptions {
        topics: topics.iter().map(|t| t.to_string()).collect(),
        ..McapOptions::default()
    };
    read_log(path, None, &o)
}

#[test]
fn ros2_cdr_topics_are_chosen_by_type_without_mixing_sources() {
    let p = tmp("ros2.mcap");
    ros2_file(&p);
    let mut r = McapSamples::open(&p, McapOptions::default()).unwrap();
    let samples: Vec<_> = r.by_ref().collect::<Result<_, _>>().unwrap();
    // 10 poses (first pose topic only), 10 batteries, 10 twists.
    assert_eq!(samples.len(), 30);
    let poses: Vec<_> = samples.iter().filter_map(|s| s.pos_enu_m).collect();
    assert_eq!(poses.len(), 10);
    assert!(
        poses.iter().all(|p| p[0] < 50.0),
        "the second pose topic must not be mixed in"
    );
    assert!((poses[9][0] - 9.0).abs() < TOL);
    let bat: Vec<_> = samples.iter().filter(|s| s.voltage_v.is_some()).collect();
    assert_eq!(bat.len(), 10);
    // BatteryState current is negative when discharging: aloft's is positive.
    assert!((bat[0].current_a.unwrap() - 10.0).abs() < TOL);
    // `percentage` is the reported state of charge (0.8 as f32: 1e-7 covers its rounding).
    assert!((bat[0].soc.unwrap() - 0.8).abs() < 1e-7, "{:?}", bat[0].soc);
    let v = samples.iter().find_map(|s| s.vel_enu_mps).unwrap();
    assert_eq!(v, [1.0, -2.0, 0.5]);
    let topics = r.topics();
    assert_eq!(topics.len(), 5);
    let mocap = topics.iter().find(|t| t.topic == "/mocap/pose").unwrap();
    assert_eq!((mocap.messages, mocap.decoded), (10, 0));
    assert!(mocap.used_for.is_empty());
    let status = topics.iter().find(|t| t.topic == "/status").unwrap();
    assert_eq!(status.messages, 10);
    // 10 Hz from the log times.
    assert!((topics[0].rate_hz().unwrap() - 10.0).abs() < 1e-6);
    assert!(samples.last().unwrap().time_s > 0.89);
    // A foreign file's messages are not joined, even at one time (above: 30 samples), and
    // three messages at one time are not time going back.
    let time = r.time_report();
    assert_eq!((time.samples, time.non_monotonic_count), (30, 0));
}

#[test]
fn named_topics_select_decode_and_fail_clearly() {
    let p = tmp("ros2-named.mcap");
    ros2_file(&p);
    let log = read_topics(&p, &["/mocap/pose"]).unwrap();
    assert_eq!(log.samples.len(), 10);
    assert!(log
        .samples
        .iter()
        .all(|s| (s.pos_enu_m.unwrap()[0] - 100.0).abs() < TOL));
    let e = log.power_series().unwrap_err();
    assert!(matches!(e, LogError::NoPowerData { .. }), "{e}");

    let e = read_topics(&p, &["/nope"]).unwrap_err();
    assert!(matches!(e, LogError::TopicNotFound { .. }), "{e}");
    assert!(
        e.to_string().contains("/vehicle/pose"),
        "lists what exists: {e}"
    );

    let e = read_topics(&p, &["/status"]).unwrap_err();
    assert!(matches!(e, LogError::UnsupportedTopic { .. }), "{e}");
    assert!(e.to_string().contains("std_msgs/msg/String"), "{e}");
}

#[test]
fn body_frame_twist_is_not_taken_as_enu() {
    let p = tmp("twist-body.mcap");
    let twist = twist_cdr(1, "base_link");
    one_topic_file(&p, "geometry_msgs/msg/TwistStamped", "/v", &[(1, &twist)]);
    let log = read_log(&p, None, &McapOptions::default()).unwrap();
    assert_eq!(log.samples.len(), 1);
    assert_eq!(log.samples[0].vel_enu_mps, None);
}

#[test]
fn corrupt_cdr_payload_names_topic_and_message() {
    let p = tmp("cdr-bad.mcap");
    let pose = pose_cdr(1, 0.0);
    let cut = &pose[..30];
    one_topic_file(
        &p,
        "geometry_msgs/msg/PoseStamped",
        "/pose",
        &[(0, &pose), (1, cut)],
    );
    let e = read_log(&p, None, &McapOptions::default()).unwrap_err();
    match &e {
        LogError::Cdr { topic, index, .. } => {
            assert_eq!(topic, "/pose");
            assert_eq!(*index, 1);
        }
        e => panic!("{e}"),
    }
}

#[test]
fn truncated_and_corrupt_files_are_errors_not_panics() {
    let p = tmp("whole.mcap");
    ros2_file(&p);
    let bytes = std::fs::read(&p).unwrap();
    // Every cut point in the first 300 bytes and a stride through the rest.
    let cuts: Vec<usize> = (0..300).chain((300..bytes.len()).step_by(37)).collect();
    for cut in cuts {
        let r = McapSamples::from_reader(
            Cursor::new(&bytes[..cut]),
            Path::new("cut.mcap"),
            McapOptions::default(),
        );
        let res: Result<Vec<_>, _> = r.collect();
        let e = res.expect_err(&format!(
            "a file cut at {cut} of {} bytes must be an error",
            bytes.len()
        ));
        assert!(e.to_string().contains("cut.mcap"), "{e}");
    }
    // Flipped bytes: an error or a clean read, never a panic.
    for at in (8..bytes.len() - 8).step_by(53) {
        let mut b = bytes.clone();
        b[at] ^= 0xff;
        let r = McapSamples::from_reader(
            Cursor::new(b),
            Path::new("flip.mcap"),
            McapOptions::default(),
        );
        let _ = r.collect::<Result<Vec<_>, _>>();
    }
    // Not an MCAP at all.
    let r = McapSamples::from_reader(
        Cursor::new(b"timestamp,a\n1,2\n".to_vec()),
        Path::new("x.mcap"),
        McapOptions::default(),
    );
    assert!(r.collect::<Result<Vec<_>, _>>().is_err());
}

#[test]
fn committed_truncated_fixture_reports_messages_read() {
    let e = read_log(&fixture("truncated.mcap"), None, &McapOptions::default()).unwrap_err();
    assert!(matches!(e, LogError::Mcap { .. }), "{e}");
    assert!(e.to_string().contains("truncated.mcap"), "{e}");
}

/// The state of charge an autopilot reports (`Sample::soc`) is written as `state_of_charge` of
/// `/aloft/battery` and read back, where the sample has it and nowhere else.
#[test]
fn the_reported_state_of_charge_reads_back() {
    let mut log = read_log(
        &fixture("kaist_small.csv"),
        Some(&Profile::Kaist),
        &McapOptions::default(),
    )
    .unwrap();
    for (k, s) in log.samples.iter_mut().enumerate() {
        s.soc = (k % 2 == 0).then_some(0.69 - 0.001 * k as f64);
    }
    let out = tmp("kaist_small_soc.mcap");
    write_log_mcap(&out, &log, true).unwrap();
    let back = read_log(&out, None, &McapOptions::default()).unwrap();
    assert_eq!(back.samples.len(), log.samples.len());
    for (a, b) in log.samples.iter().zip(&back.samples) {
        match (a.soc, b.soc) {
            (Some(x), Some(y)) => assert!((x - y).abs() < TOL, "{x} {y}"),
            (x, y) => assert_eq!(x, y),
        }
    }
}

fn log_round_trip_file() -> (aloft_logs::Log, PathBuf) {
    let log = read_log(
        &fixture("kaist_small.csv"),
        Some(&Profile::Kaist),
        &McapOptions::default(),
    )
    .unwrap();
    let out = tmp("kaist_small.mcap");
    let summary = write_log_mcap(&out, &log, true).unwrap();
    assert_eq!(summary.count("/aloft/pose"), 20);
    assert_eq!(summary.count("/aloft/state"), 20);
    assert_eq!(summary.count("/aloft/battery"), 20);
    (log, out)
}

#[test]
fn converted_log_reads_back_equal() {
    let (log, out) = log_round_trip_file();
    let back = read_log(&out, None, &McapOptions::default()).unwrap();
    // Auto-selection: /aloft/state comes first and provides position, velocity and attitude, so
    // /aloft/pose is not decoded (sources are not mixed); battery from /aloft/battery. The state
    // and battery messages of one sample are one sample again (issue 23: they were two, and
    // each equal time was reported as time going back).
    assert_eq!(back.samples.len(), 20);
    assert!(back.time.is_clean(), "{:?}", back.time);
    for (a, b) in log.samples.iter().zip(&back.samples) {
        assert!((a.time_s - b.time_s).abs() < 1e-9, "{a:?} {b:?}");
        assert!((a.voltage_v.unwrap() - b.voltage_v.unwrap()).abs() < TOL);
        assert!((a.current_a.unwrap() - b.current_a.unwrap()).abs() < TOL);
        assert!(b.pos_enu_m.is_some() && b.attitude.is_some() && b.vel_enu_mps.is_some());
    }
    let pos: Vec<_> = back.samples.iter().filter_map(|s| s.pos_enu_m).collect();
    let att: Vec<_> = back.samples.iter().filter_map(|s| s.attitude).collect();
    let vel: Vec<_> = back.samples.iter().filter_map(|s| s.vel_enu_mps).collect();
    let cur: Vec<_> = back.samples.iter().filter_map(|s| s.current_a).collect();
    let acc: Vec<_> = back.samples.iter().filter_map(|s| s.acc_enu_mps2).collect();
    let charge: Vec<_> = back.samples.iter().filter_map(|s| s.charge_ah).collect();
    assert_eq!(
        (pos.len(), att.len(), vel.len(), cur.len()),
        (20, 20, 20, 20)
    );
    // Acceleration and remaining charge are converted too (the fuzz harness found them lost:
    // fixtures/fuzz/log-csv/).
    assert_eq!((acc.len(), charge.len()), (20, 20));
    for (s, (a, c)) in log.samples.iter().zip(acc.iter().zip(&charge)) {
        let x = s.acc_enu_mps2.unwrap();
        assert!((0..3).all(|k| (x[k] - a[k]).abs() < TOL), "{x:?} {a:?}");
        assert!((s.charge_ah.unwrap() - c).abs() < TOL);
    }
    for (i, s) in log.samples.iter().enumerate() {
        let (p, q) = (s.pos_enu_m.unwrap(), pos[i]);
        assert!((0..3).all(|k| (p[k] - q[k]).abs() < TOL), "{p:?} {q:?}");
        let (a, b) = (s.attitude.unwrap(), att[i]);
        assert!((a.roll_rad - b.roll_rad).abs() < TOL);
        assert!((a.pitch_rad - b.pitch_rad).abs() < TOL);
        assert!((a.yaw_rad - b.yaw_rad).abs() < TOL);
        let v = s.vel_enu_mps.unwrap();
        assert!((0..3).all(|k| (v[k] - vel[i][k]).abs() < TOL));
        assert!((s.current_a.unwrap() - cur[i]).abs() < TOL);
    }
    // The pose topic alone: attitude through the ROS quaternion and back.
    let poses = read_topics(&out, &["/aloft/pose"]).unwrap();
    assert_eq!(poses.samples.len(), 20);
    for (s, b) in log.samples.iter().zip(&poses.samples) {
        let (a, b) = (s.attitude.unwrap(), b.attitude.unwrap());
        assert!((a.roll_rad - b.roll_rad).abs() < TOL);
        assert!((a.pitch_rad - b.pitch_rad).abs() < TOL);
        assert!((a.yaw_rad - b.yaw_rad).abs() < TOL);
    }
    // Pose and battery by name: aloft's pose topic joins its instant too.
    let named = read_topics(&out, &["/aloft/pose", "/aloft/battery"]).unwrap();
    assert_eq!(named.samples.len(), 20);
    assert!(named
        .samples
        .iter()
        .all(|s| s.pos_enu_m.is_some() && s.voltage_v.is_some()));
    // Same relative times; the absolute start (1 s of boot time) is kept as log_time.
    assert!((back.samples.last().unwrap().time_s - 1.9).abs() < 1e-6);
    assert!((back.start_time_s - 1.0).abs() < 1e-6);
}

#[test]
fn python_mcap_reads_a_converted_log() {
    let (log, out) = log_round_trip_file();
    let s = &log.samples[15];
    let p = s.pos_enu_m.unwrap();
    let expect = serde_json::json!({
        "topics": {
            "/aloft/pose": {"count": 20, "schema": "foxglove.PoseInFrame"},
            "/aloft/state": {"count": 20, "schema": "aloft.VehicleState"},
            "/aloft/battery": {"count": 20, "schema": "aloft.BatteryState"},
        },
        "values": [
            {"topic": "/aloft/pose", "index": 15, "path": "pose.position.z", "value": p[2], "tol": 1e-9},
            {"topic": "/aloft/state", "index": 15, "path": "velocity_enu_mps.x", "value": -1.0, "tol": 1e-12},
            {"topic": "/aloft/state", "index": 15, "path": "pitch_deg", "value": (-0.05f64).to_degrees(), "tol": 1e-9},
            {"topic": "/aloft/battery", "index": 15, "path": "voltage_v", "value": s.voltage_v.unwrap(), "tol": 1e-12},
            {"topic": "/aloft/battery", "index": 15, "path": "power_w", "value": s.voltage_v.unwrap() * s.current_a.unwrap(), "tol": 1e-9},
            {"topic": "/aloft/state", "index": 0, "path": "time_s", "value": 0.0, "tol": 0.0},
        ]
    });
    common::check_mcap_with_python(&out, &expect);
}

fn mission() -> (Vec<MissionSample>, Vec<PathPoint>) {
    let samples: Vec<MissionSample> = (0..50)
        .map(|i| {
            let t = i as f64 * 0.5;
            MissionSample {
                time_s: t,
                pos_enu_m: [2.0 * t, 0.0, 10.0],
                vel_enu_mps: [2.0, 0.0, 0.0],
                attitude: Attitude {
                    roll_rad: 0.0,
                    pitch_rad: -0.1,
                    yaw_rad: std::f64::consts::FRAC_PI_2,
                },
                power: PowerTerms {
                    induced_w: 300.0,
                    parasitic_w: 5.0,
                    profile_w: 20.0,
                    acceleration_w: 0.0,
                    climb_w: 0.0,
                    electrical_w: 400.0 + t,
                },
                battery: Some(BatteryPoint {
                    voltage_v: 16.0 - 0.01 * t,
                    current_a: 25.0,
                    state_of_charge: 1.0 - 0.01 * t,
                    energy_used_wh: 400.0 * t / 3600.0,
                }),
            }
        })
        .collect();
    let path = vec![
        PathPoint {
            pos_enu_m: [0.0, 0.0, 10.0],
            yaw_rad: None,
        },
        PathPoint {
            pos_enu_m: [50.0, 0.0, 10.0],
            yaw_rad: None,
        },
    ];
    (samples, path)
}

#[test]
fn mission_mcap_has_all_topics_and_reads_back() {
    let (samples, path) = mission();
    let out = tmp("mission.mcap");
    let s = write_mission_mcap(&out, &samples, &path, true).unwrap();
    assert_eq!(
        s.messages,
        vec![
            ("/aloft/battery".to_string(), 50),
            ("/aloft/path".to_string(), 1),
            ("/aloft/pose".to_string(), 50),
            ("/aloft/power".to_string(), 50),
            ("/aloft/state".to_string(), 50),
        ]
    );
    let log = read_log(&out, None, &McapOptions::default()).unwrap();
    let (_, p) = log.power_series().unwrap();
    assert_eq!(p.len(), 50);
    assert!((p[0] - 400.0).abs() < TOL, "battery power is V x I");
    assert!(log.channels().contains(&Channel::Velocity));
    let expect = serde_json::json!({
        "topics": {
            "/aloft/pose": {"count": 50, "schema": "foxglove.PoseInFrame"},
            "/aloft/state": {"count": 50, "schema": "aloft.VehicleState"},
            "/aloft/battery": {"count": 50, "schema": "aloft.BatteryState"},
            "/aloft/power": {"count": 50, "schema": "aloft.PowerTerms"},
            "/aloft/path": {"count": 1, "schema": "foxglove.PosesInFrame"},
        },
        "values": [
            {"topic": "/aloft/power", "index": 10, "path": "electrical_w", "value": 405.0, "tol": 1e-12},
            {"topic": "/aloft/path", "index": 0, "path": "poses.1.position.x", "value": 50.0, "tol": 0.0},
            // Heading east = ROS yaw 0: identity orientation.
            {"topic": "/aloft/path", "index": 0, "path": "poses.0.orientation.w", "value": 1.0, "tol": 1e-12},
            {"topic": "/aloft/battery", "index": 49, "path": "state_of_charge", "value": 1.0 - 0.01 * 24.5, "tol": 1e-12},
        ]
    });
    common::check_mcap_with_python(&out, &expect);
}

/// Issue 23: `log info` of `mission --mcap` output counted a state and a battery message of one
/// instant as two samples, and each equal time as time going back. One instant is one sample,
/// and the energy is the trapezoid of the mission's own V x I, computed here.
#[test]
fn a_mission_mcap_reads_back_one_sample_per_instant_with_its_energy() {
    let (samples, path) = mission();
    let out = tmp("mission_instants.mcap");
    write_mission_mcap(&out, &samples, &path, true).unwrap();
    let mut r = McapSamples::open(&out, McapOptions::default()).unwrap();
    let back: Vec<Sample> = r.by_ref().collect::<Result<_, _>>().unwrap();
    assert_eq!(back.len(), samples.len());
    let time = r.time_report();
    assert_eq!((time.non_monotonic_count, time.gap_count), (0, 0));
    let mut acc = InfoAccumulator::new();
    for (m, b) in samples.iter().zip(&back) {
        acc.push(b);
        assert!((m.time_s - b.time_s).abs() < 1e-9, "{m:?} {b:?}");
        let p = b.pos_enu_m.unwrap();
        assert!((0..3).all(|k| (p[k] - m.pos_enu_m[k]).abs() < TOL), "{p:?}");
        assert!((b.voltage_v.unwrap() - m.battery.unwrap().voltage_v).abs() < TOL);
    }
    let stats = acc.finish();
    let vi: Vec<(f64, f64)> = samples
        .iter()
        .map(|m| {
            let b = m.battery.unwrap();
            (m.time_s, b.voltage_v * b.current_a)
        })
        .collect();
    let wh = vi
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum::<f64>()
        / 3600.0;
    // Times pass through whole nanoseconds: 1e-9 relative.
    let got = stats.power.energy_wh.unwrap();
    assert!((got - wh).abs() < 1e-9 * wh, "{got} Wh vs {wh} Wh");
    assert_eq!(stats.power.skipped_steps, 0);
}

/// The join of one instant keeps the source's samples apart: two samples at one time (both
/// with motion, or both with battery), a battery-only sample before a motion-only one at one
/// time, and a sample with no channel all read back as they were written.
#[test]
fn samples_of_one_time_read_back_as_written() {
    let full = |t: f64, x: f64| Sample {
        time_s: t,
        pos_enu_m: Some([x, 0.0, 5.0]),
        vel_enu_mps: Some([1.0, 0.0, 0.0]),
        voltage_v: Some(16.0 - x),
        current_a: Some(10.0),
        ..Sample::default()
    };
    let battery = |t: f64, v: f64| Sample {
        time_s: t,
        voltage_v: Some(v),
        current_a: Some(5.0),
        ..Sample::default()
    };
    let motion = |t: f64, x: f64| Sample {
        time_s: t,
        pos_enu_m: Some([x, 1.0, 2.0]),
        ..Sample::default()
    };
    let written = vec![
        full(0.0, 0.0),
        full(0.0, 1.0),
        battery(0.1, 15.5),
        motion(0.1, 2.0),
        Sample {
            time_s: 0.2,
            ..Sample::default()
        },
        battery(0.2, 15.0),
        battery(0.2, 14.5),
        motion(0.3, 3.0),
        motion(0.3, 4.0),
        full(0.4, 5.0),
    ];
    let log = aloft_logs::Log {
        samples: written.clone(),
        ..aloft_logs::Log::default()
    };
    let out = tmp("one_time.mcap");
    write_log_mcap(&out, &log, true).unwrap();
    let back = read_log(&out, None, &McapOptions::default()).unwrap();
    assert_eq!(back.samples.len(), written.len());
    for (i, (a, b)) in written.iter().zip(&back.samples).enumerate() {
        // The battery message carries V x I as its power: the power channel is compared as
        // the electrical power.
        for c in Channel::ALL.into_iter().filter(|c| *c != Channel::Power) {
            assert_eq!(c.present_in(a), c.present_in(b), "sample {i}, {c:?}: {b:?}");
        }
        assert_eq!(a.electrical_power_w(), b.electrical_power_w(), "sample {i}");
        assert!((a.time_s - b.time_s).abs() < 1e-9, "sample {i}");
        assert_eq!(a.voltage_v, b.voltage_v, "sample {i}");
        assert_eq!(a.pos_enu_m, b.pos_enu_m, "sample {i}");
    }
    assert_eq!(back.time.non_monotonic_count, 0);
}

#[test]
fn non_finite_mission_values_are_refused() {
    let (mut samples, path) = mission();
    samples[7].power.induced_w = f64::NAN;
    let e = write_mission_mcap(&tmp("nan.mcap"), &samples, &path, true).unwrap_err();
    assert!(matches!(e, LogError::NonFinite { index: 7, .. }), "{e}");
}
