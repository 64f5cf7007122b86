//! The input contract (issue 13), one test per class of finding of the black-box study: every bad
//! input ends with exit 2 and one stderr line naming what is wrong, in bounded time and memory;
//! never a signal, never NaN or inf in an output.

use crate::common;
use common::{aloft, assert_refused};

use std::io::Write as _;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// `aloft args` under a virtual-memory limit (KiB) and a time limit: its exit code (None for a
/// signal, or when it had to be killed), stderr, and how long it took.
fn aloft_limited(
    args: &[&str],
    memory_kib: u64,
    limit: Duration,
) -> (Option<i32>, String, Duration) {
    let script = format!("ulimit -v {memory_kib}; exec \"$0\" \"$@\"");
    let mut child = Command::new("sh")
        // `ulimit -v` bounds address space, a proxy for memory: one malloc arena per thread
        // (glibc reserves 64 MiB of address space for each, used or not) would count the
        // signal-handling thread of the command line (`src/cli/signals.rs`) as 64 MiB of
        // memory; with one arena only the memory the run allocates counts.
        .env("MALLOC_ARENA_MAX", "1")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_aloft"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let start = Instant::now();
    let Some(status) = common::wait_within(&mut child, limit) else {
        return (None, "killed: took too long".into(), start.elapsed());
    };
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = std::io::Read::read_to_string(&mut e, &mut err);
    }
    (status.code(), err, start.elapsed())
}

/// A scratch file `name` of this test process, as a command-line word.
fn tmp(name: &str) -> String {
    let path = common::scratch("contract", name);
    path.display().to_string()
}

const TAKE_OFF: &str =
    "[[segment]]\nkind = \"take-off\"\naltitude_m = 20.0\nclimb_rate_mps = 2.0\n";
const LANDING: &str = "[[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n";

fn mission_with(middle: &str, name: &str) -> String {
    let p = tmp(name);
    std::fs::write(&p, format!("{TAKE_OFF}{middle}{LANDING}")).unwrap();
    p
}

#[test]
fn non_finite_numeric_flags_are_refused_naming_the_flag() {
    let cases: &[(&[&str], &str)] = &[
        (&["mission", "--payload-kg", "nan"], "--payload-kg"),
        (&["mission", "--time-step", "inf"], "--time-step"),
        (
            &["mission", "--reserve-percent", "NaN"],
            "--reserve-percent",
        ),
        (
            &["mission", "--wind-speed", "1e999", "--wind-from", "0"],
            "--wind-speed",
        ),
        (&["mission", "--replay", "x.csv", "--lag", "nan"], "--lag"),
        (&["endurance", "--course", "inf"], "--course"),
        (
            &["endurance", "--orbit-radius", "nan", "--orbit-speed", "5"],
            "--orbit-radius",
        ),
        (&["power", "--roll=-inf"], "--roll"),
        (
            &["propulsion", "--takeoff-mass-kg", "nan"],
            "--takeoff-mass-kg",
        ),
        (&["rotor", "--voltage", "NaN"], "--voltage"),
        (&["log", "info", "x.csv", "--max-lag", "inf"], "--max-lag"),
        (
            &[
                "fit",
                "--log",
                "x.csv",
                "--vehicle-template",
                "dji-m100",
                "-o",
                "o.toml",
                "--lag",
                "nan",
            ],
            "--lag",
        ),
        (
            &[
                "validate",
                "--log",
                "x.csv",
                "--vehicle",
                "dji-m100",
                "--calibrate-first",
                "inf",
            ],
            "--calibrate-first",
        ),
    ];
    for (args, flag) in cases {
        assert_refused(args, &["not a finite number", flag]);
    }
}

#[test]
fn huge_finite_inputs_are_refused_not_overflowed() {
    assert_refused(
        &["power", "--airspeed", "1e308"],
        &["airspeed_mps", "1e308"],
    );
    assert_refused(&["power", "--climb-rate", "-1e300"], &["climb_rate_mps"]);
    let text = std::fs::read_to_string("fixtures/vehicles/dji-m100.toml").unwrap();
    for (from, to, key) in [
        ("mass_kg = 2.355", "mass_kg = 1e308", "mass_kg"),
        (
            "mu3_n_s3_per_m3 = 0.004045",
            "mu3_n_s3_per_m3 = 1e300",
            "mu3_n_s3_per_m3",
        ),
        (
            "max_speed_mps = 17.0",
            "max_speed_mps = 1e300",
            "max_speed_mps",
        ),
        (
            "capacity_mah = 4500.0",
            "capacity_mah = 1e300",
            "capacity_mah",
        ),
    ] {
        let p = tmp(&format!("huge-{key}.toml"));
        std::fs::write(&p, text.replacen(from, to, 1)).unwrap();
        assert_refused(&["endurance", "--vehicle", &p], &[key]);
    }
    let aec = std::fs::read_to_string("fixtures/vehicles/aec-quadrotor.toml").unwrap();
    let p = tmp("huge-aec.toml");
    std::fs::write(
        &p,
        aec.replacen("kv_rpm_per_v = 515.0", "kv_rpm_per_v = 1e300", 1),
    )
    .unwrap();
    assert_refused(&["propulsion", "--vehicle", &p], &["Kv"]);
    assert_refused(
        &[
            "propulsion",
            "--vehicle",
            "aec-quadrotor",
            "--payload-kg",
            "1e300",
        ],
        &["payload_kg"],
    );
    assert_refused(
        &["mission", "--wind-speed", "1e300", "--wind-from", "0"],
        &["wind_speed_mps"],
    );
}

#[test]
fn a_tiny_ground_speed_or_a_huge_hold_is_refused_at_once() {
    let slow = mission_with(
        "[[segment]]\nkind = \"leg\"\neast_m = 100.0\nnorth_m = 0.0\nground_speed_mps = 1e-320\n",
        "slow.toml",
    );
    let plot = tmp("slow.svg");
    let (code, err, took) = aloft_limited(
        &["mission", &slow, "--plot", &plot],
        2_000_000,
        Duration::from_secs(20),
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("segment 2 (leg)") && err.contains("would take"),
        "{err}"
    );
    assert!(took < Duration::from_secs(10), "{took:?}");
    let hold = mission_with(
        "[[segment]]\nkind = \"hover\"\nduration_s = 1e9\n",
        "hold.toml",
    );
    assert_refused(&["mission", &hold], &["duration_s", "1000000000"]);
}

#[test]
fn a_tiny_time_step_ends_in_bounded_time_naming_the_step_to_use() {
    let (code, err, took) = aloft_limited(
        &["mission", "--time-step", "1e-9"],
        2_000_000,
        Duration::from_secs(60),
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("raise the time step"), "{err}");
    assert!(took < Duration::from_secs(30), "{took:?}");
}

#[test]
fn output_files_do_not_make_memory_grow_with_the_flight() {
    // A 5-minute hover at 1 ms (300,000 samples) on a hypothetical pack sized for it: the time
    // series, MCAP and chart stream as the flight is flown.
    let text = std::fs::read_to_string("fixtures/vehicles/dji-m100.toml").unwrap();
    let big_pack = text
        .replacen("max_takeoff_mass_kg = 3.6", "max_takeoff_mass_kg = 4.0", 1)
        .replacen("capacity_mah = 4500.0", "capacity_mah = 45000.0", 1)
        .replacen("energy_wh = 99.9", "energy_wh = 999.0", 1);
    let vehicle = tmp("big-pack.toml");
    std::fs::write(&vehicle, big_pack).unwrap();
    let mission = mission_with(
        "[[segment]]\nkind = \"hover\"\nduration_s = 300.0\n",
        "hover.toml",
    );
    let (csv, mcap, svg) = (tmp("hover.csv"), tmp("hover.mcap"), tmp("hover.svg"));
    // 185 MB of address space: the run needs 120-140 MB (most of it zstd's buffers for MCAP
    // chunks) besides the debug binary's own mappings (measured in all: 170-172 MB with the
    // bundled SQLite of `aloft logbook`, about 26 MiB of loaded code and data, 168-170 MB
    // without it); the code that kept every sample (250 bytes each, in a vector that doubles)
    // needed 200-260 MB for this flight (measured) and does not fit.
    let (code, err, _) = aloft_limited(
        &[
            "mission",
            &mission,
            "--vehicle",
            &vehicle,
            "--time-step",
            "0.001",
            "--timeseries",
            &csv,
            "--mcap",
            &mcap,
            "--plot",
            &svg,
        ],
        185_000,
        Duration::from_secs(300),
    );
    assert!(code == Some(0) || code == Some(1), "{code:?}: {err}");
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count();
    // One row per 1 ms step of the take-off, the hover and the landing, plus the header.
    assert!(rows > 300_000, "{rows}");
    let svg_text = std::fs::read_to_string(&svg).unwrap();
    assert!(svg_text.contains("ground track") && !svg_text.contains("NaN"));
    for p in [csv, mcap, svg] {
        let _ = std::fs::remove_file(p);
    }
}

#[cfg(unix)]
#[test]
fn a_fifo_given_as_input_is_refused_without_blocking() {
    let fifo = tmp("fifo");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        return; // no mkfifo here: nothing to test
    }
    let f = fifo.as_str();
    let cases: Vec<Vec<&str>> = vec![
        vec!["mission", f],
        vec!["mission", "--vehicle", f],
        vec!["mission", "--wind-field", f],
        vec!["power", "--input", f],
        vec!["rotor", "--rotor", f],
        vec!["log", "info", f, "--profile", "kaist"],
    ];
    for args in cases {
        let (code, err, took) = aloft_limited(&args, 2_000_000, Duration::from_secs(10));
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(err.contains("FIFO"), "{args:?}: {err}");
        assert!(took < Duration::from_secs(5), "{args:?}: {took:?}");
    }
    std::fs::remove_file(&fifo).unwrap();
}

#[test]
fn coordinates_and_orbits_out_of_range_are_named() {
    let home = "[home]\nlatitude_deg = 47.0\nlongitude_deg = 8.0\n";
    let leg = |lat: &str, lon: &str| {
        format!("{home}{TAKE_OFF}[[segment]]\nkind = \"leg\"\nlatitude_deg = {lat}\nlongitude_deg = {lon}\nground_speed_mps = 5.0\n{LANDING}")
    };
    for (lat, lon, key) in [
        ("47.001", "181.0", "longitude_deg"),
        ("91.0", "8.0", "latitude_deg"),
    ] {
        let p = tmp(&format!("coord-{key}.toml"));
        std::fs::write(&p, leg(lat, lon)).unwrap();
        assert_refused(&["mission", &p], &[key]);
    }
    // A circle too tight for the speed is flown slower (at the speed the tilt allows), but one
    // of a nanometre cannot be turned at any speed worth the name: refused, naming the radius.
    assert_refused(
        &["endurance", "--orbit-radius", "1e-9", "--orbit-speed", "5"],
        &["orbit radius_m = 1e-9 m", "1 % of the speed"],
    );
}

#[test]
fn a_repeated_csv_column_is_refused() {
    let states = tmp("dup-states.csv");
    std::fs::write(
        &states,
        "airspeed_mps,roll_deg,pitch_deg,roll_deg\n5,0,-5,1\n",
    )
    .unwrap();
    assert_refused(&["power", "--input", &states], &["roll_deg", "twice"]);
    let grid = tmp("dup-grid.csv");
    common::write_wind_grid_with_columns(
        &grid,
        "x_m,y_m,z_m,u_mps,v_mps,w_mps,u_mps",
        [500.0, 100.0],
        "1,0,0,2",
    );
    assert_refused(&["mission", "--wind-field", &grid], &["u_mps", "twice"]);
}

#[test]
fn a_mission_of_too_many_segments_is_refused_in_bounded_memory() {
    let p = tmp("many.toml");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&p).unwrap());
    f.write_all(TAKE_OFF.as_bytes()).unwrap();
    for k in 0..60_000 {
        write!(
            f,
            "[[segment]]\nkind = \"leg\"\neast_m = {}\nnorth_m = 0.0\nground_speed_mps = 5.0\n",
            (k % 2) * 10
        )
        .unwrap();
    }
    f.write_all(LANDING.as_bytes()).unwrap();
    drop(f);
    let (code, err, _) = aloft_limited(&["mission", &p], 1_500_000, Duration::from_secs(60));
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("60002 segments") && err.contains("50000"),
        "{err}"
    );
    let _ = std::fs::remove_file(p);
}

#[test]
fn successful_answers_carry_no_null_nan_or_inf() {
    for args in [
        vec!["mission", "--format", "json"],
        vec![
            "endurance",
            "--format",
            "json",
            "--orbit-radius",
            "30",
            "--orbit-speed",
            "5",
        ],
        vec!["endurance", "--format", "json", "--sweep-speed", "1"],
        vec![
            "power",
            "--format",
            "json",
            "--airspeed",
            "8",
            "--pitch",
            "-10",
            "--gradient",
        ],
        vec![
            "propulsion",
            "--format",
            "json",
            "--sweep-takeoff-mass",
            "7:30:1",
        ],
        vec!["rotor", "--rotor", "mn1806-6x2", "--format", "json"],
    ] {
        let o = aloft(&args);
        assert!(o.status.code().is_some_and(|c| c <= 1), "{args:?}");
        let text = String::from_utf8(o.stdout).unwrap();
        for bad in ["null", "NaN", "inf"] {
            assert!(!text.contains(bad), "{args:?} prints {bad}");
        }
    }
}

/// Regressions (issue 32, papercuts): a payload of 1e308 kg printed a 310-digit take-off mass; a
/// start of 1e308 % said "start_soc = 1e306  is invalid: expected a fraction in (empty point,
/// 1]". Values are checked in the user's units and printed so.
#[test]
fn huge_values_are_named_in_their_units_without_hundreds_of_digits() {
    for (args, needles) in [
        (
            vec!["mission", "--payload-kg", "1e308"],
            vec!["payload_kg = 1e308 kg", "from 0 to 1e7 kg"],
        ),
        (
            vec!["mission", "--start-percent", "1e308"],
            vec!["start_percent = 1e308 %", "at most 100 %"],
        ),
        (
            vec!["endurance", "--payload-kg", "1e308"],
            vec!["1.000e308 kg"],
        ),
    ] {
        assert_refused(&args, &needles);
        let err = common::stderr(&aloft(&args));
        // No run of 20 digits anywhere, and no double space before a missing unit.
        let digits = err
            .split(|c: char| !c.is_ascii_digit())
            .map(str::len)
            .max()
            .unwrap_or(0);
        assert!(digits < 20 && !err.contains("  "), "{args:?}: {err}");
    }
}

/// Regression (issue 32, papercuts): a plan of 20,000 waypoints and no DO_JUMP was refused as "a
/// loop repeated too often". It is flown (the planner bounds its segments, not the reader).
#[test]
fn a_long_waypoint_file_without_jumps_is_flown() {
    let p = tmp("long.waypoints");
    let mut text = String::from("QGC WPL 110\n0\t1\t0\t16\t0\t0\t0\t0\t-35.0\t149.0\t100.0\t1\n");
    text.push_str("1\t0\t3\t22\t0\t0\t0\t0\t0\t0\t20\t1\n");
    for k in 0..20_500u32 {
        // Back and forth over 20 m, 1e-4 deg north (11 m) each way.
        let lat = -35.0 + if k % 2 == 0 { 1e-4 } else { 0.0 };
        text.push_str(&format!(
            "{}\t0\t3\t16\t0\t0\t0\t0\t{lat}\t149.0\t20\t1\n",
            k + 2
        ));
    }
    std::fs::write(&p, text).unwrap();
    // A coarse step: the route is long (20,500 legs), the point is that it is read.
    let o = aloft(&["mission", &p, "--time-step", "2", "--format", "json"]);
    let err = common::stderr(&o);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{err}");
    assert!(!err.contains("loop"), "{err}");
    let _ = std::fs::remove_file(p);
}

/// `--display-component-id` is the component aloft's battery and texts come from on the
/// vehicle's system, 1-255: 0 is MAVLink's broadcast id, not a sender's, and is refused with
/// one line naming it (exit 2), as is anything outside a byte.
#[test]
fn a_display_component_id_of_0_is_refused_naming_it() {
    for bad in ["0", "256", "-1", "x"] {
        let (code, out, err) = common::run(&[
            "live",
            "--replay",
            "no-such.ulg",
            "--display-component-id",
            bad,
        ]);
        assert_eq!(code, 2, "{bad}: {out} {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains("--display-component-id"), "{bad}: {err}");
        assert!(err.contains(bad), "{bad}: {err}");
    }
    use aloft::engine::{flags::LiveFlags, parse_keywords};
    let replay = [("replay", aloft::engine::Keyword::One("x.ulg".into()))];
    let default = parse_keywords::<LiveFlags>("aloft.live", &replay, &[]).unwrap();
    assert_eq!(default.display_component_id, 191);
}

/// `--battery-id` is a MAVLink battery id, 0-255: anything else is refused with one line naming
/// it (exit 2), on the command line and as Python's or the page's `battery_id` keyword.
#[test]
fn a_battery_id_outside_0_255_is_refused_naming_it() {
    for bad in ["256", "-1", "1.5", "x", "1e3"] {
        let (code, out, err) =
            common::run(&["live", "--replay", "no-such.ulg", "--battery-id", bad]);
        assert_eq!(code, 2, "{bad}: {out} {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains("--battery-id"), "{bad}: {err}");
        assert!(err.contains(bad), "{bad}: {err}");
    }
    use aloft::engine::{flags::LiveFlags, parse_keywords, Keyword};
    let kw = |v: &str| vec![("battery_id".to_string(), Keyword::One(v.into()))];
    let replay = [("replay", Keyword::One("x.ulg".into()))];
    let err = parse_keywords::<LiveFlags>("aloft.live", &replay, &kw("300"))
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(err.contains("'battery_id' of aloft.live"), "{err}");
    let ok = parse_keywords::<LiveFlags>("aloft.live", &replay, &kw("255")).unwrap();
    assert_eq!(ok.battery_id, 255);
    let default = parse_keywords::<LiveFlags>("aloft.live", &replay, &[]).unwrap();
    assert_eq!(default.battery_id, aloft::engine::DEFAULT_BATTERY_ID);
}

/// The voltage failsafes of `aloft live --route log` are checked as on the followed route: a
/// threshold that is not a positive voltage (0, negative, NaN) is refused with one line naming
/// the flag (exit 2), before the log is read.
#[test]
fn a_route_log_voltage_threshold_that_is_not_positive_is_refused_naming_it() {
    let log = common::fixture("logs", "kaist_small.csv")
        .display()
        .to_string();
    for flag in ["--low-voltage-v", "--critical-voltage-v"] {
        for bad in ["0", "-1", "NaN"] {
            let given = format!("{flag}={bad}");
            let args = [
                "live",
                "--replay",
                log.as_str(),
                "--profile",
                "kaist",
                "--route",
                "log",
                given.as_str(),
            ];
            assert_refused(&args, &[flag.trim_start_matches('-')]);
        }
    }
}
