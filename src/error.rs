//! The facade's typed error.

use thiserror::Error;

/// Errors of the `aloft` facade: a model error, or a vehicle description that cannot be used.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// The power model rejected a parameter or a flight state.
    #[error(transparent)]
    Power(#[from] aloft_power::PowerError),
    /// The propulsion chain rejected a parameter or an operating point.
    #[error(transparent)]
    Propulsion(#[from] aloft_propulsion::PropulsionError),
    /// A vehicle name that is not built in.
    #[error("unknown vehicle '{name}': built-in vehicles are {known}")]
    UnknownVehicle {
        /// The name asked for.
        name: String,
        /// The built-in names, comma-separated.
        known: String,
    },
    /// A vehicle file that is not valid TOML or does not match the format.
    #[error("invalid vehicle description {origin}: {message}")]
    VehicleFormat {
        /// Where the text came from (file path or built-in name).
        origin: String,
        /// The parser's message (line, column and key).
        message: String,
    },
    /// A CSV input lacks a required column.
    #[error("{origin}: missing column '{column}' (found: {found})")]
    ColumnMissing {
        /// The column asked for.
        column: &'static str,
        /// File or stream name.
        origin: String,
        /// The header that was found, comma-separated.
        found: String,
    },
    /// A field that must be a number is not.
    #[error("{origin}: row {row}: {column} = '{value}' is not a number")]
    BadValue {
        /// File or stream name.
        origin: String,
        /// 1-based data row (the header is row 0).
        row: usize,
        /// Column name.
        column: &'static str,
        /// The text found.
        value: String,
    },
    /// A row whose values the model rejects.
    #[error("{origin}: row {row}: {source}")]
    BadRow {
        /// File or stream name.
        origin: String,
        /// 1-based data row.
        row: usize,
        /// The model's error.
        source: aloft_power::PowerError,
    },
    /// Malformed CSV (unequal field counts, invalid UTF-8, ...).
    #[error("{origin}: row {row}: {message}")]
    Csv {
        /// File or stream name.
        origin: String,
        /// 1-based data row (0: the header).
        row: usize,
        /// The CSV parser's message.
        message: String,
    },
    /// Reading or writing failed.
    #[error("{origin}: {source}")]
    Io {
        /// File or stream name.
        origin: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The vehicle has no table for the model that was asked for.
    #[error("vehicle '{vehicle}' has no [{table}] table, which {needed_for} needs")]
    MissingTable {
        /// Vehicle name.
        vehicle: String,
        /// The missing table.
        table: &'static str,
        /// What needs it.
        needed_for: &'static str,
    },
}
