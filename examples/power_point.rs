//! Power of one flight state with the power seed's DJI M100 at the paper's 3.29 kg (the built-in
//! `dji-m100-paper`; the four-term model, power seed eqs 7-14). `dji-m100` is the same model at
//! its take-off mass, airframe + pack + payload.
//!
//! `cargo run --example power_point`

use aloft::engine::Vehicle;
use aloft::power::FlightState;

/// Electrical power in hover and at 10 m/s with 8 deg nose down, W.
pub fn run(out: &mut dyn std::io::Write) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    let m100 = Vehicle::builtin("dji-m100-paper")?;
    let hover = m100.power(&FlightState::new(0.0, 0.0, 0.0, 0.0))?;
    let cruise = m100.power(&FlightState::new(10.0, 0.0, (-8.0f64).to_radians(), 0.0))?;
    writeln!(
        out,
        "{}, {}: hover {:.1} W (induced {:.1} W, profile {:.1} W), 10 m/s cruise {:.1} W",
        m100.name(),
        m100.takeoff_mass(None, 0.0)?.describe(),
        hover.electrical_w,
        hover.induced_w,
        hover.profile_w,
        cruise.electrical_w
    )?;
    writeln!(out, "{}", serde_json::to_string_pretty(&cruise)?)?;
    Ok((hover.electrical_w, cruise.electrical_w))
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    run(&mut std::io::stdout())?;
    Ok(())
}
