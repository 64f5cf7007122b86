//! Plan the built-in demonstration mission and a mission written in code (TOML text) with the
//! built-in DJI M100 in a wind; print the summary JSON (the same as `aloft mission --format json`).
//!
//! `cargo run --example mission`

use aloft::engine::WindSpec;
use aloft::engine::{plan_mission, Mission, MissionOptions, MissionSummary, Vehicle};

/// A 600 m out-and-back at 40 m.
const OUT_AND_BACK: &str = r#"
name = "out-and-back"
[[segment]]
kind = "take-off"
altitude_m = 40.0
climb_rate_mps = 3.0
[[segment]]
kind = "leg"
east_m = 600.0
north_m = 0.0
ground_speed_mps = 10.0
[[segment]]
kind = "return"
ground_speed_mps = 10.0
[[segment]]
kind = "landing"
rate_mps = 1.5
"#;

/// The demo's summary and the out-and-back's in a 5 m/s westerly with 0.4 kg of payload.
pub fn run(
    out: &mut dyn std::io::Write,
) -> Result<(MissionSummary, MissionSummary), Box<dyn std::error::Error>> {
    let m100 = Vehicle::builtin("dji-m100")?;
    let demo = plan_mission(&m100, &Mission::demo(), &MissionOptions::default())?;
    writeln!(out, "{}", demo.to_json()?)?;

    let options = MissionOptions {
        payload_kg: Some(0.4),
        wind: Some(WindSpec::uniform(5.0, 270.0)),
        ..MissionOptions::default()
    };
    let custom = plan_mission(&m100, &Mission::from_toml(OUT_AND_BACK, "code")?, &options)?;
    let s = custom.summary();
    writeln!(
        out,
        "{}: {:.1} Wh over {:.0} s, lands with {:.0} % usable ({})",
        s.mission,
        s.energy_wh,
        s.duration_s,
        s.reserve_soc * 100.0,
        if s.feasible {
            "feasible"
        } else {
            "NOT feasible"
        }
    )?;
    Ok((demo.summary().clone(), s.clone()))
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    run(&mut std::io::stdout())?;
    Ok(())
}
