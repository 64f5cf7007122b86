//! `aloft logbook`: the operator's flights, vehicles and packs in one SQLite file
//! (`aloft_logbook`). This module parses the arguments, finds the file and renders the answers;
//! the schema, the ingest and the queries are the logbook crate's.

use std::borrow::Cow;
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use serde::Serialize;

use aloft_logbook::{
    AddOutcome, Flight, KeyKind, Labels, Logbook, PackSummary, ReadOptions, Skipped, VehicleSummary,
};

use super::flights::escaped;
use super::output::{self, fixed, fixed_or_dash, Row};
use super::Outcome;
use aloft::engine::shown_path;

#[path = "logbook_read.rs"]
mod read;

/// Output format of the logbook's answers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Default)]
pub enum BookFormat {
    /// Aligned text for a terminal.
    #[default]
    Table,
    /// JSON: `{"flights": [...]}`, `{"vehicles": [...]}`, `{"packs": [...]}`.
    Json,
}

#[derive(Debug, Args)]
pub struct LogbookArgs {
    /// The logbook file. Default: $ALOFT_LOGBOOK, else $XDG_DATA_HOME/aloft/logbook.sqlite
    /// (~/.local/share/aloft/logbook.sqlite), whose folder is created; the folder of a file
    /// given here or in ALOFT_LOGBOOK must exist.
    #[arg(long, global = true, value_name = "FILE")]
    db: Option<PathBuf>,
    #[command(subcommand)]
    command: LogbookCommand,
}

#[derive(Debug, Subcommand)]
enum LogbookCommand {
    /// Add flight logs (CSV, MCAP, PX4 ULog, ArduPilot DataFlash, MAVLink .tlog): each file
    /// once, by content; a second log of a flight already there (the same vehicle over the same
    /// time) is recorded as a copy of it, counted once. Exit 0 when at least one is added or
    /// already there, 1 when every one is skipped.
    Add(AddArgs),
    /// Rename a vehicle or a pack (its flights follow; the packs keyed by a vehicle's name
    /// follow the vehicle).
    Relabel(RelabelArgs),
    /// The flights, in flying order.
    Flights(ListArgs),
    /// Per vehicle: flights, hours, energy, the power of each flight and its drift.
    Vehicles(ListArgs),
    /// Per pack: flights, equivalent cycles, discharged charge, resistance trend, capacity
    /// estimates, minutes of cell imbalance.
    Packs(ListArgs),
    /// The files that are not flights of the logbook, with the reason.
    Skipped(ListArgs),
    /// The pack file to fly a pack with (`aloft pack fit` over the pack's logs, read again
    /// where they were when added; a log moved or changed since is left out, with a note).
    /// Exit 1 when none of its logs can be used.
    PackFile(PackFileArgs),
}

#[derive(Debug, Args)]
struct PackFileArgs {
    /// The pack's key (as `aloft logbook packs` lists it; not "unknown").
    #[arg(value_name = "PACK")]
    pack: String,
    /// Where to write the pack file (TOML).
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    #[command(flatten)]
    force: output::ForceFlag,
    /// The pack's name in the file (default: its key).
    #[arg(long, value_name = "NAME")]
    name: Option<String>,
    /// Cells in series, when the logs do not say.
    #[arg(long, value_name = "N")]
    cells: Option<u32>,
    /// Rated capacity, mAh, when no capacity can be estimated from the logs.
    #[arg(long, value_parser = aloft::engine::flags::finite(), value_name = "MAH")]
    capacity_mah: Option<f64>,
    /// The pack's mass, kg (logs do not say it).
    #[arg(long, value_parser = aloft::engine::flags::finite(), value_name = "KG")]
    mass_kg: Option<f64>,
    /// CSV profile of the logs: kaist, px4, or a column-map TOML file.
    #[arg(long, value_name = "PROFILE")]
    profile: Option<String>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = BookFormat::Table)]
    format: BookFormat,
}

#[derive(Debug, Args)]
struct AddArgs {
    /// The logs.
    #[arg(required = true, value_name = "LOG")]
    logs: Vec<PathBuf>,
    /// The vehicle of logs that do not identify theirs (PX4 sys_uuid, ArduPilot
    /// BRD_SERIAL_NUM); without it they are filed under "unknown".
    #[arg(long, value_name = "LABEL", value_parser = label)]
    vehicle_label: Option<String>,
    /// The pack of logs that do not identify theirs (a smart pack's serial, BATT_SERIAL_NUM);
    /// without it they are filed under "unknown".
    #[arg(long, value_name = "LABEL", value_parser = label)]
    pack_label: Option<String>,
    /// CSV profile: kaist, px4, or a column-map TOML file. Default: recognised from the file.
    #[arg(long, value_name = "PROFILE")]
    profile: Option<String>,
    /// PX4 ULog / ArduPilot DataFlash: the battery instance to read (0: the first).
    #[arg(long, default_value_t = 0, value_name = "N")]
    battery_instance: u8,
    /// Output format.
    #[arg(long, value_enum, default_value_t = BookFormat::Table)]
    format: BookFormat,
}

/// Which name `relabel` changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum KeyArg {
    /// A vehicle (as `aloft logbook vehicles` lists it).
    Vehicle,
    /// A pack (as `aloft logbook packs` lists it).
    Pack,
}

#[derive(Debug, Args)]
struct RelabelArgs {
    /// A vehicle or a pack.
    #[arg(value_enum)]
    kind: KeyArg,
    /// Its name now.
    #[arg(value_name = "OLD")]
    old: String,
    /// Its new name: 1 to 200 characters, not "unknown" nor "unknown ..." (aloft's keys).
    #[arg(value_name = "NEW", value_parser = label)]
    new: String,
}

#[derive(Debug, Args)]
struct ListArgs {
    /// Output format.
    #[arg(long, value_enum, default_value_t = BookFormat::Table)]
    format: BookFormat,
}

/// A label ([`aloft_logbook::check_label`]).
fn label(s: &str) -> Result<String, String> {
    aloft_logbook::check_label(s).map_err(|e| e.to_string())
}

/// The logbook file and whether its folder may be created (only the default's).
fn db_path(given: Option<PathBuf>) -> Result<(PathBuf, bool)> {
    if let Some(p) = given {
        return Ok((p, false));
    }
    if let Some(p) = std::env::var_os("ALOFT_LOGBOOK").filter(|p| !p.is_empty()) {
        return Ok((PathBuf::from(p), false));
    }
    let data = std::env::var_os("XDG_DATA_HOME")
        .filter(|p| !p.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME")
                .filter(|p| !p.is_empty())
                .map(|h| Path::new(&h).join(".local/share"))
        })
        .context("no logbook file: give --db FILE or set ALOFT_LOGBOOK (neither XDG_DATA_HOME nor HOME is set)")?;
    Ok((data.join("aloft").join("logbook.sqlite"), true))
}

/// The logbook to add to: made when missing (the default's folder too).
fn open_to_write(given: Option<PathBuf>) -> Result<Logbook> {
    let (path, create_folder) = db_path(given)?;
    if create_folder {
        if let Some(folder) = path.parent() {
            std::fs::create_dir_all(folder)
                .with_context(|| format!("{}: cannot create the folder", folder.display()))?;
        }
    }
    Ok(Logbook::open(&path)?)
}

/// The logbook to list, read-only (a file or folder the user may not write is listed).
fn open_to_read(given: Option<PathBuf>) -> Result<Logbook> {
    let (path, _) = db_path(given)?;
    Ok(Logbook::open_read_only(&path)?)
}

pub fn run(args: LogbookArgs) -> Result<Outcome> {
    match args.command {
        LogbookCommand::Add(a) => add(&mut open_to_write(args.db)?, a),
        LogbookCommand::Relabel(a) => relabel(&mut open_to_write(args.db)?, a),
        LogbookCommand::Flights(a) => {
            let flights = open_to_read(args.db)?.flights()?;
            list(a.format, "flights", &flights, |out| {
                flights_table(out, &flights)
            })
        }
        LogbookCommand::Vehicles(a) => {
            let vehicles = open_to_read(args.db)?.vehicles()?;
            list(a.format, "vehicles", &vehicles, |out| {
                vehicles_table(out, &vehicles)
            })
        }
        LogbookCommand::Packs(a) => {
            let packs = open_to_read(args.db)?.packs()?;
            list(a.format, "packs", &packs, |out| packs_table(out, &packs))
        }
        LogbookCommand::PackFile(a) => pack_file(&open_to_read(args.db)?, a),
        LogbookCommand::Skipped(a) => {
            let skipped = open_to_read(args.db)?.skipped()?;
            list(a.format, "skipped", &skipped, |out| {
                skipped_table(out, &skipped)
            })
        }
    }
}

/// Print a list as `{"<key>": [...]}` or as its table.
fn list<T: Serialize>(
    format: BookFormat,
    key: &str,
    items: &[T],
    table: impl FnOnce(&mut std::io::StdoutLock<'static>) -> Result<()>,
) -> Result<Outcome> {
    let mut out = std::io::stdout().lock();
    match format {
        BookFormat::Json => output::write_json(&mut out, &Keyed(key, items))?,
        BookFormat::Table => table(&mut out)?,
    }
    Ok(Outcome::Ok)
}

/// The JSON answer of `aloft logbook KIND --format json` (KIND: `flights`, `vehicles`, `packs`,
/// `skipped`) from the logbook at `db`, or the command line's message (the page's
/// `/api/logbook/KIND`).
#[cfg(feature = "serve")]
pub(crate) fn answer_json(db: &Path, kind: &str) -> Result<String, String> {
    let text = |e: &dyn std::fmt::Display| e.to_string();
    let book = Logbook::open_read_only(db).map_err(|e| text(&e))?;
    let json = match kind {
        "flights" => serde_json::to_string(&Keyed(kind, &book.flights().map_err(|e| text(&e))?)),
        "vehicles" => serde_json::to_string(&Keyed(kind, &book.vehicles().map_err(|e| text(&e))?)),
        "packs" => serde_json::to_string(&Keyed(kind, &book.packs().map_err(|e| text(&e))?)),
        "skipped" => serde_json::to_string(&Keyed(kind, &book.skipped().map_err(|e| text(&e))?)),
        _ => {
            return Err(format!(
                "{kind}: not a list of the logbook (flights, vehicles, packs, skipped)"
            ))
        }
    };
    json.map_err(|e| text(&e))
}

/// `{"<key>": [...]}`, each item's fields in their declared order.
struct Keyed<'a, T>(&'a str, &'a [T]);

impl<T: Serialize> Serialize for Keyed<'_, T> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(1))?;
        map.serialize_entry(self.0, self.1)?;
        map.end()
    }
}

/// One file's outcome, as `add --format json` lists it.
#[derive(Debug, Serialize)]
struct FileOutcome {
    file: String,
    #[serde(flatten)]
    outcome: AddOutcome,
}

/// The answer of `add --format json`.
#[derive(Debug, Serialize)]
struct AddAnswer {
    files: Vec<FileOutcome>,
    added: usize,
    copies: usize,
    already_present: usize,
    skipped: usize,
}

fn add(book: &mut Logbook, a: AddArgs) -> Result<Outcome> {
    if let Some(p) = &a.profile {
        aloft::engine::check_profile(p)?;
    }
    let labels = Labels {
        vehicle: a.vehicle_label,
        pack: a.pack_label,
    };
    let options = ReadOptions {
        profile: a.profile,
        battery_instance: a.battery_instance,
    };
    let mut files = Vec::new();
    let mut out = std::io::stdout().lock();
    for log in &a.logs {
        let outcome = book.add_with(log, &labels, |p| read::read_log(p, &options))?;
        let file = log.display().to_string();
        if a.format == BookFormat::Table {
            writeln!(out, "{}", add_line(&file, &outcome))?;
        }
        files.push(FileOutcome { file, outcome });
    }
    let count = |f: fn(&AddOutcome) -> bool| files.iter().filter(|o| f(&o.outcome)).count();
    let answer = AddAnswer {
        added: count(|o| matches!(o, AddOutcome::Added { .. })),
        copies: count(|o| matches!(o, AddOutcome::Copy { .. })),
        already_present: count(|o| matches!(o, AddOutcome::AlreadyPresent { .. })),
        skipped: count(|o| matches!(o, AddOutcome::Skipped { .. })),
        files,
    };
    match a.format {
        BookFormat::Json => output::write_json(&mut out, &answer)?,
        BookFormat::Table => writeln!(
            out,
            "{} added, {} copies, {} already in the logbook, {} skipped ({})",
            answer.added,
            answer.copies,
            answer.already_present,
            answer.skipped,
            shown_path(book.path())
        )?,
    }
    Ok(if answer.skipped == answer.files.len() {
        Outcome::Failed
    } else {
        Outcome::Ok
    })
}

fn add_line(file: &str, o: &AddOutcome) -> String {
    let file = escaped(file);
    match o {
        AddOutcome::Added {
            flight_id,
            vehicle_key,
            pack_key,
        } => format!("added: {file} (flight {flight_id}, vehicle {vehicle_key}, pack {pack_key})"),
        AddOutcome::AlreadyPresent { flight_id } => {
            format!("already in the logbook: {file} (flight {flight_id})")
        }
        AddOutcome::Skipped { reason } => format!("skipped: {file} ({})", escaped(reason)),
        AddOutcome::Copy {
            flight_id,
            copy_of,
            vehicle_key,
            ..
        } => format!(
            "copy: {file} (flight {flight_id}, a copy of flight {copy_of}: vehicle {vehicle_key} over the same time; counted once)"
        ),
    }
}

fn relabel(book: &mut Logbook, a: RelabelArgs) -> Result<Outcome> {
    let kind = match a.kind {
        KeyArg::Vehicle => KeyKind::Vehicle,
        KeyArg::Pack => KeyKind::Pack,
    };
    let n = book.relabel(kind, &a.old, &a.new)?;
    let flights = if n == 1 { "flight" } else { "flights" };
    writeln!(
        std::io::stdout().lock(),
        "{kind} {:?} is now {:?} ({n} {flights}; {})",
        a.old,
        a.new,
        shown_path(book.path())
    )?;
    Ok(Outcome::Ok)
}

/// Rows as aligned columns under a header (text left, numbers right); a cell's control
/// characters escaped, so that a row stays one line.
fn write_columns(out: &mut impl Write, header: &[&str], rows: &[Vec<String>]) -> Result<()> {
    let rows: Vec<Vec<Cow<'_, str>>> = rows
        .iter()
        .map(|r| r.iter().map(|c| escaped(c)).collect())
        .collect();
    let mut widths: Vec<usize> = header.iter().map(|h| h.len()).collect();
    for r in &rows {
        for (w, c) in widths.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: Vec<&str>| -> String {
        let parts: Vec<String> = cells
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(i, (c, w))| {
                if i < 4 {
                    format!("{c:<w$}")
                } else {
                    format!("{c:>w$}")
                }
            })
            .collect();
        parts.join("  ").trim_end().to_string()
    };
    writeln!(out, "{}", line(header.to_vec()))?;
    for r in &rows {
        writeln!(out, "{}", line(r.iter().map(|c| &**c).collect()))?;
    }
    Ok(())
}

fn flights_table(out: &mut impl Write, flights: &[Flight]) -> Result<()> {
    if flights.is_empty() {
        writeln!(out, "no flights in the logbook")?;
        return Ok(());
    }
    let rows: Vec<Vec<String>> = flights
        .iter()
        .map(|f| {
            vec![
                f.id.to_string(),
                f.file_name.clone(),
                f.vehicle_key.clone(),
                f.pack_key.clone(),
                fixed(f.duration_s / 60.0, 1),
                fixed_or_dash(f.air_s.map(|s| s / 60.0), 1),
                fixed(f.energy_wh, 1),
                fixed_or_dash(f.discharged_mah, 0),
                fixed_or_dash(f.mean_power_w, 0),
                fixed_or_dash(f.hover_power_w, 0),
                fixed_or_dash(f.resistance_ohm.map(|r| r * 1000.0), 1),
                f.copy_of.map_or_else(|| "-".to_string(), |c| c.to_string()),
            ]
        })
        .collect();
    write_columns(
        out,
        &[
            "id", "file", "vehicle", "pack", "min", "air min", "Wh", "mAh", "mean W", "hover W",
            "R mOhm", "copy of",
        ],
        &rows,
    )?;
    let copies = flights.iter().filter(|f| f.copy_of.is_some()).count();
    if copies > 0 {
        writeln!(
            out,
            "{copies} of these logs are copies of another log of the same flight (\"copy of\"): counted once"
        )?;
    }
    Ok(())
}

/// A titled block of label and value lines, both left-aligned (the values are words and
/// figures with their units).
fn write_block(out: &mut impl Write, title: &str, rows: &[Row<'_>]) -> Result<()> {
    writeln!(out, "{}", escaped(title))?;
    let lw = rows.iter().map(|r| r.label.len()).max().unwrap_or(0);
    for r in rows {
        let line = format!("  {:<lw$}  {} {}", r.label, escaped(&r.value), r.unit);
        writeln!(out, "{}", line.trim_end())?;
    }
    Ok(())
}

/// Flights, and the copies not counted among them.
fn flights_and_copies(flights: usize, copies: usize) -> String {
    match copies {
        0 => flights.to_string(),
        c => format!("{flights} (and {c} copies of them, not counted)"),
    }
}

/// One block per item (its title and rows, by `block`), a blank line between them; `none` when
/// there is no item.
fn write_blocks<T>(
    out: &mut impl Write,
    items: &[T],
    none: &str,
    block: impl Fn(&T) -> (String, Vec<Row<'static>>),
) -> Result<()> {
    if items.is_empty() {
        writeln!(out, "{none}")?;
    }
    for (i, item) in items.iter().enumerate() {
        if i > 0 {
            writeln!(out)?;
        }
        let (title, rows) = block(item);
        write_block(out, &title, &rows)?;
    }
    Ok(())
}

fn vehicles_table(out: &mut impl Write, vehicles: &[VehicleSummary]) -> Result<()> {
    write_blocks(out, vehicles, "no vehicles in the logbook", vehicle_block)
}

/// A vehicle's block: flights, time, energy, packs and the drift of its power.
fn vehicle_block(v: &VehicleSummary) -> (String, Vec<Row<'static>>) {
    let mut rows = vec![
        Row::new("flights", flights_and_copies(v.flights, v.copies), ""),
        Row::num("flight time", v.hours, 2, "h"),
    ];
    if let Some(h) = v.air_hours {
        rows.push(Row::num("time in the air", h, 2, "h"));
    }
    rows.extend([
        Row::num("energy", v.energy_wh, 1, "Wh"),
        Row::num("charge", v.discharged_mah, 0, "mAh"),
        Row::new("packs", v.packs.join(", "), ""),
    ]);
    if let Some(d) = &v.power_drift {
        let what = if d.quantity == "hover_power_w" {
            "hover power"
        } else {
            "mean power"
        };
        let change = d
            .trend
            .change_percent
            .map_or_else(|| "n/a".to_string(), |c| format!("{c:+.1} %"));
        rows.push(Row::new(
            "power drift",
            format!(
                "{what} {change} over the last {} flights ({:.0} W to {:.0} W)",
                d.trend.n, d.trend.first, d.trend.last
            ),
            "",
        ));
    }
    (format!("vehicle {} ({})", v.key, v.key_source), rows)
}

fn packs_table(out: &mut impl Write, packs: &[PackSummary]) -> Result<()> {
    write_blocks(out, packs, "no packs in the logbook", pack_block)
}

/// A pack's block: flights, time, charge, cycles, cells, resistance, capacity, imbalance and
/// the vehicles it flew.
fn pack_block(p: &PackSummary) -> (String, Vec<Row<'static>>) {
    let mut rows = vec![
        Row::new("flights", flights_and_copies(p.flights, p.copies), ""),
        Row::num("flight time", p.hours, 2, "h"),
        Row::num("discharged", p.discharged_mah, 0, "mAh"),
        Row::num("energy", p.energy_wh, 1, "Wh"),
    ];
    match (p.equivalent_cycles, p.rated_capacity_mah) {
        (Some(c), Some(r)) => rows.push(Row::new(
            "equivalent cycles",
            format!("{c:.2} (rated {r:.0} mAh)"),
            "",
        )),
        _ => rows.push(Row::new(
            "equivalent cycles",
            "n/a: no rated capacity".into(),
            "",
        )),
    }
    if let Some(c) = p.cells_series {
        rows.push(Row::new("cells in series", c.to_string(), ""));
    }
    rows.push(Row::new(
        "resistance",
        match &p.resistance_trend {
            Some(t) => format!(
                "first {:.1} mOhm, last {:.1} mOhm, slope {} mOhm/flight, n {}",
                t.first * 1000.0,
                t.last * 1000.0,
                fixed_or_dash(t.slope_per_flight.map(|s| s * 1000.0), 2),
                t.n
            ),
            None if p.resistance.is_empty() => "n/a: no estimate".into(),
            None => format!(
                "{} estimates, no trend (the flights of \"{}\" are of any pack)",
                p.resistance.len(),
                aloft_logbook::UNKNOWN
            ),
        },
        "",
    ));
    rows.push(Row::new(
        "capacity estimates",
        if p.capacity.is_empty() {
            "none".into()
        } else {
            p.capacity
                .iter()
                .map(|c| format!("{:.0}", c.value))
                .collect::<Vec<_>>()
                .join(", ")
                + " mAh"
        },
        "",
    ));
    rows.push(Row::opt(
        "cell imbalance > 0.01 V",
        p.imbalance_minor_min,
        1,
        "min",
    ));
    rows.push(Row::opt(
        "cell imbalance > 0.07 V",
        p.imbalance_major_min,
        1,
        "min",
    ));
    rows.push(Row::new("vehicles", p.vehicles.join(", "), ""));
    (format!("pack {} ({})", p.key, p.key_source), rows)
}

fn skipped_table(out: &mut impl Write, skipped: &[Skipped]) -> Result<()> {
    if skipped.is_empty() {
        writeln!(out, "no skipped files")?;
    }
    for s in skipped {
        writeln!(out, "{}: {}", escaped(&s.file_name), escaped(&s.reason))?;
    }
    Ok(())
}

/// The logs of a pack that are still where they were and as they were (by content), and a note
/// for each of the others.
fn pack_logs(flights: &[Flight]) -> (Vec<PathBuf>, Vec<String>) {
    let mut logs = Vec::new();
    let mut notes = Vec::new();
    for f in flights {
        if f.format == "tlog" {
            notes.push(format!(
                "{}: left out: a telemetry log (too sparse for `aloft pack fit`'s current steps and rests)",
                f.file_name
            ));
            continue;
        }
        let Some(path) = f.file_path.as_deref().map(PathBuf::from) else {
            notes.push(format!(
                "{}: left out: added before the logbook kept where logs are",
                f.file_name
            ));
            continue;
        };
        match aloft_logbook::file_sha256(&path) {
            Ok(sha) if sha == f.file_sha256 => logs.push(path),
            Ok(_) => notes.push(format!(
                "{}: left out: the file has changed since it was added",
                path.display()
            )),
            Err(e) => notes.push(format!("{}: left out: {e}", path.display())),
        }
    }
    (logs, notes)
}

fn pack_file(book: &Logbook, a: PackFileArgs) -> Result<Outcome> {
    use aloft::engine::{fit_pack, PackFitRequest};
    if a.pack == aloft_logbook::UNKNOWN {
        anyhow::bail!(
            "pack \"{}\": its flights are of any pack; add logs with --pack-label to give a pack its flights",
            aloft_logbook::UNKNOWN
        );
    }
    let flights = book.flights_of_pack(&a.pack)?;
    if flights.is_empty() {
        anyhow::bail!(
            "pack \"{}\": no such pack in {}",
            escaped(&a.pack),
            shown_path(book.path())
        );
    }
    let (logs, notes) = pack_logs(&flights);
    for n in &notes {
        eprintln!("aloft logbook pack-file: {}", escaped(n));
    }
    if logs.is_empty() {
        eprintln!(
            "aloft logbook pack-file: no log of pack \"{}\" can be read again: no pack written",
            escaped(&a.pack)
        );
        return Ok(Outcome::Failed);
    }
    let request = PackFitRequest {
        logs,
        profile: a.profile,
        name: Some(a.name.unwrap_or_else(|| a.pack.clone())),
        cells_series: a.cells,
        capacity_mah: a.capacity_mah,
        mass_kg: a.mass_kg,
        output: Some(a.output.clone()),
        force: a.force.force,
        ..PackFitRequest::default()
    };
    let answer = fit_pack(&request)?;
    super::pack::write_fit_remarks("aloft logbook pack-file", &answer);
    if answer.pack.is_none() {
        eprintln!("aloft logbook pack-file: no usable log: no pack written");
        return Ok(Outcome::Failed);
    }
    let mut out = std::io::stdout().lock();
    match a.format {
        BookFormat::Json => output::write_json(&mut out, &answer)?,
        BookFormat::Table => writeln!(
            out,
            "wrote {}: pack {} from {} logs, resistance {} mOhm, capacity {} mAh",
            answer.output,
            escaped(&a.pack),
            answer.logs.len(),
            fixed_or_dash(answer.internal_resistance_ohm.map(|r| r * 1000.0), 1),
            fixed_or_dash(answer.pack_capacity_mah.or(answer.capacity_mah), 0)
        )?,
    }
    Ok(Outcome::Ok)
}
