//! Streaming MCAP reader: decodes the supported topics of a file into [`Sample`]s, one per message.
//!
//! # Memory
//! The file is read through `mcap`'s sans-I/O [`LinearReader`] from any `std::io::Read`, in
//! requests of the size the reader asks for: memory is bounded by the largest record or
//! (decompressed) chunk, typically a few MB, whatever the file size. This is preferred over
//! memory-mapping because it also works on pipes, and a file truncated or replaced while it is
//! being read gives an I/O error instead of a `SIGBUS`. A record whose length field exceeds
//! [`RECORD_LIMIT`] (a corrupt length) is refused before anything is allocated for it.
//!
//! # Topic selection
//! Without named topics, each model channel (position, velocity, attitude, battery, ...) is taken
//! from the first topic, in order of appearance, whose type provides it; other topics of the same
//! type are counted but not decoded, so two pose sources are never mixed. Named topics are decoded
//! in the order given; a named topic that is missing or of an unsupported type is an error.
//!
//! # Time
//! `time_s` is the message `log_time` (or, with [`McapTime::HeaderStamp`], the header stamp when
//! present) minus that of the first decoded message. Out-of-order times are reported in the
//! [`TimeReport`], not re-sorted.

use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use mcap::records::MessageHeader;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use serde::Serialize;

use crate::error::{LogError, Result};
use crate::ros::{decode_cdr, decode_json, Decoded, MessageKind, RosDecodeOptions, SUPPORTED};
use crate::sample::{Channel, Sample, TimeChecker, TimeReport};

/// Largest record (or chunk) accepted, bytes.
pub const RECORD_LIMIT: usize = 256 << 20;

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
}

/// Samples of one MCAP file, decoded message by message.
pub struct McapSamples<R: Read> {
    input: R,
    reader: LinearReader,
    records: RecordDecoder,
    done: bool,
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
}

impl McapSamples<std::io::BufReader<File>> {
    /// Open a file.
    pub fn open(path: &Path, options: McapOptions) -> Result<Self> {
        let f = File::open(path).map_err(LogError::reading(path))?;
        Ok(Self::from_reader(
            std::io::BufReader::with_capacity(1 << 16, f),
            path,
            options,
        ))
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
        let reader = LinearReader::new_with_options(
            LinearReaderOptions::default().with_record_length_limit(RECORD_LIMIT),
        );
        Self {
            input,
            reader,
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
            },
            done: false,
        }
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

    /// The next sample: feed the reader until a record decodes into one, or the file ends.
    fn step(&mut self) -> Result<Option<Sample>> {
        loop {
            let event = match self.reader.next_event() {
                None => {
                    self.done = true;
                    self.records.finish_checks()?;
                    return Ok(None);
                }
                Some(event) => event.map_err(|e| self.records.mcap_error(e))?,
            };
            match event {
                LinearReadEvent::ReadRequest(n) => self.fill(n)?,
                LinearReadEvent::Record { opcode, data } => {
                    if let Some(s) = self.records.on_record(opcode, data)? {
                        return Ok(Some(s));
                    }
                }
            }
        }
    }

    /// Hand the reader up to `n` bytes of input (0 at the end of the input).
    fn fill(&mut self, n: usize) -> Result<()> {
        let buf = self.reader.insert(n);
        let got = loop {
            match self.input.read(buf) {
                Ok(k) => break k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(cause) => return Err(LogError::reading(&self.records.path)(cause)),
            }
        };
        self.reader.notify_read(got);
        Ok(())
    }
}

impl RecordDecoder {
    /// [`LogError::Mcap`] after the messages read so far.
    fn mcap_error(&self, cause: mcap::McapError) -> LogError {
        LogError::Mcap {
            path: self.path.clone(),
            messages: self.messages,
            cause,
        }
    }

    /// One record: schemas and new channels are remembered; a message on a decoded topic is a
    /// sample.
    fn on_record(&mut self, opcode: u8, data: &[u8]) -> Result<Option<Sample>> {
        match mcap::parse_record(opcode, data).map_err(|e| self.mcap_error(e))? {
            mcap::records::Record::Schema { header, .. } => {
                self.schemas
                    .insert(header.id, (header.name, header.encoding));
            }
            mcap::records::Record::Channel(ch) if !self.channels.contains_key(&ch.id) => {
                self.add_channel(ch)?;
            }
            mcap::records::Record::Message { header, data } => {
                return self.on_message(&header, &data);
            }
            _ => {}
        }
        Ok(None)
    }

    fn add_channel(&mut self, ch: mcap::records::Channel) -> Result<()> {
        let (schema, schema_encoding) =
            self.schemas.get(&ch.schema_id).cloned().unwrap_or_default();
        let decoder = decoder_for(&schema, &schema_encoding, &ch.message_encoding);
        let info = self.topics.len();
        let named = self.options.topics.iter().position(|t| *t == ch.topic);
        if !self.options.topics.is_empty() && named.is_some() && decoder.is_none() {
            return Err(LogError::UnsupportedTopic {
                path: self.path.clone(),
                topic: ch.topic.clone(),
                schema: schema.clone(),
                encoding: ch.message_encoding.clone(),
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
            topic: ch.topic.clone(),
            schema,
            schema_encoding,
            message_encoding: ch.message_encoding.clone(),
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
            },
        );
        Ok(())
    }

    /// A message: counted on its topic, and decoded into a sample when the topic feeds a
    /// channel.
    fn on_message(&mut self, header: &MessageHeader, data: &[u8]) -> Result<Option<Sample>> {
        self.messages += 1;
        let Some(&st) = self.channels.get(&header.channel_id) else {
            return Err(LogError::Mcap {
                path: self.path.clone(),
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
        self.checker.push(s.time_s);
        Ok(Some(s))
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
