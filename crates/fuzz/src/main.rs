//! `aloft-fuzz`: fuzz aloft's parsers on the stable toolchain.
//!
//! ```sh
//! cargo run --release -p aloft-fuzz -- --target all --inputs 10000000
//! cargo run --release -p aloft-fuzz -- --target mcap --seconds 60 --seed 7
//! cargo run --release -p aloft-fuzz -- --target mcap --replay fixtures/fuzz/mcap/0123abcd.bin
//! ```
//!
//! Exit codes: 0 no finding, 1 findings (written to `fixtures/fuzz/<target>/`), 2 bad arguments.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;

use aloft_fuzz::runner::{fuzz, Limits, Run, Session};
use aloft_fuzz::{seeds, target, Target, TARGETS};

#[global_allocator]
static ALLOC: aloft_fuzz::CountingAlloc = aloft_fuzz::CountingAlloc;

/// Fuzz aloft's parsers: seeded mutations of the fixtures, each input checked for panics,
/// oversized allocations, slowness, non-finite answers and multi-line errors.
#[derive(Debug, Parser)]
#[command(version)]
struct Args {
    /// Target to fuzz, or `all` (see --list).
    #[arg(long, default_value = "all")]
    target: String,
    /// Most inputs per target (seeds included).
    #[arg(long, default_value_t = u64::MAX)]
    inputs: u64,
    /// Most seconds per target (whichever of --inputs and --seconds comes first).
    #[arg(long)]
    seconds: Option<f64>,
    /// Seed of the mutations (a run is reproduced by its seed).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Where findings are written (default: fixtures/fuzz of the repository).
    #[arg(long)]
    findings: Option<PathBuf>,
    /// Where notes (answers the engine refused as not finite) and each target's slowest input
    /// (`<target>/slowest.input`) are written (default: not written).
    #[arg(long)]
    notes: Option<PathBuf>,
    /// Seconds between progress lines on stderr (0: none).
    #[arg(long, default_value_t = 10.0)]
    progress: f64,
    /// Run these files through the target once, print what each did, and exit.
    #[arg(long, num_args = 1..)]
    replay: Vec<PathBuf>,
    /// Print the most frequent refusals of each target at the end.
    #[arg(long)]
    verbose: bool,
    /// Write the seeds of the target(s) to this directory (`<dir>/<target>/<n>.bin`) and exit.
    #[arg(long)]
    write_seeds: Option<PathBuf>,
    /// List the targets and exit.
    #[arg(long)]
    list: bool,
}

fn main() -> ExitCode {
    let args = Args::parse();
    if args.list {
        for t in TARGETS {
            println!("{:<14} {}", t.name, t.about);
        }
        return ExitCode::SUCCESS;
    }
    let Some(targets) = selected(&args.target) else {
        return ExitCode::from(2);
    };
    if let Some(dir) = &args.write_seeds {
        return write_seeds(&targets, dir);
    }
    if args.inputs == u64::MAX && args.seconds.is_none() && args.replay.is_empty() {
        eprintln!("aloft-fuzz: error: give --inputs or --seconds (or both)");
        return ExitCode::from(2);
    }
    let findings = args
        .findings
        .clone()
        .unwrap_or_else(|| seeds::repo_root().join("fixtures/fuzz"));
    let session = Session::new(Limits::default(), Some(findings.clone()));
    if !session.counts_memory() {
        eprintln!("aloft-fuzz: warning: the counting allocator is not installed; no memory checks");
    }
    if !args.replay.is_empty() {
        return replay(&session, targets[0], &args.replay);
    }
    let run = Run {
        inputs: args.inputs,
        time: args
            .seconds
            .map_or(Duration::MAX, |s| Duration::from_secs_f64(s.max(0.0))),
        seed: args.seed,
        findings: Some(findings),
        notes: args.notes.clone(),
        progress: (args.progress > 0.0).then(|| Duration::from_secs_f64(args.progress)),
    };
    println!(
        "target,inputs,seconds,inputs_per_s,accepted,corpus,finding_inputs,findings,note_inputs,notes,slowest_s,seed"
    );
    let mut any = false;
    for t in targets {
        let s = fuzz(&session, t, &run);
        any |= !s.findings.is_empty();
        report(&s, &args);
    }
    if any {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// The targets `name` selects (`all`, or one by name); none, with the error printed, for an
/// unknown name.
fn selected(name: &str) -> Option<Vec<&'static Target>> {
    if name == "all" {
        return Some(TARGETS.iter().collect());
    }
    match target(name) {
        Some(t) => Some(vec![t]),
        None => {
            let known: Vec<&str> = TARGETS.iter().map(|t| t.name).collect();
            eprintln!(
                "aloft-fuzz: error: unknown target '{name}' (known: all, {})",
                known.join(", ")
            );
            None
        }
    }
}

/// Write each target's seeds to `dir/<target>/<k>.bin`.
fn write_seeds(targets: &[&Target], dir: &std::path::Path) -> ExitCode {
    for t in targets {
        let d = dir.join(t.name);
        for (k, s) in (t.seeds)().iter().enumerate() {
            let written = std::fs::create_dir_all(&d)
                .and_then(|()| std::fs::write(d.join(format!("{k}.bin")), s));
            if let Err(e) = written {
                eprintln!("aloft-fuzz: error: cannot write to {}: {e}", d.display());
                return ExitCode::from(2);
            }
        }
    }
    aloft_fuzz::inputs::remove_scratch();
    ExitCode::SUCCESS
}

/// One target's CSV row on stdout; its slowest input beside the notes; with `--verbose` its
/// most common refusals on stderr.
fn report(s: &aloft_fuzz::runner::RunStats, args: &Args) {
    println!(
        "{},{},{:.1},{:.0},{},{},{},{},{},{},{:.3},{}",
        s.target,
        s.inputs,
        s.seconds,
        s.inputs as f64 / s.seconds.max(1e-9),
        s.accepted,
        s.corpus,
        s.finding_inputs,
        s.findings.len(),
        s.note_inputs,
        s.notes.len(),
        s.slowest_s,
        args.seed
    );
    if let Some(dir) = &args.notes {
        // The slowest input, for a look at what takes long.
        let d = dir.join(s.target);
        let _ = std::fs::create_dir_all(&d)
            .and_then(|()| std::fs::write(d.join("slowest.input"), &s.slowest));
    }
    if args.verbose {
        for (line, n) in &s.top_refusals {
            eprintln!("aloft-fuzz: {}: {n} x {line}", s.target);
        }
    }
}

/// Run each file once and print its outcome and problems.
fn replay(session: &Session, t: &Target, files: &[PathBuf]) -> ExitCode {
    let mut any = false;
    for f in files {
        let input = match std::fs::read(f) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("aloft-fuzz: error: cannot read {}: {e}", f.display());
                return ExitCode::from(2);
            }
        };
        let r = session.run(t, &input);
        println!(
            "{}: {:.3?}, largest request {} B, peak live {} B",
            f.display(),
            r.elapsed,
            r.memory.largest_request,
            r.memory.peak_live
        );
        if let Some(o) = &r.outcome {
            for x in &o.refusals {
                println!("  refused ({}): {}", x.what, x.line);
            }
            for a in &o.answers {
                println!("  answer: {a:?}");
            }
        }
        for p in &r.notes {
            println!("  NOTE {}: {}", p.check, p.detail);
        }
        for p in &r.problems {
            any = true;
            println!("  PROBLEM {}: {}", p.check, p.detail);
        }
    }
    if any {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
