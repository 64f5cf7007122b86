//! The logbook's tables, created and migrated in one place.
//!
//! The schema version is SQLite's `PRAGMA user_version`. A new file is created at version 1
//! and migrated forward like any old file: migration `n` takes a version `n` file to `n + 1`,
//! in one transaction with the version bump, so a file is always at exactly one version. A
//! migration never rewrites rows; columns it adds are `NULL` in rows written before it.
//! `docs/logbook.md` documents every table and column with its unit.

use rusqlite::{Connection, TransactionBehavior};

/// Version 1: flights with their energy figures, vehicles, packs, skipped files.
const V1: &str = "
CREATE TABLE vehicles (
    key TEXT PRIMARY KEY,
    key_source TEXT NOT NULL,
    first_added_unix_s INTEGER NOT NULL
);
CREATE TABLE packs (
    key TEXT PRIMARY KEY,
    key_source TEXT NOT NULL,
    rated_capacity_mah REAL,
    first_added_unix_s INTEGER NOT NULL
);
CREATE TABLE flights (
    id INTEGER PRIMARY KEY,
    file_sha256 TEXT NOT NULL UNIQUE,
    file_name TEXT NOT NULL,
    format TEXT NOT NULL,
    vehicle_key TEXT NOT NULL REFERENCES vehicles(key),
    pack_key TEXT NOT NULL REFERENCES packs(key),
    start_unix_s REAL,
    duration_s REAL NOT NULL,
    energy_wh REAL NOT NULL,
    discharged_mah REAL,
    max_current_a REAL,
    min_voltage_v REAL,
    mean_power_w REAL,
    added_unix_s INTEGER NOT NULL
);
CREATE INDEX flights_by_vehicle ON flights(vehicle_key);
CREATE INDEX flights_by_pack ON flights(pack_key);
CREATE TABLE skipped (
    file_sha256 TEXT PRIMARY KEY,
    file_name TEXT NOT NULL,
    reason TEXT NOT NULL,
    added_unix_s INTEGER NOT NULL
);
";

/// Version 1 to 2: the pack's analysis of each flight (resistance, capacity, cell balance) and
/// the vehicle's hover power.
const V1_TO_V2: &str = "
ALTER TABLE flights ADD COLUMN hover_power_w REAL;
ALTER TABLE flights ADD COLUMN cells_series INTEGER;
ALTER TABLE flights ADD COLUMN resistance_ohm REAL;
ALTER TABLE flights ADD COLUMN autopilot_resistance_ohm REAL;
ALTER TABLE flights ADD COLUMN capacity_mah REAL;
ALTER TABLE flights ADD COLUMN capacity_refusal TEXT;
ALTER TABLE flights ADD COLUMN imbalance_minor_min REAL;
ALTER TABLE flights ADD COLUMN imbalance_major_min REAL;
ALTER TABLE packs ADD COLUMN cells_series INTEGER;
";

/// Version 2 to 3: where each log was when added (to read it again for a pack file).
const V2_TO_V3: &str = "
ALTER TABLE flights ADD COLUMN file_path TEXT;
";

/// Version 3 to 4: a log of a flight already in the logbook is a copy of it (counted once); the
/// time in the air. From version 4 every file carries aloft's `application_id` (set by every
/// migration, so versions 1 to 3 are marked as they are brought up to date).
const V3_TO_V4: &str = "
ALTER TABLE flights ADD COLUMN copy_of INTEGER REFERENCES flights(id);
ALTER TABLE flights ADD COLUMN air_s REAL;
";

/// The schema of each version after 0: `MIGRATIONS[n]` takes a version `n` file to `n + 1`.
const MIGRATIONS: [&str; 4] = [V1, V1_TO_V2, V2_TO_V3, V3_TO_V4];

/// The schema version this code writes.
pub const SCHEMA_VERSION: i64 = MIGRATIONS.len() as i64;

/// The schema version of an open database.
pub(crate) fn version(conn: &Connection) -> rusqlite::Result<i64> {
    conn.query_row("PRAGMA user_version", [], |r| r.get(0))
}

/// What [`migrate`] found.
pub(crate) enum Migrated {
    /// The file is at [`SCHEMA_VERSION`] (it was, or has been migrated to it).
    Current,
    /// The file is at a newer version than this code knows.
    TooNew(i64),
}

/// Bring the database to [`SCHEMA_VERSION`]: each missing migration in a transaction of its own
/// that also sets the version. The version is read again inside the write lock, so two
/// processes opening a new file at once migrate it once.
pub(crate) fn migrate(conn: &mut Connection) -> rusqlite::Result<Migrated> {
    loop {
        let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
        let v = version(&tx)?;
        if v > SCHEMA_VERSION {
            return Ok(Migrated::TooNew(v));
        }
        let Some(step) = usize::try_from(v).ok().and_then(|i| MIGRATIONS.get(i)) else {
            return Ok(Migrated::Current);
        };
        tx.execute_batch(step)?;
        tx.execute_batch(&format!(
            "PRAGMA user_version = {}; PRAGMA application_id = {}",
            v + 1,
            crate::file::APPLICATION_ID
        ))?;
        tx.commit()?;
    }
}
