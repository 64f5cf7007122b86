//! End-to-end `aloft log info` and `aloft convert`: output keys, exit codes, and clean failures.

use crate::common;
use common::{aloft, ok_json, refused, stderr};

use std::path::{Path, PathBuf};

fn fixture(name: &str) -> String {
    common::fixture("logs", name).display().to_string()
}

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("logs_cli-{}-{name}", std::process::id()))
}

#[test]
fn log_info_json_reports_duration_rates_and_energy() {
    let j = ok_json(&[
        "log",
        "info",
        &fixture("kaist_small.csv"),
        "--format",
        "json",
    ]);
    assert_eq!(j["format"], "csv");
    assert_eq!(j["profile"], "kaist");
    assert_eq!(j["samples"], 20);
    // 19 intervals of 0.1 s.
    assert!((j["duration_s"].as_f64().unwrap() - 1.9).abs() < 1e-9);
    let ch = j["channels"].as_array().unwrap();
    let v = ch.iter().find(|c| c["channel"] == "voltage").unwrap();
    assert!((v["rate_hz"].as_f64().unwrap() - 10.0).abs() < 1e-6);
    // Energy: trapezoids of V x I over the fixture's rows, computed here independently.
    let text = std::fs::read_to_string(fixture("kaist_small.csv")).unwrap();
    let rows: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (f[0] * 1e-6, f[17] * f[18])
        })
        .collect();
    let wh: f64 = rows
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum::<f64>()
        / 3600.0;
    assert!(
        (j["energy_wh"].as_f64().unwrap() - wh).abs() < 1e-9,
        "{} vs {wh}",
        j["energy_wh"]
    );
    assert_eq!(j["power_available"], true);
    assert_eq!(j["time"]["gap_count"], 0);
    assert_eq!(j["columns"].as_array().unwrap().len(), 20);
}

/// The rows of a CSV with a header, as columns by name.
fn csv_columns(path: &Path) -> std::collections::HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let mut cols: std::collections::HashMap<String, Vec<f64>> =
        names.iter().map(|n| (n.clone(), Vec::new())).collect();
    for l in lines {
        for (n, v) in names.iter().zip(l.split(',')) {
            // Non-numeric columns (none expected among the ones used) read as NaN.
            cols.get_mut(n).unwrap().push(v.parse().unwrap_or(f64::NAN));
        }
    }
    cols
}

/// Issue 23: `log info` of `mission --mcap` output reported twice the samples and one
/// "non-monotonic" step per sample. Sample count = rows of the time series aloft writes beside
/// the MCAP, no step back, and the energy of V x I by trapezoids over those rows (computed here).
#[test]
fn log_info_of_a_mission_mcap_has_the_time_series_rows() {
    let (csv, mcap) = (tmp("demo.csv"), tmp("demo.mcap"));
    let o = aloft(&[
        "mission",
        "--timeseries",
        csv.to_str().unwrap(),
        "--mcap",
        mcap.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let cols = csv_columns(&csv);
    let (t, v, i) = (&cols["time_s"], &cols["voltage_v"], &cols["current_a"]);
    assert!(t.len() > 100, "{} rows", t.len());
    let wh = (1..t.len())
        .map(|k| 0.5 * (v[k - 1] * i[k - 1] + v[k] * i[k]) * (t[k] - t[k - 1]))
        .sum::<f64>()
        / 3600.0;
    let j = ok_json(&["log", "info", mcap.to_str().unwrap(), "--format", "json"]);
    assert_eq!(j["samples"], t.len() as u64);
    assert_eq!(j["time"]["non_monotonic_count"], 0);
    assert_eq!(j["time"]["gap_count"], 0);
    // Times pass through whole nanoseconds of the MCAP log time: 1e-9 relative.
    let got = j["energy_wh"].as_f64().unwrap();
    assert!((got - wh).abs() < 1e-9 * wh, "{got} Wh vs {wh} Wh");
    let span = t[t.len() - 1] - t[0];
    assert!((j["duration_s"].as_f64().unwrap() - span).abs() < 1e-6);
    for c in j["channels"].as_array().unwrap() {
        assert_eq!(c["samples"], t.len() as u64, "{c}");
    }
}

#[test]
fn log_info_table_reports_gaps() {
    let o = aloft(&[
        "log",
        "info",
        &fixture("kaist_gap_backwards.csv"),
        "--profile",
        "kaist",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("gap: "), "{out}");
    assert!(out.contains("time goes back"), "{out}");
}

#[test]
fn bad_inputs_exit_2_with_the_file_named() {
    for (args, needle) in [
        (
            vec![
                "log",
                "info",
                &fixture("kaist_missing_cur.csv") as &str,
                "--profile",
                "kaist",
            ],
            "'cur'",
        ),
        (vec!["log", "info", &fixture("kaist_empty.csv")], "empty"),
        (vec!["log", "info", &fixture("truncated.mcap")], "truncated"),
        (vec!["log", "info", &fixture("custom.csv")], "profile"),
        (
            vec!["log", "info", &fixture("custom.csv"), "--profile", "nosuch"],
            "unknown profile",
        ),
        (
            vec![
                "log",
                "info",
                &fixture("custom.csv"),
                "--profile",
                &fixture("custom_wrong_units.toml"),
            ],
            "implausible",
        ),
        (
            vec!["log", "info", "/nonexistent/flight.mcap"],
            "flight.mcap",
        ),
    ] {
        let e = refused(&args);
        assert!(e.contains(needle), "{args:?}: {e}");
        assert!(!e.contains("panicked"), "{e}");
    }
}

/// `aloft convert` of the fixture log `csv` with the custom profile to `out`.
fn convert_custom(csv: &str, out: &Path) -> Vec<String> {
    let out = out.display().to_string();
    let profile = fixture("custom.toml");
    ["convert", &fixture(csv), "--profile", &profile, "-o", &out]
        .map(String::from)
        .to_vec()
}

#[test]
fn convert_writes_mcap_that_reads_back() {
    let out = tmp("conv.mcap");
    let mut args = convert_custom("custom.csv", &out);
    args.extend(["--format".into(), "json".into()]);
    let j = ok_json(&args);
    assert_eq!(j["samples"], 10);
    let j = ok_json(&["log", "info", out.to_str().unwrap(), "--format", "json"]);
    assert_eq!(j["format"], "mcap");
    let topics = common::strs_of(&j["topics"], "topic");
    assert_eq!(
        topics,
        vec!["/aloft/state", "/aloft/pose", "/aloft/battery"]
    );
    // 16 V x 12 A at the start: mean power a little above 190 W.
    let p = j["mean_power_w"].as_f64().unwrap();
    assert!((190.0..200.0).contains(&p), "{p}");
}

#[test]
fn failed_convert_leaves_no_output_file() {
    let out = tmp("bad.mcap");
    let err = refused(&convert_custom("custom_bad_number.csv", &out));
    assert!(err.contains("row 6"), "{err}");
    assert!(!out.exists());
}

#[test]
fn power_lag_needs_power_data() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/logs/custom.csv");
    let o = aloft(&[
        "log",
        "info",
        p.to_str().unwrap(),
        "--profile",
        &fixture("custom.toml"),
        "--max-lag",
        "1",
    ]);
    // custom.csv has power but no velocity.
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("velocity"), "{}", stderr(&o));
    assert!(stderr(&o).contains("--max-lag"), "{}", stderr(&o));
}

/// Issue 23, item 7: `--lag` was the search window in `log info` and the lag itself in `fit`,
/// `validate` and `mission --replay`. The window is `--max-lag` now; the old name is refused
/// (exit 2, one line naming the new flag with the value given), never taken as an alias.
#[test]
fn the_old_lag_flag_of_log_info_names_max_lag() {
    for (args, value) in [(&["--lag", "5"][..], "5"), (&["--lag"][..], "MAX_S")] {
        let mut all = vec!["log", "info", "x.csv"];
        all.extend_from_slice(args);
        let e = refused(&all);
        assert_eq!(e.lines().count(), 1, "{e}");
        assert!(
            e.contains("--lag of log info is now --max-lag")
                && e.contains(&format!("--max-lag {value} searches")),
            "{e}"
        );
    }
    // The window under its new name (and a lag estimated within it).
    let log = fixture("kaist_small.csv");
    let j = ok_json(&["log", "info", &log, "--max-lag", "0.3", "--format", "json"]);
    assert!(
        j["lag"]["lag_s"].as_f64().unwrap().abs() <= 0.3 + 1e-9,
        "{}",
        j["lag"]
    );
}

#[test]
fn log_info_json_warnings_go_to_stderr_as_well_as_into_the_answer() {
    let dir = std::env::var("ALOFT_DATA_DIR").unwrap_or_else(|_| "../shared/data".to_string());
    let log = format!("{dir}/flight_logs/pyulog_sample_log_small.ulg");
    let o = aloft(&["log", "info", &log, "--format", "json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let warnings: Vec<String> = v["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| format!("aloft: warning: {}", w.as_str().unwrap()))
        .collect();
    // This log has a dropout and an estimator without position: something to warn about.
    assert!(!warnings.is_empty());
    let err = stderr(&o);
    assert_eq!(err.lines().collect::<Vec<_>>(), warnings);
}
