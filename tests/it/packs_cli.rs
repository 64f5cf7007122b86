//! `aloft pack fit` and `--battery pack.toml` end to end: a pack file from the shared logs
//! (research note `air-packs.md` §2.5, §6 "Packs"), flown by the commands that fly, its
//! failsafes as times in the mission, and bad input refused with exit 2 and one stderr line.
//! Expected values are computed here from the log files and the samples aloft writes, not
//! copied from aloft's answers.

use crate::common;
use common::kaist::pack_fit;
use common::{aloft, assert_refused, csv_columns, data_dir, ok_json, ok_stdout, scratch};

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
    let mut u: Vec<(f64, f64, f64)> = Vec::new();
    for [t_us, v, i] in csv_columns(p, ["timestamp", "vol", "cur"]) {
        if u.last().is_none_or(|&(_, v0, i0)| v0 != v || i0 != i) {
            u.push((t_us * 1e-6, v, i));
        }
    }
    let i_max = u.iter().map(|x| x.2).fold(0.0, f64::max);
    let thr = f64::max(2.0, 0.05 * i_max);
    let r: Vec<f64> = u
        .windows(2)
        .filter(|w| w[1].0 - w[0].0 < 1.5 && (w[1].2 - w[0].2).abs() > thr)
        .map(|w| -(w[1].1 - w[0].1) / (w[1].2 - w[0].2))
        .collect();
    common::median(r)
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
    let j = pack_fit(&[a.clone(), b.clone()], 12000.0, 4.0, s(&out));
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
    // The RC pair: two flights cannot give the pack one (three that agree are needed), said
    // in the answer and the file's [fitted]. Beside the curve fitted here (under load, holding
    // the mean polarisation) the pair written has no resistance; without a curve, none.
    let why = j["rc_refused"].as_str().unwrap();
    assert!(why.contains("at least 3 are needed"), "{why}");
    assert_eq!(file["fitted"]["rc_refused"].as_str(), Some(why));
    match j.get("ocv") {
        Some(_) => {
            assert_eq!(bat["rc_resistance_ohm"].as_float(), Some(0.0));
            assert_eq!(j["rc_resistance_ohm"].as_f64(), Some(0.0));
        }
        None => assert!(bat.get("rc_time_constant_s").is_none()),
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
    // Issue 41 item 5: left out, not `null`.
    let keys: Vec<&String> = f[1].as_object().unwrap().keys().collect();
    assert!(
        !keys.iter().any(|k| *k == "time_s" || *k == "segment"),
        "{keys:?}"
    );
    assert!(
        common::nulls(&j).is_empty(),
        "null at {:?}",
        common::nulls(&j)
    );
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
        assert_refused(&cmd, &["capacity_mah = 0", "from 10 to 1e7 mA h", s(&zero)]);
    }
    // A file that is not a log.
    let text = tmp("notes.txt");
    std::fs::write(&text, "not a log\n").unwrap();
    let out = tmp("x.toml");
    assert_refused(
        &["pack", "fit", s(&text), "--mass-kg", "1", "-o", s(&out)],
        &[s(&text), "unsupported log format"],
    );
    // A missing file.
    let missing = tmp("missing.ulg");
    assert_refused(
        &["pack", "fit", s(&missing), "--mass-kg", "1", "-o", s(&out)],
        &[s(&missing), "no such file"],
    );
    // The SITL log does not give its cells: named.
    let sitl = data_dir().join("flight_logs/sitl_ac47_00000002.BIN");
    assert_refused(
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

/// A flugdrohne ULog (`px4_flugdrohne/ulg`).
fn flugdrohne(stem: &str) -> PathBuf {
    data_dir().join(format!("px4_flugdrohne/ulg/{stem}.ulg"))
}

/// `aloft pack fit LOGS... EXTRA --capacity-mah 5000 --mass-kg 0.37 -o OUT`: the flugdrohne
/// pack as its owner states it (5000 mA h, 0.37 kg).
fn flugdrohne_fit(logs: &[&Path], extra: &[&str], out: &Path) -> Vec<String> {
    let mut args: Vec<String> = vec!["pack".into(), "fit".into()];
    args.extend(logs.iter().map(|l| s(l).to_string()));
    args.extend(extra.iter().map(|e| e.to_string()));
    args.extend(["--capacity-mah", "5000", "--mass-kg", "0.37", "-o", s(out)].map(String::from));
    args
}

/// The same with `--format json`, which must succeed: its JSON.
fn flugdrohne_fit_json(logs: &[&Path], extra: &[&str], out: &Path) -> serde_json::Value {
    let mut args = flugdrohne_fit(logs, extra, out);
    args.extend(["--format".into(), "json".into()]);
    ok_json(&args)
}

/// The rows of a flugdrohne `battery_status` table: time (s from its first row), voltage (V),
/// current (A), read here from the CSV export.
fn battery_rows(csv: &Path) -> Vec<(f64, f64, f64)> {
    let rows = csv_columns(csv, ["timestamp", "voltage_v", "current_a"]);
    let t0 = rows[0][0] * 1e-6;
    rows.into_iter()
        .map(|[t_us, v, i]| (t_us * 1e-6 - t0, v, i))
        .collect()
}

/// The first number in `text` after `after`.
fn number_after(text: &str, after: &str) -> f64 {
    let rest = &text[text
        .find(after)
        .unwrap_or_else(|| panic!("{after:?} in {text:?}"))
        + after.len()..];
    let num: String = rest
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    num.parse()
        .unwrap_or_else(|_| panic!("a number after {after:?} in {text:?}"))
}

/// Issue 41 item 10: a flugdrohne flight rests at 0 A for 9.8 s before take-off (shorter than
/// the 30 s a rest must hold). The refusal said "the current is 0.00 A at the first record,
/// above the rest limit of 0.25 A"; it says how long the pack rested, which is computed here
/// from the CSV export: the first record drawing 0.25 A or more (0.05 C of the given
/// 5000 mA h), less the first record's time.
#[test]
fn data_val_a_short_rest_says_how_long_the_pack_rested() {
    let stem = "log_66_2023-6-21-08-44-02";
    let rows =
        battery_rows(&data_dir().join(format!("px4_flugdrohne/csv/{stem}_battery_status_0.csv")));
    let load_s = rows.iter().find(|r| r.2.abs() >= 0.25).unwrap().0;
    let out = tmp("short-rest.toml");
    let j = flugdrohne_fit_json(&[&flugdrohne(stem)], &[], &out);
    let why = j["logs"][0]["capacity_refused"].as_str().unwrap();
    assert!(!why.contains("above the rest limit"), "{why}");
    assert!(why.contains("below the rest limit of 0.25 A"), "{why}");
    let rested = number_after(why, "for only ");
    // One battery record (0.2 s at 5 Hz) of slack: the ULog and its CSV export share clocks.
    assert!(
        (rested - load_s).abs() <= 0.2,
        "{rested} s vs {load_s} s: {why}"
    );
}

/// Issue 41 item 10: a 3S pack resting at 12.29 V (the first 1.9 s of a flugdrohne log, before
/// any current is drawn) read as state of charge 0.000. Its state of charge is read on the
/// typical LiPo open-circuit curve; the expectation here comes from the commonly published LiPo
/// resting-voltage table (4.20 V 100 %, 4.15 V 95 %, 4.11 V 90 %, 4.08 V 85 %, 4.02 V 80 %,
/// 3.98 V 75 %, 3.95 V 70 %, 3.91 V 65 %, 3.87 V 60 %, 3.85 V 55 %, 3.84 V 50 %, 3.82 V 45 %,
/// 3.80 V 40 %), interpolated at the mean rested voltage per cell of the CSV export; 5 points
/// of tolerance for the spread between published curves.
#[test]
fn data_val_a_pack_resting_at_12_3_v_reads_about_90_percent() {
    let stem = "log_30_2023-6-7-12-11-06";
    let prefix = common::px4_tables_until(stem, 1.9, "packs-cli", "rested");
    let rows = battery_rows(&prefix.with_file_name("rested_battery_status_0.csv"));
    assert!(rows.iter().all(|r| r.2.abs() < 0.25), "{rows:?}");
    let cell_v = rows.iter().map(|r| r.1).sum::<f64>() / rows.len() as f64 / 3.0;
    let table = [
        (3.80, 0.40),
        (3.82, 0.45),
        (3.84, 0.50),
        (3.85, 0.55),
        (3.87, 0.60),
        (3.91, 0.65),
        (3.95, 0.70),
        (3.98, 0.75),
        (4.02, 0.80),
        (4.08, 0.85),
        (4.11, 0.90),
        (4.15, 0.95),
        (4.20, 1.00),
    ];
    let k = table.windows(2).position(|w| cell_v <= w[1].0).unwrap();
    let (a, b) = (table[k], table[k + 1]);
    let want = a.1 + (b.1 - a.1) * (cell_v - a.0) / (b.0 - a.0);
    assert!((0.85..0.92).contains(&want), "{cell_v} V a cell: {want}");
    let out = tmp("rested.toml");
    let mut args = flugdrohne_fit(&[&prefix], &["--cells", "3"], &out);
    args.extend(["--format".into(), "json".into()]);
    let o = aloft(&args);
    // One log that never drew current: no resistance, so no pack (exit 2, named); the report
    // of the log is in the JSON of a second run with a pack to keep the resistance from.
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let j = flugdrohne_fit_json(&[&prefix, &flugdrohne(stem)], &["--cells", "3"], &out);
    let why = j["logs"][0]["capacity_refused"].as_str().unwrap();
    let soc = number_after(why, "state of charge ");
    assert!(
        (soc - want).abs() <= 0.05,
        "{soc} vs {want} ({cell_v} V a cell): {why}"
    );
}

/// Issue 41 item 5: `pack fit`'s JSON carried `null` for every number a log did not give
/// (`autopilot_internal_resistance_ohm`, `capacity_mah`, `imbalance_minor_min`, ...); absent
/// values are left out.
#[test]
fn data_val_pack_fit_json_carries_no_null() {
    let out = tmp("no-null.toml");
    let logs: Vec<PathBuf> = ["1x_wo_Last_5m", "log_66_2023-6-21-08-44-02"]
        .iter()
        .map(|s| flugdrohne(s))
        .collect();
    let j = flugdrohne_fit_json(&[&logs[0], &logs[1]], &[], &out);
    let nulls = common::nulls(&j);
    assert!(nulls.is_empty(), "null at {nulls:?}");
}

/// The flugdrohne ULog `stem` with every value of its parameter `BAT1_CAPACITY` (a ULog
/// `float` parameter: its key text, then 4 little-endian bytes) set to `mah`, written to the
/// scratch folder: a real log with a capacity parameter no pack has.
fn with_logged_capacity(stem: &str, mah: f32) -> PathBuf {
    let mut bytes = std::fs::read(flugdrohne(stem)).unwrap();
    let key = b"float BAT1_CAPACITY";
    let mut found = 0;
    let mut at = 0;
    while let Some(k) = bytes[at..].windows(key.len()).position(|w| w == key) {
        let v = at + k + key.len();
        bytes[v..v + 4].copy_from_slice(&mah.to_le_bytes());
        found += 1;
        at = v + 4;
    }
    assert!(found > 0, "no BAT1_CAPACITY parameter in {stem}");
    let out = tmp(&format!("{stem}-capacity.ulg"));
    std::fs::write(&out, bytes).unwrap();
    out
}

/// Issue 41 item 6: a logged `BAT1_CAPACITY` of 1e-38 mA h was read as the pack's capacity
/// (1.8e40 equivalent cycles; the pack then flew 0.0 min, exit 0). Below 10 mA h it is unset,
/// with a note: the pack needs `--capacity-mah` (exit 2, one line), and with it the cycles are
/// the charge drawn over that.
#[test]
fn data_val_a_logged_capacity_below_10_mah_is_unset_with_a_note() {
    let log = with_logged_capacity("log_66_2023-6-21-08-44-02", 1e-38);
    let out = tmp("tiny-capacity.toml");
    assert_refused(
        &["pack", "fit", s(&log), "--mass-kg", "0.37", "-o", s(&out)],
        &["--capacity-mah"],
    );
    assert!(!out.exists());
    let j = flugdrohne_fit_json(&[&log], &[], &out);
    let d = j["discharged_mah"].as_f64().unwrap();
    let cycles = j["equivalent_cycles"].as_f64().unwrap();
    assert!(
        (cycles - d / 5000.0).abs() < 1e-12,
        "{cycles} vs {d} / 5000"
    );
    let notes: Vec<&str> = j["notes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|n| n.as_str())
        .collect();
    assert!(
        notes
            .iter()
            .any(|n| n.contains("BAT1_CAPACITY") && n.contains("10 mA h")),
        "{notes:?}"
    );
}

/// Issue 41 item 6: a capacity below 10 mA h given by a flag or a file is refused with its
/// range (exit 2, one line); 10 mA h itself is a pack.
#[test]
fn a_given_capacity_below_10_mah_is_refused_with_its_range() {
    let log = flugdrohne("log_66_2023-6-21-08-44-02");
    let out = tmp("given-tiny.toml");
    for mah in ["5", "1e-38", "9.99"] {
        assert_refused(
            &[
                "pack",
                "fit",
                s(&log),
                "--capacity-mah",
                mah,
                "--mass-kg",
                "0.37",
                "-o",
                s(&out),
            ],
            &["capacity", "10"],
        );
    }
    assert!(!out.exists());
    let small = tmp("small.toml");
    for (mah, ok) in [(5.0, false), (10.0, true)] {
        // energy_wh = capacity x nominal voltage, as the file format requires.
        std::fs::write(
            &small,
            format!(
                "[battery]\nname = \"small\"\ncells_series = 1\ncapacity_mah = {mah:?}\n\
                 nominal_v = 3.7\nenergy_wh = {:?}\nmass_kg = 0.01\n\
                 internal_resistance_ohm = 0.1\ncutoff_cell_v = 3.0\n",
                mah / 1000.0 * 3.7
            ),
        )
        .unwrap();
        let args = ["endurance", "--battery", s(&small), "--format", "json"];
        if ok {
            let o = aloft(&args);
            assert!(
                matches!(o.status.code(), Some(0 | 1)),
                "{}",
                String::from_utf8_lossy(&o.stderr)
            );
        } else {
            assert_refused(&args, &["capacity_mah = 5", "from 10 to 1e7 mA h"]);
        }
    }
}

/// Issue 41 item 11: a newline (or another control character) in a log's file name broke the
/// table's rows; it is shown escaped, the row whole.
#[test]
fn a_newline_in_a_log_name_stays_in_its_table_row() {
    let link = tmp("two\nlines\u{1b}[31m.ulg");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(flugdrohne("log_66_2023-6-21-08-44-02"), &link).unwrap();
    let out = tmp("newline.toml");
    let text = ok_stdout(&flugdrohne_fit(&[&link], &[], &out));
    assert!(
        text.lines()
            .any(|l| l.contains(r"two\nlines\u{1b}[31m.ulg")),
        "{text}"
    );
    assert!(!text.lines().any(|l| l.starts_with("lines")), "{text}");
    assert!(!text.contains('\u{1b}'), "{text}");
}

/// The KAIST CSV's rows: (time s, gauge mA h, voltage V, current A), read here.
fn kaist_rows(p: &Path) -> Vec<(f64, f64, f64, f64)> {
    csv_columns(p, ["timestamp", "capacity", "vol", "cur"])
        .into_iter()
        .map(|[t_us, q, v, i]| (t_us * 1e-6, q, v, i))
        .collect()
}

/// A piecewise-linear curve's value at `s` (clamped to its ends).
fn interp(xs: &[f64], ys: &[f64], s: f64) -> f64 {
    let s = s.clamp(xs[0], xs[xs.len() - 1]);
    let k = xs.partition_point(|x| *x < s).clamp(1, xs.len() - 1);
    ys[k - 1] + (ys[k] - ys[k - 1]) * (s - xs[k - 1]) / (xs[k] - xs[k - 1])
}

/// The RMS (V) of `12 x curve(s) - I R` against the logged voltage over a KAIST flight, the state
/// of charge counted from the gauge's first reading by the logged current (trapezoid), over `C`.
fn curve_rms_v(rows: &[(f64, f64, f64, f64)], xs: &[f64], ys: &[f64], c_mah: f64, r: f64) -> f64 {
    let mut q_mah = 0.0;
    let mut sum = 0.0;
    for (k, row) in rows.iter().enumerate() {
        if k > 0 {
            let p = rows[k - 1];
            q_mah += 0.5 * (p.3 + row.3) * (row.0 - p.0) / 3.6;
        }
        let soc = (rows[0].1 - q_mah) / c_mah;
        sum += (12.0 * interp(xs, ys, soc) - row.3 * r - row.2).powi(2);
    }
    (sum / rows.len() as f64).sqrt()
}

/// Issue 44: the pack's own open-circuit curve from its gauge. Fitted on two 2018-08-03 flights
/// and written into the pack file (spanning 0-1, the measured part said); judged on a flight of
/// another day, computed here from its CSV: its voltage under load is closer on the fitted curve
/// than on the generic LiPo curve.
#[test]
fn data_val_pack_fit_on_kaist_writes_the_packs_own_curve() {
    let a = kaist("2018-08-03.10_31_21random5-1.csv");
    let b = kaist("2018-08-03.10_52_43random5-2.csv");
    let out = tmp("kaist-ocv.toml");
    let j = pack_fit(&[a, b], 13000.0, 4.0, s(&out));
    let ocv = &j["ocv"];
    let (lo, hi) = (
        ocv["measured_from_soc"].as_f64().unwrap(),
        ocv["measured_to_soc"].as_f64().unwrap(),
    );
    let file = toml_value(&out);
    let bat = file["battery"].as_table().unwrap();
    let floats = |v: &toml::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_float().unwrap())
            .collect()
    };
    let (xs, ys) = (floats(&bat["ocv_soc"]), floats(&bat["ocv_cell_v"]));
    assert_eq!(xs.first(), Some(&0.0));
    assert_eq!(xs.last(), Some(&1.0));
    let measured = floats(&file["fitted"]["ocv_measured_soc"]);
    assert_eq!(measured, [lo, hi]);
    assert!(ys.windows(2).all(|w| w[0] <= w[1]), "{ys:?}");
    let r = bat["internal_resistance_ohm"].as_float().unwrap();
    let rows = kaist_rows(&kaist("2018-08-06.10_38_16random5-2sec-1.csv"));
    let g = [
        0.0, 0.05, 0.10, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40, 0.45, 0.50, 0.55, 0.60, 0.65, 0.70,
        0.75, 0.80, 0.85, 0.90, 0.95, 1.0,
    ];
    let gv = [
        3.27, 3.61, 3.69, 3.71, 3.73, 3.75, 3.77, 3.79, 3.80, 3.82, 3.84, 3.85, 3.87, 3.91, 3.95,
        3.98, 4.02, 4.08, 4.11, 4.15, 4.20,
    ];
    let fitted = curve_rms_v(&rows, &xs, &ys, 13000.0, r);
    let generic = curve_rms_v(&rows, &g, &gv, 13000.0, r);
    eprintln!("measured {lo}-{hi}; RMS fitted {fitted:.3} V, generic {generic:.3} V");
    // Measured: 0.069 V on the fitted curve, 0.427 V on the generic one (the pack 49 V falling
    // to 44 V; the resistance alone leaves 0.15-0.19 V on the generic curve with a fitted
    // capacity, docs/validation.md).
    assert!(
        fitted < 0.1 && fitted < 0.5 * generic,
        "{fitted} against {generic}"
    );
}

/// A gauge that reads more than the capacity given: no curve, said, and the pack still written
/// (on the generic curve).
#[test]
fn pack_fit_says_why_there_is_no_curve() {
    let b = kaist("2018-08-03.10_52_43random5-2.csv");
    let out = tmp("kaist-no-ocv.toml");
    let j = pack_fit(&[b], 12000.0, 4.0, s(&out));
    let why = j["ocv_refused"].as_str().unwrap();
    // The gauge reads 12 596 mA h at the first record (the CSV's `capacity`).
    assert!(
        why.contains("more than the capacity of 12000 mA h") && why.contains("--capacity-mah"),
        "{why}"
    );
    assert!(j.get("ocv").is_none());
    let file = toml_value(&out);
    assert!(file["battery"].get("ocv_soc").is_none());
    assert_eq!(file["fitted"]["ocv_refused"].as_str(), Some(why));
}
