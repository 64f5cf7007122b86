//! `aloft.plan`: `aloft plan MISSION -o DIR --format json`, with the texts of the files.
//!
//! The engine answers ([`answers::plan_answer`]: the vehicle, the request of the flags,
//! [`plan_to_fly`](aloft::engine::plan_to_fly), [`FlyPlan::write`](aloft::engine::FlyPlan::write)).
//! An existing file is refused with "force=True replaces it" (every function's
//! [`engine_error`]). The keywords are the flags' names in snake case (`max_speed=` for
//! `--max-speed`), as everywhere in the package.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use aloft::engine::answers;
use aloft::engine::flags::PlanFlags;
use aloft::engine::parse_keywords;

use crate::{aloft_error, engine_error, options};

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
    let given = options::given("plan", options)?;
    let flags: PlanFlags = parse_keywords("aloft.plan", &[], &given).map_err(engine_error)?;
    let output = output.as_deref().map(|dir| (dir, force));
    let answer = py
        .detach(|| answers::plan_answer(path.as_deref(), &flags, output))
        .map_err(engine_error)?;
    Ok((answer.json, answer.texts))
}
