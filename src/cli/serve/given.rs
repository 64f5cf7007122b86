//! The files given on the command line, read once at start: what a request may name.
//!
//! A given file is a mission (its text is served), a log (its `log info` answer), a vehicle
//! (positionally or with `--vehicle`), a wind field or a column map. An option of a request that
//! names a file (`vehicle`, `wind_field`, `profile`: [`aloft::engine::file_keywords`]) may name
//! a built-in (`vehicle=dji-m100`, `profile=kaist`) or a file given to `serve`, by the name it
//! was given with (a vehicle also by its own name, or a vehicle sent to the server:
//! [`super::vehicles`]), never any other path of the server ([`Names`]).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::Result;

use aloft::engine::answers;
use aloft::engine::flags::LogInfoFlags;
use aloft::engine::{
    builtin_names, check_profile, parse_keywords, read_text_file, read_wind_field, Mission, Vehicle,
};

use super::vehicles::Fleet;

/// A file given on the command line.
pub(super) struct Given {
    /// As given.
    pub(super) name: String,
    /// What it holds.
    pub(super) content: Content,
}

/// What a given file holds.
pub(super) enum Content {
    /// A mission's text.
    Mission(String),
    /// A log's `aloft log info --format json` answer.
    Log(String),
    /// A vehicle file, read.
    Vehicle(Arc<Vehicle>),
    /// A gridded wind field.
    WindField,
    /// A CSV column map (a `profile`).
    ColumnMap,
}

impl Given {
    /// `mission`, `log`, `vehicle`, `wind_field` or `column_map`.
    pub(super) fn kind(&self) -> &'static str {
        match self.content {
            Content::Mission(_) => "mission",
            Content::Log(_) => "log",
            Content::Vehicle(_) => "vehicle",
            Content::WindField => "wind_field",
            Content::ColumnMap => "column_map",
        }
    }
}

/// Extensions of mission files: a file with one of them that does not read is a bad mission
/// (or, `.toml`, a bad vehicle or column map), any other a bad log.
const MISSION_EXTENSIONS: [&str; 5] = ["plan", "waypoints", "toml", "json", "txt"];

/// Read the files given: each a mission when it reads as one; a `.toml` else a vehicle or a
/// column map; a `.csv` a wind field when it has a wind field's columns; anything else a log (its
/// `log info` answer). A file that is none is bad input, named by the reader of what its
/// extension says it is.
pub(super) fn read_given(paths: &[PathBuf]) -> Result<Vec<Given>> {
    paths.iter().map(|p| read_one(p)).collect()
}

fn read_one(path: &Path) -> Result<Given> {
    let name = path.display().to_string();
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let as_mission = read_text_file(path, "mission file")
        .and_then(|text| Mission::from_text(&text, &name).map(|_| text));
    let content = match as_mission {
        Ok(text) => Content::Mission(text),
        Err(e) if extension == "toml" => toml_file(path, &name).ok_or(e)?,
        Err(e) if MISSION_EXTENSIONS.contains(&extension.as_str()) => return Err(e.into()),
        Err(_) if extension == "csv" && read_wind_field(path).is_ok() => Content::WindField,
        Err(_) => {
            let flags: LogInfoFlags = parse_keywords("aloft serve", &[], &[])?;
            Content::Log(answers::log_info_answer(path, &flags)?)
        }
    };
    Ok(Given { name, content })
}

/// The vehicle files of `--vehicle` (its values that are not built-in names) that were not given
/// positionally too, read: a file that is not a vehicle is bad input, named (a mission among
/// them, taken by `--vehicle` from the files after it, says so).
pub(super) fn read_vehicles(values: &[String], given: &[Given]) -> Result<Vec<Given>> {
    let mut read: Vec<Given> = Vec::new();
    for value in values {
        let known = |g: &Given| g.name == *value && matches!(g.content, Content::Vehicle(_));
        if builtin_names().contains(&value.as_str()) || given.iter().chain(&read).any(known) {
            continue;
        }
        let vehicle = match Vehicle::load(value) {
            Ok(v) => v,
            Err(e) => {
                let is_mission = read_text_file(Path::new(value), "mission file")
                    .is_ok_and(|text| Mission::from_text(&text, value).is_ok());
                if is_mission {
                    anyhow::bail!(
                        "--vehicle {value}: a mission, not a vehicle file (give the files \
                         before --vehicle, or --vehicle before each vehicle file)"
                    );
                }
                return Err(e.into());
            }
        };
        read.push(Given {
            name: value.clone(),
            content: Content::Vehicle(Arc::new(vehicle)),
        });
    }
    Ok(read)
}

/// A TOML file that is not a mission: a vehicle, else a column map.
fn toml_file(path: &Path, name: &str) -> Option<Content> {
    if let Ok(v) = Vehicle::load(name) {
        return Some(Content::Vehicle(Arc::new(v)));
    }
    check_profile(&path.display().to_string())
        .ok()
        .map(|()| Content::ColumnMap)
}

/// The options of a request that name files, resolved to the files given on the command line
/// and the vehicles of the server.
pub(super) struct Names<'a> {
    /// The files given on the command line.
    pub(super) files: &'a [Given],
    /// The vehicles.
    pub(super) vehicles: &'a Fleet,
}

impl Names<'_> {
    /// The value `value` of the file option `key` as the engine is to read it: a built-in as it
    /// is, a given file's path, a vehicle's name in the list (flown from memory:
    /// [`Fleet::vehicle`]); else the message of a 400.
    pub(super) fn resolve(&self, request: &str, key: &str, value: &str) -> Result<String, String> {
        if key == "vehicle" {
            return self.vehicles.resolve_name(value).ok_or_else(|| {
                let known = self.vehicles.names();
                refusal(
                    request,
                    key,
                    value,
                    "a vehicle given to aloft serve or sent to it",
                    &known,
                )
            });
        }
        let builtins: Vec<&str> = match key {
            "profile" => vec!["kaist", "px4"],
            _ => Vec::new(),
        };
        if builtins.contains(&value) {
            return Ok(value.to_string());
        }
        let kind = match key {
            "wind_field" => "wind_field",
            "profile" => "column_map",
            _ => "",
        };
        let given = self.files.iter().filter(|g| g.kind() == kind);
        if let Some(g) = given.clone().find(|g| g.name == value) {
            return Ok(g.name.clone());
        }
        let known: Vec<String> = builtins
            .iter()
            .map(|b| (*b).to_string())
            .chain(given.map(|g| g.name.clone()))
            .collect();
        Err(refusal(
            request,
            key,
            value,
            "a file given to aloft serve",
            &known,
        ))
    }
}

/// The message of a 400 for a file option naming nothing the server has.
fn refusal(request: &str, key: &str, value: &str, what: &str, known: &[String]) -> String {
    let known = match known.is_empty() {
        true => "none: give the file to aloft serve on its command line".to_string(),
        false => known.join(", "),
    };
    format!(
        "'{key}' of {request} names '{value}', which is neither a built-in nor {what} (a \
         request names no other file of the server); known: {known}"
    )
}

/// The vehicle files among the files given, each with the name it was given with.
pub(super) fn vehicles_of(files: &[Given]) -> Vec<(String, Arc<Vehicle>)> {
    files
        .iter()
        .filter_map(|g| match &g.content {
            Content::Vehicle(v) => Some((g.name.clone(), v.clone())),
            _ => None,
        })
        .collect()
}
