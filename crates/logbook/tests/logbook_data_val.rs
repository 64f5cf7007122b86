//! The logbook on every shared log: all added, twice, with damaged copies among them; the KAIST
//! totals against the CSVs themselves; the vehicle keys against the logs' own `sys_uuid` and
//! `BRD_SERIAL_NUM`, read here by a few lines of byte search (not aloft's decoders); two adds
//! at once; a version 1 file written by hand and opened by this code.

#[path = "../../../tests/it/common/data.rs"]
mod data;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use aloft_logbook::{AddOutcome, Labels, Logbook, ReadOptions, SCHEMA_VERSION, UNKNOWN};

/// The files of the data folder `sub` ending `.EXT` for one of `ext`, sorted.
fn sorted(sub: &str, ext: &[&str]) -> Vec<PathBuf> {
    data::files(sub, |n| ext.iter().any(|e| n.ends_with(&format!(".{e}"))))
}

fn kaist() -> Vec<PathBuf> {
    sorted("kaist_energy_drone", &["csv"])
}

/// The PX4 ULogs and ArduPilot DataFlash logs: the flugdrohne flights and `flight_logs/`.
fn binary_logs() -> Vec<PathBuf> {
    let mut v = sorted("px4_flugdrohne/ulg", &["ulg"]);
    v.extend(sorted("flight_logs", &["ulg", "bin", "BIN"]));
    v
}

/// Counts of the logbook's tables.
fn counts(book: &Logbook) -> (usize, usize, usize, usize) {
    (
        book.flights().unwrap().len(),
        book.vehicles().unwrap().len(),
        book.packs().unwrap().len(),
        book.skipped().unwrap().len(),
    )
}

/// A ULog's `sys_uuid` info message: the key `char[N] sys_uuid` and the N bytes after it.
fn ulog_sys_uuid(bytes: &[u8]) -> Option<String> {
    let key = b" sys_uuid";
    let at = bytes.windows(key.len()).position(|w| w == key)?;
    let head = &bytes[at.saturating_sub(12)..at];
    let open = head.iter().rposition(|&b| b == b'[')?;
    let close = head.iter().rposition(|&b| b == b']')?;
    let n: usize = std::str::from_utf8(&head[open + 1..close])
        .ok()?
        .parse()
        .ok()?;
    let value = bytes.get(at + key.len()..at + key.len() + n)?;
    Some(
        String::from_utf8_lossy(value)
            .trim_end_matches('\0')
            .to_string(),
    )
}

/// A DataFlash log's `BRD_SERIAL_NUM` (a PARM record: 16 bytes of name, then the value as an
/// f32); 0 or absent is no identity.
fn dataflash_serial(bytes: &[u8]) -> Option<f32> {
    let key = b"BRD_SERIAL_NUM";
    let at = bytes.windows(key.len()).position(|w| w == key)?;
    let v = bytes.get(at + 16..at + 20)?;
    Some(f32::from_le_bytes([v[0], v[1], v[2], v[3]])).filter(|s| *s != 0.0)
}

/// The vehicle keys of the binary logs, read from their bytes ("unknown" for those without).
fn expected_vehicle_keys(logs: &[PathBuf]) -> BTreeSet<String> {
    logs.iter()
        .map(|p| {
            let bytes = std::fs::read(p).unwrap();
            let ulog = p.extension().is_some_and(|e| e == "ulg");
            let id = if ulog {
                ulog_sys_uuid(&bytes)
            } else {
                dataflash_serial(&bytes).map(|s| format!("{s}"))
            };
            id.unwrap_or_else(|| UNKNOWN.to_string())
        })
        .collect()
}

/// Damaged copies in `dir`: a KAIST CSV cut inside its seventh row, a ULog cut inside its
/// definitions (before any battery record).
fn damaged_copies(dir: &Path) -> Vec<PathBuf> {
    let d = data::data_dir();
    let csv =
        std::fs::read(d.join("kaist_energy_drone/2018-08-08.10_58_54testgpsfense.csv")).unwrap();
    let ulg = std::fs::read(d.join("px4_flugdrohne/ulg/1x_wo_Last_5m.ulg")).unwrap();
    let a = dir.join("cut.csv");
    let b = dir.join("cut.ulg");
    std::fs::write(&a, &csv[..1000]).unwrap();
    std::fs::write(&b, &ulg[..20_000]).unwrap();
    vec![a, b]
}

/// The files without battery data in `flight_logs/` (its README: no battery records, or none
/// with a voltage).
const NO_BATTERY: [&str; 2] = ["beastayyg_sample.bin", "erle_2014-09-07_7.BIN"];

#[test]
fn data_val_every_shared_log_added_twice_with_damaged_copies_changes_no_count() {
    let tmp = tempfile::tempdir().unwrap();
    let mut book = Logbook::open(&tmp.path().join("book.sqlite")).unwrap();
    let (kaist, binary) = (kaist(), binary_logs());
    let damaged = damaged_copies(tmp.path());
    let mut files: Vec<PathBuf> = kaist.iter().chain(&binary).cloned().collect();
    files.insert(3, damaged[0].clone());
    files.push(damaged[1].clone());
    let opts = ReadOptions::default();
    let first: Vec<AddOutcome> = files
        .iter()
        .map(|f| book.add(f, &Labels::default(), &opts).unwrap())
        .collect();
    let logs_with_battery = kaist.len() + binary.len() - NO_BATTERY.len();
    let added = first
        .iter()
        .filter(|o| matches!(o, AddOutcome::Added { .. }))
        .count();
    assert_eq!(kaist.len(), 11);
    assert_eq!(added, logs_with_battery, "{first:#?}");
    let after_first = counts(&book);
    // Vehicles: the logs' own keys, plus "unknown" for the KAIST CSVs (no identity).
    let mut vehicles = expected_vehicle_keys(&binary);
    vehicles.insert(UNKNOWN.to_string());
    let got: BTreeSet<String> = book
        .vehicles()
        .unwrap()
        .into_iter()
        .map(|v| v.key)
        .collect();
    assert_eq!(got, vehicles);
    // No shared log names its pack (no smart pack, no BATT_SERIAL_NUM): each pack is keyed by
    // its vehicle, cells and rating, `unknown ... on <vehicle>`, never plain "unknown".
    let packs: BTreeSet<String> = book.packs().unwrap().into_iter().map(|p| p.key).collect();
    for p in &packs {
        let on = p.rfind(" on ").unwrap_or_else(|| panic!("{p}"));
        assert!(
            p.starts_with("unknown ") || p.starts_with("unknown on "),
            "{p}"
        );
        assert!(vehicles.contains(&p[on + 4..]), "{p}");
    }
    assert!(packs.len() >= vehicles.len(), "{packs:?}");
    assert_eq!(
        after_first,
        (
            logs_with_battery,
            vehicles.len(),
            packs.len(),
            NO_BATTERY.len() + damaged.len()
        )
    );
    let skipped: BTreeSet<String> = book
        .skipped()
        .unwrap()
        .into_iter()
        .map(|s| s.file_name)
        .collect();
    let mut expected_skipped: BTreeSet<String> = NO_BATTERY.iter().map(|s| s.to_string()).collect();
    expected_skipped.extend(["cut.csv".to_string(), "cut.ulg".to_string()]);
    assert_eq!(skipped, expected_skipped);
    // The reason of the cut CSV names the row where it breaks.
    let cut = book
        .skipped()
        .unwrap()
        .into_iter()
        .find(|s| s.file_name == "cut.csv")
        .unwrap();
    assert!(cut.reason.contains("row 7"), "{}", cut.reason);

    // Again: every log is already there (by content), the skipped ones are skipped again.
    let second: Vec<AddOutcome> = files
        .iter()
        .map(|f| book.add(f, &Labels::default(), &opts).unwrap())
        .collect();
    for (f, o) in files.iter().zip(&second) {
        match o {
            AddOutcome::AlreadyPresent { .. } | AddOutcome::Skipped { .. } => {}
            AddOutcome::Added { .. } | AddOutcome::Copy { .. } => {
                panic!("{} added twice", f.display())
            }
        }
    }
    assert_eq!(counts(&book), after_first);
    // A copy under another name is the same flight.
    let copy = tmp.path().join("renamed.csv");
    std::fs::copy(&kaist[0], &copy).unwrap();
    assert!(matches!(
        book.add(&copy, &Labels::default(), &opts).unwrap(),
        AddOutcome::AlreadyPresent { flight_id: 1 }
    ));
}

/// One KAIST CSV's rows: (time s, voltage V, current A).
fn kaist_rows(p: &Path) -> Vec<(f64, f64, f64)> {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (t, v, i) = (col("timestamp"), col("vol"), col("cur"));
    lines
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Some((
                f.get(t)?.parse::<f64>().ok()? * 1e-6,
                f.get(v)?.parse().ok()?,
                f.get(i)?.parse().ok()?,
            ))
        })
        .collect()
}

/// The KAIST flights under one label: 11 flights, and their time and charge as the CSVs give
/// them. Time: first to last row (the reader's span of battery records is the same rows: within
/// one row, 0.1 s, per flight). Charge: the trapezoid of `cur` over the rows, within 1 % per
/// flight (the reader may drop an isolated contradictory row, one file has a 90 V spike).
#[test]
fn data_val_kaist_totals_match_the_csv_rows() {
    let tmp = tempfile::tempdir().unwrap();
    let mut book = Logbook::open(&tmp.path().join("book.sqlite")).unwrap();
    let labels = Labels {
        vehicle: Some("kaist-m600".into()),
        pack: None,
    };
    let files = kaist();
    for f in &files {
        let o = book.add(f, &labels, &ReadOptions::default()).unwrap();
        assert!(matches!(o, AddOutcome::Added { .. }), "{o:?}");
    }
    let flights = book.flights().unwrap();
    assert_eq!(flights.len(), 11);
    let mut hours = 0.0;
    let mut mah = 0.0;
    for (f, path) in flights.iter().zip(&files) {
        let rows = kaist_rows(path);
        let span_s = rows.last().unwrap().0 - rows[0].0;
        let charge_mah: f64 = rows
            .windows(2)
            .map(|w| 0.5 * (w[0].2 + w[1].2) * (w[1].0 - w[0].0))
            .sum::<f64>()
            / 3.6;
        assert!(
            (f.duration_s - span_s).abs() <= 0.1,
            "{}: {} s vs {span_s} s",
            f.file_name,
            f.duration_s
        );
        let got = f.discharged_mah.unwrap();
        assert!(
            (got - charge_mah).abs() <= 0.01 * charge_mah,
            "{}: {got} vs {charge_mah} mAh",
            f.file_name
        );
        assert_eq!(f.vehicle_key, "kaist-m600");
        // The pack: the CSVs state neither its cells nor its rating, and its 44 to 50 V (12S
        // by the data's README) fit 11 to 13 lithium cells: keyed by its vehicle alone.
        assert_eq!(f.pack_key, "unknown on kaist-m600");
        hours += span_s / 3600.0;
        mah += charge_mah;
    }
    let v = book.vehicles().unwrap();
    assert_eq!(v.len(), 1);
    assert_eq!(
        (v[0].key.as_str(), v[0].key_source.as_str(), v[0].flights),
        ("kaist-m600", "label", 11)
    );
    assert!(
        (v[0].hours - hours).abs() <= 11.0 * 0.1 / 3600.0,
        "{} h vs {hours} h",
        v[0].hours
    );
    assert!((v[0].discharged_mah - mah).abs() <= 0.01 * mah);
    // The 3.2 h of the research notes.
    assert!((3.15..3.25).contains(&hours), "{hours}");
    // Every KAIST flight has a hover power and a drift over all 11.
    let drift = v[0].power_drift.as_ref().unwrap();
    assert_eq!(
        (drift.quantity.as_str(), drift.trend.n),
        ("hover_power_w", 11)
    );
}

/// The log's identity wins over a label; the label files logs without one.
#[test]
fn data_val_a_label_files_only_logs_without_an_identity() {
    let tmp = tempfile::tempdir().unwrap();
    let mut book = Logbook::open(&tmp.path().join("book.sqlite")).unwrap();
    let labels = Labels {
        vehicle: Some("my-quad".into()),
        pack: Some("pack-7".into()),
    };
    let ulog = data::data_dir().join("px4_flugdrohne/ulg/log_20_2023-6-7-10-52-56.ulg");
    let uuid = ulog_sys_uuid(&std::fs::read(&ulog).unwrap()).unwrap();
    let o = book.add(&ulog, &labels, &ReadOptions::default()).unwrap();
    assert_eq!(
        o,
        AddOutcome::Added {
            flight_id: 1,
            vehicle_key: uuid,
            pack_key: "pack-7".into()
        }
    );
    let packs = book.packs().unwrap();
    assert_eq!(
        (packs[0].key.as_str(), packs[0].key_source.as_str()),
        ("pack-7", "label")
    );
}

/// Two writers at once (two connections, as two processes have): each adds its own logs while
/// the other does; both sets land.
#[test]
fn two_adds_at_once_both_land() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("book.sqlite");
    let files = kaist();
    let (a, b) = files.split_at(5);
    std::thread::scope(|s| {
        for part in [a, b] {
            let db = db.clone();
            s.spawn(move || {
                let mut book = Logbook::open(&db).unwrap();
                for f in part {
                    let o = book
                        .add(f, &Labels::default(), &ReadOptions::default())
                        .unwrap();
                    assert!(matches!(o, AddOutcome::Added { .. }), "{o:?}");
                }
            });
        }
    });
    let book = Logbook::open(&db).unwrap();
    assert_eq!(book.flights().unwrap().len(), files.len());
}

/// Many connections opening one new file at the same moment (as `aloft logbook add` processes
/// started together do): each opens it, none is refused as locked. Opening switches the file to
/// WAL, which SQLite refuses at once, without waiting, to one of two readers that both want the
/// write lock; a CI run failed on it (one `add` of two: "database is locked").
#[test]
fn many_opens_of_a_new_file_at_once_all_succeed() {
    let tmp = tempfile::tempdir().unwrap();
    for round in 0..30 {
        let db = tmp.path().join(format!("book{round}.sqlite"));
        let start = std::sync::Barrier::new(6);
        std::thread::scope(|s| {
            for _ in 0..6 {
                let (db, start) = (&db, &start);
                s.spawn(move || {
                    start.wait();
                    if let Err(e) = Logbook::open(db) {
                        panic!("round {round}: {e}");
                    }
                });
            }
        });
    }
}

/// A logbook of version 1, written here by hand with a flight, opened by this code: migrated to
/// the current version, the flight kept, the new columns empty, and adding works.
#[test]
fn a_version_1_logbook_is_migrated_forward() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("v1.sqlite");
    {
        let c = rusqlite::Connection::open(&db).unwrap();
        c.execute_batch(
            "CREATE TABLE vehicles (key TEXT PRIMARY KEY, key_source TEXT NOT NULL,
                 first_added_unix_s INTEGER NOT NULL);
             CREATE TABLE packs (key TEXT PRIMARY KEY, key_source TEXT NOT NULL,
                 rated_capacity_mah REAL, first_added_unix_s INTEGER NOT NULL);
             CREATE TABLE flights (id INTEGER PRIMARY KEY, file_sha256 TEXT NOT NULL UNIQUE,
                 file_name TEXT NOT NULL, format TEXT NOT NULL,
                 vehicle_key TEXT NOT NULL REFERENCES vehicles(key),
                 pack_key TEXT NOT NULL REFERENCES packs(key), start_unix_s REAL,
                 duration_s REAL NOT NULL, energy_wh REAL NOT NULL, discharged_mah REAL,
                 max_current_a REAL, min_voltage_v REAL, mean_power_w REAL,
                 added_unix_s INTEGER NOT NULL);
             CREATE INDEX flights_by_vehicle ON flights(vehicle_key);
             CREATE INDEX flights_by_pack ON flights(pack_key);
             CREATE TABLE skipped (file_sha256 TEXT PRIMARY KEY, file_name TEXT NOT NULL,
                 reason TEXT NOT NULL, added_unix_s INTEGER NOT NULL);
             INSERT INTO vehicles VALUES ('quad-1', 'label', 1700000000);
             INSERT INTO packs VALUES ('pack-1', 'label', 5000, 1700000000);
             INSERT INTO flights (file_sha256, file_name, format, vehicle_key, pack_key,
                 duration_s, energy_wh, discharged_mah, added_unix_s)
               VALUES ('00', 'old.ulg', 'ulog', 'quad-1', 'pack-1', 600, 50, 2500, 1700000000);
             PRAGMA user_version = 1;",
        )
        .unwrap();
    }
    let mut book = Logbook::open(&db).unwrap();
    let flights = book.flights().unwrap();
    assert_eq!(flights.len(), 1);
    let f = &flights[0];
    assert_eq!(
        (f.file_name.as_str(), f.duration_s, f.resistance_ohm),
        ("old.ulg", 600.0, None)
    );
    let packs = book.packs().unwrap();
    // 2500 mAh of a 5000 mAh pack: half a cycle.
    assert_eq!(packs[0].equivalent_cycles, Some(0.5));
    let o = book
        .add(&kaist()[10], &Labels::default(), &ReadOptions::default())
        .unwrap();
    assert!(matches!(o, AddOutcome::Added { flight_id: 2, .. }), "{o:?}");
    drop(book);
    let c = rusqlite::Connection::open(&db).unwrap();
    let v: i64 = c
        .query_row("PRAGMA user_version", [], |r| r.get(0))
        .unwrap();
    assert_eq!(v, SCHEMA_VERSION);
    assert_eq!(v, 4);
}

/// A file written by a newer aloft (marked as aloft's, at a version above this code's) is
/// refused, not rewritten.
#[test]
fn a_newer_logbook_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("new.sqlite");
    rusqlite::Connection::open(&db)
        .unwrap()
        .execute_batch("PRAGMA user_version = 99; PRAGMA application_id = 1634494068")
        .unwrap();
    let e = Logbook::open(&db).unwrap_err().to_string();
    assert!(
        e.contains("schema version 99") && e.contains("new.sqlite"),
        "{e}"
    );
}
