//! The logbook's file: whose it is, whether it is whole, and how it is opened.
//!
//! A logbook is marked with SQLite's `PRAGMA application_id` = [`APPLICATION_ID`] (the ASCII of
//! "alft"). A file is the logbook's to write only when it carries the mark, when it is empty (no
//! schema at all: a new file, or one of zero bytes), or when it is an aloft logbook of a
//! version written before the mark ([`LAST_UNMARKED_VERSION`]), recognised by its
//! `user_version` and aloft's four tables. Anything else is another program's file and is left
//! exactly as it is: it is only read (its header and `sqlite_master`) before it is refused.
//!
//! Writing opens the file read-write, and creates a missing one without following a link at
//! its path (`O_NOFOLLOW` through `SQLITE_OPEN_NOFOLLOW`; a link to nothing is refused before).
//! Before anything is written, SQLite's `PRAGMA quick_check` must find the file whole.
//!
//! Reading opens the file read-only (`mode=ro`), so a file or folder the user may not write
//! can be listed. A WAL database needs its `-shm` side file; where SQLite can neither open nor
//! make it (a read-only folder, the last writer gone), the file is opened `immutable=1`, which
//! reads the database file alone. That is right when no one writes the file meanwhile, which a
//! folder the reader may not write makes likely, not certain.

use std::path::{Path, PathBuf};
use std::time::Duration;

use rusqlite::{Connection, OpenFlags};

use crate::error::{LogbookError, Result};

/// How long a writer waits for another's lock before giving up (two `add`s at once both land).
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(10);

/// The logbook's mark in the SQLite header (`PRAGMA application_id`): the ASCII of "alft",
/// big-endian, 0x616C6674 = 1634494068.
pub const APPLICATION_ID: i32 = i32::from_be_bytes(*b"alft");

/// The newest schema version aloft wrote without the mark: unmarked files of versions 1 to this
/// with aloft's tables are aloft logbooks of before the mark.
pub const LAST_UNMARKED_VERSION: i64 = 3;

/// The tables every aloft logbook has had since version 1.
const ALOFT_TABLES: [&str; 4] = ["flights", "packs", "skipped", "vehicles"];

/// What a SQLite file is, by its header and its schema.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Identity {
    /// No schema, no version, no mark: a new (or zero-byte) file.
    Empty,
    /// An aloft logbook at this schema version (marked, or of before the mark).
    Aloft(i64),
    /// Another program's file.
    Foreign {
        /// Its `application_id`.
        application_id: i32,
        /// Its tables, by name.
        tables: Vec<String>,
    },
}

/// Whose the database of `conn` is (reads its header and `sqlite_master` only, in one read
/// transaction: another connection making the file meanwhile is seen before or after).
pub(crate) fn identify(conn: &Connection) -> rusqlite::Result<Identity> {
    let tx = conn.unchecked_transaction()?;
    let identity = identify_in(&tx)?;
    tx.commit()?;
    Ok(identity)
}

fn identify_in(conn: &Connection) -> rusqlite::Result<Identity> {
    let application_id: i32 = conn.query_row("PRAGMA application_id", [], |r| r.get(0))?;
    let version: i64 = conn.query_row("PRAGMA user_version", [], |r| r.get(0))?;
    let mut st = conn.prepare("SELECT type, name FROM sqlite_master ORDER BY name")?;
    let objects: Vec<(String, String)> = st
        .query_map([], |r| Ok((r.get(0)?, r.get(1)?)))?
        .collect::<rusqlite::Result<_>>()?;
    let tables: Vec<String> = objects
        .iter()
        .filter(|(kind, name)| kind == "table" && !name.starts_with("sqlite_"))
        .map(|(_, name)| name.clone())
        .collect();
    let has_aloft_tables = ALOFT_TABLES.iter().all(|t| tables.iter().any(|n| n == t));
    Ok(match application_id {
        APPLICATION_ID => Identity::Aloft(version),
        0 if objects.is_empty() && version == 0 => Identity::Empty,
        0 if has_aloft_tables && (1..=LAST_UNMARKED_VERSION).contains(&version) => {
            Identity::Aloft(version)
        }
        _ => Identity::Foreign {
            application_id,
            tables,
        },
    })
}

/// The first problem SQLite's `PRAGMA quick_check` finds, `None` when the file is whole.
pub(crate) fn quick_check(conn: &Connection) -> rusqlite::Result<Option<String>> {
    let first: String = conn.query_row("PRAGMA quick_check(1)", [], |r| r.get(0))?;
    Ok((first != "ok").then(|| first.split_whitespace().collect::<Vec<_>>().join(" ")))
}

/// The error of a SQLite call on `path`.
pub(crate) fn sql_error(path: &Path) -> impl Fn(rusqlite::Error) -> LogbookError + '_ {
    move |source| LogbookError::Sqlite {
        path: path.to_path_buf(),
        source,
    }
}

/// What is at the logbook's path: `Ok(false)` nothing (the file is to be made), `Ok(true)` a
/// regular file (or a link to one).
///
/// # Errors
/// A link to nothing, something that is not a regular file, a path that cannot be looked at.
pub(crate) fn existing(path: &Path) -> Result<bool> {
    let io = |source| LogbookError::Io {
        path: path.to_path_buf(),
        source,
    };
    match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
        Err(e) => return Err(io(e)),
        Ok(_) => {}
    }
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => Ok(true),
        Ok(_) => Err(LogbookError::NotAFile {
            path: path.to_path_buf(),
        }),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(LogbookError::DanglingLink {
            path: path.to_path_buf(),
            target: std::fs::read_link(path).unwrap_or_default(),
        }),
        Err(e) => Err(io(e)),
    }
}

/// Open `path` to write: read-write, and when `create`, made without following a link at the
/// path (a link planted between the look and the open is refused by SQLite).
pub(crate) fn open_to_write(path: &Path, create: bool) -> Result<Connection> {
    let mut flags = OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX;
    if create {
        flags |= OpenFlags::SQLITE_OPEN_CREATE | OpenFlags::SQLITE_OPEN_NOFOLLOW;
    }
    let conn = Connection::open_with_flags(path, flags).map_err(sql_error(path))?;
    if conn
        .is_readonly(rusqlite::MAIN_DB)
        .map_err(sql_error(path))?
    {
        return Err(LogbookError::ReadOnly {
            path: path.to_path_buf(),
        });
    }
    Ok(conn)
}

/// Open `path` read-only and say whose it is: `mode=ro`, else (SQLite can neither open nor make
/// the WAL's `-shm`) `immutable=1`.
pub(crate) fn open_to_read(path: &Path) -> Result<(Connection, Identity)> {
    let flags = OpenFlags::SQLITE_OPEN_READ_ONLY
        | OpenFlags::SQLITE_OPEN_URI
        | OpenFlags::SQLITE_OPEN_NO_MUTEX;
    let open = |query: &str| -> rusqlite::Result<(Connection, Identity)> {
        let conn = Connection::open_with_flags(format!("{}?{query}", uri(path)), flags)?;
        conn.busy_timeout(BUSY_TIMEOUT)?;
        let identity = identify(&conn)?;
        Ok((conn, identity))
    };
    match open("mode=ro") {
        Err(rusqlite::Error::SqliteFailure(e, _))
            if matches!(
                e.code,
                rusqlite::ErrorCode::CannotOpen | rusqlite::ErrorCode::ReadOnly
            ) =>
        {
            open("mode=ro&immutable=1").map_err(sql_error(path))
        }
        other => other.map_err(sql_error(path)),
    }
}

/// `path` as a SQLite `file:` URI: every byte but the unreserved ones and `/` percent-encoded
/// (a `?` or `#` in a file name is the name's, not the URI's).
fn uri(path: &Path) -> String {
    let absolute: PathBuf = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = String::from("file:");
    for &b in absolute.as_os_str().as_encoded_bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            out.push(char::from(b));
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mark_is_alft() {
        assert_eq!(APPLICATION_ID, 0x616C_6674);
    }

    #[test]
    fn uri_escapes_what_a_uri_would_read() {
        assert_eq!(
            uri(Path::new("/a b/c?d#e%.sqlite")),
            "file:/a%20b/c%3Fd%23e%25.sqlite"
        );
    }
}
