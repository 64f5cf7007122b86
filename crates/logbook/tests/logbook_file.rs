//! The logbook's file is aloft's alone: marked with SQLite's `application_id`, a SQLite file of
//! another program refused without a byte changed, an aloft logbook of an earlier schema (before
//! the mark) recognised by its tables and migrated, a damaged one refused before any write and
//! still listed where SQLite can read it, no file created through a link planted at its path.

#[path = "../../../tests/it/common/data.rs"]
mod data;

use std::path::{Path, PathBuf};

use aloft_logbook::{AddOutcome, Labels, Logbook, LogbookError, ReadOptions, APPLICATION_ID};

/// The mark, computed here from its documented spelling: the ASCII of "alft", big-endian (as
/// SQLite stores the header's application id).
const ALFT: i32 = i32::from_be_bytes(*b"alft");

fn kaist() -> Vec<PathBuf> {
    data::files("kaist_energy_drone", |n| n.ends_with(".csv"))
}

fn pragma(db: &Path, name: &str) -> i64 {
    let c = rusqlite::Connection::open_with_flags(db, rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY)
        .unwrap();
    c.query_row(&format!("PRAGMA {name}"), [], |r| r.get(0))
        .unwrap()
}

/// The side files SQLite makes beside a database it writes.
fn side_files(db: &Path) -> Vec<PathBuf> {
    ["-wal", "-shm", "-journal"]
        .iter()
        .map(|s| PathBuf::from(format!("{}{s}", db.display())))
        .filter(|p| p.exists())
        .collect()
}

#[test]
fn a_new_logbook_carries_the_alft_application_id() {
    assert_eq!(APPLICATION_ID, ALFT);
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    drop(Logbook::open(&db).unwrap());
    assert_eq!(pragma(&db, "application_id"), i64::from(ALFT));
    // A file of zero bytes (`touch`) is no one's yet: it becomes a logbook.
    let empty = tmp.path().join("empty.sqlite");
    std::fs::write(&empty, b"").unwrap();
    drop(Logbook::open(&empty).unwrap());
    assert_eq!(pragma(&empty, "application_id"), i64::from(ALFT));
}

/// SQLite files of other programs: one of its own tables; one that happens to have tables
/// named like the logbook's but another program's application id; one with a `flights` table
/// and a user version, but not the logbook's tables. Each is refused, named, and left exactly as
/// it was (no tables, no WAL switch, no side file).
#[test]
fn a_sqlite_file_of_another_program_is_refused_and_not_changed() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (
            "other-app.sqlite",
            "CREATE TABLE notes (id INTEGER PRIMARY KEY, text TEXT);
             INSERT INTO notes (text) VALUES ('keep me');",
        ),
        (
            "geopackage.gpkg",
            "PRAGMA application_id = 1196444487;
             CREATE TABLE flights (id INTEGER); CREATE TABLE vehicles (key TEXT);
             CREATE TABLE packs (key TEXT); CREATE TABLE skipped (file_sha256 TEXT);
             PRAGMA user_version = 3;",
        ),
        (
            "tracker.db",
            "CREATE TABLE flights (id INTEGER, origin TEXT); PRAGMA user_version = 2;",
        ),
    ];
    for (name, sql) in cases {
        let db = tmp.path().join(name);
        rusqlite::Connection::open(&db)
            .unwrap()
            .execute_batch(sql)
            .unwrap();
        let before = std::fs::read(&db).unwrap();
        let e = Logbook::open(&db).unwrap_err();
        assert!(
            matches!(e, LogbookError::NotALogbook { .. }),
            "{name}: {e:?}"
        );
        let text = e.to_string();
        assert!(
            text.contains(name) && text.contains("not an aloft logbook") && !text.contains('\n'),
            "{text}"
        );
        assert!(
            std::fs::read(&db).unwrap() == before,
            "{name}: its bytes changed"
        );
        assert_eq!(side_files(&db), Vec::<PathBuf>::new(), "{name}");
        // Listing refuses it too.
        let e = Logbook::open_read_only(&db).unwrap_err();
        assert!(
            matches!(e, LogbookError::NotALogbook { .. }),
            "{name}: {e:?}"
        );
        assert!(std::fs::read(&db).unwrap() == before);
        assert_eq!(side_files(&db), Vec::<PathBuf>::new(), "{name}");
    }
}

/// Listing a logbook in a folder the user may write leaves no side file behind (a read-only
/// SQLite connection cannot remove the WAL's `-wal` and `-shm` when it closes).
#[test]
fn listing_leaves_no_side_files() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let mut book = Logbook::open(&db).unwrap();
    book.add(&kaist()[10], &Labels::default(), &ReadOptions::default())
        .unwrap();
    drop(book);
    assert_eq!(side_files(&db), Vec::<PathBuf>::new());
    let book = Logbook::open_read_only(&db).unwrap();
    assert_eq!(book.flights().unwrap().len(), 1);
    drop(book);
    assert_eq!(side_files(&db), Vec::<PathBuf>::new());
}

/// The schema of version 3, as aloft wrote it before the mark (written out here, not taken from
/// the crate), with one flight.
const V3: &str = "
CREATE TABLE vehicles (key TEXT PRIMARY KEY, key_source TEXT NOT NULL,
    first_added_unix_s INTEGER NOT NULL);
CREATE TABLE packs (key TEXT PRIMARY KEY, key_source TEXT NOT NULL, rated_capacity_mah REAL,
    first_added_unix_s INTEGER NOT NULL, cells_series INTEGER);
CREATE TABLE flights (id INTEGER PRIMARY KEY, file_sha256 TEXT NOT NULL UNIQUE,
    file_name TEXT NOT NULL, format TEXT NOT NULL,
    vehicle_key TEXT NOT NULL REFERENCES vehicles(key),
    pack_key TEXT NOT NULL REFERENCES packs(key), start_unix_s REAL, duration_s REAL NOT NULL,
    energy_wh REAL NOT NULL, discharged_mah REAL, max_current_a REAL, min_voltage_v REAL,
    mean_power_w REAL, added_unix_s INTEGER NOT NULL, hover_power_w REAL, cells_series INTEGER,
    resistance_ohm REAL, autopilot_resistance_ohm REAL, capacity_mah REAL,
    capacity_refusal TEXT, imbalance_minor_min REAL, imbalance_major_min REAL, file_path TEXT);
CREATE INDEX flights_by_vehicle ON flights(vehicle_key);
CREATE INDEX flights_by_pack ON flights(pack_key);
CREATE TABLE skipped (file_sha256 TEXT PRIMARY KEY, file_name TEXT NOT NULL,
    reason TEXT NOT NULL, added_unix_s INTEGER NOT NULL);
INSERT INTO vehicles VALUES ('quad-1', 'label', 1700000000);
INSERT INTO packs VALUES ('pack-1', 'label', 5000, 1700000000, 3);
INSERT INTO flights (file_sha256, file_name, format, vehicle_key, pack_key, duration_s,
    energy_wh, discharged_mah, added_unix_s, file_path)
  VALUES ('00', 'old.ulg', 'ulog', 'quad-1', 'pack-1', 600, 50, 2500, 1700000000, '/old.ulg');
PRAGMA user_version = 3;
";

/// A logbook of version 3 (before the mark) is aloft's by its version and tables: it is
/// migrated, marked, its flight kept, and a log can be added. Listing it first (read-only where
/// it can be written) brings it up to date too.
#[test]
fn a_version_3_logbook_without_the_mark_is_migrated_and_marked() {
    let tmp = tempfile::tempdir().unwrap();
    for listed_first in [false, true] {
        let db = tmp.path().join(format!("v3-{listed_first}.sqlite"));
        rusqlite::Connection::open(&db)
            .unwrap()
            .execute_batch(V3)
            .unwrap();
        assert_eq!(pragma(&db, "application_id"), 0);
        if listed_first {
            let book = Logbook::open_read_only(&db).unwrap();
            assert_eq!(book.flights().unwrap().len(), 1);
        }
        let mut book = Logbook::open(&db).unwrap();
        let flights = book.flights().unwrap();
        assert_eq!(flights.len(), 1);
        assert_eq!(flights[0].file_name, "old.ulg");
        let o = book
            .add(&kaist()[10], &Labels::default(), &ReadOptions::default())
            .unwrap();
        assert!(matches!(o, AddOutcome::Added { flight_id: 2, .. }), "{o:?}");
        drop(book);
        assert_eq!(pragma(&db, "application_id"), i64::from(ALFT));
        assert_eq!(
            pragma(&db, "user_version"),
            aloft_logbook::SCHEMA_VERSION,
            "listed first: {listed_first}"
        );
    }
}

/// The page of the `skipped` table overwritten in the middle of a logbook of eleven flights:
/// `add` refuses it before writing (SQLite's quick_check), in one line naming the file; the
/// flights and packs, whose pages are whole, are still listed.
#[test]
fn a_damaged_logbook_is_refused_for_adding_and_still_listed() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let files = kaist();
    {
        let mut book = Logbook::open(&db).unwrap();
        for f in &files {
            book.add(f, &Labels::default(), &ReadOptions::default())
                .unwrap();
        }
        let cut = tmp.path().join("cut.csv");
        std::fs::write(&cut, &std::fs::read(&files[0]).unwrap()[..1000]).unwrap();
        let o = book
            .add(&cut, &Labels::default(), &ReadOptions::default())
            .unwrap();
        assert!(matches!(o, AddOutcome::Skipped { .. }));
    }
    damage_table_page(&db, "skipped");
    let before = std::fs::read(&db).unwrap();
    let e = Logbook::open(&db).unwrap_err();
    assert!(matches!(e, LogbookError::Damaged { .. }), "{e:?}");
    let text = e.to_string();
    assert!(
        text.contains("book.sqlite") && text.contains("damaged") && !text.contains('\n'),
        "{text}"
    );
    assert!(
        std::fs::read(&db).unwrap() == before,
        "refused, yet written"
    );
    let book = Logbook::open_read_only(&db).unwrap();
    assert_eq!(book.flights().unwrap().len(), files.len());
    assert_eq!(
        book.packs()
            .unwrap()
            .iter()
            .map(|p| p.flights)
            .sum::<usize>(),
        files.len()
    );
    assert!(book.skipped().is_err(), "the damaged table read as whole");
}

/// Overwrite the b-tree page header of `table`'s root page (its first 12 bytes) with 0xFF: a
/// page type SQLite does not know. The page number and size are SQLite's own (`sqlite_master`,
/// `page_size`), read by a connection of the test.
fn damage_table_page(db: &Path, table: &str) {
    let c = rusqlite::Connection::open(db).unwrap();
    let page: i64 = c
        .query_row(
            "SELECT rootpage FROM sqlite_master WHERE name = ?1",
            [table],
            |r| r.get(0),
        )
        .unwrap();
    let size: i64 = c.query_row("PRAGMA page_size", [], |r| r.get(0)).unwrap();
    let count: i64 = c.query_row("PRAGMA page_count", [], |r| r.get(0)).unwrap();
    drop(c);
    assert!(page > 1 && page < count, "page {page} of {count}");
    let mut bytes = std::fs::read(db).unwrap();
    let at = usize::try_from((page - 1) * size).unwrap();
    bytes[at..at + 12].fill(0xFF);
    std::fs::write(db, bytes).unwrap();
}

/// A link planted at the logbook's path to a file that does not exist: nothing is created
/// through it, and the error names the path. A link to an existing logbook is followed (an
/// operator may keep their logbook elsewhere).
#[cfg(unix)]
#[test]
fn no_logbook_is_created_through_a_dangling_link() {
    let tmp = tempfile::tempdir().unwrap();
    let target = tmp.path().join("elsewhere.sqlite");
    let link = tmp.path().join("book.sqlite");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let e = Logbook::open(&link).unwrap_err();
    assert!(matches!(e, LogbookError::DanglingLink { .. }), "{e:?}");
    assert!(e.to_string().contains("book.sqlite"), "{e}");
    assert!(!target.exists(), "created through the link");
    assert!(Logbook::open_read_only(&link).is_err());
    assert!(!target.exists());
    // A link to a logbook is the logbook.
    drop(Logbook::open(&target).unwrap());
    let mut book = Logbook::open(&link).unwrap();
    book.add(&kaist()[10], &Labels::default(), &ReadOptions::default())
        .unwrap();
    drop(book);
    assert_eq!(
        Logbook::open_read_only(&target)
            .unwrap()
            .flights()
            .unwrap()
            .len(),
        1
    );
}

/// Listing a file that does not exist creates nothing and says so.
#[test]
fn listing_a_missing_logbook_creates_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("none.sqlite");
    let e = Logbook::open_read_only(&db).unwrap_err();
    assert!(e.to_string().contains("none.sqlite"), "{e}");
    assert!(!db.exists());
}
