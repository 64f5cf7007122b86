//! Telemetry sources for `aloft live`: a telemetry log ([`TlogSource`]) and a live MAVLink link
//! ([`LinkSource`]), both [`TelemetrySource`]s.
//!
//! # Live links
//!
//! [`LinkSource::connect`] opens `udpin:HOST:PORT` (listen on a UDP socket of aloft's own;
//! replies go to the vehicle, see below), or `udpout:HOST:PORT`, `tcpout:HOST:PORT` or
//! `serial:PATH:BAUD` with the `mavlink` crate, accepting MAVLink 1 and 2. A thread reads the link into a bounded channel (1,024 messages; a
//! consumer that falls behind holds the reader back rather than losing messages in the middle of
//! the queue), so [`LinkSource::next_telemetry`] waits at most the link timeout:
//!
//! - while the vehicle is silent for [`LinkOptions::timeout`], `next` returns
//!   [`Event::LinkLost`] (again after every further timeout), and the stream goes on: the link
//!   may come back;
//! - a link that ends (TCP closed, serial port gone) is an error, which ends the stream.
//!
//! Event times are seconds since the link opened, at each message's arrival.
//!
//! aloft speaks on the link as a ground station with [`LinkOptions::system_id`] and
//! [`LinkOptions::component_id`] (default 255/190), in the MAVLink version the vehicle speaks
//! (MAVLink 2 until the vehicle is heard):
//! - a HEARTBEAT (MAV_TYPE_GCS) every second, so that routers and autopilots that answer the
//!   last sender send to aloft ([`LinkOptions::heartbeat`]);
//! - [`LinkSource::reply`]: NAMED_VALUE_FLOAT (`time_boot_ms` since the link opened, a name of at
//!   most 10 bytes) and STATUSTEXT (WARNING or INFO, at most 50 bytes, cut at a character);
//! - the mission download of [`crate::request`] when no mission passed on the link
//!   ([`LinkOptions::request_mission`]).
//!
//! On `udpin` every message goes to the address the vehicle's last HEARTBEAT came from (the
//! vehicle as the [`Decoder`] decides it), never to another sender on the port, whatever and
//! however often it sends; nothing is sent before the vehicle's first HEARTBEAT (such sends are
//! dropped silently). Each datagram's frames are read from that datagram alone.

use std::collections::VecDeque;
use std::fs::File;
use std::io::Read;
use std::net::SocketAddr;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use aloft_logs::telemetry::{Event, Reply, Telemetry, TelemetrySource};
use mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavMessage, MavModeFlag, MavSeverity, MavState, MavType, HEARTBEAT_DATA,
    NAMED_VALUE_FLOAT_DATA, STATUSTEXT_DATA,
};
use mavlink::{
    MAVLinkMessageRaw, MAVLinkV1MessageRaw, MAVLinkV2MessageRaw, MavHeader, MavlinkVersion, Message,
};

use crate::decode::{Decoder, FixStats, MAX_SPEED_MPS};
use crate::error::LinkError;
use crate::request::MissionRequest;
use crate::tlog::{TlogReader, TlogStats};
use crate::transport::{parse_url, Incoming, Transport};

/// A step back of a telemetry log's timestamps longer than this is a step of its clock, said
/// as [`Event::ClockBack`], s; shorter ones are frames out of order (a few ms in the shared
/// logs), whose events take the time of the one before.
pub const CLOCK_BACK_S: f64 = 1.0;

/// A telemetry log read as a stream of events: times from the first frame's timestamp, less the
/// clock's steps (see [`TlogSource::next_telemetry`]).
pub struct TlogSource<R = File> {
    reader: TlogReader<R>,
    decoder: Decoder,
    queue: VecDeque<Telemetry>,
    first_us: Option<u64>,
    /// The previous frame's timestamp, µs.
    last_us: Option<u64>,
    /// Seconds of clock steps taken out of the times so far (forward positive).
    shift_s: f64,
    /// The latest event time so far, s.
    now_s: f64,
    /// Forward steps longer than this are a lost link, s.
    timeout_s: f64,
    finished: bool,
}

impl TlogSource<File> {
    /// Opens a `.tlog` file.
    pub fn open(path: &Path) -> Result<Self, LinkError> {
        let file = File::open(path).map_err(|cause| LinkError::Open {
            path: path.to_path_buf(),
            cause,
        })?;
        Ok(Self::new(file, path.display().to_string()))
    }
}

impl<R: Read> TlogSource<R> {
    /// The events of the telemetry log `source`; `name` is what errors name. Forward steps of
    /// its clock longer than [`LinkOptions::default`]'s timeout (5 s) are a lost link.
    pub fn new(source: R, name: impl Into<String>) -> Self {
        Self {
            reader: TlogReader::new(source, name),
            decoder: Decoder::new(),
            queue: VecDeque::new(),
            first_us: None,
            last_us: None,
            shift_s: 0.0,
            now_s: 0.0,
            timeout_s: LinkOptions::default().timeout.as_secs_f64(),
            finished: false,
        }
    }

    /// The same with forward steps longer than `timeout` said as a lost link (`aloft live
    /// --link-timeout`).
    pub fn with_link_timeout(mut self, timeout: Duration) -> Self {
        self.timeout_s = timeout.as_secs_f64();
        self
    }

    /// The next event, `None` at the end of the log.
    ///
    /// Times are seconds from the first frame's timestamp, with the clock's steps taken out: a
    /// forward step longer than the link timeout is an [`Event::LinkLost`] of its length, and a
    /// step back of more than [`CLOCK_BACK_S`] an [`Event::ClockBack`]; either way the frame
    /// after the step takes the time of the frame before it, so a paced playback does not wait
    /// through a jump and a flight's duration does not count it.
    ///
    /// # Errors
    /// A read error, and [`LinkError::NothingReadable`] at the end of a log in which not one
    /// frame could be read.
    pub fn next_telemetry(&mut self) -> Result<Option<Telemetry>, LinkError> {
        loop {
            if let Some(t) = self.queue.pop_front() {
                return Ok(Some(t));
            }
            if self.finished {
                return Ok(None);
            }
            match self.reader.next_frame()? {
                Some(frame) => {
                    let time_s = self.clock(frame.timestamp_us);
                    self.decoder
                        .push(time_s, &frame.header, &frame.message, &mut self.queue);
                }
                None => {
                    self.finished = true;
                    self.decoder.finish(&mut self.queue);
                    let stats = self.reader.stats();
                    if stats.frames == 0 {
                        return Err(LinkError::NothingReadable {
                            name: self.reader.name().to_owned(),
                            bytes: stats.bytes,
                        });
                    }
                }
            }
        }
    }

    /// The stream time of a frame's timestamp, the clock's steps taken out (and said).
    fn clock(&mut self, stamp_us: u64) -> f64 {
        let first = *self.first_us.get_or_insert(stamp_us);
        if let Some(last) = self.last_us {
            let step_s = (stamp_us as f64 - last as f64) * 1e-6;
            let event = if step_s > self.timeout_s {
                self.decoder.gap(step_s);
                Some(Event::LinkLost { silent_s: step_s })
            } else if step_s < -CLOCK_BACK_S {
                Some(Event::ClockBack { back_s: -step_s })
            } else {
                None
            };
            if let Some(event) = event {
                self.shift_s += step_s;
                self.queue.push_back(Telemetry {
                    time_s: self.now_s,
                    event,
                });
            }
        }
        self.last_us = Some(stamp_us);
        // Before the first frame (out of order): clamped to 0 by the decoder.
        let time_s = (stamp_us as f64 - first as f64) * 1e-6 - self.shift_s;
        self.now_s = self.now_s.max(time_s);
        time_s
    }

    /// What the reader has read and passed over so far.
    pub fn stats(&self) -> &TlogStats {
        self.reader.stats()
    }

    /// The decoder (the vehicle, the origin, the mission so far).
    pub fn decoder(&self) -> &Decoder {
        &self.decoder
    }

    /// The first frame's timestamp, µs since the Unix epoch (time 0 of the events).
    pub fn start_us(&self) -> Option<u64> {
        self.first_us
    }
}

/// `N bad frames (c wrong CRC, u unknown, d undecodable, t bad time, x cut short), B bytes
/// skipped`, or empty when nothing was passed over.
pub fn describe_stats(s: &TlogStats) -> String {
    if s.bytes_skipped == 0 && s.bad_frames() == 0 {
        return String::new();
    }
    format!(
        "{} bad frames ({} wrong CRC, {} unknown, {} undecodable, {} bad time, {} cut short), \
         {} bytes skipped",
        s.bad_frames(),
        s.bad_crc,
        s.unknown,
        s.undecoded,
        s.bad_time,
        s.truncated,
        s.bytes_skipped
    )
}

/// `N positions not believed (o off the Earth, r out of reach), h homes, v velocities`: what
/// the decoder dropped, or empty when nothing was.
pub fn describe_fixes(f: &FixStats) -> String {
    let mut parts = Vec::new();
    if f.off_earth + f.out_of_reach > 0 {
        parts.push(format!(
            "{} positions not believed ({} off the Earth, {} out of reach)",
            f.off_earth + f.out_of_reach,
            f.off_earth,
            f.out_of_reach
        ));
    }
    if f.homes > 0 {
        parts.push(format!("{} homes not believed", f.homes));
    }
    if f.velocities > 0 {
        parts.push(format!(
            "{} velocities over {MAX_SPEED_MPS} m/s",
            f.velocities
        ));
    }
    parts.join(", ")
}

/// The non-empty texts joined by `; `.
fn joined(texts: [String; 2]) -> String {
    texts
        .into_iter()
        .filter(|t| !t.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

impl<R: Read> TelemetrySource for TlogSource<R> {
    fn next_event(&mut self) -> Result<Option<Telemetry>, String> {
        self.next_telemetry().map_err(|e| e.to_string())
    }

    fn skipped(&self) -> String {
        joined([
            describe_stats(self.reader.stats()),
            describe_fixes(&self.decoder.fixes()),
        ])
    }
}

/// How aloft takes part in a live link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkOptions {
    /// aloft's system id on the link (a ground station's: 255 by default).
    pub system_id: u8,
    /// aloft's component id (190, MAV_COMP_ID_MISSIONPLANNER, by default).
    pub component_id: u8,
    /// Silence of the vehicle after which [`Event::LinkLost`] is returned (5 s by default).
    pub timeout: Duration,
    /// Send a ground-station HEARTBEAT every second (default true).
    pub heartbeat: bool,
    /// Ask the vehicle for its mission when none passed on the link (default true).
    pub request_mission: bool,
}

impl Default for LinkOptions {
    fn default() -> Self {
        Self {
            system_id: 255,
            component_id: 190,
            timeout: Duration::from_secs(5),
            heartbeat: true,
            request_mission: true,
        }
    }
}

/// What a live link has passed over so far.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LinkStats {
    /// Messages received and decoded (any system).
    pub messages: u64,
    /// Messages of the vehicle.
    pub vehicle_messages: u64,
    /// Frames with a valid CRC whose payload the dialect refused.
    pub undecoded: u64,
    /// Messages sent by aloft.
    pub sent: u64,
}

/// Messages the reading thread may hold before it waits for the consumer.
const CHANNEL: usize = 1_024;
/// Longest wait for a message in [`LinkSource::next_telemetry`] before heartbeats and the mission request
/// get their turn.
const TICK: Duration = Duration::from_millis(250);
/// Period of aloft's HEARTBEAT.
const HEARTBEAT_PERIOD: Duration = Duration::from_secs(1);

/// A live MAVLink link as a stream of events (see the module docs).
pub struct LinkSource {
    url: String,
    options: LinkOptions,
    link: Transport,
    /// On `udpin`: the address of the vehicle's last HEARTBEAT, where aloft's messages go.
    vehicle_address: Option<SocketAddr>,
    incoming: Receiver<Incoming>,
    stop: Arc<AtomicBool>,
    undecoded: Arc<AtomicU64>,
    decoder: Decoder,
    queue: VecDeque<Telemetry>,
    start: Instant,
    last_vehicle: Option<Instant>,
    last_lost: Option<Instant>,
    last_heartbeat: Option<Instant>,
    vehicle_version: MavlinkVersion,
    sequence: u8,
    request: MissionRequest,
    stats: LinkStats,
    closed: bool,
    /// Set from outside (Ctrl-C): the stream ends at the next look, within [`TICK`].
    interrupt: Option<Arc<AtomicBool>>,
}

impl LinkSource {
    /// Opens the link `url` (`udpin:HOST:PORT`, `udpout:HOST:PORT`, `tcpout:HOST:PORT`,
    /// `serial:PATH:BAUD`) and starts reading it.
    pub fn connect(url: &str, options: LinkOptions) -> Result<Self, LinkError> {
        let address = parse_url(url)?;
        let link = Transport::open(address).map_err(|cause| LinkError::Connect {
            url: url.to_owned(),
            cause,
        })?;
        let (tx, incoming) = sync_channel(CHANNEL);
        let stop = Arc::new(AtomicBool::new(false));
        let undecoded = Arc::new(AtomicU64::new(0));
        {
            let (link, stop, undecoded) = (link.clone(), stop.clone(), undecoded.clone());
            std::thread::Builder::new()
                .name("aloft-link-reader".into())
                .spawn(move || link.read(&tx, &stop, &undecoded))
                .map_err(|cause| LinkError::Connect {
                    url: url.to_owned(),
                    cause,
                })?;
        }
        Ok(Self {
            url: url.to_owned(),
            options,
            link,
            vehicle_address: None,
            incoming,
            stop,
            undecoded,
            decoder: Decoder::new(),
            queue: VecDeque::new(),
            start: Instant::now(),
            last_vehicle: None,
            last_lost: None,
            last_heartbeat: None,
            vehicle_version: MavlinkVersion::V2,
            sequence: 0,
            request: MissionRequest::new(
                (options.system_id, options.component_id),
                options.request_mission,
            ),
            stats: LinkStats::default(),
            closed: false,
            interrupt: None,
        })
    }

    /// The same link, ending its stream (`None` from [`LinkSource::next_telemetry`], not an
    /// error) within 250 ms of `interrupt` being set: how Ctrl-C ends `aloft live --connect`.
    pub fn until(mut self, interrupt: Arc<AtomicBool>) -> Self {
        self.interrupt = Some(interrupt);
        self
    }

    /// The next event: a message's, [`Event::LinkLost`] after [`LinkOptions::timeout`] of the
    /// vehicle's silence, `None` once the link has ended (after its error was returned) or was
    /// interrupted ([`LinkSource::until`]).
    pub fn next_telemetry(&mut self) -> Result<Option<Telemetry>, LinkError> {
        loop {
            if let Some(t) = self.queue.pop_front() {
                return Ok(Some(t));
            }
            let interrupted = self
                .interrupt
                .as_ref()
                .is_some_and(|i| i.load(Ordering::Relaxed));
            if self.closed || interrupted {
                return Ok(None);
            }
            let now = Instant::now();
            self.tick(now)?;
            let silent_since = self.last_vehicle.unwrap_or(self.start);
            let lost_at =
                self.last_lost.map_or(silent_since, |l| l.max(silent_since)) + self.options.timeout;
            if now >= lost_at {
                self.last_lost = Some(now);
                return Ok(Some(Telemetry {
                    time_s: self.time_s(now),
                    event: Event::LinkLost {
                        silent_s: now.duration_since(silent_since).as_secs_f64(),
                    },
                }));
            }
            let wait = lost_at.duration_since(now).min(TICK);
            match self.incoming.recv_timeout(wait) {
                Ok(Incoming::Message {
                    header,
                    version,
                    message,
                    at,
                    from,
                }) => self.received(&header, version, &message, (at, from))?,
                Ok(Incoming::Closed(cause)) => return Err(self.close(cause)),
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    let cause = std::io::Error::other("the reading thread ended");
                    return Err(self.close(cause));
                }
            }
        }
    }

    /// Sends a reply to the ground station (NAMED_VALUE_FLOAT or STATUSTEXT) from aloft's ids.
    pub fn reply(&mut self, reply: &Reply) -> Result<(), LinkError> {
        let (message, name) = match reply {
            Reply::Value { name, value } => (
                named_value(self.boot_ms(), name, *value),
                "NAMED_VALUE_FLOAT",
            ),
            Reply::Text { text, warning } => (status_text(text, *warning), "STATUSTEXT"),
        };
        self.send(&message, name)
    }

    /// What has been received, passed over and sent so far.
    pub fn stats(&self) -> LinkStats {
        LinkStats {
            undecoded: self.undecoded.load(Ordering::Relaxed),
            ..self.stats
        }
    }

    /// The decoder (the vehicle, the origin, the mission so far).
    pub fn decoder(&self) -> &Decoder {
        &self.decoder
    }

    /// The address the link was opened with.
    pub fn url(&self) -> &str {
        &self.url
    }

    fn time_s(&self, at: Instant) -> f64 {
        at.saturating_duration_since(self.start).as_secs_f64()
    }

    /// Milliseconds since the link opened, as a boot time.
    fn boot_ms(&self) -> u32 {
        u32::try_from(self.start.elapsed().as_millis()).unwrap_or(u32::MAX)
    }

    fn received(
        &mut self,
        header: &MavHeader,
        version: MavlinkVersion,
        message: &MavMessage,
        (at, from): (Instant, Option<SocketAddr>),
    ) -> Result<(), LinkError> {
        self.stats.messages += 1;
        let time_s = self.time_s(at);
        if !self.decoder.push(time_s, header, message, &mut self.queue) {
            return Ok(());
        }
        self.stats.vehicle_messages += 1;
        self.last_vehicle = Some(at);
        self.vehicle_version = version;
        // On `udpin`, aloft answers where the vehicle's HEARTBEAT came from, whoever else sends.
        if let (MavMessage::HEARTBEAT(_), Some(from)) = (message, from) {
            self.vehicle_address = Some(from);
        }
        if let Some(answer) = self.request.on_vehicle_message(at, header, message) {
            self.send(&answer, answer.message_name())?;
        }
        Ok(())
    }

    /// Heartbeat and mission request, when due.
    fn tick(&mut self, now: Instant) -> Result<(), LinkError> {
        let due = self
            .last_heartbeat
            .is_none_or(|t| now.duration_since(t) >= HEARTBEAT_PERIOD);
        // On `udpin` there is no one to send to before the vehicle's HEARTBEAT.
        let peer_known =
            self.vehicle_address.is_some() || !matches!(self.link, Transport::UdpIn(_));
        if self.options.heartbeat && due && peer_known {
            self.last_heartbeat = Some(now);
            self.send(&gcs_heartbeat(), "HEARTBEAT")?;
        }
        if !self.request.is_done() {
            let known = self.decoder.mission().is_some();
            if let Some(msg) = self.request.tick(now, self.decoder.vehicle(), known) {
                self.send(&msg, msg.message_name())?;
            }
        }
        Ok(())
    }

    fn send(&mut self, message: &MavMessage, name: &'static str) -> Result<(), LinkError> {
        let header = MavHeader {
            system_id: u32::from(self.options.system_id),
            component_id: self.options.component_id,
            sequence: self.sequence,
        };
        self.sequence = self.sequence.wrapping_add(1);
        let raw = match self.vehicle_version {
            MavlinkVersion::V1 => {
                let mut raw = MAVLinkV1MessageRaw::new();
                raw.serialize_message(header, message);
                MAVLinkMessageRaw::V1(raw)
            }
            MavlinkVersion::V2 => {
                let mut raw = MAVLinkV2MessageRaw::new();
                raw.serialize_message(header, message);
                MAVLinkMessageRaw::V2(raw)
            }
        };
        // Not sent (no vehicle yet on `udpin`, a full socket buffer): the message is dropped.
        match self.link.send(&raw, self.vehicle_address) {
            Ok(sent) => {
                self.stats.sent += u64::from(sent);
                Ok(())
            }
            Err(cause) => Err(LinkError::Send {
                url: self.url.clone(),
                message: name,
                cause,
            }),
        }
    }

    fn close(&mut self, cause: std::io::Error) -> LinkError {
        self.closed = true;
        LinkError::Closed {
            url: self.url.clone(),
            cause,
        }
    }
}

impl Drop for LinkSource {
    fn drop(&mut self) {
        // The reading thread ends at its next read timeout (UDP, TCP) or message (serial).
        self.stop.store(true, Ordering::Relaxed);
    }
}

impl TelemetrySource for LinkSource {
    fn next_event(&mut self) -> Result<Option<Telemetry>, String> {
        self.next_telemetry().map_err(|e| e.to_string())
    }

    fn skipped(&self) -> String {
        let undecoded = self.undecoded.load(Ordering::Relaxed);
        let frames = match undecoded {
            0 => String::new(),
            n => format!("{n} undecodable messages"),
        };
        joined([frames, describe_fixes(&self.decoder.fixes())])
    }

    fn reply(&mut self, reply: &Reply) -> Result<(), String> {
        LinkSource::reply(self, reply).map_err(|e| e.to_string())
    }
}

/// The HEARTBEAT aloft sends on a link, once a second: a ground station's (MAV_TYPE_GCS, no
/// autopilot, active).
pub fn gcs_heartbeat() -> MavMessage {
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype: MavType::MAV_TYPE_GCS,
        autopilot: MavAutopilot::MAV_AUTOPILOT_INVALID,
        base_mode: MavModeFlag::empty(),
        system_status: MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    })
}

/// NAMED_VALUE_FLOAT: the name's first 10 bytes.
fn named_value(time_boot_ms: u32, name: &str, value: f64) -> MavMessage {
    MavMessage::NAMED_VALUE_FLOAT(NAMED_VALUE_FLOAT_DATA {
        time_boot_ms,
        value: value as f32,
        name: truncated(name, 10).into(),
    })
}

/// STATUSTEXT at WARNING or INFO severity: the text's first 50 bytes, cut at a character.
fn status_text(text: &str, warning: bool) -> MavMessage {
    let severity = if warning {
        MavSeverity::MAV_SEVERITY_WARNING
    } else {
        MavSeverity::MAV_SEVERITY_INFO
    };
    MavMessage::STATUSTEXT(STATUSTEXT_DATA {
        severity,
        text: truncated(text, 50).into(),
        id: 0,
        chunk_seq: 0,
    })
}

/// The longest prefix of `s` of at most `max` bytes that ends at a character boundary.
fn truncated(s: &str, max: usize) -> &str {
    let mut end = s.len().min(max);
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    &s[..end]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_outside_the_four_forms_are_refused() {
        for url in [
            "udp:127.0.0.1:14550",
            "tcpin:127.0.0.1:5760",
            "file:/tmp/x.tlog",
            "udpin:14550",
            "udpin:127.0.0.1:",
            "serial:/dev/ttyUSB0:fast",
            "udpin:127.0.0.1:14550x",
            "",
        ] {
            let e = parse_url(url).err().unwrap();
            assert!(e.to_string().starts_with(url), "{e}");
        }
        assert!(parse_url("udpin:127.0.0.1:14550").is_ok());
        assert!(parse_url("serial:/dev/ttyUSB0:57600").is_ok());
    }

    /// A tlog of SYSTEM_TIME frames of the vehicle (after its HEARTBEAT) at these timestamps.
    fn tlog(stamps_us: &[u64]) -> Vec<u8> {
        let header = MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: 0,
        };
        let vehicle = MavMessage::HEARTBEAT(HEARTBEAT_DATA {
            autopilot: MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA,
            mavtype: MavType::MAV_TYPE_QUADROTOR,
            ..HEARTBEAT_DATA::default()
        });
        let mut out = Vec::new();
        for (k, &t) in stamps_us.iter().enumerate() {
            out.extend(t.to_be_bytes());
            let msg = match k {
                0 => vehicle.clone(),
                _ => MavMessage::MISSION_CURRENT(Default::default()),
            };
            mavlink::write_v2_msg(&mut out, header, &msg).unwrap();
        }
        out
    }

    fn events(bytes: &[u8], timeout_s: u64) -> Vec<Telemetry> {
        let mut s = TlogSource::new(bytes, "t").with_link_timeout(Duration::from_secs(timeout_s));
        std::iter::from_fn(|| s.next_telemetry().unwrap()).collect()
    }

    /// Forward by more than the timeout: a lost link of the step's length, and no time; back by
    /// more than 1 s: said, and no time either; small steps either way are time as before.
    #[test]
    fn clock_steps_are_said_and_not_counted() {
        const T0: u64 = 1_700_000_000_000_000;
        let s = 1_000_000;
        let stamps = [
            T0,
            T0 + s,
            T0 + 1_000_001 * s,
            T0 + 1_000_004 * s,
            T0 + 1_000_003 * s,
        ];
        let ev = events(&tlog(&stamps), 5);
        let times: Vec<f64> = ev.iter().map(|t| t.time_s).collect();
        // Heartbeat 0; 1; the step (said at 1) and its frame at 1; 4 s later 4; 1 s back: clamped.
        assert_eq!(times, [0.0, 1.0, 1.0, 1.0, 4.0, 4.0]);
        assert_eq!(ev[2].event, Event::LinkLost { silent_s: 1e6 });
        // The same 3 s step is time under a 2 s timeout; and 100 s back is said.
        let ev = events(&tlog(&[T0, T0 + 3 * s, T0 - 97 * s, T0 - 96 * s]), 2);
        let times: Vec<f64> = ev.iter().map(|t| t.time_s).collect();
        assert_eq!(times, [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(ev[1].event, Event::LinkLost { silent_s: 3.0 });
        assert_eq!(ev[3].event, Event::ClockBack { back_s: 100.0 });
    }

    #[test]
    fn a_tlog_without_one_frame_is_an_error_naming_it() {
        for bytes in [Vec::new(), tlog(&[0, 0, 0]), vec![0xFD; 300]] {
            let mut s = TlogSource::new(&bytes[..], "x.tlog");
            let e = s.next_telemetry().unwrap_err().to_string();
            assert!(e.starts_with("x.tlog: not a telemetry log"), "{e}");
        }
    }

    #[test]
    fn texts_are_cut_at_characters() {
        assert_eq!(truncated("energy_remaining", 10), "energy_rem");
        assert_eq!(truncated("ééééééé", 5), "éé");
        let long = "x".repeat(80);
        let MavMessage::STATUSTEXT(t) = status_text(&long, true) else {
            panic!("not a STATUSTEXT")
        };
        assert_eq!(t.text.to_str().unwrap().len(), 50);
        assert_eq!(t.severity, MavSeverity::MAV_SEVERITY_WARNING);
    }
}
