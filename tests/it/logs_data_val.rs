//! aloft-logs against the real logs in `ALOFT_DATA_DIR` (default `../shared/data` from the
//! workspace root; never copied into the repository): the ROS 2 MCAP recording, the 11 KAIST
//! flights, the 5 PX4 flights, and the lag of power behind motion in the KAIST logs.
//!
//! Run with `--nocapture` to see the figures each test reports.

use crate::common;
use common::files;

use std::path::Path;

use aloft_logs::{
    estimate_lag_s, read_log, InfoAccumulator, LogError, McapOptions, McapSamples, Profile,
};

#[test]
fn data_val_mcap_foreign_decodes_all_poses_on_cub1() {
    let path = files("mcap_foreign", |n| n.ends_with(".mcap")).remove(0);
    let mut r = McapSamples::open(&path, McapOptions::default()).unwrap();
    let mut poses = 0u64;
    let mut max_abs_m = 0.0f64;
    for s in r.by_ref() {
        let s = s.unwrap();
        if let Some(p) = s.pos_enu_m {
            poses += 1;
            max_abs_m = p.iter().fold(max_abs_m, |m, x| m.max(x.abs()));
            assert!(s.attitude.is_some());
        }
    }
    // The data README: 21,258 messages, 19,703 PoseStamped on /cub1/pose, 1,555 UInt16MultiArray.
    assert_eq!(poses, 19_703);
    assert_eq!(r.messages(), 21_258);
    let topics = r.topics();
    let names: Vec<&str> = topics.iter().map(|t| t.topic.as_str()).collect();
    assert!(
        names.contains(&"/cub1/pose") && names.contains(&"/cub1/joy_serial_status"),
        "{names:?}"
    );
    let pose = topics.iter().find(|t| t.topic == "/cub1/pose").unwrap();
    assert_eq!(pose.schema, "geometry_msgs/msg/PoseStamped");
    assert_eq!(pose.decoded, 19_703);
    let joy = topics
        .iter()
        .find(|t| t.topic == "/cub1/joy_serial_status")
        .unwrap();
    assert_eq!(joy.messages, 1_555);
    let report = r.time_report();
    // About 198 s of recording (README); 2 s of slack for where the first and last pose fall.
    assert!(
        (report.duration_s - 198.0).abs() < 2.0,
        "{}",
        report.duration_s
    );
    // A fixed-wing test flight stays within a few km of its origin.
    assert!(max_abs_m < 5_000.0, "{max_abs_m}");
    println!(
        "mcap_foreign: {poses} poses over {:.1} s, {:.1} Hz, {} gaps, {} non-monotonic steps, max |coordinate| {max_abs_m:.1} m",
        report.duration_s,
        pose.rate_hz().unwrap(),
        report.gap_count,
        report.non_monotonic_count
    );
}

#[test]
fn data_val_mcap_foreign_has_no_power_and_says_so() {
    let path = files("mcap_foreign", |n| n.ends_with(".mcap")).remove(0);
    let log = read_log(&path, None, &McapOptions::default()).unwrap();
    let e = log.power_series().unwrap_err();
    assert!(matches!(e, LogError::NoPowerData { .. }));
    let msg = e.to_string();
    assert!(
        msg.contains("cub_stabilize") && msg.contains("no power data"),
        "{msg}"
    );
    assert!(
        msg.contains("position") && msg.contains("attitude"),
        "{msg}"
    );
    println!("{msg}");
}

#[test]
fn data_val_kaist_flights_read_clean_and_energy_matches_capacity_drop() {
    let paths = files("kaist_energy_drone", |n| n.ends_with(".csv"));
    assert_eq!(paths.len(), 11);
    for p in &paths {
        let log = read_log(p, None, &McapOptions::default()).unwrap();
        let mut acc = InfoAccumulator::new();
        let mut charge_ah = 0.0;
        for w in log.samples.windows(2) {
            acc.push(&w[0]);
            let dt = w[1].time_s - w[0].time_s;
            charge_ah += 0.5 * (w[0].current_a.unwrap() + w[1].current_a.unwrap()) * dt / 3600.0;
        }
        let stats = acc.finish();
        let first = log.samples.first().unwrap();
        let last = log.samples.last().unwrap();
        let drop_ah = first.charge_ah.unwrap() - last.charge_ah.unwrap();
        let v = stats.power.mean_power_w.unwrap();
        println!(
            "{}: {} samples, {:.0} s, {} gaps, {} backwards, {} power values dropped, energy {:.1} Wh, mean {v:.0} W, integral of I {charge_ah:.3} Ah vs capacity drop {drop_ah:.3} Ah ({:.1} %)",
            p.file_name().unwrap().to_string_lossy(),
            log.samples.len(),
            log.time.duration_s,
            log.time.gap_count,
            log.time.non_monotonic_count,
            log.dropped_count,
            stats.power.energy_wh.unwrap(),
            100.0 * charge_ah / drop_ah,
        );
        assert_eq!(log.time.non_monotonic_count, 0, "{}", p.display());
        // The data README: 12S pack, 49 V falling to 44 V, 20-39 A, 1.0-1.7 kW. A few rows hold
        // sensor glitches (89.97 V with an overflowed power in random5-2sec-4): at most 0.1 %.
        let off = log
            .samples
            .iter()
            .filter(|s| !(40.0..=51.0).contains(&s.voltage_v.unwrap()))
            .count();
        assert!(
            off * 1000 <= log.samples.len(),
            "{off} rows outside 40-51 V"
        );
        assert!((900.0..=1800.0).contains(&v), "{v}");
        // README: integrated V x I is about 93 % of the capacity drop. Read as charge (the
        // column is mAh), the integral of I must be a large part of the drop, not a multiple of it
        // (a wrong unit or scale gives factors of 10 or 1000): 70-110 %.
        let ratio = charge_ah / drop_ah;
        assert!((0.7..=1.1).contains(&ratio), "{}: {ratio}", p.display());
    }
}

#[test]
fn data_val_px4_flights_join_onto_one_time_base() {
    let paths = files("px4_flugdrohne/csv", |n| {
        n.ends_with("_vehicle_local_position_0.csv")
    });
    assert_eq!(paths.len(), 5);
    for p in &paths {
        let log = read_log(p, Some(&Profile::Px4), &McapOptions::default()).unwrap();
        let rows = std::fs::read_to_string(p).unwrap().lines().count() - 1;
        assert_eq!(
            log.samples.len(),
            rows,
            "one joined sample per local-position row"
        );
        let with_power = log
            .samples
            .iter()
            .filter(|s| s.electrical_power_w().is_some())
            .count();
        let with_att = log.samples.iter().filter(|s| s.attitude.is_some()).count();
        let mut acc = InfoAccumulator::new();
        log.samples.iter().for_each(|s| acc.push(s));
        let stats = acc.finish();
        let vmin = log
            .samples
            .iter()
            .filter_map(|s| s.voltage_v)
            .fold(f64::INFINITY, f64::min);
        let vmax = log
            .samples
            .iter()
            .filter_map(|s| s.voltage_v)
            .fold(0.0, f64::max);
        let z0 = log.samples.iter().find_map(|s| s.pos_enu_m).unwrap()[2];
        let zmax = log
            .samples
            .iter()
            .filter_map(|s| s.pos_enu_m)
            .fold(f64::MIN, |m, p| m.max(p[2]))
            - z0;
        println!(
            "{}: {} samples over {:.1} s, power on {with_power}, attitude on {with_att}, {:.2} Wh, V {vmin:.2}-{vmax:.2}, max climb above start {zmax:.1} m, {} gaps",
            p.file_name().unwrap().to_string_lossy(),
            log.samples.len(),
            log.time.duration_s,
            stats.power.energy_wh.unwrap_or(f64::NAN),
            log.time.gap_count,
        );
        // Battery and attitude cover all but the samples before their first message.
        assert!(with_power * 10 >= rows * 9, "{with_power} of {rows}");
        assert!(with_att * 10 >= rows * 9, "{with_att} of {rows}");
        // 3S pack (README): 9-12.7 V under load.
        assert!(vmin > 9.0 && vmax < 12.8, "{vmin} {vmax}");
        // Flights with take-off: the vehicle climbs (ENU up positive).
        assert!(zmax > 1.0, "{zmax}");
    }
}

/// Uniformly sampled KAIST series (the logs are 10 Hz with no gaps; checked in the test).
struct Series {
    power_w: Vec<f64>,
    speed_mps: Vec<f64>,
    tilt_rad: Vec<f64>,
    acc_h_mps2: Vec<f64>,
}

fn kaist_series(p: &Path) -> (Series, f64) {
    let log = read_log(p, Some(&Profile::Kaist), &McapOptions::default()).unwrap();
    assert!(log.time.is_clean(), "{}", p.display());
    let dt = log.time.nominal_period_s.unwrap();
    let mut s = Series {
        power_w: vec![],
        speed_mps: vec![],
        tilt_rad: vec![],
        acc_h_mps2: vec![],
    };
    for x in &log.samples {
        s.power_w.push(x.electrical_power_w().unwrap());
        let v = x.vel_enu_mps.unwrap();
        s.speed_mps.push(v[0].hypot(v[1]));
        let a = x.attitude.unwrap();
        s.tilt_rad.push(
            (a.roll_rad.cos() * a.pitch_rad.cos())
                .clamp(-1.0, 1.0)
                .acos(),
        );
        let acc = x.acc_enu_mps2.unwrap();
        s.acc_h_mps2.push(acc[0].hypot(acc[1]));
    }
    (s, dt)
}

#[test]
fn data_val_kaist_power_lag_behind_motion() {
    // Reports the lag found with three motion proxies. Asserted is only what the data README
    // states, that power lags motion by seconds: with the tilt proxy (the thrust vector's
    // inclination, which sets the power at these speeds) the lag is positive and longer than
    // half a second on every flight. The figures themselves are reported, not asserted.
    let paths = files("kaist_energy_drone", |n| n.ends_with(".csv"));
    let max_lag_s = 10.0;
    println!("flight | lag vs speed (r) | lag vs tilt (r) | lag vs horizontal acc (r)");
    let mut speed_lags = vec![];
    let mut tilt_lags = vec![];
    for p in &paths {
        let (s, dt) = kaist_series(p);
        let mut row = format!("{}", p.file_name().unwrap().to_string_lossy());
        for (i, proxy) in [&s.speed_mps, &s.tilt_rad, &s.acc_h_mps2]
            .into_iter()
            .enumerate()
        {
            let e = estimate_lag_s(&s.power_w, proxy, dt, max_lag_s).unwrap();
            assert!(e.lag_s.is_finite() && e.lag_s.abs() <= max_lag_s + dt);
            assert!(e.correlation >= e.correlation_at_zero - 1e-12);
            row += &format!(
                " | {:+.2} s (r {:.2}, r0 {:.2}{})",
                e.lag_s,
                e.correlation,
                e.correlation_at_zero,
                if e.at_window_edge { ", edge" } else { "" }
            );
            if i == 0 {
                speed_lags.push(e.lag_s);
            }
            if i == 1 {
                assert!(
                    e.lag_s > 0.5,
                    "{}: power vs tilt lag {:.2} s",
                    p.display(),
                    e.lag_s
                );
                tilt_lags.push(e.lag_s);
            }
        }
        println!("{row}");
    }
    speed_lags.sort_by(f64::total_cmp);
    tilt_lags.sort_by(f64::total_cmp);
    println!(
        "median lag of power behind ground speed: {:.2} s, behind tilt: {:.2} s",
        speed_lags[speed_lags.len() / 2],
        tilt_lags[tilt_lags.len() / 2]
    );
}
