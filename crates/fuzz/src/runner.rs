//! Running inputs: one input with every check ([`Session::run`]), and a fuzzing run of one target
//! ([`fuzz`]): seeds first, then mutants, new kinds of answers kept in the corpus, findings
//! written as they are found.

use std::collections::{HashMap, HashSet};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, OnceLock};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::alloc;
use crate::check::{problems, Answer, Outcome, Problem};
use crate::inputs::remove_scratch;
use crate::mutate::Mutator;
use crate::rng::{fnv1a, Rng};
use crate::targets::Target;

/// The limits of one input.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// An input that takes longer is a finding.
    pub slow: Duration,
    /// An input still running after this is a hang: the watchdog writes it and aborts.
    pub hang: Duration,
    /// A single allocation request over max(this, `request_per_byte` x the input's length) is a
    /// finding, bytes.
    pub request_floor: usize,
    /// See `request_floor`.
    pub request_per_byte: usize,
    /// More live bytes than this at any moment of an input is a finding.
    pub live: usize,
}

impl Default for Limits {
    /// 2 s and 10 s in an optimised build; ten times that in a debug build (the test), whose code
    /// runs 10 to 30 times slower. Memory: 256 MiB or 64 bytes per input byte in one request,
    /// 512 MiB live.
    fn default() -> Self {
        let scale = if cfg!(debug_assertions) { 10 } else { 1 };
        Self {
            slow: Duration::from_secs(2 * scale),
            hang: Duration::from_secs(10 * scale),
            request_floor: 256 << 20,
            request_per_byte: 64,
            live: 512 << 20,
        }
    }
}

/// What one input did.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The outcome, unless the target panicked.
    pub outcome: Option<Outcome>,
    /// Every failed check (notes apart).
    pub problems: Vec<Problem>,
    /// Notes: answers the engine refused as not finite ([`crate::check::is_note`]).
    pub notes: Vec<Problem>,
    /// Wall time.
    pub elapsed: Duration,
    /// Memory figures (zero when the counting allocator is not installed).
    pub memory: alloc::MemoryUse,
}

/// One failed check of one input: what to write and print.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// The target.
    pub target: &'static str,
    /// The failed checks.
    pub problems: Vec<Problem>,
    /// The input.
    pub input: Vec<u8>,
}

impl Finding {
    /// Short hash of the input: its file name.
    pub fn name(&self) -> String {
        format!("{:016x}.bin", fnv1a(&self.input))
    }

    /// Write the input to `dir/<target>/<hash>.bin`.
    ///
    /// # Errors
    /// The directory or the file cannot be written.
    pub fn write(&self, dir: &Path) -> std::io::Result<PathBuf> {
        let d = dir.join(self.target);
        std::fs::create_dir_all(&d)?;
        let p = d.join(self.name());
        std::fs::write(&p, &self.input)?;
        Ok(p)
    }
}

/// The input being run, for the watchdog.
struct Current {
    target: &'static str,
    started: Instant,
    hang: Duration,
    input: Vec<u8>,
    findings: Option<PathBuf>,
}

static CURRENT: Mutex<Option<Current>> = Mutex::new(None);
static EXCLUSIVE: Mutex<()> = Mutex::new(());
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

fn lock<T>(m: &'static Mutex<T>) -> MutexGuard<'static, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Start the watchdog thread once: it aborts the process when an input runs past its hang
/// limit, after writing the input to the findings directory (or stderr, in hex).
fn watchdog() {
    static STARTED: OnceLock<()> = OnceLock::new();
    STARTED.get_or_init(|| {
        std::thread::spawn(|| loop {
            std::thread::sleep(Duration::from_millis(200));
            let cur = lock(&CURRENT);
            let Some(c) = cur.as_ref() else { continue };
            if c.started.elapsed() < c.hang {
                continue;
            }
            let finding = Finding {
                target: c.target,
                problems: Vec::new(),
                input: c.input.clone(),
            };
            let written = c.findings.as_ref().map(|d| finding.write(d));
            eprintln!(
                "aloft-fuzz: HANG: {} input ran for more than {:?}; {}",
                c.target,
                c.hang,
                match written {
                    Some(Ok(p)) => format!("input written to {}", p.display()),
                    _ => format!("input (hex): {}", hex(&c.input)),
                }
            );
            std::process::abort();
        });
    });
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// A fuzzing session: inputs run one at a time in this process (the memory figures are
/// process-wide), the watchdog armed; panics are silent while an input runs.
pub struct Session {
    _exclusive: MutexGuard<'static, ()>,
    limits: Limits,
    findings: Option<PathBuf>,
    counting: bool,
}

/// The panic hook while an input runs: no message on stderr, the message and place kept for the
/// finding.
fn silent_hook(info: &std::panic::PanicHookInfo<'_>) {
    let msg = info
        .payload()
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| info.payload().downcast_ref::<String>().cloned())
        .unwrap_or_default();
    let at = info
        .location()
        .map(|l| format!(" at {}:{}", l.file(), l.line()))
        .unwrap_or_default();
    *lock(&LAST_PANIC) = Some(format!("{msg}{at}"));
}

impl Session {
    /// A session with `limits`; a hang is written under `findings` when given.
    pub fn new(limits: Limits, findings: Option<PathBuf>) -> Self {
        let exclusive = lock(&EXCLUSIVE);
        watchdog();
        Self {
            _exclusive: exclusive,
            limits,
            findings,
            counting: alloc::installed(),
        }
    }

    /// Whether the memory checks are on (the counting allocator is installed).
    pub fn counts_memory(&self) -> bool {
        self.counting
    }

    /// Run one input through `target` with every check.
    pub fn run(&self, target: &Target, input: &[u8]) -> Report {
        *lock(&CURRENT) = Some(Current {
            target: target.name,
            started: Instant::now(),
            hang: self.limits.hang,
            input: input.to_vec(),
            findings: self.findings.clone(),
        });
        // The silent hook only while the input runs: a panic of the caller (a failed assertion
        // of a test) is reported as usual.
        let previous_hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(silent_hook));
        let baseline = alloc::start();
        let started = Instant::now();
        let result = catch_unwind(AssertUnwindSafe(|| (target.run)(input)));
        let elapsed = started.elapsed();
        let memory = alloc::since(baseline);
        std::panic::set_hook(previous_hook);
        *lock(&CURRENT) = None;
        let (outcome, mut found) = match result {
            Ok(o) => {
                let p = problems(&o);
                (Some(o), p)
            }
            Err(_) => (
                None,
                vec![Problem {
                    check: "panic",
                    detail: lock(&LAST_PANIC).take().unwrap_or_default(),
                }],
            ),
        };
        self.limit_problems(input.len(), elapsed, memory, &mut found);
        let (notes, found) = found.into_iter().partition(crate::check::is_note);
        Report {
            outcome,
            problems: found,
            notes,
            elapsed,
            memory,
        }
    }

    fn limit_problems(
        &self,
        len: usize,
        elapsed: Duration,
        m: alloc::MemoryUse,
        found: &mut Vec<Problem>,
    ) {
        let l = &self.limits;
        if elapsed > l.slow {
            found.push(Problem {
                check: "slow",
                detail: format!("{elapsed:.2?} (limit {:?})", l.slow),
            });
        }
        let request_limit = l.request_floor.max(l.request_per_byte.saturating_mul(len));
        if self.counting && m.largest_request > request_limit {
            found.push(Problem {
                check: "allocation",
                detail: format!(
                    "one request of {} bytes (limit {request_limit})",
                    m.largest_request
                ),
            });
        }
        if self.counting && m.peak_live > l.live {
            found.push(Problem {
                check: "memory",
                detail: format!("{} bytes live (limit {})", m.peak_live, l.live),
            });
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        remove_scratch();
    }
}

/// Run one input through `target` in a session of its own (for replaying a finding).
pub fn run_one(target: &Target, input: &[u8]) -> Report {
    Session::new(Limits::default(), None).run(target, input)
}

/// How long to fuzz one target, and where findings go.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Most inputs (seeds included).
    pub inputs: u64,
    /// Most wall time.
    pub time: Duration,
    /// Seed of the generator.
    pub seed: u64,
    /// Directory findings are written to (`fixtures/fuzz`), if any.
    pub findings: Option<PathBuf>,
    /// Directory notes are written to, if any.
    pub notes: Option<PathBuf>,
    /// Progress lines on stderr every this often, if any.
    pub progress: Option<Duration>,
}

/// The figures of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunStats {
    /// The target.
    pub target: &'static str,
    /// Inputs run (seeds included).
    pub inputs: u64,
    /// Inputs the parser accepted.
    pub accepted: u64,
    /// Wall time, s.
    pub seconds: f64,
    /// Corpus size at the end.
    pub corpus: usize,
    /// Inputs with a failed check.
    pub finding_inputs: u64,
    /// Distinct findings (by check and message, numbers left out), the first input of each.
    pub findings: Vec<Finding>,
    /// Inputs with a note.
    pub note_inputs: u64,
    /// Distinct notes, the first input of each.
    pub notes: Vec<Finding>,
    /// Slowest input, s.
    pub slowest_s: f64,
    /// The slowest input.
    pub slowest: Vec<u8>,
    /// The most frequent refusals (message without numbers and quotes) and their counts.
    pub top_refusals: Vec<(String, u64)>,
}

/// A coarse picture of an outcome: refusal messages without numbers and quoted text, the shape
/// of each answer. An input with a picture not seen before joins the corpus.
fn signature(o: Option<&Outcome>) -> u64 {
    let Some(o) = o else { return 0 };
    let mut text = String::new();
    text.push(if o.accepted { 'A' } else { 'R' });
    for r in &o.refusals {
        text.push_str(r.what);
        text.push_str(&normalise(&r.line));
    }
    for a in &o.answers {
        match a {
            Answer::Json { what, value } => {
                text.push_str(what);
                shape(value, &mut text);
            }
            Answer::Csv { what, text: t, .. } => {
                text.push_str(what);
                text.push_str(&t.lines().count().min(4).to_string());
            }
        }
    }
    fnv1a(text.as_bytes())
}

/// A message without digits, quoted text or file paths, at most 120 characters.
fn normalise(line: &str) -> String {
    let mut out = String::new();
    let mut quote: Option<char> = None;
    for c in line.chars() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if c == '\'' || c == '"' || c == '`' => {
                quote = Some(c);
                out.push('Q');
            }
            None if c.is_ascii_digit() => {}
            // What follows is a list quoted from the input (`found: a,b,c`).
            None if c == '(' => break,
            None => out.push(c),
        }
        if out.len() >= 120 {
            break;
        }
    }
    out
}

fn shape(v: &Value, out: &mut String) {
    match v {
        Value::Object(m) => {
            out.push('{');
            for (k, x) in m {
                out.push_str(k);
                shape(x, out);
            }
            out.push('}');
        }
        Value::Array(a) => {
            out.push('[');
            if let Some(x) = a.first() {
                shape(x, out);
            }
            out.push(']');
        }
        Value::Bool(b) => out.push(if *b { 't' } else { 'f' }),
        Value::Null => out.push('n'),
        Value::Number(_) => out.push('#'),
        Value::String(_) => out.push('s'),
    }
}

/// Largest input kept in the corpus, bytes.
const CORPUS_INPUT: usize = 64 << 10;
/// Most accepted inputs in the corpus.
const ACCEPTED_SIZE: usize = 2048;
/// Most refused inputs in the corpus.
const REFUSED_SIZE: usize = 512;

/// The inputs mutants are made from: the seeds, inputs the parser accepted with an answer of a
/// new shape, inputs it refused with a new kind of message. A base is a seed 40 % of the time,
/// an accepted input 40 %, a refused one 20 %, so that most mutants stay close to valid input.
struct Corpus {
    seeds: Vec<Vec<u8>>,
    accepted: Vec<Vec<u8>>,
    refused: Vec<Vec<u8>>,
    seen: HashSet<u64>,
}

impl Corpus {
    fn pick<'a>(&'a self, rng: &mut Rng) -> &'a [u8] {
        let pool = match rng.below(5) {
            0 | 1 => &self.accepted,
            2 => &self.refused,
            _ => &self.seeds,
        };
        let pool = if pool.is_empty() { &self.seeds } else { pool };
        if pool.is_empty() {
            return &[];
        }
        &pool[rng.below(pool.len())]
    }

    fn offer(&mut self, input: &[u8], report: &Report) {
        if !self.seen.insert(signature(report.outcome.as_ref())) || input.len() > CORPUS_INPUT {
            return;
        }
        let accepted = report.outcome.as_ref().is_some_and(|o| o.accepted);
        let (pool, cap) = if accepted {
            (&mut self.accepted, ACCEPTED_SIZE)
        } else {
            (&mut self.refused, REFUSED_SIZE)
        };
        if pool.len() < cap {
            pool.push(input.to_vec());
        }
    }

    fn len(&self) -> usize {
        self.seeds.len() + self.accepted.len() + self.refused.len()
    }
}

/// Fuzz `target` in `session` for `run`'s inputs or time, whichever ends first.
pub fn fuzz(session: &Session, target: &Target, run: &Run) -> RunStats {
    let started = Instant::now();
    let seeds = (target.seeds)();
    let mutator = Mutator::new(target.format, &seeds);
    let mut rng = Rng::new(run.seed ^ fnv1a(target.name.as_bytes()));
    let mut corpus = Corpus {
        seeds: seeds.clone(),
        accepted: Vec::new(),
        refused: Vec::new(),
        seen: HashSet::new(),
    };
    let mut refusals: HashMap<String, u64> = HashMap::new();
    let mut kept = Kept::default();
    let mut stats = RunStats::new(target.name);
    let mut last_progress = Instant::now();
    let mut k = 0usize;
    while stats.inputs < run.inputs && started.elapsed() < run.time {
        let input = if k < seeds.len() {
            seeds[k].clone()
        } else {
            let base = corpus.pick(&mut rng);
            let other = corpus.pick(&mut rng);
            mutator.mutate(&mut rng, base, other)
        };
        k += 1;
        let report = session.run(target, &input);
        stats.inputs += 1;
        if report.elapsed.as_secs_f64() > stats.slowest_s {
            stats.slowest_s = report.elapsed.as_secs_f64();
            stats.slowest = input.clone();
        }
        match report.outcome.as_ref() {
            Some(o) if o.accepted => stats.accepted += 1,
            Some(o) => {
                if let Some(r) = o.refusals.first() {
                    let key: String = normalise(&r.line).chars().take(60).collect();
                    *refusals.entry(key).or_insert(0) += 1;
                }
            }
            None => {}
        }
        corpus.offer(&input, &report);
        kept.book(&mut stats, run, input, report);
        if let Some(every) = run.progress {
            if last_progress.elapsed() >= every {
                last_progress = Instant::now();
                eprintln!("{}", progress_line(&stats, started, corpus.len()));
            }
        }
    }
    stats.seconds = started.elapsed().as_secs_f64();
    stats.corpus = corpus.len();
    let mut top: Vec<(String, u64)> = refusals.into_iter().collect();
    top.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    top.truncate(8);
    stats.top_refusals = top;
    stats
}

impl RunStats {
    /// Nothing run yet.
    fn new(target: &'static str) -> Self {
        Self {
            target,
            inputs: 0,
            accepted: 0,
            seconds: 0.0,
            corpus: 0,
            finding_inputs: 0,
            findings: Vec::new(),
            note_inputs: 0,
            notes: Vec::new(),
            slowest_s: 0.0,
            slowest: Vec::new(),
            top_refusals: Vec::new(),
        }
    }
}

/// The kinds of findings and notes kept so far in a run (one input of each kind is kept).
#[derive(Default)]
struct Kept {
    findings: HashSet<String>,
    notes: HashSet<String>,
}

impl Kept {
    /// Count an input's notes and findings and keep the first input of each new kind.
    fn book(&mut self, stats: &mut RunStats, run: &Run, input: Vec<u8>, report: Report) {
        if !report.notes.is_empty() {
            stats.note_inputs += 1;
            let f = Finding {
                target: stats.target,
                problems: report.notes,
                input: input.clone(),
            };
            keep(
                &mut stats.notes,
                &mut self.notes,
                f,
                run.notes.as_deref(),
                "NOTE",
            );
        }
        if !report.problems.is_empty() {
            stats.finding_inputs += 1;
            let f = Finding {
                target: stats.target,
                problems: report.problems,
                input,
            };
            keep(
                &mut stats.findings,
                &mut self.findings,
                f,
                run.findings.as_deref(),
                "FINDING",
            );
        }
    }
}

fn progress_line(stats: &RunStats, started: Instant, corpus: usize) -> String {
    let s = started.elapsed().as_secs_f64();
    format!(
        "aloft-fuzz: {}: {} inputs in {:.0} s ({:.0}/s), {} accepted, corpus {}, {} findings ({} inputs), {} notes",
        stats.target,
        stats.inputs,
        s,
        stats.inputs as f64 / s.max(1e-9),
        stats.accepted,
        corpus,
        stats.findings.len(),
        stats.finding_inputs,
        stats.notes.len()
    )
}

/// Keep the first input of each distinct finding (by check and message, numbers and quoted text
/// left out; at most 1000); write and print it.
fn keep(
    kept: &mut Vec<Finding>,
    keys: &mut HashSet<String>,
    finding: Finding,
    dir: Option<&Path>,
    label: &str,
) {
    let key: String = finding
        .problems
        .iter()
        .map(|p| format!("{}:{}", p.check, normalise(&p.detail)))
        .collect::<Vec<_>>()
        .join("|");
    if kept.len() >= 1000 || !keys.insert(key) {
        return;
    }
    let place = match dir.map(|d| finding.write(d)) {
        Some(Ok(p)) => p.display().to_string(),
        Some(Err(e)) => format!("(not written: {e})"),
        None => finding.name(),
    };
    for p in &finding.problems {
        eprintln!(
            "aloft-fuzz: {label} {} {place}: {}: {}",
            finding.target, p.check, p.detail
        );
    }
    kept.push(finding);
}
