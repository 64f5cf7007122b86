//! `aloft convert LOG -o x.mcap`, then `aloft log info x.mcap`, on the real logs in
//! `ALOFT_DATA_DIR` (never copied into the repository): the MCAP reads back with the samples and
//! the energy of the original (issue 23, item 6). Through the engine, as the CLI calls it.
//!
//! Run with `--nocapture` to see the figures of every log.

use crate::common;
use common::files;

use std::path::Path;

use aloft::engine::{convert_log, log_info, LogInfo, LogReadOptions};
use aloft_logs::{read_log, McapOptions};

fn name(p: &Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}

/// `log info` of `log`, and of the MCAP `convert` wrote of it.
fn original_and_converted(log: &Path) -> (LogInfo, LogInfo) {
    let options = LogReadOptions::default();
    let original = log_info(log, &options, None).unwrap();
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "logs_convert_data_val-{}-{}.mcap",
        std::process::id(),
        name(log)
    ));
    let c = convert_log(log, &options, &out, true).unwrap();
    assert_eq!(c.samples, original.samples, "{}", log.display());
    let back = log_info(&out, &options, None).unwrap();
    std::fs::remove_file(&out).unwrap();
    (original, back)
}

/// The trapezoid of `p` over `t`, W h.
fn trapezoid_wh(t: &[f64], p: &[f64]) -> f64 {
    (1..t.len())
        .map(|k| 0.5 * (p[k - 1] + p[k]) * (t[k] - t[k - 1]))
        .sum::<f64>()
        / 3600.0
}

/// Time (s) and V x I (W) of every row of a KAIST CSV, read here by column name.
fn kaist_power(path: &Path) -> (Vec<f64>, Vec<f64>) {
    common::csv_columns(path, ["timestamp", "vol", "cur"])
        .into_iter()
        .map(|[t_us, v, i]| (t_us * 1e-6, v * i))
        .unzip()
}

/// Relative difference.
fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The 11 KAIST flights: sample count, no step back, and the energy of the rows (timestamps in
/// microseconds, V x I, trapezoids computed here from the CSV text) for the original and the
/// MCAP. Times pass through whole nanoseconds of the MCAP log time: 1e-9 relative.
#[test]
fn data_val_converted_kaist_flights_read_back_with_their_samples_and_energy() {
    let paths = files("kaist_energy_drone", |n| n.ends_with(".csv"));
    assert_eq!(paths.len(), 11);
    for p in &paths {
        let (t, w) = kaist_power(p);
        let rows_wh = trapezoid_wh(&t, &w);
        let (a, b) = original_and_converted(p);
        let (ea, eb) = (a.energy_wh.unwrap(), b.energy_wh.unwrap());
        println!(
            "{}: {} rows {rows_wh:.6} Wh; original {} samples {ea:.6} Wh; MCAP {} samples {eb:.6} Wh, {} non-monotonic",
            name(p),
            t.len(),
            a.samples,
            b.samples,
            b.time.non_monotonic_count
        );
        assert_eq!(a.samples, t.len() as u64, "{}", name(p));
        assert_eq!(b.samples, a.samples, "{}", name(p));
        assert_eq!(b.time.non_monotonic_count, 0, "{}", name(p));
        assert_eq!(b.time.gap_count, a.time.gap_count, "{}", name(p));
        assert!(rel(ea, rows_wh) < 1e-9, "{}: {ea} vs {rows_wh}", name(p));
        assert!(rel(eb, rows_wh) < 1e-9, "{}: {eb} vs {rows_wh}", name(p));
    }
}

/// The PX4 flugdrohne flights, as per-topic CSV tables and as ULogs, and the ULog and DataFlash
/// logs of `flight_logs/`: the MCAP has the original's samples and time base, and the energy of
/// the original's samples (V x I by trapezoids computed here over the samples aloft read).
///
/// A ULog's or DataFlash log's own `energy_wh` integrates its battery records themselves; the
/// MCAP holds the battery interpolated onto the motion samples (what the join of the log gives),
/// so its energy is the samples' energy. Against the independent figures of
/// `flight_logs/README.md` (pyulog, pymavlink; 3-4 significant digits) both are within 1 %.
#[test]
fn data_val_converted_px4_and_ardupilot_logs_read_back_with_their_samples_and_energy() {
    let figures = [
        ("px4_esc_status_log.ulg", 13.391),
        ("pyulog_sample_log_small.ulg", 0.0108),
        ("upgradeenergy_test.ulg", 0.771),
        ("erle_PXFv2.0b+Rpi.BIN", 0.897),
        ("sitl_ac47_00000002.BIN", 2.035),
    ];
    let mut paths = files("px4_flugdrohne/csv", |n| {
        n.ends_with("_battery_status_0.csv")
    });
    assert_eq!(paths.len(), 5);
    paths.extend(files("px4_flugdrohne/ulg", |n| n.ends_with(".ulg")));
    paths.extend(files("flight_logs", |n| {
        let n = n.to_ascii_lowercase();
        n.ends_with(".ulg") || n.ends_with(".bin")
    }));
    assert_eq!(paths.len(), 17);
    for p in &paths {
        let samples = read_log(p, None, &McapOptions::default()).unwrap().samples;
        let (t, w): (Vec<f64>, Vec<f64>) = samples
            .iter()
            .filter_map(|s| s.electrical_power_w().map(|w| (s.time_s, w)))
            .unzip();
        let (a, b) = original_and_converted(p);
        println!(
            "{}: original {} samples {:?} Wh ({} non-monotonic); MCAP {} samples {:?} Wh ({} non-monotonic); samples' V x I {:.6} Wh",
            name(p),
            a.samples,
            a.energy_wh,
            a.time.non_monotonic_count,
            b.samples,
            b.energy_wh,
            b.time.non_monotonic_count,
            trapezoid_wh(&t, &w),
        );
        assert_eq!(b.samples, a.samples, "{}", name(p));
        assert_eq!(b.samples, samples.len() as u64, "{}", name(p));
        assert_eq!(
            b.time.non_monotonic_count,
            a.time.non_monotonic_count,
            "{}",
            name(p)
        );
        assert_eq!(b.time.gap_count, a.time.gap_count, "{}", name(p));
        match b.energy_wh {
            Some(e) => {
                let expected = trapezoid_wh(&t, &w);
                assert!(rel(e, expected) < 1e-9, "{}: {e} vs {expected}", name(p));
            }
            None => assert!(t.len() < 2, "{}: {} power samples", name(p), t.len()),
        }
        if let Some((_, f)) = figures.iter().find(|(n, _)| *n == name(p)) {
            let (ea, eb) = (a.energy_wh.unwrap(), b.energy_wh.unwrap());
            assert!(rel(ea, *f) < 0.01, "{}: {ea} vs {f}", name(p));
            assert!(rel(eb, *f) < 0.01, "{}: {eb} vs {f}", name(p));
        }
    }
}
