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

use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use serde::Serialize;

use crate::error::{LogError, Result};
use crate::ros::{decode_cdr, decode_json, MessageKind, RosDecodeOptions, SUPPORTED};
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
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Cdr,
    Json,
}

#[derive(Debug, Clone)]
struct ChanState {
    info: usize,
    decoder: Option<(MessageKind, Encoding)>,
    /// The channels this topic feeds (a copy of `TopicInfo::used_for`, kept here so the hot
    /// loop does not allocate).
    keep: [bool; 9],
}

/// Samples of one MCAP file, decoded message by message.
pub struct McapSamples<R: Read> {
    path: PathBuf,
    input: R,
    reader: LinearReader,
    options: McapOptions,
    schemas: HashMap<u16, (String, String)>,
    channels: HashMap<u16, ChanState>,
    topics: Vec<TopicInfo>,
    claimed: HashMap<Channel, u16>,
    start_s: Option<f64>,
    start_log_time_ns: Option<u64>,
    checker: TimeChecker,
    messages: u64,
    done: bool,
}

impl McapSamples<std::io::BufReader<File>> {
    /// Open a file.
    pub fn open(path: &Path, options: McapOptions) -> Result<Self> {
        let f = File::open(path).map_err(|cause| LogError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
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
            path: path.to_path_buf(),
            input,
            reader,
            options,
            schemas: HashMap::new(),
            channels: HashMap::new(),
            topics: Vec::new(),
            claimed: HashMap::new(),
            start_s: None,
            start_log_time_ns: None,
            checker: TimeChecker::new(),
            messages: 0,
            done: false,
        }
    }

    /// The topics seen so far (all of them once the stream is exhausted), in order of appearance.
    pub fn topics(&self) -> &[TopicInfo] {
        &self.topics
    }

    /// Messages read so far, on all topics.
    pub fn messages(&self) -> u64 {
        self.messages
    }

    /// Absolute time of the first decoded sample, s (Unix time for most recorders).
    pub fn start_time_s(&self) -> Option<f64> {
        self.start_s
    }

    /// Time report of the decoded samples so far.
    pub fn time_report(&self) -> TimeReport {
        self.checker.clone().finish()
    }

    /// The channels that are being decoded and from which topic.
    pub fn claimed(&self) -> Vec<(Channel, String)> {
        let mut v: Vec<(Channel, String)> = self
            .claimed
            .iter()
            .filter_map(|(c, id)| {
                let st = self.channels.get(id)?;
                Some((*c, self.topics[st.info].topic.clone()))
            })
            .collect();
        v.sort();
        v
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

    fn step(&mut self) -> Result<Option<Sample>> {
        loop {
            let event = match self.reader.next_event() {
                None => {
                    self.done = true;
                    self.finish_checks()?;
                    return Ok(None);
                }
                Some(Err(e)) => {
                    let e = LogError::Mcap {
                        path: self.path.clone(),
                        messages: self.messages,
                        cause: e,
                    };
                    return Err(e);
                }
                Some(Ok(ev)) => ev,
            };
            match event {
                LinearReadEvent::ReadRequest(n) => {
                    let buf = self.reader.insert(n);
                    let got = loop {
                        match self.input.read(buf) {
                            Ok(k) => break k,
                            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                            Err(cause) => {
                                return Err(LogError::Io {
                                    path: self.path.clone(),
                                    cause,
                                })
                            }
                        }
                    };
                    self.reader.notify_read(got);
                }
                LinearReadEvent::Record { opcode, data } => {
                    let record = match mcap::parse_record(opcode, data) {
                        Ok(r) => r,
                        Err(e) => {
                            return Err(LogError::Mcap {
                                path: self.path.clone(),
                                messages: self.messages,
                                cause: e,
                            })
                        }
                    };
                    match record {
                        mcap::records::Record::Schema { header, .. } => {
                            self.schemas
                                .insert(header.id, (header.name, header.encoding));
                        }
                        mcap::records::Record::Channel(ch)
                            if !self.channels.contains_key(&ch.id) =>
                        {
                            self.add_channel(ch)?;
                        }
                        mcap::records::Record::Message { header, data } => {
                            self.messages += 1;
                            let Some(st) = self.channels.get(&header.channel_id) else {
                                return Err(LogError::Mcap {
                                    path: self.path.clone(),
                                    messages: self.messages - 1,
                                    cause: mcap::McapError::UnknownChannel(
                                        header.sequence,
                                        header.channel_id,
                                    ),
                                });
                            };
                            let info = &mut self.topics[st.info];
                            let index = info.messages;
                            info.messages += 1;
                            info.log_time_range_ns = Some(match info.log_time_range_ns {
                                None => (header.log_time, header.log_time),
                                Some((a, b)) => (a.min(header.log_time), b.max(header.log_time)),
                            });
                            let Some((kind, enc)) = st.decoder else {
                                continue;
                            };
                            let decoded = match enc {
                                Encoding::Cdr => decode_cdr(kind, &data, self.options.decode)
                                    .map_err(|cause| LogError::Cdr {
                                        path: self.path.clone(),
                                        topic: info.topic.clone(),
                                        index,
                                        schema: info.schema.clone(),
                                        cause,
                                    }),
                                Encoding::Json => decode_json(kind, &data, self.options.decode)
                                    .map_err(|message| LogError::JsonMessage {
                                        path: self.path.clone(),
                                        topic: info.topic.clone(),
                                        index,
                                        message,
                                    }),
                            }?;
                            info.decoded += 1;
                            let mut s = decoded.sample;
                            mask(&mut s, &st.keep);
                            let t_abs = match (self.options.time, decoded.stamp_s) {
                                (McapTime::HeaderStamp, Some(t)) => t,
                                _ => header.log_time as f64 * 1e-9,
                            };
                            if self.start_log_time_ns.is_none() {
                                self.start_log_time_ns = Some(header.log_time);
                            }
                            let start = *self.start_s.get_or_insert(t_abs);
                            s.time_s = match self.options.time {
                                // Integer nanoseconds: no loss of resolution for Unix times.
                                McapTime::LogTime => {
                                    let t0 = self.start_log_time_ns.unwrap_or(header.log_time);
                                    (i128::from(header.log_time) - i128::from(t0)) as f64 * 1e-9
                                }
                                McapTime::HeaderStamp => t_abs - start,
                            };
                            self.checker.push(s.time_s);
                            return Ok(Some(s));
                        }
                        _ => {}
                    }
                }
            }
        }
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
