//! Who may ask: the checks every request passes before it is routed.
//!
//! - **`Host`**, exactly one (a request with two is 400: a proxy or a cache in front may read the
//!   other one than this server does), and the authority of an absolute-form target
//!   (`GET http://h/ HTTP/1.1`), must name this server: the address it listens on; on loopback also `localhost`; listening on every
//!   interface (`0.0.0.0`, `[::]`), the address the connection came in on, the machine's name and
//!   `NAME.local`, with the port. Anything else is a page elsewhere that reached the server
//!   through DNS rebinding: 403.
//! - **`Origin`**, when a browser sends one (every cross-origin request and every POST), must be
//!   the page's own (`http://` and an accepted host); `Sec-Fetch-Site: cross-site` or
//!   `same-site` on a request of the API is refused too (a page elsewhere can send a GET without
//!   an `Origin`, as an image). A web page cannot make the server work for it: 403. Clients that
//!   are not browsers (curl, scripts) send neither and are served.

use std::net::{IpAddr, SocketAddr};
use std::sync::Arc;

use axum::extract::{Request, State};
use axum::http::{header, HeaderMap, StatusCode, Uri};
use axum::middleware::Next;
use axum::response::Response;

use super::{error, Shared};

/// The local address of a request's connection (the address the client reached), put in the
/// request's extensions by the connection loop.
#[derive(Debug, Clone, Copy)]
pub(super) struct LocalAddr(pub(super) SocketAddr);

/// The names a server answers to.
#[derive(Debug, Clone)]
pub(super) struct Hosts {
    /// The listening address as given (`127.0.0.1:8080`).
    listen: SocketAddr,
    /// The machine's name (lower case), when it has one.
    machine: Option<String>,
}

impl Hosts {
    /// The names of a server listening at `listen` (its port resolved).
    pub(super) fn new(listen: SocketAddr) -> Self {
        Self {
            listen,
            machine: machine_name(),
        }
    }

    /// The address to name in messages and in the URL printed at start.
    pub(super) fn shown(&self) -> String {
        self.listen.to_string()
    }

    /// Whether `host` (`name:port`, as a `Host` header gives it) is this server, for a
    /// connection that came in on `local`.
    pub(super) fn accepts(&self, host: &str, local: Option<SocketAddr>) -> bool {
        let port = self.listen.port();
        let Some((name, p)) = split_host(host) else {
            return false;
        };
        if p != port {
            return false;
        }
        let name = name.to_ascii_lowercase();
        let ip: Option<IpAddr> = name.trim_matches(['[', ']']).parse().ok();
        let listen_ip = self.listen.ip();
        if ip == Some(listen_ip) {
            return true;
        }
        let loopback = listen_ip.is_loopback() || local.is_some_and(|l| l.ip().is_loopback());
        if loopback && (name == "localhost" || ip.is_some_and(|i| i.is_loopback())) {
            return true;
        }
        if !listen_ip.is_unspecified() {
            return false;
        }
        // Every interface: the address the client reached, or the machine's names.
        let reached = local.map(|l| l.ip());
        ip.is_some_and(|i| reached.is_some_and(|r| mapped(i) == mapped(r)))
            || self
                .machine
                .as_deref()
                .is_some_and(|m| name == m || name == format!("{m}.local"))
    }

    /// Whether `origin` (`http://name:port`) is the page's own.
    fn accepts_origin(&self, origin: &str, local: Option<SocketAddr>) -> bool {
        origin
            .strip_prefix("http://")
            .is_some_and(|host| self.accepts(host, local))
    }
}

/// An IPv4 address as IPv6 sees it on a dual-stack socket, and back.
fn mapped(ip: IpAddr) -> IpAddr {
    match ip {
        IpAddr::V6(v6) => v6.to_ipv4_mapped().map_or(ip, IpAddr::V4),
        IpAddr::V4(_) => ip,
    }
}

/// `name` and port of `name:port` / `[v6]:port` (port 80 when none is given).
fn split_host(host: &str) -> Option<(&str, u16)> {
    if host.is_empty() || host.contains(['/', '@', ' ']) {
        return None;
    }
    let (name, port) = match host.rsplit_once(':') {
        Some((n, p)) if !n.ends_with(':') && (n.starts_with('[') || !n.contains(':')) => {
            (n, p.parse().ok()?)
        }
        _ if host.starts_with('[') || !host.contains(':') => (host, 80),
        _ => return None,
    };
    (!name.is_empty()).then_some((name, port))
}

/// The machine's name (Linux: the kernel's hostname), lower case.
fn machine_name() -> Option<String> {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .map(|n| n.trim().to_ascii_lowercase())
        .filter(|n| !n.is_empty() && !n.contains(['/', ':', ' ']))
}

/// The checks of the module docs.
pub(super) async fn check(
    State(shared): State<Arc<Shared>>,
    request: Request,
    next: Next,
) -> Response {
    let local = request.extensions().get::<LocalAddr>().map(|l| l.0);
    if let Some(why) = malformed(request.headers()) {
        return error(StatusCode::BAD_REQUEST, &why);
    }
    match refusal(&shared.hosts, request.headers(), request.uri(), local) {
        Some(why) => error(StatusCode::FORBIDDEN, &why),
        None => next.run(request).await,
    }
}

/// Why a request's head cannot be read as one request (400), if it cannot: more than one
/// `Host`.
fn malformed(headers: &HeaderMap) -> Option<String> {
    let hosts = headers.get_all(header::HOST).iter().count();
    (hosts > 1).then(|| format!("the request has {hosts} Host headers: give one"))
}

/// Why a request is refused, if it is.
fn refusal(
    hosts: &Hosts,
    headers: &HeaderMap,
    uri: &Uri,
    local: Option<SocketAddr>,
) -> Option<String> {
    let text = |name: &str| {
        headers
            .get(name)
            .map(|v| v.to_str().unwrap_or("(not text)"))
    };
    let host = text(header::HOST.as_str()).unwrap_or("");
    if !hosts.accepts(host, local) {
        return Some(format!(
            "Host '{}' is not this server's ({})",
            shortened(host),
            hosts.shown()
        ));
    }
    if let Some(authority) = uri.authority() {
        if !hosts.accepts(authority.as_str(), local) {
            return Some(format!(
                "the request names another server ({})",
                shortened(authority.as_str())
            ));
        }
    }
    if let Some(origin) = text(header::ORIGIN.as_str()) {
        if !hosts.accepts_origin(origin, local) {
            return Some(format!(
                "a page of another origin ({}) may not use this server",
                shortened(origin)
            ));
        }
    }
    let cross = matches!(text("sec-fetch-site"), Some("cross-site" | "same-site"));
    if cross && uri.path().starts_with("/api/") {
        return Some("a page of another site may not use this server's API".to_string());
    }
    None
}

/// A header's text in a message: at most 80 characters.
fn shortened(text: &str) -> String {
    match text.char_indices().nth(80) {
        Some((at, _)) => format!("{}...", &text[..at]),
        None => text.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hosts(listen: &str, machine: Option<&str>) -> Hosts {
        Hosts {
            listen: listen.parse().unwrap(),
            machine: machine.map(str::to_string),
        }
    }

    #[test]
    fn loopback_answers_to_its_address_and_localhost_only() {
        let h = hosts("127.0.0.1:8080", Some("field-laptop"));
        for ok in [
            "127.0.0.1:8080",
            "localhost:8080",
            "LOCALHOST:8080",
            "[::1]:8080",
        ] {
            assert!(h.accepts(ok, None), "{ok}");
        }
        for no in [
            "127.0.0.1:8081",
            "evil.example:8080",
            "field-laptop:8080",
            "127.0.0.1",
            "",
            "127.0.0.1:8080/x",
            "user@127.0.0.1:8080",
        ] {
            assert!(!h.accepts(no, None), "{no}");
        }
    }

    /// Regression (issue 32): on `0.0.0.0` only `Host: 0.0.0.0:PORT` passed, so every browser
    /// was refused.
    #[test]
    fn every_interface_answers_to_the_address_reached_and_the_machine_name() {
        let h = hosts("0.0.0.0:8080", Some("field-laptop"));
        let reached: SocketAddr = "192.168.1.20:8080".parse().unwrap();
        for ok in [
            "192.168.1.20:8080",
            "field-laptop:8080",
            "field-laptop.local:8080",
        ] {
            assert!(h.accepts(ok, Some(reached)), "{ok}");
        }
        for no in [
            "192.168.1.21:8080",
            "evil.example:8080",
            "localhost:8080",
            "192.168.1.20:9090",
        ] {
            assert!(!h.accepts(no, Some(reached)), "{no}");
        }
        let local: SocketAddr = "127.0.0.1:8080".parse().unwrap();
        assert!(h.accepts("localhost:8080", Some(local)));
        // A dual-stack socket sees IPv4 clients as mapped addresses.
        let h6 = hosts("[::]:8080", None);
        let mapped_local: SocketAddr = "[::ffff:192.168.1.20]:8080".parse().unwrap();
        assert!(h6.accepts("192.168.1.20:8080", Some(mapped_local)));
    }

    #[test]
    fn origins_and_fetch_sites_of_other_pages_are_refused() {
        let h = hosts("127.0.0.1:8080", None);
        let uri: Uri = "/api/mission".parse().unwrap();
        let mut headers = HeaderMap::new();
        headers.insert(header::HOST, "127.0.0.1:8080".parse().unwrap());
        assert_eq!(refusal(&h, &headers, &uri, None), None);
        headers.insert(header::ORIGIN, "http://127.0.0.1:8080".parse().unwrap());
        assert_eq!(refusal(&h, &headers, &uri, None), None);
        for origin in ["http://evil.example", "null", "https://127.0.0.1:8080"] {
            headers.insert(header::ORIGIN, origin.parse().unwrap());
            assert!(refusal(&h, &headers, &uri, None).is_some(), "{origin}");
        }
        headers.remove(header::ORIGIN);
        headers.insert("sec-fetch-site", "cross-site".parse().unwrap());
        assert!(refusal(&h, &headers, &uri, None).is_some());
        // The page's own files may be fetched from anywhere (they do no work).
        let page: Uri = "/index.html".parse().unwrap();
        assert_eq!(refusal(&h, &headers, &page, None), None);
        headers.insert("sec-fetch-site", "same-origin".parse().unwrap());
        assert_eq!(refusal(&h, &headers, &uri, None), None);
        // An absolute-form target naming another server.
        let other: Uri = "http://evil.example/api/vehicles".parse().unwrap();
        assert!(refusal(&h, &headers, &other, None).is_some());
        let own: Uri = "http://127.0.0.1:8080/api/vehicles".parse().unwrap();
        assert_eq!(refusal(&h, &headers, &own, None), None);
    }
}
