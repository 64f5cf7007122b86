//! # aloft-core: what every aloft crate shares
//!
//! One home for the constants and the numerics the model crates, the log readers and the engine
//! all use, so each is written once:
//!
//! - [`STANDARD_GRAVITY_MPS2`] and [`ISA_SEA_LEVEL_DENSITY_KG_M3`], the defaults of vehicle files
//!   and the unit `g` of log columns;
//! - [`Trapezoid`] and [`trapezoid`], the trapezoid rule for energies (power over time) and any
//!   other integral of sampled data, sample by sample or over slices;
//! - [`input`]: opening the files aloft reads, regular files only (a FIFO or a device is refused
//!   before it is opened, so it cannot block), with a size limit for whole-file inputs.
//!
//! The crate has no dependencies; its only I/O is the opening of input files in [`input`].

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod input;
pub mod integrate;

pub use input::{open_regular_file, read_regular_text};
pub use integrate::{trapezoid, Trapezoid};

/// Standard gravity `g0`, m/s^2 (CGPM 1901; ISO 80000-3). The default when a vehicle file does
/// not give its own, and the unit `g` of accelerations in logs.
pub const STANDARD_GRAVITY_MPS2: f64 = 9.806_65;

/// Air density of the ICAO standard atmosphere at sea level (15 C, 101 325 Pa), kg/m^3. The
/// default when a vehicle file does not give its own.
pub const ISA_SEA_LEVEL_DENSITY_KG_M3: f64 = 1.225;

/// Seconds per hour: joules to watt-hours, ampere-seconds to ampere-hours.
pub const SECONDS_PER_HOUR: f64 = 3600.0;

/// A number as an error message shows it: as written for ordinary magnitudes, in scientific
/// notation when it is huge or tiny (`1e308`, not 309 digits), `NaN` and `inf` as such.
///
/// ```
/// use aloft_core::Num;
/// assert_eq!(Num(150.0).to_string(), "150");
/// assert_eq!(Num(1e308).to_string(), "1e308");
/// assert_eq!(Num(1e-320).to_string(), "1e-320");
/// assert_eq!(Num(-0.25).to_string(), "-0.25");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl Num {
    /// The display of `*value` (for error attributes that hold a reference to the field).
    pub fn of(value: &f64) -> Self {
        Self(*value)
    }
}

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if self.0.is_finite() && a != 0.0 && !(1e-4..1e15).contains(&a) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// A parser's message on one line: TOML errors come with a snippet of the file (a line number
/// gutter, the line, a caret under the spot) between their first line and the explanation; the
/// snippet is dropped and the rest joined with `: `, so a message names the line, the column and
/// the problem in one line (`TOML parse error at line 3, column 11: invalid type: string "a",
/// expected f64`).
///
/// Control characters left inside the line (a carriage return, a vertical tab or a form feed
/// that a message quotes from its input: a column name, a key, a topic) are written as escapes
/// (`\r`, `\u{b}`), as are the Unicode line and paragraph separators, so that the message stays
/// one line on a terminal and for any reader that splits lines; a tab is kept.
///
/// ```
/// let text = "TOML parse error at line 2, column 8\n  |\n2 | kind = 1\n  |        ^\ninvalid type";
/// assert_eq!(aloft_core::one_line(text), "TOML parse error at line 2, column 8: invalid type");
/// assert_eq!(aloft_core::one_line("column 'a\rb\u{b}c'"), "column 'a\\rb\\u{b}c'");
/// ```
pub fn one_line(message: &str) -> String {
    let snippet = |l: &str| {
        let t = l.trim_start();
        let gutter = t.trim_start_matches(|c: char| c.is_ascii_digit());
        gutter.trim_start().starts_with('|')
    };
    let joined = message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !snippet(l))
        .collect::<Vec<_>>()
        .join(": ");
    let escaped = |c: char| (c.is_control() && c != '\t') || matches!(c, '\u{2028}' | '\u{2029}');
    if !joined.chars().any(escaped) {
        return joined;
    }
    let mut out = String::with_capacity(joined.len() + 8);
    for c in joined.chars() {
        if escaped(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod one_line_tests {
    use super::one_line;

    /// Regression (found by aloft-fuzz): a carriage return, vertical tab or form feed quoted
    /// from the input (a CSV header, an unknown TOML or JSON key, an MCAP topic) was printed as
    /// is, so the one-line error of the CLI broke into several lines on a terminal.
    #[test]
    fn quoted_control_characters_do_not_break_the_line() {
        let m = one_line("missing column (found: a\u{b}b,c\rd)\nunknown field `pro\u{c}ile`");
        assert_eq!(
            m,
            "missing column (found: a\\u{b}b,c\\rd): unknown field `pro\\u{c}ile`"
        );
        assert!(!m.chars().any(char::is_control));
        assert_eq!(one_line("x\u{2028}y\u{85}z\0"), "x\\u{2028}y\\u{85}z\\u{0}");
        // Tabs and ordinary text are kept.
        assert_eq!(one_line("a\tb: c"), "a\tb: c");
    }
}
