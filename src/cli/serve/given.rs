//! The files given on the command line, read once at start: what a request may name.
//!
//! A given file is a mission (its text is served), a log (its `log info` answer), a vehicle, a
//! wind field or a column map. An option of a request that names a file (`vehicle`,
//! `wind_field`, `profile`: [`aloft::engine::file_keywords`]) may name a built-in
//! (`vehicle=dji-m100`, `profile=kaist`) or a file given to `serve`, by the name it was given
//! with (a vehicle also by its own name), never any other path of the server ([`Names`]).

use std::path::{Path, PathBuf};

use anyhow::Result;

use aloft::engine::answers;
use aloft::engine::flags::LogInfoFlags;
use aloft::engine::{
    builtin_names, check_profile, parse_keywords, read_text_file, read_wind_field, Mission, Vehicle,
};

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
    /// A vehicle file, and the vehicle's own name.
    Vehicle(String),
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

/// A TOML file that is not a mission: a vehicle, else a column map.
fn toml_file(path: &Path, name: &str) -> Option<Content> {
    if let Ok(v) = Vehicle::load(name) {
        return Some(Content::Vehicle(v.name().to_string()));
    }
    check_profile(&path.display().to_string())
        .ok()
        .map(|()| Content::ColumnMap)
}

/// The options of a request that name files, resolved to the files given on the command line.
pub(super) struct Names<'a>(pub(super) &'a [Given]);

impl Names<'_> {
    /// The value `value` of the file option `key` as the engine is to read it: a built-in as it
    /// is, a given file's path; else the message of a 400.
    pub(super) fn resolve(&self, request: &str, key: &str, value: &str) -> Result<String, String> {
        let builtins: Vec<&str> = match key {
            "vehicle" => builtin_names(),
            "profile" => vec!["kaist", "px4"],
            _ => Vec::new(),
        };
        if builtins.contains(&value) {
            return Ok(value.to_string());
        }
        let kind = match key {
            "vehicle" => "vehicle",
            "wind_field" => "wind_field",
            "profile" => "column_map",
            _ => "",
        };
        let given = self.0.iter().filter(|g| g.kind() == kind);
        let by_name =
            |g: &&Given| g.name == value || matches!(&g.content, Content::Vehicle(n) if n == value);
        if let Some(g) = given.clone().find(by_name) {
            return Ok(g.name.clone());
        }
        let known: Vec<String> = builtins
            .iter()
            .map(|b| (*b).to_string())
            .chain(given.map(|g| g.name.clone()))
            .collect();
        let known = match known.is_empty() {
            true => "none: give the file to aloft serve on its command line".to_string(),
            false => known.join(", "),
        };
        Err(format!(
            "'{key}' of {request} names '{value}', which is neither a built-in nor a file given \
             to aloft serve (a request names no other file of the server); known: {known}"
        ))
    }
}
