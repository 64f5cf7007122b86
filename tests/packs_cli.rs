//! `aloft pack fit` and `--battery pack.toml` end to end: a pack file from the shared logs
//! (research note `air-packs.md` §2.5, §6 "Packs"), flown by the commands that fly, its
//! failsafes as times in the mission, and bad input refused with exit 2 and one stderr line.
//! Expected values are computed here from the log files and the samples aloft writes, not
//! copied from aloft's answers.

mod common;
use common::{aloft, data_dir, ok_json, scratch};

use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    scratch("packs-cli", name)
}

fn kaist(name: &str) -> PathBuf {
    data_dir().join("kaist_energy_drone").join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The step resistance of a KAIST CSV computed here from its `timestamp` (us), `vol` and `cur`
/// columns with the rule `aloft pack fit` documents: updates are rows whose voltage or current
/// changed; steps are consecutive updates under 1.5 s apart whose current changed by more than
/// max(2 A, 5 % of the largest current); the median of -dV/dI.
fn kaist_step_r(p: &Path) -> f64 {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (ct, cv, ci) = (col("timestamp"), col("vol"), col("cur"));
    let mut u: Vec<(f64, f64, f64)> = Vec::new();
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        let (t, v, i): (f64, f64, f64) = (
            f[ct].parse::<f64>().unwrap() * 1e-6,
            f[cv].parse().unwrap(),
            f[ci].parse().unwrap(),
        );
        if u.last().is_none_or(|&(_, v0, i0)| v0 != v || i0 != i) {
            u.push((t, v, i));
        }
    }
    let i_max = u.iter().map(|x| x.2).fold(0.0, f64::max);
    let thr = f64::max(2.0, 0.05 * i_max);
    let mut r: Vec<f64> = u
        .windows(2)
        .filter(|w| w[1].0 - w[0].0 < 1.5 && (w[1].2 - w[0].2).abs() > thr)
        .map(|w| -(w[1].1 - w[0].1) / (w[1].2 - w[0].2))
        .collect();
    r.sort_by(f64::total_cmp);
    let n = r.len();
    if n % 2 == 1 {
        r[n / 2]
    } else {
        0.5 * (r[n / 2 - 1] + r[n / 2])
    }
}

fn toml_value(path: &Path) -> toml::Table {
    std::fs::read_to_string(path).unwrap().parse().unwrap()
}

/// §2.5: two KAIST flights give a pack whose resistance is the median of their step estimates
/// (each computed here from the CSV), and the pack file loads and flies.
#[test]
fn data_val_pack_fit_on_kaist_writes_the_median_step_resistance() {
    let a = kaist("2018-08-03.10_31_21random5-1.csv");
    let b = kaist("2018-08-03.10_52_43random5-2.csv");
    let out = tmp("kaist.toml");
    let j = ok_json(&[
        "pack",
        "fit",
        s(&a),
        s(&b),
        "--profile",
        "kaist",
        "--cells",
        "12",
        "--capacity-mah",
        "12000",
        "--mass-kg",
        "4.0",
        "-o",
        s(&out),
        "--format",
        "json",
    ]);
    let (ra, rb) = (kaist_step_r(&a), kaist_step_r(&b));
    let want = 0.5 * (ra + rb);
    let got = j["internal_resistance_ohm"].as_f64().unwrap();
    // Same arithmetic on the same numbers: only the time stamps' rounding may differ.
    assert!(
        (got / want - 1.0).abs() < 1e-9,
        "{got} vs {want} ({ra}, {rb})"
    );
    let file = toml_value(&out);
    let bat = file["battery"].as_table().unwrap();
    assert!((bat["internal_resistance_ohm"].as_float().unwrap() / want - 1.0).abs() < 1e-9);
    assert_eq!(bat["cells_series"].as_integer(), Some(12));
    assert_eq!(bat["capacity_mah"].as_float(), Some(12000.0));
    // No rest in these logs (they start in flight): no capacity, with the reason.
    for l in j["logs"].as_array().unwrap() {
        assert!(l["capacity_mah"].is_null());
        let why = l["capacity_refused"].as_str().unwrap();
        assert!(why.starts_with("no rest before the flight"), "{why}");
        let ratio = l["coulomb_to_reported_ratio"].as_f64().unwrap();
        assert!((0.85..1.0).contains(&ratio), "{ratio}");
    }
    // Equivalent cycles: discharged / rated.
    let d = j["discharged_mah"].as_f64().unwrap();
    assert!((j["equivalent_cycles"].as_f64().unwrap() - d / 12000.0).abs() < 1e-9);
    // The pack file flies, selected by its name, at airframe + its mass: the M600's airframe is
    // its 9.100 kg take-off mass less its default 3.570 kg pack (fixtures/vehicles/dji-m600.toml).
    let e = ok_json(&[
        "endurance",
        "--vehicle",
        "dji-m600",
        "--battery",
        s(&out),
        "--format",
        "json",
    ]);
    assert_eq!(e["battery"], "fitted");
    let m = e["takeoff_mass_kg"].as_f64().unwrap();
    assert!((m - (9.100 - 3.570 + 4.0)).abs() < 1e-9, "{m}");
}

/// A pack file's `[failsafe]` and the flags: the time the mission says is the first sample of
/// its own time series whose voltage is below the threshold.
#[test]
fn failsafe_time_is_the_first_sample_below_the_threshold() {
    let pack = tmp("failsafe.toml");
    std::fs::write(
        &pack,
        "[battery]\nname = \"test-6s\"\ncells_series = 6\ncapacity_mah = 5700.0\nnominal_v = 22.8\n\
         energy_wh = 129.96\nmass_kg = 0.676\ninternal_resistance_ohm = 0.04\ncutoff_cell_v = 3.0\n\
         usable_fraction = 1.0\n\n[failsafe]\nlow_voltage_v = 22.6\n\n[fitted]\nlogs = [\"x\"]\n",
    )
    .unwrap();
    let ts = tmp("failsafe-ts.csv");
    let out = aloft(&[
        "mission",
        "--battery",
        s(&pack),
        "--start-percent",
        "60",
        "--critical-voltage-v",
        "20",
        "--timeseries",
        s(&ts),
        "--format",
        "json",
    ]);
    assert!(
        matches!(out.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let f = j["failsafes"].as_array().unwrap();
    assert_eq!(f.len(), 2);
    assert_eq!(f[0]["kind"], "low");
    assert_eq!(f[0]["voltage_v"].as_f64(), Some(22.6));
    // 20 V is below anything a 6S pack at 60 % reaches: never.
    assert_eq!(f[1]["kind"], "critical");
    assert!(f[1]["time_s"].is_null() && f[1]["segment"].is_null());
    // The first sample below 22.6 V in the written time series.
    let csv = std::fs::read_to_string(&ts).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (ct, cs, cv) = (col("time_s"), col("segment"), col("voltage_v"));
    let first = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|r| r[cv].parse::<f64>().unwrap() < 22.6)
        .expect("the voltage falls below 22.6 V");
    assert_eq!(
        f[0]["time_s"].as_f64(),
        Some(first[ct].parse::<f64>().unwrap())
    );
    assert_eq!(
        f[0]["segment"].as_u64(),
        Some(first[cs].parse::<u64>().unwrap())
    );
    // The table says it in words.
    let table = aloft(&["mission", "--battery", s(&pack), "--start-percent", "60"]);
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(
        text.contains("the low-voltage failsafe (22.6 V) would trigger at "),
        "{text}"
    );
}

/// Exit 2 and one stderr line naming what is wrong.
fn refused(args: &[&str], needles: &[&str]) {
    let out = aloft(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: {err} lacks {n}");
    }
}

#[test]
fn bad_input_is_exit_2_with_one_line() {
    // A pack file whose capacity is 0: the key and its range.
    let zero = tmp("zero.toml");
    std::fs::write(
        &zero,
        "[battery]\nname = \"z\"\ncells_series = 6\ncapacity_mah = 0.0\nnominal_v = 22.8\n\
         energy_wh = 129.96\nmass_kg = 0.676\ninternal_resistance_ohm = 0.04\ncutoff_cell_v = 3.0\n",
    )
    .unwrap();
    for cmd in [
        vec!["mission", "--battery", s(&zero)],
        vec!["endurance", "--battery", s(&zero)],
        vec!["power", "--battery", s(&zero), "--airspeed", "5"],
    ] {
        refused(
            &cmd,
            &[
                "capacity_mah = 0",
                "a positive finite number up to 1e7",
                s(&zero),
            ],
        );
    }
    // A file that is not a log.
    let text = tmp("notes.txt");
    std::fs::write(&text, "not a log\n").unwrap();
    let out = tmp("x.toml");
    refused(
        &["pack", "fit", s(&text), "--mass-kg", "1", "-o", s(&out)],
        &[s(&text), "unsupported log format"],
    );
    // A missing file.
    let missing = tmp("missing.ulg");
    refused(
        &["pack", "fit", s(&missing), "--mass-kg", "1", "-o", s(&out)],
        &[s(&missing), "no such file"],
    );
    // The SITL log does not give its cells: named.
    let sitl = data_dir().join("flight_logs/sitl_ac47_00000002.BIN");
    refused(
        &["pack", "fit", s(&sitl), "--mass-kg", "0.3", "-o", s(&out)],
        &["cells_series", "--cells"],
    );
    assert!(!out.exists(), "nothing is written on bad input");
}

/// A log without battery data is skipped with its reason; none usable is exit 1.
#[test]
fn data_val_no_usable_log_is_exit_1() {
    let erle = data_dir().join("flight_logs/erle_2014-09-07_7.BIN");
    let out = tmp("none.toml");
    let o = aloft(&["pack", "fit", s(&erle), "--mass-kg", "1", "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("erle_2014-09-07_7.BIN: skipped"), "{err}");
    assert!(!out.exists());
}

/// §6.5: the SITL BIN's `BAT.Res` is reported beside the step estimate, its `BATT_LOW_VOLT`
/// (10.5 V in its parameters, `flight_logs/README.md`'s log) becomes the pack's `[failsafe]`.
#[test]
fn data_val_sitl_bin_gives_the_autopilot_resistance_and_failsafe() {
    let sitl = data_dir().join("flight_logs/sitl_ac47_00000002.BIN");
    let out = tmp("sitl.toml");
    let j = ok_json(&[
        "pack",
        "fit",
        s(&sitl),
        "--cells",
        "3",
        "--mass-kg",
        "0.3",
        "-o",
        s(&out),
        "--format",
        "json",
    ]);
    assert!(j["logs"][0]["autopilot_internal_resistance_ohm"]
        .as_f64()
        .is_some());
    // BATT_CAPACITY 3300 mAh is logged.
    assert_eq!(j["logs"][0]["rated_capacity_mah"].as_f64(), Some(3300.0));
    let file = toml_value(&out);
    assert_eq!(file["failsafe"]["low_voltage_v"].as_float(), Some(10.5));
}

/// Over `aloft serve` (and Python) a request names no file of the server's: the keyword entry
/// point takes a `.toml` battery value as a pack name, never as a file to read.
#[test]
fn the_keyword_entry_point_does_not_read_a_pack_file() {
    use aloft::engine::{answers, flags::MissionScenarioFlags, parse_keywords, Keyword};
    let pack = tmp("served.toml");
    std::fs::write(
        &pack,
        "[battery]\nname = \"served\"\ncells_series = 6\ncapacity_mah = 5700.0\nnominal_v = 22.8\n\
         energy_wh = 129.96\nmass_kg = 0.676\ninternal_resistance_ohm = 0.04\ncutoff_cell_v = 3.0\n",
    )
    .unwrap();
    let flags: MissionScenarioFlags = parse_keywords(
        "POST /api/mission",
        &[],
        &[("battery".to_string(), Keyword::One(s(&pack).into()))],
    )
    .unwrap();
    let e = answers::mission_answer(None, &flags)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no battery"), "{e}");
    // And the command line does read it.
    let o = aloft(&["mission", "--battery", s(&pack), "--format", "json"]);
    assert!(matches!(o.status.code(), Some(0 | 1)));
}
