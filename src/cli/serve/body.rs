//! Request bodies, read within their limits: a body whose `Content-Length` is over its limit is
//! refused before a byte of it is read (so a client that asked `Expect: 100-continue` is not told
//! to send it); one that grows past its limit as it arrives is refused when it does; one that
//! stops arriving for [`BODY_IDLE_TIMEOUT`] is refused (408). Every refusal is the documented
//! JSON error.
//!
//! | body | limit |
//! |---|---|
//! | a mission (`/api/mission`, `/api/map`, `/api/plan`) | [`MISSION_LIMIT`]: the command line's limit on whole-file inputs, as the text is held and parsed whole |
//! | a log (`/api/log/info`) | `--max-upload-mb` (256 MiB by default): streamed to a file, never held |
//! | a vehicle file (`POST /api/vehicles`) | [`VEHICLE_LIMIT`]: held and parsed whole, and kept (parsed) in memory |

use axum::body::{Body, Bytes};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::Response;
use futures_util::{Stream, StreamExt};

use super::conn::BODY_IDLE_TIMEOUT;
use super::{error, Refused};

/// Largest mission body, bytes.
pub(super) const MISSION_LIMIT: usize = aloft::engine::MAX_INPUT_BYTES as usize;

/// Largest vehicle file body, bytes: the built-in files are 2-5 KiB, and a vehicle sent is kept
/// in memory (at most [`super::vehicles::MAX_SENT`] of them).
pub(super) const VEHICLE_LIMIT: usize = 256 << 10;

/// 413 when the body's declared length is over `limit` bytes (`what` names the limit).
pub(super) fn within_declared(
    headers: &HeaderMap,
    limit: usize,
    what: &str,
) -> Result<(), Refused> {
    let declared = headers
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<u64>().ok());
    match declared {
        Some(d) if d > limit as u64 => Err(too_large(limit, what).into()),
        _ => Ok(()),
    }
}

/// 413 naming the limit (in MiB, or KiB below one).
pub(super) fn too_large(limit: usize, what: &str) -> Response {
    let size = match limit < 1 << 20 {
        true => format!("{} KiB", limit.div_ceil(1 << 10)),
        false => format!("{} MiB", limit.div_ceil(1 << 20)),
    };
    error(
        StatusCode::PAYLOAD_TOO_LARGE,
        &format!("the body is larger than the limit ({size}, {what})"),
    )
}

/// A whole body of at most `limit` bytes.
pub(super) async fn read_whole(body: Body, limit: usize, what: &str) -> Result<Bytes, Response> {
    let mut chunks = body.into_data_stream();
    let mut whole: Vec<u8> = Vec::new();
    while let Some(chunk) = next_chunk(&mut chunks).await? {
        if whole.len() + chunk.len() > limit {
            return Err(too_large(limit, what));
        }
        whole.extend_from_slice(&chunk);
    }
    Ok(Bytes::from(whole))
}

/// The next chunk of a body, `None` at its end; 408 after [`BODY_IDLE_TIMEOUT`] without one,
/// 400 when the connection fails under it.
pub(super) async fn next_chunk<S, E>(chunks: &mut S) -> Result<Option<Bytes>, Response>
where
    S: Stream<Item = Result<Bytes, E>> + Unpin,
    E: std::fmt::Display,
{
    match tokio::time::timeout(BODY_IDLE_TIMEOUT, chunks.next()).await {
        Err(_) => Err(error(
            StatusCode::REQUEST_TIMEOUT,
            &format!(
                "the body stopped arriving (nothing for {} s)",
                BODY_IDLE_TIMEOUT.as_secs()
            ),
        )),
        Ok(None) => Ok(None),
        Ok(Some(Ok(chunk))) => Ok(Some(chunk)),
        Ok(Some(Err(e))) => Err(error(
            StatusCode::BAD_REQUEST,
            &format!("the body could not be read: {e}"),
        )),
    }
}
