//! PX4 ULog and ArduPilot DataFlash logs of `flight_logs/` (and the flugdrohne ULogs) against
//! figures computed independently of aloft: the energies of `flight_logs/README.md` (pyulog
//! 1.3.0, pymavlink 2.4.50), recomputed by those readers here when Python has them, and the
//! `ardupilot-binlog` crate's decoding of every DataFlash record aloft uses.

use crate::common;
use common::data_dir;

use std::collections::BTreeMap;
use std::path::PathBuf;

use aloft_logs::dataflash::DataflashRecords;
use aloft_logs::{read_dataflash, read_ulog, BinaryLog, BinaryOptions};

fn path(name: &str) -> PathBuf {
    data_dir().join("flight_logs").join(name)
}

fn read(p: &std::path::Path) -> BinaryLog {
    let f = std::fs::File::open(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let r = std::io::BufReader::new(f);
    let o = BinaryOptions::default();
    let ulog = p.extension().is_some_and(|e| e == "ulg");
    if ulog {
        read_ulog(r, &o)
    } else {
        read_dataflash(r, &o)
    }
    .unwrap()
}

/// The README's table: file, battery records, energy (W h; `None`: no battery data).
const FIGURES: [(&str, u64, Option<f64>); 7] = [
    ("px4_esc_status_log.ulg", 73, Some(13.391)),
    ("pyulog_sample_log_small.ulg", 21, Some(0.0108)),
    ("upgradeenergy_test.ulg", 166, Some(0.771)),
    ("erle_PXFv2.0b+Rpi.BIN", 4675, Some(0.897)),
    ("erle_2014-09-07_7.BIN", 89, None),
    ("sitl_ac47_00000002.BIN", 405, Some(2.035)),
    ("beastayyg_sample.bin", 0, None),
];

/// Energies agree within 1 %: the independent figures are rounded to 3-4 significant digits
/// (0.0108 Wh is +-0.5 %), and both sides integrate the same records by the same rule.
#[test]
fn data_val_energy_of_every_shared_binary_log_matches_the_independent_figure() {
    for (name, records, energy) in FIGURES {
        let b = read(&path(name));
        let s = &b.summary;
        assert_eq!(s.battery.records, records, "{name}");
        match energy {
            Some(e) => {
                let got = s.energy_wh().unwrap();
                assert!((got - e).abs() <= 0.01 * e, "{name}: {got} Wh vs {e} Wh");
                assert!(s.power_available(), "{name}");
            }
            None => {
                assert!(!s.power_available(), "{name}");
                assert!(
                    s.warnings.iter().any(|w| w.contains("no battery data")),
                    "{name}"
                );
            }
        }
        assert_eq!(s.bytes_skipped, 0, "{name}: {:?}", s.warnings);
        assert!(!b.log.samples.is_empty(), "{name}");
    }
}

/// What each log exercises (README "what it exercises").
#[test]
fn data_val_what_each_log_exercises() {
    // Two battery instances: instance 0 by default, instance 1 on request.
    let p = path("pyulog_sample_log_small.ulg");
    let b = read(&p);
    assert_eq!(b.summary.battery_instances, vec![0, 1]);
    let o = BinaryOptions {
        battery_instance: 1,
        ..BinaryOptions::default()
    };
    let one = read_ulog(std::fs::File::open(&p).unwrap(), &o).unwrap();
    assert_eq!(one.summary.battery.records, 21);
    // The stray `mission` message (1194 s) is not a topic of the join: the log spans 6.5 s.
    assert!(b.log.time.duration_s < 7.0, "{}", b.log.time.duration_s);
    // Stamps at 0 s and vehicle_command do not stretch the span: 33 s, and 6 cells (BAT1_N_CELLS
    // wins over the old BAT_N_CELLS 3).
    let u = read(&path("upgradeenergy_test.ulg"));
    assert!(u.log.time.duration_s < 34.0);
    assert_eq!(u.summary.battery_cells, Some(6));
    // Old CURR: centi-units, 3S at 9.9-12.4 V.
    let e = read(&path("erle_PXFv2.0b+Rpi.BIN"));
    let v: Vec<f64> = e.log.samples.iter().filter_map(|s| s.voltage_v).collect();
    assert!(v.iter().all(|v| (9.0..12.6).contains(v)), "{:?}", &v[..5]);
    // GPS TimeMS is week time: the old log's span is its 303 s, not 6.8 days.
    let g = read(&path("erle_2014-09-07_7.BIN"));
    assert!(g.log.time.duration_s < 400.0, "{}", g.log.time.duration_s);
    // PARM stamped 1183 s does not stretch the SITL flight's 40 s.
    let sitl = read(&path("sitl_ac47_00000002.BIN"));
    assert!(sitl.log.time.duration_s < 41.0);
    assert!(sitl.log.origin.is_some());
}

#[test]
fn data_val_flugdrohne_ulogs_read_with_power() {
    let dir = data_dir().join("px4_flugdrohne").join("ulg");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "ulg") {
            continue;
        }
        let b = read(&p);
        assert!(
            b.summary.power_available(),
            "{}: {:?}",
            p.display(),
            b.summary.warnings
        );
        assert_eq!(b.summary.battery_cells, Some(3), "{}", p.display());
        assert!(b.summary.energy_wh().unwrap() > 1.0, "{}", p.display());
        n += 1;
    }
    assert_eq!(n, 5);
}

/// Counts and numeric values of the records aloft uses agree with the `ardupilot-binlog` crate
/// (which scales c/C/e/E by 0.01 as aloft does; `L` it may leave raw).
#[test]
fn data_val_dataflash_decoding_agrees_with_ardupilot_binlog() {
    const KINDS: [&str; 9] = [
        "BAT", "CURR", "POS", "GPS", "ATT", "CTUN", "PARM", "MODE", "CMD",
    ];
    for (name, _, _) in FIGURES.iter().filter(|f| !f.0.ends_with(".ulg")) {
        let p = path(name);
        let mut ours: BTreeMap<String, Vec<Vec<(String, f64)>>> = BTreeMap::new();
        for r in DataflashRecords::new(std::io::BufReader::new(std::fs::File::open(&p).unwrap())) {
            if KINDS.contains(&r.name.as_str()) {
                ours.entry(r.name.clone()).or_default().push(r.values);
            }
        }
        let file = ardupilot_binlog::File::open(&p).unwrap();
        let mut theirs: BTreeMap<String, Vec<ardupilot_binlog::Entry>> = BTreeMap::new();
        for e in file.entries().unwrap().map_while(Result::ok) {
            if KINDS.contains(&e.name.as_str()) {
                theirs.entry(e.name.clone()).or_default().push(e);
            }
        }
        for kind in KINDS {
            let (a, b) = (ours.get(kind), theirs.get(kind));
            let (na, nb) = (a.map_or(0, Vec::len), b.map_or(0, Vec::len));
            assert_eq!(
                na, nb,
                "{name} {kind}: {na} records vs ardupilot-binlog {nb}"
            );
            for (ra, rb) in a.into_iter().flatten().zip(b.into_iter().flatten()) {
                for (col, v) in ra {
                    let Some(w) = rb.get_f64(col) else { continue };
                    // f32 values widened the same way: equal. `L` (raw there) and the FMTU
                    // multipliers aloft applies (MULT: powers of ten, stored from f32) differ
                    // from it by a power of ten.
                    let ratio = v / w;
                    let power_of_ten = w != 0.0
                        && ratio > 0.0
                        && (ratio.log10() - ratio.log10().round()).abs() < 1e-6;
                    let same = (v - w).abs() <= 1e-9 * v.abs().max(1.0)
                        || power_of_ten
                        || (v.is_nan() && w.is_nan());
                    assert!(same, "{name} {kind}.{col}: {v} vs {w}");
                }
            }
        }
    }
}

/// The Python script that computes the README's figures with pyulog and pymavlink.
const INDEPENDENT: &str = r#"
import sys
from pyulog import ULog
from pymavlink import DFReader
p = sys.argv[1]
rows = []
if p.endswith('.ulg'):
    u = ULog(p, ['battery_status'])
    d = [x for x in u.data_list if x.multi_id == 0][0].data
    rows = [(t * 1e-6, v, i) for t, v, i in zip(d['timestamp'], d['voltage_v'], d['current_a']) if v > 0 and i >= 0]
else:
    m = DFReader.DFReader_binary(p)
    names = set(f.name for f in m.formats.values())
    kind = 'BAT' if 'BAT' in names else 'CURR'
    while True:
        r = m.recv_match(type=kind)
        if r is None:
            break
        inst = getattr(r, 'Instance', getattr(r, 'Inst', 0))
        if inst != 0:
            continue
        t = getattr(r, 'TimeUS', None)
        t = t * 1e-6 if t is not None else r.TimeMS * 1e-3
        v, i = r.Volt, r.Curr
        if kind == 'CURR' and isinstance(v, int):
            v, i = v / 100.0, i / 100.0
        if v > 0:
            rows.append((t, v, i))
e = sum(0.5 * (a[1] * a[2] + b[1] * b[2]) * (b[0] - a[0]) for a, b in zip(rows, rows[1:]) if b[0] > a[0])
print(len(rows), e / 3600.0)
"#;

#[test]
fn data_val_energy_matches_pyulog_and_pymavlink_when_present() {
    if !common::python_has("pyulog, pymavlink") {
        eprintln!("NOTICE: skipping the pyulog/pymavlink check: python3 with pyulog and pymavlink is not available (the figures they gave are in FIGURES)");
        return;
    }
    for (name, _, energy) in FIGURES {
        let Some(_) = energy else { continue };
        let p = path(name);
        let text = common::python_stdout(INDEPENDENT, &[p.to_str().unwrap()]);
        let mut it = text.split_whitespace();
        let valid: u64 = it.next().unwrap().parse().unwrap();
        let e: f64 = it.next().unwrap().parse().unwrap();
        let b = read(&p);
        assert_eq!(b.summary.battery.valid, valid, "{name}");
        let got = b.summary.energy_wh().unwrap();
        // Same records, same rule: agreement to 1e-6 relative (f32 values, f64 sums).
        assert!((got - e).abs() <= 1e-6 * e, "{name}: {got} vs {e}");
    }
}

/// The log's own air from ArduPilot's `BARO` records (issue 34): the mean of `Press / (Rd (Temp +
/// 273.15))` over the records, with the pressure and temperature decoded by `ardupilot-binlog`
/// (Rd = 287.053 J/(kg K), dry air), equals the density aloft reads from the file.
#[test]
fn data_val_dataflash_air_density_from_baro_agrees_with_ardupilot_binlog() {
    let mut checked = 0;
    for (name, _, _) in FIGURES.iter().filter(|f| !f.0.ends_with(".ulg")) {
        let p = path(name);
        let file = ardupilot_binlog::File::open(&p).unwrap();
        let (mut sum, mut n) = (0.0, 0u32);
        for e in file.entries().unwrap().map_while(Result::ok) {
            if e.name != "BARO" {
                continue;
            }
            let (Some(pa), Some(t)) = (e.get_f64("Press"), e.get_f64("Temp")) else {
                continue;
            };
            let rho = pa / (287.053 * (t + 273.15));
            if (0.3..=1.6).contains(&rho) {
                sum += rho;
                n += 1;
            }
        }
        let ours = read(&p).summary.air_density_kg_m3;
        if n == 0 {
            assert_eq!(ours, None, "{name}: no BARO, yet a density");
            continue;
        }
        let theirs = sum / f64::from(n);
        let ours = ours.unwrap_or_else(|| panic!("{name}: {n} BARO records, no density"));
        // The same records, the same formula: to rounding.
        assert!(
            (ours / theirs - 1.0).abs() < 1e-9,
            "{name}: {ours} vs {theirs}"
        );
        checked += 1;
    }
    assert!(checked >= 1, "no shared DataFlash log has BARO records");
}
