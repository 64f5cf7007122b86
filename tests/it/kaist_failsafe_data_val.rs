//! The time until the voltage failsafe, predicted in flight on held-out KAIST days (issue 44,
//! "How it is checked", second bullet), through the CLI: `aloft live --route log
//! --low-voltage-v V`.
//!
//! For each day that has long flights (2018-08-03 and 2018-08-06: five each; 2018-08-08's one
//! flight lasts 300 s), the vehicle is fitted on the other days (`aloft fit`, as the
//! leave-one-day-out check of the energy does) and so is the pack: `aloft pack fit` on the other
//! days' long flights, its resistance the median of their current-step estimates, its own
//! open-circuit curve from their gauge (issue 44), on a capacity their gauge holds (the most it
//! read, rounded up to 100 mA h). Each flight of the
//! held-out day is then replayed with a threshold it reached: the voltage under load averaged
//! over 5 s (time-weighted, computed here from the CSV) as it stood at 85 % of the flight,
//! rounded to 10 mV. The test finds when that average first fell below it, checks that aloft's
//! check finds the same record (within one sample), and reads aloft's predictions made at the
//! updates 300 s and 120 s before the crossing, beside the naive rate (the average's linear trend
//! over the last 60 s extrapolated to the threshold).
//!
//! The fits run once (a `OnceLock`, the two days in parallel) and the tests read the result.
//! Data from `ALOFT_DATA_DIR` (default `../shared/data`).

use crate::common;
use common::kaist::{
    fit_without_day, kaist, live_check, most_gauge_mah, pack_evidence, pack_fit, per_day, DAYS,
};
use common::median;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Share of the flight at which the threshold is read from the 5 s average.
const THRESHOLD_AT: f64 = 0.85;

/// The prediction at one checkpoint: (before, actual s, p5, p50, p95, naive), times s from the
/// update (a percentile or the naive time absent where it does not trigger).
#[derive(Debug, Clone)]
struct Checkpoint {
    before: String,
    actual_s: f64,
    p5: Option<f64>,
    p50: Option<f64>,
    p95: Option<f64>,
    naive_s: Option<f64>,
}

/// One held-out flight.
#[derive(Debug, Clone)]
struct Judged {
    file: String,
    threshold_v: f64,
    /// The crossing computed here, s from the first row.
    crossed_s: f64,
    /// aloft's crossing, s of the log.
    aloft_crossed_s: Option<f64>,
    /// The row interval at the crossing, s.
    row_interval_s: f64,
    checkpoints: Vec<Checkpoint>,
}

/// The CSV's (time s from the first row, voltage V), read here (not through aloft).
fn csv_voltage(path: &Path) -> Vec<(f64, f64)> {
    let rows = common::csv_columns(path, ["timestamp", "vol"]);
    let t0 = rows[0][0] * 1e-6;
    rows.into_iter()
        .map(|[t_us, v]| (t_us * 1e-6 - t0, v))
        .collect()
}

/// The voltage averaged over the 5 s before each row, time-weighted, each row's value held until
/// the next row (over the first 5 s, over what there is; the first row its own value).
fn average_5s(rows: &[(f64, f64)]) -> Vec<f64> {
    (0..rows.len())
        .map(|i| {
            let t = rows[i].0;
            let (mut sum, mut weight) = (0.0, 0.0);
            for j in (0..i).rev() {
                let start = rows[j].0.max(t - 5.0);
                let end = rows[j + 1].0;
                if end <= t - 5.0 {
                    break;
                }
                sum += rows[j].1 * (end - start);
                weight += end - start;
            }
            if weight > 0.0 {
                sum / weight
            } else {
                rows[i].1
            }
        })
        .collect()
}

/// The first row whose 5 s average is below `threshold_v`.
fn first_below(averages: &[f64], threshold_v: f64) -> usize {
    averages.iter().position(|a| *a < threshold_v).unwrap()
}

/// The vehicle fitted without `held_out` with a pack fitted on the other days' long flights:
/// the resistance of their current steps, and their own open-circuit curve (`aloft pack fit` on
/// them) on a capacity their gauge holds (the most it read, rounded up to 100 mA h; no rated
/// capacity is logged).
fn vehicle_without(held_out: &str) -> String {
    let path = common::scratch("failsafe", &format!("{held_out}.toml"));
    let path = path.display().to_string();
    fit_without_day(held_out, &path);
    let other_days: Vec<PathBuf> = common::kaist::long_flights()
        .into_iter()
        .filter(|p| !p.to_string_lossy().contains(held_out))
        .collect();
    let others: Vec<_> = other_days.iter().map(|p| pack_evidence(p)).collect();
    let r_ohm = median(others.iter().map(|o| o.1).collect());
    let gauge_mah = other_days
        .iter()
        .map(|p| most_gauge_mah(p))
        .fold(0.0, f64::max);
    let q_mah = (gauge_mah / 100.0).ceil() * 100.0;
    let pack_file = format!("{path}.pack.toml");
    let fit = pack_fit(&other_days, q_mah, 1.0, &pack_file);
    std::fs::remove_file(&pack_file).ok();
    let battery = &fit["pack"]["battery"];
    let list = |k: &str| {
        let v: Vec<String> = battery[k]
            .as_array()
            .unwrap_or_else(|| panic!("no {k}: {}", fit["ocv_refused"]))
            .iter()
            .map(|x| x.as_f64().unwrap().to_string())
            .collect();
        v.join(", ")
    };
    let (ocv_soc, ocv_cell_v) = (list("ocv_soc"), list("ocv_cell_v"));
    println!(
        "held out {held_out}: pack {q_mah:.0} mAh, {r_ohm:.4} ohm, its curve measured over {:.3}-{:.3}",
        fit["ocv"]["measured_from_soc"], fit["ocv"]["measured_to_soc"]
    );
    // The resistance pack fit writes is the one the steps give here.
    let fitted_r = battery["internal_resistance_ohm"].as_f64().unwrap();
    assert!((fitted_r / r_ohm - 1.0).abs() < 1e-9, "{fitted_r} {r_ohm}");
    // The RC pair pack fit writes beside its curve (none identified on these logs: one of no
    // resistance, the curve fitted under load holding the mean polarisation).
    let rc = ["rc_resistance_ohm", "rc_time_constant_s"]
        .iter()
        .filter_map(|k| battery[*k].as_f64().map(|v| format!("{k} = {v:?}\n")))
        .collect::<String>();
    let pack = format!(
        "\n[[battery]]\nname = \"kaist-12s\"\ndefault = true\ncells_series = 12\n\
         capacity_mah = {q_mah}\nnominal_v = 44.4\nenergy_wh = {}\nmass_kg = 1.0\n\
         internal_resistance_ohm = {r_ohm}\ncutoff_cell_v = 3.0\n\
         ocv_soc = [{ocv_soc}]\nocv_cell_v = [{ocv_cell_v}]\n{rc}",
        q_mah / 1000.0 * 44.4
    );
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.push_str(&pack);
    std::fs::write(&path, text).unwrap();
    path
}

/// One flight judged with `vehicle`.
fn judge_flight(path: &str, vehicle: &str) -> Judged {
    let rows = csv_voltage(Path::new(path));
    let averages = average_5s(&rows);
    let span_s = rows[rows.len() - 1].0;
    let at = rows.partition_point(|r| r.0 < THRESHOLD_AT * span_s);
    let threshold_v = (averages[at] * 100.0).round() / 100.0;
    let k = first_below(&averages, threshold_v);
    let threshold = format!("{threshold_v:.2}");
    let check = live_check(path, vehicle, &["--low-voltage-v", &threshold]);
    let f = &check["failsafes"][0];
    let time = |c: &serde_json::Value, p: &str| c["predicted_s"][p].as_f64();
    let checkpoints = f["checkpoints"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|c| Checkpoint {
                    before: c["before"].as_str().unwrap().to_string(),
                    actual_s: c["actual_s"].as_f64().unwrap(),
                    p5: time(c, "p5"),
                    p50: time(c, "p50"),
                    p95: time(c, "p95"),
                    naive_s: c["naive_s"].as_f64(),
                })
                .collect()
        })
        .unwrap_or_default();
    Judged {
        file: Path::new(path)
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned(),
        threshold_v,
        crossed_s: rows[k].0,
        aloft_crossed_s: f["crossed_s"].as_f64(),
        row_interval_s: rows[k].0 - rows[k - 1].0,
        checkpoints,
    }
}

fn or_dash(x: Option<f64>) -> String {
    x.map_or_else(|| "-".to_string(), |v| format!("{v:.0}"))
}

/// The held-out flights, judged once (the two days with long flights in parallel).
fn judged() -> &'static [Judged] {
    static JUDGED: OnceLock<Vec<Judged>> = OnceLock::new();
    JUDGED.get_or_init(|| {
        let out: Vec<Judged> = per_day(&[DAYS[0], DAYS[1]], |d| {
            let vehicle = vehicle_without(d);
            let flights: Vec<String> = kaist(d)
                .into_iter()
                .filter(|f| !f.contains("testgpsfense"))
                .collect();
            let j: Vec<Judged> = flights.iter().map(|f| judge_flight(f, &vehicle)).collect();
            std::fs::remove_file(&vehicle).ok();
            j
        });
        println!("| flight | threshold, V | crossed, s | before | actual, s | predicted p50 (p5-p95), s | error, s | naive, s | naive error, s |");
        for j in &out {
            for c in &j.checkpoints {
                println!(
                    "| {} | {:.2} | {:.1} | {} | {:.0} | {} ({}-{}) | {} | {} | {} |",
                    j.file,
                    j.threshold_v,
                    j.crossed_s,
                    c.before,
                    c.actual_s,
                    or_dash(c.p50),
                    or_dash(c.p5),
                    or_dash(c.p95),
                    or_dash(c.p50.map(|p| p - c.actual_s)),
                    or_dash(c.naive_s),
                    or_dash(c.naive_s.map(|n| n - c.actual_s)),
                );
            }
        }
        for before in ["300 s", "120 s"] {
            let s = summary(&out, before);
            println!(
                "{before} before: median |error| predicted {:.0} s (signed {:+.0} s, {} of {} early), naive {:.0} s (signed {:+.0} s); p5-p95 held it on {} of {}",
                s.predicted_abs_s, s.predicted_signed_s, s.early, s.n, s.naive_abs_s, s.naive_signed_s, s.in_band, s.n
            );
        }
        out
    })
}

/// The medians over the flights at one checkpoint.
#[derive(Debug)]
struct Summary {
    n: usize,
    /// Median |p50 - actual|, s.
    predicted_abs_s: f64,
    /// Median p50 - actual, s.
    predicted_signed_s: f64,
    /// Flights whose p50 is earlier than the crossing.
    early: usize,
    /// Median |naive - actual|, s (a naive time absent: its trend did not fall, counted as
    /// infinitely wrong).
    naive_abs_s: f64,
    naive_signed_s: f64,
    /// Flights whose p5-p95 holds the crossing.
    in_band: usize,
}

fn summary(judged: &[Judged], before: &str) -> Summary {
    let at: Vec<&Checkpoint> = judged
        .iter()
        .flat_map(|j| j.checkpoints.iter().filter(|c| c.before == before))
        .collect();
    let err = |x: Option<f64>, c: &Checkpoint| x.map_or(f64::INFINITY, |p| p - c.actual_s);
    let predicted: Vec<f64> = at.iter().map(|c| err(c.p50, c)).collect();
    let naive: Vec<f64> = at.iter().map(|c| err(c.naive_s, c)).collect();
    let abs = |v: &[f64]| median(v.iter().map(|x| x.abs()).collect());
    Summary {
        n: at.len(),
        predicted_abs_s: abs(&predicted),
        predicted_signed_s: median(predicted.clone()),
        early: predicted.iter().filter(|e| **e < 0.0).count(),
        naive_abs_s: abs(&naive),
        naive_signed_s: median(naive.clone()),
        in_band: at
            .iter()
            .filter(|c| {
                c.p5.is_some_and(|lo| lo <= c.actual_s) && c.p95.is_none_or(|hi| c.actual_s <= hi)
            })
            .count(),
    }
}

/// aloft's check finds the crossing this test computes from the CSV, within one sample (the two
/// hold a record's value over the interval before or after it), at least 300 s into the flight,
/// on each of the ten long flights; and it judges the prediction 300 s and 120 s before it.
#[test]
fn data_val_kaist_failsafe_crossing_matches_the_csv() {
    let j = judged();
    assert_eq!(j.len(), 10);
    for f in j {
        let aloft = f.aloft_crossed_s.unwrap_or(f64::NAN);
        // One sample: the row interval there, and 1 ms for the microsecond stamps' rounding.
        assert!(
            (aloft - f.crossed_s).abs() <= f.row_interval_s + 1e-3,
            "{}: aloft {aloft} s, the CSV {} s",
            f.file,
            f.crossed_s
        );
        assert!(f.crossed_s >= 300.0, "{f:?}");
        let before: Vec<&str> = f.checkpoints.iter().map(|c| c.before.as_str()).collect();
        assert_eq!(before, ["300 s", "120 s"], "{f:?}");
        for c in &f.checkpoints {
            let target = if c.before == "300 s" { 300.0 } else { 120.0 };
            // The last update (every 10 s) at least that long before.
            assert!(
                (target..target + 10.0 + 1e-6).contains(&c.actual_s),
                "{c:?}"
            );
        }
    }
}

/// On the pack's own open-circuit curve with the RC pair `aloft pack fit` writes beside it (one of
/// no resistance: the curve, fitted under load, holds the mean polarisation), aloft's p50 is
/// within 15 s of the crossing 120 s before it and within 30 s 300 s before it, by the median over
/// the ten held-out flights (measured: 6 s and 14 s; with the filter's default pair on the same
/// curve, counting that sag twice, 54 s and 76 s, early on every flight; on the generic LiPo curve
/// 62 s and 97 s); its p5-p95 band holds the crossing on at least 7 of the 10 (measured: 9 and 8;
/// before, 0); and its p5, the time a ground station is sent, is later than the crossing by at
/// most 30 s (measured: once, by 23 s, 300 s before). The naive rate (median 35 s and 80 s,
/// late on half the flights by up to 145 s) is worse by the median at both: reported, and asserted
/// only as aloft's own bound.
#[test]
fn data_val_kaist_failsafe_predicted_on_the_packs_own_circuit() {
    let j = judged();
    for (at, bound_s) in [("120 s", 15.0), ("300 s", 30.0)] {
        let s = summary(j, at);
        assert_eq!(s.n, 10);
        assert!(s.predicted_abs_s < bound_s, "{at}: {s:?}");
        assert!(s.in_band >= 7, "{at}: {s:?}");
    }
    for f in j {
        for c in &f.checkpoints {
            let p5 = c.p5.unwrap_or_else(|| panic!("{}: no p5 at {c:?}", f.file));
            assert!(p5 <= c.actual_s + 30.0, "{}: late at {c:?}", f.file);
        }
    }
}
