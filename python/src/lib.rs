//! # aloft._native: the engine of aloft for Python
//!
//! The compiled half of the `aloft` Python package (the other half, `python/aloft/__init__.py`,
//! gives the functions their Python signatures, docstrings and pandas output). Like the CLI and
//! the C ABI it is a thin layer over [`aloft::engine`]: each function turns keyword arguments
//! into the engine's request (`options.rs`), calls the engine's entry point with the GIL
//! released, and returns the engine's JSON text (the CLI's `--format json`, parsed in Python so
//! every float round-trips exactly) or numpy arrays.
//!
//! Errors are `aloft.AloftError` (a `ValueError`) with the CLI's one-line message.
//!
//! Fast path: [`power`] evaluates arrays with the power crate's batch kernels
//! (`PowerModel::evaluate_batch`, identical bit for bit to the single evaluation that
//! `aloft power` uses), in blocks, without the GIL.

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

mod options;
mod plan;

use std::path::PathBuf;

use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use aloft::engine::answers;
use aloft::engine::flags::{LogInfoFlags, MissionFlags, MissionScenarioFlags, PowerModelFlags};
use aloft::engine::{
    plan_mission, power_model, power_point, power_values, FlagGroup, FlightStateDeg, Keyword,
    Mission, PowerModelQuery, PowerQuery, Vehicle, POWER_KEYS,
};
use aloft_power::{AoaInput, FlightState, PowerBreakdown};

create_exception!(
    aloft,
    AloftError,
    PyValueError,
    "A request aloft refuses: the message is the one `aloft` prints (without `aloft: error:`)."
);

/// An `AloftError` with this message.
pub(crate) fn aloft_error(message: impl Into<String>) -> PyErr {
    AloftError::new_err(message.into())
}

/// An engine error as Python sees it.
pub(crate) fn engine_error(e: aloft::Error) -> PyErr {
    use aloft::engine::OutputError;
    match e {
        // Python's word for the command line's --force.
        aloft::Error::Output(OutputError::Exists { path }) => aloft_error(format!(
            "{} exists: aloft keeps it (force=True replaces it)",
            aloft::engine::shown_path(&path)
        )),
        e => aloft_error(aloft::engine::error_line(&e)),
    }
}

/// The JSON text of an entry point's answer: `function`'s keyword `options` (after its
/// `positional` values) read as its flags, then `answer` computed with the GIL released.
fn answer_json<T: FlagGroup + Sync>(
    py: Python<'_>,
    function: &str,
    positional: &[(&str, Keyword)],
    options: Option<&Bound<'_, PyDict>>,
    answer: impl FnOnce(&T) -> Result<String, aloft::Error> + Send,
) -> PyResult<String> {
    let flags: T = options::parse(function, positional, options)?;
    py.detach(|| answer(&flags)).map_err(engine_error)
}

/// `aloft mission --format json` as text.
#[pyfunction]
#[pyo3(signature = (path=None, options=None))]
fn mission_json(
    py: Python<'_>,
    path: Option<PathBuf>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    answer_json(
        py,
        "mission",
        &[],
        options,
        |flags: &MissionScenarioFlags| answers::mission_answer(path.as_deref(), flags),
    )
}

/// The map of a mission (`aloft serve`'s `/api/map`) as compact JSON text.
#[pyfunction]
#[pyo3(signature = (path=None, options=None))]
fn mission_map_json(
    py: Python<'_>,
    path: Option<PathBuf>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    answer_json(
        py,
        "mission",
        &[],
        options,
        |flags: &MissionScenarioFlags| answers::mission_map_answer(path.as_deref(), flags),
    )
}

/// The columns of `aloft mission --timeseries`: names and arrays (`segment` as int64).
#[pyfunction]
#[pyo3(signature = (path=None, options=None))]
fn timeseries_columns<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Vec<(String, Bound<'py, PyAny>)>> {
    let flags: MissionFlags = options::parse("timeseries", &[], options)?;
    let mut opts = flags.options();
    opts.record_samples = true;
    let table = py.detach(|| -> Result<Table, aloft::Error> {
        let v = Vehicle::load(&flags.vehicle)?;
        let m = Mission::load(path.as_deref())?;
        let plan = plan_mission(&v, &m, &opts)?;
        Table::of_samples(&plan.report().samples)
    });
    let table = table.map_err(engine_error)?;
    let mut out = Vec::with_capacity(table.names.len());
    for (name, column) in table.names.into_iter().zip(table.columns) {
        let array = match column {
            Column::Int(v) => v.into_pyarray(py).into_any(),
            Column::Float(v) => v.into_pyarray(py).into_any(),
        };
        out.push((name, array));
    }
    Ok(out)
}

/// One column of the time series.
enum Column {
    Int(Vec<i64>),
    Float(Vec<f64>),
}

/// The time series by column.
struct Table {
    names: Vec<String>,
    columns: Vec<Column>,
}

impl Table {
    /// The samples through the CSV serialiser the CLI's `--timeseries` file is written with (so
    /// the columns and their order are the file's), read back by column. The CSV holds the
    /// shortest text that round-trips, so every value is the sample's, bit for bit; an empty
    /// cell (a power term the model does not have) is NaN.
    fn of_samples(samples: &[aloft::engine::Sample]) -> Result<Self, aloft::Error> {
        let csv_error = |e: csv::Error| aloft::Error::Csv {
            origin: "time series".to_string(),
            row: 0,
            message: e.to_string(),
        };
        let mut w = csv::Writer::from_writer(Vec::new());
        for s in samples {
            w.serialize(s).map_err(csv_error)?;
        }
        let bytes = w
            .into_inner()
            .map_err(|e| csv_error(csv::Error::from(e.into_error())))?;
        let mut r = csv::Reader::from_reader(bytes.as_slice());
        let names: Vec<String> = r
            .headers()
            .map_err(csv_error)?
            .iter()
            .map(str::to_string)
            .collect();
        let mut columns: Vec<Column> = names
            .iter()
            .map(|n| {
                if n == "segment" {
                    Column::Int(Vec::with_capacity(samples.len()))
                } else {
                    Column::Float(Vec::with_capacity(samples.len()))
                }
            })
            .collect();
        for record in r.records() {
            let record = record.map_err(csv_error)?;
            for (cell, column) in record.iter().zip(columns.iter_mut()) {
                match column {
                    Column::Int(v) => v.push(cell.parse().unwrap_or(-1)),
                    Column::Float(v) => v.push(cell.parse().unwrap_or(f64::NAN)),
                }
            }
        }
        Ok(Self { names, columns })
    }
}

/// `aloft endurance --format json` as text (with `sweep_speed`: the power curve; with
/// `payload_sweep`: endurance against payload per pack).
#[pyfunction]
#[pyo3(signature = (options=None))]
fn endurance_json(py: Python<'_>, options: Option<&Bound<'_, PyDict>>) -> PyResult<String> {
    answer_json(py, "endurance", &[], options, answers::endurance_answer)
}

/// `aloft vehicles --format json` as text: the built-in vehicles with their packs and sources.
#[pyfunction]
fn vehicles_json() -> PyResult<String> {
    answers::vehicles_answer().map_err(engine_error)
}

/// `aloft vehicles calibrate SPEC -o OUTPUT [--force] --format json` as text: the vehicle file
/// of a spec sheet, written to `output` (an existing file replaced only with `force`).
#[pyfunction]
#[pyo3(signature = (spec, output, force=false))]
fn calibrate_vehicle_json(
    py: Python<'_>,
    spec: PathBuf,
    output: PathBuf,
    force: bool,
) -> PyResult<String> {
    py.detach(|| answers::calibrate_vehicle_answer(&spec, &output, force))
        .map_err(engine_error)
}

/// `aloft log info --format json` as text.
#[pyfunction]
#[pyo3(signature = (path, options=None))]
fn log_info_json(
    py: Python<'_>,
    path: PathBuf,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    options::refuse_renamed(
        "log_info",
        options,
        "lag",
        "max_lag",
        "the search window of the lag estimate, s; 'lag' is the lag itself in fit and validate",
    )?;
    answer_json(py, "log_info", &[], options, |flags: &LogInfoFlags| {
        answers::log_info_answer(&path, flags)
    })
}

/// `aloft fit --format json` as text (the vehicle file written only when `output` is given).
#[pyfunction]
#[pyo3(signature = (logs, vehicle_template=None, options=None))]
fn fit_json(
    py: Python<'_>,
    logs: Vec<PathBuf>,
    vehicle_template: Option<String>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let mut positional = vec![("log", options::paths(&logs))];
    if let Some(t) = &vehicle_template {
        positional.push(("vehicle_template", options::text(t)));
    }
    answer_json(py, "fit", &positional, options, answers::fit_answer)
}

/// `aloft validate --format json` as text.
#[pyfunction]
#[pyo3(signature = (logs, vehicle, options=None))]
fn validate_json(
    py: Python<'_>,
    logs: Vec<PathBuf>,
    vehicle: String,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let positional = [
        ("log", options::paths(&logs)),
        ("vehicle", options::text(&vehicle)),
    ];
    answer_json(
        py,
        "validate",
        &positional,
        options,
        answers::validate_answer,
    )
}

/// `aloft live --replay LOG --format json` as one JSON text: `{"updates": [...], "check" or
/// "summary": {...}}`. This package is built without the `live` feature: `tlog` and `connect`
/// are refused with a message saying so.
#[pyfunction]
#[pyo3(signature = (replay, vehicle, options=None))]
fn live_json(
    py: Python<'_>,
    replay: PathBuf,
    vehicle: String,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let positional = [
        ("replay", options::path(&replay)),
        ("vehicle", options::text(&vehicle)),
    ];
    answer_json(py, "live", &positional, options, answers::live_answer)
}

/// States per block of the batch kernel.
const BLOCK: usize = 4096;

/// The inputs of [`power`], one value per state (equal lengths, checked).
struct States<'a> {
    airspeed: &'a [f64],
    roll: &'a [f64],
    pitch: &'a [f64],
    climb: &'a [f64],
    direction: Option<&'a [f64]>,
}

impl States<'_> {
    /// The point query of state `i`, as `aloft power` would be asked it.
    fn query(&self, i: usize, base: &PowerModelQuery) -> PowerQuery {
        PowerQuery {
            model: base.clone(),
            state: FlightStateDeg {
                airspeed_mps: self.airspeed[i],
                roll_deg: self.roll[i],
                pitch_deg: self.pitch[i],
                climb_rate_mps: self.climb[i],
                air_direction_deg: self.direction.map(|d| d[i]),
            },
            gradient: false,
        }
    }

    /// The flight state of element `i` (as `power_point` builds it).
    fn state(&self, i: usize) -> FlightState {
        FlightState {
            airspeed_mps: self.airspeed[i],
            roll_rad: self.roll[i].to_radians(),
            pitch_rad: self.pitch[i].to_radians(),
            climb_rate_mps: self.climb[i],
            aoa: match self.direction {
                Some(d) => AoaInput::Geometric {
                    air_direction_rad: d[i].to_radians(),
                },
                None => AoaInput::Paper,
            },
        }
    }

    /// The first input that is not a finite number (the CLI refuses them in its flags).
    fn first_non_finite(&self) -> Option<(&'static str, usize, f64)> {
        let mut named = vec![
            ("airspeed", self.airspeed),
            ("roll", self.roll),
            ("pitch", self.pitch),
            ("climb_rate", self.climb),
        ];
        if let Some(d) = self.direction {
            named.push(("air_direction_deg", d));
        }
        named.into_iter().find_map(|(name, v)| {
            v.iter()
                .position(|x| !x.is_finite())
                .map(|i| (name, i, v[i]))
        })
    }
}

/// The power model over arrays: one array per key of `POWER_KEYS`.
fn power_arrays(
    vehicle: &str,
    base: &PowerModelQuery,
    s: &States<'_>,
) -> Result<Vec<Vec<f64>>, PyErr> {
    let n = s.airspeed.len();
    if let Some((name, i, x)) = s.first_non_finite() {
        return Err(aloft_error(format!(
            "invalid value {x} for '{name}' (element {i}) of aloft.power: not a finite number"
        )));
    }
    let v = Vehicle::load(vehicle).map_err(engine_error)?;
    // The configuration (a [power] table, the angle-of-attack choice) checked by the engine's
    // point query, so its refusals are the CLI's words.
    let first = if n > 0 {
        s.query(0, base)
    } else {
        PowerQuery {
            model: base.clone(),
            ..PowerQuery::default()
        }
    };
    power_point(&v, &first).map_err(engine_error)?;
    let model = power_model(&v, base).map_err(engine_error)?;
    let mut columns: Vec<Vec<f64>> = (0..POWER_KEYS.len())
        .map(|_| Vec::with_capacity(n))
        .collect();
    let mut states = Vec::with_capacity(BLOCK);
    let mut out = vec![PowerBreakdown::default(); BLOCK];
    for start in (0..n).step_by(BLOCK) {
        let end = (start + BLOCK).min(n);
        states.clear();
        states.extend((start..end).map(|i| s.state(i)));
        let out = &mut out[..end - start];
        let failed = model.evaluate_batch(&states, out).is_err()
            || out
                .iter()
                .any(|p| power_values(p).iter().any(|x| !x.is_finite()));
        if failed {
            return Err(first_failure(&v, base, s, start..end));
        }
        for p in out.iter() {
            for (column, x) in columns.iter_mut().zip(power_values(p)) {
                column.push(x);
            }
        }
    }
    Ok(columns)
}

/// The engine's refusal of the first state in `range` it refuses (the CLI's message for that
/// state as a point query).
fn first_failure(
    v: &Vehicle,
    base: &PowerModelQuery,
    s: &States<'_>,
    range: std::ops::Range<usize>,
) -> PyErr {
    for i in range.clone() {
        if let Err(e) = power_point(v, &s.query(i, base)) {
            return aloft_error(format!("element {i}: {}", aloft::engine::error_line(&e)));
        }
    }
    aloft_error(format!(
        "the power model failed on elements {}..{} but each alone evaluates; please report it",
        range.start, range.end
    ))
}

/// `aloft power` over arrays of equal length: a dict of float64 arrays keyed as the CLI's
/// power JSON/CSV.
#[pyfunction]
#[pyo3(signature = (airspeed, roll, pitch, climb_rate, air_direction_deg=None, options=None))]
fn power<'py>(
    py: Python<'py>,
    airspeed: PyReadonlyArray1<'py, f64>,
    roll: PyReadonlyArray1<'py, f64>,
    pitch: PyReadonlyArray1<'py, f64>,
    climb_rate: PyReadonlyArray1<'py, f64>,
    air_direction_deg: Option<PyReadonlyArray1<'py, f64>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let flags: PowerModelFlags = options::parse("power", &[], options)?;
    let vehicle = flags.vehicle.clone();
    let base = flags.query();
    let states = States {
        airspeed: airspeed.as_slice()?,
        roll: roll.as_slice()?,
        pitch: pitch.as_slice()?,
        climb: climb_rate.as_slice()?,
        direction: match &air_direction_deg {
            Some(d) => Some(d.as_slice()?),
            None => None,
        },
    };
    let n = states.airspeed.len();
    let lengths = [
        states.roll.len(),
        states.pitch.len(),
        states.climb.len(),
        states.direction.map_or(n, <[f64]>::len),
    ];
    if lengths.iter().any(|&l| l != n) {
        return Err(aloft_error("aloft.power: the arrays differ in length"));
    }
    let columns = py.detach(|| power_arrays(&vehicle, &base, &states))?;
    let dict = PyDict::new(py);
    for (key, column) in POWER_KEYS.iter().zip(columns) {
        dict.set_item(key, column.into_pyarray(py))?;
    }
    Ok(dict)
}

/// The version of the aloft crate this module was built from.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// The native module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("AloftError", m.py().get_type::<AloftError>())?;
    m.add("POWER_KEYS", POWER_KEYS.to_vec())?;
    m.add("DEMO_MISSION", aloft::engine::DEMO_MISSION)?;
    m.add("DEFAULT_VEHICLE", aloft::engine::DEFAULT_VEHICLE)?;
    m.add_function(wrap_pyfunction!(mission_json, m)?)?;
    m.add_function(wrap_pyfunction!(mission_map_json, m)?)?;
    m.add_function(wrap_pyfunction!(timeseries_columns, m)?)?;
    m.add_function(wrap_pyfunction!(endurance_json, m)?)?;
    m.add_function(wrap_pyfunction!(vehicles_json, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_vehicle_json, m)?)?;
    m.add_function(wrap_pyfunction!(log_info_json, m)?)?;
    m.add_function(wrap_pyfunction!(fit_json, m)?)?;
    m.add_function(wrap_pyfunction!(validate_json, m)?)?;
    m.add_function(wrap_pyfunction!(live_json, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan_json, m)?)?;
    m.add_function(wrap_pyfunction!(power, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    Ok(())
}
