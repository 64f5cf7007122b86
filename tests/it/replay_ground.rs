//! `aloft mission --replay` of a record with ground time before, between and after two flights
//! (issue 23, item 4): the ground time is found, priced at the measured idle power, and the
//! airborne and ground parts add up. The record is built here, so every expected figure is
//! computed from the input: the ground stretches from the rows written, the measured energies as
//! trapezoids of the rows' V x I, the predicted airborne power from the four-term model in
//! closed form at hover.

use crate::common;
use common::{aloft, ok_json};

use std::path::{Path, PathBuf};

use serde_json::Value;

fn dir(name: &str) -> PathBuf {
    let d = common::scratch("replay-ground", name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The record: (start, end, airborne) stretches at 10 Hz. On the ground 50 V x 0.3 A = 15 W at
/// 0 m; in the air a hover 10 m up at 50 V x 24 A = 1200 W. Velocity and acceleration are 0
/// throughout, so the model's power is the hover power at every row.
const STRETCHES: [(f64, f64, bool); 5] = [
    (0.0, 20.0, false),
    (20.0, 60.0, true),
    (60.0, 80.0, false),
    (80.0, 110.0, true),
    (110.0, 130.0, false),
];
const IDLE_W: f64 = 15.0;
const FLIGHT_W: f64 = 1200.0;

/// Rows `(t, airborne)` of the record.
fn rows() -> Vec<(f64, bool)> {
    let mut out = Vec::new();
    for (a, b, air) in STRETCHES {
        let n = ((b - a) * 10.0).round() as usize;
        out.extend((0..n).map(|k| (a + 0.1 * k as f64, air)));
    }
    out
}

/// The record as a KAIST CSV (`power` is 10 x V x I, as in the KAIST files).
fn kaist_csv(dir: &Path) -> PathBuf {
    let mut s = String::from("timestamp,lat,log,alt,roll,pitch,yaw,vel_x,vel_y,vel_z,acc_x,acc_y,acc_z,act_vx,act_vy,act_yr,capacity,vol,cur,power\n");
    for (k, (_, air)) in rows().iter().enumerate() {
        let (alt, cur) = if *air { (10.0, 24.0) } else { (0.0, 0.3) };
        s.push_str(&format!(
            "{},0.6368,2.2338,{alt},0,0,0,0,0,0,0,0,0,0,0,0,5000,50,{cur},{}\n",
            k as u64 * 100_000,
            10.0 * 50.0 * cur
        ));
    }
    let p = dir.join("two-flights.csv");
    std::fs::write(&p, s).unwrap();
    p
}

/// A `[power]`-only vehicle: 3 kg, one 0.2 m disk, kappa1 0.1, eta 0.7, no drag.
const VEHICLE: &str = r#"
name = "ground-test"
[power]
mass_kg = 3.0
gravity_mps2 = 9.80665
air_density_kg_m3 = 1.225
rotor_count = 4
rotor_radius_m = 0.2
disk_area = "one-rotor"
mu1_n_s_per_m = 0.0
mu2_n_s2_per_m2 = 0.0
mu3_n_s3_per_m3 = 0.0
kappa1_w_per_n1_5 = 0.1
kappa2_w_s2_per_m2_n0_5 = 0.0
efficiency = 0.7
"#;

/// Hover power of [`VEHICLE`], W: `(T v_h + kappa1 T^1.5) / eta` with `T = m g` and
/// `v_h = sqrt(T / (2 rho A))` (power seed eqs 8-14 at zero airspeed).
fn hover_w() -> f64 {
    let t = 3.0 * 9.80665;
    let vh = (t / (2.0 * 1.225 * std::f64::consts::PI * 0.2 * 0.2)).sqrt();
    (t * vh + 0.1 * t.powf(1.5)) / 0.7
}

/// Trapezoid of the rows' measured power over `[a, b]` (both row times), J.
fn measured_j(a: f64, b: f64) -> f64 {
    let r = rows();
    let p = |air: bool| if air { FLIGHT_W } else { IDLE_W };
    r.windows(2)
        .filter(|w| w[0].0 >= a - 1e-9 && w[1].0 <= b + 1e-9)
        .map(|w| 0.5 * (p(w[0].1) + p(w[1].1)) * (w[1].0 - w[0].0))
        .sum()
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing in {v}"))
}

/// The test vehicle, written into the folder `d`.
fn vehicle_in(d: &Path) -> PathBuf {
    let vehicle = d.join("vehicle.toml");
    std::fs::write(&vehicle, VEHICLE).unwrap();
    vehicle
}

/// The JSON of `aloft mission --replay csv --profile profile --vehicle <the test vehicle>
/// extra... --format json`, which must succeed.
fn replay_json(d: &Path, csv: &Path, profile: &str, extra: &[&str]) -> Value {
    let vehicle = vehicle_in(d);
    let base = [
        "mission",
        "--replay",
        csv.to_str().unwrap(),
        "--profile",
        profile,
        "--vehicle",
        vehicle.to_str().unwrap(),
    ];
    ok_json(&[&base[..], extra, &["--format", "json"]].concat())
}

fn close(a: f64, b: f64, rel: f64, what: &str) {
    assert!(
        (a - b).abs() <= rel * b.abs().max(1e-12),
        "{what}: {a} vs {b}"
    );
}

#[test]
fn ground_time_before_between_and_after_two_flights_is_priced_at_idle() {
    let d = dir("two");
    let csv = kaist_csv(&d);
    let v = replay_json(&d, &csv, "kaist", &["--lag", "0"]);

    // Detected (the CSV has no landed state) at the rows where the stretches change: take-off at
    // the first airborne row, landing at the first ground row. Row times are multiples of 0.1 s
    // written to the microsecond: 1e-6 s.
    assert_eq!(v["ground_source"], "detected");
    assert_eq!(v["flights"], 2);
    let spans = v["airborne_spans"].as_array().unwrap();
    assert_eq!(spans.len(), 2);
    for (s, (a, b)) in spans.iter().zip([(20.0, 60.0), (80.0, 110.0)]) {
        assert!((num(s, "start_s") - a).abs() < 1e-6, "{s}");
        assert!((num(s, "end_s") - b).abs() < 1e-6, "{s}");
    }
    // The key of the answer to 1e-9, relative.
    let close_v = |key: &str, want: f64, what: &str| close(num(&v, key), want, 1e-9, what);
    // The span is the first to the last row, 0 to 129.9 s.
    let (air_s, ground_s) = (70.0, 129.9 - 70.0);
    close_v("duration_s", 129.9, "duration_s");
    close_v("airborne_s", air_s, "airborne_s");
    close_v("ground_s", ground_s, "ground_s");

    // Measured: trapezoids of the rows over each part. The ground stretches end at a take-off
    // row, so each of the two holds one 0.1 s interval that ramps from 15 W to 1200 W.
    let ground_j = measured_j(0.0, 20.0) + measured_j(60.0, 80.0) + measured_j(110.0, 129.9);
    let air_j = measured_j(20.0, 60.0) + measured_j(80.0, 110.0);
    close_v("measured_ground_energy_wh", ground_j / 3600.0, "ground");
    close_v("measured_airborne_energy_wh", air_j / 3600.0, "air");
    close_v(
        "measured_energy_wh",
        (ground_j + air_j) / 3600.0,
        "measured",
    );
    // Idle: the ground energy over the ground time; the two ramps add 2 x 59.25 J over 59.9 s
    // (1.98 W) to the 15 W written.
    let idle = num(&v, "idle_power_w");
    close(idle, ground_j / ground_s, 1e-9, "idle_power_w");
    assert!(
        (idle - IDLE_W - 2.0 * 59.25 / ground_s).abs() < 1e-6,
        "{idle}"
    );

    // Predicted: the hover power on the airborne time only, the ground at idle.
    let hover = hover_w();
    close_v(
        "predicted_airborne_energy_wh",
        hover * air_s / 3600.0,
        "predicted airborne",
    );
    close_v(
        "predicted_ground_energy_wh",
        ground_j / 3600.0,
        "predicted ground",
    );
    close_v(
        "predicted_energy_wh",
        (hover * air_s + ground_j) / 3600.0,
        "predicted",
    );
    close_v(
        "airborne_energy_error_percent",
        100.0 * (hover * air_s - air_j) / air_j,
        "airborne error",
    );
    // Flying the whole record would have cost the hover power over the ground time as well.
    assert!(num(&v, "predicted_energy_wh") < 0.6 * hover * 129.9 / 3600.0);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn ground_time_is_free_when_the_log_has_no_power() {
    // The same record without power: position and velocity only, through a column map. The
    // ground is then told by the height (10 m up in the air, 0 m on the ground).
    let d = dir("nopower");
    let mut s = String::from("t_s,x,y,z,vx,vy,vz\n");
    for (t, air) in rows() {
        let z = if air { 10.0 } else { 0.0 };
        s.push_str(&format!("{t:.1},0,0,{z},0,0,0\n"));
    }
    let csv = d.join("no-power.csv");
    std::fs::write(&csv, s).unwrap();
    let map = d.join("map.toml");
    std::fs::write(
        &map,
        "name = \"no power\"\n[time]\ncolumn = \"t_s\"\nunit = \"s\"\n[position]\ntype = \"local\"\ncolumns = [\"x\", \"y\", \"z\"]\nframe = \"enu\"\nunit = \"m\"\n[velocity]\ncolumns = [\"vx\", \"vy\", \"vz\"]\nframe = \"enu\"\nunit = \"m/s\"\n",
    )
    .unwrap();
    let v = replay_json(&d, &csv, map.to_str().unwrap(), &[]);
    assert_eq!(v["flights"], 2);
    close(num(&v, "airborne_s"), 70.0, 1e-9, "airborne_s");
    assert_eq!(num(&v, "predicted_ground_energy_wh"), 0.0);
    close(
        num(&v, "predicted_energy_wh"),
        hover_w() * 70.0 / 3600.0,
        1e-9,
        "predicted",
    );
    for key in [
        "idle_power_w",
        "measured_energy_wh",
        "measured_ground_energy_wh",
    ] {
        assert!(v.get(key).is_none(), "{key} in {v}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn battery_with_replay_is_part_of_the_mass_and_an_unknown_one_is_bad_input() {
    let d = dir("battery");
    let csv = kaist_csv(&d);
    let csv = csv.to_str().unwrap();
    let base = [
        "mission",
        "--replay",
        csv,
        "--profile",
        "kaist",
        "--lag",
        "0",
    ];
    // The M100 with its TB48D: airframe + pack, read from the vehicle file here.
    let file: toml::Value = toml::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/fixtures/vehicles/dji-m100.toml"
        ))
        .unwrap(),
    )
    .unwrap();
    let airframe = file["airframe"]["mass_kg"].as_float().unwrap();
    let pack = file["battery"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["name"].as_str() == Some("TB48D"))
        .unwrap()["mass_kg"]
        .as_float()
        .unwrap();
    let mut args = base.to_vec();
    args.extend([
        "--vehicle",
        "dji-m100",
        "--battery",
        "tb48d",
        "--payload-kg",
        "0.25",
        "--format",
        "json",
    ]);
    let v = ok_json(&args);
    assert_eq!(v["battery"], "TB48D");
    close(num(&v, "mass_kg"), airframe + pack + 0.25, 1e-12, "mass_kg");
    // The table prints the mass and the pack.
    let mut args = base.to_vec();
    args.extend(["--vehicle", "dji-m100", "--battery", "TB48D"]);
    let out = aloft(&args);
    let table = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        table.contains("TB48D")
            && table.contains(&format!("take-off mass {:.3} kg", airframe + pack)),
        "{table}"
    );

    // Bad input: exit 2 with one line naming the value.
    let vehicle = vehicle_in(&d);
    let vehicle = vehicle.to_str().unwrap();
    for (extra, needle) in [
        (["--vehicle", "dji-m100", "--battery", "NOPE"], "NOPE"),
        (["--vehicle", vehicle, "--battery", "TB48D"], "airframe"),
    ] {
        let mut args = base.to_vec();
        args.extend(extra);
        let out = aloft(&args);
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{err}");
        assert!(out.stdout.is_empty());
    }
    std::fs::remove_dir_all(&d).unwrap();
}
