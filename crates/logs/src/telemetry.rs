//! What a flight reports while it flies, whatever carries it: a MAVLink link or telemetry log
//! (the `aloft-link` crate), or a flight log replayed as if live. One event type, aloft's units
//! (SI, ENU from a stream origin, seconds from the stream's start), so `aloft live` follows every
//! source with the same code.
//!
//! The MAVLink messages each event comes from are named beside it; a flight log's topics map to
//! the same events (a sample per record, `Heartbeat` from its arming and mode records where it
//! has them).

use crate::sample::{GeoOrigin, Log, Sample};

/// One event of a flight, at a time.
#[derive(Debug, Clone, PartialEq)]
pub struct Telemetry {
    /// Time since the start of the stream, s (the tlog's clock, the log's, or the link's arrival).
    pub time_s: f64,
    /// What happened.
    pub event: Event,
}

/// What a flight reports.
// Most events are samples: boxing the large variant would allocate once per message.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// The state at an instant: the channels the message carried, the others `None`
    /// (GLOBAL_POSITION_INT: position and velocity; ATTITUDE; SYS_STATUS/BATTERY_STATUS: voltage
    /// and current; WIND; EXTENDED_SYS_STATE: landed). `sample.time_s` equals the event's time.
    Sample(Sample),
    /// The geodetic origin of the samples' ENU positions, sent once before the first position (a
    /// source that only has local positions sends none).
    Origin(GeoOrigin),
    /// Home, ENU from the origin, m (HOME_POSITION).
    Home([f64; 3]),
    /// HEARTBEAT of the vehicle: armed, flight mode by name, MAV_TYPE.
    Heartbeat(Heartbeat),
    /// The battery as the autopilot states it (SYS_STATUS `battery_remaining`, BATTERY_STATUS
    /// `current_consumed`).
    Battery(BatteryState),
    /// Airspeed and ground speed as the autopilot states them (VFR_HUD), m/s.
    Speeds {
        /// Airspeed, m/s (an estimate on most multirotors).
        airspeed_mps: f64,
        /// Ground speed, m/s.
        groundspeed_mps: f64,
    },
    /// The mission item being flown (MISSION_CURRENT `seq`).
    MissionCurrent(u32),
    /// The whole mission, as the vehicle holds it (MISSION_COUNT and every MISSION_ITEM(_INT) of
    /// one upload or download, in sequence order).
    Mission(Vec<MissionItem>),
    /// The vehicle restarted (its boot time went back): what was learned of the flight so far no
    /// longer holds.
    Reboot,
    /// Nothing from the vehicle for `silent_s` seconds. On a live link, after the link's timeout,
    /// and again after every further timeout while the silence lasts; the stream goes on, as the
    /// link may come back. In a telemetry log, where its timestamps jump forward by more than the
    /// timeout: the jump is not counted in the stream's times (nothing was received over it).
    LinkLost {
        /// Time since the vehicle's last message (or since the link opened), s.
        silent_s: f64,
    },
    /// A telemetry log's timestamps stepped back by `back_s` seconds (the ground station's clock
    /// was set back): the stream's times go on from before the step.
    ClockBack {
        /// The step back, s.
        back_s: f64,
    },
    /// One of the vehicle's parameters (PARAM_VALUE on a link; a flight log's parameters,
    /// sent before its first record): what its failsafes act on (ArduPilot `BATT_*`, PX4
    /// `BAT_*`/`BAT1_*`).
    Parameter {
        /// The parameter's name, as the autopilot spells it (at most 16 characters).
        name: String,
        /// Its value.
        value: f64,
    },
}

/// The vehicle's HEARTBEAT.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Heartbeat {
    /// Motors armed.
    pub armed: bool,
    /// Flight mode by the autopilot's name (`AUTO`, `LOITER`, `RTL`, PX4 `MISSION`, ...), or
    /// `custom N` where the autopilot is not known.
    pub mode: String,
    /// MAV_TYPE (2 quadrotor, 13 hexarotor, 14 octorotor, ...).
    pub vehicle_type: u8,
}

/// The battery as the autopilot states it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BatteryState {
    /// State of charge, 0-1 (`battery_remaining` percent / 100); `None` where not sent (-1).
    pub soc: Option<f64>,
    /// Charge drawn since the start, A h, as sent (a negative or implausible count too: the
    /// reader judges it); `None` where not sent (-1).
    pub consumed_ah: Option<f64>,
}

/// One mission item as a MAVLink link or log carries it (MISSION_ITEM_INT, MISSION_ITEM,
/// DataFlash `CMD`): the fields of a `.waypoints` row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MissionItem {
    /// Sequence number, from 0 (0 is home on ArduPilot).
    pub seq: u32,
    /// MAV_FRAME.
    pub frame: u32,
    /// MAV_CMD.
    pub command: u32,
    /// param1-param4, latitude (deg), longitude (deg), altitude (m), as a `.waypoints` row.
    pub params: [f64; 7],
}

/// A source of telemetry: a link, a telemetry log, a flight log replayed.
pub trait TelemetrySource {
    /// The next event, `None` at the end of the stream. An error ends the stream (a file that
    /// cannot be read further); damaged frames inside a stream are skipped, not errors.
    fn next_event(&mut self) -> Result<Option<Telemetry>, String>;

    /// What the source has passed over so far (corrupt frames, bytes skipped), for the status
    /// line; empty by default.
    fn skipped(&self) -> String {
        String::new()
    }

    /// Send `reply` back to the vehicle's link (a ground station on it shows it); a source that
    /// is not a link ignores it (the default).
    ///
    /// # Errors
    /// The link's, as a message naming it.
    fn reply(&mut self, reply: &Reply) -> Result<(), String> {
        let _ = reply;
        Ok(())
    }
}

impl<T: TelemetrySource + ?Sized> TelemetrySource for Box<T> {
    fn next_event(&mut self) -> Result<Option<Telemetry>, String> {
        (**self).next_event()
    }

    fn skipped(&self) -> String {
        (**self).skipped()
    }

    fn reply(&mut self, reply: &Reply) -> Result<(), String> {
        (**self).reply(reply)
    }
}

/// What `aloft live` sends back on a link, so a ground station shows it without a plugin.
#[derive(Debug, Clone, PartialEq)]
pub enum Reply {
    /// A named value (NAMED_VALUE_FLOAT: name of at most 10 characters).
    Value {
        /// The name, at most 10 ASCII characters.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// A text (STATUSTEXT, at most 50 characters) at a severity.
    Text {
        /// The text.
        text: String,
        /// How grave it is (QGroundControl speaks [`Severity::Notice`] and graver).
        severity: Severity,
    },
    /// aloft's own estimate of the pack, as a battery of its own id (BATTERY_STATUS).
    Battery(BatteryReply),
}

/// The severity of a [`Reply::Text`]: MAVLink's MAV_SEVERITY, the four aloft uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// Action required now (MAV_SEVERITY_CRITICAL, 2).
    Critical,
    /// Something will go wrong unless acted on (MAV_SEVERITY_WARNING, 4).
    Warning,
    /// Unusual, not an error (MAV_SEVERITY_NOTICE, 5).
    Notice,
    /// Information (MAV_SEVERITY_INFO, 6).
    Info,
}

impl Severity {
    /// Its MAV_SEVERITY value.
    pub fn mav_severity(self) -> u8 {
        match self {
            Severity::Critical => 2,
            Severity::Warning => 4,
            Severity::Notice => 5,
            Severity::Info => 6,
        }
    }
}

/// How far the pack is discharged, as a ground station shows it (MAV_BATTERY_CHARGE_STATE).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum ChargeState {
    /// Not known (MAV_BATTERY_CHARGE_STATE_UNDEFINED, 0).
    #[default]
    Undefined,
    /// Normal operation (OK, 1).
    Ok,
    /// Warn and watch closely (LOW, 2).
    Low,
    /// Return or abort now (CRITICAL, 3).
    Critical,
    /// Too low for an ordinary return: land now (EMERGENCY, 4).
    Emergency,
}

impl ChargeState {
    /// Its MAV_BATTERY_CHARGE_STATE value.
    pub fn mav_charge_state(self) -> u8 {
        match self {
            ChargeState::Undefined => 0,
            ChargeState::Ok => 1,
            ChargeState::Low => 2,
            ChargeState::Critical => 3,
            ChargeState::Emergency => 4,
        }
    }
}

/// aloft's estimate of the pack, sent as a battery of its own (BATTERY_STATUS); `None` is "not
/// known" (MAVLink's invalid value for the field).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BatteryReply {
    /// The battery id aloft's battery is shown under (`--battery-id`).
    pub id: u8,
    /// State of charge, percent (0-100).
    pub remaining_percent: Option<f64>,
    /// Time remaining, s (until the first failsafe ahead).
    pub time_remaining_s: Option<f64>,
    /// The pack's voltage, V (measured).
    pub voltage_v: Option<f64>,
    /// The pack's current, A, positive discharging (measured).
    pub current_a: Option<f64>,
    /// Charge drawn, mA h.
    pub consumed_mah: Option<f64>,
    /// How far it is discharged.
    pub charge_state: ChargeState,
}

/// A source played at a pace: event `t` is returned no earlier than `t / speed` seconds of wall
/// time after the first (a telemetry log "in its own time", `--speed 1`, or faster). The waits
/// are sleeps; nothing is buffered. With [`Paced::until`], a wait ends as soon as its flag is
/// set, and the stream with it.
pub struct Paced<S> {
    source: S,
    speed: f64,
    start: Option<(std::time::Instant, f64)>,
    stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// The longest slice of a paced wait before the stop flag is looked at again.
const STOP_POLL: std::time::Duration = std::time::Duration::from_millis(50);

impl<S: TelemetrySource> Paced<S> {
    /// `source` at `speed` times its own time (positive and finite; the caller checks it).
    pub fn new(source: S, speed: f64) -> Self {
        Self {
            source,
            speed,
            start: None,
            stop: None,
        }
    }

    /// The same, ending (`None` from [`TelemetrySource::next_event`]) once `stop` is set, in the
    /// middle of a wait too (Ctrl-C).
    pub fn until(mut self, stop: std::sync::Arc<std::sync::atomic::AtomicBool>) -> Self {
        self.stop = Some(stop);
        self
    }

    fn stopped(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed))
    }

    /// Sleeps until `due_s` of wall time after the first event, in slices that look at the
    /// stop flag; false when it was set.
    fn wait_until(&self, wall0: std::time::Instant, due_s: f64) -> bool {
        loop {
            if self.stopped() {
                return false;
            }
            let left_s = due_s - wall0.elapsed().as_secs_f64();
            if left_s <= 0.0 {
                return true;
            }
            let slice = std::time::Duration::from_secs_f64(left_s);
            std::thread::sleep(match self.stop {
                Some(_) => slice.min(STOP_POLL),
                None => slice,
            });
        }
    }
}

impl<S: TelemetrySource> TelemetrySource for Paced<S> {
    fn next_event(&mut self) -> Result<Option<Telemetry>, String> {
        let Some(t) = self.source.next_event()? else {
            return Ok(None);
        };
        let (wall0, t0) = *self
            .start
            .get_or_insert_with(|| (std::time::Instant::now(), t.time_s));
        let due_s = ((t.time_s - t0) / self.speed).clamp(0.0, 1e9);
        Ok(self.wait_until(wall0, due_s).then_some(t))
    }

    fn skipped(&self) -> String {
        self.source.skipped()
    }

    fn reply(&mut self, reply: &Reply) -> Result<(), String> {
        self.source.reply(reply)
    }
}

/// A flight log replayed as events: its origin (where its positions were geodetic), its
/// parameters ([`LogEvents::with_parameters`]), then a sample event per record and the log's
/// other events (a DataFlash log's mode, arming and mission: [`crate::flight_events`]) in time
/// order (`aloft live --replay`).
pub struct LogEvents {
    origin: Option<GeoOrigin>,
    parameters: std::vec::IntoIter<(String, f64)>,
    samples: std::iter::Peekable<std::vec::IntoIter<Sample>>,
    events: std::iter::Peekable<std::vec::IntoIter<Telemetry>>,
}

impl LogEvents {
    /// The events of `log` alone.
    pub fn new(log: Log) -> Self {
        Self::with_events(log, Vec::new())
    }

    /// The events of `log` and `events` (in time order, times as the samples'), merged by time.
    pub fn with_events(log: Log, events: Vec<Telemetry>) -> Self {
        Self {
            origin: log.origin,
            parameters: Vec::new().into_iter(),
            samples: log.samples.into_iter().peekable(),
            events: events.into_iter().peekable(),
        }
    }

    /// The same, with the log's `parameters` (name, value) sent as [`Event::Parameter`] before
    /// its first record (after its origin), at the first record's time.
    pub fn with_parameters(mut self, parameters: Vec<(String, f64)>) -> Self {
        self.parameters = parameters.into_iter();
        self
    }
}

impl TelemetrySource for LogEvents {
    fn next_event(&mut self) -> Result<Option<Telemetry>, String> {
        if let Some(o) = self.origin.take() {
            let first = self.samples.peek().map_or(0.0, |s| s.time_s);
            return Ok(Some(Telemetry {
                time_s: first,
                event: Event::Origin(o),
            }));
        }
        if let Some((name, value)) = self.parameters.next() {
            let first = self.samples.peek().map_or(0.0, |s| s.time_s);
            return Ok(Some(Telemetry {
                time_s: first,
                event: Event::Parameter { name, value },
            }));
        }
        let sample_first = match (self.samples.peek(), self.events.peek()) {
            (Some(s), Some(e)) => s.time_s <= e.time_s,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (None, None) => return Ok(None),
        };
        Ok(match sample_first {
            true => self.samples.next().map(|s| Telemetry {
                time_s: s.time_s,
                event: Event::Sample(s),
            }),
            false => self.events.next(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The log's parameters come after its origin and before its first record, at that
    /// record's time, in the order given.
    #[test]
    fn a_replayed_log_sends_its_parameters_before_its_first_record() {
        let samples = [3.0, 3.5].map(|time_s| Sample {
            time_s,
            ..Sample::default()
        });
        let log = Log {
            samples: samples.to_vec(),
            origin: Some(GeoOrigin {
                lat_rad: 0.8,
                lon_rad: 0.1,
                alt_m: 10.0,
            }),
            ..Log::default()
        };
        let params = vec![
            ("BAT_LOW_THR".to_string(), 0.15),
            ("BAT1_N_CELLS".into(), 3.0),
        ];
        let mut events = LogEvents::new(log).with_parameters(params);
        let got: Vec<Telemetry> = std::iter::from_fn(|| events.next_event().unwrap()).collect();
        assert_eq!(got.len(), 5);
        assert!(matches!(got[0].event, Event::Origin(_)));
        assert_eq!(
            got[1].event,
            Event::Parameter {
                name: "BAT_LOW_THR".into(),
                value: 0.15
            }
        );
        assert_eq!(
            got[2].event,
            Event::Parameter {
                name: "BAT1_N_CELLS".into(),
                value: 3.0
            }
        );
        // Times copied from the samples, not computed: exact.
        assert_eq!(got[1].time_s.to_bits(), 3.0f64.to_bits());
        let Event::Sample(first) = &got[3].event else {
            panic!("not a sample: {:?}", got[3])
        };
        assert_eq!(first.time_s.to_bits(), 3.0f64.to_bits());
    }

    #[test]
    fn severities_and_charge_states_are_mavlinks() {
        let sev = [
            Severity::Critical,
            Severity::Warning,
            Severity::Notice,
            Severity::Info,
        ]
        .map(Severity::mav_severity);
        // common.xml MAV_SEVERITY: CRITICAL 2, WARNING 4, NOTICE 5, INFO 6.
        assert_eq!(sev, [2, 4, 5, 6]);
        let states = [
            ChargeState::Undefined,
            ChargeState::Ok,
            ChargeState::Low,
            ChargeState::Critical,
            ChargeState::Emergency,
        ]
        .map(ChargeState::mav_charge_state);
        assert_eq!(states, [0, 1, 2, 3, 4]);
    }
}
