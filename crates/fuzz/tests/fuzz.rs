//! The short fuzz of CI, and the replay of every committed finding.
//!
//! - `every_target_survives_a_short_fuzz`: each target is fuzzed with a fixed number of inputs
//!   ([`short_inputs`]: 4,000, 1,000 to 2,000 for the slower new targets) from a
//!   fixed seed (so the run is the same on every machine; at most 8 s a target, which only the
//!   slow `px4-csv` reaches in a debug build), and any finding fails the test (the input is written
//!   under the target directory's `tmp/fuzz-findings/`; copy it to `fixtures/fuzz/<target>/` with
//!   the fix). The long run is `cargo run --release -p aloft-fuzz -- --target all --inputs N`.
//! - `committed_findings_pass_every_check`: every input under `fixtures/fuzz/<target>/` (inputs
//!   that once failed a check, kept as regressions) passes every check today, notes included.

use std::path::{Path, PathBuf};
use std::time::Duration;

use aloft_fuzz::runner::{fuzz, Limits, Run, Session};
use aloft_fuzz::{seeds, target, TARGETS};

#[global_allocator]
static ALLOC: aloft_fuzz::CountingAlloc = aloft_fuzz::CountingAlloc;

/// Inputs of the short fuzz of `target`: 4,000, fewer for the slower targets added with the
/// planner files and binary logs (a `.plan` plans a whole mission, a log seed is up to 64 KiB),
/// so that each stays near 2 s unloaded (about 6 s for the four) and a busy machine stays under
/// the 8 s cap (the count, not the time, ends the run).
fn short_inputs(target: &str) -> u64 {
    match target {
        "qgc-plan" | "ulog" | "tlog" => 2_000,
        "dataflash" => 1_000,
        _ => 4_000,
    }
}

#[test]
fn every_target_survives_a_short_fuzz() {
    let session = Session::new(Limits::default(), None);
    assert!(
        session.counts_memory(),
        "the counting allocator is not installed"
    );
    let findings = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz-findings");
    let mut failed = Vec::new();
    for t in TARGETS {
        let run = Run {
            inputs: short_inputs(t.name),
            time: Duration::from_secs(8),
            seed: 13,
            findings: Some(findings.clone()),
            notes: None,
            progress: None,
        };
        let s = fuzz(&session, t, &run);
        eprintln!(
            "{}: {} inputs in {:.1} s, {} accepted, corpus {}, {} findings, {} notes",
            s.target,
            s.inputs,
            s.seconds,
            s.accepted,
            s.corpus,
            s.findings.len(),
            s.notes.len()
        );
        // Every seed ran and the parser accepted some of the inputs (a target whose seeds all
        // fail to parse fuzzes nothing but the error path).
        assert!(s.inputs >= (t.seeds)().len() as u64, "{}", t.name);
        assert!(s.accepted > 0, "{}: no input was accepted", t.name);
        for f in &s.findings {
            for p in &f.problems {
                failed.push(format!(
                    "{} {}: {}: {}",
                    t.name,
                    f.name(),
                    p.check,
                    p.detail
                ));
            }
        }
    }
    assert!(
        failed.is_empty(),
        "findings (inputs in {}):\n{}",
        findings.display(),
        failed.join("\n")
    );
}

fn committed() -> Vec<(String, PathBuf)> {
    let root = seeds::repo_root().join("fixtures/fuzz");
    let mut out = Vec::new();
    let Ok(dirs) = std::fs::read_dir(&root) else {
        return out;
    };
    for d in dirs.flatten() {
        let name = d.file_name().to_string_lossy().into_owned();
        let Ok(files) = std::fs::read_dir(d.path()) else {
            continue;
        };
        for f in files.flatten() {
            if f.path().extension().is_some_and(|e| e == "bin") {
                out.push((name.clone(), f.path()));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn committed_findings_pass_every_check() {
    let files = committed();
    assert!(!files.is_empty(), "no inputs under fixtures/fuzz");
    let session = Session::new(Limits::default(), None);
    let mut failed = Vec::new();
    for (name, path) in &files {
        let t = target(name).unwrap_or_else(|| panic!("fixtures/fuzz/{name}: no such target"));
        let input = std::fs::read(path).unwrap();
        let r = session.run(t, &input);
        // Notes too: a committed input is one whose problem was fixed.
        for p in r.problems.iter().chain(&r.notes) {
            failed.push(format!("{}: {}: {}", path.display(), p.check, p.detail));
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
