//! `aloft serve`: a local web server whose JSON API is the command line (first step of the page:
//! the API and its guards; the map page comes next).
//!
//! | request | answer |
//! |---|---|
//! | `GET /api/vehicles` | `aloft vehicles --format json` |
//! | `GET /api/endurance?OPTIONS` | `aloft endurance OPTIONS --format json` |
//! | `POST /api/mission?OPTIONS` (body: the mission file; empty: the built-in demo) | `aloft mission FILE OPTIONS --format json` |
//!
//! OPTIONS are the command's flags in snake_case, as the Python package's keywords
//! (`payload_kg=0.5`, `no_ground_effect=true`); `file` names the upload as the command line would
//! be given it (its name in the answer). Logs (`log info`), the map page and the live stream are
//! the next steps. Every answer is the engine's
//! ([`aloft::engine::answers`]), so it is the command line's text; an infeasible mission is an
//! answer (200). Errors: 400 with `{"error": ...}` for options the command does not take, 422
//! for a request the engine refuses (the command line's one-line message), 413 for an upload
//! past `--max-upload-mb`, 403 for a `Host` that is not the listening address (a page elsewhere
//! reaching the server through DNS rebinding).

use std::io::Write;
use std::net::SocketAddr;
use std::sync::Arc;

use anyhow::{Context, Result};
use axum::body::Bytes;
use axum::extract::{DefaultBodyLimit, Query, Request, State};
use axum::http::{header, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use clap::Args;

use aloft::engine::answers;
use aloft::engine::flags::{EnduranceFlags, MissionScenarioFlags};
use aloft::engine::{parse_keywords, FlagGroup, Keyword, Mission};

use super::Outcome;

#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Address to listen on (loopback by default: the page is for this machine).
    #[arg(long, default_value = "127.0.0.1:8080", value_name = "HOST:PORT")]
    listen: SocketAddr,
    /// Largest upload (a mission or a log), MiB.
    #[arg(long, default_value_t = 256, value_name = "MIB")]
    max_upload_mb: usize,
}

/// What every request shares.
struct Shared {
    /// The `Host` values accepted: the listening address, and `localhost` on loopback.
    hosts: Vec<String>,
}

pub fn run(args: ServeArgs) -> Result<Outcome> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the server's runtime")?;
    runtime.block_on(serve(args))?;
    Ok(Outcome::Ok)
}

async fn serve(args: ServeArgs) -> Result<()> {
    let listener = tokio::net::TcpListener::bind(args.listen)
        .await
        .with_context(|| format!("--listen {}: cannot listen there", args.listen))?;
    let local = listener.local_addr()?;
    let shared = Arc::new(Shared {
        hosts: accepted_hosts(local),
    });
    let app = Router::new()
        .route("/api/vehicles", get(vehicles))
        .route("/api/endurance", get(endurance))
        .route("/api/mission", post(mission))
        .layer(DefaultBodyLimit::max(
            args.max_upload_mb.saturating_mul(1 << 20),
        ))
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

/// The query's options (all but `file`) as the command's flag group, or the message of a 400.
fn flags<T: FlagGroup>(function: &str, query: &[(String, String)]) -> Result<T, String> {
    // Each key's values, in order: one is a value (or a switch), several are a list.
    let mut values: Vec<(&String, Vec<&str>)> = Vec::new();
    for (k, v) in query.iter().filter(|(k, _)| k != "file") {
        match values.iter_mut().find(|(g, _)| *g == k) {
            Some((_, vs)) => vs.push(v),
            None => values.push((k, vec![v])),
        }
    }
    let given: Vec<(String, Keyword)> = values
        .into_iter()
        .map(|(k, vs)| {
            let value = match vs.as_slice() {
                ["true"] => Keyword::Switch(true),
                ["false"] => Keyword::Switch(false),
                [one] => Keyword::One((*one).into()),
                many => Keyword::Many(many.iter().map(|v| (*v).into()).collect()),
            };
            (k.clone(), value)
        })
        .collect();
    parse_keywords::<T>(function, &[], &given).map_err(super::engine_message)
}

/// The upload's name (`file=`), else `default`.
fn file_name(query: &[(String, String)], default: &str) -> String {
    query
        .iter()
        .find(|(k, _)| k == "file")
        .map_or_else(|| default.to_string(), |(_, v)| v.clone())
}

async fn vehicles() -> Response {
    blocking(answers::vehicles_answer).await
}

async fn endurance(Query(query): Query<Vec<(String, String)>>) -> Response {
    let flags: EnduranceFlags = match flags("endurance", &query) {
        Ok(f) => f,
        Err(m) => return error(StatusCode::BAD_REQUEST, &m),
    };
    let run = move || answers::endurance_answer(&flags);
    blocking(run).await
}

async fn mission(Query(query): Query<Vec<(String, String)>>, body: Bytes) -> Response {
    let flags: MissionScenarioFlags = match flags("mission", &query) {
        Ok(f) => f,
        Err(m) => return error(StatusCode::BAD_REQUEST, &m),
    };
    let origin = file_name(&query, "upload");
    let run = move || {
        let mission = match body.is_empty() {
            true => Mission::demo(),
            false => {
                let text = std::str::from_utf8(&body).map_err(|_| aloft::Error::MissionFormat {
                    origin: origin.clone(),
                    message: "not UTF-8 text".to_string(),
                })?;
                Mission::from_text(text, &origin)?
            }
        };
        answers::mission_answer_for(&mission, &flags)
    };
    blocking(run).await
}

/// The engine's work of a request on the blocking pool, and its answer.
async fn blocking(
    work: impl FnOnce() -> Result<String, aloft::Error> + Send + 'static,
) -> Response {
    answer(
        tokio::task::spawn_blocking(work)
            .await
            .unwrap_or_else(join_error),
    )
}

/// A request's work that panicked: never expected (the engine does not panic on any input), said
/// as an error rather than taking the server down.
fn join_error(e: tokio::task::JoinError) -> Result<String, aloft::Error> {
    Err(aloft::Error::Link(format!(
        "the request's work failed: {e}"
    )))
}
