//! `aloft log info`, `convert`, `fit` and `validate` on PX4 ULog and ArduPilot DataFlash logs of
//! the shared data: the output contract, "no battery data" as an answer, and the MCAP written
//! read back by the Python `mcap` reader.

use crate::common;
use common::ok_json;

use std::path::Path;

fn shared(name: &str) -> String {
    common::data_dir()
        .join("flight_logs")
        .join(name)
        .display()
        .to_string()
}

fn info(name: &str) -> serde_json::Value {
    ok_json(&["log", "info", &shared(name), "--format", "json"])
}

#[test]
fn data_val_log_info_json_on_ulog_and_dataflash() {
    let j = info("px4_esc_status_log.ulg");
    assert_eq!(j["format"], "px4_ulog");
    assert_eq!(j["power_available"], true);
    // 13.391 Wh (README, pyulog); 1 %.
    assert!((j["energy_wh"].as_f64().unwrap() - 13.391).abs() < 0.134);
    assert!(j["warnings"].as_array().unwrap().is_empty());
    for key in [
        "samples",
        "duration_s",
        "channels",
        "time",
        "dropped_values",
    ] {
        assert!(j.get(key).is_some(), "{key}");
    }
    assert_eq!(j["log"]["battery_records"], 73);
    let j = info("sitl_ac47_00000002.BIN");
    assert_eq!(j["format"], "ardupilot_dataflash");
    assert!((j["energy_wh"].as_f64().unwrap() - 2.035).abs() < 0.0204);
}

#[test]
fn data_val_no_battery_data_is_an_answer_for_info_and_an_error_for_fit_and_validate() {
    for name in ["beastayyg_sample.bin", "erle_2014-09-07_7.BIN"] {
        let j = info(name);
        assert_eq!(j["power_available"], false, "{name}");
        let w = j["warnings"].as_array().unwrap();
        assert!(
            w.iter()
                .any(|w| w.as_str().unwrap().contains("no battery data")),
            "{name}: {w:?}"
        );
        // A fit skips a log it cannot use (issue 35), and validate decides as fit does (issue
        // 41); with no other it is a failed check (exit 1) that says why, and a fit writes no
        // vehicle.
        let o = common::aloft(&["validate", "--log", &shared(name), "--vehicle", "dji-m100"]);
        assert_eq!(o.status.code(), Some(1), "{name}");
        assert!(common::stdout(&o).contains("no battery data"), "{name}");
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("nobat-fit.toml");
        // A file of an earlier run is kept without --force: start without it.
        let _ = std::fs::remove_file(&out);
        let o = common::aloft(&[
            "fit",
            "--log",
            &shared(name),
            "--vehicle-template",
            "dji-m100",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(1), "{name}");
        let said = common::stdout(&o);
        assert!(said.contains("no battery data"), "{said}");
        assert!(!out.exists());
    }
}

#[test]
fn a_truncated_ulog_gives_its_prefix_and_a_warning_with_the_offset() {
    let bytes = std::fs::read(shared("upgradeenergy_test.ulg")).unwrap();
    let p = Path::new(env!("CARGO_TARGET_TMPDIR")).join("truncated.ulg");
    std::fs::write(&p, &bytes[..bytes.len() * 2 / 3 + 7]).unwrap();
    let j = ok_json(&["log", "info", p.to_str().unwrap(), "--format", "json"]);
    let w = j["warnings"].to_string();
    assert!(w.contains("at byte"), "{w}");
    assert!(j["samples"].as_u64().unwrap() > 100);
}

#[test]
fn data_val_converted_ulog_and_dataflash_open_in_the_python_mcap_reader() {
    for (name, samples) in [
        ("px4_esc_status_log.ulg", 315),
        ("sitl_ac47_00000002.BIN", 405),
    ] {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}.mcap"));
        // A file of an earlier run is kept without --force: start without it.
        let _ = std::fs::remove_file(&out);
        let j = ok_json(&[
            "convert",
            &shared(name),
            "-o",
            out.to_str().unwrap(),
            "--format",
            "json",
        ]);
        assert_eq!(j["samples"], samples);
        if !common::python_has("mcap") {
            assert!(
                std::env::var_os("CI").is_none(),
                "CI is set but python3 has no mcap"
            );
            eprintln!(
                "NOTICE: skipping the Python MCAP check: python3 with `mcap` is not available"
            );
            continue;
        }
        let script = "import sys\nfrom mcap.reader import make_reader\nn = 0\nwith open(sys.argv[1], 'rb') as f:\n    for schema, channel, message in make_reader(f).iter_messages():\n        n += 1\nprint(n)\n";
        let py = common::python_stdout(script, &[out.to_str().unwrap()]);
        let n: u64 = py.trim().parse().unwrap();
        let written: u64 = j["topics"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["messages"].as_u64().unwrap())
            .sum();
        assert_eq!(n, written, "{name}");
    }
}
