//! One vehicle, one mass (issue 23, item 5): every command flies a built-in vehicle at its
//! take-off mass, airframe + pack + payload, so `aloft power` and `aloft endurance` (and, for the
//! propulsion-chain vehicle, `aloft propulsion`) agree on the hover power of every built-in
//! vehicle and every pack. The expected hover power is computed here in closed form from the
//! constants of the vehicle files, read as plain TOML (not through aloft's vehicle types).

use crate::common;
use common::{aloft, cli, ok_json as json, refused};

use toml::Value;

/// The vehicle file of a built-in, as plain TOML.
fn fixture(name: &str) -> Value {
    let path = common::fixture("vehicles", &format!("{name}.toml"));
    toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn num(table: &Value, key: &str) -> f64 {
    let v = &table[key];
    v.as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .unwrap_or_else(|| panic!("{key} in {table}"))
}

/// Airframe (without battery) + the pack named `battery` + payload, kg, from the file.
fn takeoff_mass_kg(file: &Value, battery: &str, payload_kg: f64) -> f64 {
    let pack = file["battery"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["name"].as_str() == Some(battery))
        .unwrap();
    num(&file["airframe"], "mass_kg") + num(pack, "mass_kg") + payload_kg
}

/// Hover power of the four-term model in closed form (power seed eqs 8, 10, 12, 14 at zero
/// airspeed, no climb): `T = m g`, `vh = sqrt(T / (2 rho A))` with `A` one rotor disk or all of
/// them as the file says, `P = (T vh + kappa1 T^1.5) / eta` (kappa2 multiplies the in-plane speed,
/// zero in hover).
fn four_term_hover_w(power: &Value, mass_kg: f64) -> f64 {
    let t = mass_kg * num(power, "gravity_mps2");
    let r = num(power, "rotor_radius_m");
    let disks = match power["disk_area"].as_str() {
        Some("all-rotors") => num(power, "rotor_count"),
        Some("one-rotor") => 1.0,
        other => panic!("disk_area {other:?}"),
    };
    let area = disks * std::f64::consts::PI * r * r;
    let vh = (t / (2.0 * num(power, "air_density_kg_m3") * area)).sqrt();
    (t * vh + num(power, "kappa1_w_per_n1_5") * t.powf(1.5)) / num(power, "efficiency")
}

/// Supply power of the propulsion chain at hover in closed form (propulsion seed): thrust per
/// rotor `m g / N`, raised by the installed loss to the stand thrust; rotor speed from
/// `T = C_T rho n^2 D^4`; shaft power `C_P rho n^3 D^5`; motor current `Q / K_t + I_0` with
/// `K_t = 60 / (2 pi Kv)` (SI); back-EMF `60 n / Kv`; supply power `I^2 R + I V` per motor
/// (eq 28 with the file's ideal ESC), summed over the rotors.
fn chain_hover_w(propulsion: &Value, mass_kg: f64) -> f64 {
    let (prop, motor) = (&propulsion["propeller"], &propulsion["motor"]);
    let esc = &propulsion["esc"];
    assert_eq!(num(esc, "electronics_power_w"), 0.0);
    assert_eq!(num(esc, "resistance_ohm"), 0.0);
    let rotors = num(propulsion, "rotor_count");
    let rho = num(propulsion, "air_density_kg_m3");
    let d = num(prop, "diameter_in") * 0.0254;
    let thrust = mass_kg * num(propulsion, "gravity_mps2") / rotors;
    let stand = thrust / (1.0 - num(prop, "installed_thrust_loss_fraction"));
    let n = (stand / (num(prop, "thrust_coefficient_ct") * rho * d.powi(4))).sqrt();
    let shaft_w = num(prop, "power_coefficient_cp") * rho * n.powi(3) * d.powi(5);
    let torque = shaft_w / (2.0 * std::f64::consts::PI * n);
    let kv = num(motor, "kv_rpm_per_v");
    let kt = 60.0 / (2.0 * std::f64::consts::PI * kv);
    let current = torque / kt + num(motor, "no_load_current_a");
    let emf = 60.0 * n / kv;
    rotors * (current * current * num(motor, "armature_resistance_ohm") + current * emf)
}

fn close(got: f64, want: f64, rel: f64) -> bool {
    (got / want - 1.0).abs() <= rel
}

/// Asserts `close(got, want, rel)`, naming both values.
fn assert_close(got: f64, want: f64, rel: f64) {
    assert!(close(got, want, rel), "{got} vs {want} (rel {rel})");
}

/// Every built-in vehicle with an airframe, every pack, with and without payload: `aloft power`
/// (hover: zero airspeed, roll, pitch and climb) and `aloft endurance` name the same take-off
/// mass and the same hover power, and both equal the closed form from the file's constants.
/// Tolerances: the two commands evaluate the same model at the same mass, so they agree to
/// rounding (1e-12 relative); the closed form takes another order of operations (1e-9).
#[test]
fn power_and_endurance_agree_on_hover_power_for_every_builtin_and_pack() {
    let vehicles = json(&["vehicles", "--format", "json"]);
    let mut checked = 0;
    for entry in vehicles.as_array().unwrap() {
        let name = entry["name"].as_str().unwrap();
        let file = fixture(name);
        if file.get("airframe").is_none() {
            continue; // the power model alone: `paper_case_is_a_power_model_alone` below
        }
        for battery in entry["batteries"].as_array().unwrap() {
            let battery = battery.as_str().unwrap();
            for payload in ["0", "0.2"] {
                let args = [
                    "--vehicle",
                    name,
                    "--battery",
                    battery,
                    "--payload-kg",
                    payload,
                ];
                let e = json(&[&["endurance", "--format", "json"], &args[..]].concat());
                let mass = takeoff_mass_kg(&file, battery, payload.parse().unwrap());
                let e_mass = e["takeoff_mass_kg"].as_f64().unwrap();
                assert!(
                    close(e_mass, mass, 1e-12),
                    "{name} {battery} {payload}: {e_mass}"
                );
                let hover = e["hover_power_w"].as_f64().unwrap();
                let (other, expected) = if file.get("power").is_some() {
                    let p = json(&[&["power", "--format", "json"], &args[..]].concat());
                    let p_mass = p["takeoff_mass_kg"].as_f64().unwrap();
                    assert_eq!(p_mass.to_bits(), e_mass.to_bits(), "{name} {battery}");
                    assert_eq!(p["battery"].as_str(), Some(battery));
                    let expected = four_term_hover_w(&file["power"], mass);
                    (p["electrical_w"].as_f64().unwrap(), expected)
                } else {
                    // The propulsion chain has no four-term table: `aloft power` refuses it
                    // (checked below) and `aloft propulsion` is its power model.
                    let m = e_mass.to_string();
                    let p = json(&[
                        "propulsion",
                        "--vehicle",
                        name,
                        "--takeoff-mass-kg",
                        &m,
                        "--format",
                        "json",
                    ]);
                    let expected = chain_hover_w(&file["propulsion"], mass);
                    (p["power_required_w"].as_f64().unwrap(), expected)
                };
                assert!(
                    close(other, hover, 1e-12),
                    "{name} {battery} {payload}: {other} vs {hover} W"
                );
                assert!(
                    close(hover, expected, 1e-9),
                    "{name} {battery} {payload}: {hover} vs closed form {expected} W"
                );
                checked += 1;
            }
        }
    }
    // 4 + 2 + 2 + 2 + 1 packs, two payloads each: a vehicle that drops out shows here.
    assert_eq!(checked, 22);
}

/// The default take-off mass (default pack, no payload) is what `power` and `endurance` fly
/// without flags, and what the table prints with its parts.
#[test]
fn the_default_is_airframe_plus_default_pack_and_the_tables_say_so() {
    let m100 = fixture("dji-m100");
    let mass = takeoff_mass_kg(&m100, "TB47D", 0.0);
    let p = json(&["power", "--format", "json"]);
    assert_close(p["takeoff_mass_kg"].as_f64().unwrap(), mass, 1e-12);
    let expected = four_term_hover_w(&m100["power"], mass);
    assert_close(p["electrical_w"].as_f64().unwrap(), expected, 1e-9);
    let line = "take-off mass 2.355 kg (airframe 1.755 kg + TB47D 0.600 kg + payload 0.000 kg)";
    for command in ["power", "endurance"] {
        let o = aloft(&[command]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains(line), "{command}: {text}");
    }
    let o = aloft(&["endurance", "--sweep-speed", "5"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains(line));
}

/// The propulsion seed's quadrotor flies missions and endurance queries (its airframe and packs
/// from the seed) at 16.5 lb, and `aloft power` says it has no four-term table.
#[test]
fn aec_quadrotor_answers_endurance_and_mission() {
    let e = json(&[
        "endurance",
        "--vehicle",
        "aec-quadrotor",
        "--format",
        "json",
    ]);
    assert_close(
        e["takeoff_mass_kg"].as_f64().unwrap(),
        16.5 * 0.45359237,
        1e-9,
    );
    assert_eq!(e["battery"].as_str(), Some("4xTP8000-5S4PL"));
    // Exit 0 or 1: feasible or not, the mission is answered.
    let s: serde_json::Value = serde_json::from_str(&cli(&[
        "mission",
        "--vehicle",
        "aec-quadrotor",
        "--format",
        "json",
    ]))
    .unwrap();
    assert_close(
        s["takeoff_mass_kg"].as_f64().unwrap(),
        16.5 * 0.45359237,
        1e-9,
    );
    let err = refused(&["power", "--vehicle", "aec-quadrotor"]);
    assert!(err.contains("[power]"));
}

/// The seed's 3.29 kg is the named validation case `dji-m100-paper`: a power model alone, whose
/// one mass is its [power] table's (+ payload), and which the planner refuses for want of an
/// airframe and packs.
#[test]
fn paper_case_is_a_power_model_alone() {
    let paper = fixture("dji-m100-paper");
    let p = json(&[
        "power",
        "--vehicle",
        "dji-m100-paper",
        "--payload-kg",
        "0.5",
        "--format",
        "json",
    ]);
    assert_close(p["takeoff_mass_kg"].as_f64().unwrap(), 3.29 + 0.5, 1e-12);
    assert!(p.get("battery").is_none());
    let expected = four_term_hover_w(&paper["power"], 3.79);
    assert_close(p["electrical_w"].as_f64().unwrap(), expected, 1e-9);
    // The planner names the first table it misses ([airframe], or the [[battery]] packs).
    for command in ["endurance", "mission"] {
        let err = refused(&[command, "--vehicle", "dji-m100-paper"]);
        assert!(
            err.contains("dji-m100-paper' has no [") && err.contains("mission planner"),
            "{err}"
        );
    }
}

/// The small KAIST log of the fixtures.
const KAIST_SMALL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/logs/kaist_small.csv");

/// `command flag <the small KAIST log> --profile kaist --lag 0 --vehicle dji-m100 extra...`.
fn on_kaist_small<'a>(command: &'a str, flag: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let base = [
        command,
        flag,
        KAIST_SMALL,
        "--profile",
        "kaist",
        "--lag",
        "0",
    ];
    [&base[..], &["--vehicle", "dji-m100"], extra].concat()
}

/// `aloft validate` flies the take-off mass of `--battery` and `--payload-kg` too: a heavier
/// vehicle predicts more energy for the same logged flight, and the JSON names the mass.
#[test]
fn validate_flies_the_takeoff_mass_it_is_given() {
    let run = |extra: &[&str]| {
        let extra = [&["--format", "json"][..], extra].concat();
        json(&on_kaist_small("validate", "--log", &extra))
    };
    let light = run(&[]);
    let heavy = run(&["--battery", "TB48D", "--payload-kg", "0.3"]);
    assert_close(
        light["takeoff_mass_kg"].as_f64().unwrap(),
        1.755 + 0.600,
        1e-12,
    );
    assert_close(
        heavy["takeoff_mass_kg"].as_f64().unwrap(),
        1.755 + 0.676 + 0.3,
        1e-12,
    );
    let energy = |v: &serde_json::Value| v["flights"][0]["predicted_energy_wh"].as_f64().unwrap();
    assert!(
        energy(&heavy) > energy(&light),
        "{} vs {}",
        energy(&heavy),
        energy(&light)
    );
    let err = refused(&on_kaist_small("validate", "--log", &["--payload-kg", "2"]));
    assert!(err.contains("3.600 kg limit"));
}

/// `aloft mission --replay` flies the take-off mass of `--battery` and `--payload-kg` (before,
/// `--battery` was refused there and the default pack flown).
#[test]
fn replay_flies_the_takeoff_mass_it_is_given() {
    let extra = [
        "--battery",
        "TB48D",
        "--payload-kg",
        "0.1",
        "--format",
        "json",
    ];
    let r = json(&on_kaist_small("mission", "--replay", &extra));
    assert_close(r["mass_kg"].as_f64().unwrap(), 1.755 + 0.676 + 0.1, 1e-12);
}
