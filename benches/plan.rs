//! Bench of `aloft plan` (issue 33): [`plan_to_fly`] on the largest survey of the shared data.
//!
//! Target: at most 2 s per plan on the 2-core machine (an operator waits for it at the field).
//! The mission is `$ALOFT_DATA_DIR/missions/neilvaltec_test.plan` (default `../shared/data`): a
//! QGroundControl survey v5 of 52 waypoints and 15 camera triggers, about 5 km, flown by the
//! DJI M100 with its default pack. Two cases, each a reserve that makes several sorties:
//!
//! - `plan/plan_to_fly/survey_wind_8mps`: wind 8 m/s from the north, reserve 70 % (2 sorties
//!   when written: the survey turned to the wind, the legs at the wind's speeds);
//! - `plan/plan_to_fly/survey_still_air`: still air, reserve 80 % (4 sorties when written).
//!
//! Each plan flies every candidate (the mission's speeds and the wind's, cut inside legs, the
//! as-given split; then the same for the survey turned to the angle of least energy, where one
//! saves energy) and each candidate's sorties from their own files read back; no file is written. Without the shared data the bench says so and
//! measures nothing.
//!
//! Measured on the 2-core machine (`--warm-up-time 1 --measurement-time 5`, 10 samples) while
//! other builds kept its load average at about 3.5: `survey_wind_8mps` 623-749 ms,
//! `survey_still_air` 402-467 ms. Before surveys were turned to the wind (3 sorties in the wind),
//! at a load average of about 2: 241-277 ms and 339-374 ms.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};

use aloft::engine::{plan_to_fly, FlyPlanRequest, Mission, MissionOptions, Vehicle};

fn data_dir() -> PathBuf {
    std::env::var_os("ALOFT_DATA_DIR").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"),
        PathBuf::from,
    )
}

/// The request: the mission's options as JSON (`aloft mission`'s), the plan's defaults.
fn request(options_json: &str) -> FlyPlanRequest {
    FlyPlanRequest {
        options: MissionOptions::from_json(options_json).expect("mission options"),
        ..FlyPlanRequest::default()
    }
}

fn bench_plan(c: &mut Criterion) {
    let path = data_dir().join("missions/neilvaltec_test.plan");
    if !path.is_file() {
        eprintln!(
            "plan bench skipped: {} is missing (set ALOFT_DATA_DIR to the shared data)",
            path.display()
        );
        return;
    }
    let vehicle = Vehicle::builtin("dji-m100").expect("built-in vehicle");
    let mission = Mission::load(Some(&path)).expect("the shared survey reads");
    let cases = [
        (
            "survey_wind_8mps",
            r#"{"reserve_percent": 70, "wind": {"speed_mps": 8, "from_deg": 0}}"#,
        ),
        ("survey_still_air", r#"{"reserve_percent": 80}"#),
    ];
    let mut group = c.benchmark_group("plan/plan_to_fly");
    group.sample_size(10);
    for (name, options) in cases {
        let request = request(options);
        // The workload is the one described above: several sorties, each with its file.
        let plan = plan_to_fly(&vehicle, &mission, &request).expect("a plan");
        assert!(
            plan.sorties.len() >= 2,
            "{name}: {} sortie(s)",
            plan.sorties.len()
        );
        assert_eq!(plan.texts.len(), plan.sorties.len(), "{name}");
        eprintln!("{name}: {} sorties", plan.sorties.len());
        group.bench_function(name, |b| {
            b.iter(|| {
                plan_to_fly(
                    black_box(&vehicle),
                    black_box(&mission),
                    black_box(&request),
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_plan);
criterion_main!(benches);
