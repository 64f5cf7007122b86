//! A log's battery records read whole: [`read_battery_log`] for a file of any format aloft
//! reads, [`read_ulog_battery`] and [`read_dataflash_battery`] for bytes. The records and their
//! conventions (units, the whole pack's resistance, PX4's thresholds, cells) are in
//! [`crate::battery_records`].

use std::path::Path;

use crate::battery_records::{BatteryDetails, BatteryLog, BatterySample};
use crate::binary_samples::{BinarySamples, BinarySummary, Decoder};
use crate::error::{LogError, Result};
use crate::open::{open_log_with, LogReader, OpenOptions, Profile};

/// Read the battery records of the log at `path` (any format [`open_log_with`] opens; a CSV
/// through `profile` or recognised by its header).
///
/// # Errors
/// [`LogError`] when the file cannot be read or is not a log aloft reads; a log without a
/// single battery record with a voltage is [`LogError::NoBatteryData`].
pub fn read_battery_log(
    path: &Path,
    profile: Option<&Profile>,
    options: &OpenOptions,
) -> Result<BatteryLog> {
    let mut o = options.clone();
    o.binary.battery_details = true;
    let source = path.display().to_string();
    let mut reader = open_log_with(path, profile, &o)?;
    let log = match &reader {
        LogReader::Ulog(_) | LogReader::Dataflash(_) => {
            let format = if matches!(reader, LogReader::Ulog(_)) {
                "ulog"
            } else {
                "dataflash"
            };
            for s in reader.by_ref() {
                s?;
            }
            let summary = reader.binary_summary().cloned().unwrap_or_default();
            battery_of(&summary, &source, format)
        }
        _ => from_samples(&mut reader, &source)?,
    };
    if log.samples.is_empty() {
        return Err(LogError::NoBatteryData {
            source_name: source,
            reason: "the log has no battery record with a voltage".into(),
        });
    }
    Ok(log)
}

/// A [`BatteryLog`] from a reader of joined samples (CSV, PX4 tables, MCAP): one record per
/// sample with a voltage.
fn from_samples(reader: &mut LogReader, source: &str) -> Result<BatteryLog> {
    let format = match reader {
        LogReader::Mcap(_) => "mcap",
        _ => "csv",
    };
    let mut samples = Vec::new();
    for s in reader.by_ref() {
        let s = s?;
        let Some(v) = s.voltage_v.filter(|v| v.is_finite() && *v > 0.0) else {
            continue;
        };
        samples.push(BatterySample {
            time_s: s.time_s,
            voltage_v: v,
            current_a: s.current_a.filter(|i| i.is_finite()),
            remaining: s.soc.filter(|r| r.is_finite() && (0.0..=1.0).contains(r)),
            remaining_mah: s.charge_ah.filter(|c| c.is_finite()).map(|c| c * 1000.0),
            ..BatterySample::default()
        });
    }
    let details = BatteryDetails {
        samples,
        ..BatteryDetails::default()
    };
    let mut log = details.into_log(source, format, Vec::new());
    // A CSV's clock: KAIST's `timestamp` is not wall-clock time, so none is claimed.
    log.start_unix_s = None;
    Ok(log)
}

/// Read the battery records of a PX4 ULog from bytes (sans-I/O; the fuzz harness's entry).
///
/// # Errors
/// [`LogError::UnsupportedFormat`] when the input is not a ULog.
pub fn read_ulog_battery<R: std::io::Read>(
    reader: R,
    options: &crate::BinaryOptions,
) -> Result<BatteryLog> {
    read_binary_battery(reader, options, crate::ulog::ulog_samples, "ulog")
}

/// Read the battery records of an ArduPilot DataFlash log from bytes (sans-I/O).
///
/// # Errors
/// [`LogError::UnsupportedFormat`] when the input is not a DataFlash log.
pub fn read_dataflash_battery<R: std::io::Read>(
    reader: R,
    options: &crate::BinaryOptions,
) -> Result<BatteryLog> {
    read_binary_battery(
        reader,
        options,
        crate::dataflash::dataflash_samples,
        "dataflash",
    )
}

/// The decoder of a binary format over bytes (`ulog_samples`, `dataflash_samples`).
type OpenBinary<R, D> = fn(R, &crate::BinaryOptions, &Path) -> Result<BinarySamples<R, D>>;

/// Read a binary log's bytes through `open`, every sample, and keep its battery records.
fn read_binary_battery<R: std::io::Read, D: Decoder>(
    reader: R,
    options: &crate::BinaryOptions,
    open: OpenBinary<R, D>,
    format: &str,
) -> Result<BatteryLog> {
    let o = crate::BinaryOptions {
        battery_details: true,
        ..*options
    };
    let mut it = open(reader, &o, Path::new("<bytes>"))?;
    for s in it.by_ref() {
        s?;
    }
    Ok(battery_of(it.summary(), "<bytes>", format))
}

/// The battery records a binary log's summary gathered, once every sample has been read.
fn battery_of(summary: &BinarySummary, source: &str, format: &str) -> BatteryLog {
    let details = summary.battery_details.clone().unwrap_or_default();
    details.into_log(source, format, summary.warnings.clone())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{
        dataflash_fmt, dataflash_fmt_of_fmt, ulog_data, ulog_record, ulog_start, ulog_subscription,
    };
    use crate::BinaryOptions;

    fn param_i32(name: &str, v: i32) -> Vec<u8> {
        let key = format!("int32_t {name}");
        let mut p = vec![key.len() as u8];
        p.extend_from_slice(key.as_bytes());
        p.extend_from_slice(&v.to_le_bytes());
        ulog_record(b'P', &p)
    }

    /// A ULog of 20 `battery_status` records whose `internal_resistance_estimate` is 0.01 ohm
    /// per cell, with `BAT1_N_CELLS` = `cells` when given.
    fn px4_log(cells: Option<i32>) -> Vec<u8> {
        let mut b = ulog_start(&[
            "battery_status:uint64_t timestamp;float voltage_v;float current_a;float remaining;float internal_resistance_estimate;",
        ]);
        if let Some(n) = cells {
            b.extend(param_i32("BAT1_N_CELLS", n));
        }
        b.extend(ulog_subscription(1, "battery_status"));
        for k in 0..20u64 {
            b.extend(ulog_data(
                1,
                1_000_000 + k * 200_000,
                &[16.0, 10.0, 0.9, 0.01],
            ));
        }
        b
    }

    /// PX4's `internal_resistance_estimate` is per cell: reported as the pack's only times the
    /// cells (4 x 0.01 = 0.04 ohm), and not at all when the cell count is unknown.
    #[test]
    fn a_px4_per_cell_resistance_is_never_a_pack_value() {
        let with = read_ulog_battery(&px4_log(Some(4))[..], &BinaryOptions::default()).unwrap();
        assert_eq!(with.samples.len(), 20);
        assert_eq!(with.cells_series, Some(4));
        for s in &with.samples {
            // f32 0.01 times 4: within 1e-6 of 0.04.
            let r = s.autopilot_resistance_ohm.unwrap();
            assert!((r - 0.04).abs() < 1e-6, "{r}");
        }
        let without = read_ulog_battery(&px4_log(None)[..], &BinaryOptions::default()).unwrap();
        assert_eq!(without.cells_series, None);
        assert!(without
            .samples
            .iter()
            .all(|s| s.autopilot_resistance_ohm.is_none()));
    }

    /// A smart pack's serial in both layouts (`uint16`, `char[32]`), 0 as none; `sys_uuid`.
    #[test]
    fn px4_serial_numbers_and_sys_uuid() {
        for (field, bytes, want) in [
            (
                "uint16_t serial_number;",
                4242u16.to_le_bytes().to_vec(),
                Some("4242"),
            ),
            ("uint16_t serial_number;", vec![0, 0], None),
            (
                "char[32] serial_number;",
                {
                    let mut v = b"PK-0042".to_vec();
                    v.resize(32, 0);
                    v
                },
                Some("PK-0042"),
            ),
        ] {
            let mut b = ulog_start(&[format!(
                "battery_status:uint64_t timestamp;float voltage_v;float current_a;{field}"
            )]);
            let key = b"char[8] sys_uuid";
            let mut info = vec![key.len() as u8];
            info.extend_from_slice(key);
            info.extend_from_slice(b"00ab12cd");
            b.extend(ulog_record(b'I', &info));
            b.extend(ulog_subscription(1, "battery_status"));
            for k in 0..3u64 {
                let mut d = 1u16.to_le_bytes().to_vec();
                d.extend((1_000_000 + k * 200_000).to_le_bytes());
                d.extend(16.0f32.to_le_bytes());
                d.extend(10.0f32.to_le_bytes());
                d.extend(&bytes);
                b.extend(ulog_record(b'D', &d));
            }
            let l = read_ulog_battery(&b[..], &BinaryOptions::default()).unwrap();
            assert_eq!(l.pack_id.as_deref(), want, "{field}");
            assert_eq!(l.vehicle_id.as_deref(), Some("00ab12cd"));
            assert_eq!(l.samples.len(), 3);
        }
    }

    proptest::proptest! {
        /// Hostile bytes after a valid start (a ULog with a battery, a DataFlash with BAT and
        /// BCL) never panic and never give a non-finite record.
        #[test]
        fn hostile_bytes_never_panic(tail in proptest::collection::vec(proptest::num::u8::ANY, 0..600), cut in 0usize..400) {
            let mut u = px4_log(Some(4));
            u.truncate(u.len().saturating_sub(cut));
            u.extend(&tail);
            if let Ok(l) = read_ulog_battery(&u[..], &BinaryOptions::default()) {
                for s in &l.samples {
                    proptest::prop_assert!(s.voltage_v.is_finite() && s.time_s.is_finite());
                    proptest::prop_assert!(s.autopilot_resistance_ohm.is_none_or(f64::is_finite));
                    proptest::prop_assert!(s.cell_v.iter().all(|c| c.is_finite()));
                }
            }
            let mut d = dataflash_fmt_of_fmt();
            d.extend(&tail);
            let _ = read_dataflash_battery(&d[..], &BinaryOptions::default());
        }
    }

    fn parm(name: &str, v: f32) -> Vec<u8> {
        let mut r = vec![0xA3, 0x95, 3];
        r.extend(5_000_000u64.to_le_bytes());
        let mut n = name.as_bytes().to_vec();
        n.resize(16, 0);
        r.extend(n);
        r.extend(v.to_le_bytes());
        r
    }

    /// ArduPilot: `BAT.Res` is the pack's as is; `BCL` cells in mV (65535 dropped);
    /// `BATT_SERIAL_NUM` -1 is no serial; `BATT_LOW_VOLT` is the low-voltage failsafe in volts.
    #[test]
    fn ardupilot_res_cells_and_parameters() {
        let mut b = dataflash_fmt_of_fmt();
        b.extend(dataflash_fmt(
            2,
            3 + 8 + 1 + 4 * 4,
            "BAT",
            "QBffff",
            "TimeUS,Inst,Volt,Curr,CurrTot,Res",
        ));
        b.extend(dataflash_fmt(
            3,
            3 + 8 + 16 + 4,
            "PARM",
            "QNf",
            "TimeUS,Name,Value",
        ));
        b.extend(dataflash_fmt(
            4,
            3 + 8 + 1 + 4 + 12 * 2,
            "BCL",
            "QBfHHHHHHHHHHHH",
            "TimeUS,Instance,Volt,V1,V2,V3,V4,V5,V6,V7,V8,V9,V10,V11,V12",
        ));
        b.extend(parm("BATT_SERIAL_NUM", -1.0));
        b.extend(parm("BATT_LOW_VOLT", 14.2));
        b.extend(parm("BATT_CAPACITY", 5000.0));
        for k in 0..5u64 {
            let t = 1_000_000 + k * 100_000;
            b.extend([0xA3, 0x95, 2]);
            b.extend(t.to_le_bytes());
            b.push(0);
            for f in [16.0f32, 10.0, k as f32, 0.05] {
                b.extend(f.to_le_bytes());
            }
            b.extend([0xA3, 0x95, 4]);
            b.extend(t.to_le_bytes());
            b.push(0);
            b.extend(16.0f32.to_le_bytes());
            for c in [4001u16, 3999, 4000, 3990, 65535, 0, 0, 0, 0, 0, 0, 0] {
                b.extend(c.to_le_bytes());
            }
        }
        let l = read_dataflash_battery(&b[..], &BinaryOptions::default()).unwrap();
        assert_eq!(l.samples.len(), 5);
        assert_eq!(l.pack_id, None);
        assert_eq!(l.low_voltage_failsafe_v, Some(14.2f32 as f64));
        assert_eq!(l.rated_capacity_mah, Some(5000.0));
        assert_eq!(l.cells_series, Some(4));
        let s = &l.samples[2];
        assert_eq!(s.autopilot_resistance_ohm, Some(0.05f32 as f64));
        assert_eq!(s.consumed_mah, Some(2.0));
        assert_eq!(s.cell_v, vec![4.001, 3.999, 4.0, 3.99]);
    }
}
