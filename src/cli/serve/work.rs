//! The engine's work of the requests: bounded in number, in size and in time nobody waits for.
//!
//! - **How many at once**: [`Pool`] holds `2 x cores` permits; a request that would need one
//!   more is answered 503 with `Retry-After: 1` at once (never queued behind the others). The
//!   cheap answers (`/api/config`, `/api/vehicles`, the page's files, the live feed) take no
//!   permit.
//! - **How much**: a request's scenarios fly at most `--max-request-steps` planner steps in all
//!   (samples x the flight's steps; 422 beyond, naming the most samples that fit), on at most one
//!   thread per core whatever `threads` asks (the answer does not depend on it; each thread holds
//!   its own state, so the threads bound the memory too). The flights of its mission, or of its
//!   plan to fly (`/api/plan`: candidates, sorties, trials, the maps of its files), fly at most
//!   `--max-request-steps` more, metered as they fly ([`StepMeter`]: 422 once a flight would
//!   pass it, naming the bound). One flight is bounded by the planner's own limit of ten million
//!   steps.
//! - **For whom**: when the client goes away (its connection closes), the request's future is
//!   dropped, which cancels its work: the scenarios stop before their next flight, a mission or
//!   a plan to fly within the flight it is flying (no flight starts after).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use tokio::sync::Semaphore;

use aloft::engine::flags::ScenarioFlags;
use aloft::engine::{StepMeter, WorkBounds};

use super::{answer, error};

/// The default bound on the planner steps of one request's scenarios: about half a minute of one
/// core (0.35 µs a step on the demo); 25,000 scenarios of the built-in demo, 1,300 of a 2-hour
/// survey at the default 0.1 s step.
pub const DEFAULT_MAX_REQUEST_STEPS: u64 = 100_000_000;

/// Permits for the engine's work, and the bounds of each request.
pub(super) struct Pool {
    permits: Arc<Semaphore>,
    max_steps: u64,
    cores: usize,
}

impl Pool {
    /// A pool for this machine's cores, each request's scenarios within `max_steps`.
    pub(super) fn new(max_steps: u64) -> Self {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        Self {
            permits: Arc::new(Semaphore::new(2 * cores)),
            max_steps,
            cores,
        }
    }

    /// Requests the pool runs at once.
    pub(super) fn capacity(&self) -> usize {
        2 * self.cores
    }

    /// Bound a request's scenarios: threads at most one per core, the steps, and `cancel`.
    pub(super) fn bound(&self, scenarios: &mut ScenarioFlags, cancel: &Arc<AtomicBool>) {
        let asked = match usize::from(scenarios.threads) {
            0 => self.cores,
            t => t,
        };
        scenarios.threads = u16::try_from(asked.min(self.cores)).unwrap_or(1);
        scenarios.bounds = WorkBounds {
            max_steps: Some(self.max_steps),
            cancel: Some(cancel.clone()),
        };
    }

    /// The meter of a request's flights: at most the pool's steps, stopped by `cancel`.
    pub(super) fn meter(&self, cancel: &Arc<AtomicBool>) -> StepMeter {
        StepMeter::new(WorkBounds {
            max_steps: Some(self.max_steps),
            cancel: Some(cancel.clone()),
        })
    }

    /// Run `work` on the blocking pool with a permit (503 without one) and a cancellation flag
    /// set if this future is dropped (the client went away): its answer, or its refusal (422,
    /// the command line's message).
    pub(super) async fn run(
        &self,
        work: impl FnOnce(&Arc<AtomicBool>) -> Result<String, String> + Send + 'static,
    ) -> Response {
        let Ok(permit) = self.permits.clone().try_acquire_owned() else {
            return busy(self.capacity());
        };
        let cancel = Arc::new(AtomicBool::new(false));
        let _on_drop = CancelOnDrop(cancel.clone());
        let handle = tokio::task::spawn_blocking(move || {
            // The permit is held while the work runs, even when its client has gone.
            let _permit = permit;
            work(&cancel)
        });
        answer(handle.await.unwrap_or_else(join_error))
    }
}

/// Sets its flag when dropped: a request's future dropped before its work ended cancels it.
struct CancelOnDrop(Arc<AtomicBool>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// 503: every permit is taken.
fn busy(capacity: usize) -> Response {
    let mut response = error(
        StatusCode::SERVICE_UNAVAILABLE,
        &format!(
            "the server is busy with {capacity} requests (twice its cores): try again shortly"
        ),
    );
    response
        .headers_mut()
        .insert(header::RETRY_AFTER, HeaderValue::from_static("1"));
    response.into_response()
}

/// A request's work that panicked: never expected (the engine does not panic on any input), said
/// as an error rather than taking the server down.
fn join_error(e: tokio::task::JoinError) -> Result<String, String> {
    Err(format!("the request's work failed: {e}"))
}
