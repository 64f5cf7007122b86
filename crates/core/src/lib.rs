//! # aloft-core: what every aloft crate shares
//!
//! One home for the constants and the numerics the model crates, the log readers and the engine
//! all use, so each is written once:
//!
//! - [`STANDARD_GRAVITY_MPS2`] and [`ISA_SEA_LEVEL_DENSITY_KG_M3`], the defaults of vehicle files
//!   and the unit `g` of log columns;
//! - [`Trapezoid`] and [`trapezoid`], the trapezoid rule for energies (power over time) and any
//!   other integral of sampled data, sample by sample or over slices;
//! - [`atmosphere`]: the International Standard Atmosphere and the density of a day's air
//!   (elevation, temperature, humidity, QNH);
//! - [`IndexLine`], the least-squares line through values one step apart (a trend over flights,
//!   a series' slow drift);
//! - [`bisect`], the bracketing of a crossing by halving;
//! - [`input`]: opening the files aloft reads, regular files only (a FIFO or a device is refused
//!   before it is opened, so it cannot block), with a size limit for whole-file inputs;
//! - [`output`]: the one way aloft writes a file (a name from the input's file name only, an
//!   exclusive temporary file beside the target, then a rename; nothing replaced without `force`,
//!   never a device or a FIFO; sets of files all or nothing; nothing left when interrupted).
//!
//! Its only I/O is the opening of input files in [`input`] and the writing of outputs in
//! [`output`]; its dependencies are `tempfile` (the exclusive temporary files) and `thiserror`.

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod atmosphere;
pub mod bisect;
pub mod input;
pub mod integrate;
pub mod line;
pub mod output;

pub use bisect::bisect;
pub use input::{open_regular_file, read_regular_text};
pub use integrate::{trapezoid, trapezoid_window, Trapezoid};
pub use line::IndexLine;

/// Standard gravity `g0`, m/s^2 (CGPM 1901; ISO 80000-3). The default when a vehicle file does
/// not give its own, and the unit `g` of accelerations in logs.
pub const STANDARD_GRAVITY_MPS2: f64 = 9.806_65;

/// Air density of the ICAO standard atmosphere at sea level (15 C, 101 325 Pa), kg/m^3. The
/// default when a vehicle file does not give its own.
pub const ISA_SEA_LEVEL_DENSITY_KG_M3: f64 = 1.225;

/// Seconds per hour: joules to watt-hours, ampere-seconds to ampere-hours.
pub const SECONDS_PER_HOUR: f64 = 3600.0;

/// The capacities a battery pack may have, mA h: from 10 mA h (below it a value is a unit slip
/// or an unset parameter, such as a logged `BAT1_CAPACITY` of 1e-38; the smallest flying packs
/// hold tens of mA h) to 1e7 mA h (10,000 A h: beyond it a unit slip, not a pack).
pub const BATTERY_CAPACITY_RANGE_MAH: (f64, f64) = (10.0, 1e7);

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

/// A number with `decimals` decimals as a message shows it (`{:.3}`), in scientific notation
/// when it is too large for that to be readable (`1.000e308`, not 309 digits and three zeros).
///
/// ```
/// use aloft_core::Fixed;
/// assert_eq!(Fixed(2.3554, 3).to_string(), "2.355");
/// assert_eq!(Fixed(1e308, 3).to_string(), "1.000e308");
/// assert_eq!(Fixed(-1e20, 1).to_string(), "-1.0e20");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fixed(pub f64, pub usize);

impl std::fmt::Display for Fixed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Self(value, decimals) = *self;
        if value.is_finite() && value.abs() >= 1e15 {
            write!(f, "{value:.decimals$e}")
        } else {
            write!(f, "{value:.decimals$}")
        }
    }
}

/// A unit after a number in a message: ` m/s`, or nothing for a number without one (so that
/// `start_soc = 1.5 is invalid` has one space).
///
/// ```
/// assert_eq!(format!("1{}", aloft_core::Unit("m/s")), "1 m/s");
/// assert_eq!(format!("1{}", aloft_core::Unit("")), "1");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit<'a>(pub &'a str);

impl std::fmt::Display for Unit<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            "" => Ok(()),
            u => write!(f, " {u}"),
        }
    }
}

/// A parameter outside its valid range, with its value, unit and what a valid value looks like:
/// the `InvalidParameter` of the model crates' errors (`PlannerError`, `PropulsionError`), which
/// wrap it.
///
/// ```
/// let e = aloft_core::parameter("rotor_radius_m", -0.2, "m", false, "a positive length");
/// assert_eq!(
///     e.unwrap_err().to_string(),
///     "rotor_radius_m = -0.2 m is invalid: expected a positive length"
/// );
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InvalidParameter {
    /// Parameter name, with its unit suffix.
    pub name: &'static str,
    /// The rejected value.
    pub value: f64,
    /// Unit of `value`.
    pub unit: &'static str,
    /// What a valid value looks like.
    pub expected: &'static str,
}

impl std::fmt::Display for InvalidParameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Self {
            name,
            value,
            unit,
            expected,
        } = *self;
        write!(
            f,
            "{name} = {}{} is invalid: expected {expected}",
            Num(value),
            Unit(unit)
        )
    }
}

impl std::error::Error for InvalidParameter {}

/// `value` when `ok`, else [`InvalidParameter`] saying what was `expected`.
///
/// # Errors
/// [`InvalidParameter`] when `ok` is false.
pub fn parameter(
    name: &'static str,
    value: f64,
    unit: &'static str,
    ok: bool,
    expected: &'static str,
) -> Result<f64, InvalidParameter> {
    if ok {
        Ok(value)
    } else {
        Err(InvalidParameter {
            name,
            value,
            unit,
            expected,
        })
    }
}

/// An error and its causes on one line, as the command line prints it: each cause through
/// [`one_line`], joined with `: `, a cause whose text is already there not repeated (errors often
/// say their cause in their own message).
///
/// ```
/// let e = std::io::Error::other("disk full");
/// assert_eq!(aloft_core::error_line(&e), "disk full");
/// ```
pub fn error_line(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = String::new();
    let mut cause = Some(e);
    while let Some(c) = cause {
        let line = one_line(&c.to_string());
        if text.is_empty() {
            text = line;
        } else if !text.contains(&line) {
            text.push_str(": ");
            text.push_str(&line);
        }
        cause = c.source();
    }
    text
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

/// The most values (separators and brackets: `,` `[` `{` `=` `:`) a TOML or JSON text that aloft
/// reads whole may hold: one million, which a 32 MiB QGroundControl plan of the usual shape (about
/// 3 % of its bytes) does not reach, nor a mission of the planner's 50,000 segments.
///
/// A parser holds a tree of the whole text before the file's own types see it (about 150 bytes a
/// value for TOML, 50 for JSON); a text of nothing but values (`x = [1,1,1,...]`) would take
/// gigabytes from a file of 32 MiB. Counted before parsing, the tree stays under about 150 MB.
pub const MAX_TEXT_VALUES: usize = 1_000_000;

/// `Err(count)` when `text` holds more than [`MAX_TEXT_VALUES`] values (counted as the bytes
/// `,` `[` `{` `=` `:`, inside strings too: an over-count only ever refuses a text of millions of
/// them).
///
/// ```
/// assert!(aloft_core::check_value_count("a = [1, 2, 3]").is_ok());
/// let many = format!("a = [{}1]", "1,".repeat(aloft_core::MAX_TEXT_VALUES));
/// assert!(aloft_core::check_value_count(&many).is_err());
/// ```
pub fn check_value_count(text: &str) -> Result<(), usize> {
    let count = text
        .bytes()
        .filter(|b| matches!(b, b',' | b'[' | b'{' | b'=' | b':'))
        .count();
    if count > MAX_TEXT_VALUES {
        Err(count)
    } else {
        Ok(())
    }
}

/// The message of a text refused by [`check_value_count`].
pub fn too_many_values(count: usize) -> String {
    format!(
        "{count} values (separators and brackets), more than the {MAX_TEXT_VALUES} aloft parses \
         from one file: not a mission, vehicle or map of any size aloft plans"
    )
}

/// A parser's message about a file (TOML, JSON), on one line ([`one_line`]) and without the
/// file's content: the text serde quotes from the input (an unknown key or variant, a string of the
/// wrong type or value, a duplicate key) is left out, the place (line and column) and what was
/// expected are kept.
///
/// A file named where a vehicle, a mission or a column map is expected may be any file the
/// process can read (a password file, a process's environment): what the message says of it must
/// not tell its content to whoever named it (a request to `aloft serve`, a script's caller).
///
/// ```
/// let m = "TOML parse error at line 1, column 1\n  |\n1 | TOKEN=1\n  | ^\nunknown field `TOKEN`, expected `name`";
/// assert_eq!(
///     aloft_core::file_message(m),
///     "TOML parse error at line 1, column 1: unknown field, expected `name`"
/// );
/// assert_eq!(
///     aloft_core::file_message("invalid type: string \"s3cr\\\"et\", expected f64 at line 2 column 9"),
///     "invalid type: string, expected f64 at line 2 column 9"
/// );
/// ```
pub fn file_message(message: &str) -> String {
    let mut text = with_nearest_key(&one_line(message));
    for (prefix, close) in [
        ("unknown field ", '`'),
        ("unknown variant ", '`'),
        ("duplicate key ", '`'),
        ("duplicate field ", '`'),
        ("invalid type: string ", '"'),
        ("invalid value: string ", '"'),
        ("invalid type: character ", '`'),
        ("invalid value: character ", '`'),
    ] {
        text = without_quoted(&text, prefix, close);
    }
    text
}

/// "unknown field `X`, expected one of `a`, `b`": the known key nearest `X` (by edit distance,
/// at most a third of the longer name's letters apart) named after "unknown field", so that the
/// message still helps once `X` is left out.
fn with_nearest_key(text: &str) -> String {
    let Some((head, rest)) = text.split_once("unknown field `") else {
        return text.to_string();
    };
    let Some((unknown, tail)) = rest.split_once('`') else {
        return text.to_string();
    };
    let known = tail.split('`').skip(1).step_by(2);
    let nearest = known
        .map(|k| (edit_distance(unknown, k), k))
        .filter(|(d, k)| 3 * d <= unknown.chars().count().max(k.chars().count()))
        .min_by_key(|(d, _)| *d);
    match nearest {
        Some((_, k)) => format!("{head}unknown field `{unknown}` (did you mean `{k}`?){tail}"),
        None => text.to_string(),
    }
}

/// Edit distance between two names, by characters: insertions, deletions, substitutions and
/// swaps of two neighbours (`nmae` is one from `name`).
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let width = b.len() + 1;
    let mut d: Vec<usize> = vec![0; (a.len() + 1) * width];
    for (i, row) in d.chunks_mut(width).enumerate() {
        row[0] = i;
    }
    for (j, cell) in d.iter_mut().take(width).enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[(i - 1) * width + j] + 1)
                .min(d[i * width + j - 1] + 1)
                .min(d[(i - 1) * width + j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[(i - 2) * width + j - 2] + 1);
            }
            d[i * width + j] = best;
        }
    }
    d[a.len() * width + b.len()]
}

/// `text` with every quotation that follows `prefix` (opened and closed by `close`, a backslash
/// escaping the next character) left out, the space before it with it.
fn without_quoted(text: &str, prefix: &str, close: char) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(prefix) {
        let after = &rest[at + prefix.len()..];
        out.push_str(&rest[..at]);
        out.push_str(prefix.trim_end());
        let Some(body) = after.strip_prefix(close) else {
            rest = after;
            out.push(' ');
            continue;
        };
        let mut escaped = false;
        let mut end = body.len();
        for (i, c) in body.char_indices() {
            match c {
                _ if escaped => escaped = false,
                '\\' => escaped = true,
                c if c == close => {
                    end = i + c.len_utf8();
                    break;
                }
                _ => {}
            }
        }
        rest = &body[end..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod one_line_tests {
    use super::{file_message, one_line};

    /// The content serde quotes is left out; the expected keys and the place stay.
    #[test]
    fn file_messages_quote_nothing_of_the_file() {
        for (raw, want) in [
            (
                "unknown field `SECRET`, expected one of `name`, `power`",
                "unknown field, expected one of `name`, `power`",
            ),
            (
                "unknown variant `SECRET`, expected `pass` or `stop`",
                "unknown variant, expected `pass` or `stop`",
            ),
            (
                "invalid type: string \"SECRET\", expected f64",
                "invalid type: string, expected f64",
            ),
            (
                "invalid value: string \"a\\\"SECRET\", expected x",
                "invalid value: string, expected x",
            ),
            ("duplicate key `SECRET` in table", "duplicate key in table"),
            // Cut short: nothing after the opening quote survives.
            ("unknown field `SECRET", "unknown field"),
            ("missing field `mass_kg`", "missing field `mass_kg`"),
            // The nearest known key is named in its place.
            (
                "unknown field `mass_lb`, expected one of `name`, `mass_kg`",
                "unknown field (did you mean `mass_kg`?), expected one of `name`, `mass_kg`",
            ),
        ] {
            assert_eq!(file_message(raw), want);
        }
    }

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
