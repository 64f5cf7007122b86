//! A small decoder for ROS 2 CDR (OMG XCDR1 "plain CDR", little or big endian), enough for the
//! fixed layouts of the message types in [`crate::ros`].
//!
//! Layout: a 4-byte encapsulation header (`00 00` CDR big endian, `00 01` CDR little endian, then
//! two option bytes), then the fields in declaration order. Each primitive is aligned to its own
//! size (8 for `float64`), measured from the end of the encapsulation header. Strings are a
//! `uint32` length that counts the terminating NUL, then the bytes. Sequences are a `uint32` count,
//! then the elements; fixed arrays have no count. XCDR2 plain encodings (`00 06`/`00 07`, as
//! written by some DDS vendors) cap alignment at 4 bytes and are accepted too. Parameter-list
//! encodings are rejected.

use thiserror::Error;

/// What went wrong decoding a CDR message.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum CdrError {
    /// The message ended before a field.
    #[error("truncated CDR message: {needed} bytes needed at offset {offset}, {len} in message")]
    Truncated {
        /// Offset of the field from the start of the message (header included).
        offset: usize,
        /// Bytes needed.
        needed: usize,
        /// Message length.
        len: usize,
    },
    /// An encapsulation other than plain CDR.
    #[error("unsupported CDR encapsulation {0:#06x} (only plain CDR/XCDR2 LE and BE)")]
    Encapsulation(u16),
    /// A string that is not NUL-terminated UTF-8.
    #[error("invalid CDR string at offset {offset}")]
    InvalidString {
        /// Offset of the string's length field.
        offset: usize,
    },
    /// A sequence length that cannot fit in the message.
    #[error("CDR sequence of {count} elements at offset {offset} exceeds the message")]
    SequenceTooLong {
        /// Offset of the count.
        offset: usize,
        /// The count found.
        count: u32,
    },
}

/// A cursor over one CDR message.
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    buf: &'a [u8],
    pos: usize,
    little: bool,
    max_align: usize,
}

const HEADER: usize = 4;

impl<'a> CdrReader<'a> {
    /// Start reading a message (checks the encapsulation header).
    pub fn new(buf: &'a [u8]) -> Result<Self, CdrError> {
        if buf.len() < HEADER {
            return Err(CdrError::Truncated {
                offset: 0,
                needed: HEADER,
                len: buf.len(),
            });
        }
        let kind = u16::from_be_bytes([buf[0], buf[1]]);
        let (little, max_align) = match kind {
            0x0000 => (false, 8),
            0x0001 => (true, 8),
            0x0006 => (false, 4),
            0x0007 => (true, 4),
            k => return Err(CdrError::Encapsulation(k)),
        };
        Ok(Self {
            buf,
            pos: HEADER,
            little,
            max_align,
        })
    }

    /// Whether the message is little endian.
    pub fn is_little_endian(&self) -> bool {
        self.little
    }

    /// Current offset from the start of the message.
    pub fn position(&self) -> usize {
        self.pos
    }

    fn align(&mut self, size: usize) {
        let a = size.min(self.max_align);
        let rel = self.pos - HEADER;
        self.pos += (a - rel % a) % a;
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], CdrError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.buf.len());
        match end {
            Some(end) => {
                let s = &self.buf[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(CdrError::Truncated {
                offset: self.pos,
                needed: n,
                len: self.buf.len(),
            }),
        }
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], CdrError> {
        self.align(N);
        let s = self.take(N)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    /// `uint8` / `bool` / `char`.
    pub fn u8(&mut self) -> Result<u8, CdrError> {
        Ok(self.take(1)?[0])
    }

    /// A number of `N` bytes, aligned, in the message's byte order.
    #[inline]
    fn number<const N: usize, T>(
        &mut self,
        from_le: fn([u8; N]) -> T,
        from_be: fn([u8; N]) -> T,
    ) -> Result<T, CdrError> {
        let a = self.array::<N>()?;
        Ok(if self.little { from_le(a) } else { from_be(a) })
    }

    /// `uint32`.
    pub fn u32(&mut self) -> Result<u32, CdrError> {
        self.number(u32::from_le_bytes, u32::from_be_bytes)
    }

    /// `int32`.
    pub fn i32(&mut self) -> Result<i32, CdrError> {
        self.number(i32::from_le_bytes, i32::from_be_bytes)
    }

    /// `float32`.
    pub fn f32(&mut self) -> Result<f32, CdrError> {
        self.number(f32::from_le_bytes, f32::from_be_bytes)
    }

    /// `float64`.
    pub fn f64(&mut self) -> Result<f64, CdrError> {
        self.number(f64::from_le_bytes, f64::from_be_bytes)
    }

    /// `n` consecutive `float64` (a fixed array, or the elements of a sequence).
    pub fn f64s<const N: usize>(&mut self) -> Result<[f64; N], CdrError> {
        let mut out = [0.0; N];
        for o in &mut out {
            *o = self.f64()?;
        }
        Ok(out)
    }

    /// Skip `n` consecutive `float64`.
    pub fn skip_f64s(&mut self, n: usize) -> Result<(), CdrError> {
        self.align(8);
        self.take(n * 8).map(|_| ())
    }

    /// `string`, borrowed (without the NUL).
    pub fn string(&mut self) -> Result<&'a str, CdrError> {
        let offset = {
            self.align(4);
            self.pos
        };
        let n = self.u32()? as usize;
        if n == 0 {
            // Some writers encode the empty string with length 0.
            return Ok("");
        }
        let bytes = self.take(n).map_err(|_| CdrError::Truncated {
            offset,
            needed: n,
            len: self.buf.len(),
        })?;
        let (body, nul) = bytes.split_at(n - 1);
        if nul != [0] {
            return Err(CdrError::InvalidString { offset });
        }
        std::str::from_utf8(body).map_err(|_| CdrError::InvalidString { offset })
    }

    /// A sequence count, checked against the bytes left for elements of `elem_size` bytes.
    pub fn sequence_len(&mut self, elem_size: usize) -> Result<usize, CdrError> {
        self.align(4);
        let offset = self.pos;
        let count = self.u32()?;
        let left = self.buf.len().saturating_sub(self.pos);
        if (count as usize).saturating_mul(elem_size.max(1)) > left {
            return Err(CdrError::SequenceTooLong { offset, count });
        }
        Ok(count as usize)
    }

    /// Skip a sequence of `float32`.
    pub fn skip_f32_sequence(&mut self) -> Result<(), CdrError> {
        let n = self.sequence_len(4)?;
        if n > 0 {
            self.align(4);
            self.take(n * 4)?;
        }
        Ok(())
    }
}

/// A minimal CDR writer (little endian), used by tests and benches to make ROS 2 messages.
#[derive(Debug, Clone, Default)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl CdrWriter {
    /// A little-endian plain-CDR message with its encapsulation header.
    pub fn new() -> Self {
        Self {
            buf: vec![0x00, 0x01, 0x00, 0x00],
        }
    }

    fn align(&mut self, n: usize) {
        while (self.buf.len() - HEADER) % n != 0 {
            self.buf.push(0);
        }
    }

    /// `uint8`.
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.buf.push(v);
        self
    }

    /// The little-endian bytes of a number, aligned to their size.
    fn number<const N: usize>(&mut self, bytes: [u8; N]) -> &mut Self {
        self.align(N);
        self.buf.extend_from_slice(&bytes);
        self
    }

    /// `uint32`.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.number(v.to_le_bytes())
    }

    /// `int32`.
    pub fn i32(&mut self, v: i32) -> &mut Self {
        self.number(v.to_le_bytes())
    }

    /// `float32`.
    pub fn f32(&mut self, v: f32) -> &mut Self {
        self.number(v.to_le_bytes())
    }

    /// `float64`.
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.number(v.to_le_bytes())
    }

    /// `string`.
    pub fn string(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32 + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
        self
    }

    /// `std_msgs/Header`.
    pub fn header(&mut self, sec: i32, nanosec: u32, frame_id: &str) -> &mut Self {
        self.i32(sec).u32(nanosec).string(frame_id)
    }

    /// The message bytes.
    pub fn finish(&self) -> Vec<u8> {
        self.buf.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aligns_float64_after_string() {
        let mut w = CdrWriter::new();
        w.header(5, 7, "map").f64(1.5);
        let b = w.finish();
        // 4 header + 4 sec + 4 nsec + 4 len + 4 "map\0" = 20, f64 aligned to 8 from offset 4 -> 20.
        assert_eq!(b.len(), 28);
        let mut r = CdrReader::new(&b).unwrap();
        assert_eq!(r.i32().unwrap(), 5);
        assert_eq!(r.u32().unwrap(), 7);
        assert_eq!(r.string().unwrap(), "map");
        assert_eq!(r.f64().unwrap().to_bits(), 1.5f64.to_bits());
        let mut w = CdrWriter::new();
        w.header(5, 7, "base").f64(2.5);
        let b = w.finish();
        // "base\0" ends at offset 21: the f64 starts at 28 (24 from the header end).
        assert_eq!(b.len(), 36);
    }

    #[test]
    fn big_endian_reads() {
        let mut b = vec![0x00, 0x00, 0x00, 0x00];
        b.extend_from_slice(&7i32.to_be_bytes());
        b.extend_from_slice(&[0, 0, 0, 0]);
        b.extend_from_slice(&2.0f64.to_be_bytes());
        let mut r = CdrReader::new(&b).unwrap();
        assert_eq!(r.i32().unwrap(), 7);
        assert_eq!(r.f64().unwrap().to_bits(), 2.0f64.to_bits());
    }

    #[test]
    fn truncation_and_bad_headers_are_errors() {
        let mut w = CdrWriter::new();
        w.header(1, 2, "map").f64(3.0);
        let b = w.finish();
        let mut r = CdrReader::new(&b[..b.len() - 1]).unwrap();
        r.i32().unwrap();
        r.u32().unwrap();
        r.string().unwrap();
        assert!(matches!(
            r.f64(),
            Err(CdrError::Truncated { offset: 20, .. })
        ));
        assert!(matches!(
            CdrReader::new(&[0x00, 0x03, 0, 0]),
            Err(CdrError::Encapsulation(3))
        ));
        assert!(CdrReader::new(&[0x00]).is_err());
        // String length beyond the message.
        let mut r = CdrReader::new(&[0, 1, 0, 0, 200, 0, 0, 0, b'a']).unwrap();
        assert!(r.string().is_err());
    }
}
