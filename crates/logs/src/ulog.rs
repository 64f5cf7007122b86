//! PX4 ULog, decoded here (sans-I/O, over a [`ByteWindow`]).
//!
//! # Why not the `px4-ulog` crate
//! The PX4 organisation's `px4-ulog` 0.6.1 streams and handles appended data, but it indexes
//! record bytes without checking their length: a 3-byte `A` (add logged message) or `P`
//! (parameter) record of length 0 panics (`index out of bounds` in
//! `stream_parser/file_reader.rs`, lines 405 and 418), which a fuzzed or corrupted log reaches;
//! its errors carry no byte offset, and it stops at the first corrupt record (resynchronisation
//! is "planned"). aloft needs the valid prefix and the rest of the log after a corrupt stretch,
//! with the offset of every problem, so the format (a few record types) is decoded here.
//!
//! # What is read
//! - `vehicle_local_position` (instance 0) is the time base: position, velocity, acceleration,
//!   NED converted to ENU, each only when its `*_valid` flags say so.
//! - `vehicle_attitude` (instance 0): the quaternion (body FRD to NED) as Euler angles.
//! - `wind` or `wind_estimate`: `windspeed_north`, `windspeed_east`.
//! - `battery_status` of the chosen instance (multi_id): `voltage_v`, `current_a`; records with
//!   `current_a` < 0 (unknown) or `voltage_v` <= 0 are dropped and counted. `remaining` (0-1,
//!   negative or NaN when PX4 does not know it) is the reported state of charge
//!   ([`Sample::soc`]) of the records kept.
//! - `vehicle_air_data.rho` (mean air density) and `vehicle_land_detected.landed` (time in the
//!   air, and [`Sample::landed`] of every sample, held from one record to the next), parameters `BAT1_N_CELLS` (or `BAT_N_CELLS`) and `BAT1_CAPACITY`.
//!
//! # Robustness
//! Every length is checked against the record and the record against the input before use;
//! a record that cannot be valid (unknown type, a data record whose size contradicts its format)
//! starts a scan for the next offset where two consecutive plausible records begin, and the
//! bytes skipped are counted and reported with their offset. Appended-data sections (after a
//! crash) are read from the offsets the flag bits give. Records stamped 0 (never set) are left
//! out and counted.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use crate::binary_samples::{self, BinaryOptions, BinarySamples, BinarySummary, Decoder};
use crate::bytes::{le, ByteWindow};
use crate::error::{LogError, Result};
use crate::frame::{attitude_from_ned_frd_quat, ned_to_enu};
use crate::join::{Event, Stream};
use crate::sample::Sample;

/// The first 7 bytes of a ULog file (then a version byte and the start time).
pub const ULOG_MAGIC: [u8; 7] = [0x55, 0x4C, 0x6F, 0x67, 0x01, 0x12, 0x35];

/// Record types of the format.
const KNOWN_TYPES: &[u8] = b"BFIMPQARDLCSO";

/// Deepest nesting of message formats followed.
const MAX_NESTING: usize = 8;

/// A primitive field type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Prim {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
    Bool,
    Char,
}

impl Prim {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "int8_t" => Prim::I8,
            "uint8_t" => Prim::U8,
            "int16_t" => Prim::I16,
            "uint16_t" => Prim::U16,
            "int32_t" => Prim::I32,
            "uint32_t" => Prim::U32,
            "int64_t" => Prim::I64,
            "uint64_t" => Prim::U64,
            "float" => Prim::F32,
            "double" => Prim::F64,
            "bool" => Prim::Bool,
            "char" => Prim::Char,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Prim::I8 | Prim::U8 | Prim::Bool | Prim::Char => 1,
            Prim::I16 | Prim::U16 => 2,
            Prim::I32 | Prim::U32 | Prim::F32 => 4,
            Prim::I64 | Prim::U64 | Prim::F64 => 8,
        }
    }

    /// The value at `at` of `b`, as f64.
    fn read(self, b: &[u8], at: usize) -> Option<f64> {
        Some(match self {
            Prim::I8 => i8::from_le_bytes(le::bytes(b, at)?) as f64,
            Prim::U8 | Prim::Bool | Prim::Char => *b.get(at)? as f64,
            Prim::I16 => i16::from_le_bytes(le::bytes(b, at)?) as f64,
            Prim::U16 => le::u16(b, at)? as f64,
            Prim::I32 => i32::from_le_bytes(le::bytes(b, at)?) as f64,
            Prim::U32 => u32::from_le_bytes(le::bytes(b, at)?) as f64,
            Prim::I64 => i64::from_le_bytes(le::bytes(b, at)?) as f64,
            Prim::U64 => le::u64(b, at)? as f64,
            Prim::F32 => f32::from_le_bytes(le::bytes(b, at)?) as f64,
            Prim::F64 => f64::from_le_bytes(le::bytes(b, at)?),
        })
    }
}

/// One field of a format: type name, array length (1 for a scalar), name.
#[derive(Debug, Clone)]
struct FieldDef {
    type_name: String,
    count: usize,
    name: String,
}

/// Parse `name:type field;type[n] field;...`; `None` when malformed.
fn parse_format(text: &str) -> Option<(String, Vec<FieldDef>)> {
    let (name, body) = text.split_once(':')?;
    if name.is_empty() {
        return None;
    }
    let mut fields = Vec::new();
    for f in body.split(';').filter(|f| !f.is_empty()) {
        let (ty, fname) = f.split_once(' ')?;
        let (type_name, count) = match ty.split_once('[') {
            Some((t, n)) => (t, n.strip_suffix(']')?.parse::<usize>().ok()?),
            None => (ty, 1),
        };
        if count > u16::MAX as usize {
            return None;
        }
        fields.push(FieldDef {
            type_name: type_name.to_string(),
            count,
            name: fname.to_string(),
        });
    }
    Some((name.to_string(), fields))
}

/// Where a kept field lies in a data record (after the message id).
#[derive(Debug, Clone, Copy)]
struct Loc {
    offset: usize,
    prim: Prim,
}

/// One `battery_status` record's fields: voltage (V), current (A) and the state of charge PX4
/// reports (`remaining`, 0-1; negative or NaN: unknown; `None` in a format without it).
#[derive(Debug, Clone, Copy)]
struct BatteryReading {
    volt: f64,
    amp: f64,
    remaining: Option<f64>,
}

/// The topics aloft reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Topic {
    LocalPosition,
    Attitude,
    Wind,
    Battery,
    AirData,
    LandDetected,
}

impl Topic {
    fn of(name: &str) -> Option<Self> {
        Some(match name {
            "vehicle_local_position" => Topic::LocalPosition,
            "vehicle_attitude" => Topic::Attitude,
            "wind" | "wind_estimate" => Topic::Wind,
            "battery_status" => Topic::Battery,
            "vehicle_air_data" => Topic::AirData,
            "vehicle_land_detected" => Topic::LandDetected,
            _ => return None,
        })
    }

    /// The fields read, in the order of [`Sub::locs`].
    fn fields(self) -> &'static [&'static str] {
        match self {
            Topic::LocalPosition => &[
                "x",
                "y",
                "z",
                "vx",
                "vy",
                "vz",
                "ax",
                "ay",
                "az",
                "xy_valid",
                "z_valid",
                "v_xy_valid",
                "v_z_valid",
            ],
            Topic::Attitude => &["q[0]", "q[1]", "q[2]", "q[3]"],
            Topic::Wind => &["windspeed_north", "windspeed_east"],
            Topic::Battery => &["voltage_v", "current_a", "remaining"],
            Topic::AirData => &["rho"],
            Topic::LandDetected => &["landed"],
        }
    }
}

/// A subscription (`A` record): what its data records are.
#[derive(Debug, Clone)]
struct Sub {
    name: String,
    multi_id: u8,
    /// Payload size after the message id: full, and without trailing padding.
    full: usize,
    min: usize,
    timestamp: Option<Loc>,
    topic: Option<Topic>,
    locs: Vec<Option<Loc>>,
    /// `battery_status` fields read for [`crate::battery_records`].
    battery: Option<Box<BatteryLocs>>,
    /// `time_utc_usec` of a GPS topic (`vehicle_gps_position`, `sensor_gps`).
    utc: Option<Loc>,
}

/// Where the `battery_status` fields of [`crate::battery_records`] lie in a data record.
#[derive(Debug, Clone, Default)]
struct BatteryLocs {
    voltage: Option<Loc>,
    current: Option<Loc>,
    remaining: Option<Loc>,
    discharged_mah: Option<Loc>,
    resistance_per_cell: Option<Loc>,
    temperature: Option<Loc>,
    cell_count: Option<Loc>,
    cells: Vec<Loc>,
    /// The serial number: `uint16` in older releases, `char[32]` in the versioned message.
    serial: Option<(Loc, usize)>,
    cycle_count: Option<Loc>,
    state_of_health: Option<Loc>,
}

impl BatteryLocs {
    fn new(named: &HashMap<String, Loc>, arrays: &HashMap<String, (Loc, usize)>) -> Self {
        let g = |k: &str| named.get(k).copied();
        Self {
            voltage: g("voltage_v"),
            current: g("current_a"),
            remaining: g("remaining"),
            discharged_mah: g("discharged_mah"),
            resistance_per_cell: g("internal_resistance_estimate"),
            temperature: g("temperature"),
            cell_count: g("cell_count"),
            cells: (0..16)
                .map_while(|i| g(&format!("voltage_cell_v[{i}]")))
                .collect(),
            serial: arrays
                .get("serial_number")
                .copied()
                .or_else(|| g("serial_number").map(|l| (l, 1))),
            cycle_count: g("cycle_count"),
            state_of_health: g("state_of_health"),
        }
    }
}

/// The state of the ULog decoder.
pub struct UlogDecoder {
    options: BinaryOptions,
    header_done: bool,
    formats: HashMap<String, Vec<FieldDef>>,
    subs: HashMap<u16, Sub>,
    appended: Vec<u64>,
    landed: Option<(f64, bool)>,
    in_air_s: f64,
    stamped_zero: u64,
    unknown_ids: u64,
    /// `vehicle_local_position` records read, and those whose position or velocity PX4 marked
    /// invalid (`xy_valid`/`z_valid`, `v_xy_valid`/`v_z_valid` = 0).
    local_records: u64,
    invalid_position: u64,
    invalid_velocity: u64,
    /// Message ids of subscriptions without a usable format (their records are skipped).
    ignored: std::collections::HashSet<u16>,
}

/// The size of format `name`, bytes (`None`: unknown type, too deep, or over 64 KiB).
fn size_of(formats: &HashMap<String, Vec<FieldDef>>, name: &str, depth: usize) -> Option<usize> {
    if let Some(p) = Prim::parse(name) {
        return Some(p.size());
    }
    if depth > MAX_NESTING {
        return None;
    }
    let mut total = 0usize;
    for f in formats.get(name)? {
        let one = size_of(formats, &f.type_name, depth + 1)?;
        total = total.checked_add(one.checked_mul(f.count)?)?;
        if total > u16::MAX as usize {
            return None;
        }
    }
    Some(total)
}

impl UlogDecoder {
    /// A decoder that has read nothing.
    pub fn new(options: BinaryOptions) -> Self {
        Self {
            options,
            header_done: false,
            formats: HashMap::new(),
            subs: HashMap::new(),
            appended: Vec::new(),
            landed: None,
            in_air_s: 0.0,
            stamped_zero: 0,
            unknown_ids: 0,
            local_records: 0,
            invalid_position: 0,
            invalid_velocity: 0,
            ignored: std::collections::HashSet::new(),
        }
    }

    /// Field offsets of a subscribed format.
    fn subscription(&self, name: &str, multi_id: u8) -> Option<Sub> {
        let fields = self.formats.get(name)?;
        let full = size_of(&self.formats, name, 0)?;
        let mut at = 0usize;
        let mut named: HashMap<String, Loc> = HashMap::new();
        let mut arrays: HashMap<String, (Loc, usize)> = HashMap::new();
        let mut trailing_pad = 0usize;
        for f in fields {
            let one = size_of(&self.formats, &f.type_name, 1)?;
            if let Some(prim) = Prim::parse(&f.type_name) {
                if f.count > 1 {
                    arrays.insert(f.name.clone(), (Loc { offset: at, prim }, f.count));
                }
                if f.count == 1 {
                    named.insert(f.name.clone(), Loc { offset: at, prim });
                } else if f.count <= 16 {
                    for i in 0..f.count {
                        let offset = at + i * one;
                        named.insert(format!("{}[{i}]", f.name), Loc { offset, prim });
                    }
                }
            }
            trailing_pad = if f.name.starts_with("_padding") {
                trailing_pad + one * f.count
            } else {
                0
            };
            at += one * f.count;
        }
        let topic = Topic::of(name);
        let locs = topic.map_or_else(Vec::new, |t| {
            t.fields().iter().map(|f| named.get(*f).copied()).collect()
        });
        Some(Sub {
            name: name.to_string(),
            multi_id,
            full,
            min: full - trailing_pad,
            timestamp: named.get("timestamp").copied(),
            topic,
            locs,
            battery: (name == "battery_status" && self.options.battery_details)
                .then(|| Box::new(BatteryLocs::new(&named, &arrays))),
            utc: matches!(name, "vehicle_gps_position" | "sensor_gps")
                .then(|| named.get("time_utc_usec").copied())
                .flatten(),
        })
    }
}

/// What is wrong with a record, for warnings.
type Problem = String;

impl UlogDecoder {
    /// The length of a plausible record whose header is `h` (3 bytes and, for data, 2 more).
    fn plausible(&self, h: &[u8]) -> Option<usize> {
        let size = le::u16(h, 0)? as usize;
        let t = *h.get(2)?;
        let ok = match t {
            b'D' => {
                let id = le::u16(h, 3)?;
                self.subs
                    .get(&id)
                    .is_some_and(|s| (s.min..=s.full).contains(&size.saturating_sub(2)))
            }
            b'S' => size == 8,
            b'O' | b'R' => size == 2,
            b'A' => size >= 4,
            b'P' => size >= 6,
            b'L' => size >= 9,
            b'C' => size >= 11,
            b'I' | b'M' | b'Q' | b'F' => size >= 3,
            _ => false,
        };
        ok.then_some(size + 3)
    }

    /// After a record that cannot be valid at `from`: skip to the next offset where two
    /// consecutive plausible records start. `false` when the input ends first.
    fn resync<R: Read>(&self, w: &mut ByteWindow<R>, s: &mut BinarySummary, from: u64) -> bool {
        binary_samples::resync(w, s, from, ("ULog record", 5), |h| self.plausible(h))
    }

    /// Skip to an appended-data section when the record at `at` (of `len` bytes) runs into it.
    fn enter_appended<R: Read>(
        &mut self,
        w: &mut ByteWindow<R>,
        s: &mut BinarySummary,
        at: u64,
        len: usize,
    ) -> bool {
        self.appended.retain(|a| *a > at);
        let Some(&a) = self.appended.first() else {
            return false;
        };
        if at + len as u64 <= a {
            return false;
        }
        s.warn(format!(
            "ULog record at byte {at} runs into the appended data at byte {a}: {} bytes left out",
            a - at
        ));
        w.skip_to(a)
    }

    fn header<R: Read>(&mut self, w: &mut ByteWindow<R>) {
        w.consume(16);
        self.header_done = true;
    }

    /// The next record: `Ok(Some(event))` for a kept record, `Ok(None)` for any other, `Err` for
    /// a record that cannot be valid (the caller resynchronises). The outer `None`: the end.
    fn record<R: Read>(
        &mut self,
        w: &mut ByteWindow<R>,
        s: &mut BinarySummary,
    ) -> Option<std::result::Result<Option<Event>, Problem>> {
        let at = w.offset();
        let Some(h) = w.peek(3) else {
            if w.remaining() > 0 {
                s.warn(format!(
                    "truncated ULog: {} bytes at byte {at} are not a whole record header",
                    w.remaining()
                ));
            }
            return None;
        };
        let size = le::u16(h, 0).unwrap_or(0) as usize;
        let t = h[2];
        if self.enter_appended(w, s, at, size + 3) {
            return Some(Ok(None));
        }
        if !KNOWN_TYPES.contains(&t) {
            return Some(Err(format!("unknown record type 0x{t:02x} (size {size})")));
        }
        if t == b'D' {
            let h = w.peek_max(5);
            let id = le::u16(h, 3).unwrap_or(u16::MAX);
            if self.plausible(h).is_none() && !self.ignored.contains(&id) {
                return Some(Err(format!(
                    "data record of {size} bytes for msg_id {id} contradicts its subscription"
                )));
            }
        }
        let Some(rec) = w.peek(size + 3) else {
            return Some(Err(format!(
                "truncated or corrupt: the '{}' record needs {} bytes, {} remain",
                t as char,
                size + 3,
                w.remaining()
            )));
        };
        let r = self.handle(t, &rec[3..], s);
        w.consume(size + 3);
        Some(r)
    }

    fn handle(
        &mut self,
        t: u8,
        b: &[u8],
        s: &mut BinarySummary,
    ) -> std::result::Result<Option<Event>, Problem> {
        match t {
            b'B' => self.flag_bits(b, s),
            b'F' => {
                let text = std::str::from_utf8(b).map_err(|_| "format is not UTF-8".to_string())?;
                let (name, fields) =
                    parse_format(text).ok_or_else(|| format!("malformed format '{text}'"))?;
                self.formats.insert(name, fields);
            }
            b'P' => self.parameter(b, s)?,
            b'I' if self.options.battery_details => info(b, s),
            b'A' => self.add_logged(b, s)?,
            b'R' => {
                let id = le::u16(b, 0).ok_or("short remove record")?;
                self.subs.remove(&id);
            }
            b'D' => return self.data(b, s),
            b'O' => {
                let ms = le::u16(b, 0).ok_or("short dropout record")?;
                s.count("dropout");
                s.warn(format!("ULog dropout: {ms} ms of data lost"));
            }
            _ => {}
        }
        Ok(None)
    }

    fn flag_bits(&mut self, b: &[u8], s: &mut BinarySummary) {
        let incompat = b.get(8).copied().unwrap_or(0);
        if incompat & !1 != 0 || b.get(9..16).is_some_and(|x| x.iter().any(|v| *v != 0)) {
            s.warn("ULog flag bits declare unknown incompatible features".to_string());
        }
        if incompat & 1 != 0 {
            self.appended = (0..3)
                .filter_map(|i| le::u64(b, 16 + 8 * i))
                .filter(|a| *a > 0)
                .collect();
            self.appended.sort_unstable();
        }
    }

    fn parameter(&mut self, b: &[u8], s: &mut BinarySummary) -> std::result::Result<(), Problem> {
        let kl = *b.first().ok_or("empty parameter record")? as usize;
        let key = b
            .get(1..1 + kl)
            .ok_or("parameter key longer than its record")?;
        let key = std::str::from_utf8(key).map_err(|_| "parameter key is not UTF-8")?;
        let value: [u8; 4] = le::bytes(b, 1 + kl).ok_or("parameter value missing")?;
        let v = match key.split_once(' ') {
            Some(("int32_t", _)) => i32::from_le_bytes(value) as f64,
            Some(("float", _)) => f32::from_le_bytes(value) as f64,
            _ => return Err(format!("parameter '{key}' of unknown type")),
        };
        if let (Some(name), Some(d)) = (key.split_once(' ').map(|k| k.1), &mut s.battery_details) {
            if crate::battery_records::is_kept_parameter(name) && v.is_finite() {
                d.parameters.insert(name.to_string(), v);
            }
        }
        match key.split_once(' ').map(|k| k.1) {
            Some("BAT1_N_CELLS") if v >= 1.0 => s.battery_cells = Some(v as u32),
            Some("BAT_N_CELLS") if v >= 1.0 && s.battery_cells.is_none() => {
                s.battery_cells = Some(v as u32)
            }
            Some("BAT1_CAPACITY") if crate::binary_samples::capacity_ah(v).is_some() => {
                s.battery_capacity_ah = crate::binary_samples::capacity_ah(v);
            }
            _ => {}
        }
        Ok(())
    }

    fn add_logged(&mut self, b: &[u8], s: &mut BinarySummary) -> std::result::Result<(), Problem> {
        let multi_id = *b.first().ok_or("empty subscription record")?;
        let id = le::u16(b, 1).ok_or("short subscription record")?;
        let name = std::str::from_utf8(&b[3..]).map_err(|_| "topic name is not UTF-8")?;
        if name == "battery_status" {
            s.battery_declared = true;
        }
        match self.subscription(name, multi_id) {
            Some(sub) => {
                self.ignored.remove(&id);
                self.subs.insert(id, sub);
            }
            None => {
                self.ignored.insert(id);
                s.warn(format!(
                "ULog topic '{name}' (msg_id {id}) has no valid format: its records are skipped"
            ))
            }
        }
        Ok(())
    }
}

impl UlogDecoder {
    fn data(
        &mut self,
        b: &[u8],
        s: &mut BinarySummary,
    ) -> std::result::Result<Option<Event>, Problem> {
        let id = le::u16(b, 0).ok_or("short data record")?;
        let Some(sub) = self.subs.get(&id) else {
            self.unknown_ids += 1;
            return Ok(None);
        };
        let payload = &b[2..];
        if !(sub.min..=sub.full).contains(&payload.len()) {
            return Err(format!(
                "data record of '{}' (msg_id {id}) has {} bytes, its format {}",
                sub.name,
                payload.len(),
                sub.full
            ));
        }
        if s.battery_details.is_some() {
            battery_details(sub, payload, self.options.battery_instance, s);
        }
        // Instance 0 of every topic but the battery (whose instance is chosen).
        let Some(topic) = sub
            .topic
            .filter(|t| *t == Topic::Battery || sub.multi_id == 0)
        else {
            return Ok(None);
        };
        let ts = sub.timestamp.and_then(|l| l.prim.read(payload, l.offset));
        let Some(ts) = ts.filter(|t| *t > 0.0) else {
            self.stamped_zero += 1;
            return Ok(None);
        };
        let t = ts * 1e-6;
        let v: Vec<Option<f64>> = sub
            .locs
            .iter()
            .map(|l| l.and_then(|l| l.prim.read(payload, l.offset)))
            .collect();
        let multi_id = sub.multi_id;
        s.count(&sub.name.clone());
        Ok(self.event(topic, multi_id, t, &v, s))
    }

    fn event(
        &mut self,
        topic: Topic,
        multi_id: u8,
        t: f64,
        v: &[Option<f64>],
        s: &mut BinarySummary,
    ) -> Option<Event> {
        let vec3 = |i: usize| -> Option<[f64; 3]> {
            let a = [v[i]?, v[i + 1]?, v[i + 2]?];
            a.iter().all(|x| x.is_finite()).then(|| ned_to_enu(a))
        };
        let flag = |i: usize| v[i].is_none_or(|x| x > 0.5);
        if topic == Topic::LocalPosition {
            self.local_records += 1;
            self.invalid_position += u64::from(!(flag(9) && flag(10)));
            self.invalid_velocity += u64::from(!(flag(11) && flag(12)));
        }
        let (stream, sample) = match topic {
            Topic::LocalPosition => (
                Stream::Base,
                Sample {
                    pos_enu_m: vec3(0).filter(|_| flag(9) && flag(10)),
                    vel_enu_mps: vec3(3).filter(|_| flag(11) && flag(12)),
                    acc_enu_mps2: vec3(6),
                    ..Sample::default()
                },
            ),
            Topic::Attitude => {
                let q = [v[0]?, v[1]?, v[2]?, v[3]?];
                let a = attitude_from_ned_frd_quat(q)?;
                (
                    Stream::Attitude,
                    Sample {
                        attitude: Some(a),
                        ..Sample::default()
                    },
                )
            }
            Topic::Wind => {
                let (n, e) = (v[0]?, v[1]?);
                let w = [e, n, 0.0];
                w.iter().all(|x| x.is_finite()).then_some(())?;
                (
                    Stream::Wind,
                    Sample {
                        wind_enu_mps: Some(w),
                        ..Sample::default()
                    },
                )
            }
            Topic::Battery => {
                let reading = BatteryReading {
                    volt: v[0]?,
                    amp: v[1]?,
                    remaining: v[2],
                };
                return self.battery(multi_id, t, reading, s);
            }
            Topic::AirData => {
                let rho = v[0].filter(|r| r.is_finite() && *r > 0.0)?;
                s.rho_sum += rho;
                s.rho_n += 1;
                return None;
            }
            Topic::LandDetected => {
                let landed = v[0]? > 0.5;
                if let Some((t0, false)) = self.landed {
                    if t > t0 {
                        self.in_air_s += t - t0;
                    }
                }
                self.landed = Some((t, landed));
                s.in_air_s = Some(self.in_air_s);
                (
                    Stream::Landed,
                    Sample {
                        landed: Some(landed),
                        ..Sample::default()
                    },
                )
            }
        };
        Some(Event {
            time_s: t,
            stream,
            sample,
        })
    }

    fn battery(
        &mut self,
        multi_id: u8,
        t: f64,
        reading: BatteryReading,
        s: &mut BinarySummary,
    ) -> Option<Event> {
        let BatteryReading {
            volt,
            amp,
            remaining,
        } = reading;
        if !s.battery_instances.contains(&multi_id) {
            s.battery_instances.push(multi_id);
        }
        if multi_id != self.options.battery_instance {
            return None;
        }
        s.battery.records += 1;
        if !(volt.is_finite() && volt > 0.0) {
            s.battery.no_voltage += 1;
            return None;
        }
        if !(amp.is_finite() && amp >= 0.0) {
            s.battery.unknown_current += 1;
            return None;
        }
        s.battery.push(t, volt, amp);
        Some(Event {
            time_s: t,
            stream: Stream::Battery,
            sample: Sample {
                voltage_v: Some(volt),
                current_a: Some(amp),
                soc: remaining.filter(|r| r.is_finite() && *r >= 0.0),
                ..Sample::default()
            },
        })
    }

    fn finish(&mut self, s: &mut BinarySummary) {
        for (count, what, flags) in [
            (self.invalid_position, "position", "xy_valid/z_valid"),
            (self.invalid_velocity, "velocity", "v_xy_valid/v_z_valid"),
        ] {
            if count > 0 {
                s.warn(format!(
                    "vehicle_local_position: the {what} is marked invalid ({flags} = 0) in {count} of {} records and was left out (the estimator had no {what} it trusted, e.g. no GPS); fit, validate and replay need the velocity",
                    self.local_records
                ));
            }
        }
        if self.stamped_zero > 0 {
            s.warn(format!(
                "{} records of the topics read are stamped 0 (never set) and were left out",
                self.stamped_zero
            ));
        }
        if self.unknown_ids > 0 {
            s.warn(format!(
                "{} data records name a msg_id that no subscription declares; skipped",
                self.unknown_ids
            ));
        }
        let b = &s.battery;
        if b.unknown_current > 0 {
            s.warn(format!(
                "{} battery records with unknown current (current_a < 0) were left out",
                b.unknown_current
            ));
        }
    }
}

impl Decoder for UlogDecoder {
    fn next_event<R: Read>(
        &mut self,
        w: &mut ByteWindow<R>,
        s: &mut BinarySummary,
    ) -> Option<Event> {
        if !self.header_done {
            self.header(w);
        }
        loop {
            let at = w.offset();
            match self.record(w, s) {
                None => {
                    self.finish(s);
                    return None;
                }
                Some(Ok(Some(e))) => return Some(e),
                Some(Ok(None)) => {}
                Some(Err(problem)) => {
                    s.warn(format!("ULog record at byte {at}: {problem}"));
                    if !self.resync(w, s, at) {
                        self.finish(s);
                        return None;
                    }
                }
            }
        }
    }
}

/// An information record (`I`): the vehicle's `sys_uuid` into the battery details.
fn info(b: &[u8], s: &mut BinarySummary) {
    let Some(kl) = b.first().map(|k| *k as usize) else {
        return;
    };
    let (Some(key), Some(value)) = (b.get(1..1 + kl), b.get(1 + kl..)) else {
        return;
    };
    let Ok(key) = std::str::from_utf8(key) else {
        return;
    };
    if key.starts_with("char[") && key.ends_with(" sys_uuid") {
        let text = crate::battery_records::text_id(value);
        if let (Some(d), Some(t)) = (&mut s.battery_details, text) {
            d.vehicle_id = Some(t);
        }
    }
}

/// A `battery_status` record of the chosen instance (and the GPS clock) into the details.
fn battery_details(sub: &Sub, payload: &[u8], instance: u8, s: &mut BinarySummary) {
    let Some(d) = &mut s.battery_details else {
        return;
    };
    let read = |l: Option<Loc>| l.and_then(|l| l.prim.read(payload, l.offset));
    let t = read(sub.timestamp).filter(|t| *t > 0.0).map(|t| t * 1e-6);
    if let (Some(utc), Some(t), None) = (sub.utc, t, d.gps_clock) {
        if let Some(us) = utc.prim.read(payload, utc.offset).filter(|u| *u > 1e15) {
            d.gps_clock = Some((t, us * 1e-6));
        }
    }
    let (Some(l), Some(t)) = (&sub.battery, t) else {
        return;
    };
    if sub.multi_id != instance {
        return;
    }
    let Some(volt) = read(l.voltage).filter(|v| v.is_finite() && *v > 0.0) else {
        return;
    };
    let cells: Vec<f64> = l
        .cells
        .iter()
        .filter_map(|c| c.prim.read(payload, c.offset))
        .filter(|v| crate::battery_records::valid_cell(*v))
        .collect();
    if let Some(n) = read(l.cell_count).filter(|n| *n >= 1.0 && *n <= 64.0) {
        d.cells_logged = Some(n as u32);
    }
    if let Some((loc, count)) = l.serial {
        let id = if count > 1 {
            payload
                .get(loc.offset..loc.offset + count)
                .and_then(crate::battery_records::text_id)
        } else {
            read(Some(loc))
                .filter(|v| *v >= 1.0)
                .map(|v| format!("{}", v as u64))
        };
        if id.is_some() {
            d.pack_id = id;
        }
    }
    if let Some(c) = read(l.cycle_count).filter(|c| *c >= 1.0) {
        d.cycle_count = Some(c as u32);
    }
    if let Some(h) = read(l.state_of_health).filter(|h| *h > 0.0 && *h <= 100.0) {
        d.state_of_health_percent = Some(h);
    }
    let r_cell = read(l.resistance_per_cell).filter(|r| r.is_finite() && *r > 0.0);
    if let Some(r) = r_cell {
        d.per_cell_resistance.push((d.samples.len(), r));
    }
    d.samples.push(crate::battery_records::BatterySample {
        time_s: t,
        voltage_v: volt,
        current_a: read(l.current).filter(|i| i.is_finite() && *i >= 0.0),
        remaining: read(l.remaining).filter(|r| r.is_finite() && (0.0..=1.0).contains(r)),
        remaining_mah: None,
        consumed_mah: read(l.discharged_mah).filter(|c| c.is_finite() && *c >= 0.0),
        cell_v: cells,
        // Per cell: made the pack's at the end, once the cell count is known.
        autopilot_resistance_ohm: None,
        temperature_c: read(l.temperature).filter(|c| c.is_finite() && (-60.0..150.0).contains(c)),
    });
}

/// Whether `head` (the first bytes of a file) is a ULog.
pub fn is_ulog(head: &[u8]) -> bool {
    head.starts_with(&ULOG_MAGIC)
}

/// Joined samples of the ULog read from `reader`; `path` names it in errors.
///
/// # Errors
/// [`LogError::UnsupportedFormat`] when the input does not start with the ULog header.
pub fn ulog_samples<R: Read>(
    reader: R,
    options: &BinaryOptions,
    path: &Path,
) -> Result<BinarySamples<R, UlogDecoder>> {
    let mut it = BinarySamples::with_decoder(reader, UlogDecoder::new(*options), options);
    let head = it.window.peek(16).unwrap_or(&[]);
    if !is_ulog(head) {
        return Err(LogError::UnsupportedFormat {
            path: path.to_path_buf(),
            reason: "not a ULog file: the 16-byte header (magic 55 4C 6F 67 01 12 35) is missing"
                .into(),
        });
    }
    Ok(it)
}

#[cfg(test)]
mod tests {
    use crate::synth::{ulog_data, ulog_start, ulog_subscription};
    use crate::{read_ulog, BinaryOptions};

    /// `battery_status.remaining` is the reported state of charge of the samples it is joined
    /// onto; PX4's "unknown" (negative, NaN) is none; a value above 1 is carried as reported.
    #[test]
    fn remaining_is_the_reported_state_of_charge() {
        let mut b = ulog_start(&[
            "battery_status:uint64_t timestamp;float voltage_v;float current_a;float remaining;",
            "vehicle_local_position:uint64_t timestamp;float x;float y;float z;",
        ]);
        b.extend(ulog_subscription(1, "battery_status"));
        b.extend(ulog_subscription(2, "vehicle_local_position"));
        let remaining = [0.69, 0.69, -1.0, f32::NAN, 1.5, 0.68];
        for (k, r) in remaining.into_iter().enumerate() {
            let t = 1_000_000 + k as u64 * 100_000;
            // The battery first: the join emits a sample once its streams have a record.
            b.extend(ulog_data(1, t, &[11.6, 0.0, r]));
            b.extend(ulog_data(2, t, &[0.0, 0.0, -1.0]));
        }
        let log = read_ulog(&b[..], &BinaryOptions::default()).unwrap().log;
        let soc: Vec<Option<f64>> = log.samples.iter().map(|s| s.soc).collect();
        // f32 values: 1e-6 covers their rounding.
        let near = |s: Option<f64>, want: f64| s.is_some_and(|s| (s - want).abs() < 1e-6);
        assert_eq!(soc.len(), 6);
        assert!(near(soc[0], 0.69) && near(soc[1], 0.69), "{soc:?}");
        assert_eq!(soc[2..4], [None, None]);
        assert!(near(soc[4], 1.5) && near(soc[5], 0.68), "{soc:?}");
    }
}
