//! `aloft.plan`: `aloft plan MISSION -o DIR --format json`, with the texts of the files.
//!
//! The engine answers ([`answers::plan_answer`]: the vehicle, the request of the flags,
//! [`plan_to_fly`](aloft::engine::plan_to_fly), [`FlyPlan::write`](aloft::engine::FlyPlan::write));
//! what is left here is Python's words for two of the command's:
//!
//! - the top speed of a leg is `max_speed_mps=` (the engine request's name, with its unit) for
//!   the flag `--max-speed`; `max_speed=` is refused with the name to use, never taken as an
//!   alias, and the messages about the option name it `max_speed_mps`;
//! - an existing file is refused with "give force=True" rather than "give --force".

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use aloft::engine::answers;
use aloft::engine::flags::PlanFlags;
use aloft::engine::{parse_keywords, Keyword};

use crate::{aloft_error, engine_error, options};

/// The flag's keyword (`--max-speed`).
const FLAG: &str = "max_speed";
/// Python's keyword for it.
const KEYWORD: &str = "max_speed_mps";

/// `aloft plan [PATH] -o OUTPUT --format json` as text, and the files' texts in flight order.
/// Without `output` no file is written (`files` are the names the files would have).
#[pyfunction]
#[pyo3(signature = (path=None, options=None, output=None, force=false))]
pub fn plan_json(
    py: Python<'_>,
    path: Option<PathBuf>,
    options: Option<&Bound<'_, PyDict>>,
    output: Option<PathBuf>,
    force: bool,
) -> PyResult<(String, Vec<String>)> {
    if force && output.is_none() {
        return Err(aloft_error(
            "'force' of aloft.plan needs 'output' (the folder whose files it overwrites)",
        ));
    }
    let given = python_keywords(options::given("plan", options)?)?;
    let flags: PlanFlags = parse_keywords("aloft.plan", &[], &given).map_err(in_python_words)?;
    let output = output.as_deref().map(|dir| (dir, force));
    let answer = py
        .detach(|| answers::plan_answer(path.as_deref(), &flags, output))
        .map_err(in_python_words)?;
    Ok((answer.json, answer.texts))
}

/// The keywords as the flags' names: `max_speed_mps` is `max_speed`; `max_speed` itself is
/// refused.
fn python_keywords(given: Vec<(String, Keyword)>) -> PyResult<Vec<(String, Keyword)>> {
    given
        .into_iter()
        .map(|(key, value)| match key.as_str() {
            FLAG => Err(aloft_error(format!(
                "'{FLAG}' of aloft.plan is '{KEYWORD}' (the highest ground speed a leg is given, m/s)"
            ))),
            KEYWORD => Ok((FLAG.to_string(), value)),
            _ => Ok((key, value)),
        })
        .collect()
}

/// An engine error in Python's words (module docs).
fn in_python_words(e: aloft::Error) -> PyErr {
    match e {
        aloft::Error::FileExists { path } => {
            aloft_error(format!("{path} exists: give force=True to overwrite it"))
        }
        aloft::Error::InvalidInput {
            name: FLAG,
            value,
            unit,
            expected,
        } => engine_error(aloft::Error::InvalidInput {
            name: KEYWORD,
            value,
            unit,
            expected,
        }),
        aloft::Error::Keyword { message } => aloft_error(renamed(&message)),
        e => engine_error(e),
    }
}

/// `message` with the word `max_speed` (not a part of a longer name) written `max_speed_mps`:
/// in "invalid value ... for 'max_speed'" and in the list of known options.
fn renamed(message: &str) -> String {
    let part_of_name = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut out = String::with_capacity(message.len() + 8);
    let mut rest = message;
    while let Some(at) = rest.find(FLAG) {
        let (before, after) = (&rest[..at], &rest[at + FLAG.len()..]);
        out.push_str(before);
        let whole = !before.ends_with(part_of_name) && !after.starts_with(part_of_name);
        out.push_str(if whole { KEYWORD } else { FLAG });
        rest = after;
    }
    out.push_str(rest);
    out
}
