//! Benches of log reading.
//!
//! Targets (issue 5): `logs/csv_read` and `logs/mcap_read` at least 100 MB/s per core on a
//! generated log (criterion reports the throughput in bytes of input per second).
//! Issue 15: `logs/read/ulog` and `logs/read/dataflash` (decode, join, battery energy) on generated
//! logs with the topic mix of a real flight (kept topics and a high-rate IMU topic that is
//! skipped); guards the same 100 MB/s, so a 1 GB log reads in about 10 s.

use std::hint::black_box;
use std::io::Cursor;
use std::path::Path;

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};

use aloft_logs::synth;
use aloft_logs::{
    read_dataflash, read_ulog, BinaryOptions, ColumnMap, CsvSamples, McapOptions, McapSamples,
};

#[path = "../tests/it/common/ros2.rs"]
mod ros2;
use ros2::{battery_state, message_header, pose_stamped, ros2_channel};

/// A KAIST-layout CSV of `rows` rows at 10 Hz with varying, realistic values (about 170 bytes a row).
fn kaist_csv(rows: usize) -> Vec<u8> {
    let mut s = String::from("timestamp,lat,log,alt,roll,pitch,yaw,vel_x,vel_y,vel_z,acc_x,acc_y,acc_z,act_vx,act_vy,act_yr,capacity,vol,cur,power\n");
    for i in 0..rows {
        let t = i as f64 * 0.1;
        let (a, b) = ((0.37 * t).sin(), (0.11 * t).cos());
        let v = 49.0 - 5.0 * i as f64 / rows as f64;
        let c = 28.0 + 8.0 * a;
        s.push_str(&format!(
            "{},{:.6},{:.6},{:.4},{:.6},{:.6},{:.6},{:.5},{:.5},{:.6},{:.5},{:.5},{:.5},{:.1},{:.1},0,{},{:.3},{:.3},{:.1}\n",
            202_600_741 + i as u64 * 100_000,
            0.634769 + 1e-6 * a,
            2.223 + 1e-6 * b,
            89.0 + 0.01 * a,
            0.3 * a,
            -0.3 * b,
            0.8 + 0.05 * b,
            3.0 * a,
            2.0 * b,
            0.01 * a,
            0.5 * b,
            0.4 * a,
            0.02 * b,
            -2.0 * a,
            1.4 * b,
            12150 - i / 100,
            v,
            c,
            10.0 * v * c
        ));
    }
    s.into_bytes()
}

/// An MCAP (zstd chunks, the `mcap` crate's default) with ROS 2 CDR PoseStamped at 100 Hz and
/// BatteryState at 10 Hz.
fn ros2_mcap(poses: u32) -> Vec<u8> {
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let cp = ros2_channel(&mut w, "geometry_msgs/msg/PoseStamped", "/pose");
    let cb = ros2_channel(&mut w, "sensor_msgs/msg/BatteryState", "/battery");
    for k in 0..poses {
        let ns = 1_700_000_000_000_000_000 + u64::from(k) * 10_000_000;
        let t = f64::from(k) * 0.01;
        let sec = (ns / 1_000_000_000) as i32;
        let pose = pose_stamped(
            sec,
            (ns % 1_000_000_000) as u32,
            "map",
            [t.sin(), t.cos(), 10.0 + 0.1 * t],
            [0.0, 0.0, (0.5 * t).sin(), (0.5 * t).cos()],
        );
        w.write_to_known_channel(&message_header(cp, k, ns), &pose)
            .unwrap();
        if k % 10 == 0 {
            let numbers = [16.0 - 0.0001 * t as f32, 25.0, -20.0, 3.0, 5.0, 5.0, 0.6];
            let battery = battery_state(sec, numbers, &[4.0; 4]);
            w.write_to_known_channel(&message_header(cb, k, ns), &battery)
                .unwrap();
        }
    }
    w.finish().unwrap();
    w.into_inner().into_inner()
}

/// The bench group `name`, of 10 samples (each reads a whole log).
fn group<'a>(c: &'a mut Criterion, name: &str) -> BenchmarkGroup<'a, WallTime> {
    let mut g = c.benchmark_group(name);
    g.sample_size(10);
    g
}

/// In `g`, the bench `name` of `read` over `data` (a whole log in memory), in bytes of input per
/// second.
fn bench_bytes<R>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    data: &[u8],
    read: impl Fn(&[u8]) -> R,
) {
    g.throughput(Throughput::Bytes(data.len() as u64));
    g.bench_function(name, |b| b.iter(|| black_box(read(black_box(data)))));
}

fn csv_read(c: &mut Criterion) {
    let data = kaist_csv(150_000);
    let mut g = group(c, "logs/csv_read");
    bench_bytes(&mut g, "kaist_150k_rows", &data, |data| {
        let map = ColumnMap::kaist();
        let r = CsvSamples::from_reader(data, Path::new("bench.csv"), &map).unwrap();
        r.filter(|s| s.as_ref().unwrap().voltage_v.is_some())
            .count()
    });
    g.finish();
}

fn mcap_read(c: &mut Criterion) {
    let data = ros2_mcap(200_000);
    let mut g = group(c, "logs/mcap_read");
    bench_bytes(&mut g, "ros2_cdr_pose_battery", &data, |data| {
        let path = Path::new("bench.mcap");
        let r = McapSamples::from_reader(Cursor::new(data), path, McapOptions::default());
        r.filter(|s| s.as_ref().unwrap().pos_enu_m.is_some())
            .count()
    });
    g.finish();
}

fn binary_read(c: &mut Criterion) {
    let mut g = group(c, "logs/read");
    let options = BinaryOptions::default();
    let ulog = synth::ulog_flight(3_000);
    bench_bytes(&mut g, "ulog", &ulog, |data| {
        read_ulog(data, &options).unwrap().summary.energy_wh()
    });
    let df = synth::dataflash_flight(3_000);
    bench_bytes(&mut g, "dataflash", &df, |data| {
        read_dataflash(data, &options).unwrap().summary.energy_wh()
    });
    g.finish();
}

criterion_group!(benches, csv_read, mcap_read, binary_read);
criterion_main!(benches);
