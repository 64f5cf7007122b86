//! Endurance against payload (`aloft endurance --payload-sweep START:STOP:STEP`, the engine's
//! `payload_sweep`): each row is the endurance answer at that payload, the curves stop at the
//! maximum take-off mass with a note, and the CLI's table, JSON, CSV, chart and refusals.

use crate::common;
use common::{assert_refused, ok_json, ok_stdout as stdout_of};

use aloft::engine::{
    endurance, payload_sweep, EnduranceOptions, PayloadCurve, PayloadSweep, Vehicle,
};
use aloft::vehicle::VehicleFile;

fn m100() -> Vehicle {
    Vehicle::builtin("dji-m100").unwrap()
}

/// Options away from the defaults, so the sweep must pass them on: a wind across the course, a
/// reserve and an orbit.
fn windy() -> EnduranceOptions {
    EnduranceOptions {
        wind: common::uniform_wind(5.0, 30.0),
        course_deg: 90.0,
        reserve_percent: 20.0,
        orbit_radius_m: Some(40.0),
        orbit_speed_mps: Some(6.0),
        ..EnduranceOptions::default()
    }
}

fn sweep(text: &str) -> PayloadSweep {
    PayloadSweep::parse(text).unwrap()
}

/// Airframe + pack + payload and the limit, from the vehicle file (not from the engine).
fn limits(file: &VehicleFile, pack: &str) -> (f64, f64) {
    let airframe = file.airframe.as_ref().unwrap();
    let pack_kg = file
        .batteries
        .iter()
        .find(|b| b.name == pack)
        .unwrap()
        .mass_kg
        .unwrap();
    (airframe.mass_kg + pack_kg, airframe.max_takeoff_mass_kg)
}

#[test]
fn sweep_rows_equal_endurance_at_the_same_payload_bit_for_bit() {
    let v = m100();
    let options = windy();
    let curve = payload_sweep(&v, &options, &sweep("0:1.2:0.2")).unwrap();
    assert!(!curve.rows.is_empty());
    for row in &curve.rows {
        let alone = endurance(
            &v,
            &EnduranceOptions {
                battery: Some(row.battery.clone()),
                payload_kg: row.payload_kg,
                ..options.clone()
            },
        )
        .unwrap();
        assert_eq!(alone.battery, row.battery);
        assert_eq!(
            alone.takeoff_mass_kg.to_bits(),
            row.takeoff_mass_kg.to_bits()
        );
        // The whole report, every field, bit for bit.
        let bits = |r: &aloft::engine::EnduranceReport| {
            [
                r.hover_power_w,
                r.hover_endurance_s,
                r.max_endurance_speed_mps,
                r.max_endurance_power_w,
                r.max_endurance_s,
                r.max_range_speed_mps,
                r.max_range_ground_speed_mps,
                r.max_range_power_w,
                r.max_range_m,
            ]
            .map(f64::to_bits)
        };
        assert_eq!(
            bits(&alone.report),
            bits(&row.report),
            "{} at {} kg",
            row.battery,
            row.payload_kg
        );
        // The orbit's answers too (options as well as bits).
        assert!(row.report.orbit_endurance_s.is_some());
        assert_eq!(alone.report, row.report);
    }
    assert_eq!(curve.wind, "5.0 m/s from 30 deg");
}

#[test]
fn every_pack_gets_a_curve_and_hover_endurance_falls_with_payload() {
    let v = m100();
    let curve = payload_sweep(&v, &EnduranceOptions::default(), &sweep("0:1:0.1")).unwrap();
    let names: Vec<&str> = curve.batteries.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, v.file().battery_names());
    assert!(names.contains(&"TB47D") && names.contains(&"TB48D"));
    for pack in &curve.batteries {
        let rows: Vec<_> = curve.rows_of(&pack.name).collect();
        assert!(rows.len() >= 2, "{}", pack.name);
        for w in rows.windows(2) {
            assert!(w[1].payload_kg > w[0].payload_kg);
            assert!(w[1].takeoff_mass_kg > w[0].takeoff_mass_kg);
            assert!(w[1].report.hover_power_w > w[0].report.hover_power_w);
            assert!(w[1].report.hover_endurance_s < w[0].report.hover_endurance_s);
            assert!(w[1].report.max_endurance_s < w[0].report.max_endurance_s);
            assert!(w[1].report.max_range_m < w[0].report.max_range_m);
        }
    }
    // The bigger pack flies longer at the same payload.
    let at = |pack: &str, p: f64| {
        curve
            .rows_of(pack)
            .find(|r| (r.payload_kg - p).abs() < 1e-12)
            .unwrap()
            .report
            .hover_endurance_s
    };
    assert!(at("TB48D", 0.5) > at("TB47D", 0.5));
}

#[test]
fn each_curve_stops_at_the_maximum_takeoff_mass_with_a_note() {
    let v = m100();
    let step = 0.1;
    let curve = payload_sweep(&v, &EnduranceOptions::default(), &sweep("0:2:0.1")).unwrap();
    for pack in &curve.batteries {
        let (empty_kg, max_kg) = limits(v.file(), &pack.name);
        assert!((pack.max_payload_kg - (max_kg - empty_kg)).abs() < 1e-12);
        let last = curve.rows_of(&pack.name).last().unwrap();
        assert!(last.takeoff_mass_kg <= max_kg, "{}", pack.name);
        // The next payload of the sweep would be too heavy, so the curve stops exactly here.
        assert!(empty_kg + last.payload_kg + step > max_kg, "{}", pack.name);
        let note = curve
            .notes
            .iter()
            .find(|n| n.starts_with(&format!("{}:", pack.name)))
            .unwrap_or_else(|| panic!("no note for {}: {:?}", pack.name, curve.notes));
        assert!(
            note.contains(&format!("{:.3} kg", max_kg - empty_kg))
                && note.contains("3.600 kg maximum take-off mass"),
            "{note}"
        );
    }
    // Within every pack's limit (the lightest margin is the 2xTB48D's 0.333 kg): no note.
    let light = payload_sweep(&v, &EnduranceOptions::default(), &sweep("0:0.3:0.1")).unwrap();
    assert!(light.notes.is_empty(), "{:?}", light.notes);
}

#[test]
fn a_pack_too_heavy_for_any_payload_is_noted_and_the_others_still_swept() {
    let text = include_str!("../../fixtures/vehicles/dji-m100.toml");
    assert!(text.contains("mass_kg = 0.676"));
    // A 1.9 kg TB48D: with the 1.755 kg airframe, 3.655 kg before any payload (limit 3.6 kg).
    let heavy = Vehicle::from_toml(
        &text.replace("mass_kg = 0.676", "mass_kg = 1.9"),
        "heavy pack",
    )
    .unwrap();
    let curve = payload_sweep(&heavy, &EnduranceOptions::default(), &sweep("0:0.5:0.25")).unwrap();
    assert_eq!(curve.rows_of("TB48D").count(), 0);
    assert_eq!(curve.rows_of("TB47D").count(), 3);
    assert!(
        curve
            .notes
            .iter()
            .any(|n| n.starts_with("TB48D:") && n.contains("alone exceeds")),
        "{:?}",
        curve.notes
    );
    // That pack alone: nothing at all can be swept, an error naming the limit.
    let only = EnduranceOptions {
        battery: Some("TB48D".into()),
        ..EnduranceOptions::default()
    };
    let e = payload_sweep(&heavy, &only, &sweep("0:0.5:0.25")).unwrap_err();
    assert!(
        e.to_string().contains("3.600 kg maximum take-off mass"),
        "{e}"
    );
}

#[test]
fn every_number_of_a_sweep_is_finite_and_none_is_null() {
    let curve = payload_sweep(&m100(), &windy(), &sweep("0:3:0.05")).unwrap();
    fn walk(v: &serde_json::Value) {
        match v {
            serde_json::Value::Null => panic!("null in the sweep"),
            serde_json::Value::Number(n) => assert!(n.as_f64().unwrap().is_finite()),
            serde_json::Value::Array(a) => a.iter().for_each(walk),
            serde_json::Value::Object(o) => o.values().for_each(walk),
            _ => {}
        }
    }
    walk(&serde_json::to_value(&curve).unwrap());
}

// ---- the command line ----

fn tmp(name: &str) -> std::path::PathBuf {
    common::scratch("payload-sweep", name)
}

/// How many payloads of `0, step, ..., n step` fit with each pack of the M100 (from the file).
fn expected_rows(payloads: &[f64]) -> usize {
    let file = VehicleFile::builtin("dji-m100").unwrap();
    file.battery_names()
        .iter()
        .map(|pack| {
            let (empty_kg, max_kg) = limits(&file, pack);
            payloads.iter().filter(|&&p| empty_kg + p <= max_kg).count()
        })
        .sum()
}

#[test]
fn cli_json_has_the_keys_one_row_per_pack_and_payload_and_equals_the_engine() {
    let v = ok_json(&[
        "endurance",
        "--payload-sweep",
        "0:1.5:0.25",
        "--format",
        "json",
    ]);
    for k in [
        "vehicle",
        "wind",
        "max_takeoff_mass_kg",
        "batteries",
        "rows",
        "notes",
    ] {
        assert!(v.get(k).is_some(), "missing {k}");
    }
    let rows = v["rows"].as_array().unwrap();
    let payloads: Vec<f64> = (0..=6).map(|i| f64::from(i) * 0.25).collect();
    assert_eq!(rows.len(), expected_rows(&payloads));
    for r in rows {
        let own = ["battery", "payload_kg", "takeoff_mass_kg"];
        for k in own.iter().chain(&common::ENDURANCE_KEYS) {
            assert!(r.get(k).is_some(), "row key {k}: {r}");
        }
    }
    // 1.25 and 1.5 kg exceed the limit with every pack: a note each.
    assert_eq!(
        v["notes"].as_array().unwrap().len(),
        v["batteries"].as_array().unwrap().len(),
        "{}",
        v["notes"]
    );
    let engine: PayloadCurve =
        payload_sweep(&m100(), &EnduranceOptions::default(), &sweep("0:1.5:0.25")).unwrap();
    assert_eq!(v, serde_json::to_value(&engine).unwrap());
}

#[test]
fn cli_table_has_a_block_per_pack_with_units_and_the_notes() {
    let out = stdout_of(&["endurance", "--payload-sweep", "0:1.5:0.25"]);
    for needle in [
        "endurance against payload",
        "TB47D: 99.9 Wh",
        "TB48D: 129.96 Wh",
        "best endurance",
        "best range",
        "kg        kg       W     min",
        "note: TB47D: payloads above 1.245 kg exceed the 3.600 kg maximum take-off mass",
    ] {
        assert!(out.contains(needle), "missing '{needle}' in:\n{out}");
    }
    // The first row of the TB47D block: 0 kg payload, 2.355 kg (1.755 + 0.600).
    assert!(out.contains("      0.00     2.355"), "{out}");
}

#[test]
fn cli_csv_is_a_header_and_a_row_per_pack_and_payload() {
    let out = stdout_of(&[
        "endurance",
        "--payload-sweep",
        "0:1:0.5",
        "--battery",
        "TB48D",
        "--format",
        "csv",
    ]);
    let mut lines = out.lines();
    assert!(lines
        .next()
        .unwrap()
        .starts_with("battery,payload_kg,takeoff_mass_kg,hover_power_w,hover_endurance_s,"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 3, "{out}");
    assert!(rows.iter().all(|r| r.starts_with("TB48D,")));
    assert!(rows[2].starts_with("TB48D,1,3.431,"), "{}", rows[2]);
}

#[test]
fn cli_plot_draws_a_curve_per_pack() {
    let svg = tmp("sweep.svg");
    stdout_of(&[
        "endurance",
        "--payload-sweep",
        "0:1.2:0.1",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&svg).unwrap();
    for needle in [
        "<svg",
        "TB47D",
        "TB48D",
        "payload (kg)",
        "hover endurance (min)",
        "best range (km)",
    ] {
        assert!(text.contains(needle), "missing '{needle}' in the chart");
    }
    std::fs::remove_file(&svg).ok();
}

#[test]
fn cli_refuses_bad_sweeps_with_one_line_and_exit_2() {
    let flag = "--payload-sweep";
    // A bad START:STOP:STEP is named, with what is wrong with it.
    for (sweep, why) in [
        ("1:0:0.1", "below START"),
        ("0:1:0", "not positive"),
        ("a:b:c", "not a number"),
        ("0:1:nan", "not a finite"),
        ("0:1e9:1e-9", "more than the 1000"),
        ("50:60:1", "3.600 kg maximum take-off mass"),
    ] {
        assert_refused(&["endurance", flag, sweep], &[flag, sweep, why]);
    }
    assert_refused(&["endurance", flag, "-1:1:0.5"], &[flag, "negative"]);
    assert_refused(&["endurance", flag, "0:1"], &[flag, "START:STOP:STEP"]);
    // An option that does not go with a sweep is named beside it.
    for (option, value) in [
        ("--payload-kg", "1"),
        ("--sweep-speed", "1"),
        ("--samples", "10"),
    ] {
        assert_refused(
            &["endurance", flag, "0:1:0.5", option, value],
            &[flag, option],
        );
    }
    assert_refused(
        &["endurance", "--plot", "x.svg"],
        &["--payload-sweep", "--sweep-speed"],
    );
}
