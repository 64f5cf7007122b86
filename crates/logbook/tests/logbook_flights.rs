//! The logbook counts flights, not files: a second log of one flight (the same vehicle over the
//! same time, e.g. a truncated copy, whose content and hash differ) is a copy of the first,
//! counted once; a pack the log does not name is keyed by its vehicle, cells and rated
//! capacity, not one `unknown` for all; `relabel` renames a pack or a vehicle.

#[path = "../../../tests/it/common/data.rs"]
mod data;

use std::path::{Path, PathBuf};

use aloft_logbook::{AddOutcome, KeyKind, Labels, Logbook, LogbookError, ReadOptions};

fn add(book: &mut Logbook, f: &Path, labels: &Labels) -> AddOutcome {
    book.add(f, labels, &ReadOptions::default()).unwrap()
}

/// The first `fraction` of a file's bytes, as a file in `dir`.
fn truncated(dir: &Path, f: &Path, fraction: f64) -> PathBuf {
    let bytes = std::fs::read(f).unwrap();
    let n = (bytes.len() as f64 * fraction) as usize;
    let out = dir.join(format!("cut-{}", f.file_name().unwrap().to_string_lossy()));
    std::fs::write(&out, &bytes[..n]).unwrap();
    out
}

/// A ULog's `sys_uuid` info message, read from its bytes (the key `char[N] sys_uuid` and the N
/// bytes after it), not by aloft's decoder.
fn ulog_sys_uuid(bytes: &[u8]) -> String {
    let key = b" sys_uuid";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap();
    let head = &bytes[at - 12..at];
    let open = head.iter().rposition(|&b| b == b'[').unwrap();
    let close = head.iter().rposition(|&b| b == b']').unwrap();
    let n: usize = std::str::from_utf8(&head[open + 1..close])
        .unwrap()
        .parse()
        .unwrap();
    String::from_utf8_lossy(&bytes[at + key.len()..at + key.len() + n])
        .trim_end_matches('\0')
        .to_string()
}

/// A ULog parameter's value from its bytes: the key `<type> NAME` and the 4 bytes after it.
fn ulog_param(bytes: &[u8], key: &str) -> Option<f64> {
    let at = bytes.windows(key.len()).position(|w| w == key.as_bytes())?;
    let v: [u8; 4] = bytes[at + key.len()..at + key.len() + 4].try_into().ok()?;
    Some(if key.starts_with("float") {
        f64::from(f32::from_le_bytes(v))
    } else {
        f64::from(i32::from_le_bytes(v))
    })
}

fn flugdrohne(name: &str) -> PathBuf {
    data::data_dir().join("px4_flugdrohne/ulg").join(name)
}

/// A PX4 ULog with a GPS clock, then the first 70 % of it (a log cut short: other bytes, other
/// hash, the same start), then another flight of the same quad: the cut log is a copy of the
/// first flight, listed as such and counted once; the other flight is a flight.
#[test]
fn data_val_a_truncated_copy_of_a_log_is_the_same_flight() {
    let tmp = tempfile::tempdir().unwrap();
    let mut book = Logbook::open(&tmp.path().join("book.sqlite")).unwrap();
    let full = flugdrohne("log_20_2023-6-7-10-52-56.ulg");
    let cut = truncated(tmp.path(), &full, 0.7);
    let none = Labels::default();
    let AddOutcome::Added { flight_id, .. } = add(&mut book, &full, &none) else {
        panic!("not added");
    };
    let o = add(&mut book, &cut, &none);
    assert!(
        matches!(o, AddOutcome::Copy { copy_of, .. } if copy_of == flight_id),
        "{o:?}"
    );
    let other = add(
        &mut book,
        &flugdrohne("log_30_2023-6-7-12-11-06.ulg"),
        &none,
    );
    assert!(matches!(other, AddOutcome::Added { .. }), "{other:?}");

    let flights = book.flights().unwrap();
    assert_eq!(flights.len(), 3);
    let by_name = |n: &str| flights.iter().find(|f| f.file_name == n).unwrap();
    let (f_full, f_cut, f_other) = (
        by_name("log_20_2023-6-7-10-52-56.ulg"),
        by_name("cut-log_20_2023-6-7-10-52-56.ulg"),
        by_name("log_30_2023-6-7-12-11-06.ulg"),
    );
    assert_eq!(f_cut.copy_of, Some(f_full.id));
    assert_eq!((f_full.copy_of, f_other.copy_of), (None, None));
    assert!(f_cut.duration_s < f_full.duration_s);
    let v = book.vehicles().unwrap();
    assert_eq!(v.len(), 1);
    assert_eq!((v[0].flights, v[0].copies), (2, 1));
    let hours = (f_full.duration_s + f_other.duration_s) / 3600.0;
    assert!((v[0].hours - hours).abs() < 1e-12, "{} h", v[0].hours);
    let wh = f_full.energy_wh + f_other.energy_wh;
    assert!((v[0].energy_wh - wh).abs() < 1e-9);
    let packs = book.packs().unwrap();
    assert_eq!(packs.iter().map(|p| p.flights).sum::<usize>(), 2);
    assert_eq!(packs.iter().map(|p| p.copies).sum::<usize>(), 1);
    // The copy's own figures are kept (listed), not summed; its pack file leaves it out.
    let pack = &f_full.pack_key;
    assert!(book
        .flights_of_pack(pack)
        .unwrap()
        .iter()
        .all(|f| f.copy_of.is_none()));
}

/// An ArduPilot SITL log of a vehicle without an identity (`unknown`) and its truncated copy:
/// the same start, so the same flight.
#[test]
fn data_val_a_truncated_copy_of_an_unidentified_log_is_the_same_flight() {
    let tmp = tempfile::tempdir().unwrap();
    let mut book = Logbook::open(&tmp.path().join("book.sqlite")).unwrap();
    let full = data::data_dir().join("flight_logs/sitl_ac47_00000002.BIN");
    let cut = truncated(tmp.path(), &full, 0.8);
    let none = Labels::default();
    let AddOutcome::Added {
        flight_id,
        vehicle_key,
        ..
    } = add(&mut book, &full, &none)
    else {
        panic!()
    };
    assert_eq!(vehicle_key, aloft_logbook::UNKNOWN);
    let o = add(&mut book, &cut, &none);
    assert!(
        matches!(o, AddOutcome::Copy { copy_of, .. } if copy_of == flight_id),
        "{o:?}"
    );
}

/// Packs the logs do not name: the flugdrohne quad's 3S pack (3S by the data's README; this
/// log states neither cells nor rating, and only 3 cells fit its voltage), the KAIST pack under
/// the label of its vehicle (12S by the README, but 11 to 13 cells fit its voltage: no count),
/// and a PX4 log whose cells and rating (`BAT_N_CELLS`, `BAT_CAPACITY`) are read here from its
/// bytes. Each its own pack, keyed `unknown [<cells>S] [<capacity> mAh] on <vehicle>`; none is
/// plain `unknown`.
#[test]
fn data_val_packs_without_a_name_are_keyed_by_vehicle_cells_and_capacity() {
    let tmp = tempfile::tempdir().unwrap();
    let mut book = Logbook::open(&tmp.path().join("book.sqlite")).unwrap();
    let d = data::data_dir();
    let flug = flugdrohne("log_20_2023-6-7-10-52-56.ulg");
    let kaist = d.join("kaist_energy_drone/2018-08-03.10_31_21random5-1.csv");
    let esc = d.join("flight_logs/px4_esc_status_log.ulg");
    let none = Labels::default();
    add(&mut book, &flug, &none);
    let kaist_labels = Labels {
        vehicle: Some("kaist-m600".into()),
        pack: None,
    };
    add(&mut book, &kaist, &kaist_labels);
    add(&mut book, &esc, &none);

    let flug_uuid = ulog_sys_uuid(&std::fs::read(&flug).unwrap());
    let esc_bytes = std::fs::read(&esc).unwrap();
    let esc_uuid = ulog_sys_uuid(&esc_bytes);
    // PX4 of 2019: BAT_N_CELLS and BAT_CAPACITY (BAT1_ since).
    let cells = ulog_param(&esc_bytes, "int32_t BAT_N_CELLS")
        .or_else(|| ulog_param(&esc_bytes, "int32_t BAT1_N_CELLS"))
        .unwrap();
    let rating = ulog_param(&esc_bytes, "float BAT_CAPACITY")
        .or_else(|| ulog_param(&esc_bytes, "float BAT1_CAPACITY"))
        .filter(|c| *c >= 10.0)
        .map_or(String::new(), |c| format!(" {c:.0} mAh"));
    let mut expected = vec![
        format!("unknown 3S on {flug_uuid}"),
        "unknown on kaist-m600".to_string(),
        format!("unknown {cells}S{rating} on {esc_uuid}"),
    ];
    expected.sort();
    let packs = book.packs().unwrap();
    let keys: Vec<&str> = packs.iter().map(|p| p.key.as_str()).collect();
    assert_eq!(keys, expected);
    for p in &packs {
        assert_eq!((p.key_source.as_str(), p.flights), ("derived", 1), "{p:?}");
    }
    let esc_pack = packs.iter().find(|p| p.key.contains(&esc_uuid)).unwrap();
    assert_eq!(esc_pack.cells_series, Some(cells as u32));
}

/// `relabel`: a pack and a vehicle renamed, their flights with them (and the packs keyed by
/// the vehicle's name follow it); an unknown name, a name taken, and a name that is not a label
/// are refused, naming them, with nothing changed.
#[test]
fn data_val_relabel_renames_a_pack_or_a_vehicle() {
    let tmp = tempfile::tempdir().unwrap();
    let mut book = Logbook::open(&tmp.path().join("book.sqlite")).unwrap();
    let none = Labels::default();
    for n in [
        "log_20_2023-6-7-10-52-56.ulg",
        "log_30_2023-6-7-12-11-06.ulg",
    ] {
        add(&mut book, &flugdrohne(n), &none);
    }
    let labelled = Labels {
        vehicle: None,
        pack: Some("spare".into()),
    };
    add(
        &mut book,
        &flugdrohne("log_65_2023-6-21-08-36-08.ulg"),
        &labelled,
    );
    let uuid = ulog_sys_uuid(&std::fs::read(flugdrohne("log_20_2023-6-7-10-52-56.ulg")).unwrap());
    let derived = format!("unknown 3S on {uuid}");
    let keys =
        |b: &Logbook| -> Vec<String> { b.packs().unwrap().into_iter().map(|p| p.key).collect() };
    assert_eq!(keys(&book), vec!["spare".to_string(), derived.clone()]);

    // Refused: each names what is wrong, nothing changes.
    let e = book.relabel(KeyKind::Pack, "nope", "x").unwrap_err();
    assert!(
        matches!(e, LogbookError::NoSuchKey { .. }) && e.to_string().contains("\"nope\""),
        "{e}"
    );
    let e = book.relabel(KeyKind::Pack, &derived, "spare").unwrap_err();
    assert!(
        matches!(e, LogbookError::KeyTaken { .. }) && e.to_string().contains("\"spare\""),
        "{e}"
    );
    for bad in ["", "unknown", "unknown 3S on x"] {
        let e = book.relabel(KeyKind::Pack, &derived, bad).unwrap_err();
        assert!(matches!(e, LogbookError::BadLabel { .. }), "{bad:?}: {e}");
    }
    let e = book.relabel(KeyKind::Vehicle, "nope", "x").unwrap_err();
    assert!(matches!(e, LogbookError::NoSuchKey { .. }), "{e}");
    assert_eq!(keys(&book), vec!["spare".to_string(), derived.clone()]);

    // The pack.
    assert_eq!(
        book.relabel(KeyKind::Pack, &derived, "flug-3s-a").unwrap(),
        2
    );
    let packs = book.packs().unwrap();
    let a = packs.iter().find(|p| p.key == "flug-3s-a").unwrap();
    assert_eq!((a.flights, a.key_source.as_str()), (2, "label"));
    assert!(packs.iter().all(|p| p.key != derived));

    // The vehicle, and a pack keyed by its name.
    let mut book2 = Logbook::open(&tmp.path().join("two.sqlite")).unwrap();
    add(
        &mut book2,
        &flugdrohne("log_20_2023-6-7-10-52-56.ulg"),
        &none,
    );
    assert_eq!(
        book2
            .relabel(KeyKind::Vehicle, &uuid, "flugdrohne")
            .unwrap(),
        1
    );
    let v = book2.vehicles().unwrap();
    assert_eq!(
        (v[0].key.as_str(), v[0].key_source.as_str()),
        ("flugdrohne", "label")
    );
    assert_eq!(keys(&book2), vec!["unknown 3S on flugdrohne".to_string()]);
    let f = &book2.flights().unwrap()[0];
    assert_eq!(
        (f.vehicle_key.as_str(), f.pack_key.as_str()),
        ("flugdrohne", "unknown 3S on flugdrohne")
    );
}
