//! `--samples N` end to end (issue 17): the JSON `uncertainty`, the table's line and bands, the
//! chart, the endurance percentiles, and bad values exiting 2 with the flag named.

use crate::common;
use common::{ok_json, ok_stdout, run as aloft};

#[test]
fn mission_json_carries_the_uncertainty_keys() {
    let out = ok_stdout(&[
        "mission",
        "--samples",
        "30",
        "--time-step",
        "0.5",
        "--payload-sd-kg",
        "0.1",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let u = &v["uncertainty"];
    assert_eq!(u["samples"], 30);
    assert_eq!(u["seed"], 1);
    for key in [
        "p_feasible",
        "feasible_scenarios",
        "completed_scenarios",
        "p_point_of_no_return",
    ] {
        assert!(u[key].is_number(), "{key}: {u}");
    }
    for key in ["energy_wh", "end_soc", "duration_s"] {
        for p in ["p5", "p50", "p95"] {
            assert!(u[key][p].is_number(), "{key}.{p}: {u}");
        }
    }
    assert_eq!(u["spreads"]["power_sd_percent"], 3.0);
    assert_eq!(u["spreads"]["payload_sd_kg"], 0.1);
    // The demo has no point of no return in nearly every scenario: the key is left out, never null.
    assert!(u.get("point_of_no_return_s").is_none() || u["point_of_no_return_s"].is_object());
    assert_eq!(
        u["segments"].as_array().unwrap().len(),
        v["segments"].as_array().unwrap().len()
    );
    assert!(!out.contains("null") && !out.contains("NaN"));
    // The deterministic keys are those of a run without --samples, unchanged.
    let (_, plain, _) = aloft(&["mission", "--time-step", "0.5", "--format", "json"]);
    let plain: serde_json::Value = serde_json::from_str(&plain).unwrap();
    let mut without = v.clone();
    without.as_object_mut().unwrap().remove("uncertainty");
    assert_eq!(without, plain);
}

#[test]
fn the_table_says_it_in_a_line_and_the_chart_is_drawn() {
    let svg = common::scratch("scenarios", "fan.svg");
    // A file of an earlier run is kept without --force: start without it.
    let _ = std::fs::remove_file(&svg);
    let (code, out, err) = aloft(&[
        "mission",
        "--samples",
        "40",
        "--time-step",
        "0.5",
        "--reserve-percent",
        "62",
        "--payload-sd-kg",
        "0.2",
        "--payload-kg",
        "0.35",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(code == 0 || code == 1, "{err}");
    assert!(
        out.contains("lands with the reserve in ") && out.contains(" % of 40 scenarios"),
        "{out}"
    );
    assert!(
        out.contains("Point of no return with 95 % confidence"),
        "{out}"
    );
    assert!(out.contains("p5 end") && out.contains("p95 end"), "{out}");
    let svg = std::fs::read_to_string(&svg).unwrap();
    assert!(svg.contains("5th-95th percentile") && svg.contains("95 % confidence"));
    assert!(svg.contains("<polygon"), "the fan is a filled band");
}

#[test]
fn endurance_gives_percentiles_of_hover_endurance_and_range() {
    let v = ok_json(&[
        "endurance",
        "--samples",
        "50",
        "--wind-speed",
        "5",
        "--wind-from",
        "0",
        "--wind-speed-sd",
        "2",
        "--format",
        "json",
    ]);
    let u = &v["uncertainty"];
    for key in ["hover_endurance_s", "max_endurance_s", "max_range_m"] {
        let (a, b, c) = (
            u[key]["p5"].as_f64().unwrap(),
            u[key]["p50"].as_f64().unwrap(),
            u[key]["p95"].as_f64().unwrap(),
        );
        assert!(a <= b && b <= c, "{key}: {u}");
    }
    assert!(v["hover_endurance_s"].is_number());
    let (code, out, _) = aloft(&["endurance", "--samples", "20"]);
    assert_eq!(code, 0);
    assert!(
        out.contains("Uncertainty (5th percentile / median / 95th)"),
        "{out}"
    );
}

#[test]
fn bad_scenario_values_exit_2_naming_the_flag() {
    for (args, flag) in [
        (vec!["mission", "--samples", "0"], "--samples"),
        (vec!["mission", "--samples", "100001"], "--samples"),
        (vec!["mission", "--samples", "ten"], "--samples"),
        (
            vec!["mission", "--samples", "10", "--wind-speed-sd", "-1"],
            "--wind-speed-sd",
        ),
        (
            vec!["mission", "--samples", "10", "--wind-from-sd", "nan"],
            "--wind-from-sd",
        ),
        (
            vec!["mission", "--samples", "10", "--payload-sd-kg", "-0.1"],
            "--payload-sd-kg",
        ),
        (
            vec!["mission", "--samples", "10", "--capacity-sd-percent", "60"],
            "--capacity-sd-percent",
        ),
        (
            vec!["mission", "--samples", "10", "--power-sd-percent", "inf"],
            "--power-sd-percent",
        ),
        (vec!["mission", "--seed", "3"], "--samples"),
        (
            vec!["endurance", "--samples", "10", "--sweep-speed", "1"],
            "--samples",
        ),
        (
            vec!["mission", "--samples", "10", "--replay", "x.csv"],
            "--samples",
        ),
    ] {
        let (code, out, err) = aloft(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}");
        assert!(err.contains(flag), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    }
}
