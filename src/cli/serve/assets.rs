//! The page's files (`web/`), built into the binary: the page works offline, and the binary is
//! all there is to install. (A debug build reads them from `web/` at each request, so the page
//! can be edited without a rebuild.)

use axum::http::{header, StatusCode, Uri};
use axum::response::{IntoResponse, Response};
use rust_embed::RustEmbed;

use super::error;

#[derive(RustEmbed)]
#[folder = "web/"]
struct Assets;

/// `GET /PATH`: a file of the page (`/` is `index.html`), else 404.
pub(super) async fn asset(uri: Uri) -> Response {
    let path = match uri.path().trim_start_matches('/') {
        "" => "index.html",
        p => p,
    };
    match Assets::get(path) {
        Some(file) => (
            StatusCode::OK,
            [
                (header::CONTENT_TYPE, content_type(path)),
                (header::CACHE_CONTROL, "no-cache"),
            ],
            file.data.into_owned(),
        )
            .into_response(),
        None => error(StatusCode::NOT_FOUND, &format!("no page file '{path}'")),
    }
}

/// The content type of a page file, by its extension (`.js` is `text/javascript`: a browser
/// refuses a module script, `web/app.js` and `web/js/*.js`, served as any other type).
fn content_type(path: &str) -> &'static str {
    match path.rsplit('.').next().unwrap_or("") {
        "html" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "png" => "image/png",
        "svg" => "image/svg+xml",
        "json" => "application/json",
        _ => "application/octet-stream",
    }
}
