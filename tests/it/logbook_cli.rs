//! `aloft logbook` as a program: exit codes (0 something added or there, 1 all skipped, 2 bad
//! input), the JSON shapes (`{"flights": [...]}`, `{"vehicles": [...]}`, `{"packs": [...]}`),
//! two processes adding at once, where the file is (`--db`, `ALOFT_LOGBOOK`, the user's data
//! folder), and the file read back by Python's own `sqlite3` against the schema that
//! `docs/logbook.md` documents.

use crate::common;
use common::data_dir;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

fn aloft_env(args: &[&str], env: &[(&str, &Path)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_aloft"));
    c.args(args).env_remove("ALOFT_LOGBOOK");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run aloft")
}

fn run(args: &[&str]) -> (i32, String, String) {
    let o = aloft_env(args, &[]);
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// The KAIST flights (`kaist_energy_drone/*.csv`), sorted.
fn kaist() -> Vec<PathBuf> {
    common::files("kaist_energy_drone", |n| n.ends_with(".csv"))
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn json(args: &[&str]) -> Value {
    let (code, out, err) = run(args);
    assert_eq!(code, 0, "{args:?}: {err}");
    serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}"))
}

#[test]
fn logbook_json_shapes_and_exit_codes() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let db = s(&db);
    let files = kaist();
    let ulog = data_dir().join("px4_flugdrohne/ulg/log_30_2023-6-7-12-11-06.ulg");
    let (code, out, err) = run(&[
        "logbook",
        "add",
        "--db",
        db,
        s(&files[0]),
        s(&files[1]),
        s(&ulog),
        "--vehicle-label",
        "kaist-m600",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("added: ")
            && out.contains("3 added, 0 copies, 0 already in the logbook, 0 skipped"),
        "{out}"
    );

    // The same again, as JSON: all already there.
    let again = json(&[
        "logbook",
        "add",
        "--db",
        db,
        s(&files[0]),
        "--format",
        "json",
    ]);
    assert_eq!(again["already_present"], 1);
    assert_eq!(again["files"][0]["status"], "already_present");

    for (cmd, key, n) in [
        ("flights", "flights", 3),
        ("vehicles", "vehicles", 2),
        ("packs", "packs", 2),
    ] {
        let v = json(&["logbook", cmd, "--db", db, "--format", "json"]);
        let obj = v.as_object().unwrap();
        assert_eq!(obj.keys().collect::<Vec<_>>(), vec![key], "{v}");
        assert_eq!(obj[key].as_array().unwrap().len(), n, "{v}");
    }
    let flights = json(&["logbook", "flights", "--db", db, "--format", "json"]);
    let f0 = &flights["flights"][0];
    for k in [
        "id",
        "file_sha256",
        "file_name",
        "format",
        "vehicle_key",
        "pack_key",
        "duration_s",
        "energy_wh",
        "discharged_mah",
        "resistance_ohm",
        "capacity_refusal",
    ] {
        assert!(f0.get(k).is_some(), "no {k}: {f0}");
    }
    // The ULog has no cell voltages: no imbalance, and no key for it (never `null`).
    assert!(f0.get("imbalance_minor_min").is_none(), "{f0}");
    // The ULog is filed under its own sys_uuid, not the label.
    let vehicles = json(&["logbook", "vehicles", "--db", db, "--format", "json"]);
    let keys: Vec<&str> = vehicles["vehicles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["key"].as_str().unwrap())
        .collect();
    assert!(keys.contains(&"kaist-m600") && keys.len() == 2, "{keys:?}");
    // No log names its pack: each is keyed by its vehicle (and cells where they are known).
    let packs = json(&["logbook", "packs", "--db", db, "--format", "json"]);
    let keyed: Vec<(&str, u64)> = packs["packs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p["key"].as_str().unwrap(), p["flights"].as_u64().unwrap()))
        .collect();
    // The ULog's pack: 3S (the quad's, by the data's README) on the ULog's own vehicle.
    let ulog_vehicle = keys.iter().find(|k| **k != "kaist-m600").unwrap();
    assert_eq!(
        keyed,
        vec![
            (format!("unknown 3S on {ulog_vehicle}").as_str(), 1),
            ("unknown on kaist-m600", 2)
        ]
    );

    // All skipped (a missing file, a damaged one): exit 1, one line each.
    let cut = tmp.path().join("cut.csv");
    std::fs::write(&cut, &std::fs::read(&files[2]).unwrap()[..1000]).unwrap();
    let missing = tmp.path().join("missing.ulg");
    let (code, out, _) = run(&["logbook", "add", "--db", db, s(&cut), s(&missing)]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("skipped: ") && out.contains("cut.csv (row 7"),
        "{out}"
    );
    assert!(out.contains("missing.ulg (cannot read the file"), "{out}");
    // One added among skipped ones: exit 0.
    let (code, _, _) = run(&["logbook", "add", "--db", db, s(&cut), s(&files[3])]);
    assert_eq!(code, 0);
    let skipped = json(&["logbook", "skipped", "--db", db, "--format", "json"]);
    assert_eq!(skipped["skipped"].as_array().unwrap().len(), 1, "{skipped}");

    // Bad input: exit 2 with one line naming it.
    let nodir = tmp.path().join("no/such/folder/book.sqlite");
    let (code, _, err) = run(&["logbook", "flights", "--db", s(&nodir)]);
    assert_eq!(code, 2);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("no/such/folder") && err.contains("does not exist"),
        "{err}"
    );
    let not_db = tmp.path().join("not.sqlite");
    std::fs::write(
        &not_db,
        "this is not a database, it is text long enough to be one",
    )
    .unwrap();
    let (code, _, err) = run(&["logbook", "flights", "--db", s(&not_db)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not.sqlite"), "{err}");
    let (code, _, _) = run(&["logbook", "add", "--db", db]);
    assert_eq!(code, 2);
    let (code, _, err) = run(&[
        "logbook",
        "add",
        "--db",
        db,
        "--pack-label",
        "unknown",
        s(&files[0]),
    ]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = run(&[
        "logbook",
        "add",
        "--db",
        db,
        "--profile",
        "nonsense",
        s(&files[0]),
    ]);
    assert_eq!(code, 2, "{err}");
    let (code, _, _) = run(&["logbook", "flights", "--db", db, "--format", "csv"]);
    assert_eq!(code, 2);
}

/// `--db`, else `ALOFT_LOGBOOK`, else `$XDG_DATA_HOME/aloft/logbook.sqlite` (folder created).
#[test]
fn logbook_file_from_env_and_data_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let f = kaist();
    let env_db = tmp.path().join("env.sqlite");
    let o = aloft_env(
        &["logbook", "add", s(&f[10])],
        &[("ALOFT_LOGBOOK", &env_db)],
    );
    assert_eq!(o.status.code(), Some(0));
    assert!(env_db.is_file());
    let xdg = tmp.path().join("xdg");
    let o = aloft_env(&["logbook", "add", s(&f[10])], &[("XDG_DATA_HOME", &xdg)]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(xdg.join("aloft/logbook.sqlite").is_file());
    // A missing folder in ALOFT_LOGBOOK is not created.
    let o = aloft_env(
        &["logbook", "flights"],
        &[("ALOFT_LOGBOOK", &tmp.path().join("nope/b.sqlite"))],
    );
    assert_eq!(o.status.code(), Some(2));
}

/// Two `aloft logbook add` processes at once, each with its own logs: both sets land.
#[test]
fn logbook_two_processes_adding_at_once_both_land() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let files = kaist();
    let spawn = |part: &[PathBuf]| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_aloft"));
        c.args(["logbook", "add", "--db", s(&db)]).args(part);
        c.stdout(std::process::Stdio::null()).spawn().unwrap()
    };
    let (a, b) = files.split_at(6);
    let (mut pa, mut pb) = (spawn(a), spawn(b));
    assert!(pa.wait().unwrap().success());
    assert!(pb.wait().unwrap().success());
    let v = json(&["logbook", "flights", "--db", s(&db), "--format", "json"]);
    assert_eq!(v["flights"].as_array().unwrap().len(), 11);
}

/// The tables and columns of `docs/logbook.md`, in its order.
const SCHEMA: [(&str, &[&str]); 4] = [
    (
        "flights",
        &[
            "id",
            "file_sha256",
            "file_name",
            "format",
            "vehicle_key",
            "pack_key",
            "start_unix_s",
            "duration_s",
            "energy_wh",
            "discharged_mah",
            "max_current_a",
            "min_voltage_v",
            "mean_power_w",
            "added_unix_s",
            "hover_power_w",
            "cells_series",
            "resistance_ohm",
            "autopilot_resistance_ohm",
            "capacity_mah",
            "capacity_refusal",
            "imbalance_minor_min",
            "imbalance_major_min",
            "file_path",
            "copy_of",
            "air_s",
        ],
    ),
    (
        "packs",
        &[
            "key",
            "key_source",
            "rated_capacity_mah",
            "first_added_unix_s",
            "cells_series",
        ],
    ),
    (
        "skipped",
        &["file_sha256", "file_name", "reason", "added_unix_s"],
    ),
    ("vehicles", &["key", "key_source", "first_added_unix_s"]),
];

/// The documented schema is the file's: every table of `docs/logbook.md` has its columns in
/// its order; Python's `sqlite3` (the system's SQLite, not aloft's bundled one) reads the file
/// aloft wrote: the version, the tables, the columns, the rows.
#[test]
fn logbook_read_back_by_python_sqlite3_with_the_documented_schema() {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/logbook.md"))
            .unwrap();
    for (table, columns) in SCHEMA {
        let at = doc
            .find(&format!("### `{table}`"))
            .unwrap_or_else(|| panic!("docs/logbook.md: no table {table}"));
        let section = &doc[at..];
        let end = section[4..].find("\n### ").map_or(section.len(), |e| e + 4);
        let documented: Vec<&str> = section[..end]
            .lines()
            .filter_map(|l| l.strip_prefix("| `")?.split('`').next())
            .collect();
        assert_eq!(documented, columns, "docs/logbook.md, table {table}");
    }
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let f = kaist();
    let (code, _, err) = run(&["logbook", "add", "--db", s(&db), s(&f[0]), s(&f[10])]);
    assert_eq!(code, 0, "{err}");
    let script = r#"
import json, sqlite3, sys
c = sqlite3.connect(sys.argv[1])
out = {"user_version": c.execute("PRAGMA user_version").fetchone()[0],
       "application_id": c.execute("PRAGMA application_id").fetchone()[0],
       "journal_mode": c.execute("PRAGMA journal_mode").fetchone()[0], "tables": {}}
for (t,) in c.execute("SELECT name FROM sqlite_master WHERE type='table' ORDER BY name"):
    out["tables"][t] = [r[1] for r in c.execute(f"PRAGMA table_info({t})")]
out["flights"] = c.execute("SELECT count(*), sum(duration_s) FROM flights").fetchone()
print(json.dumps(out))
"#;
    let o = match Command::new("python3")
        .args(["-c", script, s(&db)])
        .output()
    {
        Ok(o) => o,
        Err(e) => {
            assert!(std::env::var_os("CI").is_none(), "python3: {e}");
            eprintln!("skipped: no python3 ({e})");
            return;
        }
    };
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["user_version"], 4);
    // The mark: the ASCII of "alft", big-endian.
    assert_eq!(v["application_id"], i32::from_be_bytes(*b"alft"));
    assert_eq!(v["journal_mode"], "wal");
    let tables = v["tables"].as_object().unwrap();
    assert_eq!(tables.len(), SCHEMA.len(), "{v}");
    for (table, columns) in SCHEMA {
        let got = common::strs(&tables[table]);
        assert_eq!(got, columns, "{table}");
    }
    assert_eq!(v["flights"][0], 2);
    // The two KAIST flights: 1018.2 s and 301.5 s of rows.
    let secs = v["flights"][1].as_f64().unwrap();
    assert!((secs - 1319.7).abs() < 0.5, "{secs}");
}

/// `aloft serve --logbook FILE`: `/api/logbook/KIND` is `aloft logbook KIND --format json`; an
/// unknown list and a server without a logbook are 404; a missing file stops the server at its
/// start (exit 2 naming it).
#[cfg(feature = "serve")]
#[test]
fn logbook_served_as_the_command_line_answers() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let f = kaist();
    let (code, _, err) = run(&[
        "logbook",
        "add",
        "--db",
        s(&db),
        s(&f[0]),
        s(&f[10]),
        "--vehicle-label",
        "kaist-m600",
    ]);
    assert_eq!(code, 0, "{err}");
    let server = common::serve::Server::start(&["--logbook", s(&db)]);
    for kind in ["flights", "vehicles", "packs", "skipped"] {
        let (status, body) = server.get(&format!("/api/logbook/{kind}"));
        assert_eq!(status, 200, "{body}");
        let served: Value = serde_json::from_str(&body).unwrap();
        assert_eq!(
            served,
            json(&["logbook", kind, "--db", s(&db), "--format", "json"]),
            "{kind}"
        );
    }
    assert_eq!(server.get("/api/logbook/etc").0, 404);
    let (_, config) = server.get("/api/config");
    assert!(config.contains("\"logbook\":true"), "{config}");
    drop(server);
    let plain = common::serve::Server::start(&[]);
    let (status, body) = plain.get("/api/logbook/vehicles");
    assert_eq!(status, 404, "{body}");
    assert!(body.contains("--logbook"), "{body}");
    drop(plain);
    let (code, _, err) = run(&[
        "serve",
        "--logbook",
        s(&tmp.path().join("none.sqlite")),
        "--listen",
        "127.0.0.1:0",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("none.sqlite"), "{err}");
}

/// `aloft logbook pack-file`: the pack file of a pack's logs, read again where they were; its
/// resistance the median of the flights' (5 flugdrohne ULogs: the middle one); a log moved
/// since is left out with a note, and with none left the answer is exit 1; "unknown" and a pack
/// not in the logbook are exit 2.
#[test]
fn logbook_pack_file_from_the_packs_logs() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let ulgs = common::files("px4_flugdrohne/ulg", |_| true);
    let mut args = vec![
        "logbook",
        "add",
        "--db",
        s(&db),
        "--pack-label",
        "flugdrohne-3s",
    ];
    args.extend(ulgs.iter().map(|p| s(p)));
    assert_eq!(run(&args).0, 0);
    let flights = json(&["logbook", "flights", "--db", s(&db), "--format", "json"]);
    let mut r: Vec<f64> = flights["flights"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f["resistance_ohm"].as_f64())
        .collect();
    assert_eq!(r.len(), 5);
    r.sort_by(f64::total_cmp);
    let pack = tmp.path().join("pack.toml");
    // `logbook pack-file KEY --db DB -o pack.toml EXTRA`.
    let pack_file = |key: &str, db: &Path, extra: &[&str]| {
        let mut args = vec!["logbook", "pack-file", key, "--db", s(db), "-o", s(&pack)];
        args.extend_from_slice(extra);
        run(&args)
    };
    let rating = ["--capacity-mah", "2200", "--mass-kg", "0.19"];
    let (code, out, err) = pack_file("flugdrohne-3s", &db, &rating);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("from 5 logs"), "{out}");
    let text = std::fs::read_to_string(&pack).unwrap();
    let file: toml::Table = toml::from_str(&text).unwrap();
    let battery = file["battery"].as_table().unwrap();
    assert_eq!(battery["name"].as_str(), Some("flugdrohne-3s"));
    assert_eq!(battery["cells_series"].as_integer(), Some(3));
    let ohm = battery["internal_resistance_ohm"].as_float().unwrap();
    assert!((ohm - r[2]).abs() < 1e-12, "{ohm} vs {r:?}");
    // The file flies.
    let (code, _, err) = run(&["mission", "--battery", s(&pack)]);
    assert!(code == 0 || code == 1, "{err}");

    // A log moved away after it was added.
    let moved = tmp.path().join("moved.ulg");
    std::fs::copy(&ulgs[0], &moved).unwrap();
    let db2 = tmp.path().join("two.sqlite");
    assert_eq!(
        run(&[
            "logbook",
            "add",
            "--db",
            s(&db2),
            "--pack-label",
            "p",
            s(&moved)
        ])
        .0,
        0
    );
    std::fs::remove_file(&moved).unwrap();
    let (code, _, err) = pack_file("p", &db2, &rating);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("moved.ulg: left out"), "{err}");
    let (code, _, err) = pack_file("unknown", &db2, &[]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = pack_file("nope", &db2, &[]);
    assert_eq!(code, 2);
    assert!(err.contains("no such pack"), "{err}");
}

/// `logbook add --db other-app.sqlite` (a SQLite file of another program): exit 2, one line
/// naming the file and saying it is not an aloft logbook; the file's bytes as they were, no WAL
/// or other side file made. Listing it is refused the same way.
#[test]
fn logbook_refuses_another_programs_sqlite_file_and_changes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("other-app.sqlite");
    let script = "import sqlite3, sys\nc = sqlite3.connect(sys.argv[1])\nc.execute('CREATE TABLE notes (id INTEGER PRIMARY KEY, text TEXT)')\nc.execute(\"INSERT INTO notes (text) VALUES ('keep me')\")\nc.commit()\n";
    match Command::new("python3")
        .args(["-c", script, s(&db)])
        .status()
    {
        Ok(st) => assert!(st.success()),
        Err(e) => {
            assert!(std::env::var_os("CI").is_none(), "python3: {e}");
            eprintln!("skipped: no python3 ({e})");
            return;
        }
    }
    let before = std::fs::read(&db).unwrap();
    let f = kaist();
    for args in [
        vec!["logbook", "add", "--db", s(&db), s(&f[0])],
        vec!["logbook", "flights", "--db", s(&db)],
        vec!["logbook", "packs", "--db", s(&db), "--format", "json"],
    ] {
        let (code, out, err) = run(&args);
        assert_eq!(code, 2, "{args:?}: {out}{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains("other-app.sqlite") && err.contains("not an aloft logbook"),
            "{err}"
        );
        assert!(std::fs::read(&db).unwrap() == before, "{args:?}: changed");
        let names: Vec<String> = std::fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, vec!["other-app.sqlite"], "{args:?}");
    }
}

/// A logbook with a page overwritten in the middle (the `skipped` table's): `add` is refused
/// in one line before anything is written; `flights` and `packs` still list what SQLite reads.
#[test]
fn logbook_damaged_is_refused_on_add_and_still_listed() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let f = kaist();
    let cut = tmp.path().join("cut.csv");
    std::fs::write(&cut, &std::fs::read(&f[0]).unwrap()[..1000]).unwrap();
    let (code, _, err) = run(&[
        "logbook",
        "add",
        "--db",
        s(&db),
        s(&f[0]),
        s(&f[1]),
        s(&f[2]),
        s(&cut),
    ]);
    assert_eq!(code, 0, "{err}");
    // The root page of `skipped`, by the page numbers of Python's sqlite3.
    let o = Command::new("python3")
        .args([
            "-c",
            "import sqlite3, sys\nc = sqlite3.connect(sys.argv[1])\nprint(c.execute(\"SELECT rootpage FROM sqlite_master WHERE name = 'skipped'\").fetchone()[0], c.execute('PRAGMA page_size').fetchone()[0])",
            s(&db),
        ])
        .output();
    let Ok(o) = o else {
        assert!(std::env::var_os("CI").is_none(), "no python3");
        return;
    };
    let text = String::from_utf8(o.stdout).unwrap();
    let nums: Vec<usize> = text
        .split_whitespace()
        .map(|n| n.parse().unwrap())
        .collect();
    let mut bytes = std::fs::read(&db).unwrap();
    let at = (nums[0] - 1) * nums[1];
    assert!(at > 0 && at < bytes.len() - nums[1], "{nums:?}");
    bytes[at..at + 12].fill(0xFF);
    std::fs::write(&db, &bytes).unwrap();

    let (code, out, err) = run(&["logbook", "add", "--db", s(&db), s(&f[3])]);
    assert_eq!(code, 2, "{out}{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("book.sqlite") && err.contains("damaged"),
        "{err}"
    );
    assert!(std::fs::read(&db).unwrap() == bytes, "written after all");
    let flights = json(&["logbook", "flights", "--db", s(&db), "--format", "json"]);
    assert_eq!(flights["flights"].as_array().unwrap().len(), 3);
    let packs = json(&["logbook", "packs", "--db", s(&db), "--format", "json"]);
    let n: u64 = packs["packs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["flights"].as_u64().unwrap())
        .sum();
    assert_eq!(n, 3);
}

/// Run aloft as another user than root (`setpriv` to nobody), where the tests run as root (root
/// ignores file permissions); as the user itself otherwise. `None` when root cannot switch.
fn as_unprivileged(args: &[&str]) -> Option<(i32, String, String)> {
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    let o = if root {
        let mut c = Command::new("setpriv");
        c.args(["--reuid=65534", "--regid=65534", "--clear-groups"])
            .arg(env!("CARGO_BIN_EXE_aloft"))
            .args(args)
            .env_remove("ALOFT_LOGBOOK");
        c.output().ok()?
    } else {
        aloft_env(args, &[])
    };
    Some((
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    ))
}

/// A logbook the user may read but not write: the file read-only in a folder they may write,
/// and the file in a folder they may not write (where SQLite cannot make the WAL's side files).
/// `flights`, `vehicles` and `packs` list it; `add` is refused (exit 2); the file is unchanged.
#[cfg(unix)]
#[test]
fn logbook_listed_from_a_read_only_file_and_a_read_only_folder() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let f = kaist();
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    for (folder_mode, file_mode) in [(0o777, 0o444), (0o555, 0o444), (0o755, 0o644)] {
        let dir = tmp.path().join(format!("d{folder_mode:o}-{file_mode:o}"));
        std::fs::create_dir(&dir).unwrap();
        let db = dir.join("book.sqlite");
        let (code, _, err) = run(&["logbook", "add", "--db", s(&db), s(&f[0]), s(&f[10])]);
        assert_eq!(code, 0, "{err}");
        if !root && folder_mode == 0o755 {
            // Owned by the user: a folder they may write; covered by the 0o555 case.
            continue;
        }
        std::fs::set_permissions(&db, std::fs::Permissions::from_mode(file_mode)).unwrap();
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(folder_mode)).unwrap();
        std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
        let before = std::fs::read(&db).unwrap();
        for kind in ["flights", "vehicles", "packs"] {
            let Some((code, out, err)) =
                as_unprivileged(&["logbook", kind, "--db", s(&db), "--format", "json"])
            else {
                assert!(std::env::var_os("CI").is_none(), "cannot run as nobody");
                eprintln!("skipped: cannot run as another user");
                return;
            };
            assert_eq!(code, 0, "{folder_mode:o}/{file_mode:o} {kind}: {err}");
            let v: Value = serde_json::from_str(&out).unwrap();
            assert!(!v[kind].as_array().unwrap().is_empty(), "{v}");
        }
        let (code, _, err) =
            as_unprivileged(&["logbook", "add", "--db", s(&db), s(&f[1])]).unwrap();
        assert_eq!(code, 2, "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(std::fs::read(&db).unwrap() == before);
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
}

/// A link planted at the logbook's path, to a file that does not exist: `add` creates nothing
/// through it (exit 2 naming the path).
#[cfg(unix)]
#[test]
fn logbook_not_created_through_a_planted_link() {
    let tmp = tempfile::tempdir().unwrap();
    let target = tmp.path().join("victim.sqlite");
    let db = tmp.path().join("book.sqlite");
    std::os::unix::fs::symlink(&target, &db).unwrap();
    let (code, _, err) = run(&["logbook", "add", "--db", s(&db), s(&kaist()[0])]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("book.sqlite"), "{err}");
    assert!(!target.exists());
}

/// Paths of every `null` in a JSON value.
/// The paths of every `null` in `v`, each after `at`.
fn nulls(v: &Value, at: &str, out: &mut Vec<String>) {
    out.extend(common::nulls(v).into_iter().map(|p| format!("{at}{p}")));
}

/// Real logs that lack some figures (the KAIST CSVs have no clock, no cells, no rating; some
/// ULogs no hover or resistance): no `null` anywhere in the JSON of `add`, `flights`,
/// `vehicles`, `packs`; an absent figure is an absent key, a present one is there.
#[test]
fn logbook_json_has_no_null_where_a_figure_is_absent() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let d = data_dir();
    let kaist = kaist();
    let ulog = d.join("px4_flugdrohne/ulg/log_20_2023-6-7-10-52-56.ulg");
    let bin = d.join("flight_logs/sitl_ac47_00000002.BIN");
    let added = json(&[
        "logbook",
        "add",
        "--db",
        s(&db),
        s(&kaist[0]),
        s(&kaist[1]),
        s(&ulog),
        s(&bin),
        "--format",
        "json",
    ]);
    let mut found = Vec::new();
    nulls(&added, "add", &mut found);
    for kind in ["flights", "vehicles", "packs", "skipped"] {
        let v = json(&["logbook", kind, "--db", s(&db), "--format", "json"]);
        nulls(&v, kind, &mut found);
    }
    assert_eq!(found, Vec::<String>::new());
    let v = json(&["logbook", "flights", "--db", s(&db), "--format", "json"]);
    let by_name = |n: &str| -> Value {
        v["flights"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["file_name"] == n)
            .cloned()
            .unwrap()
    };
    // A CSV has no clock: no start; the ULog's GPS clock gives one.
    let csv = by_name(kaist[0].file_name().unwrap().to_str().unwrap());
    assert!(csv.get("start_unix_s").is_none(), "{csv}");
    assert!(csv["duration_s"].as_f64().unwrap() > 0.0);
    let u = by_name("log_20_2023-6-7-10-52-56.ulg");
    assert!(u["start_unix_s"].as_f64().unwrap() > 1.6e9, "{u}");
}

/// The armed spans of a telemetry log, from the HEARTBEATs of system 1 component 1 read here
/// frame by frame (aloft-link's CRC-checked frame reader, not the logbook's reading of it):
/// their count, their total and the first arming to the last disarming, s.
fn armed_spans(tlog: &Path) -> (usize, f64, f64) {
    use aloft_link::mavlink::dialects::ardupilotmega::{MavMessage, MavModeFlag};
    let mut r = aloft_link::TlogReader::new(std::fs::File::open(tlog).unwrap(), "t");
    let (mut first, mut armed_at, mut spans, mut total) = (None, None::<f64>, 0, 0.0);
    let (mut from, mut until) = (None, 0.0);
    while let Some(fr) = r.next_frame().unwrap() {
        let f0 = *first.get_or_insert(fr.timestamp_us);
        let t = (fr.timestamp_us as f64 - f0 as f64) * 1e-6;
        let MavMessage::HEARTBEAT(hb) = &fr.message else {
            continue;
        };
        if (fr.header.system_id, fr.header.component_id) != (1, 1) {
            continue;
        }
        let armed = hb
            .base_mode
            .contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED);
        match (armed_at, armed) {
            (None, true) => {
                armed_at = Some(t);
                from.get_or_insert(t);
            }
            (Some(a), false) => {
                spans += 1;
                total += t - a;
                until = t;
                armed_at = None;
            }
            _ => {}
        }
    }
    (spans, total, until - from.unwrap())
}

/// `logbook add` of the shared `.tlog` files: the flights of the telemetry, or one line saying
/// why not (never "stream did not contain valid UTF-8"). The real dronekit flight: from its
/// first arming to its last disarming 575 s in 7 armed spans (the data's README, by
/// pymavlink), about 2060 mAh (README); its time in the air the sum of the spans read here from
/// the HEARTBEATs. The SITL flights: armed 214 s and 184 s (README), and their charge within 3 %
/// of the autopilot's own counter (BATTERY_STATUS `current_consumed`) over the log. The bench
/// log that never armed, the real flight without a power module, and a file that is no log at
/// all (a terrain tile) are skipped, each with its reason.
#[test]
fn data_val_logbook_reads_the_flights_of_telemetry_logs() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let t = data_dir().join("telemetry");
    let tile = data_dir().join("terrain/N44W072.hgt");
    let files = [
        "dronekit_flight_replay.tlog",
        "ayoub_auto_mission_sitl.tlog",
        "kudrone_guided_sitl.tlog",
        "eagle_c2_bench_v2.tlog",
        "phoenix_mission1_real.tlog",
    ]
    .map(|n| t.join(n));
    let mut args = vec!["logbook", "add", "--db", s(&db)];
    args.extend(files.iter().map(|p| s(p)));
    args.push(s(&tile));
    let (code, out, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains("UTF-8") && !err.contains("UTF-8"), "{out}");
    assert!(
        out.contains("3 added, 0 copies, 0 already in the logbook, 3 skipped"),
        "{out}"
    );
    let line = |name: &str| out.lines().find(|l| l.contains(name)).unwrap().to_string();
    assert!(line("eagle_c2_bench_v2").contains("never armed"), "{out}");
    assert!(
        line("phoenix_mission1_real").contains("no battery voltage"),
        "{out}"
    );
    assert!(
        line("N44W072.hgt").contains("not a log the logbook reads"),
        "{out}"
    );

    let v = json(&["logbook", "flights", "--db", s(&db), "--format", "json"]);
    let flights = v["flights"].as_array().unwrap();
    let by = |n: &str| flights.iter().find(|f| f["file_name"] == n).unwrap();
    let dk = by("dronekit_flight_replay.tlog");
    assert_eq!(dk["format"], "tlog");
    let (spans, armed_s, window_s) = armed_spans(&files[0]);
    assert_eq!(spans, 7);
    assert!((window_s - 575.0).abs() < 2.0, "{window_s}");
    let duration = dk["duration_s"].as_f64().unwrap();
    assert!(
        (duration - window_s).abs() < 2.0,
        "{duration} vs {window_s}"
    );
    let air = dk["air_s"].as_f64().unwrap();
    assert!((air - armed_s).abs() < 1.0, "{air} vs {armed_s}");
    let mah = dk["discharged_mah"].as_f64().unwrap();
    assert!((mah - 2060.0).abs() < 0.02 * 2060.0, "{mah}");
    assert!(dk["start_unix_s"].as_f64().unwrap() > 1.4e9);
    for (name, armed_readme_s) in [
        ("ayoub_auto_mission_sitl.tlog", 214.0),
        ("kudrone_guided_sitl.tlog", 184.0),
    ] {
        let f = by(name);
        let air = f["air_s"].as_f64().unwrap();
        assert!((air - armed_readme_s).abs() < 2.0, "{name}: {air}");
    }
    let ku = by("kudrone_guided_sitl.tlog");
    let counter_mah = consumed_growth_mah(&files[2]);
    let mah = ku["discharged_mah"].as_f64().unwrap();
    assert!(
        (mah - counter_mah).abs() < 0.03 * counter_mah,
        "{mah} vs {counter_mah}"
    );
}

/// The growth of BATTERY_STATUS `current_consumed` (battery 0) over a telemetry log, mAh.
fn consumed_growth_mah(tlog: &Path) -> f64 {
    use aloft_link::mavlink::dialects::ardupilotmega::MavMessage;
    let mut r = aloft_link::TlogReader::new(std::fs::File::open(tlog).unwrap(), "t");
    let mut v = Vec::new();
    while let Some(fr) = r.next_frame().unwrap() {
        if let MavMessage::BATTERY_STATUS(b) = &fr.message {
            if b.id == 0 && b.current_consumed >= 0 {
                v.push(f64::from(b.current_consumed));
            }
        }
    }
    v[v.len() - 1] - v[0]
}

/// A telemetry log and a truncated copy of it (the first 60 % of its bytes: other content, the
/// same start): the copy is recorded as a copy of the first, and the vehicle's flights, hours
/// and energy count the flight once; `flights` shows the copy as such.
#[test]
fn logbook_counts_a_truncated_copy_of_a_tlog_once() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let full = data_dir().join("telemetry/ayoub_auto_mission_sitl.tlog");
    let bytes = std::fs::read(&full).unwrap();
    let cut = tmp.path().join("ayoub-cut.tlog");
    std::fs::write(&cut, &bytes[..bytes.len() * 6 / 10]).unwrap();
    let (code, out, err) = run(&["logbook", "add", "--db", s(&db), s(&full), s(&cut)]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("1 added, 1 copies"), "{out}");
    assert!(
        out.lines().any(|l| l.starts_with("copy: ")
            && l.contains("ayoub-cut.tlog")
            && l.contains("copy of flight 1")),
        "{out}"
    );
    let v = json(&["logbook", "vehicles", "--db", s(&db), "--format", "json"]);
    let veh = &v["vehicles"][0];
    assert_eq!(
        (veh["flights"].as_u64(), veh["copies"].as_u64()),
        (Some(1), Some(1))
    );
    let f = json(&["logbook", "flights", "--db", s(&db), "--format", "json"]);
    let flights = f["flights"].as_array().unwrap();
    let whole = flights
        .iter()
        .find(|x| x["file_name"] == "ayoub_auto_mission_sitl.tlog")
        .unwrap();
    let copy = flights
        .iter()
        .find(|x| x["file_name"] == "ayoub-cut.tlog")
        .unwrap();
    assert_eq!(copy["copy_of"], whole["id"]);
    assert!(whole.get("copy_of").is_none());
    let hours = veh["hours"].as_f64().unwrap();
    assert!((hours * 3600.0 - whole["duration_s"].as_f64().unwrap()).abs() < 1e-6);
    let (_, table, _) = run(&["logbook", "flights", "--db", s(&db)]);
    assert!(table.contains("copy of"), "{table}");
    // The pack file of a pack flown only in telemetry: none (exit 1), saying why, not the
    // CSV reader's "stream did not contain valid UTF-8".
    let pack = whole["pack_key"].as_str().unwrap();
    let out = tmp.path().join("pack.toml");
    let (code, _, err) = run(&[
        "logbook",
        "pack-file",
        pack,
        "--db",
        s(&db),
        "-o",
        s(&out),
        "--mass-kg",
        "0.2",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("a telemetry log") && !err.contains("UTF-8"),
        "{err}"
    );
    assert!(!out.exists());
}

/// `aloft logbook relabel pack|vehicle OLD NEW`: renamed (exit 0, saying how many flights);
/// an unknown name, a name taken and a name that is not a label are exit 2 in one line naming
/// it, with nothing changed.
#[test]
fn logbook_relabel_from_the_command_line() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let d = data_dir().join("px4_flugdrohne/ulg");
    let (a, b) = (
        d.join("log_20_2023-6-7-10-52-56.ulg"),
        d.join("log_66_2023-6-21-08-44-02.ulg"),
    );
    assert_eq!(run(&["logbook", "add", "--db", s(&db), s(&a)]).0, 0);
    assert_eq!(
        run(&[
            "logbook",
            "add",
            "--db",
            s(&db),
            "--pack-label",
            "spare",
            s(&b)
        ])
        .0,
        0
    );
    let packs = json(&["logbook", "packs", "--db", s(&db), "--format", "json"]);
    let derived = packs["packs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["key"].as_str().unwrap().to_string())
        .find(|k| k.starts_with("unknown 3S on "))
        .unwrap();
    let vehicle = derived.trim_start_matches("unknown 3S on ").to_string();
    for (args, says) in [
        (vec!["pack", "nope", "x"], "no pack \"nope\""),
        (
            vec!["pack", derived.as_str(), "spare"],
            "a pack \"spare\" is already",
        ),
        (vec!["pack", derived.as_str(), "unknown"], "is not a label"),
        (vec!["vehicle", "nope", "x"], "no vehicle \"nope\""),
    ] {
        let mut full = vec!["logbook", "relabel", "--db", s(&db)];
        full.extend(&args);
        let (code, out, err) = run(&full);
        assert_eq!(code, 2, "{args:?}: {out}{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
    let (code, out, err) = run(&[
        "logbook",
        "relabel",
        "--db",
        s(&db),
        "pack",
        &derived,
        "flug-a",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("flug-a") && out.contains("1 flight"), "{out}");
    let (code, _, err) = run(&[
        "logbook",
        "relabel",
        "--db",
        s(&db),
        "vehicle",
        &vehicle,
        "flugdrohne",
    ]);
    assert_eq!(code, 0, "{err}");
    let f = json(&["logbook", "flights", "--db", s(&db), "--format", "json"]);
    for x in f["flights"].as_array().unwrap() {
        assert_eq!(x["vehicle_key"], "flugdrohne", "{x}");
    }
    let keys: Vec<String> = json(&["logbook", "packs", "--db", s(&db), "--format", "json"])
        ["packs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["key"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(keys, vec!["flug-a", "spare"]);
}

/// Issue 41's rule in the logbook's text answers: a log whose name holds a newline and an
/// escape sequence is shown escaped on one line by `logbook add`, `flights`, `skipped` and
/// `pack-file` (its notes on a log moved or changed since it was added), never as a second line
/// or a terminal's colour.
#[test]
fn logbook_text_answers_show_hostile_file_names_escaped_on_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let ulgs = common::files("px4_flugdrohne/ulg", |_| true);
    // Two flights, moved and changed before pack-file reads them again, and a damaged file.
    let gone = tmp.path().join("gone\nFORGED: \u{1b}[31mmoved.ulg");
    let changed = tmp.path().join("changed\nFORGED: edited.ulg");
    let damaged = tmp.path().join("cut\nFORGED: damaged.csv");
    std::fs::copy(&ulgs[0], &gone).unwrap();
    std::fs::copy(&ulgs[1], &changed).unwrap();
    std::fs::write(&damaged, "time_s,voltage_v\n0,").unwrap();
    let clean = |what: &str, text: &str| {
        for line in text.lines() {
            assert!(
                !line.starts_with("FORGED") && !line.contains('\u{1b}'),
                "{what}: a name broke a line or coloured it: {line:?} in\n{text}"
            );
        }
    };
    let (_, out, err) = run(&[
        "logbook",
        "add",
        "--db",
        s(&db),
        "--pack-label",
        "p",
        s(&gone),
        s(&changed),
        s(&damaged),
    ]);
    clean("logbook add", &out);
    clean("logbook add", &err);
    assert!(out.contains(r"gone\nFORGED: \u{1b}[31mmoved"), "{out}");
    for kind in ["flights", "skipped"] {
        let (code, out, err) = run(&["logbook", kind, "--db", s(&db)]);
        assert_eq!(code, 0, "{err}");
        clean(kind, &out);
        assert!(out.contains(r"\nFORGED"), "{kind}: {out}");
    }
    std::fs::remove_file(&gone).unwrap();
    std::fs::write(&changed, b"not the log it was").unwrap();
    let pack = tmp.path().join("pack.toml");
    let (_, out, err) = run(&[
        "logbook",
        "pack-file",
        "p",
        "--db",
        s(&db),
        "-o",
        s(&pack),
        "--capacity-mah",
        "5000",
    ]);
    clean("logbook pack-file", &out);
    clean("logbook pack-file", &err);
    assert!(
        err.contains(r"gone\nFORGED: \u{1b}[31mmoved.ulg: left out"),
        "{err}"
    );
    assert!(
        err.contains(r"changed\nFORGED: edited.ulg: left out"),
        "{err}"
    );
}
