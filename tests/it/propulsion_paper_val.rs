//! Checks of aloft-propulsion against figures published in the seeds
//! (`../shared/seeds/propulsion-system-design.txt`, `rotor-transient-response.txt`), plus the
//! typed errors for bad input.

use crate::common;

use aloft::vehicle::VehicleFile;
use aloft_propulsion::battery::{Battery, BatteryConstants, InternalResistance};
use aloft_propulsion::motor::{kt_oz_in_per_a, KV_KT_HOBBY};
use aloft_propulsion::propeller::{self, Propeller};
use aloft_propulsion::transient::{motor_inertia_kgm2, prop_inertia_kgm2, EQ9_TO_KGM2};
use aloft_propulsion::{
    mass_range_kg, rotor_step_response, EscProtocol, PropulsionError, PropulsionSpec,
    PropulsionSystem, RotorSpec,
};
use proptest::prelude::*;

const LB_KG: f64 = 0.453_592_37;

/// `fixtures/vehicles/aec-quadrotor.toml`, as compiled into the binary.
fn aec_text() -> &'static str {
    aloft::vehicle::BUILTIN_VEHICLES
        .iter()
        .find(|b| b.name == "aec-quadrotor")
        .expect("aec-quadrotor is built in")
        .toml
}

fn aec_spec() -> PropulsionSpec {
    let file = VehicleFile::builtin("aec-quadrotor").expect("aec-quadrotor.toml parses");
    assert!(file.power.is_none(), "aec-quadrotor has no [power] table");
    file.propulsion
        .expect("aec-quadrotor has a [propulsion] table")
}

fn aec() -> PropulsionSystem {
    aec_spec().into_model().expect("aec-quadrotor is valid")
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Seed "Mission Planning", Fig. 13 worked example: 10 lb payload (26.5 lb take-off) needs
/// "nearly 3 kW", "505 W dissipated as heat, a 42.5 A current draw, and over 9 min of flight".
/// Tolerances are those of issue 3: 10 % on power and current (the seed reads them off a chart
/// and says "nearly"), 15 % on heat (a difference of two chart curves), 9-10.5 min.
/// Independence: R_b and C_e in the fixture are derived from this same statement (see the TOML),
/// so heat and time test the chain's consistency; power and current are predicted from the
/// propeller, motor and the 11 % installed loss alone.
#[test]
fn paper_val_worked_example_aec_quadrotor() {
    let h = aec().hover_with_payload(10.0 * LB_KG).unwrap();
    eprintln!("worked example: {h:#?}");
    assert!(rel(h.takeoff_mass_kg, 26.5 * LB_KG) < 1e-4);
    assert!(
        rel(h.power_required_w, 3000.0) <= 0.10,
        "power {} W",
        h.power_required_w
    );
    assert!(
        rel(h.pack_current_a, 42.5) <= 0.10,
        "current {} A",
        h.pack_current_a
    );
    assert!(
        rel(h.battery_heat_w, 505.0) <= 0.15,
        "heat {} W",
        h.battery_heat_w
    );
    assert!(
        (9.0..=10.5).contains(&h.flight_time_min),
        "flight time {} min",
        h.flight_time_min
    );
    // The motor must stay inside its 55 A rating (seed: pack capacity "exceeding the 55 A maximum
    // rating of the motor").
    assert!(h.motor_current_a < 55.0);
    // JSON contract keys.
    let json = serde_json::to_value(h).unwrap();
    for key in common::HOVER_KEYS {
        assert!(json.get(key).and_then(|v| v.as_f64()).is_some(), "{key}");
    }
}

/// Seed S2 ("Modeling Core Loss"): between 16.5 and 26.5 lb the motor runs at 50-70 % of its
/// 10,500 rpm no-load speed (thrust stand). The fixture's C_T is taken from the 70 % end, so the
/// check here is the light end and the flight (installed-loss) speeds: the model must stay
/// inside 45-80 % over the whole range. The 45 % floor is 5 points under the seed's 50 %
/// because the seed's two ends are not consistent with thrust ~ speed^2 (the light end maps to
/// 63 % on the stand; see the fixture); the 80 % ceiling allows the installed loss (+6 % speed).
#[test]
fn paper_val_operating_speed_range() {
    let s = aec();
    for lb in [16.5, 21.5, 26.5] {
        let h = s.hover_at_takeoff_mass(lb * LB_KG).unwrap();
        let frac = h.rotor_speed_rpm / 10_500.0;
        assert!((0.45..=0.80).contains(&frac), "{lb} lb -> {frac}");
    }
}

/// Seed Fig. 13: power required and battery current rise, and flight duration falls, with
/// take-off weight; the heat in the packs rises faster than the power (Fig. 12: "at greater loads
/// ... the internal resistance of the battery plays an increasing factor").
#[test]
fn paper_val_fig13_trends() {
    let s = aec();
    let masses = mass_range_kg(7.0, 13.0, 0.5).unwrap();
    let pts: Vec<_> = s
        .sweep_takeoff_mass(&masses)
        .into_iter()
        .map(|r| r.unwrap())
        .collect();
    assert_eq!(pts.len(), 13);
    for w in pts.windows(2) {
        assert!(w[1].power_required_w > w[0].power_required_w);
        assert!(w[1].pack_current_a > w[0].pack_current_a);
        assert!(w[1].flight_time_min < w[0].flight_time_min);
        assert!(
            w[1].battery_heat_w / w[1].power_drawn_w > w[0].battery_heat_w / w[0].power_drawn_w
        );
    }
}

/// Eq (4): K_v K_t = 1352 (rpm/V x oz in/A); rounding of the printed constant: 0.05 %.
#[test]
fn paper_val_eq4_kv_kt() {
    for kv in [515.0, 775.0, 2300.0] {
        assert!(rel(kv * kt_oz_in_per_a(kv), KV_KT_HOBBY) < 5e-4);
    }
}

/// Eqs (21)-(22) vs the propeller-table convention: the same thrust and torque either way.
#[test]
fn paper_val_eq21_22_conventions() {
    let p = Propeller::new(14.0 * 0.0254, 0.10026, 0.03914).unwrap();
    let (rho, rpm) = (1.225, 7350.0);
    let omega = propeller::rpm_to_radps(rpm);
    let r: f64 = 7.0 * 0.0254;
    let t = propeller::ct_prop_to_rotor(0.10026)
        * rho
        * std::f64::consts::PI
        * r.powi(4)
        * omega.powi(2);
    let q = propeller::cp_prop_to_cq_rotor(0.03914)
        * rho
        * std::f64::consts::PI
        * r.powi(5)
        * omega.powi(2);
    // identities: rounding only
    assert!(rel(t, p.thrust_n(rpm, rho)) < 1e-12);
    assert!(rel(q, p.torque_nm(rpm, rho)) < 1e-12);
}

/// Transient seed Table 2 motors (mass g, diameter mm): eq (9) in the documented unit reading
/// (result in g m^2, x 1e-3 for kg m^2) must lie under the thin-ring bound m (d/2)^2 (no rotating
/// part is outside the case) and above 20 % of it (an outrunner's bell and magnets are a third
/// to a half of its mass, near the case). The literal SI reading is > 100 x the bound.
#[test]
fn paper_val_eq9_thin_ring_bound() {
    for (m_g, d_mm) in [
        (16.4, 24.7),
        (16.6, 24.7),
        (46.9, 33.9),
        (18.0, 23.0),
        (80.0, 37.7),
    ] {
        let (m, d): (f64, f64) = (m_g * 1e-3, d_mm * 1e-3);
        let ring = m * (d / 2.0).powi(2);
        let j = motor_inertia_kgm2(m, d).unwrap();
        assert!(j < ring && j > 0.2 * ring, "{m_g} g: J {j} ring {ring}");
        assert!(j / EQ9_TO_KGM2 > 100.0 * ring);
    }
}

/// Eq (10) is SI as printed: every Table 1 propeller's inertia is positive and under the
/// all-mass-at-the-tips bound m (d/2)^2.
#[test]
fn paper_val_eq10_prop_inertia_bounds() {
    for (m_g, d_in) in [
        (14.0, 12.0),
        (14.1, 13.0),
        (15.0, 14.0),
        (1.86, 6.0),
        (3.0, 6.0),
        (3.56, 6.0),
        (6.6, 7.0),
        (3.38, 5.1),
        (1.45, 4.0),
    ] {
        let (m, d): (f64, f64) = (m_g * 1e-3, d_in * 0.0254);
        let j = prop_inertia_kgm2(m, d).unwrap();
        assert!(
            j > 0.0 && j < m * (d / 2.0).powi(2),
            "{m_g} g {d_in} in: {j}"
        );
    }
}

/// The MN1806 + T-Motor 6x2 rotor of the transient seed. Inputs and where they come from:
/// * Kv 2300 rpm/V, 18 g, 23 mm: transient seed Table 2; prop 1.86 g, 6 in: Table 1.
/// * R 0.117 ohm, I0 0.4 A: not printed in the seed and the MN1806 is not in the catalogues; the
///   closest catalogue motor is used as a proxy, fastuav_catalogues/Motors_Data.csv line 99,
///   KDEDirect KDE1806XF-2350 (same 1806 size, 2350 rpm/V, 18 g).
/// * 11.1 V (3S nominal): not printed; the seed's Fig. 4 reaches 1900 rad/s, which a 2S pack
///   cannot (2300 x 7.4 V = 1782 rad/s no-load), so 3S.
/// * c = 1.46e-8 N m s^2: not printed (the seed fits eq 1 to its own stand data). From the UIUC
///   static table of the nearest low-pitch 2-blade propeller, uiuc_propdb/volume-1/data/
///   da4002_5x1.58_static_1137ga.txt line 18 (9943 rpm, C_P 0.0351; pitch/diameter 0.32 vs 0.33),
///   scaled to 6 in: c = C_P rho D^5 / (8 pi^3) = 0.0351 x 1.225 x 0.1524^5 / 248.05.
/// * protocol dshot300 (delay from Table 4).
///
/// Steps: three equal speed increments ending at the top of the seed's Fig. 4 range
/// (550 -> 1000 -> 1450 -> 1900 rad/s). The 2 % settling time must fall in 65-150 ms (issue 3;
/// Table 4 reports 98-114 ms across protocols).
#[test]
fn paper_val_mn1806_settling_time() {
    let c = 0.0351 * 1.225 * (6.0f64 * 0.0254).powi(5) / (8.0 * std::f64::consts::PI.powi(3));
    // The built-in rotor file holds these values: the same decimals read exactly, and c to the
    // rounding of its 17 digits.
    let mn1806: RotorSpec =
        toml::from_str(include_str!("../../fixtures/rotors/mn1806-6x2.toml")).unwrap();
    assert!((mn1806.torque_coefficient_nms2 - c).abs() <= 1e-15 * c);
    let want = (2300.0, 0.117, 0.4, 11.1, 18.0, 23.0, 1.86, 6.0);
    let got = (
        mn1806.motor_kv_rpm_per_v,
        mn1806.motor_resistance_ohm,
        mn1806.no_load_current_a,
        mn1806.voltage_v,
        mn1806.motor_mass_g,
        mn1806.motor_diameter_mm,
        mn1806.prop_mass_g,
        mn1806.prop_diameter_in,
    );
    assert_eq!(got, want);
    assert_eq!(mn1806.protocol, Some(EscProtocol::Dshot300));
    for (from, to) in [(550.0, 1000.0), (1000.0, 1450.0), (1450.0, 1900.0)] {
        let spec = RotorSpec {
            step_from_radps: Some(from),
            step_to_radps: Some(to),
            ..mn1806.clone()
        };
        let r = rotor_step_response(&spec).unwrap();
        eprintln!(
            "MN1806 {from}->{to} rad/s: settling {:.1} ms, rise {:.1} ms, tau7 {:.1} ms, tau_lin {:.1} ms, J_m {:.3e}, J_p {:.3e}, I {:.2} A",
            r.settling_time_s * 1e3,
            r.rise_time_s * 1e3,
            r.time_constant_s * 1e3,
            r.linearised_time_constant_s * 1e3,
            r.motor_inertia_kgm2,
            r.prop_inertia_kgm2,
            r.steady_current_a
        );
        assert!(
            (0.065..=0.150).contains(&r.settling_time_s),
            "{from}->{to}: {} s",
            r.settling_time_s
        );
        // The simulation's rise time lies between the linearised and eq (7) predictions'
        // 2.2 tau (eq 8 uses ln 9 ~ 2.2 for 10-90 %): the load stiffens with speed.
        assert!(r.rise_time_s <= r.rise_time_eq8_s * 1.0001);
    }
}

// ---------------------------------------------------------------- bad input

fn spec_with(table: &str, key: &str, value: &str) -> Result<PropulsionSystem, String> {
    let text = aec_text();
    let mut out = String::new();
    let mut current = String::new();
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            current = t.trim_matches(['[', ']']).to_string();
        }
        if current == table && t.starts_with(&format!("{key} ")) {
            out.push_str(&format!("{key} = {value}\n"));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    // Parse without the facade's validation, so the propulsion model's own error is what we see.
    let file: VehicleFile = toml::from_str(&out).map_err(|e| e.to_string())?;
    file.propulsion
        .ok_or("no [propulsion] table")?
        .into_model()
        .map_err(|e| e.to_string())
}

#[test]
fn bad_kv_mass_voltage_are_typed_errors() {
    for v in ["0.0", "-515.0", "nan"] {
        let e = spec_with("propulsion.motor", "kv_rpm_per_v", v).unwrap_err();
        assert!(e.contains("Kv") && e.contains("rpm/V"), "{e}");
    }
    let e = spec_with("propulsion", "empty_mass_kg", "-1.0").unwrap_err();
    assert!(e.contains("empty_mass_kg") && e.contains("kg"), "{e}");
    let e = spec_with("propulsion.battery", "full_charge_cell_v", "0.0").unwrap_err();
    assert!(e.contains(" V"), "{e}");
    let e = spec_with("propulsion.propeller", "diameter_in", "-14.0").unwrap_err();
    assert!(e.contains("diameter_in"), "{e}");
    // unknown keys are rejected
    let e = spec_with("propulsion.motor", "kv_rpm_per_v", "515.0\nkv = 3").unwrap_err();
    assert!(e.contains("unknown field"), "{e}");
    // direct constructors
    assert!(matches!(
        aec().hover_with_payload(f64::NAN),
        Err(PropulsionError::InvalidMass { .. })
    ));
}

#[test]
fn thrust_beyond_motor_current_limit_is_a_typed_error() {
    // 20 kg on four 55 A motors
    match aec().hover_at_takeoff_mass(20.0) {
        Err(PropulsionError::CurrentLimitExceeded {
            current_a, limit_a, ..
        }) => assert!(current_a > limit_a),
        other => panic!("expected CurrentLimitExceeded, got {other:?}"),
    }
}

#[test]
fn power_the_pack_cannot_deliver_is_a_typed_error() {
    let b = aec().battery;
    // V_f^2 / (4 R_b) = 20.5^2 / (4 x 0.0699) = 1503 W
    match b.current_for_power_a(1600.0) {
        Err(PropulsionError::PowerExceedsPack { max_power_w, .. }) => {
            assert!(rel(max_power_w, 20.5 * 20.5 / (4.0 * 0.0699)) < 1e-12)
        }
        other => panic!("expected PowerExceedsPack, got {other:?}"),
    }
    // A pack shared by four motors hits that wall at the worked example (4 x ~740 W).
    let mut spec = aec_spec();
    spec.packs_count = 1;
    assert!(matches!(
        spec.into_model().unwrap().hover_with_payload(4.536),
        Err(PropulsionError::PowerExceedsPack { .. })
    ));
}

proptest! {
    /// Eqs (29)-(30): the pack current delivers the asked power and the energy balance closes.
    #[test]
    fn pack_current_delivers_power(p in 0.0f64..1500.0, r in 0.01f64..0.2) {
        let b = Battery::new(BatteryConstants {
            cells_series: 5,
            cells_parallel: 4,
            capacity_ah: 8.0,
            effective_capacity: 0.9,
            full_cell_v: 4.1,
            nominal_cell_v: 3.7,
            resistance: InternalResistance::Constant { resistance_ohm: r },
            max_current_a: f64::INFINITY,
        }).unwrap();
        match b.current_for_power_a(p) {
            Ok(i) => {
                // closed form: relative rounding error only
                prop_assert!((b.total_power_w(i) - b.heat_w(i) - p).abs() <= 1e-9 * p.max(1.0));
                prop_assert!(i <= 20.5 / (2.0 * r) + 1e-9);
            }
            Err(PropulsionError::PowerExceedsPack { max_power_w, .. }) => prop_assert!(p > max_power_w),
            Err(e) => prop_assert!(false, "{e}"),
        }
    }

    /// Hover results are non-negative, finite and balance: drawn = required + heat.
    #[test]
    fn hover_is_finite_and_balanced(m in 2.0f64..14.0) {
        let h = aec().hover_at_takeoff_mass(m).unwrap();
        prop_assert!(h.power_required_w > 0.0 && h.flight_time_min.is_finite());
        prop_assert!((h.power_drawn_w - h.power_required_w - h.battery_heat_w).abs() < 1e-9 * h.power_drawn_w);
    }
}
