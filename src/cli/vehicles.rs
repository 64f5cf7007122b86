//! `aloft vehicles`: list the built-in vehicles with their sources; `aloft vehicles calibrate`:
//! a vehicle file from a spec sheet; `aloft vehicles template`: a commented vehicle file to
//! fill in.

use std::io::Write;
use std::path::PathBuf;

use aloft::engine::{
    calibrate_spec_file, list_vehicles, SpecCalibration, VehicleEntry, VEHICLE_TEMPLATE,
};
use anyhow::Result;
use clap::{Args, Subcommand};

use super::{output, Format, Outcome};

#[derive(Debug, Args)]
pub struct VehiclesArgs {
    #[command(subcommand)]
    action: Option<VehiclesAction>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

#[derive(Debug, Subcommand)]
enum VehiclesAction {
    /// Make a vehicle file from a spec sheet: rotors, masses, battery and one published hover time
    /// (the efficiency is calibrated on it; see "A vehicle from its spec sheet" in docs/guide.md).
    Calibrate(CalibrateArgs),
    /// Print a commented vehicle file for your own multirotor, which loads as it is: replace the
    /// values marked CHANGE (every key, unit, range and default: docs/vehicle-file.md).
    Template,
}

#[derive(Debug, Args)]
struct CalibrateArgs {
    /// The spec sheet (TOML: name, rotors, rotor_diameter_m, frame_mass_kg, [battery],
    /// [published_hover]).
    spec: PathBuf,
    /// Write the vehicle file here.
    #[arg(short = 'o', long, value_name = "VEHICLE.toml")]
    output: PathBuf,
    /// Replace an existing output (a regular file, or a link itself, never what it points to;
    /// never a device, a FIFO or a folder). Without it an existing output is kept (exit 2).
    #[arg(long)]
    force: bool,
    /// Output format of the summary.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(args: VehiclesArgs) -> Result<Outcome> {
    match args.action {
        Some(VehiclesAction::Calibrate(c)) => calibrate(c),
        Some(VehiclesAction::Template) => {
            std::io::stdout()
                .lock()
                .write_all(VEHICLE_TEMPLATE.as_bytes())?;
            Ok(Outcome::Ok)
        }
        None => list(args.format),
    }
}

fn list(format: Format) -> Result<Outcome> {
    let entries = list_vehicles()?;
    let mut out = std::io::stdout().lock();
    match format {
        Format::Json => output::write_json(&mut out, &entries)?,
        Format::Csv => list_csv(out, &entries)?,
        Format::Table => list_table(&mut out, &entries)?,
    }
    Ok(Outcome::Ok)
}

fn list_csv(out: impl Write, entries: &[VehicleEntry]) -> Result<()> {
    let header = [
        "name",
        "takeoff_mass_kg",
        "models",
        "batteries",
        "description",
        "calibrated_on",
        "published",
    ];
    let records = entries.iter().map(|e| {
        let (cal, publ) = source_words(e);
        [
            e.name.to_string(),
            e.takeoff_mass_kg.to_string(),
            e.models.join(" "),
            e.batteries.join(" "),
            e.description.clone(),
            cal.to_string(),
            publ.to_string(),
        ]
    });
    output::write_csv(out, &header, records)
}

/// What the efficiency was calibrated on and where it was published, or empty.
fn source_words(e: &VehicleEntry) -> (&str, &str) {
    e.source
        .as_ref()
        .map(|s| (s.calibrated_on.as_str(), s.published.as_str()))
        .unwrap_or(("", ""))
}

fn list_table(out: &mut impl Write, entries: &[VehicleEntry]) -> Result<()> {
    let nw = entries.iter().map(|e| e.name.len()).max().unwrap_or(4);
    writeln!(
        out,
        "{:<nw$}  {:>8}  {:<10}  {:<28}  description",
        "name", "take-off", "models", "batteries"
    )?;
    for e in entries {
        let mass = format!("{:.3} kg", e.takeoff_mass_kg);
        writeln!(
            out,
            "{:<nw$}  {:>8}  {:<10}  {:<28}  {}",
            e.name,
            mass,
            e.models.join(","),
            e.batteries.join(","),
            e.description
        )?;
        if let Some(s) = &e.source {
            writeln!(out, "{:<nw$}  figures: {}", "", s.figures)?;
            writeln!(out, "{:<nw$}  calibrated on: {}", "", s.calibrated_on)?;
            writeln!(out, "{:<nw$}  published: {}", "", s.published)?;
        }
    }
    Ok(())
}

fn calibrate(args: CalibrateArgs) -> Result<Outcome> {
    let c = calibrate_spec_file(&args.spec)?;
    c.write_vehicle_file(&args.output, args.force)?;
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &c)?,
        Format::Csv => calibrate_csv(out, &c)?,
        Format::Table => calibrate_table(&mut out, &c, &args.output)?,
    }
    Ok(Outcome::Ok)
}

fn calibrate_csv(out: impl Write, c: &SpecCalibration) -> Result<()> {
    let header = [
        "name",
        "battery",
        "takeoff_mass_kg",
        "published_minutes",
        "efficiency",
        "hover_power_w",
        "max_minutes_at_unit_efficiency",
    ];
    let record = [
        c.name.clone(),
        c.battery.clone(),
        c.takeoff_mass_kg.to_string(),
        c.published_minutes.to_string(),
        c.calibration.efficiency.to_string(),
        c.calibration.hover_power_w.to_string(),
        c.calibration.max_minutes_at_unit_efficiency.to_string(),
    ];
    output::write_csv(out, &header, [record])
}

fn calibrate_table(
    out: &mut impl Write,
    c: &SpecCalibration,
    path: &std::path::Path,
) -> Result<()> {
    writeln!(
        out,
        "{}: efficiency {:.4}, so that it hovers {} min at {} kg with {} ({:.1} W)",
        c.name,
        c.calibration.efficiency,
        c.published_minutes,
        c.takeoff_mass_kg,
        c.battery,
        c.calibration.hover_power_w
    )?;
    writeln!(
        out,
        "  the pack could give at most {:.1} min at this mass with efficiency 1",
        c.calibration.max_minutes_at_unit_efficiency
    )?;
    for d in &c.defaults {
        writeln!(out, "  default: {d}")?;
    }
    writeln!(out, "wrote {}", path.display())?;
    Ok(())
}
