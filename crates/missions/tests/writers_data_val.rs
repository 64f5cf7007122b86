//! The shared mission files (`ALOFT_DATA_DIR/missions`: `.plan`, `.waypoints`, `.txt`; never
//! copied into the repository), each read, written back in its own format by
//! `write_like_source`, and read again.
//!
//! - What the readers keep: the items in file order (their count is the reader's item count),
//!   the flying order with the segments each item made: ranges that follow each other from
//!   segment 0 to the last, each segment carrying its item's number.
//! - The round trip: the same mission spec, route figures (warnings included), item counts,
//!   home, items, header, surveys and flying order. Compared to the last bit: both writers
//!   write each number as the shortest decimal that reads back as the same `f64`, and both
//!   readers parse correctly rounded (serde_json's `float_roundtrip`, Rust's `f64::from_str`),
//!   so no tolerance is needed; the `Debug` text of spec and route is compared as well, which
//!   tells -0 from 0.

use std::path::PathBuf;

use aloft_missions::{import, write_like_source, Imported, ItemOrigin, MissionItem, SourceFormat};

#[path = "../../../tests/it/common/data.rs"]
mod data;

/// The files aloft refuses, by design (see the data's README): a VTOL mission and a malformed
/// VTOL plan.
const REFUSED: [&str; 2] = ["uas_lol_mission8.waypoints", "wolkstein_vtol_mission.plan"];

/// Every mission file of the shared data, sorted.
fn mission_files() -> Vec<PathBuf> {
    data::files("missions", |n| {
        [".plan", ".waypoints", ".txt"]
            .iter()
            .any(|e| n.ends_with(e))
    })
}

fn name(p: &std::path::Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}

/// The files aloft reads, with what it read; the refused ones are exactly [`REFUSED`].
fn read_all() -> Vec<(String, Imported)> {
    let mut read = Vec::new();
    let mut refused = Vec::new();
    for path in mission_files() {
        let text = std::fs::read_to_string(&path).unwrap();
        match import(&text) {
            Ok(i) => read.push((name(&path), i)),
            Err(_) => refused.push(name(&path)),
        }
    }
    assert_eq!(refused, REFUSED);
    assert_eq!(
        read.len(),
        10,
        "the shared data's missions/README lists 12 files"
    );
    read
}

/// Each item's fields, the parameters as bits (NaN equal to itself).
fn bits(items: &[MissionItem]) -> Vec<(u32, u32, u32, [u64; 7])> {
    items
        .iter()
        .map(|i| (i.seq, i.frame, i.command, i.params.map(f64::to_bits)))
        .collect()
}

/// The invariant of `Imported::flown` (see `aloft_missions::kept`).
fn check_flown(file: &str, i: &Imported) {
    let mut next = 0;
    for f in &i.flown {
        assert_eq!(f.segments.start, next, "{file}: ranges follow each other");
        let seq = i.items[f.item].seq;
        for s in &i.spec.segments[f.segments.clone()] {
            assert_eq!(s.item(), Some(seq), "{file}: segment of item {seq}");
        }
        next = f.segments.end;
    }
    assert_eq!(next, i.spec.segments.len(), "{file}: every segment covered");
    // No shared file jumps: the flying order is the file order up to where the route ends.
    let order: Vec<usize> = i.flown.iter().map(|f| f.item).collect();
    assert_eq!(order, (0..order.len()).collect::<Vec<_>>(), "{file}");
    let reached = i.counted.total - i.counted.unreachable;
    assert_eq!(
        order.len(),
        reached,
        "{file}: every item reached is flown once"
    );
}

/// What the readers keep of the file, against the file's own numbers.
fn check_kept(file: &str, i: &Imported) {
    assert_eq!(i.items.len(), i.counted.total, "{file}");
    match i.format {
        SourceFormat::QgcPlan => {
            // Numbered from 1 in file order (surveys flattened).
            let seqs: Vec<u32> = i.items.iter().map(|x| x.seq).collect();
            assert_eq!(seqs, (1..=i.items.len() as u32).collect::<Vec<_>>());
            let plan = i.plan.as_ref().unwrap();
            assert_eq!(plan.origins.len(), i.items.len());
            for (k, s) in i.surveys.iter().enumerate() {
                let from_it = plan
                    .origins
                    .iter()
                    .filter(|o| matches!(o, ItemOrigin::Survey { survey, .. } if *survey == k))
                    .count();
                assert_eq!(from_it, s.item_count, "{file}: survey {k}");
            }
            assert!(i.home.is_some());
        }
        _ => assert!(i.plan.is_none() && i.surveys.is_empty()),
    }
}

#[test]
fn data_val_the_readers_keep_items_and_the_segments_each_item_flew() {
    let files = read_all();
    let mut segments = 0;
    for (file, i) in &files {
        check_kept(file, i);
        check_flown(file, i);
        segments += i.spec.segments.len();
    }
    println!(
        "{} files: every one of {segments} segments in its item's range",
        files.len()
    );
}

#[test]
fn data_val_every_shared_mission_written_back_reads_as_the_file() {
    let files = read_all();
    let mut items = 0;
    for (file, i) in &files {
        let written = write_like_source(i).unwrap_or_else(|e| panic!("{file}: {e}"));
        let back = import(&written).unwrap_or_else(|e| panic!("{file}: {e}\n{written}"));
        assert_eq!(back.format, i.format, "{file}");
        assert_eq!(back.spec, i.spec, "{file}");
        assert_eq!(
            format!("{:?}", back.spec),
            format!("{:?}", i.spec),
            "{file}"
        );
        assert_eq!(back.route, i.route, "{file}");
        assert_eq!(
            format!("{:?}", back.route),
            format!("{:?}", i.route),
            "{file}"
        );
        assert_eq!(back.warnings, i.warnings, "{file}");
        assert_eq!(back.counted, i.counted, "{file}");
        assert_eq!(back.home, i.home, "{file}");
        assert_eq!(bits(&back.items), bits(&i.items), "{file}");
        assert_eq!(back.plan, i.plan, "{file}");
        assert_eq!(back.flown, i.flown, "{file}");
        assert_eq!(back.surveys.len(), i.surveys.len(), "{file}");
        for (b, s) in back.surveys.iter().zip(&i.surveys) {
            assert_eq!(
                b.complex_item, s.complex_item,
                "{file}: the survey verbatim"
            );
            assert_eq!(b.survey, s.survey, "{file}");
        }
        // Written again, the text is the same: the writer is a fixed point.
        assert_eq!(write_like_source(&back).unwrap(), written, "{file}");
        items += i.items.len();
    }
    println!(
        "{} files, {items} items written back and read as written",
        files.len()
    );
}
