//! `aloft pack fit`: a pack file from the pack's own logs (the pipeline is
//! `aloft::engine::fit_pack`; this module parses and renders).

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Subcommand};

use aloft::engine::flags::finite;
use aloft::engine::{fit_pack, PackFitAnswer, PackFitRequest, Vehicle, DEFAULT_VEHICLE};

use super::flights::{escaped, file_name};
use super::output::{self, Row};
use super::{Format, Outcome};

#[derive(Debug, Args)]
pub struct PackArgs {
    #[command(subcommand)]
    command: PackCommand,
}

#[derive(Debug, Subcommand)]
enum PackCommand {
    /// Fit a pack file from logs: internal resistance from current steps, capacity between
    /// rests, the autopilot's own figures and failsafes beside them. Exit 1 when no log is usable.
    Fit(PackFitArgs),
}

#[derive(Debug, Args)]
pub struct PackFitArgs {
    /// Logs: PX4 .ulg, ArduPilot .bin, CSV (with --profile), PX4 CSV tables, MCAP.
    #[arg(required = true, value_name = "LOG")]
    logs: Vec<PathBuf>,
    /// The pack of --vehicle whose mass, nominal voltage and cut-off the logs cannot give (its
    /// resistance, and capacity when estimated, are replaced).
    #[arg(long, value_name = "NAME")]
    battery: Option<String>,
    /// Vehicle of --battery: a built-in name or a vehicle TOML file.
    #[arg(long, default_value = DEFAULT_VEHICLE, value_name = "NAME|FILE")]
    vehicle: String,
    /// CSV profile (kaist, px4) or a column-map TOML file.
    #[arg(long, value_name = "PROFILE")]
    profile: Option<String>,
    /// PX4 ULog / ArduPilot DataFlash: the battery instance to read (0: the first).
    #[arg(long, default_value_t = 0)]
    battery_instance: u8,
    /// The pack file to write.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    #[command(flatten)]
    force: output::ForceFlag,
    /// The pack's name in the file (default: the --battery pack's, the logged serial, `fitted`).
    #[arg(long)]
    name: Option<String>,
    /// Cells in series (default: --battery's, else the logs').
    #[arg(long, value_name = "N")]
    cells: Option<u32>,
    /// Rated capacity, mA h, when none is estimated between rests (default: --battery's, else
    /// the logs' BAT1_CAPACITY / BATT_CAPACITY).
    #[arg(long, value_parser = finite(), value_name = "MAH")]
    capacity_mah: Option<f64>,
    /// Pack mass, kg (required without --battery).
    #[arg(long, value_parser = finite(), value_name = "KG")]
    mass_kg: Option<f64>,
    /// Nominal pack voltage, V (default: --battery's, else 3.7 V per cell).
    #[arg(long, value_parser = finite(), value_name = "V")]
    nominal_v: Option<f64>,
    /// Cut-off cell voltage under load, V (default: --battery's, else 3.3 V).
    #[arg(long, value_parser = finite(), value_name = "V")]
    cutoff_cell_v: Option<f64>,
    /// Fraction of the capacity that may be drawn (default: --battery's, else 1).
    #[arg(long, value_parser = finite(), value_name = "FRACTION")]
    usable_fraction: Option<f64>,
    /// Output format of the report (stdout).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(args: PackArgs) -> Result<Outcome> {
    match args.command {
        PackCommand::Fit(a) => fit(a),
    }
}

fn fit(a: PackFitArgs) -> Result<Outcome> {
    let vehicle = match &a.battery {
        Some(_) => Some(Vehicle::load(&a.vehicle)?),
        None => None,
    };
    let request = PackFitRequest {
        logs: a.logs.clone(),
        profile: a.profile.clone(),
        battery_instance: a.battery_instance,
        vehicle,
        battery: a.battery.clone(),
        name: a.name.clone(),
        cells_series: a.cells,
        capacity_mah: a.capacity_mah,
        mass_kg: a.mass_kg,
        nominal_v: a.nominal_v,
        cutoff_cell_v: a.cutoff_cell_v,
        usable_fraction: a.usable_fraction,
        output: Some(a.output.clone()),
        force: a.force.force,
    };
    let answer = fit_pack(&request)?;
    write_fit_remarks("aloft pack fit", &answer);
    if answer.pack.is_none() {
        eprintln!("aloft pack fit: no usable log: no pack written");
        return Ok(Outcome::Failed);
    }
    let mut out = std::io::stdout().lock();
    match a.format {
        Format::Json => output::write_json(&mut out, &answer)?,
        Format::Table | Format::Csv => render(&mut out, &answer)?,
    }
    Ok(Outcome::Ok)
}

/// A pack fit's logs left out and its notes, a line each on standard error after `command`'s
/// name (`aloft pack fit`, `aloft logbook pack-file`), names and reasons escaped.
pub(super) fn write_fit_remarks(command: &str, answer: &PackFitAnswer) {
    for s in &answer.skipped {
        eprintln!(
            "{command}: {}: skipped: {}",
            file_name(&s.file),
            escaped(&s.reason)
        );
    }
    for n in &answer.notes {
        eprintln!("{command}: {}", escaped(n));
    }
}

fn render(out: &mut impl Write, a: &PackFitAnswer) -> Result<()> {
    for r in &a.logs {
        let rows = vec![
            Row::num("duration", r.duration_s, 1, "s"),
            Row::num("energy", r.energy_wh, 2, "Wh"),
            Row::num("lowest voltage", r.min_voltage_v, 2, "V"),
            Row::opt("discharged (coulomb count)", r.discharged_mah, 0, "mAh"),
            Row::opt("reported drop", r.reported_drop_mah, 0, "mAh"),
            Row::opt(
                "internal resistance (steps)",
                r.internal_resistance_ohm,
                4,
                "ohm",
            ),
            Row::new(
                "current steps",
                r.resistance
                    .as_ref()
                    .map_or("-".into(), |e| e.steps.to_string()),
                "",
            ),
            Row::opt(
                "autopilot's resistance",
                r.autopilot_internal_resistance_ohm,
                4,
                "ohm",
            ),
            Row::opt("capacity between rests", r.capacity_mah, 0, "mAh"),
            Row::opt("cell imbalance > 0.01 V", r.imbalance_minor_min, 1, "min"),
            Row::opt("cell imbalance > 0.07 V", r.imbalance_major_min, 1, "min"),
        ];
        output::write_table(out, &file_name(&r.source), &rows)?;
        if let Some(why) = &r.capacity_refused {
            writeln!(out, "  capacity: {}", escaped(why))?;
        }
    }
    let rows = vec![
        Row::opt("internal resistance", a.internal_resistance_ohm, 4, "ohm"),
        Row::opt(
            "autopilot's resistance",
            a.autopilot_internal_resistance_ohm,
            4,
            "ohm",
        ),
        Row::opt("capacity written", a.pack_capacity_mah, 0, "mAh"),
        Row::num("discharged over the logs", a.discharged_mah, 0, "mAh"),
        Row::opt("equivalent full cycles", a.equivalent_cycles, 2, ""),
    ];
    output::write_table(
        out,
        &format!("pack written to {}", escaped(&a.output)),
        &rows,
    )?;
    Ok(())
}
