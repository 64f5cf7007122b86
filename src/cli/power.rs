//! `aloft power`: the four-term model for one flight state, or a CSV of states streamed through it.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use aloft::engine::{
    power_csv_file, power_point, power_values, PowerAnswer, PowerQuery, Vehicle, POWER_KEYS,
};

use super::output::{self, Row};
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
}

impl PowerArgs {
    fn query(&self) -> PowerQuery {
        PowerQuery {
            airspeed_mps: self.airspeed,
            roll_deg: self.roll,
            pitch_deg: self.pitch,
            climb_rate_mps: self.climb_rate,
            air_direction_deg: self.air_direction_deg,
            gradient: self.gradient,
            ..self.model.query()
        }
    }
}

pub fn run(args: PowerArgs) -> Result<Outcome> {
    let vehicle = Vehicle::load(&args.model.vehicle)?;
    if let Some(path) = &args.input {
        if matches!(args.format, Some(Format::Json | Format::Table)) {
            bail!("batch mode (--input) writes CSV only; drop --format or use --format csv");
        }
        if args.model.aoa.is_some() || args.air_direction_deg.is_some() {
            bail!("in batch mode the angle of attack is per row: add an air_direction_deg column for the geometric model");
        }
        power_csv_file(&vehicle, &args.query(), path, args.output.as_deref())?;
        return Ok(Outcome::Ok);
    }
    let answer = power_point(&vehicle, &args.query())?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match args.format.unwrap_or_default() {
        Format::Json => output::write_json(&mut out, &answer)?,
        Format::Csv => write_csv(out, &args, &answer)?,
        Format::Table => write_table(&mut out, &args, &answer)?,
    }
    Ok(Outcome::Ok)
}

fn write_csv(out: impl Write, args: &PowerArgs, a: &PowerAnswer) -> Result<()> {
    let mut w = csv::Writer::from_writer(out);
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
    w.write_record(&header)?;
    w.write_record(row.iter().map(|v| v.to_string()))?;
    w.flush()?;
    Ok(())
}

fn write_table(out: &mut impl Write, args: &PowerArgs, a: &PowerAnswer) -> Result<()> {
    let p = &a.power;
    let title = format!(
        "{}, {}\nairspeed {:.2} m/s, roll {:.2} deg, pitch {:.2} deg, climb {:.2} m/s (angle of attack: {})",
        a.context.vehicle, a.context.mass, args.airspeed, args.roll, args.pitch, args.climb_rate, a.context.aoa
    );
    let f1 = |v: f64| format!("{v:.1}");
    let f2 = |v: f64| format!("{v:.2}");
    let mut rows = vec![
        Row::new("thrust", f2(p.thrust_n), "N"),
        Row::new("induced velocity", f2(p.induced_velocity_mps), "m/s"),
        Row::new(
            "hover induced velocity",
            f2(p.hover_induced_velocity_mps),
            "m/s",
        ),
        Row::new("induced power (eq 8)", f1(p.induced_w), "W"),
        Row::new("parasitic power (eq 11)", f1(p.parasitic_w), "W"),
        Row::new("profile power (eq 12)", f1(p.profile_w), "W"),
        Row::new(
            "acceleration work (eq 8, exact AoA)",
            f1(p.acceleration_w),
            "W",
        ),
        Row::new("climb power (eq 13)", f1(p.climb_w), "W"),
        Row::new("aerodynamic total (eq 7)", f1(p.aero_w), "W"),
        Row::new("electrical (eq 14)", f1(p.electrical_w), "W"),
        Row::new("efficiency eta", format!("{:.4}", a.context.efficiency), ""),
    ];
    if let Some(g) = &a.electrical_gradient {
        rows.push(Row::new(
            "dP/d airspeed",
            f2(g.d_airspeed_w_per_mps),
            "W per m/s",
        ));
        rows.push(Row::new("dP/d roll", f2(g.d_roll_w_per_deg), "W per deg"));
        rows.push(Row::new("dP/d pitch", f2(g.d_pitch_w_per_deg), "W per deg"));
    }
    output::write_table(out, &title, &rows)?;
    if !a.context.removed.is_empty() {
        writeln!(out, "  (terms removed: {})", a.context.removed.join(", "))?;
    }
    Ok(())
}
