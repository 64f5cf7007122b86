//! The files a request names: the one place where the engine opens an input by path, and the
//! engine's door to aloft's one way of writing a file.
//!
//! Inputs are regular files only: a FIFO, a device or a directory is refused before it is opened
//! (it could block or never end). Whole-file inputs (vehicle, mission, rotor files, wind fields)
//! are read only up to [`MAX_INPUT_BYTES`]; logs and CSV batches are streamed and have no limit.
//!
//! Outputs are written by [`aloft_core::output`] only ([`write_output`], [`Output`],
//! [`OutputSet`]): an exclusive temporary file with a random name beside the target, then a
//! rename; an existing output kept unless `force`, which replaces a regular file or a link
//! itself, never a link's target, a device or a FIFO; a set of files all or nothing; names taken
//! from an input's file name only ([`safe_stem`]); [`abandon_outputs`] for a program's signal
//! handler.

use std::fs::File;
use std::path::Path;

pub use aloft_core::output::{
    escaped, safe_stem, shown as shown_path, Output, OutputError, OutputSet,
};

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

/// Write `bytes` to the file `path` in aloft's one way ([`aloft_core::output`]): nothing
/// replaced unless `force` (a regular file or a link itself, never a device, a FIFO or a
/// folder), never half-written.
///
/// # Errors
/// [`Error::Output`]: the file exists (without `force`), something aloft never replaces is there,
/// its folder is missing, the write failed, or the program was interrupted.
pub fn write_output(path: &Path, bytes: &[u8], force: bool) -> Result<(), Error> {
    Ok(aloft_core::output::write_file(path, bytes, force)?)
}

/// Check, before long work, that `path` could be written ([`aloft_core::output::check`]): its
/// folder exists, and nothing is there (or, with `force`, a regular file or a link).
///
/// # Errors
/// [`Error::Output`] saying why not.
pub fn check_output(path: &Path, force: bool) -> Result<(), Error> {
    Ok(aloft_core::output::check(path, force)?)
}

/// Remove the temporary files of every output this process is writing and refuse to place any
/// from now on (a set being placed is finished first); the number removed. For the SIGINT and
/// SIGTERM handler of a program that exits right after.
pub fn abandon_outputs() -> usize {
    aloft_core::output::abandon_all()
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
