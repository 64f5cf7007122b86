//! What `aloft fit`, `aloft validate` and `aloft pack fit` share in their tables.

use std::borrow::Cow;
use std::path::Path;

use aloft::engine::FitQuality;

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

/// `text` with its control characters (a newline, an escape sequence) and the bidirectional
/// overrides (U+202A-U+202E, U+2066-U+2069, which reorder what follows them on a terminal)
/// written as Rust escapes (`\n`, `\u{1b}`), the rest as it is: a message or a table row
/// that quotes a file name or a reason stays one line and shows what is there.
pub fn escaped(text: &str) -> Cow<'_, str> {
    let hidden = |c: char| {
        c.is_control()
            || ('\u{202a}'..='\u{202e}').contains(&c)
            || ('\u{2066}'..='\u{2069}').contains(&c)
    };
    if !text.chars().any(hidden) {
        return Cow::Borrowed(text);
    }
    Cow::Owned(
        text.chars()
            .map(|c| match c {
                c if hidden(c) => c.escape_default().to_string(),
                c => c.to_string(),
            })
            .collect(),
    )
}

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
