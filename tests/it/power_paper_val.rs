//! Checks of the power seed's M100 against published figures. The seed's vehicle at its own mass
//! (m = 3.29 kg, section V) is the built-in `dji-m100-paper`, the power-model-only validation
//! case; `dji-m100` is the same [power] table flown at its take-off mass (airframe + pack +
//! payload).

use aloft::power::{
    calibrate_efficiency, efficiency_from_hover, mean_power_w, FlightState, PowerModel, Terms,
};
use aloft::vehicle::VehicleFile;

/// The paper's M100 at the paper's 3.29 kg.
fn m100() -> aloft::power::Vehicle {
    let v = VehicleFile::builtin("dji-m100-paper")
        .unwrap()
        .power_vehicle()
        .unwrap();
    // The validation case is at the seed's mass, stated here rather than taken on trust.
    assert_eq!(v.mass_kg().to_bits(), 3.29f64.to_bits());
    v
}

/// The vehicle file's efficiency is reproduced from the one DJI figure it is calibrated on: the full
/// model (eqs 7-14) hovers 22 min with the TB47D (99.9 Wh) at 2355 g (1755 g + 600 g, no payload)
/// through the planner's pack model. The file rounds eta to 4 digits: tolerance 5e-5. The seed's
/// own definition (ideal over measured hover power, eq 14 without the profile term) gives 0.8577
/// for DJI's 13 min with 1 kg, lower by the profile share (see the fixture's comment).
#[test]
fn paper_val_m100_efficiency_from_dji_hover_time() {
    let file = VehicleFile::builtin("dji-m100").unwrap();
    let c = aloft::engine::calibrate_hover(&file, Some("TB47D"), 2.355, 22.0).unwrap();
    assert!(
        (c.efficiency - m100().efficiency()).abs() < 5e-5,
        "eta {} vs file {}",
        c.efficiency,
        m100().efficiency()
    );
    let measured = mean_power_w(99.9, 13.0 * 60.0).unwrap();
    let paper = efficiency_from_hover(&m100().with_mass(3.355).unwrap(), measured).unwrap();
    assert!((paper - 0.8577).abs() < 5e-5, "{paper}");
    // The same figure through the rated energy instead of the pack model
    // (`calibrate_efficiency`, mean power 99.9 Wh / 22 min): within 3 % of the file's value (the
    // pack model's open-circuit energy and resistive loss differ from the rated 99.9 Wh).
    let hover = FlightState::new(0.0, 0.0, 0.0, 0.0);
    let rated = calibrate_efficiency(
        &PowerModel::new(m100().with_mass(2.355).unwrap()),
        &hover,
        mean_power_w(99.9, 22.0 * 60.0).unwrap(),
    )
    .unwrap();
    assert!((rated / m100().efficiency() - 1.0).abs() < 0.03, "{rated}");
}

/// Eq (10) with the paper's constants (m = 3.29 kg, r = 0.172 m, one disk, rho = 1.225):
/// vh = sqrt(3.29 * 9.8066 / (2 * 1.225 * pi * 0.172^2)) = 11.9034 m/s, computed by hand.
#[test]
fn paper_val_eq10_hover_induced_velocity_of_the_m100() {
    let vh = m100().hover_induced_velocity_mps();
    assert!((vh - 11.9034).abs() < 1e-4, "{vh}");
}

/// The ablation of Table I, in the model's own terms: at hover the induced term dominates (its
/// removal is the paper's largest error, 80.7 %), parasitic power vanishes, and climb power is
/// zero in level flight; the profile share is kappa1 T^1.5 / (T vh + kappa1 T^1.5).
#[test]
fn paper_val_table1_term_shares_at_hover_and_8_mps() {
    let model = PowerModel::new(m100());
    let hover = model
        .evaluate(&FlightState::new(0.0, 0.0, 0.0, 0.0))
        .unwrap();
    assert!(hover.induced_w / hover.aero_w > 0.85);
    assert_eq!(hover.parasitic_w, 0.0);
    // At 8 m/s (pitch for steady flight: tan(theta) = f_D / (m g), about -6 deg) parasitic power
    // grows but induced power still dominates, as the paper reports.
    let w = m100().weight_n();
    let drag = m100().drag().force_n(8.0);
    let pitch = -(drag / w).atan();
    let fast = model
        .evaluate(&FlightState::new(8.0, 0.0, pitch, 0.0))
        .unwrap();
    assert!(fast.parasitic_w > 10.0 && fast.induced_w > 5.0 * fast.parasitic_w);
    let no_ind = PowerModel::with_options(
        m100(),
        aloft::power::ModelOptions {
            terms: Terms::ALL.without(aloft::power::Term::Induced),
            profile_cutoff_mps: None,
        },
    )
    .unwrap();
    let p = no_ind
        .evaluate(&FlightState::new(8.0, 0.0, pitch, 0.0))
        .unwrap();
    assert_eq!(p.induced_w, 0.0);
    assert!((fast.aero_w - p.aero_w - fast.induced_w).abs() < 1e-9);
}
