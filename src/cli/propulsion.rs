//! `aloft propulsion`: the propulsion chain at hover for a payload, or swept over take-off mass
//! (the propulsion seed's Fig. 13).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;

use aloft::engine::{hover, hover_sweep, HoverRequest, HoverResult, SweepPoint, Vehicle};

use aloft::engine::flags::finite;

use super::output::{self, ForceFlag, Row};
use super::plot::ChartFile;
use super::{Format, Outcome};

#[derive(Debug, Args)]
pub struct PropulsionArgs {
    /// Vehicle with a [propulsion] table: a built-in name or a vehicle TOML file.
    #[arg(long, default_value = "aec-quadrotor")]
    vehicle: String,
    /// Payload in kg, added to the vehicle's empty mass.
    #[arg(value_parser = finite(),
        long,
        default_value_t = 0.0,
        allow_negative_numbers = true,
        conflicts_with = "takeoff_mass_kg"
    )]
    payload_kg: f64,
    /// Take-off mass in kg (instead of --payload-kg).
    #[arg(value_parser = finite(), long, allow_negative_numbers = true)]
    takeoff_mass_kg: Option<f64>,
    /// Sweep take-off mass FROM:TO:STEP in kg (e.g. 7:13:0.5), the seed's Fig. 13.
    #[arg(long, value_name = "FROM:TO:STEP", conflicts_with_all = ["payload_kg", "takeoff_mass_kg"])]
    sweep_takeoff_mass: Option<String>,
    /// With --sweep-takeoff-mass: also write an SVG chart of flight time and power against mass.
    #[arg(long, value_name = "SVG", requires = "sweep_takeoff_mass")]
    plot: Option<PathBuf>,
    #[command(flatten)]
    force: ForceFlag,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(args: PropulsionArgs) -> Result<Outcome> {
    args.force.check(args.plot.as_deref())?;
    let vehicle = Vehicle::load(&args.vehicle)?;
    if let Some(spec) = &args.sweep_takeoff_mass {
        let (from, to, step) = parse_range(spec)?;
        let sweep = hover_sweep(&vehicle, from, to, step)
            .with_context(|| format!("--sweep-takeoff-mass '{spec}'"))?;
        if let Some(path) = &args.plot {
            plot_sweep(args.force.chart(path), vehicle.name(), &sweep.points)
                .with_context(|| format!("cannot write the plot {}", path.display()))?;
        }
        let mut out = std::io::stdout().lock();
        match args.format {
            Format::Json => output::write_json(&mut out, &sweep)?,
            Format::Csv => write_sweep_csv(out, &sweep.points)?,
            Format::Table => write_sweep_table(&mut out, vehicle.name(), &sweep.points)?,
        }
        return Ok(Outcome::Ok);
    }
    let request = match args.takeoff_mass_kg {
        Some(m) => HoverRequest::TakeoffMass(m),
        None => HoverRequest::Payload(args.payload_kg),
    };
    let h = hover(&vehicle, request)?;
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &h)?,
        Format::Csv => output::write_csv_value(out, &h)?,
        Format::Table => write_table(&mut out, vehicle.name(), &h)?,
    }
    Ok(Outcome::Ok)
}

/// `FROM:TO:STEP` in kg.
fn parse_range(spec: &str) -> Result<(f64, f64, f64)> {
    let parts: Vec<&str> = spec.split(':').collect();
    let [from, to, step] = parts.as_slice() else {
        bail!("--sweep-takeoff-mass '{spec}': expected FROM:TO:STEP in kg, e.g. 7:13:0.5");
    };
    let num = |s: &str, what: &str| -> Result<f64> {
        s.trim()
            .parse::<f64>()
            .with_context(|| format!("--sweep-takeoff-mass '{spec}': {what} '{s}' is not a number"))
    };
    Ok((num(from, "FROM")?, num(to, "TO")?, num(step, "STEP")?))
}

fn write_sweep_csv(out: impl Write, points: &[SweepPoint]) -> Result<()> {
    let header = [
        "takeoff_mass_kg",
        "thrust_per_rotor_n",
        "rotor_speed_rpm",
        "motor_current_a",
        "pack_current_a",
        "power_required_w",
        "power_drawn_w",
        "battery_heat_w",
        "flight_time_min",
        "error",
    ];
    output::write_csv(out, &header, points.iter().map(sweep_record))
}

/// A mass of the sweep: the hover's figures, or empty cells and the reason it cannot hover.
fn sweep_record(p: &SweepPoint) -> Vec<String> {
    let mut row = vec![p.takeoff_mass_kg.to_string()];
    match &p.result {
        Some(h) => row.extend(
            [
                h.thrust_per_rotor_n,
                h.rotor_speed_rpm,
                h.motor_current_a,
                h.pack_current_a,
                h.power_required_w,
                h.power_drawn_w,
                h.battery_heat_w,
                h.flight_time_min,
            ]
            .map(|v| v.to_string()),
        ),
        None => row.extend(std::iter::repeat_n(String::new(), 8)),
    }
    row.push(p.error.clone().unwrap_or_default());
    row
}

fn write_sweep_table(out: &mut impl Write, name: &str, points: &[SweepPoint]) -> Result<()> {
    writeln!(
        out,
        "{name}: hover across take-off mass (propulsion seed Fig. 13)"
    )?;
    writeln!(
        out,
        "{:>9} {:>9} {:>9} {:>9} {:>9} {:>9}  rotor rpm",
        "mass kg", "power W", "drawn W", "pack A", "heat W", "time min"
    )?;
    for p in points {
        match &p.result {
            Some(h) => writeln!(
                out,
                "{:>9.2} {:>9.0} {:>9.0} {:>9.2} {:>9.0} {:>9.2}  {:.0}",
                p.takeoff_mass_kg,
                h.power_required_w,
                h.power_drawn_w,
                h.pack_current_a,
                h.battery_heat_w,
                h.flight_time_min,
                h.rotor_speed_rpm
            )?,
            None => writeln!(
                out,
                "{:>9.2}  cannot hover: {}",
                p.takeoff_mass_kg,
                p.error.as_deref().unwrap_or_default()
            )?,
        }
    }
    Ok(())
}

fn write_table(out: &mut impl Write, name: &str, h: &HoverResult) -> Result<()> {
    let title = format!(
        "{}: hover at {:.3} kg take-off mass ({} rotors, {} packs)",
        name, h.takeoff_mass_kg, h.rotor_count, h.pack_count
    );
    let rows = vec![
        Row::num("thrust per rotor", h.thrust_per_rotor_n, 2, "N"),
        Row::num("rotor speed", h.rotor_speed_rpm, 0, "rpm"),
        Row::num("rotor torque", h.torque_nm, 3, "N m"),
        Row::num("motor current", h.motor_current_a, 2, "A"),
        Row::num("motor voltage", h.motor_voltage_v, 2, "V"),
        Row::num("pack current", h.pack_current_a, 2, "A"),
        Row::num("pack terminal voltage", h.pack_terminal_voltage_v, 2, "V"),
        Row::num("power required (all motors)", h.power_required_w, 0, "W"),
        Row::num("power drawn from packs", h.power_drawn_w, 0, "W"),
        Row::num("heat in packs", h.battery_heat_w, 0, "W"),
        Row::num("flight time", h.flight_time_min, 2, "min"),
    ];
    output::write_table(out, &title, &rows)?;
    if h.motor_voltage_v > h.pack_terminal_voltage_v {
        writeln!(
            out,
            "  note: the motor needs {:.2} V but the pack delivers {:.2} V at this current ({:.1} % over full throttle)",
            h.motor_voltage_v,
            h.pack_terminal_voltage_v,
            100.0 * (h.motor_voltage_v / h.pack_terminal_voltage_v - 1.0)
        )?;
    }
    Ok(())
}

fn plot_sweep(file: ChartFile<'_>, name: &str, points: &[SweepPoint]) -> Result<()> {
    use plotters::prelude::*;
    let ok: Vec<(f64, &HoverResult)> = points
        .iter()
        .filter_map(|p| p.result.as_ref().map(|h| (p.takeoff_mass_kg, h)))
        .collect();
    if ok.is_empty() {
        bail!("no mass in the sweep can hover: nothing to plot");
    }
    let (x0, x1) = (ok[0].0, ok[ok.len() - 1].0.max(ok[0].0 + 1e-6));
    let t_max = ok
        .iter()
        .map(|(_, h)| h.flight_time_min)
        .fold(0.0, f64::max)
        * 1.1;
    let p_max = ok
        .iter()
        .map(|(_, h)| h.power_required_w)
        .fold(0.0, f64::max)
        * 1.1;
    super::plot::dual_lines_file(
        file,
        (800, 500),
        format!("{name}: flight time and power against take-off mass"),
        (x0..x1, "take-off mass (kg)"),
        super::plot::Line {
            desc: "flight time (min)",
            max: t_max,
            color: BLUE,
            points: ok.iter().map(|(m, h)| (*m, h.flight_time_min)).collect(),
        },
        super::plot::Line {
            desc: "power required (W)",
            max: p_max,
            color: RED,
            points: ok.iter().map(|(m, h)| (*m, h.power_required_w)).collect(),
        },
    )
}
