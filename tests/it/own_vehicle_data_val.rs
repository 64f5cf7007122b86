//! Your own vehicle from your logs (issue 35 item 1), on the shared PX4 and ArduPilot logs:
//! `aloft fit` without a template asks by flag for what logs do not record, then writes a vehicle
//! file that flies (`endurance`, `mission` on every shared multirotor plan, `live --replay` on
//! every shared PX4 log), its envelope the autopilot's parameters (read independently: the
//! flugdrohne `*_params.csv` export, pymavlink's PARM records of the SITL log), its pack the
//! logs'. And the leave-one-out of docs/validation.md: each usable flugdrohne flight held out,
//! the vehicle fitted on the other three, its energy predicted by `aloft validate`, with one mass
//! for every flight and with per-flight masses from PX4's own hover-thrust estimate, next to the
//! naive rate (the training flights' mean power times the held-out duration).

use crate::common;

use std::path::{Path, PathBuf};

use common::{data_dir, fit_json as fit, run, scratch, strings, FLUGDROHNE_OWNER as OWNER};
use serde_json::Value;

fn flugdrohne() -> Vec<PathBuf> {
    common::files("px4_flugdrohne/ulg", |n| n.ends_with(".ulg"))
}

fn usable() -> Vec<PathBuf> {
    flugdrohne()
        .into_iter()
        .filter(|p| !p.to_string_lossy().contains("log_65"))
        .collect()
}

fn toml_of(path: &Path) -> toml::Table {
    std::fs::read_to_string(path).unwrap().parse().unwrap()
}

/// Without a template the fit asks, one flag at a time, for what the logs do not record: the
/// propellers, the mass, and (BAT1_CAPACITY is -1 in every flugdrohne log) the capacity.
#[test]
fn data_val_fit_without_a_template_asks_for_what_logs_do_not_record() {
    let out = scratch("own-vehicle", "asked.toml");
    let logs = strings(&flugdrohne());
    for (given, missing) in [
        (&[][..], "--rotor-diameter-m"),
        (&["--rotor-diameter-m", "0.254"][..], "--mass-kg"),
        (
            &["--rotor-diameter-m", "0.254", "--mass-kg", "1.2"][..],
            "--battery-capacity-mah",
        ),
    ] {
        let (code, _, err) = fit(&logs, given, &out);
        assert_eq!(code, 2, "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(&format!("missing {missing}")), "{err}");
    }
    assert!(!out.exists(), "nothing is written on bad input");
}

/// The complete vehicle of the five flugdrohne logs: log_65 skipped by name, the envelope the
/// autopilot's (the params.csv export: MPC_TILTMAX_AIR 45, MPC_XY_VEL_MAX 12 and 20, the smaller
/// written; MPC_Z_VEL_MAX_UP 3; MPC_Z_VEL_MAX_DN 1.5 and 2; MPC_ACC_HOR 3; MPC_XY_CRUISE 5), 3
/// cells, the given capacity, the measured resistance in the range `aloft pack fit` measures
/// on these logs (docs/validation.md: 0.031-0.049 ohm), and a vehicle that flies.
#[test]
fn data_val_the_fitted_vehicle_is_complete_and_flies() {
    let out = scratch("own-vehicle", "flugdrohne.toml");
    let (code, v, err) = fit(&strings(&flugdrohne()), &OWNER, &out);
    assert_eq!(code, 0, "{err}");
    let skipped = v["skipped_logs"].as_array().unwrap();
    assert_eq!(skipped.len(), 1, "{v}");
    assert!(skipped[0]["file"].as_str().unwrap().contains("log_65"));
    assert!(v["quality"].is_string() && v["quality_reasons"].is_array());
    let file = toml_of(&out);
    assert_eq!(file["name"].as_str(), Some("flugdrohne"));
    let a = &file["airframe"];
    for (key, want) in [
        ("max_tilt_deg", 45.0),
        ("max_speed_mps", 12.0),
        ("max_climb_rate_mps", 3.0),
        ("max_descent_rate_mps", 1.5),
        ("acceleration_mps2", 3.0),
        ("cruise_speed_mps", 5.0),
    ] {
        assert_eq!(a[key].as_float(), Some(want), "{key}: {a}");
    }
    let b = &file["battery"].as_array().unwrap()[0];
    assert_eq!(b["cells_series"].as_integer(), Some(3));
    assert_eq!(b["capacity_mah"].as_float(), Some(5000.0));
    let r = b["internal_resistance_ohm"].as_float().unwrap();
    assert!((0.031..=0.049).contains(&r), "{r}");
    // Airframe + pack is the stated take-off mass.
    let total = a["mass_kg"].as_float().unwrap() + b["mass_kg"].as_float().unwrap();
    assert!((total - 1.2).abs() < 1e-6, "{total}");
    let vehicle = out.display().to_string();
    let (code, _, err) = run(&["endurance", "--vehicle", &vehicle]);
    assert_eq!(code, 0, "{err}");
    // Every shared plan a multirotor flies (two are VTOL plans, refused for any vehicle).
    let mut flown = 0;
    for plan in common::files("missions", |n| !n.ends_with(".md")) {
        let plan = plan.display().to_string();
        let (code, _, err) = run(&["mission", &plan, "--vehicle", &vehicle]);
        let (builtin, _, _) = run(&["mission", &plan]);
        if builtin == 2 {
            assert_eq!(code, 2, "{plan}: {err}");
            continue;
        }
        assert!(code == 0 || code == 1, "{plan}: exit {code}: {err}");
        flown += 1;
    }
    assert!(flown >= 10, "{flown}");
    // Followed as if live: every update's figures in their physical range.
    for log in flugdrohne() {
        let log = log.display().to_string();
        let args = [
            "live",
            "--replay",
            &log,
            "--vehicle",
            &vehicle,
            "--every",
            "5",
            "--format",
            "json",
        ];
        let (code, out, err) = run(&args);
        assert!(code == 0 || code == 1, "{log}: exit {code}: {err}");
        let updates: Vec<Value> = out
            .lines()
            .filter_map(|l| serde_json::from_str::<Value>(l).ok())
            .filter(|u| u.get("time_s").is_some())
            .collect();
        assert!(!updates.is_empty(), "{log}");
        for u in &updates {
            if let Some(soc) = u["soc"].as_f64() {
                assert!((0.0..=1.0).contains(&soc), "{log}: soc {soc}");
            }
            let eta = u["efficiency"].as_f64().unwrap();
            assert!(eta > 0.0 && eta <= 1.0, "{log}: efficiency {eta}");
            for band in ["remaining_wh", "landing_soc"] {
                if let Some(b) = u.get(band) {
                    let p: Vec<f64> = ["p5", "p50", "p95"]
                        .iter()
                        .map(|k| b[k].as_f64().unwrap())
                        .collect();
                    assert!(p.iter().all(|x| x.is_finite() && *x >= 0.0), "{log}: {b}");
                    assert!(p[0] <= p[1] && p[1] <= p[2], "{log}: {band} {b}");
                }
            }
        }
    }
}

/// The ArduPilot SITL log records its capacity (BATT_CAPACITY 3300) and envelope, read by
/// pymavlink 2.4.50 from its PARM records: ANGLE_MAX 3000 cdeg, WPNAV_SPEED 1000 cm/s,
/// WPNAV_SPEED_UP 250, WPNAV_SPEED_DN 150, WPNAV_ACCEL 250, WPNAV_ACCEL_Z 100, RTL_ALT 1500 cm;
/// ATC_RATE_Y_MAX 0 (no limit) keeps the template's yaw rate.
#[test]
fn data_val_an_ardupilot_log_gives_its_capacity_and_envelope() {
    let out = scratch("own-vehicle", "sitl.toml");
    let log = data_dir().join("flight_logs/sitl_ac47_00000002.BIN");
    let (code, _, err) = fit(
        &strings(&[log]),
        &["--mass-kg", "1.5", "--rotor-diameter-m", "0.254"],
        &out,
    );
    assert_eq!(code, 0, "{err}");
    let file = toml_of(&out);
    let a = &file["airframe"];
    for (key, want) in [
        ("max_tilt_deg", 30.0),
        ("max_speed_mps", 10.0),
        ("cruise_speed_mps", 10.0),
        ("max_climb_rate_mps", 2.5),
        ("max_descent_rate_mps", 1.5),
        ("acceleration_mps2", 2.5),
        ("vertical_acceleration_mps2", 1.0),
        ("rtl_altitude_m", 15.0),
        ("yaw_rate_deg_s", 90.0),
    ] {
        let got = a[key].as_float().unwrap();
        assert!((got - want).abs() < 1e-9, "{key}: {got} against {want}");
    }
    let b = &file["battery"].as_array().unwrap()[0];
    assert_eq!(b["capacity_mah"].as_float(), Some(3300.0));
}

/// A per-log payload is parsed, bounded and used: a bad value or key is exit 2 naming it.
#[test]
fn per_log_payload_is_checked() {
    let log = usable()[0].display().to_string();
    let out = scratch("own-vehicle", "payload.toml");
    for (arg, needle) in [
        (format!("{log}:payload_kg=heavy"), "payload_kg 'heavy'"),
        (format!("{log}:payload_kg=-1"), "payload_kg '-1'"),
        (format!("{log}:mass=2"), "'mass' is not a per-log option"),
    ] {
        let (code, _, err) = fit(&[arg], &OWNER, &out);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(needle), "{err}");
    }
    // The owner's values in their ranges, named (before any log is read).
    for (flag, value) in [
        ("--mass-kg", "0"),
        ("--rotor-diameter-m", "-0.254"),
        ("--battery-capacity-mah", "1e9"),
        ("--battery-mass-kg", "0"),
        ("--max-takeoff-mass-kg", "nan"),
    ] {
        // The owner's flags with this one's value in place (or added), as `--flag=value`.
        let mut args: Vec<String> = OWNER
            .chunks(2)
            .filter(|kv| kv[0] != flag)
            .map(|kv| format!("{}={}", kv[0], kv[1]))
            .collect();
        args.push(format!("{flag}={value}"));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = fit(std::slice::from_ref(&log), &args, &out);
        assert_eq!(code, 2, "{flag} {value}: {err}");
        assert!(err.contains(flag), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
    // A file whose whole name exists is that file, whatever its name holds.
    let odd = scratch("own-vehicle", "odd:payload_kg=2.ulg");
    std::fs::copy(&log, &odd).unwrap();
    let (code, v, err) = fit(&[odd.display().to_string()], &OWNER, &out);
    assert_eq!(code, 0, "{err}");
    assert_eq!(v["logs"][0]["file"].as_str(), odd.to_str());
}

/// PX4's own hover-thrust estimate of a log (`hover_thrust_estimate.hover_thrust`, median of the
/// valid records), read from the per-topic CSV export, not through aloft.
fn hover_thrust(log: &Path) -> f64 {
    let stem = log.file_stem().unwrap().to_string_lossy();
    let csv = data_dir().join(format!(
        "px4_flugdrohne/csv/{stem}_hover_thrust_estimate_0.csv"
    ));
    let mut reader = csv::Reader::from_path(&csv).unwrap();
    let headers = reader.headers().unwrap().clone();
    let col = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let (h, valid) = (col("hover_thrust"), col("valid"));
    let mut v: Vec<f64> = reader
        .records()
        .map(|r| r.unwrap())
        .filter(|r| r[valid].trim() == "1" || r[valid].trim().eq_ignore_ascii_case("true"))
        .map(|r| r[h].parse::<f64>().unwrap())
        .collect();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// `aloft validate --vehicle V --log L --format json`'s one flight.
fn validate(vehicle: &Path, log: &str) -> Value {
    let vehicle = vehicle.display().to_string();
    let (code, out, err) = run(&[
        "validate",
        "--vehicle",
        &vehicle,
        "--log",
        log,
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{log}: {err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    v["flights"][0].clone()
}

/// Leave one out over the four usable flugdrohne flights (docs/validation.md). Per-flight
/// masses: `1x_wo_Last_5m` ("without load") at the stated 1.2 kg, each other flight at 1.2 kg
/// times its hover thrust over that flight's (PX4's thrust model, THR_MDL_FAC = 0 in every
/// log: thrust linear in the command). The estimate saturates at 0.7 (MPC_THR_HOVER 0.5 +
/// HTE_THR_RANGE 0.2) on log_20 and log_30, so their masses are lower bounds.
#[test]
fn data_val_leave_one_out_with_per_flight_masses() {
    let logs = usable();
    let unloaded = logs
        .iter()
        .find(|p| p.to_string_lossy().contains("wo_Last"))
        .unwrap();
    let h0 = hover_thrust(unloaded);
    let payload = |p: &Path| 1.2 * (hover_thrust(p) / h0 - 1.0).max(0.0);
    let mut rows = Vec::new();
    for (i, held) in logs.iter().enumerate() {
        let train: Vec<&PathBuf> = logs
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, p)| p)
            .collect();
        // The naive rate: the training flights' mean measured power times the held-out time.
        let mut row = Vec::new();
        for per_flight in [false, true] {
            let arg = |p: &Path| match per_flight {
                true => format!("{}:payload_kg={:.4}", p.display(), payload(p)),
                false => p.display().to_string(),
            };
            let out = scratch("own-vehicle", &format!("loo-{i}-{per_flight}.toml"));
            let train_args: Vec<String> = train.iter().map(|p| arg(p)).collect();
            let (code, _, err) = fit(&train_args, &OWNER, &out);
            assert_eq!(code, 0, "{err}");
            let f = validate(&out, &arg(held));
            row.push(f["energy_error_percent"].as_f64().unwrap());
            if !per_flight {
                let (mut e, mut t) = (0.0, 0.0);
                for p in &train {
                    let g = validate(&out, &p.display().to_string());
                    e += g["measured_energy_wh"].as_f64().unwrap();
                    t += g["duration_s"].as_f64().unwrap();
                }
                let naive = e / t * f["duration_s"].as_f64().unwrap();
                let measured = f["measured_energy_wh"].as_f64().unwrap();
                row.push(100.0 * (naive - measured) / measured);
            }
        }
        let name = held.file_stem().unwrap().to_string_lossy().to_string();
        eprintln!(
            "held out {name}: payload {:.3} kg; one mass {:+.1} %, naive {:+.1} %, per-flight masses {:+.1} %",
            payload(held),
            row[0],
            row[1],
            row[2]
        );
        rows.push(row);
    }
    let mean_abs = |k: usize| rows.iter().map(|r| r[k].abs()).sum::<f64>() / rows.len() as f64;
    eprintln!(
        "mean |error|: one mass {:.1} %, naive {:.1} %, per-flight masses {:.1} %",
        mean_abs(0),
        mean_abs(1),
        mean_abs(2)
    );
    for r in &rows {
        assert!(r.iter().all(|x| x.is_finite()), "{r:?}");
    }
    // The claim of docs/validation.md: the flights' own masses beat one mass for all.
    assert!(mean_abs(2) < mean_abs(0), "{rows:?}");
}

/// Issue 41 items 6 and 11: the owner's capacity below 10 mA h is refused with its range (a pack
/// that small is a unit slip); a subnormal `max_speed` (1e-310 m/s) in the written vehicle's
/// `[airframe]` or given to `aloft plan --max-speed` is refused naming it, and nothing is written.
#[test]
fn data_val_a_tiny_capacity_or_a_subnormal_speed_is_refused() {
    let log = usable()[0].display().to_string();
    let out = scratch("own-vehicle", "tiny.toml");
    for value in ["5", "1e-38"] {
        let mut args: Vec<String> = OWNER
            .chunks(2)
            .filter(|kv| kv[0] != "--battery-capacity-mah")
            .map(|kv| format!("{}={}", kv[0], kv[1]))
            .collect();
        args.push(format!("--battery-capacity-mah={value}"));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = fit(std::slice::from_ref(&log), &args, &out);
        assert_eq!(code, 2, "{value}: {err}");
        assert!(
            err.contains("--battery-capacity-mah") && err.contains("10"),
            "{err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
    assert!(!out.exists());
    let vehicle = scratch("own-vehicle", "subnormal.toml");
    let (code, _, err) = fit(std::slice::from_ref(&log), &OWNER, &vehicle);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&vehicle).unwrap();
    let mut file: toml::Table = text.parse().unwrap();
    file["airframe"]["max_speed_mps"] = toml::Value::Float(1e-310);
    assert!(file["airframe"]["max_speed_mps"]
        .as_float()
        .unwrap()
        .is_subnormal());
    std::fs::write(&vehicle, toml::to_string(&file).unwrap()).unwrap();
    let (code, _, err) = run(&["endurance", "--vehicle", vehicle.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("max_speed_mps"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let plan = data_dir().join("missions/kasperg3_uas_test_plan.plan");
    let folder = scratch("own-vehicle", "subnormal-plan");
    let (code, _, err) = run(&[
        "plan",
        plan.to_str().unwrap(),
        "--max-speed",
        "1e-310",
        "-o",
        folder.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("max_speed"), "{err}");
    assert!(std::fs::read_dir(&folder).map_or(true, |mut d| d.next().is_none()));
}
