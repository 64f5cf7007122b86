//! Issue 41, item 1: every command that writes a file writes it in aloft's one way
//! (`aloft_core::output`), tested as a hostile or careless user would attack it:
//!
//! - an existing output is kept unless `--force` (exit 2, one line naming it);
//! - a link planted at an output name is never written through, with or without `--force`
//!   (`--force` replaces the link itself);
//! - a FIFO or a device at an output name is never replaced, even with `--force`, and never
//!   blocks the command;
//! - no temporary file is left beside an output, whatever happened;
//! - `aloft plan` names its files after the input's file name only (never the mission's own
//!   `name`, never a path), writes its set of files all or nothing, and an interrupted plan
//!   (SIGINT, SIGTERM) leaves the whole set or none of it.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{data_dir, fixture, scratch, survey_lines};

/// A new empty folder of this test's own.
fn folder(name: &str) -> PathBuf {
    let d = scratch("outputs", name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Temporary files left in `dir`: aloft's (`.aloft-*.tmp`) and those of the writers before
/// (`*.aloft-tmp`, `.NAME.PID.tmp`).
fn temporaries(dir: &Path) -> Vec<String> {
    names(dir)
        .into_iter()
        .filter(|n| n.starts_with(".aloft-") || n.ends_with(".aloft-tmp") || n.ends_with(".tmp"))
        .collect()
}

/// `aloft args`, killed (and the test failed) if it runs longer than `limit`: a command that
/// opens a FIFO for writing would wait for a reader for ever.
fn run_within(args: &[String], limit: Duration) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_aloft"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    if common::wait_within(&mut child, limit).is_none() {
        panic!("aloft {args:?} still runs after {limit:?} (blocked on a FIFO?)");
    }
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// The KAIST flight every log command of this file reads (shared real data).
fn kaist_log() -> String {
    s(&data_dir().join("kaist_energy_drone/2018-08-03.10_31_21random5-1.csv"))
}

/// A command that writes one file: its name, and its arguments for an output at a path.
struct Writer {
    name: &'static str,
    args: fn(&str) -> Vec<String>,
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|x| (*x).to_string()).collect()
}

/// Every command of the command line that writes a file, with an input that succeeds.
fn writers() -> Vec<Writer> {
    vec![
        Writer {
            name: "convert -o",
            args: |o| {
                let log = s(&fixture("logs", "kaist_small.csv"));
                strings(&["convert", &log, "--profile", "kaist", "-o", o])
            },
        },
        Writer {
            name: "mission --timeseries",
            args: |o| strings(&["mission", "--timeseries", o]),
        },
        Writer {
            name: "mission --mcap",
            args: |o| strings(&["mission", "--mcap", o]),
        },
        Writer {
            name: "mission --plot",
            args: |o| strings(&["mission", "--plot", o]),
        },
        Writer {
            name: "power -o",
            args: |o| {
                let states = s(&fixture("power", "states.csv"));
                strings(&["power", "--input", &states, "-o", o])
            },
        },
        Writer {
            name: "endurance --plot",
            args: |o| strings(&["endurance", "--sweep-speed", "2", "--plot", o]),
        },
        Writer {
            name: "propulsion --plot",
            args: |o| strings(&["propulsion", "--sweep-takeoff-mass", "7:13:1", "--plot", o]),
        },
        Writer {
            name: "vehicles calibrate -o",
            args: |o| {
                let spec = s(&fixture("vehicles", "specs/dji-m600.toml"));
                strings(&["vehicles", "calibrate", &spec, "-o", o])
            },
        },
        Writer {
            name: "pack fit -o",
            args: |o| common::kaist::pack_fit_words(&[kaist_log()], 12000.0, 4.0, o),
        },
        Writer {
            name: "fit -o",
            args: |o| {
                let log = kaist_log();
                let template = s(&fixture("vehicles", "kaist-template.toml"));
                strings(&[
                    "fit",
                    "--profile",
                    "kaist",
                    "--log",
                    &log,
                    "--vehicle-template",
                    &template,
                    "-o",
                    o,
                ])
            },
        },
        Writer {
            name: "validate --plot",
            args: |o| {
                let log = kaist_log();
                strings(&[
                    "validate",
                    "--profile",
                    "kaist",
                    "--log",
                    &log,
                    "--vehicle",
                    "dji-m100",
                    "--plot",
                    o,
                ])
            },
        },
        Writer {
            name: "live --mcap",
            args: |o| {
                let log = s(&fixture("logs", "kaist_small.csv"));
                strings(&[
                    "live",
                    "--replay",
                    &log,
                    "--profile",
                    "kaist",
                    "--vehicle",
                    "dji-m100",
                    "--mcap",
                    o,
                ])
            },
        },
    ]
}

const LIMIT: Duration = Duration::from_secs(120);

/// `aloft` of `w` writing to `out`, with `--force` when asked.
fn write(w: &Writer, out: &Path, force: bool) -> (i32, String, String) {
    let mut args = (w.args)(&s(out));
    if force {
        args.push("--force".into());
    }
    run_within(&args, LIMIT)
}

/// A refusal: exit 2, one stderr line naming the output.
fn assert_refused(w: &Writer, (code, out, err): &(i32, String, String), out_path: &Path) {
    assert_eq!(*code, 2, "{}: {err}", w.name);
    assert!(out.is_empty(), "{}: stdout {out}", w.name);
    assert_eq!(err.lines().count(), 1, "{}: {err}", w.name);
    let name = out_path.file_name().unwrap().to_string_lossy();
    assert!(err.contains(name.as_ref()), "{}: {err}", w.name);
    // Never a file of aloft's own (a temporary name) in what the user reads.
    assert!(!err.contains(".aloft-"), "{}: {err}", w.name);
}

#[test]
fn every_writer_writes_a_new_file_and_keeps_an_existing_one_without_force() {
    for (k, w) in writers().iter().enumerate() {
        let d = folder(&format!("keep-{k}"));
        let out = d.join("out.file");
        let (code, _, err) = write(w, &out, false);
        assert!(matches!(code, 0 | 1), "{}: {err}", w.name);
        let first = std::fs::read(&out).unwrap_or_else(|e| panic!("{}: {e}", w.name));
        assert!(!first.is_empty(), "{}", w.name);
        // Again: the file is kept, byte for byte.
        std::fs::write(&out, b"the operator's own file").unwrap();
        let refused = write(w, &out, false);
        assert_refused(w, &refused, &out);
        assert!(refused.2.contains("--force"), "{}: {}", w.name, refused.2);
        assert_eq!(
            std::fs::read(&out).unwrap(),
            b"the operator's own file",
            "{}",
            w.name
        );
        // With --force it is replaced.
        let (code, _, err) = write(w, &out, true);
        assert!(matches!(code, 0 | 1), "{}: {err}", w.name);
        assert_ne!(
            std::fs::read(&out).unwrap(),
            b"the operator's own file",
            "{}",
            w.name
        );
        assert_eq!(names(&d), ["out.file"], "{}", w.name);
    }
}

#[cfg(unix)]
#[test]
fn no_writer_writes_through_a_planted_link() {
    for (k, w) in writers().iter().enumerate() {
        let d = folder(&format!("link-{k}"));
        let victim = d.join("victim.txt");
        std::fs::write(&victim, b"precious").unwrap();
        let out = d.join("out.file");
        std::os::unix::fs::symlink(&victim, &out).unwrap();
        let refused = write(w, &out, false);
        assert_refused(w, &refused, &out);
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious", "{}", w.name);
        // --force replaces the link itself, never the file it points to.
        let (code, _, err) = write(w, &out, true);
        assert!(matches!(code, 0 | 1), "{}: {err}", w.name);
        let meta = std::fs::symlink_metadata(&out).unwrap();
        assert!(meta.file_type().is_file(), "{}: {meta:?}", w.name);
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious", "{}", w.name);
        // A dangling link: nothing is created where it points.
        let nowhere = d.join("created-through-the-link");
        let dangling = d.join("dangling.file");
        std::os::unix::fs::symlink(&nowhere, &dangling).unwrap();
        let refused = write(w, &dangling, false);
        assert_refused(w, &refused, &dangling);
        assert!(!nowhere.exists(), "{}", w.name);
        assert!(temporaries(&d).is_empty(), "{}: {:?}", w.name, names(&d));
    }
}

/// A FIFO at the output name: refused with or without --force (before the fix, `pack fit -o`
/// replaced it with a regular file and `mission --timeseries` blocked on it).
#[cfg(unix)]
#[test]
fn no_writer_replaces_or_blocks_on_a_fifo() {
    use std::os::unix::fs::FileTypeExt;
    for (k, w) in writers().iter().enumerate() {
        let d = folder(&format!("fifo-{k}"));
        let fifo = d.join("out.file");
        assert!(Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        for force in [false, true] {
            let refused = write(w, &fifo, force);
            assert_refused(w, &refused, &fifo);
            assert!(refused.2.contains("FIFO"), "{}: {}", w.name, refused.2);
            let ft = std::fs::symlink_metadata(&fifo).unwrap().file_type();
            assert!(ft.is_fifo(), "{} --force {force}: {ft:?}", w.name);
        }
        assert_eq!(names(&d), ["out.file"], "{}", w.name);
    }
}

/// A device node at the output name (made here, where the test may: root) is never replaced.
/// Before the fix, as root, `pack fit -o /dev/full` turned the device into a regular file.
#[cfg(unix)]
#[test]
fn no_writer_replaces_a_device() {
    use std::os::unix::fs::FileTypeExt;
    let d = folder("device");
    let dev = d.join("null-device");
    // The null device's numbers (1, 3); mknod needs privileges: without them, nothing to test.
    let made = Command::new("mknod")
        .args([s(&dev).as_str(), "c", "1", "3"])
        .stderr(Stdio::null())
        .status();
    if !made.is_ok_and(|st| st.success()) {
        eprintln!("no mknod here (not root): the device case is left to the FIFO's");
        return;
    }
    for w in writers() {
        let refused = write(&w, &dev, true);
        assert_refused(&w, &refused, &dev);
        assert!(refused.2.contains("device"), "{}: {}", w.name, refused.2);
        let ft = std::fs::symlink_metadata(&dev).unwrap().file_type();
        assert!(ft.is_char_device(), "{}: {ft:?}", w.name);
    }
}

/// A missing folder is named, and nothing is created.
#[test]
fn an_output_in_a_missing_folder_is_refused_naming_it() {
    for (k, w) in writers().iter().enumerate() {
        let d = folder(&format!("missing-{k}"));
        let out = d.join("no-such-folder").join("out.file");
        let (code, _, err) = write(w, &out, false);
        assert_eq!(code, 2, "{}: {err}", w.name);
        assert!(
            err.contains("no-such-folder") && err.lines().count() == 1,
            "{}: {err}",
            w.name
        );
        assert!(names(&d).is_empty(), "{}", w.name);
    }
}

// ---------------------------------------------------------------------------------------------
// aloft plan: names, links, sets, interrupts.

fn plan(mission: &Path, out: &Path, extra: &[&str]) -> (i32, String, String) {
    let mut args = strings(&["plan", &s(mission), "-o", &s(out)]);
    args.extend(strings(extra));
    run_within(&args, LIMIT)
}

/// The output names are the input's file name, made safe: never the mission's `name`, never a
/// path (before the fix a mission file without an extension named `../escaped` was written
/// beside the output folder, and one named by an absolute path there).
#[test]
fn plan_names_its_files_after_the_input_file_only() {
    let d = folder("plan-names");
    let inputs = d.join("inputs");
    std::fs::create_dir_all(&inputs).unwrap();
    let outside = d.join("escaped-1-of-1.toml");
    let absolute = d.join("absolute");
    for (file, inner) in [
        ("mission-without-extension", "../escaped".to_string()),
        ("abs", s(&absolute)),
        (
            "<img src=x onerror=alert(1)>.toml",
            "<b>bold</b>".to_string(),
        ),
        ("..hidden.toml", "../../x".to_string()),
        ("-rf.toml", "-rf".to_string()),
        ("line\nbreak.toml", "x".to_string()),
    ] {
        let mission = inputs.join(file);
        std::fs::write(&mission, survey_lines(&inner, 2)).unwrap();
        let out = d.join("out");
        let _ = std::fs::remove_dir_all(&out);
        let (code, _, err) = plan(&mission, &out, &[]);
        assert_eq!(code, 0, "{file}: {err}");
        let written = names(&out);
        assert!(!written.is_empty(), "{file}");
        for n in &written {
            assert!(
                n.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "._-".contains(c)),
                "{file}: {n}"
            );
            assert!(!n.starts_with(['.', '-']), "{file}: {n}");
        }
        assert!(!outside.exists() && !absolute.exists(), "{file}");
        assert!(!d.join("x-1-of-1.toml").exists(), "{file}");
    }
    assert_eq!(names(&d), ["inputs", "out"]);
    // The file name's stem, sanitised; the extension is the format's.
    let mission = inputs.join("mission-without-extension");
    let out = d.join("out");
    let _ = std::fs::remove_dir_all(&out);
    assert_eq!(plan(&mission, &out, &[]).0, 0);
    assert_eq!(names(&out), ["mission-without-extension-1-of-1.toml"]);
}

/// The number of files of a plan of `mission` (written once into a folder of its own).
fn files_of(mission: &Path, tag: &str) -> Vec<String> {
    let out = folder(tag);
    let (code, _, err) = plan(mission, &out, &[]);
    assert_eq!(code, 0, "{err}");
    names(&out)
}

/// A folder of its own (`tag`) with a 30-line survey (`lines.toml`) whose plan is two files or
/// more: the folder, the mission, the names of its plan's files, and an empty `out` folder.
#[cfg(unix)]
fn a_plan_of_several_files(tag: &str) -> (PathBuf, PathBuf, Vec<String>, PathBuf) {
    let d = folder(tag);
    let mission = d.join("lines.toml");
    std::fs::write(&mission, survey_lines("lines", 30)).unwrap();
    let expected = files_of(&mission, &format!("{tag}-dry"));
    assert!(expected.len() >= 2, "{expected:?}");
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    (d, mission, expected, out)
}

#[cfg(unix)]
#[test]
fn plan_never_writes_through_links_planted_at_its_names() {
    let (d, mission, expected, out) = a_plan_of_several_files("plan-links");
    let victim = d.join("victim.txt");
    std::fs::write(&victim, b"precious").unwrap();
    // Links at every name the old writer used: the files and their temporary names.
    for n in &expected {
        let stem = n.trim_end_matches(".toml");
        for planted in [n.clone(), format!("{stem}.aloft-tmp")] {
            std::os::unix::fs::symlink(&victim, out.join(planted)).unwrap();
        }
    }
    let (code, _, err) = plan(&mission, &out, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--force") && err.lines().count() == 1, "{err}");
    assert_eq!(std::fs::read(&victim).unwrap(), b"precious");
    let (code, _, err) = plan(&mission, &out, &["--force"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read(&victim).unwrap(), b"precious");
    for n in &expected {
        let ft = std::fs::symlink_metadata(out.join(n)).unwrap().file_type();
        assert!(ft.is_file(), "{n}: {ft:?}");
    }
    assert!(temporaries(&out).iter().all(|t| t.ends_with(".aloft-tmp")));
}

/// A FIFO at the second file's name: with --force the set is refused before any file of it is
/// placed (none is left), and the FIFO stays.
#[cfg(unix)]
#[test]
fn plan_writes_its_set_all_or_nothing() {
    use std::os::unix::fs::FileTypeExt;
    let (_, mission, expected, out) = a_plan_of_several_files("plan-set");
    let fifo = out.join(&expected[1]);
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let (code, _, err) = plan(&mission, &out, &["--force"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("FIFO"), "{err}");
    assert_eq!(names(&out), [expected[1].clone()]);
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
}

/// SIGINT or SIGTERM at any moment of a plan: the folder holds the whole set or nothing of it,
/// and no temporary file. Each signal is sent at a different moment of the run (spread over
/// one uninterrupted run's time), so some land while it plans and, around the end, some while
/// it writes.
#[cfg(unix)]
#[test]
fn an_interrupted_plan_leaves_the_whole_set_or_nothing() {
    let d = folder("plan-interrupt");
    let mission = d.join("lines.toml");
    std::fs::write(&mission, survey_lines("lines", 30)).unwrap();
    let start = Instant::now();
    let expected = files_of(&mission, "plan-interrupt-dry");
    let whole = start.elapsed();
    assert!(expected.len() >= 2, "{expected:?}");
    let mut interrupted = 0;
    for k in 0..6u32 {
        let out = d.join(format!("out-{k}"));
        std::fs::create_dir_all(&out).unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_aloft"))
            .args(["plan", &s(&mission), "-o", &s(&out)])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // From 10 % to 110 % of an uninterrupted run.
        std::thread::sleep(whole.mul_f64(0.1 + 0.2 * f64::from(k)));
        let signal = if k % 2 == 0 { "-INT" } else { "-TERM" };
        let _ = Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status();
        let status = child.wait().unwrap();
        let left = names(&out);
        match status.code() {
            Some(130) => {
                interrupted += 1;
                assert!(
                    left.is_empty() || left == expected,
                    "{signal} at {k}: {left:?}"
                );
            }
            Some(0) => assert_eq!(left, expected, "{signal} at {k}"),
            other => panic!("{signal} at {k}: exit {other:?} ({status:?}), left {left:?}"),
        }
    }
    assert!(interrupted > 0, "no run was interrupted");
}

/// A log's file name is written into the fitted vehicle's comment header: a newline in it stays
/// in its comment line (escaped), so the name cannot add keys to the file (before, a log named
/// "x\nmass_kg = 99.0\n#.csv" wrote `mass_kg = 99.0` as a line of the vehicle file).
#[cfg(unix)]
#[test]
fn fit_writes_a_log_name_with_a_newline_as_one_comment_line() {
    let d = folder("fit-name");
    let log = d.join("x\nmass_kg = 99.0\n#.csv");
    std::fs::copy(kaist_log(), &log).unwrap();
    let out = d.join("fitted.toml");
    let template = s(&fixture("vehicles", "kaist-template.toml"));
    let args = strings(&[
        "fit",
        "--profile",
        "kaist",
        "--log",
        &s(&log),
        "--vehicle-template",
        &template,
        "-o",
        &s(&out),
    ]);
    let (code, _, err) = run_within(&args, LIMIT);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.lines().all(|l| !l.starts_with("mass_kg = 99")),
        "{text}"
    );
    let comment = text.lines().find(|l| l.starts_with("# Log ")).unwrap();
    assert!(comment.contains("x\\nmass_kg = 99.0\\n#.csv"), "{comment}");
    let table: toml::Table = text.parse().unwrap();
    assert!(!table.contains_key("mass_kg"), "{table:?}");
}
