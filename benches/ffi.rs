//! Benches of the C ABI against the Rust facade it wraps.
//!
//! Target (issue 6): `ffi/mission_roundtrip` (the demonstration mission as JSON text in, plan, the
//! summary JSON out, through `aloft_mission_json` and `aloft_string_free`) costs less than 10 %
//! more than `ffi/mission_roundtrip_rust`, the same work through `aloft::engine` (parse the same
//! JSON, plan, serialise). What the ABI adds: UTF-8 checks of the inputs, the handle registry,
//! `catch_unwind`, one copy of the output into a C string.

use std::ffi::{c_char, CString};
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};

use aloft::engine::{plan_mission, Mission, MissionOptions, Vehicle};
use aloft_ffi::{
    aloft_mission_json, aloft_string_free, aloft_vehicle_builtin, aloft_vehicle_free, AloftStatus,
    AloftVehicle,
};

fn bench_roundtrip(c: &mut Criterion) {
    let demo_json = Mission::demo()
        .to_json()
        .expect("the demo mission serialises");
    let demo_c = CString::new(demo_json.clone()).expect("no NUL in JSON");
    let options_c = CString::new("{}").expect("no NUL");

    let mut vehicle: *mut AloftVehicle = std::ptr::null_mut();
    // SAFETY: valid NUL-terminated name and out pointer.
    let status = unsafe { aloft_vehicle_builtin(c"dji-m100".as_ptr(), &mut vehicle) };
    assert_eq!(status, AloftStatus::Ok);

    let mut group = c.benchmark_group("ffi");
    group.sample_size(30);
    group.bench_function("mission_roundtrip", |b| {
        b.iter(|| {
            let mut out: *mut c_char = std::ptr::null_mut();
            // SAFETY: a live vehicle, NUL-terminated texts, a writable out pointer.
            let status = unsafe {
                aloft_mission_json(
                    black_box(vehicle),
                    black_box(demo_c.as_ptr()),
                    black_box(options_c.as_ptr()),
                    &mut out,
                )
            };
            assert_eq!(status, AloftStatus::Ok);
            // SAFETY: `out` was returned by aloft and is freed once.
            unsafe { aloft_string_free(black_box(out)) };
        })
    });

    let rust_vehicle = Vehicle::builtin("dji-m100").expect("built-in");
    group.bench_function("mission_roundtrip_rust", |b| {
        b.iter(|| {
            let mission = Mission::from_text(black_box(&demo_json), "bench").expect("mission");
            let options = MissionOptions::from_json(black_box("{}")).expect("options");
            let plan = plan_mission(black_box(&rust_vehicle), &mission, &options).expect("plan");
            black_box(plan.to_json().expect("json"))
        })
    });
    group.finish();

    // Paired measurement, robust to the load of a shared machine: alternate the two calls and
    // take the median of the per-pair ratios.
    let mut ratios: Vec<f64> = (0..200)
        .map(|_| {
            let t0 = std::time::Instant::now();
            let mut out: *mut c_char = std::ptr::null_mut();
            // SAFETY: as above.
            unsafe {
                aloft_mission_json(vehicle, demo_c.as_ptr(), options_c.as_ptr(), &mut out);
                aloft_string_free(out);
            }
            let ffi = t0.elapsed().as_secs_f64();
            let t1 = std::time::Instant::now();
            let mission = Mission::from_text(&demo_json, "bench").expect("mission");
            let options = MissionOptions::from_json("{}").expect("options");
            let plan = plan_mission(&rust_vehicle, &mission, &options).expect("plan");
            black_box(plan.to_json().expect("json"));
            ffi / t1.elapsed().as_secs_f64()
        })
        .collect();
    ratios.sort_by(f64::total_cmp);
    eprintln!(
        "ffi/mission_roundtrip: paired overhead over the Rust call, median of 200 pairs: {:+.1} % (target < 10 %)",
        (ratios[ratios.len() / 2] - 1.0) * 100.0
    );

    // SAFETY: the vehicle is live and freed once.
    unsafe { aloft_vehicle_free(vehicle) };
}

criterion_group!(benches, bench_roundtrip);
criterion_main!(benches);
