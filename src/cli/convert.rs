//! `aloft convert`: a flight log to MCAP (JSON with JSON Schemas) that Foxglove displays.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use aloft::engine::{convert_log, ConvertSummary};

use aloft::engine::flags::LogReadFlags;

use super::output::{self, ForceFlag, Row};
use super::{Format, Outcome};

#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// The log: a CSV file, one PX4 topic table (or the tables' common prefix), an MCAP file, a
    /// PX4 ULog (.ulg) or an ArduPilot DataFlash log (.bin).
    log: PathBuf,
    /// How the log is read.
    #[command(flatten)]
    read: LogReadFlags,
    /// The MCAP file to write.
    #[arg(long, short = 'o', value_name = "MCAP")]
    output: PathBuf,
    #[command(flatten)]
    force: ForceFlag,
    /// Output format of the summary.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(args: ConvertArgs) -> Result<Outcome> {
    let json = convert_log(
        &args.log,
        &args.read.options(),
        &args.output,
        args.force.force,
    )?;
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &json)?,
        Format::Table | Format::Csv => write_table(&mut out, &json)?,
    }
    if let Some((gaps, backwards)) = json.time_notes {
        eprintln!(
            "aloft: note: the input's time base has {gaps} gap(s) and {backwards} non-monotonic step(s); they are kept as they are"
        );
    }
    Ok(Outcome::Ok)
}

/// The topics written and their messages, under the input, the output and the samples.
fn write_table(out: &mut impl std::io::Write, json: &ConvertSummary) -> Result<()> {
    let rows: Vec<Row<'_>> = json
        .topics
        .iter()
        .map(|t| Row::new(&t.topic, t.messages.to_string(), "messages"))
        .collect();
    let title = format!(
        "{} -> {} ({} samples)",
        json.input, json.output, json.samples
    );
    output::write_table(out, &title, &rows)?;
    Ok(())
}
