//! `aloft log info`: summarise a flight log (CSV through a profile, PX4 tables, or MCAP).

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Subcommand};

use aloft::engine::flags::LogInfoFlags;
use aloft::engine::{log_info, LogFormat, LogInfo};

use super::output::{self, Row};
use super::{Format, Outcome};

#[derive(Debug, Args)]
pub struct LogArgs {
    #[command(subcommand)]
    command: LogCommand,
}

#[derive(Debug, Subcommand)]
enum LogCommand {
    /// Duration, rates, channels or columns found, energy used (integrated V x I) and the
    /// regularity of the time base.
    Info(InfoArgs),
}

#[derive(Debug, Args)]
struct InfoArgs {
    /// The log: a CSV file, one PX4 topic table (or the tables' common prefix), an MCAP file, a
    /// PX4 ULog (.ulg) or an ArduPilot DataFlash log (.bin).
    file: PathBuf,
    /// How the log is read, and the lag search.
    #[command(flatten)]
    flags: LogInfoFlags,
    /// The old name of --max-lag, refused with a message: --lag is the lag itself in fit,
    /// validate and mission --replay.
    #[arg(long, hide = true, num_args = 0..=1, value_name = "S")]
    lag: Option<Option<String>>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(args: LogArgs) -> Result<Outcome> {
    match args.command {
        LogCommand::Info(a) => info(a),
    }
}

fn info(args: InfoArgs) -> Result<Outcome> {
    if let Some(value) = &args.lag {
        let value = value.as_deref().unwrap_or("MAX_S");
        anyhow::bail!(
            "--lag of log info is now --max-lag: --max-lag {value} searches the lag of power behind ground speed within +-{value} s (--lag is the lag itself in fit, validate and mission --replay)"
        );
    }
    let info = log_info(&args.file, &args.flags.read.options(), args.flags.max_lag)?;
    if args.format == Format::Json {
        output::warn(&info.warnings);
    }
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &info)?,
        Format::Table | Format::Csv => write_table(&mut out, &info)?,
    }
    Ok(Outcome::Ok)
}

fn write_table(out: &mut impl Write, j: &LogInfo) -> Result<()> {
    output::write_table(out, &title(j), &summary_rows(j))?;
    write_contents(out, j)?;
    write_time_notes(out, j)?;
    for w in &j.warnings {
        writeln!(out, "warning: {w}")?;
    }
    Ok(())
}

fn title(j: &LogInfo) -> String {
    let fmt = match j.format {
        LogFormat::Csv => "CSV",
        LogFormat::Px4Csv => "PX4 CSV tables",
        LogFormat::Mcap => "MCAP",
        LogFormat::Px4Ulog => "PX4 ULog",
        LogFormat::ArduPilotDataflash => "ArduPilot DataFlash",
    };
    match &j.profile {
        Some(p) => format!("{} ({fmt}, profile {p})", j.file),
        None => format!("{} ({fmt})", j.file),
    }
}

fn summary_rows(j: &LogInfo) -> Vec<Row<'static>> {
    let mut rows = vec![
        Row::new("samples", j.samples.to_string(), ""),
        Row::num("duration", j.duration_s, 2, "s"),
    ];
    if let Some(p) = j.time.nominal_period_s {
        rows.push(Row::num("nominal period", p, 4, "s"));
    }
    rows.push(Row::new(
        "gaps (> 3 periods)",
        j.time.gap_count.to_string(),
        "",
    ));
    rows.push(Row::new(
        "non-monotonic time steps",
        j.time.non_monotonic_count.to_string(),
        "",
    ));
    if j.dropped_values > 0 {
        rows.push(Row::new(
            "values dropped (contradict V x I)",
            j.dropped_values.to_string(),
            "",
        ));
    }
    match j.energy_wh {
        Some(e) => rows.push(Row::num("energy used (V x I)", e, 2, "Wh")),
        None => rows.push(Row::new("energy used", "n/a: no power data".into(), "")),
    }
    if let Some(p) = j.mean_power_w {
        rows.push(Row::num("mean power", p, 1, "W"));
    }
    if let Some(p) = j.max_power_w {
        rows.push(Row::num("max power", p, 1, "W"));
    }
    // What a ULog or DataFlash log says of its vehicle (what `aloft fit` reads, or asks for).
    if let Some(b) = &j.log {
        rows.push(match b.battery_cells {
            Some(n) => Row::new("pack cells (params)", n.to_string(), ""),
            None => Row::new("pack cells (params)", "not set".into(), ""),
        });
        rows.push(match b.battery_capacity_ah {
            Some(c) => Row::num("pack capacity (params)", 1000.0 * c, 0, "mAh"),
            None => Row::new("pack capacity (params)", "not set".into(), ""),
        });
        if let Some(rho) = b.air_density_kg_m3 {
            rows.push(Row::num("air density (mean)", rho, 3, "kg/m^3"));
        }
        if let Some(t) = b.in_air_s {
            rows.push(Row::num("time in the air", t, 1, "s"));
        }
    }
    if let Some(l) = &j.lag {
        rows.push(Row::new(
            "power lag behind ground speed",
            format!(
                "{:.2} (r = {:.2}{})",
                l.lag_s,
                l.correlation,
                if l.at_window_edge {
                    ", at window edge"
                } else {
                    ""
                }
            ),
            "s",
        ));
    }
    rows
}

/// Channels, and the CSV columns or MCAP topics they came from.
fn write_contents(out: &mut impl Write, j: &LogInfo) -> Result<()> {
    writeln!(out, "channels")?;
    for c in &j.channels {
        let rate = rate(c.rate_hz);
        writeln!(
            out,
            "  {:<13} {:>9} samples  {rate}",
            c.channel.name(),
            c.samples
        )?;
    }
    if let Some(cols) = &j.columns {
        writeln!(out, "columns ({}): {}", cols.len(), cols.join(", "))?;
    }
    if let Some(topics) = &j.topics {
        writeln!(out, "topics")?;
        for t in topics {
            let rate = rate(t.rate_hz);
            let used: Vec<&str> = t.used_for.iter().map(|c| c.name()).collect();
            let used = if used.is_empty() {
                "not decoded".to_string()
            } else {
                format!("-> {}", used.join(", "))
            };
            writeln!(
                out,
                "  {} [{} {}] {} messages, {rate}, {used}",
                t.topic, t.schema, t.message_encoding, t.messages
            )?;
        }
    }
    Ok(())
}

/// A rate in Hz with two decimals, or `-` when there is none.
fn rate(hz: Option<f64>) -> String {
    hz.map_or("-".into(), |r| format!("{r:.2} Hz"))
}

/// The first gaps, dropped values and backward steps of the time base.
fn write_time_notes(out: &mut impl Write, j: &LogInfo) -> Result<()> {
    for g in j.time.gaps.iter().take(5) {
        write_step(out, "gap", g.from_s, g.to_s, g.index)?;
    }
    for d in j.dropped.iter().take(5) {
        writeln!(out, "dropped: row {} {} = {:.1}", d.row, d.channel, d.value)?;
    }
    for n in j.time.non_monotonic.iter().take(5) {
        write_step(out, "time goes back", n.previous_s, n.time_s, n.index)?;
    }
    Ok(())
}

/// A step of the time base: `what: FROM s -> TO s (sample INDEX)`.
fn write_step(out: &mut impl Write, what: &str, from_s: f64, to_s: f64, index: u64) -> Result<()> {
    writeln!(out, "{what}: {from_s:.3} s -> {to_s:.3} s (sample {index})")?;
    Ok(())
}
