//! Bench of `aloft live` (issue 25): one update with 200 scenarios within 100 ms on 2 cores.
//!
//! The flight is the shared simulator AUTO mission with battery
//! (`$ALOFT_DATA_DIR/telemetry/ayoub_auto_mission_sitl.tlog`, default `../shared/data`), folded
//! into a [`LiveSession`] up to `t` = 100 s (in the air, item 2 of 7 in AUTO: the longest rest of
//! the flight); the bench is one [`LiveSession::update`]: the efficiency's estimate, then the rest
//! of the mission and its Monte-Carlo scenarios (the learned mission is read at the first
//! update, before the measurement).

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};

use aloft::engine::{LiveRequest, LiveSession, Vehicle, LIVE_SCENARIOS};
use aloft_link::{TelemetrySource, TlogSource};

fn data_dir() -> PathBuf {
    std::env::var_os("ALOFT_DATA_DIR").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"),
        PathBuf::from,
    )
}

fn bench_update(c: &mut Criterion) {
    let vehicle = Vehicle::builtin("dji-m100").expect("built-in vehicle");
    let request = LiveRequest {
        scenarios: LIVE_SCENARIOS,
        ..LiveRequest::new()
    };
    let mut session = LiveSession::new(&vehicle, &request).expect("session");
    let path = data_dir().join("telemetry/ayoub_auto_mission_sitl.tlog");
    let mut source = TlogSource::open(&path).expect("the shared telemetry log");
    while let Some(t) = source.next_event().expect("readable") {
        session.apply(&t);
        if t.time_s >= 100.0 {
            break;
        }
    }
    let first = session.update();
    assert!(first.in_air && first.remaining_wh.is_some(), "{first:?}");
    c.bench_function("live/update/200_scenarios", |b| {
        b.iter(|| black_box(session.update()))
    });
}

criterion_group!(benches, bench_update);
criterion_main!(benches);
