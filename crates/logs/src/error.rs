//! The crate's typed error: every variant names the file, row, column, topic or channel at fault.

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::mcap_records::{McapPlace, McapProblem};

/// Errors of `aloft-logs`. Each carries the offending file and, where known, row, column, channel
/// or topic and value, so a user can find the problem without a debugger.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum LogError {
    /// The file could not be opened or read.
    #[error("cannot read {path}: {cause}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        cause: std::io::Error,
    },
    /// An output file that aloft's one writer refused or could not place (it exists, a link or
    /// a FIFO is there, its folder is missing).
    #[error(transparent)]
    Output(#[from] aloft_core::output::OutputError),
    /// The file could not be created or written.
    #[error("cannot write {path}: {cause}")]
    WriteIo {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        cause: std::io::Error,
    },
    /// The log holds no data rows or messages.
    #[error("{path}: the log is empty ({what})")]
    Empty {
        /// The file.
        path: PathBuf,
        /// What was missing (e.g. "no data rows", "no decodable messages").
        what: String,
    },
    /// A column named by the column map is not in the CSV header.
    #[error(
        "{path}: column '{column}' for {channel} is missing from the header (none of its {columns} columns is named so)"
    )]
    ColumnMissing {
        /// The file.
        path: PathBuf,
        /// The column the map asked for.
        column: String,
        /// The channel the column was to feed (e.g. "voltage").
        channel: &'static str,
        /// How many columns the header has (their names are the file's text, not quoted: the
        /// file may be anything the caller could name).
        columns: usize,
    },
    /// A CSV row could not be read (bad quoting, wrong number of fields, invalid UTF-8).
    #[error("{path}: row {row}: malformed CSV: {message}")]
    CsvRow {
        /// The file.
        path: PathBuf,
        /// The 1-based line number in the file (the header is line 1).
        row: u64,
        /// The CSV parser's message.
        message: String,
    },
    /// A field is not a number.
    #[error("{path}: row {row}, column '{column}': '{text}' is not a number")]
    ParseValue {
        /// The file.
        path: PathBuf,
        /// The 1-based line number (header is line 1).
        row: u64,
        /// The column.
        column: String,
        /// The text found.
        text: String,
    },
    /// A value outside the physically plausible range for its declared unit: usually a wrong unit
    /// in the column map (mV declared as V, degrees declared as radians, ms declared as s).
    #[error("{path}: row {row}, channel {channel}: {value} {unit} is implausible (expected {expected}); check the unit in the column map")]
    Implausible {
        /// The file.
        path: PathBuf,
        /// The 1-based line number, or message index for MCAP.
        row: u64,
        /// The channel.
        channel: &'static str,
        /// The value after conversion to SI.
        value: f64,
        /// The SI unit of `value`.
        unit: &'static str,
        /// The accepted range, in words.
        expected: &'static str,
    },
    /// A column-map file that is not valid TOML or does not match the format.
    #[error("invalid column map {path}: {message}")]
    MapFile {
        /// The map file (or built-in profile name).
        path: PathBuf,
        /// The parser's message, with the key at fault.
        message: String,
    },
    /// A profile name that is neither built in nor an existing map file.
    #[error(
        "unknown profile '{name}': built-in profiles are {known}, or give a column-map TOML file"
    )]
    UnknownProfile {
        /// The name asked for.
        name: String,
        /// The built-in names, comma-separated.
        known: String,
    },
    /// A CSV header that names the same column twice: which one a map means is ambiguous.
    #[error("{path}: column '{column}' appears twice in the header (columns {first} and {second}); rename one of them")]
    DuplicateColumn {
        /// The file.
        path: PathBuf,
        /// The column name.
        column: String,
        /// 1-based position of its first occurrence.
        first: usize,
        /// 1-based position of the second.
        second: usize,
    },
    /// A CSV line longer than aloft reads (a file that is not a table of rows, or has no line
    /// breaks): refused so that memory does not grow with it.
    #[error("{path}: line {line} is longer than {limit_bytes} bytes; this is not a CSV log aloft can read")]
    LineTooLong {
        /// The file.
        path: PathBuf,
        /// The 1-based line (the header is line 1).
        line: u64,
        /// The longest line accepted, bytes.
        limit_bytes: usize,
    },
    /// A PX4 per-topic table needed for the join is missing.
    #[error("PX4 log {prefix}: topic table {expected} is missing")]
    Px4TopicMissing {
        /// The common prefix of the log's tables.
        prefix: PathBuf,
        /// The file that was looked for.
        expected: PathBuf,
    },
    /// A file whose format could not be recognised.
    #[error("{path}: unsupported log format ({reason})")]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The MCAP container is truncated or corrupt (as found by the `mcap` crate's reader).
    #[error("{path}: corrupt or truncated MCAP at {place}, after {messages} messages: {cause}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// Where the record being read starts.
        place: McapPlace,
        /// Messages read successfully before the error.
        messages: u64,
        /// The `mcap` crate's error.
        cause: mcap::McapError,
    },
    /// An MCAP record or chunk whose lengths contradict its size (a corrupt file), refused before
    /// anything is allocated for it.
    #[error("{path}: corrupt MCAP: the {record} record at {place} (after {messages} messages) is invalid: {problem}")]
    McapCorrupt {
        /// The file.
        path: PathBuf,
        /// The record type (`Channel`, `Chunk`, ...).
        record: &'static str,
        /// Where the record starts.
        place: McapPlace,
        /// Messages read successfully before the error.
        messages: u64,
        /// What is wrong.
        problem: McapProblem,
    },
    /// A ROS 2 CDR message that does not decode as its declared type.
    #[error("{path}: topic {topic}, message {index} ({schema}): {cause}")]
    Cdr {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The 0-based index of the message on its topic.
        index: u64,
        /// The message type.
        schema: String,
        /// What went wrong.
        cause: crate::cdr::CdrError,
    },
    /// A JSON message that does not parse or lacks a field its schema promises.
    #[error("{path}: topic {topic}, message {index}: {message}")]
    JsonMessage {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The 0-based index of the message on its topic.
        index: u64,
        /// What went wrong (parser message or missing field).
        message: String,
    },
    /// A topic the user named is not in the file.
    #[error("{path}: topic '{topic}' not found (topics: {available})")]
    TopicNotFound {
        /// The file.
        path: PathBuf,
        /// The topic asked for.
        topic: String,
        /// The topics present, comma-separated.
        available: String,
    },
    /// A topic the user named has a type aloft cannot decode.
    #[error("{path}: topic '{topic}' has type '{schema}' ({encoding}), which aloft cannot decode; supported: {supported}")]
    UnsupportedTopic {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Its schema name.
        schema: String,
        /// Its message encoding.
        encoding: String,
        /// The supported types.
        supported: &'static str,
    },
    /// Power was asked for but the log has no voltage and current (or power) channel.
    #[error("{source_name}: no power data: the log has no battery voltage and current (channels found: {found})")]
    NoPowerData {
        /// The file.
        source_name: String,
        /// What the log does hold.
        found: String,
    },
    /// A ULog or DataFlash log without battery data for the flight (no battery topic, a battery
    /// topic declared and never written, no valid record, or records covering a small part).
    #[error("{source_name}: {reason}")]
    NoBatteryData {
        /// The file.
        source_name: String,
        /// Why, in words (starts with "the log has no battery data").
        reason: String,
    },
    /// Motion was asked for but the log has no velocity, position or attitude channel.
    #[error("{source_name}: no {channel} data in the log (channels found: {found})")]
    NoChannel {
        /// The file.
        source_name: String,
        /// The channel asked for.
        channel: &'static str,
        /// What the log does hold.
        found: String,
    },
    /// An argument of a library call out of its valid range.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidArgument {
        /// The argument.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The valid range.
        reason: &'static str,
    },
    /// Writing an MCAP file failed.
    #[error("cannot write MCAP {path}: {cause}")]
    McapWrite {
        /// The file.
        path: PathBuf,
        /// The `mcap` crate's error.
        cause: mcap::McapError,
    },
    /// A value handed to the writer that cannot be written (NaN or infinite).
    #[error("cannot write {what} at sample {index}: value {value} is not finite")]
    NonFinite {
        /// The quantity.
        what: &'static str,
        /// The 0-based sample index.
        index: usize,
        /// The value.
        value: f64,
    },
}

impl LogError {
    /// The [`LogError::Io`] of reading `path`, for `map_err`.
    pub(crate) fn reading(path: &Path) -> impl FnOnce(std::io::Error) -> LogError + '_ {
        move |cause| LogError::Io {
            path: path.to_path_buf(),
            cause,
        }
    }
}

/// Result with a [`LogError`].
pub type Result<T, E = LogError> = std::result::Result<T, E>;
