//! Decoders of the standard message types a drone log carries, from ROS 2 CDR or JSON, into
//! partial [`Sample`]s.
//!
//! Frames (REP-103, REP-105): positions, velocities and orientations are in the message's
//! `frame_id`, taken as ENU (orientation: body FLU to ENU) unless the frame id ends in `_ned`
//! (then NED, orientation body FRD to NED). `nav_msgs/Odometry` gives its twist in the body frame
//! (`child_frame_id`); it is rotated to ENU with the message's own orientation. A
//! `TwistStamped` whose `frame_id` is a body frame (anything other than `map`, `odom`, `world`,
//! `earth` or a `_ned`/`_enu` variant) cannot be rotated without an attitude and is dropped.
//! `sensor_msgs/Imu` gives attitude (unless its orientation covariance is flagged -1) and the
//! kinematic acceleration `R f - g` from the specific force `f`. `sensor_msgs/BatteryState`
//! defines current as negative while discharging; it is negated to aloft's positive-discharging
//! convention unless [`RosDecodeOptions::battery_current_positive_discharging`] is set (some
//! drivers publish the opposite sign); its `percentage` (0-1) is the reported state of charge
//! ([`Sample::soc`]), as `state_of_charge` of `aloft.BatteryState`. NaN fields (unmeasured) leave
//! the channel empty.

use aloft_core::STANDARD_GRAVITY_MPS2;
use serde_json::Value;

use crate::cdr::{CdrError, CdrReader};
use crate::frame::{mat_ned_frd_to_euler, Mat3};
use crate::frame::{mat_vec, ned_to_enu, quat_to_mat, ros_quat_to_mat_ned_frd};
use crate::sample::{Attitude, Channel, Sample};

/// Message types aloft decodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MessageKind {
    /// `sensor_msgs/msg/BatteryState`, or JSON with `voltage`/`current` (`aloft.BatteryState`:
    /// `voltage_v`/`current_a`).
    BatteryState,
    /// `geometry_msgs/msg/PoseStamped` or `foxglove.PoseInFrame`.
    PoseStamped,
    /// `geometry_msgs/msg/TwistStamped`.
    TwistStamped,
    /// `nav_msgs/msg/Odometry`.
    Odometry,
    /// `sensor_msgs/msg/Imu`.
    Imu,
    /// `aloft.VehicleState` (JSON, written by aloft).
    AloftState,
}

/// The supported types, for messages.
pub const SUPPORTED: &str = "sensor_msgs/msg/BatteryState, geometry_msgs/msg/PoseStamped, geometry_msgs/msg/TwistStamped, nav_msgs/msg/Odometry, sensor_msgs/msg/Imu (CDR or JSON), foxglove.PoseInFrame, aloft.VehicleState, aloft.BatteryState (JSON)";

impl MessageKind {
    /// The kind of a schema name (`pkg/msg/Type`, `pkg/Type` or `pkg::msg::Type`, or a JSON
    /// schema title such as `foxglove.PoseInFrame`).
    pub fn from_schema_name(name: &str) -> Option<Self> {
        let n = name.replace("::", "/");
        let n = n.replace("/msg/", "/");
        Some(match n.as_str() {
            "sensor_msgs/BatteryState" | "aloft.BatteryState" => MessageKind::BatteryState,
            "geometry_msgs/PoseStamped" | "foxglove.PoseInFrame" => MessageKind::PoseStamped,
            "geometry_msgs/TwistStamped" => MessageKind::TwistStamped,
            "nav_msgs/Odometry" => MessageKind::Odometry,
            "sensor_msgs/Imu" => MessageKind::Imu,
            "aloft.VehicleState" => MessageKind::AloftState,
            _ => return None,
        })
    }

    /// The model channels this type can fill.
    pub fn provides(self) -> &'static [Channel] {
        match self {
            MessageKind::BatteryState => &[
                Channel::Voltage,
                Channel::Current,
                Channel::Power,
                Channel::Charge,
            ],
            MessageKind::PoseStamped => &[Channel::Position, Channel::Attitude],
            MessageKind::TwistStamped => &[Channel::Velocity],
            MessageKind::Odometry => &[Channel::Position, Channel::Velocity, Channel::Attitude],
            MessageKind::Imu => &[Channel::Attitude, Channel::Acceleration],
            MessageKind::AloftState => &[
                Channel::Position,
                Channel::Velocity,
                Channel::Acceleration,
                Channel::Attitude,
                Channel::Wind,
            ],
        }
    }
}

/// Options of the decoders.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RosDecodeOptions {
    /// Take `BatteryState.current` as positive while discharging (against the message definition).
    pub battery_current_positive_discharging: bool,
}

/// A decoded message: header stamp (s) when the type has one, and the channels it filled.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Decoded {
    /// `header.stamp` (or `timestamp`), s.
    pub stamp_s: Option<f64>,
    /// Channels; `time_s` is left 0.
    pub sample: Sample,
}

fn is_ned(frame_id: &str) -> bool {
    frame_id.ends_with("_ned") || frame_id == "ned"
}

fn is_world(frame_id: &str) -> bool {
    let base = frame_id
        .trim_start_matches('/')
        .trim_end_matches("_ned")
        .trim_end_matches("_enu");
    matches!(
        base,
        "map" | "odom" | "world" | "earth" | "ned" | "enu" | "local_origin"
    )
}

/// Body-FRD-to-NED matrix of an orientation in a frame (ENU/FLU unless `_ned`).
fn orientation(q_xyzw: [f64; 4], frame_id: &str) -> Option<(Mat3, Attitude)> {
    let q = [q_xyzw[3], q_xyzw[0], q_xyzw[1], q_xyzw[2]];
    let r = if is_ned(frame_id) {
        quat_to_mat(q)?
    } else {
        ros_quat_to_mat_ned_frd(q)?
    };
    Some((r, mat_ned_frd_to_euler(&r)))
}

fn world_vec(v: [f64; 3], frame_id: &str) -> [f64; 3] {
    if is_ned(frame_id) {
        ned_to_enu(v)
    } else {
        v
    }
}

/// A body-frame vector (FLU, or FRD for `_ned` frames) rotated to ENU.
fn body_to_enu(r_ned_frd: &Mat3, v: [f64; 3], ned: bool) -> [f64; 3] {
    let frd = if ned { v } else { [v[0], -v[1], -v[2]] };
    ned_to_enu(mat_vec(r_ned_frd, frd))
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

fn finite3(v: [f64; 3]) -> Option<[f64; 3]> {
    v.iter().all(|x| x.is_finite()).then_some(v)
}

fn stamp(sec: i64, nanosec: u64) -> Option<f64> {
    let t = sec as f64 + nanosec as f64 * 1e-9;
    (t > 0.0).then_some(t)
}

fn battery(
    voltage: f64,
    current: f64,
    charge: f64,
    opts: RosDecodeOptions,
    ros_sign: bool,
) -> Sample {
    let sign = if ros_sign && !opts.battery_current_positive_discharging {
        -1.0
    } else {
        1.0
    };
    Sample {
        voltage_v: finite(voltage),
        current_a: finite(current).map(|i| sign * i),
        charge_ah: finite(charge),
        ..Sample::default()
    }
}

fn odometry(
    frame_id: &str,
    child_frame_id: &str,
    pos: [f64; 3],
    q: [f64; 4],
    lin: [f64; 3],
) -> Sample {
    let mut s = Sample {
        pos_enu_m: finite3(world_vec(pos, frame_id)),
        ..Sample::default()
    };
    if let Some((r, att)) = orientation(q, frame_id) {
        s.attitude = Some(att);
        if is_world(child_frame_id) {
            s.vel_enu_mps = finite3(world_vec(lin, child_frame_id));
        } else {
            s.vel_enu_mps = finite3(body_to_enu(&r, lin, is_ned(child_frame_id)));
        }
    }
    s
}

fn imu(frame_id: &str, q: [f64; 4], orientation_cov0: f64, acc: [f64; 3]) -> Sample {
    let mut s = Sample::default();
    // REP-145: covariance[0] = -1 means "no orientation estimate".
    if orientation_cov0 < -0.5 {
        return s;
    }
    if let Some((r, att)) = orientation(q, frame_id) {
        s.attitude = Some(att);
        let mut a = body_to_enu(&r, acc, is_ned(frame_id));
        a[2] -= STANDARD_GRAVITY_MPS2;
        s.acc_enu_mps2 = finite3(a);
    }
    s
}

/// `PoseStamped`: position and orientation in the header's frame.
fn pose(frame_id: &str, pos: [f64; 3], q: [f64; 4]) -> Sample {
    Sample {
        pos_enu_m: finite3(world_vec(pos, frame_id)),
        attitude: orientation(q, frame_id).map(|(_, a)| a),
        ..Sample::default()
    }
}

/// `TwistStamped`: the linear velocity, when the header's frame is a world frame (a body-frame
/// twist cannot be rotated without an attitude).
fn twist(frame_id: &str, lin: [f64; 3]) -> Sample {
    Sample {
        vel_enu_mps: if is_world(frame_id) {
            finite3(world_vec(lin, frame_id))
        } else {
            None
        },
        ..Sample::default()
    }
}

fn header<'a>(r: &mut CdrReader<'a>) -> Result<(Option<f64>, &'a str), CdrError> {
    let sec = r.i32()?;
    let nsec = r.u32()?;
    let frame = r.string()?;
    Ok((stamp(sec.into(), nsec.into()), frame))
}

/// Decode a ROS 2 CDR message of a known type.
pub fn decode_cdr(
    kind: MessageKind,
    data: &[u8],
    opts: RosDecodeOptions,
) -> Result<Decoded, CdrError> {
    let mut r = CdrReader::new(data)?;
    let (stamp_s, frame_id) = header(&mut r)?;
    let sample = match kind {
        MessageKind::BatteryState => cdr_battery_state(&mut r, opts)?,
        MessageKind::PoseStamped => {
            let pos = r.f64s::<3>()?;
            let q = r.f64s::<4>()?;
            pose(frame_id, pos, q)
        }
        MessageKind::TwistStamped => {
            let lin = r.f64s::<3>()?;
            let _ang = r.f64s::<3>()?;
            twist(frame_id, lin)
        }
        MessageKind::Odometry => cdr_odometry(&mut r, frame_id)?,
        MessageKind::Imu => cdr_imu(&mut r, frame_id)?,
        MessageKind::AloftState => return Err(CdrError::Encapsulation(0xffff)),
    };
    Ok(Decoded { stamp_s, sample })
}

/// The body of a `sensor_msgs/BatteryState` after its header (every field is read, so a
/// truncated message is an error).
fn cdr_battery_state(r: &mut CdrReader<'_>, opts: RosDecodeOptions) -> Result<Sample, CdrError> {
    let voltage = r.f32()? as f64;
    let _temperature = r.f32()?;
    let current = r.f32()? as f64;
    let charge = r.f32()? as f64;
    let _capacity = r.f32()?;
    let _design = r.f32()?;
    let percentage = r.f32()? as f64;
    let _status = r.u8()?;
    let _health = r.u8()?;
    let _technology = r.u8()?;
    let _present = r.u8()?;
    r.skip_f32_sequence()?; // cell_voltage
    r.skip_f32_sequence()?; // cell_temperature
    r.string()?; // location
    r.string()?; // serial_number
    let mut s = battery(voltage, current, charge, opts, true);
    s.soc = reported_soc(percentage);
    Ok(s)
}

/// A reported state of charge (0-1), `None` where it is unknown: NaN (ROS `percentage`
/// unmeasured), a negative value, an infinity.
fn reported_soc(fraction: f64) -> Option<f64> {
    (fraction.is_finite() && fraction >= 0.0).then_some(fraction)
}

/// The body of a `nav_msgs/Odometry` after its header.
fn cdr_odometry(r: &mut CdrReader<'_>, frame_id: &str) -> Result<Sample, CdrError> {
    let child = r.string()?;
    let pos = r.f64s::<3>()?;
    let q = r.f64s::<4>()?;
    r.skip_f64s(36)?;
    let lin = r.f64s::<3>()?;
    let _ang = r.f64s::<3>()?;
    r.skip_f64s(36)?;
    Ok(odometry(frame_id, child, pos, q, lin))
}

/// The body of a `sensor_msgs/Imu` after its header.
fn cdr_imu(r: &mut CdrReader<'_>, frame_id: &str) -> Result<Sample, CdrError> {
    let q = r.f64s::<4>()?;
    let cov = r.f64s::<9>()?;
    let _w = r.f64s::<3>()?;
    r.skip_f64s(9)?;
    let acc = r.f64s::<3>()?;
    r.skip_f64s(9)?;
    Ok(imu(frame_id, q, cov[0], acc))
}

fn num(v: &Value, path: &[&str]) -> Result<f64, String> {
    let mut cur = v;
    for p in path {
        cur = cur
            .get(p)
            .ok_or_else(|| format!("missing field '{}'", path.join(".")))?;
    }
    match cur {
        Value::Number(n) => n
            .as_f64()
            .ok_or_else(|| format!("field '{}' is not a number", path.join("."))),
        // JSON has no NaN: writers use null for unmeasured values.
        Value::Null => Ok(f64::NAN),
        _ => Err(format!("field '{}' is not a number", path.join("."))),
    }
}

/// The top-level number `key`, NaN (unmeasured) when the field is absent.
fn optional_num(v: &Value, key: &str) -> Result<f64, String> {
    v.get(key).map_or(Ok(f64::NAN), |_| num(v, &[key]))
}

/// The numbers `keys` of the object at `path`.
fn components<const N: usize>(
    v: &Value,
    path: &[&str],
    keys: [&str; N],
) -> Result<[f64; N], String> {
    let mut p: Vec<&str> = path.to_vec();
    let mut out = [0.0; N];
    for (o, k) in out.iter_mut().zip(keys) {
        p.push(k);
        *o = num(v, &p)?;
        p.pop();
    }
    Ok(out)
}

fn vec3(v: &Value, path: &[&str]) -> Result<[f64; 3], String> {
    components(v, path, ["x", "y", "z"])
}

fn quat(v: &Value, path: &[&str]) -> Result<[f64; 4], String> {
    components(v, path, ["x", "y", "z", "w"])
}

fn json_stamp(v: &Value) -> (Option<f64>, String) {
    let t = v
        .get("header")
        .and_then(|h| h.get("stamp"))
        .or_else(|| v.get("timestamp"));
    let s = t.and_then(|t| {
        let sec = t.get("sec")?.as_i64()?;
        let ns = t
            .get("nanosec")
            .or_else(|| t.get("nsec"))
            .and_then(Value::as_u64)
            .unwrap_or(0);
        stamp(sec, ns)
    });
    let frame = v
        .get("header")
        .and_then(|h| h.get("frame_id"))
        .or_else(|| v.get("frame_id"))
        .and_then(Value::as_str)
        .unwrap_or("")
        .to_string();
    (s, frame)
}

/// Decode a JSON message of a known type (ROS field names, or the foxglove/aloft schemas).
pub fn decode_json(
    kind: MessageKind,
    data: &[u8],
    opts: RosDecodeOptions,
) -> Result<Decoded, String> {
    let v: Value = serde_json::from_slice(data).map_err(|e| format!("invalid JSON: {e}"))?;
    let (stamp_s, frame_id) = json_stamp(&v);
    let sample = match kind {
        MessageKind::BatteryState => json_battery_state(&v, opts)?,
        MessageKind::PoseStamped => pose(
            &frame_id,
            vec3(&v, &["pose", "position"])?,
            quat(&v, &["pose", "orientation"])?,
        ),
        MessageKind::TwistStamped => twist(&frame_id, vec3(&v, &["twist", "linear"])?),
        MessageKind::Odometry => json_odometry(&v, &frame_id)?,
        MessageKind::Imu => json_imu(&v, &frame_id)?,
        MessageKind::AloftState => json_aloft_state(&v)?,
    };
    Ok(Decoded { stamp_s, sample })
}

/// The fields of `aloft.BatteryState`, each optional: aloft's writer leaves out what the log did
/// not have (a row with current but no voltage).
const ALOFT_BATTERY_KEYS: [&str; 5] = [
    "voltage_v",
    "current_a",
    "power_w",
    "charge_ah",
    "state_of_charge",
];

/// `aloft.BatteryState` (SI field names, every one optional, current positive while
/// discharging; `state_of_charge` 0-1) or `sensor_msgs/BatteryState` field names with the ROS
/// sign (`percentage` 0-1, NaN unmeasured).
fn json_battery_state(v: &Value, opts: RosDecodeOptions) -> Result<Sample, String> {
    if !ALOFT_BATTERY_KEYS.iter().any(|k| v.get(k).is_some()) {
        let mut s = json_battery_fields(v, ["voltage", "current", "charge"], opts, true)?;
        s.soc = reported_soc(optional_num(v, "percentage")?);
        return Ok(s);
    }
    let mut s = battery(
        optional_num(v, "voltage_v")?,
        optional_num(v, "current_a")?,
        optional_num(v, "charge_ah")?,
        opts,
        false,
    );
    s.power_w = finite(optional_num(v, "power_w")?);
    s.soc = reported_soc(optional_num(v, "state_of_charge")?);
    Ok(s)
}

/// Voltage, current and (optional) charge from the fields named `keys`.
fn json_battery_fields(
    v: &Value,
    keys: [&str; 3],
    opts: RosDecodeOptions,
    ros_sign: bool,
) -> Result<Sample, String> {
    Ok(battery(
        num(v, &[keys[0]])?,
        num(v, &[keys[1]])?,
        optional_num(v, keys[2])?,
        opts,
        ros_sign,
    ))
}

fn json_odometry(v: &Value, frame_id: &str) -> Result<Sample, String> {
    let child = v
        .get("child_frame_id")
        .and_then(Value::as_str)
        .unwrap_or("");
    Ok(odometry(
        frame_id,
        child,
        vec3(v, &["pose", "pose", "position"])?,
        quat(v, &["pose", "pose", "orientation"])?,
        vec3(v, &["twist", "twist", "linear"])?,
    ))
}

fn json_imu(v: &Value, frame_id: &str) -> Result<Sample, String> {
    let cov0 = v
        .get("orientation_covariance")
        .and_then(|c| c.get(0))
        .and_then(Value::as_f64)
        .unwrap_or(0.0);
    Ok(imu(
        frame_id,
        quat(v, &["orientation"])?,
        cov0,
        vec3(v, &["linear_acceleration"])?,
    ))
}

/// `aloft.VehicleState`: every field but the timestamp is optional.
fn json_aloft_state(v: &Value) -> Result<Sample, String> {
    Ok(Sample {
        pos_enu_m: optional_vec3(v, "position_enu_m")?,
        vel_enu_mps: optional_vec3(v, "velocity_enu_mps")?,
        acc_enu_mps2: optional_vec3(v, "acceleration_enu_mps2")?,
        wind_enu_mps: optional_vec3(v, "wind_enu_mps")?,
        attitude: optional_euler(v)?,
        ..Sample::default()
    })
}

/// The vector `key` when present and finite.
fn optional_vec3(v: &Value, key: &str) -> Result<Option<[f64; 3]>, String> {
    match v.get(key) {
        Some(_) => Ok(finite3(vec3(v, &[key])?)),
        None => Ok(None),
    }
}

/// `roll_rad`, `pitch_rad`, `yaw_rad` when present and finite.
fn optional_euler(v: &Value) -> Result<Option<Attitude>, String> {
    if v.get("roll_rad").is_none() {
        return Ok(None);
    }
    let a = Attitude {
        roll_rad: num(v, &["roll_rad"])?,
        pitch_rad: num(v, &["pitch_rad"])?,
        yaw_rad: num(v, &["yaw_rad"])?,
    };
    Ok(Some(a)
        .filter(|a| a.roll_rad.is_finite() && a.pitch_rad.is_finite() && a.yaw_rad.is_finite()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::CdrWriter;

    // Conversions of exactly representable inputs through a few products: 1e-9.
    const TOL: f64 = 1e-9;

    #[test]
    fn pose_stamped_cdr_enu() {
        let mut w = CdrWriter::new();
        let h = std::f64::consts::FRAC_1_SQRT_2;
        w.header(10, 500_000_000, "map")
            .f64(1.0)
            .f64(2.0)
            .f64(3.0)
            .f64(0.0)
            .f64(0.0)
            .f64(h)
            .f64(h);
        let d = decode_cdr(
            MessageKind::PoseStamped,
            &w.finish(),
            RosDecodeOptions::default(),
        )
        .unwrap();
        assert!((d.stamp_s.unwrap() - 10.5).abs() < TOL);
        assert_eq!(d.sample.pos_enu_m, Some([1.0, 2.0, 3.0]));
        // ROS yaw +90 deg (nose to ENU +y = north) is aerospace heading 0.
        let a = d.sample.attitude.unwrap();
        assert!(a.yaw_rad.abs() < TOL && a.roll_rad.abs() < TOL && a.pitch_rad.abs() < TOL);
    }

    #[test]
    fn battery_state_cdr_sign_and_truncation() {
        let mut w = CdrWriter::new();
        w.header(1, 0, "")
            .f32(12.5)
            .f32(f32::NAN)
            .f32(-8.0)
            .f32(f32::NAN)
            .f32(5.0)
            .f32(5.0)
            .f32(0.5)
            .u8(2)
            .u8(1)
            .u8(3)
            .u8(1)
            .u32(3)
            .f32(4.1)
            .f32(4.2)
            .f32(4.2)
            .u32(0)
            .string("")
            .string("sn");
        let b = w.finish();
        let d = decode_cdr(MessageKind::BatteryState, &b, RosDecodeOptions::default()).unwrap();
        assert_eq!(d.sample.voltage_v, Some(12.5));
        assert_eq!(d.sample.current_a, Some(8.0));
        assert_eq!(d.sample.charge_ah, None);
        assert!(decode_cdr(
            MessageKind::BatteryState,
            &b[..b.len() - 3],
            RosDecodeOptions::default()
        )
        .is_err());
    }

    #[test]
    fn odometry_body_twist_is_rotated() {
        // Heading east in ENU (ROS yaw 0), 2 m/s forward in the body frame: ENU velocity +x.
        let mut w = CdrWriter::new();
        w.header(1, 0, "odom").string("base_link");
        for v in [0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 1.0] {
            w.f64(v);
        }
        for _ in 0..36 {
            w.f64(0.0);
        }
        for v in [2.0, 0.0, 0.0, 0.0, 0.0, 0.0] {
            w.f64(v);
        }
        for _ in 0..36 {
            w.f64(0.0);
        }
        let d = decode_cdr(
            MessageKind::Odometry,
            &w.finish(),
            RosDecodeOptions::default(),
        )
        .unwrap();
        let v = d.sample.vel_enu_mps.unwrap();
        assert!(
            (v[0] - 2.0).abs() < TOL && v[1].abs() < TOL && v[2].abs() < TOL,
            "{v:?}"
        );
        // Aerospace heading east is +90 deg.
        assert!((d.sample.attitude.unwrap().yaw_rad - std::f64::consts::FRAC_PI_2).abs() < TOL);
    }

    #[test]
    fn imu_level_at_rest_has_zero_kinematic_acceleration() {
        let mut w = CdrWriter::new();
        w.header(1, 0, "map");
        for v in [0.0, 0.0, 0.0, 1.0] {
            w.f64(v);
        }
        for _ in 0..9 {
            w.f64(0.0);
        }
        for _ in 0..3 {
            w.f64(0.0);
        }
        for _ in 0..9 {
            w.f64(0.0);
        }
        for v in [0.0, 0.0, STANDARD_GRAVITY_MPS2] {
            w.f64(v);
        }
        for _ in 0..9 {
            w.f64(0.0);
        }
        let d = decode_cdr(MessageKind::Imu, &w.finish(), RosDecodeOptions::default()).unwrap();
        let a = d.sample.acc_enu_mps2.unwrap();
        assert!(a.iter().all(|x| x.abs() < TOL), "{a:?}");
    }

    #[test]
    fn json_pose_in_frame_and_battery() {
        let j = br#"{"timestamp":{"sec":3,"nsec":0},"frame_id":"map","pose":{"position":{"x":1,"y":2,"z":3},"orientation":{"x":0,"y":0,"z":0,"w":1}}}"#;
        let d = decode_json(MessageKind::PoseStamped, j, RosDecodeOptions::default()).unwrap();
        assert_eq!(d.sample.pos_enu_m, Some([1.0, 2.0, 3.0]));
        assert!((d.stamp_s.unwrap() - 3.0).abs() < TOL);
        let j = br#"{"timestamp":{"sec":3,"nsec":0},"voltage_v":12.0,"current_a":10.0,"power_w":120.0}"#;
        let d = decode_json(MessageKind::BatteryState, j, RosDecodeOptions::default()).unwrap();
        assert_eq!(d.sample.current_a, Some(10.0));
        let e = decode_json(
            MessageKind::BatteryState,
            br#"{"voltage": 3}"#,
            RosDecodeOptions::default(),
        )
        .unwrap_err();
        assert!(e.contains("current"), "{e}");
        assert!(decode_json(MessageKind::BatteryState, b"{", RosDecodeOptions::default()).is_err());
    }

    /// Regression (found by aloft-fuzz): `aloft convert` of a log row with current but no
    /// voltage (a `nan` in the voltage column) wrote an `aloft.BatteryState` without `voltage_v`,
    /// which this decoder refused ("missing field 'voltage'"): aloft could not read the MCAP it
    /// wrote. Every field of aloft's battery message is optional.
    #[test]
    fn aloft_battery_messages_may_leave_out_any_field() {
        let opts = RosDecodeOptions::default();
        let d = decode_json(
            MessageKind::BatteryState,
            br#"{"time_s":0.7,"current_a":25.0}"#,
            opts,
        )
        .unwrap();
        assert_eq!((d.sample.voltage_v, d.sample.current_a), (None, Some(25.0)));
        let d = decode_json(
            MessageKind::BatteryState,
            br#"{"time_s":0.7,"voltage_v":47.9,"charge_ah":11.9}"#,
            opts,
        )
        .unwrap();
        assert_eq!((d.sample.voltage_v, d.sample.current_a), (Some(47.9), None));
        assert_eq!(d.sample.charge_ah, Some(11.9));
        let d = decode_json(MessageKind::BatteryState, br#"{"power_w":100.5}"#, opts).unwrap();
        assert_eq!(d.sample.power_w, Some(100.5));
    }

    #[test]
    fn schema_names() {
        assert_eq!(
            MessageKind::from_schema_name("geometry_msgs/msg/PoseStamped"),
            Some(MessageKind::PoseStamped)
        );
        assert_eq!(
            MessageKind::from_schema_name("geometry_msgs/PoseStamped"),
            Some(MessageKind::PoseStamped)
        );
        assert_eq!(
            MessageKind::from_schema_name("std_msgs/msg/UInt16MultiArray"),
            None
        );
    }
}
