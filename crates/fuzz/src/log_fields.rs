//! The fields of a PX4 ULog or ArduPilot DataFlash log that structure-aware mutations aim at,
//! found by walking the records as far as they hold together: the integer fields that say how
//! long a record is or which record it is (sizes, message ids, `FMT` lengths and types,
//! timestamps), the float fields of the data records, and the format characters of `FMT` records.

/// Where the fields of one log are.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LogFields {
    /// Integer fields (offset, width in bytes): record sizes, ids, lengths, timestamps.
    pub ints: Vec<(usize, usize)>,
    /// Offsets of 4-byte floats in data records.
    pub floats: Vec<usize>,
    /// Offsets of format characters (DataFlash `FMT` formats, ULog field types).
    pub format_chars: Vec<usize>,
}

/// Most fields collected from one input (the walk stops there).
const MAX_FIELDS: usize = 4096;

/// The ULog file header's length, bytes.
const ULOG_HEADER: usize = 16;

impl LogFields {
    fn full(&self) -> bool {
        self.ints.len() + self.floats.len() + self.format_chars.len() >= MAX_FIELDS
    }

    /// True when no field was found.
    pub fn is_empty(&self) -> bool {
        self.ints.is_empty() && self.floats.is_empty() && self.format_chars.is_empty()
    }
}

/// The fields of a ULog: each record's size (`u16`); a data record's message id and timestamp
/// and its floats (every 4 bytes after the timestamp); a subscription's multi id and message id;
/// the first byte of each field type of a format record.
pub fn ulog_fields(d: &[u8]) -> LogFields {
    let mut f = LogFields::default();
    let mut i = ULOG_HEADER;
    while i + 3 <= d.len() && !f.full() {
        let size = usize::from(u16::from_le_bytes([d[i], d[i + 1]]));
        let body = i + 3;
        let end = body + size;
        if end > d.len() {
            f.ints.push((i, 2));
            return f;
        }
        f.ints.push((i, 2));
        match d[i + 2] {
            b'D' if size >= 10 => {
                f.ints.extend([(body, 2), (body + 2, 8)]);
                f.floats
                    .extend((body + 10..end.saturating_sub(3)).step_by(4));
            }
            b'A' if size >= 3 => f.ints.extend([(body, 1), (body + 1, 2)]),
            b'F' => {
                // `name:type field;type field;...`: the first byte of each type.
                let text = &d[body..end];
                let starts = text
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| matches!(c, b':' | b';'))
                    .map(|(k, _)| body + k + 1)
                    .filter(|k| *k < end);
                f.format_chars.extend(starts);
            }
            _ => {}
        }
        i = end;
    }
    f
}

/// The fields of a DataFlash log: an `FMT` record's type and length bytes and its format
/// characters; a data record's type byte, its first `u64` (the time) and its floats (4-byte
/// steps after it), for types an `FMT` declared. The walk skips bytes to the next `A3 95` when
/// a record's type is unknown.
pub fn dataflash_fields(d: &[u8]) -> LogFields {
    let mut f = LogFields::default();
    let mut lengths = [0u8; 256];
    lengths[0x80] = 89;
    let mut i = 0;
    while i + 3 <= d.len() && !f.full() {
        if d[i] != 0xA3 || d[i + 1] != 0x95 {
            i += 1;
            continue;
        }
        let t = d[i + 2];
        let len = usize::from(lengths[usize::from(t)]);
        if len < 3 || i + len > d.len() {
            f.ints.push((i + 2, 1));
            i += 3;
            continue;
        }
        f.ints.push((i + 2, 1));
        if t == 0x80 {
            f.ints.extend([(i + 3, 1), (i + 4, 1)]);
            lengths[usize::from(d[i + 3])] = d[i + 4];
            let format = i + 9;
            f.format_chars
                .extend((format..format + 16).take_while(|k| d[*k] != 0));
        } else if len >= 11 {
            f.ints.push((i + 3, 8));
            f.floats.extend((i + 11..i + len - 3).step_by(4));
        }
        i += len;
    }
    f
}

/// The fields of a MAVLink telemetry log, for each frame aloft-link's reader finds: the
/// timestamp (`u64`), the payload length, the sender's system id and the message id (one byte in
/// MAVLink 1; in MAVLink 2 also the incompatibility flags and the message id's three bytes),
/// the CRC, and the payload's floats (every 4 bytes; MAVLink lays out the widest fields first).
pub fn tlog_fields(d: &[u8]) -> LogFields {
    let mut f = LogFields::default();
    for frame in aloft_link::TlogReader::new(d, "fields").flatten() {
        if f.full() {
            break;
        }
        let at = usize::try_from(frame.offset).unwrap_or(usize::MAX);
        let magic = at + 8;
        let v2 = d.get(magic) == Some(&0xFD);
        let header = if v2 { 10 } else { 6 };
        f.ints.extend([(at, 8), (magic + 1, 1)]);
        if v2 {
            f.ints
                .extend([(magic + 2, 1), (magic + 5, 1), (magic + 7, 3)]);
        } else {
            f.ints.extend([(magic + 3, 1), (magic + 5, 1)]);
        }
        let payload_len = usize::from(d.get(magic + 1).copied().unwrap_or(0));
        let payload = magic + header;
        f.ints.push((payload + payload_len, 2));
        f.floats
            .extend((payload..(payload + payload_len).saturating_sub(3)).step_by(4));
    }
    f
}

/// Float values that break decoders and models, as `f32` bits: zeros of both signs, NaN, the
/// infinities, the largest and smallest magnitudes.
pub const EXTREME_F32: [f32; 12] = [
    0.0,
    -0.0,
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::MAX,
    f32::MIN,
    f32::MIN_POSITIVE,
    1e-45,
    -1.0,
    1e9,
    -1e9,
];

/// DataFlash format characters and the first letters of ULog field types, to write in place of
/// another: a wider or narrower field shifts every column after it.
pub const FORMAT_CHARS: &[u8] = b"bBhHiIfdnNZqQcCeELMaiubdfc";

#[cfg(test)]
mod tests {
    use super::*;
    use aloft_logs::synth;

    #[test]
    fn ulog_sizes_ids_and_floats_are_found() {
        let mut d = synth::ULOG_HEADER.to_vec();
        d.extend(synth::ulog_subscription(1, "battery_status"));
        d.extend(synth::ulog_data(1, 1_000, &[16.0, 10.0]));
        let f = ulog_fields(&d);
        // Subscription at 16: size, multi id, msg id; data at 16 + 3 + 17 = 36.
        assert_eq!(
            f.ints,
            [(16, 2), (19, 1), (20, 2), (36, 2), (39, 2), (41, 8)]
        );
        assert_eq!(f.floats, [49, 53]);
        assert_eq!(d[53..57], 10.0f32.to_le_bytes());
    }

    #[test]
    fn tlog_timestamps_lengths_ids_crc_and_floats_are_found() {
        let d = crate::seeds::tlog_made_in_code();
        let f = tlog_fields(&d);
        // The first frame: a MAVLink 1 HEARTBEAT (9 bytes of payload) at 0.
        assert_eq!(f.ints[..5], [(0, 8), (9, 1), (11, 1), (13, 1), (23, 2)]);
        assert_eq!(f.floats[..2], [14, 18]);
        assert!(f.ints.len() > 50);
    }

    #[test]
    fn dataflash_fmt_fields_and_record_floats_are_found() {
        let mut d = synth::dataflash_fmt(2, 3 + 8 + 8, "BAT", "Qff", "TimeUS,Volt,Curr");
        d.extend(synth::dataflash_record(2, 5, &[12.0, 5.0]));
        let f = dataflash_fields(&d);
        assert_eq!(f.ints, [(2, 1), (3, 1), (4, 1), (91, 1), (92, 8)]);
        assert_eq!(f.floats, [100, 104]);
        assert_eq!(f.format_chars, [9, 10, 11]);
        assert_eq!(d[104..108], 5.0f32.to_le_bytes());
    }
}
