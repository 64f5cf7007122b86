//! The logbook's errors: each names the file or value at fault.

use std::path::PathBuf;

/// A logbook that cannot be opened, read or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LogbookError {
    /// The folder the database file is to be in does not exist (it is not created: a typo in
    /// `--db` should not leave a new folder behind).
    #[error("{}: the folder of the logbook does not exist", folder.display())]
    FolderMissing {
        /// The missing folder.
        folder: PathBuf,
    },
    /// SQLite failed on the database file.
    #[error("{}: {source}", path.display())]
    Sqlite {
        /// The database file.
        path: PathBuf,
        /// What SQLite said.
        #[source]
        source: rusqlite::Error,
    },
    /// The database was written by a newer aloft (its schema version is above this one's).
    #[error("{}: schema version {found} is newer than this aloft's {supported}: use a newer aloft", path.display())]
    SchemaTooNew {
        /// The database file.
        path: PathBuf,
        /// Its `PRAGMA user_version`.
        found: i64,
        /// The newest version this code writes.
        supported: i64,
    },
    /// A SQLite file of another program (without aloft's mark, not of aloft's tables): refused,
    /// nothing in it changed.
    #[error(
        "{}: not an aloft logbook: a SQLite file of another program (application_id {application_id}, \
         not aloft's {}; tables: {}); nothing in it was changed",
        path.display(),
        crate::APPLICATION_ID,
        table_list(tables)
    )]
    NotALogbook {
        /// The file.
        path: PathBuf,
        /// Its `PRAGMA application_id`.
        application_id: i32,
        /// Its tables.
        tables: Vec<String>,
    },
    /// SQLite's `quick_check` finds the logbook damaged: nothing is written to it.
    #[error(
        "{}: the logbook is damaged (SQLite quick_check: {problem}); nothing was added: \
         `aloft logbook flights` lists what can still be read; add to a copy restored from a backup",
        path.display()
    )]
    Damaged {
        /// The file.
        path: PathBuf,
        /// The first problem `quick_check` reports.
        problem: String,
    },
    /// A link to a file that does not exist at the logbook's path: no logbook is made through it.
    #[error(
        "{}: a link to {}, which does not exist: no logbook is made through a link",
        path.display(),
        target.display()
    )]
    DanglingLink {
        /// The link.
        path: PathBuf,
        /// Where it points.
        target: PathBuf,
    },
    /// Something other than a regular file at the logbook's path (a folder, a FIFO, a device).
    #[error("{}: not a regular file: not a logbook", path.display())]
    NotAFile {
        /// The path.
        path: PathBuf,
    },
    /// Listing a logbook that does not exist (listing makes no file).
    #[error("{}: no logbook there (`aloft logbook add` makes one)", path.display())]
    NoLogbook {
        /// The path.
        path: PathBuf,
    },
    /// Adding to a logbook the user may not write.
    #[error(
        "{}: the logbook cannot be written (a read-only file or folder): it can be listed, not added to",
        path.display()
    )]
    ReadOnly {
        /// The file.
        path: PathBuf,
    },
    /// Listing a logbook of an older schema that cannot be written to bring it up to date.
    #[error(
        "{}: schema version {found} is older than this aloft's {supported}, and the file cannot \
         be written to bring it up to date: list a copy in a folder you may write",
        path.display()
    )]
    CannotMigrate {
        /// The file.
        path: PathBuf,
        /// Its `PRAGMA user_version`.
        found: i64,
        /// The version this code reads.
        supported: i64,
    },
    /// No vehicle or pack of that key in the logbook.
    #[error(
        "{}: no {kind} {key:?} in the logbook (`aloft logbook {kind}s` lists them)",
        path.display()
    )]
    NoSuchKey {
        /// The file.
        path: PathBuf,
        /// Vehicle or pack.
        kind: crate::KeyKind,
        /// The key asked for.
        key: String,
    },
    /// A vehicle or pack of that key is already in the logbook.
    #[error(
        "{}: a {kind} {key:?} is already in the logbook: give a name not taken",
        path.display()
    )]
    KeyTaken {
        /// The file.
        path: PathBuf,
        /// Vehicle or pack.
        kind: crate::KeyKind,
        /// The key taken.
        key: String,
    },
    /// A label that cannot be a key.
    #[error("{label:?} is not a label: {reason}")]
    BadLabel {
        /// The label given.
        label: String,
        /// What a label must be.
        reason: &'static str,
    },
    /// The logbook's path cannot be looked at.
    #[error("{}: {source}", path.display())]
    Io {
        /// The path.
        path: PathBuf,
        /// What the system said.
        #[source]
        source: std::io::Error,
    },
}

/// The first tables of a file, for a message.
fn table_list(tables: &[String]) -> String {
    // Another program's names: control characters would break the message's one line.
    let clean = |t: &String| -> String {
        t.chars()
            .take(40)
            .map(|c| if c.is_control() { '?' } else { c })
            .collect()
    };
    let shown: Vec<String> = tables.iter().take(5).map(clean).collect();
    match tables.len() {
        0 => "none".to_string(),
        n if n <= 5 => shown.join(", "),
        n => format!("{}, and {} more", shown.join(", "), n - 5),
    }
}

/// The result of a logbook operation.
pub type Result<T> = std::result::Result<T, LogbookError>;
