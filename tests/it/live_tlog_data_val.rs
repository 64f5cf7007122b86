//! `aloft live` on the shared telemetry logs (`$ALOFT_DATA_DIR/telemetry`, see its README): the
//! three sources end to end through the command line, the mission learned from the link, and
//! bad input.

use crate::common;

use common::{aloft, data_dir, stderr};
use serde_json::Value;

/// The JSON lines of `aloft live --tlog FILE --speed max` with `extra` options: the updates and
/// the summary.
fn follow(file: &str, extra: &[&str]) -> (Vec<Value>, Value) {
    let path = data_dir().join("telemetry").join(file);
    let mut args = vec!["live", "--tlog", path.to_str().unwrap(), "--speed", "max"];
    // 50 scenarios an update (200 by default): the debug build of the tests is slow.
    args.extend_from_slice(&[
        "--vehicle",
        "dji-m100",
        "--format",
        "json",
        "--scenarios",
        "50",
    ]);
    args.extend_from_slice(extra);
    let out = aloft(&args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    // What is not known is left out: never null, NaN or inf.
    for bad in ["null", "NaN", "inf"] {
        assert!(!text.contains(bad), "{bad} in {file}");
    }
    let mut lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let summary = lines.pop().unwrap()["summary"].clone();
    assert!(summary.is_object(), "{summary}");
    (lines, summary)
}

fn in_air(updates: &[Value]) -> Vec<&Value> {
    updates.iter().filter(|u| u["in_air"] == true).collect()
}

/// A mission flown: an update every `every` s, the mission learned from the link, more than
/// `min_air` updates in the air; all the updates and those in the air.
fn follow_mission(file: &str, every: u32, min_air: usize) -> (Vec<Value>, Vec<Value>) {
    let (updates, summary) = follow(file, &["--every", &every.to_string()]);
    assert!(summary["missions"].as_u64().unwrap() >= 1, "{summary}");
    let air: Vec<Value> = in_air(&updates).into_iter().cloned().collect();
    assert!(air.len() > min_air, "{} updates in the air", air.len());
    (updates, air)
}

/// The real AUTO mission without a power module: the mission (11 items on the link, 5 after the
/// protocol's home and jumps as `aloft_link` reads it) is learned from MISSION_ITEM_INT,
/// `mission_item` follows MISSION_CURRENT through each of the six runs, and the rest is predicted
/// from the model alone.
#[test]
fn data_val_live_tlog_learns_the_real_auto_mission_and_follows_its_items() {
    let (updates, air) = follow_mission("phoenix_mission1_real.tlog", 2, 100);
    assert!(updates.iter().all(|u| u["power_available"] == false));
    // In AUTO, in the air: the item only goes forward within a run, and every run reaches the
    // last waypoints (items 3 and 4).
    let items: Vec<u64> = air
        .iter()
        .filter(|u| u["mode"] == "AUTO")
        .filter_map(|u| u["mission_item"].as_u64())
        .collect();
    for i in [1, 3, 4] {
        assert!(items.contains(&i), "item {i} never flown: {items:?}");
    }
    let backwards = items.windows(2).filter(|w| w[1] < w[0]).count();
    // Once per run after the first (a new run starts from item 1 again).
    assert!(backwards <= 6, "{backwards} steps back in {items:?}");
    // The rest shrinks along a run: on its first leg more than near its end.
    let rest = |u: &Value| u["remaining_wh"]["p50"].as_f64();
    let first = air.iter().find_map(rest).unwrap();
    let near_end = air
        .iter()
        .filter(|u| u["mission_item"] == 4)
        .find_map(rest)
        .unwrap();
    assert!(
        near_end < first,
        "{near_end} Wh at item 4, {first} Wh at the start"
    );
    for u in &air {
        assert!(u["position"]["latitude_deg"].as_f64().is_some(), "{u}");
    }
}

/// A simulator AUTO mission with battery: the energy used grows, the state of charge falls,
/// the efficiency is re-estimated from the measured power, and every update in the air has a
/// band, a landing state of charge and advice.
#[test]
fn data_val_live_tlog_follows_a_mission_with_battery_data() {
    let (_, air) = follow_mission("ayoub_auto_mission_sitl.tlog", 5, 30);
    let used: Vec<f64> = air
        .iter()
        .map(|u| u["energy_used_wh"].as_f64().unwrap())
        .collect();
    assert!(used.windows(2).all(|w| w[1] >= w[0]), "{used:?}");
    let soc: Vec<f64> = air.iter().map(|u| u["soc"].as_f64().unwrap()).collect();
    assert!(soc[soc.len() - 1] < soc[0] - 0.3, "{soc:?}");
    for u in &air {
        assert_eq!(u["power_available"], true);
        let r = &u["remaining_wh"];
        let (p5, p50, p95) = (
            r["p5"].as_f64().unwrap(),
            r["p50"].as_f64().unwrap(),
            r["p95"].as_f64().unwrap(),
        );
        assert!(p5 <= p50 && p50 <= p95 && p5 > 0.0, "{u}");
        assert!(u["landing_soc"]["p50"].as_f64().unwrap() < u["soc"].as_f64().unwrap());
        assert_eq!(u["advice"], "continue", "{u}");
    }
    // Efficiency re-estimated away from the vehicle file's 0.9503 (this is not an M100).
    let eta = air[air.len() - 1]["efficiency"].as_f64().unwrap();
    assert!((eta - 0.9503).abs() > 0.02, "{eta}");
    // The item follows the mission forward.
    let items: Vec<u64> = air
        .iter()
        .filter_map(|u| u["mission_item"].as_u64())
        .collect();
    assert!(items.windows(2).all(|w| w[1] >= w[0]), "{items:?}");
    assert!(items[items.len() - 1] >= 5, "{items:?}");
}

/// A reserve the pack cannot keep: the advice turns from `continue` to `return now` or `land
/// now` as the charge falls.
#[test]
fn data_val_live_tlog_advises_to_turn_back_when_the_reserve_will_not_hold() {
    let (updates, _) = follow(
        "ayoub_auto_mission_sitl.tlog",
        &["--every", "5", "--reserve-percent", "55"],
    );
    let advice: Vec<&str> = in_air(&updates)
        .iter()
        .filter_map(|u| u["advice"].as_str())
        .collect();
    assert_eq!(advice[0], "continue", "{advice:?}");
    assert!(
        advice
            .iter()
            .any(|a| *a == "return now" || *a == "land now"),
        "{advice:?}"
    );
}

/// The real flight with 1.7 % garbage and a restart: the damage is skipped and counted, the
/// restart seen, the battery followed to 20 %.
#[test]
fn data_val_live_tlog_survives_a_damaged_real_log_with_a_restart() {
    let (updates, summary) = follow("dronekit_flight_replay.tlog", &["--every", "10"]);
    assert!(
        summary["skipped"].as_str().unwrap().contains("wrong CRC"),
        "{summary}"
    );
    assert!(summary["reboots"].as_u64().unwrap() >= 1, "{summary}");
    let last = &updates[updates.len() - 1];
    assert!(
        (last["soc"].as_f64().unwrap() - 0.20).abs() < 0.02,
        "{last}"
    );
    assert!(last["energy_used_wh"].as_f64().unwrap() > 15.0, "{last}");
}

/// Bad input: one line on stderr naming the value, exit 2.
#[test]
fn live_bad_input_is_one_line_and_exit_2() {
    let tlog = data_dir()
        .join("telemetry")
        .join("ayoub_auto_mission_sitl.tlog");
    let tlog = tlog.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (&["live", "--tlog", tlog, "--speed", "0"], "--speed"),
        (&["live", "--tlog", tlog, "--speed", "fast"], "--speed"),
        (&["live", "--tlog", tlog, "--route", "log"], "--replay"),
        (
            &["live", "--tlog", "/nonexistent/x.tlog"],
            "/nonexistent/x.tlog",
        ),
        (&["live", "--connect", "udp:1.2.3.4"], "udp:1.2.3.4"),
        (&["live", "--tlog", tlog, "--every", "0"], "every"),
    ];
    for (args, names) in cases {
        let out = aloft(args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(names), "{args:?}: {err}");
    }
}

/// `--mcap FILE` records every update, as its JSON line, on `/aloft/live` (read back with the
/// `mcap` crate, not aloft's reader).
#[test]
fn data_val_live_tlog_records_its_updates_in_mcap() {
    let file = common::scratch("live-mcap", "ayoub.mcap");
    let (updates, _) = follow(
        "ayoub_auto_mission_sitl.tlog",
        &["--every", "20", "--mcap", file.to_str().unwrap()],
    );
    let bytes = std::fs::read(&file).unwrap();
    let mut seen = Vec::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        assert_eq!(m.channel.topic, "/aloft/live");
        assert_eq!(m.channel.message_encoding, "json");
        let v: Value = serde_json::from_slice(&m.data).unwrap();
        seen.push(v);
    }
    assert_eq!(seen.len(), updates.len());
    for (recorded, printed) in seen.iter().zip(&updates) {
        assert_eq!(recorded["time_s"], printed["time_s"]);
        assert_eq!(recorded["remaining_wh"], printed["remaining_wh"]);
        assert_eq!(recorded["advice"], printed["advice"]);
    }
}

/// `--mission FILE` replaces the mission on the link: the demo survey (no item numbers) is
/// flown whole from where the vehicle is, in AUTO; a file that is not there is bad input.
#[test]
fn data_val_live_tlog_flies_a_given_mission() {
    let demo = format!(
        "{}/fixtures/missions/demo-survey.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let (learned, _) = follow("ayoub_auto_mission_sitl.tlog", &["--every", "30"]);
    let (given, _) = follow(
        "ayoub_auto_mission_sitl.tlog",
        &["--every", "30", "--mission", &demo],
    );
    let first_auto = |u: &[Value]| {
        u.iter()
            .find(|u| u["in_air"] == true && u["mode"] == "AUTO")
            .map(|u| u["remaining_wh"]["p50"].as_f64().unwrap())
            .unwrap()
    };
    // The demo flies 32.4 Wh from the ground; the simulator's own mission about 11 Wh.
    let (l, g) = (first_auto(&learned), first_auto(&given));
    assert!(g > 20.0 && l < 15.0, "given {g} Wh, learned {l} Wh");
    let tlog = data_dir().join("telemetry/ayoub_auto_mission_sitl.tlog");
    let out = aloft(&[
        "live",
        "--tlog",
        tlog.to_str().unwrap(),
        "--mission",
        "/nonexistent/m.plan",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("/nonexistent/m.plan"),
        "{}",
        stderr(&out)
    );
}

/// `--speed X` plays the log at X times its own time: never faster (the 271 s of the simulator
/// mission at 500 times take at least 0.54 s of wall time).
#[test]
fn data_val_live_tlog_plays_at_its_speed() {
    let tlog = data_dir().join("telemetry/ayoub_auto_mission_sitl.tlog");
    let start = std::time::Instant::now();
    let out = aloft(&[
        "live",
        "--tlog",
        tlog.to_str().unwrap(),
        "--speed",
        "500",
        "--every",
        "60",
        "--scenarios",
        "10",
        "--format",
        "json",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let elapsed = start.elapsed().as_secs_f64();
    assert!(elapsed >= 271.0 / 500.0, "{elapsed} s");
}

/// On the ground, a mission that will not keep the reserve: `do not take off`.
#[test]
fn data_val_live_tlog_advises_not_to_take_off() {
    let (updates, _) = follow(
        "ayoub_auto_mission_sitl.tlog",
        &["--every", "30", "--reserve-percent", "95"],
    );
    let on_ground = updates
        .iter()
        .find(|u| u["in_air"] == false && u["advice"].is_string())
        .unwrap();
    assert_eq!(on_ground["advice"], "do not take off", "{on_ground}");
}
