//! Small rendering helpers shared by the subcommands.

use std::io::{self, Write};

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
