//! The shared KAIST energy-drone days (`kaist_energy_drone`): the flights of a day, the vehicle
//! fitted on the other days (leave one day out), and the pack fitted on logs (the resistance from
//! current steps, the capacity whose predicted voltage under load fits best).

use std::path::PathBuf;

use aloft_logs::BatteryLog;
use aloft_planner::{BatterySpec, Pack};

/// The shared KAIST days: 2018-08-03 (5 flights), 2018-08-06 (5) and 2018-08-08 (1, 300 s).
pub const DAYS: [&str; 3] = ["2018-08-03", "2018-08-06", "2018-08-08"];

/// `judge` of each of `days`, the days in parallel, the results in the days' order.
pub fn per_day<T: Send>(
    days: &[&'static str],
    judge: impl Fn(&'static str) -> Vec<T> + Sync,
) -> Vec<T> {
    let judge = &judge;
    std::thread::scope(|s| {
        let handles: Vec<_> = days.iter().map(|&d| s.spawn(move || judge(d))).collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    })
}

/// The flights of one day, as command-line words.
pub fn kaist(day: &str) -> Vec<String> {
    super::strings(&super::files_like("kaist_energy_drone", day, ".csv"))
}

/// The long flights (all but the 300 s `testgpsfense`), sorted.
pub fn long_flights() -> Vec<PathBuf> {
    super::files("kaist_energy_drone", |n| {
        n.ends_with(".csv") && !n.contains("testgpsfense")
    })
}

/// The words as owned strings.
pub fn words(w: &[&str]) -> Vec<String> {
    w.iter().map(|s| s.to_string()).collect()
}

/// `aloft fit` on every day but `held_out` from the KAIST template, written to `vehicle`: the
/// fit's JSON answer.
pub fn fit_without_day(held_out: &str, vehicle: &str) -> serde_json::Value {
    let template = format!(
        "{}/fixtures/vehicles/kaist-template.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut fit = words(&["fit", "--profile", "kaist", "--log"]);
    for d in DAYS.iter().filter(|d| **d != held_out) {
        fit.extend(kaist(d));
    }
    fit.extend(words(&["--vehicle-template", &template, "-o", vehicle]));
    fit.extend(words(&["--format", "json"]));
    super::ok_json(&fit)
}

/// A record: time s, voltage V, current A.
pub type Record = (f64, f64, f64);

/// The (time s, voltage V, current A) of a log's records with a current, each record once (the
/// KAIST rows repeat the pack's 1 Hz values at 10 Hz).
pub fn records(log: &BatteryLog) -> Vec<Record> {
    let mut out: Vec<Record> = Vec::new();
    for s in &log.samples {
        let Some(i) = s.current_a else { continue };
        if out.last().is_some_and(|&(_, v, c)| {
            v.to_bits() == s.voltage_v.to_bits() && c.to_bits() == i.to_bits()
        }) {
            continue;
        }
        out.push((s.time_s, s.voltage_v, i));
    }
    // A logged glitch is not the pack: a record more than 5 V from both neighbours, which agree
    // within 1 V, is left out (one in the shared files: 90 V in `2018-08-06.11_52_45`, research
    // note section 2.5). The pack cannot jump 5 V and back in two seconds.
    let glitch = |k: usize| {
        k > 0
            && k + 1 < out.len()
            && (out[k].1 - out[k - 1].1).abs() > 5.0
            && (out[k].1 - out[k + 1].1).abs() > 5.0
            && (out[k - 1].1 - out[k + 1].1).abs() < 1.0
    };
    let keep: Vec<bool> = (0..out.len()).map(|k| !glitch(k)).collect();
    out.into_iter()
        .zip(keep)
        .filter_map(|(r, k)| k.then_some(r))
        .collect()
}

/// A 12S pack of `capacity_mah` and `r_ohm` on the generic LiPo open-circuit curve.
pub fn pack(capacity_mah: f64, r_ohm: f64) -> Pack {
    Pack::new(&spec(capacity_mah, r_ohm)).unwrap()
}

/// [`pack`] on the open-circuit curve `(ocv_soc, ocv_cell_v)` instead of the generic one.
pub fn pack_on_curve(capacity_mah: f64, r_ohm: f64, ocv_soc: &[f64], ocv_cell_v: &[f64]) -> Pack {
    Pack::new(&BatterySpec {
        ocv_soc: Some(ocv_soc.to_vec()),
        ocv_cell_v: Some(ocv_cell_v.to_vec()),
        ..spec(capacity_mah, r_ohm)
    })
    .unwrap()
}

/// The spec of [`pack`]: 12S at 3.7 V a cell nominal, 1 kg, cut off at 3.0 V a cell.
fn spec(capacity_mah: f64, r_ohm: f64) -> BatterySpec {
    let nominal = 12.0 * 3.7;
    BatterySpec {
        name: "kaist".into(),
        cells_series: 12,
        capacity_mah,
        nominal_v: Some(nominal),
        energy_wh: Some(capacity_mah / 1000.0 * nominal),
        mass_kg: Some(1.0),
        internal_resistance_ohm: Some(r_ohm),
        cutoff_cell_v: Some(3.0),
        ..BatterySpec::default()
    }
}

/// The RMS (V) of the terminal voltage the pack predicts for the logged power, against the
/// logged voltage: the state of charge starts where the first record's voltage plus `I R` sits on
/// the open-circuit curve and is counted down by the current the pack gives for the logged power.
pub fn rms_v(pack: &Pack, recs: &[Record]) -> f64 {
    let (_, v0, i0) = recs[0];
    let mut soc = pack.soc_at_ocv_v(v0 + i0 * pack.resistance_ohm());
    let mut sum = 0.0;
    for w in recs.windows(2) {
        let (t0, v, i) = w[0];
        let t1 = w[1].0;
        let Some(draw) = pack.draw(v * i, soc) else {
            return f64::INFINITY;
        };
        sum += (draw.terminal_v - v).powi(2);
        soc -= draw.current_a * (t1 - t0) / (3600.0 * pack.capacity_ah());
    }
    (sum / (recs.len() - 1) as f64).sqrt()
}

/// The capacity (mA h, 250 mA h steps) whose predicted voltage fits `recs` best with `r_ohm`.
pub fn best_capacity(recs: &[Record], r_ohm: f64) -> f64 {
    (20..=200)
        .map(|k| f64::from(k) * 250.0)
        .min_by(|a, b| rms_v(&pack(*a, r_ohm), recs).total_cmp(&rms_v(&pack(*b, r_ohm), recs)))
        .unwrap()
}

/// The most the pack's gauge (KAIST's BMS `capacity`, mA h) reads in `path`.
pub fn most_gauge_mah(path: &std::path::Path) -> f64 {
    let profile = aloft_logs::Profile::resolve("kaist").unwrap();
    let log = aloft_logs::read_battery_log(path, Some(&profile), &Default::default()).unwrap();
    log.samples
        .iter()
        .filter_map(|s| s.remaining_mah)
        .fold(0.0, f64::max)
}

/// `aloft pack fit LOGS --profile kaist --cells 12 --capacity-mah C --mass-kg M -o OUT` as
/// words.
pub fn pack_fit_words(logs: &[String], capacity_mah: f64, mass_kg: f64, out: &str) -> Vec<String> {
    let mut args = words(&["pack", "fit"]);
    args.extend_from_slice(logs);
    let (capacity, mass) = (format!("{capacity_mah}"), format!("{mass_kg}"));
    args.extend(words(&[
        "--profile",
        "kaist",
        "--cells",
        "12",
        "--capacity-mah",
        &capacity,
        "--mass-kg",
        &mass,
        "-o",
        out,
    ]));
    args
}

/// `aloft pack fit` on `logs` (12S, `capacity_mah`, `mass_kg`), written to `out` (`--force`):
/// its JSON answer, the pack's own open-circuit curve in `pack.battery.ocv_soc` / `ocv_cell_v`.
pub fn pack_fit(logs: &[PathBuf], capacity_mah: f64, mass_kg: f64, out: &str) -> serde_json::Value {
    let mut args = pack_fit_words(&super::strings(logs), capacity_mah, mass_kg, out);
    args.extend(words(&["--force", "--format", "json"]));
    super::ok_json(&args)
}

/// `aloft live --replay FLIGHT --profile kaist --route log --vehicle VEHICLE --every 10 EXTRA
/// --format json`: its last line's `check` (an update every 10 s: the checkpoints at 40, 60 and
/// 80 % fall on the first update after them).
pub fn live_check(path: &str, vehicle: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = words(&[
        "live",
        "--replay",
        path,
        "--profile",
        "kaist",
        "--route",
        "log",
        "--vehicle",
        vehicle,
        "--every",
        "10",
    ]);
    args.extend(words(extra));
    args.extend(words(&["--format", "json"]));
    let out = super::ok_stdout(&args);
    let last = out.lines().last().unwrap();
    serde_json::from_str::<serde_json::Value>(last).unwrap()["check"].clone()
}

/// A long flight's pack evidence: its records and the resistance of its current steps (ohm,
/// `aloft_packs::analyse`, as `aloft pack fit` takes it).
pub fn pack_evidence(path: &std::path::Path) -> (Vec<Record>, f64) {
    let profile = aloft_logs::Profile::resolve("kaist").unwrap();
    let log = aloft_logs::read_battery_log(path, Some(&profile), &Default::default()).unwrap();
    let r = aloft_packs::analyse(&log)
        .unwrap()
        .internal_resistance_ohm
        .unwrap();
    (records(&log), r)
}
