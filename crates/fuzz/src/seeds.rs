//! Seeds: the repository's fixtures, and inputs aloft makes itself (a mission as JSON, logs
//! converted to MCAP, the same MCAP re-encoded without compression and without chunks, a ROS 2
//! CDR file, a planned mission's MCAP).

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use aloft::engine::{
    convert_log, plan_mission_with, LogReadOptions, Mission, MissionOptions, MissionOutputs,
    Vehicle, DEMO_MISSION,
};
use aloft_logs::cdr::CdrWriter;

use crate::targets::{scratch, MAP_SEPARATOR, TABLE_SEPARATOR};

/// The repository's root (fixtures are read from it).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The CSV log of the column-map seeds (`fixtures/logs/custom.csv`), also the log of a
/// `column-map` input that has no separator line.
pub const CUSTOM_CSV: &[u8] = include_bytes!("../../../fixtures/logs/custom.csv");

/// The files of `fixtures/<dir>` whose names end in `suffix`, sorted by name.
fn fixtures(dir: &str, suffix: &str) -> Vec<Vec<u8>> {
    let dir = repo_root().join("fixtures").join(dir);
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    paths.retain(|p| p.to_string_lossy().ends_with(suffix));
    paths.sort();
    paths.iter().filter_map(|p| std::fs::read(p).ok()).collect()
}

/// `fixtures/vehicles/*.toml`.
pub fn vehicles() -> Vec<Vec<u8>> {
    fixtures("vehicles", ".toml")
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
        if convert_log(&log, &options, &path).is_ok() {
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
        crate::targets::remove_scratch();
    }
}
