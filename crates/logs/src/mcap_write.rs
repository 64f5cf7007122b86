//! MCAP output that Foxglove displays: JSON messages with JSON Schemas.
//!
//! Topics (all JSON, `frame_id` `map` = ENU; orientations are ROS quaternions, body FLU to ENU, so
//! Foxglove's 3D panel draws them as it draws ROS data):
//!
//! | topic | schema | content |
//! |---|---|---|
//! | `/aloft/pose` | `foxglove.PoseInFrame` | position and attitude |
//! | `/aloft/state` | `aloft.VehicleState` | ENU position, velocity, acceleration, wind, roll/pitch/yaw (rad and deg), ground speed |
//! | `/aloft/battery` | `aloft.BatteryState` | `voltage_v`, `current_a`, `power_w`, `charge_ah`, `state_of_charge`, `energy_used_wh` |
//! | `/aloft/power` | `aloft.PowerTerms` | `induced_w`, `parasitic_w`, `profile_w`, `acceleration_w`, `climb_w`, `electrical_w` |
//! | `/aloft/path` | `foxglove.PosesInFrame` | the planned path, once |
//! | `/aloft/live` | `aloft.LiveUpdate` | an update of `aloft live`, its JSON line as it is |
//!
//! One sample of a log (or instant of a mission) is written as consecutive messages at one time,
//! `/aloft/state` first (every sample has one), and [`crate::mcap_read`] joins them back into one
//! sample.
//!
//! Every message has `timestamp` `{sec, nsec}`; the MCAP `log_time` is the same instant. Values that
//! do not exist are omitted (never NaN); non-finite input is refused with [`LogError::NonFinite`].
//! The writer streams: memory is one chunk (the `mcap` crate's default, zstd-compressed).

use std::collections::HashMap;
use std::io::{BufWriter, Seek, Write};
use std::ops::{Deref, DerefMut};
use std::path::{Path, PathBuf};

use aloft_core::output::Output;

use serde::Serialize;
use serde_json::{json, Map, Value};

use crate::error::{LogError, Result};
use crate::frame::attitude_to_enu_flu_quat;
use crate::sample::{Attitude, Log, Sample};

/// Topic of [`McapWriter::write_sample`]'s pose.
pub const TOPIC_POSE: &str = "/aloft/pose";
/// Topic of the vehicle state.
pub const TOPIC_STATE: &str = "/aloft/state";
/// Topic of the battery state.
pub const TOPIC_BATTERY: &str = "/aloft/battery";
/// Topic of the power terms.
pub const TOPIC_POWER: &str = "/aloft/power";
/// Topic of the planned path.
pub const TOPIC_PATH: &str = "/aloft/path";
/// Topic of `aloft live`'s updates ([`McapWriter::write_object`]).
pub const TOPIC_LIVE: &str = "/aloft/live";

/// The four terms of the power model and the electrical total, W.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct PowerTerms {
    /// Induced power, W.
    pub induced_w: f64,
    /// Parasitic power, W.
    pub parasitic_w: f64,
    /// Profile power, W.
    pub profile_w: f64,
    /// Work of accelerating the vehicle (exact angle of attack; see aloft_power::four_term), W.
    pub acceleration_w: f64,
    /// Climb power, W.
    pub climb_w: f64,
    /// Electrical power drawn from the battery, W.
    pub electrical_w: f64,
}

/// Battery state at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct BatteryPoint {
    /// Terminal voltage, V.
    pub voltage_v: f64,
    /// Current, positive discharging, A.
    pub current_a: f64,
    /// State of charge, 0 to 1.
    pub state_of_charge: f64,
    /// Energy drawn since the start, W h.
    pub energy_used_wh: f64,
}

/// One instant of a planned or simulated mission.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct MissionSample {
    /// Time since the mission start, s.
    pub time_s: f64,
    /// Position east, north, up, m.
    pub pos_enu_m: [f64; 3],
    /// Ground velocity east, north, up, m/s.
    pub vel_enu_mps: [f64; 3],
    /// Attitude (aerospace Euler angles relative to NED).
    pub attitude: Attitude,
    /// Power terms.
    pub power: PowerTerms,
    /// Battery state, when simulated.
    pub battery: Option<BatteryPoint>,
}

/// One point of a planned path.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct PathPoint {
    /// Position east, north, up, m.
    pub pos_enu_m: [f64; 3],
    /// Heading (aerospace yaw, clockwise from north), rad; `None`: along the path.
    pub yaw_rad: Option<f64>,
}

/// What was written.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct WriteSummary {
    /// Messages per topic, sorted by topic.
    pub messages: Vec<(String, u64)>,
}

impl WriteSummary {
    /// Messages on one topic.
    pub fn count(&self, topic: &str) -> u64 {
        self.messages
            .iter()
            .find(|(t, _)| t == topic)
            .map_or(0, |(_, n)| *n)
    }
}

fn xyz(v: [f64; 3]) -> Value {
    json!({"x": v[0], "y": v[1], "z": v[2]})
}

fn schema_vec3() -> Value {
    json!({"type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}}, "required": ["x", "y", "z"]})
}

fn schema_time() -> Value {
    json!({"type": "object", "title": "time", "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}, "required": ["sec", "nsec"]})
}

fn schema_pose() -> Value {
    json!({"type": "object", "properties": {
        "position": schema_vec3(),
        "orientation": {"type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}, "w": {"type": "number"}}, "required": ["x", "y", "z", "w"]}
    }, "required": ["position", "orientation"]})
}

fn numbers(title: &str, description: &str, required: &[&str], optional: &[&str]) -> Value {
    let mut props = Map::new();
    props.insert("timestamp".into(), schema_time());
    for k in required.iter().chain(optional) {
        props.insert((*k).into(), json!({"type": "number"}));
    }
    let mut req = vec![Value::from("timestamp")];
    req.extend(required.iter().map(|k| Value::from(*k)));
    json!({"title": title, "description": description, "type": "object", "properties": props, "required": req})
}

fn schema_for(name: &str) -> Value {
    match name {
        "foxglove.PoseInFrame" => json!({
            "title": "foxglove.PoseInFrame", "description": "A timestamped pose in a named frame",
            "type": "object",
            "properties": {"timestamp": schema_time(), "frame_id": {"type": "string"}, "pose": schema_pose()},
            "required": ["timestamp", "frame_id", "pose"]}),
        "foxglove.PosesInFrame" => json!({
            "title": "foxglove.PosesInFrame", "description": "An array of timestamped poses in a named frame",
            "type": "object",
            "properties": {"timestamp": schema_time(), "frame_id": {"type": "string"}, "poses": {"type": "array", "items": schema_pose()}},
            "required": ["timestamp", "frame_id", "poses"]}),
        "aloft.VehicleState" => json!({
            "title": "aloft.VehicleState", "description": "Vehicle state: ENU position (m), velocity (m/s), acceleration (m/s^2) and wind (m/s), aerospace Euler angles relative to NED",
            "type": "object",
            "properties": {
                "timestamp": schema_time(), "time_s": {"type": "number"},
                "position_enu_m": schema_vec3(), "velocity_enu_mps": schema_vec3(),
                "ground_speed_mps": {"type": "number"},
                "acceleration_enu_mps2": schema_vec3(), "wind_enu_mps": schema_vec3(),
                "roll_rad": {"type": "number"}, "pitch_rad": {"type": "number"}, "yaw_rad": {"type": "number"},
                "roll_deg": {"type": "number"}, "pitch_deg": {"type": "number"}, "yaw_deg": {"type": "number"}},
            "required": ["timestamp", "time_s"]}),
        "aloft.LiveUpdate" => json!({
            "title": "aloft.LiveUpdate",
            "description": "An update of aloft live: the JSON line of --format json (time_s, soc, energy_used_wh, power_w, efficiency, wind, remaining_wh and landing_soc as {p5, p50, p95}, point_of_no_return_s, advice, ...)",
            "type": "object",
            "properties": {"timestamp": schema_time(), "time_s": {"type": "number"}},
            "required": ["timestamp", "time_s"]}),
        "aloft.BatteryState" => numbers(
            "aloft.BatteryState",
            "Battery: voltage (V), current positive discharging (A), power (W), remaining charge (A h), state of charge (0-1), energy used (W h)",
            &[],
            &["time_s", "voltage_v", "current_a", "power_w", "charge_ah", "state_of_charge", "energy_used_wh"],
        ),
        _ => numbers(
            "aloft.PowerTerms",
            "Four-term power model: induced, parasitic, profile, climb (aerodynamic, W) and electrical power (W)",
            &[
                "time_s",
                "induced_w",
                "parasitic_w",
                "profile_w",
                "acceleration_w",
                "climb_w",
                "electrical_w",
            ],
            &[],
        ),
    }
}

/// A streaming MCAP writer for aloft's topics.
pub struct McapWriter<W: Write + Seek> {
    path: PathBuf,
    inner: mcap::Writer<W>,
    channels: HashMap<&'static str, u16>,
    counts: HashMap<&'static str, u64>,
    start_ns: u64,
}

/// An MCAP file being written through aloft's one way of writing a file
/// ([`aloft_core::output`]): its messages go to a temporary file beside `path`, and
/// [`McapFile::commit`] finishes it and puts it in place. Dropped before (an error on the way, an
/// interrupted run), it leaves nothing at `path`. It writes as a [`McapWriter`] does (it
/// dereferences to one).
pub struct McapFile(McapWriter<BufWriter<Output>>);

impl McapFile {
    /// Start the file `path`: refused when something is there, unless `force` (which replaces a
    /// regular file or a link, never a device or a FIFO).
    ///
    /// # Errors
    /// [`LogError::Output`] (the file is there, its folder is missing, ...); the MCAP header.
    pub fn create(path: &Path, force: bool) -> Result<Self> {
        let out = Output::create(path, force)?;
        McapWriter::new(BufWriter::new(out), path).map(Self)
    }

    /// Finish the file (its summary and footer) and put it in place.
    ///
    /// # Errors
    /// Writing the summary, or placing the file ([`LogError::Output`]).
    pub fn commit(self) -> Result<WriteSummary> {
        let (summary, out) = self.finish_output()?;
        out.commit()?;
        Ok(summary)
    }

    /// Finish the file (its summary and footer) without placing it: the output, to be placed
    /// with others as one set ([`aloft_core::output::OutputSet::push`]).
    ///
    /// # Errors
    /// Writing the summary or flushing the file.
    pub fn finish_output(self) -> Result<(WriteSummary, Output)> {
        let path = self.0.path.clone();
        let (summary, buffered) = self.0.finish_into_inner()?;
        let out = buffered.into_inner().map_err(|e| LogError::WriteIo {
            path,
            cause: e.into_error(),
        })?;
        Ok((summary, out))
    }
}

impl Deref for McapFile {
    type Target = McapWriter<BufWriter<Output>>;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl DerefMut for McapFile {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.0
    }
}

fn check(what: &'static str, index: usize, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(LogError::NonFinite {
            what,
            index,
            value: v,
        })
    }
}

fn check3(what: &'static str, index: usize, v: [f64; 3]) -> Result<[f64; 3]> {
    for x in v {
        check(what, index, x)?;
    }
    Ok(v)
}

impl<W: Write + Seek> McapWriter<W> {
    /// Write to any seekable writer; `path` names it in errors.
    pub fn new(w: W, path: &Path) -> Result<Self> {
        let inner = mcap::WriteOptions::new()
            .profile("")
            .library(concat!("aloft-logs ", env!("CARGO_PKG_VERSION")))
            .create(w)
            .map_err(|cause| LogError::McapWrite {
                path: path.to_path_buf(),
                cause,
            })?;
        Ok(Self {
            path: path.to_path_buf(),
            inner,
            channels: HashMap::new(),
            counts: HashMap::new(),
            start_ns: 0,
        })
    }

    /// Set the absolute time of `time_s = 0`, ns since the Unix epoch (default 0).
    pub fn set_start_ns(&mut self, start_ns: u64) {
        self.start_ns = start_ns;
    }

    fn err(&self, cause: mcap::McapError) -> LogError {
        LogError::McapWrite {
            path: self.path.clone(),
            cause,
        }
    }

    fn channel(&mut self, topic: &'static str, schema: &'static str) -> Result<u16> {
        if let Some(id) = self.channels.get(topic) {
            return Ok(*id);
        }
        let data = serde_json::to_vec(&schema_for(schema)).unwrap_or_default();
        let sid = self
            .inner
            .add_schema(schema, "jsonschema", &data)
            .map_err(|e| self.err(e))?;
        let cid = self
            .inner
            .add_channel(sid, topic, "json", &Default::default())
            .map_err(|e| self.err(e))?;
        self.channels.insert(topic, cid);
        Ok(cid)
    }

    /// The `log_time` of `time_s`: the start plus whole nanoseconds, added as integers (a Unix
    /// time in nanoseconds as an `f64` keeps only about 256 ns, and two samples of one instant
    /// must get one time).
    fn time_ns(&self, time_s: f64, index: usize) -> Result<u64> {
        let t = check("time_s", index, time_s)?;
        // A float-to-integer cast saturates: far out of range stays out of range.
        let ns = i128::from(self.start_ns) + (t * 1e9).round() as i128;
        u64::try_from(ns).map_err(|_| LogError::InvalidArgument {
            name: "time_s",
            value: time_s,
            reason: if ns < 0 {
                "before the Unix epoch"
            } else {
                "after the year 2554 (the last time MCAP stores)"
            },
        })
    }

    fn put(
        &mut self,
        topic: &'static str,
        schema: &'static str,
        ns: u64,
        mut msg: Map<String, Value>,
    ) -> Result<()> {
        let id = self.channel(topic, schema)?;
        msg.insert(
            "timestamp".into(),
            json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000}),
        );
        let data = serde_json::to_vec(&Value::Object(msg)).unwrap_or_default();
        let n = self.counts.entry(topic).or_insert(0);
        let header = mcap::records::MessageHeader {
            channel_id: id,
            sequence: (*n).min(u64::from(u32::MAX)) as u32,
            log_time: ns,
            publish_time: ns,
        };
        *n += 1;
        self.inner
            .write_to_known_channel(&header, &data)
            .map_err(|e| self.err(e))
    }

    fn state(&mut self, index: usize, s: &StateFields) -> Result<()> {
        let (time_s, pos, att) = (s.time_s, s.pos, s.att);
        let ns = self.time_ns(time_s, index)?;
        let mut m = Map::new();
        m.insert("time_s".into(), json!(time_s));
        if let Some(p) = pos {
            m.insert("position_enu_m".into(), xyz(check3("pos_enu_m", index, p)?));
        }
        if let Some(v) = s.vel {
            let v = check3("vel_enu_mps", index, v)?;
            m.insert("velocity_enu_mps".into(), xyz(v));
            m.insert("ground_speed_mps".into(), json!(v[0].hypot(v[1])));
        }
        if let Some(a) = s.acc {
            let a = check3("acc_enu_mps2", index, a)?;
            m.insert("acceleration_enu_mps2".into(), xyz(a));
        }
        if let Some(w) = s.wind {
            let w = check3("wind_enu_mps", index, w)?;
            m.insert("wind_enu_mps".into(), xyz(w));
        }
        if let Some(a) = att {
            for (k, v) in [
                ("roll", a.roll_rad),
                ("pitch", a.pitch_rad),
                ("yaw", a.yaw_rad),
            ] {
                let v = check("attitude", index, v)?;
                m.insert(format!("{k}_rad"), json!(v));
                m.insert(format!("{k}_deg"), json!(v.to_degrees()));
            }
        }
        self.put(TOPIC_STATE, "aloft.VehicleState", ns, m)?;
        if let Some(p) = pos {
            let q = att.map_or([1.0, 0.0, 0.0, 0.0], |a| attitude_to_enu_flu_quat(&a));
            let mut m = Map::new();
            m.insert("frame_id".into(), json!("map"));
            m.insert(
                "pose".into(),
                json!({"position": xyz(p), "orientation": {"x": q[1], "y": q[2], "z": q[3], "w": q[0]}}),
            );
            self.put(TOPIC_POSE, "foxglove.PoseInFrame", ns, m)?;
        }
        Ok(())
    }

    /// Write one log sample: state (always: with the time alone when the sample has no motion,
    /// attitude or wind channel), pose (when it has position), battery (when it has any battery
    /// channel), so every channel and every time of the sample is in the file. The messages of
    /// one sample share one time and the state comes first: the reader makes one sample of
    /// them again ([`crate::mcap_read`]), and two samples at one time stay two.
    pub fn write_sample(&mut self, index: usize, s: &Sample) -> Result<()> {
        let state = StateFields {
            time_s: s.time_s,
            pos: s.pos_enu_m,
            vel: s.vel_enu_mps,
            acc: s.acc_enu_mps2,
            att: s.attitude,
            wind: s.wind_enu_mps,
        };
        let battery = s.voltage_v.is_some()
            || s.current_a.is_some()
            || s.power_w.is_some()
            || s.charge_ah.is_some()
            || s.soc.is_some();
        self.state(index, &state)?;
        if battery {
            let ns = self.time_ns(s.time_s, index)?;
            let mut m = Map::new();
            m.insert("time_s".into(), json!(s.time_s));
            for (k, v) in [
                ("voltage_v", s.voltage_v),
                ("current_a", s.current_a),
                ("power_w", s.electrical_power_w()),
                ("charge_ah", s.charge_ah),
                ("state_of_charge", s.soc),
            ] {
                if let Some(v) = v {
                    m.insert(k.into(), json!(check("battery", index, v)?));
                }
            }
            self.put(TOPIC_BATTERY, "aloft.BatteryState", ns, m)?;
        }
        Ok(())
    }

    /// Write one mission sample: state, pose, power terms and (when present) battery state.
    pub fn write_mission_sample(&mut self, index: usize, s: &MissionSample) -> Result<()> {
        self.state(
            index,
            &StateFields {
                time_s: s.time_s,
                pos: Some(s.pos_enu_m),
                vel: Some(s.vel_enu_mps),
                acc: None,
                att: Some(s.attitude),
                wind: None,
            },
        )?;
        let ns = self.time_ns(s.time_s, index)?;
        let p = &s.power;
        let mut m = Map::new();
        m.insert("time_s".into(), json!(s.time_s));
        for (k, v) in [
            ("induced_w", p.induced_w),
            ("parasitic_w", p.parasitic_w),
            ("profile_w", p.profile_w),
            ("acceleration_w", p.acceleration_w),
            ("climb_w", p.climb_w),
            ("electrical_w", p.electrical_w),
        ] {
            m.insert(k.into(), json!(check("power", index, v)?));
        }
        self.put(TOPIC_POWER, "aloft.PowerTerms", ns, m)?;
        if let Some(b) = &s.battery {
            let mut m = Map::new();
            m.insert("time_s".into(), json!(s.time_s));
            for (k, v) in [
                ("voltage_v", b.voltage_v),
                ("current_a", b.current_a),
                ("power_w", b.voltage_v * b.current_a),
                ("state_of_charge", b.state_of_charge),
                ("energy_used_wh", b.energy_used_wh),
            ] {
                m.insert(k.into(), json!(check("battery", index, v)?));
            }
            self.put(TOPIC_BATTERY, "aloft.BatteryState", ns, m)?;
        }
        Ok(())
    }

    /// Write one JSON object at `time_s` on `topic` with the schema `schema` (`aloft.LiveUpdate`
    /// for [`TOPIC_LIVE`]); `index` names it in errors. Its numbers must be finite (the caller's
    /// JSON has no NaN: `serde_json` writes them as `null`).
    pub fn write_object(
        &mut self,
        topic: &'static str,
        schema: &'static str,
        time_s: f64,
        index: usize,
        msg: Map<String, Value>,
    ) -> Result<()> {
        let ns = self.time_ns(time_s, index)?;
        self.put(topic, schema, ns, msg)
    }

    /// Write the planned path as one `foxglove.PosesInFrame` message at `time_s`.
    pub fn write_path(&mut self, time_s: f64, path: &[PathPoint]) -> Result<()> {
        let ns = self.time_ns(time_s, 0)?;
        let mut poses = Vec::with_capacity(path.len());
        for (i, p) in path.iter().enumerate() {
            let pos = check3("path position", i, p.pos_enu_m)?;
            let yaw = match p.yaw_rad {
                Some(y) => check("path yaw", i, y)?,
                None => {
                    // Along the path: toward the next point (or from the previous one at the end).
                    let (a, b) = match (path.get(i), path.get(i + 1)) {
                        (Some(a), Some(b)) => (a.pos_enu_m, b.pos_enu_m),
                        _ if i > 0 => (path[i - 1].pos_enu_m, p.pos_enu_m),
                        _ => (pos, pos),
                    };
                    // Heading clockwise from north: atan2(east, north).
                    (b[0] - a[0]).atan2(b[1] - a[1])
                }
            };
            let q = attitude_to_enu_flu_quat(&Attitude {
                roll_rad: 0.0,
                pitch_rad: 0.0,
                yaw_rad: yaw,
            });
            poses.push(json!({"position": xyz(pos), "orientation": {"x": q[1], "y": q[2], "z": q[3], "w": q[0]}}));
        }
        let mut m = Map::new();
        m.insert("frame_id".into(), json!("map"));
        m.insert("poses".into(), Value::Array(poses));
        self.put(TOPIC_PATH, "foxglove.PosesInFrame", ns, m)
    }

    /// Write the summary and the footer (of an [`McapFile`]: [`McapFile::commit`], which also
    /// puts the file in place).
    ///
    /// # Errors
    /// The writer's error, naming the file.
    pub fn finish(self) -> Result<WriteSummary> {
        self.finish_into_inner().map(|(summary, _)| summary)
    }

    /// [`McapWriter::finish`], giving back the writer the file went to.
    ///
    /// # Errors
    /// As [`McapWriter::finish`].
    pub fn finish_into_inner(mut self) -> Result<(WriteSummary, W)> {
        self.inner.finish().map_err(|e| self.err(e))?;
        let mut messages: Vec<(String, u64)> = self
            .counts
            .iter()
            .map(|(t, n)| ((*t).to_string(), *n))
            .collect();
        messages.sort();
        Ok((WriteSummary { messages }, self.inner.into_inner()))
    }
}

fn start_ns_of(start_time_s: f64) -> u64 {
    if start_time_s.is_finite() && start_time_s > 0.0 {
        (start_time_s * 1e9).round() as u64
    } else {
        0
    }
}

/// Write a whole log (e.g. for `aloft convert`), keeping its absolute start time when known; an
/// existing file at `path` is replaced only with `force` ([`McapFile::create`]).
pub fn write_log_mcap(path: &Path, log: &Log, force: bool) -> Result<WriteSummary> {
    let mut w = McapFile::create(path, force)?;
    w.set_start_ns(start_ns_of(log.start_time_s));
    for (i, s) in log.samples.iter().enumerate() {
        w.write_sample(i, s)?;
    }
    w.commit()
}

/// Write a mission: its samples and the planned path (written once, at the first sample's time).
/// Takes plain data so a planner can call it without other aloft types.
pub fn write_mission_mcap(
    path: &Path,
    samples: &[MissionSample],
    planned_path: &[PathPoint],
    force: bool,
) -> Result<WriteSummary> {
    let mut w = McapFile::create(path, force)?;
    if !planned_path.is_empty() {
        w.write_path(samples.first().map_or(0.0, |s| s.time_s), planned_path)?;
    }
    for (i, s) in samples.iter().enumerate() {
        w.write_mission_sample(i, s)?;
    }
    w.commit()
}

/// The fields of one `aloft.VehicleState` message (each optional but the time).
struct StateFields {
    time_s: f64,
    pos: Option<[f64; 3]>,
    vel: Option<[f64; 3]>,
    acc: Option<[f64; 3]>,
    att: Option<Attitude>,
    wind: Option<[f64; 3]>,
}
