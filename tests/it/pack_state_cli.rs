//! Issue 44, before the flight: `aloft mission` starts from the pack's rested voltage
//! (`--start-voltage-v`) on its open-circuit curve, and the voltage failsafes carry bands over
//! the scenarios. The defect it answers: a flight planned from PX4's reported 37 % (the pack
//! rested at 3.58 V a cell, a few per cent) was told its 9.9 V critical failsafe "would not
//! trigger"; the log went below it 2.2 s after take-off.
//!
//! The M100's TB47D (6S) on the demo mission: 3.58 V a cell is 21.48 V, and its critical
//! failsafe at 3.3 V a cell is 19.8 V.

use crate::common;

use common::{aloft, stderr};
use serde_json::Value;

fn mission_json(args: &[&str]) -> Value {
    let mut all = vec!["mission", "--format", "json"];
    all.extend(args);
    let out = aloft(&all);
    assert!(matches!(out.status.code(), Some(0 | 1)), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).expect("JSON")
}

#[test]
fn a_rested_voltage_starts_the_mission_on_the_pack_curve() {
    // The generic LiPo curve (fixtures: 3.27 V at 0 %, 3.61 V at 5 %): 3.58 V a cell is
    // 5 % x (3.58 - 3.27) / (3.61 - 3.27) = 4.559 %.
    let v = mission_json(&["--start-voltage-v", "21.48"]);
    let want = 0.05 * (3.58 - 3.27) / (3.61 - 3.27);
    let got = v["start_soc"].as_f64().unwrap();
    assert!((got - want).abs() < 1e-9, "{got} vs {want}");
    // A full pack's rested voltage (4.20 V a cell) starts full.
    let v = mission_json(&["--start-voltage-v", "25.2"]);
    assert!((v["start_soc"].as_f64().unwrap() - 1.0).abs() < 1e-9, "{v}");
}

#[test]
fn from_the_rested_voltage_the_critical_failsafe_triggers_where_the_report_said_it_would_not() {
    let reported = mission_json(&["--start-percent", "37", "--critical-voltage-v", "19.8"]);
    let critical = &reported["failsafes"][0];
    assert!(critical.get("time_s").is_none(), "{reported}");
    let rested = mission_json(&["--start-voltage-v", "21.48", "--critical-voltage-v", "19.8"]);
    let critical = &rested["failsafes"][0];
    let t = critical["time_s"].as_f64().expect("it triggers");
    assert!(t < 60.0, "{critical}");
    // The bands over the scenarios: every one triggers it, p5 <= p50 <= p95 within the first
    // minute, around the deterministic time.
    let banded = mission_json(&[
        "--start-voltage-v",
        "21.48",
        "--critical-voltage-v",
        "19.8",
        "--samples",
        "100",
    ]);
    let band = &banded["uncertainty"]["failsafes"][0];
    assert_eq!(band["kind"], "critical", "{band}");
    assert_eq!(band["p_triggers"].as_f64(), Some(1.0), "{band}");
    let (p5, p50, p95) = (
        band["time_s"]["p5"].as_f64().unwrap(),
        band["time_s"]["p50"].as_f64().unwrap(),
        band["time_s"]["p95"].as_f64().unwrap(),
    );
    assert!(p5 <= p50 && p50 <= p95 && p95 < 60.0, "{band}");
    assert!(p5 <= t + 2.0 && t <= p95 + 2.0, "{t} outside {band}");
}

#[test]
fn a_voltage_that_is_not_the_packs_is_refused_naming_it() {
    for (args, what) in [
        (vec!["--start-voltage-v", "5"], "start_voltage_v"),
        (vec!["--start-voltage-v", "30"], "start_voltage_v"),
        (vec!["--start-voltage-v", "NaN"], "start-voltage-v"),
        (
            vec!["--start-voltage-v", "22", "--start-percent", "50"],
            "--start-voltage-v",
        ),
    ] {
        let mut all = vec!["mission"];
        all.extend(&args);
        let out = aloft(&all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        let err = stderr(&out);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(what), "{args:?}: {err}");
    }
}

#[test]
fn live_failsafe_thresholds_are_checked_naming_the_flag() {
    for (flag, value) in [("--low-voltage-v", "-3"), ("--critical-voltage-v", "0")] {
        let arg = format!("{flag}={value}");
        let out = aloft(&["live", "--tlog", "/nonexistent.tlog", &arg]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        let err = stderr(&out);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(flag.trim_start_matches('-')), "{err}");
    }
}
