//! Benches of aloft-propulsion.
//!
//! * `propulsion/operating_point`: one thrust-to-pack-current solve (propeller speed, motor
//!   current, eq 28, eqs 29-30) for the seed's AEC quadrotor. Target: <= 200 ns.
//! * `propulsion/step_response`: a 0.5 s fixed-step RK4 simulation of eq (2) at 0.1 ms steps
//!   (5000 steps, metrics only) for the MN1806 + 6x2 rotor. Target: <= 200 us.

use aloft::vehicle::VehicleFile;
use aloft_propulsion::transient::{kt_from_kv, motor_inertia_kgm2, prop_inertia_kgm2};
use aloft_propulsion::{EscProtocol, PropulsionSystem, RotorConstants, RotorTransient};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

/// The AEC quadrotor's propulsion chain, as `fixtures/vehicles/aec-quadrotor.toml` (the
/// built-in vehicle, provenance there) gives it.
fn aec() -> PropulsionSystem {
    VehicleFile::builtin("aec-quadrotor")
        .expect("built-in")
        .propulsion_system()
        .expect("propulsion chain")
}

fn mn1806() -> RotorTransient {
    let c = 0.0351 * 1.225 * (6.0f64 * 0.0254).powi(5) / (8.0 * std::f64::consts::PI.powi(3));
    RotorTransient::new(RotorConstants {
        kt_nm_per_a: kt_from_kv(2300.0, 11.1, 0.4, 0.117).unwrap(),
        resistance_ohm: 0.117,
        no_load_current_a: 0.4,
        supply_voltage_v: 11.1,
        motor_inertia_kgm2: motor_inertia_kgm2(0.018, 0.023).unwrap(),
        prop_inertia_kgm2: prop_inertia_kgm2(0.00186, 6.0 * 0.0254).unwrap(),
        torque_coefficient_nms2: c,
        delay_s: EscProtocol::Dshot300.added_delay_s(),
    })
    .unwrap()
}

fn benches(c: &mut Criterion) {
    let s = aec();
    // Target: <= 200 ns per solve.
    c.bench_function("propulsion/operating_point", |b| {
        b.iter(|| s.pack_current_for_thrust_a(black_box(29.47)).unwrap())
    });
    let r = mn1806();
    // Target: <= 200 us for 0.5 s at 0.1 ms (5000 RK4 steps).
    c.bench_function("propulsion/step_response", |b| {
        b.iter(|| {
            r.simulate_step_metrics(black_box(1000.0), black_box(1450.0), 0.5, 1e-4)
                .unwrap()
        })
    });
}

criterion_group!(propulsion, benches);
criterion_main!(propulsion);
