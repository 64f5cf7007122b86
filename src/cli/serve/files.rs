//! Uploads to `POST /api/log/info`, and the given files served back (`GET /api/files/N`).
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
use aloft::engine::safe_stem;

use super::api::{file_name, flags, Answered, QueryPairs};
use super::body::{next_chunk, too_large, within_declared};
use super::given::{Content, Given};
use super::{answer, engine_message, error, Shared};

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

/// The file name an upload named `name` is kept under: aloft's rule for a name taken from an
/// input ([`safe_stem`]: the last path component, every character outside `A-Z a-z 0-9 . _ -`
/// replaced, no leading dot or dash), its extension kept when it is plain letters and digits
/// (the readers tell `.ulg`, `.bin`, `.tlog`, `.csv` by it); `upload` when nothing is left. The
/// client's name is only ever shown (in messages), never used as a path. A NUL byte or a name
/// over 255 bytes is the message of a 400.
fn upload_file_name(name: &str) -> Result<String, String> {
    if name.contains('\0') {
        return Err("the upload's name holds a NUL byte".to_string());
    }
    if name.len() > 255 {
        return Err(format!(
            "the upload's file name is {} bytes long, more than the 255 a file name may have",
            name.len()
        ));
    }
    // Both separators: a name from a Windows browser is a path there.
    let base = name.rsplit(['/', '\\']).next().unwrap_or(name);
    let stem = safe_stem(Path::new(base)).unwrap_or_else(|| "upload".to_string());
    let extension = Path::new(base)
        .extension()
        .and_then(|e| e.to_str())
        .filter(|e| e.len() <= 16 && !e.is_empty() && e.chars().all(|c| c.is_ascii_alphanumeric()));
    Ok(match extension {
        Some(e) => format!("{stem}.{e}"),
        None => stem,
    })
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
            path: dir.join(&base),
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
    fn upload_names_are_safe_file_names() {
        let name = |n: &str| upload_file_name(n).unwrap();
        assert_eq!(name("a/b/log.ulg"), "log.ulg");
        assert_eq!(name("..\\..\\x.bin"), "x.bin");
        assert_eq!(name(".."), "upload");
        assert_eq!(name("dir/"), "upload");
        assert_eq!(
            name("<img src=x onerror=alert(1)>.plan"),
            "_img_src_x_onerror_alert_1__.plan"
        );
        assert_eq!(name("flight 3\n\u{202E}gol.ulg"), "flight_3__gol.ulg");
        assert_eq!(name(".hidden.csv"), "_hidden.csv");
        assert_eq!(name("x.t<b>"), "x");
        assert!(upload_file_name("a\0b").is_err());
        assert!(upload_file_name(&"x".repeat(256)).is_err());
        assert_eq!(name(&"x".repeat(255)).len(), 100);
    }
}
