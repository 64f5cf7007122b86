//! Helpers shared by the integration tests: running the `aloft` binary, the shared real-data
//! folder and the repository's fixtures, files and checks several tests make, and ROS 2 messages
//! ([`ros2`]; also taken by the benches with `#[path]`). Missions written in code take their
//! segments from `aloft_planner::mission_toml`. Each test file takes what it needs with
//! `mod common;`.
#![allow(dead_code)] // not every test file uses every helper

pub mod big_survey;
mod data;
pub mod kaist;
pub mod ros2;
pub mod serve;

pub use data::{data_dir, files};

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Output};
use std::time::{Duration, Instant};

/// Runs the `aloft` binary built for this test with `args`.
pub fn aloft<S: AsRef<OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_aloft"))
        .args(args)
        .output()
        .expect("run aloft")
}

/// The exit code (-1 when killed by a signal), stdout and stderr of `aloft args`.
pub fn run(args: &[&str]) -> (i32, String, String) {
    let out = aloft(args);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The standard output of a run, which must be UTF-8.
pub fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("stdout is UTF-8")
}

/// The standard error of a run, which must be UTF-8.
pub fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).expect("stderr is UTF-8")
}

/// The stdout of `aloft args`, which must exit 0 (success) or 1 (a plan that is not feasible).
pub fn cli(args: &[&str]) -> String {
    let out = aloft(args);
    assert!(
        out.status.code() == Some(0) || out.status.code() == Some(1),
        "aloft {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8")
}

/// The stdout of `aloft args`, which must succeed.
pub fn ok_stdout<S: AsRef<OsStr> + std::fmt::Debug>(args: &[S]) -> String {
    let o = aloft(args);
    assert!(
        o.status.success(),
        "aloft {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).expect("stdout is UTF-8")
}

/// The JSON answer of `aloft args`, which must succeed.
pub fn ok_json<S: AsRef<OsStr> + std::fmt::Debug>(args: &[S]) -> serde_json::Value {
    serde_json::from_str(&ok_stdout(args)).expect("stdout is JSON")
}

/// A file of the repository's `fixtures/<folder>`.
pub fn fixture(folder: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(folder)
        .join(name)
}

/// A scratch file `name` in the folder `tag` of this test process's own scratch folder
/// ([`scratch_root`]; the folders are created if need be, the file is not).
pub fn scratch(tag: &str, name: &str) -> PathBuf {
    let dir = scratch_root().join(tag);
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The start of the name of a test process's scratch folder in the system's temporary directory.
const SCRATCH_PREFIX: &str = "aloft-test-scratch-";

/// This test process's scratch folder, `<temp>/aloft-test-scratch-<pid>`. The first call removes
/// the scratch folders of test processes that have ended (where `/proc` says which processes
/// run), so that runs of the suite leave at most the last one's files behind, not theirs all.
pub fn scratch_root() -> &'static Path {
    static ROOT: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    ROOT.get_or_init(|| {
        let temp = std::env::temp_dir();
        remove_ended_scratch(&temp);
        let root = temp.join(format!("{SCRATCH_PREFIX}{}", std::process::id()));
        std::fs::create_dir_all(&root).unwrap();
        root
    })
}

/// Removes the folders `aloft-test-scratch-<pid>` of `temp` whose process has ended: a folder
/// (never a link) whose name is the prefix and a number, and no `/proc/<pid>`.
fn remove_ended_scratch(temp: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(temp) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let pid = name
            .to_str()
            .and_then(|n| n.strip_prefix(SCRATCH_PREFIX))
            .and_then(|n| n.parse::<u32>().ok());
        let is_folder = entry.file_type().is_ok_and(|t| t.is_dir());
        if let Some(pid) = pid {
            if is_folder && !Path::new("/proc").join(pid.to_string()).exists() {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
    }
}

/// The files `<prefix>*<suffix>` of the data folder `sub`, sorted; there must be some.
pub fn files_like(sub: &str, prefix: &str, suffix: &str) -> Vec<PathBuf> {
    let v = files(sub, |n| n.starts_with(prefix) && n.ends_with(suffix));
    assert!(
        !v.is_empty(),
        "no {prefix}*{suffix} in {}",
        data_dir().join(sub).display()
    );
    v
}

/// The same paths as strings, for the command line.
pub fn strings(paths: &[PathBuf]) -> Vec<String> {
    paths.iter().map(|p| p.display().to_string()).collect()
}

/// The stderr of `aloft args`, which must be refused with exit 2.
pub fn refused<S: AsRef<OsStr> + std::fmt::Debug>(args: &[S]) -> String {
    let o = aloft(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "aloft {args:?}: {err}");
    err
}

/// The columns `names` of every row of the CSV file at `path` (a header row, then one record
/// a line, blank lines passed over), read as numbers here, not through aloft.
pub fn csv_columns<const N: usize>(path: &Path, names: [&str; N]) -> Vec<[f64; N]> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = names.map(|n| head.iter().position(|h| *h == n).unwrap());
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            col.map(|k| f[k].parse::<f64>().unwrap())
        })
        .collect()
}

/// Refused as the input contract says: exit 2, exactly one stderr line holding every needle, no
/// panic, nothing on stdout.
pub fn assert_refused(args: &[&str], needles: &[&str]) {
    let o = aloft(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{args:?}: one line expected: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "{args:?}: '{n}' missing in: {err}");
    }
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(o.stdout.is_empty(), "{args:?}: nothing on stdout expected");
}

/// Writes a wind-field CSV to `path` (`x_m,y_m,z_m,u_mps,v_mps,w_mps`): the same `wind` (`u,v,w`
/// in m/s) at each corner of the box `[half_width_m, top_m]`, ±`half_width_m` east and north of
/// home from the ground to `top_m`.
pub fn write_wind_grid(path: impl AsRef<Path>, box_m: [f64; 2], wind: &str) {
    write_wind_grid_with_columns(path, "x_m,y_m,z_m,u_mps,v_mps,w_mps", box_m, wind);
}

/// [`write_wind_grid`] with other `columns`: each row is `x,y,z,` and `values`.
pub fn write_wind_grid_with_columns(
    path: impl AsRef<Path>,
    columns: &str,
    box_m: [f64; 2],
    values: &str,
) {
    let [half_width_m, top_m] = box_m;
    let mut text = format!("{columns}\n");
    for x in [-half_width_m, half_width_m] {
        for y in [-half_width_m, half_width_m] {
            for z in [0.0, top_m] {
                text.push_str(&format!("{x},{y},{z},{values}\n"));
            }
        }
    }
    std::fs::write(path, text).unwrap();
}

/// Whether `python3` can import `modules` (as an `import` statement names them: `a, b`).
pub fn python_has(modules: &str) -> bool {
    Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// The standard output of `python3 -c script args`, which must succeed.
pub fn python_stdout(script: &str, args: &[&str]) -> String {
    let out = Command::new("python3")
        .args(["-c", script])
        .args(args)
        .output()
        .expect("run python3");
    assert!(
        out.status.success(),
        "python3 {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8")
}

/// Checks the MCAP `file` with the independent reader, the Python `mcap` package
/// (`tests/python/check_mcap.py`), against `expect` (topics with counts and schemas, values at
/// paths with tolerances), which is written beside it. Skipped (with a notice) only outside CI
/// when `mcap` is not installed; returns whether it ran.
pub fn check_mcap_with_python(file: &Path, expect: &serde_json::Value) -> bool {
    if !python_has("mcap") {
        if std::env::var_os("CI").is_some() {
            panic!("CI is set but `python3 -c 'import mcap'` fails: install it (python3 -m pip install mcap)");
        }
        eprintln!("NOTICE: skipping the Python MCAP check: python3 with the `mcap` package is not available (set CI to make this an error)");
        return false;
    }
    let exp = file.with_extension("expect.json");
    std::fs::write(&exp, serde_json::to_vec_pretty(expect).unwrap()).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/check_mcap.py");
    let out = Command::new("python3")
        .arg(script)
        .arg(file)
        .arg(&exp)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "check_mcap.py failed:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    true
}

/// Waits for `child` to end, at most `limit`: its exit status, or `None` when it ran longer (it
/// is then killed and reaped). Its pipes are left to the caller.
pub fn wait_within(child: &mut Child, limit: Duration) -> Option<ExitStatus> {
    let status = ended_within(child, limit);
    if status.is_none() {
        let _ = child.kill();
        let _ = child.wait();
    }
    status
}

/// Waits for `child` to end, at most `limit`: its exit status, or `None` when it still runs.
pub fn ended_within(child: &mut Child, limit: Duration) -> Option<ExitStatus> {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            return Some(status);
        }
        if start.elapsed() > limit {
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Stops `child` as a user stops a server (SIGTERM), so that it removes what it made in the
/// temporary directory; killed when it is not gone within 5 s.
pub fn stop(child: &mut Child) {
    let asked = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .is_ok_and(|s| s.success());
    if !asked || ended_within(child, Duration::from_secs(5)).is_none() {
        let _ = child.kill();
        let _ = child.wait();
    }
}

/// A written sortie flown by `aloft mission PATH --format json FLAGS`: exit 0, feasible, and
/// the energy the plan gave it (`sortie["energy_wh"]`) within the fraction `tolerance`; the
/// flown answer.
pub fn flies_as_planned(
    path: &str,
    flags: &[&str],
    sortie: &serde_json::Value,
    tolerance: f64,
) -> serde_json::Value {
    let mut args = vec!["mission", path, "--format", "json"];
    args.extend_from_slice(flags);
    let (code, out, err) = run(&args);
    assert_eq!(code, 0, "{path} read back: {err}");
    let flown: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(flown["feasible"], true, "{path}");
    let number = |v: &serde_json::Value| v.as_f64().unwrap_or_else(|| panic!("{path}: {v}"));
    let (got, want) = (number(&flown["energy_wh"]), number(&sortie["energy_wh"]));
    assert!(
        (got - want).abs() <= tolerance * want,
        "{path}: flown {got} Wh, planned {want} Wh"
    );
    flown
}

/// The median of `v`: its middle value, or the mean of the middle two (panics when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n % 2 {
        1 => v[n / 2],
        _ => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The strings of the JSON array `array`.
pub fn strs(array: &serde_json::Value) -> Vec<&str> {
    let items = array.as_array().expect("a JSON array");
    items.iter().map(|x| x.as_str().unwrap()).collect()
}

/// The `key` string of each element of the JSON array `array`.
pub fn strs_of<'a>(array: &'a serde_json::Value, key: &str) -> Vec<&'a str> {
    let items = array.as_array().expect("a JSON array");
    items.iter().map(|x| x[key].as_str().unwrap()).collect()
}

/// Asserts that one of `warnings` contains `needle`.
pub fn assert_warned(warnings: &[String], needle: &str) {
    assert!(
        warnings.iter().any(|w| w.contains(needle)),
        "no warning with {needle:?}: {warnings:?}"
    );
}

/// A uniform wind of `speed_mps` from `from_deg`, without gusts.
pub fn uniform_wind(speed_mps: f64, from_deg: f64) -> Option<aloft::engine::WindSpec> {
    Some(aloft::engine::WindSpec::uniform(speed_mps, from_deg))
}

/// The keys of a propulsion hover answer (`aloft propulsion --format json`), all numbers.
pub const HOVER_KEYS: [&str; 9] = [
    "takeoff_mass_kg",
    "thrust_per_rotor_n",
    "rotor_speed_rpm",
    "motor_current_a",
    "pack_current_a",
    "power_required_w",
    "power_drawn_w",
    "battery_heat_w",
    "flight_time_min",
];

/// The numbers of an endurance answer (`aloft endurance --format json`) that every vehicle and
/// payload has, and that a payload sweep gives for each row.
pub const ENDURANCE_KEYS: [&str; 6] = [
    "hover_power_w",
    "hover_endurance_s",
    "max_endurance_speed_mps",
    "max_endurance_s",
    "max_range_speed_mps",
    "max_range_m",
];

/// The owner's statement for the flugdrohne quadrotor (docs/guide.md, "Your own quadrotor"): a
/// 1.2 kg quadrotor on 10 in propellers with a 5000 mAh pack; its mass, propellers and pack are
/// not logged, so every fit of its logs is given these flags.
pub const FLUGDROHNE_OWNER: [&str; 6] = [
    "--mass-kg",
    "1.2",
    "--rotor-diameter-m",
    "0.254",
    "--battery-capacity-mah",
    "5000",
];

/// `aloft fit --log L... EXTRA -o OUT --format json`: exit code, JSON (null when stdout is not
/// JSON), stderr.
pub fn fit_json(logs: &[String], extra: &[&str], out: &Path) -> (i32, serde_json::Value, String) {
    let mut args: Vec<String> = vec!["fit".into()];
    for l in logs {
        args.push("--log".into());
        args.push(l.clone());
    }
    args.extend(extra.iter().map(|s| s.to_string()));
    args.extend([
        "-o".into(),
        out.display().to_string(),
        "--format".into(),
        "json".into(),
    ]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, stdout, stderr) = run(&args);
    let json = serde_json::from_str(&stdout).unwrap_or(serde_json::Value::Null);
    (code, json, stderr)
}

/// The first `until_s` seconds of a flugdrohne log's per-topic CSV tables (`px4_flugdrohne/csv`,
/// the log named by its `stem`), written under a scratch folder as the tables of a log named
/// `name` (its parameters whole), and that log's prefix for `--log`: a real log cut short, e.g.
/// before its take-off (a log that never flew).
pub fn px4_tables_until(stem: &str, until_s: f64, tag: &str, name: &str) -> PathBuf {
    let src = data_dir().join("px4_flugdrohne/csv");
    let prefix = scratch(tag, name);
    let mut first_us: Option<i64> = None;
    // The log's clock starts at its earliest table row (all tables share the boot clock).
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        let file = p.file_name().unwrap().to_string_lossy().into_owned();
        if file.starts_with(&format!("{stem}_")) && !file.ends_with("_params.csv") {
            let text = std::fs::read_to_string(&p).unwrap();
            if let Some(t) = text.lines().nth(1).and_then(|l| l.split(',').next()) {
                let t: i64 = t.parse().unwrap();
                first_us = Some(first_us.map_or(t, |f| f.min(t)));
            }
        }
    }
    let end_us = first_us.unwrap() + (until_s * 1e6) as i64;
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        let file = p.file_name().unwrap().to_string_lossy().into_owned();
        let Some(rest) = file.strip_prefix(&format!("{stem}_")) else {
            continue;
        };
        let text = std::fs::read_to_string(&p).unwrap();
        let kept: Vec<&str> = text
            .lines()
            .enumerate()
            .filter(|(i, l)| {
                *i == 0
                    || rest == "params.csv"
                    || l.split(',').next().unwrap().parse::<i64>().unwrap() < end_us
            })
            .map(|(_, l)| l)
            .collect();
        let out = prefix.with_file_name(format!("{name}_{rest}"));
        std::fs::write(out, kept.join("\n") + "\n").unwrap();
    }
    prefix
}

/// The paths of every `null` in a JSON answer (the contract: a value that does not exist is
/// left out, never `null`).
pub fn nulls(v: &serde_json::Value) -> Vec<String> {
    fn walk(v: &serde_json::Value, at: String, out: &mut Vec<String>) {
        match v {
            serde_json::Value::Null => out.push(at),
            serde_json::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(x, format!("{at}[{i}]"), out);
                }
            }
            serde_json::Value::Object(o) => {
                for (k, x) in o {
                    walk(x, format!("{at}.{k}"), out);
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(v, String::new(), &mut out);
    out
}

/// A survey mission named `name`: `lines` lines 1 km long, 40 m apart, at 8 m/s, out from and
/// back to home at 40 m (about 16 minutes of an M100's TB47D at 20 % reserve per 10 lines in
/// still air: several packs for 24 lines and more).
pub fn survey_lines(name: &str, lines: usize) -> String {
    use aloft_planner::mission_toml::{landing, leg, return_home, take_off};
    let mut text = format!("name = {name:?}\ndefault_speed_mps = 8.0\n");
    text.push_str(&take_off(40.0, 3.0));
    for k in 0..lines {
        let east = if k % 2 == 0 { 1000.0 } else { 0.0 };
        let north = 40.0 * k as f64;
        text.push_str(&leg(east, north, 8.0));
        text.push_str(&leg(east, north + 40.0, 8.0));
    }
    text.push_str(&return_home(8.0));
    text.push_str(&landing(1.0));
    text
}

/// The scratch folders of ended runs go, and nothing else: not a live process's, not a link
/// named like one (nor what it points to), not a name with more after the number.
#[test]
fn scratch_folders_of_ended_runs_are_removed_and_nothing_else() {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let temp = tempfile::tempdir().unwrap();
    let ended = temp.path().join(format!("{SCRATCH_PREFIX}4294967294"));
    let live = temp
        .path()
        .join(format!("{SCRATCH_PREFIX}{}", std::process::id()));
    let longer = temp.path().join(format!("{SCRATCH_PREFIX}4294967294-keep"));
    let target = temp.path().join("kept");
    let link = temp.path().join(format!("{SCRATCH_PREFIX}4294967293"));
    for d in [&ended, &live, &longer, &target] {
        std::fs::create_dir_all(d.join("inner")).unwrap();
    }
    std::os::unix::fs::symlink(&target, &link).unwrap();
    remove_ended_scratch(temp.path());
    assert!(!ended.exists());
    for kept in [&live, &longer, &target.join("inner")] {
        assert!(kept.exists(), "{}", kept.display());
    }
    assert!(link.symlink_metadata().is_ok());
}
