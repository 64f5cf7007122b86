//! The followed flight of `aloft serve --live URL` / `--tlog FILE`: `aloft live` runs on a thread
//! of its own (the engine's [`follow_live`], as the command line's), and each update is sent to
//! every page that listens on `GET /api/live`, as server-sent events:
//!
//! - `update`: one update, the JSON of a line of `aloft live --format json`;
//! - `end`: the flight's end, `{"summary": ...}` or `{"error": "..."}`.
//!
//! A page that connects late gets the last update at once.

use std::convert::Infallible;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use anyhow::{Context, Result};
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use futures_util::stream::{self, Stream};
use tokio::sync::broadcast;

use aloft::engine::flags::{LiveFlags, LiveTask};
use aloft::engine::{follow_live, Keyword, Vehicle};

use super::{error, ServeArgs, Shared};

/// Updates a slow page may fall behind by before it skips to the newest.
const BACKLOG: usize = 64;

/// The followed flight's updates.
pub(super) struct Feed {
    tx: broadcast::Sender<(&'static str, String)>,
    /// The last message sent (a late page starts from it).
    last: Arc<Mutex<Option<(&'static str, String)>>>,
}

/// Start following the flight of `--live` / `--tlog`, if one is given, with `vehicle` (the
/// first `--vehicle`, read at start) and `battery` (the pack of `--battery`, by its name among
/// the vehicle's packs): its source opened here (a bad address or file is bad
/// input, before the server starts), followed on a thread.
pub(super) fn start(
    args: &ServeArgs,
    vehicle: Arc<Vehicle>,
    battery: Option<String>,
) -> Result<Option<Feed>> {
    let mut given: Vec<(String, Keyword)> = Vec::new();
    let one = |k: &str, v: String| (k.to_string(), Keyword::One(v.into()));
    match (&args.live, &args.tlog) {
        (Some(url), _) => given.push(one("connect", url.clone())),
        (None, Some(path)) => given.push(one("tlog", path.display().to_string())),
        (None, None) => return Ok(None),
    }
    given.extend(args.speed.clone().map(|s| one("speed", s)));
    given.extend(battery.map(|b| one("battery", b)));
    let flags: LiveFlags = parse(&given)?;
    let LiveTask::Follow { source, request } = flags.request()? else {
        anyhow::bail!("--live/--tlog: not a flight to follow");
    };
    // The source is opened on the thread that reads it; whether it opened is said back first.
    let (opened_tx, opened_rx) = std::sync::mpsc::channel();
    let (tx, _) = broadcast::channel(BACKLOG);
    let last = Arc::new(Mutex::new(None));
    let feed = Feed {
        tx: tx.clone(),
        last: last.clone(),
    };
    std::thread::Builder::new()
        .name("aloft-live".into())
        .spawn(move || {
            let mut source = match source.open() {
                Ok(s) => {
                    let _ = opened_tx.send(Ok(()));
                    s
                }
                Err(e) => {
                    let _ = opened_tx.send(Err(e));
                    return;
                }
            };
            let send = |kind: &'static str, text: String| {
                if let Ok(mut l) = last.lock() {
                    *l = Some((kind, text.clone()));
                }
                let _ = tx.send((kind, text));
            };
            let mut emit = |u: &aloft::engine::LiveUpdate| -> Result<(), aloft::Error> {
                send("update", serde_json::to_string(u).unwrap_or_default());
                Ok(())
            };
            let end = match follow_live(&vehicle, &request, source.as_mut(), &mut emit) {
                Ok(summary) => serde_json::json!({ "summary": summary }),
                Err(e) => serde_json::json!({ "error": super::super::engine_message(e) }),
            };
            send("end", end.to_string());
        })
        .context("starting the live thread")?;
    opened_rx
        .recv()
        .context("the live source's thread ended before opening it")??;
    Ok(Some(feed))
}

/// `aloft live`'s flags of the keywords, a bad one as bad input.
fn parse(given: &[(String, Keyword)]) -> Result<LiveFlags> {
    aloft::engine::parse_keywords::<LiveFlags>("aloft serve --live/--tlog", &[], given)
        .map_err(|e| anyhow::Error::msg(super::super::engine_message(e)))
}

/// `GET /api/live`: the updates as server-sent events (404 without `--live` / `--tlog`).
pub(super) async fn events(State(shared): State<Arc<Shared>>) -> Response {
    let Some(feed) = &shared.live else {
        return error(
            StatusCode::NOT_FOUND,
            "no flight is followed (aloft serve --live URL or --tlog FILE)",
        );
    };
    let rx = feed.tx.subscribe();
    let first = feed.last.lock().ok().and_then(|l| l.clone());
    Sse::new(updates(first, rx))
        .keep_alive(KeepAlive::new().interval(Duration::from_secs(15)))
        .into_response()
}

/// The stream of a page: the last message, then each new one (a page that fell behind skips to
/// the newest), until the flight's end.
fn updates(
    first: Option<(&'static str, String)>,
    rx: broadcast::Receiver<(&'static str, String)>,
) -> impl Stream<Item = Result<Event, Infallible>> {
    let start = (first, Some(rx));
    stream::unfold(start, |(first, rx)| async move {
        if let Some((kind, text)) = first {
            let done = kind == "end";
            let next = (None, if done { None } else { rx });
            return Some((Ok(Event::default().event(kind).data(text)), next));
        }
        let mut rx = rx?;
        loop {
            match rx.recv().await {
                Ok((kind, text)) => {
                    let event = Event::default().event(kind).data(text);
                    let rx = if kind == "end" { None } else { Some(rx) };
                    return Some((Ok(event), (None, rx)));
                }
                Err(broadcast::error::RecvError::Lagged(_)) => continue,
                Err(broadcast::error::RecvError::Closed) => return None,
            }
        }
    })
}
