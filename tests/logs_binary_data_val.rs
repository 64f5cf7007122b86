//! PX4 ULog and ArduPilot DataFlash logs of `flight_logs/` (and the flugdrohne ULogs) read
//! against the energies computed independently of aloft (pyulog 1.3.0, pymavlink 2.4.50; table
//! in `flight_logs/README.md`).

use std::path::PathBuf;

use aloft_logs::{read_dataflash, read_ulog, BinaryLog, BinaryOptions};

fn data_dir() -> PathBuf {
    PathBuf::from(std::env::var("ALOFT_DATA_DIR").unwrap_or_else(|_| "../shared/data".into()))
}

fn read(name: &str) -> Option<BinaryLog> {
    let p = data_dir().join("flight_logs").join(name);
    let f = std::fs::File::open(&p).ok()?;
    let r = std::io::BufReader::new(f);
    let o = BinaryOptions::default();
    Some(
        if name.ends_with(".ulg") {
            read_ulog(r, &o)
        } else {
            read_dataflash(r, &o)
        }
        .unwrap(),
    )
}

#[test]
fn probe() {
    for n in [
        "px4_esc_status_log.ulg",
        "pyulog_sample_log_small.ulg",
        "upgradeenergy_test.ulg",
        "erle_PXFv2.0b+Rpi.BIN",
        "erle_2014-09-07_7.BIN",
        "sitl_ac47_00000002.BIN",
        "beastayyg_sample.bin",
    ] {
        let b = read(n).unwrap();
        let s = &b.summary;
        println!("{n}: samples {} dur {:.1} energy {:?} power {} bat {:?} inst {:?} span {:.1} base {:.1} skipped {} cells {:?} cap {:?} rho {:?} air {:?}\n  records {:?}\n  warnings {:?}\n  time {:?}", b.log.samples.len(), b.log.time.duration_s, s.energy_wh(), s.power_available(), s.battery, s.battery_instances, s.battery.span_s(), s.base_span_s, s.bytes_skipped, s.battery_cells, s.battery_capacity_ah, s.air_density_kg_m3, s.in_air_s, s.records, s.warnings, (b.log.time.gap_count, b.log.time.non_monotonic_count));
        let ch: Vec<_> = b.log.channels();
        println!("  channels {ch:?}");
    }
}
