//! `aloft live --replay` follows the pack's own state of charge, not a full pack (a defect found
//! on the shared PX4 flights: PX4 said 69 % at take-off, aloft 100 %) nor PX4's voltage-based
//! report, which sags under load (issue 44), and every figure of every update stays in its
//! physical range on every shared log aloft can replay.
//!
//! The expected states of charge are read here from the per-topic CSVs beside the ULog files
//! (`px4_flugdrohne/csv`, decoded by `ulog2csv`, independently of aloft): `battery_status`
//! (`remaining`, `voltage_v`, `current_a`, `discharged_mah`) and `vehicle_land_detected`
//! (take-off and landing).

use crate::common;

use std::path::{Path, PathBuf};

use common::{aloft, data_dir, files, stderr};
use serde_json::Value;

/// The PX4 flights with a usable power and motion record (as `live_px4_data_val.rs`).
const FLIGHTS: [&str; 4] = [
    "1x_wo_Last_5m",
    "log_20_2023-6-7-10-52-56",
    "log_30_2023-6-7-12-11-06",
    "log_66_2023-6-21-08-44-02",
];

/// The airframe and pack appended to a fitted PX4 vehicle: the flights' mass and pack are not
/// documented (`BAT1_CAPACITY` -1); the template's 1.2 kg split as 0.8 kg of airframe and a
/// 0.4 kg 3S 5000 mA h pack (the capacity only scales the charge drawn between reports).
const AIRFRAME_AND_PACK: &str = r#"
[airframe]
mass_kg = 0.8
max_takeoff_mass_kg = 2.0
max_tilt_deg = 30.0
max_speed_mps = 10.0
max_climb_rate_mps = 3.0
max_descent_rate_mps = 2.0
acceleration_mps2 = 2.0
vertical_acceleration_mps2 = 1.5
yaw_rate_deg_s = 60.0
rotor_height_m = 0.1

[[battery]]
name = "3S-5000"
default = true
cells_series = 3
capacity_mah = 5000.0
nominal_v = 11.1
energy_wh = 55.5
mass_kg = 0.4
internal_resistance_ohm = 0.02
cutoff_cell_v = 3.3
"#;

/// A vehicle of the PX4 quadrotor: fitted (`px4-template.toml`, `--no-drag`, as
/// docs/validation.md fits these flights) on the flights other than `held`, with
/// [`AIRFRAME_AND_PACK`], in a file of its own. Fitted without `log_66`, its efficiency is 0.74, and the power
/// measured on `log_66` is below the model's at any efficiency up to 1.
fn px4_vehicle(held: &str) -> String {
    let dir = data_dir().join("px4_flugdrohne/ulg");
    // A file of its own per call: the tests run at once, and one must not read another's file
    // between the fit and the appended airframe.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = common::scratch("live-soc", &format!("{held}-{call}.toml"));
    let mut args = vec!["fit".to_string(), "--log".to_string()];
    for f in FLIGHTS.iter().filter(|f| **f != held) {
        args.push(dir.join(format!("{f}.ulg")).display().to_string());
    }
    let template = format!(
        "{}/fixtures/vehicles/px4-template.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let out_path = path.display().to_string();
    for w in [
        "--vehicle-template",
        &template,
        "--no-drag",
        "-o",
        &out_path,
    ] {
        args.push(w.to_string());
    }
    let out = aloft(&args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let fitted = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, fitted + AIRFRAME_AND_PACK).unwrap();
    out_path
}

/// The JSON updates of `aloft live` over `source` (`--replay LOG` or `--tlog FILE`).
fn updates(source: &[&str], vehicle: &str, extra: &[&str]) -> Vec<Value> {
    let mut args = vec!["live"];
    args.extend(source);
    args.extend(["--vehicle", vehicle, "--format", "json"]);
    args.extend(extra);
    let out = aloft(&args);
    assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    let v: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .filter(|v: &Value| v.get("time_s").is_some())
        .collect();
    assert!(!v.is_empty(), "{args:?}: no updates");
    v
}

/// The columns `names` of a PX4 topic table, as numbers (`True`/`False` as 1/0), row by row.
fn table(log: &str, topic: &str, names: &[&str]) -> Vec<Vec<f64>> {
    let path = data_dir()
        .join("px4_flugdrohne/csv")
        .join(format!("{log}_{topic}_0.csv"));
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at: Vec<usize> = names
        .iter()
        .map(|n| head.iter().position(|h| h == n).unwrap())
        .collect();
    let num = |s: &str| match s {
        "True" => 1.0,
        "False" => 0.0,
        _ => s.parse::<f64>().unwrap(),
    };
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            at.iter().map(|&i| num(f[i])).collect()
        })
        .collect()
}

/// What PX4 reported on one flight, read from its CSVs: the boot time of the ULog's first
/// sample (the first `vehicle_local_position`, s), the take-off (boot time, s) from
/// `vehicle_land_detected`, and `battery_status` rows `(time s, remaining,
/// voltage V, current A, discharged mA h)`.
struct Reported {
    first_s: f64,
    take_off_s: f64,
    battery: Vec<[f64; 5]>,
}

impl Reported {
    fn of(log: &str) -> Self {
        let first_s = table(log, "vehicle_local_position", &["timestamp"])[0][0] * 1e-6;
        let land = table(log, "vehicle_land_detected", &["timestamp", "landed"]);
        let take_off_s = land.iter().find(|r| r[1] < 0.5).unwrap()[0] * 1e-6;
        let names = [
            "timestamp",
            "remaining",
            "voltage_v",
            "current_a",
            "discharged_mah",
        ];
        let battery = table(log, "battery_status", &names)
            .into_iter()
            .map(|r| [r[0] * 1e-6, r[1], r[2], r[3], r[4]])
            .collect();
        Self {
            first_s,
            take_off_s,
            battery,
        }
    }

    /// The last `battery_status` row at or before boot time `t_s`.
    fn at(&self, t_s: f64) -> [f64; 5] {
        *self.battery.iter().rev().find(|r| r[0] <= t_s).unwrap()
    }

    /// `remaining` at the stream time of an update (s from the first sample).
    fn remaining_at_stream_s(&self, time_s: f64) -> f64 {
        self.at(self.first_s + time_s)[1]
    }

    /// The pack's rested voltage before take-off: the median of the records at under 0.5 A in
    /// the 10 s before it, V.
    fn rested_v(&self) -> f64 {
        let mut v: Vec<f64> = self
            .battery
            .iter()
            .filter(|b| b[0] < self.take_off_s && b[0] >= self.take_off_s - 10.0 && b[3] < 0.5)
            .map(|b| b[2])
            .collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    }

    /// The pack's state of charge at the stream time of an update: the rested voltage's on the
    /// generic LiPo curve (the vehicle's pack gives none of its own), less the charge PX4
    /// counted since take-off over the 5000 mA h the owner states.
    fn counted_at_stream_s(&self, time_s: f64) -> f64 {
        let s0 = aloft_propulsion::OcvCurve::typical_lipo().soc_at(self.rested_v() / 3.0);
        let drawn = self.at(self.first_s + time_s)[4] - self.at(self.take_off_s)[4];
        s0 - drawn / 5000.0
    }
}

fn num(u: &Value, key: &str) -> f64 {
    u[key].as_f64().unwrap_or_else(|| panic!("{key} in {u}"))
}

fn in_air(v: &[Value]) -> Vec<&Value> {
    v.iter().filter(|u| u["in_air"] == true).collect()
}

/// Issue 44 on the five PX4 flights (3S, 5000 mA h from the owner): the state of charge in the
/// air is the pack's (its rested voltage before take-off on the pack's curve, less the charge
/// PX4 counted since, computed here from the CSVs) within 3 points, `log_66` (the flight that
/// reports 69 % at take-off) among them; it does not rise at touchdown by more than 3
/// points; and the vehicle's own report is beside it as `reported_soc` (PX4's `remaining`
/// within 2 %: the updates fall between PX4's 5 Hz records). PX4 estimates from the voltage
/// under load (`BAT1_CAPACITY` unset), which sags: before, `soc` was that report, which fell to
/// 44 % in the air on `log_66` (the pack 59-63 %), 53 % on `log_65` (65-68 %), 72 % on
/// `1x_wo_Last_5m` (85-92 %), and rose 4 points at the first update on the ground. Measured
/// now: worst 0.6, 0.1, 0.2, 0.6, 1.2 points from the pack's, no rise at touchdown. With a
/// 60 % reserve `log_66` still does not say `continue` throughout.
#[test]
fn data_val_live_replay_follows_the_pack_not_the_sagging_report() {
    let dir = data_dir().join("px4_flugdrohne/ulg");
    let vehicle = px4_vehicle("log_66_2023-6-21-08-44-02");
    let configured = ["log_66", "log_65", "1x_wo_Last"];
    for log in [
        "log_66_2023-6-21-08-44-02",
        "log_65_2023-6-21-08-36-08",
        "1x_wo_Last_5m",
        "log_20_2023-6-7-10-52-56",
        "log_30_2023-6-7-12-11-06",
    ] {
        let r = Reported::of(log);
        let ulog = dir.join(format!("{log}.ulg")).display().to_string();
        let v = updates(
            &["--replay", &ulog],
            &vehicle,
            &["--every", "1", "--reserve-percent", "60"],
        );
        let air = in_air(&v);
        let tolerance = 0.03;
        let mut worst: f64 = 0.0;
        for u in &air {
            let t = num(u, "time_s");
            let (soc, want) = (num(u, "soc"), r.counted_at_stream_s(t));
            worst = worst.max((soc - want).abs());
            assert!(
                (soc - want).abs() <= tolerance,
                "{log}: {u} vs the pack's {want}"
            );
            if configured.iter().any(|c| log.starts_with(c)) {
                let px4 = r.remaining_at_stream_s(t);
                let reported = num(u, "reported_soc");
                assert!((reported - px4).abs() < 0.02, "{log}: {u} vs PX4 {px4}");
            }
        }
        // Touchdown: the first update on the ground after the last landing against the last
        // one in the air.
        let last_air = air[air.len() - 1];
        let t_last = num(last_air, "time_s");
        let after = v
            .iter()
            .find(|u| u["in_air"] == false && num(u, "time_s") > t_last);
        let rise = after.map_or(0.0, |u| num(u, "soc") - num(last_air, "soc"));
        println!("{log}: worst {worst:.3} from the pack's; rise at touchdown {rise:+.3}");
        assert!(rise <= 0.03, "{log}: rose {rise} at touchdown");
        if log.starts_with("log_66") {
            assert!(
                (r.at(r.take_off_s)[1] - 0.69).abs() < 0.01,
                "{:?}",
                r.at(r.take_off_s)
            );
            assert!(
                air.iter().any(|u| u["advice"] != "continue"),
                "{log}: continue all flight with a 60 % reserve from 60 %"
            );
        }
    }
}

/// `log_20` and `log_30` report 100 % throughout (`battery_status.remaining` 1.0 in every
/// record: PX4's estimate is not configured, `BAT1_N_CELLS` 0), while the pack sags to 9.5 and
/// 10.3 V. `log_20`'s rested voltage before take-off, 11.35 V (3.78 V a cell), is a third of a
/// LiPo's charge: the reported 100 % is not believed, the flight starts from the rested
/// voltage. On `log_30` (12.29 V rested, 4.10 V a cell, near full) the reported 100 % agrees at
/// take-off, then does not move while the charge drawn does: it is not believed from then on.
#[test]
fn data_val_live_replay_does_not_believe_a_px4_soc_that_does_not_move() {
    let dir = data_dir().join("px4_flugdrohne/ulg");
    let vehicle = px4_vehicle("log_66_2023-6-21-08-44-02");
    for log in ["log_20_2023-6-7-10-52-56", "log_30_2023-6-7-12-11-06"] {
        let r = Reported::of(log);
        assert!(r.battery.iter().all(|b| (b[1] - 1.0).abs() < 1e-9));
        let ulog = dir.join(format!("{log}.ulg")).display().to_string();
        let v = updates(&["--replay", &ulog], &vehicle, &["--every", "1"]);
        let air = in_air(&v);
        let (first, last) = (num(air[0], "soc"), num(air[air.len() - 1], "soc"));
        let rested_cell_v = r.at(r.take_off_s - 0.5)[2] / 3.0;
        println!(
            "{log}: rested {rested_cell_v:.3} V a cell; aloft take-off {first:.3}, landing \
             {last:.3}; notes {:?}",
            v.iter()
                .filter_map(|u| u["note"].as_str())
                .collect::<std::collections::BTreeSet<_>>()
        );
        if log.starts_with("log_20") {
            // 3.78 V a cell at rest: between 30 and 45 % on LiPo rest-voltage tables.
            assert!((3.75..3.80).contains(&rested_cell_v), "{rested_cell_v}");
            assert!((0.25..0.45).contains(&first), "{log}: {first}");
            assert!(air[0]["note"]
                .as_str()
                .is_some_and(|n| n.contains("not believed")));
        } else {
            assert!(last < 0.95, "{log}: {last}");
        }
        assert!(last < first, "{log}: {first} -> {last}");
    }
}

/// Every log aloft can replay among the shared ones: the PX4 and ArduPilot logs, the telemetry
/// logs and two KAIST flights.
fn replayable() -> Vec<(Vec<String>, PathBuf)> {
    let mut out = Vec::new();
    let replay = |p: &Path| vec!["--replay".to_string(), p.display().to_string()];
    for p in files("px4_flugdrohne/ulg", |n| n.ends_with(".ulg")) {
        out.push((replay(&p), p));
    }
    for p in files("flight_logs", |n| {
        let n = n.to_ascii_lowercase();
        n.ends_with(".ulg") || n.ends_with(".bin")
    }) {
        out.push((replay(&p), p));
    }
    for p in files("telemetry", |n| n.ends_with(".tlog")) {
        let args = vec![
            "--tlog".into(),
            p.display().to_string(),
            "--speed".into(),
            "max".into(),
        ];
        out.push((args, p));
    }
    let kaist = files("kaist_energy_drone", |n| n.ends_with(".csv"));
    for p in kaist.iter().take(2) {
        let mut args = replay(p);
        args.extend(["--profile".to_string(), "kaist".to_string()]);
        out.push((args, p.clone()));
    }
    out
}

/// A `{p5, p50, p95}` that is finite, non-negative, ordered, and at most `max`.
fn check_band(u: &Value, key: &str, max: f64, what: &str) {
    let Some(b) = u.get(key) else { return };
    let (p5, p50, p95) = (num(b, "p5"), num(b, "p50"), num(b, "p95"));
    assert!(
        [p5, p50, p95]
            .iter()
            .all(|x| x.is_finite() && (0.0..=max).contains(x)),
        "{what}: {key} {b}"
    );
    assert!(p5 <= p50 && p50 <= p95, "{what}: {key} {b}");
}

/// The property over every update of every replayable shared log, with the M100 (the built-in
/// vehicle: no file of these vehicles) and with the fitted PX4 quadrotor: the state of charge
/// in [0, 1], the efficiency reported in (0, 1], the energies finite and non-negative, the
/// remaining energy and the landing state of charge finite and ordered (p5 <= p50 <= p95).
#[test]
fn data_val_live_every_update_is_in_its_physical_range() {
    let px4 = px4_vehicle("log_66_2023-6-21-08-44-02");
    let mut checked = 0;
    for (source, path) in replayable() {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let vehicle = match name.ends_with(".ulg") && path.to_string_lossy().contains("flugdrohne")
        {
            true => px4.as_str(),
            false => "dji-m100",
        };
        let src: Vec<&str> = source.iter().map(String::as_str).collect();
        let every = if name.ends_with(".csv") { "60" } else { "5" };
        let v = updates(&src, vehicle, &["--every", every, "--scenarios", "50"]);
        for u in &v {
            let what = format!("{name} at {} s", u["time_s"]);
            if let Some(soc) = u["soc"].as_f64() {
                assert!((0.0..=1.0).contains(&soc), "{what}: soc {soc}");
            }
            let eta = num(u, "efficiency");
            assert!(eta > 0.0 && eta <= 1.0, "{what}: efficiency {eta}");
            let used = num(u, "energy_used_wh");
            assert!(used.is_finite() && used >= 0.0, "{what}: {used} Wh used");
            for key in ["power_w", "naive_remaining_wh"] {
                if let Some(x) = u[key].as_f64() {
                    assert!(x.is_finite() && x >= 0.0, "{what}: {key} {x}");
                }
            }
            check_band(u, "remaining_wh", f64::MAX, &what);
            check_band(u, "landing_soc", 1.0, &what);
        }
        println!("{name}: {} updates", v.len());
        checked += 1;
    }
    // 5 PX4 flights, 7 ULog/DataFlash logs, 5 telemetry logs, 2 KAIST flights.
    assert_eq!(checked, 19);
}

/// Before the pack has said anything (no report, no rested voltage, no power measured) the
/// update on the ground gives no state of charge: `log_66` starts 0.1 s before its first
/// `battery_status` record, and its first update said 100 % (the assumed full pack, shown as the
/// vehicle's) where PX4 reports 69 % a moment later. The note says what is assumed.
#[test]
fn data_val_no_state_of_charge_is_shown_before_the_pack_says_one() {
    let vehicle = px4_vehicle("log_66_2023-6-21-08-44-02");
    let log = data_dir().join("px4_flugdrohne/ulg/log_66_2023-6-21-08-44-02.ulg");
    let log = log.display().to_string();
    let v = updates(&["--replay", &log], &vehicle, &["--every", "5"]);
    let first = &v[0];
    assert_eq!(first["power_available"], false, "{first}");
    assert!(first.get("soc").is_none(), "{first}");
    assert!(
        first["note"].as_str().unwrap_or("").contains("full pack"),
        "{first}"
    );
    // From the first battery record on, every update has one.
    for u in v.iter().filter(|u| u["power_available"] == true) {
        assert!(u["soc"].is_number(), "{u}");
    }
}

/// `--start-voltage-v`: the state of charge starts from the rested voltage given, before any the
/// log gives (`log_66` rested at 11.68 V; told 11.0 V, 3.667 V a cell, 8.5 % on the generic LiPo
/// curve: 5 % + 5 % x (3.667 - 3.61) / (3.69 - 3.61)), and the charge drawn is counted from it; a
/// voltage that is not the pack's is refused naming it.
#[test]
fn data_val_live_starts_from_the_rested_voltage_given() {
    let dir = data_dir().join("px4_flugdrohne/ulg");
    let vehicle = px4_vehicle("log_66_2023-6-21-08-44-02");
    let log = "log_66_2023-6-21-08-44-02";
    let ulog = dir.join(format!("{log}.ulg")).display().to_string();
    let v = updates(
        &["--replay", &ulog],
        &vehicle,
        &["--every", "1", "--start-voltage-v", "11.0"],
    );
    let air = in_air(&v);
    let want = 0.05 + 0.05 * (11.0 / 3.0 - 3.61) / (3.69 - 3.61);
    let first = num(air[0], "soc");
    assert!((first - want).abs() < 0.02, "{first} vs {want}");
    let out = aloft(&[
        "live",
        "--replay",
        &ulog,
        "--vehicle",
        &vehicle,
        "--start-voltage-v",
        "20",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("start_voltage_v"), "{}", stderr(&out));
}

/// A pack file's `[failsafe]` is watched in flight where the flags give none (its source
/// `[failsafe]`), and a flag replaces it (its source the flag): `log_66` flown on a 3S pack file
/// whose low-voltage failsafe is 10.8 V, which the flight's loaded voltage reaches (10.16 V at
/// 25 A).
#[test]
fn data_val_live_watches_the_pack_files_failsafe() {
    let dir = data_dir().join("px4_flugdrohne/ulg");
    let vehicle = px4_vehicle("log_66_2023-6-21-08-44-02");
    let ulog = dir
        .join("log_66_2023-6-21-08-44-02.ulg")
        .display()
        .to_string();
    let pack = common::scratch("live-soc", "pack-failsafe.toml");
    std::fs::write(
        &pack,
        "[battery]\nname = \"3S-file\"\ncells_series = 3\ncapacity_mah = 5000.0\n\
         nominal_v = 11.1\nenergy_wh = 55.5\nmass_kg = 0.4\ninternal_resistance_ohm = 0.02\n\
         cutoff_cell_v = 3.3\n\n[failsafe]\nlow_voltage_v = 10.8\n",
    )
    .unwrap();
    let pack = pack.display().to_string();
    let sources = |extra: &[&str]| {
        let mut args = vec!["--every", "5", "--battery", pack.as_str()];
        args.extend(extra);
        let v = updates(&["--replay", &ulog], &vehicle, &args);
        v.iter()
            .flat_map(|u| u["failsafes"].as_array().cloned().unwrap_or_default())
            .filter(|f| f["unit"] == "V")
            .map(|f| {
                let t = f["threshold"].as_f64().unwrap();
                (f["source"].as_str().unwrap().to_string(), format!("{t}"))
            })
            .collect::<std::collections::BTreeSet<_>>()
    };
    let from_file = sources(&[]);
    assert!(
        from_file
            .iter()
            .any(|(s, t)| s == "[failsafe]" && t == "10.8"),
        "{from_file:?}"
    );
    let from_flag = sources(&["--low-voltage-v", "10.5"]);
    assert!(!from_flag.is_empty());
    assert!(
        from_flag
            .iter()
            .all(|(s, t)| s == "--low-voltage-v" && t == "10.5"),
        "{from_flag:?}"
    );
}
