//! `aloft power`: the four-term model for one flight state, or a CSV of states streamed through it.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use aloft::engine::{
    power_csv_file, power_point, power_values, FlightStateDeg, PowerAnswer, PowerQuery, POWER_KEYS,
};

use super::output::{self, ForceFlag};
use super::{Format, Outcome};
use aloft::engine::flags::{finite, PowerModelFlags};

#[derive(Debug, Args)]
pub struct PowerArgs {
    /// The engine's model options (vehicle, pack, payload, terms, angle of attack).
    #[command(flatten)]
    model: PowerModelFlags,
    /// Airspeed in m/s: the speed of the vehicle relative to the air (horizontal, as the paper assumes).
    #[arg(value_parser = finite(), long, default_value_t = 0.0, allow_negative_numbers = true)]
    airspeed: f64,
    /// Roll in degrees (positive: right side down).
    #[arg(value_parser = finite(), long, default_value_t = 0.0, allow_negative_numbers = true)]
    roll: f64,
    /// Pitch in degrees (positive: nose up; forward flight pitches the nose down, e.g. -8).
    #[arg(value_parser = finite(), long, default_value_t = 0.0, allow_negative_numbers = true)]
    pitch: f64,
    /// Vertical speed in m/s, positive up (only the climb term, eq 13, uses it).
    #[arg(value_parser = finite(), long, default_value_t = 0.0, allow_negative_numbers = true)]
    climb_rate: f64,
    /// Direction of the air-relative velocity in degrees from the nose (0 forward, 90 to the
    /// right); selects the geometric angle of attack.
    #[arg(value_parser = finite(), long, allow_negative_numbers = true, value_name = "DEG")]
    air_direction_deg: Option<f64>,
    /// Also report the gradient of electrical power with respect to airspeed, roll and pitch.
    #[arg(long)]
    gradient: bool,
    /// Output format (batch mode always writes CSV).
    #[arg(long, value_enum)]
    format: Option<Format>,
    /// Batch mode: CSV of states with columns airspeed_mps, roll_deg, pitch_deg and optionally
    /// climb_rate_mps and air_direction_deg; streamed row by row.
    #[arg(long, value_name = "CSV", conflicts_with_all = ["gradient"])]
    input: Option<PathBuf>,
    /// Batch mode: write the result CSV here instead of standard output.
    #[arg(long, short = 'o', value_name = "CSV", requires = "input")]
    output: Option<PathBuf>,
    #[command(flatten)]
    force: ForceFlag,
}

impl PowerArgs {
    fn query(&self) -> PowerQuery {
        PowerQuery {
            model: self.model.query(),
            state: FlightStateDeg {
                airspeed_mps: self.airspeed,
                roll_deg: self.roll,
                pitch_deg: self.pitch,
                climb_rate_mps: self.climb_rate,
                air_direction_deg: self.air_direction_deg,
            },
            gradient: self.gradient,
        }
    }
}

pub fn run(mut args: PowerArgs) -> Result<Outcome> {
    let flying = aloft::engine::load_flying(&args.model.vehicle, &mut args.model.battery)?;
    let vehicle = flying.vehicle;
    if let Some(path) = &args.input {
        if matches!(args.format, Some(Format::Json | Format::Table)) {
            bail!("batch mode (--input) writes CSV only; drop --format or use --format csv");
        }
        if args.model.aoa.is_some() || args.air_direction_deg.is_some() {
            bail!("in batch mode the angle of attack is per row: add an air_direction_deg column for the geometric model");
        }
        let output = args.output.as_deref().map(|p| (p, args.force.force));
        power_csv_file(&vehicle, &args.model.query(), path, output)?;
        return Ok(Outcome::Ok);
    }
    let answer = power_point(&vehicle, &args.query())?;
    let mut out = std::io::stdout().lock();
    match args.format.unwrap_or_default() {
        Format::Json => output::write_json(&mut out, &answer)?,
        Format::Csv => write_csv(out, &args, &answer)?,
        Format::Table => write_table(&mut out, &args, &answer)?,
    }
    Ok(Outcome::Ok)
}

fn write_csv(out: impl Write, args: &PowerArgs, a: &PowerAnswer) -> Result<()> {
    let mut header = vec!["airspeed_mps", "roll_deg", "pitch_deg", "climb_rate_mps"];
    header.extend(POWER_KEYS);
    let mut row = vec![args.airspeed, args.roll, args.pitch, args.climb_rate];
    row.extend(power_values(&a.power));
    if let Some(g) = &a.electrical_gradient {
        header.extend([
            "d_airspeed_w_per_mps",
            "d_roll_w_per_deg",
            "d_pitch_w_per_deg",
        ]);
        row.extend([
            g.d_airspeed_w_per_mps,
            g.d_roll_w_per_deg,
            g.d_pitch_w_per_deg,
        ]);
    }
    output::write_csv(out, &header, [row.iter().map(|v| v.to_string())])
}

fn write_table(out: &mut impl Write, args: &PowerArgs, a: &PowerAnswer) -> Result<()> {
    let p = &a.power;
    let title = format!(
        "{}, {}\nAir: {}\nairspeed {:.2} m/s, roll {:.2} deg, pitch {:.2} deg, climb {:.2} m/s (angle of attack: {})",
        a.context.vehicle, a.context.mass, a.air.describe(), args.airspeed, args.roll, args.pitch, args.climb_rate, a.context.aoa
    );
    let mut rows = output::num_rows(&[
        ("thrust", p.thrust_n, 2, "N"),
        ("induced velocity", p.induced_velocity_mps, 2, "m/s"),
        (
            "hover induced velocity",
            p.hover_induced_velocity_mps,
            2,
            "m/s",
        ),
        ("induced power (eq 8)", p.induced_w, 1, "W"),
        ("parasitic power (eq 11)", p.parasitic_w, 1, "W"),
        ("profile power (eq 12)", p.profile_w, 1, "W"),
        (
            "acceleration work (eq 8, exact AoA)",
            p.acceleration_w,
            1,
            "W",
        ),
        ("climb power (eq 13)", p.climb_w, 1, "W"),
        ("aerodynamic total (eq 7)", p.aero_w, 1, "W"),
        ("electrical (eq 14)", p.electrical_w, 1, "W"),
        ("efficiency eta", a.context.efficiency, 4, ""),
    ]);
    if let Some(g) = &a.electrical_gradient {
        rows.extend(output::num_rows(&[
            ("dP/d airspeed", g.d_airspeed_w_per_mps, 2, "W per m/s"),
            ("dP/d roll", g.d_roll_w_per_deg, 2, "W per deg"),
            ("dP/d pitch", g.d_pitch_w_per_deg, 2, "W per deg"),
        ]));
    }
    output::write_table(out, &title, &rows)?;
    if !a.context.removed.is_empty() {
        writeln!(out, "  (terms removed: {})", a.context.removed.join(", "))?;
    }
    Ok(())
}
