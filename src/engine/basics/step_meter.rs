//! The planner steps one request flies, against what its caller allows (`aloft serve`): every
//! flight of the request (a mission's, a plan's candidates and sorties, its trials and maps)
//! draws from one budget and stops when the caller gives up.
//!
//! A request's scenarios are bounded before they fly ([`WorkBounds`] in
//! [`super::ScenarioOptions`]: samples times the flight's steps). The flights of a mission and of
//! a plan to fly cannot be counted before they fly (a plan searches: how many trial flights it
//! takes depends on where each sortie ends), so they are metered as they fly: each flight may
//! take at most the steps the budget has left (the planner's own limit,
//! [`aloft_planner::PlanOptions::max_samples`], lowered to it), and none is flown once the
//! caller has cancelled. The caller then reads the meter's [`StepMeter::verdict`]: the answer,
//! or [`Error::RequestTooLong`] / [`Error::Cancelled`] in place of whatever the search made of
//! its refused flights.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

use aloft_planner::{MissionReport, PlanOptions, PlannerError};

use crate::error::Error;

/// What one request's scenarios may spend: a caller that answers others (`aloft serve`) bounds
/// the work of each request and stops the work whose answer nobody waits for any more.
#[derive(Debug, Clone, Default)]
pub struct WorkBounds {
    /// Most planner steps (samples of the flight's time grid) over all the scenarios of a
    /// mission, checked before any is flown from the plan's duration and time step
    /// ([`Error::TooMuchWork`]); `None`: no bound.
    pub max_steps: Option<u64>,
    /// Set by the caller when the answer is no longer wanted: the scenarios stop before their
    /// next flight with [`Error::Cancelled`].
    pub cancel: Option<Arc<AtomicBool>>,
}

impl WorkBounds {
    /// Whether the caller has given up on the answer.
    pub(in crate::engine) fn cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// `samples` flights of about `steps_per_flight` steps each, against [`Self::max_steps`].
    ///
    /// # Errors
    /// [`Error::TooMuchWork`] beyond the bound.
    pub(in crate::engine) fn check(
        &self,
        samples: u32,
        steps_per_flight: u64,
    ) -> Result<(), Error> {
        let Some(max_steps) = self.max_steps else {
            return Ok(());
        };
        let steps = steps_per_flight.max(1);
        if u64::from(samples).saturating_mul(steps) <= max_steps {
            return Ok(());
        }
        Err(Error::TooMuchWork {
            samples,
            steps_per_flight: steps,
            max_steps,
            max_samples: max_steps / steps,
        })
    }
}

/// The same bounds: the same step bound and the same cancellation flag (or none).
impl PartialEq for WorkBounds {
    fn eq(&self, other: &Self) -> bool {
        let same_flag = match (&self.cancel, &other.cancel) {
            (None, None) => true,
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        };
        self.max_steps == other.max_steps && same_flag
    }
}

/// One request's budget of planner steps and its cancellation: a handle, cloned into every
/// flight of the request (the clones share the count).
#[derive(Debug, Clone, Default)]
pub struct StepMeter(Arc<Budget>);

/// What a [`StepMeter`]'s clones share.
#[derive(Debug, Default)]
struct Budget {
    /// The bound and the cancellation flag.
    bounds: WorkBounds,
    /// Steps flown so far.
    spent: AtomicU64,
    /// Whether a flight was refused because the budget ran out.
    refused: AtomicBool,
}

impl StepMeter {
    /// A meter of `bounds` (`max_steps`: the request's budget, none for no bound; `cancel`:
    /// the caller's flag).
    pub fn new(bounds: WorkBounds) -> Self {
        Self(Arc::new(Budget {
            bounds,
            spent: AtomicU64::new(0),
            refused: AtomicBool::new(false),
        }))
    }

    /// Planner steps flown so far.
    pub fn steps(&self) -> u64 {
        self.0.spent.load(Ordering::Relaxed)
    }

    /// Steps left (none once cancelled), `None` for no bound.
    fn left(&self) -> Option<u64> {
        if self.0.bounds.cancelled() {
            return Some(0);
        }
        let max = self.0.bounds.max_steps?;
        Some(max.saturating_sub(self.steps()))
    }

    /// `options` with the planner's limit on a flight's steps lowered to what is left (at least
    /// one step: a flight with none left stops at its first block).
    pub(in crate::engine) fn within(&self, options: &PlanOptions) -> PlanOptions {
        match self.left() {
            Some(left) if left < options.max_samples => PlanOptions {
                max_samples: left.max(1),
                ..*options
            },
            _ => *options,
        }
    }

    /// Count a flight flown with `options` ([`Self::within`]) of `own_max` steps of its own: its
    /// steps (its duration over the time step), or, when it stopped at the lowered limit, that
    /// limit and the budget refused.
    pub(in crate::engine) fn count(
        &self,
        flown: &Result<MissionReport, PlannerError>,
        options: &PlanOptions,
        own_max: u64,
    ) {
        match flown {
            Ok(report) => {
                let steps = (report.duration_s / options.time_step_s).ceil();
                // A duration is finite and not negative; the cast saturates anyway.
                self.add(steps.max(0.0) as u64, false);
            }
            Err(PlannerError::TooManySamples { limit, .. }) => self.add(*limit, *limit < own_max),
            Err(_) => {}
        }
    }

    /// `steps` more flown; `refused`: the last flight stopped at the budget.
    fn add(&self, steps: u64, refused: bool) {
        self.0.spent.fetch_add(steps, Ordering::Relaxed);
        if refused {
            self.0.refused.store(true, Ordering::Relaxed);
        }
    }

    /// The request's answer as its caller is to see it: [`Error::Cancelled`] once cancelled,
    /// [`Error::RequestTooLong`] when a flight was refused for the budget (whatever the search
    /// made of it), else `result`.
    ///
    /// # Errors
    /// As said, and `result`'s own.
    pub fn verdict<T>(&self, result: Result<T, Error>) -> Result<T, Error> {
        if self.0.bounds.cancelled() {
            return Err(Error::Cancelled);
        }
        match (
            self.0.refused.load(Ordering::Relaxed),
            self.0.bounds.max_steps,
        ) {
            (true, Some(max_steps)) => Err(Error::RequestTooLong { max_steps }),
            _ => result,
        }
    }
}

/// The same meter (the same shared budget), or none on both sides.
impl PartialEq for StepMeter {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_budget_lowers_the_flights_limit_and_its_refusal_is_the_verdict() {
        let meter = StepMeter::new(WorkBounds {
            max_steps: Some(1000),
            cancel: None,
        });
        let options = PlanOptions::default();
        assert_eq!(meter.within(&options).max_samples, 1000);
        meter.add(600, false);
        assert_eq!(meter.steps(), 600);
        assert_eq!(meter.within(&options).max_samples, 400);
        assert_eq!(meter.verdict(Ok(1)).ok(), Some(1));
        // A flight stopped at the lowered limit of 400 steps: the budget refused it.
        let stopped = Err(PlannerError::TooManySamples {
            limit: 400,
            time_step_s: 0.1,
            flown_s: 40.0,
            suggested_time_step_s: 1.0,
        });
        meter.count(&stopped, &meter.within(&options), options.max_samples);
        assert_eq!(meter.within(&options).max_samples, 1);
        assert!(matches!(
            meter.verdict(Ok(1)),
            Err(Error::RequestTooLong { max_steps: 1000 })
        ));
    }

    #[test]
    fn a_flight_past_its_own_limit_is_no_refusal_of_the_budget() {
        let meter = StepMeter::new(WorkBounds {
            max_steps: Some(1_000_000_000),
            cancel: None,
        });
        let options = PlanOptions {
            max_samples: 50,
            ..PlanOptions::default()
        };
        let own = Err(PlannerError::TooManySamples {
            limit: 50,
            time_step_s: 0.1,
            flown_s: 5.0,
            suggested_time_step_s: 1.0,
        });
        meter.count(&own, &meter.within(&options), options.max_samples);
        assert_eq!(meter.steps(), 50);
        assert_eq!(meter.verdict(Ok(2)).ok(), Some(2));
    }

    #[test]
    fn a_cancelled_request_flies_nothing_more() {
        let cancel = Arc::new(AtomicBool::new(false));
        let meter = StepMeter::new(WorkBounds {
            max_steps: None,
            cancel: Some(cancel.clone()),
        });
        let options = PlanOptions::default();
        assert_eq!(meter.within(&options), options);
        cancel.store(true, Ordering::Relaxed);
        assert_eq!(meter.within(&options).max_samples, 1);
        assert!(matches!(meter.verdict(Ok(3)), Err(Error::Cancelled)));
    }
}
