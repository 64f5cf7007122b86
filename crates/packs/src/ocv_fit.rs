//! The pack's own open-circuit curve from its flight logs.
//!
//! # Model
//! Each record with a current gives a point of the cell's open-circuit curve:
//!
//! `s_k = (A − Q_k) / C`, `V_oc,k = (V_k + I_k R) / n`
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | Q_k | charge drawn from the first record to record k (the coulomb count, [`crate::coulomb_count_mah`]'s trapezoid) | mA h |
//! | A | the charge the pack held at the first record (below) | mA h |
//! | C | the pack's capacity (the one the pack file carries) | mA h |
//! | V_k, I_k | terminal voltage and current of record k (discharge positive) | V, A |
//! | R | the pack's internal resistance (the current-step estimate, [`crate::resistance_from_steps`]) | Ω |
//! | n | cells in series | - |
//!
//! `A` comes from the pack's own gauge where the log has one ([`BatterySample::remaining_mah`],
//! KAIST's BMS `capacity`): the **median** over the records of `gauge_k + Q_k`. Without a gauge,
//! from a rested start: the first record rests (|I| below [`crate::rest_limit_a`]) for at least
//! [`crate::REST_HOLD_S`], and the last rested voltage reads a state of charge `s_0` on the
//! generic curve ([`OcvCurve::typical_lipo`]): `A = s_0 C`.
//!
//! The points are binned by state of charge ([`OCV_BIN_SOC`], 2.5 %); a bin with at least
//! [`MIN_RECORDS_PER_BIN`] records gives its median voltage at the bin's centre. Flights combine
//! by the median of their bins ([`combine_flight_ocv`]); the medians are made non-decreasing in
//! charge (pool-adjacent-violators, each bin weighted by its flights); at least
//! [`MIN_MEASURED_BINS`] bins are needed. Outside the bins the logs cover, the curve is the
//! generic one shifted to meet the fitted ends, so it spans 0-1 and says which part was measured
//! ([`FittedOcv::measured_from_soc`], [`FittedOcv::measured_to_soc`]).
//!
//! # Deviation: the gauge places the flight, the count moves along it
//! Reading each record's state of charge straight off the gauge (`gauge_k / C`) would put the
//! curve on the gauge's scale of charge, while the filter and the planner count the logged
//! current: on the KAIST flights the coulomb count is 0.95 of the BMS drop, so a curve on the
//! gauge's scale would fall 5 % slower per counted charge than the pack. And a gauge that jumps
//! (a recalibration, a glitch) would move every record after it. The median of `gauge_k + Q_k`
//! is the gauge's reading of the flight's start that most records agree on: a jump over less than
//! half of the records does not move it.
//!
//! # Deviation: `V + I R` is not the rested voltage
//! Under a sustained load the pack's diffusion (the RC pair of [`crate::Circuit`]) sags the
//! voltage beyond `I R`; these points carry that sag, so the curve is the voltage the pack holds
//! under the flight's load less its resistive drop, not its rested voltage (a pack rested after
//! the flight reads higher). That is the voltage the planner's model `V_oc(s) − I R` flies on.

use aloft_core::Trapezoid;
use aloft_logs::BatterySample;
use aloft_propulsion::OcvCurve;
use serde::Serialize;

use crate::capacity::{rest_limit_a, MAX_GAP_S, REST_HOLD_S};
use crate::PackError;

/// Width of a bin of state of charge, 0-1 (2.5 %).
pub const OCV_BIN_SOC: f64 = 0.025;
/// Fewest records in a flight's bin for its median to count.
pub const MIN_RECORDS_PER_BIN: usize = 10;
/// Fewest bins (10 % of charge) for a curve.
pub const MIN_MEASURED_BINS: usize = 4;

/// Bins over the state of charge.
const BINS: usize = 40;

/// Where a flight's state of charge comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ChargeAnchor {
    /// The pack's own gauge (remaining mA h).
    PackGauge,
    /// A rested start read on the generic curve.
    RestedStart,
}

impl ChargeAnchor {
    /// The anchor in words.
    pub fn words(self) -> &'static str {
        match self {
            Self::PackGauge => "the pack's gauge and the coulomb count",
            Self::RestedStart => "a rested start on the generic curve and the coulomb count",
        }
    }
}

/// One bin of one flight: the median open-circuit voltage of its records.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OcvBin {
    /// Bin index: the bin covers `[index, index + 1) × OCV_BIN_SOC`.
    pub index: usize,
    /// Median of `(V + I R) / n` over its records, V a cell.
    pub cell_v: f64,
    /// Records in it.
    pub records: usize,
}

/// One flight's points of the open-circuit curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlightOcv {
    /// Where its state of charge comes from.
    pub anchor: ChargeAnchor,
    /// The state of charge at its first record, 0-1.
    pub start_soc: f64,
    /// Its bins with at least [`MIN_RECORDS_PER_BIN`] records, by rising charge.
    pub bins: Vec<OcvBin>,
}

/// The pack's open-circuit curve fitted on its flights.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedOcv {
    /// State of charge of the curve's points, 0-1 (0 and 1 included).
    pub soc: Vec<f64>,
    /// Cell voltage at them, V.
    pub cell_v: Vec<f64>,
    /// Lowest state of charge the logs measured (a bin's centre).
    pub measured_from_soc: f64,
    /// Highest state of charge the logs measured (a bin's centre).
    pub measured_to_soc: f64,
    /// Flights that gave bins.
    pub flights: usize,
}

impl FittedOcv {
    /// The curve as the planner and the filter read it.
    ///
    /// # Errors
    /// None for a fit this module made (its points rise); kept for a value built by hand.
    pub fn curve(&self) -> Result<OcvCurve, PackError> {
        OcvCurve::new(self.soc.clone(), self.cell_v.clone()).map_err(|_| PackError::InvalidValue {
            name: "fitted open-circuit curve",
            value: self.cell_v.first().copied().unwrap_or(f64::NAN),
            unit: "V",
            expected: "points rising in charge and voltage",
        })
    }
}

/// A record: (state of charge not yet known: charge drawn so far mA h, gauge mA h, V, A).
struct Point {
    drawn_mah: f64,
    gauge_mah: Option<f64>,
    voltage_v: f64,
    current_a: f64,
}

/// One flight's bins of the open-circuit curve (module docs).
///
/// # Errors
/// [`PackError::CellsUnknown`] with no cells; [`PackError::InvalidValue`] for a capacity or
/// resistance out of range; [`PackError::OcvChargeUnknown`] with neither a gauge nor a rested
/// start; [`PackError::OcvGaugeAboveCapacity`] when the gauge reads more than the capacity;
/// [`PackError::OcvTooFewRecords`] with fewer than [`MIN_MEASURED_BINS`] full bins.
pub fn flight_ocv(
    samples: &[BatterySample],
    cells_series: Option<u32>,
    capacity_mah: f64,
    resistance_ohm: f64,
) -> Result<FlightOcv, PackError> {
    let cells = f64::from(
        cells_series
            .filter(|n| *n > 0)
            .ok_or(PackError::CellsUnknown)?,
    );
    check_inputs(capacity_mah, resistance_ohm)?;
    let points = points(samples);
    let (anchor, held_mah) = anchor(samples, &points, cells, capacity_mah)?;
    let start_soc = held_mah / capacity_mah;
    let mut bins: Vec<Vec<f64>> = vec![Vec::new(); BINS];
    for p in &points {
        let soc = (held_mah - p.drawn_mah) / capacity_mah;
        if !(0.0..1.0).contains(&soc) {
            continue;
        }
        let k = ((soc / OCV_BIN_SOC) as usize).min(BINS - 1);
        bins[k].push((p.voltage_v + p.current_a * resistance_ohm) / cells);
    }
    let bins = full_bins(bins);
    if bins.len() < MIN_MEASURED_BINS {
        return Err(too_few(bins.len()));
    }
    Ok(FlightOcv {
        anchor,
        start_soc,
        bins,
    })
}

/// A capacity and a resistance a curve can be fitted with.
fn check_inputs(capacity_mah: f64, resistance_ohm: f64) -> Result<(), PackError> {
    if !(capacity_mah.is_finite() && capacity_mah > 0.0) {
        return Err(PackError::InvalidValue {
            name: "capacity_mah",
            value: capacity_mah,
            unit: "mA h",
            expected: "a positive finite capacity",
        });
    }
    if !(resistance_ohm.is_finite() && resistance_ohm >= 0.0) {
        return Err(PackError::InvalidValue {
            name: "internal_resistance_ohm",
            value: resistance_ohm,
            unit: "ohm",
            expected: "a finite resistance, not negative",
        });
    }
    Ok(())
}

/// The records with a finite voltage and current, each once (a repeated reading is one), with
/// the charge drawn up to each (trapezoid over all records, gaps over [`MAX_GAP_S`] not bridged).
fn points(samples: &[BatterySample]) -> Vec<Point> {
    let mut out: Vec<Point> = Vec::new();
    let mut q_as = Trapezoid::new();
    for s in samples {
        let Some(i) = s.current_a.filter(|i| i.is_finite()) else {
            continue;
        };
        if !(s.voltage_v.is_finite() && s.time_s.is_finite()) {
            continue;
        }
        q_as.push_bridging(s.time_s, i, MAX_GAP_S);
        let repeat = out.last().is_some_and(|p| {
            p.voltage_v.to_bits() == s.voltage_v.to_bits() && p.current_a.to_bits() == i.to_bits()
        });
        if !repeat {
            out.push(Point {
                drawn_mah: q_as.integral() / 3.6,
                gauge_mah: s.remaining_mah.filter(|g| g.is_finite() && *g >= 0.0),
                voltage_v: s.voltage_v,
                current_a: i,
            });
        }
    }
    out
}

/// The charge the pack held at the first record, mA h, and where it comes from (module docs).
fn anchor(
    samples: &[BatterySample],
    points: &[Point],
    cells: f64,
    capacity_mah: f64,
) -> Result<(ChargeAnchor, f64), PackError> {
    let mut held: Vec<f64> = points
        .iter()
        .filter_map(|p| p.gauge_mah.map(|g| g + p.drawn_mah))
        .collect();
    if let Some(a) = crate::resistance::median(&mut held) {
        if a > capacity_mah {
            return Err(PackError::OcvGaugeAboveCapacity {
                gauge_mah: a,
                capacity_mah,
            });
        }
        return Ok((ChargeAnchor::PackGauge, a));
    }
    let rested_v = rested_start_v(samples, capacity_mah).ok_or(PackError::OcvChargeUnknown {
        rest_hold_s: REST_HOLD_S,
    })?;
    let soc = OcvCurve::typical_lipo().soc_at(rested_v / cells);
    Ok((ChargeAnchor::RestedStart, soc * capacity_mah))
}

/// The last rested voltage before the first load, V, when the log starts with a rest of at
/// least [`REST_HOLD_S`] (the rule of [`crate::capacity_between_rests`]).
fn rested_start_v(samples: &[BatterySample], capacity_mah: f64) -> Option<f64> {
    let limit_a = rest_limit_a(Some(capacity_mah));
    let pts: Vec<(f64, f64, f64)> = samples
        .iter()
        .filter_map(|s| Some((s.time_s, s.voltage_v, s.current_a?)))
        .filter(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite())
        .collect();
    let load = pts.iter().position(|p| p.2.abs() >= limit_a)?;
    (load > 0 && pts[load].0 - pts[0].0 >= REST_HOLD_S).then(|| pts[load - 1].1)
}

/// The bins with at least [`MIN_RECORDS_PER_BIN`] records, their medians.
fn full_bins(bins: Vec<Vec<f64>>) -> Vec<OcvBin> {
    bins.into_iter()
        .enumerate()
        .filter(|(_, v)| v.len() >= MIN_RECORDS_PER_BIN)
        .filter_map(|(index, mut v)| {
            let records = v.len();
            crate::resistance::median(&mut v).map(|cell_v| OcvBin {
                index,
                cell_v,
                records,
            })
        })
        .collect()
}

fn too_few(bins: usize) -> PackError {
    PackError::OcvTooFewRecords {
        bins,
        min_bins: MIN_MEASURED_BINS,
        min_records: MIN_RECORDS_PER_BIN,
        bin_soc: OCV_BIN_SOC,
    }
}

/// The flights' bins combined into the pack's curve (module docs): the median per bin over the
/// flights that have it, made non-decreasing in charge, the generic curve shifted to meet its
/// ends outside them.
///
/// # Errors
/// [`PackError::OcvTooFewRecords`] with fewer than [`MIN_MEASURED_BINS`] bins over all flights.
pub fn combine_flight_ocv(flights: &[FlightOcv]) -> Result<FittedOcv, PackError> {
    let mut per_bin: Vec<Vec<f64>> = vec![Vec::new(); BINS];
    for b in flights.iter().flat_map(|f| &f.bins) {
        if b.index < BINS && b.cell_v.is_finite() {
            per_bin[b.index].push(b.cell_v);
        }
    }
    let measured: Vec<(f64, f64, usize)> = per_bin
        .into_iter()
        .enumerate()
        .filter_map(|(k, mut v)| {
            let n = v.len();
            let centre = (k as f64 + 0.5) * OCV_BIN_SOC;
            crate::resistance::median(&mut v).map(|m| (centre, m, n))
        })
        .collect();
    if measured.len() < MIN_MEASURED_BINS {
        return Err(too_few(measured.len()));
    }
    let weights: Vec<f64> = measured.iter().map(|m| m.2 as f64).collect();
    let values: Vec<f64> = measured.iter().map(|m| m.1).collect();
    // Rounded to 1e-6 of charge and 10 µV, as a pack file keeps them (rounding keeps the order).
    let rising: Vec<f64> = non_decreasing(&values, &weights)
        .into_iter()
        .map(|v| (v * 1e5).round() / 1e5)
        .collect();
    let centres: Vec<f64> = measured.iter().map(|m| (m.0 * 1e6).round() / 1e6).collect();
    let (soc, cell_v) = joined_to_generic(&centres, &rising);
    let fitted = FittedOcv {
        soc,
        cell_v,
        measured_from_soc: centres[0],
        measured_to_soc: centres[centres.len() - 1],
        flights: flights.iter().filter(|f| !f.bins.is_empty()).count(),
    };
    fitted.curve()?;
    Ok(fitted)
}

/// The weighted least-squares non-decreasing sequence nearest `values` (pool adjacent
/// violators).
pub fn non_decreasing(values: &[f64], weights: &[f64]) -> Vec<f64> {
    // Blocks of (mean, weight, length).
    let mut blocks: Vec<(f64, f64, usize)> = Vec::new();
    for (&v, &w) in values.iter().zip(weights) {
        blocks.push((v, w, 1));
        while blocks.len() > 1 && blocks[blocks.len() - 2].0 > blocks[blocks.len() - 1].0 {
            let (m1, w1, n1) = blocks.pop().unwrap_or_default();
            let (m0, w0, n0) = blocks.pop().unwrap_or_default();
            blocks.push(((m0 * w0 + m1 * w1) / (w0 + w1), w0 + w1, n0 + n1));
        }
    }
    blocks
        .into_iter()
        .flat_map(|(m, _, n)| std::iter::repeat_n(m, n))
        .collect()
}

/// The measured points with the generic curve's nodes outside them, shifted to meet the
/// measured ends.
fn joined_to_generic(centres: &[f64], cell_v: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let generic = OcvCurve::typical_lipo();
    let nodes: Vec<f64> = (0..=20).map(|k| f64::from(k) * 0.05).collect();
    let (lo, hi) = (centres[0], centres[centres.len() - 1]);
    let below = cell_v[0] - generic.cell_v(lo);
    let above = cell_v[cell_v.len() - 1] - generic.cell_v(hi);
    let mut soc = Vec::new();
    let mut v = Vec::new();
    let round = |v: f64| (v * 1e5).round() / 1e5;
    for &s in nodes.iter().filter(|s| **s < lo) {
        soc.push((s * 1e6).round() / 1e6);
        v.push(round(generic.cell_v(s) + below));
    }
    soc.extend_from_slice(centres);
    v.extend_from_slice(cell_v);
    for &s in nodes.iter().filter(|s| **s > hi) {
        soc.push((s * 1e6).round() / 1e6);
        v.push(round(generic.cell_v(s) + above));
    }
    (soc, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell curve in closed form (V a cell at state of charge `s`).
    fn truth(s: f64) -> f64 {
        3.5 + 0.4 * s + 0.3 * s * s
    }

    const CELLS: u32 = 4;
    const CAPACITY_MAH: f64 = 5000.0;
    const R_OHM: f64 = 0.05;

    /// A 4S 5000 mA h pack discharged from 90 % at 1 Hz on a load alternating 15 and 25 A each
    /// second (20 A on average: 0.11 % of charge a second, 80 % in 720 s) for `seconds`, its
    /// gauge exact.
    fn discharge(seconds: usize) -> Vec<BatterySample> {
        let mut soc = 0.9;
        (0..seconds)
            .map(|k| {
                let i = if k % 2 == 0 { 15.0 } else { 25.0 };
                let s = BatterySample {
                    time_s: k as f64,
                    voltage_v: f64::from(CELLS) * truth(soc) - i * R_OHM,
                    current_a: Some(i),
                    remaining_mah: Some(soc * CAPACITY_MAH),
                    ..BatterySample::default()
                };
                soc -= i / 3600.0 / (CAPACITY_MAH / 1000.0);
                s
            })
            .collect()
    }

    fn fit(samples: &[BatterySample]) -> FittedOcv {
        let f = flight_ocv(samples, Some(CELLS), CAPACITY_MAH, R_OHM).unwrap();
        combine_flight_ocv(&[f]).unwrap()
    }

    /// The discharge on a known curve gives it back at the bins' centres, and the generic curve
    /// shifted to meet it outside them.
    #[test]
    fn a_discharge_on_a_known_curve_gives_it_back() {
        // 720 s at 20 A on average: 4000 mA h, 90 % down to 10 %, a record every 0.11 % of
        // charge (22 a bin): measured from the centre of 10-12.5 % to that of 87.5-90 %.
        let fitted = fit(&discharge(720));
        assert_eq!(fitted.flights, 1);
        assert!(
            (fitted.measured_from_soc - 0.1125).abs() < 1e-12,
            "{fitted:?}"
        );
        assert!(
            (fitted.measured_to_soc - 0.8875).abs() < 1e-12,
            "{fitted:?}"
        );
        let curve = fitted.curve().unwrap();
        for (&s, &v) in fitted.soc.iter().zip(&fitted.cell_v) {
            if (fitted.measured_from_soc..=fitted.measured_to_soc).contains(&s) {
                // The bin's median record sits within one record's charge (0.14 % at 25 A) of
                // its centre, where the curve's slope is at most 0.94 V a cell: 1.3 mV.
                assert!((v - truth(s)).abs() < 2e-3, "{s}: {v} against {}", truth(s));
            }
        }
        // Outside: the generic curve shifted to meet the fitted ends (to the 10 µV the points
        // are rounded to).
        let g = OcvCurve::typical_lipo();
        let lo = fitted.measured_from_soc;
        let shift = curve.cell_v(lo) - g.cell_v(lo);
        assert!((curve.cell_v(0.0) - (g.cell_v(0.0) + shift)).abs() < 1e-5);
        assert!((curve.cell_v(0.05) - (g.cell_v(0.05) + shift)).abs() < 1e-5);
        let hi = fitted.measured_to_soc;
        let shift = curve.cell_v(hi) - g.cell_v(hi);
        assert!((curve.cell_v(1.0) - (g.cell_v(1.0) + shift)).abs() < 1e-5);
        assert!(
            (fitted.soc[0]).abs() < 1e-15 && (fitted.soc[fitted.soc.len() - 1] - 1.0).abs() < 1e-15
        );
    }

    /// A gauge that jumps 2000 mA h over the last third of the flight (a recalibration) does
    /// not move the curve: the median of gauge + count is the start most records agree on.
    #[test]
    fn a_gauge_that_jumps_does_not_bend_the_curve() {
        let honest = fit(&discharge(720));
        let mut lying = discharge(720);
        for s in &mut lying[480..] {
            s.remaining_mah = s.remaining_mah.map(|g| g + 2000.0);
        }
        // And one record of a gauge gone wild.
        lying[300].remaining_mah = Some(4.0e4);
        assert_eq!(fit(&lying), honest);
    }

    /// Without a gauge, a rested start anchors the count: 60 s at 0.1 A at the generic curve's
    /// 90 % (4.11 V a cell) then the discharge; the points land where the rest says.
    #[test]
    fn a_rested_start_anchors_the_count() {
        let mut s: Vec<BatterySample> = (0..60)
            .map(|k| BatterySample {
                time_s: k as f64,
                voltage_v: 4.0 * 4.11,
                current_a: Some(0.1),
                ..BatterySample::default()
            })
            .collect();
        for mut d in discharge(720) {
            d.time_s += 60.0;
            d.remaining_mah = None;
            s.push(d);
        }
        let f = flight_ocv(&s, Some(CELLS), CAPACITY_MAH, R_OHM).unwrap();
        assert_eq!(f.anchor, ChargeAnchor::RestedStart);
        // 0.1 A for 59 s is 1.6 mA h: the start is 90 % less 0.03 %.
        assert!((f.start_soc - 0.9).abs() < 1e-3, "{f:?}");
    }

    #[test]
    fn too_few_records_is_said() {
        // 60 s at 20 A: 333 mA h, 6.7 % of charge: two full bins of 22 records at most.
        let e = flight_ocv(&discharge(60), Some(CELLS), CAPACITY_MAH, R_OHM).unwrap_err();
        assert!(
            matches!(e, PackError::OcvTooFewRecords { bins, .. } if bins < MIN_MEASURED_BINS),
            "{e}"
        );
        assert!(e.to_string().contains("at least 4"), "{e}");
        let mut no_gauge = discharge(720);
        for s in &mut no_gauge {
            s.remaining_mah = None;
        }
        let e = flight_ocv(&no_gauge, Some(CELLS), CAPACITY_MAH, R_OHM).unwrap_err();
        assert!(matches!(e, PackError::OcvChargeUnknown { .. }), "{e}");
        let e = flight_ocv(&discharge(720), Some(CELLS), 4000.0, R_OHM).unwrap_err();
        assert!(matches!(e, PackError::OcvGaugeAboveCapacity { .. }), "{e}");
        assert!(matches!(
            combine_flight_ocv(&[]),
            Err(PackError::OcvTooFewRecords { bins: 0, .. })
        ));
    }

    /// Pool adjacent violators: a dip is pooled with what it breaks, weighted.
    #[test]
    fn made_non_decreasing() {
        let v = non_decreasing(&[1.0, 3.0, 2.0, 4.0], &[1.0, 1.0, 3.0, 1.0]);
        // 3 (weight 1) and 2 (weight 3) pool to 2.25.
        let want = [1.0, 2.25, 2.25, 4.0];
        for (a, b) in v.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{v:?}");
        }
    }
}
