//! Replay of real flights from their trajectory alone (issue 5): fit the power model on the
//! KAIST 2018-08-03 flights, then predict the energy of each 2018-08-06 flight from its velocities
//! alone (`aloft mission --replay`, no power data) and compare with the measured V x I energy.
//!
//! Data from `ALOFT_DATA_DIR` (default `../shared/data` from the workspace root).

mod common;
use common::files_like;

use std::path::PathBuf;
use std::process::Command;

use aloft::identify::{align_flight, force_samples, AlignOptions};
use aloft::power::fit::FitParameter;
use aloft::power::{fit_drag, fit_power_model, FitOptions};
use aloft::vehicle::VehicleFile;

/// The KAIST flights `<prefix>*.csv`.
fn kaist(prefix: &str) -> Vec<PathBuf> {
    files_like("kaist_energy_drone", prefix, ".csv")
}

/// The fitted vehicle file (TOML text) from the 2018-08-03 flights: drag from the force balance
/// (as `aloft fit` does: with the geometric angle of attack power does not identify drag), then
/// the power constants that the known-geometry fit frees, less the profile constant and the drag.
fn fit_on_08_03() -> String {
    let profile = aloft_logs::Profile::resolve("kaist").unwrap();
    let template_path = format!(
        "{}/fixtures/vehicles/kaist-template.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let template_text = std::fs::read_to_string(&template_path).unwrap();
    let mut template = VehicleFile::from_toml_str(&template_text, &template_path).unwrap();
    let mut vehicle = template.power_vehicle().unwrap();
    let mut samples = Vec::new();
    let mut forces = Vec::new();
    for path in kaist("2018-08-03") {
        let log = aloft_logs::read_log(&path, Some(&profile), &Default::default()).unwrap();
        let flight = align_flight(&log, &AlignOptions::default()).unwrap();
        println!(
            "fit flight {}: lag {:.2} s, {} samples",
            path.file_name().unwrap().to_str().unwrap(),
            flight.lag_s,
            flight.samples.len()
        );
        samples.extend_from_slice(&flight.samples);
        forces.extend(force_samples(&log));
    }
    let drag = fit_drag(vehicle.mass_kg(), vehicle.gravity_mps2(), &forces, 1.0, 5.0).unwrap();
    let mut p = vehicle.params().clone();
    [p.mu1_n_s_per_m, p.mu2_n_s2_per_m2, p.mu3_n_s3_per_m3] = drag.mu_n;
    vehicle = aloft::power::Vehicle::new(p).unwrap();
    let options = FitOptions::known_geometry()
        .without(FitParameter::Profile)
        .without(FitParameter::Mu1)
        .without(FitParameter::Mu2)
        .without(FitParameter::Mu3);
    let fit = fit_power_model(&vehicle, &samples, &options).unwrap();
    println!(
        "fit: {} samples, RMSE {:.1} W, NRMSE {:.2} %, eta {:.4}, drag mu = {:?}",
        fit.samples_used,
        fit.rmse_w,
        100.0 * fit.nrmse,
        fit.vehicle.efficiency,
        drag.mu_n
    );
    template.name = "kaist-fitted-replay".into();
    template.power = Some(fit.vehicle);
    toml::to_string(&template).unwrap()
}

/// Issue 5 target: each validation flight replayed from its trajectory alone is within 5 % of
/// the measured energy.
#[test]
fn data_val_kaist_replay_from_trajectory() {
    let fitted = fit_on_08_03();
    let vehicle_path =
        std::env::temp_dir().join(format!("aloft-replay-kaist-{}.toml", std::process::id()));
    std::fs::write(&vehicle_path, fitted).unwrap();
    let mut worst: f64 = 0.0;
    let mut lines = Vec::new();
    for path in kaist("2018-08-06") {
        let out = Command::new(env!("CARGO_BIN_EXE_aloft"))
            .args(["mission", "--replay"])
            .arg(&path)
            .args(["--profile", "kaist", "--vehicle"])
            .arg(&vehicle_path)
            .args(["--format", "json"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "replay of {}: {}",
            path.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        for key in [
            "file",
            "duration_s",
            "predicted_energy_wh",
            "measured_energy_wh",
            "energy_error_percent",
            "lag_s",
        ] {
            assert!(!v[key].is_null(), "missing {key}");
        }
        let e = v["energy_error_percent"].as_f64().unwrap();
        let line = format!(
            "replay {}: {:.0} s, lag {:.2} s, predicted {:.1} Wh, measured {:.1} Wh, error {:+.2} %",
            path.file_name().unwrap().to_str().unwrap(),
            v["duration_s"].as_f64().unwrap(),
            v["lag_s"].as_f64().unwrap(),
            v["predicted_energy_wh"].as_f64().unwrap(),
            v["measured_energy_wh"].as_f64().unwrap(),
            e
        );
        println!("{line}");
        lines.push(line);
        worst = worst.max(e.abs());
    }
    std::fs::remove_file(&vehicle_path).ok();
    assert_eq!(lines.len(), 5);
    assert!(
        worst <= 5.0,
        "worst replay energy error {worst:.2} % > 5 %:\n{}",
        lines.join("\n")
    );
}
