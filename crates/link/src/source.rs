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
//! aloft speaks on the link, in the MAVLink version the vehicle speaks (MAVLink 2 until the
//! vehicle is heard), as a ground station with [`LinkOptions::system_id`] and
//! [`LinkOptions::component_id`] (default 255/190):
//! - a HEARTBEAT (MAV_TYPE_GCS) every second, so that routers and autopilots that answer the
//!   last sender send to aloft ([`LinkOptions::heartbeat`]);
//! - PARAM_REQUEST_READ of the vehicle's failsafe parameters when it is first heard and after it
//!   restarts ([`crate::params`], [`LinkOptions::request_parameters`]);
//! - the mission download of [`crate::request`] when no mission passed on the link
//!   ([`LinkOptions::request_mission`]);
//!
//! and, for a ground station to show beside the autopilot's, as a component of the vehicle's
//! own system ([`LinkOptions::display_component_id`], default 191), [`LinkSource::reply`]:
//! NAMED_VALUE_FLOAT (`time_boot_ms` since the link opened, a name of at most 10 bytes),
//! STATUSTEXT (at the reply's severity, at most 50 bytes, cut at a character) and BATTERY_STATUS
//! of aloft's own battery ([`battery_status`]). QGroundControl's vehicle takes only messages of
//! its system id (`Vehicle::_mavlinkMessageReceived`), whatever the component, and needs no
//! HEARTBEAT of that component; none is sent, because an ONBOARD_CONTROLLER heartbeat of its
//! own system makes PX4 say "Connection to mission computer lost" when aloft stops
//! (`COM_OBC_LOSS_T`). These replies are sent only once the vehicle is known and while it was
//! heard in the last [`DISPLAY_HEARD`] ([`LinkSource::display_ids`]): QGroundControl counts any
//! message of the vehicle's system as the vehicle being there, so aloft must not keep a silent
//! vehicle alive on its screen. BATTERY_STATUS goes from the vehicle's system only to an
//! ArduPilot: PX4 takes a BATTERY_STATUS of its own system from another component as a battery
//! of its own (`MavlinkReceiver::handle_message_battery_status`), whose warning drives its
//! battery failsafe; to any other autopilot it goes from aloft's own ids.
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

use aloft_logs::telemetry::{
    BatteryReply, ChargeState, Event, Reply, Severity, Telemetry, TelemetrySource,
};
use mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavBatteryChargeState, MavBatteryFault, MavBatteryFunction, MavBatteryMode,
    MavBatteryType, MavMessage, MavModeFlag, MavSeverity, MavState, MavType, BATTERY_STATUS_DATA,
    HEARTBEAT_DATA, NAMED_VALUE_FLOAT_DATA, STATUSTEXT_DATA,
};
use mavlink::{
    MAVLinkMessageRaw, MAVLinkV1MessageRaw, MAVLinkV2MessageRaw, MavHeader, MavlinkVersion, Message,
};

use crate::decode::{Decoder, FixStats, MAX_SPEED_MPS};
use crate::error::LinkError;
use crate::params::ParamRequest;
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

/// The component of the vehicle's system aloft's displayed replies come from unless told
/// otherwise: MAV_COMP_ID_ONBOARD_COMPUTER, common.xml's id for a generic component on the
/// companion computer, which neither ArduPilot nor PX4 routes or watches specially (PX4 watches
/// heartbeats of 68, 240 and 241 and MAVSDK's companion is 195).
pub const DISPLAY_COMPONENT_ID: u8 = 191;

/// Longest silence of the vehicle after which aloft's displayed replies are no longer sent
/// (QGroundControl would take them for the vehicle's own and not say the link is lost).
pub const DISPLAY_HEARD: Duration = Duration::from_secs(2);

/// How aloft takes part in a live link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkOptions {
    /// aloft's system id on the link (a ground station's: 255 by default).
    pub system_id: u8,
    /// aloft's component id (190, MAV_COMP_ID_MISSIONPLANNER, by default).
    pub component_id: u8,
    /// The component of the vehicle's system aloft's displayed replies come from
    /// ([`DISPLAY_COMPONENT_ID`] by default; 0 is broadcast and not a sender's id).
    pub display_component_id: u8,
    /// Silence of the vehicle after which [`Event::LinkLost`] is returned (5 s by default).
    pub timeout: Duration,
    /// Send a ground-station HEARTBEAT every second (default true).
    pub heartbeat: bool,
    /// Ask the vehicle for its mission when none passed on the link (default true).
    pub request_mission: bool,
    /// Ask the vehicle for its failsafe parameters when it is first heard and after it
    /// restarts (default true; [`crate::params`]).
    pub request_parameters: bool,
}

impl Default for LinkOptions {
    fn default() -> Self {
        Self {
            system_id: 255,
            component_id: 190,
            display_component_id: DISPLAY_COMPONENT_ID,
            timeout: Duration::from_secs(5),
            heartbeat: true,
            request_mission: true,
            request_parameters: true,
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
    /// The sequence of aloft's own ids, and of its display component.
    sequence: u8,
    display_sequence: u8,
    request: MissionRequest,
    params: ParamRequest,
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
            display_sequence: 0,
            request: MissionRequest::new(
                (options.system_id, options.component_id),
                options.request_mission,
            ),
            params: ParamRequest::new(options.request_parameters),
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

    /// Sends a reply to the ground station (NAMED_VALUE_FLOAT, STATUSTEXT or BATTERY_STATUS)
    /// from the ids [`LinkSource::display_ids`] gives; dropped (not an error) where it gives
    /// none.
    pub fn reply(&mut self, reply: &Reply) -> Result<(), LinkError> {
        let (message, name) = match reply {
            Reply::Value { name, value } => (
                named_value(self.boot_ms(), name, *value),
                "NAMED_VALUE_FLOAT",
            ),
            Reply::Text { text, severity } => (status_text(text, *severity), "STATUSTEXT"),
            Reply::Battery(b) => (battery_status(b), "BATTERY_STATUS"),
        };
        let battery = matches!(reply, Reply::Battery(_));
        match self.display_ids(battery, Instant::now()) {
            Some(ids) => self.send_from(&message, name, ids),
            None => Ok(()),
        }
    }

    /// The (system, component) a displayed reply is sent from at `now`: the vehicle's system and
    /// [`LinkOptions::display_component_id`]; aloft's own ids for a BATTERY_STATUS to a vehicle
    /// that is not an ArduPilot (see the module docs); none before the vehicle is known, nor
    /// once it has been silent longer than [`DISPLAY_HEARD`].
    pub fn display_ids(&self, battery: bool, now: Instant) -> Option<(u8, u8)> {
        let (system, _) = self.decoder.vehicle()?;
        let heard = self.last_vehicle?;
        if now.saturating_duration_since(heard) > DISPLAY_HEARD {
            return None;
        }
        let ardupilot = self.decoder.autopilot() == Some(MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA);
        if battery && !ardupilot {
            return Some(self.own_ids());
        }
        Some((
            u8::try_from(system).ok()?,
            self.options.display_component_id,
        ))
    }

    /// aloft's own (system, component): a ground station's.
    fn own_ids(&self) -> (u8, u8) {
        (self.options.system_id, self.options.component_id)
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
        self.params.on_vehicle_message(message);
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
        let (vehicle, autopilot) = (self.decoder.vehicle(), self.decoder.autopilot());
        let asks = self
            .params
            .tick(now, vehicle, autopilot, self.decoder.reboots());
        for msg in asks {
            self.send(&msg, msg.message_name())?;
        }
        Ok(())
    }

    /// Sends `message` from aloft's own ids.
    fn send(&mut self, message: &MavMessage, name: &'static str) -> Result<(), LinkError> {
        self.send_from(message, name, self.own_ids())
    }

    /// Sends `message` from `(system, component)`, each sender with its own sequence.
    fn send_from(
        &mut self,
        message: &MavMessage,
        name: &'static str,
        (system, component): (u8, u8),
    ) -> Result<(), LinkError> {
        let sequence = if (system, component) == self.own_ids() {
            &mut self.sequence
        } else {
            &mut self.display_sequence
        };
        let header = MavHeader {
            system_id: u32::from(system),
            component_id: component,
            sequence: *sequence,
        };
        *sequence = sequence.wrapping_add(1);
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

/// STATUSTEXT at `severity`: the text's first 50 bytes, cut at a character.
fn status_text(text: &str, severity: Severity) -> MavMessage {
    let severity = match severity {
        Severity::Critical => MavSeverity::MAV_SEVERITY_CRITICAL,
        Severity::Warning => MavSeverity::MAV_SEVERITY_WARNING,
        Severity::Notice => MavSeverity::MAV_SEVERITY_NOTICE,
        Severity::Info => MavSeverity::MAV_SEVERITY_INFO,
    };
    MavMessage::STATUSTEXT(STATUSTEXT_DATA {
        severity,
        text: truncated(text, 50).into(),
        id: 0,
        chunk_seq: 0,
    })
}

/// The largest value of one `voltages` field, mV: UINT16_MAX is "no cell".
const CELL_MAX_MV: u16 = u16::MAX - 1;

/// BATTERY_STATUS of aloft's own battery, as common.xml asks of a battery whose cells are not
/// known:
/// - `voltages[0]` the pack's voltage, mV, the others UINT16_MAX; a pack above 65,534 mV fills
///   cell 0 with 65,534 and the rest in cell 1 (and on, for each further 65,534 mV); a voltage
///   not known, or beyond ten fields (655 V), leaves every field UINT16_MAX; `voltages_ext` 0
///   (none);
/// - `current_battery` cA, saturated to the `int16` range (-1 is "not measured": a current that
///   rounds to -1 cA is sent as 0); `current_consumed` mA h (-1 not known);
///   `energy_consumed` -1; `battery_remaining` percent, rounded into 0-100 (-1 not known);
///   `temperature` INT16_MAX (not known);
/// - extensions: `time_remaining` s, rounded, at least 1 (0 is "not provided"); `charge_state`
///   from the reply; `battery_function` ALL, `type` LIPO, `mode` 0, `fault_bitmask` 0.
pub fn battery_status(b: &BatteryReply) -> MavMessage {
    let current_battery = b.current_a.filter(|i| i.is_finite()).map_or(-1, |i| {
        let ca = (i * 100.0)
            .round()
            .clamp(f64::from(i16::MIN), f64::from(i16::MAX)) as i16;
        if ca == -1 {
            0
        } else {
            ca
        }
    });
    let finite = |v: Option<f64>| v.filter(|v| v.is_finite());
    MavMessage::BATTERY_STATUS(BATTERY_STATUS_DATA {
        current_consumed: finite(b.consumed_mah)
            .map_or(-1, |c| c.round().clamp(0.0, f64::from(i32::MAX)) as i32),
        energy_consumed: -1,
        temperature: i16::MAX,
        voltages: pack_voltages(finite(b.voltage_v)),
        current_battery,
        id: b.id,
        battery_function: MavBatteryFunction::MAV_BATTERY_FUNCTION_ALL,
        mavtype: MavBatteryType::MAV_BATTERY_TYPE_LIPO,
        battery_remaining: finite(b.remaining_percent)
            .map_or(-1, |p| p.round().clamp(0.0, 100.0) as i8),
        time_remaining: finite(b.time_remaining_s)
            .filter(|t| *t >= 0.0)
            .map_or(0, |t| t.round().clamp(1.0, f64::from(i32::MAX)) as i32),
        charge_state: charge_state(b.charge_state),
        voltages_ext: [0; 4],
        mode: MavBatteryMode::MAV_BATTERY_MODE_UNKNOWN,
        fault_bitmask: MavBatteryFault::empty(),
    })
}

/// The `voltages` of a pack of `voltage_v` whose cells are not known (see [`battery_status`]).
fn pack_voltages(voltage_v: Option<f64>) -> [u16; 10] {
    let mut fields = [u16::MAX; 10];
    let Some(v) = voltage_v.filter(|v| *v >= 0.0) else {
        return fields;
    };
    let mut left_mv = (v * 1000.0).round();
    let cell = f64::from(CELL_MAX_MV);
    if left_mv > cell * fields.len() as f64 {
        return fields;
    }
    for field in &mut fields {
        *field = left_mv.min(cell) as u16;
        left_mv -= cell;
        if left_mv <= 0.0 {
            break;
        }
    }
    fields
}

/// MAV_BATTERY_CHARGE_STATE of a charge state.
fn charge_state(state: ChargeState) -> MavBatteryChargeState {
    match state {
        ChargeState::Undefined => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_UNDEFINED,
        ChargeState::Ok => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_OK,
        ChargeState::Low => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_LOW,
        ChargeState::Critical => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_CRITICAL,
        ChargeState::Emergency => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_EMERGENCY,
    }
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
        let MavMessage::STATUSTEXT(t) = status_text(&long, Severity::Warning) else {
            panic!("not a STATUSTEXT")
        };
        assert_eq!(t.text.to_str().unwrap().len(), 50);
        assert_eq!(t.severity, MavSeverity::MAV_SEVERITY_WARNING);
    }

    fn battery(b: &BatteryReply) -> BATTERY_STATUS_DATA {
        let MavMessage::BATTERY_STATUS(d) = battery_status(b) else {
            panic!("not a BATTERY_STATUS")
        };
        d
    }

    /// Field by field against common.xml's BATTERY_STATUS (147): a 3S pack at 11.1 V, 12.34 A,
    /// 63 %, 190 s to the first failsafe, low.
    #[test]
    fn battery_status_fills_each_field_as_common_xml_says() {
        let d = battery(&BatteryReply {
            id: 100,
            remaining_percent: Some(62.6),
            time_remaining_s: Some(190.4),
            voltage_v: Some(11.1),
            current_a: Some(12.34),
            consumed_mah: Some(850.2),
            charge_state: ChargeState::Low,
        });
        assert_eq!(d.id, 100);
        // Cells unknown: the pack in cell 0, the others UINT16_MAX; cells 11-14 0 (none).
        let mut cells = [u16::MAX; 10];
        cells[0] = 11_100;
        assert_eq!(d.voltages, cells);
        assert_eq!(d.voltages_ext, [0; 4]);
        assert_eq!(d.current_battery, 1_234);
        assert_eq!(d.current_consumed, 850);
        assert_eq!(d.energy_consumed, -1);
        assert_eq!(d.battery_remaining, 63);
        assert_eq!(d.temperature, i16::MAX);
        assert_eq!(d.time_remaining, 190);
        assert_eq!(
            d.charge_state,
            MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_LOW
        );
        assert_eq!(
            d.battery_function,
            MavBatteryFunction::MAV_BATTERY_FUNCTION_ALL
        );
        assert_eq!(d.mavtype, MavBatteryType::MAV_BATTERY_TYPE_LIPO);
        assert_eq!(d.mode, MavBatteryMode::MAV_BATTERY_MODE_UNKNOWN);
        assert!(d.fault_bitmask.is_empty());
    }

    /// Nothing known: every field its "unknown" value (-1, UINT16_MAX, 0 for the time).
    #[test]
    fn battery_status_unknowns_are_mavlinks_invalid_values() {
        let d = battery(&BatteryReply {
            id: 7,
            voltage_v: Some(f64::NAN),
            ..BatteryReply::default()
        });
        assert_eq!(d.voltages, [u16::MAX; 10]);
        assert_eq!(d.current_battery, -1);
        assert_eq!(d.current_consumed, -1);
        assert_eq!(d.battery_remaining, -1);
        assert_eq!(d.time_remaining, 0);
        assert_eq!(
            d.charge_state,
            MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_UNDEFINED
        );
    }

    /// Above 65,534 mV cell 0 holds 65,534 and cell 1 the rest; beyond ten fields (655.34 V)
    /// the voltage is not sent. Currents saturate at the int16 range, and one that would read
    /// as -1 (unknown) is 0; a time under 1 s is 1 (0 is "not provided"); percentages are cut
    /// to 0-100.
    #[test]
    fn battery_status_edges() {
        let v = |volts: f64| {
            battery(&BatteryReply {
                voltage_v: Some(volts),
                ..BatteryReply::default()
            })
            .voltages
        };
        let mut two = [u16::MAX; 10];
        two[0] = 65_534;
        two[1] = 4_466; // 70,000 - 65,534 mV
        assert_eq!(v(70.0), two);
        let mut exact = [u16::MAX; 10];
        exact[0] = 65_534;
        assert_eq!(v(65.534), exact);
        assert_eq!(v(700.0), [u16::MAX; 10]);
        assert_eq!(v(0.0)[0], 0);
        let i = |amps: f64| {
            battery(&BatteryReply {
                current_a: Some(amps),
                ..BatteryReply::default()
            })
            .current_battery
        };
        assert_eq!(i(400.0), i16::MAX);
        assert_eq!(i(-400.0), i16::MIN);
        assert_eq!(i(-0.01), 0);
        assert_eq!(i(-0.5), -50);
        let other = battery(&BatteryReply {
            time_remaining_s: Some(0.2),
            remaining_percent: Some(104.0),
            ..BatteryReply::default()
        });
        assert_eq!(other.time_remaining, 1);
        assert_eq!(other.battery_remaining, 100);
        let below = battery(&BatteryReply {
            time_remaining_s: Some(-3.0),
            remaining_percent: Some(-2.0),
            ..BatteryReply::default()
        });
        assert_eq!(below.time_remaining, 0);
        assert_eq!(below.battery_remaining, 0);
    }

    #[test]
    fn statustext_severities_are_mavlinks() {
        for (severity, want) in [
            (Severity::Critical, MavSeverity::MAV_SEVERITY_CRITICAL),
            (Severity::Warning, MavSeverity::MAV_SEVERITY_WARNING),
            (Severity::Notice, MavSeverity::MAV_SEVERITY_NOTICE),
            (Severity::Info, MavSeverity::MAV_SEVERITY_INFO),
        ] {
            let MavMessage::STATUSTEXT(t) = status_text("aloft: x", severity) else {
                panic!("not a STATUSTEXT")
            };
            assert_eq!(t.severity, want);
            assert_eq!(t.severity as u8, severity.mav_severity());
        }
    }
}
