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
use crate::file::{self, Identity, APPLICATION_ID};
use crate::record::{read_flight, FlightFacts, ReadOptions};
use crate::schema::{migrate, Migrated, SCHEMA_VERSION};

/// How long a writer waits for another's lock before giving up (two `add`s at once both land).
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(10);

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
        let sql = file::sql_error(path);
        let mut conn = file::open_to_write(path, create)?;
        conn.busy_timeout(BUSY_TIMEOUT).map_err(&sql)?;
        match file::identify(&conn).map_err(&sql)? {
            Identity::Foreign {
                application_id,
                tables,
            } => {
                return Err(LogbookError::NotALogbook {
                    path: path.to_path_buf(),
                    application_id,
                    tables,
                })
            }
            Identity::Aloft(found) if found > SCHEMA_VERSION => {
                return Err(too_new(path, found));
            }
            Identity::Aloft(_) => {
                if let Some(problem) = file::quick_check(&conn).map_err(&sql)? {
                    return Err(LogbookError::Damaged {
                        path: path.to_path_buf(),
                        problem,
                    });
                }
            }
            Identity::Empty => {}
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
        match identity {
            Identity::Aloft(SCHEMA_VERSION) => Ok(Self {
                conn,
                path: path.to_path_buf(),
            }),
            Identity::Aloft(found) if found > SCHEMA_VERSION => Err(too_new(path, found)),
            Identity::Foreign {
                application_id,
                tables,
            } => Err(LogbookError::NotALogbook {
                path: path.to_path_buf(),
                application_id,
                tables,
            }),
            Identity::Aloft(found) => {
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
            Identity::Empty => Self::open(path),
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
        let facts = read_flight(file, options);
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
        let (vehicle_key, pack_key) = insert_flight(&tx, sha, (name, path), &f, labels, now)?;
        let flight_id = tx.last_insert_rowid();
        tx.execute("DELETE FROM skipped WHERE file_sha256 = ?1", [sha])?;
        tx.commit()?;
        Ok(AddOutcome::Added {
            flight_id,
            vehicle_key,
            pack_key,
        })
    }
}

/// The flight's row, with its vehicle and pack (each added when new, the pack's rating and cells
/// from the first log that states them); its vehicle and pack keys.
fn insert_flight(
    tx: &rusqlite::Transaction<'_>,
    sha: &str,
    (name, path): (&str, &str),
    f: &FlightFacts,
    labels: &Labels,
    now: i64,
) -> rusqlite::Result<(String, String)> {
    let (vehicle_key, vehicle_source) = key(f.vehicle_id.as_deref(), labels.vehicle.as_deref());
    let (pack_key, pack_source) = key(f.pack_id.as_deref(), labels.pack.as_deref());
    tx.execute(
        "INSERT OR IGNORE INTO vehicles (key, key_source, first_added_unix_s)
         VALUES (?1, ?2, ?3)",
        params![vehicle_key, vehicle_source, now],
    )?;
    tx.execute(
        "INSERT OR IGNORE INTO packs (key, key_source, first_added_unix_s)
         VALUES (?1, ?2, ?3)",
        params![pack_key, pack_source, now],
    )?;
    if pack_key != UNKNOWN {
        // The pack's rating and cells: the first log that states them.
        tx.execute(
            "UPDATE packs SET
               rated_capacity_mah = COALESCE(rated_capacity_mah, ?2),
               cells_series = COALESCE(cells_series, ?3)
             WHERE key = ?1",
            params![pack_key, f.rated_capacity_mah, f.cells_series],
        )?;
    }
    tx.execute(
        "INSERT INTO flights (
           file_sha256, file_name, format, vehicle_key, pack_key, start_unix_s, duration_s,
           energy_wh, discharged_mah, max_current_a, min_voltage_v, mean_power_w,
           added_unix_s, hover_power_w, cells_series, resistance_ohm,
           autopilot_resistance_ohm, capacity_mah, capacity_refusal, imbalance_minor_min,
           imbalance_major_min, file_path)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16,
                 ?17, ?18, ?19, ?20, ?21, ?22)",
        params![
            sha,
            name,
            f.format,
            vehicle_key,
            pack_key,
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
        ],
    )?;
    Ok((vehicle_key, pack_key))
}
