//! The JSON API's requests that answer from options alone or a mission's text: each is the
//! command line's `--format json` (or the page's map of the same plan).

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use axum::body::Body;
use axum::extract::{Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{post, MethodRouter};

use aloft::engine::answers;
use aloft::engine::flags::{EnduranceFlags, MissionFlags, MissionScenarioFlags, PlanFlags};
use aloft::engine::{
    file_keywords, parse_keywords, FlagGroup, Keyword, Mission, StepMeter, Vehicle,
};

use super::body::{read_whole, within_declared, MISSION_LIMIT, VEHICLE_LIMIT};
use super::given::Names;
use super::vehicles::Fleet;
use super::work::Pool;
use super::{engine_message, error, json_type, Refused, Shared};

/// The query of a request: its keys and values in order.
pub(super) type QueryPairs = Query<Vec<(String, String)>>;

/// `GET /api/config`: what the page opens with.
pub(super) async fn config(State(shared): State<Arc<Shared>>) -> Response {
    let files: Vec<serde_json::Value> = shared
        .files
        .iter()
        .enumerate()
        .map(|(index, f)| serde_json::json!({ "index": index, "name": f.name, "kind": f.kind() }))
        .collect();
    let mut config = serde_json::json!({
        "files": files,
        "live": shared.live.is_some(),
        "max_upload_bytes": shared.max_upload,
        "logbook": shared.logbook.is_some(),
        "default_vehicle": shared.vehicles.default_name(),
    });
    let fleet = &shared.vehicles;
    if let (Some(pack), Some(c)) = (
        fleet.default_pack(fleet.default_name()),
        config.as_object_mut(),
    ) {
        c.insert("default_battery".into(), pack.name.as_str().into());
    }
    if let (Some((url, attribution)), Some(c)) = (&shared.tiles, config.as_object_mut()) {
        c.insert("tiles".into(), url.as_str().into());
        c.insert("attribution".into(), attribution.as_str().into());
    }
    json(config.to_string())
}

/// A JSON answer.
fn json(text: String) -> Response {
    (StatusCode::OK, [(header::CONTENT_TYPE, json_type())], text).into_response()
}

/// `GET /api/logbook/KIND`: the list of the logbook given with `--logbook` (404 without one),
/// read on the engine's queue.
pub(super) async fn logbook(
    State(shared): State<Arc<Shared>>,
    axum::extract::Path(kind): axum::extract::Path<String>,
) -> Response {
    let Some(db) = shared.logbook.clone() else {
        return error(
            StatusCode::NOT_FOUND,
            "no logbook: start aloft serve with --logbook FILE",
        );
    };
    if !["flights", "vehicles", "packs", "skipped"].contains(&kind.as_str()) {
        return error(
            StatusCode::NOT_FOUND,
            &format!("/api/logbook/{kind}: not a list of the logbook (flights, vehicles, packs, skipped)"),
        );
    }
    logbook_answer(&shared, db, kind).await
}

#[cfg(feature = "logbook")]
async fn logbook_answer(shared: &Shared, db: std::path::PathBuf, kind: String) -> Response {
    shared
        .work
        .run(move |_: &_| crate::cli::logbook::answer_json(&db, &kind))
        .await
}

#[cfg(not(feature = "logbook"))]
async fn logbook_answer(_: &Shared, _: std::path::PathBuf, _: String) -> Response {
    error(
        StatusCode::NOT_FOUND,
        "this aloft is built without the logbook",
    )
}

/// An answer, or the refusal that ends the request early (a 4xx with its JSON error): handlers
/// return it so that each refusal is one `?`.
pub(super) type Answered = Result<Response, Refused>;

/// `GET /api/endurance?OPTIONS`.
pub(super) async fn endurance(
    State(shared): State<Arc<Shared>>,
    Query(query): QueryPairs,
) -> Answered {
    let request = "GET /api/endurance";
    let mut flags: EnduranceFlags = flags(request, &query, &shared)?;
    let vehicle = shared.vehicles.vehicle(request, &flags.vehicle)?;
    if let Some(pack) = shared.vehicles.default_pack(&flags.vehicle) {
        flags.battery.get_or_insert_with(|| pack.name.clone());
    }
    let work = shared.clone();
    let job = move |cancel: &_| {
        work.work.bound(&mut flags.scenarios, cancel);
        answers::endurance_answer_with(&vehicle, &flags).map_err(engine_message)
    };
    Ok(shared.work.run(job).await)
}

/// The options of a request with a mission as its body: a flag group whose work the server
/// bounds ([`super::work`]).
pub(super) trait MissionRequest: FlagGroup + Send + 'static {
    /// Bound the request's work within the pool's, with the cancellation flag of its client:
    /// the meter of its flights ([`StepMeter`]), whose verdict is the request's answer.
    fn bound(&mut self, pool: &Pool, cancel: &Arc<AtomicBool>) -> StepMeter;

    /// The mission's options.
    fn mission(&mut self) -> &mut MissionFlags;
}

impl MissionRequest for MissionScenarioFlags {
    /// The scenarios within the pool's bound before they fly, the mission's own flights (the
    /// plan, its sorties) metered as they fly.
    fn bound(&mut self, pool: &Pool, cancel: &Arc<AtomicBool>) -> StepMeter {
        pool.bound(&mut self.scenarios, cancel);
        let meter = pool.meter(cancel);
        self.mission.meter = Some(meter.clone());
        meter
    }

    fn mission(&mut self) -> &mut MissionFlags {
        &mut self.mission
    }
}

impl MissionRequest for PlanFlags {
    /// A plan has no scenarios: every flight of its search (candidates, sorties, trials, the
    /// maps of its files) is metered, and none flies on once its client leaves.
    fn bound(&mut self, pool: &Pool, cancel: &Arc<AtomicBool>) -> StepMeter {
        self.bounds.cancel = Some(cancel.clone());
        let meter = pool.meter(cancel);
        self.mission.meter = Some(meter.clone());
        meter
    }

    fn mission(&mut self) -> &mut MissionFlags {
        &mut self.mission
    }
}

/// How a mission request is answered, with the vehicle flown: `aloft mission`'s JSON, the
/// page's map, `aloft plan`'s.
type MissionAnswer<T> = fn(&Vehicle, &Mission, &T) -> Result<String, aloft::Error>;

/// The route of a mission request (`POST PATH?file=NAME&OPTIONS`, the body a mission file, the
/// demo when empty): `/api/mission` answers with `answers::mission_answer_with`, `/api/map` (the
/// page's map of the same plan) with `answers::mission_map_answer_with`, both with the options
/// of `aloft mission`; `/api/plan` with `answers::plan_answer_with` and those of `aloft plan`.
pub(super) fn planned_route<T: MissionRequest>(
    request: &'static str,
    answer: MissionAnswer<T>,
) -> MethodRouter<Arc<Shared>> {
    post(
        move |State(shared): State<Arc<Shared>>,
              headers: HeaderMap,
              Query(query): QueryPairs,
              body: Body| planned(request, (shared, headers), query, body, answer),
    )
}

/// A mission request: its options, its mission (the body, or the demo when empty, within
/// [`MISSION_LIMIT`]), the answer.
async fn planned<T: MissionRequest>(
    request: &str,
    (shared, headers): (Arc<Shared>, HeaderMap),
    query: Vec<(String, String)>,
    body: Body,
    answer: MissionAnswer<T>,
) -> Answered {
    let limit_name = "the limit on mission files";
    within_declared(&headers, MISSION_LIMIT, limit_name)?;
    if query.iter().any(|(k, _)| k == "terrain") {
        let m = format!(
            "{request}: 'terrain' names a directory: a request names none (the server's tiles \
             are `aloft serve --terrain DIR`)"
        );
        return Err(Refused::from(error(StatusCode::BAD_REQUEST, &m)));
    }
    let mut flags: T = flags(request, &query, &shared)?;
    let vehicle = shared.vehicles.vehicle(request, &flags.mission().vehicle)?;
    with_default_pack(&shared.vehicles, flags.mission());
    // The server's tiles, and only those (not the environment's ALOFT_TERRAIN).
    flags.mission().terrain = shared.terrain.clone();
    let body = read_whole(body, MISSION_LIMIT, limit_name).await?;
    let origin = file_name(&query, "upload");
    let work = shared.clone();
    let job = move |cancel: &_| {
        let meter = flags.bound(&work.work, cancel);
        let answered = mission_of(&body, &origin).and_then(|m| {
            // A mission placed in metres from home (the built-in demo) has no place on the
            // tiles: it is answered over a flat Earth.
            if m.spec().home.latitude_deg.is_none() {
                flags.mission().terrain = None;
            }
            answer(&vehicle, &m, &flags)
        });
        meter.verdict(answered).map_err(engine_message)
    };
    Ok(shared.work.run(job).await)
}

/// A request that flies the default vehicle and names no pack flies the pack of `--battery`,
/// with a pack file's failsafes where the request gives none (as `aloft mission --battery FILE`).
fn with_default_pack(fleet: &Fleet, mission: &mut MissionFlags) {
    let Some(pack) = fleet.default_pack(&mission.vehicle) else {
        return;
    };
    if mission.battery.is_some() {
        return;
    }
    mission.battery = Some(pack.name.clone());
    if let Some(f) = &pack.failsafe {
        mission.low_voltage_v = mission.low_voltage_v.or(f.low_voltage_v);
        mission.critical_voltage_v = mission.critical_voltage_v.or(f.critical_voltage_v);
    }
}

/// The mission of an upload: the built-in demo when empty, else the file's text in any of the
/// formats `aloft mission` reads.
fn mission_of(body: &[u8], origin: &str) -> Result<Mission, aloft::Error> {
    if body.is_empty() {
        return Ok(Mission::demo());
    }
    let text = std::str::from_utf8(body).map_err(|_| aloft::Error::MissionFormat {
        origin: origin.to_string(),
        message: "not UTF-8 text".to_string(),
    })?;
    Mission::from_text(text, origin)
}

/// The query's options (all but `file`) as the command's flag group, the options that name a
/// file resolved to the files given to the server ([`Names`]), a `vehicle` to its name in the
/// server's list (the server's default vehicle when the command flies one and the query names
/// none); or a 400 naming the option and the `request`.
pub(super) fn flags<T: FlagGroup>(
    request: &str,
    query: &[(String, String)],
    shared: &Shared,
) -> Result<T, Refused> {
    let bad = |m: String| Refused::from(error(StatusCode::BAD_REQUEST, &m));
    let file_options = file_keywords::<T>();
    let names = Names {
        files: &shared.files,
        vehicles: &shared.vehicles,
    };
    let vehicle = "vehicle".to_string();
    let default = (vehicle.clone(), shared.vehicles.default_name().to_string());
    let named = query.iter().any(|(k, _)| *k == vehicle);
    let default = (file_options.contains(&vehicle) && !named).then_some(&default);
    // Each key's values, in order: one is a value (or a switch), several are a list.
    let mut values: Vec<(&String, Vec<String>)> = Vec::new();
    for (k, v) in query.iter().filter(|(k, _)| k != "file").chain(default) {
        let v = match file_options.contains(k) {
            true => names.resolve(request, k, v).map_err(bad)?,
            false => v.clone(),
        };
        match values.iter_mut().find(|(g, _)| *g == k) {
            Some((_, vs)) => vs.push(v),
            None => values.push((k, vec![v])),
        }
    }
    let given: Vec<(String, Keyword)> = values
        .into_iter()
        .map(|(k, vs)| {
            let value = match vs.as_slice() {
                [one] if one == "true" => Keyword::Switch(true),
                [one] if one == "false" => Keyword::Switch(false),
                [one] => Keyword::One(one.into()),
                many => Keyword::Many(many.iter().map(Into::into).collect()),
            };
            (k.clone(), value)
        })
        .collect();
    parse_keywords::<T>(request, &[], &given).map_err(|e| bad(engine_message(e)))
}

/// The upload's name (`file=`), else `default`.
pub(super) fn file_name(query: &[(String, String)], default: &str) -> String {
    query
        .iter()
        .find(|(k, _)| k == "file")
        .map_or_else(|| default.to_string(), |(_, v)| v.clone())
}

/// `GET /api/vehicles`: the list (off the engine's queue: it depends on nothing a request
/// gives, and is small).
pub(super) async fn vehicles(State(shared): State<Arc<Shared>>) -> axum::response::Response {
    super::answer(answers::vehicles_answer_of(&shared.vehicles.entries()).map_err(engine_message))
}

/// `POST /api/vehicles?file=NAME` (body: a vehicle file, at most [`VEHICLE_LIMIT`]): the
/// vehicle kept under its own name, answered with its entry in the list.
pub(super) async fn send_vehicle(
    State(shared): State<Arc<Shared>>,
    headers: HeaderMap,
    Query(query): QueryPairs,
    body: Body,
) -> Answered {
    let request = "POST /api/vehicles";
    let limit_name = "the limit on vehicle files";
    within_declared(&headers, VEHICLE_LIMIT, limit_name)?;
    if let Some((k, _)) = query.iter().find(|(k, _)| k != "file") {
        return Err(error(
            StatusCode::BAD_REQUEST,
            &format!("unknown option '{k}' of {request} (known: file)"),
        )
        .into());
    }
    let body = read_whole(body, VEHICLE_LIMIT, limit_name).await?;
    let origin = file_name(&query, "upload.toml");
    let work = shared.clone();
    let job = move |_: &_| work.vehicles.keep(&body, &origin);
    Ok(shared.work.run(job).await)
}
