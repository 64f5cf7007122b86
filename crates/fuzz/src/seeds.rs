//! Seeds: the repository's fixtures, and inputs aloft makes itself (a mission as JSON, logs
//! converted to MCAP, the same MCAP re-encoded without compression and without chunks, a ROS 2
//! CDR file, a planned mission's MCAP), planner files and binary logs made in code, and, when the
//! shared data folder is there at run time ([`data_dir`]), its mission files and the first
//! [`DATA_LOG_HEAD`] bytes of its flight logs (read, never copied into the repository).

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use aloft::engine::{
    convert_log, plan_mission_with, LogReadOptions, Mission, MissionOptions, MissionOutputs,
    Vehicle, DEMO_MISSION,
};
use aloft_logs::cdr::CdrWriter;
use aloft_logs::synth;
use serde_json::{json, Value};

use crate::inputs::{scratch, MAP_SEPARATOR, TABLE_SEPARATOR};

/// The repository's root (fixtures are read from it).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The CSV log of the column-map seeds (`fixtures/logs/custom.csv`), also the log of a
/// `column-map` input that has no separator line.
pub const CUSTOM_CSV: &[u8] = include_bytes!("../../../fixtures/logs/custom.csv");

/// The paths in `dir` whose names pass `keep`, sorted (none where `dir` cannot be read).
fn sorted_paths(dir: &Path, keep: impl Fn(&str) -> bool) -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    paths.retain(|p| p.file_name().is_some_and(|n| keep(&n.to_string_lossy())));
    paths.sort();
    paths
}

/// The files of `fixtures/<dir>` whose names end in `suffix`, sorted by name.
fn fixtures(dir: &str, suffix: &str) -> Vec<Vec<u8>> {
    let dir = repo_root().join("fixtures").join(dir);
    let paths = sorted_paths(&dir, |name| name.ends_with(suffix));
    paths.iter().filter_map(|p| std::fs::read(p).ok()).collect()
}

/// `fixtures/vehicles/*.toml`.
pub fn vehicles() -> Vec<Vec<u8>> {
    fixtures("vehicles", ".toml")
}

/// `fixtures/vehicles/specs/*.toml`: the spec sheets of the built-in DJI vehicles.
pub fn spec_sheets() -> Vec<Vec<u8>> {
    fixtures("vehicles/specs", ".toml")
}

/// `fixtures/missions/*.toml` and the built-in demo mission.
pub fn missions_toml() -> Vec<Vec<u8>> {
    let mut s = fixtures("missions", ".toml");
    s.push(DEMO_MISSION.as_bytes().to_vec());
    s.dedup();
    s
}

/// The TOML missions as JSON ([`Mission::to_json`]), compact and pretty (one key a line, so the
/// line mutations apply).
pub fn missions_json() -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for t in missions_toml() {
        let Ok(m) = Mission::from_toml(&String::from_utf8_lossy(&t), "seed") else {
            continue;
        };
        let Ok(json) = m.to_json() else { continue };
        if let Ok(v) = serde_json::from_str::<serde_json::Value>(&json) {
            if let Ok(pretty) = serde_json::to_string_pretty(&v) {
                out.push(pretty.into_bytes());
            }
        }
        out.push(json.into_bytes());
    }
    out
}

/// Flight states for `aloft power --states`: the required columns, the optional ones, a column
/// passed through.
pub fn power_csv() -> Vec<Vec<u8>> {
    [
        "airspeed_mps,roll_deg,pitch_deg\n0,0,0\n6,0,-8\n15,5,-20\n",
        "airspeed_mps,roll_deg,pitch_deg,climb_rate_mps,air_direction_deg,note\n\
         0,0,0,0,,hover\n6,0,-8,0.5,0,cruise\n12,10,-15,-1,30,turn\n3,0,0,3,,climb\n",
        "note,pitch_deg,airspeed_mps,roll_deg\nx,-5,4.5,1\ny,0,0,0\n",
        "airspeed_mps , roll_deg , pitch_deg\n 1 , 2 , 3 \n",
    ]
    .iter()
    .map(|s| s.as_bytes().to_vec())
    .collect()
}

/// `fixtures/logs/*.csv`.
pub fn log_csv() -> Vec<Vec<u8>> {
    fixtures("logs", ".csv")
}

/// Column maps of `fixtures/logs/*.toml`, each followed by [`MAP_SEPARATOR`] and a CSV log.
pub fn column_map() -> Vec<Vec<u8>> {
    let logs = [
        CUSTOM_CSV.to_vec(),
        std::fs::read(repo_root().join("fixtures/logs/custom_bad_number.csv")).unwrap_or_default(),
    ];
    let mut out = Vec::new();
    for map in fixtures("logs", ".toml") {
        for log in &logs {
            let mut s = map.clone();
            s.extend_from_slice(MAP_SEPARATOR);
            s.extend_from_slice(log);
            out.push(s);
        }
    }
    out
}

/// PX4 tables as `ulog2csv` writes them (local position at 10 Hz, battery at 5 Hz, attitude at
/// 20 Hz, a 2 s climb and turn), joined by [`TABLE_SEPARATOR`]; and the same with a missing
/// battery current and a `nan` row.
pub fn px4_csv() -> Vec<Vec<u8>> {
    let mut position = String::from("timestamp,x,y,z,vx,vy,vz,ax,ay,az\n");
    for k in 0..20 {
        let t = f64::from(k) * 0.1;
        position += &format!(
            "{},{:.3},{:.3},{:.3},2.0,1.0,-0.5,0.1,0,0\n",
            1_000_000 + k * 100_000,
            2.0 * t,
            t,
            -0.5 * t
        );
    }
    let mut battery = String::from("timestamp,voltage_v,current_a,remaining\n");
    for k in 0..10 {
        battery += &format!(
            "{},{:.2},{:.1},0.9\n",
            1_000_000 + k * 200_000,
            16.4 - 0.01 * f64::from(k),
            12.0 + 0.1 * f64::from(k)
        );
    }
    let mut attitude = String::from("timestamp,q[0],q[1],q[2],q[3]\n");
    for k in 0..40 {
        let yaw = 0.01 * f64::from(k);
        attitude += &format!(
            "{},{:.6},0,0,{:.6}\n",
            1_000_000 + k * 50_000,
            (yaw / 2.0).cos(),
            (yaw / 2.0).sin()
        );
    }
    let join = |tables: [&str; 3]| -> Vec<u8> {
        let mut out = Vec::new();
        for (k, t) in tables.iter().enumerate() {
            if k > 0 {
                out.extend_from_slice(TABLE_SEPARATOR);
            }
            out.extend_from_slice(t.as_bytes());
        }
        out
    };
    let gappy_battery = battery
        .replacen(",12.3,", ",nan,", 1)
        .replacen(",16.36,", ",,", 1);
    vec![
        join([&position, &battery, &attitude]),
        join([&position, &gappy_battery, &attitude]),
    ]
}

/// `fixtures/logs/*.mcap`; the CSV logs converted by `aloft convert` (zstd chunks, JSON
/// messages), one of them re-encoded with uncompressed chunks and without chunks; a ROS 2 CDR
/// file; the MCAP of a short planned mission.
pub fn mcap() -> Vec<Vec<u8>> {
    let mut out = fixtures("logs", ".mcap");
    let logs = repo_root().join("fixtures/logs");
    let converted = [
        (logs.join("kaist_small.csv"), None),
        (
            logs.join("custom.csv"),
            Some(logs.join("custom.toml").display().to_string()),
        ),
    ];
    for (log, profile) in converted {
        let path = scratch("seed.mcap");
        let options = LogReadOptions {
            profile,
            ..LogReadOptions::default()
        };
        if convert_log(&log, &options, &path, true).is_ok() {
            if let Ok(bytes) = std::fs::read(&path) {
                out.extend(reencoded(&bytes));
                out.push(bytes);
            }
        }
    }
    out.extend(ros2_cdr());
    out.extend(mission_mcap());
    out
}

/// `bytes` written again by the `mcap` crate with uncompressed chunks, and without chunks.
fn reencoded(bytes: &[u8]) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for chunked in [true, false] {
        let written = (|| -> mcap::McapResult<Vec<u8>> {
            let mut w = mcap::WriteOptions::new()
                .compression(None)
                .use_chunks(chunked)
                .create(Cursor::new(Vec::new()))?;
            for m in mcap::MessageStream::new(bytes)? {
                w.write(&m?)?;
            }
            w.finish()?;
            Ok(w.into_inner().into_inner())
        })();
        if let Ok(b) = written {
            out.push(b);
        }
    }
    out
}

fn pose_cdr(sec: i32, x: f64) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.header(sec, 0, "map").f64(x).f64(2.0).f64(3.0);
    for q in [0.0, 0.0, 0.0, 1.0] {
        w.f64(q);
    }
    w.finish()
}

fn battery_cdr(sec: i32, v: f32, i: f32) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.header(sec, 0, "").f32(v).f32(f32::NAN).f32(i);
    w.f32(f32::NAN).f32(f32::NAN).f32(5.0).f32(0.8);
    w.u8(2)
        .u8(1)
        .u8(3)
        .u8(1)
        .u32(0)
        .u32(0)
        .string("")
        .string("");
    w.finish()
}

fn twist_cdr(sec: i32) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.header(sec, 0, "map");
    for v in [1.0, -2.0, 0.5, 0.0, 0.0, 0.0] {
        w.f64(v);
    }
    w.finish()
}

/// A ROS 2 file (CDR messages, no compression): pose, battery, twist, an unsupported topic.
fn ros2_cdr() -> Vec<Vec<u8>> {
    let written = (|| -> mcap::McapResult<Vec<u8>> {
        let mut w = mcap::WriteOptions::new()
            .compression(None)
            .create(Cursor::new(Vec::new()))?;
        let meta = BTreeMap::new();
        let schemas = [
            ("geometry_msgs/msg/PoseStamped", "/vehicle/pose"),
            ("sensor_msgs/msg/BatteryState", "/battery"),
            ("geometry_msgs/msg/TwistStamped", "/vehicle/velocity"),
            ("std_msgs/msg/String", "/status"),
        ];
        let mut channels = Vec::new();
        for (schema, topic) in schemas {
            let s = w.add_schema(schema, "ros2msg", b"...")?;
            channels.push(w.add_channel(s, topic, "cdr", &meta)?);
        }
        for k in 0..6u32 {
            let ns = 1_000_000_000 + u64::from(k) * 100_000_000;
            let sec = 1 + k as i32;
            let payloads = [
                pose_cdr(sec, f64::from(k)),
                battery_cdr(sec, 12.0, -10.0),
                twist_cdr(sec),
                vec![0, 1, 0, 0, 1, 0, 0, 0, 0],
            ];
            for (c, p) in channels.iter().zip(payloads) {
                let header = mcap::records::MessageHeader {
                    channel_id: *c,
                    sequence: k,
                    log_time: ns,
                    publish_time: ns,
                };
                w.write_to_known_channel(&header, &p)?;
            }
        }
        w.finish()?;
        Ok(w.into_inner().into_inner())
    })();
    written.into_iter().collect()
}

/// The MCAP of a short mission planned with dji-m100 (`aloft mission --mcap`).
fn mission_mcap() -> Vec<Vec<u8>> {
    let text = "name = \"seed\"\ntime_step_s = 1.0\n\
                [[segment]]\nkind = \"take-off\"\naltitude_m = 6.0\nclimb_rate_mps = 2.0\n\
                [[segment]]\nkind = \"hover\"\nduration_s = 3.0\n\
                [[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n";
    let path = scratch("mission-seed.mcap");
    let outputs = MissionOutputs {
        mcap: Some(path.clone()),
        force: true,
        ..MissionOutputs::default()
    };
    let planned = Vehicle::builtin("dji-m100").and_then(|v| {
        let m = Mission::from_toml(text, "seed")?;
        plan_mission_with(&v, &m, &MissionOptions::default(), &outputs)
    });
    match planned {
        Ok(_) => std::fs::read(&path).into_iter().collect(),
        Err(_) => Vec::new(),
    }
}

/// The shared data folder: `ALOFT_DATA_DIR`, else `../shared/data` beside the workspace (as the
/// `data_val` tests find it); `None` when it is not a directory.
pub fn data_dir() -> Option<PathBuf> {
    let dir = match std::env::var_os("ALOFT_DATA_DIR") {
        Some(d) => PathBuf::from(d),
        None => repo_root().join("../shared/data"),
    };
    dir.is_dir().then_some(dir)
}

/// The files of the shared data folder's `sub` whose names end in one of `suffixes` (any case),
/// sorted, at most `limit` bytes of each.
fn shared(sub: &str, suffixes: &[&str], limit: usize) -> Vec<Vec<u8>> {
    let Some(dir) = data_dir() else {
        return Vec::new();
    };
    let paths = sorted_paths(&dir.join(sub), |name| {
        let name = name.to_ascii_lowercase();
        suffixes.iter().any(|s| name.ends_with(s))
    });
    let head = |p: &PathBuf| -> Option<Vec<u8>> {
        use std::io::Read;
        let mut out = Vec::new();
        let f = std::fs::File::open(p).ok()?;
        f.take(limit as u64).read_to_end(&mut out).ok()?;
        Some(out)
    };
    paths.iter().filter_map(head).collect()
}

/// How much of each shared flight log is a seed, bytes (a log's definitions and its first
/// seconds; whole logs are megabytes).
pub const DATA_LOG_HEAD: usize = 64 << 10;

/// A QGroundControl SimpleItem.
fn qgc_item(command: u32, frame: u32, jump_id: u32, params: Value) -> Value {
    json!({"type": "SimpleItem", "command": command, "frame": frame, "doJumpId": jump_id,
           "params": params, "autoContinue": true})
}

/// A `.plan` of `items` with its home at 47.3977 N, 8.5456 E, 488 m.
fn qgc_plan(items: Vec<Value>) -> Vec<u8> {
    let plan = json!({
        "fileType": "Plan", "version": 1, "groundStation": "QGroundControl",
        "geoFence": {"circles": [], "polygons": [], "version": 2},
        "rallyPoints": {"points": [], "version": 2},
        "mission": {"version": 2, "firmwareType": 12, "vehicleType": 2, "cruiseSpeed": 15,
                    "hoverSpeed": 5, "plannedHomePosition": [47.3977, 8.5456, 488.0],
                    "items": items},
    });
    serde_json::to_string_pretty(&plan)
        .unwrap_or_default()
        .into_bytes()
}

/// QGroundControl `.plan` files made in code: take-off (22), waypoints (16) with a hold, in the
/// relative (3) and AMSL (0) frames, a speed change (178), a gripper (211), camera commands
/// (530, 206), a delay (93), loiters (18 turns with a radius, 19 time, 31 to altitude), a jump
/// back (177, `doJumpId` and a repeat), a survey ComplexItem, `null` params, then a return
/// (20) or a landing (21); and the shared folder's `.plan` files.
pub fn qgc_plan_files() -> Vec<Vec<u8>> {
    let (lat, lon) = (47.3977, 8.5456);
    let wp = |id, hold: f64, dn: f64, de: f64, alt: f64, frame| {
        qgc_item(
            16,
            frame,
            id,
            json!([hold, 0, 0, null, lat + dn, lon + de, alt]),
        )
    };
    let survey_inner = vec![
        wp(100, 0.0, 0.0010, 0.0005, 30.0, 3),
        qgc_item(206, 2, 101, json!([25, 0, 1, 0, 0, 0, 0])),
        wp(102, 0.0, 0.0010, 0.0015, 30.0, 3),
        wp(103, 0.0, 0.0005, 0.0015, 30.0, 3),
        qgc_item(206, 2, 104, json!([0, 0, 1, 0, 0, 0, 0])),
    ];
    let survey = json!({"type": "ComplexItem", "complexItemType": "survey", "version": 5,
        "TransectStyleComplexItem": {"Items": survey_inner, "CameraTriggerInTurnAround": true},
        "angle": 0, "entryLocation": 0, "flyAlternateTransects": false,
        "polygon": [[lat + 0.0005, lon + 0.0005], [lat + 0.0010, lon + 0.0005],
                    [lat + 0.0010, lon + 0.0015], [lat + 0.0005, lon + 0.0015]]});
    let full = vec![
        qgc_item(22, 3, 1, json!([0, 0, 0, null, lat, lon, 30])),
        wp(2, 5.0, 0.0003, 0.0, 30.0, 3),
        qgc_item(178, 2, 3, json!([1, 8, -1, 0, 0, 0, 0])),
        wp(4, 0.0, 0.0006, 0.0004, 528.0, 0),
        qgc_item(
            18,
            3,
            5,
            json!([2, 0, 20, 0, lat + 0.0006, lon + 0.0008, 30]),
        ),
        qgc_item(
            19,
            3,
            6,
            json!([10, 0, 15, 0, lat + 0.0003, lon + 0.0008, 35]),
        ),
        qgc_item(211, 2, 7, json!([1, 0, 0, 0, 0, 0, 0])),
        qgc_item(530, 2, 8, json!([0, 1, null, null, null, null, null])),
        qgc_item(93, 2, 9, json!([3, -1, -1, -1, 0, 0, 0])),
        qgc_item(31, 3, 10, json!([0, 15, 0, 0, lat, lon + 0.0004, 40])),
        qgc_item(177, 2, 11, json!([2, 1, 0, 0, 0, 0, 0])),
        survey,
        qgc_item(20, 2, 13, json!([0, 0, 0, 0, 0, 0, 0])),
    ];
    let short = vec![
        qgc_item(22, 3, 1, json!([0, 0, 0, null, lat, lon, 20])),
        wp(2, 0.0, 0.0004, 0.0004, 20.0, 3),
        qgc_item(
            21,
            3,
            3,
            json!([0, 0, 0, null, lat + 0.0004, lon + 0.0004, 0]),
        ),
    ];
    let mut out = vec![qgc_plan(full), qgc_plan(short)];
    out.extend(shared("missions", &[".plan"], usize::MAX));
    out
}

/// One `QGC WPL 110` row: index, current, frame, command, four params, lat, lon, alt, continue.
fn wpl_row(index: u32, frame: u32, command: u32, p: [f64; 4], pos: [f64; 3]) -> String {
    let current = u32::from(index == 0);
    format!(
        "{index}\t{current}\t{frame}\t{command}\t{:.6}\t{:.6}\t{:.6}\t{:.6}\t{:.8}\t{:.8}\t{:.6}\t1\n",
        p[0], p[1], p[2], p[3], pos[0], pos[1], pos[2]
    )
}

/// Mission Planner `.waypoints` made in code: the home row (0, AMSL), a take-off, waypoints (one
/// with a hold, one in the AMSL frame), a loiter, a jump back to row 2 repeated twice (the row
/// index), a return; the same with CRLF line ends; and the shared folder's `.waypoints` and
/// `.txt` files.
pub fn qgc_wpl_files() -> Vec<Vec<u8>> {
    let (lat, lon) = (-35.363262, 149.165237);
    let zero = [0.0; 4];
    let rows = [
        wpl_row(0, 0, 16, zero, [lat, lon, 584.0]),
        wpl_row(1, 3, 22, zero, [0.0, 0.0, 20.0]),
        wpl_row(2, 3, 16, [3.0, 0.0, 0.0, 0.0], [lat + 0.0003, lon, 20.0]),
        wpl_row(3, 0, 16, zero, [lat + 0.0003, lon + 0.0004, 610.0]),
        wpl_row(4, 3, 18, [1.0, 0.0, 15.0, 0.0], [lat, lon + 0.0004, 25.0]),
        wpl_row(5, 0, 177, [2.0, 2.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
        wpl_row(6, 3, 20, zero, [0.0, 0.0, 0.0]),
    ];
    let text = format!("QGC WPL 110\n{}", rows.concat());
    let crlf = text.replace('\n', "\r\n");
    let mut out = vec![text.into_bytes(), crlf.into_bytes()];
    out.extend(shared("missions", &[".waypoints", ".txt"], usize::MAX));
    out
}

/// PX4 ULogs made in code ([`synth`]: a small one with a parameter, one second of a flight's
/// topic mix), a ULog without its battery records, and the heads of the shared `.ulg` logs.
pub fn ulog() -> Vec<Vec<u8>> {
    let small = synth::ulog_small();
    // The definitions and subscriptions only: 50 position (3 + 34 bytes) and 50 battery
    // (3 + 18 bytes) data records cut off.
    let definitions = small[..small.len() - 50 * ((3 + 34) + (3 + 18))].to_vec();
    let mut out = vec![small, synth::ulog_flight(1), definitions];
    out.extend(shared("flight_logs", &[".ulg"], DATA_LOG_HEAD));
    out
}

/// ArduPilot DataFlash logs made in code ([`synth`]: a small one with a battery instance, one
/// second of a flight's record mix) and the heads of the shared `.bin` logs.
pub fn dataflash() -> Vec<Vec<u8>> {
    let mut out = vec![synth::dataflash_small(), synth::dataflash_flight(1)];
    out.extend(shared("flight_logs", &[".bin"], DATA_LOG_HEAD));
    out
}

/// How much of each shared telemetry log is a seed, bytes: its first frames (a few hundred,
/// the first seconds: heartbeats, parameters, the first positions), small enough that a million
/// inputs run in minutes.
pub const TLOG_HEAD: usize = 16 << 10;

/// A telemetry log made in code, frames of MAVLink 1 and 2 every 50 ms from 2024-05-01: a ground
/// station's and the vehicle's HEARTBEAT, HOME_POSITION before the fix, GLOBAL_POSITION_INT
/// without and with a fix, ATTITUDE, SYS_STATUS, BATTERY_STATUS, VFR_HUD, WIND,
/// EXTENDED_SYS_STATE, an upload of a 3-item mission by the ground station (MISSION_COUNT,
/// MISSION_ITEM_INT, MISSION_ITEM, MISSION_ACK), MISSION_CURRENT, SYSTEM_TIME going back (a
/// restart).
pub fn tlog_made_in_code() -> Vec<u8> {
    let gcs = mav_header(255, 190);
    let vehicle = mav_header(1, 1);
    let mut frames = state_frames(gcs, vehicle);
    frames.extend(mission_frames(gcs, vehicle));
    let mut out = Vec::new();
    for (k, (header, v2, msg)) in frames.iter().enumerate() {
        let t_us = 1_714_521_600_000_000u64 + 50_000 * k as u64;
        out.extend(t_us.to_be_bytes());
        let written = if *v2 {
            aloft_link::mavlink::write_v2_msg(&mut out, *header, msg)
        } else {
            aloft_link::mavlink::write_v1_msg(&mut out, *header, msg)
        };
        // Writing to a Vec cannot fail.
        let _ = written;
    }
    out
}

/// One frame of the log made in code: header, MAVLink 2, message.
type Frame = (
    aloft_link::mavlink::MavHeader,
    bool,
    aloft_link::mavlink::dialects::ardupilotmega::MavMessage,
);

/// A sender's header.
fn mav_header(system_id: u32, component_id: u8) -> aloft_link::mavlink::MavHeader {
    aloft_link::mavlink::MavHeader {
        system_id,
        component_id,
        sequence: 0,
    }
}

/// A HEARTBEAT of the ground station or the vehicle.
fn heartbeat(gcs_type: bool) -> aloft_link::mavlink::dialects::ardupilotmega::MavMessage {
    use aloft_link::mavlink::dialects::ardupilotmega as m;
    m::MavMessage::HEARTBEAT(m::HEARTBEAT_DATA {
        custom_mode: if gcs_type { 0 } else { 3 },
        mavtype: if gcs_type {
            m::MavType::MAV_TYPE_GCS
        } else {
            m::MavType::MAV_TYPE_QUADROTOR
        },
        autopilot: if gcs_type {
            m::MavAutopilot::MAV_AUTOPILOT_INVALID
        } else {
            m::MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA
        },
        base_mode: m::MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED,
        system_status: m::MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    })
}

/// A GLOBAL_POSITION_INT at `ms` (latitude 0: no fix).
fn position(ms: u32, lat: i32) -> aloft_link::mavlink::dialects::ardupilotmega::MavMessage {
    use aloft_link::mavlink::dialects::ardupilotmega as m;
    m::MavMessage::GLOBAL_POSITION_INT(m::GLOBAL_POSITION_INT_DATA {
        time_boot_ms: ms,
        lat,
        lon: if lat == 0 { 0 } else { 85_456_000 },
        alt: 490_000,
        relative_alt: 2_000,
        vx: 150,
        vy: -40,
        vz: -20,
        hdg: 9_000,
    })
}

/// A MISSION_ITEM_INT of the 3-item mission.
fn mission_item(seq: u16) -> aloft_link::mavlink::dialects::ardupilotmega::MavMessage {
    use aloft_link::mavlink::dialects::ardupilotmega as m;
    m::MavMessage::MISSION_ITEM_INT(m::MISSION_ITEM_INT_DATA {
        param4: f32::NAN,
        x: 473_977_000 + i32::from(seq) * 500,
        y: 85_456_000,
        z: 25.0,
        seq,
        command: m::MavCmd::MAV_CMD_NAV_WAYPOINT,
        target_system: 1,
        target_component: 1,
        frame: m::MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
        ..m::MISSION_ITEM_INT_DATA::default()
    })
}

/// The vehicle's state messages of the log made in code, and the two heartbeats.
fn state_frames(
    gcs: aloft_link::mavlink::MavHeader,
    vehicle: aloft_link::mavlink::MavHeader,
) -> Vec<Frame> {
    use aloft_link::mavlink::dialects::ardupilotmega as m;
    let mut voltages = [u16::MAX; 10];
    voltages[0] = 16_100;
    vec![
        (vehicle, false, heartbeat(false)),
        (gcs, true, heartbeat(true)),
        (
            vehicle,
            true,
            m::MavMessage::HOME_POSITION(m::HOME_POSITION_DATA {
                latitude: 473_977_000,
                longitude: 85_456_000,
                altitude: 488_000,
                ..m::HOME_POSITION_DATA::default()
            }),
        ),
        (vehicle, false, position(1_000, 0)),
        (vehicle, true, position(1_100, 473_977_000)),
        (
            vehicle,
            false,
            m::MavMessage::ATTITUDE(m::ATTITUDE_DATA {
                time_boot_ms: 1_150,
                roll: 0.05,
                pitch: -0.1,
                yaw: 1.5,
                ..m::ATTITUDE_DATA::default()
            }),
        ),
        (
            vehicle,
            false,
            m::MavMessage::SYS_STATUS(m::SYS_STATUS_DATA {
                voltage_battery: 16_100,
                current_battery: 2_250,
                battery_remaining: 87,
                ..m::SYS_STATUS_DATA::default()
            }),
        ),
        (
            vehicle,
            true,
            m::MavMessage::BATTERY_STATUS(m::BATTERY_STATUS_DATA {
                current_consumed: 420,
                voltages,
                current_battery: 2_250,
                battery_remaining: 87,
                ..m::BATTERY_STATUS_DATA::default()
            }),
        ),
        (
            vehicle,
            false,
            m::MavMessage::VFR_HUD(m::VFR_HUD_DATA {
                airspeed: 6.0,
                groundspeed: 5.5,
                ..m::VFR_HUD_DATA::default()
            }),
        ),
        (
            vehicle,
            true,
            m::MavMessage::WIND(m::WIND_DATA {
                direction: 270.0,
                speed: 3.0,
                speed_z: 0.1,
            }),
        ),
        (
            vehicle,
            true,
            m::MavMessage::EXTENDED_SYS_STATE(m::EXTENDED_SYS_STATE_DATA {
                landed_state: m::MavLandedState::MAV_LANDED_STATE_IN_AIR,
                ..m::EXTENDED_SYS_STATE_DATA::default()
            }),
        ),
    ]
}

/// The mission upload, MISSION_CURRENT, the restart and the last fix of the log made in code.
fn mission_frames(
    gcs: aloft_link::mavlink::MavHeader,
    vehicle: aloft_link::mavlink::MavHeader,
) -> Vec<Frame> {
    use aloft_link::mavlink::dialects::ardupilotmega as m;
    #[allow(deprecated)] // MISSION_ITEM: deprecated by MAVLink, still in logs
    let float_item = m::MavMessage::MISSION_ITEM(m::MISSION_ITEM_DATA {
        x: 47.399,
        y: 8.5456,
        z: 0.0,
        seq: 2,
        command: m::MavCmd::MAV_CMD_NAV_LAND,
        target_system: 1,
        target_component: 1,
        frame: m::MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
        ..m::MISSION_ITEM_DATA::default()
    });
    let item = mission_item;
    vec![
        (
            gcs,
            true,
            m::MavMessage::MISSION_COUNT(m::MISSION_COUNT_DATA {
                count: 3,
                target_system: 1,
                target_component: 1,
                ..m::MISSION_COUNT_DATA::default()
            }),
        ),
        (gcs, true, item(0)),
        (gcs, false, item(1)),
        (gcs, false, float_item),
        (
            vehicle,
            true,
            m::MavMessage::MISSION_ACK(m::MISSION_ACK_DATA {
                target_system: 255,
                target_component: 190,
                ..m::MISSION_ACK_DATA::default()
            }),
        ),
        (
            vehicle,
            false,
            m::MavMessage::MISSION_CURRENT(m::MISSION_CURRENT_DATA {
                seq: 1,
                ..m::MISSION_CURRENT_DATA::default()
            }),
        ),
        (
            vehicle,
            true,
            m::MavMessage::SYSTEM_TIME(m::SYSTEM_TIME_DATA {
                time_unix_usec: 0,
                time_boot_ms: 9_000,
            }),
        ),
        (
            vehicle,
            true,
            m::MavMessage::SYSTEM_TIME(m::SYSTEM_TIME_DATA {
                time_unix_usec: 0,
                time_boot_ms: 500,
            }),
        ),
        (vehicle, false, position(600, 473_978_000)),
    ]
}

/// The telemetry log made in code, and the first [`TLOG_HEAD`] bytes of the shared `.tlog`s.
pub fn tlog() -> Vec<Vec<u8>> {
    let mut out = vec![tlog_made_in_code()];
    out.extend(shared("telemetry", &[".tlog"], TLOG_HEAD));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_of_seed_is_there() {
        assert!(vehicles().len() >= 4);
        assert!(missions_toml().len() >= 2);
        assert_eq!(missions_json().len(), 2 * missions_toml().len());
        assert!(log_csv().len() >= 5);
        assert!(column_map().len() >= 4);
        assert_eq!(px4_csv().len(), 2);
        // truncated.mcap, two converted logs and their two re-encodings, ROS 2, mission.
        assert_eq!(mcap().len(), 1 + 2 * 3 + 1 + 1);
        crate::inputs::remove_scratch();
        // Made in code, and the shared files when the folder is there.
        let shared = usize::from(data_dir().is_some());
        assert!(qgc_plan_files().len() >= 2 + 6 * shared);
        assert!(qgc_wpl_files().len() >= 2 + 6 * shared);
        assert!(ulog().len() >= 3 + 3 * shared);
        assert!(dataflash().len() >= 2 + 4 * shared);
        assert!(ulog().iter().all(|s| s.len() <= DATA_LOG_HEAD));
        assert!(tlog().len() > 5 * shared);
    }

    /// The seeds made in code are read whole, so the fuzzing starts from the accepted path.
    #[test]
    fn the_planner_files_and_logs_made_in_code_are_accepted() {
        for (i, text) in qgc_plan_files()[..2].iter().enumerate() {
            let m = Mission::from_text(&String::from_utf8_lossy(text), "seed.plan");
            assert!(m.is_ok(), "plan {i}: {:?}", m.err());
        }
        for (i, text) in qgc_wpl_files()[..2].iter().enumerate() {
            let m = Mission::from_text(&String::from_utf8_lossy(text), "seed.waypoints");
            assert!(m.is_ok(), "waypoints {i}: {:?}", m.err());
        }
        let o = aloft_logs::BinaryOptions::default();
        for u in &ulog()[..2] {
            assert!(aloft_logs::read_ulog(&u[..], &o)
                .unwrap()
                .summary
                .warnings
                .is_empty());
        }
        // Every frame of the telemetry log made in code reads back.
        let t = tlog_made_in_code();
        let mut r = aloft_link::TlogReader::new(&t[..], "seed");
        assert_eq!(r.by_ref().count(), 20);
        assert_eq!(r.stats().bytes_skipped, 0);
        let defs = aloft_logs::read_ulog(&ulog()[2][..], &o).unwrap();
        assert!(defs.log.samples.is_empty());
        let w = &defs.summary.warnings;
        assert!(w.iter().any(|w| w.contains("never written")), "{w:?}");
    }
}
