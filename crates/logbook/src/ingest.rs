//! Opening a logbook and adding logs to it: one transaction per file, keyed by the file's
//! SHA-256, so adding a log twice changes nothing and a log that fails leaves no row but its
//! `skipped` entry.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use rusqlite::{params, Connection, OptionalExtension, TransactionBehavior};
use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::error::{LogbookError, Result};
use crate::file::{self, Identity, APPLICATION_ID, BUSY_TIMEOUT};
use crate::record::{read_flight, FlightFacts, ReadOptions};
use crate::schema::{migrate, Migrated, SCHEMA_VERSION};

/// Switch the file to WAL, waiting up to [`BUSY_TIMEOUT`] for other connections. The switch
/// reads the file and then takes its write lock; when two connections do so at once SQLite
/// refuses one at once, without its busy handler (the two would otherwise wait on each other),
/// so the refused one tries again here once the other is done.
fn use_wal(conn: &Connection) -> rusqlite::Result<()> {
    let deadline = Instant::now() + BUSY_TIMEOUT;
    loop {
        match conn.query_row("PRAGMA journal_mode = WAL", [], |r| r.get::<_, String>(0)) {
            Err(rusqlite::Error::SqliteFailure(e, _))
                if e.code == rusqlite::ErrorCode::DatabaseBusy && Instant::now() < deadline =>
            {
                std::thread::sleep(Duration::from_millis(5));
            }
            other => return other.map(drop),
        }
    }
}

/// The folder the logbook is to be in must exist (it is not made: a typo in `--db` should not
/// leave a folder behind).
fn check_folder(path: &Path) -> Result<()> {
    let folder = match path.parent() {
        Some(p) if p.as_os_str().is_empty() => Path::new("."),
        Some(p) => p,
        None => Path::new("."),
    };
    if folder.is_dir() {
        Ok(())
    } else {
        Err(LogbookError::FolderMissing {
            folder: folder.to_path_buf(),
        })
    }
}

/// Refuse another program's file and a newer aloft's; the schema version of an aloft logbook
/// (`None`: an empty file, to be made one).
fn check_identity(path: &Path, identity: Identity) -> Result<Option<i64>> {
    match identity {
        Identity::Foreign {
            application_id,
            tables,
        } => Err(LogbookError::NotALogbook {
            path: path.to_path_buf(),
            application_id,
            tables,
        }),
        Identity::Aloft(found) if found > SCHEMA_VERSION => Err(too_new(path, found)),
        Identity::Aloft(found) => Ok(Some(found)),
        Identity::Empty => Ok(None),
    }
}

/// A read-write connection to the logbook at `path` that can read it, where the file and its
/// folder can be written.
fn writable_reader(path: &Path) -> Option<Connection> {
    let conn = file::open_to_write(path, false).ok()?;
    conn.busy_timeout(BUSY_TIMEOUT).ok()?;
    file::identify(&conn).ok()?;
    Some(conn)
}

fn too_new(path: &Path, found: i64) -> LogbookError {
    LogbookError::SchemaTooNew {
        path: path.to_path_buf(),
        found,
        supported: SCHEMA_VERSION,
    }
}

/// Mark the file as aloft's ([`APPLICATION_ID`]) where it is not yet (a logbook of before the
/// mark, once migrated).
fn mark(conn: &Connection) -> rusqlite::Result<()> {
    let id: i32 = conn.query_row("PRAGMA application_id", [], |r| r.get(0))?;
    if id != APPLICATION_ID {
        conn.execute_batch(&format!("PRAGMA application_id = {APPLICATION_ID}"))?;
    }
    Ok(())
}

/// The key of a vehicle or pack whose log does not identify it and that was given no label.
pub const UNKNOWN: &str = "unknown";

/// An open logbook: one SQLite file in WAL mode at [`SCHEMA_VERSION`].
#[derive(Debug)]
pub struct Logbook {
    pub(crate) conn: Connection,
    pub(crate) path: PathBuf,
}

/// Keys given on the command line for logs that do not identify their vehicle or pack.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Labels {
    /// The vehicle of logs without a vehicle identity (`--vehicle-label`).
    pub vehicle: Option<String>,
    /// The pack of logs without a pack identity (`--pack-label`).
    pub pack: Option<String>,
}

/// What adding one file did.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum AddOutcome {
    /// A new flight.
    Added {
        /// Its id in `flights`.
        flight_id: i64,
        /// The vehicle key it was filed under.
        vehicle_key: String,
        /// The pack key it was filed under.
        pack_key: String,
    },
    /// Another log of a flight already in the logbook (the same vehicle over the same time:
    /// a truncated copy, the telemetry of a flight whose own log is there): recorded as a copy
    /// of it, its hours and energy not counted again.
    Copy {
        /// Its id in `flights`.
        flight_id: i64,
        /// The flight it is a copy of.
        copy_of: i64,
        /// The vehicle key it was filed under.
        vehicle_key: String,
        /// The pack key it was filed under.
        pack_key: String,
    },
    /// The same file (by content) is already a flight of the logbook.
    AlreadyPresent {
        /// Its id in `flights`.
        flight_id: i64,
    },
    /// The file is not a flight of the logbook: recorded in `skipped` (when it could be read
    /// to hash it) with the reason.
    Skipped {
        /// Why, in words.
        reason: String,
    },
}

/// Seconds since the Unix epoch, now.
fn now_unix_s() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_secs()).unwrap_or(i64::MAX))
}

/// The SHA-256 of a file's content, as 64 lowercase hex digits.
///
/// # Errors
/// The file cannot be opened or read.
pub fn file_sha256(path: &Path) -> std::io::Result<String> {
    let mut file = std::fs::File::open(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = file.read(&mut buf)?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
}

/// A key and where it came from: the log's identity, else the label, else [`UNKNOWN`].
fn key(from_log: Option<&str>, label: Option<&str>) -> (String, &'static str) {
    match (from_log, label) {
        (Some(id), _) => (id.to_string(), "log"),
        (None, Some(l)) => (l.to_string(), "label"),
        (None, None) => (UNKNOWN.to_string(), UNKNOWN),
    }
}

/// The highest voltage of a cell of a charged lithium pack (LiHV), V.
pub const MAX_CELL_V: f64 = 4.35;
/// The lowest voltage of a cell at the high voltage of a flight, V: a pack is not flown from
/// below it (a LiPo cell at 3.6 V has about a tenth of its charge left).
pub const MIN_FLOWN_CELL_V: f64 = 3.6;
/// The least rated capacity believed, mAh (a smaller one is a placeholder, not a pack).
pub const MIN_RATED_CAPACITY_MAH: f64 = 10.0;

/// Cells in series of a pack whose high voltage over a flight is `high_v`: the one count `n`
/// with `n` x [`MIN_FLOWN_CELL_V`] <= `high_v` <= `n` x [`MAX_CELL_V`], where only one fits
/// (up to 4 or 5 cells; above that two counts fit, e.g. 11 to 13 cells at 47.8 V, and the
/// voltage does not say).
pub fn cells_from_voltage(high_v: f64) -> Option<u32> {
    if !(high_v.is_finite() && high_v > 0.0) {
        return None;
    }
    let least = (high_v / MAX_CELL_V).ceil();
    let most = (high_v / MIN_FLOWN_CELL_V).floor();
    ((least - most).abs() < 0.5 && least >= 1.0).then_some(least as u32)
}

/// Cells in series of a flight's pack: its log's parameters or cell voltages, else its high
/// voltage where it says ([`cells_from_voltage`]).
pub fn cells_of(f: &FlightFacts) -> Option<u32> {
    f.cells_series
        .or_else(|| f.high_voltage_v.and_then(cells_from_voltage))
}

/// The rated capacity of a flight's pack, where it is a pack's ([`MIN_RATED_CAPACITY_MAH`]).
fn rated_of(f: &FlightFacts) -> Option<f64> {
    f.rated_capacity_mah
        .filter(|c| c.is_finite() && *c >= MIN_RATED_CAPACITY_MAH)
}

/// The key of a pack the log does not name and no label names: `unknown`, its cells and rated
/// capacity where known, and its vehicle (`unknown 3S 5000 mAh on quad-1`).
pub fn derived_pack_key(cells: Option<u32>, rated_mah: Option<f64>, vehicle_key: &str) -> String {
    let mut k = UNKNOWN.to_string();
    if let Some(n) = cells {
        k.push_str(&format!(" {n}S"));
    }
    if let Some(c) = rated_mah {
        k.push_str(&format!(" {c:.0} mAh"));
    }
    format!("{k} on {vehicle_key}")
}

/// What a pack key of a derived pack ends with: its vehicle.
pub(crate) fn derived_suffix(vehicle_key: &str) -> String {
    format!(" on {vehicle_key}")
}

/// A label the operator gives a vehicle or pack: trimmed, 1 to 200 characters, no control
/// characters, not [`UNKNOWN`] and not a key aloft derives (`unknown ...`).
///
/// # Errors
/// [`LogbookError::BadLabel`], saying why.
pub fn check_label(label: &str) -> Result<String> {
    let t = label.trim();
    let bad = |reason: &'static str| {
        Err(LogbookError::BadLabel {
            label: label.to_string(),
            reason,
        })
    };
    if t.is_empty() || t.chars().count() > 200 {
        return bad("1 to 200 characters");
    }
    if t.chars().any(char::is_control) {
        return bad("no control characters");
    }
    if t == UNKNOWN || t.starts_with("unknown ") {
        return bad("not \"unknown\" nor a key aloft gives (\"unknown ...\")");
    }
    Ok(t.to_string())
}

impl Logbook {
    /// Open the logbook at `path` to add to it, creating it (not its folder) when missing, and
    /// migrate it to [`SCHEMA_VERSION`] (see [`crate::file`] for what is refused, and why).
    ///
    /// # Errors
    /// The folder is missing; a link to nothing or not a regular file is at the path; the file
    /// is not a SQLite database, is another program's ([`LogbookError::NotALogbook`], nothing
    /// in it changed), is damaged ([`LogbookError::Damaged`]) or cannot be written; its schema is
    /// newer than this code's.
    pub fn open(path: &Path) -> Result<Self> {
        check_folder(path)?;
        let create = !file::existing(path)?;
        if !create {
            // Whose the file is, read by a connection that cannot write it.
            let (read, identity) = file::open_to_read(path)?;
            drop(read);
            check_identity(path, identity)?;
        }
        let sql = file::sql_error(path);
        let mut conn = file::open_to_write(path, create)?;
        conn.busy_timeout(BUSY_TIMEOUT).map_err(&sql)?;
        // Again under this connection: another `add` may have made the file meanwhile.
        if check_identity(path, file::identify(&conn).map_err(&sql)?)?.is_some() {
            if let Some(problem) = file::quick_check(&conn).map_err(&sql)? {
                return Err(LogbookError::Damaged {
                    path: path.to_path_buf(),
                    problem,
                });
            }
        }
        use_wal(&conn).map_err(&sql)?;
        conn.execute_batch("PRAGMA foreign_keys = ON")
            .map_err(&sql)?;
        match migrate(&mut conn).map_err(&sql)? {
            Migrated::Current => {}
            Migrated::TooNew(found) => return Err(too_new(path, found)),
        }
        mark(&conn).map_err(&sql)?;
        Ok(Self {
            conn,
            path: path.to_path_buf(),
        })
    }

    /// Open the logbook at `path` to list it, read-only: a file or folder the user may not
    /// write can be listed. A logbook of an older schema (or a file of zero bytes) is brought up
    /// to date first, as [`Logbook::open`] does, where the file can be written.
    ///
    /// # Errors
    /// No file at the path ([`LogbookError::NoLogbook`]: listing makes none); the file is not a
    /// SQLite database or is another program's; its schema is newer than this code's, or older
    /// and the file cannot be written ([`LogbookError::CannotMigrate`]).
    pub fn open_read_only(path: &Path) -> Result<Self> {
        check_folder(path)?;
        if !file::existing(path)? {
            return Err(LogbookError::NoLogbook {
                path: path.to_path_buf(),
            });
        }
        let (conn, identity) = file::open_to_read(path)?;
        match check_identity(path, identity)? {
            // Read through a read-write connection where the file and its folder can be
            // written: SQLite then removes the WAL's side files when it closes (a read-only
            // one leaves them). Nothing is written either way.
            Some(SCHEMA_VERSION) => Ok(Self {
                conn: writable_reader(path).unwrap_or(conn),
                path: path.to_path_buf(),
            }),
            Some(found) => {
                drop(conn);
                Self::open(path).map_err(|e| match e {
                    LogbookError::ReadOnly { .. } => LogbookError::CannotMigrate {
                        path: path.to_path_buf(),
                        found,
                        supported: SCHEMA_VERSION,
                    },
                    e => e,
                })
            }
            None => Self::open(path),
        }
    }

    /// The database file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    pub(crate) fn sql(&self, source: rusqlite::Error) -> LogbookError {
        LogbookError::Sqlite {
            path: self.path.clone(),
            source,
        }
    }

    /// Add the log at `file`: a new flight, one already there (same content), or skipped with
    /// the reason (recorded in `skipped` when the file could be hashed; a file that cannot be
    /// read at all is only reported).
    ///
    /// # Errors
    /// The database cannot be written (a log's own faults are [`AddOutcome::Skipped`]).
    pub fn add(
        &mut self,
        file: &Path,
        labels: &Labels,
        options: &ReadOptions,
    ) -> Result<AddOutcome> {
        self.add_with(file, labels, |p| read_flight(p, options))
    }

    /// [`Logbook::add`] with the figures of the flight read by `read` (a reader of a format
    /// this crate does not decode, such as a MAVLink telemetry log): its `Err` is the reason the
    /// file is skipped.
    ///
    /// # Errors
    /// The database cannot be written.
    pub fn add_with(
        &mut self,
        file: &Path,
        labels: &Labels,
        read: impl FnOnce(&Path) -> std::result::Result<FlightFacts, String>,
    ) -> Result<AddOutcome> {
        let sha = match file_sha256(file) {
            Ok(s) => s,
            Err(e) => {
                return Ok(AddOutcome::Skipped {
                    reason: format!("cannot read the file: {e}"),
                })
            }
        };
        if let Some(flight_id) = self.flight_of(&sha)? {
            return Ok(AddOutcome::AlreadyPresent { flight_id });
        }
        let name = file.file_name().map_or_else(
            || file.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        // Where it is, to read it again (`aloft logbook pack-file`): absolute when it can be.
        let path = std::fs::canonicalize(file)
            .unwrap_or_else(|_| file.to_path_buf())
            .display()
            .to_string();
        // Read outside the write lock: another `add` writes meanwhile.
        let facts = read(file);
        self.write(&sha, (&name, &path), facts, labels)
            .map_err(|e| self.sql(e))
    }

    /// The flight with this file hash.
    fn flight_of(&self, sha: &str) -> Result<Option<i64>> {
        self.conn
            .query_row(
                "SELECT id FROM flights WHERE file_sha256 = ?1",
                [sha],
                |r| r.get(0),
            )
            .optional()
            .map_err(|e| self.sql(e))
    }

    /// Write one file's row (its flight, or its `skipped` entry) in one transaction.
    fn write(
        &mut self,
        sha: &str,
        (name, path): (&str, &str),
        facts: std::result::Result<FlightFacts, String>,
        labels: &Labels,
    ) -> rusqlite::Result<AddOutcome> {
        let now = now_unix_s();
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)?;
        // Another process may have added the same file since it was looked up.
        let present: Option<i64> = tx
            .query_row(
                "SELECT id FROM flights WHERE file_sha256 = ?1",
                [sha],
                |r| r.get(0),
            )
            .optional()?;
        if let Some(flight_id) = present {
            return Ok(AddOutcome::AlreadyPresent { flight_id });
        }
        let f = match facts {
            Ok(f) => f,
            Err(reason) => {
                tx.execute(
                    "INSERT INTO skipped (file_sha256, file_name, reason, added_unix_s)
                     VALUES (?1, ?2, ?3, ?4)
                     ON CONFLICT(file_sha256) DO UPDATE SET
                       file_name = excluded.file_name, reason = excluded.reason",
                    params![sha, name, reason, now],
                )?;
                tx.commit()?;
                return Ok(AddOutcome::Skipped { reason });
            }
        };
        let outcome = insert_flight(&tx, sha, (name, path), &f, labels, now)?;
        tx.execute("DELETE FROM skipped WHERE file_sha256 = ?1", [sha])?;
        tx.commit()?;
        Ok(outcome)
    }
}

/// The vehicle and pack keys of a flight, with where they came from.
struct Keys {
    vehicle: (String, &'static str),
    pack: (String, &'static str),
}

/// The keys of a flight: the log's identities, else the labels, else `unknown` for the vehicle
/// and a key of the vehicle, cells and rating for the pack ([`derived_pack_key`]).
fn keys_of(f: &FlightFacts, labels: &Labels) -> Keys {
    let vehicle = key(f.vehicle_id.as_deref(), labels.vehicle.as_deref());
    let pack = match key(f.pack_id.as_deref(), labels.pack.as_deref()) {
        (_, UNKNOWN) => (
            derived_pack_key(cells_of(f), rated_of(f), &vehicle.0),
            "derived",
        ),
        named => named,
    };
    Keys { vehicle, pack }
}

/// The flight that a log of `vehicle_key` starting at `start_unix_s` and lasting `duration_s`
/// is another log of: the first flight (not itself a copy) of the same vehicle whose span
/// overlaps. For the vehicle [`UNKNOWN`], whose logs may be of several vehicles flying at once,
/// the starts must also agree within a second (a log cut short starts where the whole one
/// does). A log without a clock is never a copy (only its content can say it is the same).
fn original_of(
    tx: &rusqlite::Transaction<'_>,
    vehicle_key: &str,
    start_unix_s: Option<f64>,
    duration_s: f64,
) -> rusqlite::Result<Option<i64>> {
    let Some(start) = start_unix_s.filter(|s| s.is_finite()) else {
        return Ok(None);
    };
    let end = start + duration_s.max(0.0);
    tx.query_row(
        "SELECT id FROM flights
         WHERE vehicle_key = ?1 AND copy_of IS NULL AND start_unix_s IS NOT NULL
           AND start_unix_s <= ?3 AND start_unix_s + duration_s >= ?2
           AND (vehicle_key != ?4 OR abs(start_unix_s - ?2) < 1.0)
         ORDER BY id LIMIT 1",
        params![vehicle_key, start, end, UNKNOWN],
        |r| r.get(0),
    )
    .optional()
}

/// The vehicle and pack rows of a flight's keys, each added when new; the pack's rating and
/// cells from the first log that states them.
fn insert_keys(
    tx: &rusqlite::Transaction<'_>,
    k: &Keys,
    f: &FlightFacts,
    now: i64,
) -> rusqlite::Result<()> {
    tx.execute(
        "INSERT OR IGNORE INTO vehicles (key, key_source, first_added_unix_s)
         VALUES (?1, ?2, ?3)",
        params![k.vehicle.0, k.vehicle.1, now],
    )?;
    tx.execute(
        "INSERT OR IGNORE INTO packs (key, key_source, first_added_unix_s)
         VALUES (?1, ?2, ?3)",
        params![k.pack.0, k.pack.1, now],
    )?;
    tx.execute(
        "UPDATE packs SET
           rated_capacity_mah = COALESCE(rated_capacity_mah, ?2),
           cells_series = COALESCE(cells_series, ?3)
         WHERE key = ?1",
        params![k.pack.0, rated_of(f), cells_of(f)],
    )?;
    Ok(())
}

/// The flight's row, with its vehicle and pack: a new flight, or a copy of one already there.
fn insert_flight(
    tx: &rusqlite::Transaction<'_>,
    sha: &str,
    (name, path): (&str, &str),
    f: &FlightFacts,
    labels: &Labels,
    now: i64,
) -> rusqlite::Result<AddOutcome> {
    let k = keys_of(f, labels);
    insert_keys(tx, &k, f, now)?;
    let copy_of = original_of(tx, &k.vehicle.0, f.start_unix_s, f.duration_s)?;
    tx.execute(
        "INSERT INTO flights (
           file_sha256, file_name, format, vehicle_key, pack_key, start_unix_s, duration_s,
           energy_wh, discharged_mah, max_current_a, min_voltage_v, mean_power_w,
           added_unix_s, hover_power_w, cells_series, resistance_ohm,
           autopilot_resistance_ohm, capacity_mah, capacity_refusal, imbalance_minor_min,
           imbalance_major_min, file_path, copy_of, air_s)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16,
                 ?17, ?18, ?19, ?20, ?21, ?22, ?23, ?24)",
        params![
            sha,
            name,
            f.format,
            k.vehicle.0,
            k.pack.0,
            f.start_unix_s,
            f.duration_s,
            f.energy_wh,
            f.discharged_mah,
            f.max_current_a,
            f.min_voltage_v,
            f.mean_power_w,
            now,
            f.hover_power_w,
            f.cells_series,
            f.resistance_ohm,
            f.autopilot_resistance_ohm,
            f.capacity_mah,
            f.capacity_refusal,
            f.imbalance_minor_min,
            f.imbalance_major_min,
            path,
            copy_of,
            f.air_s,
        ],
    )?;
    let flight_id = tx.last_insert_rowid();
    let (vehicle_key, pack_key) = (k.vehicle.0, k.pack.0);
    Ok(match copy_of {
        Some(copy_of) => AddOutcome::Copy {
            flight_id,
            copy_of,
            vehicle_key,
            pack_key,
        },
        None => AddOutcome::Added {
            flight_id,
            vehicle_key,
            pack_key,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The counts of full and nearly empty 3S, 4S, 6S and 12S packs, against n x 3.6 V to
    /// n x 4.35 V by hand.
    #[test]
    fn cells_from_voltage_where_one_count_fits() {
        assert_eq!(cells_from_voltage(12.6), Some(3));
        assert_eq!(cells_from_voltage(11.1), Some(3));
        assert_eq!(cells_from_voltage(16.8), Some(4));
        assert_eq!(cells_from_voltage(14.4), Some(4));
        // 25.2 V: 6 x 4.2 V or 7 x 3.6 V.
        assert_eq!(cells_from_voltage(25.2), None);
        assert_eq!(cells_from_voltage(47.8), None);
        assert_eq!(cells_from_voltage(f64::NAN), None);
        assert_eq!(cells_from_voltage(0.0), None);
    }

    #[test]
    fn derived_keys_say_what_is_known() {
        assert_eq!(
            derived_pack_key(Some(3), Some(5000.0), "q"),
            "unknown 3S 5000 mAh on q"
        );
        assert_eq!(derived_pack_key(None, None, "q"), "unknown on q");
        assert!(check_label("unknown 3S on q").is_err());
        assert!(check_label("a\nb").is_err());
        assert_eq!(check_label(" pack-7 ").unwrap(), "pack-7");
    }
}
