//! `aloft vehicles calibrate`: a vehicle file from a spec sheet, end to end, and bad spec sheets
//! refused with exit 2 and one stderr line naming the key.

use crate::common;
use common::{aloft, ok_json};

use std::path::{Path, PathBuf};
use std::process::Output;

fn scratch(name: &str) -> PathBuf {
    common::scratch("vehicles-cli", name)
}

/// `aloft vehicles calibrate spec -o out`.
fn calibrate(spec: &Path, out: &Path) -> Output {
    aloft(&[
        "vehicles",
        "calibrate",
        spec.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ])
}

const SPEC: &str = r#"
name = "my-quad"
rotors = 4
rotor_diameter_m = 0.33
frame_mass_kg = 2.118

[battery]
cells = 6
capacity_mah = 4500
energy_wh = 99.9
mass_kg = 0.570

[published_hover]
takeoff_mass_kg = 2.935
minutes = 18
"#;

/// The spec sheet of the M600 becomes a vehicle file every command accepts, and its efficiency is
/// the one that hovers 35 min at 9.1 kg.
#[test]
fn calibrate_writes_a_vehicle_every_command_accepts() {
    let spec = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/vehicles/specs/dji-m600.toml"
    );
    let out = scratch("m600.toml");
    let v = ok_json(&[
        "vehicles",
        "calibrate",
        spec,
        "-o",
        out.to_str().unwrap(),
        "--format",
        "json",
    ]);
    let eta = v["efficiency"].as_f64().unwrap();
    assert!((eta - 0.4995).abs() < 1e-4, "{eta}");
    assert!(!v["defaults"].as_array().unwrap().is_empty());
    let e = ok_json(&[
        "endurance",
        "--vehicle",
        out.to_str().unwrap(),
        "--format",
        "json",
    ]);
    let minutes = e["hover_endurance_s"].as_f64().unwrap() / 60.0;
    assert!((minutes - 35.0).abs() < 0.01, "{minutes}");
    let o = aloft(&[
        "power",
        "--vehicle",
        out.to_str().unwrap(),
        "--airspeed",
        "8",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The table of the same calibration, over the file written above (--force).
    let o = aloft(&[
        "vehicles",
        "calibrate",
        spec,
        "-o",
        out.to_str().unwrap(),
        "--force",
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("efficiency 0.499") && text.contains("default: drag"),
        "{text}"
    );
}

/// Each bad spec: exit 2, one stderr line naming the key.
#[test]
fn bad_spec_sheets_are_refused_naming_the_key() {
    let cases: [(&str, &str, &str); 9] = [
        ("rotors = 4", "rotors = 0", "rotors"),
        ("rotors = 4\n", "", "rotors"),
        ("rotors = 4", "rotors = -4", "rotors"),
        (
            "frame_mass_kg = 2.118",
            "frame_mass_kg = -2.118",
            "frame_mass_kg",
        ),
        ("mass_kg = 0.570", "mass_kg = -0.5", "battery.mass_kg"),
        ("minutes = 18", "minutes = 60", "published_hover.minutes"),
        ("minutes = 18", "minutes = nan", "published_hover.minutes"),
        (
            "takeoff_mass_kg = 2.935",
            "takeoff_mass_kg = 2.0",
            "published_hover.takeoff_mass_kg",
        ),
        ("energy_wh = 99.9", "energy_wh = 999", "battery.energy_wh"),
    ];
    for (k, (from, to, key)) in cases.iter().enumerate() {
        assert!(SPEC.contains(from), "{from}");
        let path = scratch(&format!("bad{k}.toml"));
        std::fs::write(&path, SPEC.replacen(from, to, 1)).unwrap();
        let out = scratch(&format!("bad{k}-out.toml"));
        let o = calibrate(&path, &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{to}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{to}: {err}");
        assert!(err.contains(key), "{to}: {err}");
        assert!(!out.exists(), "{to}: wrote a vehicle file");
    }
    // The good one calibrates.
    let path = scratch("good.toml");
    std::fs::write(&path, SPEC).unwrap();
    let out = scratch("good-out.toml");
    let o = calibrate(&path, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// An impossible hover time says how long the pack could hover at efficiency 1.
#[test]
fn impossible_hover_time_says_the_longest_possible() {
    let path = scratch("long.toml");
    std::fs::write(&path, SPEC.replacen("minutes = 18", "minutes = 40", 1)).unwrap();
    let out = scratch("long-out.toml");
    let o = calibrate(&path, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        err.contains("published_hover.minutes") && err.contains("at most 3"),
        "{err}"
    );
}
