//! Errors quote at most [`MAX_QUOTED`] characters of any value: a request's error (4xx, 5xx)
//! names the value it refuses, and a value of thousands of characters (an option, a file name,
//! a path) is shown by its start. One layer over every route, so that no message (the engine's,
//! the option parser's, the server's own) sends a long value back whole:
//!
//! 1. each value of the request (its path's segments, its options' names and values, as sent
//!    and decoded) longer than [`MAX_QUOTED`] characters is cut to its first [`MAX_QUOTED`]
//!    and `...` wherever the message quotes it;
//! 2. any other run of characters without a space longer than that (a value the message took
//!    from the body, a mission's name) is cut alike, the quotes around it kept.

use axum::body::{to_bytes, Body};
use axum::extract::Request;
use axum::http::{header, Uri};
use axum::middleware::Next;
use axum::response::Response;

use super::error;

/// Most characters of a value an error quotes.
pub(super) const MAX_QUOTED: usize = 80;

/// Largest error body read to be shortened, bytes (an error is a line; a larger body is left
/// as it is).
const MAX_ERROR_BYTES: usize = 1 << 20;

/// The layer of the module docs.
pub(super) async fn shortened_errors(request: Request, next: Next) -> Response {
    let values = request_values(request.uri());
    let response = next.run(request).await;
    let is_error = response.status().is_client_error() || response.status().is_server_error();
    let is_json = response
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|t| t.as_bytes().starts_with(b"application/json"));
    if !is_error || !is_json {
        return response;
    }
    let (mut parts, body) = response.into_parts();
    let Ok(bytes) = to_bytes(body, MAX_ERROR_BYTES).await else {
        return error(parts.status, "the error's message was too long to send");
    };
    let message = serde_json::from_slice::<serde_json::Value>(&bytes)
        .ok()
        .and_then(|v| v.get("error").and_then(|m| m.as_str()).map(str::to_string));
    let Some(message) = message else {
        return Response::from_parts(parts, Body::from(bytes));
    };
    let body = serde_json::json!({ "error": shortened(&message, &values) }).to_string();
    parts.headers.remove(header::CONTENT_LENGTH);
    Response::from_parts(parts, Body::from(body))
}

/// The values of a request a message may quote: its path's segments and its query's names and
/// values, each as sent and decoded (`%2F`, `+`).
fn request_values(uri: &Uri) -> Vec<String> {
    let mut values: Vec<String> = Vec::new();
    let mut both = |raw: &str, plus_is_space: bool| {
        values.push(raw.to_string());
        values.push(decoded(raw, plus_is_space));
    };
    for segment in uri.path().split('/') {
        both(segment, false);
    }
    for pair in uri.query().unwrap_or("").split('&') {
        let (k, v) = pair.split_once('=').unwrap_or((pair, ""));
        both(k, true);
        both(v, true);
    }
    values.retain(|v| v.chars().count() > MAX_QUOTED);
    // The longest first: a value that holds another is cut whole.
    values.sort_by_key(|v| std::cmp::Reverse(v.len()));
    values.dedup();
    values
}

/// `raw` with its `%XX` escapes decoded (and `+` as a space in a query), bytes that are not
/// UTF-8 replaced.
fn decoded(raw: &str, plus_is_space: bool) -> String {
    let bytes = raw.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        match bytes[i] {
            b'%' if i + 2 < bytes.len() => match (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                (Some(h), Some(l)) => {
                    out.push((h * 16 + l) as u8);
                    i += 3;
                    continue;
                }
                _ => out.push(b'%'),
            },
            b'+' if plus_is_space => out.push(b' '),
            b => out.push(b),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// `text` with its first [`MAX_QUOTED`] characters and `...` when it is longer.
fn cut(text: &str) -> String {
    match text.char_indices().nth(MAX_QUOTED) {
        Some((at, _)) => format!("{}...", &text[..at]),
        None => text.to_string(),
    }
}

/// `message` quoting at most [`MAX_QUOTED`] characters of each of `values` (module steps 1-2).
fn shortened(message: &str, values: &[String]) -> String {
    let mut out = message.to_string();
    for v in values {
        if out.contains(v.as_str()) {
            out = out.replace(v.as_str(), &cut(v));
        }
    }
    out.split(' ').map(cut_word).collect::<Vec<_>>().join(" ")
}

/// A word of a message with its core (the word without the quotes, brackets and punctuation
/// around it) cut to [`MAX_QUOTED`] characters.
fn cut_word(word: &str) -> String {
    let mark = |c: char| "'\"`()[]{}<>,;:.!?".contains(c);
    let start = word.len() - word.trim_start_matches(mark).len();
    let end = word.trim_end_matches(mark).len().max(start);
    format!(
        "{}{}{}",
        &word[..start],
        cut(&word[start..end]),
        &word[end..]
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_values_are_cut_where_they_are_quoted() {
        let long = "w".repeat(300);
        let spaced = "a b ".repeat(50);
        let uri: Uri = format!("/api/plan?speeds={long}&file={}", spaced.replace(' ', "+"))
            .parse()
            .unwrap();
        let values = request_values(&uri);
        let message = format!("invalid value '{long}' for speeds; mission {spaced}: bad");
        let short = shortened(&message, &values);
        assert!(
            short.contains(&format!("'{}...'", "w".repeat(80))),
            "{short}"
        );
        assert!(!short.contains(&"a b ".repeat(21)), "{short}");
        assert!(short.ends_with(": bad"), "{short}");
        // A long word of the message's own (no request value) is cut alike; short ones are kept.
        let word = "x".repeat(200);
        assert_eq!(
            shortened(&format!("name '{word}' is taken"), &[]),
            format!("name '{}...' is taken", "x".repeat(80))
        );
        // A value cut in step 1 keeps its quotes through step 2.
        let quoted = shortened(&format!("value '{long}': bad"), &values);
        assert_eq!(quoted, format!("value '{}...': bad", "w".repeat(80)));
        assert_eq!(shortened("a short message", &values), "a short message");
        assert_eq!(decoded("a%2Fb+c%zz%", true), "a/b c%zz%");
    }
}
