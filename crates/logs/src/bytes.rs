//! A bounded look-ahead window over any byte reader, for the sans-I/O binary log decoders
//! ([`crate::ulog`], [`crate::dataflash`]).
//!
//! The decoders ask for "the next `n` bytes" and then consume them; the window holds at most
//! what one record needs (a ULog record is at most 65 538 bytes, a DataFlash record 258), so
//! memory does not grow with the file. Every byte has an absolute offset from the start of the
//! input, which errors and warnings carry.

use std::io::Read;

/// Bytes read from the underlying reader at once.
const READ_CHUNK: usize = 64 << 10;

/// A look-ahead window over a reader.
pub struct ByteWindow<R> {
    reader: R,
    buf: Vec<u8>,
    /// Start of the unconsumed bytes in `buf`.
    start: usize,
    /// Absolute offset of `buf[start]`.
    offset: u64,
    eof: bool,
    /// The reader's error, if reading failed (the stream then ends there).
    error: Option<std::io::Error>,
}

impl<R: Read> ByteWindow<R> {
    /// A window at offset 0 of `reader`.
    pub fn new(reader: R) -> Self {
        Self {
            reader,
            buf: Vec::new(),
            start: 0,
            offset: 0,
            eof: false,
            error: None,
        }
    }

    /// Absolute offset of the next unconsumed byte.
    pub fn offset(&self) -> u64 {
        self.offset
    }

    /// The I/O error that ended the input, if any.
    pub fn take_error(&mut self) -> Option<std::io::Error> {
        self.error.take()
    }

    /// The next `n` bytes, or `None` when the input ends before them (the bytes that remain
    /// are then [`Self::remaining`]). Only what the input actually holds is allocated.
    pub fn peek(&mut self, n: usize) -> Option<&[u8]> {
        while self.buf.len() - self.start < n && !self.eof {
            self.refill();
        }
        let avail = &self.buf[self.start..];
        (avail.len() >= n).then(|| &avail[..n])
    }

    /// At most `n` next bytes: fewer only at the end of the input.
    pub fn peek_max(&mut self, n: usize) -> &[u8] {
        while self.buf.len() - self.start < n && !self.eof {
            self.refill();
        }
        let avail = &self.buf[self.start..];
        &avail[..n.min(avail.len())]
    }

    /// The bytes the window holds now, after reading more when it holds fewer than `want`.
    pub fn available(&mut self, want: usize) -> &[u8] {
        if self.buf.len() - self.start < want && !self.eof {
            self.refill();
        }
        &self.buf[self.start..]
    }

    /// The bytes left in the window (at the end of the input: the incomplete tail).
    pub fn remaining(&self) -> usize {
        self.buf.len() - self.start
    }

    /// Drop the next `n` bytes (at most what the window holds).
    pub fn consume(&mut self, n: usize) {
        let n = n.min(self.buf.len() - self.start);
        self.start += n;
        self.offset += n as u64;
    }

    /// Skip forward to the absolute offset `to` (no-op when already past it); `false` when the
    /// input ends first.
    pub fn skip_to(&mut self, to: u64) -> bool {
        while self.offset < to {
            if self.remaining() == 0 && self.peek(1).is_none() {
                return false;
            }
            let n = (to - self.offset).min(self.remaining() as u64) as usize;
            self.consume(n);
        }
        true
    }

    /// True when every byte has been consumed and the input is at its end.
    pub fn at_end(&mut self) -> bool {
        self.peek(1).is_none()
    }

    fn refill(&mut self) {
        if self.start > 0 && (self.start >= READ_CHUNK || self.start == self.buf.len()) {
            self.buf.drain(..self.start);
            self.start = 0;
        }
        let old = self.buf.len();
        self.buf.resize(old + READ_CHUNK, 0);
        loop {
            match self.reader.read(&mut self.buf[old..]) {
                Ok(0) => {
                    self.eof = true;
                    self.buf.truncate(old);
                    return;
                }
                Ok(k) => {
                    self.buf.truncate(old + k);
                    return;
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    self.error = Some(e);
                    self.eof = true;
                    self.buf.truncate(old);
                    return;
                }
            }
        }
    }
}

/// Little-endian readers over a record's bytes; out-of-range reads give `None`.
pub(crate) mod le {
    /// `N` bytes at `at`.
    pub fn bytes<const N: usize>(b: &[u8], at: usize) -> Option<[u8; N]> {
        b.get(at..at.checked_add(N)?)?.try_into().ok()
    }
    /// u16 at `at`.
    pub fn u16(b: &[u8], at: usize) -> Option<u16> {
        bytes(b, at).map(u16::from_le_bytes)
    }
    /// u64 at `at`.
    pub fn u64(b: &[u8], at: usize) -> Option<u64> {
        bytes(b, at).map(u64::from_le_bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_peeks_consumes_and_skips_across_chunks() {
        let data: Vec<u8> = (0..200_000u32).map(|i| (i % 251) as u8).collect();
        let mut w = ByteWindow::new(&data[..]);
        assert_eq!(w.peek(3).unwrap(), &[0, 1, 2]);
        w.consume(3);
        assert!(w.skip_to(100_000));
        assert_eq!(w.offset(), 100_000);
        assert_eq!(w.peek(1).unwrap()[0], (100_000 % 251) as u8);
        assert!(w.skip_to(199_999));
        assert!(w.peek(2).is_none());
        assert_eq!(w.remaining(), 1);
        assert!(!w.skip_to(300_000));
        assert!(w.at_end());
    }
}
