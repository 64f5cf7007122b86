//! The one error type of the planner.

use thiserror::Error;

/// Everything the planner rejects. Variants carry the offending value with its unit and, for
/// errors found while flying a mission, the time, segment and position where they happened.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum PlannerError {
    /// The power model rejected a vehicle or a flight condition.
    #[error(transparent)]
    Power(#[from] aloft_power::PowerError),
    /// The propulsion chain rejected a parameter or an operating point.
    #[error(transparent)]
    Propulsion(#[from] aloft_propulsion::PropulsionError),
    /// A parameter outside its valid range.
    #[error(transparent)]
    InvalidParameter(#[from] aloft_core::InvalidParameter),
    /// A mission text that does not parse or does not match the format.
    #[error("invalid mission file: {message}")]
    MissionFormat {
        /// The parser's message (line, column and key).
        message: String,
    },
    /// A mission without segments.
    #[error("the mission has no segments: add at least a take-off and a landing")]
    EmptyMission,
    /// A mission segment that is invalid in itself.
    #[error("segment {index} ({kind}{}): {name} = {}{} is invalid: {expected}", ItemNote(*.item), aloft_core::Num::of(.value), aloft_core::Unit(.unit))]
    InvalidSegment {
        /// Segment number, from 1.
        index: usize,
        /// Segment kind (`leg`, `orbit`, ...).
        kind: &'static str,
        /// The operator's item number, when the segment came from a planner file.
        item: Option<u32>,
        /// The offending key.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Unit of `value`.
        unit: &'static str,
        /// Why it is invalid.
        expected: &'static str,
    },
    /// A segment asks for something the vehicle cannot do (speed, climb rate, turn load).
    #[error("segment {index} ({kind}{}): {name} = {}{} is beyond the vehicle's limit of {}{}", ItemNote(*.item), aloft_core::Fixed(*.value, 3), aloft_core::Unit(.unit), aloft_core::Fixed(*.limit, 3), aloft_core::Unit(.unit))]
    Unreachable {
        /// Segment number, from 1.
        index: usize,
        /// Segment kind.
        kind: &'static str,
        /// The operator's item number, when the segment came from a planner file.
        item: Option<u32>,
        /// What is beyond the limit.
        name: &'static str,
        /// The value asked for.
        value: f64,
        /// The vehicle's limit.
        limit: f64,
        /// Unit of both.
        unit: &'static str,
    },
    /// Segments in an order that cannot be flown (a leg before take-off, a take-off in the air).
    #[error("segment {index} ({kind}{}) cannot be flown here: {reason}", ItemNote(*.item))]
    SegmentOrder {
        /// Segment number, from 1.
        index: usize,
        /// Segment kind.
        kind: &'static str,
        /// The operator's item number, when the segment came from a planner file.
        item: Option<u32>,
        /// Why.
        reason: &'static str,
    },
    /// The gridded wind field does not cover a point of the route.
    #[error("the wind grid does not cover the route at t = {} s: E {} m, N {} m, alt {} m (grid spans E {min_m:?}..{max_m:?} m as [E, N, Up])", aloft_core::Fixed(*.time_s, 1), aloft_core::Fixed(*.east_m, 1), aloft_core::Fixed(*.north_m, 1), aloft_core::Fixed(*.up_m, 1))]
    OutsideWindGrid {
        /// Mission time, s.
        time_s: f64,
        /// East, m.
        east_m: f64,
        /// North, m.
        north_m: f64,
        /// Up, m.
        up_m: f64,
        /// Lower corner of the grid, m.
        min_m: [f64; 3],
        /// Upper corner of the grid, m.
        max_m: [f64; 3],
    },
    /// Wind-grid rows that do not form a complete regular grid.
    #[error("wind grid: {reason} (found {found})")]
    InvalidWindGrid {
        /// What is wrong.
        reason: &'static str,
        /// The count or value found.
        found: f64,
    },
    /// A battery description that is inconsistent.
    #[error("battery '{name}': {key} = {}{} is invalid: {expected}", aloft_core::Num::of(.value), aloft_core::Unit(.unit))]
    InvalidBattery {
        /// Pack name.
        name: String,
        /// The offending key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// Unit.
        unit: &'static str,
        /// What is expected.
        expected: &'static str,
    },
    /// A mission with more segments than the planner takes.
    #[error("the mission has {segments} segments, more than the {limit} a mission may have: split it into several missions")]
    TooManySegments {
        /// Segments in the mission.
        segments: usize,
        /// The limit.
        limit: usize,
    },
    /// A segment whose piece of trajectory would take longer than a flight can.
    #[error("segment {index} ({kind}{}) would take {duration_s:e} s, more than the {max_s:e} s a segment may take: check its speed, rate and length", ItemNote(*.item))]
    SegmentTooLong {
        /// Segment number, from 1.
        index: usize,
        /// Segment kind.
        kind: &'static str,
        /// The operator's item number, when the segment came from a planner file.
        item: Option<u32>,
        /// Its duration, s.
        duration_s: f64,
        /// The limit, s.
        max_s: f64,
    },
    /// A flight that would take more steps than the limit (a tiny time step, a huge hold).
    #[error("the flight takes more than {limit} samples at a time step of {time_step_s} s (stopped at t = {} s of flight): raise the time step (--time-step) to at least {} s", aloft_core::Fixed(*.flown_s, 0), aloft_core::Num::of(.suggested_time_step_s))]
    TooManySamples {
        /// The limit on samples (steps).
        limit: u64,
        /// The time step asked for, s.
        time_step_s: f64,
        /// Mission time reached when the limit was hit, s.
        flown_s: f64,
        /// A time step at which the whole mission fits the limit, s.
        suggested_time_step_s: f64,
    },
    /// A sample sink failed (a file that cannot be written).
    #[error("{message}")]
    Output {
        /// What failed.
        message: String,
    },
    /// A battery description without a key the mission planner needs.
    #[error("battery '{name}': {key} is missing, and the mission planner needs it")]
    MissingBatteryKey {
        /// Pack name.
        name: String,
        /// The missing key.
        key: &'static str,
    },
    /// The speed search of a query found no airspeed that can be flown.
    #[error("no airspeed between {} and {} m/s can make headway along the course in this wind", aloft_core::Fixed(*.min_mps, 1), aloft_core::Fixed(*.max_mps, 1))]
    NoHeadway {
        /// Lower end of the search, m/s.
        min_mps: f64,
        /// Upper end of the search, m/s.
        max_mps: f64,
    },
}

/// Reject NaN, infinities, values that are zero or negative, and subnormal ones (below
/// 2.2e-308: no physical quantity in its SI unit, and a divisor that overflows to infinity).
pub(crate) fn positive(
    name: &'static str,
    value: f64,
    unit: &'static str,
) -> Result<f64, PlannerError> {
    let ok = value.is_normal() && value > 0.0;
    Ok(aloft_core::parameter(
        name,
        value,
        unit,
        ok,
        "a positive finite number (not subnormal)",
    )?)
}

/// Reject NaN, infinities and negative values.
pub(crate) fn non_negative(
    name: &'static str,
    value: f64,
    unit: &'static str,
) -> Result<f64, PlannerError> {
    let ok = value.is_finite() && value >= 0.0;
    Ok(aloft_core::parameter(
        name,
        value,
        unit,
        ok,
        "a finite number, not negative",
    )?)
}

/// Check that `value` lies in `[min, max]` (a finite range), naming the range in the error.
pub(crate) fn within(
    name: &'static str,
    value: f64,
    (min, max): (f64, f64),
    unit: &'static str,
    expected: &'static str,
) -> Result<f64, PlannerError> {
    let ok = (min..=max).contains(&value);
    Ok(aloft_core::parameter(name, value, unit, ok, expected)?)
}

/// A reserve: a fraction of the capacity in `[0, 1)`.
pub(crate) fn reserve_fraction(value: f64) -> Result<f64, PlannerError> {
    let ok = (0.0..1.0).contains(&value);
    Ok(aloft_core::parameter(
        "reserve_fraction",
        value,
        "",
        ok,
        "a fraction in [0, 1)",
    )?)
}

/// `, item 7` after a segment's kind when it came from a planner file, else nothing.
pub(crate) struct ItemNote(pub(crate) Option<u32>);

impl std::fmt::Display for ItemNote {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some(i) => write!(f, ", item {i}"),
            None => Ok(()),
        }
    }
}
