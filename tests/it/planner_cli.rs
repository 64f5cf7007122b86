//! End-to-end checks of `aloft mission` and `aloft endurance`: outputs, JSON keys, exit codes.

use crate::common;
use aloft_planner::mission_toml::{hover, landing, orbit, take_off, OrbitFor};
use common::run as aloft;

use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    common::scratch("planner-cli", name)
}

/// A mission file `name` of `segments` in this test's scratch folder.
fn mission_file(name: &str, segments: &[String]) -> PathBuf {
    let path = tmp(name);
    std::fs::write(&path, segments.concat()).unwrap();
    path
}

/// Flies the demo writing an output file for each (flag, file name) of `outputs` in this test's
/// scratch folder; it must succeed. The files' paths, in order.
fn demo_writing<const N: usize>(outputs: [(&str, &str); N]) -> [PathBuf; N] {
    let files = outputs.map(|(_, name)| tmp(name));
    let mut args = vec!["mission".to_string()];
    for ((flag, _), file) in outputs.iter().zip(&files) {
        args.push(flag.to_string());
        args.push(file.display().to_string());
    }
    common::ok_stdout(&args);
    files
}

#[test]
fn the_demo_runs_feasible_and_reads_as_a_report() {
    let (code, out, err) = aloft(&["mission"]);
    assert_eq!(code, 0, "{err}");
    for needle in [
        "FEASIBLE",
        "Point of no return: none",
        "Segments",
        "orbit",
        "TB47D",
        "Wind: 6.0 m/s from 250",
    ] {
        assert!(out.contains(needle), "missing '{needle}' in:\n{out}");
    }
}

#[test]
fn mission_json_has_the_contract_keys_and_omits_a_missing_point_of_no_return() {
    let v = common::ok_json(&["mission", "--format", "json"]);
    for k in [
        "feasible",
        "duration_s",
        "distance_m",
        "energy_wh",
        "start_soc",
        "end_soc",
        "min_voltage_v",
        "peak_power_w",
        "reserve_soc",
        "segments",
    ] {
        assert!(v.get(k).is_some(), "missing {k}");
    }
    assert!(v.get("point_of_no_return_s").is_none());
    let segs = v["segments"].as_array().unwrap();
    for k in [
        "kind",
        "duration_s",
        "distance_m",
        "energy_wh",
        "mean_power_w",
        "peak_power_w",
    ] {
        assert!(segs.iter().all(|s| s.get(k).is_some()), "segment key {k}");
    }
    let sum: f64 = segs.iter().map(|s| s["energy_wh"].as_f64().unwrap()).sum();
    assert!((sum - v["energy_wh"].as_f64().unwrap()).abs() < 1e-9);
}

#[test]
fn an_infeasible_mission_exits_1_and_says_where() {
    let path = mission_file(
        "long-hover.toml",
        &[take_off(20.0, 2.0), hover(3600.0), landing(1.0)],
    );
    let (code, out, _) = aloft(&["mission", path.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("NOT FEASIBLE")
            && out.contains("runs out")
            && out.contains("segment 2 (hover)"),
        "{out}"
    );
    let (code, out, _) = aloft(&["mission", path.to_str().unwrap(), "--format", "json"]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["feasible"], serde_json::Value::Bool(false));
    assert!(v["reason"].as_str().unwrap().contains("runs out"));
    assert!(v["point_of_no_return_s"].as_f64().is_some());
}

#[test]
fn bad_input_exits_2_with_a_clear_message() {
    let negative = orbit([0.0, 0.0], -25.0, 4.0, "clockwise", OrbitFor::Laps(1.0));
    let path = mission_file(
        "bad-radius.toml",
        &[take_off(20.0, 2.0), negative, landing(1.0)],
    );
    let (code, _, err) = aloft(&["mission", path.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("radius_m") && err.contains("-25"), "{err}");
    let empty = tmp("empty.toml");
    std::fs::write(&empty, "name = \"nothing\"\n").unwrap();
    let (code, _, err) = aloft(&["mission", empty.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("no segments"), "{err}");
    // A wind grid that does not reach the demo's survey area.
    let grid = tmp("small-grid.csv");
    common::write_wind_grid(&grid, [10.0, 50.0], "3,0,0");
    let (code, _, err) = aloft(&["mission", "--wind-field", grid.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("does not cover"), "{err}");
    let (code, _, err) = aloft(&["mission", "--battery", "TB99"]);
    assert_eq!(code, 2);
    assert!(err.contains("TB99") && err.contains("TB48D"), "{err}");
}

#[test]
fn timeseries_and_plot_are_written() {
    let [csv, svg] = demo_writing([("--timeseries", "demo.csv"), ("--plot", "demo.svg")]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let header = text.lines().next().unwrap();
    for k in [
        "time_s",
        "east_m",
        "north_m",
        "up_m",
        "power_w",
        "current_a",
        "voltage_v",
        "soc",
        "roll_deg",
    ] {
        assert!(header.split(',').any(|h| h == k), "{k} in {header}");
    }
    // 6:56 at a 0.1 s step: about 4160 rows
    assert!(text.lines().count() > 4000);
    let svg_text = std::fs::read_to_string(&svg).unwrap();
    assert!(svg_text.contains("<svg") && svg_text.contains("ground track"));
}

#[test]
fn endurance_json_has_the_contract_keys() {
    let v = common::ok_json(&[
        "endurance",
        "--format",
        "json",
        "--wind-speed",
        "5",
        "--wind-from",
        "0",
        "--course",
        "0",
        "--orbit-radius",
        "25",
        "--orbit-speed",
        "5",
    ]);
    for k in common::ENDURANCE_KEYS.iter().chain(&["orbit_endurance_s"]) {
        assert!(v[*k].as_f64().is_some_and(|x| x > 0.0), "{k}: {v}");
    }
    let (code, out, _) = aloft(&["endurance", "--sweep-speed", "1", "--format", "csv"]);
    assert_eq!(code, 0);
    assert!(out.starts_with("airspeed_mps,ground_speed_mps,power_w,endurance_s,range_m"));
    assert_eq!(out.lines().count(), 1 + 18); // 0..=17 m/s
}

#[test]
fn mission_mcap_is_written_with_samples_power_battery_and_the_path() {
    let [mcap, csv] = demo_writing([
        ("--mcap", "demo.mcap"),
        ("--timeseries", "demo-for-mcap.csv"),
    ]);
    let bytes = std::fs::read(&mcap).unwrap();
    // MCAP magic at both ends (MCAP spec: 0x89 "MCAP0" CR LF).
    let magic = b"\x89MCAP0\r\n";
    assert!(bytes.len() > 2 * magic.len());
    assert_eq!(&bytes[..magic.len()], magic);
    assert_eq!(&bytes[bytes.len() - magic.len()..], magic);

    // The samples as the CSV has them: one message per sample on each per-sample topic.
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let col = |k: &str| header.iter().position(|h| *h == k).unwrap();
    let n = rows.len();
    assert!(n > 4000);
    let k = n / 2;
    let expect = serde_json::json!({
        "topics": {
            "/aloft/pose": {"count": n, "schema": "foxglove.PoseInFrame"},
            "/aloft/state": {"count": n},
            "/aloft/power": {"count": n, "schema": "aloft.PowerTerms"},
            "/aloft/battery": {"count": n, "schema": "aloft.BatteryState"},
            "/aloft/path": {"count": 1, "schema": "foxglove.PosesInFrame"},
        },
        "values": [
            {"topic": "/aloft/power", "index": k, "path": "electrical_w",
             "value": rows[k][col("power_w")], "tol": 1e-6 * rows[k][col("power_w")]},
            {"topic": "/aloft/battery", "index": k, "path": "state_of_charge",
             "value": rows[k][col("soc")], "tol": 1e-9},
            {"topic": "/aloft/battery", "index": k, "path": "current_a",
             "value": rows[k][col("current_a")], "tol": 1e-9 * rows[k][col("current_a")]},
            {"topic": "/aloft/pose", "index": k, "path": "pose.position.x",
             "value": rows[k][col("east_m")], "tol": 1e-9},
            {"topic": "/aloft/path", "index": 0, "path": "poses.0.position.x", "value": 0.0, "tol": 1e-9},
        ],
    });
    common::check_mcap_with_python(&mcap, &expect);
}

/// `--corners`: the demo's survey flown through its corners (the default) is shorter than with
/// stop-and-turn, over the same route (the distance flown differs only by the arcs' cuts); the
/// command line's answer is the engine's, byte for byte; an unknown mode is refused.
#[test]
fn corners_pass_through_by_default_and_stop_on_request() {
    use aloft::engine::{plan_mission, CornerMode, Mission, MissionOptions, Vehicle};
    let json = |args: &[&str]| -> serde_json::Value {
        let (code, out, err) = aloft(args);
        assert_eq!(code, 0, "{err}");
        serde_json::from_str(&out).unwrap()
    };
    let pass = json(&["mission", "--format", "json"]);
    let stop = json(&["mission", "--format", "json", "--corners", "stop"]);
    let t = |v: &serde_json::Value| v["duration_s"].as_f64().unwrap();
    let d = |v: &serde_json::Value| v["distance_m"].as_f64().unwrap();
    // The demo has eight turns of 90 deg between its legs: each saves a few seconds.
    assert!(t(&stop) - t(&pass) > 8.0, "{} {}", t(&stop), t(&pass));
    // Each 2 m cut is replaced by a quarter circle of 2 m radius: 4 - pi m shorter a corner.
    assert!(d(&stop) > d(&pass) && d(&stop) - d(&pass) < 8.0 * (4.0 - std::f64::consts::PI) + 1.0);
    // The engine gives the same answer.
    let m100 = Vehicle::builtin("dji-m100").unwrap();
    let options = MissionOptions {
        corners: Some(CornerMode::Stop),
        ..MissionOptions::default()
    };
    let engine = plan_mission(&m100, &Mission::demo(), &options).unwrap();
    let engine: serde_json::Value = serde_json::from_str(&engine.to_json().unwrap()).unwrap();
    assert_eq!(engine, stop);
    let (code, out, err) = aloft(&["mission", "--corners", "round"]);
    assert_eq!(code, 2, "{out}");
    assert!(
        err.contains("--corners") && err.lines().count() == 1,
        "{err}"
    );
}

#[test]
fn json_mode_warnings_go_to_stderr_as_well_as_into_the_answer() {
    // A planner file that ends in the air, with no take-off: the reader's warnings and the
    // planner's (the way home added) are in the JSON and, one line each, on stderr.
    let dir = std::env::var("ALOFT_DATA_DIR").unwrap_or_else(|_| "../shared/data".to_string());
    let plan = format!("{dir}/missions/kasperg3_mission.plan");
    let (code, out, err) = aloft(&["mission", &plan, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let mut warnings: Vec<String> = v["route"]["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .chain(v["warnings"].as_array().unwrap())
        .map(|w| format!("aloft: warning: {}", w.as_str().unwrap()))
        .collect();
    assert!(warnings.len() >= 3, "{warnings:?}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(
        lines,
        warnings.iter().map(String::as_str).collect::<Vec<_>>()
    );
    // The table shows them in its header instead; stderr stays quiet.
    let (code, out, err) = aloft(&["mission", &plan]);
    assert_eq!(code, 0);
    assert!(err.is_empty(), "{err}");
    for w in warnings.drain(..) {
        let w = w.replace("aloft: warning: ", "Warning: ");
        assert!(out.contains(&w), "'{w}' missing in:\n{out}");
    }
}
