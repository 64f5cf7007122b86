//! ROS 2 messages in CDR, and MCAP channels of them, for the tests and benches that write ROS 2
//! logs. The field order is that of the message definitions (`geometry_msgs/msg/PoseStamped`,
//! `sensor_msgs/msg/BatteryState`); [`CdrWriter`] aligns each field.
#![allow(dead_code)] // not every user takes every message

use std::io::{Seek, Write};

use aloft_logs::cdr::CdrWriter;

/// A `geometry_msgs/msg/PoseStamped` stamped `sec`.`nanosec` in `frame`: `position_m` (x, y, z)
/// and the `orientation` quaternion (x, y, z, w).
pub fn pose_stamped(
    sec: i32,
    nanosec: u32,
    frame: &str,
    position_m: [f64; 3],
    orientation: [f64; 4],
) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.header(sec, nanosec, frame);
    for v in position_m.into_iter().chain(orientation) {
        w.f64(v);
    }
    w.finish()
}

/// A `sensor_msgs/msg/BatteryState` stamped `sec` with no frame: `numbers` are voltage (V),
/// temperature (C), current (A, negative when discharging), charge, capacity and design capacity
/// (Ah) and percentage; status discharging (2), health good (1), technology LiPo (3), present;
/// the `cell_voltage`s, no cell temperatures, an empty location and serial number.
pub fn battery_state(sec: i32, numbers: [f32; 7], cell_voltage: &[f32]) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.header(sec, 0, "");
    for v in numbers {
        w.f32(v);
    }
    w.u8(2).u8(1).u8(3).u8(1).u32(cell_voltage.len() as u32);
    for &v in cell_voltage {
        w.f32(v);
    }
    w.u32(0).string("").string("");
    w.finish()
}

/// Adds the schema of the ROS 2 `message_type` (without its text) and a CDR channel `topic` of
/// it to `w`; the channel's id.
pub fn ros2_channel<W: Write + Seek>(
    w: &mut mcap::Writer<W>,
    message_type: &str,
    topic: &str,
) -> u16 {
    let schema = w.add_schema(message_type, "ros2msg", b"").unwrap();
    w.add_channel(schema, topic, "cdr", &Default::default())
        .unwrap()
}

/// The header of message `sequence` on `channel`, logged and published at `ns`.
pub fn message_header(channel: u16, sequence: u32, ns: u64) -> mcap::records::MessageHeader {
    mcap::records::MessageHeader {
        channel_id: channel,
        sequence,
        log_time: ns,
        publish_time: ns,
    }
}
