//! Keyword arguments of the Python functions, parsed by the engine with the CLI's own option
//! groups (`aloft::engine::flags`): the names (the CLI's flags in snake_case), defaults, ranges
//! and pairs are written once, in the engine. What is left here is Python's side of it: turning
//! Python values (bool, int, float, str, os.PathLike, lists and tuples) into the values a flag
//! takes.

use std::ffi::OsString;
use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyList, PyTuple};

use aloft::engine::{parse_keywords, FlagGroup, Keyword};

use crate::{aloft_error, engine_error};

/// A number as the command line would read it back exactly (Rust's shortest round-trip form;
/// `inf` and `NaN` stay words, which the flag refuses by name).
fn number_text(x: f64) -> OsString {
    OsString::from(x.to_string())
}

/// One Python value as a flag's value, or `None` when the value is `None` (flag not given).
fn keyword_of(key: &str, function: &str, v: &Bound<'_, PyAny>) -> PyResult<Option<Keyword>> {
    if v.is_none() {
        return Ok(None);
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(Some(Keyword::Switch(v.extract::<bool>()?)));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .map(|item| scalar(key, function, &item?))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(Some(Keyword::Many(items)));
    }
    Ok(Some(Keyword::One(scalar(key, function, v)?)))
}

/// A scalar Python value as text: a number, a string or a path.
fn scalar(key: &str, function: &str, v: &Bound<'_, PyAny>) -> PyResult<OsString> {
    if v.is_instance_of::<PyFloat>() {
        return Ok(number_text(v.extract::<f64>()?));
    }
    if let Ok(i) = v.extract::<i128>() {
        return Ok(OsString::from(i.to_string()));
    }
    if let Ok(s) = v.extract::<String>() {
        return Ok(OsString::from(s));
    }
    if let Ok(p) = v.extract::<PathBuf>() {
        return Ok(p.into_os_string());
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(number_text(x));
    }
    let shown = v
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".to_string());
    Err(aloft_error(format!(
        "invalid value {shown} for '{key}' of aloft.{function}: not a number, a string or a path"
    )))
}

/// The options of `aloft.<function>`: `options` (the keyword arguments) and the options the
/// function takes positionally, parsed into the engine's option group `T`.
pub fn parse<T: FlagGroup>(
    function: &str,
    positional: &[(&str, Keyword)],
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<T> {
    let given = given(function, options)?;
    parse_keywords::<T>(&format!("aloft.{function}"), positional, &given).map_err(engine_error)
}

/// The keyword arguments of `aloft.<function>` that are given (not `None`), as flag values.
pub fn given(
    function: &str,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<(String, Keyword)>> {
    let mut given = Vec::new();
    if let Some(d) = options {
        for (k, v) in d.iter() {
            let key = k.extract::<String>()?;
            if let Some(value) = keyword_of(&key, function, &v)? {
                given.push((key, value));
            }
        }
    }
    Ok(given)
}

/// Paths given positionally (the logs of `fit` and `validate`).
pub fn paths(ps: &[PathBuf]) -> Keyword {
    Keyword::Many(ps.iter().map(|p| p.as_os_str().to_os_string()).collect())
}

/// One path given positionally (the log of `live`).
pub fn path(p: &std::path::Path) -> Keyword {
    Keyword::One(p.as_os_str().to_os_string())
}

/// A text given positionally.
pub fn text(s: &str) -> Keyword {
    Keyword::One(OsString::from(s))
}

/// Refuse the old name `old` of the option `new`, saying what it is now (a clear error, never
/// a silent alias).
pub fn refuse_renamed(
    function: &str,
    options: Option<&Bound<'_, PyDict>>,
    old: &str,
    new: &str,
    what: &str,
) -> PyResult<()> {
    if let Some(d) = options {
        if d.get_item(old)?.is_some_and(|v| !v.is_none()) {
            return Err(aloft_error(format!(
                "'{old}' of aloft.{function} is now '{new}' ({what})"
            )));
        }
    }
    Ok(())
}
