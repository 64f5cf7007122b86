//! Damaged telemetry logs: flipped bytes, garbage inserted, files cut short, arbitrary bytes.
//! The reader never panics, never invents a frame, and loses only the frames that were damaged.

mod common;

use std::collections::{BTreeMap, BTreeSet};

use aloft_link::{Event, LinkError, TlogFrame, TlogSource};
use common::{frames, tlog_bytes};
use proptest::prelude::*;

/// A small deterministic generator (xorshift64*), so a failure is reproduced by its seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Frames by their offset in the input.
fn by_offset(frames: &[TlogFrame]) -> BTreeMap<u64, &TlogFrame> {
    frames.iter().map(|f| (f.offset, f)).collect()
}

/// Flips one byte in each of `n` frames (anywhere: timestamp, header, payload, CRC) of a log;
/// every other frame is read as before, at the same offset, and no frame appears that was not
/// there.
fn flips_lose_only_the_flipped_frames(stem: &str, n: usize, seed: u64) {
    let bytes = tlog_bytes(stem);
    let (clean, _) = frames(&bytes);
    let mut rng = Rng(seed);
    let mut damaged = bytes.clone();
    let mut hit = BTreeSet::new();
    while hit.len() < n {
        let f = &clean[rng.below(clean.len())];
        if hit.insert(f.offset) {
            let at = f.offset as usize + rng.below(f.len);
            damaged[at] ^= 1 << rng.below(8);
        }
    }
    let (read, stats) = frames(&damaged);
    let clean_at = by_offset(&clean);
    let read_at = by_offset(&read);
    for f in &read {
        assert!(
            clean_at.contains_key(&f.offset),
            "{stem}: a frame at {} that was not there",
            f.offset
        );
    }
    let mut lost = 0;
    for f in &clean {
        match read_at.get(&f.offset) {
            Some(r) if !hit.contains(&f.offset) => {
                // By their Debug text: HOME_POSITION's unset quaternion is NaN.
                assert_eq!(r.timestamp_us, f.timestamp_us, "{stem}");
                assert_eq!(
                    format!("{:?}", r.message),
                    format!("{:?}", f.message),
                    "{stem}"
                );
            }
            Some(_) => {}
            None => {
                assert!(
                    hit.contains(&f.offset),
                    "{stem}: undamaged frame at {} lost",
                    f.offset
                );
                lost += 1;
            }
        }
    }
    // Most flips hit the payload or CRC: the frame is lost and counted; a flip of a timestamp's
    // low bits keeps the frame (at another time).
    assert!(
        lost >= n / 2 && lost <= n,
        "{stem}: {lost} of {n} lost ({stats:?})"
    );
}

#[test]
fn data_val_flipped_bytes_lose_only_their_frames() {
    flips_lose_only_the_flipped_frames("phoenix_mission1_real", 500, 1);
    flips_lose_only_the_flipped_frames("eagle_c2_bench_v2", 200, 2);
    // Already 1.7 % garbage, MAVLink 1.
    flips_lose_only_the_flipped_frames("dronekit_flight_replay", 500, 3);
}

/// Garbage inserted between frames (random bytes, magic bytes, plausible timestamps followed by
/// a magic byte): every frame is still read.
#[test]
fn data_val_inserted_garbage_loses_nothing() {
    let bytes = tlog_bytes("kudrone_guided_sitl");
    let (clean, _) = frames(&bytes);
    let mut rng = Rng(7);
    let mut cuts: Vec<usize> = (0..300)
        .map(|_| clean[rng.below(clean.len())].offset as usize)
        .collect();
    cuts.sort_unstable();
    cuts.dedup();
    let mut damaged = Vec::with_capacity(bytes.len() + 300 * 40);
    let mut from = 0;
    let mut inserted = 0;
    for &c in &cuts {
        damaged.extend_from_slice(&bytes[from..c]);
        let garbage: Vec<u8> = match rng.below(3) {
            0 => (0..rng.below(40) + 1).map(|_| rng.next() as u8).collect(),
            1 => vec![0xFD, 0xFE, 0xFD, 0x09, 0x00],
            // A plausible timestamp (the next frame's) and a magic byte with a bogus header.
            _ => {
                let mut g = bytes[c..c + 8].to_vec();
                g.extend([0xFE, 0x21, 0x00, 0x01, 0x01, 0x21]);
                g
            }
        };
        inserted += garbage.len();
        damaged.extend(garbage);
        from = c;
    }
    damaged.extend_from_slice(&bytes[from..]);
    let (read, stats) = frames(&damaged);
    assert_eq!(read.len(), clean.len());
    for (r, c) in read.iter().zip(&clean) {
        assert_eq!(r.timestamp_us, c.timestamp_us);
        assert_eq!(format!("{:?}", r.message), format!("{:?}", c.message));
    }
    // The log's own 30 bytes of garbage, and what was inserted.
    assert_eq!(stats.bytes_skipped, 30 + inserted as u64);
}

/// A log cut anywhere: the frames that end before the cut are read, the one cut short is counted.
#[test]
fn data_val_cut_files_lose_only_the_cut_frame() {
    let bytes = tlog_bytes("phoenix_mission1_real");
    let (clean, _) = frames(&bytes);
    let mut rng = Rng(11);
    for _ in 0..200 {
        let cut = rng.below(bytes.len());
        let (read, stats) = frames(&bytes[..cut]);
        let complete = clean
            .iter()
            .filter(|f| f.offset as usize + f.len <= cut)
            .count();
        assert_eq!(read.len(), complete, "cut at {cut}");
        let cut_inside = clean
            .iter()
            .any(|f| (f.offset as usize) < cut && f.offset as usize + f.len > cut);
        // A cut inside a timestamp leaves no frame start to count.
        assert!(
            stats.truncated <= u64::from(cut_inside),
            "cut at {cut}: {stats:?}"
        );
    }
}

/// Events of arbitrary bytes: times finite and never going back, sample values finite; bytes
/// without a single frame end as [`LinkError::NothingReadable`], and only they.
fn events_are_sane(bytes: &[u8]) {
    let mut s = TlogSource::new(bytes, "fuzz");
    let mut last = 0.0;
    loop {
        let t = match s.next_telemetry() {
            Ok(Some(t)) => t,
            Ok(None) => break,
            Err(LinkError::NothingReadable { bytes: n, .. }) => {
                assert_eq!((s.stats().frames, n), (0, bytes.len() as u64));
                break;
            }
            Err(e) => panic!("{e}"),
        };
        assert!(t.time_s.is_finite() && t.time_s >= last);
        last = t.time_s;
        if let Event::Sample(x) = &t.event {
            let vectors = [x.pos_enu_m, x.vel_enu_mps, x.wind_enu_mps];
            assert!(vectors.iter().flatten().flatten().all(|v| v.is_finite()));
        }
    }
    let st = s.stats();
    assert_eq!(st.bytes, bytes.len() as u64);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any bytes: no panic, every byte in a frame or skipped.
    #[test]
    fn any_bytes_are_framed_or_skipped(bytes in proptest::collection::vec(any::<u8>(), 0..4096)) {
        let (read, stats) = frames(&bytes);
        let framed: usize = read.iter().map(|f| f.len).sum();
        prop_assert_eq!(framed as u64 + stats.bytes_skipped, bytes.len() as u64);
        events_are_sane(&bytes);
    }

    /// The head of a real log with bytes overwritten: no panic, sane events.
    #[test]
    fn a_real_head_with_bytes_overwritten_is_read(
        edits in proptest::collection::vec((0usize..16_384, any::<u8>()), 1..64),
    ) {
        let head = &tlog_bytes("dronekit_flight_replay")[..16_384];
        let mut bytes = head.to_vec();
        for (at, b) in edits {
            bytes[at] = b;
        }
        let (read, stats) = frames(&bytes);
        let framed: usize = read.iter().map(|f| f.len).sum();
        prop_assert_eq!(framed as u64 + stats.bytes_skipped, bytes.len() as u64);
        events_are_sane(&bytes);
    }
}
