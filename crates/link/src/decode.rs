//! MAVLink messages of the vehicle into aloft's telemetry events ([`Telemetry`]).
//!
//! The vehicle is the first system to send a HEARTBEAT whose autopilot is not
//! `MAV_AUTOPILOT_INVALID` and whose type is not a ground station; its state comes from the
//! component that sent that HEARTBEAT (the autopilot), so a companion computer or camera of the
//! same system, other vehicles and ground stations are ignored. Mission transfers are the
//! exception: a ground station's upload to the vehicle is read too ([`crate::mission`]).
//! Messages before the vehicle's first HEARTBEAT cannot be told apart and are dropped (the
//! first second of a log at most).
//!
//! | message | event |
//! |---|---|
//! | HEARTBEAT | [`Event::Heartbeat`]: armed (`base_mode` safety flag), mode by name ([`mode_name`]), MAV_TYPE |
//! | SYS_STATUS | [`Event::Sample`]: `voltage_battery` mV -> V (unless 0 or UINT16_MAX), `current_battery` cA -> A (unless -1); [`Event::Battery`]: `battery_remaining` % -> soc (unless -1) |
//! | BATTERY_STATUS (id 0) | [`Event::Sample`]: sum of the cell voltages, current; [`Event::Battery`]: soc, `current_consumed` mAh -> A h (unless -1; another negative count is passed on for the reader to judge) |
//! | GLOBAL_POSITION_INT | [`Event::Origin`] at the first fix the next one confirms, then [`Event::Sample`]: position ENU from the origin (east and north on the WGS84 tangent plane, up from `relative_alt`, see below), velocity NED cm/s -> ENU m/s; fixes off the Earth or out of reach are dropped (see below) |
//! | ATTITUDE | [`Event::Sample`]: roll, pitch, yaw (rad, yaw wrapped to (-pi, pi]) |
//! | VFR_HUD | [`Event::Speeds`] |
//! | WIND | [`Event::Sample`]: the velocity of the air, ENU: `direction` is where it comes from (deg), `speed` horizontal, `speed_z` down (ArduPilot's NED z) |
//! | HOME_POSITION | [`Event::Home`], ENU from the origin (held until the origin; up where `relative_alt` is 0); dropped off the Earth or over 100 km from the vehicle |
//! | EXTENDED_SYS_STATE | [`Event::Sample`]: landed (ON_GROUND) or not (IN_AIR, TAKEOFF, LANDING) |
//! | MISSION_CURRENT | [`Event::MissionCurrent`] |
//! | PARAM_VALUE | [`Event::Parameter`], asked for or not: its value decoded by [`param_value`] |
//! | MISSION_COUNT, MISSION_ITEM(_INT), MISSION_ACK | [`Event::Mission`] ([`crate::mission`]) |
//! | SYSTEM_TIME, ATTITUDE, GLOBAL_POSITION_INT `time_boot_ms` | [`Event::Reboot`] when it goes back by more than [`REBOOT_BACK_MS`] |
//!
//! Height: up is `relative_alt` (the height above home) less its value at the origin, plus the
//! change of home's altitude since then (HOME_POSITION; ArduPilot moves home when it arms,
//! and `relative_alt` with it). `alt` (AMSL) is not used for it: in the shared logs of older
//! ArduCopter versions it equals `relative_alt` (`phoenix_mission1_real.tlog`, APM:Copter 3.5.7:
//! 0.85 m at the first fix, 90 m below its HOME_POSITION). The origin's altitude is `alt` at the
//! first fix, as the autopilot reports it.
//!
//! Time: each event carries the time it was given, never less than the last one (a message out of
//! order takes the time of the one before it). A value that is not finite is dropped (a sample
//! without that channel), except mission parameters, which are passed as sent (MAVLink's NaN
//! means "not set").
//!
//! Positions: a fix off the Earth (latitude beyond +-90 deg, longitude beyond +-180 deg, an
//! altitude below -500 m or above 12 km, a height over 10 km from home's) or out of reach of the
//! last one believed (faster than [`MAX_SPEED_MPS`], 150 m/s, over the time between them, with
//! [`FIX_SLACK_M`] of slack) is not believed: the message is dropped and counted
//! ([`Decoder::fixes`]), and the vehicle stays where it was. The first fix of a flight becomes
//! the origin only once the next one is within its reach, so a bad first fix is never the origin
//! (nor home, which is the origin until the vehicle sends one). A velocity faster than
//! [`MAX_SPEED_MPS`] is dropped too. See [`fix`] for the bounds and why.
//!
//! After a [`Event::Reboot`] the decoder starts the flight over: the next fix sends a new
//! [`Event::Origin`], and the mission the vehicle keeps in its storage is sent again.

use std::f64::consts::PI;

use aloft_logs::frame::{geodetic_to_enu, ned_to_enu};
use aloft_logs::sample::{Attitude, GeoOrigin, Sample};
use aloft_logs::telemetry::{BatteryState, Event, Heartbeat, MissionItem, Telemetry};
#[allow(deprecated)] // MISSION_ITEM_DATA (see `Decoder::vehicle_message`)
use mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavLandedState, MavMessage, MavMissionType, MavModeFlag, MavParamType, MavType,
    ATTITUDE_DATA, BATTERY_STATUS_DATA, GLOBAL_POSITION_INT_DATA, HEARTBEAT_DATA,
    HOME_POSITION_DATA, MISSION_ITEM_DATA, MISSION_ITEM_INT_DATA, PARAM_VALUE_DATA,
    SYS_STATUS_DATA, WIND_DATA,
};
use mavlink::MavHeader;

use crate::mission::{MissionAssembler, Sender};
use crate::modes::mode_name;

pub mod fix;

use fix::{on_earth, plausible_velocity, reachable, Fix, DEG_E7};
pub use fix::{FIX_SLACK_M, MAX_HOME_DISTANCE_M, MAX_SPEED_MPS};

/// How far the vehicle's boot time must go back to be a restart, ms (messages out of order by
/// more than a second are rare; a restart takes its boot time back to a few seconds).
pub const REBOOT_BACK_MS: u32 = 3_000;

/// Positions the decoder did not believe (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FixStats {
    /// GLOBAL_POSITION_INT off the Earth (latitude, longitude, altitude out of range).
    pub off_earth: u64,
    /// GLOBAL_POSITION_INT out of reach of the last fix believed.
    pub out_of_reach: u64,
    /// HOME_POSITION off the Earth or too far from the vehicle.
    pub homes: u64,
    /// Velocities faster than [`MAX_SPEED_MPS`].
    pub velocities: u64,
}

impl FixStats {
    /// Whether nothing was dropped.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }
}

/// What the decoder makes of a fix on the Earth.
enum Verdict {
    /// Believed: the position ENU from the origin.
    Believed([f64; 3]),
    /// Waiting for the next fix to confirm it as the origin (no position yet).
    Pending,
    /// Out of reach of the last fix believed: dropped.
    Glitch,
}

/// Turns messages into events (see the module docs). Memory is flat: a few numbers of state and
/// the mission being assembled.
#[derive(Debug, Default)]
pub struct Decoder {
    vehicle: Option<Sender>,
    /// The vehicle's autopilot (its first HEARTBEAT's): how its parameters are encoded.
    autopilot: Option<MavAutopilot>,
    /// Restarts of the vehicle seen.
    reboots: u32,
    origin: Option<GeoOrigin>,
    /// HOME_POSITION received before the origin: latitude, longitude (rad).
    pending_home: Option<[f64; 2]>,
    /// The last fix believed; before the origin, the fix waiting for the next to confirm it.
    last_fix: Option<Fix>,
    fixes: FixStats,
    /// `relative_alt` at the first fix, m.
    origin_relative_m: f64,
    /// Home's altitude at its last HOME_POSITION, m.
    home_alt_m: Option<f64>,
    /// Change of home's altitude since the origin was set, m.
    home_shift_m: f64,
    last_time_s: f64,
    boot_ms: Option<u32>,
    mission: MissionAssembler,
    vehicle_messages: u64,
}

impl Decoder {
    /// A decoder that has seen nothing yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The vehicle's system and component ids, once its HEARTBEAT was seen.
    pub fn vehicle(&self) -> Option<(u32, u8)> {
        self.vehicle
    }

    /// The vehicle's autopilot (MAV_AUTOPILOT of its first HEARTBEAT), once seen.
    pub fn autopilot(&self) -> Option<MavAutopilot> {
        self.autopilot
    }

    /// Restarts of the vehicle seen so far ([`Event::Reboot`]).
    pub fn reboots(&self) -> u32 {
        self.reboots
    }

    /// The origin of the ENU positions, once the first fix was seen.
    pub fn origin(&self) -> Option<GeoOrigin> {
        self.origin
    }

    /// The mission as the vehicle holds it, once a whole one has been seen.
    pub fn mission(&self) -> Option<&[MissionItem]> {
        self.mission.known()
    }

    /// Messages of the vehicle decoded so far.
    pub fn vehicle_messages(&self) -> u64 {
        self.vehicle_messages
    }

    /// Positions, homes and velocities not believed so far.
    pub fn fixes(&self) -> FixStats {
        self.fixes
    }

    /// The stream was silent for `silent_s` seconds that its times do not count (a telemetry
    /// log's clock step, taken out of its times): the vehicle may have moved that much longer
    /// since its last fix.
    pub fn gap(&mut self, silent_s: f64) {
        if let Some(f) = &mut self.last_fix {
            if silent_s.is_finite() && silent_s > 0.0 {
                f.time_s -= silent_s;
            }
        }
    }

    /// Decodes one message received at `time_s` (s from the stream's start), appending its
    /// events to `out`. Returns whether the message came from the vehicle.
    pub fn push(
        &mut self,
        time_s: f64,
        header: &MavHeader,
        msg: &MavMessage,
        out: &mut impl Extend<Telemetry>,
    ) -> bool {
        if time_s.is_finite() && time_s > self.last_time_s {
            self.last_time_s = time_s;
        }
        let sender = (header.system_id, header.component_id);
        if self.vehicle.is_none() {
            if let MavMessage::HEARTBEAT(hb) = msg {
                if is_vehicle(hb) {
                    self.vehicle = Some(sender);
                    self.autopilot = Some(hb.autopilot);
                }
            }
        }
        let Some(vehicle) = self.vehicle else {
            return false;
        };
        if sender != vehicle {
            self.other_message(sender, vehicle.0, msg, out);
            return false;
        }
        self.vehicle_messages += 1;
        self.vehicle_message(sender, msg, out);
        true
    }

    /// The end of the stream: a mission being collected without a count is emitted.
    pub fn finish(&mut self, out: &mut impl Extend<Telemetry>) {
        if let Some(items) = self.mission.finish() {
            self.emit(out, Event::Mission(items));
        }
    }

    fn emit(&self, out: &mut impl Extend<Telemetry>, event: Event) {
        out.extend(std::iter::once(Telemetry {
            time_s: self.last_time_s,
            event,
        }));
    }

    fn sample(&self) -> Sample {
        Sample {
            time_s: self.last_time_s,
            ..Sample::default()
        }
    }

    // MISSION_ITEM is deprecated by MAVLink (2020) but still sent by older autopilots and ground
    // stations (one shared log has it).
    #[allow(deprecated)]
    fn vehicle_message(
        &mut self,
        sender: Sender,
        msg: &MavMessage,
        out: &mut impl Extend<Telemetry>,
    ) {
        match msg {
            MavMessage::HEARTBEAT(hb) => self.heartbeat(hb, out),
            MavMessage::SYS_STATUS(s) => self.sys_status(s, out),
            MavMessage::BATTERY_STATUS(b) => self.battery_status(b, out),
            MavMessage::GLOBAL_POSITION_INT(p) => {
                self.boot_time(p.time_boot_ms, out);
                self.position(p, out);
            }
            MavMessage::ATTITUDE(a) => {
                self.boot_time(a.time_boot_ms, out);
                self.attitude(a, out);
            }
            MavMessage::SYSTEM_TIME(t) => self.boot_time(t.time_boot_ms, out),
            MavMessage::VFR_HUD(v) => {
                let (airspeed_mps, groundspeed_mps) =
                    (f64::from(v.airspeed), f64::from(v.groundspeed));
                if airspeed_mps.is_finite() && groundspeed_mps.is_finite() {
                    self.emit(
                        out,
                        Event::Speeds {
                            airspeed_mps,
                            groundspeed_mps,
                        },
                    );
                }
            }
            MavMessage::WIND(w) => self.wind(w, out),
            MavMessage::HOME_POSITION(h) => self.home(h, out),
            MavMessage::EXTENDED_SYS_STATE(e) => {
                let landed = match e.landed_state {
                    MavLandedState::MAV_LANDED_STATE_ON_GROUND => Some(true),
                    MavLandedState::MAV_LANDED_STATE_IN_AIR
                    | MavLandedState::MAV_LANDED_STATE_TAKEOFF
                    | MavLandedState::MAV_LANDED_STATE_LANDING => Some(false),
                    MavLandedState::MAV_LANDED_STATE_UNDEFINED => None,
                };
                if landed.is_some() {
                    let s = Sample {
                        landed,
                        ..self.sample()
                    };
                    self.emit(out, Event::Sample(s));
                }
            }
            MavMessage::MISSION_CURRENT(m) => {
                self.emit(out, Event::MissionCurrent(u32::from(m.seq)));
            }
            MavMessage::PARAM_VALUE(p) => self.parameter(p, out),
            MavMessage::MISSION_COUNT(c) if is_mission(c.mission_type) => {
                let done = self.mission.count(sender, c.count);
                self.mission_event(done, out);
            }
            MavMessage::MISSION_ITEM(i) if is_mission(i.mission_type) => {
                let done = self.mission.item(sender, true, mission_item(i));
                self.mission_event(done, out);
            }
            MavMessage::MISSION_ITEM_INT(i) if is_mission(i.mission_type) => {
                let done = self.mission.item(sender, true, mission_item_int(i));
                self.mission_event(done, out);
            }
            MavMessage::MISSION_ACK(a) if is_mission(a.mission_type) => {
                let done = self.mission.ack();
                self.mission_event(done, out);
            }
            _ => {}
        }
    }

    /// Mission protocol messages of another system addressed to the vehicle's system (an upload
    /// and its acknowledgement).
    #[allow(deprecated)] // MISSION_ITEM, as above
    fn other_message(
        &mut self,
        sender: Sender,
        vehicle_system: u32,
        msg: &MavMessage,
        out: &mut impl Extend<Telemetry>,
    ) {
        let to_vehicle = |target: u8| u32::from(target) == vehicle_system;
        let done = match msg {
            MavMessage::MISSION_COUNT(c)
                if to_vehicle(c.target_system) && is_mission(c.mission_type) =>
            {
                self.mission.count(sender, c.count)
            }
            MavMessage::MISSION_ITEM(i)
                if to_vehicle(i.target_system) && is_mission(i.mission_type) =>
            {
                self.mission.item(sender, false, mission_item(i))
            }
            MavMessage::MISSION_ITEM_INT(i)
                if to_vehicle(i.target_system) && is_mission(i.mission_type) =>
            {
                self.mission.item(sender, false, mission_item_int(i))
            }
            MavMessage::MISSION_ACK(a)
                if to_vehicle(a.target_system) && is_mission(a.mission_type) =>
            {
                self.mission.ack()
            }
            _ => None,
        };
        self.mission_event(done, out);
    }

    fn mission_event(&self, done: Option<Vec<MissionItem>>, out: &mut impl Extend<Telemetry>) {
        if let Some(items) = done {
            self.emit(out, Event::Mission(items));
        }
    }

    fn heartbeat(&self, hb: &HEARTBEAT_DATA, out: &mut impl Extend<Telemetry>) {
        let heartbeat = Heartbeat {
            armed: hb
                .base_mode
                .contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED),
            mode: mode_name(hb.autopilot, hb.mavtype, hb.custom_mode),
            vehicle_type: hb.mavtype as u8,
        };
        self.emit(out, Event::Heartbeat(heartbeat));
    }

    fn sys_status(&self, s: &SYS_STATUS_DATA, out: &mut impl Extend<Telemetry>) {
        let voltage_v = (s.voltage_battery != 0 && s.voltage_battery != u16::MAX)
            .then(|| f64::from(s.voltage_battery) / 1000.0);
        let current_a = (s.current_battery != -1).then(|| f64::from(s.current_battery) / 100.0);
        self.battery_sample(voltage_v, current_a, out);
        if let Some(soc) = soc(s.battery_remaining) {
            let battery = BatteryState {
                soc: Some(soc),
                consumed_ah: None,
            };
            self.emit(out, Event::Battery(battery));
        }
    }

    /// PARAM_VALUE: the parameter by name, its value as [`param_value`] decodes it (not sent
    /// where it cannot be, or is not finite).
    fn parameter(&self, p: &PARAM_VALUE_DATA, out: &mut impl Extend<Telemetry>) {
        // The id up to its first NUL (16 characters without one); not UTF-8: not a name.
        let Ok(name) = p.param_id.to_str() else {
            return;
        };
        let bytewise = self.autopilot == Some(MavAutopilot::MAV_AUTOPILOT_PX4);
        let value = param_value(p.param_value, p.param_type, bytewise);
        if let (false, Some(value)) = (name.is_empty(), value.filter(|v| v.is_finite())) {
            let name = name.to_string();
            self.emit(out, Event::Parameter { name, value });
        }
    }

    /// A sample of the pack's voltage and current, where the message carried either.
    fn battery_sample(
        &self,
        voltage_v: Option<f64>,
        current_a: Option<f64>,
        out: &mut impl Extend<Telemetry>,
    ) {
        if voltage_v.is_some() || current_a.is_some() {
            let sample = Sample {
                voltage_v,
                current_a,
                ..self.sample()
            };
            self.emit(out, Event::Sample(sample));
        }
    }

    /// BATTERY_STATUS of the first battery (id 0); the others are not the flight pack's total.
    fn battery_status(&self, b: &BATTERY_STATUS_DATA, out: &mut impl Extend<Telemetry>) {
        if b.id != 0 {
            return;
        }
        let voltage_v = pack_voltage_v(b);
        let current_a = (b.current_battery != -1).then(|| f64::from(b.current_battery) / 100.0);
        self.battery_sample(voltage_v, current_a, out);
        let battery = BatteryState {
            soc: soc(b.battery_remaining),
            // -1 is "not sent"; any other count is the reader's to believe or not.
            consumed_ah: (b.current_consumed != -1).then(|| f64::from(b.current_consumed) / 1000.0),
        };
        if battery.soc.is_some() || battery.consumed_ah.is_some() {
            self.emit(out, Event::Battery(battery));
        }
    }

    fn position(&mut self, p: &GLOBAL_POSITION_INT_DATA, out: &mut impl Extend<Telemetry>) {
        let vel_enu_mps = self.velocity(p);
        let pos_enu_m = if p.lat != 0 || p.lon != 0 {
            let Some(fix) = Fix::new(self.last_time_s, p) else {
                self.fixes.off_earth += 1;
                return;
            };
            match self.believe(fix, out) {
                Verdict::Believed(enu) => Some(enu),
                Verdict::Pending => None,
                Verdict::Glitch => return,
            }
        } else {
            None
        };
        if vel_enu_mps.is_some() || pos_enu_m.is_some() {
            let sample = Sample {
                vel_enu_mps,
                pos_enu_m,
                ..self.sample()
            };
            self.emit(out, Event::Sample(sample));
        }
    }

    /// The velocity of GLOBAL_POSITION_INT, ENU m/s, unless faster than [`MAX_SPEED_MPS`].
    fn velocity(&mut self, p: &GLOBAL_POSITION_INT_DATA) -> Option<[f64; 3]> {
        let vel_ned = [p.vx, p.vy, p.vz].map(|v| f64::from(v) / 100.0);
        let vel = ned_to_enu(vel_ned);
        if plausible_velocity(vel) {
            return Some(vel);
        }
        self.fixes.velocities += 1;
        None
    }

    /// Whether a fix on the Earth is believed: within reach of the last one believed; before the
    /// origin, within reach of the fix before it, which then becomes the origin (else it waits
    /// in its place for the next).
    fn believe(&mut self, fix: Fix, out: &mut impl Extend<Telemetry>) -> Verdict {
        let within = self
            .last_fix
            .as_ref()
            .is_some_and(|last| reachable(last, &fix));
        match (self.origin, self.last_fix) {
            (Some(origin), Some(_)) if within => {
                self.last_fix = Some(fix);
                Verdict::Believed(self.enu(&origin, &fix))
            }
            (Some(_), _) => {
                self.fixes.out_of_reach += 1;
                Verdict::Glitch
            }
            (None, Some(first)) if within => {
                let origin = self.set_origin(&first, out);
                self.last_fix = Some(fix);
                Verdict::Believed(self.enu(&origin, &fix))
            }
            (None, last) => {
                // Two fixes that disagree: one of them is wrong, the next fix tells which.
                if last.is_some() {
                    self.fixes.out_of_reach += 1;
                }
                self.last_fix = Some(fix);
                Verdict::Pending
            }
        }
    }

    /// A fix ENU from the origin: up from `relative_alt` (see the module docs).
    fn enu(&self, origin: &GeoOrigin, fix: &Fix) -> [f64; 3] {
        let [east, north, _] = geodetic_to_enu(origin, fix.lat_rad, fix.lon_rad, fix.alt_m);
        let up = fix.relative_m - self.origin_relative_m + self.home_shift_m;
        [east, north, up]
    }

    /// The origin at `first` (announced, with a home received before it).
    fn set_origin(&mut self, first: &Fix, out: &mut impl Extend<Telemetry>) -> GeoOrigin {
        let origin = first.origin();
        self.origin = Some(origin);
        self.origin_relative_m = first.relative_m;
        // `relative_alt` is above the current home: home's moves count from here.
        self.home_shift_m = 0.0;
        self.emit(out, Event::Origin(origin));
        if let Some([lat, lon]) = self.pending_home.take() {
            if self.home_near(first, lat, lon) {
                self.emit(out, Event::Home(self.home_enu(&origin, lat, lon)));
            } else {
                self.home_alt_m = None;
            }
        }
        origin
    }

    /// Whether a home (rad) is within [`MAX_HOME_DISTANCE_M`] of a fix; counted when not.
    fn home_near(&mut self, fix: &Fix, lat_rad: f64, lon_rad: f64) -> bool {
        let d = fix::ground_distance_m(fix.lat_rad, fix.lon_rad, lat_rad, lon_rad);
        let near = d <= MAX_HOME_DISTANCE_M;
        if !near {
            self.fixes.homes += 1;
        }
        near
    }

    /// Home ENU: up where `relative_alt` is 0.
    fn home_enu(&self, origin: &GeoOrigin, lat_rad: f64, lon_rad: f64) -> [f64; 3] {
        let [east, north, _] = geodetic_to_enu(origin, lat_rad, lon_rad, origin.alt_m);
        [east, north, self.home_shift_m - self.origin_relative_m]
    }

    fn attitude(&self, a: &ATTITUDE_DATA, out: &mut impl Extend<Telemetry>) {
        let [roll_rad, pitch_rad, yaw_rad] = [a.roll, a.pitch, a.yaw].map(f64::from);
        if !(roll_rad.is_finite() && pitch_rad.is_finite() && yaw_rad.is_finite()) {
            return;
        }
        let attitude = Attitude {
            roll_rad,
            pitch_rad,
            yaw_rad: wrap_pi(yaw_rad),
        };
        let s = Sample {
            attitude: Some(attitude),
            ..self.sample()
        };
        self.emit(out, Event::Sample(s));
    }

    /// WIND: the velocity of the air, ENU. `direction` is where the wind comes from, clockwise
    /// from north, so the air moves towards `direction + 180 deg`.
    fn wind(&self, w: &WIND_DATA, out: &mut impl Extend<Telemetry>) {
        let [from_deg, speed_mps, down_mps] = [w.direction, w.speed, w.speed_z].map(f64::from);
        if !(from_deg.is_finite() && speed_mps.is_finite() && down_mps.is_finite()) {
            return;
        }
        let from = from_deg.to_radians();
        let wind = [-speed_mps * from.sin(), -speed_mps * from.cos(), -down_mps];
        let s = Sample {
            wind_enu_mps: Some(wind),
            ..self.sample()
        };
        self.emit(out, Event::Sample(s));
    }

    /// HOME_POSITION, unless off the Earth or too far from the vehicle's last fix believed.
    fn home(&mut self, h: &HOME_POSITION_DATA, out: &mut impl Extend<Telemetry>) {
        let (lat_deg, lon_deg) = (
            f64::from(h.latitude) * DEG_E7,
            f64::from(h.longitude) * DEG_E7,
        );
        let alt_m = f64::from(h.altitude) / 1000.0;
        if !on_earth(lat_deg, lon_deg, alt_m) {
            self.fixes.homes += 1;
            return;
        }
        let (lat, lon) = (lat_deg.to_radians(), lon_deg.to_radians());
        let believed = self.origin.and(self.last_fix);
        if let Some(fix) = believed {
            if !self.home_near(&fix, lat, lon) {
                return;
            }
        }
        if let Some(previous) = self.home_alt_m.replace(alt_m) {
            self.home_shift_m += alt_m - previous;
        }
        match self.origin {
            Some(origin) => self.emit(out, Event::Home(self.home_enu(&origin, lat, lon))),
            None => self.pending_home = Some([lat, lon]),
        }
    }

    /// The vehicle's boot time: a restart when it goes back by more than [`REBOOT_BACK_MS`].
    fn boot_time(&mut self, boot_ms: u32, out: &mut impl Extend<Telemetry>) {
        let restarted = self
            .boot_ms
            .is_some_and(|last| boot_ms.saturating_add(REBOOT_BACK_MS) < last);
        self.boot_ms = Some(boot_ms);
        if !restarted {
            return;
        }
        self.emit(out, Event::Reboot);
        self.reboots += 1;
        self.origin = None;
        self.last_fix = None;
        self.pending_home = None;
        self.origin_relative_m = 0.0;
        self.home_alt_m = None;
        self.home_shift_m = 0.0;
        if let Some(items) = self.mission.reboot() {
            self.emit(out, Event::Mission(items));
        }
    }
}

/// Whether a HEARTBEAT is a vehicle's: an autopilot, not a ground station.
fn is_vehicle(hb: &HEARTBEAT_DATA) -> bool {
    hb.autopilot != MavAutopilot::MAV_AUTOPILOT_INVALID && hb.mavtype != MavType::MAV_TYPE_GCS
}

fn is_mission(t: MavMissionType) -> bool {
    t == MavMissionType::MAV_MISSION_TYPE_MISSION
}

/// The pack's voltage of a BATTERY_STATUS, V: the sum of the cells it reports (mV; UINT16_MAX
/// unreported, and 0 too in the extension); `None` when it reports none.
pub(crate) fn pack_voltage_v(b: &BATTERY_STATUS_DATA) -> Option<f64> {
    let cells_mv: u32 = b
        .voltages
        .iter()
        .filter(|&&v| v != u16::MAX)
        .chain(b.voltages_ext.iter().filter(|&&v| v != 0 && v != u16::MAX))
        .map(|&v| u32::from(v))
        .sum();
    (cells_mv > 0).then(|| f64::from(cells_mv) / 1000.0)
}

/// The value of a PARAM_VALUE's `param_value` (a float on the wire) as the parameter's own
/// number.
///
/// The rule: a `REAL32` parameter is the float itself. An integer parameter is encoded one of
/// two ways (MAVLink parameter protocol, "Parameter encoding"; AUTOPILOT_VERSION capabilities
/// `MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE` and `..._C_CAST`): PX4 copies the integer's
/// bytes into the float (`bytewise`: the float's bits, read as the type, are the value; an
/// `INT32` of 3 is the float 4.2e-45), ArduPilot and the others convert the integer to a float
/// (a C cast: the float is the value). Which one is decided by the vehicle's HEARTBEAT autopilot
/// (`MAV_AUTOPILOT_PX4` bytewise), as QGroundControl does. 64-bit types do not fit the float and
/// are `None`.
pub fn param_value(raw: f32, kind: MavParamType, bytewise: bool) -> Option<f64> {
    use MavParamType as T;
    let bits = raw.to_bits();
    let integer = match kind {
        T::MAV_PARAM_TYPE_REAL32 => return Some(f64::from(raw)),
        T::MAV_PARAM_TYPE_UINT64 | T::MAV_PARAM_TYPE_INT64 | T::MAV_PARAM_TYPE_REAL64 => {
            return None
        }
        _ if !bytewise => return Some(f64::from(raw)),
        // The low bytes of the float's bits, as the type (little-endian copy of the value).
        T::MAV_PARAM_TYPE_UINT8 => f64::from(bits as u8),
        T::MAV_PARAM_TYPE_INT8 => f64::from(bits as u8 as i8),
        T::MAV_PARAM_TYPE_UINT16 => f64::from(bits as u16),
        T::MAV_PARAM_TYPE_INT16 => f64::from(bits as u16 as i16),
        T::MAV_PARAM_TYPE_UINT32 => f64::from(bits),
        T::MAV_PARAM_TYPE_INT32 => f64::from(bits as i32),
    };
    Some(integer)
}

/// State of charge of a `battery_remaining` percentage; `None` for -1 (not sent) and values
/// outside 0-100.
fn soc(remaining: i8) -> Option<f64> {
    (0..=100)
        .contains(&remaining)
        .then(|| f64::from(remaining) / 100.0)
}

/// An angle in (-pi, pi].
fn wrap_pi(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI {
        w + 2.0 * PI
    } else {
        w
    }
}

#[allow(deprecated)] // MISSION_ITEM, as above
fn mission_item(i: &MISSION_ITEM_DATA) -> MissionItem {
    let [p1, p2, p3, p4, x, y, z] =
        [i.param1, i.param2, i.param3, i.param4, i.x, i.y, i.z].map(f64::from);
    MissionItem {
        seq: u32::from(i.seq),
        frame: i.frame as u32,
        command: i.command as u32,
        params: [p1, p2, p3, p4, x, y, z],
    }
}

/// MISSION_ITEM_INT: `x`, `y` are degrees x 1e7 in global frames, metres x 1e4 in local frames,
/// and the integer parameters 5 and 6 themselves in the mission frame and others.
fn mission_item_int(i: &MISSION_ITEM_INT_DATA) -> MissionItem {
    let frame = i.frame as u32;
    let scale = match frame {
        // GLOBAL, GLOBAL_RELATIVE_ALT, GLOBAL_INT, GLOBAL_RELATIVE_ALT_INT, GLOBAL_TERRAIN_ALT(_INT).
        0 | 3 | 5 | 6 | 10 | 11 => DEG_E7,
        // LOCAL_NED, LOCAL_ENU, LOCAL_OFFSET_NED, BODY_NED, BODY_OFFSET_NED, BODY_FRD, LOCAL_FRD/FLU.
        1 | 4 | 7 | 8 | 9 | 12 | 20 | 21 => 1e-4,
        _ => 1.0,
    };
    let [p1, p2, p3, p4, z] = [i.param1, i.param2, i.param3, i.param4, i.z].map(f64::from);
    MissionItem {
        seq: u32::from(i.seq),
        frame,
        command: i.command as u32,
        params: [
            p1,
            p2,
            p3,
            p4,
            f64::from(i.x) * scale,
            f64::from(i.y) * scale,
            z,
        ],
    }
}

#[cfg(test)]
mod tests;
