//! `aloft mission --replay`: the energy of a recorded flight from its trajectory alone.

use anyhow::{bail, Result};

use aloft::engine::{replay_log, ReplayAcceleration, ReplayAnswer, ReplayRequest, Vehicle};

use super::mission_args::{AccelArg, MissionArgs};
use super::output::{self, Row};
use super::{Format, Outcome};

pub fn run(args: &MissionArgs) -> Result<Outcome> {
    let Some(log) = &args.replay else {
        bail!("--replay needs a log");
    };
    if args.format == Format::Csv {
        bail!("aloft mission --replay writes table or json");
    }
    if args.flags.wind_field.is_some() || args.flags.gust_std.is_some() {
        bail!("--replay takes a steady wind (--wind-speed, --wind-from) for logs without one; a field or gusts belong to a planned mission");
    }
    let flying = aloft::engine::fly_with_battery(
        Vehicle::load(&args.flags.vehicle)?,
        args.flags.battery.as_deref(),
    )?;
    let vehicle = flying.vehicle;
    let request = ReplayRequest {
        log: log.clone(),
        profile: args.profile.clone(),
        payload_kg: args.flags.payload_kg.unwrap_or(0.0),
        lag_s: args.lag,
        acceleration: match args.acceleration {
            AccelArg::Velocity => ReplayAcceleration::Velocity {
                window_s: args.acceleration_window,
            },
            AccelArg::Log => ReplayAcceleration::Log,
        },
        aoa: args.flags.aoa,
        wind: args.flags.wind.spec(),
        battery: flying.battery,
        air: args.flags.air.input(),
    };
    let answer = replay_log(&vehicle, &request)?;
    for n in &answer.context.notes {
        eprintln!("aloft mission --replay: {n}");
    }
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &answer)?,
        Format::Table | Format::Csv => write_table(&mut out, &answer)?,
    }
    Ok(Outcome::Ok)
}

fn write_table(out: &mut impl std::io::Write, a: &ReplayAnswer) -> Result<()> {
    writeln!(
        out,
        "Replay of {}: {} trajectory points, {:.0} s, vehicle {} at {}",
        a.file, a.points, a.duration_s, a.vehicle, a.context.mass
    )?;
    writeln!(
        out,
        "Acceleration: {}; wind: {}\nAir: {}",
        a.context.acceleration,
        a.context.wind,
        a.air.describe()
    )?;
    writeln!(
        out,
        "{} flight(s): {:.1} s airborne, {:.1} s on the ground ({}){}",
        a.flights,
        a.airborne_s,
        a.ground_s,
        match a.ground_source {
            "log" => "the log's landed state",
            "detected" => "detected from height, speed and power",
            _ => "the log's landed state, detected where it has none",
        },
        match a.idle_power_w {
            Some(w) => format!(", priced at the measured idle {w:.1} W"),
            None if a.ground_s > 0.0 => ", priced at 0 W (no power in the log)".to_string(),
            None => String::new(),
        }
    )?;
    writeln!(out)?;
    output::write_table(out, "Replay", &energy_rows(a))?;
    Ok(())
}

/// The energy rows: predicted and measured, airborne and on the ground.
fn energy_rows(a: &ReplayAnswer) -> Vec<Row<'_>> {
    let wh = |x: f64| format!("{x:.2}");
    let mut rows = vec![
        Row::new(
            "predicted energy, airborne (trajectory only)",
            wh(a.predicted_airborne_energy_wh),
            "Wh",
        ),
        Row::new(
            "predicted energy, on the ground (idle)",
            wh(a.predicted_ground_energy_wh),
            "Wh",
        ),
        Row::new("predicted energy", wh(a.predicted_energy_wh), "Wh"),
    ];
    let Some(m) = a.measured_energy_wh else {
        rows.push(Row::new(
            "measured energy",
            "no power in the log".to_string(),
            "",
        ));
        return rows;
    };
    if let Some(air) = a.measured_airborne_energy_wh {
        rows.push(Row::new("measured energy, airborne", wh(air), "Wh"));
    }
    if let Some(g) = a.measured_ground_energy_wh {
        rows.push(Row::new("measured energy, on the ground", wh(g), "Wh"));
    }
    rows.push(Row::new("measured energy (V x I)", wh(m), "Wh"));
    if let Some(e) = a.airborne_energy_error_percent {
        rows.push(Row::new("error, airborne", format!("{e:+.2}"), "%"));
    }
    rows.push(Row::new(
        "error",
        format!("{:+.2}", a.energy_error_percent.unwrap_or(0.0)),
        "%",
    ));
    rows.push(Row::new(
        "lag of power behind motion",
        format!("{:.2}", a.lag_s.unwrap_or(0.0)),
        "s",
    ));
    rows
}
