//! Reading the files a request names: the one place where the engine opens an input by path.

use std::path::Path;

use crate::error::Error;

/// The text of the file at `path`; `what` says what it is in the error ("mission file",
/// "vehicle file", ...).
///
/// # Errors
/// [`Error::Io`] naming the file when it cannot be read (missing, not UTF-8, ...).
pub fn read_text_file(path: &Path, what: &str) -> Result<String, Error> {
    std::fs::read_to_string(path).map_err(|source| Error::Io {
        origin: format!("cannot read {what} {}", path.display()),
        source,
    })
}
