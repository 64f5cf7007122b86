//! Published-figure checks of the planner: DJI's hover times for the Matrice 100.
//!
//! DJI publishes hover times for the M100 (product specification): TB47D (99.9 Wh, 600 g) 22 min
//! without payload, 17 min with 500 g, 13 min with 1 kg; TB48D (129.96 Wh, 676 g) 28 / 20 / 16 min.
//! The airframe is 1755 g without battery. The vehicle file's efficiency (0.9703) was calibrated
//! on the TB47D 1 kg case so that the full model reproduces the measured hover power
//! (`aloft_power::calibrate_efficiency`), so that case is circular; the other five are independent
//! checks of the model's mass scaling through the planner's pack model.

use aloft::power::ModelOptions;
use aloft::vehicle::VehicleFile;
use aloft_planner::{endurance_at_power_s, AoaModel};

/// (battery, payload kg, DJI hover time min)
const DJI_HOVER: [(&str, f64, f64); 6] = [
    ("TB47D", 0.0, 22.0),
    ("TB47D", 0.5, 17.0),
    ("TB47D", 1.0, 13.0),
    ("TB48D", 0.0, 28.0),
    ("TB48D", 0.5, 20.0),
    ("TB48D", 1.0, 16.0),
];

fn hover_minutes(battery: &str, payload_kg: f64, options: ModelOptions) -> (f64, f64) {
    let f = VehicleFile::builtin("dji-m100").unwrap();
    let (aircraft, _) = f.aircraft(options).unwrap();
    let b = f.battery(Some(battery)).unwrap();
    let m = aircraft.airframe().mass_kg() + b.mass_kg() + payload_kg;
    let p = aircraft.at_mass(m, AoaModel::Geometric).unwrap();
    let hover_w = p.level_power_w([0.0, 0.0], [0.0, 1.0]).unwrap();
    // Flown to the empty point (no reserve): DJI's figures are times to the end of the pack.
    (
        endurance_at_power_s(&b, hover_w, 1.0, b.empty_soc()) / 60.0,
        hover_w,
    )
}

/// DJI's six hover times with the full model, through the planner's pack model (open-circuit
/// curve, 0.048/0.038 ohm).
///
/// Tolerance 7 %, set from the known uncertainties before comparing: the calibration's own spread
/// over DJI's four main cases (+/-2 %, fixture comment), the pack model's energy against the rated
/// energy (+4.3 % open-circuit energy, -2 to -5 % resistive loss at 13-25 A with an assumed
/// resistance) and DJI's rounding to whole minutes (up to 4 % at 13 min).
#[test]
fn paper_val_m100_hover_times_match_dji_with_eta_as_calibrated() {
    let calibrated = ModelOptions::default();
    for (battery, payload, dji_min) in DJI_HOVER {
        let (model_min, _) = hover_minutes(battery, payload, calibrated);
        let err = model_min / dji_min - 1.0;
        println!(
            "{battery} + {payload} kg: model {model_min:.2} min, DJI {dji_min} min ({:+.1} %)",
            err * 100.0
        );
        assert!(
            err.abs() < 0.07,
            "{battery} {payload}: {model_min:.2} vs {dji_min}"
        );
    }
    // The stated check of the issue: TB47D, no payload, against 22 min.
    let (m, _) = hover_minutes("TB47D", 0.0, calibrated);
    assert!((m / 22.0 - 1.0).abs() < 0.07, "{m}");
}
