//! PX4's battery estimate, emulated, against what PX4 v1.14 logged on the five shared
//! flugdrohne flights (`px4_flugdrohne/csv/<log>_battery_status_0.csv`, `<log>_params.csv`).
//! The expected values are the log's own `remaining`; the parameters are the log's.

#[path = "../../../tests/it/common/data.rs"]
mod data;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use aloft_packs::{Px4Battery, Px4BatteryParams, Px4Resume, Px4Warning};

/// One `battery_status` record.
struct Record {
    time_s: f64,
    voltage_v: f64,
    voltage_filtered_v: f64,
    current_a: f64,
    current_filtered_a: f64,
    discharged_mah: f64,
    remaining: f64,
    warning: u8,
}

fn battery_files() -> Vec<PathBuf> {
    data::files("px4_flugdrohne/csv", |n| {
        n.ends_with("_battery_status_0.csv")
    })
}

fn read_records(path: &Path) -> Vec<Record> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("{}: no column {name}", path.display()))
    };
    let cols = [
        "timestamp",
        "voltage_v",
        "voltage_filtered_v",
        "current_a",
        "current_filtered_a",
        "discharged_mah",
        "remaining",
        "warning",
    ]
    .map(col);
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let num =
                |i: usize| -> f64 { f[cols[i]].parse().unwrap_or_else(|e| panic!("{line}: {e}")) };
            Record {
                time_s: num(0) * 1e-6,
                voltage_v: num(1),
                voltage_filtered_v: num(2),
                current_a: num(3),
                current_filtered_a: num(4),
                discharged_mah: num(5),
                remaining: num(6),
                warning: num(7) as u8,
            }
        })
        .collect()
}

fn read_params(battery_csv: &Path) -> BTreeMap<String, f64> {
    let name = battery_csv.file_name().unwrap().to_string_lossy();
    let path = battery_csv.with_file_name(name.replace("_battery_status_0.csv", "_params.csv"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .filter_map(|l| l.split_once(','))
        .filter_map(|(k, v)| Some((k.to_string(), v.parse().ok()?)))
        .collect()
}

/// RMS and worst absolute difference.
fn rms_worst(errors: &[f64]) -> (f64, f64) {
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    (rms, errors.iter().fold(0.0_f64, |w, e| w.max(e.abs())))
}

/// The emulation fed each record's voltage and current (5 Hz: PX4 itself sampled at 100 Hz),
/// resumed from the first record's filters and estimate.
fn replay(params: &Px4BatteryParams, records: &[Record]) -> Vec<f64> {
    let first = &records[0];
    let mut b = Px4Battery::resumed(
        params,
        &Px4Resume {
            voltage_filtered_v: first.voltage_filtered_v,
            current_filtered_a: first.current_filtered_a,
            remaining: first.remaining,
            discharged_mah: first.discharged_mah,
        },
    );
    let mut errors = vec![0.0];
    for w in records.windows(2) {
        let (prev, r) = (&w[0], &w[1]);
        let e = b.update(r.time_s - prev.time_s, r.voltage_v, Some(r.current_a));
        errors.push(e.remaining - r.remaining);
    }
    errors
}

/// With the capacity unset, PX4 v1.14's `remaining` is the load-corrected cell voltage read
/// linearly: fed PX4's own filtered voltage and current (one step of 0 s holds them), the
/// emulation gives the logged value to float precision on every record of the 3S flights.
/// Fed the 5 Hz raw samples, it follows within 2 % RMS (5.5 % worst): the filters saw 20
/// samples for each one logged. The two flights with `BAT1_N_CELLS` 0 log 1.0 throughout,
/// and so does the emulation (v1.14 divides by zero cells).
#[test]
fn data_val_px4_remaining_is_reproduced_from_the_logged_voltage_and_current() {
    let files = battery_files();
    assert_eq!(files.len(), 5, "five flugdrohne flights");
    let mut configured = 0;
    for path in &files {
        let name = path
            .file_name()
            .unwrap()
            .to_string_lossy()
            .replace("_battery_status_0.csv", "");
        let params = Px4BatteryParams::from_parameters(&read_params(path))
            .expect("valid parameters")
            .expect("a PX4 vehicle");
        assert_eq!(
            params.capacity_mah, None,
            "{name}: BAT1_CAPACITY is -1 on these flights"
        );
        let records = read_records(path);
        let errors = replay(&params, &records);
        let (rms, worst) = rms_worst(&errors);
        let exact = records
            .iter()
            .map(|r| {
                let state = Px4Resume {
                    voltage_filtered_v: r.voltage_filtered_v,
                    current_filtered_a: r.current_filtered_a,
                    remaining: r.remaining,
                    discharged_mah: r.discharged_mah,
                };
                let mut b = Px4Battery::resumed(&params, &state);
                b.update(0.0, r.voltage_filtered_v, Some(r.current_filtered_a))
                    .remaining
                    - r.remaining
            })
            .collect::<Vec<_>>();
        let (_, exact_worst) = rms_worst(&exact);
        eprintln!(
            "{name}: {} cells, {} records: remaining from the 5 Hz samples RMS {:.4}, worst {:.4}; \
             from PX4's filtered values worst {:.2e}",
            params.n_cells,
            records.len(),
            rms,
            worst,
            exact_worst
        );
        assert!(
            records.iter().all(|r| r.warning == 0),
            "{name}: no warning logged"
        );
        if params.n_cells == 0 {
            assert!(
                records.iter().all(|r| r.remaining == 1.0),
                "{name}: PX4 logs 1.0"
            );
            assert!(
                errors.iter().all(|e| *e == 0.0),
                "{name}: the emulation gives 1.0"
            );
            continue;
        }
        configured += 1;
        // PX4 logs f32: 1e-6 of a fraction is its precision at 0.5-0.9.
        assert!(
            exact_worst < 1e-6,
            "{name}: the formula, worst {exact_worst:.2e}"
        );
        // 2 % RMS, 5.5 % worst: the 5 Hz samples miss the 100 Hz ones PX4 filtered (the
        // filtered voltage differs from PX4's by 0.04-0.05 V RMS, 1.4-1.7 % of the 1 V range).
        assert!(
            rms < 0.02 && worst < 0.055,
            "{name}: RMS {rms:.4}, worst {worst:.4}"
        );
    }
    assert_eq!(configured, 3, "three flights with BAT1_N_CELLS 3");
}

/// The same replay stepping PX4's warnings: the logged `remaining` never goes below 0.44,
/// so no warning, and the emulation raises none either.
#[test]
fn data_val_px4_no_warning_on_the_shared_flights() {
    for path in battery_files() {
        let params = Px4BatteryParams::from_parameters(&read_params(&path))
            .unwrap()
            .unwrap();
        let records = read_records(&path);
        let mut b = Px4Battery::new(&params);
        let mut prev_s = records[0].time_s;
        for r in &records {
            let e = b.update(r.time_s - prev_s, r.voltage_v, Some(r.current_a));
            prev_s = r.time_s;
            assert_eq!(e.failsafe_warning, Px4Warning::None, "{}", path.display());
        }
    }
}
