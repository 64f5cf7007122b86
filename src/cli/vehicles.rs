//! `aloft vehicles`: list the built-in vehicles.

use std::io::Write;

use aloft::engine::list_vehicles;
use anyhow::Result;
use clap::Args;

use super::{output, Format, Outcome};

#[derive(Debug, Args)]
pub struct VehiclesArgs {
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(args: VehiclesArgs) -> Result<Outcome> {
    let entries = list_vehicles()?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &entries)?,
        Format::Csv => {
            let mut w = csv::Writer::from_writer(out);
            w.write_record(["name", "mass_kg", "models", "description"])?;
            for e in &entries {
                let mass = e.mass_kg.map(|m| m.to_string()).unwrap_or_default();
                w.write_record([e.name, &mass, &e.models.join(" "), &e.description])?;
            }
            w.flush()?;
        }
        Format::Table => {
            let nw = entries.iter().map(|e| e.name.len()).max().unwrap_or(4);
            writeln!(
                out,
                "{:<nw$}  {:>8}  {:<10}  description",
                "name", "mass", "models"
            )?;
            for e in &entries {
                let mass = e.mass_kg.map(|m| format!("{m:.3} kg")).unwrap_or_default();
                writeln!(
                    out,
                    "{:<nw$}  {:>8}  {:<10}  {}",
                    e.name,
                    mass,
                    e.models.join(","),
                    e.description
                )?;
            }
        }
    }
    Ok(Outcome::Ok)
}
