//! Helpers of aloft-link's integration tests: the shared data folder and whole-file reads.
#![allow(dead_code)] // not every test file uses every helper

use std::collections::BTreeMap;
use std::path::PathBuf;

use aloft_link::mavlink::Message;
use aloft_link::{Telemetry, TlogFrame, TlogReader, TlogSource, TlogStats};

#[path = "../../../../tests/it/common/data.rs"]
mod data;
pub use data::data_dir;

/// A shared telemetry log by its file stem.
pub fn tlog(stem: &str) -> PathBuf {
    data_dir().join("telemetry").join(format!("{stem}.tlog"))
}

/// The bytes of a shared telemetry log.
pub fn tlog_bytes(stem: &str) -> Vec<u8> {
    let p = tlog(stem);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Every frame of `bytes` and the reader's statistics.
pub fn frames(bytes: &[u8]) -> (Vec<TlogFrame>, TlogStats) {
    let mut r = TlogReader::new(bytes, "test");
    let frames: Vec<TlogFrame> = r.by_ref().map(|f| f.expect("no read error")).collect();
    (frames, *r.stats())
}

/// Frames per message name.
pub fn counts(frames: &[TlogFrame]) -> BTreeMap<&'static str, u64> {
    let mut c = BTreeMap::new();
    for f in frames {
        *c.entry(f.message.message_name()).or_default() += 1;
    }
    c
}

/// Every event of a shared telemetry log.
pub fn events(stem: &str) -> Vec<Telemetry> {
    let mut s = TlogSource::open(&tlog(stem)).expect("open");
    let mut out = Vec::new();
    while let Some(t) = s.next_telemetry().expect("no read error") {
        out.push(t);
    }
    out
}
