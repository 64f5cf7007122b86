//! Files: those given on the command line (read once at start: a mission's text, a log's
//! `log info` answer) and logs uploaded to `POST /api/log/info`, streamed to a temporary file of
//! the upload's name (the readers take a file; the body is never held in memory whole) and
//! removed after the answer.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use anyhow::Result;
use axum::body::Body;
use axum::extract::{Path as UrlPath, Query, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use futures_util::StreamExt;
use tokio::io::AsyncWriteExt;

use aloft::engine::answers;
use aloft::engine::flags::LogInfoFlags;
use aloft::engine::{read_text_file, Mission};

use super::api::{file_name, flags, QueryPairs};
use super::{answer, error, Shared};

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
}

impl Given {
    /// `mission` or `log`.
    pub(super) fn kind(&self) -> &'static str {
        match self.content {
            Content::Mission(_) => "mission",
            Content::Log(_) => "log",
        }
    }
}

/// Extensions of mission files: a file with one of them that does not read is a bad mission,
/// any other a bad log.
const MISSION_EXTENSIONS: [&str; 5] = ["plan", "waypoints", "toml", "json", "txt"];

/// Read the files given: each a mission when it reads as one, else a log (its `log info`
/// answer); a file that is neither is bad input, named by the mission reader's message when its
/// extension is a mission's, else the log reader's.
pub(super) fn read_given(paths: &[PathBuf]) -> Result<Vec<Given>> {
    paths.iter().map(|p| read_one(p)).collect()
}

fn read_one(path: &Path) -> Result<Given> {
    let name = path.display().to_string();
    let mission_like = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| MISSION_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()));
    let as_mission = read_text_file(path, "mission file")
        .and_then(|text| Mission::from_text(&text, &name).map(|_| text));
    let content = match as_mission {
        Ok(text) => Content::Mission(text),
        Err(e) if mission_like => return Err(e.into()),
        Err(_) => {
            let flags: LogInfoFlags = flags("aloft serve", &[]).map_err(anyhow::Error::msg)?;
            Content::Log(answers::log_info_answer(path, &flags)?)
        }
    };
    Ok(Given { name, content })
}

/// The file given at `index` (a number in the URL; anything else is no file).
fn given<'a>(shared: &'a Shared, index: &str) -> Option<&'a Content> {
    let k: usize = index.parse().ok()?;
    shared.files.get(k).map(|f| &f.content)
}

/// `GET /api/files/N`: a given mission's text.
pub(super) async fn given_file(
    State(shared): State<Arc<Shared>>,
    UrlPath(index): UrlPath<String>,
) -> Response {
    match given(&shared, &index) {
        Some(Content::Mission(text)) => (
            StatusCode::OK,
            [(header::CONTENT_TYPE, "text/plain; charset=utf-8")],
            text.clone(),
        )
            .into_response(),
        Some(Content::Log(_)) => error(StatusCode::NOT_FOUND, &format!("file {index} is a log")),
        None => error(StatusCode::NOT_FOUND, &format!("no file {index}")),
    }
}

/// `GET /api/files/N/info`: a given log's `log info` answer.
pub(super) async fn given_log_info(
    State(shared): State<Arc<Shared>>,
    UrlPath(index): UrlPath<String>,
) -> Response {
    match given(&shared, &index) {
        Some(Content::Log(text)) => answer(Ok(text.clone())),
        Some(Content::Mission(_)) => {
            error(StatusCode::NOT_FOUND, &format!("file {index} is a mission"))
        }
        None => error(StatusCode::NOT_FOUND, &format!("no file {index}")),
    }
}

/// `POST /api/log/info?file=NAME&OPTIONS`: `aloft log info NAME OPTIONS --format json` of the
/// body.
pub(super) async fn log_info(
    State(shared): State<Arc<Shared>>,
    Query(query): QueryPairs,
    body: Body,
) -> Response {
    let flags: LogInfoFlags = match flags("POST /api/log/info", &query) {
        Ok(f) => f,
        Err(m) => return error(StatusCode::BAD_REQUEST, &m),
    };
    let name = file_name(&query, "upload");
    let upload = match Upload::receive(&name, body, shared.max_upload).await {
        Ok(u) => u,
        Err(response) => return response,
    };
    let (path, shown) = (upload.path.clone(), name.clone());
    let work = move || answers::log_info_answer_as(&path, &shown, &flags);
    let response = match super::on_blocking_pool(work).await {
        Ok(text) => answer(Ok(text)),
        // The readers' messages name the file they read: the temporary file, named as sent.
        Err(e) => error(
            StatusCode::UNPROCESSABLE_ENTITY,
            &super::super::engine_message(e).replace(&upload.path.display().to_string(), &name),
        ),
    };
    drop(upload);
    response
}

/// Uploads so far (each its own directory).
static UPLOADS: AtomicU64 = AtomicU64::new(0);

/// An upload in a temporary directory of its own, removed when dropped.
struct Upload {
    dir: PathBuf,
    path: PathBuf,
}

impl Upload {
    /// Stream `body` into a file named as the upload's last path component (`upload` when it has
    /// none), refusing it past `limit` bytes (413).
    async fn receive(name: &str, body: Body, limit: usize) -> Result<Self, Response> {
        let base = Path::new(name)
            .file_name()
            .and_then(|n| n.to_str())
            .filter(|n| !n.is_empty())
            .unwrap_or("upload");
        let n = UPLOADS.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("aloft-serve-{}-{n}", std::process::id()));
        let failed = |e: std::io::Error| {
            error(
                StatusCode::INTERNAL_SERVER_ERROR,
                &format!("cannot keep the upload: {e}"),
            )
        };
        tokio::fs::create_dir_all(&dir).await.map_err(failed)?;
        let upload = Self {
            path: dir.join(base),
            dir,
        };
        let mut file = tokio::fs::File::create(&upload.path)
            .await
            .map_err(failed)?;
        let mut stream = body.into_data_stream();
        let mut size = 0usize;
        while let Some(chunk) = stream.next().await {
            let chunk = chunk
                .map_err(|e| error(StatusCode::BAD_REQUEST, &format!("the upload failed: {e}")))?;
            size += chunk.len();
            if size > limit {
                return Err(too_large(limit.div_ceil(1 << 20)));
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

/// 413 with the limit.
fn too_large(limit_mib: usize) -> Response {
    error(
        StatusCode::PAYLOAD_TOO_LARGE,
        &format!("the upload is larger than the limit ({limit_mib} MiB, --max-upload-mb)"),
    )
}
