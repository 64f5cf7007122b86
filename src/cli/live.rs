//! `aloft live`: a flight followed as it flies, an answer every `--every` seconds: JSON lines, or
//! a line of text per update; the validation replay ends with how the predictions did.

use std::io::Write;

use anyhow::Result;
use clap::{Args, ValueEnum};

use aloft::engine::flags::LiveFlags;
use aloft::engine::{replay_live, Error, LiveCheck, LiveCheckpoint, LiveUpdate, Vehicle};

use super::Outcome;

/// Output of `aloft live`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum LiveFormat {
    /// A line of text per update, then the check.
    #[default]
    Table,
    /// JSON lines: one object per update, then `{"check": ...}`.
    Json,
}

#[derive(Debug, Args)]
pub struct LiveArgs {
    /// The engine's options (source, route, vehicle, update interval).
    #[command(flatten)]
    flags: LiveFlags,
    /// Output format.
    #[arg(long, value_enum, default_value_t = LiveFormat::Table)]
    format: LiveFormat,
}

pub fn run(args: LiveArgs) -> Result<Outcome> {
    let vehicle = Vehicle::load(&args.flags.vehicle)?;
    let request = args.flags.request();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let format = args.format;
    let mut header = format == LiveFormat::Table;
    let mut emit = |u: &LiveUpdate| -> Result<(), Error> {
        let written = match format {
            LiveFormat::Json => serde_json::to_string(u)
                .map_err(std::io::Error::from)
                .and_then(|line| writeln!(out, "{line}")),
            LiveFormat::Table if std::mem::take(&mut header) => {
                writeln!(out, "{HEADER}").and_then(|()| writeln!(out, "{}", row(u)))
            }
            LiveFormat::Table => writeln!(out, "{}", row(u)),
        };
        written.map_err(|source| Error::Io {
            origin: "standard output".to_string(),
            source,
        })
    };
    let check = replay_live(&vehicle, &request, &mut emit)?;
    match format {
        LiveFormat::Json => {
            let line = serde_json::json!({ "check": check });
            writeln!(out, "{line}")?;
        }
        LiveFormat::Table => render_check(&mut out, &check)?,
    }
    Ok(Outcome::Ok)
}

/// The column heads of the lines of text.
const HEADER: &str =
    "  time s   used Wh  power W     eta   remaining Wh p5 / p50 / p95  naive Wh  truth Wh";

/// One update as a line of text.
fn row(u: &LiveUpdate) -> String {
    let opt = |x: Option<f64>| x.map_or_else(|| "-".to_string(), |v| format!("{v:.2}"));
    let r = &u.remaining_wh;
    format!(
        "{:>8.1} {:>9.2} {:>8} {:>7.4} {:>29} {:>9} {:>9}",
        u.time_s,
        u.energy_used_wh,
        opt(u.power_w),
        u.efficiency,
        format!("{:.2} / {:.2} / {:.2}", r.p5, r.p50, r.p95),
        opt(u.naive_remaining_wh),
        opt(u.measured_remaining_wh)
    )
}

/// How the predictions did against the measured rest.
fn render_check(out: &mut impl Write, c: &LiveCheck) -> Result<()> {
    writeln!(
        out,
        "\n{}: {} updates over {:.0} s; p5-p95 held the measured rest in {:.0} % of them",
        c.file,
        c.updates,
        c.duration_s,
        100.0 * c.band_coverage
    )?;
    writeln!(out, "{CHECK_HEADER}")?;
    for p in &c.checkpoints {
        writeln!(out, "{}", checkpoint_row(p))?;
    }
    Ok(())
}

/// The column heads of the checkpoints.
const CHECK_HEADER: &str = "    at   time s    error %  naive err %  in band";

/// One checkpoint as a line of text.
fn checkpoint_row(p: &LiveCheckpoint) -> String {
    let in_band = if p.in_band { "yes" } else { "no" };
    format!(
        "{:>6} {:>8.1} {:>+10.2} {:>+12.2} {in_band:>8}",
        p.at, p.time_s, p.error_percent, p.naive_error_percent
    )
}
