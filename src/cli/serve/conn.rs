//! The server's connections: accepted one by one, each served by hyper's HTTP/1 with the limits a
//! server on a shared machine or a field network needs, until Ctrl-C or SIGTERM.
//!
//! | limit | value | what it stops |
//! |---|---|---|
//! | open connections | [`MAX_CONNECTIONS`] | a client that opens connections until the process runs out of files (the usual limit is 1,024): a connection beyond it is closed at once |
//! | a request's head | [`HEADER_TIMEOUT`] from the first byte awaited | slow headers, and idle keep-alive connections (the next request's head is awaited under the same clock) |
//! | a body | [`BODY_IDLE_TIMEOUT`] without a byte | half-sent bodies (see [`super::body`]) |

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use anyhow::Result;
use axum::Router;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use tokio::net::TcpListener;
use tokio::sync::Semaphore;

use super::guard::LocalAddr;

/// Most connections open at once.
pub(super) const MAX_CONNECTIONS: usize = 256;

/// Longest wait for a request's head (the whole of it), s: also how long an idle keep-alive
/// connection is kept.
pub(super) const HEADER_TIMEOUT: Duration = Duration::from_secs(10);

/// Longest wait for the next bytes of a request's body.
pub(super) const BODY_IDLE_TIMEOUT: Duration = Duration::from_secs(30);

/// Serve `app` on `listener` until a stop signal (Ctrl-C, SIGTERM).
pub(super) async fn serve(listener: TcpListener, app: Router) -> Result<()> {
    let slots = Arc::new(Semaphore::new(MAX_CONNECTIONS));
    let stop = stop_signal();
    tokio::pin!(stop);
    loop {
        let accepted = tokio::select! {
            accepted = listener.accept() => accepted,
            () = &mut stop => return Ok(()),
        };
        let stream = match accepted {
            Ok((stream, _)) => stream,
            // Out of files or a connection reset before it was taken: wait a little, go on.
            Err(_) => {
                tokio::time::sleep(Duration::from_millis(50)).await;
                continue;
            }
        };
        // Beyond the cap: closed at once (dropped), so the process keeps its files.
        let Ok(slot) = slots.clone().try_acquire_owned() else {
            continue;
        };
        let local = stream.local_addr().ok();
        let app = app.clone();
        tokio::spawn(async move {
            let _slot = slot;
            connection(stream, local, app).await;
        });
    }
}

/// One connection, served until it closes or a limit ends it.
async fn connection(stream: tokio::net::TcpStream, local: Option<SocketAddr>, app: Router) {
    let app = match local {
        Some(l) => app.layer(axum::Extension(LocalAddr(l))),
        None => app,
    };
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new())
        .header_read_timeout(HEADER_TIMEOUT);
    let service = TowerToHyperService::new(app);
    // A connection that ends in an error (a timeout, a reset) is simply closed.
    let _ = http.serve_connection(TokioIo::new(stream), service).await;
}

/// Ctrl-C or SIGTERM.
async fn stop_signal() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let term = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! {
        () = ctrl_c => {}
        () = term => {}
    }
}
