//! What `aloft fit` and `aloft validate` share in their tables.

use std::path::Path;

/// The file name of a path, for tables.
pub fn file_name(p: &str) -> &str {
    Path::new(p)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or(p)
}
