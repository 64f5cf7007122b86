//! What the logbook answers: its flights, and per vehicle and per pack the sums and trends over
//! their flights. Flights are in flying order: by start time where the log gives one, then in
//! the order they were added.

use aloft_core::IndexLine;
use rusqlite::Row;
use serde::Serialize;

use crate::error::Result;
use crate::ingest::{Logbook, UNKNOWN};

/// Flights a vehicle's power drift is measured over (the last this many).
pub const DRIFT_FLIGHTS: usize = 30;

/// One row of `flights`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Flight {
    /// Id.
    pub id: i64,
    /// SHA-256 of the file's content.
    pub file_sha256: String,
    /// The file's name when added.
    pub file_name: String,
    /// The log's container.
    pub format: String,
    /// The vehicle's key.
    pub vehicle_key: String,
    /// The pack's key.
    pub pack_key: String,
    /// Start, Unix time, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_unix_s: Option<f64>,
    /// First to last battery sample, s.
    pub duration_s: f64,
    /// Energy drawn, Wh.
    pub energy_wh: f64,
    /// Charge drawn, mAh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub discharged_mah: Option<f64>,
    /// Largest current, A.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_current_a: Option<f64>,
    /// Lowest voltage, V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_voltage_v: Option<f64>,
    /// Mean power, W.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_power_w: Option<f64>,
    /// Mean power while hovering, W.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hover_power_w: Option<f64>,
    /// Cells in series.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cells_series: Option<u32>,
    /// The pack's resistance from current steps, ohm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resistance_ohm: Option<f64>,
    /// The autopilot's estimate of the pack's resistance, ohm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub autopilot_resistance_ohm: Option<f64>,
    /// Usable capacity between rested points, mAh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacity_mah: Option<f64>,
    /// Why no capacity was estimated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacity_refusal: Option<String>,
    /// Minutes with a cell more than 0.01 V from the others.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub imbalance_minor_min: Option<f64>,
    /// Minutes with a cell more than 0.07 V from the others.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub imbalance_major_min: Option<f64>,
    /// When it was added, Unix time, s.
    pub added_unix_s: i64,
    /// Where the file was when added (absolute); `None` for flights added before version 3.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file_path: Option<String>,
    /// The flight this log is another log of (the same vehicle over the same time); `None`
    /// for a flight of its own. A copy is listed, and counted in no sum.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub copy_of: Option<i64>,
    /// Time in the air, s (where the log says its landed or armed state).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub air_s: Option<f64>,
}

const FLIGHT_COLUMNS: &str = "id, file_sha256, file_name, format, vehicle_key, pack_key,
    start_unix_s, duration_s, energy_wh, discharged_mah, max_current_a, min_voltage_v,
    mean_power_w, hover_power_w, cells_series, resistance_ohm, autopilot_resistance_ohm,
    capacity_mah, capacity_refusal, imbalance_minor_min, imbalance_major_min, added_unix_s,
    file_path, copy_of, air_s";

/// Flying order: start time where known (unknown last), then the order of adding.
const FLYING_ORDER: &str = "ORDER BY start_unix_s IS NULL, start_unix_s, id";

impl Flight {
    fn of(r: &Row<'_>) -> rusqlite::Result<Self> {
        Ok(Self {
            id: r.get(0)?,
            file_sha256: r.get(1)?,
            file_name: r.get(2)?,
            format: r.get(3)?,
            vehicle_key: r.get(4)?,
            pack_key: r.get(5)?,
            start_unix_s: r.get(6)?,
            duration_s: r.get(7)?,
            energy_wh: r.get(8)?,
            discharged_mah: r.get(9)?,
            max_current_a: r.get(10)?,
            min_voltage_v: r.get(11)?,
            mean_power_w: r.get(12)?,
            hover_power_w: r.get(13)?,
            cells_series: r.get(14)?,
            resistance_ohm: r.get(15)?,
            autopilot_resistance_ohm: r.get(16)?,
            capacity_mah: r.get(17)?,
            capacity_refusal: r.get(18)?,
            imbalance_minor_min: r.get(19)?,
            imbalance_major_min: r.get(20)?,
            added_unix_s: r.get(21)?,
            file_path: r.get(22)?,
            copy_of: r.get(23)?,
            air_s: r.get(24)?,
        })
    }
}

/// One file that is not a flight of the logbook.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Skipped {
    /// SHA-256 of the file's content.
    pub file_sha256: String,
    /// The file's name.
    pub file_name: String,
    /// Why.
    pub reason: String,
}

/// A least-squares line through a quantity over a sequence of flights.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Trend {
    /// Flights with the quantity.
    pub n: usize,
    /// Its value on the first of them.
    pub first: f64,
    /// Its value on the last.
    pub last: f64,
    /// Least-squares slope per flight (`None` with fewer than two flights).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slope_per_flight: Option<f64>,
    /// Change from the line's value at the first flight to its value at the last, percent of
    /// the first (`None` with fewer than three flights).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub change_percent: Option<f64>,
}

/// The trend of `values` in their order.
pub fn trend(values: &[f64]) -> Option<Trend> {
    let (first, last) = (*values.first()?, *values.last()?);
    let n = values.len();
    let nf = n as f64;
    let slope = (n >= 2).then(|| {
        let line = IndexLine::of(values);
        (line.slope, line.at(0.0))
    });
    let change_percent = slope
        .filter(|_| n >= 3)
        .and_then(|(b, a)| (a.abs() > f64::EPSILON).then(|| 100.0 * b * (nf - 1.0) / a));
    Some(Trend {
        n,
        first,
        last,
        slope_per_flight: slope.map(|(b, _)| b),
        change_percent,
    })
}

/// One flight's power, for a vehicle's history.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PowerPoint {
    /// The flight.
    pub flight_id: i64,
    /// Its start, Unix time, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_unix_s: Option<f64>,
    /// Its mean power, W.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_power_w: Option<f64>,
    /// Its hover power, W.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hover_power_w: Option<f64>,
}

/// The drift of a vehicle's power over its last flights.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PowerDrift {
    /// Which power: `hover_power_w` where flights have it, else `mean_power_w` (which moves
    /// with what was flown, not only with the vehicle).
    pub quantity: String,
    /// Its trend over the last [`DRIFT_FLIGHTS`] flights that have it.
    pub trend: Trend,
}

/// A vehicle's history.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VehicleSummary {
    /// Key.
    pub key: String,
    /// Where the key came from: `log`, `label`, `unknown`.
    pub key_source: String,
    /// Flights (copies not counted).
    pub flights: usize,
    /// Logs that are copies of its flights (listed by `flights`, counted in no sum).
    pub copies: usize,
    /// Flight time (sum of durations), h.
    pub hours: f64,
    /// Energy drawn, Wh.
    pub energy_wh: f64,
    /// Charge drawn, mAh.
    pub discharged_mah: f64,
    /// Time in the air of the flights whose logs say it, h (`None` when none does).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub air_hours: Option<f64>,
    /// Packs flown.
    pub packs: Vec<String>,
    /// Power per flight, in flying order.
    pub power: Vec<PowerPoint>,
    /// Drift of the power over the last flights (at least two with a power; none for the
    /// vehicle "unknown", whose flights are of any vehicle).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power_drift: Option<PowerDrift>,
}

/// One estimate of a pack's figure on one flight.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PackPoint {
    /// The flight.
    pub flight_id: i64,
    /// Its start, Unix time, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_unix_s: Option<f64>,
    /// The value (ohm for resistance, mAh for capacity).
    pub value: f64,
}

/// A pack's history.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PackSummary {
    /// Key.
    pub key: String,
    /// Where the key came from: `log`, `label`, `unknown`.
    pub key_source: String,
    /// Rated capacity, mAh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rated_capacity_mah: Option<f64>,
    /// Cells in series.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cells_series: Option<u32>,
    /// Flights (copies not counted).
    pub flights: usize,
    /// Logs that are copies of its flights (counted in no sum).
    pub copies: usize,
    /// Flight time, h.
    pub hours: f64,
    /// Charge drawn over all flights, mAh.
    pub discharged_mah: f64,
    /// Energy drawn, Wh.
    pub energy_wh: f64,
    /// Equivalent full cycles: discharged charge / rated charge (`None` without a rating).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub equivalent_cycles: Option<f64>,
    /// Vehicles it flew.
    pub vehicles: Vec<String>,
    /// Resistance per flight, ohm.
    pub resistance: Vec<PackPoint>,
    /// Its trend (slope in ohm per flight; none for the pack "unknown").
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resistance_trend: Option<Trend>,
    /// Capacity estimates, mAh.
    pub capacity: Vec<PackPoint>,
    /// Minutes with a cell more than 0.01 V from the others, over all flights.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub imbalance_minor_min: Option<f64>,
    /// Minutes with a cell more than 0.07 V from the others, over all flights.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub imbalance_major_min: Option<f64>,
}

/// A row of `packs`: key, key source, rated capacity (mAh), cells in series.
type PackRow = (String, String, Option<f64>, Option<u32>);

/// Sum of the values present (`None` when none is).
fn sum_present(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    values
        .flatten()
        .fold(None, |acc, v| Some(acc.unwrap_or(0.0) + v))
}

/// Distinct values in first-seen order.
fn distinct<'a>(values: impl Iterator<Item = &'a String>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for v in values {
        if !out.contains(v) {
            out.push(v.clone());
        }
    }
    out
}

impl Logbook {
    /// Every flight, in flying order.
    ///
    /// # Errors
    /// The database cannot be read.
    pub fn flights(&self) -> Result<Vec<Flight>> {
        self.select_flights("", &[])
    }

    fn select_flights(&self, filter: &str, args: &[&str]) -> Result<Vec<Flight>> {
        let q = format!("SELECT {FLIGHT_COLUMNS} FROM flights {filter} {FLYING_ORDER}");
        let run = || -> rusqlite::Result<Vec<Flight>> {
            let mut st = self.conn.prepare(&q)?;
            let rows = st.query_map(rusqlite::params_from_iter(args), Flight::of)?;
            rows.collect()
        };
        run().map_err(|e| self.sql(e))
    }

    /// Every skipped file, by name.
    ///
    /// # Errors
    /// The database cannot be read.
    pub fn skipped(&self) -> Result<Vec<Skipped>> {
        let run = || -> rusqlite::Result<Vec<Skipped>> {
            let mut st = self.conn.prepare(
                "SELECT file_sha256, file_name, reason FROM skipped ORDER BY file_name, file_sha256",
            )?;
            let rows = st.query_map([], |r| {
                Ok(Skipped {
                    file_sha256: r.get(0)?,
                    file_name: r.get(1)?,
                    reason: r.get(2)?,
                })
            })?;
            rows.collect()
        };
        run().map_err(|e| self.sql(e))
    }

    /// Keys and key sources of a table (`vehicles` or `packs`), by key.
    fn keys(&self, table: &str) -> Result<Vec<(String, String)>> {
        let q = format!("SELECT key, key_source FROM {table} ORDER BY key");
        let run = || -> rusqlite::Result<Vec<(String, String)>> {
            let mut st = self.conn.prepare(&q)?;
            let rows = st.query_map([], |r| Ok((r.get(0)?, r.get(1)?)))?;
            rows.collect()
        };
        run().map_err(|e| self.sql(e))
    }

    /// The flights of one pack, in flying order, copies left out (for its pack file).
    ///
    /// # Errors
    /// The database cannot be read.
    pub fn flights_of_pack(&self, key: &str) -> Result<Vec<Flight>> {
        self.select_flights("WHERE pack_key = ?1 AND copy_of IS NULL", &[key])
    }

    /// Every vehicle's history, by key.
    ///
    /// # Errors
    /// The database cannot be read.
    pub fn vehicles(&self) -> Result<Vec<VehicleSummary>> {
        let mut out = Vec::new();
        for (key, key_source) in self.keys("vehicles")? {
            let flights = self.select_flights("WHERE vehicle_key = ?1", &[key.as_str()])?;
            out.push(vehicle_summary(key, key_source, &flights));
        }
        Ok(out)
    }

    /// Every pack's history, by key.
    ///
    /// # Errors
    /// The database cannot be read.
    pub fn packs(&self) -> Result<Vec<PackSummary>> {
        let run = || -> rusqlite::Result<Vec<PackRow>> {
            let mut st = self.conn.prepare(
                "SELECT key, key_source, rated_capacity_mah, cells_series FROM packs ORDER BY key",
            )?;
            let rows = st.query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?)))?;
            rows.collect()
        };
        let packs = run().map_err(|e| self.sql(e))?;
        let mut out = Vec::new();
        for (key, key_source, rated, cells) in packs {
            let flights = self.select_flights("WHERE pack_key = ?1", &[key.as_str()])?;
            out.push(pack_summary(key, key_source, rated, cells, &flights));
        }
        Ok(out)
    }
}

/// The flights of their own and the number of copies among `all`.
fn originals(all: &[Flight]) -> (Vec<Flight>, usize) {
    let flights: Vec<Flight> = all
        .iter()
        .filter(|f| f.copy_of.is_none())
        .cloned()
        .collect();
    let copies = all.len() - flights.len();
    (flights, copies)
}

/// A vehicle's sums and power history over its flights (in flying order), copies left out.
fn vehicle_summary(key: String, key_source: String, all: &[Flight]) -> VehicleSummary {
    let (flights, copies) = originals(all);
    let flights = &flights[..];
    let power: Vec<PowerPoint> = flights
        .iter()
        .map(|f| PowerPoint {
            flight_id: f.id,
            start_unix_s: f.start_unix_s,
            mean_power_w: f.mean_power_w,
            hover_power_w: f.hover_power_w,
        })
        .collect();
    let last = |pick: fn(&PowerPoint) -> Option<f64>| -> Vec<f64> {
        let all: Vec<f64> = power.iter().filter_map(pick).collect();
        all[all.len().saturating_sub(DRIFT_FLIGHTS)..].to_vec()
    };
    let hover = last(|p| p.hover_power_w);
    let (quantity, series) = if hover.len() >= 2 {
        ("hover_power_w", hover)
    } else {
        ("mean_power_w", last(|p| p.mean_power_w))
    };
    let power_drift = trend(&series).filter(|t| t.n >= 2).map(|trend| PowerDrift {
        quantity: quantity.to_string(),
        trend,
    });
    VehicleSummary {
        key,
        key_source,
        flights: flights.len(),
        copies,
        hours: flights.iter().map(|f| f.duration_s).sum::<f64>() / 3600.0,
        energy_wh: flights.iter().map(|f| f.energy_wh).sum(),
        discharged_mah: flights.iter().filter_map(|f| f.discharged_mah).sum(),
        air_hours: sum_present(flights.iter().map(|f| f.air_s)).map(|s| s / 3600.0),
        packs: distinct(flights.iter().map(|f| &f.pack_key)),
        power,
        power_drift,
    }
}

/// A pack's sums, cycles and trends over its flights (in flying order), copies left out.
fn pack_summary(
    key: String,
    key_source: String,
    rated_capacity_mah: Option<f64>,
    cells_series: Option<u32>,
    all: &[Flight],
) -> PackSummary {
    let (flights, copies) = originals(all);
    let flights = &flights[..];
    let points = |pick: fn(&Flight) -> Option<f64>| -> Vec<PackPoint> {
        flights
            .iter()
            .filter_map(|f| {
                pick(f).map(|value| PackPoint {
                    flight_id: f.id,
                    start_unix_s: f.start_unix_s,
                    value,
                })
            })
            .collect()
    };
    let resistance = points(|f| f.resistance_ohm);
    let values: Vec<f64> = resistance.iter().map(|p| p.value).collect();
    let discharged_mah: f64 = flights.iter().filter_map(|f| f.discharged_mah).sum();
    // The flights of "unknown" are of any pack: no one pack's trend.
    let resistance_trend = trend(&values).filter(|_| key != UNKNOWN);
    PackSummary {
        equivalent_cycles: rated_capacity_mah
            .filter(|r| *r > 0.0)
            .map(|r| discharged_mah / r),
        key,
        key_source,
        rated_capacity_mah,
        cells_series,
        flights: flights.len(),
        copies,
        hours: flights.iter().map(|f| f.duration_s).sum::<f64>() / 3600.0,
        discharged_mah,
        energy_wh: flights.iter().map(|f| f.energy_wh).sum(),
        vehicles: distinct(flights.iter().map(|f| &f.vehicle_key)),
        resistance_trend,
        resistance,
        capacity: points(|f| f.capacity_mah),
        imbalance_minor_min: sum_present(flights.iter().map(|f| f.imbalance_minor_min)),
        imbalance_major_min: sum_present(flights.iter().map(|f| f.imbalance_major_min)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line 10, 11, 12, 13: slope 1 per flight, +30 % from the first to the last.
    #[test]
    fn trend_of_a_line() {
        let t = trend(&[10.0, 11.0, 12.0, 13.0]).unwrap();
        assert_eq!(t.n, 4);
        assert!((t.slope_per_flight.unwrap() - 1.0).abs() < 1e-12);
        assert!((t.change_percent.unwrap() - 30.0).abs() < 1e-9);
        let one = trend(&[5.0]).unwrap();
        assert_eq!(
            (one.n, one.slope_per_flight, one.change_percent),
            (1, None, None)
        );
        assert!(trend(&[]).is_none());
    }
}
