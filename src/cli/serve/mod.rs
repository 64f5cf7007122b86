//! `aloft serve`: a local web server, the mission on a map and a JSON API that is the command
//! line.
//!
//! | request | answer |
//! |---|---|
//! | `GET /` | the page (its files built into the binary: [`assets`]) |
//! | `GET /api/config` | the files given on the command line, the default vehicle (`default_vehicle`: the first `--vehicle`) and its pack when `--battery` gives one (`default_battery`), the tile layer, whether a flight is followed |
//! | `GET /api/vehicles` | `aloft vehicles --format json`, then the entries of the vehicle files given (`--vehicle FILE...` and positionally) and sent ([`vehicles`]) |
//! | `POST /api/vehicles?file=NAME` (body: a vehicle file, at most 256 KiB) | the vehicle kept in memory under its own name (no built-in's nor given vehicle's: 422), answered with its entry of `/api/vehicles`; at most 32 kept, the oldest forgotten |
//! | `GET /api/endurance?OPTIONS` | `aloft endurance OPTIONS --format json` |
//! | `POST /api/mission?file=NAME&OPTIONS` (body: the mission file; empty: the built-in demo) | `aloft mission NAME OPTIONS --format json` |
//! | `POST /api/map?file=NAME&OPTIONS` (as `/api/mission`) | the route, point of no return and state of charge over time that the page draws ([`aloft::engine::MissionMap`]) |
//! | `POST /api/plan?file=NAME&OPTIONS` (as `/api/mission`, the options of `aloft plan`) | `aloft plan NAME OPTIONS --format json`, with each file's text (`texts`) and each sortie's path (`maps`, [`aloft::engine::SortieMap`]); no file is written |
//! | `POST /api/log/info?file=NAME&OPTIONS` (body: the log) | `aloft log info NAME OPTIONS --format json` |
//! | `GET /api/files/N` | the N-th file given on the command line (a mission's text) |
//! | `GET /api/files/N/info` | `aloft log info FILE --format json` of the N-th file, a log |
//! | `GET /api/live` | with `--live` or `--tlog`: the updates of `aloft live --format json`, as server-sent events |
//! | `GET /api/logbook/KIND` (`flights`, `vehicles`, `packs`, `skipped`) | with `--logbook FILE`: `aloft logbook KIND --db FILE --format json` (404 without `--logbook`) |
//!
//! OPTIONS are the command's flags in snake_case, as the Python package's keywords
//! (`payload_kg=0.5`, `no_ground_effect=true`); `file` names the upload as the command line would
//! be given it (its name in the answer). An option that names a file (`vehicle`, `wind_field`,
//! `profile`) names a built-in or a file given on the command line (a vehicle also one sent to
//! `POST /api/vehicles`), never another file of the server ([`given`]); a request that names no
//! vehicle flies the server's default (the first `--vehicle`, else dji-m100). Every answer is the engine's ([`aloft::engine::answers`]), so it is the
//! command line's text; an infeasible mission is an answer (200), and so is a mission no plan
//! keeps the reserve for (`{"feasible": false, "reason": ...}`, as `aloft plan` answers it).
//!
//! Every answer carries a Content-Security-Policy without inline script and `nosniff`
//! ([`policy`]).
//!
//! Errors, each `{"error": "..."}` quoting at most 80 characters of any value ([`quotes`]): 400
//! for options the command does not take, a file option naming no given file or a request with
//! two `Host` headers, 403 for a request from elsewhere ([`guard`]: a `Host` that is not this
//! server's, a page of another origin), 404 for anything else, 405 for a method a route does
//! not take, 408 for a body that stops
//! arriving, 413 for a body past its limit ([`body`]), 422 for a request the engine refuses (the
//! command line's one-line message, a request for more work than [`work`] allows among them),
//! 503 with `Retry-After` when the server is busy ([`work`]). Connections are bounded in number
//! and time ([`conn`]).

mod api;
mod assets;
mod body;
mod conn;
mod files;
mod given;
mod guard;
mod live;
mod policy;
mod quotes;
mod vehicles;
mod work;

use std::io::Write;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context, Result};
use axum::http::{header, HeaderValue, StatusCode};
use axum::middleware;
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use clap::Args;

use aloft::engine::{answers, DEFAULT_VEHICLE};

use super::Outcome;

#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Files to open on the page and for requests to name: missions (`.plan`, `.waypoints`,
    /// `.toml`, `.json`), flight logs, vehicle files (`vehicle=NAME`), wind fields
    /// (`wind_field=FILE`) and column maps (`profile=FILE`). A request names no other file.
    #[arg(value_name = "FILE")]
    files: Vec<PathBuf>,
    /// Address to listen on (loopback by default: the page is for this machine; `0.0.0.0:PORT`
    /// serves every interface, see docs/reliability.md).
    #[arg(long, default_value = "127.0.0.1:8080", value_name = "HOST:PORT")]
    listen: SocketAddr,
    /// Largest log upload, MiB (a mission's body is limited to 32 MiB, as the command line's
    /// mission files).
    #[arg(long, default_value_t = 256, value_name = "MIB")]
    max_upload_mb: usize,
    /// Most planner steps of one request's scenarios (samples x steps of the flight): a request
    /// for more is refused (422) naming the most samples that fit.
    #[arg(long, default_value_t = work::DEFAULT_MAX_REQUEST_STEPS, value_name = "STEPS",
        value_parser = clap::value_parser!(u64).range(1..))]
    max_request_steps: u64,
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
    /// Vehicles for the page's list and for requests to name (`vehicle=NAME`): built-in names or
    /// vehicle TOML files, each file read once at start. The first is the page's and the
    /// requests' default, and the vehicle followed by `--live` / `--tlog` (default: dji-m100).
    /// Takes several values: give missions and logs before it.
    #[arg(long, value_name = "NAME|FILE", num_args = 1..)]
    vehicle: Vec<String>,
    /// The default vehicle's pack (the first `--vehicle`'s): one of its packs by name, or a
    /// pack file (`aloft pack fit`, `aloft logbook pack-file`) flown as `aloft mission --battery
    /// FILE` flies it. Requests that fly that vehicle and name no pack fly it, and so does
    /// `--live` / `--tlog` (default: the vehicle's own default pack).
    #[arg(long, value_name = "NAME|FILE")]
    battery: Option<String>,
    /// A logbook (`aloft logbook --db FILE`) whose vehicles' and packs' histories the page
    /// charts. Only this file: a request never names a logbook.
    #[cfg(feature = "logbook")]
    #[arg(long, value_name = "FILE")]
    logbook: Option<PathBuf>,
    /// Elevation tiles (SRTM .hgt, .hgt.zip, WGS84 GeoTIFF) under every mission request: each
    /// segment's least height above the ground, terrain-frame items flown over it, the profile
    /// on the page. Only this directory: a request never names one.
    #[arg(long, value_name = "DIR")]
    terrain: Option<PathBuf>,
}

/// What every request shares.
struct Shared {
    /// The names the server answers to.
    hosts: guard::Hosts,
    /// The files given on the command line.
    files: Vec<given::Given>,
    /// The tile layer: URL template and attribution.
    tiles: Option<(String, String)>,
    /// The followed flight's updates, with `--live` or `--tlog`.
    live: Option<live::Feed>,
    /// Largest log upload, bytes.
    max_upload: usize,
    /// The server's private folder of uploads.
    uploads: PathBuf,
    /// The engine's work: permits and bounds.
    work: work::Pool,
    /// The vehicles a request may fly: built-in, given, sent.
    vehicles: vehicles::Fleet,
    /// The logbook given with `--logbook`.
    logbook: Option<PathBuf>,
    /// The terrain tiles given with `--terrain`.
    terrain: Option<PathBuf>,
    /// The Content-Security-Policy of every answer ([`policy`]).
    policy: HeaderValue,
}

pub fn run(args: ServeArgs) -> Result<Outcome> {
    if let Some(t) = &args.tiles {
        if !["{z}", "{x}", "{y}"].iter().all(|k| t.contains(k)) {
            anyhow::bail!("--tiles '{t}': the URL template needs {{z}}, {{x}} and {{y}}");
        }
    }
    let policy = policy::content_policy(args.tiles.as_deref())?;
    let mut given = given::read_given(&args.files)?;
    given.extend(given::read_vehicles(&args.vehicle, &given)?);
    let default = args.vehicle.first().map_or(DEFAULT_VEHICLE, String::as_str);
    let mut fleet = vehicles::Fleet::new(&given::vehicles_of(&given), default)?;
    if let Some(battery) = &args.battery {
        fleet.fly_default_with(battery)?;
    }
    let logbook = logbook_of(&args)?;
    // Tiles that cannot be read stop the server at its start, not each request.
    if let Some(dir) = &args.terrain {
        aloft::engine::terrain::from_flag_or_env(Some(dir))
            .map_err(|e| anyhow::anyhow!("--terrain: {e}"))?;
    }
    let uploads = uploads_folder().context("creating the uploads' folder")?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the server's runtime")?;
    let state = AtStart {
        files: given,
        vehicles: fleet,
        logbook,
        policy,
    };
    let served = runtime.block_on(serve(args, state, uploads.path().to_path_buf()));
    // Work still running for clients that have gone is not waited for; the uploads' folder is
    // removed whatever happened.
    runtime.shutdown_background();
    drop(uploads);
    served?;
    Ok(Outcome::Ok)
}

/// The server's private folder of uploads: a random name in the temporary directory, readable
/// by this user only.
fn uploads_folder() -> std::io::Result<tempfile::TempDir> {
    let mut builder = tempfile::Builder::new();
    builder.prefix("aloft-serve-");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o700));
    }
    builder.tempdir()
}

/// The logbook of `--logbook`: an existing file, opened once here (so that a file that is not
/// a logbook stops the server at its start, and an old one is migrated before any request where
/// it can be written); read-only, as every request reads it.
#[cfg(feature = "logbook")]
fn logbook_of(args: &ServeArgs) -> Result<Option<PathBuf>> {
    let Some(path) = &args.logbook else {
        return Ok(None);
    };
    if !path.is_file() {
        anyhow::bail!("--logbook {}: no such file", path.display());
    }
    aloft_logbook::Logbook::open_read_only(path)?;
    Ok(Some(path.clone()))
}

#[cfg(not(feature = "logbook"))]
fn logbook_of(_: &ServeArgs) -> Result<Option<PathBuf>> {
    Ok(None)
}

/// What the command line gave, read at start.
struct AtStart {
    files: Vec<given::Given>,
    vehicles: vehicles::Fleet,
    logbook: Option<PathBuf>,
    policy: HeaderValue,
}

async fn serve(args: ServeArgs, given: AtStart, uploads: PathBuf) -> Result<()> {
    let listener = tokio::net::TcpListener::bind(args.listen)
        .await
        .with_context(|| format!("--listen {}: cannot listen there", args.listen))?;
    let local = listener.local_addr()?;
    let fleet = &given.vehicles;
    let pack = fleet
        .default_pack(fleet.default_name())
        .map(|p| p.name.clone());
    let live = live::start(&args, fleet.default_vehicle(), pack)?;
    let shared = Arc::new(Shared {
        hosts: guard::Hosts::new(local),
        files: given.files,
        tiles: args.tiles.zip(args.attribution),
        live,
        max_upload: args.max_upload_mb.saturating_mul(1 << 20),
        uploads,
        work: work::Pool::new(args.max_request_steps),
        vehicles: given.vehicles,
        logbook: given.logbook,
        terrain: args.terrain,
        policy: given.policy,
    });
    let app = router(shared);
    let mut out = std::io::stdout().lock();
    writeln!(out, "aloft serve: http://{local}/ (Ctrl-C to stop)")?;
    out.flush()?;
    drop(out);
    conn::serve(listener, app).await
}

/// The routes, behind the checks of [`guard`].
fn router(shared: Arc<Shared>) -> Router {
    Router::new()
        .route("/api/config", get(api::config))
        .route("/api/vehicles", get(api::vehicles).post(api::send_vehicle))
        .route("/api/endurance", get(api::endurance))
        .route(
            "/api/mission",
            api::planned_route("POST /api/mission", answers::mission_answer_with),
        )
        .route(
            "/api/map",
            api::planned_route("POST /api/map", answers::mission_map_answer_with),
        )
        .route(
            "/api/plan",
            api::planned_route("POST /api/plan", answers::plan_answer_with),
        )
        .route("/api/log/info", post(files::log_info))
        .route("/api/files/{index}", get(files::given_file))
        .route("/api/files/{index}/info", get(files::given_log_info))
        .route("/api/live", get(live::events))
        .route("/api/logbook/{kind}", get(api::logbook))
        .fallback(get(assets::asset).fallback(not_allowed))
        .method_not_allowed_fallback(not_allowed)
        .layer(middleware::from_fn_with_state(shared.clone(), guard::check))
        .layer(middleware::from_fn(quotes::shortened_errors))
        .layer(middleware::from_fn_with_state(
            shared.clone(),
            policy::headers,
        ))
        .with_state(shared)
}

/// 405 for a method a route does not take (`GET /api/mission`), as the other errors: JSON.
async fn not_allowed(method: axum::http::Method, uri: axum::http::Uri) -> Response {
    error(
        StatusCode::METHOD_NOT_ALLOWED,
        &format!("{method} is not a method of {}", uri.path()),
    )
}

/// A request refused before its answer (a 4xx with its JSON error), boxed: an answer is large,
/// and a refusal travels up through `?`.
pub(super) struct Refused(Box<Response>);

impl From<Response> for Refused {
    fn from(response: Response) -> Self {
        Self(Box::new(response))
    }
}

impl IntoResponse for Refused {
    fn into_response(self) -> Response {
        *self.0
    }
}

/// A JSON error answer.
fn error(status: StatusCode, message: &str) -> Response {
    let body = serde_json::json!({ "error": message }).to_string();
    (status, [(header::CONTENT_TYPE, json_type())], body).into_response()
}

fn json_type() -> HeaderValue {
    HeaderValue::from_static("application/json")
}

/// An answer: its JSON text, or the command line's message with 422.
fn answer(result: Result<String, String>) -> Response {
    match result {
        Ok(text) => (StatusCode::OK, [(header::CONTENT_TYPE, json_type())], text).into_response(),
        Err(message) => error(StatusCode::UNPROCESSABLE_ENTITY, &message),
    }
}

/// The command line's one-line message of an engine error.
fn engine_message(e: aloft::Error) -> String {
    super::engine_message(e)
}
