//! The errors of the pack analysis.

/// Why an analysis, or one of its estimates, cannot be made. The capacity variants are the
/// reasons a capacity is refused, in words.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PackError {
    /// Fewer than two battery records.
    #[error("{source_name}: {records} battery record(s): at least 2 are needed")]
    TooFewRecords {
        /// The log.
        source_name: String,
        /// Records it has.
        records: usize,
    },
    /// No record measures the current.
    #[error("no current is logged (voltage only): nothing to count or step on")]
    NoCurrent,
    /// The number of cells in series is unknown, so no rested voltage reads as a state of charge.
    #[error("the number of cells in series is unknown: a rested voltage cannot be read on the per-cell OCV curve")]
    CellsUnknown,
    /// The log does not start with a rest: its first record draws the rest limit or more.
    #[error("no rest before the flight: the current is {current_a:.2} A at the first record, above the rest limit of {limit_a:.2} A (a rest must hold {hold_s:.0} s before the discharge)")]
    NoRestBefore {
        /// The current at the first record, A.
        current_a: f64,
        /// The rest limit, A.
        limit_a: f64,
        /// How long a rest must hold, s.
        hold_s: f64,
    },
    /// The log starts at rest, but the rest ends before it has held long enough.
    #[error("no rest before the flight: the current is below the rest limit of {limit_a:.2} A for only {rested_s:.1} s from the first record (a rest must hold {hold_s:.0} s)")]
    RestBeforeTooShort {
        /// From the first record to the first one above the limit, s.
        rested_s: f64,
        /// The rest limit, A.
        limit_a: f64,
        /// How long a rest must hold, s.
        hold_s: f64,
    },
    /// The current never reaches the rest limit: no discharge to measure; the state of charge
    /// the pack rests at, read on the typical LiPo curve.
    #[error("the pack was never loaded (the current stays below the rest limit of {limit_a:.2} A): no discharge to measure a capacity; it rests at {voltage_v:.2} V ({cell_v:.3} V a cell), state of charge {soc:.2} on the typical LiPo curve")]
    NeverLoaded {
        /// The rest limit, A.
        limit_a: f64,
        /// The pack's last (most relaxed) voltage, V.
        voltage_v: f64,
        /// That voltage per cell, V.
        cell_v: f64,
        /// The state of charge it reads, 0-1.
        soc: f64,
    },
    /// The current never reaches the rest limit, and the cells are unknown.
    #[error("the pack was never loaded (the current stays below the rest limit of {limit_a:.2} A): no discharge to measure a capacity")]
    NeverLoadedCellsUnknown {
        /// The rest limit, A.
        limit_a: f64,
    },
    /// The log does not end with a rest.
    #[error("no rest after the flight: the log ends {tail_s:.1} s after the last current above the rest limit of {limit_a:.2} A (a rest must hold {hold_s:.0} s)")]
    NoRestAfter {
        /// Time from the last loaded record to the end of the log, s.
        tail_s: f64,
        /// The rest limit, A.
        limit_a: f64,
        /// How long a rest must hold, s.
        hold_s: f64,
    },
    /// The state of charge fell too little between the rests for a capacity.
    #[error("the state of charge fell only {drop:.3} between the rests ({soc_before:.3} to {soc_after:.3}); at least {min_drop:.2} is needed for a capacity")]
    SocDropTooSmall {
        /// State of charge at the rest before, 0-1.
        soc_before: f64,
        /// State of charge at the rest after, 0-1.
        soc_after: f64,
        /// The drop, 0-1.
        drop: f64,
        /// The smallest drop used, 0-1.
        min_drop: f64,
    },
    /// A value out of its range (a circuit's, a filter's start).
    #[error("{name} = {value} {unit} is invalid: {expected}")]
    InvalidValue {
        /// The value's name.
        name: &'static str,
        /// The value.
        value: f64,
        /// Its unit.
        unit: &'static str,
        /// What it should be.
        expected: &'static str,
    },
    /// An autopilot parameter (or a threshold given for one) that is not a number, or lies
    /// outside what the autopilot accepts.
    #[error("parameter {name} = {value} is invalid: expected {expected}")]
    InvalidParameter {
        /// The parameter (`BAT1_CAPACITY`, `BATT_LOW_VOLT`) or the flag (`--low-voltage-v`).
        name: String,
        /// Its value, in the parameter's own unit.
        value: f64,
        /// What it may be, in words with the unit.
        expected: &'static str,
    },
    /// The empty cell voltage is not below the full one, so no voltage reads as a state of charge.
    #[error("parameter {empty_name} = {empty_v} V is not below {charged_name} = {charged_v} V: the empty cell voltage must be below the full one")]
    EmptyNotBelowCharged {
        /// The empty voltage's parameter (`BAT1_V_EMPTY`).
        empty_name: String,
        /// Its value, V a cell.
        empty_v: f64,
        /// The full voltage's parameter (`BAT1_V_CHARGED`).
        charged_name: String,
        /// Its value, V a cell.
        charged_v: f64,
    },
    /// The records' state of charge is unknown: no gauge and no rested start.
    #[error("the state of charge of the records is unknown: the log has no pack gauge (remaining mA h) and does not start with a rest of {rest_hold_s:.0} s, so no open-circuit curve is fitted")]
    OcvChargeUnknown {
        /// How long a rest must hold, s.
        rest_hold_s: f64,
    },
    /// The pack's gauge reads more than the capacity the curve is fitted on.
    #[error("the pack's gauge reads {gauge_mah:.0} mA h at the start, more than the capacity of {capacity_mah:.0} mA h: give the pack's full capacity (--capacity-mah)")]
    OcvGaugeAboveCapacity {
        /// The charge the gauge says the pack held at the first record, mA h.
        gauge_mah: f64,
        /// The capacity, mA h.
        capacity_mah: f64,
    },
    /// Too few bins of state of charge hold enough records for an open-circuit curve.
    #[error("only {bins} bin(s) of {bin_soc} state of charge hold {min_records} records or more; at least {min_bins} are needed for an open-circuit curve")]
    OcvTooFewRecords {
        /// Bins with enough records.
        bins: usize,
        /// Bins needed.
        min_bins: usize,
        /// Records a bin needs.
        min_records: usize,
        /// A bin's width, 0-1.
        bin_soc: f64,
    },
}
