//! Bench of `aloft live` (issue 25): one update with 200 scenarios within 100 ms on 2 cores; and
//! (issue 44) the same on the pack flown, its state filtered and two voltage failsafes flown in
//! every scenario.
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

/// The shared simulator mission folded into `session` up to 100 s.
fn fold_to_100_s(session: &mut LiveSession<'_>) {
    let path = data_dir().join("telemetry/ayoub_auto_mission_sitl.tlog");
    let mut source = TlogSource::open(&path).expect("the shared telemetry log");
    while let Some(t) = source.next_event().expect("readable") {
        session.apply(&t);
        if t.time_s >= 100.0 {
            break;
        }
    }
}

fn bench_update(c: &mut Criterion) {
    let vehicle = Vehicle::builtin("dji-m100").expect("built-in vehicle");
    let request = LiveRequest {
        scenarios: LIVE_SCENARIOS,
        ..LiveRequest::new()
    };
    let mut session = LiveSession::new(&vehicle, &request).expect("session");
    fold_to_100_s(&mut session);
    let first = session.update();
    assert!(first.in_air && first.remaining_wh.is_some(), "{first:?}");
    c.bench_function("live/update/200_scenarios", |b| {
        b.iter(|| black_box(session.update()))
    });
}

/// A 3S pack added to the M100's file, so that the simulator's 12.6 V pack is the one flown: the
/// pack's state is the filter's, and the failsafes (`--low-voltage-v 10.5`, `--critical-voltage-v
/// 9.9`) are flown on it in every scenario.
const SITL_PACK: &str = r#"
[[battery]]
name = "sitl-3s"
cells_series = 3
capacity_mah = 5000.0
nominal_v = 11.1
energy_wh = 55.5
mass_kg = 0.6
internal_resistance_ohm = 0.02
cutoff_cell_v = 3.3
"#;

fn bench_update_on_the_pack(c: &mut Criterion) {
    let m100 = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/vehicles/dji-m100.toml"),
    )
    .expect("the M100's file");
    let vehicle = Vehicle::from_toml(&(m100 + SITL_PACK), "m100-3s").expect("vehicle");
    let request = LiveRequest {
        scenarios: LIVE_SCENARIOS,
        battery: Some("sitl-3s".to_string()),
        low_voltage_v: Some(10.5),
        critical_voltage_v: Some(9.9),
        ..LiveRequest::new()
    };
    let mut session = LiveSession::new(&vehicle, &request).expect("session");
    fold_to_100_s(&mut session);
    let first = session.update();
    assert!(
        first.in_air && first.soc_band.is_some() && !first.failsafes.is_empty(),
        "{first:?}"
    );
    c.bench_function("live/update/200_scenarios_on_the_pack", |b| {
        b.iter(|| black_box(session.update()))
    });
}

criterion_group!(benches, bench_update, bench_update_on_the_pack);
criterion_main!(benches);
