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
    #[error("unknown vehicle '{name}': neither a built-in vehicle ({known}) nor a vehicle file")]
    UnknownVehicle {
        /// The name asked for.
        name: String,
        /// The built-in names, comma-separated.
        known: String,
    },
    /// A `--vehicle` that names a file (it has a directory or an extension) which does not exist.
    #[error("vehicle file {path}: no such file")]
    NoSuchVehicleFile {
        /// The path as given.
        path: String,
    },
    /// A vehicle file that is not valid TOML or does not match the format.
    #[error("invalid vehicle description {origin}: {message}")]
    VehicleFormat {
        /// Where the text came from (file path or built-in name).
        origin: String,
        /// The parser's message (line, column and key).
        message: String,
    },
    /// A request whose scenarios would fly more steps than its caller allows
    /// ([`WorkBounds::max_steps`](crate::engine::WorkBounds::max_steps), `aloft serve`).
    #[error("{samples} scenarios of about {steps_per_flight} steps each is more work than one request may ask for ({max_steps} steps): ask for at most {max_samples} samples, or a longer time step")]
    TooMuchWork {
        /// Scenarios asked for.
        samples: u32,
        /// Steps of one flight: its duration over the time step.
        steps_per_flight: u64,
        /// The bound on the steps of all the scenarios.
        max_steps: u64,
        /// The most scenarios within the bound.
        max_samples: u64,
    },
    /// A request whose flights (a mission's, a plan's candidates, sorties and trials) would fly
    /// more planner steps than its caller allows ([`StepMeter`](crate::engine::StepMeter),
    /// `aloft serve --max-request-steps`).
    #[error("the request would fly more than {max_steps} planner steps, more work than one request may ask for: give a longer time step (time_step) or a shorter mission")]
    RequestTooLong {
        /// The bound on the steps of all the request's flights.
        max_steps: u64,
    },
    /// A value of the day's air outside its range (`--elevation-m`, `--temperature-c`,
    /// `--humidity-percent`, `--qnh-hpa`).
    #[error("{name} = {} {unit} is outside the air aloft flies in: expected {expected}", aloft_core::Num::of(.value))]
    Air {
        /// The option's name (its JSON key).
        name: &'static str,
        /// The value given.
        value: f64,
        /// Its unit.
        unit: &'static str,
        /// The range, in words.
        expected: &'static str,
    },
    /// A day's air that cannot exist: its water vapour pressure at or above a tenth of the air's
    /// pressure (air at 100 % humidity near its boiling point).
    #[error("the air of {} m, {} C, {} % humidity and QNH {} hPa cannot exist: its water vapour pressure, {:.0} Pa, is at least a tenth of the air's pressure, {:.0} Pa", aloft_core::Num(round2(*.elevation_m)), aloft_core::Num(round2(*.temperature_c)), aloft_core::Num(round2(*.humidity_percent)), aloft_core::Num(round2(*.qnh_hpa)), .vapour_pa, .pressure_pa)]
    AirVapour {
        /// Elevation, m.
        elevation_m: f64,
        /// Air temperature, C.
        temperature_c: f64,
        /// Relative humidity, percent.
        humidity_percent: f64,
        /// QNH, hPa.
        qnh_hpa: f64,
        /// The water vapour's partial pressure, Pa.
        vapour_pa: f64,
        /// The air's pressure, Pa.
        pressure_pa: f64,
    },
    /// A day's air thinner than the thinnest the atmosphere answers for (ISA's at 11 km).
    #[error("the air of {} m, {} C, {} % humidity and QNH {} hPa would have a density of {:.3} kg/m^3, below {:.4} kg/m^3 (ISA's at 11 km, the thinnest air aloft flies in)", aloft_core::Num(round2(*.elevation_m)), aloft_core::Num(round2(*.temperature_c)), aloft_core::Num(round2(*.humidity_percent)), aloft_core::Num(round2(*.qnh_hpa)), .density_kg_m3, .min_density_kg_m3)]
    AirTooThin {
        /// Elevation, m.
        elevation_m: f64,
        /// Air temperature, C.
        temperature_c: f64,
        /// Relative humidity, percent.
        humidity_percent: f64,
        /// QNH, hPa.
        qnh_hpa: f64,
        /// The density of that air, kg/m^3.
        density_kg_m3: f64,
        /// The thinnest air flown, kg/m^3.
        min_density_kg_m3: f64,
    },
    /// No log of a fit or a validation could be used (`aloft fit` and `aloft validate` exit 1).
    #[error("no log can be used: {reasons}")]
    NoUsableLog {
        /// Each log's reason, `; `-separated.
        reasons: String,
    },
    /// Work stopped because its caller no longer wants the answer (a client that went away).
    #[error("the work was cancelled: its answer is no longer wanted")]
    Cancelled,
    /// No way of cutting a mission into sorties keeps the reserve (`aloft plan`).
    #[error("no plan keeps the reserve: {reason}")]
    NoPlan {
        /// Why (the part of the route a full pack cannot fly out and back).
        reason: String,
    },
    /// A mission format `aloft plan` does not write.
    #[error("aloft plan writes aloft TOML and JSON missions; {format} files are not written yet")]
    PlanFormat {
        /// The input's format.
        format: &'static str,
    },
    /// An output file refused or not written by aloft's one way of writing a file
    /// ([`aloft_core::output`]): it exists (without `force`), something aloft never replaces is
    /// at its name (a FIFO, a device, a folder), its folder is missing, or the write failed.
    #[error(transparent)]
    Output(#[from] aloft_core::output::OutputError),
    /// A CSV input lacks a required column.
    #[error("{origin}: missing column '{column}' (none of the {columns} columns of its first line is named so)")]
    ColumnMissing {
        /// The column asked for.
        column: &'static str,
        /// File or stream name.
        origin: String,
        /// How many columns its first line has (their names are the file's text: not quoted, as
        /// the file may be anything the caller could name).
        columns: usize,
    },
    /// An answer that would carry a number that is not finite (an overflow the input checks did
    /// not foresee): refused rather than printed as `null` or `inf`.
    #[error("{answer}: {field} would be {}, not a finite number, for {request}", aloft_core::Num::of(.value))]
    NonFinite {
        /// Which answer.
        answer: &'static str,
        /// The field, as a path (`segments.3.energy_wh`).
        field: String,
        /// The value.
        value: f64,
        /// The inputs that led to it.
        request: String,
    },
    /// A CSV header that names a column twice.
    #[error("{origin}: the column '{column}' appears twice in the header")]
    DuplicateColumn {
        /// The repeated name.
        column: String,
        /// File or stream name.
        origin: String,
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
    /// A pack file (`--battery pack.toml`, the output of `aloft pack fit`) that does not read or
    /// whose `[battery]` is not a pack the planner flies.
    #[error("invalid pack file {path}: {message}")]
    PackFile {
        /// The file.
        path: String,
        /// What is wrong (the key, its value and its range).
        message: String,
    },
    /// A key of the pack `aloft pack fit` writes that neither the logs, a flag nor `--battery`
    /// gives.
    #[error("aloft pack fit: {key} is unknown: {hint}")]
    PackKeyMissing {
        /// The `[battery]` key.
        key: &'static str,
        /// Where it can come from.
        hint: &'static str,
    },
    /// Reading or writing failed.
    #[error("{origin}: {source}")]
    Io {
        /// File or stream name.
        origin: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A flight log could not be read or decoded.
    #[error("{origin}: {source}")]
    Log {
        /// File.
        origin: String,
        /// The log reader's error.
        source: Box<aloft_logs::LogError>,
    },
    /// A telemetry source (a link, a telemetry log) failed: the message names it.
    #[error("{0}")]
    Link(String),
    /// A log file that cannot be opened, read or written (the message names the file).
    #[error(transparent)]
    LogFile(Box<aloft_logs::LogError>),
    /// A log without the channel a request needs.
    #[error("{origin}: {needed_for} needs {channel}, which the log does not have")]
    MissingChannel {
        /// File.
        origin: String,
        /// What needs it (an option).
        needed_for: &'static str,
        /// The channel, in words.
        channel: &'static str,
    },
    /// Power and velocity that share too little time for a lag estimate.
    #[error("{origin}: --max-lag needs power and velocity over a common span of at least 10 samples; power covers {power}, velocity {velocity} ({shared} samples of {step} shared)")]
    NoCommonSpan {
        /// File.
        origin: String,
        /// The power series' span, in words with units.
        power: String,
        /// The velocity series' span, in words with units.
        velocity: String,
        /// Samples the two share on the resampling grid.
        shared: usize,
        /// The grid's step, in words with its unit.
        step: String,
    },
    /// A log whose own landed state keeps it on the ground throughout (`aloft fit` and `aloft
    /// validate` skip it).
    #[error("{origin}: never flew: its landed state keeps it on the ground for all of its {duration_s:.1} s")]
    NeverFlew {
        /// File.
        origin: String,
        /// From its first record to its last, s.
        duration_s: f64,
    },
    /// A log in the air at no second where its motion and its power are both logged.
    #[error("{origin}: in the air at no time where both its motion and its power are logged: nothing to validate")]
    NoAirborneTime {
        /// File.
        origin: String,
    },
    /// Power and motion that overlap too briefly for the lag search's window.
    #[error("{origin}: power and motion overlap for {overlap_s:.1} s, too short to search the lag of power behind motion within +-{} s (the search needs {} s): give the lag with --lag S, or a smaller window with --max-lag S", aloft_core::Num::of(.max_lag_s), aloft_core::Num(2.0 * *.max_lag_s))]
    TooShortForLag {
        /// File.
        origin: String,
        /// The span power and motion share, s.
        overlap_s: f64,
        /// The search window, s.
        max_lag_s: f64,
    },
    /// A log with no decodable samples.
    #[error("{origin}: the log holds no decodable samples")]
    EmptyLog {
        /// File.
        origin: String,
    },
    /// A log without electrical power (no voltage and current, no power column).
    #[error(
        "{origin}: no electrical power in this log (no voltage and current, no power channel)"
    )]
    NoPower {
        /// File.
        origin: String,
    },
    /// A log without the pack's voltage, asked for the voltage failsafes (`aloft live --route
    /// log` with `--low-voltage-v` or `--critical-voltage-v`).
    #[error("{origin}: no pack voltage in this log, so the voltage failsafes ({flags}) cannot be judged")]
    NoVoltage {
        /// File.
        origin: String,
        /// The flags given.
        flags: String,
    },
    /// A log without velocity and attitude.
    #[error("{origin}: no samples with both velocity and attitude")]
    NoMotion {
        /// File.
        origin: String,
    },
    /// A log whose time stamps span far longer than its samples could cover.
    #[error("{origin}: the time stamps span {} s for {samples} samples: a time stamp is off (see `aloft log info`)", aloft_core::Num::of(.span_s))]
    SparseTime {
        /// File.
        origin: String,
        /// The span of the time stamps, s.
        span_s: f64,
        /// Samples of the longer channel.
        samples: usize,
    },
    /// Time runs backwards in a log that must be aligned.
    #[error("{origin}: time is not monotonic; alignment needs an ordered time base (see `aloft log info`)")]
    NotMonotonic {
        /// File.
        origin: String,
    },
    /// The calibration window leaves too little of the flight (or is too short).
    #[error(
        "{origin}: a calibration window of {window_s} s does not fit a flight of {duration_s:.1} s"
    )]
    CalibrationWindow {
        /// File.
        origin: String,
        /// Requested window, s.
        window_s: f64,
        /// Flight duration, s.
        duration_s: f64,
    },
    /// The power-model fit failed or was refused.
    #[error(transparent)]
    Fit(#[from] aloft_power::FitError),
    /// The planner rejected an input (a wind, an endurance query, a mass). Boxed: the planner's
    /// error is large and this enum travels in every `Result` of the facade.
    #[error(transparent)]
    Planner(Box<aloft_planner::PlannerError>),
    /// A terrain tile that cannot be read, or no ground (no tile, a void) under a place asked.
    #[error(transparent)]
    Terrain(#[from] aloft_terrain::TerrainError),
    /// A wind the planner rejects (a speed, a profile, a field, gusts).
    #[error("{origin}: {source}")]
    Wind {
        /// Which wind: `wind options`, `wind field <file>`, `gusts`.
        origin: String,
        /// The planner's error.
        source: Box<aloft_planner::PlannerError>,
    },
    /// A mission text (TOML or JSON) that does not parse or does not match the format.
    #[error("invalid mission {origin}: {message}")]
    MissionFormat {
        /// Where the text came from (file path, `built-in demo`, `C caller`).
        origin: String,
        /// The parser's message (line, column and key).
        message: String,
    },
    /// A planner file (QGroundControl `.plan`, `.waypoints`) that cannot be read or holds what
    /// aloft does not fly; the message names the item (or row, or line) and the command or key.
    #[error("invalid mission {origin}: {source}")]
    MissionImport {
        /// Where the text came from.
        origin: String,
        /// The importer's error.
        source: aloft_missions::ImportError,
    },
    /// A mission that cannot be compiled or flown by this vehicle.
    #[error("mission {origin} with {vehicle}: {source}")]
    Mission {
        /// Where the mission came from.
        origin: String,
        /// Vehicle name.
        vehicle: String,
        /// The planner's error.
        source: Box<aloft_planner::PlannerError>,
    },
    /// A number outside its valid range in an option or a measured sample.
    #[error("{name} = {}{} is invalid: expected {expected}", aloft_core::Num::of(.value), aloft_core::Unit(.unit))]
    InvalidInput {
        /// Option or field name, with its unit suffix.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// Unit of `value`.
        unit: &'static str,
        /// What a valid value looks like.
        expected: &'static str,
    },
    /// A spec sheet (`aloft vehicles calibrate`) with a missing, malformed or impossible value.
    #[error("spec sheet {origin}: {key}: {message}")]
    SpecSheet {
        /// The spec sheet's path or name.
        origin: String,
        /// The key at fault, as written in the file (e.g. `published_hover.minutes`).
        key: String,
        /// What is wrong, with the value and its unit.
        message: String,
    },
    /// An option given by keyword (Python) that is unknown, of the wrong kind, out of range, or
    /// without the option it needs; the message names the keyword and the function.
    #[error("{message}")]
    Keyword {
        /// The message, naming the keyword as the caller wrote it.
        message: String,
    },
    /// An option document (JSON) that does not parse or has unknown keys.
    #[error("invalid {what}: {message}")]
    OptionsFormat {
        /// Which document (`mission options`, `endurance options`, `flight state`).
        what: &'static str,
        /// The parser's message.
        message: String,
    },
    /// The propulsion chain cannot hover as asked.
    #[error("{request}: {source}")]
    Hover {
        /// What was asked (`payload_kg 3`, `takeoff_mass_kg 9`).
        request: String,
        /// The chain's error.
        source: aloft_propulsion::PropulsionError,
    },
    /// A rotor whose values the transient model rejects.
    #[error("invalid rotor: {source}")]
    Rotor {
        /// The model's error.
        source: aloft_propulsion::PropulsionError,
    },
    /// A rotor name that is neither built in nor a file.
    #[error("unknown rotor '{name}': not a built-in rotor ({known}) and no such file")]
    UnknownRotor {
        /// The name asked for.
        name: String,
        /// The built-in names, comma-separated.
        known: String,
    },
    /// A rotor file that does not parse.
    #[error("invalid rotor description {origin}: {message}")]
    RotorFormat {
        /// File or built-in name.
        origin: String,
        /// The parser's message.
        message: String,
    },
    /// A value given neither as an option nor in a file.
    #[error("missing {flag}: {hint}")]
    MissingValue {
        /// The option that gives it.
        flag: &'static str,
        /// Where else it may come from.
        hint: &'static str,
    },
    /// A name that is not among the known ones.
    #[error("unknown {what} '{name}' (known: {known})")]
    UnknownName {
        /// What kind of name.
        what: &'static str,
        /// The name given.
        name: String,
        /// The known names.
        known: &'static str,
    },
    /// Drag could not be fitted from the force balance.
    #[error("drag from the force balance: {source}")]
    Drag {
        /// The fit's error.
        source: aloft_power::FitError,
    },
    /// A log with too little trajectory to replay.
    #[error("{origin}: fewer than two samples with a velocity: nothing to replay")]
    NothingToReplay {
        /// File.
        origin: String,
    },
    /// The planner could not replay a trajectory.
    #[error("replay of {origin}: {source}")]
    Replay {
        /// File.
        origin: String,
        /// The planner's error.
        source: Box<aloft_planner::PlannerError>,
    },
    /// The power channel of a log does not overlap its trajectory.
    #[error("{origin}: the power channel does not overlap the trajectory with a lag of {lag_s} s")]
    NoOverlap {
        /// File.
        origin: String,
        /// Lag applied, s.
        lag_s: f64,
    },
    /// Options that contradict each other (the message says which and why).
    #[error("{message}")]
    Contradiction {
        /// Which options, and why they cannot go together.
        message: String,
    },
    /// A flight state the power model rejects.
    #[error("invalid flight state ({state}): {source}")]
    FlightState {
        /// The state's values with their names and units.
        state: String,
        /// The model's error.
        source: aloft_power::PowerError,
    },
    /// The take-off mass exceeds the airframe's limit.
    #[error("take-off mass {} kg (airframe + {battery} + payload) exceeds the vehicle's {} kg limit", aloft_core::Fixed(*.mass_kg, 3), aloft_core::Fixed(*.max_kg, 3))]
    TooHeavy {
        /// Take-off mass asked for, kg.
        mass_kg: f64,
        /// The airframe's limit, kg.
        max_kg: f64,
        /// The pack's name.
        battery: String,
    },
    /// A payload sweep `START:STOP:STEP` (kg) that cannot be swept.
    #[error("payload sweep {text}: {problem}")]
    PayloadSweep {
        /// The sweep as given.
        text: String,
        /// What is wrong with it.
        problem: SweepProblem,
    },
    /// No payload of a sweep can be carried with any of the packs swept: every take-off mass
    /// exceeds the airframe's limit.
    #[error("every payload from {start_kg} kg exceeds the {} kg maximum take-off mass with every pack swept (the most any of them leaves for payload is {} kg)", aloft_core::Fixed(*.max_takeoff_mass_kg, 3), aloft_core::Fixed(*.max_payload_kg, 3))]
    SweepTooHeavy {
        /// The sweep's first payload, kg.
        start_kg: f64,
        /// The airframe's maximum take-off mass, kg.
        max_takeoff_mass_kg: f64,
        /// The largest payload any pack swept leaves room for, kg (negative when even the
        /// airframe and pack alone exceed the limit).
        max_payload_kg: f64,
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

/// What is wrong with a payload sweep `START:STOP:STEP` ([`Error::PayloadSweep`]).
#[derive(Debug, Clone, Error)]
#[non_exhaustive]
pub enum SweepProblem {
    /// Not three fields separated by colons.
    #[error("expected START:STOP:STEP in kg, three numbers such as 0:1:0.25")]
    Format,
    /// A field that is not a number.
    #[error("{field} '{text}' is not a number")]
    NotANumber {
        /// `START`, `STOP` or `STEP`.
        field: &'static str,
        /// The text found.
        text: String,
    },
    /// A field that is NaN or infinite.
    #[error("{field} = {} kg is not a finite number", aloft_core::Num::of(.value_kg))]
    NotFinite {
        /// `START`, `STOP` or `STEP`.
        field: &'static str,
        /// The value, kg.
        value_kg: f64,
    },
    /// A negative first payload.
    #[error("START = {} kg is negative: a payload is 0 kg or more", aloft_core::Num::of(.start_kg))]
    NegativeStart {
        /// START, kg.
        start_kg: f64,
    },
    /// The last payload below the first.
    #[error("STOP = {} kg is below START = {} kg", aloft_core::Num::of(.stop_kg), aloft_core::Num::of(.start_kg))]
    StopBelowStart {
        /// START, kg.
        start_kg: f64,
        /// STOP, kg.
        stop_kg: f64,
    },
    /// A step that is zero or negative.
    #[error("STEP = {} kg is not positive", aloft_core::Num::of(.step_kg))]
    StepNotPositive {
        /// STEP, kg.
        step_kg: f64,
    },
    /// More payloads than a sweep may have.
    #[error("{} payloads, more than the {max} a sweep may have: take a larger STEP", aloft_core::Num::of(.points))]
    TooManyPoints {
        /// How many payloads the sweep would have.
        points: f64,
        /// The most a sweep may have.
        max: usize,
    },
}

impl From<aloft_planner::PlannerError> for Error {
    fn from(e: aloft_planner::PlannerError) -> Self {
        Error::Planner(Box::new(e))
    }
}

impl From<aloft_logs::LogError> for Error {
    fn from(e: aloft_logs::LogError) -> Self {
        match e {
            // An output refused or not placed says so in aloft's one way, whichever writer.
            aloft_logs::LogError::Output(o) => Error::Output(o),
            e => Error::LogFile(Box::new(e)),
        }
    }
}

/// `x` to two decimals, as a message shows a day's figure (ISA's -56.5 C at 11 km, not
/// -56.49999999999997).
fn round2(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}
