//! Bench of `aloft plan` (issues 33 and 43): [`plan_to_fly`] on the largest survey of the shared
//! data, and on one of a held-out survey's size built from it.
//!
//! Targets on the 2-core machine (an operator waits for it at the field): at most 2 s per plan of
//! the shared survey; a 38 km survey planned at the default confidence (0.95 of 400 scenarios)
//! in at most 3 s, and for the forecast alone (`confidence` 0.5) in at most 1 s (issue 43).
//! The shared mission is `$ALOFT_DATA_DIR/missions/neilvaltec_test.plan` (default
//! `../shared/data`): a QGroundControl survey v5 of 52 waypoints and 15 camera triggers, about
//! 5 km, flown by the DJI M100 with its default pack. Cases, each a reserve that makes several
//! sorties:
//!
//! - `plan/plan_to_fly/survey_wind_8mps`: wind 8 m/s from the north, reserve 70 % (2 sorties
//!   when written: the survey turned to the wind, the legs at the wind's speeds), cut for the
//!   forecast alone (confidence 0.5, as before issue 43);
//! - `plan/plan_to_fly/survey_still_air`: still air, reserve 80 % (4 sorties when written), cut
//!   for the forecast alone;
//! - `plan/plan_to_fly/survey_38km_confidence_95`: the shared survey's polygon scaled 2.8 times
//!   (`tests/it/common/big_survey.rs`: its transects drawn again at the same spacing, about
//!   38 km of flight), wind 8 m/s from 240 deg, the 20 % reserve, the default confidence (6
//!   sorties);
//! - `plan/plan_to_fly/survey_38km_nominal`: the same cut for the forecast alone (4 sorties).
//!
//! Each plan flies every candidate (the mission's speeds and the wind's, cut inside legs, the
//! as-given split; then the same for the survey turned to the angle of least energy, where one
//! saves energy) and each candidate's sorties from their own files read back, then cuts the best
//! again with each sortie judged in the day's scenarios; no file is written. Without the shared
//! data the bench says so and measures nothing.
//!
//! Measured on the 2-core machine (`--warm-up-time 1 --measurement-time 5`, 10 samples, load
//! average 0.4, 2026-11-29): 212 ms, 168 ms, 2.98 s and 821 ms (docs/architecture.md, the
//! benches' table).

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};

use aloft::engine::{
    plan_to_fly, FlyPlanRequest, Mission, MissionOptions, PlanConfidence, Vehicle,
};

#[path = "../tests/it/common/big_survey.rs"]
mod big_survey;

fn data_dir() -> PathBuf {
    std::env::var_os("ALOFT_DATA_DIR").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"),
        PathBuf::from,
    )
}

/// The request: the mission's options as JSON (`aloft mission`'s), the plan's defaults but the
/// confidence.
fn request(options_json: &str, confidence: f64) -> FlyPlanRequest {
    FlyPlanRequest {
        options: MissionOptions::from_json(options_json).expect("mission options"),
        confidence: PlanConfidence {
            confidence,
            ..PlanConfidence::default()
        },
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
    let big = Mission::from_text(&big_survey::scaled_survey(&path, 2.8), "survey-38km.plan")
        .expect("the scaled survey reads");
    let wind_240 = r#"{"wind": {"speed_mps": 8, "from_deg": 240}}"#;
    let cases = [
        (
            "survey_wind_8mps",
            &mission,
            r#"{"reserve_percent": 70, "wind": {"speed_mps": 8, "from_deg": 0}}"#,
            0.5,
        ),
        (
            "survey_still_air",
            &mission,
            r#"{"reserve_percent": 80}"#,
            0.5,
        ),
        ("survey_38km_confidence_95", &big, wind_240, 0.95),
        ("survey_38km_nominal", &big, wind_240, 0.5),
    ];
    let mut group = c.benchmark_group("plan/plan_to_fly");
    group.sample_size(10);
    for (name, mission, options, confidence) in cases {
        let request = request(options, confidence);
        // The workload is the one described above: several sorties, each with its file.
        let plan = plan_to_fly(&vehicle, mission, &request).expect("a plan");
        assert!(
            plan.sorties.len() >= 2,
            "{name}: {} sortie(s)",
            plan.sorties.len()
        );
        assert_eq!(plan.texts.len(), plan.sorties.len(), "{name}");
        eprintln!("{name}: {} sorties", plan.sorties.len());
        group.bench_function(name, |b| {
            b.iter(|| plan_to_fly(black_box(&vehicle), black_box(mission), black_box(&request)))
        });
    }
    group.finish();
}

/// A tile under the shared survey (25-26 N, 121-122 E) with the White Mountains' shape
/// (`terrain/N44W072.hgt`) at 2 % of their relief: the ground rises 0-33 m over the survey, so
/// its 50 m transects stay clear and a terrain-following plan has hills to follow.
fn gentle_tile(dir: &std::path::Path) -> bool {
    let Ok(bytes) = std::fs::read(data_dir().join("terrain/N44W072.hgt")) else {
        return false;
    };
    let heights: Vec<i16> = bytes
        .chunks_exact(2)
        .map(|b| i16::from_be_bytes([b[0], b[1]]))
        .collect();
    let low = heights
        .iter()
        .copied()
        .filter(|h| *h > -1000)
        .min()
        .unwrap_or(0);
    let out: Vec<u8> = heights
        .iter()
        .flat_map(|h| {
            let g = 5.0 + 0.02 * f64::from(h.saturating_sub(low).max(0));
            (g.round() as i16).to_be_bytes()
        })
        .collect();
    std::fs::write(dir.join("N25E121.hgt"), out).is_ok()
}

/// Issue 45: the 38 km survey planned over the ground. `plan/terrain/mission_38km_*`: the
/// mission answer (`plan_mission`) flat and with each segment's clearance;
/// `plan/terrain/plan_38km_*`: `aloft plan` for the forecast alone (confidence 0.5), flat and
/// written to follow the ground at 60 m (`--follow-terrain 60`, PX4: a waypoint at every
/// terrain sample kept, every sortie's file flown over the ground). Target: at most 100 ms more
/// than flat for each. Measured on the 2-core machine (`--warm-up-time 1 --measurement-time 5`,
/// 2026-11-29): the mission 37.3 ms flat, 88.2 ms with its clearances (+51 ms; least clearance
/// 49 m); the plan 951 ms flat, 760 ms following the ground (5 sorties; faster: its survey is
/// written as items, so no turned survey is tried).
fn bench_terrain(c: &mut Criterion) {
    let path = data_dir().join("missions/neilvaltec_test.plan");
    let dir = std::env::temp_dir().join(format!("aloft-bench-terrain-{}", std::process::id()));
    if !path.is_file() || std::fs::create_dir_all(&dir).is_err() || !gentle_tile(&dir) {
        eprintln!("terrain bench skipped: the shared survey or tile is missing");
        return;
    }
    let vehicle = Vehicle::builtin("dji-m100").expect("built-in vehicle");
    let big = Mission::from_text(&big_survey::scaled_survey(&path, 2.8), "survey-38km.plan")
        .expect("the scaled survey reads");
    let flat = MissionOptions::from_json(r#"{"wind": {"speed_mps": 8, "from_deg": 240}}"#)
        .expect("options");
    let over = MissionOptions {
        terrain: Some(dir.clone()),
        rtl_altitude_m: Some(120.0),
        ..flat.clone()
    };
    let mut group = c.benchmark_group("plan/terrain");
    group.sample_size(10);
    let answer = aloft::engine::plan_mission(&vehicle, &big, &over).expect("over the ground");
    eprintln!(
        "38 km survey: least clearance {:?} m",
        answer.summary().min_clearance_m
    );
    for (name, options) in [
        ("mission_38km_flat", &flat),
        ("mission_38km_clearances", &over),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| aloft::engine::plan_mission(black_box(&vehicle), black_box(&big), options))
        });
    }
    let plain = FlyPlanRequest {
        options: flat.clone(),
        ..request("{}", 0.5)
    };
    let following = FlyPlanRequest {
        options: over.clone(),
        follow_terrain_m: Some(60.0),
        ..request("{}", 0.5)
    };
    let written = plan_to_fly(&vehicle, &big, &following).expect("a terrain-following plan");
    eprintln!(
        "38 km survey following the ground: {} sorties",
        written.sorties.len()
    );
    for (name, req) in [
        ("plan_38km_flat", &plain),
        ("plan_38km_follow_terrain", &following),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| plan_to_fly(black_box(&vehicle), black_box(&big), black_box(req)))
        });
    }
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench_plan, bench_terrain);
criterion_main!(benches);
