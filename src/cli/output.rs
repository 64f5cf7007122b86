//! The shared writers every answer's renderer writes with (below the renderers, which pick the
//! format): JSON, CSV, aligned tables and their cells; `--force`; a broken pipe.

use std::io::{self, Write};

/// `--force`, of every command that writes files.
#[derive(Debug, Clone, Copy, Default, clap::Args)]
pub struct ForceFlag {
    /// Replace output files that exist (a regular file, or a link itself, never what it points
    /// to; never a device, a FIFO or a folder). Without it an existing output is kept (exit 2).
    #[arg(long)]
    pub force: bool,
}

impl ForceFlag {
    /// Check, before the work, that `path` may be written (its folder exists; nothing there, or
    /// with `--force` a regular file or a link).
    pub fn check(self, path: Option<&std::path::Path>) -> anyhow::Result<()> {
        if let Some(p) = path {
            aloft::engine::check_output(p, self.force)?;
        }
        Ok(())
    }

    /// Where a chart goes.
    pub fn chart(self, path: &std::path::Path) -> super::plot::ChartFile<'_> {
        super::plot::ChartFile {
            path,
            force: self.force,
        }
    }
}

/// True when the error chain holds a broken pipe (the reader went away: exit quietly).
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<io::Error>()
            .is_some_and(|io| io.kind() == io::ErrorKind::BrokenPipe)
            || c.downcast_ref::<csv::Error>().is_some_and(|ce| {
                matches!(ce.kind(), csv::ErrorKind::Io(io) if io.kind() == io::ErrorKind::BrokenPipe)
            })
    })
}

/// One row of a text table: label, value already formatted, unit.
pub struct Row<'a> {
    pub label: &'a str,
    pub value: String,
    pub unit: &'a str,
}

impl<'a> Row<'a> {
    pub fn new(label: &'a str, value: String, unit: &'a str) -> Self {
        Self { label, value, unit }
    }

    /// A row of one number shown with `decimals` digits after the point.
    pub fn num(label: &'a str, value: f64, decimals: usize, unit: &'a str) -> Self {
        Self::new(label, fixed(value, decimals), unit)
    }

    /// A row of a number that may be absent (`-`), shown with `decimals` digits after the point.
    pub fn opt(label: &'a str, value: Option<f64>, decimals: usize, unit: &'a str) -> Self {
        Self::new(label, fixed_or_dash(value, decimals), unit)
    }
}

/// Rows of numbers from a table of label, value, decimals and unit.
pub fn num_rows<'a>(table: &[(&'a str, f64, usize, &'a str)]) -> Vec<Row<'a>> {
    let row = |&(label, value, decimals, unit)| Row::num(label, value, decimals, unit);
    table.iter().map(row).collect()
}

/// A number with `decimals` digits after the point, as tables show it.
pub fn fixed(value: f64, decimals: usize) -> String {
    format!("{value:.decimals$}")
}

/// An optional number with `decimals` digits after the point, `-` when absent.
pub fn fixed_or_dash(value: Option<f64>, decimals: usize) -> String {
    value.map_or_else(|| "-".to_string(), |v| fixed(v, decimals))
}

/// Minutes and seconds, `m:ss`.
pub fn mmss(t_s: f64) -> String {
    let s = t_s.max(0.0).round() as u64;
    format!("{}:{:02}", s / 60, s % 60)
}

/// A band of scenarios in one cell, `p5 / median / p95`, each shown by `show`; `-` when no
/// scenario gave the figure.
pub fn percentiles(p: Option<aloft::engine::Percentiles>, show: &dyn Fn(f64) -> String) -> String {
    p.map_or("-".to_string(), |p| {
        format!("{} / {} / {}", show(p.p5), show(p.p50), show(p.p95))
    })
}

/// Write rows as an aligned two-column table with units.
pub fn write_table(out: &mut impl Write, title: &str, rows: &[Row<'_>]) -> io::Result<()> {
    writeln!(out, "{title}")?;
    let lw = rows.iter().map(|r| r.label.len()).max().unwrap_or(0);
    let vw = rows.iter().map(|r| r.value.len()).max().unwrap_or(0);
    for r in rows {
        let line = format!("  {:<lw$}  {:>vw$} {}", r.label, r.value, r.unit);
        writeln!(out, "{}", line.trim_end())?;
    }
    Ok(())
}

/// The warnings of an answer on stderr, one line each (`aloft: warning: ...`): in JSON mode they
/// are also in the answer's `warnings`, where a script reads them; a person at a terminal sees
/// them here.
pub fn warn(warnings: impl IntoIterator<Item = impl std::fmt::Display>) {
    for w in warnings {
        eprintln!("aloft: warning: {w}");
    }
}

/// Write a serializable value as pretty JSON with a trailing newline.
pub fn write_json(out: &mut impl Write, value: &impl serde::Serialize) -> anyhow::Result<()> {
    // An I/O failure inside serde_json (a closed pipe) comes back as an io::Error, so that
    // `is_broken_pipe` recognises it and the run ends quietly.
    serde_json::to_writer_pretty(&mut *out, value).map_err(|e| {
        if e.is_io() {
            anyhow::Error::from(io::Error::from(e))
        } else {
            anyhow::Error::from(e)
        }
    })?;
    writeln!(out)?;
    Ok(())
}

/// An answer as JSON, with its `uncertainty` when scenarios were drawn (`--samples N`): the
/// answer's own keys either way, as the engine's [`WithUncertainty`] writes them.
///
/// [`WithUncertainty`]: aloft::engine::WithUncertainty
#[derive(serde::Serialize)]
#[serde(untagged)]
pub enum MaybeUncertain<'a, A, U> {
    /// No scenarios: the answer alone.
    Sure(&'a A),
    /// The answer and its scenarios.
    Uncertain(aloft::engine::WithUncertainty<'a, A, U>),
}

impl<'a, A, U> MaybeUncertain<'a, A, U> {
    /// The answer `summary`, with `uncertainty` when there is one.
    pub fn new(summary: &'a A, uncertainty: Option<&'a U>) -> Self {
        match uncertainty {
            None => Self::Sure(summary),
            Some(uncertainty) => Self::Uncertain(aloft::engine::WithUncertainty {
                summary,
                uncertainty,
            }),
        }
    }
}

/// Write a CSV: the header, then one line per record.
pub fn write_csv<R>(
    out: impl Write,
    header: &[&str],
    records: impl IntoIterator<Item = R>,
) -> anyhow::Result<()>
where
    R: IntoIterator,
    R::Item: AsRef<[u8]>,
{
    let mut w = csv::Writer::from_writer(out);
    w.write_record(header)?;
    for r in records {
        w.write_record(r)?;
    }
    w.flush()?;
    Ok(())
}

/// Write one value as a CSV of one line, its field names the header.
pub fn write_csv_value(out: impl Write, value: &impl serde::Serialize) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    w.serialize(value)?;
    w.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Serialize)]
    struct Answer {
        energy_wh: f64,
    }

    #[derive(serde::Serialize)]
    struct Spread {
        p5: f64,
    }

    /// Without scenarios the JSON is the answer's own; with them, its keys then `uncertainty`
    /// (the keys `aloft mission --samples` and the C ABI promise).
    #[test]
    fn maybe_uncertain_is_the_answer_alone_or_the_answer_then_its_uncertainty() {
        let (a, u) = (Answer { energy_wh: 1.5 }, Spread { p5: 0.25 });
        let sure = MaybeUncertain::<Answer, Spread>::new(&a, None);
        assert_eq!(
            serde_json::to_string(&sure).unwrap(),
            r#"{"energy_wh":1.5}"#
        );
        let uncertain = MaybeUncertain::new(&a, Some(&u));
        assert_eq!(
            serde_json::to_string(&uncertain).unwrap(),
            r#"{"energy_wh":1.5,"uncertainty":{"p5":0.25}}"#
        );
    }

    #[test]
    fn cells_round_as_tables_show_them() {
        assert_eq!(mmss(59.6), "1:00");
        assert_eq!(mmss(-3.0), "0:00");
        assert_eq!(mmss(3725.0), "62:05");
        assert_eq!(fixed_or_dash(None, 2), "-");
        assert_eq!(fixed_or_dash(Some(0.16), 1), "0.2");
        let p = aloft::engine::Percentiles {
            p5: 1.0,
            p50: 2.0,
            p95: 3.5,
        };
        assert_eq!(percentiles(Some(p), &|x| fixed(x, 1)), "1.0 / 2.0 / 3.5");
        assert_eq!(percentiles(None, &|x| fixed(x, 1)), "-");
    }
}
