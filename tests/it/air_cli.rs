//! The day's air (issue 34, part 1) from the command line: the density every answer carries and
//! where it came from, the precedence of its defaults, hover power scaling by `sqrt(rho0 / rho)`
//! (power seed eqs 8-12 with the four-term model's density terms), the thrust limit a vehicle
//! states falling with density, the logs' own air, and bad values refused by name with their
//! range. Check values are the ISA's (PX4 `test_atmosphere.cpp`: 0.9091 kg/m^3 at 3000 m) and
//! closed forms, never aloft's own output.

use crate::common;

use common::{data_dir, run, scratch};
use serde_json::Value;

fn json(args: &[&str]) -> (i32, Value) {
    let mut all = args.to_vec();
    all.extend(["--format", "json"]);
    let (code, out, err) = run(&all);
    assert!(code == 0 || code == 1, "{args:?}: exit {code}: {err}");
    (code, serde_json::from_str(&out).expect("JSON"))
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing in {v}"))
}

/// Hover at a fixed mass: the induced and profile terms and so the electrical power each grow
/// by `sqrt(rho0 / rho)`, 1.161 at 3000 m ISA (0.9091 kg/m^3); the parasitic term at a given
/// airspeed falls with `rho`.
#[test]
fn paper_val_hover_power_scales_by_the_root_of_the_density_ratio() {
    let (_, sea) = json(&["power", "--airspeed", "0"]);
    let (_, high) = json(&["power", "--airspeed", "0", "--elevation-m", "3000"]);
    assert!((num(&high, "air_density_kg_m3") - 0.9091).abs() < 0.001);
    assert_eq!(high["density_source"], "given");
    assert_eq!(high["temperature_source"], "isa");
    assert!((num(&high, "temperature_c") - (-4.5)).abs() < 1e-9);
    let ratio = (1.225 / num(&high, "air_density_kg_m3")).sqrt();
    for key in ["induced_w", "profile_w", "electrical_w"] {
        let r = num(&high, key) / num(&sea, key);
        assert!((r / ratio - 1.0).abs() < 1e-9, "{key}: {r} against {ratio}");
    }
    assert!((ratio - 1.161).abs() < 0.001);
    // Forward flight at one attitude: the drag force falls with the density (and with it the
    // parasitic power of eq 11 at that airspeed).
    let fwd = [
        "power",
        "--airspeed",
        "10",
        "--pitch",
        "-10",
        "--aoa",
        "paper",
    ];
    let (_, a) = json(&fwd);
    let mut thin = fwd.to_vec();
    thin.extend(["--elevation-m", "3000"]);
    let (_, b) = json(&thin);
    let r = num(&b, "parasitic_w") / num(&a, "parasitic_w");
    assert!(
        (r - num(&high, "air_density_kg_m3") / 1.225).abs() < 1e-9,
        "parasitic ratio {r}"
    );
}

/// Which air a mission flies in: the flags, else the home altitude of the file (a `.plan`'s
/// `plannedHomePosition` altitude, 483 m in the shared PX4 delivery mission) in ISA air, else the
/// vehicle file's density (the demo has no home altitude).
#[test]
fn data_val_air_precedence_flags_then_home_altitude_then_vehicle() {
    let plan = data_dir().join("missions/px4_triangle_gripper_package_delivery.plan");
    let plan = plan.to_str().unwrap();
    let text = std::fs::read_to_string(plan).unwrap();
    let file: Value = serde_json::from_str(&text).unwrap();
    let home_alt = file["mission"]["plannedHomePosition"][2].as_f64().unwrap();
    let (_, home) = json(&["mission", plan]);
    assert_eq!(home["elevation_source"], "mission_home");
    assert!((num(&home, "elevation_m") - home_alt).abs() < 1e-9);
    // ISA at the home: T = 288.15 - 0.0065 h, p = 101325 (T / 288.15)^5.2559, rho = p / (R T).
    let t = 288.15 - 0.0065 * home_alt;
    let p = 101_325.0 * (t / 288.15_f64).powf(9.80665 / (287.053 * 0.0065));
    assert!((num(&home, "air_density_kg_m3") - p / (287.053 * t)).abs() < 1e-9);
    // A temperature alone keeps the home's elevation; an elevation overrides it.
    let (_, hot) = json(&["mission", plan, "--temperature-c", "35"]);
    assert_eq!(hot["elevation_source"], "mission_home");
    assert!((num(&hot, "air_density_kg_m3") - p / (287.053 * 308.15)).abs() < 1e-9);
    assert!(num(&hot, "energy_wh") > num(&home, "energy_wh"));
    let (_, given) = json(&["mission", plan, "--elevation-m", "0"]);
    assert_eq!(given["elevation_source"], "given");
    assert!((num(&given, "air_density_kg_m3") - 1.225).abs() < 1e-4);
    // No flag and no home altitude: the vehicle file's density (ISA sea level for the M100).
    let (_, demo) = json(&["mission"]);
    assert_eq!(demo["density_source"], "isa");
    assert!(demo.get("elevation_m").is_none());
    assert!((num(&demo, "air_density_kg_m3") - 1.225).abs() < 1e-12);
}

/// Moist air is lighter (30 C, 80 %: -1.27 % against dry air, the research note's section 1.3),
/// and a low QNH thins the air in proportion to the pressure.
#[test]
fn humidity_and_qnh_change_the_density_as_the_gas_law_says() {
    let (_, dry) = json(&["endurance", "--elevation-m", "0", "--temperature-c", "30"]);
    let (_, wet) = json(&[
        "endurance",
        "--elevation-m",
        "0",
        "--temperature-c",
        "30",
        "--humidity-percent",
        "80",
    ]);
    let change = 100.0 * (num(&wet, "air_density_kg_m3") / num(&dry, "air_density_kg_m3") - 1.0);
    assert!((change - (-1.27)).abs() < 0.05, "{change} %");
    let (_, low) = json(&[
        "endurance",
        "--elevation-m",
        "0",
        "--temperature-c",
        "30",
        "--qnh-hpa",
        "990",
    ]);
    let r = num(&low, "air_density_kg_m3") / num(&dry, "air_density_kg_m3");
    assert!((r - 990.0 / 1013.25).abs() < 1e-9, "{r}");
    assert!(num(&low, "hover_endurance_s") < num(&dry, "hover_endurance_s"));
}

/// A vehicle that states its largest thrust loses it in thin air (thrust `∝ rho` at the rotors'
/// top speed): the M100 given 30 N hovers at sea level (23.1 N) and cannot at 3000 m, where 30 N
/// becomes 22.3 N. A vehicle that does not state it keeps its envelope.
#[test]
fn a_stated_thrust_limit_falls_with_the_density() {
    let builtin = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/vehicles/dji-m100.toml"
    ))
    .unwrap();
    let with_thrust = builtin.replacen("[airframe]\n", "[airframe]\nmax_thrust_n = 30.0\n", 1);
    assert_ne!(
        with_thrust, builtin,
        "no [airframe] table in the M100's file"
    );
    let path = scratch("air", "m100-30n.toml");
    std::fs::write(&path, with_thrust).unwrap();
    let vehicle = path.to_str().unwrap();
    let (code, sea) = json(&["mission", "--vehicle", vehicle]);
    assert_eq!(code, 0, "{sea}");
    let (code, high) = json(&["mission", "--vehicle", vehicle, "--elevation-m", "3000"]);
    assert_eq!(code, 1, "{high}");
    let reason = high["reason"].as_str().unwrap_or_default();
    assert!(reason.contains("thrust"), "{reason}");
    // The built-in M100 (no stated thrust) flies at 3000 m.
    let (code, _) = json(&["mission", "--elevation-m", "3000"]);
    assert_eq!(code, 0);
}

/// A PX4 log's own air (`vehicle_air_data.rho`, about 1.157 kg/m^3 on the shared flights at
/// about 325 m and 20 C: the research note's section 1.2) is the air its replay flies in.
#[test]
fn data_val_a_replay_flies_in_the_logs_own_air() {
    let log = data_dir().join("px4_flugdrohne/ulg/log_66_2023-6-21-08-44-02.ulg");
    let (_, a) = json(&["mission", "--replay", log.to_str().unwrap()]);
    assert_eq!(a["density_source"], "log");
    let rho = num(&a, "air_density_kg_m3");
    assert!((1.150..1.165).contains(&rho), "{rho}");
    let (_, given) = json(&[
        "mission",
        "--replay",
        log.to_str().unwrap(),
        "--elevation-m",
        "325",
        "--temperature-c",
        "20",
    ]);
    assert_eq!(given["density_source"], "given");
}

/// Bad values: exit 2 with one line naming the value and its range.
#[test]
fn absurd_air_is_exit_2_naming_the_value_and_its_range() {
    for (flag, value, name) in [
        ("--elevation-m", "-500", "elevation_m"),
        ("--elevation-m", "12000", "elevation_m"),
        ("--temperature-c", "300", "temperature_c"),
        ("--temperature-c", "-100", "temperature_c"),
        ("--humidity-percent", "101", "humidity_percent"),
        ("--qnh-hpa", "29.92", "qnh_hpa"),
    ] {
        for command in [
            vec!["mission"],
            vec!["endurance"],
            vec!["power", "--airspeed", "0"],
        ] {
            let mut args = command.clone();
            args.extend([flag, value]);
            let (code, out, err) = run(&args);
            assert_eq!(code, 2, "{args:?}: {out}");
            assert_eq!(err.trim().lines().count(), 1, "{err}");
            assert!(err.contains(name) && err.contains("from "), "{err}");
        }
    }
}

/// Saturation vapour pressure over water, Pa, by Buck's equation (1981), not the Vaisala fit
/// aloft uses: `6.1121 exp((18.678 - t/234.5) (t / (257.14 + t)))` hPa, `t` in C.
fn buck_vapour_pa(t_c: f64) -> f64 {
    611.21 * ((18.678 - t_c / 234.5) * (t_c / (257.14 + t_c))).exp()
}

/// ISA station pressure at `h_m` for a sea-level pressure `p0_pa` (troposphere law), Pa.
fn isa_pressure_pa(h_m: f64, p0_pa: f64) -> f64 {
    p0_pa * (1.0 - 0.0065 * h_m / 288.15).powf(9.80665 / (287.053 * 0.0065))
}

/// Issue 41 item 6: air that cannot exist was flown (11,000 m at 60 C, 100 % humidity, QNH
/// 850 hPa: water vapour pressure above the air's own, density 0.119 kg/m^3). A vapour pressure
/// at or above a tenth of the air's pressure, or a density below ISA's at 11 km
/// (0.3639 kg/m^3), is exit 2 with one line naming the combination; the hot and humid days that
/// exist still fly. Expectations from Buck's vapour pressure and the ISA pressure law, here.
#[test]
fn air_that_cannot_exist_is_exit_2_naming_the_combination() {
    // The case: the vapour pressure is above the air's.
    let e = buck_vapour_pa(60.0);
    let p = isa_pressure_pa(11_000.0, 85_000.0);
    assert!(e > p, "{e} {p}");
    // Dry air at 11 km and 60 C: p / (Rd T) = 0.237 kg/m^3, below ISA's 0.3639 there.
    let rho_dry = isa_pressure_pa(11_000.0, 101_325.0) / (287.053 * 333.15);
    assert!(rho_dry < 0.3639, "{rho_dry}");
    for (flags, needles) in [
        (
            &[
                "--elevation-m",
                "11000",
                "--temperature-c",
                "60",
                "--humidity-percent",
                "100",
                "--qnh-hpa",
                "850",
            ][..],
            &["vapour pressure", "11000 m", "60 C", "100 %", "850 hPa"][..],
        ),
        (
            &["--elevation-m", "11000", "--temperature-c", "60"][..],
            &["density", "0.3639", "11000 m", "60 C"][..],
        ),
    ] {
        for command in [
            vec!["mission"],
            vec!["endurance"],
            vec!["power", "--airspeed", "0"],
        ] {
            let mut args = command.clone();
            args.extend(flags);
            let (code, out, err) = run(&args);
            assert_eq!(code, 2, "{args:?}: {out}");
            assert_eq!(err.trim().lines().count(), 1, "{err}");
            for n in needles {
                assert!(err.contains(n), "{args:?}: {err} lacks {n}");
            }
        }
    }
    // The same through the keywords of Python and the page.
    use aloft::engine::{answers, flags::EnduranceFlags, parse_keywords, Keyword};
    let kw = |k: &str, v: &str| (k.to_string(), Keyword::One(v.into()));
    let flags: EnduranceFlags = parse_keywords(
        "aloft.endurance",
        &[],
        &[
            kw("elevation_m", "11000"),
            kw("temperature_c", "60"),
            kw("humidity_percent", "100"),
            kw("qnh_hpa", "850"),
        ],
    )
    .unwrap();
    let err = answers::endurance_answer(&flags).unwrap_err().to_string();
    assert!(err.contains("vapour pressure"), "{err}");
    // Days that exist: sea level at 40 C and 100 % (vapour 7.4 kPa, 7 % of the air's pressure),
    // ISA at 11 km itself (0.3639 kg/m^3), and 3000 m at 45 C and 100 % (9.6 kPa of 70.1 kPa,
    // 13.7 %: refused by the tenth) against 35 C (5.6 kPa, 8 %: flown).
    assert!(buck_vapour_pa(40.0) < 0.1 * 101_325.0);
    assert!(buck_vapour_pa(35.0) < 0.1 * isa_pressure_pa(3000.0, 101_325.0));
    assert!(buck_vapour_pa(45.0) > 0.1 * isa_pressure_pa(3000.0, 101_325.0));
    for flags in [
        &["--temperature-c", "40", "--humidity-percent", "100"][..],
        &["--elevation-m", "11000"][..],
        &[
            "--elevation-m",
            "3000",
            "--temperature-c",
            "35",
            "--humidity-percent",
            "100",
        ][..],
    ] {
        let mut args = vec!["endurance"];
        args.extend(flags);
        json(&args);
    }
    let (code, _, err) = run(&[
        "endurance",
        "--elevation-m",
        "3000",
        "--temperature-c",
        "45",
        "--humidity-percent",
        "100",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("vapour pressure"), "{err}");
}
