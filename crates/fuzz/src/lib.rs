//! # aloft-fuzz
//!
//! A fuzz harness of every parser aloft has, on the stable toolchain (no `cargo fuzz`, no
//! sanitizers): seeded mutations of the repository's fixtures, each input run through the engine
//! as the command line runs it, and five checks per input:
//!
//! 1. no panic ([`std::panic::catch_unwind`], with a silent panic hook during the run);
//! 2. no oversized allocation: no single request over max(256 MiB, 64 x the input's length), no
//!    more than 512 MiB live ([`CountingAlloc`], which the binary and the tests install);
//! 3. bounded time: an input over 2 s is a finding; a watchdog writes an input that runs past
//!    10 s to the findings and aborts the process (a hang);
//! 4. no number that is not finite and no `null` in an answer (the JSON or CSV the command line
//!    would print), and no answer refused by the engine's own finiteness check;
//! 5. a refusal is one line (the error and its causes as the command line prints them).
//!
//! Targets are a table ([`TARGETS`]): a new parser joins with one entry. Findings are written to
//! `fixtures/fuzz/<target>/<hash>.bin`; the test `tests/fuzz.rs` runs every file there through
//! its target and fails on any of the checks, and fuzzes every target briefly.
//!
//! Mutations ([`Mutator`]): bit flips, random bytes, truncation, insertion and deletion of chunks,
//! splices of two inputs, little-endian integers overwritten with extreme values; for text,
//! numbers replaced by extreme values ([`EXTREME_NUMBERS`]), keys by other keys of the seeds, lines
//! dropped, repeated or swapped, CSV columns repeated, `key = value` lines inserted; for MCAP,
//! the record, string and chunk length fields overwritten; for ULog and DataFlash, record sizes,
//! ids, `FMT` lengths and timestamps set to extreme values, the floats of data records to NaN,
//! infinities and extremes, and format characters to other ones ([`log_fields`]); for MAVLink
//! telemetry logs, frame timestamps, lengths, flags and ids, CRCs and payload floats. Inputs that end in a new kind of
//! answer or message join the corpus (a coarse stand-in for coverage feedback). The generator is
//! seeded ([`Rng`]), so a run is reproduced by its seed.

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod alloc;
pub mod check;
pub mod inputs;
pub mod log_fields;
pub mod mutate;
pub mod rng;
pub mod runner;
pub mod seeds;
pub mod targets;

pub use alloc::CountingAlloc;
pub use check::{Answer, Outcome, Problem, Refusal};
pub use mutate::{Format, Mutator, EXTREME_NUMBERS};
pub use rng::Rng;
pub use runner::{fuzz, run_one, Finding, Limits, Report, Run, RunStats, Session};
pub use targets::{target, Target, TARGETS};
