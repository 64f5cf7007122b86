//! Corrupt lengths in MCAP files: every length field the reader meets (record lengths, string,
//! byte-array and map lengths in Schema and Channel records, chunk sizes, record lengths inside
//! chunks) set past what the file holds is an error, never a panic, and the read never allocates
//! more than a small multiple of the file.
//!
//! Allocation is measured by a counting global allocator, per thread (the test harness runs
//! tests on several threads): the peak of the bytes live on the reading thread above what was
//! live before the read, and the largest single request. (zstd's C context is allocated by
//! libzstd, not through Rust's allocator; the end-to-end tests in the root `tests/` run the
//! binary under `ulimit -v`, which covers it.)

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;

use aloft_logs::cdr::CdrWriter;
use aloft_logs::{LogError, McapOptions, McapSamples, Sample};

struct Counting;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn count(delta: isize, request: usize) {
    let _ = LIVE.try_with(|live| {
        let v = live.get() + delta;
        live.set(v);
        let _ = PEAK.try_with(|p| p.set(p.get().max(v)));
    });
    let _ = LARGEST.try_with(|l| l.set(l.get().max(request)));
}

// SAFETY: every call is forwarded to `System` unchanged; the counting only reads sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            count(layout.size() as isize, layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            count(layout.size() as isize, layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        count(-(layout.size() as isize), 0);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            count(new_size as isize - layout.size() as isize, new_size);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// What reading `bytes` gave, and the most it allocated.
struct Read {
    result: Result<Vec<Sample>, LogError>,
    peak_bytes: usize,
    largest_bytes: usize,
}

fn read(bytes: &[u8]) -> Read {
    let before = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(before));
    LARGEST.with(|l| l.set(0));
    let result = McapSamples::from_reader(
        Cursor::new(bytes),
        Path::new("corrupt.mcap"),
        McapOptions::default(),
    )
    .with_input_len(bytes.len() as u64)
    .collect::<Result<Vec<_>, _>>();
    Read {
        result,
        peak_bytes: (PEAK.with(Cell::get) - before).max(0) as usize,
        largest_bytes: LARGEST.with(Cell::get),
    }
}

/// The most a read of a file of `len` bytes may allocate: the piece of input handed to the reader
/// (256 KiB), a chunk's minimum record limit (64 KiB), and a few copies of the file (its bytes in
/// the reader, a chunk's copy, the decompressed records, the samples).
fn bound(len: usize) -> usize {
    (256 << 10) + (64 << 10) + 8 * len + (64 << 10)
}

/// Read `bytes` and check that it allocated within [`bound`]; `what` names the case.
fn read_bounded(bytes: &[u8], what: &str) -> Result<Vec<Sample>, LogError> {
    let r = read(bytes);
    let limit = bound(bytes.len());
    assert!(
        r.peak_bytes <= limit && r.largest_bytes <= limit,
        "{what}: peak {} bytes, largest request {} bytes, for a file of {} bytes (bound {limit})",
        r.peak_bytes,
        r.largest_bytes,
        bytes.len()
    );
    r.result
}

/// Read `bytes`, which must be an error naming the file, within the allocation bound.
fn expect_error(bytes: &[u8], what: &str) -> LogError {
    match read_bounded(bytes, what) {
        Ok(s) => panic!("{what}: read {} samples from a corrupt file", s.len()),
        Err(e) => {
            assert!(e.to_string().contains("corrupt.mcap"), "{what}: {e}");
            e
        }
    }
}

/// [`expect_error`], and that error is a corrupt MCAP whose problem names `field`.
fn expect_corrupt_field(bytes: &[u8], what: &str, field: &str) {
    match expect_error(bytes, what) {
        LogError::McapCorrupt { problem, .. } => {
            assert!(problem.to_string().contains(field), "{what}: {problem}")
        }
        e => panic!("{what}: {e}"),
    }
}

// ---- Building MCAP files ----

/// A ROS 2 log: PoseStamped at 100 Hz and BatteryState at 10 Hz, schemas with text, a channel
/// with metadata.
fn ros2_mcap(chunked: bool) -> Vec<u8> {
    ros2_mcap_compressed(chunked, None)
}

/// [`ros2_mcap`] with chunks of about 4 KiB compressed as `compression`.
fn ros2_mcap_compressed(chunked: bool, compression: Option<mcap::Compression>) -> Vec<u8> {
    let options = mcap::WriteOptions::new()
        .use_chunks(chunked)
        .compression(compression)
        .chunk_size(Some(4096));
    let mut w = options.create(Cursor::new(Vec::new())).unwrap();
    let sp = w
        .add_schema(
            "geometry_msgs/msg/PoseStamped",
            "ros2msg",
            b"std_msgs/Header header\ngeometry_msgs/Pose pose",
        )
        .unwrap();
    let sb = w
        .add_schema(
            "sensor_msgs/msg/BatteryState",
            "ros2msg",
            b"float32 voltage",
        )
        .unwrap();
    let metadata = BTreeMap::from([(
        "offered_qos_profiles".to_string(),
        "- history: 3".to_string(),
    )]);
    let cp = w.add_channel(sp, "/pose", "cdr", &metadata).unwrap();
    let cb = w
        .add_channel(sb, "/battery", "cdr", &BTreeMap::new())
        .unwrap();
    for k in 0..60u32 {
        let ns = 1_700_000_000_000_000_000 + u64::from(k) * 10_000_000;
        let t = f64::from(k) * 0.01;
        let header = |c: u16| mcap::records::MessageHeader {
            channel_id: c,
            sequence: k,
            log_time: ns,
            publish_time: ns,
        };
        let mut m = CdrWriter::new();
        m.header(
            (ns / 1_000_000_000) as i32,
            (ns % 1_000_000_000) as u32,
            "map",
        )
        .f64(t.sin())
        .f64(t.cos())
        .f64(10.0)
        .f64(0.0)
        .f64(0.0)
        .f64(0.0)
        .f64(1.0);
        w.write_to_known_channel(&header(cp), &m.finish()).unwrap();
        if k % 10 == 0 {
            let mut b = CdrWriter::new();
            b.header((ns / 1_000_000_000) as i32, 0, "");
            for v in [16.0f32, 25.0, -20.0, 3.0, 5.0, 5.0, 0.6] {
                b.f32(v);
            }
            b.u8(2).u8(1).u8(3).u8(1).u32(4);
            for _ in 0..4 {
                b.f32(4.0);
            }
            b.u32(0).string("").string("");
            w.write_to_known_channel(&header(cb), &b.finish()).unwrap();
        }
    }
    w.finish().unwrap();
    w.into_inner().into_inner()
}

/// A record of the file: its opcode, and where it starts and its body lies.
#[derive(Debug, Clone, Copy)]
struct Rec {
    op: u8,
    at: usize,
    body: usize,
    len: usize,
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn put_u64(b: &mut [u8], at: usize, v: u64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}

fn put_u32(b: &mut [u8], at: usize, v: u32) {
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

/// The records in `b[start..end]`.
fn records_in(b: &[u8], start: usize, end: usize) -> Vec<Rec> {
    let mut v = Vec::new();
    let mut at = start;
    while at + 9 <= end {
        let len = u64_at(b, at + 1) as usize;
        v.push(Rec {
            op: b[at],
            at,
            body: at + 9,
            len,
        });
        if b[at] == mcap::records::op::FOOTER {
            break;
        }
        at += 9 + len;
    }
    v
}

/// The file's own records (after the magic).
fn file_records(b: &[u8]) -> Vec<Rec> {
    records_in(b, 8, b.len() - 8)
}

/// Where a chunk's fields are: (uncompressed size, compression length, compressed size,
/// records start).
fn chunk_fields(b: &[u8], chunk: &Rec) -> (usize, usize, usize, usize) {
    let uncompressed = chunk.body + 16;
    let compression_len = uncompressed + 8 + 4;
    let n = u32_at(b, compression_len) as usize;
    let compressed = compression_len + 4 + n;
    (uncompressed, compression_len, compressed, compressed + 8)
}

/// Every record, with the records inside uncompressed chunks.
fn all_records(b: &[u8]) -> Vec<Rec> {
    let mut v = Vec::new();
    for r in file_records(b) {
        v.push(r);
        if r.op == mcap::records::op::CHUNK {
            let (_, _, compressed, start) = chunk_fields(b, &r);
            v.extend(records_in(b, start, start + u64_at(b, compressed) as usize));
        }
    }
    v
}

/// A zstd frame holding `data` in raw (stored) blocks, so that a test can put any bytes,
/// corrupt ones included, in a compressed chunk.
fn zstd_raw(data: &[u8]) -> Vec<u8> {
    // Magic; frame header: no content size, not single-segment, window 2^17 (128 KiB).
    let mut f = vec![0x28, 0xb5, 0x2f, 0xfd, 0x00, 7 << 3];
    let blocks: Vec<&[u8]> = data.chunks(100_000).collect();
    let n = blocks.len().max(1);
    for i in 0..n {
        let block = blocks.get(i).copied().unwrap_or(&[]);
        let last = u32::from(i + 1 == n);
        // Block header: last flag, type 0 (raw), size.
        let h = last | ((block.len() as u32) << 3);
        f.extend_from_slice(&h.to_le_bytes()[..3]);
        f.extend_from_slice(block);
    }
    f
}

/// A chunk record's body with `records` compressed as `compression` (`""` or `"zstd"`), declaring
/// `uncompressed_size`.
fn chunk_body(records: &[u8], compression: &str, uncompressed_size: u64) -> Vec<u8> {
    let data = if compression == "zstd" {
        zstd_raw(records)
    } else {
        records.to_vec()
    };
    let mut v = Vec::new();
    v.extend(0u64.to_le_bytes());
    v.extend(0u64.to_le_bytes());
    v.extend(uncompressed_size.to_le_bytes());
    v.extend(0u32.to_le_bytes());
    v.extend((compression.len() as u32).to_le_bytes());
    v.extend(compression.as_bytes());
    v.extend((data.len() as u64).to_le_bytes());
    v.extend(data);
    v
}

/// `b` with every uncompressed chunk recompressed as zstd (raw blocks); `edit` may change each
/// chunk's records first (and returns the uncompressed size to declare, given the true one).
fn as_zstd(b: &[u8], edit: &dyn Fn(&mut Vec<u8>, u64) -> u64) -> Vec<u8> {
    let mut out = b[..8].to_vec();
    for r in file_records(b) {
        if r.op == mcap::records::op::CHUNK {
            let (_, _, compressed, start) = chunk_fields(b, &r);
            let mut records = b[start..start + u64_at(b, compressed) as usize].to_vec();
            let true_size = records.len() as u64;
            let size = edit(&mut records, true_size);
            let body = chunk_body(&records, "zstd", size);
            out.push(r.op);
            out.extend((body.len() as u64).to_le_bytes());
            out.extend(body);
        } else {
            out.extend_from_slice(&b[r.at..r.body + r.len]);
        }
    }
    out.extend_from_slice(mcap::MAGIC);
    out
}

fn unchanged(_: &mut Vec<u8>, size: u64) -> u64 {
    size
}

/// The layouts: records at the top level, in uncompressed chunks, in zstd chunks of stored
/// blocks, in zstd and lz4 chunks written by the `mcap` crate.
fn layouts() -> Vec<(&'static str, Vec<u8>)> {
    let chunked = ros2_mcap(true);
    vec![
        ("unchunked", ros2_mcap(false)),
        ("zstd chunks", as_zstd(&chunked, &unchanged)),
        ("uncompressed chunks", chunked),
        (
            "mcap zstd",
            ros2_mcap_compressed(true, Some(mcap::Compression::Zstd)),
        ),
        (
            "mcap lz4",
            ros2_mcap_compressed(true, Some(mcap::Compression::Lz4)),
        ),
    ]
}

/// Offsets of the length fields of a Schema or Channel body, with their names.
fn string_fields(b: &[u8], r: &Rec) -> Vec<(usize, &'static str)> {
    use mcap::records::op;
    let mut v = Vec::new();
    let mut at = r.body + if r.op == op::SCHEMA { 2 } else { 4 };
    let names: &[&str] = if r.op == op::SCHEMA {
        &["schema name", "schema encoding", "schema data"]
    } else {
        &["topic", "message encoding", "metadata"]
    };
    for name in names {
        v.push((at, *name));
        at += 4 + u32_at(b, at) as usize;
    }
    v
}

// ---- The tests ----

#[test]
fn valid_files_read_the_same_in_every_layout() {
    let reference = read_bounded(&ros2_mcap(false), "reference").unwrap();
    // 60 poses 10 ms apart, a battery message every 100 ms.
    assert_eq!(reference.len(), 66);
    assert!((reference.last().unwrap().time_s - 0.59).abs() < 1e-9);
    for (name, b) in layouts() {
        let s = read_bounded(&b, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(s, reference, "{name}");
    }
}

#[test]
fn record_lengths_past_the_end_of_the_file_are_errors() {
    for (name, b) in layouts().into_iter().take(3) {
        for r in file_records(&b) {
            let left = (b.len() - r.body) as u64;
            for claimed in [
                u64::MAX,
                1 << 40,
                u64::from(u32::MAX),
                b.len() as u64,
                (256 << 20) + 1,
                left + 1,
            ] {
                let mut c = b.clone();
                put_u64(&mut c, r.at + 1, claimed);
                let what = format!("{name}: record {:#04x} at {} claims {claimed}", r.op, r.at);
                let e = expect_error(&c, &what);
                assert!(
                    matches!(e, LogError::Mcap { .. } | LogError::McapCorrupt { .. }),
                    "{what}: {e}"
                );
            }
            // Each byte of the length flipped: an error or a read, within the bound.
            for k in 0..8 {
                let mut c = b.clone();
                c[r.at + 1 + k] ^= 0xff;
                let _ = read_bounded(&c, &format!("{name}: record at {} byte {k}", r.at));
            }
        }
    }
}

#[test]
fn string_lengths_beyond_their_record_are_errors_naming_the_field() {
    use mcap::records::op;
    for (name, b) in layouts().into_iter().take(3) {
        // In zstd chunks the records are found through the uncompressed layout.
        let (base, zstd) = if name == "zstd chunks" {
            (ros2_mcap(true), true)
        } else {
            (b.clone(), false)
        };
        let mut seen = 0;
        for r in all_records(&base) {
            if r.op != op::SCHEMA && r.op != op::CHANNEL {
                continue;
            }
            for (at, field) in string_fields(&base, &r) {
                let left = (r.body + r.len - at - 4) as u32;
                for claimed in [u32::MAX, 0xff00_0000 | u32_at(&base, at), left + 1] {
                    let mut c = base.clone();
                    put_u32(&mut c, at, claimed);
                    if zstd {
                        c = as_zstd(&c, &unchanged);
                    }
                    let what = format!("{name}: {field} at {at} claims {claimed}");
                    expect_corrupt_field(&c, &what, field);
                    seen += 1;
                }
            }
        }
        // Schemas and channels are written once at the top and once in the summary (and in
        // chunks when chunked): at least 2 schemas and 2 channels, 3 fields each, 3 values.
        assert!(seen >= 36, "{name}: {seen}");
    }
}

#[test]
fn map_entries_beyond_their_map_are_errors() {
    use mcap::records::op;
    let b = ros2_mcap(false);
    let channels: Vec<Rec> = file_records(&b)
        .into_iter()
        .filter(|r| r.op == op::CHANNEL)
        .collect();
    let mut seen = 0;
    for r in channels {
        let (map_at, _) = string_fields(&b, &r)[2];
        let map_len = u32_at(&b, map_at);
        if map_len == 0 {
            continue;
        }
        // The first key and value lengths, past the map (though within the record when the map
        // is shortened), and the map itself past the record.
        let key_at = map_at + 4;
        let value_at = key_at + 4 + u32_at(&b, key_at) as usize;
        for (at, claimed, field) in [
            (key_at, map_len, "metadata key"),
            (key_at, u32::MAX, "metadata key"),
            (value_at, map_len, "metadata value"),
            (map_at, u32::MAX, "metadata"),
            (map_at, map_len + 1, "metadata"),
        ] {
            let mut c = b.clone();
            put_u32(&mut c, at, claimed);
            let what = format!("channel at {}: {field} claims {claimed}", r.at);
            expect_corrupt_field(&c, &what, field);
            seen += 1;
        }
    }
    assert!(seen >= 5, "{seen}");
}

#[test]
fn chunk_sizes_beyond_the_chunk_are_errors() {
    let b = as_zstd(&ros2_mcap(true), &unchanged);
    let chunks: Vec<Rec> = file_records(&b)
        .into_iter()
        .filter(|r| r.op == mcap::records::op::CHUNK)
        .collect();
    assert!(chunks.len() > 1);
    for r in chunks {
        let (uncompressed, compression_len, compressed, _) = chunk_fields(&b, &r);
        let size = u64_at(&b, compressed);
        let true_size = u64_at(&b, uncompressed);
        let cases: Vec<(usize, u64, &str)> = vec![
            (compressed, u64::MAX, "compressed size"),
            (compressed, size + 1, "compressed size"),
            (compressed, 1 << 40, "compressed size"),
            (uncompressed, u64::MAX, "uncompressed size"),
            (uncompressed, 1 << 40, "uncompressed size"),
            (uncompressed, (256 << 20) + 1, "uncompressed size"),
            (uncompressed, size * 1001 + (64 << 10), "uncompressed size"),
            // Within the ratio, but more than the records: decompression runs out.
            (uncompressed, true_size * 10, "uncompressed size"),
            (uncompressed, true_size + 1, "uncompressed size"),
        ];
        for (at, claimed, field) in cases {
            let mut c = b.clone();
            put_u64(&mut c, at, claimed);
            expect_error(&c, &format!("chunk at {}: {field} = {claimed}", r.at));
        }
        for claimed in [u32::MAX, 1 << 20] {
            let mut c = b.clone();
            put_u32(&mut c, compression_len, claimed);
            expect_error(
                &c,
                &format!("chunk at {}: compression length {claimed}", r.at),
            );
        }
    }
}

#[test]
fn record_lengths_inside_chunks_beyond_the_chunk_are_errors() {
    let base = ros2_mcap(true);
    let chunks: Vec<Rec> = file_records(&base)
        .into_iter()
        .filter(|r| r.op == mcap::records::op::CHUNK)
        .collect();
    let mut seen = 0;
    for chunk in &chunks {
        let (_, _, compressed, start) = chunk_fields(&base, chunk);
        let end = start + u64_at(&base, compressed) as usize;
        for inner in records_in(&base, start, end) {
            let left = (end - inner.body) as u64;
            for claimed in [u64::MAX, 1 << 31, (256 << 20) + 1, left + 1] {
                let mut c = base.clone();
                put_u64(&mut c, inner.at + 1, claimed);
                let what = format!(
                    "record {:#04x} at {} in the chunk at {} claims {claimed}",
                    inner.op, inner.at, chunk.at
                );
                expect_error(&c, &format!("uncompressed chunk: {what}"));
                // The same inside a zstd chunk (the edit is made on the chunk's records).
                let rel = inner.at + 1 - start;
                let z = as_zstd(&base, &|records: &mut Vec<u8>, size| {
                    let n = records.len();
                    if n == end - start && rel + 8 <= n {
                        let orig = u64_at(records, rel);
                        if orig == inner.len as u64 {
                            put_u64(records, rel, claimed);
                        }
                    }
                    size
                });
                if z != as_zstd(&base, &unchanged) {
                    expect_error(&z, &format!("zstd chunk: {what}"));
                }
                seen += 1;
            }
        }
    }
    assert!(seen > 20, "{seen}");
}

/// Regression (found by aloft-fuzz): an uncompressed chunk declaring an uncompressed size of
/// u64::MAX lifted the record length limit of its reader to usize::MAX, and a record inside it
/// claiming u64::MAX - 1 bytes overflowed in the `mcap` reader (a panic, in debug and release).
#[test]
fn an_uncompressed_chunk_of_declared_size_u64_max_does_not_lift_the_record_limit() {
    let base = ros2_mcap(true);
    let chunk = file_records(&base)
        .into_iter()
        .find(|r| r.op == mcap::records::op::CHUNK)
        .unwrap();
    let (uncompressed, _, compressed, start) = chunk_fields(&base, &chunk);
    let end = start + u64_at(&base, compressed) as usize;
    let inner = records_in(&base, start, end);
    assert!(inner.len() > 2);
    for r in &inner {
        for claimed in [u64::MAX, u64::MAX - 1, u64::MAX - 8, 1 << 63] {
            let mut c = base.clone();
            put_u64(&mut c, uncompressed, u64::MAX);
            put_u64(&mut c, r.at + 1, claimed);
            expect_error(
                &c,
                &format!("record {:#04x} at {} claims {claimed}", r.op, r.at),
            );
        }
    }
}

#[test]
fn every_flipped_byte_is_an_error_or_a_read_within_the_bound() {
    // Every third byte (length fields are 4 or 8 bytes wide, so each is hit), to keep the test
    // short in debug builds.
    for (name, b) in layouts() {
        for at in (0..b.len()).step_by(3) {
            let mut c = b.clone();
            c[at] ^= 0xff;
            let _ = read_bounded(&c, &format!("{name}: byte {at} flipped"));
        }
    }
}

#[test]
fn truncated_files_are_errors_within_the_bound() {
    for (name, b) in layouts() {
        for cut in (0..b.len()).step_by(7) {
            let e = expect_error(&b[..cut], &format!("{name}: cut at {cut}"));
            assert!(
                matches!(e, LogError::Mcap { .. } | LogError::McapCorrupt { .. }),
                "{name}: cut at {cut}: {e}"
            );
        }
    }
}

/// Records aloft does not use are skipped, not held: an 8 MiB attachment and an 8 MiB message on
/// a topic it does not decode cost no memory (the message is counted on its topic).
#[test]
fn records_aloft_does_not_use_are_skipped_without_being_held() {
    let plain = ros2_mcap(false);
    let mut w = mcap::WriteOptions::new()
        .use_chunks(false)
        .create(Cursor::new(Vec::new()))
        .unwrap();
    let si = w
        .add_schema_with_id(50, "sensor_msgs/msg/Image", "ros2msg", b"")
        .unwrap();
    let ci = w
        .add_channel_with_id(50, si, "/camera", "cdr", &BTreeMap::new())
        .unwrap();
    let image = mcap::records::MessageHeader {
        channel_id: ci,
        sequence: 0,
        log_time: 1_700_000_000_000_000_000,
        publish_time: 0,
    };
    w.write_to_known_channel(&image, &vec![9u8; 8 << 20])
        .unwrap();
    w.attach(&mcap::Attachment {
        log_time: 0,
        create_time: 0,
        name: "calibration.bin".into(),
        media_type: "application/octet-stream".into(),
        data: std::borrow::Cow::Owned(vec![7u8; 8 << 20]),
    })
    .unwrap();
    w.finish().unwrap();
    let attachment_file = w.into_inner().into_inner();
    // The camera's schema, channel and message and the attachment spliced in after the plain
    // file's header (the records before the data end).
    let header = file_records(&plain)[0];
    let mut b = plain[..header.body + header.len].to_vec();
    for r in file_records(&attachment_file) {
        if r.op == mcap::records::op::DATA_END {
            break;
        }
        if r.op != mcap::records::op::HEADER {
            b.extend_from_slice(&attachment_file[r.at..r.body + r.len]);
        }
    }
    b.extend_from_slice(&plain[header.body + header.len..]);
    let mut reader = McapSamples::from_reader(
        Cursor::new(&b[..]),
        Path::new("skip.mcap"),
        McapOptions::default(),
    )
    .with_input_len(b.len() as u64);
    let before = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(before));
    LARGEST.with(|l| l.set(0));
    let r = Read {
        result: reader.by_ref().collect(),
        peak_bytes: (PEAK.with(Cell::get) - before).max(0) as usize,
        largest_bytes: LARGEST.with(Cell::get),
    };
    assert_eq!(r.result.as_ref().unwrap().len(), 66);
    let camera = reader
        .topics()
        .iter()
        .find(|t| t.topic == "/camera")
        .unwrap();
    assert_eq!((camera.messages, camera.decoded), (1, 0));
    assert!(
        r.peak_bytes < 1 << 20 && r.largest_bytes < 1 << 20,
        "peak {} largest {} for a file of {} bytes",
        r.peak_bytes,
        r.largest_bytes,
        b.len()
    );
}
