//! `aloft serve`: a local web server, the mission on a map and a JSON API that is the command
//! line.
//!
//! | request | answer |
//! |---|---|
//! | `GET /` | the page (its files built into the binary: [`assets`]) |
//! | `GET /api/config` | the files given on the command line, the tile layer, whether a flight is followed |
//! | `GET /api/vehicles` | `aloft vehicles --format json` |
//! | `GET /api/endurance?OPTIONS` | `aloft endurance OPTIONS --format json` |
//! | `POST /api/mission?file=NAME&OPTIONS` (body: the mission file; empty: the built-in demo) | `aloft mission NAME OPTIONS --format json` |
//! | `POST /api/map?file=NAME&OPTIONS` (as `/api/mission`) | the route, point of no return and state of charge over time that the page draws ([`aloft::engine::MissionMap`]) |
//! | `POST /api/log/info?file=NAME&OPTIONS` (body: the log) | `aloft log info NAME OPTIONS --format json` |
//! | `GET /api/files/N` | the N-th file given on the command line (a mission's text) |
//! | `GET /api/files/N/info` | `aloft log info FILE --format json` of the N-th file, a log |
//! | `GET /api/live` | with `--live` or `--tlog`: the updates of `aloft live --format json`, as server-sent events |
//!
//! OPTIONS are the command's flags in snake_case, as the Python package's keywords
//! (`payload_kg=0.5`, `no_ground_effect=true`); `file` names the upload as the command line would
//! be given it (its name in the answer). Every answer is the engine's
//! ([`aloft::engine::answers`]), so it is the command line's text; an infeasible mission is an
//! answer (200). Errors: 400 with `{"error": ...}` for options the command does not take, 422
//! for a request the engine refuses (the command line's one-line message), 413 for an upload
//! past `--max-upload-mb`, 403 for a `Host` that is not the listening address (a page elsewhere
//! reaching the server through DNS rebinding), 404 for anything else.

mod api;
mod assets;
mod files;
mod live;

use std::io::Write;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context, Result};
use axum::extract::{DefaultBodyLimit, Request, State};
use axum::http::{header, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use clap::Args;

use aloft::engine::DEFAULT_VEHICLE;

use super::Outcome;

#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Missions (`.plan`, `.waypoints`, `.toml`, `.json`) and flight logs to open on the page.
    #[arg(value_name = "FILE")]
    files: Vec<PathBuf>,
    /// Address to listen on (loopback by default: the page is for this machine).
    #[arg(long, default_value = "127.0.0.1:8080", value_name = "HOST:PORT")]
    listen: SocketAddr,
    /// Largest upload (a mission or a log), MiB.
    #[arg(long, default_value_t = 256, value_name = "MIB")]
    max_upload_mb: usize,
    /// A tile layer under the route, as a URL template with `{z}`, `{x}` and `{y}` (none by
    /// default: the route over a plain background, offline).
    #[arg(long, value_name = "URL", requires = "attribution")]
    tiles: Option<String>,
    /// The tile layer's attribution, shown on the map (required with `--tiles`).
    #[arg(long, value_name = "TEXT", requires = "tiles")]
    attribution: Option<String>,
    /// Follow a flight on a MAVLink link (`udpin:`, `udpout:`, `tcpout:`, `serial:`, as
    /// `aloft live --connect`) and stream its estimates to the page.
    #[arg(long, value_name = "URL", conflicts_with = "tlog")]
    live: Option<String>,
    /// Follow a flight from a telemetry log (as `aloft live --tlog`).
    #[arg(long, value_name = "FILE")]
    tlog: Option<PathBuf>,
    /// Playback speed of `--tlog`: `max` or times its own time (as `aloft live --speed`).
    #[arg(long, value_name = "X|max", requires = "tlog")]
    speed: Option<String>,
    /// The vehicle followed by `--live` / `--tlog`: a built-in name or a vehicle TOML file.
    #[arg(long, default_value = DEFAULT_VEHICLE, value_name = "NAME|FILE")]
    vehicle: String,
    /// Its battery pack (default: the vehicle's first).
    #[arg(long)]
    battery: Option<String>,
}

/// What every request shares.
struct Shared {
    /// The `Host` values accepted: the listening address, and `localhost` on loopback.
    hosts: Vec<String>,
    /// The files given on the command line.
    files: Vec<files::Given>,
    /// The tile layer: URL template and attribution.
    tiles: Option<(String, String)>,
    /// The followed flight's updates, with `--live` or `--tlog`.
    live: Option<live::Feed>,
    /// Largest upload, bytes.
    max_upload: usize,
}

pub fn run(args: ServeArgs) -> Result<Outcome> {
    if let Some(t) = &args.tiles {
        if !["{z}", "{x}", "{y}"].iter().all(|k| t.contains(k)) {
            anyhow::bail!("--tiles '{t}': the URL template needs {{z}}, {{x}} and {{y}}");
        }
    }
    let given = files::read_given(&args.files)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the server's runtime")?;
    runtime.block_on(serve(args, given))?;
    Ok(Outcome::Ok)
}

async fn serve(args: ServeArgs, given: Vec<files::Given>) -> Result<()> {
    let listener = tokio::net::TcpListener::bind(args.listen)
        .await
        .with_context(|| format!("--listen {}: cannot listen there", args.listen))?;
    let local = listener.local_addr()?;
    let live = live::start(&args)?;
    let max_upload = args.max_upload_mb.saturating_mul(1 << 20);
    let shared = Arc::new(Shared {
        hosts: accepted_hosts(local),
        files: given,
        tiles: args.tiles.zip(args.attribution),
        live,
        max_upload,
    });
    let app = Router::new()
        .route("/api/config", get(api::config))
        .route("/api/vehicles", get(api::vehicles))
        .route("/api/endurance", get(api::endurance))
        .route("/api/mission", post(api::mission))
        .route("/api/map", post(api::map))
        .route("/api/log/info", post(files::log_info))
        .route("/api/files/{index}", get(files::given_file))
        .route("/api/files/{index}/info", get(files::given_log_info))
        .route("/api/live", get(live::events))
        .fallback(get(assets::asset))
        .layer(DefaultBodyLimit::max(max_upload))
        .layer(middleware::from_fn_with_state(shared.clone(), check_host))
        .with_state(shared);
    let mut out = std::io::stdout().lock();
    writeln!(out, "aloft serve: http://{local}/ (Ctrl-C to stop)")?;
    out.flush()?;
    drop(out);
    axum::serve(listener, app).await.context("serving")?;
    Ok(())
}

/// The `Host` values of a server at `local`: the address itself, and on loopback `localhost`
/// and `127.0.0.1` / `[::1]` with its port.
fn accepted_hosts(local: SocketAddr) -> Vec<String> {
    let port = local.port();
    let mut hosts = vec![local.to_string()];
    if local.ip().is_loopback() {
        hosts.extend([
            format!("localhost:{port}"),
            format!("127.0.0.1:{port}"),
            format!("[::1]:{port}"),
        ]);
    }
    hosts
}

/// Refuse a request whose `Host` is not the server's own (DNS rebinding).
async fn check_host(State(shared): State<Arc<Shared>>, request: Request, next: Next) -> Response {
    let host = request
        .headers()
        .get(header::HOST)
        .and_then(|h| h.to_str().ok())
        .unwrap_or("");
    if !shared.hosts.iter().any(|h| h.eq_ignore_ascii_case(host)) {
        return error(
            StatusCode::FORBIDDEN,
            &format!("Host '{host}' is not this server's ({})", shared.hosts[0]),
        );
    }
    next.run(request).await
}

/// A JSON error answer.
fn error(status: StatusCode, message: &str) -> Response {
    let body = serde_json::json!({ "error": message }).to_string();
    (status, [(header::CONTENT_TYPE, json_type())], body).into_response()
}

fn json_type() -> HeaderValue {
    HeaderValue::from_static("application/json")
}

/// An engine answer: its JSON text, or the command line's message with 422.
fn answer(result: Result<String, aloft::Error>) -> Response {
    match result {
        Ok(text) => (StatusCode::OK, [(header::CONTENT_TYPE, json_type())], text).into_response(),
        Err(e) => error(StatusCode::UNPROCESSABLE_ENTITY, &super::engine_message(e)),
    }
}

/// The engine's work of a request on the blocking pool, and its answer.
async fn blocking(
    work: impl FnOnce() -> Result<String, aloft::Error> + Send + 'static,
) -> Response {
    answer(on_blocking_pool(work).await)
}

/// The engine's work of a request on the blocking pool (the server's threads go on serving).
async fn on_blocking_pool(
    work: impl FnOnce() -> Result<String, aloft::Error> + Send + 'static,
) -> Result<String, aloft::Error> {
    tokio::task::spawn_blocking(work)
        .await
        .unwrap_or_else(join_error)
}

/// A request's work that panicked: never expected (the engine does not panic on any input), said
/// as an error rather than taking the server down.
fn join_error(e: tokio::task::JoinError) -> Result<String, aloft::Error> {
    Err(aloft::Error::Link(format!(
        "the request's work failed: {e}"
    )))
}
