//! Streaming MCAP reader: decodes the supported topics of a file into [`Sample`]s, one per message,
//! or one per instant for the topics aloft writes.
//!
//! # Memory
//! The file is read front to back from any `std::io::Read` (pipes too; a file truncated or
//! replaced while it is read gives an error, not the `SIGBUS` of a memory map). Only the records
//! aloft decodes are held in memory, one at a time: Schema, Channel and Message records of the
//! file, and one record of a chunk at a time (its compressed records are streamed through
//! `mcap`'s sans-I/O [`LinearReader`], which decompresses them). Any other record (attachments,
//! metadata, indexes, the summary) is skipped without being kept. Memory is bounded by the
//! largest decoded record, typically a few kB, whatever the file size.
//!
//! # Corrupt lengths
//! Every length read out of the file is checked before anything is allocated for it, so a
//! flipped byte is an error, never a multi-gigabyte allocation:
//! - Records of the file: none may claim more than remains of the file (when its size is known,
//!   [`McapSamples::with_input_len`]; [`McapSamples::open`] knows it): that is refused before
//!   anything is read, as the same error as a truncated file ([`LogError::Mcap`], at the
//!   record's byte offset). A record that is kept may not claim more than [`RECORD_LIMIT`]
//!   ([`LogError::McapCorrupt`]), and its buffer grows with the bytes actually read.
//! - Chunks: the header is read first and checked ([`crate::mcap_records::chunk_header_len`],
//!   [`crate::mcap_records::chunk_header`]: the compression string and the records must fit in
//!   the record; an uncompressed size over [`MAX_CHUNK_RATIO`] times the compressed size or
//!   over [`RECORD_LIMIT`] is refused). The records are then read by a [`LinearReader`] of
//!   their own whose record length limit is what the chunk holds, handed the compressed bytes
//!   in pieces of at most [`FILL_BYTES`]: a record inside a chunk cannot claim (and make the
//!   decompressor reserve) more than its chunk holds, nor run past it.
//! - Schema, Channel and Message records are parsed by [`crate::mcap_records`], which checks
//!   every string, byte array and map length against the record and allocates nothing; other
//!   records are not parsed at all.
//!
//! # Topic selection
//! Without named topics, each model channel (position, velocity, attitude, battery, ...) is taken
//! from the first topic, in order of appearance, whose type provides it; other topics of the same
//! type are counted but not decoded, so two pose sources are never mixed. Named topics are decoded
//! in the order given; a named topic that is missing or of an unsupported type is an error.
//!
//! # Samples
//! A message of a foreign file is one sample: its channels, at its time. aloft writes one
//! instant of a log or a mission as consecutive messages at one time (`/aloft/state`, then
//! `/aloft/pose`, `/aloft/power`, `/aloft/battery`: [`crate::mcap_write`]), and those are joined
//! back into one sample: a decoded message of a topic aloft writes (schema `aloft.*`, or
//! `foxglove.PoseInFrame` on `/aloft/pose`) joins the sample before it when that sample came
//! from such topics too, has the same time, and holds no message of the same topic yet (its
//! model channels are still empty). Anything else starts a new sample. The join holds one
//! sample at a time (the instant being assembled), so memory does not grow with the file, and a
//! log converted with `aloft convert` reads back with the samples of the original. (Two samples
//! of a source at one time are kept apart when both have motion or both battery data; a
//! battery-only sample followed by a motion-only one at the same time would be joined.)
//!
//! # Time
//! `time_s` is the message `log_time` (or, with [`McapTime::HeaderStamp`], the header stamp when
//! present) minus that of the first decoded message. Out-of-order times are reported in the
//! [`TimeReport`], not re-sorted.

use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use mcap::records::{op, MessageHeader};
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use serde::Serialize;

use crate::error::{LogError, Result};
use crate::mcap_records::{self, record_name, ChannelView, McapPlace, McapProblem};
use crate::mcap_write::TOPIC_POSE;
use crate::ros::{decode_cdr, decode_json, Decoded, MessageKind, RosDecodeOptions, SUPPORTED};
use crate::sample::{Channel, Sample, TimeChecker, TimeReport};

/// Largest record (or chunk, compressed or not) accepted, bytes.
pub const RECORD_LIMIT: usize = 256 << 20;

/// Largest accepted ratio of a chunk's declared uncompressed size to its compressed size
/// (flight data compress 3 to 20 times; 1000 leaves room for runs of zeros).
pub const MAX_CHUNK_RATIO: u64 = 1000;

/// A compressed chunk may always declare this many bytes uncompressed, whatever its ratio (a
/// tiny chunk of empty messages can compress more than [`MAX_CHUNK_RATIO`] times).
const MIN_CHUNK_LIMIT: u64 = 64 << 10;

/// Largest piece of input handed to the reader at once, bytes.
pub const FILL_BYTES: usize = 256 << 10;

/// A Footer record's body: summary start, summary offset start, summary CRC, bytes.
const FOOTER_LEN: u64 = 8 + 8 + 4;

/// A Message record's header: channel id, sequence, log time, publish time, bytes.
const MESSAGE_HEADER_LEN: u64 = 2 + 4 + 8 + 8;

/// Opcode and length before every record, bytes.
const RECORD_PREFIX: u64 = 1 + 8;

/// Which clock gives [`Sample::time_s`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum McapTime {
    /// The MCAP message `log_time` (always present, common to all topics).
    #[default]
    LogTime,
    /// The message header stamp when it has one and it is non-zero, else `log_time`.
    HeaderStamp,
}

/// Options of the MCAP reader.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct McapOptions {
    /// Topics to decode; empty: choose by type.
    pub topics: Vec<String>,
    /// Time source.
    pub time: McapTime,
    /// Decoder options.
    pub decode: RosDecodeOptions,
}

/// What the file says about one channel (topic), and what aloft did with it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TopicInfo {
    /// Topic name.
    pub topic: String,
    /// Schema name (`geometry_msgs/msg/PoseStamped`), empty without a schema.
    pub schema: String,
    /// Schema encoding (`ros2msg`, `jsonschema`, ...).
    pub schema_encoding: String,
    /// Message encoding (`cdr`, `json`, ...).
    pub message_encoding: String,
    /// Messages seen.
    pub messages: u64,
    /// Messages decoded into samples.
    pub decoded: u64,
    /// First and last `log_time`, ns.
    pub log_time_range_ns: Option<(u64, u64)>,
    /// Model channels taken from this topic.
    pub used_for: Vec<Channel>,
}

impl TopicInfo {
    /// Message rate from the `log_time` range, Hz (`None` below two messages).
    pub fn rate_hz(&self) -> Option<f64> {
        let (a, b) = self.log_time_range_ns?;
        (self.messages > 1 && b > a).then(|| (self.messages - 1) as f64 / ((b - a) as f64 * 1e-9))
    }

    /// Count a message logged at `log_time_ns`; returns its 0-based index on the topic.
    fn count_message(&mut self, log_time_ns: u64) -> u64 {
        let index = self.messages;
        self.messages += 1;
        self.log_time_range_ns = Some(match self.log_time_range_ns {
            None => (log_time_ns, log_time_ns),
            Some((a, b)) => (a.min(log_time_ns), b.max(log_time_ns)),
        });
        index
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Cdr,
    Json,
}

#[derive(Debug, Clone, Copy)]
struct ChanState {
    info: usize,
    decoder: Option<(MessageKind, Encoding)>,
    /// The channels this topic feeds (a copy of `TopicInfo::used_for`, kept here so the hot
    /// loop does not allocate).
    keep: [bool; 9],
    /// Whether the topic is one aloft writes: its messages of one instant are one sample.
    aloft: bool,
}

/// The sample being assembled from the messages of one instant (see the module docs).
#[derive(Debug, Clone, Copy)]
struct Instant {
    sample: Sample,
    /// The model channels of the topics that fed it (their [`ChanState::keep`] together).
    fed: [bool; 9],
    /// Whether another message at its time may still join it (it came from aloft's topics).
    open: bool,
}

impl Instant {
    /// Join the message `s` of a topic whose channels are `keep`, when it belongs to this
    /// instant; otherwise give it back.
    fn join(&mut self, s: Sample, keep: [bool; 9], aloft: bool) -> Option<Sample> {
        let same_time = self.sample.time_s.total_cmp(&s.time_s).is_eq();
        let disjoint = self.fed.iter().zip(&keep).all(|(a, b)| !(*a && *b));
        if !(aloft && self.open && same_time && disjoint) {
            return Some(s);
        }
        merge(&mut self.sample, &s);
        for (f, k) in self.fed.iter_mut().zip(keep) {
            *f |= k;
        }
        None
    }
}

/// Fill the channels `a` lacks from `b`. Every field is named, so a channel added to
/// [`Sample`] must be added here too.
fn merge(a: &mut Sample, b: &Sample) {
    let Sample {
        time_s: _,
        pos_enu_m,
        vel_enu_mps,
        acc_enu_mps2,
        attitude,
        voltage_v,
        current_a,
        power_w,
        charge_ah,
        soc,
        wind_enu_mps,
        landed,
    } = *b;
    a.pos_enu_m = a.pos_enu_m.or(pos_enu_m);
    a.vel_enu_mps = a.vel_enu_mps.or(vel_enu_mps);
    a.acc_enu_mps2 = a.acc_enu_mps2.or(acc_enu_mps2);
    a.attitude = a.attitude.or(attitude);
    a.voltage_v = a.voltage_v.or(voltage_v);
    a.current_a = a.current_a.or(current_a);
    a.power_w = a.power_w.or(power_w);
    a.charge_ah = a.charge_ah.or(charge_ah);
    a.soc = a.soc.or(soc);
    a.wind_enu_mps = a.wind_enu_mps.or(wind_enu_mps);
    a.landed = a.landed.or(landed);
}

/// Whether a channel is one aloft writes ([`crate::mcap_write`]): a schema of its own
/// (`aloft.VehicleState`, `aloft.BatteryState`, ...) or its pose topic.
fn written_by_aloft(topic: &str, schema: &str) -> bool {
    schema.starts_with("aloft.") || (topic == TOPIC_POSE && schema == "foxglove.PoseInFrame")
}

/// Samples of one MCAP file, decoded message by message.
pub struct McapSamples<R: Read> {
    input: R,
    /// Size of the input when known: no record may claim more than remains of it.
    input_len: Option<u64>,
    /// Bytes of the input read so far (the offset of what comes next).
    offset: u64,
    /// Where the reading is in the file's layout.
    at: At,
    /// The body of the record being decoded (reused).
    body: Vec<u8>,
    /// The chunk whose records are being read.
    chunk: Option<ChunkRecords>,
    records: RecordDecoder,
    done: bool,
}

/// Where the reading is in the file's layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum At {
    /// Before the start magic.
    Start,
    /// Before a record of the file.
    Record,
    /// In the records of a chunk (`self.chunk`), which `padding` bytes follow.
    Chunk { padding: u64 },
    /// After the footer: the end magic.
    EndMagic,
    /// After the end magic.
    End,
}

/// The records of one chunk, read by a [`LinearReader`] of their own: it is handed the chunk's
/// header, then the compressed records as it asks for them, and its record length limit is what
/// the chunk holds.
struct ChunkRecords {
    reader: LinearReader,
    /// The reader's record length limit, bytes.
    limit: usize,
    /// Compressed bytes of the chunk not yet handed to the reader.
    compressed_left: u64,
    /// Byte offset of the chunk record in the file.
    at: u64,
    /// Byte offset of the next record in the chunk's records.
    offset: u64,
}

impl ChunkRecords {
    /// Check the chunk at byte `at`, whose header is `head`, and set up the reading of its
    /// records.
    fn new(head: &[u8], record_len: u64, at: u64) -> std::result::Result<Self, McapProblem> {
        let header = mcap_records::chunk_header(head, record_len)?;
        let compressed = header.compressed_size;
        if !header.compression.is_empty() {
            let most = (RECORD_LIMIT as u64).min(
                compressed
                    .saturating_mul(MAX_CHUNK_RATIO)
                    .max(MIN_CHUNK_LIMIT),
            );
            if header.uncompressed_size > most {
                return Err(McapProblem::ChunkSize {
                    uncompressed: header.uncompressed_size,
                    compressed,
                    max_ratio: MAX_CHUNK_RATIO,
                    limit: RECORD_LIMIT as u64,
                });
            }
        }
        // No record inside can be longer than the chunk's records, compressed or not (the
        // header's own length is checked against the limit too: never below it), nor than
        // RECORD_LIMIT: an uncompressed chunk's declared size is not checked above, and a
        // corrupt one (u64::MAX) must not lift the limit, or a record length near u64::MAX
        // overflows in the `mcap` reader (a panic, found by aloft-fuzz).
        let limit = header
            .uncompressed_size
            .max(compressed)
            .max(MIN_CHUNK_LIMIT)
            .min(RECORD_LIMIT as u64) as usize;
        let mut reader = LinearReader::new_with_options(
            LinearReaderOptions::default()
                .with_skip_start_magic(true)
                .with_skip_end_magic(true)
                .with_record_length_limit(limit),
        );
        // The chunk record without what follows its records: a record cannot run into padding.
        let len = RECORD_PREFIX as usize + head.len();
        let buf = reader.insert(len);
        buf[0] = op::CHUNK;
        buf[1..9].copy_from_slice(&(head.len() as u64 + compressed).to_le_bytes());
        buf[9..len].copy_from_slice(head);
        reader.notify_read(len);
        Ok(Self {
            reader,
            limit,
            compressed_left: compressed,
            at,
            offset: 0,
        })
    }

    fn place(&self) -> McapPlace {
        McapPlace::Chunk {
            chunk: self.at,
            offset: self.offset,
        }
    }
}

/// What one step of the reader gave. (It lives on the stack for one step; boxing the sample would
/// allocate once per message.)
#[allow(clippy::large_enum_variant)]
enum Step {
    /// A record decoded into a sample.
    Sample(Sample),
    /// Nothing yet.
    More,
    /// The end of the file.
    End,
}

/// The sans-I/O half of [`McapSamples`]: what the records seen so far say (schemas, channels,
/// topics, the time base), and the decoding of the next record into a sample.
struct RecordDecoder {
    path: PathBuf,
    options: McapOptions,
    schemas: HashMap<u16, (String, String)>,
    channels: HashMap<u16, ChanState>,
    topics: Vec<TopicInfo>,
    claimed: HashMap<Channel, u16>,
    start_s: Option<f64>,
    start_log_time_ns: Option<u64>,
    checker: TimeChecker,
    messages: u64,
    /// The sample being assembled (one instant), not yet given out.
    instant: Option<Instant>,
}

impl McapSamples<std::io::BufReader<File>> {
    /// Open a file.
    ///
    /// A FIFO, device or directory is refused before it is opened.
    pub fn open(path: &Path, options: McapOptions) -> Result<Self> {
        let f = aloft_core::open_regular_file(path).map_err(LogError::reading(path))?;
        let len = f.metadata().map_err(LogError::reading(path))?.len();
        Ok(
            Self::from_reader(std::io::BufReader::with_capacity(1 << 16, f), path, options)
                .with_input_len(len),
        )
    }
}

fn decoder_for(
    schema: &str,
    schema_encoding: &str,
    message_encoding: &str,
) -> Option<(MessageKind, Encoding)> {
    let kind = MessageKind::from_schema_name(schema)?;
    match message_encoding {
        "cdr"
            if kind != MessageKind::AloftState
                && matches!(schema_encoding, "ros2msg" | "ros2idl" | "") =>
        {
            Some((kind, Encoding::Cdr))
        }
        "json" => Some((kind, Encoding::Json)),
        _ => None,
    }
}

fn mask(s: &mut Sample, keep: &[bool; 9]) {
    for (c, k) in Channel::ALL.into_iter().zip(keep) {
        if *k {
            continue;
        }
        match c {
            Channel::Position => s.pos_enu_m = None,
            Channel::Velocity => s.vel_enu_mps = None,
            Channel::Acceleration => s.acc_enu_mps2 = None,
            Channel::Attitude => s.attitude = None,
            Channel::Voltage => s.voltage_v = None,
            Channel::Current => s.current_a = None,
            Channel::Power => s.power_w = None,
            Channel::Charge => s.charge_ah = None,
            Channel::Wind => s.wind_enu_mps = None,
        }
    }
}

impl<R: Read> McapSamples<R> {
    /// Read from any reader; `path` names the source in errors.
    pub fn from_reader(input: R, path: &Path, options: McapOptions) -> Self {
        Self {
            input,
            input_len: None,
            offset: 0,
            at: At::Start,
            body: Vec::new(),
            chunk: None,
            records: RecordDecoder {
                path: path.to_path_buf(),
                options,
                schemas: HashMap::new(),
                channels: HashMap::new(),
                topics: Vec::new(),
                claimed: HashMap::new(),
                start_s: None,
                start_log_time_ns: None,
                checker: TimeChecker::new(),
                messages: 0,
                instant: None,
            },
            done: false,
        }
    }

    /// Declare the size of the input, bytes (before reading): no record may then claim more
    /// than the input holds, nor more than remains of it after the record's offset.
    /// [`Self::open`] does this with the file's size.
    pub fn with_input_len(mut self, len: u64) -> Self {
        self.input_len = Some(len);
        self
    }

    /// The topics seen so far (all of them once the stream is exhausted), in order of appearance.
    pub fn topics(&self) -> &[TopicInfo] {
        &self.records.topics
    }

    /// Messages read so far, on all topics.
    pub fn messages(&self) -> u64 {
        self.records.messages
    }

    /// Absolute time of the first decoded sample, s (Unix time for most recorders).
    pub fn start_time_s(&self) -> Option<f64> {
        self.records.start_s
    }

    /// Time report of the decoded samples so far.
    pub fn time_report(&self) -> TimeReport {
        self.records.checker.clone().finish()
    }

    /// The channels that are being decoded and from which topic.
    pub fn claimed(&self) -> Vec<(Channel, String)> {
        let records = &self.records;
        let mut v: Vec<(Channel, String)> = records
            .claimed
            .iter()
            .filter_map(|(c, id)| {
                let st = records.channels.get(id)?;
                Some((*c, records.topics[st.info].topic.clone()))
            })
            .collect();
        v.sort();
        v
    }

    /// The next sample: read until a record decodes into one, or the file ends.
    fn step(&mut self) -> Result<Option<Sample>> {
        loop {
            let step = match self.at {
                At::Start => self.magic(At::Record)?,
                At::Record => self.file_record()?,
                At::Chunk { padding } => self.chunk_step(padding)?,
                At::EndMagic => self.magic(At::End)?,
                At::End => Step::End,
            };
            match step {
                Step::Sample(s) => return Ok(Some(s)),
                Step::More => {}
                Step::End => {
                    if let Some(s) = self.records.flush() {
                        return Ok(Some(s));
                    }
                    self.done = true;
                    self.records.finish_checks()?;
                    return Ok(None);
                }
            }
        }
    }

    /// The magic at the start or end of the file; `next` is what follows it.
    fn magic(&mut self, next: At) -> Result<Step> {
        let place = self.file_place();
        self.read_body(mcap::MAGIC.len() as u64, place)?;
        if self.body != mcap::MAGIC {
            return Err(self.records.mcap_error(place, mcap::McapError::BadMagic));
        }
        self.at = next;
        Ok(Step::More)
    }

    /// The next record of the file: Schema, Channel and Message records are read and decoded,
    /// a chunk's records are read next, the footer leads to the end magic, and any other record
    /// is skipped unread.
    fn file_record(&mut self) -> Result<Step> {
        let place = self.file_place();
        self.read_body(RECORD_PREFIX, place)?;
        let opcode = self.body[0];
        let mut len = [0u8; 8];
        len.copy_from_slice(&self.body[1..9]);
        let len = u64::from_le_bytes(len);
        self.check_remaining(len, place)?;
        match opcode {
            op::MESSAGE if len >= MESSAGE_HEADER_LEN => self.file_message(len, place),
            op::SCHEMA | op::CHANNEL | op::MESSAGE | op::FOOTER => {
                if len > RECORD_LIMIT as u64 {
                    let problem = McapProblem::RecordTooLong {
                        claimed: len,
                        limit: RECORD_LIMIT as u64,
                    };
                    return Err(self.records.corrupt(opcode, place, problem));
                }
                if opcode == op::FOOTER && len < FOOTER_LEN {
                    let problem = McapProblem::Truncated {
                        field: "footer",
                        needed: FOOTER_LEN,
                        available: len,
                    };
                    return Err(self.records.corrupt(opcode, place, problem));
                }
                self.read_body(len, place)?;
                if opcode == op::FOOTER {
                    self.at = At::EndMagic;
                    return Ok(Step::More);
                }
                let body = std::mem::take(&mut self.body);
                let sample = self.records.on_record(opcode, &body, place);
                self.body = body;
                Ok(sample?.map_or(Step::More, Step::Sample))
            }
            op::CHUNK => {
                self.start_chunk(len, place)?;
                Ok(Step::More)
            }
            _ => {
                self.skip(len, place)?;
                Ok(Step::More)
            }
        }
    }

    /// A Message record of the file, `len` bytes long: its header is read, and its data only if
    /// its topic is decoded (otherwise it is counted and skipped).
    fn file_message(&mut self, len: u64, place: McapPlace) -> Result<Step> {
        self.read_body(MESSAGE_HEADER_LEN, place)?;
        let header = mcap_records::message(&self.body)
            .map_err(|p| self.records.corrupt(op::MESSAGE, place, p))?
            .header;
        if !self.records.decodes(header.channel_id) {
            let counted = self.records.on_message(&header, &[], place);
            self.skip(len - MESSAGE_HEADER_LEN, place)?;
            return counted.map(|s| s.map_or(Step::More, Step::Sample));
        }
        if len > RECORD_LIMIT as u64 {
            let problem = McapProblem::RecordTooLong {
                claimed: len,
                limit: RECORD_LIMIT as u64,
            };
            return Err(self.records.corrupt(op::MESSAGE, place, problem));
        }
        self.read_more(len - MESSAGE_HEADER_LEN, place)?;
        let body = std::mem::take(&mut self.body);
        let sample = self.records.on_record(op::MESSAGE, &body, place);
        self.body = body;
        Ok(sample?.map_or(Step::More, Step::Sample))
    }

    /// Read and check the header of the chunk at `place`, whose record is `len` bytes long, and
    /// set up the reading of its records.
    fn start_chunk(&mut self, len: u64, place: McapPlace) -> Result<()> {
        let McapPlace::File { offset: at } = place else {
            return Ok(());
        };
        let corrupt = |me: &Self, problem| me.records.corrupt(op::CHUNK, place, problem);
        let fixed_len = mcap_records::CHUNK_HEADER_FIXED;
        let head_len = {
            let mut fixed = [0u8; mcap_records::CHUNK_HEADER_FIXED];
            self.body.clear();
            if len >= fixed_len as u64 {
                self.read_body(fixed_len as u64, place)?;
                fixed.copy_from_slice(&self.body);
            }
            mcap_records::chunk_header_len(&fixed, len).map_err(|p| corrupt(self, p))?
        };
        self.read_more((head_len - fixed_len) as u64, place)?;
        let chunk = ChunkRecords::new(&self.body, len, at).map_err(|p| corrupt(self, p))?;
        self.at = At::Chunk {
            padding: len - head_len as u64 - chunk.compressed_left,
        };
        self.chunk = Some(chunk);
        Ok(())
    }

    /// One event of the current chunk's reader: a record, a read of compressed records, or the
    /// end of the chunk (then its `padding` is skipped).
    fn chunk_step(&mut self, padding: u64) -> Result<Step> {
        let Some(chunk) = self.chunk.as_mut() else {
            self.at = At::Record;
            return Ok(Step::More);
        };
        let (place, limit) = (chunk.place(), chunk.limit);
        let event = match chunk.reader.next_event() {
            None => {
                let at = McapPlace::File { offset: chunk.at };
                self.chunk = None;
                self.skip(padding, at)?;
                self.at = At::Record;
                return Ok(Step::More);
            }
            Some(event) => event.map_err(|e| self.records.reader_error(place, e, limit))?,
        };
        match event {
            LinearReadEvent::ReadRequest(n) => {
                let at = McapPlace::File { offset: chunk.at };
                let want = (n.min(FILL_BYTES) as u64).min(chunk.compressed_left) as usize;
                let buf = chunk.reader.insert(want);
                let got = read_some(&mut self.input, buf)
                    .map_err(LogError::reading(&self.records.path))?;
                chunk.reader.notify_read(got);
                chunk.compressed_left -= got as u64;
                self.offset += got as u64;
                if got == 0 && want > 0 {
                    return Err(self.records.mcap_error(at, mcap::McapError::UnexpectedEof));
                }
                Ok(Step::More)
            }
            LinearReadEvent::Record { opcode, data } => {
                chunk.offset += RECORD_PREFIX + data.len() as u64;
                Ok(self
                    .records
                    .on_record(opcode, data, place)?
                    .map_or(Step::More, Step::Sample))
            }
        }
    }

    /// The place of the next record of the file.
    fn file_place(&self) -> McapPlace {
        McapPlace::File {
            offset: self.offset,
        }
    }

    /// A record at `place` may not claim more than remains of an input of known size: that is
    /// the error of a truncated file, given before anything is read or allocated.
    fn check_remaining(&self, len: u64, place: McapPlace) -> Result<()> {
        match self.input_len {
            Some(total) if len > total.saturating_sub(self.offset) => Err(self
                .records
                .mcap_error(place, mcap::McapError::UnexpectedEof)),
            _ => Ok(()),
        }
    }

    /// Read the next `n` bytes into `self.body`, for the record at `place`. The buffer grows
    /// with the bytes actually read, whatever `n` claims.
    fn read_body(&mut self, n: u64, place: McapPlace) -> Result<()> {
        self.body.clear();
        self.read_more(n, place)
    }

    /// Read the next `n` bytes onto the end of `self.body`, as [`Self::read_body`].
    fn read_more(&mut self, n: u64, place: McapPlace) -> Result<()> {
        self.check_remaining(n, place)?;
        let got = (&mut self.input)
            .take(n)
            .read_to_end(&mut self.body)
            .map_err(LogError::reading(&self.records.path))?;
        self.offset += got as u64;
        if (got as u64) < n {
            return Err(self
                .records
                .mcap_error(place, mcap::McapError::UnexpectedEof));
        }
        Ok(())
    }

    /// Skip the next `n` bytes (a record aloft does not use), without keeping them.
    fn skip(&mut self, n: u64, place: McapPlace) -> Result<()> {
        self.check_remaining(n, place)?;
        let got = std::io::copy(&mut (&mut self.input).take(n), &mut std::io::sink())
            .map_err(LogError::reading(&self.records.path))?;
        self.offset += got;
        if got < n {
            return Err(self
                .records
                .mcap_error(place, mcap::McapError::UnexpectedEof));
        }
        Ok(())
    }
}

/// One `read` into `buf`, retried when interrupted.
fn read_some(input: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    loop {
        match input.read(buf) {
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            r => return r,
        }
    }
}

impl RecordDecoder {
    /// [`LogError::Mcap`] at `place`, after the messages read so far.
    fn mcap_error(&self, place: McapPlace, cause: mcap::McapError) -> LogError {
        LogError::Mcap {
            path: self.path.clone(),
            place,
            messages: self.messages,
            cause,
        }
    }

    /// The error of a reader whose record length limit is `limit`: a record over the limit is
    /// [`LogError::McapCorrupt`], anything else [`LogError::Mcap`].
    fn reader_error(&self, place: McapPlace, cause: mcap::McapError, limit: usize) -> LogError {
        match cause {
            mcap::McapError::RecordTooLarge { opcode, len } => self.corrupt(
                opcode,
                place,
                McapProblem::RecordTooLong {
                    claimed: len,
                    limit: limit as u64,
                },
            ),
            cause => self.mcap_error(place, cause),
        }
    }

    /// [`LogError::McapCorrupt`]: the record `opcode` at `place` is invalid.
    fn corrupt(&self, opcode: u8, place: McapPlace, problem: McapProblem) -> LogError {
        LogError::McapCorrupt {
            path: self.path.clone(),
            record: record_name(opcode),
            place,
            messages: self.messages,
            problem,
        }
    }

    /// Whether messages on channel `id` are decoded (an unknown channel is, so that its first
    /// message is the error).
    fn decodes(&self, id: u16) -> bool {
        self.channels.get(&id).is_none_or(|c| c.decoder.is_some())
    }

    /// One record: schemas and new channels are remembered; a message on a decoded topic is a
    /// sample. Records aloft does not use are not parsed.
    fn on_record(&mut self, opcode: u8, data: &[u8], place: McapPlace) -> Result<Option<Sample>> {
        let corrupt = |d: &Self, e| d.corrupt(opcode, place, e);
        match opcode {
            op::SCHEMA => {
                let s = mcap_records::schema(data).map_err(|e| corrupt(self, e))?;
                self.schemas
                    .insert(s.id, (s.name.to_string(), s.encoding.to_string()));
            }
            op::CHANNEL => {
                let ch = mcap_records::channel(data).map_err(|e| corrupt(self, e))?;
                if !self.channels.contains_key(&ch.id) {
                    self.add_channel(&ch)?;
                }
            }
            op::MESSAGE => {
                let m = mcap_records::message(data).map_err(|e| corrupt(self, e))?;
                return self.on_message(&m.header, m.data, place);
            }
            _ => {}
        }
        Ok(None)
    }

    fn add_channel(&mut self, ch: &ChannelView<'_>) -> Result<()> {
        let (schema, schema_encoding) =
            self.schemas.get(&ch.schema_id).cloned().unwrap_or_default();
        let decoder = decoder_for(&schema, &schema_encoding, ch.message_encoding);
        let aloft = written_by_aloft(ch.topic, &schema);
        let info = self.topics.len();
        let named = self.options.topics.iter().position(|t| *t == ch.topic);
        if !self.options.topics.is_empty() && named.is_some() && decoder.is_none() {
            return Err(LogError::UnsupportedTopic {
                path: self.path.clone(),
                topic: ch.topic.to_string(),
                schema: schema.clone(),
                encoding: ch.message_encoding.to_string(),
                supported: SUPPORTED,
            });
        }
        let wanted = self.options.topics.is_empty() || named.is_some();
        let mut used_for = Vec::new();
        if let (Some((kind, _)), true) = (decoder, wanted) {
            for c in kind.provides() {
                if let std::collections::hash_map::Entry::Vacant(e) = self.claimed.entry(*c) {
                    e.insert(ch.id);
                    used_for.push(*c);
                }
            }
        }
        self.topics.push(TopicInfo {
            topic: ch.topic.to_string(),
            schema,
            schema_encoding,
            message_encoding: ch.message_encoding.to_string(),
            messages: 0,
            decoded: 0,
            log_time_range_ns: None,
            used_for: used_for.clone(),
        });
        let mut keep = [false; 9];
        for (k, c) in keep.iter_mut().zip(Channel::ALL) {
            *k = used_for.contains(&c);
        }
        self.channels.insert(
            ch.id,
            ChanState {
                info,
                decoder: if used_for.is_empty() { None } else { decoder },
                keep,
                aloft,
            },
        );
        Ok(())
    }

    /// A message: counted on its topic, and decoded into a sample when the topic feeds a
    /// channel.
    fn on_message(
        &mut self,
        header: &MessageHeader,
        data: &[u8],
        place: McapPlace,
    ) -> Result<Option<Sample>> {
        self.messages += 1;
        let Some(&st) = self.channels.get(&header.channel_id) else {
            return Err(LogError::Mcap {
                path: self.path.clone(),
                place,
                messages: self.messages - 1,
                cause: mcap::McapError::UnknownChannel(header.sequence, header.channel_id),
            });
        };
        let index = self.topics[st.info].count_message(header.log_time);
        let Some((kind, encoding)) = st.decoder else {
            return Ok(None);
        };
        let decoded = self.decode(st.info, index, kind, encoding, data)?;
        self.topics[st.info].decoded += 1;
        let mut s = decoded.sample;
        mask(&mut s, &st.keep);
        s.time_s = self.sample_time_s(header.log_time, decoded.stamp_s);
        Ok(self.join(s, st.keep, st.aloft))
    }

    /// A decoded message, into the instant being assembled (see the module docs): the sample
    /// that instant completes, if any.
    fn join(&mut self, s: Sample, keep: [bool; 9], aloft: bool) -> Option<Sample> {
        let s = match self.instant.as_mut() {
            Some(instant) => instant.join(s, keep, aloft)?,
            // A message of another writer with nothing held: nothing can join it, so it is a
            // sample as it is (the common case of a foreign file, without a copy into the
            // instant and out).
            None if !aloft => return Some(self.emit(s)),
            None => s,
        };
        let done = self.instant.replace(Instant {
            sample: s,
            fed: keep,
            open: aloft,
        });
        done.map(|i| self.emit(i.sample))
    }

    /// The instant still being assembled, at the end of the file.
    fn flush(&mut self) -> Option<Sample> {
        let i = self.instant.take()?;
        Some(self.emit(i.sample))
    }

    /// A sample given out: its time is checked.
    fn emit(&mut self, s: Sample) -> Sample {
        self.checker.push(s.time_s);
        s
    }

    /// Decode message `index` of topic `info`.
    fn decode(
        &self,
        info: usize,
        index: u64,
        kind: MessageKind,
        encoding: Encoding,
        data: &[u8],
    ) -> Result<Decoded> {
        let info = &self.topics[info];
        match encoding {
            Encoding::Cdr => {
                decode_cdr(kind, data, self.options.decode).map_err(|cause| LogError::Cdr {
                    path: self.path.clone(),
                    topic: info.topic.clone(),
                    index,
                    schema: info.schema.clone(),
                    cause,
                })
            }
            Encoding::Json => decode_json(kind, data, self.options.decode).map_err(|message| {
                LogError::JsonMessage {
                    path: self.path.clone(),
                    topic: info.topic.clone(),
                    index,
                    message,
                }
            }),
        }
    }

    /// Time of a sample since the first decoded one, s, on the clock the options choose.
    fn sample_time_s(&mut self, log_time_ns: u64, stamp_s: Option<f64>) -> f64 {
        let t_abs = match (self.options.time, stamp_s) {
            (McapTime::HeaderStamp, Some(t)) => t,
            _ => log_time_ns as f64 * 1e-9,
        };
        if self.start_log_time_ns.is_none() {
            self.start_log_time_ns = Some(log_time_ns);
        }
        let start = *self.start_s.get_or_insert(t_abs);
        match self.options.time {
            // Integer nanoseconds: no loss of resolution for Unix times.
            McapTime::LogTime => {
                let t0 = self.start_log_time_ns.unwrap_or(log_time_ns);
                (i128::from(log_time_ns) - i128::from(t0)) as f64 * 1e-9
            }
            McapTime::HeaderStamp => t_abs - start,
        }
    }

    fn finish_checks(&self) -> Result<()> {
        for t in &self.options.topics {
            if !self.topics.iter().any(|i| i.topic == *t) {
                return Err(LogError::TopicNotFound {
                    path: self.path.clone(),
                    topic: t.clone(),
                    available: self
                        .topics
                        .iter()
                        .map(|i| i.topic.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                });
            }
        }
        if self.messages == 0 {
            return Err(LogError::Empty {
                path: self.path.clone(),
                what: "no messages".into(),
            });
        }
        Ok(())
    }
}

impl<R: Read> Iterator for McapSamples<R> {
    type Item = Result<Sample>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        match self.step() {
            Ok(Some(s)) => Some(Ok(s)),
            Ok(None) => None,
            Err(e) => {
                self.done = true;
                Some(Err(e))
            }
        }
    }
}

impl<R: Read> McapSamples<R> {
    /// Read to the end, discarding samples: fills [`Self::topics`] (for listing a file).
    pub fn drain(&mut self) -> Result<()> {
        for s in self.by_ref() {
            s?;
        }
        Ok(())
    }
}
