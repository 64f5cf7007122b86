//! The built-in DJI vehicles against DJI's published hover times.
//!
//! Source of every figure: DJI Mobile SDK documentation, "Hardware Introduction" (2017-03-07),
//! table "Payload & Flight Time" (aircraft, battery, camera and payload masses, take-off mass, max
//! flight time in minutes): developer.dji.com/mobile-sdk/documentation/introduction/
//! product_introduction.html, text in github.com/dji-sdk/Mobile-SDK-Doc,
//! source/introduction/product_introduction.md. Each vehicle is calibrated on ONE figure (the
//! issue's: M100 TB47D 2355 g 22 min, M600 6x TB47S 9100 g 35 min, Inspire 1 TB47 + X3 2935 g
//! 18 min, Inspire 1 Pro TB47 + X5 3396 g 15 min); every other row is a prediction.
//!
//! Hover times are `aloft endurance`'s `hover_endurance_s` (still air, no reserve, flown to the
//! empty point), the camera as payload.

use aloft::engine::{endurance, EnduranceOptions, Vehicle};

/// (vehicle, battery, camera + payload kg, DJI take-off mass kg, DJI minutes, calibration point)
type Row = (&'static str, &'static str, f64, f64, f64, bool);

const DJI_TABLE: [Row; 22] = [
    ("dji-m100", "TB47D", 0.0, 2.355, 22.0, true),
    ("dji-m100", "TB47D", 0.5, 2.855, 17.0, false),
    ("dji-m100", "TB47D", 1.0, 3.355, 13.0, false),
    ("dji-m100", "TB48D", 0.0, 2.431, 28.0, false),
    ("dji-m100", "TB48D", 0.5, 2.931, 20.0, false),
    ("dji-m100", "TB48D", 1.0, 3.431, 16.0, false),
    ("dji-m100", "2xTB47D", 0.0, 3.115, 33.0, false),
    ("dji-m100", "2xTB48D", 0.0, 3.267, 40.0, false),
    ("dji-m100", "TB47D", 0.247, 2.602, 19.0, false),
    ("dji-m100", "TB48D", 0.247, 2.678, 23.0, false),
    ("dji-m100", "2xTB48D", 0.247, 3.514, 33.0, false),
    ("dji-m600", "6xTB47S", 0.0, 9.100, 35.0, true),
    ("dji-m600", "6xTB47S", 6.0, 15.100, 16.0, false),
    ("dji-m600", "6xTB48S", 0.0, 9.610, 40.0, false),
    ("dji-m600", "6xTB48S", 5.5, 15.110, 18.0, false),
    ("dji-inspire1", "TB47", 0.247, 2.935, 18.0, true),
    ("dji-inspire1", "TB48", 0.247, 3.035, 21.0, false),
    ("dji-inspire1", "TB48", 0.270, 3.058, 21.0, false),
    ("dji-inspire1-pro", "TB47", 0.526, 3.396, 15.0, true),
    ("dji-inspire1-pro", "TB48", 0.526, 3.496, 18.0, false),
    ("dji-inspire1-pro", "TB48", 0.583, 3.553, 18.0, false),
    ("dji-inspire1-pro", "TB48", 0.270, 3.240, 20.0, false),
];

/// Model hover minutes and take-off mass for one row.
fn hover(vehicle: &str, battery: &str, payload_kg: f64) -> (f64, f64) {
    let v = Vehicle::builtin(vehicle).unwrap();
    let s = endurance(
        &v,
        &EnduranceOptions {
            battery: Some(battery.to_string()),
            payload_kg,
            ..EnduranceOptions::default()
        },
    )
    .unwrap();
    (s.report.hover_endurance_s / 60.0, s.takeoff_mass_kg)
}

/// Rows where the model and DJI disagree beyond the rounding of the figures, with the band the
/// disagreement is pinned to (fractions). DJI's table is not consistent with any hover power that
/// depends on take-off mass alone, which is what a hover model is:
/// - M100 dual packs: 2x TB47D gives 33 min at 3115 g, i.e. 363 W from 199.8 Wh, while one TB47D
///   with 1 kg gives 13 min at 3355 g, 461 W: 27 % more power for 7.7 % more mass, an exponent of
///   3.2 where momentum theory (and the aircraft's single-pack figures) give about 1.5.
/// - M600 6x TB48S with 5.5 kg: 18 min at 15110 g from 779.8 Wh, while 6x TB47S with 6 kg gives
///   16 min at 15100 g from 599.4 Wh: at the same mass the times differ by 12.5 % and the
///   energies by 30 %.
const KNOWN_DISAGREEMENTS: [(&str, &str, f64, f64, f64); 4] = [
    ("dji-m100", "2xTB47D", 0.0, -0.16, -0.08),
    ("dji-m100", "2xTB48D", 0.0, -0.18, -0.10),
    ("dji-m100", "2xTB48D", 0.247, -0.10, -0.04),
    ("dji-m600", "6xTB48S", 5.5, 0.10, 0.17),
];

/// Each prediction within the rounding of the two figures it rests on (DJI rounds to whole
/// minutes: +/-0.5 min on the predicted row and on the calibration row) plus 1.5 % for the pack
/// model's assumed resistance and open-circuit curve; the calibration rows within the rounding of
/// eta to 4 digits; the known disagreements within their pinned bands.
#[test]
fn paper_val_dji_hover_table() {
    let mut within = 0;
    let mut sum_sq = 0.0;
    for (vehicle, battery, payload, mass, dji, cal) in DJI_TABLE {
        let (model, m) = hover(vehicle, battery, payload);
        let err = model / dji - 1.0;
        println!(
            "| {vehicle} | {battery} | {payload:.3} | {m:.3} | {dji} | {model:.2} | {:+.1} % |{}",
            err * 100.0,
            if cal { " calibration" } else { "" }
        );
        assert!(
            (m - mass).abs() < 5e-4,
            "{vehicle} {battery}: mass {m} vs DJI {mass}"
        );
        if cal {
            assert!(err.abs() < 2e-4, "{vehicle} calibration point: {model} min");
            continue;
        }
        let cal_min = DJI_TABLE
            .iter()
            .find(|r| r.0 == vehicle && r.5)
            .map(|r| r.4)
            .unwrap();
        let known = KNOWN_DISAGREEMENTS
            .iter()
            .find(|k| k.0 == vehicle && k.1 == battery && (k.2 - payload).abs() < 1e-9);
        match known {
            Some(&(_, _, _, lo, hi)) => assert!(
                err > lo && err < hi,
                "{vehicle} {battery} {payload}: {err:+.3} left its pinned band {lo}..{hi}"
            ),
            None => {
                let tol = 0.5 / dji + 0.5 / cal_min + 0.015;
                assert!(
                    err.abs() < tol,
                    "{vehicle} {battery} {payload}: {model:.2} min vs DJI {dji} ({err:+.3}, tolerance {tol:.3})"
                );
                within += 1;
                sum_sq += err * err;
            }
        }
    }
    assert_eq!(within, 14);
    let rms = (sum_sq / f64::from(within)).sqrt();
    println!(
        "RMS of the {within} predictions within rounding: {:.2} %",
        rms * 100.0
    );
    // The Monte-Carlo default model error (3 %) is meant to cover this.
    assert!(rms < 0.03, "{rms}");
}

/// The spec sheet behind a built-in vehicle, calibrated by `aloft vehicles calibrate`'s engine.
fn from_spec(name: &str) -> aloft::vehicle::VehicleFile {
    let path = format!(
        "{}/fixtures/vehicles/specs/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    aloft::engine::calibrate_spec_file(std::path::Path::new(&path))
        .unwrap()
        .vehicle
}

/// The built-in M600 and Inspires carry the power model `aloft vehicles calibrate` makes from
/// their spec sheets (efficiency rounded to 4 digits in the built-in file).
#[test]
fn builtin_m600_is_its_spec_sheet_calibrated() {
    for name in ["dji-m600", "dji-inspire1", "dji-inspire1-pro"] {
        let built = Vehicle::builtin(name)
            .unwrap()
            .file()
            .power
            .clone()
            .unwrap();
        let spec = from_spec(name).power.unwrap();
        assert!(
            (built.efficiency - spec.efficiency).abs() < 5e-5,
            "{name}: {} vs {}",
            built.efficiency,
            spec.efficiency
        );
        let mut spec = spec;
        spec.efficiency = built.efficiency;
        assert_eq!(built, spec, "{name}");
    }
}

/// A spec-sheet M600 (`aloft vehicles calibrate fixtures/vehicles/specs/dji-m600.toml`) predicts
/// the aircraft at other masses as well as the built-in one: DJI's 6 kg figure (16 min at
/// 15100 g) and a payload sweep 0-6 kg agree with the built-in vehicle to 0.2 %.
#[test]
fn spec_sheet_m600_predicts_other_masses_as_the_builtin() {
    let spec = Vehicle::from_file(from_spec("dji-m600")).unwrap();
    let built = Vehicle::builtin("dji-m600").unwrap();
    let at = |v: &Vehicle, payload_kg: f64| {
        endurance(
            v,
            &EnduranceOptions {
                battery: Some("6xTB47S".into()),
                payload_kg,
                ..EnduranceOptions::default()
            },
        )
        .unwrap()
        .report
        .hover_endurance_s
            / 60.0
    };
    let (s6, b6) = (at(&spec, 6.0), at(&built, 6.0));
    println!("6 kg: spec sheet {s6:.2} min, built-in {b6:.2} min, DJI 16 min");
    assert!((s6 / 16.0 - 1.0).abs() < 0.5 / 16.0 + 0.5 / 35.0 + 0.015);
    for k in 0..=12 {
        let p = 0.5 * f64::from(k);
        let (s, b) = (at(&spec, p), at(&built, p));
        assert!((s / b - 1.0).abs() < 2e-3, "{p} kg: {s} vs {b}");
    }
}
