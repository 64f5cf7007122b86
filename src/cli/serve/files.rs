//! Files: those given on the command line (read once at start) and the logs uploaded to
//! `POST /api/log/info`.
//!
//! **Given files** are what a request may name: a mission (its text is served), a log (its
//! `log info` answer), a vehicle, a wind field, a column map. An option of a request that names a
//! file (`vehicle`, `wind_field`, `profile`: [`aloft::engine::file_keywords`]) may name a
//! built-in (`vehicle=dji-m100`, `profile=kaist`) or a file given to `serve`, by the name it was
//! given with (a vehicle also by its own name), never any other path of the server ([`Names`]).
//!
//! **Uploads** are streamed into a private folder of the server's (a random name, mode 0700,
//! [`tempfile`]), each to a new file of its own that is created, never opened through a link,
//! and removed after its answer; the folder goes with the server (Ctrl-C and SIGTERM included).
//! An upload's name must be a file name of at most 255 bytes without NUL (400 otherwise).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use anyhow::Result;
use axum::body::Body;
use axum::extract::{Path as UrlPath, Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use tokio::io::AsyncWriteExt;

use aloft::engine::answers;
use aloft::engine::flags::LogInfoFlags;
use aloft::engine::{
    builtin_names, check_profile, parse_keywords, read_text_file, read_wind_field, Mission, Vehicle,
};

use super::api::{file_name, flags, Answered, QueryPairs};
use super::body::{next_chunk, too_large, within_declared};
use super::{answer, engine_message, error, Shared};

/// A file given on the command line.
pub(super) struct Given {
    /// As given.
    pub(super) name: String,
    /// What it holds.
    content: Content,
}

enum Content {
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

/// The file given at `index` (a number in the URL; anything else is no file).
fn given<'a>(shared: &'a Shared, index: &str) -> Option<&'a Given> {
    let k: usize = index.parse().ok()?;
    shared.files.get(k)
}

/// `GET /api/files/N`: a given mission's text.
pub(super) async fn given_file(
    State(shared): State<Arc<Shared>>,
    UrlPath(index): UrlPath<String>,
) -> Response {
    match given(&shared, &index).map(|g| &g.content) {
        Some(Content::Mission(text)) => (
            StatusCode::OK,
            [(header::CONTENT_TYPE, "text/plain; charset=utf-8")],
            text.clone(),
        )
            .into_response(),
        Some(_) => error(
            StatusCode::NOT_FOUND,
            &format!("file {index} is not a mission"),
        ),
        None => error(StatusCode::NOT_FOUND, &format!("no file {index}")),
    }
}

/// `GET /api/files/N/info`: a given log's `log info` answer.
pub(super) async fn given_log_info(
    State(shared): State<Arc<Shared>>,
    UrlPath(index): UrlPath<String>,
) -> Response {
    match given(&shared, &index).map(|g| &g.content) {
        Some(Content::Log(text)) => answer(Ok(text.clone())),
        Some(_) => error(StatusCode::NOT_FOUND, &format!("file {index} is not a log")),
        None => error(StatusCode::NOT_FOUND, &format!("no file {index}")),
    }
}

/// `POST /api/log/info?file=NAME&OPTIONS`: `aloft log info NAME OPTIONS --format json` of the
/// body.
pub(super) async fn log_info(
    State(shared): State<Arc<Shared>>,
    headers: HeaderMap,
    Query(query): QueryPairs,
    body: Body,
) -> Answered {
    within_declared(&headers, shared.max_upload, "--max-upload-mb")?;
    let flags: LogInfoFlags = flags("POST /api/log/info", &query, &shared)?;
    let name = file_name(&query, "upload");
    let upload = Upload::receive(&shared.uploads, &name, body, shared.max_upload).await?;
    let path = upload.path.clone();
    let work = move |_: &_| {
        // The readers name the file they read: the upload's own, named as it was sent.
        answers::log_info_answer_as(&path, &name, &flags)
            .map_err(|e| engine_message(e).replace(&path.display().to_string(), &name))
    };
    let response = shared.work.run(work).await;
    drop(upload);
    Ok(response)
}

/// Uploads so far (each its own folder in the uploads' folder).
static UPLOADS: AtomicU64 = AtomicU64::new(0);

/// An upload in a folder of its own inside the server's private folder, removed when dropped.
struct Upload {
    dir: PathBuf,
    path: PathBuf,
}

/// The file name of an upload named `name` (its last path component), or the message of a 400.
fn upload_file_name(name: &str) -> Result<&str, String> {
    if name.contains('\0') {
        return Err("the upload's name holds a NUL byte".to_string());
    }
    let base = match name.rsplit(['/', '\\']).next() {
        Some(b) if !b.is_empty() && b != "." && b != ".." => b,
        _ => "upload",
    };
    if base.len() > 255 {
        return Err(format!(
            "the upload's file name is {} bytes long, more than the 255 a file name may have",
            base.len()
        ));
    }
    Ok(base)
}

impl Upload {
    /// Stream `body` into a new file named as the upload (see [`upload_file_name`]) in a new
    /// folder of `root`, refusing it past `limit` bytes (413).
    async fn receive(root: &Path, name: &str, body: Body, limit: usize) -> Result<Self, Response> {
        let base = upload_file_name(name).map_err(|m| error(StatusCode::BAD_REQUEST, &m))?;
        let failed = |e: std::io::Error| {
            error(
                StatusCode::INTERNAL_SERVER_ERROR,
                &format!("cannot keep the upload: {e}"),
            )
        };
        let n = UPLOADS.fetch_add(1, Ordering::Relaxed);
        let dir = root.join(n.to_string());
        // A new folder and a new file: neither can be a link planted before (`create_new` does
        // not follow one), and the private folder keeps other users out.
        tokio::fs::create_dir(&dir).await.map_err(failed)?;
        let upload = Self {
            path: dir.join(base),
            dir,
        };
        let mut file = tokio::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&upload.path)
            .await
            .map_err(failed)?;
        let mut chunks = body.into_data_stream();
        let mut size = 0usize;
        while let Some(chunk) = next_chunk(&mut chunks).await? {
            size += chunk.len();
            if size > limit {
                return Err(too_large(limit, "--max-upload-mb"));
            }
            file.write_all(&chunk).await.map_err(failed)?;
        }
        file.flush().await.map_err(failed)?;
        Ok(upload)
    }
}

impl Drop for Upload {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn upload_names_are_file_names() {
        assert_eq!(upload_file_name("a/b/log.ulg"), Ok("log.ulg"));
        assert_eq!(upload_file_name("..\\..\\x.bin"), Ok("x.bin"));
        assert_eq!(upload_file_name(".."), Ok("upload"));
        assert_eq!(upload_file_name("dir/"), Ok("upload"));
        assert!(upload_file_name("a\0b").is_err());
        assert!(upload_file_name(&"x".repeat(256)).is_err());
        assert_eq!(upload_file_name(&"x".repeat(255)).map(str::len), Ok(255));
    }
}
