//! `aloft vehicles`: list the built-in vehicles.

use std::io::Write;

use anyhow::Result;
use clap::Args;
use serde::Serialize;

use super::{output, Format, Outcome};

#[derive(Debug, Args)]
pub struct VehiclesArgs {
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

#[derive(Serialize)]
struct Entry {
    name: &'static str,
    description: String,
    mass_kg: Option<f64>,
    models: Vec<&'static str>,
}

pub fn run(args: VehiclesArgs) -> Result<Outcome> {
    let mut entries = Vec::new();
    for b in aloft::vehicle::BUILTIN_VEHICLES {
        let f = aloft::vehicle::VehicleFile::builtin(b.name)?;
        let mut models = Vec::new();
        if f.power.is_some() {
            models.push("power");
        }
        if f.propulsion.is_some() {
            models.push("propulsion");
        }
        entries.push(Entry {
            name: b.name,
            description: f.description.clone(),
            mass_kg: f
                .power
                .as_ref()
                .map(|p| p.mass_kg)
                .or(f.propulsion.as_ref().map(|p| p.empty_mass_kg)),
            models,
        });
    }
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
