//! ArduPilot DataFlash (`.bin`), decoded here (sans-I/O, over a [`ByteWindow`]).
//!
//! # Format
//! Every record is `A3 95`, a type byte, then the payload its `FMT` record declares. `FMT`
//! (type 128, 89 bytes) defines every type: name, length, format characters, column names. The
//! characters: `b B h H i I q Q` integers, `f d` floats, `n N Z` strings of 4, 16, 64 bytes, `a`
//! 32 int16, `M` flight mode (u8), and the scaled ones `c C e E` (x 0.01) and `L` (x 1e-7,
//! degrees). `MULT` and `FMTU` records (newer logs) give per-column multipliers, applied here to
//! unscaled integer columns.
//!
//! # What is read
//! - `ATT` is the time base (attitude). Its angles are degrees when the column is `f`/`d` or a
//!   scaled `c`/`C`, centidegrees when an unscaled integer (old logs) unless `FMTU` says otherwise.
//! - `POS` (or, without `POS`, a `GPS` with a 3D fix): position, ENU from the first fix.
//! - `GPS` with a 3D fix: ground velocity from `Spd`, `GCrs`, `VZ` (down).
//! - `BAT` of the chosen instance (`Instance` or `Inst`), else old `CURR`: `Volt`, `Curr`. Old
//!   `CURR` integers have no multiplier in the file: their scale (centi-units in the logs seen)
//!   is chosen so the first non-zero voltage is 3.3-4.4 V per cell for some 1-14 cells. A
//!   record counts when `Volt` > 0 (a battery that reads 0 V has no sensor). `BAT.RemPct`
//!   (ArduPilot 4.1 and later; percent, 255 when unknown) is the reported state of charge
//!   ([`Sample::soc`]); `CURR` has none.
//! - The landed state ([`Sample::landed`]): `EV` events armed (10), disarmed (11) and land
//!   complete (18) mean on the ground, not landed (28) in the air (the ids of ArduPilot's
//!   `LogEvent`, kept stable across versions); an `ARM` record (armed or disarmed) means on the
//!   ground (ArduCopter arms and disarms landed). Land complete maybe (17) is left out: the
//!   vehicle may still be sliding or bouncing. `MODE` is not read for it: a flight mode says how
//!   the vehicle is flown, not whether it is on the ground. An `EV` without a time stamp (old
//!   logs) takes the boot time of the record before it (records are written in time order).
//! - `PARM` (`BATT_CAPACITY`), `CTUN`, `MODE`, `CMD`: counted (and decoded by [`DataflashRecords`]).
//!
//! # Time
//! `TimeUS` (microseconds since boot) or, in old logs, `TimeMS` (milliseconds since boot). `GPS`
//! `TimeMS` is GPS time of week, never boot time: a GPS record without `TimeUS` takes its boot
//! time from `T` (ms), or is not joined.
//!
//! # Robustness
//! A record that does not start with `A3 95`, or whose type has no `FMT`, starts a scan for the
//! next `A3 95` of a declared type followed by another record header (or the end); the bytes
//! skipped are counted and reported with their offset. A truncated last record is a warning.

use std::io::Read;
use std::path::Path;

use crate::binary_samples::{self, BinaryOptions, BinarySamples, BinarySummary, Decoder};
use crate::bytes::ByteWindow;
use crate::csv_read::wrap_pi;
use crate::error::{LogError, Result};
use crate::frame::geodetic_to_enu;
use crate::join::{Event, Stream};
use crate::sample::{Attitude, GeoOrigin, Sample};

/// The first bytes of a DataFlash log: a record header and the type of `FMT`.
pub const DATAFLASH_MAGIC: [u8; 3] = [0xA3, 0x95, 0x80];

/// Type id of `FMT`.
const FMT_TYPE: u8 = 0x80;
/// Length of an `FMT` record, header included.
const FMT_LEN: usize = 89;

/// Size and scale of a format character (`None`: unknown character).
fn char_size(c: u8) -> Option<usize> {
    Some(match c {
        b'b' | b'B' | b'M' => 1,
        b'h' | b'H' | b'c' | b'C' => 2,
        b'i' | b'I' | b'e' | b'E' | b'L' | b'f' | b'n' => 4,
        b'd' | b'q' | b'Q' => 8,
        b'N' => 16,
        b'Z' | b'a' => 64,
        _ => return None,
    })
}

/// Whether a character is an integer without a scale of its own (a multiplier may apply).
fn unscaled_int(c: u8) -> bool {
    matches!(
        c,
        b'b' | b'B' | b'h' | b'H' | b'i' | b'I' | b'q' | b'Q' | b'M'
    )
}

/// A numeric value of character `c` at the start of `b`, scaled by the character.
fn number(c: u8, b: &[u8]) -> Option<f64> {
    fn a<const N: usize>(b: &[u8]) -> Option<[u8; N]> {
        b.get(..N)?.try_into().ok()
    }
    Some(match c {
        b'b' => i8::from_le_bytes(a(b)?) as f64,
        b'B' | b'M' => *b.first()? as f64,
        b'h' => i16::from_le_bytes(a(b)?) as f64,
        b'H' => u16::from_le_bytes(a(b)?) as f64,
        b'c' => i16::from_le_bytes(a(b)?) as f64 * 0.01,
        b'C' => u16::from_le_bytes(a(b)?) as f64 * 0.01,
        b'i' => i32::from_le_bytes(a(b)?) as f64,
        b'I' => u32::from_le_bytes(a(b)?) as f64,
        b'e' => i32::from_le_bytes(a(b)?) as f64 * 0.01,
        b'E' => u32::from_le_bytes(a(b)?) as f64 * 0.01,
        b'L' => i32::from_le_bytes(a(b)?) as f64 * 1e-7,
        b'f' => f32::from_le_bytes(a(b)?) as f64,
        b'd' => f64::from_le_bytes(a(b)?),
        b'q' => i64::from_le_bytes(a(b)?) as f64,
        b'Q' => u64::from_le_bytes(a(b)?) as f64,
        _ => return None,
    })
}

/// The text of a NUL-padded string column.
fn text(b: &[u8]) -> String {
    let end = b.iter().position(|c| *c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).into_owned()
}

/// One column of a record type.
#[derive(Debug, Clone)]
pub struct Column {
    /// Its name.
    pub name: String,
    /// Its format character.
    pub format: u8,
    /// Offset in the payload (after the 3-byte header).
    pub offset: usize,
    /// Multiplier from `FMTU`/`MULT` (unscaled integer columns only).
    pub mult: Option<f64>,
}

/// A record type declared by `FMT`.
#[derive(Debug, Clone)]
pub struct Format {
    /// Type id.
    pub type_id: u8,
    /// Name (`BAT`, `ATT`, ...).
    pub name: String,
    /// Length with the header, bytes.
    pub length: usize,
    /// Columns.
    pub columns: Vec<Column>,
}

impl Format {
    fn col(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.name == name)
    }

    /// The numeric value of column `name` in `payload` (character scale and multiplier applied).
    pub fn num(&self, payload: &[u8], name: &str) -> Option<f64> {
        let c = self.col(name)?;
        let v = number(c.format, payload.get(c.offset..)?)?;
        Some(v * c.mult.unwrap_or(1.0))
    }

    /// The value of column `name` scaled by its character only (time stamps).
    pub fn raw(&self, payload: &[u8], name: &str) -> Option<f64> {
        let c = self.col(name)?;
        number(c.format, payload.get(c.offset..)?)
    }

    /// The text of string column `name`.
    pub fn text(&self, payload: &[u8], name: &str) -> Option<String> {
        let c = self.col(name)?;
        let n = char_size(c.format)?;
        Some(text(payload.get(c.offset..c.offset + n)?))
    }

    /// Parse an `FMT` payload; `None` when it is not a usable definition.
    fn parse(p: &[u8]) -> Option<Self> {
        let type_id = *p.first()?;
        let length = *p.get(1)? as usize;
        let name = text(p.get(2..6)?);
        let chars: Vec<u8> = p
            .get(6..22)?
            .iter()
            .copied()
            .take_while(|c| *c != 0)
            .collect();
        let names = text(p.get(22..86)?);
        let names: Vec<&str> = if names.is_empty() {
            Vec::new()
        } else {
            names.split(',').collect()
        };
        if name.is_empty() || length < 3 || (type_id == FMT_TYPE && length != FMT_LEN) {
            return None;
        }
        let mut offset = 0;
        let mut columns = Vec::with_capacity(chars.len());
        for (i, c) in chars.iter().enumerate() {
            let size = char_size(*c)?;
            columns.push(Column {
                name: names
                    .get(i)
                    .map_or_else(|| format!("col{i}"), |n| n.to_string()),
                format: *c,
                offset,
                mult: None,
            });
            offset += size;
        }
        (offset <= length - 3).then_some(Format {
            type_id,
            name,
            length,
            columns,
        })
    }
}

/// The `FMT` of `FMT`, which every log starts from.
fn fmt_of_fmt() -> Format {
    let mut p = vec![FMT_TYPE, FMT_LEN as u8];
    p.extend_from_slice(b"FMT\0");
    let mut f = [0u8; 16];
    f[..5].copy_from_slice(b"BBnNZ");
    p.extend_from_slice(&f);
    let mut c = [0u8; 64];
    c[..30].copy_from_slice(b"Type,Length,Name,Format,Column");
    p.extend_from_slice(&c);
    Format::parse(&p).expect("the FMT of FMT is valid")
}

/// The records the join reads, by role.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    Att,
    Pos,
    Gps,
    Bat,
    Curr,
    Baro,
    Bcl,
    Event,
    Arm,
    Parm,
    Fmtu,
    Mult,
    Counted,
    Other,
}

fn role(name: &str) -> Role {
    match name {
        "ATT" => Role::Att,
        "POS" => Role::Pos,
        "GPS" => Role::Gps,
        "BAT" => Role::Bat,
        "CURR" => Role::Curr,
        "BARO" => Role::Baro,
        "BCL" => Role::Bcl,
        "EV" => Role::Event,
        "ARM" => Role::Arm,
        "PARM" => Role::Parm,
        "FMTU" => Role::Fmtu,
        "MULT" => Role::Mult,
        "CTUN" | "MODE" | "CMD" | "UNIT" => Role::Counted,
        _ => Role::Other,
    }
}

/// The record framing and `FMT` table of a DataFlash log: yields raw records, skipping
/// corruption (see the module docs).
pub struct Framer {
    formats: Vec<Option<Format>>,
    roles: Vec<Role>,
    mults: Vec<(u8, f64)>,
}

impl Default for Framer {
    fn default() -> Self {
        let mut formats = vec![None; 256];
        formats[FMT_TYPE as usize] = Some(fmt_of_fmt());
        Self {
            formats,
            roles: vec![Role::Other; 256],
            mults: Vec::new(),
        }
    }
}

impl Framer {
    /// The format of type `t`.
    pub fn format(&self, t: u8) -> Option<&Format> {
        self.formats[t as usize].as_ref()
    }

    /// Length of a valid record starting at `h` (header bytes), if its type is declared.
    fn plausible(&self, h: &[u8]) -> Option<usize> {
        (h.len() >= 3 && h[0] == 0xA3 && h[1] == 0x95)
            .then(|| self.format(h[2]).map(|f| f.length))
            .flatten()
    }

    /// Skip to the next record header of a declared type followed by another (or the end).
    fn resync<R: Read>(&self, w: &mut ByteWindow<R>, s: &mut BinarySummary, from: u64) -> bool {
        binary_samples::resync(w, s, from, ("DataFlash data", 3), |h| self.plausible(h))
    }

    /// The next record: its offset, type and payload (copied into `payload`). `None` at the end.
    pub fn next_record<R: Read>(
        &mut self,
        w: &mut ByteWindow<R>,
        s: &mut BinarySummary,
        payload: &mut Vec<u8>,
    ) -> Option<(u64, u8)> {
        loop {
            let at = w.offset();
            let h = w.peek_max(3);
            if h.len() < 3 {
                if !h.is_empty() {
                    s.warn(format!(
                        "truncated DataFlash: {} bytes at byte {at} are not a whole record header",
                        h.len()
                    ));
                }
                return None;
            }
            let Some(len) = self.plausible(h) else {
                let what = if h[0] == 0xA3 && h[1] == 0x95 {
                    format!("record type {} has no FMT", h[2])
                } else {
                    format!("bytes {:02x} {:02x} are not a record header", h[0], h[1])
                };
                s.warn(format!("DataFlash record at byte {at}: {what}"));
                if !self.resync(w, s, at) {
                    return None;
                }
                continue;
            };
            let t = h[2];
            let Some(rec) = w.peek(len) else {
                let name = self.format(t).map_or(String::new(), |f| f.name.clone());
                s.warn(format!(
                    "truncated or corrupt DataFlash: the {name} record at byte {at} needs {len} bytes, {} remain",
                    w.remaining()
                ));
                if !self.resync(w, s, at) {
                    return None;
                }
                continue;
            };
            payload.clear();
            payload.extend_from_slice(&rec[3..]);
            w.consume(len);
            if t == FMT_TYPE {
                self.define(payload, s, at);
            }
            return Some((at, t));
        }
    }

    fn define(&mut self, p: &[u8], s: &mut BinarySummary, at: u64) {
        match Format::parse(p) {
            Some(f) if f.type_id != FMT_TYPE => {
                let t = f.type_id as usize;
                self.roles[t] = role(&f.name);
                self.formats[t] = Some(f);
            }
            Some(_) => {}
            None => s.warn(format!(
                "DataFlash FMT at byte {at} is not a valid definition; ignored"
            )),
        }
    }

    /// `MULT`: a multiplier id and its value.
    fn mult(&mut self, f: &Format, p: &[u8]) {
        if let (Some(id), Some(m)) = (f.num(p, "Id"), f.num(p, "Mult")) {
            self.mults.retain(|(i, _)| *i != id as u8);
            self.mults.push((id as u8, m));
        }
    }

    /// `FMTU`: multipliers of one type's columns (unscaled integers only; `-` and `?` mean none).
    fn fmtu(&mut self, f: &Format, p: &[u8]) {
        let (Some(t), Some(ids)) = (f.num(p, "FmtType"), f.text(p, "MultIds")) else {
            return;
        };
        let mults = self.mults.clone();
        let Some(target) = self.formats[(t as usize).min(255)].as_mut() else {
            return;
        };
        for (c, id) in target.columns.iter_mut().zip(ids.bytes()) {
            if unscaled_int(c.format) && id != b'-' && id != b'?' {
                c.mult = mults
                    .iter()
                    .find(|(i, _)| *i == id)
                    .map(|(_, m)| *m)
                    .filter(|m| m.is_finite() && *m != 0.0);
            }
        }
    }
}

/// The state of the DataFlash decoder.
pub struct DataflashDecoder {
    options: BinaryOptions,
    framer: Framer,
    payload: Vec<u8>,
    origin: Option<GeoOrigin>,
    has_bat: bool,
    has_pos: bool,
    curr_scale: Option<f64>,
    untimed: u64,
    /// Boot time of the last timed record read, s (for events without a time of their own).
    last_time_s: Option<f64>,
    /// Whether `EV` or `ARM` is declared.
    events_declared: bool,
}

/// Boot time of a record, s: `TimeUS`, else `TimeMS` (not for GPS), else GPS `T` (ms). A time
/// that is not finite (a format declaring the time column as a float holding NaN) is no time.
fn boot_time_s(f: &Format, p: &[u8]) -> Option<f64> {
    let t = if let Some(us) = f.raw(p, "TimeUS") {
        Some(us * 1e-6)
    } else if f.name.starts_with("GPS") {
        f.raw(p, "T").map(|ms| ms * 1e-3)
    } else {
        f.raw(p, "TimeMS").map(|ms| ms * 1e-3)
    };
    t.filter(|t| t.is_finite())
}

/// The scale of old integer `CURR` voltages: the first of centi, milli and whole units that puts
/// `raw` at 3.3-4.4 V per cell for some 1-14 cells (centi when none does).
fn curr_scale(raw: f64) -> f64 {
    let fits = |v: f64| (1..=14).any(|n| (3.3..=4.4).contains(&(v / n as f64)));
    [0.01, 0.001, 1.0]
        .into_iter()
        .find(|k| fits(raw * k))
        .unwrap_or(0.01)
}

impl DataflashDecoder {
    /// A decoder that has read nothing.
    pub fn new(options: BinaryOptions) -> Self {
        Self {
            options,
            framer: Framer::default(),
            payload: Vec::new(),
            origin: None,
            has_bat: false,
            has_pos: false,
            curr_scale: None,
            untimed: 0,
            last_time_s: None,
            events_declared: false,
        }
    }

    /// The origin of the ENU positions (the first fix).
    pub fn origin(&self) -> Option<GeoOrigin> {
        self.origin
    }

    /// The event of the record just framed, if the join keeps it.
    fn event(&mut self, t: u8, s: &mut BinarySummary) -> Option<Event> {
        let r = self.framer.roles[t as usize];
        if r == Role::Other {
            return None;
        }
        // Taken out of the table while it is used (put back below), so nothing is cloned.
        let f = self.framer.formats[t as usize].take()?;
        let p = std::mem::take(&mut self.payload);
        s.count(&f.name);
        let e = self.by_role(r, &f, &p, s);
        self.payload = p;
        self.framer.formats[t as usize] = Some(f);
        e
    }

    fn by_role(&mut self, r: Role, f: &Format, p: &[u8], s: &mut BinarySummary) -> Option<Event> {
        match r {
            Role::Fmtu => self.framer.fmtu(f, p),
            Role::Mult => self.framer.mult(f, p),
            Role::Parm => {
                let name = f.text(p, "Name")?;
                let v = f.num(p, "Value")?;
                if name == "BATT_CAPACITY" {
                    s.battery_capacity_ah =
                        crate::binary_samples::capacity_ah(v).or(s.battery_capacity_ah);
                }
                if let Some(d) = &mut s.battery_details {
                    if crate::battery_records::is_kept_parameter(&name) && v.is_finite() {
                        d.parameters.insert(name, v);
                    }
                }
            }
            Role::Baro => {
                // The log's own air: the barometer's pressure (Pa) and temperature (C), dry air.
                // The sensor sits on the board, whose warmth may bias the density low.
                let pa = f.num(p, "Press")?;
                let t_k = f.num(p, "Temp")? + aloft_core::atmosphere::ZERO_CELSIUS_K;
                let rho = aloft_core::atmosphere::air_density_kg_m3(pa, t_k, 0.0);
                if rho.is_finite() && (0.3..=1.6).contains(&rho) {
                    s.rho_sum += rho;
                    s.rho_n += 1;
                }
            }
            Role::Bcl => self.cells(f, p, s),
            Role::Event | Role::Arm => return self.landed(r, f, p),
            Role::Att | Role::Pos | Role::Gps | Role::Bat | Role::Curr => {
                let Some(time_s) = boot_time_s(f, p) else {
                    self.untimed += 1;
                    return None;
                };
                self.last_time_s = Some(time_s);
                let (stream, sample) = match r {
                    Role::Att => (Stream::Base, self.attitude(f, p)?),
                    Role::Pos => (Stream::Position, self.position(f, p)?),
                    Role::Gps => {
                        gps_clock(f, p, time_s, s);
                        return self.gps(f, p, time_s);
                    }
                    _ => (Stream::Battery, self.battery(r, f, p, time_s, s)?),
                };
                return Some(Event {
                    time_s,
                    stream,
                    sample,
                });
            }
            Role::Counted | Role::Other => {}
        }
        None
    }

    /// The landed state of an `EV` or `ARM` record (see the module docs), at its own time or
    /// that of the record before it.
    fn landed(&mut self, r: Role, f: &Format, p: &[u8]) -> Option<Event> {
        let landed = match r {
            Role::Arm => true,
            _ => match f.num(p, "Id")? as u8 {
                10 | 11 | 18 => true,
                28 => false,
                _ => return None,
            },
        };
        let time_s = boot_time_s(f, p).or(self.last_time_s)?;
        Some(Event {
            time_s,
            stream: Stream::Landed,
            sample: Sample {
                landed: Some(landed),
                ..Sample::default()
            },
        })
    }

    fn attitude(&self, f: &Format, p: &[u8]) -> Option<Sample> {
        let deg = |name: &str| -> Option<f64> {
            let c = f.col(name)?;
            let v = f.num(p, name)?;
            // Unscaled integers without a multiplier are centidegrees (old logs).
            Some(if unscaled_int(c.format) && c.mult.is_none() {
                v * 0.01
            } else {
                v
            })
        };
        let (r, pi, y) = (deg("Roll")?, deg("Pitch")?, deg("Yaw")?);
        [r, pi, y].iter().all(|x| x.is_finite()).then_some(())?;
        Some(Sample {
            attitude: Some(Attitude {
                roll_rad: r.to_radians(),
                pitch_rad: pi.to_radians(),
                yaw_rad: wrap_pi(y.to_radians()),
            }),
            ..Sample::default()
        })
    }

    fn enu(&mut self, lat: f64, lon: f64, alt: f64) -> Option<[f64; 3]> {
        if !(lat.is_finite() && lon.is_finite() && alt.is_finite()) || (lat == 0.0 && lon == 0.0) {
            return None;
        }
        let o = *self.origin.get_or_insert(GeoOrigin {
            lat_rad: lat.to_radians(),
            lon_rad: lon.to_radians(),
            alt_m: alt,
        });
        Some(geodetic_to_enu(&o, lat.to_radians(), lon.to_radians(), alt))
    }

    fn position(&mut self, f: &Format, p: &[u8]) -> Option<Sample> {
        let pos = self.enu(f.num(p, "Lat")?, f.num(p, "Lng")?, f.num(p, "Alt")?)?;
        Some(Sample {
            pos_enu_m: Some(pos),
            ..Sample::default()
        })
    }

    /// A GPS record with a 3D fix: velocity, and position when the log has no POS.
    fn gps(&mut self, f: &Format, p: &[u8], time_s: f64) -> Option<Event> {
        if f.num(p, "Status")? < 3.0 {
            return None;
        }
        let (spd, crs) = (f.num(p, "Spd")?, f.num(p, "GCrs")?.to_radians());
        let vz = f.num(p, "VZ").unwrap_or(0.0);
        let vel = [spd * crs.sin(), spd * crs.cos(), -vz];
        if self.has_pos {
            return vel.iter().all(|x| x.is_finite()).then_some(Event {
                time_s,
                stream: Stream::Velocity,
                sample: Sample {
                    vel_enu_mps: Some(vel),
                    ..Sample::default()
                },
            });
        }
        let pos = self.enu(f.num(p, "Lat")?, f.num(p, "Lng")?, f.num(p, "Alt")?);
        // Without POS, GPS feeds position too (through the velocity stream's record).
        Some(Event {
            time_s,
            stream: Stream::Velocity,
            sample: Sample {
                vel_enu_mps: vel.iter().all(|x| x.is_finite()).then_some(vel),
                pos_enu_m: pos,
                ..Sample::default()
            },
        })
    }

    fn battery(
        &mut self,
        r: Role,
        f: &Format,
        p: &[u8],
        t: f64,
        s: &mut BinarySummary,
    ) -> Option<Sample> {
        if r == Role::Curr && self.has_bat {
            return None;
        }
        let inst = f
            .num(p, "Instance")
            .or_else(|| f.num(p, "Inst"))
            .unwrap_or(0.0) as u8;
        if !s.battery_instances.contains(&inst) {
            s.battery_instances.push(inst);
        }
        if inst != self.options.battery_instance {
            return None;
        }
        let (mut v, mut i) = (f.num(p, "Volt")?, f.num(p, "Curr")?);
        if r == Role::Curr && f.col("Volt").is_some_and(|c| unscaled_int(c.format)) {
            if self.curr_scale.is_none() && v > 0.0 {
                let k = curr_scale(v);
                self.curr_scale = Some(k);
                s.warn(format!(
                    "CURR Volt and Curr are integers without a unit in the file: read as x{k} (first voltage {:.2} V)",
                    v * k
                ));
            }
            let k = self.curr_scale.unwrap_or(0.01);
            v *= k;
            i *= k;
        }
        s.battery.records += 1;
        if !(v.is_finite() && v > 0.0 && i.is_finite()) {
            s.battery.no_voltage += 1;
            return None;
        }
        if let Some(d) = &mut s.battery_details {
            let finite = |x: Option<f64>| x.filter(|x| x.is_finite());
            d.samples.push(crate::battery_records::BatterySample {
                time_s: t,
                voltage_v: v,
                current_a: Some(i),
                remaining: f.num(p, "RemPct").and_then(reported_soc),
                remaining_mah: None,
                consumed_mah: finite(f.num(p, "CurrTot")),
                cell_v: Vec::new(),
                // BAT.Res is the whole pack's, ohm; 0 before the first estimate.
                autopilot_resistance_ohm: finite(f.num(p, "Res")).filter(|r| *r > 0.0),
                temperature_c: finite(f.num(p, "Temp")).filter(|c| (-60.0..150.0).contains(c)),
            });
        }
        s.battery.push(t, v, i);
        Some(Sample {
            voltage_v: Some(v),
            current_a: Some(i),
            soc: f.num(p, "RemPct").and_then(reported_soc),
            ..Sample::default()
        })
    }

    /// A `BCL` record of the chosen instance: its cells (mV, `V1..V12`) onto the last battery
    /// record of the details.
    fn cells(&self, f: &Format, p: &[u8], s: &mut BinarySummary) {
        let Some(d) = &mut s.battery_details else {
            return;
        };
        let inst = f
            .num(p, "Instance")
            .or_else(|| f.num(p, "Inst"))
            .unwrap_or(0.0);
        if (inst - f64::from(self.options.battery_instance)).abs() > 0.5 {
            return;
        }
        let cells: Vec<f64> = (1..=12)
            .filter_map(|k| f.num(p, &format!("V{k}")))
            .map(|mv| mv * 1e-3)
            .filter(|v| crate::battery_records::valid_cell(*v))
            .collect();
        if let Some(last) = d.samples.last_mut() {
            if last.cell_v.is_empty() {
                last.cell_v = cells;
            }
        }
    }

    fn declare(&mut self, s: &mut BinarySummary) {
        let names =
            |n: &str| (0..=255u8).any(|t| self.framer.format(t).is_some_and(|f| f.name == n));
        self.has_bat = names("BAT");
        self.has_pos = names("POS");
        s.battery_declared = self.has_bat || names("CURR");
        self.events_declared = names("EV") || names("ARM");
    }
}

/// Seconds from the GPS epoch (1980-01-06) to the Unix epoch.
const GPS_EPOCH_UNIX_S: f64 = 315_964_800.0;
/// GPS time runs ahead of UTC by the leap seconds since 1980: 18 s since 2017-01-01 (none added
/// since), which is the era of the logs that carry `GWk`.
const GPS_LEAP_S: f64 = 18.0;

/// The first GPS record with a fix and a week number gives the log's wall clock.
fn gps_clock(f: &Format, p: &[u8], time_s: f64, s: &mut BinarySummary) {
    let Some(d) = &mut s.battery_details else {
        return;
    };
    if d.gps_clock.is_some() || f.num(p, "Status").is_none_or(|st| st < 3.0) {
        return;
    }
    let (Some(wk), Some(ms)) = (f.num(p, "GWk"), f.num(p, "GMS")) else {
        return;
    };
    if wk >= 1.0 && ms.is_finite() && wk.is_finite() {
        let utc = GPS_EPOCH_UNIX_S + wk * 604_800.0 + ms * 1e-3 - GPS_LEAP_S;
        d.gps_clock = Some((time_s, utc));
    }
}

/// The state of charge of a `BAT.RemPct` percentage, 0-1; `None` for 255 (ArduPilot's
/// "unknown": no capacity or no current sensor) and what is not a number.
fn reported_soc(percent: f64) -> Option<f64> {
    // RemPct is a u8: half a unit tells 255 from its neighbours.
    let unknown = (percent - f64::from(u8::MAX)).abs() < 0.5;
    (percent.is_finite() && !unknown).then_some(percent / 100.0)
}

impl Decoder for DataflashDecoder {
    fn next_event<R: Read>(
        &mut self,
        w: &mut ByteWindow<R>,
        s: &mut BinarySummary,
    ) -> Option<Event> {
        loop {
            let Some((_, t)) = self.framer.next_record(w, s, &mut self.payload) else {
                if self.untimed > 0 {
                    s.warn(format!(
                        "{} records without a boot time stamp were not joined",
                        self.untimed
                    ));
                }
                return None;
            };
            if t == FMT_TYPE {
                let before = self.events_declared;
                self.declare(s);
                if self.events_declared && !before {
                    // The join waits for the landed state from here (see `Stream::Landed`).
                    return Some(Event {
                        time_s: 0.0,
                        stream: Stream::Landed,
                        sample: Sample::default(),
                    });
                }
                continue;
            }
            if let Some(e) = self.event(t, s) {
                return Some(e);
            }
        }
    }

    fn origin(&self) -> Option<GeoOrigin> {
        self.origin
    }
}

/// Whether `head` (the first bytes of a file) is a DataFlash log.
pub fn is_dataflash(head: &[u8]) -> bool {
    head.starts_with(&DATAFLASH_MAGIC)
}

/// Joined samples of the DataFlash log read from `reader`; `path` names it in errors.
///
/// # Errors
/// [`LogError::UnsupportedFormat`] when the input does not start with `A3 95 80`.
pub fn dataflash_samples<R: Read>(
    reader: R,
    options: &BinaryOptions,
    path: &Path,
) -> Result<BinarySamples<R, DataflashDecoder>> {
    let mut it = BinarySamples::with_decoder(reader, DataflashDecoder::new(*options), options);
    if !is_dataflash(it.window.peek_max(3)) {
        return Err(LogError::UnsupportedFormat {
            path: path.to_path_buf(),
            reason: "not a DataFlash log: it does not start with the FMT record (A3 95 80)".into(),
        });
    }
    Ok(it)
}

/// Every record of a DataFlash log with its numeric columns (for inspection and cross-checks).
pub struct DataflashRecords<R> {
    window: ByteWindow<R>,
    framer: Framer,
    payload: Vec<u8>,
    /// Warnings and bytes skipped.
    pub summary: BinarySummary,
}

/// One decoded record.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// Offset of its header, bytes.
    pub offset: u64,
    /// Type name.
    pub name: String,
    /// Numeric columns (scaled), by name; string columns are left out.
    pub values: Vec<(String, f64)>,
    /// Boot time, s (as the samples': `TimeUS`, else `TimeMS`, else GPS `T`).
    pub time_s: Option<f64>,
}

impl<R: Read> DataflashRecords<R> {
    /// Records of `reader`.
    pub fn new(reader: R) -> Self {
        Self {
            window: ByteWindow::new(reader),
            framer: Framer::default(),
            payload: Vec::new(),
            summary: BinarySummary::default(),
        }
    }
}

impl<R: Read> Iterator for DataflashRecords<R> {
    type Item = Record;

    fn next(&mut self) -> Option<Record> {
        let (offset, t) =
            self.framer
                .next_record(&mut self.window, &mut self.summary, &mut self.payload)?;
        let f = self.framer.format(t)?.clone();
        match role(&f.name) {
            Role::Fmtu => self.framer.fmtu(&f, &self.payload),
            Role::Mult => self.framer.mult(&f, &self.payload),
            _ => {}
        }
        let values = f
            .columns
            .iter()
            .filter_map(|c| Some((c.name.clone(), f.num(&self.payload, &c.name)?)))
            .collect();
        Some(Record {
            offset,
            name: f.name.clone(),
            values,
            time_s: boot_time_s(&f, &self.payload),
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::synth::{att_fmt, dataflash_fmt, dataflash_fmt_of_fmt, dataflash_record};
    use crate::{read_dataflash, BinaryOptions};

    /// Fuzz finding `fixtures/fuzz/dataflash/07eadf3218906b21.bin`: an `FMT` declaring `TimeUS`
    /// as a float let a NaN time into the base topic, and the span of the flight was NaN.
    #[test]
    fn a_time_that_is_not_finite_is_no_time() {
        let mut b = dataflash_fmt_of_fmt();
        b.extend(dataflash_fmt(
            1,
            3 + 16,
            "ATT",
            "ffff",
            "TimeUS,Roll,Pitch,Yaw",
        ));
        b.extend(dataflash_fmt(
            2,
            3 + 8 + 8,
            "BAT",
            "Qff",
            "TimeUS,Volt,Curr",
        ));
        for (k, t_us) in [f32::NAN, 1e6, f32::INFINITY, 1.1e6, 1.2e6]
            .into_iter()
            .enumerate()
        {
            b.extend([0xA3, 0x95, 1]);
            for v in [t_us, 1.0, 2.0, 90.0] {
                b.extend(v.to_le_bytes());
            }
            b.extend(dataflash_record(
                2,
                1_000_000 + 100_000 * k as u64,
                &[12.0, 5.0],
            ));
        }
        let r = read_dataflash(&b[..], &BinaryOptions::default()).unwrap();
        let s = &r.summary;
        // 1.0 to 1.2 s; 1e-9 s covers the f32 microseconds' rounding.
        assert!((s.base_span_s - 0.2).abs() < 1e-9, "{}", s.base_span_s);
        assert!(r.log.samples.iter().all(|x| x.time_s.is_finite()));
        assert!(
            s.warnings.iter().any(|w| w.contains('2')),
            "{:?}",
            s.warnings
        );
    }

    /// Arming and landing events become the landed state of the samples after them; an event
    /// without a time stamp (old logs) takes the time of the record before it.
    #[test]
    fn events_give_the_landed_state() {
        let mut b = dataflash_fmt_of_fmt();
        b.extend(att_fmt(1));
        b.extend(dataflash_fmt(2, 3 + 8 + 1, "EV", "QB", "TimeUS,Id"));
        b.extend(dataflash_fmt(3, 3 + 1, "EV", "B", "Id"));
        let ev = |t_us: u64, id: u8| {
            let mut r = vec![0xA3, 0x95, 2];
            r.extend(t_us.to_le_bytes());
            r.push(id);
            r
        };
        // Samples at 0.0, 0.1, ... 5.9 s; armed at 1 s, not landed at 2 s, land complete at
        // 4 s (an event with no time of its own, after the ATT record at 4.0 s), disarmed at
        // 5 s; 17 (land complete maybe) and 15 (auto armed) change nothing.
        for k in 0..60u64 {
            let t = k * 100_000;
            b.extend(dataflash_record(1, t, &[0.0, 0.0, 0.0]));
            match k {
                10 => b.extend(ev(t, 10)),
                15 => b.extend(ev(t, 15)),
                20 => b.extend(ev(t, 28)),
                38 => b.extend(ev(t, 17)),
                40 => b.extend([0xA3, 0x95, 3, 18]),
                50 => b.extend(ev(t, 11)),
                _ => {}
            }
        }
        let r = read_dataflash(&b[..], &BinaryOptions::default()).unwrap();
        let s = &r.log.samples;
        assert_eq!(s.len(), 60);
        for (k, x) in s.iter().enumerate() {
            let want = match k {
                0..10 => None,
                20..40 => Some(false),
                _ => Some(true),
            };
            assert_eq!(x.landed, want, "sample {k}");
        }
    }

    /// `BAT.RemPct` is the reported state of charge, percent; 255 (ArduPilot's "unknown") is
    /// none, and a log whose `BAT` has no `RemPct` (before 4.1) reports none.
    #[test]
    fn bat_rem_pct_is_the_reported_state_of_charge() {
        for (with_rem, pct, want) in [
            (true, 69u8, Some(0.69)),
            (true, 255, None),
            (false, 69, None),
        ] {
            let mut b = dataflash_fmt_of_fmt();
            b.extend(att_fmt(1));
            let (format, cols) = match with_rem {
                true => ("QffB", "TimeUS,Volt,Curr,RemPct"),
                false => ("Qff", "TimeUS,Volt,Curr"),
            };
            let len = 3 + 8 + 8 + u8::from(with_rem);
            b.extend(dataflash_fmt(2, len, "BAT", format, cols));
            for k in 0..5u64 {
                let t = 1_000_000 + k * 100_000;
                // The battery first: the join emits a sample once its streams have a record.
                let mut bat = dataflash_record(2, t, &[11.6, 0.5]);
                if with_rem {
                    bat.push(pct);
                }
                b.extend(bat);
                b.extend(dataflash_record(1, t, &[0.0, 0.0, 0.0]));
            }
            let r = read_dataflash(&b[..], &BinaryOptions::default()).unwrap();
            assert_eq!(r.log.samples.len(), 5);
            for s in &r.log.samples {
                // 1e-12: a percentage over 100.
                let same = match (s.soc, want) {
                    (Some(a), Some(b)) => (a - b).abs() < 1e-12,
                    (a, b) => a == b,
                };
                assert!(same, "RemPct {pct} ({with_rem}): {:?}", s.soc);
            }
        }
    }

    /// Fuzz finding `fixtures/fuzz/dataflash/f70328e305c524bd.bin`: a `BATT_CAPACITY` of
    /// infinity was read as an infinite capacity, which `log info` refused as not finite.
    #[test]
    fn a_battery_capacity_that_is_not_plausible_is_not_read() {
        for (mah, ah) in [
            (f32::INFINITY, None),
            (f32::NAN, None),
            (-1.0, None),
            // Issue 41: a capacity no pack has (below 10 mA h) is unset.
            (1e-38, None),
            (9.0, None),
            (10.0, Some(0.01)),
            (5000.0, Some(5.0)),
        ] {
            let mut b = dataflash_fmt_of_fmt();
            b.extend(dataflash_fmt(
                3,
                3 + 8 + 16 + 4,
                "PARM",
                "QNf",
                "TimeUS,Name,Value",
            ));
            b.extend([0xA3, 0x95, 3]);
            b.extend(1_000_000u64.to_le_bytes());
            let mut name = b"BATT_CAPACITY".to_vec();
            name.resize(16, 0);
            b.extend(name);
            b.extend(mah.to_le_bytes());
            let r = read_dataflash(&b[..], &BinaryOptions::default()).unwrap();
            assert_eq!(r.summary.battery_capacity_ah, ah, "{mah} mA h");
        }
    }
}
