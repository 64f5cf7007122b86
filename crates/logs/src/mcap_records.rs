//! Checked, allocation-free views of the MCAP records aloft uses (Schema, Channel, Message) and
//! of a Chunk's header: the sans-I/O layer under [`crate::mcap_read`].
//!
//! # Why not `mcap::parse_record`
//! `mcap` 0.26 parses records with `binrw`, which reserves the length a string or byte array
//! claims (`Vec::reserve_exact(len)`) before reading it: one flipped byte in a Channel's topic
//! length asks for up to 4 GiB and aborts the process. Here every length-prefixed field (a string
//! or byte array: `u32` length then the bytes; a map: `u32` byte length then its entries) is
//! checked against the bytes that remain in the record before it is read, and the fields are
//! borrowed from the record, so reading a record allocates nothing. A field that does not fit is
//! a [`McapProblem`] naming the field, the length it claims and the bytes left.
//!
//! What is accepted on a valid record is exactly what `mcap::parse_record` accepts: the same
//! fields in the same order, strings as UTF-8, bytes after the last field ignored. Where this
//! parser is stricter, it is on corrupt records only: an entry of a Channel's metadata map must
//! lie inside the map's byte length (binrw reads on past it). Duplicate metadata keys, which
//! `mcap` refuses, are not looked for: aloft does not read the metadata.

use mcap::records::MessageHeader;
use thiserror::Error;

/// What is wrong with an MCAP record or chunk (the location is in [`crate::LogError`]).
#[derive(Debug, Error, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum McapProblem {
    /// A length-prefixed field claims more bytes than remain in its record (or map).
    #[error("its {field} claims {claimed} bytes, but only {available} are left for it")]
    FieldTooLong {
        /// The field (`topic`, `schema name`, `metadata`, `metadata key`, ...).
        field: &'static str,
        /// The length the field claims, bytes.
        claimed: u64,
        /// The bytes left where the field must fit (the rest of the record, or of the map for a
        /// map's entry), bytes.
        available: u64,
    },
    /// A record whose length is more than the chunk it is in holds, or than any record may have.
    #[error("its length, {claimed} bytes, is more than the {limit} bytes a record can have there")]
    RecordTooLong {
        /// The length the record claims, bytes.
        claimed: u64,
        /// The most it can have, bytes.
        limit: u64,
    },
    /// The record ends inside a fixed-size field.
    #[error("it ends inside its {field} ({needed} bytes needed, {available} left)")]
    Truncated {
        /// The field.
        field: &'static str,
        /// Bytes the field needs.
        needed: u64,
        /// Bytes left in the record.
        available: u64,
    },
    /// A string field that is not UTF-8.
    #[error("its {field} is not UTF-8")]
    NotUtf8 {
        /// The field.
        field: &'static str,
    },
    /// A chunk whose declared uncompressed size is implausible for its compressed size.
    #[error("its uncompressed size, {uncompressed} bytes, is more than {max_ratio} times its {compressed} compressed bytes or more than {limit} bytes: a corrupt size")]
    ChunkSize {
        /// The declared uncompressed size, bytes.
        uncompressed: u64,
        /// The compressed size, bytes.
        compressed: u64,
        /// The largest ratio accepted.
        max_ratio: u64,
        /// The largest uncompressed size accepted, bytes.
        limit: u64,
    },
}

/// Record names for messages, by opcode.
pub fn record_name(opcode: u8) -> &'static str {
    use mcap::records::op;
    match opcode {
        op::HEADER => "Header",
        op::FOOTER => "Footer",
        op::SCHEMA => "Schema",
        op::CHANNEL => "Channel",
        op::MESSAGE => "Message",
        op::CHUNK => "Chunk",
        op::MESSAGE_INDEX => "MessageIndex",
        op::CHUNK_INDEX => "ChunkIndex",
        op::ATTACHMENT => "Attachment",
        op::ATTACHMENT_INDEX => "AttachmentIndex",
        op::STATISTICS => "Statistics",
        op::METADATA => "Metadata",
        op::METADATA_INDEX => "MetadataIndex",
        op::SUMMARY_OFFSET => "SummaryOffset",
        op::DATA_END => "DataEnd",
        _ => "unknown",
    }
}

/// A Schema record (its `data`, the schema text, is not needed by aloft and not returned).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SchemaView<'a> {
    /// Schema id.
    pub id: u16,
    /// Schema name (`geometry_msgs/msg/PoseStamped`).
    pub name: &'a str,
    /// Schema encoding (`ros2msg`, `jsonschema`, ...).
    pub encoding: &'a str,
}

/// A Channel record (its metadata map is checked, not returned).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChannelView<'a> {
    /// Channel id.
    pub id: u16,
    /// Id of the channel's schema (0: none).
    pub schema_id: u16,
    /// Topic.
    pub topic: &'a str,
    /// Message encoding (`cdr`, `json`, ...).
    pub message_encoding: &'a str,
}

/// A Message record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MessageView<'a> {
    /// Channel, sequence and times.
    pub header: MessageHeader,
    /// The message bytes.
    pub data: &'a [u8],
}

/// A Chunk record's header (what precedes its compressed records).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChunkHeaderView<'a> {
    /// Size of the records once decompressed, bytes.
    pub uncompressed_size: u64,
    /// Compression (`""` for none, `zstd`, `lz4`).
    pub compression: &'a str,
    /// Size of the (compressed) records that follow the header, bytes.
    pub compressed_size: u64,
}

/// Bytes of a Chunk header up to and including its compression's length: start and end times,
/// uncompressed size and CRC, then the `u32` length of the compression string.
pub const CHUNK_HEADER_FIXED: usize = 8 + 8 + 8 + 4 + 4;

/// The length of a Chunk header from its first [`CHUNK_HEADER_FIXED`] bytes, checked against
/// the length of its record (`record_len`, the body's bytes).
pub fn chunk_header_len(
    fixed: &[u8; CHUNK_HEADER_FIXED],
    record_len: u64,
) -> Result<usize, McapProblem> {
    let min = (CHUNK_HEADER_FIXED + 8) as u64;
    if record_len < min {
        return Err(McapProblem::Truncated {
            field: "chunk header",
            needed: min,
            available: record_len,
        });
    }
    let claimed = u32::from_le_bytes([fixed[28], fixed[29], fixed[30], fixed[31]]);
    if u64::from(claimed) > record_len - min {
        return Err(McapProblem::FieldTooLong {
            field: "compression",
            claimed: u64::from(claimed),
            available: record_len - min,
        });
    }
    Ok(min as usize + claimed as usize)
}

/// A Chunk header (its [`chunk_header_len`] bytes), its records checked against the length of
/// its record (`record_len`): they must fit after the header. Bytes after them (padding) are
/// allowed, as by `mcap`.
pub fn chunk_header(head: &[u8], record_len: u64) -> Result<ChunkHeaderView<'_>, McapProblem> {
    let mut f = Fields::new(head);
    f.u64("message start time")?;
    f.u64("message end time")?;
    let uncompressed_size = f.u64("uncompressed size")?;
    f.u32("uncompressed CRC")?;
    let compression = f.string("compression")?;
    let compressed_size = f.u64("compressed size")?;
    let available = record_len.saturating_sub(f.pos as u64);
    if compressed_size > available {
        return Err(McapProblem::FieldTooLong {
            field: "records",
            claimed: compressed_size,
            available,
        });
    }
    Ok(ChunkHeaderView {
        uncompressed_size,
        compression,
        compressed_size,
    })
}

/// Where in an MCAP file a record is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum McapPlace {
    /// A record of the file, at this byte offset (its opcode).
    File {
        /// Byte offset in the file.
        offset: u64,
    },
    /// A record inside a chunk.
    Chunk {
        /// Byte offset of the chunk record in the file.
        chunk: u64,
        /// Byte offset of the record in the chunk's (decompressed) records.
        offset: u64,
    },
}

impl std::fmt::Display for McapPlace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            McapPlace::File { offset } => write!(f, "byte {offset}"),
            McapPlace::Chunk { chunk, offset } => write!(
                f,
                "byte {offset} of the records of the chunk at byte {chunk}"
            ),
        }
    }
}

/// A cursor over one record's bytes that checks every read against what remains.
struct Fields<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> Fields<'a> {
    fn new(buf: &'a [u8]) -> Self {
        Self { buf, pos: 0 }
    }

    fn left(&self) -> usize {
        self.buf.len() - self.pos
    }

    fn bytes(&mut self, n: usize, field: &'static str) -> Result<&'a [u8], McapProblem> {
        if n > self.left() {
            return Err(McapProblem::Truncated {
                field,
                needed: n as u64,
                available: self.left() as u64,
            });
        }
        let s = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], McapProblem> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.bytes(N, field)?);
        Ok(a)
    }

    fn u16(&mut self, field: &'static str) -> Result<u16, McapProblem> {
        self.array(field).map(u16::from_le_bytes)
    }

    fn u32(&mut self, field: &'static str) -> Result<u32, McapProblem> {
        self.array(field).map(u32::from_le_bytes)
    }

    fn u64(&mut self, field: &'static str) -> Result<u64, McapProblem> {
        self.array(field).map(u64::from_le_bytes)
    }

    /// A `u32` length, then that many bytes, checked against the bytes left (in the record, or the map).
    fn prefixed(&mut self, field: &'static str) -> Result<&'a [u8], McapProblem> {
        let claimed = self.u32(field)?;
        let available = self.left();
        if u64::from(claimed) > available as u64 {
            return Err(McapProblem::FieldTooLong {
                field,
                claimed: u64::from(claimed),
                available: available as u64,
            });
        }
        self.bytes(claimed as usize, field)
    }

    fn string(&mut self, field: &'static str) -> Result<&'a str, McapProblem> {
        let bytes = self.prefixed(field)?;
        std::str::from_utf8(bytes).map_err(|_| McapProblem::NotUtf8 { field })
    }
}

/// Check a map of string keys to string values: its byte length against the record, and each
/// entry against the map.
fn check_string_map(f: &mut Fields<'_>, field: &'static str) -> Result<(), McapProblem> {
    let map = f.prefixed(field)?;
    let mut entries = Fields::new(map);
    while entries.left() > 0 {
        entries.string("metadata key")?;
        entries.string("metadata value")?;
    }
    Ok(())
}

/// A Schema record's body.
pub fn schema(body: &[u8]) -> Result<SchemaView<'_>, McapProblem> {
    let mut f = Fields::new(body);
    let id = f.u16("schema id")?;
    let name = f.string("schema name")?;
    let encoding = f.string("schema encoding")?;
    f.prefixed("schema data")?;
    Ok(SchemaView { id, name, encoding })
}

/// A Channel record's body.
pub fn channel(body: &[u8]) -> Result<ChannelView<'_>, McapProblem> {
    let mut f = Fields::new(body);
    let id = f.u16("channel id")?;
    let schema_id = f.u16("schema id")?;
    let topic = f.string("topic")?;
    let message_encoding = f.string("message encoding")?;
    check_string_map(&mut f, "metadata")?;
    Ok(ChannelView {
        id,
        schema_id,
        topic,
        message_encoding,
    })
}

/// A Message record's body.
pub fn message(body: &[u8]) -> Result<MessageView<'_>, McapProblem> {
    let mut f = Fields::new(body);
    let header = MessageHeader {
        channel_id: f.u16("channel id")?,
        sequence: f.u32("sequence")?,
        log_time: f.u64("log time")?,
        publish_time: f.u64("publish time")?,
    };
    Ok(MessageView {
        header,
        data: &body[f.pos..],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn string(s: &str) -> Vec<u8> {
        let mut v = (s.len() as u32).to_le_bytes().to_vec();
        v.extend_from_slice(s.as_bytes());
        v
    }

    fn channel_body(topic: &str, metadata: &[(&str, &str)]) -> Vec<u8> {
        let mut v = vec![3, 0, 1, 0];
        v.extend(string(topic));
        v.extend(string("cdr"));
        let mut map = Vec::new();
        for (k, val) in metadata {
            map.extend(string(k));
            map.extend(string(val));
        }
        v.extend((map.len() as u32).to_le_bytes());
        v.extend(map);
        v
    }

    /// Every body the `mcap` crate parses is parsed here to the same fields.
    #[test]
    fn valid_records_read_as_mcap_reads_them() {
        let body = channel_body("/pose", &[("k", "v"), ("a", "")]);
        let c = channel(&body).unwrap();
        let m = match mcap::parse_record(mcap::records::op::CHANNEL, &body).unwrap() {
            mcap::records::Record::Channel(m) => m,
            r => panic!("{r:?}"),
        };
        assert_eq!((c.id, c.schema_id), (m.id, m.schema_id));
        assert_eq!(
            (c.topic, c.message_encoding),
            (&*m.topic, &*m.message_encoding)
        );

        let mut body = vec![7, 0];
        body.extend(string("geometry_msgs/msg/PoseStamped"));
        body.extend(string("ros2msg"));
        body.extend(string("float64 x"));
        let s = schema(&body).unwrap();
        assert_eq!(
            (s.id, s.name, s.encoding),
            (7, "geometry_msgs/msg/PoseStamped", "ros2msg")
        );

        let mut body = vec![3, 0, 9, 0, 0, 0];
        body.extend(5u64.to_le_bytes());
        body.extend(6u64.to_le_bytes());
        body.extend(b"payload");
        let m = message(&body).unwrap();
        assert_eq!(m.header.channel_id, 3);
        assert_eq!((m.header.sequence, m.header.log_time), (9, 5));
        assert_eq!(m.data, b"payload");
    }

    /// Every way of claiming more than the record holds: each string of a Channel, its map,
    /// an entry of the map, and the strings and data of a Schema.
    #[test]
    fn lengths_beyond_the_record_are_refused_naming_the_field() {
        let body = channel_body("/pose", &[("key", "value")]);
        // Offsets of the u32 lengths: topic at 4, encoding after "/pose", map after "cdr".
        let topic_at = 4;
        let encoding_at = topic_at + 4 + 5;
        let map_at = encoding_at + 4 + 3;
        let key_at = map_at + 4;
        for (at, field) in [
            (topic_at, "topic"),
            (encoding_at, "message encoding"),
            (map_at, "metadata"),
            (key_at, "metadata key"),
        ] {
            for claimed in [u32::MAX, 0xff00_0000, body.len() as u32] {
                let mut b = body.clone();
                b[at..at + 4].copy_from_slice(&claimed.to_le_bytes());
                match channel(&b) {
                    Err(McapProblem::FieldTooLong { field: f, .. }) => assert_eq!(f, field),
                    r => panic!("{field} = {claimed}: {r:?}"),
                }
            }
        }
        let mut body = vec![1, 0];
        body.extend(string("n"));
        body.extend(string("e"));
        body.extend(string("data"));
        for (at, field) in [
            (2, "schema name"),
            (7, "schema encoding"),
            (12, "schema data"),
        ] {
            let mut b = body.clone();
            b[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
            match schema(&b) {
                Err(McapProblem::FieldTooLong { field: f, .. }) => assert_eq!(f, field),
                r => panic!("{field}: {r:?}"),
            }
        }
        // A body cut anywhere is an error, never a panic.
        for cut in 0..body.len() {
            assert!(schema(&body[..cut]).is_err(), "{cut}");
        }
        let c = channel_body("/t", &[]);
        for cut in 0..c.len() {
            assert!(channel(&c[..cut]).is_err(), "{cut}");
        }
        assert!(message(&[0; 21]).is_err());
    }

    #[test]
    fn chunk_records_must_fit_in_the_chunk() {
        let mut head = Vec::new();
        head.extend(0u64.to_le_bytes());
        head.extend(0u64.to_le_bytes());
        head.extend(4u64.to_le_bytes());
        head.extend(0u32.to_le_bytes());
        head.extend(string("zstd"));
        head.extend(4u64.to_le_bytes());
        let fixed: [u8; CHUNK_HEADER_FIXED] = head[..CHUNK_HEADER_FIXED].try_into().unwrap();
        let record_len = head.len() as u64 + 4;
        assert_eq!(chunk_header_len(&fixed, record_len).unwrap(), head.len());
        let c = chunk_header(&head, record_len).unwrap();
        assert_eq!(
            (c.uncompressed_size, c.compression, c.compressed_size),
            (4, "zstd", 4)
        );
        // The records, then the compression string, claiming more than the record holds.
        assert!(matches!(
            chunk_header(&head, record_len - 1),
            Err(McapProblem::FieldTooLong {
                field: "records",
                claimed: 4,
                available: 3,
            })
        ));
        let mut fixed = fixed;
        fixed[28..32].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(
            chunk_header_len(&fixed, record_len),
            Err(McapProblem::FieldTooLong {
                field: "compression",
                ..
            })
        ));
        assert!(chunk_header_len(&fixed, 39).is_err());
    }
}
