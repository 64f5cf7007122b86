//! Endurance queries of the built-in DJI M100: hover, best-endurance and best-range speeds along a
//! course into a headwind, orbit endurance (the same JSON as `aloft endurance --format json`).
//!
//! `cargo run --example endurance`

use aloft::engine::{endurance, EnduranceOptions, EnduranceSummary, Vehicle};

/// Still air, then a 6 m/s northerly with the course north (a headwind) and a 30 m orbit.
pub fn run(
    out: &mut dyn std::io::Write,
) -> Result<(EnduranceSummary, EnduranceSummary), Box<dyn std::error::Error>> {
    let m100 = Vehicle::builtin("dji-m100")?;
    let still = endurance(&m100, &EnduranceOptions::default())?;
    let headwind = endurance(
        &m100,
        &EnduranceOptions::from_json(
            r#"{"wind": {"speed_mps": 6, "from_deg": 0}, "course_deg": 0,
                "orbit_radius_m": 30, "orbit_speed_mps": 5, "reserve_percent": 20}"#,
        )?,
    )?;
    writeln!(out, "{}", still.to_json()?)?;
    writeln!(
        out,
        "into a 6 m/s headwind: best-range airspeed {:.1} m/s (still air {:.1}), range {:.2} km (still air {:.2})",
        headwind.report.max_range_speed_mps,
        still.report.max_range_speed_mps,
        headwind.report.max_range_m / 1000.0,
        still.report.max_range_m / 1000.0
    )?;
    Ok((still, headwind))
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    run(&mut std::io::stdout())?;
    Ok(())
}
