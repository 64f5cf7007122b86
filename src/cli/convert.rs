//! `aloft convert`: a flight log to MCAP (JSON with JSON Schemas) that Foxglove displays.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;

use aloft_logs::{open_log, McapWriter};

use super::log::ReadOptions;
use super::output::{self, Row};
use super::{Format, Outcome};

#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// The log: a CSV file, one PX4 topic table (or the tables' common prefix), or an MCAP file.
    log: PathBuf,
    #[command(flatten)]
    read: ReadOptions,
    /// The MCAP file to write.
    #[arg(long, short = 'o', value_name = "MCAP")]
    output: PathBuf,
    /// Output format of the summary.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

#[derive(Serialize)]
struct TopicCount {
    topic: String,
    messages: u64,
}

#[derive(Serialize)]
struct ConvertJson {
    input: String,
    output: String,
    samples: u64,
    topics: Vec<TopicCount>,
}

pub fn run(args: ConvertArgs) -> Result<Outcome> {
    let profile = args.read.profile()?;
    let mut reader = open_log(&args.log, profile.as_ref(), &args.read.mcap())?;
    // Read the first sample before creating the output, so a bad input leaves no empty file.
    let first = match reader.next() {
        Some(s) => s?,
        None => anyhow::bail!("{}: the log holds no decodable samples", args.log.display()),
    };
    let mut w = McapWriter::create(&args.output)?;
    if let Some(t) = reader.start_time_s().filter(|t| *t > 0.0) {
        w.set_start_ns((t * 1e9).round() as u64);
    }
    w.write_sample(0, &first)?;
    let mut n = 1u64;
    let result = (|| -> Result<()> {
        for s in reader.by_ref() {
            w.write_sample(n as usize, &s?)?;
            n += 1;
        }
        Ok(())
    })();
    if let Err(e) = result {
        // Do not leave a half-written file that looks valid.
        drop(w);
        let _ = std::fs::remove_file(&args.output);
        return Err(e);
    }
    let summary = w.finish()?;
    let json = ConvertJson {
        input: args.log.display().to_string(),
        output: args.output.display().to_string(),
        samples: n,
        topics: summary
            .messages
            .iter()
            .map(|(t, m)| TopicCount {
                topic: t.clone(),
                messages: *m,
            })
            .collect(),
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &json)?,
        Format::Table | Format::Csv => {
            let rows: Vec<Row<'_>> = json
                .topics
                .iter()
                .map(|t| Row::new(&t.topic, t.messages.to_string(), "messages"))
                .collect();
            output::write_table(
                &mut out,
                &format!(
                    "{} -> {} ({} samples)",
                    json.input, json.output, json.samples
                ),
                &rows,
            )?;
        }
    }
    let time = reader.time_report();
    if !time.is_clean() {
        eprintln!(
            "aloft: note: the input's time base has {} gap(s) and {} non-monotonic step(s); they are kept as they are",
            time.gap_count, time.non_monotonic_count
        );
    }
    Ok(Outcome::Ok)
}
