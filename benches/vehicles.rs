//! Benches of the vehicle library (issue 16): `vehicles/calibrate/m600_spec`, a spec sheet to a
//! calibrated vehicle (parse, checks, the bisection on the pack model's hover time, the file
//! read back), and `vehicles/payload_sweep/m100_all_packs`, `aloft endurance --payload-sweep
//! 0:1.5:0.05` for the M100's four packs (every endurance query at each payload). The issue
//! names no target; an interactive command should answer well under a second.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};

use aloft::engine::{
    calibrate_spec, payload_sweep, EnduranceOptions, PayloadSweep, SpecSheet, Vehicle,
};

fn benches(c: &mut Criterion) {
    let text = include_str!("../fixtures/vehicles/specs/dji-m600.toml");
    let spec = SpecSheet::from_toml(text, "dji-m600.toml").unwrap();
    c.bench_function("vehicles/calibrate/m600_spec", |b| {
        b.iter(|| calibrate_spec(black_box(&spec), "dji-m600.toml").unwrap())
    });
    let m100 = Vehicle::builtin("dji-m100").unwrap();
    let sweep = PayloadSweep::new(0.0, 1.5, 0.05).unwrap();
    c.bench_function("vehicles/payload_sweep/m100_all_packs", |b| {
        b.iter(|| payload_sweep(black_box(&m100), &EnduranceOptions::default(), &sweep).unwrap())
    });
}

criterion_group! {
    name = group;
    config = Criterion::default().sample_size(20);
    targets = benches
}
criterion_main!(group);
