//! `aloft::engine` is a drop-in for the CLI's JSON: for the same inputs its summaries serialise to
//! exactly what `aloft mission --format json` and `aloft endurance --format json` print.

use crate::common;
use common::{cli, uniform_wind as wind};

use aloft::engine::{endurance, plan_mission, EnduranceOptions, Mission, MissionOptions, Vehicle};

/// For the defaults and then each case's flags and options, `aloft command --format json flags`
/// prints the engine's `answer` to the options and a newline.
fn same_json<O: Default>(command: &str, cases: Vec<(Vec<&str>, O)>, answer: impl Fn(&O) -> String) {
    for (args, options) in [(vec![], O::default())].into_iter().chain(cases) {
        let mut full = vec![command, "--format", "json"];
        full.extend(&args);
        assert_eq!(format!("{}\n", answer(&options)), cli(&full), "{args:?}");
    }
}

#[test]
fn mission_summary_is_the_cli_json() {
    let m100 = Vehicle::builtin("dji-m100").unwrap();
    let cases: Vec<(Vec<&str>, MissionOptions)> = vec![
        (
            vec![
                "--payload-kg",
                "0.3",
                "--wind-speed",
                "4",
                "--wind-from",
                "120",
                "--reserve-percent",
                "30",
                "--aoa",
                "paper",
            ],
            MissionOptions {
                payload_kg: Some(0.3),
                wind: wind(4.0, 120.0),
                reserve_percent: Some(30.0),
                aoa: aloft::engine::AoaModel::Paper,
                ..MissionOptions::default()
            },
        ),
        // Infeasible: the CLI exits 1 and still prints the summary, with a reason and the point
        // of no return.
        (
            vec!["--start-percent", "45", "--no-ground-effect"],
            MissionOptions {
                start_percent: 45.0,
                ground_effect: false,
                ..MissionOptions::default()
            },
        ),
    ];
    same_json("mission", cases, |options| {
        let plan = plan_mission(&m100, &Mission::demo(), options).unwrap();
        plan.to_json().unwrap()
    });
}

#[test]
fn infeasible_case_has_the_optional_keys() {
    let m100 = Vehicle::builtin("dji-m100").unwrap();
    let plan = plan_mission(
        &m100,
        &Mission::demo(),
        &MissionOptions {
            start_percent: 45.0,
            ..MissionOptions::default()
        },
    )
    .unwrap();
    let s = plan.summary();
    assert!(!s.feasible && s.reason.is_some());
    assert!(s.point_of_no_return_s.is_some() && s.point_of_no_return.is_some());
}

#[test]
fn endurance_summary_is_the_cli_json() {
    let m100 = Vehicle::builtin("dji-m100").unwrap();
    let cases: Vec<(Vec<&str>, EnduranceOptions)> = vec![(
        vec![
            "--wind-speed",
            "6",
            "--wind-from",
            "30",
            "--course",
            "45",
            "--payload-kg",
            "0.5",
            "--reserve-percent",
            "20",
            "--orbit-radius",
            "30",
            "--orbit-speed",
            "5",
        ],
        EnduranceOptions {
            wind: wind(6.0, 30.0),
            course_deg: 45.0,
            payload_kg: 0.5,
            reserve_percent: 20.0,
            orbit_radius_m: Some(30.0),
            orbit_speed_mps: Some(5.0),
            ..EnduranceOptions::default()
        },
    )];
    same_json("endurance", cases, |options| {
        endurance(&m100, options).unwrap().to_json().unwrap()
    });
}
