//! Benches of the four-term power model.
//!
//! Targets (issue 2): `power/four_term/single` at most 25 ns per evaluation;
//! `power/four_term/batch` at least 20 million states per second on one core;
//! `fit/power_model`: a fit over 100,000 samples in under 1 s (issue 5).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

use aloft::power::{AoaInput, FlightState, PowerBreakdown, PowerModel};
use aloft::vehicle::VehicleFile;

fn model() -> PowerModel {
    PowerModel::new(
        VehicleFile::builtin("dji-m100")
            .and_then(|f| f.power_vehicle())
            .expect("built-in vehicle"),
    )
}

/// A spread of states over the envelope the paper flew and beyond: 0-20 m/s, +-25 deg roll and
/// pitch, climb +-3 m/s, so the quartic solver sees many different inflows (generated, not random,
/// so the workload is the same on every run).
fn states(n: usize, geometric: bool) -> Vec<FlightState> {
    (0..n)
        .map(|i| {
            let f = i as f64 / n as f64;
            let s = (i as f64 * 0.618_033_988_75).fract();
            FlightState {
                airspeed_mps: 20.0 * f,
                roll_rad: (50.0 * s - 25.0).to_radians(),
                pitch_rad: (25.0 - 50.0 * (1.0 - f) * s).to_radians(),
                climb_rate_mps: 6.0 * s - 3.0,
                aoa: if geometric {
                    AoaInput::Geometric {
                        air_direction_rad: 6.0 * s - 3.0,
                    }
                } else {
                    AoaInput::Paper
                },
            }
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let m = model();
    let mut group = c.benchmark_group("power/four_term");
    let one = FlightState::new(6.0, 0.03, -0.14, 0.2);
    group.bench_function("single", |b| {
        b.iter(|| m.evaluate(black_box(&one)).map(|p| p.electrical_w))
    });
    let geo = FlightState {
        aoa: AoaInput::Geometric {
            air_direction_rad: 0.3,
        },
        ..one
    };
    group.bench_function("single_geometric", |b| {
        b.iter(|| m.evaluate(black_box(&geo)).map(|p| p.electrical_w))
    });
    for (name, geometric) in [("batch", false), ("batch_geometric", true)] {
        let input = states(100_000, geometric);
        let mut out = vec![
            PowerBreakdown {
                thrust_n: 0.0,
                induced_velocity_mps: 0.0,
                hover_induced_velocity_mps: 0.0,
                induced_w: 0.0,
                parasitic_w: 0.0,
                profile_w: 0.0,
                acceleration_w: 0.0,
                climb_w: 0.0,
                aero_w: 0.0,
                electrical_w: 0.0,
            };
            input.len()
        ];
        group.throughput(Throughput::Elements(input.len() as u64));
        group.bench_function(name, |b| {
            b.iter(|| {
                m.evaluate_batch(black_box(&input), &mut out)
                    .expect("states are valid");
                black_box(&out);
            })
        });
    }
    group.finish();
}

/// 100,000 synthetic samples of the M100 (forward flight 0-14 m/s at the pitch that balances
/// drag, rolls, some climbs), fitted from a wrong template with the known-geometry options.
fn bench_fit(c: &mut Criterion) {
    use aloft::power::{fit_power_model, FitOptions, FitSample, Vehicle, VehicleParams};
    let truth = model();
    let samples: Vec<FitSample> = (0..100_000)
        .map(|i| {
            let f = f64::from(i % 1000) / 1000.0;
            let s = (f64::from(i) * 0.618_033_988_75).fract() - 0.5;
            let v = 14.0 * f;
            let w = truth.vehicle().weight_n();
            let pitch = -(truth.vehicle().drag().force_n(v) / w).atan() + 0.05 * s;
            let state = FlightState::new(v, 0.3 * s, pitch, if i % 7 == 0 { 2.0 * s } else { 0.0 });
            let p = truth.evaluate(&state).expect("valid").electrical_w;
            FitSample::new(state, p * (1.0 + 0.01 * s))
        })
        .collect();
    let start = Vehicle::new(VehicleParams {
        efficiency: 0.7,
        mu1_n_s_per_m: 0.3,
        ..truth.vehicle().params().clone()
    })
    .expect("valid template");
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    group.bench_function("power_model", |b| {
        b.iter(|| {
            fit_power_model(&start, black_box(&samples), &FitOptions::known_geometry())
                .expect("fit")
        })
    });
    group.finish();
}

criterion_group!(benches, bench, bench_fit);
criterion_main!(benches);
