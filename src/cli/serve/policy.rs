//! What every answer tells the browser, page files and API answers alike (errors too):
//!
//! - **`Content-Security-Policy`**: scripts, styles, fonts and connections from the server
//!   itself only (`'self'`), so that no inline script runs, not even one that a value slipped
//!   into the page as markup would carry (the page puts every value in as text: `web/js/dom.js`);
//!   images from the server, `data:` URLs (the page's empty icon) and the tile layer's server
//!   when `--tiles` names one; no plugin (`object-src 'none'`), no `<base>`, no form sent
//!   anywhere, and the page in no other page's frame.
//! - **`X-Content-Type-Options: nosniff`**: an answer is read as the type it says (a JSON error
//!   or a mission's text is never run as a script or shown as a page).

use std::sync::Arc;

use anyhow::Result;
use axum::extract::{Request, State};
use axum::http::{header, HeaderValue};
use axum::middleware::Next;
use axum::response::Response;

use super::Shared;

/// The policy of a server with the tile layer `tiles` (a URL template), or the message of a
/// template whose server cannot be named in a policy.
///
/// # Errors
/// A template that is not an `http://` or `https://` URL, nor a path of the server's own.
pub(super) fn content_policy(tiles: Option<&str>) -> Result<HeaderValue> {
    let mut images = "'self' data:".to_string();
    if let Some(source) = tiles.map(tile_source).transpose()?.flatten() {
        images.push(' ');
        images.push_str(&source);
    }
    let policy = format!(
        "default-src 'self'; script-src 'self'; style-src 'self'; img-src {images}; \
         connect-src 'self'; font-src 'self'; object-src 'none'; base-uri 'none'; \
         form-action 'none'; frame-ancestors 'none'"
    );
    Ok(HeaderValue::from_str(&policy)?)
}

/// The source of a tile layer's images in a policy: its scheme, host and port (`None` for a
/// template of the server's own, a path); `{s}` (the subdomains Leaflet rotates through) as
/// `*.`.
fn tile_source(template: &str) -> Result<Option<String>> {
    if template.starts_with('/') && !template.starts_with("//") {
        return Ok(None);
    }
    let bad = || {
        anyhow::anyhow!(
            "--tiles '{template}': give an http:// or https:// URL template, or a path of the \
             server's own (/...)"
        )
    };
    let (scheme, rest) = template.split_once("://").ok_or_else(bad)?;
    if scheme != "http" && scheme != "https" {
        return Err(bad());
    }
    let authority = rest.split(['/', '?', '#']).next().unwrap_or("");
    let host = authority.replace("{s}.", "*.");
    let plain = |c: char| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | ':' | '[' | ']');
    let wildcard_ok = host.strip_prefix("*.").unwrap_or(&host).chars().all(plain);
    if host.is_empty() || !wildcard_ok || host.contains('@') {
        return Err(anyhow::anyhow!(
            "--tiles '{template}': its server '{authority}' is not a host name a browser's \
             policy can name (letters, digits, '.', '-', a port; {{s}}. for the subdomains)"
        ));
    }
    Ok(Some(format!("{scheme}://{host}")))
}

/// The headers of the module docs, on every answer.
pub(super) async fn headers(
    State(shared): State<Arc<Shared>>,
    request: Request,
    next: Next,
) -> Response {
    let mut response = next.run(request).await;
    let headers = response.headers_mut();
    headers.insert(header::CONTENT_SECURITY_POLICY, shared.policy.clone());
    headers.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    response
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tile_layer_adds_its_server_to_the_images_only() {
        let policy = |t: Option<&str>| {
            content_policy(t)
                .map(|p| p.to_str().unwrap_or_default().to_string())
                .map_err(|e| e.to_string())
        };
        let own = policy(None).unwrap();
        assert!(own.contains("script-src 'self';") && own.contains("img-src 'self' data:;"));
        let osm = policy(Some("https://{s}.tile.openstreetmap.org/{z}/{x}/{y}.png")).unwrap();
        assert!(
            osm.contains("img-src 'self' data: https://*.tile.openstreetmap.org;"),
            "{osm}"
        );
        let port = policy(Some("http://10.0.0.2:8081/tiles/{z}/{x}/{y}.png")).unwrap();
        assert!(
            port.contains("img-src 'self' data: http://10.0.0.2:8081;"),
            "{port}"
        );
        assert_eq!(policy(Some("/tiles/{z}/{x}/{y}.png")).unwrap(), own);
        // A template that would add a directive, or names no server a policy can hold.
        for bad in [
            "https://evil.example;script-src *;/{z}/{x}/{y}",
            "https://a b/{z}/{x}/{y}",
            "ftp://t.example/{z}/{x}/{y}",
            "//t.example/{z}/{x}/{y}",
            "https://user@t.example/{z}/{x}/{y}",
            "https://{z}.t.example/{x}/{y}",
        ] {
            assert!(policy(Some(bad)).is_err(), "{bad}");
        }
    }
}
