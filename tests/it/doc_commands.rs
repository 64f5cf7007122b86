//! The documented commands are tests: every `aloft` command in `README.md` and `docs/*.md` runs
//! here, in the order the document gives them, with its documented exit code; where the
//! document shows what a command prints, every line shown must be in what it prints, in order.
//! A README example can then never fail again unnoticed, nor its figures drift from the code.
//!
//! # How the documents are read
//! - A command is a line of a fenced code block that starts with `aloft ` or `$ aloft ` (or the
//!   quick start's `cargo run --release -- `, which runs the same program), continued over lines
//!   that end with a backslash. Blocks of other programs (`cargo test`, `pip`, the fuzz runner's
//!   `cargo run -p aloft-fuzz`) are not run, but for the few tools a document uses to prepare a
//!   file for the next command (`head`, `cp`, `mkdir`, `printf`: [`PREPARING`]), which run too.
//! - A command runs in `sh` (so its variables, globs and comments behave as in a terminal) with
//!   the `aloft` under test first on `PATH`. Lines of the form `NAME=value` in a block set a
//!   variable for the commands after them in that document.
//! - The exit code is 0 unless the command says otherwise in a comment: `# exit 1`.
//! - A server (`aloft serve`) says `# until stopped`: it runs until what the document shows has
//!   been printed (at most [`SERVER_WAIT`]) and must still be running then; it is then stopped.
//! - Output: in a block whose commands start with `$ `, the lines after a command (up to the next
//!   `$ ` line or the block's end) are what it prints, abridged: each must appear in its stdout
//!   and stderr, in that order; a line `...` stands for lines left out, and `...` within a line
//!   for any text there.
//! - Each document runs in a fresh directory of its own, where `fixtures/` is the repository's
//!   and `../shared` the shared data's (from `ALOFT_DATA_DIR`), so the commands read the files
//!   they name and write theirs there, and a command may read what an earlier one wrote (a
//!   `fit` writes the vehicle a `validate` reads). A page under `docs/` without commands is
//!   skipped.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// One command of a document, with what the document says of it.
#[derive(Debug)]
struct DocCommand {
    /// Line number in the document (from 1).
    line: usize,
    /// The command as the shell runs it (continuations joined).
    text: String,
    /// The documented exit code.
    exit: i32,
    /// The output shown (abridged), when the document shows it.
    shown: Vec<String>,
}

/// The fenced code blocks of a markdown text: (first line number, lines).
fn blocks(text: &str) -> Vec<(usize, Vec<&str>)> {
    let mut out = Vec::new();
    let mut current: Option<(usize, Vec<&str>)> = None;
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            match current.take() {
                Some(b) => out.push(b),
                None => current = Some((i + 2, Vec::new())),
            }
        } else if let Some((_, lines)) = current.as_mut() {
            lines.push(line);
        }
    }
    out
}

/// The tools a document may use to prepare a file for the next aloft command (a truncated copy
/// of a log, a folder): run as they are written.
const PREPARING: [&str; 4] = ["head ", "cp ", "mkdir ", "printf "];

/// The command a line runs: an aloft command (`aloft ...`), or a [`PREPARING`] tool's.
fn runnable(line: &str) -> Option<String> {
    if let Some(rest) = aloft_command(line) {
        return Some(format!("aloft {rest}"));
    }
    let line = line.strip_prefix("$ ").unwrap_or(line);
    PREPARING
        .iter()
        .any(|tool| line.starts_with(tool))
        .then(|| line.to_string())
}

/// The program the command line runs, when it is aloft.
fn aloft_command(line: &str) -> Option<&str> {
    let line = line.strip_prefix("$ ").unwrap_or(line);
    if let Some(rest) = line.strip_prefix("cargo run --release -- ") {
        return Some(rest);
    }
    line.starts_with("aloft ").then(|| &line["aloft ".len()..])
}

/// The exit code a command documents (`# exit N`), else 0.
fn documented_exit(text: &str) -> i32 {
    text.split("# exit ")
        .nth(1)
        .map(|rest| {
            rest.chars()
                .take_while(char::is_ascii_digit)
                .collect::<String>()
        })
        .and_then(|n| n.parse().ok())
        .unwrap_or(0)
}

/// The variables (`NAME=value` lines) and commands of a document, in order.
fn commands(text: &str) -> (Vec<(usize, String)>, Vec<DocCommand>) {
    let mut vars = Vec::new();
    let mut cmds = Vec::new();
    for (first, lines) in blocks(text) {
        let mut k = 0;
        while k < lines.len() {
            let line = lines[k];
            let is_var = line.split_once('=').is_some_and(|(name, _)| {
                !name.is_empty() && name.chars().all(|c| c.is_ascii_uppercase() || c == '_')
            });
            if is_var {
                vars.push((cmds.len(), line.to_string()));
                k += 1;
                continue;
            }
            let Some(mut text) = runnable(line) else {
                k += 1;
                continue;
            };
            let console = line.starts_with("$ ");
            let start = k;
            while text.trim_end().ends_with('\\') && k + 1 < lines.len() {
                k += 1;
                text = format!("{}\n{}", text.trim_end(), lines[k]);
            }
            let mut shown = Vec::new();
            if console {
                while k + 1 < lines.len() && !lines[k + 1].starts_with("$ ") {
                    k += 1;
                    shown.push(lines[k].trim_end().to_string());
                }
            }
            cmds.push(DocCommand {
                line: first + start,
                exit: documented_exit(&text),
                text,
                shown,
            });
            k += 1;
        }
    }
    (vars, cmds)
}

/// Whether `actual` (one line) matches the shown `pattern`, in which `...` stands for any text.
fn line_matches(pattern: &str, actual: &str) -> bool {
    let pattern = pattern.trim_end();
    let actual = actual.trim_end();
    let pieces: Vec<&str> = pattern.split("...").collect();
    if pieces.len() == 1 {
        return pattern == actual;
    }
    let (first, last) = (pieces[0], pieces[pieces.len() - 1]);
    if !actual.starts_with(first) || !actual[first.len()..].ends_with(last) {
        return false;
    }
    let mut rest = &actual[first.len()..actual.len() - last.len()];
    for piece in &pieces[1..pieces.len() - 1] {
        match rest.find(piece) {
            Some(at) => rest = &rest[at + piece.len()..],
            None => return false,
        }
    }
    true
}

/// The first shown line that is not in `output` in order, if any.
fn missing_line(shown: &[String], output: &str) -> Option<String> {
    let mut lines = output.lines();
    for want in shown {
        if want.trim() == "..." || want.trim().is_empty() {
            continue;
        }
        if !lines.by_ref().any(|l| line_matches(want, l)) {
            return Some(want.clone());
        }
    }
    None
}

fn data_dir() -> PathBuf {
    let dir = std::env::var("ALOFT_DATA_DIR").unwrap_or_else(|_| "../shared/data".to_string());
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    assert!(
        dir.is_dir(),
        "{}: set ALOFT_DATA_DIR to shared/data",
        dir.display()
    );
    dir.canonicalize().unwrap()
}

/// A fresh directory to run a document's commands in: `work/` with `fixtures/` linked to the
/// repository's, beside `shared/` linked to the shared data's parent.
fn sandbox(name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("doc-commands-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let work = root.join("work");
    std::fs::create_dir_all(&work).unwrap();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::os::unix::fs::symlink(repo.join("fixtures"), work.join("fixtures")).unwrap();
    std::os::unix::fs::symlink(data_dir().parent().unwrap(), root.join("shared")).unwrap();
    work
}

/// Run every command of the document at `path` (relative to the repository); the failures.
fn run_document(path: &str) -> Vec<String> {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap();
    let (vars, cmds) = commands(&text);
    if cmds.is_empty() {
        // A page under docs/ may have none (python.md); the README always has some.
        assert!(path != "README.md", "{path}: no aloft command found");
        return Vec::new();
    }
    let work = sandbox(&path.replace('/', "_"));
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_aloft")).parent().unwrap();
    let path_var = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut failures = Vec::new();
    for (k, cmd) in cmds.iter().enumerate() {
        let env: Vec<&str> = vars
            .iter()
            .filter(|(before, _)| *before <= k)
            .map(|(_, v)| v.as_str())
            .collect();
        let at = format!("{path}:{}: `{}`", cmd.line, cmd.text.replace('\n', " "));
        if cmd.text.contains(UNTIL_STOPPED) {
            let script = format!("{}\nexec {}", env.join("\n"), cmd.text);
            let mut server = Command::new("sh");
            server
                .arg("-c")
                .arg(&script)
                .current_dir(&work)
                .env("PATH", &path_var);
            if let Err(e) = run_server(server, &cmd.shown) {
                failures.push(format!("{at}: {e}"));
            }
            continue;
        }
        let script = format!("{}\n{}", env.join("\n"), cmd.text);
        let out = Command::new("sh")
            .arg("-c")
            .arg(&script)
            .current_dir(&work)
            .env("PATH", &path_var)
            .output()
            .unwrap();
        let code = out.status.code().unwrap_or(-1);
        let printed = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        if code != cmd.exit {
            failures.push(format!(
                "{at}: exit {code}, documented {}\n{printed}",
                cmd.exit
            ));
        } else if let Some(line) = missing_line(&cmd.shown, &printed) {
            failures.push(format!(
                "{at}: the documented line\n    {line}\nis not in what it prints:\n{printed}"
            ));
        }
    }
    failures
}

/// The comment of a command that runs until stopped (a server).
const UNTIL_STOPPED: &str = "# until stopped";

/// Longest a documented server may take to print what the document shows.
const SERVER_WAIT: Duration = Duration::from_secs(30);

/// Run a server until its stdout holds the `shown` lines (or [`SERVER_WAIT`] passes), then stop
/// it: an error when it exited first or did not print them.
fn run_server(mut command: Command, shown: &[String]) -> Result<(), String> {
    let mut child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())?;
    let stdout = child.stdout.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let start = Instant::now();
    let mut printed = String::new();
    let result = loop {
        if missing_line(shown, &printed).is_none() && !printed.is_empty() {
            break match child.try_wait() {
                Ok(None) => Ok(()),
                _ => Err(format!("it exited instead of serving:\n{printed}")),
            };
        }
        let left = SERVER_WAIT.saturating_sub(start.elapsed());
        match rx.recv_timeout(left.min(Duration::from_millis(200))) {
            Ok(line) => printed = format!("{printed}{line}\n"),
            Err(_) if start.elapsed() >= SERVER_WAIT => {
                break Err(format!(
                    "it did not print what is shown in {SERVER_WAIT:?}:\n{printed}"
                ))
            }
            Err(_) => {
                if let Ok(Some(status)) = child.try_wait() {
                    break Err(format!(
                        "it exited ({status}) instead of serving:\n{printed}"
                    ));
                }
            }
        }
    };
    crate::common::stop(&mut child);
    result
}

/// The documents whose commands are run: the README and every page under `docs/`.
fn documents() -> Vec<String> {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut docs = vec!["README.md".to_string()];
    if let Ok(entries) = std::fs::read_dir(repo.join("docs")) {
        let mut pages: Vec<String> = entries
            .filter_map(Result::ok)
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".md"))
            .map(|n| format!("docs/{n}"))
            .collect();
        pages.sort();
        docs.extend(pages);
    }
    docs
}

#[test]
fn every_documented_command_runs_with_its_documented_exit_code_and_output() {
    let mut failures = Vec::new();
    for doc in documents() {
        failures.extend(run_document(&doc));
    }
    assert!(
        failures.is_empty(),
        "{} documented command(s) fail:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

#[test]
fn the_reader_of_documents_finds_commands_exits_and_output() {
    let doc = "Text.\n\n```sh\nK=../shared/data\naloft mission   # the demo\naloft mission --wind-speed 20 \\\n  --wind-from 250   # exit 1: too strong\ncargo test --workspace\n```\n\n```\n$ aloft vehicles\nname  mass\n...\n$ cargo run --release -- mission\nFEASIBLE: ...\n```\n";
    let (vars, cmds) = commands(doc);
    assert_eq!(vars, [(0, "K=../shared/data".to_string())]);
    let got: Vec<(usize, &str, i32, usize)> = cmds
        .iter()
        .map(|c| (c.line, c.text.as_str(), c.exit, c.shown.len()))
        .collect();
    assert_eq!(
        got,
        [
            (5, "aloft mission   # the demo", 0, 0),
            (
                6,
                "aloft mission --wind-speed 20 \\\n  --wind-from 250   # exit 1: too strong",
                1,
                0
            ),
            (12, "aloft vehicles", 0, 2),
            (15, "aloft mission", 0, 1),
        ]
    );
    assert!(line_matches("FEASIBLE: ...", "FEASIBLE: lands with 70 %"));
    assert!(line_matches(
        "Replay of ...log_66.ulg: 706",
        "Replay of ../x/log_66.ulg: 706"
    ));
    assert!(!line_matches(
        "Replay of ...log_66.ulg: 706",
        "Replay of ../x/log_67.ulg: 706"
    ));
    assert!(!line_matches("FEASIBLE", "NOT FEASIBLE"));
    let shown = vec!["a".to_string(), "...".to_string(), "c".to_string()];
    assert_eq!(missing_line(&shown, "a\nb\nc\n"), None);
    assert_eq!(missing_line(&shown, "c\na\n"), Some("c".to_string()));
}
