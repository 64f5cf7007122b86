//! Reading the files a request names: the one place where the engine opens an input by path.
//!
//! Inputs are regular files only: a FIFO, a device or a directory is refused before it is opened
//! (it could block or never end). Whole-file inputs (vehicle, mission, rotor files, wind fields)
//! are read only up to [`MAX_INPUT_BYTES`]; logs and CSV batches are streamed and have no limit.

use std::fs::File;
use std::path::Path;

use crate::error::Error;

/// The largest whole-file input aloft reads, bytes (32 MiB: a QGroundControl survey of thousands of
/// waypoints is well under 1 MiB).
pub const MAX_INPUT_BYTES: u64 = 32 << 20;

/// The text of the file at `path`; `what` says what it is in the error ("mission file",
/// "vehicle file", ...).
///
/// # Errors
/// [`Error::Io`] naming the file when it cannot be read: missing, not a regular file, larger than
/// [`MAX_INPUT_BYTES`], not UTF-8.
pub fn read_text_file(path: &Path, what: &str) -> Result<String, Error> {
    aloft_core::read_regular_text(path, MAX_INPUT_BYTES).map_err(|source| Error::Io {
        origin: format!("cannot read {what} {}", path.display()),
        source,
    })
}

/// Open the regular file at `path` for streaming; `what` says what it is in the error.
///
/// # Errors
/// [`Error::Io`] naming the file when it is missing, not a regular file or cannot be opened.
pub fn open_input_file(path: &Path, what: &str) -> Result<File, Error> {
    aloft_core::open_regular_file(path).map_err(|source| Error::Io {
        origin: format!("cannot open {what} {}", path.display()),
        source,
    })
}

/// A CSV header must name each column once: a repeated name would leave the reader to pick one
/// of two columns silently.
///
/// # Errors
/// [`Error::DuplicateColumn`] naming the first repeated column.
pub fn check_csv_header(headers: &csv::StringRecord, origin: &str) -> Result<(), Error> {
    for (k, name) in headers.iter().enumerate() {
        if headers.iter().take(k).any(|h| h == name) {
            return Err(Error::DuplicateColumn {
                column: name.to_string(),
                origin: origin.to_string(),
            });
        }
    }
    Ok(())
}
