//! The flight envelope as a limit the vehicle flies at (issue 23): per limit (tilt, airspeed,
//! climb rate, orbit bank), a segment that asks for more is flown at the limit, and the ground
//! speed it holds is checked against an independent calculation here (the drag polynomial of
//! power seed eq (6) with the vehicle file's constants, solved by bisection in the test). A wind
//! beyond the vehicle is an infeasible mission (exit 1 with the answer), never "bad input".

use crate::common;
use common::run as aloft;

use aloft::power::ModelOptions;
use aloft::vehicle::VehicleFile;
use aloft_planner::{
    plan, Aircraft, Airframe, Limit, MissionReport, MissionSpec, Pack, PlanOptions, PowerSource,
    Sample, Wind,
};

/// The built-in M100 (its default TB47D pack) with its airframe as given, or changed by `edit`.
fn m100_with(edit: impl FnOnce(&mut aloft_planner::AirframeSpec)) -> (Aircraft, Pack) {
    let f = VehicleFile::builtin("dji-m100").unwrap();
    let (a, _) = f.aircraft(ModelOptions::default()).unwrap();
    let mut spec = a.airframe().spec().clone();
    edit(&mut spec);
    let PowerSource::FourTerm { vehicle, options } = a.source() else {
        panic!("the M100 flies the four-term model");
    };
    let aircraft = Aircraft::four_term(Airframe::new(spec).unwrap(), vehicle.clone(), *options);
    (aircraft, f.battery(None).unwrap())
}

fn fly(aircraft: &Aircraft, pack: &Pack, text: &str, wind: &Wind) -> MissionReport {
    let mission = MissionSpec::from_toml_str(text)
        .unwrap()
        .compile(aircraft.airframe(), pack.mass_kg(), None)
        .unwrap();
    let opts = PlanOptions {
        record_samples: true,
        ..PlanOptions::default()
    };
    plan(aircraft, pack, &mission, wind, &opts).unwrap()
}

/// The airspeed at which the vehicle's cubic drag `f_D(v) = mu1 v + mu2 v^2 + mu3 v^3` (power
/// seed eq 6) balances `force_n`, by bisection on the polynomial.
fn airspeed_at_drag(aircraft: &Aircraft, force_n: f64) -> f64 {
    let (mu1, mu2, mu3) = aircraft.drag().coefficients();
    let f = |v: f64| mu1 * v + mu2 * v * v + mu3 * v * v * v - force_n;
    // The root of the increasing `f` in [0, 100], to rounding.
    aloft_core::bisect(0.0, 100.0, 200, |v| f(v) < 0.0).0
}

/// Speed along the path of a sample, m/s.
fn speed(s: &Sample) -> f64 {
    (s.vel_east_mps.powi(2) + s.vel_north_mps.powi(2) + s.vel_up_mps.powi(2)).sqrt()
}

/// The samples of segment `segment` (from 1) in the middle half of its time.
fn middle(r: &MissionReport, segment: usize) -> Vec<Sample> {
    let of: Vec<&Sample> = r.samples.iter().filter(|s| s.segment == segment).collect();
    let (a, b) = (of[0].time_s, of[of.len() - 1].time_s);
    of.into_iter()
        .filter(|s| s.time_s > a + 0.25 * (b - a) && s.time_s < b - 0.25 * (b - a))
        .copied()
        .collect()
}

const TAKE_OFF: &str =
    "[[segment]]\nkind = \"take-off\"\naltitude_m = 30.0\nclimb_rate_mps = 2.0\n";
const LAND: &str = "[[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n";

#[test]
fn into_a_headwind_past_the_tilt_limit_the_leg_is_flown_at_the_tilt_limited_airspeed() {
    // 12 m/s east into a 10 m/s wind from the east: 22 m/s of airspeed needs more than the
    // M100's 35 deg. At the limit in steady level flight `f_D(A) = m g tan(35 deg)`, and the
    // vehicle holds `A - 10` over the ground.
    let (aircraft, pack) = m100_with(|_| {});
    let text = format!(
        "{TAKE_OFF}[[segment]]\nkind = \"leg\"\neast_m = 1200.0\nnorth_m = 0.0\nground_speed_mps = 12.0\n\
         [[segment]]\nkind = \"return\"\nground_speed_mps = 12.0\n{LAND}"
    );
    let r = fly(
        &aircraft,
        &pack,
        &text,
        &Wind::constant(10.0, 90.0).unwrap(),
    );
    assert!(r.feasible, "{:?}", r.shortfall);
    let m = r.takeoff_mass_kg;
    let g = aircraft.gravity_mps2();
    let a = airspeed_at_drag(&aircraft, m * g * 35f64.to_radians().tan());
    let want = a - 10.0;
    for s in middle(&r, 2) {
        // The bisection of the planner stops within 1e-9 of the fraction: micrometres per second.
        assert!((speed(&s) - want).abs() < 1e-6, "{} vs {want}", speed(&s));
    }
    let leg = &r.segments[1];
    let edge = leg.edge.unwrap();
    assert_eq!(edge.limit, Limit::Tilt);
    assert!((edge.slowest_mps.unwrap() - want).abs() < 1e-6);
    assert!((edge.planned_mps - 12.0).abs() < 1e-6);
    // Time lost: the 1200 m at (A - 10) instead of 12 m/s, less the ramps' share (a few
    // seconds at most: the ramps of the plan are 6 s each at 2 m/s^2).
    let cruise_lost = 1200.0 / want - 1200.0 / 12.0;
    assert!(
        (leg.time_lost_s - cruise_lost).abs() < 6.0,
        "{} vs {cruise_lost}",
        leg.time_lost_s
    );
    // The way back has the wind behind it: flown as planned.
    assert!(r.segments[2].edge.is_none() && r.segments[2].time_lost_s == 0.0);
    // Slower into the wind costs more than the plan would have in still air.
    let calm = fly(&aircraft, &pack, &text, &Wind::calm());
    assert!(r.duration_s > calm.duration_s + cruise_lost - 6.0);
    assert!(r.energy_wh > calm.energy_wh);
}

#[test]
fn past_an_airspeed_limit_the_leg_is_flown_at_that_airspeed() {
    // The M100 given an airspeed limit of 10 m/s (within its tilt at that speed): 12 m/s into
    // a 4 m/s headwind is 16 m/s of air; it holds 10 - 4 = 6 m/s over the ground.
    let (aircraft, pack) = m100_with(|a| a.max_airspeed_mps = Some(10.0));
    let text = format!(
        "{TAKE_OFF}[[segment]]\nkind = \"leg\"\neast_m = 800.0\nnorth_m = 0.0\nground_speed_mps = 12.0\n\
         [[segment]]\nkind = \"return\"\nground_speed_mps = 12.0\n{LAND}"
    );
    let r = fly(&aircraft, &pack, &text, &Wind::constant(4.0, 90.0).unwrap());
    assert!(r.feasible);
    for s in middle(&r, 2) {
        assert!((speed(&s) - 6.0).abs() < 1e-6, "{}", speed(&s));
        assert!((s.airspeed_mps - 10.0).abs() < 1e-6);
    }
    assert_eq!(r.segments[1].edge.unwrap().limit, Limit::Airspeed);
    // Downwind 12 m/s over the ground is 8 m/s of air: as planned.
    assert!(r.segments[2].edge.is_none());
}

#[test]
fn a_climb_past_the_rate_limit_is_flown_at_the_limit() {
    // A take-off asked at 8 m/s to 100 m: the M100 climbs at most 5 m/s. The trapezoid of the
    // plan (0 -> 8 -> 0 m/s at the vertical acceleration a) flown with its speed capped at 5
    // m/s takes as long as the trapezoid at 5 m/s: L / 5 + 5 / a.
    let (aircraft, pack) = m100_with(|_| {});
    let max = aircraft.airframe().max_climb_rate_mps();
    assert!((max - 5.0).abs() < 1e-12);
    let a = aircraft.airframe().vertical_acceleration_mps2();
    let text = format!(
        "[[segment]]\nkind = \"take-off\"\naltitude_m = 100.0\nclimb_rate_mps = 8.0\n\
         [[segment]]\nkind = \"hover\"\nduration_s = 5.0\n{LAND}"
    );
    let r = fly(&aircraft, &pack, &text, &Wind::calm());
    assert!(r.feasible);
    let climb = &r.segments[0];
    let want = 100.0 / max + max / a;
    // The midpoint rule over 0.1 s steps: the cap falls inside a step at each end.
    assert!(
        (climb.duration_s - want).abs() < 0.05,
        "{} vs {want}",
        climb.duration_s
    );
    let top = r
        .samples
        .iter()
        .filter(|s| s.segment == 1)
        .map(|s| s.vel_up_mps)
        .fold(0.0, f64::max);
    assert!((top - max).abs() < 1e-6, "{top}");
    assert_eq!(climb.edge.unwrap().limit, Limit::Climb);
    assert!((climb.edge.unwrap().slowest_mps.unwrap() - max).abs() < 1e-6);
}

#[test]
fn an_orbit_too_tight_for_its_speed_is_flown_at_the_speed_the_bank_allows() {
    // A 10 m circle at 10 m/s in still air: v^2 / r = 10 m/s^2, beyond g tan(35 deg) = 6.9.
    // Level, the horizontal force is the centripetal m v^2 / r across the track and the drag
    // f_D(v) along it, so at the tilt limit sqrt((m v^2 / r)^2 + f_D(v)^2) = m g tan(35 deg).
    let (aircraft, pack) = m100_with(|_| {});
    let text = format!(
        "{TAKE_OFF}[[segment]]\nkind = \"orbit\"\ncentre_east_m = 0.0\ncentre_north_m = 20.0\nradius_m = 10.0\n\
         ground_speed_mps = 10.0\ndirection = \"clockwise\"\nlaps = 3.0\n{LAND}"
    );
    let r = fly(&aircraft, &pack, &text, &Wind::calm());
    assert!(r.feasible, "{:?}", r.shortfall);
    let m = r.takeoff_mass_kg;
    let g = aircraft.gravity_mps2();
    let (mu1, mu2, mu3) = aircraft.drag().coefficients();
    let budget = m * g * 35f64.to_radians().tan();
    let excess = |v: f64| {
        let drag = mu1 * v + mu2 * v * v + mu3 * v * v * v;
        (m * v * v / 10.0).hypot(drag) - budget
    };
    let (want, _) = aloft_core::bisect(0.0, 10.0, 200, |v| excess(v) < 0.0);
    // The arc's cruise: samples on the circle with no tangential acceleration (the ramps at
    // its ends accelerate along the path).
    let arc: Vec<&Sample> = r
        .samples
        .iter()
        .filter(|s| s.segment == 2 && (s.east_m.hypot(s.north_m - 20.0) - 10.0).abs() < 1e-6)
        .filter(|s| {
            let tangential =
                (s.acc_east_mps2 * s.vel_east_mps + s.acc_north_mps2 * s.vel_north_mps) / speed(s);
            tangential.abs() < 1e-9
        })
        .collect();
    assert!(arc.len() > 50);
    for s in arc {
        assert!((speed(s) - want).abs() < 1e-6, "{} vs {want}", speed(s));
    }
    let orbit = r.segments.iter().find(|s| s.kind == "orbit").unwrap();
    assert_eq!(orbit.edge.unwrap().limit, Limit::Tilt);
    // Three laps of 62.8 m at `want` instead of 10 m/s.
    let laps_m = 3.0 * std::f64::consts::TAU * 10.0;
    assert!((orbit.time_lost_s - (laps_m / want - laps_m / 10.0)).abs() < 3.0);
}

#[test]
fn a_wind_beyond_the_vehicle_is_exit_1_with_the_answer_and_where_and_by_how_much() {
    // 20 m/s on the built-in demo: beyond what the M100 (2.355 kg with its TB47D) can fly
    // against within its 35 deg tilt, A with f_D(A) = m g tan(35 deg).
    let (code, out, err) = aloft(&[
        "mission",
        "--wind-speed",
        "20",
        "--wind-from",
        "250",
        "--format",
        "json",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.is_empty(), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["feasible"], false);
    let (aircraft, _) = m100_with(|_| {});
    let a = airspeed_at_drag(
        &aircraft,
        2.355 * aircraft.gravity_mps2() * 35f64.to_radians().tan(),
    );
    let reason = v["reason"].as_str().unwrap();
    for needle in [
        "segment 1 (take-off)".to_string(),
        "20.0 m/s from 250 deg".to_string(),
        format!("dji-m100 flies at most {a:.1} m/s of airspeed"),
        "tilt limit of 35.00 deg".to_string(),
        "cannot hold its position".to_string(),
    ] {
        assert!(reason.contains(&needle), "'{needle}' missing in: {reason}");
    }
    // No batteries can help a vehicle that cannot fly there.
    assert!(v.get("batteries_required").is_none());
    assert!(v.get("warnings").is_none(), "{v}");
}

#[test]
fn the_windy_cases_that_were_bad_input_now_answer() {
    // The list: each answers with exit 0 or 1 and a JSON answer, none with exit 2.
    let demo_10 = ["mission", "--wind-speed", "10", "--wind-from", "250"];
    let example = [
        "mission",
        "fixtures/missions/example.toml",
        "--vehicle",
        "dji-m100",
        "--battery",
        "TB48D",
        "--payload-kg",
        "0.5",
        "--wind-speed",
        "8",
        "--wind-from",
        "270",
        "--reserve-percent",
        "25",
    ];
    let cases: [&[&str]; 4] = [
        &example,
        &["mission", "fixtures/missions/example.toml"],
        &demo_10,
        &["mission", "--vehicle", "dji-m600"],
    ];
    for args in cases {
        let mut args = args.to_vec();
        args.extend(["--format", "json"]);
        let (code, out, err) = aloft(&args);
        assert!(code == 0 || code == 1, "{args:?}: exit {code}: {err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert!(v["duration_s"].as_f64().unwrap() > 0.0);
    }
    // A 10 m/s wind costs the demo more time and energy than still air.
    let json = |args: &[&str]| -> serde_json::Value {
        let mut args = args.to_vec();
        args.extend(["--format", "json"]);
        let (code, out, err) = aloft(&args);
        assert_eq!(code, 0, "{err}");
        serde_json::from_str(&out).unwrap()
    };
    let calm = json(&["mission", "--wind-speed", "0", "--wind-from", "250"]);
    let windy = json(&demo_10);
    for k in ["duration_s", "energy_wh"] {
        assert!(
            windy[k].as_f64().unwrap() > calm[k].as_f64().unwrap(),
            "{k}: {} vs {}",
            windy[k],
            calm[k]
        );
    }
    // ... and the time it lost at the edge is reported, per segment and in all.
    assert!(windy["time_lost_s"].as_f64().unwrap() > 1.0);
    let slowed: Vec<&serde_json::Value> = windy["segments"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s.get("time_lost_s").is_some())
        .collect();
    assert!(!slowed.is_empty());
    for s in slowed {
        assert_eq!(s["limit"], "tilt");
        assert!(s["min_ground_speed_mps"].as_f64().unwrap() < 8.0);
    }
    assert!(windy["warnings"][0]
        .as_str()
        .unwrap()
        .contains("longer than planned"));
}

#[test]
fn data_val_a_qgroundcontrol_survey_in_a_12_mps_wind_answers() {
    let dir = std::env::var("ALOFT_DATA_DIR").unwrap_or_else(|_| "../shared/data".to_string());
    let plan = format!("{dir}/missions/neilvaltec_test.plan");
    if !std::path::Path::new(&plan).exists() {
        panic!("{plan} not found: set ALOFT_DATA_DIR to shared/data");
    }
    let run = |wind: &str| -> serde_json::Value {
        let (code, out, err) = aloft(&[
            "mission",
            &plan,
            "--wind-speed",
            wind,
            "--wind-from",
            "270",
            "--format",
            "json",
        ]);
        assert!(code == 0 || code == 1, "exit {code}: {err}");
        serde_json::from_str(&out).unwrap()
    };
    // 12 m/s (the case, 35.x deg needed at the 5 m/s planning speed upwind): answered.
    let v = run("12");
    assert!(v["duration_s"].as_f64().unwrap() > 0.0);
    // 14 m/s: the upwind leg out (item 3) and the return (item 70) are flown slower, named by
    // the operator's item numbers; the survey lines across the wind are not.
    let v = run("14");
    let lost = v["time_lost_s"].as_f64().unwrap();
    assert!(lost > 10.0, "{lost}");
    let warned: Vec<&str> = v["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .filter(|w| w.contains("longer than planned"))
        .collect();
    assert!(
        warned.iter().any(|w| w.starts_with("item 3 (leg)")),
        "{warned:?}"
    );
    assert!(
        warned.iter().any(|w| w.starts_with("item 70 (return)")),
        "{warned:?}"
    );
}
