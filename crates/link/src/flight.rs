//! What a telemetry log says of its flight, for a logbook: when the vehicle was armed and in the
//! air, and the energy it drew meanwhile ([`read_tlog_flight`]).
//!
//! - **Armed**: HEARTBEAT's `MAV_MODE_FLAG_SAFETY_ARMED`, from the vehicle (the autopilot
//!   [`Decoder`] takes as the vehicle). The flight is the stretch from the first arming to the
//!   last disarming (or the vehicle's last message, when the log ends armed): a ground station
//!   records from when it connects, an autopilot's own log from arming, and this makes the two
//!   alike.
//! - **In the air**: armed and not landed, where EXTENDED_SYS_STATE says the landed state
//!   (`ON_GROUND` landed; `IN_AIR`, `TAKEOFF`, `LANDING` not); armed alone where it never does.
//! - **Battery**: the records of the flight's stretch with a voltage, from SYS_STATUS
//!   (`voltage_battery`, `current_battery`) or BATTERY_STATUS of battery 0 (the sum of its cells,
//!   `current_battery`), whichever gives more records with both. Energy and charge are the
//!   trapezoids of V·I and I over them, as for every other log of the logbook; where no record
//!   has a current, the charge is the growth of BATTERY_STATUS `current_consumed` over the
//!   stretch and the energy that of `energy_consumed`, when they only grow.
//! - **Identity**: the vehicle's ArduPilot `BRD_SERIAL_NUM` (PARAM_VALUE, not 0, as the logbook
//!   keys a DataFlash log), else AUTOPILOT_VERSION `uid2` in hex (PX4 sends its `px4_guid`, the
//!   `sys_uuid` of its ULogs), else `uid` in hex; the pack's `BATT_SERIAL_NUM` (not -1 or 0);
//!   the rated capacity `BATT_CAPACITY` or `BAT1_CAPACITY`.
//!
//! Times are the log's timestamps (µs since 1970), never less than the frame before's.

use std::io::Read;

use mavlink::dialects::ardupilotmega::{
    MavLandedState, MavMessage, MavModeFlag, BATTERY_STATUS_DATA, SYS_STATUS_DATA,
};
use mavlink::MavHeader;

use crate::decode::Decoder;
use crate::error::LinkError;
use crate::tlog::TlogReader;

/// The flight of a telemetry log (see the module docs).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TlogFlight {
    /// The vehicle's identity (see the module docs).
    pub vehicle_id: Option<String>,
    /// The pack's serial number (`BATT_SERIAL_NUM`).
    pub pack_id: Option<String>,
    /// The pack's rated capacity (`BATT_CAPACITY`, `BAT1_CAPACITY`), mAh.
    pub rated_capacity_mah: Option<f64>,
    /// The first battery record of the flight, Unix time, s.
    pub start_unix_s: f64,
    /// From the first to the last battery record of the flight, s.
    pub duration_s: f64,
    /// Time armed, s.
    pub armed_s: f64,
    /// Time in the air (armed and not landed), s.
    pub air_s: f64,
    /// Times the vehicle went into the air.
    pub air_spans: usize,
    /// Energy drawn over the flight, Wh.
    pub energy_wh: f64,
    /// Charge drawn over the flight, mAh (`None` without a current or a counter).
    pub discharged_mah: Option<f64>,
    /// Largest current, A.
    pub max_current_a: Option<f64>,
    /// Lowest voltage, V.
    pub min_voltage_v: f64,
    /// The pack's high voltage: the 95th percentile of the flight's records (a spike of a few
    /// records aside), V.
    pub high_voltage_v: f64,
    /// Battery records of the flight.
    pub battery_records: usize,
}

/// One battery record: time (s from the first frame), voltage (V), current (A, where sent).
type Record = (f64, f64, Option<f64>);
/// The autopilot's counters at a time: (s, `current_consumed` mAh, `energy_consumed` hJ).
type Counters = (f64, Option<f64>, Option<f64>);

/// The vehicle's state as the log goes: what [`read_tlog_flight`] gathers in one pass.
#[derive(Debug, Default)]
struct Gathered {
    first_us: Option<u64>,
    now_s: f64,
    armed: bool,
    landed: Option<bool>,
    /// First arming and last disarming (or last message while armed), s.
    armed_from_s: Option<f64>,
    armed_until_s: Option<f64>,
    armed_s: f64,
    air_s: f64,
    air_spans: usize,
    /// When the armed or landed state last changed, s.
    state_since_s: Option<f64>,
    /// The vehicle's last message, s.
    last_vehicle_s: f64,
    sys_status: Vec<Record>,
    battery_status: Vec<Record>,
    /// (time s, current_consumed mAh, energy_consumed hJ), where sent.
    counters: Vec<Counters>,
    brd_serial: Option<f64>,
    batt_serial: Option<f64>,
    rated_capacity_mah: Option<f64>,
    uid: u64,
    uid2: Vec<u8>,
}

/// Read the flight of the telemetry log `source` (`name` is what errors say).
///
/// # Errors
/// A read error; no MAVLink frame at all ([`LinkError::NothingReadable`]); a vehicle never
/// armed ([`LinkError::NeverArmed`]); fewer than two battery records with a voltage while armed
/// ([`LinkError::NoBatteryVoltage`]).
pub fn read_tlog_flight<R: Read>(source: R, name: &str) -> Result<TlogFlight, LinkError> {
    let mut reader = TlogReader::new(source, name);
    let mut decoder = Decoder::new();
    let mut g = Gathered::default();
    let mut sink: Vec<aloft_logs::telemetry::Telemetry> = Vec::new();
    while let Some(frame) = reader.next_frame()? {
        let first = *g.first_us.get_or_insert(frame.timestamp_us);
        let t_s = (frame.timestamp_us as f64 - first as f64) * 1e-6;
        g.now_s = g.now_s.max(t_s);
        sink.clear();
        if decoder.push(g.now_s, &frame.header, &frame.message, &mut sink) {
            g.vehicle_message(&frame.header, &frame.message);
        }
    }
    if reader.stats().frames == 0 {
        return Err(LinkError::NothingReadable {
            name: name.to_owned(),
            bytes: reader.stats().bytes,
        });
    }
    g.finish();
    g.flight(name)
}

impl Gathered {
    fn vehicle_message(&mut self, _header: &MavHeader, msg: &MavMessage) {
        match msg {
            MavMessage::HEARTBEAT(hb) => {
                let armed = hb
                    .base_mode
                    .contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED);
                self.set_state(armed, self.landed);
            }
            MavMessage::EXTENDED_SYS_STATE(e) => {
                let landed = match e.landed_state {
                    MavLandedState::MAV_LANDED_STATE_ON_GROUND => Some(true),
                    MavLandedState::MAV_LANDED_STATE_UNDEFINED => self.landed,
                    _ => Some(false),
                };
                self.set_state(self.armed, landed);
            }
            MavMessage::SYS_STATUS(s) => self.sys_status(s),
            MavMessage::BATTERY_STATUS(b) if b.id == 0 => self.battery_status(b),
            MavMessage::PARAM_VALUE(p) => {
                let id: String = p
                    .param_id
                    .iter()
                    .take_while(|&&c| c != 0)
                    .map(|&c| char::from(c))
                    .collect();
                self.parameter(&id, f64::from(p.param_value));
            }
            MavMessage::AUTOPILOT_VERSION(a) => {
                if a.uid != 0 {
                    self.uid = a.uid;
                }
                if a.uid2.iter().any(|&b| b != 0) {
                    self.uid2 = a.uid2.to_vec();
                }
            }
            _ => {}
        }
        if self.armed {
            self.armed_until_s = Some(self.now_s);
        }
        self.last_vehicle_s = self.now_s;
    }

    /// The vehicle's armed and landed state from now on: the time since the last change
    /// counted as armed and in the air by the state before it.
    fn set_state(&mut self, armed: bool, landed: Option<bool>) {
        let since_s = self.state_since_s.unwrap_or(self.now_s);
        let was_airborne = self.armed && self.landed != Some(true);
        let airborne = armed && landed != Some(true);
        if self.armed {
            self.armed_s += self.now_s - since_s;
        }
        if was_airborne {
            self.air_s += self.now_s - since_s;
        }
        if airborne && !was_airborne {
            self.air_spans += 1;
        }
        if armed && self.armed_from_s.is_none() {
            self.armed_from_s = Some(self.now_s);
        }
        if armed || self.armed {
            self.armed_until_s = Some(self.now_s);
        }
        self.state_since_s = Some(self.now_s);
        self.armed = armed;
        self.landed = landed;
    }

    /// The end of the log: a vehicle still armed is taken to disarm at its last message.
    fn finish(&mut self) {
        self.now_s = self.last_vehicle_s;
        self.set_state(false, self.landed);
    }

    fn sys_status(&mut self, s: &SYS_STATUS_DATA) {
        if s.voltage_battery != 0 && s.voltage_battery != u16::MAX {
            let current_a = (s.current_battery >= 0).then(|| f64::from(s.current_battery) / 100.0);
            self.sys_status
                .push((self.now_s, f64::from(s.voltage_battery) / 1000.0, current_a));
        }
    }

    fn battery_status(&mut self, b: &BATTERY_STATUS_DATA) {
        if let Some(voltage_v) = crate::decode::pack_voltage_v(b) {
            let current_a = (b.current_battery >= 0).then(|| f64::from(b.current_battery) / 100.0);
            self.battery_status.push((self.now_s, voltage_v, current_a));
        }
        let mah = (b.current_consumed >= 0).then(|| f64::from(b.current_consumed));
        let hj = (b.energy_consumed >= 0).then(|| f64::from(b.energy_consumed));
        if mah.is_some() || hj.is_some() {
            self.counters.push((self.now_s, mah, hj));
        }
    }

    fn parameter(&mut self, id: &str, value: f64) {
        if !value.is_finite() {
            return;
        }
        match id {
            "BRD_SERIAL_NUM" => self.brd_serial = Some(value),
            "BATT_SERIAL_NUM" => self.batt_serial = Some(value),
            "BATT_CAPACITY" | "BAT1_CAPACITY" => {
                self.rated_capacity_mah = (value > 0.0).then_some(value);
            }
            _ => {}
        }
    }

    /// The flight of the gathered log.
    fn flight(&self, name: &str) -> Result<TlogFlight, LinkError> {
        let (Some(from_s), Some(until_s)) = (self.armed_from_s, self.armed_until_s) else {
            return Err(LinkError::NeverArmed {
                name: name.to_owned(),
            });
        };
        let in_flight = |r: &&Record| r.0 >= from_s && r.0 <= until_s;
        let with_current =
            |v: &[Record]| v.iter().filter(in_flight).filter(|r| r.2.is_some()).count();
        let source = if with_current(&self.battery_status) > with_current(&self.sys_status) {
            &self.battery_status
        } else {
            &self.sys_status
        };
        let records: Vec<Record> = source.iter().filter(in_flight).copied().collect();
        if records.len() < 2 {
            return Err(LinkError::NoBatteryVoltage {
                name: name.to_owned(),
            });
        }
        let (energy_wh, discharged_mah) = self.energy(&records, from_s, until_s);
        let first_us = self.first_us.unwrap_or(0) as f64 * 1e-6;
        let mut volts: Vec<f64> = records.iter().map(|r| r.1).collect();
        volts.sort_by(f64::total_cmp);
        Ok(TlogFlight {
            vehicle_id: self.vehicle_id(),
            pack_id: self
                .batt_serial
                .filter(|v| v.abs() >= 0.5 && (v + 1.0).abs() >= 0.5)
                .map(|v| format!("{}", v.round() as i64)),
            rated_capacity_mah: self.rated_capacity_mah,
            start_unix_s: first_us + records[0].0,
            duration_s: records[records.len() - 1].0 - records[0].0,
            armed_s: self.armed_s,
            air_s: self.air_s,
            air_spans: self.air_spans,
            energy_wh,
            discharged_mah,
            max_current_a: records.iter().filter_map(|r| r.2).reduce(f64::max),
            min_voltage_v: volts[0],
            high_voltage_v: volts[((volts.len() - 1) as f64 * 0.95).floor() as usize],
            battery_records: records.len(),
        })
    }

    /// Energy (Wh) and charge (mAh) over the records: the trapezoids of V·I and I over the
    /// intervals whose two ends have a current; else the growth of the autopilot's counters
    /// over the flight, where they only grow.
    fn energy(&self, records: &[Record], from_s: f64, until_s: f64) -> (f64, Option<f64>) {
        let (mut joules, mut coulombs, mut any) = (0.0, 0.0, false);
        for w in records.windows(2) {
            let ((t0, v0, i0), (t1, v1, i1)) = (w[0], w[1]);
            if let (Some(i0), Some(i1)) = (i0, i1) {
                let dt = t1 - t0;
                joules += 0.5 * (v0 * i0 + v1 * i1) * dt;
                coulombs += 0.5 * (i0 + i1) * dt;
                any = true;
            }
        }
        if any {
            return (joules / 3600.0, Some(coulombs / 3.6));
        }
        let counters: Vec<_> = self
            .counters
            .iter()
            .filter(|c| c.0 >= from_s && c.0 <= until_s)
            .collect();
        let growth = |pick: fn(&Counters) -> Option<f64>| {
            let v: Vec<f64> = counters.iter().filter_map(|c| pick(c)).collect();
            let grows = v.len() >= 2 && v.windows(2).all(|w| w[1] >= w[0]);
            grows.then(|| v[v.len() - 1] - v[0])
        };
        // energy_consumed is in hJ: 100 J each, 3600 J a Wh.
        let wh = growth(|c| c.2).map(|hj| hj * 100.0 / 3600.0);
        (wh.unwrap_or(0.0), growth(|c| c.1))
    }

    fn vehicle_id(&self) -> Option<String> {
        if let Some(s) = self.brd_serial.filter(|v| v.abs() >= 0.5) {
            return Some(format!("{}", s.round() as i64));
        }
        if !self.uid2.is_empty() {
            return Some(self.uid2.iter().map(|b| format!("{b:02x}")).collect());
        }
        (self.uid != 0).then(|| format!("{:016x}", self.uid))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(g: &mut Gathered, t: f64) {
        g.now_s = t;
        g.last_vehicle_s = t;
    }

    /// Armed at 0 s (landed state not yet said: in the air), on the ground at 20 s, disarmed at
    /// 25 s; armed again at 30 s until the log ends at 40 s: 35 s armed, 30 s in the air in two
    /// spans, the flight from 0 s to 40 s.
    #[test]
    fn armed_and_air_time_by_hand() {
        let mut g = Gathered::default();
        at(&mut g, 0.0);
        g.set_state(true, None);
        at(&mut g, 10.0);
        g.set_state(true, Some(false));
        at(&mut g, 20.0);
        g.set_state(true, Some(true));
        at(&mut g, 25.0);
        g.set_state(false, Some(true));
        at(&mut g, 30.0);
        g.set_state(true, Some(false));
        at(&mut g, 40.0);
        g.armed_until_s = Some(40.0);
        g.finish();
        assert!((g.armed_s - 35.0).abs() < 1e-12, "{}", g.armed_s);
        assert!((g.air_s - 30.0).abs() < 1e-12, "{}", g.air_s);
        assert_eq!(g.air_spans, 2);
        assert_eq!((g.armed_from_s, g.armed_until_s), (Some(0.0), Some(40.0)));
    }

    /// 10 V and 2 A for an hour: 20 Wh and 2000 mAh by the trapezoids; without a current, the
    /// counters' growth (1500 mAh, 360 hJ = 10 Wh), and none where a counter goes back.
    #[test]
    fn energy_by_trapezoid_else_by_the_counters() {
        let g = Gathered::default();
        let records = [
            (0.0, 10.0, Some(2.0)),
            (1800.0, 10.0, Some(2.0)),
            (3600.0, 10.0, Some(2.0)),
        ];
        let (wh, mah) = g.energy(&records, 0.0, 3600.0);
        assert!((wh - 20.0).abs() < 1e-9 && (mah.unwrap() - 2000.0).abs() < 1e-9);
        let mut g = Gathered {
            counters: vec![
                (0.0, Some(100.0), Some(40.0)),
                (3600.0, Some(1600.0), Some(400.0)),
            ],
            ..Gathered::default()
        };
        let bare = [(0.0, 10.0, None), (3600.0, 10.0, None)];
        let (wh, mah) = g.energy(&bare, 0.0, 3600.0);
        assert!((wh - 10.0).abs() < 1e-9 && (mah.unwrap() - 1500.0).abs() < 1e-9);
        g.counters.push((3601.0, Some(5.0), None));
        let (_, mah) = g.energy(&bare, 0.0, 4000.0);
        assert_eq!(mah, None);
    }
}
