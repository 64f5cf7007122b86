//! Benches of the telemetry-log reader and decoder.
//!
//! Target (issue 25): `aloft live --tlog --speed max` follows a log at least 50 times faster than
//! real time, engine included, so reading and decoding alone must be far faster: these guard
//! 1,000 times real time on a whole shared log (`dronekit_flight_replay.tlog`, 1,377 s, 75,477
//! frames, 1.7 % garbage) and on a generated 10-minute flight. Criterion reports frames per
//! second; the log's span over the time per iteration is the factor over real time.
//!
//! - `link/tlog/frames/*`: [`TlogReader`] alone (framing, CRC, payload decoding);
//! - `link/tlog/events/*`: [`TlogSource`], frames decoded into telemetry events.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

use aloft_link::mavlink::dialects::ardupilotmega as m;
use aloft_link::mavlink::MavHeader;
use aloft_link::{TlogReader, TlogSource};

/// The shared log, when the data folder is there (`ALOFT_DATA_DIR` or `../shared/data`).
fn shared_log() -> Option<Vec<u8>> {
    let dir = std::env::var_os("ALOFT_DATA_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| {
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
        });
    std::fs::read(dir.join("telemetry/dronekit_flight_replay.tlog")).ok()
}

/// A 10-minute flight as a ground station logs it: ATTITUDE, GLOBAL_POSITION_INT and VFR_HUD at
/// 10 Hz, HEARTBEAT, SYS_STATUS and MISSION_CURRENT at 1 Hz, MAVLink 2 (19,800 frames).
fn generated_log() -> Vec<u8> {
    let vehicle = MavHeader {
        system_id: 1,
        component_id: 1,
        sequence: 0,
    };
    let mut out = Vec::new();
    let mut write = |t_us: u64, msg: &m::MavMessage| {
        out.extend(t_us.to_be_bytes());
        // Writing to a Vec cannot fail.
        let _ = aloft_link::mavlink::write_v2_msg(&mut out, vehicle, msg);
    };
    let t0 = 1_714_521_600_000_000u64;
    for k in 0..6_000u32 {
        let t_us = t0 + u64::from(k) * 100_000;
        let s = f64::from(k) * 0.1;
        if k % 10 == 0 {
            write(
                t_us,
                &m::MavMessage::HEARTBEAT(m::HEARTBEAT_DATA {
                    custom_mode: 3,
                    mavtype: m::MavType::MAV_TYPE_QUADROTOR,
                    autopilot: m::MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA,
                    base_mode: m::MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED,
                    system_status: m::MavState::MAV_STATE_ACTIVE,
                    mavlink_version: 3,
                }),
            );
            write(
                t_us,
                &m::MavMessage::SYS_STATUS(m::SYS_STATUS_DATA {
                    voltage_battery: 16_000 - (k / 10) as u16,
                    current_battery: 2_000 + (k % 300) as i16,
                    battery_remaining: (100 - k / 100) as i8,
                    ..m::SYS_STATUS_DATA::default()
                }),
            );
            write(
                t_us,
                &m::MavMessage::MISSION_CURRENT(m::MISSION_CURRENT_DATA {
                    seq: (k / 1_000) as u16,
                    ..m::MISSION_CURRENT_DATA::default()
                }),
            );
        }
        write(
            t_us,
            &m::MavMessage::ATTITUDE(m::ATTITUDE_DATA {
                time_boot_ms: 60_000 + k * 100,
                roll: (0.3 * s).sin() as f32 * 0.1,
                pitch: -0.15,
                yaw: (0.01 * s) as f32,
                ..m::ATTITUDE_DATA::default()
            }),
        );
        write(
            t_us,
            &m::MavMessage::GLOBAL_POSITION_INT(m::GLOBAL_POSITION_INT_DATA {
                time_boot_ms: 60_000 + k * 100,
                lat: 473_977_000 + (k * 5) as i32,
                lon: 85_456_000 + (k * 3) as i32,
                alt: 520_000,
                relative_alt: 30_000,
                vx: 500,
                vy: 300,
                vz: 0,
                hdg: 3_000,
            }),
        );
        write(
            t_us,
            &m::MavMessage::VFR_HUD(m::VFR_HUD_DATA {
                airspeed: 6.0,
                groundspeed: 5.8,
                ..m::VFR_HUD_DATA::default()
            }),
        );
    }
    out
}

fn frames_of(bytes: &[u8]) -> u64 {
    TlogReader::new(bytes, "bench").flatten().count() as u64
}

fn bench_log(c: &mut Criterion, name: &str, bytes: &[u8]) {
    let frames = frames_of(bytes);
    per_frame(c, "link/tlog/frames", name, frames, || {
        let mut r = TlogReader::new(black_box(bytes), "bench");
        let n = r.by_ref().flatten().count();
        black_box((n as u64, r.stats().bytes_skipped as f64))
    });
    per_frame(c, "link/tlog/events", name, frames, || {
        let mut s = TlogSource::new(black_box(bytes), "bench");
        let mut events = 0u64;
        let mut last_s = 0.0;
        while let Ok(Some(t)) = s.next_telemetry() {
            events += 1;
            last_s = t.time_s;
        }
        black_box((events, last_s))
    });
}

/// One bench of `group`, its throughput in frames.
fn per_frame(
    c: &mut Criterion,
    group: &str,
    name: &str,
    frames: u64,
    mut run: impl FnMut() -> (u64, f64),
) {
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(frames));
    g.sample_size(20);
    g.bench_function(name, |b| b.iter(&mut run));
    g.finish();
}

fn tlog(c: &mut Criterion) {
    if let Some(bytes) = shared_log() {
        bench_log(c, "dronekit_flight_replay", &bytes);
    }
    bench_log(c, "generated_10_min", &generated_log());
}

criterion_group!(benches, tlog);
criterion_main!(benches);
