//! The feed: how blocks get from pass A ([`super::sampler`]) to the pack pass, on a second thread
//! or in line. The only part of the planner that knows about threads.
//!
//! Pass A does not depend on the pack, so on a mission of [`THREADED_FROM_STEPS`] steps or more,
//! with two cores or more, it runs on a scoped thread, chunks of [`BLOCKS_PER_CHUNK`] blocks ahead
//! of the pack pass; the used chunks come back over a second channel, so no block is copied or
//! reallocated. Otherwise pass A runs in line, one block at a time, when the pack pass asks. The
//! plain reference is the in-line feed; the test `pass_a_on_its_own_thread_gives_the_same_report`
//! proves the reports equal bit for bit (a mission that completes, one whose pack runs out
//! part-way, one that pass A stops with an error).
//!
//! # Does the second thread earn its keep?
//! On the 2-core machine (bench `planner/mission/one_hour` against `one_hour_one_thread`, issue
//! 12): quiet, 13.0-13.6 ms with the thread against 19.2-19.5 ms without, 1.43-1.49x, for about
//! 12 % more CPU time in all (22.5 ms against 20.0), so it stays on by default (the bar is 1.3x).
//! While other builds load the machine (load average 4-8) it gains nothing (28-41 ms against
//! 28-31 ms): a caller that runs missions side by side should turn it off
//! ([`PlanOptions::second_thread`](super::PlanOptions::second_thread)).

use super::sampler::{BlockA, PassA};

/// Missions with at least this many steps run pass A on a second thread (below it, starting the
/// thread costs more than it saves).
const THREADED_FROM_STEPS: usize = 4096;

/// Blocks handed from pass A's thread to pass B at a time.
const BLOCKS_PER_CHUNK: usize = 32;

/// Whether pass A runs on a second thread: asked for (`parallel`), a mission long enough that the
/// thread pays for its start, and a second core.
pub(super) fn second_thread(parallel: bool, total_steps: usize) -> bool {
    parallel
        && total_steps >= THREADED_FROM_STEPS
        && std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2)
}

/// Run `fly` (the pack pass) on the blocks of `pass`: from a second thread when `threaded` (and
/// the thread starts), else in line.
pub(super) fn run<'p, 'a: 'p, R>(
    pass: PassA<'p, 'a>,
    threaded: bool,
    fly: impl FnOnce(&mut Feed<'p, 'a>) -> R,
) -> R {
    std::thread::scope(|scope| {
        let started = if threaded {
            Feed::threaded(scope, pass.clone())
        } else {
            None
        };
        let mut feed = started.unwrap_or_else(|| Feed::Inline {
            pass,
            block: Box::new(BlockA::EMPTY),
        });
        fly(&mut feed)
    })
}

/// Where pass B takes its blocks from: pass A run in line, or pass A's thread. (One per plan, so
/// the size of the in-line variant does not matter.)
#[allow(clippy::large_enum_variant)]
pub(super) enum Feed<'p, 'a> {
    Inline {
        pass: PassA<'p, 'a>,
        block: Box<BlockA>,
    },
    Threaded {
        full: std::sync::mpsc::Receiver<(Vec<BlockA>, usize)>,
        empty: std::sync::mpsc::Sender<Vec<BlockA>>,
        chunk: Vec<BlockA>,
        len: usize,
        next: usize,
    },
}

impl<'p, 'a: 'p> Feed<'p, 'a> {
    /// Start pass A on a thread of `scope`, handing chunks of blocks over a channel (and getting
    /// the used chunks back, so no block is copied or reallocated).
    /// `None` when the thread cannot be started (pass A then runs in line).
    fn threaded<'s>(scope: &'s std::thread::Scope<'s, '_>, mut pass: PassA<'p, 'a>) -> Option<Self>
    where
        'p: 's,
    {
        let (full_tx, full) = std::sync::mpsc::sync_channel::<(Vec<BlockA>, usize)>(2);
        let (empty, empty_rx) = std::sync::mpsc::channel::<Vec<BlockA>>();
        let worker = std::thread::Builder::new().name("aloft-pass-a".into());
        let started = worker.spawn_scoped(scope, move || loop {
            let mut chunk = empty_rx.try_recv().unwrap_or_else(|_| {
                std::iter::repeat_with(|| BlockA::EMPTY)
                    .take(BLOCKS_PER_CHUNK)
                    .collect()
            });
            let mut len = 0;
            while len < BLOCKS_PER_CHUNK && pass.next_block(&mut chunk[len]) {
                len += 1;
            }
            // Pass B hung up (it stopped early) or the mission is done.
            if full_tx.send((chunk, len)).is_err() || len < BLOCKS_PER_CHUNK {
                return;
            }
        });
        started.ok().map(|_| Feed::Threaded {
            full,
            empty,
            chunk: Vec::new(),
            len: 0,
            next: 0,
        })
    }

    /// The next block; pass B asks only for blocks the mission has.
    pub(super) fn next(&mut self) -> &mut BlockA {
        match self {
            Feed::Inline { pass, block } => {
                let more = pass.next_block(block);
                debug_assert!(more, "pass B asked past the mission's end");
                block
            }
            Feed::Threaded {
                full,
                empty,
                chunk,
                len,
                next,
            } => {
                if *next == *len {
                    let used = std::mem::take(chunk);
                    if !used.is_empty() {
                        // Pass A may have finished: then nobody takes it back.
                        let _ = empty.send(used);
                    }
                    (*chunk, *len) = full.recv().expect("pass A's thread ended early");
                    *next = 0;
                }
                *next += 1;
                &mut chunk[*next - 1]
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_mission::m100_survey;
    use super::super::{plan_with, sampler::piece_steps, PlanOptions};
    use super::*;
    use crate::wind::Wind;

    #[test]
    fn pass_a_on_its_own_thread_gives_the_same_report() {
        // At a 10 ms step the survey has over 4096 steps, so `plan` runs pass A on a second
        // thread; the report must be the in-line one exactly, samples included, whether the
        // mission completes, the pack runs out part-way, or pass A meets an error.
        let (aircraft, battery, mission) = m100_survey();
        let steps: usize = mission
            .pieces()
            .iter()
            .map(|p| piece_steps(p, 0.01).0)
            .sum();
        assert!(steps >= THREADED_FROM_STEPS, "{steps}");
        // A grid that covers only the first 100 m east: pass A stops with an error there.
        let grid = crate::wind::WindGrid::from_rows(&[
            [-10.0, -10.0, 0.0, 2.0, 0.0, 0.0],
            [100.0, -10.0, 0.0, 2.0, 0.0, 0.0],
            [-10.0, 400.0, 0.0, 2.0, 0.0, 0.0],
            [100.0, 400.0, 0.0, 2.0, 0.0, 0.0],
            [-10.0, -10.0, 100.0, 2.0, 0.0, 0.0],
            [100.0, -10.0, 100.0, 2.0, 0.0, 0.0],
            [-10.0, 400.0, 100.0, 2.0, 0.0, 0.0],
            [100.0, 400.0, 100.0, 2.0, 0.0, 0.0],
        ])
        .unwrap();
        let mut errors = 0;
        let mut slowed = 0;
        let mut stuck = 0;
        let cases = [
            (1.0, Wind::constant(6.0, 250.0).unwrap()),
            (0.12, Wind::constant(6.0, 250.0).unwrap()),
            // Beyond the M100's tilt on the upwind legs at their speed: flown slower.
            (1.0, Wind::constant(16.0, 250.0).unwrap()),
            // Beyond anything the M100 can fly against: it cannot even climb from the ground in
            // place (it is stopped at take-off, before any segment is slowed).
            (1.0, Wind::constant(30.0, 250.0).unwrap()),
            (1.0, Wind::grid(grid)),
        ];
        for (start_soc, wind) in cases {
            let opts = PlanOptions {
                time_step_s: 0.01,
                record_samples: true,
                start_soc,
                ..PlanOptions::default()
            };
            let threaded = plan_with(&aircraft, &battery, &mission, &wind, &opts, true, true);
            let inline = plan_with(&aircraft, &battery, &mission, &wind, &opts, true, false);
            match (threaded, inline) {
                (Ok(t), Ok(i)) => {
                    assert_eq!(t, i, "start {start_soc}, wind {wind:?}");
                    if start_soc < 1.0 {
                        assert!(!t.feasible && t.samples.len() < steps);
                    }
                    if t.segments.iter().any(|s| s.time_lost_s > 0.0) {
                        slowed += 1;
                    }
                    if matches!(t.shortfall, Some(super::super::Shortfall::NoProgress(_))) {
                        stuck += 1;
                    }
                }
                (Err(t), Err(i)) => {
                    assert!(t.to_string().contains("wind grid"), "{t}");
                    assert_eq!(t.to_string(), i.to_string());
                    errors += 1;
                }
                (t, i) => panic!("threaded {t:?} against in line {i:?}"),
            }
        }
        assert_eq!((errors, slowed, stuck), (1, 1, 1));
    }
}
