//! `aloft fit` says how good a fit is and goes on past a log it cannot use (issue 35 item 2), on
//! the shared logs: a KAIST flight fits within the power seed's accuracy (good); the five PX4
//! flugdrohne logs, one without a usable velocity, finish with that log skipped by name and the
//! misaligned one (-2.6 s, correlation 0.28) named in a poor verdict; a vehicle flown only slowly
//! is told its drag is extrapolated; no usable log at all is exit 1.

use crate::common;

use common::{data_dir, run, scratch};
use serde_json::Value;

fn fit(logs: &[std::path::PathBuf], template: &str, tag: &str) -> (i32, Value, String) {
    let out = scratch("fit-quality", &format!("{tag}.toml"));
    let logs: Vec<String> = logs.iter().map(|l| l.display().to_string()).collect();
    common::fit_json(&logs, &["--vehicle-template", template], &out)
}

fn template(name: &str) -> String {
    format!("{}/fixtures/vehicles/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn flugdrohne() -> Vec<std::path::PathBuf> {
    common::files("px4_flugdrohne/ulg", |n| n.ends_with(".ulg"))
}

/// The fit's `quality_reasons`.
fn reasons(v: &Value) -> Vec<&str> {
    common::strs(&v["quality_reasons"])
}

#[test]
fn data_val_a_kaist_flight_fits_good() {
    let log = data_dir().join("kaist_energy_drone/2018-08-03.10_31_21random5-1.csv");
    let (code, v, err) = fit(&[log], &template("kaist-template.toml"), "kaist");
    assert_eq!(code, 0, "{err}");
    assert_eq!(v["quality"], "good", "{:?}", reasons(&v));
    assert!(v["power"]["nrmse"].as_f64().unwrap() <= 0.10);
    assert!(v["skipped_logs"].as_array().unwrap().is_empty());
}

#[test]
fn data_val_the_flugdrohne_logs_fit_past_the_unusable_one_and_say_why_it_is_poor() {
    let logs = flugdrohne();
    assert_eq!(logs.len(), 5);
    let (code, v, err) = fit(&logs, &template("px4-template.toml"), "flugdrohne");
    assert_eq!(code, 0, "{err}");
    let skipped = v["skipped_logs"].as_array().unwrap();
    assert_eq!(skipped.len(), 1, "{skipped:?}");
    assert!(skipped[0]["file"]
        .as_str()
        .unwrap()
        .ends_with("log_65_2023-6-21-08-36-08.ulg"));
    assert!(!skipped[0]["reason"].as_str().unwrap().is_empty());
    assert!(err.contains("skipped log_65"), "{err}");
    assert_eq!(v["logs"].as_array().unwrap().len(), 4);
    assert_eq!(v["quality"], "poor");
    let r = reasons(&v);
    assert!(
        r.iter()
            .any(|x| x.starts_with("log_30") && x.contains("correlation 0.28")),
        "{r:?}"
    );
    assert!(
        r.iter()
            .any(|x| x.starts_with("log_30") && x.contains("leads motion")),
        "{r:?}"
    );
    assert!(r.iter().any(|x| x.starts_with("NRMSE 33.8 %")), "{r:?}");
}

/// The flugdrohne flights are flown below 5 m/s: a vehicle whose envelope goes to 20 m/s (the
/// log's own PX4 MPC_XY_VEL_MAX, `log_66_..._params.csv`) is told its drag is extrapolated.
#[test]
fn data_val_a_fit_from_slow_flights_says_its_drag_is_extrapolated() {
    let dir = scratch("fit-quality", "template");
    let vehicle = dir.with_extension("toml");
    std::fs::write(&vehicle, aloft::engine::VEHICLE_TEMPLATE).unwrap();
    let log = data_dir().join("px4_flugdrohne/ulg/log_66_2023-6-21-08-44-02.ulg");
    let (code, v, err) = fit(&[log], vehicle.to_str().unwrap(), "slow");
    assert_eq!(code, 0, "{err}");
    assert_ne!(v["quality"], "good");
    let r = reasons(&v);
    assert!(
        r.iter()
            .any(|x| x.starts_with("drag fitted up to") && x.contains("used up to 20.0 m/s")),
        "{r:?}"
    );
}

#[test]
fn data_val_no_usable_log_is_exit_1_saying_why() {
    let log = data_dir().join("px4_flugdrohne/ulg/log_65_2023-6-21-08-36-08.ulg");
    let out = scratch("fit-quality", "none.toml");
    let (code, stdout, _) = run(&[
        "fit",
        "--log",
        log.to_str().unwrap(),
        "--vehicle-template",
        &template("px4-template.toml"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{stdout}");
    assert!(stdout.starts_with("NO FIT: no log can be used"), "{stdout}");
    assert!(!out.exists(), "a vehicle was written");
}

/// Issue 41 item 5: a failed fit's JSON said `"quality": null`; a fit that did not happen has
/// no verdict key, and nothing in its JSON is `null`.
#[test]
fn data_val_a_failed_fit_has_no_null_in_its_json() {
    let log = data_dir().join("px4_flugdrohne/ulg/log_65_2023-6-21-08-36-08.ulg");
    let (code, v, err) = fit(&[log], &template("px4-template.toml"), "none-json");
    assert_eq!(code, 1, "{err}");
    assert!(v.is_object(), "not a JSON answer: {err}");
    assert!(common::nulls(&v).is_empty(), "{v}");
    assert!(v.get("quality").is_none_or(Value::is_string), "{v}");
    assert!(v["reason"].as_str().unwrap().contains("log_65"), "{v}");
}
