//! `aloft plan --confidence` (issue 43, items 1 and 2): sorties cut where the share P of the
//! day's scenarios still lands them with the reserve, checked from outside the plan: each written
//! file flown by `aloft mission` in a fresh draw of scenarios (another seed, the mission's own
//! scenario machinery with its 0.1 s step and its point of no return) and in a grid of winds
//! around the forecast (docs/validation.md, "Plans that hold"); bad values refused.

use crate::common;

use std::path::{Path, PathBuf};

use common::{run, scratch};
use serde_json::Value;

fn survey() -> PathBuf {
    common::data_dir().join("missions/neilvaltec_test.plan")
}

/// `aloft plan FILE -o DIR --format json EXTRA`: exit code and JSON.
fn plan(file: &Path, tag: &str, extra: &[&str]) -> Value {
    let dir = scratch("plan-confidence", tag);
    let _ = std::fs::remove_dir_all(&dir);
    let (f, d) = (file.display().to_string(), dir.display().to_string());
    let mut args = vec![
        "plan",
        f.as_str(),
        "-o",
        d.as_str(),
        "--format",
        "json",
        "--force",
    ];
    args.extend_from_slice(extra);
    let (code, out, err) = run(&args);
    assert_eq!(code, 0, "{args:?}: {err}");
    serde_json::from_str(&out).unwrap()
}

/// `aloft mission FILE --format json EXTRA`.
fn mission(file: &str, extra: &[&str]) -> Value {
    let mut args = vec!["mission", file, "--format", "json"];
    args.extend_from_slice(extra);
    let (code, out, err) = run(&args);
    assert!(matches!(code, 0 | 1), "{args:?}: {err}");
    serde_json::from_str(&out).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The files a plan wrote.
fn files(answer: &Value) -> Vec<&str> {
    common::strs(&answer["files"])
}

/// The forecast of the survey's plans: 8 m/s from 240 deg, a 70 % reserve (several packs of the
/// shared survey, about 5 km).
const FORECAST: [&str; 6] = [
    "--wind-speed",
    "8",
    "--wind-from",
    "240",
    "--reserve-percent",
    "70",
];

/// Cut at the default confidence (0.95 of 400 scenarios, seed 1), each sortie of the shared
/// survey lands with the reserve in at least 95 % of 1000 other scenarios that `aloft mission`
/// draws from its file (seed 7, the plan's spreads: 2 m/s and 25 deg, capacity 3 %, power 3 %),
/// within three standard errors of the share (3 sqrt(0.95 x 0.05 / 1000) = 0.021); the plan
/// said at least 0.95 of its own. Cut for the forecast alone (`--confidence 0.5`), the sorties
/// it cuts hold in about half of them, as the issue measured (p_feasible 0.46).
#[test]
fn data_val_sorties_cut_at_95_percent_hold_in_a_fresh_draw() {
    let sure = plan(&survey(), "sure", &FORECAST);
    let mut nominal_flags = FORECAST.to_vec();
    nominal_flags.extend(["--confidence", "0.5"]);
    let nominal = plan(&survey(), "nominal", &nominal_flags);
    assert_eq!(f(&sure["confidence"]), 0.95);
    assert_eq!(f(&nominal["confidence"]), 0.5);
    let spreads = &sure["scenarios"]["spreads"];
    // The default spreads for an 8 m/s forecast: 25 % of it, 25 deg, 3 % and 3 %.
    assert_eq!(f(&spreads["wind_speed_sd_mps"]), 2.0);
    assert_eq!(f(&spreads["wind_from_sd_deg"]), 25.0);
    assert_eq!(f(&spreads["capacity_sd_percent"]), 3.0);
    assert_eq!(f(&spreads["power_sd_percent"]), 3.0);
    assert_eq!(sure["scenarios"]["samples"], 400);
    let mut draw = FORECAST.to_vec();
    draw.extend([
        "--samples",
        "1000",
        "--seed",
        "7",
        "--wind-speed-sd",
        "2",
        "--wind-from-sd",
        "25",
        "--capacity-sd-percent",
        "3",
        "--power-sd-percent",
        "3",
    ]);
    for (file, sortie) in files(&sure).iter().zip(sure["sorties"].as_array().unwrap()) {
        assert!(f(&sortie["p_reserve"]) >= 0.95, "{sortie}");
        let band = &sortie["landing_soc"];
        assert!(f(&band["p5"]) <= f(&band["p50"]) && f(&band["p50"]) <= f(&band["p95"]));
        let flown = mission(file, &draw);
        let p = f(&flown["uncertainty"]["p_feasible"]);
        eprintln!(
            "{file}: the plan's {} , a fresh draw's {p}",
            sortie["p_reserve"]
        );
        assert!(p >= 0.95 - 0.021, "{file}: {p}");
    }
    let cut: Vec<&Value> = nominal["sorties"].as_array().unwrap().iter().collect();
    assert!(cut.len() >= 2, "{nominal}");
    for (file, sortie) in files(&nominal).iter().zip(&cut[..cut.len() - 1]) {
        let p = f(&mission(file, &draw)["uncertainty"]["p_feasible"]);
        eprintln!(
            "{file} (nominal): the plan's {}, a fresh draw's {p}",
            sortie["p_reserve"]
        );
        assert!((0.2..0.7).contains(&p), "{file}: {p}");
    }
    assert!(f(&sure["batteries"]) >= f(&nominal["batteries"]));
}

/// Each written sortie of `file` (planned for 8 m/s from 240 deg with the reserve `reserve`
/// percent) flown by `aloft mission` in 16 winds around the forecast (6, 8, 10 and 12 m/s from
/// 195, 240, 285 and 60 deg: the grid), for the plan cut at 0.95 and the one cut for the
/// forecast alone: the shares of flights that land with the reserve and that do not land at all
/// (the pack empty, or a wind it cannot make headway in), printed (docs/validation.md, "Plans
/// that hold").
fn grid_of_winds(file: &Path, reserve: &str) -> Vec<(f64, f64)> {
    let mut rows = Vec::new();
    for confidence in ["0.5", "0.95"] {
        let flags = [
            "--wind-speed",
            "8",
            "--wind-from",
            "240",
            "--reserve-percent",
            reserve,
            "--confidence",
            confidence,
        ];
        let answer = plan(file, &format!("grid-{reserve}-{confidence}"), &flags);
        let (mut kept, mut dry, mut flights) = (0, 0, 0);
        for file in files(&answer) {
            for speed in ["6", "8", "10", "12"] {
                for from in ["195", "240", "285", "60"] {
                    let winds = ["--wind-speed", speed, "--wind-from", from];
                    let flown = mission(
                        file,
                        &[&winds[..], &["--reserve-percent", reserve]].concat(),
                    );
                    flights += 1;
                    kept += usize::from(flown["feasible"] == true);
                    let landed = flown["reason"]
                        .as_str()
                        .is_none_or(|r| r.contains("reserve"));
                    dry += usize::from(!landed);
                }
            }
        }
        let p5: Vec<String> = answer["sorties"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| format!("{:.1}", 100.0 * f(&s["landing_soc"]["p5"])))
            .collect();
        eprintln!(
            "{} at {reserve} %, confidence {confidence}: {} packs, {:.1} Wh; reserve kept in \
             {kept} of {flights} flights, {dry} did not land; p5 at landing {} %",
            file.display(),
            answer["batteries"],
            f(&answer["energy_wh"]),
            p5.join(", ")
        );
        rows.push((kept as f64 / flights as f64, dry as f64 / flights as f64));
    }
    rows
}

/// The shared survey at a 70 % reserve in the grid of winds: the plan cut at 0.95 keeps the
/// reserve in more of its flights than the one cut for the forecast alone, and lands in as many.
#[test]
fn data_val_written_sorties_flown_in_a_grid_of_winds() {
    let rows = grid_of_winds(&survey(), "70");
    let (nominal, sure) = (rows[0], rows[1]);
    assert!(sure.0 > nominal.0 && sure.0 >= 0.85, "{rows:?}");
    assert!(sure.1 <= nominal.1, "{rows:?}");
}

/// The same for a survey of the held-out one's size: the shared survey's polygon scaled 2.8
/// times (about 38 km of flight, `common::big_survey`) at a 20 % reserve, where the plan cut
/// for the forecast runs packs dry. Slow in a debug build: `cargo test --release --test it --
/// --ignored plan_confidence::`.
#[test]
#[ignore]
fn data_val_a_38_km_survey_flown_in_a_grid_of_winds() {
    let file = scratch("plan-confidence", "survey-38km.plan");
    std::fs::write(&file, common::big_survey::scaled_survey(&survey(), 2.8)).unwrap();
    let rows = grid_of_winds(&file, "20");
    let (nominal, sure) = (rows[0], rows[1]);
    assert!(sure.0 > nominal.0 && sure.0 >= 0.85, "{rows:?}");
    assert!(sure.1 < nominal.1, "{rows:?}");
}

/// A confidence outside 0.5 to 0.999, a spread out of range and no scenarios are refused (exit
/// 2, one line naming the value); nothing is written.
#[test]
fn bad_confidence_and_spreads_are_refused_naming_them() {
    let dir = scratch("plan-confidence", "refused");
    let d = dir.display().to_string();
    for (flags, name) in [
        (&["--confidence", "0.3"][..], "confidence"),
        (&["--confidence", "1"][..], "confidence"),
        (&["--confidence", "nan"][..], "confidence"),
        (&["--samples", "0"][..], "samples"),
        (&["--wind-from-sd", "200"][..], "wind-from-sd"),
        (&["--wind-speed-sd=-1"][..], "wind-speed-sd"),
        (&["--capacity-sd-percent", "80"][..], "capacity-sd-percent"),
    ] {
        let mut args = vec!["plan", "-o", d.as_str()];
        args.extend_from_slice(flags);
        let (code, out, err) = run(&args);
        assert_eq!(code, 2, "{flags:?}: {out}{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{flags:?}: {err}");
        assert!(
            err.contains(name) || err.contains(&name.replace('-', "_")),
            "{flags:?}: {err}"
        );
        assert!(!dir.exists(), "{flags:?}");
    }
}
