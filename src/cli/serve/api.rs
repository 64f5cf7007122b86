//! The JSON API's requests that answer from options alone or a mission's text: each is the
//! command line's `--format json` (or the page's map of the same plan).

use std::sync::Arc;

use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};

use aloft::engine::answers;
use aloft::engine::flags::{EnduranceFlags, MissionScenarioFlags};
use aloft::engine::{parse_keywords, FlagGroup, Keyword, Mission};

use super::{blocking, error, json_type, Shared};

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
    });
    if let (Some((url, attribution)), Some(c)) = (&shared.tiles, config.as_object_mut()) {
        c.insert("tiles".into(), url.as_str().into());
        c.insert("attribution".into(), attribution.as_str().into());
    }
    (
        StatusCode::OK,
        [(header::CONTENT_TYPE, json_type())],
        config.to_string(),
    )
        .into_response()
}

/// `GET /api/vehicles`.
pub(super) async fn vehicles() -> Response {
    blocking(answers::vehicles_answer).await
}

/// `GET /api/endurance?OPTIONS`.
pub(super) async fn endurance(Query(query): QueryPairs) -> Response {
    let flags: EnduranceFlags = match flags("GET /api/endurance", &query) {
        Ok(f) => f,
        Err(m) => return error(StatusCode::BAD_REQUEST, &m),
    };
    blocking(move || answers::endurance_answer(&flags)).await
}

/// `POST /api/mission?file=NAME&OPTIONS`.
pub(super) async fn mission(Query(query): QueryPairs, body: Bytes) -> Response {
    planned(
        "POST /api/mission",
        query,
        body,
        answers::mission_answer_for,
    )
    .await
}

/// `POST /api/map?file=NAME&OPTIONS`: the page's map of the plan `/api/mission` answers.
pub(super) async fn map(Query(query): QueryPairs, body: Bytes) -> Response {
    planned(
        "POST /api/map",
        query,
        body,
        answers::mission_map_answer_for,
    )
    .await
}

/// A mission request: its options, its mission (the body, or the demo when empty), the answer.
async fn planned(
    request: &str,
    query: Vec<(String, String)>,
    body: Bytes,
    answer: fn(&Mission, &MissionScenarioFlags) -> Result<String, aloft::Error>,
) -> Response {
    let flags: MissionScenarioFlags = match flags(request, &query) {
        Ok(f) => f,
        Err(m) => return error(StatusCode::BAD_REQUEST, &m),
    };
    let origin = file_name(&query, "upload");
    blocking(move || answer(&mission_of(&body, &origin)?, &flags)).await
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

/// The query's options (all but `file`) as the command's flag group, or the message of a 400
/// (naming the option and the `request`).
pub(super) fn flags<T: FlagGroup>(request: &str, query: &[(String, String)]) -> Result<T, String> {
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
    parse_keywords::<T>(request, &[], &given).map_err(super::super::engine_message)
}

/// The upload's name (`file=`), else `default`.
pub(super) fn file_name(query: &[(String, String)], default: &str) -> String {
    query
        .iter()
        .find(|(k, _)| k == "file")
        .map_or_else(|| default.to_string(), |(_, v)| v.clone())
}
