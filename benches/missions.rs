//! Benches of the mission importers.
//!
//! Target (issue 14): `missions/import/survey_500kb`, a QGroundControl survey `.plan` of about
//! 500 KB (generated here: a lawn-mower survey whose `TransectStyleComplexItem.Items` hold
//! waypoints and camera triggers, pretty-printed as QGroundControl writes it) read into a
//! mission spec with its route figures in well under a second. Measured on the 2-core machine:
//! 1.92-2.00 ms for 502 KB (about 245 MiB/s).
//!
//! Target (issue 26): `serve/replan/*`, what the page of `aloft serve` computes when a control
//! changes (the mission's answer and its map), interactive: the demo well under 100 ms, the
//! 500 KB survey (1,342 items) under a second.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use serde_json::{json, Value};

/// A SimpleItem as QGroundControl stores it.
fn item(seq: usize, command: u32, frame: u32, params: Value) -> Value {
    json!({
        "autoContinue": true,
        "command": command,
        "doJumpId": seq,
        "frame": frame,
        "params": params,
        "type": "SimpleItem",
    })
}

/// A survey `.plan` with `lines` transects 20 m apart, each a waypoint pair with a camera
/// trigger at either end, near Zurich; take-off first, RTL last.
fn survey_plan(lines: usize) -> String {
    let (lat0, lon0) = (47.3977, 8.5456);
    let mut inner = Vec::new();
    let mut seq = 2;
    for k in 0..lines {
        let lat = lat0 + 0.00018 * k as f64;
        let (a, b) = if k % 2 == 0 {
            (0.0, 0.0066)
        } else {
            (0.0066, 0.0)
        };
        for (lon, trigger) in [(lon0 + a, 25.0), (lon0 + b, 0.0)] {
            inner.push(item(seq, 16, 3, json!([0, 0, 0, null, lat, lon, 50])));
            inner.push(item(seq + 1, 206, 2, json!([trigger, 0, 1, 0, 0, 0, 0])));
            seq += 2;
        }
    }
    let survey = json!({
        "type": "ComplexItem",
        "complexItemType": "survey",
        "version": 5,
        "TransectStyleComplexItem": {"Items": inner, "TurnAroundDistance": 10, "version": 2},
    });
    let items = vec![
        item(1, 22, 3, json!([0, 0, 0, null, lat0, lon0, 50])),
        survey,
        item(seq, 20, 2, json!([0, 0, 0, 0, 0, 0, 0])),
    ];
    let plan = json!({
        "fileType": "Plan",
        "groundStation": "QGroundControl",
        "version": 1,
        "mission": {
            "cruiseSpeed": 15, "firmwareType": 12, "hoverSpeed": 5, "vehicleType": 2,
            "version": 2, "plannedHomePosition": [lat0, lon0, 400], "items": items,
        },
    });
    serde_json::to_string_pretty(&plan).expect("plan JSON")
}

fn bench_import(c: &mut Criterion) {
    let text = survey_plan(335);
    assert!(
        (450_000..600_000).contains(&text.len()),
        "{} bytes",
        text.len()
    );
    let imported = aloft_missions::read_plan(&text).expect("the survey imports");
    assert_eq!(imported.counted.total, 2 + 335 * 4);
    let mut g = c.benchmark_group("missions/import");
    g.throughput(Throughput::Bytes(text.len() as u64));
    g.bench_function("survey_500kb", |b| {
        b.iter(|| aloft_missions::read_plan(black_box(&text)).expect("imports"))
    });
    g.finish();
}

/// The page's re-plan (`aloft serve`): a mission's answer and its map, as the page asks for both
/// on every change of a control.
fn bench_page_replan(c: &mut Criterion) {
    use aloft::engine::answers::{mission_answer_for, mission_map_answer_for};
    use aloft::engine::flags::MissionScenarioFlags;
    use aloft::engine::{parse_keywords, Mission};
    let flags: MissionScenarioFlags = parse_keywords("the bench", &[], &[]).expect("defaults");
    let survey = Mission::from_text(&survey_plan(335), "survey.plan").expect("the survey reads");
    let mut g = c.benchmark_group("serve/replan");
    g.sample_size(10);
    for (name, mission) in [("demo", Mission::demo()), ("survey_500kb", survey)] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let answer = mission_answer_for(black_box(&mission), &flags).expect("answer");
                let map = mission_map_answer_for(&mission, &flags).expect("map");
                (answer.len(), map.len())
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_import, bench_page_replan);
criterion_main!(benches);
