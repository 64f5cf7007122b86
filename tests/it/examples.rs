//! The examples of `examples/` run as functions (compiled once into this test, no `cargo run`),
//! with their results checked. `cargo test` also builds them as example binaries.

#[allow(dead_code)]
#[path = "../../examples/power_point.rs"]
mod power_point;

#[allow(dead_code)]
#[path = "../../examples/mission.rs"]
mod mission;

#[allow(dead_code)]
#[path = "../../examples/endurance.rs"]
mod endurance;

#[allow(dead_code)]
#[path = "../../examples/inflight_replan.rs"]
mod inflight_replan;

#[test]
fn power_point_example() {
    let mut out = Vec::new();
    let (hover_w, cruise_w) = power_point::run(&mut out).unwrap();
    // The M100 at the paper's 3.29 kg hovers on 400-600 W in the paper's data (power seed
    // Fig. 4) and its power curve dips below hover at moderate speed (translational lift).
    assert!((400.0..600.0).contains(&hover_w), "{hover_w}");
    assert!(cruise_w < hover_w, "{cruise_w} vs {hover_w}");
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("\"electrical_w\""));
    assert!(text.contains("take-off mass 3.290 kg"), "{text}");
}

#[test]
fn mission_example() {
    let mut out = Vec::new();
    let (demo, custom) = mission::run(&mut out).unwrap();
    assert!(demo.feasible && custom.feasible);
    assert_eq!(custom.mission, "out-and-back");
    assert!((custom.payload_kg - 0.4).abs() < 1e-12);
    // 1200 m plus the climb and descent.
    assert!(
        (custom.distance_m - 1280.0).abs() < 1.0,
        "{}",
        custom.distance_m
    );
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.starts_with("{\n  \"mission\": \"demo-survey\""),
        "{text}"
    );
}

#[test]
fn endurance_example() {
    let mut out = Vec::new();
    let (still, headwind) = endurance::run(&mut out).unwrap();
    // Into a headwind the best-range airspeed rises and the range over ground falls.
    assert!(headwind.report.max_range_speed_mps > still.report.max_range_speed_mps);
    assert!(headwind.report.max_range_m < still.report.max_range_m);
    assert!(headwind.report.orbit_endurance_s.is_some());
}

#[test]
fn inflight_replan_example_converges_on_the_true_efficiency() {
    let mut out = Vec::new();
    // As the example binary runs it: a re-plan every second, the check after one minute.
    let o = inflight_replan::run(&mut out, 1.0, 60.0).unwrap();
    // One re-plan a second from t = 1 s to the landing.
    assert!(
        (o.replans as f64 - o.duration_s.floor()).abs() <= 1.0,
        "{} re-plans in {} s",
        o.replans,
        o.duration_s
    );
    // With 2 % current and 0.5 % voltage noise (zero-mean), a minute of 10 Hz samples gives the
    // energy ratio to well under 0.5 %.
    assert!(
        (o.estimated_efficiency / o.true_efficiency - 1.0).abs() < 5e-3,
        "{o:?}"
    );
    // The nominal plan misses the landing charge by the 12 % efficiency error; the re-plan after
    // one minute must be within 0.5 percentage points of it.
    assert!(
        (o.nominal_landing_soc - o.true_landing_soc).abs() > 0.03,
        "{o:?}"
    );
    assert!(
        (o.replanned_landing_soc - o.true_landing_soc).abs() < 5e-3,
        "{o:?}"
    );
    assert!(o.nominal_efficiency > o.true_efficiency);
}
