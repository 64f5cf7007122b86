//! The pack analysis on the shared real logs (research note `air-packs.md` §2.5, §6 "Packs"
//! 5-7): KAIST's 11 flights of one DJI M600 (12S), the five flugdrohne PX4 flights (3S), and the
//! ArduCopter SITL log's `BAT.Res`. Expected values come from the data and closed forms: the
//! note's figures were computed with a small Python script independent of aloft.

#[path = "../../../tests/it/common/data.rs"]
mod data;
use data::data_dir;

use std::path::PathBuf;

use aloft_logs::{read_battery_log, BatteryLog, BatterySample, OpenOptions, Profile};
use aloft_packs::{analyse, resistance_from_steps};

fn kaist_files() -> Vec<PathBuf> {
    data::files("kaist_energy_drone", |n| n.ends_with(".csv"))
}

fn read(p: &std::path::Path, profile: Option<&Profile>) -> BatteryLog {
    read_battery_log(p, profile, &OpenOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The naive fit this crate does not ship: ordinary least squares of V on I over the whole
/// flight, with a constant open-circuit voltage (slope = −R). Kept here only to show it is
/// biased (§2.5: 0.09-0.37 Ω on KAIST).
fn naive_ols_ohm(s: &[BatterySample]) -> f64 {
    let pts: Vec<(f64, f64)> = s
        .iter()
        .filter_map(|x| Some((x.current_a?, x.voltage_v)))
        .collect();
    let n = pts.len() as f64;
    let (mi, mv) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mi) * (p.1 - mv)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mi) * (p.0 - mi)).sum();
    -sxy / sxx
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// KAIST's long flights (all but the 5-minute geofence test, §2.5).
fn kaist_long() -> Vec<(PathBuf, BatteryLog)> {
    kaist_files()
        .into_iter()
        .map(|p| {
            let l = read(&p, Some(&Profile::Kaist));
            (p, l)
        })
        .filter(|(_, l)| l.duration_s() > 600.0)
        .collect()
}

/// §2.5 / §6.6: each long KAIST flight's step estimate lies within 15 % of their median
/// (≈ 0.021 Ω in the note), and the naive whole-flight OLS is several times higher.
#[test]
fn data_val_kaist_step_resistance_is_stable_and_not_the_naive_fit() {
    let flights = kaist_long();
    assert_eq!(flights.len(), 10, "the note counts 10 long flights");
    let mut rs = Vec::new();
    for (p, l) in &flights {
        let e = resistance_from_steps(&l.samples).unwrap_or_else(|| panic!("{}", p.display()));
        let ols = naive_ols_ohm(&l.samples);
        eprintln!(
            "{}: step R {:.4} ohm ({} steps, IQR {:.4}-{:.4}), naive OLS {:.3} ohm",
            p.file_name().unwrap().to_string_lossy(),
            e.ohm,
            e.steps,
            e.p25_ohm,
            e.p75_ohm,
            ols
        );
        // The naive fit is biased high several-fold (the note: 7-17x); 3x is a floor that
        // holds with margin and is what "not what ships" needs.
        assert!(
            ols > 3.0 * e.ohm,
            "{}: OLS {ols} vs step {}",
            p.display(),
            e.ohm
        );
        rs.push(e.ohm);
    }
    let m = median(rs.clone());
    eprintln!("median step R over the 10 long flights: {m:.4} ohm");
    // The note's Python found a median of about 0.021 ohm with a 2 A threshold; this one's
    // threshold is max(2 A, 10 % of the largest current), so allow the band 0.015-0.027.
    assert!((0.015..0.027).contains(&m), "{m}");
    for (r, (p, _)) in rs.iter().zip(&flights) {
        assert!(
            (r / m - 1.0).abs() < 0.15,
            "{}: {r} vs median {m}",
            p.display()
        );
    }
}

/// §2.5: one 90 V glitch sample (as in `2018-08-06.11_52_45`) moves the estimate < 5 %. The
/// glitch is put on the record that ends the largest current step of the flight, so it enters
/// the steps (a glitch between steps would not be seen at all).
#[test]
fn data_val_kaist_a_glitch_sample_moves_the_estimate_less_than_5_percent() {
    for (p, l) in kaist_long() {
        let base = resistance_from_steps(&l.samples).unwrap().ohm;
        let mut g = l.samples.clone();
        let k = (1..g.len())
            .max_by(|&a, &b| {
                let d = |k: usize| (g[k].current_a.unwrap() - g[k - 1].current_a.unwrap()).abs();
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        g[k].voltage_v = 90.0;
        let glitched = resistance_from_steps(&g).unwrap().ohm;
        let shift = (glitched / base - 1.0).abs();
        eprintln!(
            "{}: glitch shift {:.2} %",
            p.file_name().unwrap().to_string_lossy(),
            100.0 * shift
        );
        assert!(shift < 0.05, "{}: {base} -> {glitched}", p.display());
    }
}

/// §2.5 / §6.7: the coulomb count against the BMS's own drop of `capacity` (0.88-0.96 in the
/// note, median ≈ 0.95).
#[test]
fn data_val_kaist_coulomb_count_against_the_bms() {
    let mut ratios = Vec::new();
    for p in kaist_files() {
        let l = read(&p, Some(&Profile::Kaist));
        let r = analyse(&l).unwrap();
        let ratio = r.coulomb_to_reported_ratio.unwrap();
        eprintln!(
            "{}: {:.0} mAh counted, BMS drop {:.0} mAh, ratio {ratio:.3}; capacity: {}",
            p.file_name().unwrap().to_string_lossy(),
            r.discharged_mah.unwrap(),
            r.reported_drop_mah.unwrap(),
            r.capacity_refused.as_deref().unwrap_or("estimated")
        );
        assert_eq!(
            r.reported_drop_source.as_deref(),
            Some("pack remaining mAh")
        );
        ratios.push(ratio);
    }
    let m = median(ratios.clone());
    eprintln!("median coulomb / BMS ratio {m:.3}");
    assert!((0.85..1.0).contains(&m), "{m}");
    for r in ratios {
        assert!((0.8..1.05).contains(&r), "{r}");
    }
}

/// §2.5 / §6.6: the flugdrohne flights (3S, PX4 1.14 power module) give 0.03-0.055 Ω per flight.
#[test]
fn data_val_flugdrohne_step_resistance() {
    let files = data::files("px4_flugdrohne/ulg", |_| true);
    assert_eq!(files.len(), 5);
    let mut clocks = 0;
    for p in files {
        let l = read(&p, None);
        assert_eq!(l.format, "ulog");
        let r = analyse(&l).unwrap();
        let ohm = r.internal_resistance_ohm.unwrap();
        eprintln!(
            "{}: step R {ohm:.4} ohm ({} steps), vehicle {:?}, cells {:?}, autopilot R {:?}",
            p.file_name().unwrap().to_string_lossy(),
            r.resistance.as_ref().unwrap().steps,
            r.vehicle_id,
            r.cells_series,
            r.autopilot_internal_resistance_ohm
        );
        assert!((0.03..=0.055).contains(&ohm), "{}: {ohm}", p.display());
        // PX4 1.14 has no resistance estimate in battery_status (§2.3).
        assert_eq!(r.autopilot_internal_resistance_ohm, None);
        assert!(r.vehicle_id.is_some(), "sys_uuid is in every ULog's info");
        // The wall clock from the GPS (`time_utc_usec`): on the day the file is named after
        // (`log_20_2023-6-7-...`: 2023-06-07), within the day either side for the time zone.
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        // A flight without a GPS time (no fix) has none; the two flights of 2023-06-07 have it.
        if let (Some(day_unix_s), Some(t)) = (day_of_name(&name), l.start_unix_s) {
            assert!(
                (t - day_unix_s).abs() < 2.0 * 86_400.0,
                "{name}: {t} vs {day_unix_s}"
            );
            clocks += 1;
        }
    }
    assert!(clocks >= 2, "{clocks} flights with a GPS clock");
}

/// Midnight UTC of the date in a flugdrohne file name `log_N_YYYY-M-D-...`, s since 1970.
fn day_of_name(name: &str) -> Option<f64> {
    let date = name.split('_').nth(2)?;
    let mut it = date.split('-').map(|x| x.parse::<i64>().ok());
    let (y, m, d) = (it.next()??, it.next()??, it.next()??);
    // Days from 1970-01-01 to y-m-d (civil calendar, Howard Hinnant's days_from_civil).
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    Some((era * 146_097 + doe - 719_468) as f64 * 86_400.0)
}

/// §6.5: the ArduCopter 4.7 SITL log's `BAT.Res` is read as the pack's resistance.
#[test]
fn data_val_sitl_bin_reads_bat_res() {
    let p = data_dir().join("flight_logs/sitl_ac47_00000002.BIN");
    let l = read(&p, None);
    assert_eq!(l.format, "dataflash");
    let res: Vec<f64> = l
        .samples
        .iter()
        .filter_map(|s| s.autopilot_resistance_ohm)
        .collect();
    eprintln!(
        "sitl: {} BAT records, {} with Res, params {:?}, start {:?}",
        l.samples.len(),
        res.len(),
        l.parameters,
        l.start_unix_s
    );
    assert_eq!(
        l.samples.len(),
        405,
        "flight_logs/README.md: BAT 405 records"
    );
    assert!(!res.is_empty());
    assert_eq!(l.rated_capacity_mah, Some(3300.0));
    let r = analyse(&l).unwrap();
    // CurrTot ran 162 mAh over the log (README); the coulomb count agrees within 2 %.
    let d = r.discharged_mah.unwrap();
    assert!((d / 162.0 - 1.0).abs() < 0.02, "{d}");
    assert!(r.autopilot_internal_resistance_ohm.is_some());
}

/// The RC pair from the flights' records (`aloft_packs::rc`): the KAIST flights' random velocity
/// commands make a current that fits most time constants alike (a Python least squares of the
/// detrended residual on `random5-2` gave R1 from 0.017 ohm at 2 s to 0.109 ohm at 60 s with the
/// residual's RMS within 1 mV); where a flight does prefer one, the flights disagree (KAIST 5,
/// 10, 20 s; PX4 10, 30, 60, 60 s), so neither pack is given a pair the records do not support.
#[test]
fn data_val_the_rc_pair_is_not_claimed_where_the_flights_do_not_agree_on_it() {
    let kaist: Vec<aloft_packs::RcEstimate> = kaist_long()
        .iter()
        .map(|(p, l)| {
            let r0 = aloft_packs::resistance_from_steps(&l.samples).unwrap().ohm;
            let e = aloft_packs::rc_from_flight(&l.samples, r0).expect("a long flight");
            eprintln!("{}: {e:?}", p.file_name().unwrap().to_string_lossy());
            e
        })
        .collect();
    let why = aloft_packs::rc_of_flights(&kaist).unwrap_err();
    assert!(why.contains("disagree"), "{why}");
    let px4: Vec<aloft_packs::RcEstimate> = data::files("px4_flugdrohne/ulg", |_| true)
        .iter()
        .filter_map(|p| {
            let l = read(p, None);
            let r0 = aloft_packs::resistance_from_steps(&l.samples).map_or(0.04, |r| r.ohm);
            aloft_packs::rc_from_flight(&l.samples, r0)
        })
        .collect();
    let why = aloft_packs::rc_of_flights(&px4).unwrap_err();
    assert!(why.contains("disagree"), "{why}");
}
