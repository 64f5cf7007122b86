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
}

/// The result of a logbook operation.
pub type Result<T> = std::result::Result<T, LogbookError>;
