//! Small PX4 ULog and ArduPilot DataFlash logs made in code, record by record: the workloads of
//! the log benches, the inputs of the hostile-bytes tests and the seeds of the fuzz targets
//! (one copy of the record layouts for all three). Not part of the reading API.
//!
//! Layouts: a ULog record is its payload size (`u16`, little-endian), its type byte and the
//! payload; a data record's payload is the subscription id (`u16`), the timestamp (`u64`, us)
//! and the fields. A DataFlash record is `A3 95`, its type byte and the fields; an `FMT` record
//! (type `0x80`, 89 bytes) declares a type's length, name (4 bytes), format (16) and columns (64).

/// The ULog file header: magic, version 1, a timestamp of 0.
pub const ULOG_HEADER: [u8; 16] = [
    0x55, 0x4C, 0x6F, 0x67, 0x01, 0x12, 0x35, 1, 0, 0, 0, 0, 0, 0, 0, 0,
];

/// A ULog record: size, type, payload.
pub fn ulog_record(t: u8, payload: &[u8]) -> Vec<u8> {
    let mut r = (payload.len() as u16).to_le_bytes().to_vec();
    r.push(t);
    r.extend_from_slice(payload);
    r
}

/// The start of a ULog: the header, the flag bits (`B`, none set) and a format record (`F`) per
/// entry of `formats` (`name:type field;...`).
pub fn ulog_start(formats: &[impl AsRef<str>]) -> Vec<u8> {
    let mut b = ULOG_HEADER.to_vec();
    b.extend(ulog_record(b'B', &[0u8; 40]));
    for f in formats {
        b.extend(ulog_record(b'F', f.as_ref().as_bytes()));
    }
    b
}

/// A ULog data record (`D`) of subscription `id` at `t_us` with `floats`.
pub fn ulog_data(id: u16, t_us: u64, floats: &[f32]) -> Vec<u8> {
    let mut d = id.to_le_bytes().to_vec();
    d.extend_from_slice(&t_us.to_le_bytes());
    for f in floats {
        d.extend_from_slice(&f.to_le_bytes());
    }
    ulog_record(b'D', &d)
}

/// A ULog subscription (`A`) of `name` as `id`.
pub fn ulog_subscription(id: u16, name: &str) -> Vec<u8> {
    let mut a = vec![0u8];
    a.extend_from_slice(&id.to_le_bytes());
    a.extend_from_slice(name.as_bytes());
    ulog_record(b'A', &a)
}

/// A small ULog: 50 local positions at 10 Hz (NED 1, 2, -3) and 50 battery records of 16 V,
/// 10 A (160 W), a `BAT1_N_CELLS = 4` parameter.
pub fn ulog_small() -> Vec<u8> {
    let mut b = ulog_start(&[
        "battery_status:uint64_t timestamp;float voltage_v;float current_a;uint8_t[4] _padding0;",
        "vehicle_local_position:uint64_t timestamp;float x;float y;float z;float vx;float vy;float vz;",
    ]);
    let mut p = vec![20u8];
    p.extend_from_slice(b"int32_t BAT1_N_CELLS");
    p.extend_from_slice(&4i32.to_le_bytes());
    b.extend(ulog_record(b'P', &p));
    b.extend(ulog_subscription(1, "battery_status"));
    b.extend(ulog_subscription(2, "vehicle_local_position"));
    for i in 0..50u64 {
        let t = 1_000_000 + i * 100_000;
        b.extend(ulog_data(2, t, &[1.0, 2.0, -3.0, 0.5, 0.0, 0.0]));
        b.extend(ulog_data(1, t, &[16.0, 10.0]));
    }
    b
}

/// A ULog of `seconds` of flight with the topic mix of a real one: sensor_combined 200 Hz (not
/// read by aloft), vehicle_attitude 50 Hz, vehicle_local_position 10 Hz, battery_status 5 Hz.
pub fn ulog_flight(seconds: u64) -> Vec<u8> {
    let position = ["x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"];
    let formats: [(&str, u16, String); 4] = [
        (
            "sensor_combined",
            1,
            (0..12).map(|i| format!("float f{i};")).collect(),
        ),
        ("vehicle_attitude", 2, "float[4] q;".into()),
        ("vehicle_local_position", 3, floats(&position)),
        ("battery_status", 4, floats(&["voltage_v", "current_a"])),
    ];
    let texts: Vec<String> = formats
        .iter()
        .map(|(name, _, body)| format!("{name}:uint64_t timestamp;{body}"))
        .collect();
    let mut b = ulog_start(&texts);
    for (name, id, _) in &formats {
        b.extend(ulog_subscription(*id, name));
    }
    for k in 0..seconds * 200 {
        let t = 1_000_000 + k * 5_000;
        let x = (k as f32 * 0.001).sin();
        b.extend(ulog_data(1, t, &[x; 12]));
        if k % 4 == 0 {
            b.extend(ulog_data(2, t, &[1.0, 0.01 * x, 0.02, 0.0]));
        }
        if k % 20 == 0 {
            let p = [x, 2.0 * x, -10.0, 1.0, 2.0, 0.1, 0.0, 0.0, 0.0];
            b.extend(ulog_data(3, t, &p));
        }
        if k % 40 == 0 {
            b.extend(ulog_data(4, t, &[16.0 - x, 20.0 + x]));
        }
    }
    b
}

/// `float <name>;` fields.
fn floats(names: &[&str]) -> String {
    names.iter().map(|n| format!("float {n};")).collect()
}

/// A DataFlash `FMT` record declaring type `t` of `len` bytes.
pub fn dataflash_fmt(t: u8, len: u8, name: &str, format: &str, cols: &str) -> Vec<u8> {
    let mut r = vec![0xA3, 0x95, 0x80, t, len];
    for (s, n) in [(name, 4), (format, 16), (cols, 64)] {
        let mut v = s.as_bytes().to_vec();
        v.resize(n, 0);
        r.extend(v);
    }
    r
}

/// A DataFlash record of type `t` at `t_us` (a `Q` field) with `floats`.
pub fn dataflash_record(t: u8, t_us: u64, floats: &[f32]) -> Vec<u8> {
    let mut r = vec![0xA3, 0x95, t];
    r.extend(t_us.to_le_bytes());
    for f in floats {
        r.extend(f.to_le_bytes());
    }
    r
}

/// The `FMT` record that declares `FMT` itself.
pub fn dataflash_fmt_of_fmt() -> Vec<u8> {
    dataflash_fmt(0x80, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")
}

/// The `FMT` of an `ATT` record (roll, pitch, yaw in degrees) as type `t`.
pub fn att_fmt(t: u8) -> Vec<u8> {
    dataflash_fmt(t, 3 + 8 + 12, "ATT", "Qfff", "TimeUS,Roll,Pitch,Yaw")
}

/// A small DataFlash log: 50 ATT (1, 2, 90 degrees) and 50 BAT (instance 0, 12 V, 5 A) at 10 Hz.
pub fn dataflash_small() -> Vec<u8> {
    let mut b = dataflash_fmt_of_fmt();
    b.extend(att_fmt(1));
    b.extend(dataflash_fmt(
        2,
        3 + 8 + 1 + 8,
        "BAT",
        "QBff",
        "TimeUS,Instance,Volt,Curr",
    ));
    for i in 0..50u64 {
        let t = 1_000_000 + i * 100_000;
        b.extend(dataflash_record(1, t, &[1.0, 2.0, 90.0]));
        b.extend([0xA3, 0x95, 2]);
        b.extend(t.to_le_bytes());
        b.push(0);
        b.extend(12.0f32.to_le_bytes());
        b.extend(5.0f32.to_le_bytes());
    }
    b
}

/// A DataFlash log of `seconds`: IMU 400 Hz (not read by aloft), ATT 25 Hz, BAT 10 Hz.
pub fn dataflash_flight(seconds: u64) -> Vec<u8> {
    let mut b = dataflash_fmt_of_fmt();
    let imu = "TimeUS,GyrX,GyrY,GyrZ,AccX,AccY,AccZ";
    b.extend(dataflash_fmt(1, 3 + 8 + 24, "IMU", "Qffffff", imu));
    b.extend(att_fmt(2));
    b.extend(dataflash_fmt(
        3,
        3 + 8 + 8,
        "BAT",
        "Qff",
        "TimeUS,Volt,Curr",
    ));
    for k in 0..seconds * 400 {
        let t = 1_000_000 + k * 2_500;
        let x = (k as f32 * 0.001).sin();
        b.extend(dataflash_record(1, t, &[x; 6]));
        if k % 16 == 0 {
            b.extend(dataflash_record(2, t, &[x, -x, 90.0 + x]));
        }
        if k % 40 == 0 {
            b.extend(dataflash_record(3, t, &[12.0 - x, 10.0 + x]));
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{read_dataflash, read_ulog, BinaryOptions};

    #[test]
    fn the_generated_logs_read_whole_without_warnings() {
        let o = BinaryOptions::default();
        for (bytes, samples) in [(ulog_small(), 50), (ulog_flight(2), 20)] {
            let r = read_ulog(&bytes[..], &o).unwrap();
            assert_eq!(r.log.samples.len(), samples);
            assert!(r.summary.warnings.is_empty(), "{:?}", r.summary.warnings);
            assert!(r.summary.energy_wh().is_some());
        }
        for bytes in [dataflash_small(), dataflash_flight(2)] {
            let r = read_dataflash(&bytes[..], &o).unwrap();
            assert!(r.log.samples.len() >= 20, "{}", r.log.samples.len());
            assert!(r.summary.warnings.is_empty(), "{:?}", r.summary.warnings);
            assert!(r.summary.energy_wh().is_some());
        }
    }
}
