//! The batch path streams: memory stays flat while far more data passes through than it holds.
//! (Its own test binary, so no other test allocates in the same process while it measures.)

use std::io::{Read, Write};

/// A CSV source that generates rows on the fly: no file, no buffer of the whole input.
struct Rows {
    next: u64,
    total: u64,
    pending: Vec<u8>,
    pos: usize,
}

impl Read for Rows {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.pos == self.pending.len() {
            if self.next > self.total {
                return Ok(0);
            }
            self.pending.clear();
            self.pos = 0;
            if self.next == 0 {
                self.pending
                    .extend_from_slice(b"airspeed_mps,roll_deg,pitch_deg,climb_rate_mps\n");
            } else {
                let i = self.next;
                writeln!(
                    self.pending,
                    "{},{},{},{}",
                    (i % 17) as f64,
                    (i % 7) as f64 - 3.0,
                    -((i % 11) as f64),
                    0.5
                )
                .unwrap();
            }
            self.next += 1;
        }
        let n = buf.len().min(self.pending.len() - self.pos);
        buf[..n].copy_from_slice(&self.pending[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}

/// Counts bytes and drops them.
struct Sink(u64);

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0 += buf.len() as u64;
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Peak resident memory of this process, kB (Linux `VmHWM`).
fn peak_rss_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

#[test]
fn batch_memory_does_not_grow_with_the_input() {
    let model = aloft::power::PowerModel::new(
        aloft::vehicle::VehicleFile::builtin("dji-m100")
            .unwrap()
            .power_vehicle()
            .unwrap(),
    );
    // Warm up (allocator, first buffers) before taking the baseline.
    let mut sink = Sink(0);
    let warm = Rows {
        next: 0,
        total: 1_000,
        pending: Vec::new(),
        pos: 0,
    };
    aloft::engine::power_csv(&model, warm, &mut sink, "warm-up").unwrap();
    let Some(before) = peak_rss_kb() else {
        panic!("/proc/self/status has no VmHWM: this test needs Linux");
    };
    let rows = 300_000;
    let mut sink = Sink(0);
    let input = Rows {
        next: 0,
        total: rows,
        pending: Vec::new(),
        pos: 0,
    };
    let n = aloft::engine::power_csv(&model, input, &mut sink, "generated").unwrap();
    let after = peak_rss_kb().unwrap();
    assert_eq!(n, rows);
    // About 49 MB of output went through; holding it (or the 6 MB input) would raise the peak by
    // tens of MB. Streaming keeps the growth to buffers: allow 4 MB.
    assert!(sink.0 > 40_000_000, "output {} bytes", sink.0);
    assert!(
        after - before < 4_096,
        "peak RSS grew {} kB (from {before} kB)",
        after - before
    );
}
