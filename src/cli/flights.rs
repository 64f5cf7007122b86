//! What `aloft fit`, `aloft validate` and `aloft pack fit` share in their tables.

use std::borrow::Cow;
use std::path::Path;

use aloft::engine::{FitQuality, SkippedLog};

/// A verdict as the tables print it.
pub fn quality_word(q: FitQuality) -> &'static str {
    match q {
        FitQuality::Good => "good",
        FitQuality::Usable => "usable",
        FitQuality::Poor => "poor",
    }
}

/// The file name of a path, for tables: control characters escaped ([`escaped`]), so that a
/// name holding a newline stays in its row.
pub fn file_name(p: &str) -> Cow<'_, str> {
    escaped(
        Path::new(p)
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or(p),
    )
}

/// The verdict of a fit or a validation, its reasons, and the logs left out with theirs (the
/// table's last lines of `aloft fit` and `aloft validate`).
pub fn write_verdict(
    out: &mut impl std::io::Write,
    quality: FitQuality,
    reasons: &[String],
    skipped: &[SkippedLog],
) -> std::io::Result<()> {
    writeln!(out, "\nQuality: {}", quality_word(quality))?;
    for reason in reasons {
        writeln!(out, "  {}", escaped(reason))?;
    }
    for s in skipped {
        writeln!(
            out,
            "Skipped {}: {}",
            file_name(&s.file),
            escaped(&s.reason)
        )?;
    }
    Ok(())
}

/// `text` with its control characters and bidirectional overrides escaped (aloft's one rule:
/// [`aloft::engine::escaped`]).
pub use aloft::engine::escaped;

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 41: a newline or an escape sequence in a name is shown escaped; a plain name and
    /// one with accents are borrowed as they are.
    #[test]
    fn control_characters_are_escaped_and_the_rest_kept() {
        assert_eq!(
            file_name("/a/two\nlines\u{1b}[31m.ulg"),
            r"two\nlines\u{1b}[31m.ulg"
        );
        assert_eq!(escaped("x\u{202e}gpj.ulg"), r"x\u{202e}gpj.ulg");
        assert!(matches!(
            file_name("/a/Flug_Übung.ulg"),
            Cow::Borrowed("Flug_Übung.ulg")
        ));
    }
}
