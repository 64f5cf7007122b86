//! Monte-Carlo scenarios (issue 17): `p_feasible` against an independent threshold found by
//! bisection, reproducibility across threads, zero spreads giving the deterministic plan bit for
//! bit, ordered percentiles and spreads that widen the answer (property tests).

use aloft::engine::{
    endurance, endurance_scenarios, plan_mission, plan_scenarios, EnduranceOptions, Mission,
    MissionOptions, Percentiles, ScenarioOptions, Uncertainty, Vehicle, WorkBounds,
};
use proptest::prelude::*;

use aloft_planner::mission_toml::{landing, leg, return_home, take_off};

fn m100() -> Vehicle {
    Vehicle::builtin("dji-m100").unwrap()
}

/// No spread at all: every draw is the request's own value.
fn no_spread(samples: u32) -> ScenarioOptions {
    ScenarioOptions {
        samples,
        power_sd_percent: 0.0,
        ..ScenarioOptions::default()
    }
}

/// The demo at a reserve that makes the payload the binding limit well below the take-off mass
/// limit, sampled at 0.5 s so that thousands of flights fit a debug test run.
fn reserve_bound() -> MissionOptions {
    MissionOptions {
        reserve_percent: Some(62.0),
        time_step_s: Some(0.5),
        ..MissionOptions::default()
    }
}

fn feasible_at(v: &Vehicle, payload_kg: f64) -> bool {
    let o = MissionOptions {
        payload_kg: Some(payload_kg),
        ..reserve_bound()
    };
    match plan_mission(v, &Mission::demo(), &o) {
        Ok(p) => p.summary().feasible,
        // beyond the take-off mass limit: cannot be flown
        Err(_) => false,
    }
}

/// Standard normal CDF from the complementary error function (Abramowitz and Stegun 7.1.26 is
/// too coarse here; this is the W. J. Cody rational form via libm-free series: erfc by its
/// continued fraction would do too). Accurate to 1e-7, far below the test's tolerance.
fn normal_cdf(x: f64) -> f64 {
    // Zelen and Severo (A&S 26.2.17), absolute error below 7.5e-8.
    let t = 1.0 / (1.0 + 0.231_641_9 * x.abs());
    let poly = t
        * (0.319_381_530
            + t * (-0.356_563_782
                + t * (1.781_477_937 + t * (-1.821_255_978 + t * 1.330_274_429))));
    let upper = (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt() * poly;
    if x >= 0.0 {
        1.0 - upper
    } else {
        upper
    }
}

#[test]
fn p_feasible_matches_the_normal_cdf_at_the_bisected_payload_threshold() {
    let v = m100();
    // Deterministic bisection of the payload at which the mission stops landing with the reserve.
    assert!(feasible_at(&v, 0.0) && !feasible_at(&v, 1.2));
    let (lo, hi) = aloft_core::bisect(0.0, 1.2, 30, |payload_kg| feasible_at(&v, payload_kg));
    let threshold = 0.5 * (lo + hi);
    // Payload drawn around a mean below the threshold; nothing else drawn.
    let (mean, sd) = (threshold - 0.1, 0.2);
    let sc = ScenarioOptions {
        samples: 2000,
        seed: 17,
        payload_sd_kg: sd,
        ..no_spread(0)
    };
    let o = MissionOptions {
        payload_kg: Some(mean),
        ..reserve_bound()
    };
    let u = plan_scenarios(&v, &Mission::demo(), &o, &sc).unwrap();
    // Feasible exactly when the drawn payload is below the threshold (a draw clipped at 0 is
    // below it too), so p = Phi((threshold - mean) / sd) = Phi(0.5) = 0.691.
    let expected = normal_cdf((threshold - mean) / sd);
    // Binomial standard error of a fraction of 2000 draws: sqrt(p (1 - p) / n) = 0.0103; four
    // of them (a false alarm once in 16,000 seeds), plus the bisection's 1e-9 kg (negligible).
    let se = (expected * (1.0 - expected) / 2000.0).sqrt();
    println!(
        "threshold {threshold:.6} kg, mean {mean:.6} kg, sd {sd} kg: p_feasible {} against Phi = {expected:.4} (4 se = {:.4})",
        u.p_feasible,
        4.0 * se
    );
    assert!(
        (u.p_feasible - expected).abs() < 4.0 * se,
        "p_feasible {} against {expected} +- {}",
        u.p_feasible,
        4.0 * se
    );
    assert_eq!(u.samples, 2000);
}

#[test]
fn zero_spreads_give_the_deterministic_plan_bit_for_bit() {
    let v = m100();
    for o in [MissionOptions::default(), reserve_bound()] {
        let plan = plan_mission(&v, &Mission::demo(), &o).unwrap();
        let s = plan.summary();
        let u = plan_scenarios(&v, &Mission::demo(), &o, &no_spread(8)).unwrap();
        assert_eq!(u.p_feasible, if s.feasible { 1.0 } else { 0.0 });
        let e = u.energy_wh.unwrap();
        for x in [e.p5, e.p50, e.p95] {
            assert_eq!(x.to_bits(), s.energy_wh.to_bits());
        }
        let soc = u.end_soc.unwrap();
        assert_eq!(soc.p50.to_bits(), s.end_soc.to_bits());
        assert_eq!(u.duration_s.unwrap().p95.to_bits(), s.duration_s.to_bits());
        assert_eq!(
            u.point_of_no_return_s.p5.map(f64::to_bits),
            s.point_of_no_return_s.map(f64::to_bits)
        );
        assert_eq!(u.segments.len(), s.segments.len());
        for (b, seg) in u.segments.iter().zip(&s.segments) {
            assert_eq!(b.end_soc.p5.to_bits(), seg.end_soc.to_bits());
            assert_eq!(b.end_soc.p95.to_bits(), seg.end_soc.to_bits());
        }
    }
}

#[test]
fn the_same_seed_gives_the_same_answer_on_one_two_or_three_threads() {
    let v = m100();
    let o = MissionOptions {
        time_step_s: Some(0.5),
        gusts: Some(aloft::engine::GustSpec {
            std_mps: 1.0,
            seed: 3,
        }),
        ..reserve_bound()
    };
    let sc = |threads| ScenarioOptions {
        samples: 60,
        seed: 99,
        wind_speed_sd_mps: 1.5,
        wind_from_sd_deg: 20.0,
        payload_sd_kg: 0.2,
        capacity_sd_percent: 5.0,
        power_sd_percent: 3.0,
        threads,
        soc_fan: true,
        ..ScenarioOptions::default()
    };
    let one = plan_scenarios(&v, &Mission::demo(), &o, &sc(1)).unwrap();
    for t in [2, 3] {
        let other = plan_scenarios(&v, &Mission::demo(), &o, &sc(t)).unwrap();
        assert_eq!(one, other, "{t} threads");
        assert_eq!(
            serde_json::to_string(&one).unwrap(),
            serde_json::to_string(&other).unwrap()
        );
    }
    // Something was drawn: the answer is not the deterministic one.
    let e = one.energy_wh.unwrap();
    assert!(e.p5 < e.p95, "{e:?}");
    assert!(one.soc_fan.is_some());
    // Another seed, another answer.
    let other_seed = plan_scenarios(
        &v,
        &Mission::demo(),
        &o,
        &ScenarioOptions { seed: 100, ..sc(2) },
    )
    .unwrap();
    assert_ne!(one.energy_wh, other_seed.energy_wh);
}

/// Work bounds (issue 32): the steps of a request's scenarios are its samples times the plan's
/// duration over the time step, checked before any is flown; the most samples that fit are
/// named; a cancelled request stops.
#[test]
fn a_bound_on_the_steps_refuses_the_scenarios_that_pass_it_and_a_cancelled_one_stops() {
    let v = m100();
    let o = MissionOptions::default();
    let plan = plan_mission(&v, &Mission::demo(), &o).unwrap();
    // The demo's steps at the default 0.1 s, from the plan's duration (an independent figure).
    let steps = (plan.summary().duration_s / 0.1).ceil() as u64;
    let bounded = |samples: u32, max_steps: u64| ScenarioOptions {
        bounds: WorkBounds {
            max_steps: Some(max_steps),
            cancel: None,
        },
        ..no_spread(samples)
    };
    // Exactly at the bound: flown; one sample more: refused, naming the most that fit.
    let within = plan_scenarios(&v, &Mission::demo(), &o, &bounded(10, 10 * steps)).unwrap();
    assert_eq!(within.samples, 10);
    let e = plan_scenarios(&v, &Mission::demo(), &o, &bounded(11, 10 * steps)).unwrap_err();
    let message = e.to_string();
    assert!(
        matches!(
            e,
            aloft::Error::TooMuchWork {
                max_samples: 10,
                ..
            }
        ),
        "{message}"
    );
    assert!(message.contains("at most 10 samples"), "{message}");
    // Cancelled before the first flight: nothing is flown.
    let cancel = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
    let sc = ScenarioOptions {
        bounds: WorkBounds {
            max_steps: None,
            cancel: Some(cancel),
        },
        ..no_spread(1000)
    };
    let e = plan_scenarios(&v, &Mission::demo(), &o, &sc).unwrap_err();
    assert!(matches!(e, aloft::Error::Cancelled), "{e}");
}

#[test]
fn scenarios_the_vehicle_cannot_fly_are_infeasible_not_errors() {
    let v = m100();
    // Payload drawn around the take-off mass limit (1.245 kg of payload on the M100 with the
    // TB47D): about half the scenarios are too heavy to take off.
    let o = MissionOptions {
        payload_kg: Some(1.2),
        time_step_s: Some(0.5),
        ..MissionOptions::default()
    };
    let sc = ScenarioOptions {
        samples: 40,
        payload_sd_kg: 0.1,
        ..no_spread(0)
    };
    let u = plan_scenarios(&v, &Mission::demo(), &o, &sc).unwrap();
    assert!(u.p_feasible > 0.1 && u.p_feasible < 0.9, "{}", u.p_feasible);
    // Those that cannot be flown count as a point of no return at take-off.
    assert!(u.p_point_of_no_return >= 1.0 - u.p_feasible - 1e-12);
    assert_eq!(u.point_of_no_return_s.p5, Some(0.0));
    // Real input errors stay errors.
    let bad = MissionOptions {
        reserve_percent: Some(120.0),
        ..MissionOptions::default()
    };
    assert!(plan_scenarios(&v, &Mission::demo(), &bad, &sc).is_err());
    for bad in [
        ScenarioOptions {
            samples: 0,
            ..sc.clone()
        },
        ScenarioOptions {
            samples: 100_001,
            ..sc.clone()
        },
        ScenarioOptions {
            payload_sd_kg: -0.1,
            ..sc.clone()
        },
        ScenarioOptions {
            power_sd_percent: f64::NAN,
            ..sc.clone()
        },
    ] {
        let e = plan_scenarios(&v, &Mission::demo(), &o, &bad).unwrap_err();
        assert!(matches!(e, aloft::Error::InvalidInput { .. }), "{e}");
    }
}

#[test]
fn a_power_scale_on_a_propulsion_chain_scales_its_energy() {
    // The AEC quadrotor is flown by its propulsion chain: the model error scales the chain's
    // power, so every scenario's energy is the plan's times its factor, and with the spread at
    // zero it is the plan's exactly. (Its airframe and packs are the built-in's, from the
    // propulsion seed.)
    let v = Vehicle::builtin("aec-quadrotor").unwrap();
    let o = MissionOptions {
        time_step_s: Some(0.5),
        ..MissionOptions::default()
    };
    let plan = plan_mission(&v, &Mission::demo(), &o).unwrap();
    let zero = plan_scenarios(&v, &Mission::demo(), &o, &no_spread(3)).unwrap();
    assert_eq!(
        zero.energy_wh.unwrap().p50.to_bits(),
        plan.summary().energy_wh.to_bits()
    );
    let spread = ScenarioOptions {
        samples: 40,
        power_sd_percent: 5.0,
        ..no_spread(0)
    };
    let u = plan_scenarios(&v, &Mission::demo(), &o, &spread).unwrap();
    let e = u.energy_wh.unwrap();
    let nominal = plan.summary().energy_wh;
    // 40 normal draws: the 5th and 95th percentiles lie a few percent either side.
    assert!(e.p5 < nominal && e.p95 > nominal, "{e:?} around {nominal}");
    assert!(e.p5 > 0.8 * nominal && e.p95 < 1.2 * nominal, "{e:?}");
}

#[test]
fn endurance_scenarios_give_ordered_percentiles_around_the_answer() {
    let v = m100();
    let o = EnduranceOptions::default();
    let nominal = endurance(&v, &o).unwrap();
    let zero = endurance_scenarios(&v, &o, &no_spread(4)).unwrap();
    let h = zero.hover_endurance_s.unwrap();
    assert_eq!(h.p5.to_bits(), nominal.report.hover_endurance_s.to_bits());
    assert_eq!(
        zero.max_range_m.unwrap().p95.to_bits(),
        nominal.report.max_range_m.to_bits()
    );
    let u = endurance_scenarios(
        &v,
        &o,
        &ScenarioOptions {
            samples: 200,
            wind_speed_sd_mps: 2.0,
            capacity_sd_percent: 5.0,
            ..ScenarioOptions::default()
        },
    )
    .unwrap();
    assert_eq!(u.p_feasible, 1.0);
    let h = u.hover_endurance_s.unwrap();
    assert!(h.p5 < h.p50 && h.p50 < h.p95, "{h:?}");
    assert!(h.p5 < nominal.report.hover_endurance_s && h.p95 > nominal.report.hover_endurance_s);
    let r = u.max_range_m.unwrap();
    assert!(r.p5 < r.p95);
}

/// A short mission for the property tests: take-off, one leg, home, landing.
fn short_mission() -> Mission {
    let text = [
        "name = \"short\"\n[wind]\nspeed_mps = 4.0\nfrom_deg = 270.0\n".to_string(),
        take_off(20.0, 3.0),
        leg(300.0, 0.0, 10.0),
        return_home(10.0),
        landing(2.0),
    ]
    .concat();
    Mission::from_toml(&text, "test").unwrap()
}

/// The p95 - p5 width of the `band` of the short mission's answer (at a 0.5 s step) in the
/// scenarios of `sc` drawn with `seed`.
fn band_width(
    seed: u64,
    sc: ScenarioOptions,
    band: impl Fn(&Uncertainty) -> Option<Percentiles>,
) -> f64 {
    let o = MissionOptions {
        time_step_s: Some(0.5),
        ..MissionOptions::default()
    };
    let sc = ScenarioOptions { seed, ..sc };
    let b = band(&plan_scenarios(&m100(), &short_mission(), &o, &sc).unwrap()).unwrap();
    b.p95 - b.p5
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn percentiles_are_ordered(
        seed in any::<u64>(),
        wind_sd in 0.0f64..3.0,
        from_sd in 0.0f64..40.0,
        payload_sd in 0.0f64..0.3,
        capacity_sd in 0.0f64..10.0,
        power_sd in 0.0f64..10.0,
    ) {
        let o = MissionOptions { time_step_s: Some(0.5), payload_kg: Some(0.3), ..MissionOptions::default() };
        let sc = ScenarioOptions {
            samples: 24, seed,
            wind_speed_sd_mps: wind_sd, wind_from_sd_deg: from_sd, payload_sd_kg: payload_sd,
            capacity_sd_percent: capacity_sd, power_sd_percent: power_sd,
            ..ScenarioOptions::default()
        };
        let u = plan_scenarios(&m100(), &short_mission(), &o, &sc).unwrap();
        prop_assert!((0.0..=1.0).contains(&u.p_feasible));
        for p in [u.energy_wh, u.end_soc, u.duration_s].into_iter().flatten() {
            prop_assert!(p.p5 <= p.p50 && p.p50 <= p.p95, "{:?}", p);
        }
        for b in &u.segments {
            prop_assert!(b.end_soc.p5 <= b.end_soc.p50 && b.end_soc.p50 <= b.end_soc.p95);
        }
        let t = u.point_of_no_return_s;
        if let (Some(a), Some(b)) = (t.p5, t.p50) { prop_assert!(a <= b); }
        if let (Some(a), Some(b)) = (t.p50, t.p95) { prop_assert!(a <= b); }
    }

    #[test]
    fn the_energy_band_widens_with_the_power_spread(
        seed in any::<u64>(),
        sd in 0.5f64..10.0,
        more in 0.5f64..10.0,
    ) {
        // The same draws scaled further from 1: every scenario's energy moves away from the
        // plan's in proportion (the flight is the same, its power times the factor), so the
        // p95 - p5 width grows, and it is zero without a spread.
        let at = |power_sd_percent| {
            let sc = ScenarioOptions { power_sd_percent, ..no_spread(20) };
            band_width(seed, sc, |u| u.energy_wh)
        };
        let (zero, narrow, wide) = (at(0.0), at(sd), at(sd + more));
        prop_assert!(zero == 0.0);
        prop_assert!(narrow > 0.0 && wide > narrow, "{} {} {}", zero, narrow, wide);
    }

    #[test]
    fn the_end_state_band_widens_with_the_capacity_spread(
        seed in any::<u64>(),
        sd in 0.5f64..8.0,
        more in 0.5f64..8.0,
    ) {
        let at = |capacity_sd_percent| {
            let sc = ScenarioOptions { capacity_sd_percent, ..no_spread(20) };
            band_width(seed, sc, |u| u.end_soc)
        };
        prop_assert!(at(sd + more) > at(sd));
    }
}
