//! Telemetry logs (`.tlog`): the frames a ground station saved from its link, each MAVLink frame
//! (v1 starts `0xFE`, v2 `0xFD`) preceded by a big-endian `u64` timestamp, microseconds since the
//! Unix epoch.
//!
//! [`TlogReader`] streams the frames of any [`Read`] (a file, a `&[u8]`) through a fixed 64 KiB
//! window, so memory stays flat whatever the log's length. Each frame's CRC is checked with the
//! ArduPilot dialect's CRC_EXTRA ([`MAVLinkV1MessageRaw::has_valid_crc`],
//! [`MAVLinkV2MessageRaw::has_valid_crc`]) and its payload decoded by the dialect
//! ([`Message::parse`]); v1 and v2 frames may be mixed.
//!
//! # Damage
//!
//! A frame is taken only where a plausible timestamp (years 2000 to 2100) is followed by a magic
//! byte, a complete frame and a valid CRC. Anything else (garbage between frames, a flipped bit, a
//! frame cut short by the end of the file or by the next frame) is passed over byte by byte until
//! the next plausible timestamp and magic byte, so one damaged frame costs that frame only. A
//! timestamp more than [`MAX_GAP_US`] away from the previous frame's is believed only when one
//! of the two frames after it agrees (a real pause in the log), otherwise the frame is dropped (a
//! corrupt timestamp in a frame whose CRC, which does not cover the timestamp, is valid). Frames of
//! messages the dialect does not know cannot be checked: they are passed over whole when the next
//! frame starts right after them, else byte by byte. Every skipped byte and every dropped frame is
//! counted in [`TlogStats`].

use std::io::{ErrorKind, Read};

use mavlink::dialects::ardupilotmega::MavMessage;
use mavlink::error::ParserError;
use mavlink::{MAVLinkV1MessageRaw, MAVLinkV2MessageRaw, MavHeader, MavlinkVersion, Message};

use crate::error::LinkError;

/// Bytes of the timestamp before each frame.
pub const TIMESTAMP_LEN: usize = 8;
/// The earliest plausible timestamp, µs since the Unix epoch (2000-01-01).
pub const MIN_TIMESTAMP_US: u64 = 946_684_800_000_000;
/// The first implausible timestamp, µs since the Unix epoch (2100-01-01).
pub const MAX_TIMESTAMP_US: u64 = 4_102_444_800_000_000;
/// The largest step between consecutive frames' timestamps believed without the next frame's
/// agreement, µs (30 s: telemetry arrives several times a second, so a longer silence is a real
/// pause only when the frames after it continue from the new time).
pub const MAX_GAP_US: u64 = 30_000_000;

const MAGIC_V1: u8 = mavlink::MAV_STX;
const MAGIC_V2: u8 = mavlink::MAV_STX_V2;
/// Magic byte and header of a v1 frame.
const V1_HEADER: usize = 1 + 5;
/// Magic byte and header of a v2 frame.
const V2_HEADER: usize = 1 + 9;
const CHECKSUM: usize = 2;
const SIGNATURE: usize = 13;
const IFLAG_SIGNED: u8 = 0x01;
/// The longest frame: a signed v2 frame with 255 bytes of payload.
const MAX_FRAME: usize = V2_HEADER + 255 + CHECKSUM + SIGNATURE;
/// Bytes kept ahead of the read position: two of the longest frames with their timestamps, and
/// the timestamp and magic byte of a third (to check the timestamps of the two frames after a
/// frame).
const LOOKAHEAD: usize = 2 * (TIMESTAMP_LEN + MAX_FRAME) + TIMESTAMP_LEN + 1;
/// The read window.
const WINDOW: usize = 64 * 1024;

/// What the reader has read and passed over so far.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TlogStats {
    /// Bytes read.
    pub bytes: u64,
    /// Frames returned (timestamp, valid CRC, decoded).
    pub frames: u64,
    /// Bytes not part of a returned frame (garbage, damaged and dropped frames).
    pub bytes_skipped: u64,
    /// Frames of a known message with a wrong CRC.
    pub bad_crc: u64,
    /// Frames of a message the dialect does not know (their CRC cannot be checked).
    pub unknown: u64,
    /// Frames with a valid CRC whose payload the dialect refused (an enum value it does not know,
    /// a payload longer than the message).
    pub undecoded: u64,
    /// Frames with a valid CRC but a timestamp out of line with the frames around it.
    pub bad_time: u64,
    /// Frames cut short by the end of the input.
    pub truncated: u64,
}

impl TlogStats {
    /// Frames found but not returned: wrong CRC, unknown message, refused payload, bad timestamp,
    /// cut short.
    pub fn bad_frames(&self) -> u64 {
        self.bad_crc + self.unknown + self.undecoded + self.bad_time + self.truncated
    }
}

/// One frame of a telemetry log.
#[derive(Debug, Clone, PartialEq)]
pub struct TlogFrame {
    /// The log's timestamp of the frame, µs since the Unix epoch.
    pub timestamp_us: u64,
    /// Byte offset of the frame's timestamp in the input.
    pub offset: u64,
    /// Bytes of the frame in the input, its timestamp included.
    pub len: usize,
    /// MAVLink 1 or 2.
    pub version: MavlinkVersion,
    /// Sender's system and component ids, sequence number.
    pub header: MavHeader,
    /// The decoded message (ArduPilot dialect, common included).
    pub message: MavMessage,
}

/// Where the bytes at the read position lead.
// Moved out once per frame: boxing the frame would allocate once per frame.
#[allow(clippy::large_enum_variant)]
enum Step {
    /// A frame to return, `len` bytes from the read position (timestamp included).
    Frame(TlogFrame, usize),
    /// Bytes to pass over.
    Skip(usize),
}

/// The shape of a candidate frame from its magic byte.
enum Shape {
    /// Not enough bytes to tell.
    NeedMore,
    /// Not a frame (unsupported incompatibility flags).
    NotAFrame,
    /// A frame of `len` bytes from the magic byte.
    Frame { version: MavlinkVersion, len: usize },
}

/// A streaming reader of `.tlog` frames with bounded memory (see the module docs).
pub struct TlogReader<R> {
    source: R,
    name: String,
    buf: Box<[u8]>,
    /// Read position in `buf`.
    start: usize,
    /// End of the valid bytes in `buf`.
    end: usize,
    /// Input offset of `buf[0]`.
    base: u64,
    eof: bool,
    /// Whether the frame cut by the end of the input has been counted.
    truncation_counted: bool,
    last_timestamp_us: Option<u64>,
    stats: TlogStats,
    v1: MAVLinkV1MessageRaw,
    v2: MAVLinkV2MessageRaw,
}

impl<R: Read> TlogReader<R> {
    /// A reader of `source`; `name` (the file's path) is what errors name.
    pub fn new(source: R, name: impl Into<String>) -> Self {
        Self {
            source,
            name: name.into(),
            buf: vec![0; WINDOW].into_boxed_slice(),
            start: 0,
            end: 0,
            base: 0,
            eof: false,
            truncation_counted: false,
            last_timestamp_us: None,
            stats: TlogStats::default(),
            v1: MAVLinkV1MessageRaw::new(),
            v2: MAVLinkV2MessageRaw::new(),
        }
    }

    /// What has been read and passed over so far.
    pub fn stats(&self) -> &TlogStats {
        &self.stats
    }

    /// The name errors give the input (the file's path).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The input offset of the read position.
    pub fn offset(&self) -> u64 {
        self.base + self.start as u64
    }

    /// The next frame, `None` at the end of the input. Damaged bytes are passed over (and
    /// counted); only a failing read is an error.
    pub fn next_frame(&mut self) -> Result<Option<TlogFrame>, LinkError> {
        loop {
            if self.end - self.start < LOOKAHEAD && !self.eof {
                self.fill()?;
            }
            if self.start == self.end {
                return Ok(None);
            }
            match self.step() {
                Step::Frame(frame, len) => {
                    self.start += len;
                    self.stats.frames += 1;
                    return Ok(Some(frame));
                }
                Step::Skip(n) => {
                    let n = n.clamp(1, self.end - self.start);
                    self.start += n;
                    self.stats.bytes_skipped += n as u64;
                }
            }
        }
    }

    /// Reads until [`LOOKAHEAD`] bytes are ahead of the read position or the input ends.
    fn fill(&mut self) -> Result<(), LinkError> {
        if self.start > 0 && WINDOW - self.end < LOOKAHEAD {
            self.buf.copy_within(self.start..self.end, 0);
            self.base += self.start as u64;
            self.end -= self.start;
            self.start = 0;
        }
        while self.end - self.start < LOOKAHEAD && !self.eof {
            match self.source.read(&mut self.buf[self.end..]) {
                Ok(0) => self.eof = true,
                Ok(n) => {
                    self.end += n;
                    self.stats.bytes += n as u64;
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(cause) => {
                    return Err(LinkError::Read {
                        name: self.name.clone(),
                        offset: self.base + self.end as u64,
                        cause,
                    })
                }
            }
        }
        Ok(())
    }

    /// What the bytes at the read position are.
    fn step(&mut self) -> Step {
        let b = &self.buf[self.start..self.end];
        let Some(timestamp_us) = candidate(b, 0) else {
            return Step::Skip(self.next_candidate(1));
        };
        let (version, len) = match shape(&b[TIMESTAMP_LEN..]) {
            Shape::Frame { version, len } if TIMESTAMP_LEN + len <= b.len() => (version, len),
            Shape::NotAFrame => return Step::Skip(self.next_candidate(1)),
            // The buffer holds the longest frame unless the input ended: cut short.
            Shape::Frame { .. } | Shape::NeedMore => {
                if !self.truncation_counted {
                    self.truncation_counted = true;
                    self.stats.truncated += 1;
                }
                return Step::Skip(self.next_candidate(1));
            }
        };
        let total = TIMESTAMP_LEN + len;
        let Some((header, msgid)) = self.checked(version, len) else {
            return self.bad_crc(version, len, timestamp_us);
        };
        if !self.time_fits(timestamp_us, total) {
            self.stats.bad_time += 1;
            return Step::Skip(total);
        }
        self.last_timestamp_us = Some(timestamp_us);
        let payload = match version {
            MavlinkVersion::V1 => self.v1.payload(),
            MavlinkVersion::V2 => self.v2.payload(),
        };
        match MavMessage::parse(version, msgid, payload) {
            Ok(message) => Step::Frame(
                TlogFrame {
                    timestamp_us,
                    offset: self.offset(),
                    len: total,
                    version,
                    header,
                    message,
                },
                total,
            ),
            Err(_) => {
                self.stats.undecoded += 1;
                Step::Skip(total)
            }
        }
    }

    /// Copies the frame at the read position into the raw frame of its version and checks its
    /// CRC: the header and message id when it is valid.
    fn checked(&mut self, version: MavlinkVersion, len: usize) -> Option<(MavHeader, u32)> {
        let from = self.start + TIMESTAMP_LEN;
        let bytes = &self.buf[from..from + len];
        match version {
            MavlinkVersion::V1 => {
                self.v1.as_mut_slice()[..len].copy_from_slice(bytes);
                let raw = &self.v1;
                raw.has_valid_crc::<MavMessage>().then(|| {
                    let header = MavHeader {
                        system_id: u32::from(raw.system_id()),
                        component_id: raw.component_id(),
                        sequence: raw.sequence(),
                    };
                    (header, u32::from(raw.message_id()))
                })
            }
            MavlinkVersion::V2 => {
                self.v2.as_mut_slice()[..len].copy_from_slice(bytes);
                let raw = &self.v2;
                raw.has_valid_crc::<MavMessage>().then(|| {
                    let header = MavHeader {
                        system_id: raw.system_id(),
                        component_id: raw.component_id(),
                        sequence: raw.sequence(),
                    };
                    (header, raw.message_id())
                })
            }
        }
    }

    /// A frame whose CRC failed: a known message is damaged (pass over one byte and look for the
    /// next frame); an unknown one is passed over whole when the next frame starts right after
    /// it.
    fn bad_crc(&mut self, version: MavlinkVersion, len: usize, timestamp_us: u64) -> Step {
        let msgid = match version {
            MavlinkVersion::V1 => u32::from(self.v1.message_id()),
            MavlinkVersion::V2 => self.v2.message_id(),
        };
        let total = TIMESTAMP_LEN + len;
        let known = !matches!(
            MavMessage::parse(version, msgid, &[]),
            Err(ParserError::UnknownMessage { .. })
        );
        if !known && self.continues(total, timestamp_us) {
            self.stats.unknown += 1;
            return Step::Skip(total);
        }
        if known {
            self.stats.bad_crc += 1;
        }
        Step::Skip(self.next_candidate(1))
    }

    /// Whether a frame of `total` bytes with this timestamp is in line with the frames around it:
    /// near the previous frame's, or near one of the next two frames' (a real pause, or a corrupt
    /// previous timestamp); the first frame also when no frame follows to contradict it.
    fn time_fits(&self, timestamp_us: u64, total: usize) -> bool {
        let near = |other: u64| other.abs_diff(timestamp_us) <= MAX_GAP_US;
        if self.last_timestamp_us.is_some_and(near) {
            return true;
        }
        let b = &self.buf[self.start..self.end];
        let next = candidate(b, total);
        let after_next = next.and_then(|_| match shape(b.get(total + TIMESTAMP_LEN..)?) {
            Shape::Frame { len, .. } => candidate(b, total + TIMESTAMP_LEN + len),
            _ => None,
        });
        if next.is_some_and(near) || after_next.is_some_and(near) {
            return true;
        }
        self.last_timestamp_us.is_none() && next.is_none()
    }

    /// Whether the frame of `total` bytes ends the input or is followed by a frame of a nearby
    /// timestamp.
    fn continues(&self, total: usize, timestamp_us: u64) -> bool {
        let b = &self.buf[self.start..self.end];
        (self.eof && total == b.len())
            || candidate(b, total).is_some_and(|t| t.abs_diff(timestamp_us) <= MAX_GAP_US)
    }

    /// Bytes from the read position to the next plausible timestamp and magic byte at or after
    /// `from`; all but the last few bytes when there is none in the buffer (a candidate may start
    /// in them), all of them at the end of the input.
    fn next_candidate(&self, from: usize) -> usize {
        let b = &self.buf[self.start..self.end];
        let last = b.len().saturating_sub(TIMESTAMP_LEN);
        // Only the magic byte is tested at each position first: the timestamp is read only where
        // it could start a frame.
        let found =
            (from..last).find(|&i| is_magic(b[i + TIMESTAMP_LEN]) && candidate(b, i).is_some());
        match found {
            Some(i) => i,
            None if self.eof => b.len(),
            None => last.max(from),
        }
    }
}

impl<R: Read> Iterator for TlogReader<R> {
    type Item = Result<TlogFrame, LinkError>;

    fn next(&mut self) -> Option<Self::Item> {
        self.next_frame().transpose()
    }
}

fn is_magic(b: u8) -> bool {
    b == MAGIC_V1 || b == MAGIC_V2
}

/// The timestamp at `at` when it is plausible and followed by a magic byte.
fn candidate(b: &[u8], at: usize) -> Option<u64> {
    let bytes: [u8; TIMESTAMP_LEN] = b.get(at..at + TIMESTAMP_LEN)?.try_into().ok()?;
    let magic = *b.get(at + TIMESTAMP_LEN)?;
    let t = u64::from_be_bytes(bytes);
    ((MIN_TIMESTAMP_US..MAX_TIMESTAMP_US).contains(&t) && is_magic(magic)).then_some(t)
}

/// The shape of the frame starting at `b[0]` (a magic byte).
fn shape(b: &[u8]) -> Shape {
    let (Some(&magic), Some(&payload_len)) = (b.first(), b.get(1)) else {
        return Shape::NeedMore;
    };
    let payload_len = usize::from(payload_len);
    if magic == MAGIC_V1 {
        return Shape::Frame {
            version: MavlinkVersion::V1,
            len: V1_HEADER + payload_len + CHECKSUM,
        };
    }
    let Some(&flags) = b.get(2) else {
        return Shape::NeedMore;
    };
    if flags & !IFLAG_SIGNED != 0 {
        return Shape::NotAFrame;
    }
    let signature = if flags & IFLAG_SIGNED != 0 {
        SIGNATURE
    } else {
        0
    };
    Shape::Frame {
        version: MavlinkVersion::V2,
        len: V2_HEADER + payload_len + CHECKSUM + signature,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::ardupilotmega::{HEARTBEAT_DATA, SYSTEM_TIME_DATA};

    const T0: u64 = 1_700_000_000_000_000;

    fn frame(version: MavlinkVersion, t_us: u64, msg: &MavMessage) -> Vec<u8> {
        let header = MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: 7,
        };
        let mut out = t_us.to_be_bytes().to_vec();
        match version {
            MavlinkVersion::V1 => mavlink::write_v1_msg(&mut out, header, msg),
            MavlinkVersion::V2 => mavlink::write_v2_msg(&mut out, header, msg),
        }
        .unwrap();
        out
    }

    fn time(ms: u32) -> MavMessage {
        MavMessage::SYSTEM_TIME(SYSTEM_TIME_DATA {
            time_unix_usec: 0,
            time_boot_ms: ms,
        })
    }

    fn read_all(bytes: &[u8]) -> (Vec<TlogFrame>, TlogStats) {
        let mut r = TlogReader::new(bytes, "test.tlog");
        let frames: Vec<TlogFrame> = r.by_ref().map(|f| f.unwrap()).collect();
        (frames, *r.stats())
    }

    #[test]
    fn mixed_v1_and_v2_frames_are_read_with_their_timestamps() {
        let mut bytes = frame(MavlinkVersion::V1, T0, &time(1));
        bytes.extend(frame(
            MavlinkVersion::V2,
            T0 + 10,
            &MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()),
        ));
        bytes.extend(frame(MavlinkVersion::V1, T0 + 20, &time(3)));
        let (frames, stats) = read_all(&bytes);
        assert_eq!(frames.len(), 3);
        assert_eq!(frames[1].version, MavlinkVersion::V2);
        assert_eq!(frames[2].timestamp_us, T0 + 20);
        assert_eq!(frames[2].message, time(3));
        assert_eq!(frames[1].offset, 8 + 6 + 12 + 2);
        assert_eq!(stats.bytes_skipped, 0);
        assert_eq!(stats.bytes, bytes.len() as u64);
    }

    #[test]
    fn garbage_between_frames_is_skipped_and_counted() {
        let mut bytes = vec![0xFE, 0x00, 0x42, 0xFD];
        bytes.extend(frame(MavlinkVersion::V1, T0, &time(1)));
        bytes.extend([0xAA; 37]);
        bytes.extend(frame(MavlinkVersion::V2, T0 + 1, &time(2)));
        let (frames, stats) = read_all(&bytes);
        assert_eq!(frames.len(), 2);
        assert_eq!(stats.bytes_skipped, 4 + 37);
        assert_eq!(stats.bad_frames(), 0);
    }

    #[test]
    fn a_flipped_payload_bit_loses_that_frame_only() {
        let a = frame(MavlinkVersion::V1, T0, &time(1));
        let mut b = frame(MavlinkVersion::V1, T0 + 1, &time(2));
        let c = frame(MavlinkVersion::V1, T0 + 2, &time(3));
        b[8 + 6 + 9] ^= 0x10;
        let bytes = [a, b.clone(), c].concat();
        let (frames, stats) = read_all(&bytes);
        assert_eq!(frames.len(), 2);
        assert_eq!(frames[1].message, time(3));
        assert_eq!(stats.bad_crc, 1);
        assert_eq!(stats.bytes_skipped, b.len() as u64);
    }

    #[test]
    fn a_frame_cut_by_the_next_and_one_cut_by_the_end_are_counted() {
        let a = frame(MavlinkVersion::V2, T0, &time(1));
        let b = frame(MavlinkVersion::V2, T0 + 1, &time(2));
        let c = frame(MavlinkVersion::V2, T0 + 2, &time(3));
        let bytes = [&a[..a.len() - 5], &b[..], &c[..c.len() - 3]].concat();
        let (frames, stats) = read_all(&bytes);
        assert_eq!(frames.len(), 1);
        assert_eq!(frames[0].message, time(2));
        assert_eq!(stats.bad_crc, 1);
        assert_eq!(stats.truncated, 1);
    }

    #[test]
    fn a_corrupt_timestamp_is_dropped_and_a_real_pause_is_kept() {
        let mut bytes = frame(MavlinkVersion::V1, T0, &time(1));
        // A single frame a year later: not confirmed by the next one.
        bytes.extend(frame(MavlinkVersion::V1, T0 + 31_536_000_000_000, &time(2)));
        bytes.extend(frame(MavlinkVersion::V1, T0 + 1_000, &time(3)));
        // A pause of ten minutes, confirmed by the frame after it.
        bytes.extend(frame(MavlinkVersion::V1, T0 + 600_000_000, &time(4)));
        bytes.extend(frame(MavlinkVersion::V1, T0 + 600_100_000, &time(5)));
        let (frames, stats) = read_all(&bytes);
        let kept: Vec<u64> = frames.iter().map(|f| f.timestamp_us - T0).collect();
        assert_eq!(kept, [0, 1_000, 600_000_000, 600_100_000]);
        assert_eq!(stats.bad_time, 1);
    }

    #[test]
    fn an_unknown_message_is_passed_over_whole() {
        let mut unknown = frame(MavlinkVersion::V2, T0 + 1, &time(2));
        // Message id 0xABCDEF is in no dialect.
        unknown[8 + 7..8 + 10].copy_from_slice(&[0xEF, 0xCD, 0xAB]);
        let bytes = [
            frame(MavlinkVersion::V2, T0, &time(1)),
            unknown.clone(),
            frame(MavlinkVersion::V2, T0 + 2, &time(3)),
        ]
        .concat();
        let (frames, stats) = read_all(&bytes);
        assert_eq!(frames.len(), 2);
        assert_eq!(stats.unknown, 1);
        assert_eq!(stats.bytes_skipped, unknown.len() as u64);
    }

    #[test]
    fn a_reader_that_returns_one_byte_at_a_time_reads_the_same() {
        struct Trickle<'a>(&'a [u8]);
        impl Read for Trickle<'_> {
            fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
                match (self.0.split_first(), buf.first_mut()) {
                    (Some((b, rest)), Some(out)) => {
                        *out = *b;
                        self.0 = rest;
                        Ok(1)
                    }
                    _ => Ok(0),
                }
            }
        }
        let bytes: Vec<u8> = (0..2_000u32)
            .flat_map(|k| frame(MavlinkVersion::V2, T0 + u64::from(k), &time(k)))
            .collect();
        let frames = TlogReader::new(Trickle(&bytes), "trickle").count();
        assert_eq!(frames, 2_000);
    }

    #[test]
    fn a_read_error_names_the_input_and_offset() {
        struct Failing;
        impl Read for Failing {
            fn read(&mut self, _: &mut [u8]) -> std::io::Result<usize> {
                Err(std::io::Error::other("disk on fire"))
            }
        }
        let e = TlogReader::new(Failing, "flight.tlog")
            .next_frame()
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "flight.tlog: read error at byte 0: disk on fire"
        );
    }
}
