//! ULog and DataFlash decoders against hostile bytes: truncation at every few bytes, byte flips,
//! length fields at their extremes. Nothing may panic, allocate beyond the input, or lose the
//! valid prefix; every problem is a warning with its byte offset.

use aloft_logs::synth::{self, dataflash_fmt as fmt, ulog_record};
use aloft_logs::{read_dataflash, read_ulog, BinaryLog, BinaryOptions};

/// A small ULog: 50 local positions at 10 Hz and 50 battery records of 16 V, 10 A (160 W).
fn ulog_bytes() -> Vec<u8> {
    synth::ulog_small()
}

/// A small DataFlash log: 50 ATT (degrees) and 50 BAT (12 V, 5 A) at 10 Hz.
fn dataflash_bytes() -> Vec<u8> {
    synth::dataflash_small()
}

fn ulog(b: &[u8]) -> Option<BinaryLog> {
    read_ulog(b, &BinaryOptions::default()).ok()
}

fn dataflash(b: &[u8]) -> Option<BinaryLog> {
    read_dataflash(b, &BinaryOptions::default()).ok()
}

#[test]
fn the_generated_logs_read_whole() {
    let u = ulog(&ulog_bytes()).unwrap();
    assert_eq!(u.log.samples.len(), 50);
    assert_eq!(u.summary.battery.valid, 50);
    assert_eq!(u.summary.battery_cells, Some(4));
    // 160 W over 4.9 s; 1e-9 covers rounding.
    assert!((u.summary.energy_wh().unwrap() - 160.0 * 4.9 / 3600.0).abs() < 1e-9);
    assert!(u.summary.warnings.is_empty(), "{:?}", u.summary.warnings);
    let s = &u.log.samples[3];
    // NED (1, 2, -3) is ENU (2, 1, 3).
    assert_eq!(s.pos_enu_m, Some([2.0, 1.0, 3.0]));
    assert_eq!(s.voltage_v, Some(16.0));
    let d = dataflash(&dataflash_bytes()).unwrap();
    assert_eq!(d.log.samples.len(), 50);
    assert!((d.summary.energy_wh().unwrap() - 60.0 * 4.9 / 3600.0).abs() < 1e-9);
    let a = d.log.samples[0].attitude.unwrap();
    assert!((a.yaw_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
}

#[test]
fn truncation_anywhere_keeps_the_prefix_and_warns_with_the_offset() {
    for (bytes, read, header) in [
        (ulog_bytes(), ulog as fn(&[u8]) -> Option<BinaryLog>, 16),
        (dataflash_bytes(), dataflash, 3),
    ] {
        let full = read(&bytes).unwrap().summary.battery.valid;
        let mut last = 0;
        for cut in (0..bytes.len()).step_by(3) {
            let Some(r) = read(&bytes[..cut]) else {
                assert!(cut < header, "refused at {cut}");
                continue;
            };
            let n = r.summary.battery.valid;
            assert!(
                n >= last && n <= full,
                "cut {cut}: {n} records after {last}"
            );
            last = n;
            if r.summary.warnings.iter().any(|w| w.contains("truncated")) {
                assert!(r.summary.warnings.iter().any(|w| w.contains("at byte")));
            }
        }
        assert!(last + 1 >= full);
    }
}

#[test]
fn byte_flips_never_panic_and_resynchronise() {
    for (bytes, read) in [
        (ulog_bytes(), ulog as fn(&[u8]) -> Option<BinaryLog>),
        (dataflash_bytes(), dataflash),
    ] {
        let full = read(&bytes).unwrap().summary.battery.valid;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..2000 {
            // xorshift: reproducible positions and values.
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let mut b = bytes.clone();
            let at = (state % b.len() as u64) as usize;
            b[at] ^= (state >> 32) as u8 | 1;
            if let Some(r) = read(&b) {
                // One flipped byte loses at most a few records.
                assert!(
                    r.summary.battery.valid + 5 >= full || at < 400,
                    "flip at {at}: {} of {full}: {:?}",
                    r.summary.battery.valid,
                    r.summary.warnings
                );
            }
        }
        // A run of garbage in the middle: skipped, counted, and the records after it read.
        let mut b = bytes.clone();
        let mid = b.len() / 2;
        b.splice(mid..mid, std::iter::repeat_n(0x5Au8, 1000));
        let r = read(&b).unwrap();
        assert!(r.summary.bytes_skipped >= 1000, "{:?}", r.summary.warnings);
        assert!(r.summary.battery.valid + 2 >= full);
        assert!(r.summary.warnings.iter().any(|w| w.contains("byte")));
    }
}

#[test]
fn length_fields_at_their_extremes_allocate_only_what_the_input_holds() {
    // ULog: a record claiming 65535 bytes with 10 following; a data record of size 0; an
    // add-logged and a parameter record of size 0 (which panic the px4-ulog crate).
    let base = ulog_bytes();
    for tail in [
        vec![0xFF, 0xFF, b'D', 1, 2, 3, 4, 5, 6, 7, 8, 9, 10],
        vec![0, 0, b'D'],
        vec![0, 0, b'A'],
        vec![0, 0, b'P'],
        vec![255, 0, b'P', 255],
        vec![4, 0, b'F', b':', b';', b' ', b'['],
        vec![
            20, 0, b'F', b'x', b':', b'x', b' ', b'a', b';', b'y', b'[', b'9', b'9', b'9', b'9',
            b'9', b'9', b']', b' ', b'b', b';', 0, 0,
        ],
    ] {
        let mut b = base.clone();
        b.extend(&tail);
        let r = ulog(&b).unwrap();
        assert_eq!(r.summary.battery.valid, 50);
    }
    // Nested formats that refer to each other, and huge arrays: sizes refused, no recursion.
    let mut b = base[..16 + 43].to_vec();
    b.extend(ulog_record(b'F', b"a:b x;"));
    b.extend(ulog_record(b'F', b"b:a y;"));
    b.extend(ulog_record(
        b'F',
        b"c:uint64_t timestamp;double[65535] big;",
    ));
    b.extend(ulog_record(b'A', b"\x00\x05\x00a"));
    b.extend(ulog_record(b'A', b"\x00\x06\x00c"));
    let r = ulog(&b).unwrap();
    assert!(r
        .summary
        .warnings
        .iter()
        .any(|w| w.contains("no valid format")));
    // DataFlash: an FMT declaring length 0 or 255 with formats that do not fit, a record type
    // redefined as 255 bytes at the end of the input.
    let mut b = dataflash_bytes();
    b.extend(fmt(3, 0, "BAD", "Q", "TimeUS"));
    b.extend(fmt(4, 5, "BAD2", "ZZZZ", "a,b,c,d"));
    b.extend(fmt(1, 255, "ATT", "Qfff", "TimeUS,Roll,Pitch,Yaw"));
    b.extend([0xA3, 0x95, 1, 0, 0]);
    let r = dataflash(&b).unwrap();
    assert_eq!(r.summary.battery.valid, 50);
    assert!(r.summary.warnings.iter().any(|w| w.contains("truncated")));
}

#[test]
fn a_battery_declared_and_never_written_is_no_battery_data() {
    let b = ulog_bytes();
    // Keep the definitions and the local positions only (drop battery data records).
    let r = ulog(&b).unwrap();
    assert!(r.summary.power_available());
    let mut d = dataflash_bytes();
    d.truncate(3 * 89);
    for i in 0..50u64 {
        d.extend([0xA3, 0x95, 1]);
        d.extend((1_000_000 + i * 100_000).to_le_bytes());
        d.extend([0u8; 12]);
    }
    let r = dataflash(&d).unwrap();
    assert!(!r.summary.power_available());
    let why = r.summary.no_power_reason().unwrap();
    assert!(why.contains("declared but never written"), "{why}");
    assert!(r
        .summary
        .warnings
        .iter()
        .any(|w| w.contains("no battery data")));
}
