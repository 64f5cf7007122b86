//! One battery pack as a vehicle file describes it: the one description every pack model of
//! aloft is built from.
//!
//! A vehicle file describes packs in two places with the same keys: `[[battery]]` tables (the
//! packs a mission can fly with) and `[propulsion.battery]` (the pack of the propulsion chain).
//! Two models read the description:
//!
//! - the propulsion seed's pack at its full-charge voltage (eqs 16-17, 29-31),
//!   [`BatterySpec::to_seed_model`] ([`crate::Battery`]);
//! - the mission planner's pack, charge counting on an open-circuit curve
//!   (`aloft_planner::Pack::new`).
//!
//! Each model says which keys it needs; a description may carry keys only the other model reads.
//!
//! | key | meaning | unit | read by |
//! |---|---|---|---|
//! | `name`, `default` | name on the command line; the vehicle's default pack | - | planner |
//! | `cells_series`, `cells_parallel` | cells in series; in parallel (default 1) | - | both |
//! | `capacity_mah` | rated capacity | mA h | both |
//! | `nominal_v` | rated (nominal) pack voltage (default for the seed: cells x 3.7 V, eq 31) | V | both |
//! | `energy_wh` | rated energy (within 1 % of capacity x nominal voltage) | W h | planner |
//! | `mass_kg` | pack mass | kg | planner |
//! | `internal_resistance_ohm` | constant pack resistance | ohm | both |
//! | `r1_ohm`, `r2_ohm_a`, `r3_ohm_a`, `eq17_min_current_a`, `eq17_max_current_a` | eq (17) resistance and its valid range | ohm, ohm A, A | seed |
//! | `cutoff_cell_v` | cut-off voltage per cell under load | V | planner |
//! | `usable_fraction` | fraction of the capacity that may be drawn (default 1) | - | planner |
//! | `effective_capacity_fraction` | `C_e` of eq (31) | - | seed |
//! | `full_charge_cell_v` | full-charge cell voltage of eq (30) (default 4.1 V) | V | seed |
//! | `ocv_soc`, `ocv_cell_v` | a measured open-circuit curve (default: typical LiPo) | -, V | planner |
//! | `rc_resistance_ohm`, `rc_time_constant_s` | the RC pair of the pack's equivalent circuit (default: the state-of-charge filter's) | ohm, s | in flight |
//! | `max_current_a` | rated continuous current (default: no limit) | A | both |
//!
//! Capacity is in mA h everywhere (as packs are labelled) and the nominal voltage is the pack's
//! (as spec sheets print it): a file with the old keys `capacity_ah` or `nominal_cell_v` gets an
//! error that names the key to use instead.

use serde::{Deserialize, Serialize};

use crate::battery::{
    Battery, BatteryConstants, Eq17Resistance, InternalResistance, SEED_FULL_CELL_V,
    SEED_NOMINAL_CELL_V,
};
use crate::error::PropulsionError;

fn one() -> u32 {
    1
}

fn is_one(n: &u32) -> bool {
    *n == 1
}

fn full_usable() -> f64 {
    1.0
}

/// One battery pack (see the module docs for the keys and which model reads each).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BatteryTable")]
pub struct BatterySpec {
    /// Name used on the command line (`--battery`).
    #[serde(skip_serializing_if = "String::is_empty")]
    pub name: String,
    /// The vehicle's default pack (at most one per vehicle; else the first).
    pub default: bool,
    /// Cells in series.
    pub cells_series: u32,
    /// Cells in parallel.
    #[serde(skip_serializing_if = "is_one")]
    pub cells_parallel: u32,
    /// Rated capacity, mA h.
    pub capacity_mah: f64,
    /// Rated (nominal) pack voltage, V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal_v: Option<f64>,
    /// Rated energy, W h.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_wh: Option<f64>,
    /// Pack mass, kg.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Constant pack internal resistance, ohm (0 allowed for missions: an ideal source).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub internal_resistance_ohm: Option<f64>,
    /// `r_1` of eq (17), ohm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub r1_ohm: Option<f64>,
    /// `r_2` of eq (17), ohm A.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub r2_ohm_a: Option<f64>,
    /// `r_3` of eq (17), ohm A.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub r3_ohm_a: Option<f64>,
    /// Lower end of eq (17)'s valid current range, A.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eq17_min_current_a: Option<f64>,
    /// Upper end of eq (17)'s valid current range, A.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eq17_max_current_a: Option<f64>,
    /// Cut-off voltage per cell under load, V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cutoff_cell_v: Option<f64>,
    /// Fraction of the rated capacity that may be drawn, in `(0, 1]`.
    pub usable_fraction: f64,
    /// Effective-capacity coefficient `C_e` of eq (31).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effective_capacity_fraction: Option<f64>,
    /// Full-charge cell voltage of eq (30), V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub full_charge_cell_v: Option<f64>,
    /// Open-circuit curve: state-of-charge points in `[0, 1]`, increasing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ocv_soc: Option<Vec<f64>>,
    /// Open-circuit curve: cell voltage at each `ocv_soc` point, V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ocv_cell_v: Option<Vec<f64>>,
    /// The RC pair of the pack's equivalent circuit: its resistance, ohm (`aloft pack fit`,
    /// where the logs identify it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rc_resistance_ohm: Option<f64>,
    /// The RC pair's time constant, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rc_time_constant_s: Option<f64>,
    /// Rated continuous current, A.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_current_a: Option<f64>,
}

impl Default for BatterySpec {
    /// An empty description (no cells, no capacity): fill in what a model needs.
    fn default() -> Self {
        Self {
            name: String::new(),
            default: false,
            cells_series: 0,
            cells_parallel: 1,
            capacity_mah: 0.0,
            nominal_v: None,
            energy_wh: None,
            mass_kg: None,
            internal_resistance_ohm: None,
            r1_ohm: None,
            r2_ohm_a: None,
            r3_ohm_a: None,
            eq17_min_current_a: None,
            eq17_max_current_a: None,
            cutoff_cell_v: None,
            usable_fraction: 1.0,
            effective_capacity_fraction: None,
            full_charge_cell_v: None,
            ocv_soc: None,
            ocv_cell_v: None,
            rc_resistance_ohm: None,
            rc_time_constant_s: None,
            max_current_a: None,
        }
    }
}

impl BatterySpec {
    /// The propulsion seed's pack model (eqs 16-17, 29-31): full-charge voltage `full_charge_cell_v`
    /// per cell (default 4.1 V), nominal voltage `nominal_v` (default cells x 3.7 V), capacity
    /// `C_b = capacity_mah / 1000`, `C_e = effective_capacity_fraction`, constant or eq (17)
    /// resistance.
    ///
    /// # Errors
    /// A missing `effective_capacity_fraction`, neither or both resistance forms, values the model
    /// rejects.
    pub fn to_seed_model(&self) -> Result<Battery, PropulsionError> {
        let effective =
            self.effective_capacity_fraction
                .ok_or(PropulsionError::ConflictingKeys {
                    table: "propulsion.battery",
                    problem: "give effective_capacity_fraction (C_e of seed eq 31)",
                })?;
        let nominal_cell_v = match self.nominal_v {
            Some(v) if self.cells_series > 0 => v / f64::from(self.cells_series),
            _ => SEED_NOMINAL_CELL_V,
        };
        Battery::new(BatteryConstants {
            cells_series: self.cells_series,
            cells_parallel: self.cells_parallel,
            capacity_ah: self.capacity_mah / 1000.0,
            effective_capacity: effective,
            full_cell_v: self.full_charge_cell_v.unwrap_or(SEED_FULL_CELL_V),
            nominal_cell_v,
            resistance: self.resistance_model()?,
            max_current_a: self.max_current_a.unwrap_or(f64::INFINITY),
        })
    }

    /// The resistance of the seed model: a constant, or eq (17) with its valid range.
    fn resistance_model(&self) -> Result<InternalResistance, PropulsionError> {
        match (
            self.internal_resistance_ohm,
            self.r1_ohm,
            self.r2_ohm_a,
            self.r3_ohm_a,
            self.eq17_min_current_a,
            self.eq17_max_current_a,
        ) {
            (Some(r), None, None, None, None, None) => Ok(InternalResistance::Constant {
                resistance_ohm: r,
            }),
            (None, Some(r1), Some(r2), Some(r3), Some(lo), Some(hi)) => {
                Ok(InternalResistance::Logarithmic(Eq17Resistance {
                    r1_ohm: r1,
                    r2_ohm_a: r2,
                    r3_ohm_a: r3,
                    min_current_a: lo,
                    max_current_a: hi,
                }))
            }
            _ => Err(PropulsionError::ConflictingKeys {
                table: "propulsion.battery",
                problem: "give either internal_resistance_ohm, or all of r1_ohm, r2_ohm_a, r3_ohm_a, eq17_min_current_a, eq17_max_current_a",
            }),
        }
    }
}

/// The keys a battery table may hold, the old ones included so that they get a clear error.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BatteryTable {
    #[serde(default)]
    name: String,
    #[serde(default)]
    default: bool,
    cells_series: u32,
    #[serde(default = "one")]
    cells_parallel: u32,
    capacity_mah: Option<f64>,
    nominal_v: Option<f64>,
    energy_wh: Option<f64>,
    mass_kg: Option<f64>,
    internal_resistance_ohm: Option<f64>,
    r1_ohm: Option<f64>,
    r2_ohm_a: Option<f64>,
    r3_ohm_a: Option<f64>,
    eq17_min_current_a: Option<f64>,
    eq17_max_current_a: Option<f64>,
    cutoff_cell_v: Option<f64>,
    #[serde(default = "full_usable")]
    usable_fraction: f64,
    effective_capacity_fraction: Option<f64>,
    full_charge_cell_v: Option<f64>,
    ocv_soc: Option<Vec<f64>>,
    ocv_cell_v: Option<Vec<f64>>,
    rc_resistance_ohm: Option<f64>,
    rc_time_constant_s: Option<f64>,
    max_current_a: Option<f64>,
    /// Old key: the capacity is `capacity_mah`.
    capacity_ah: Option<f64>,
    /// Old key: the nominal voltage is the pack's, `nominal_v`.
    nominal_cell_v: Option<f64>,
}

impl TryFrom<BatteryTable> for BatterySpec {
    type Error = String;

    fn try_from(t: BatteryTable) -> Result<Self, String> {
        if let Some(ah) = t.capacity_ah {
            return Err(format!(
                "capacity_ah = {ah} is no longer read: give the capacity in mA h as capacity_mah = {}",
                ah * 1000.0
            ));
        }
        if let Some(v) = t.nominal_cell_v {
            return Err(format!(
                "nominal_cell_v = {v} is no longer read: give the pack's nominal voltage as nominal_v = {} (cells in series x cell voltage)",
                v * f64::from(t.cells_series)
            ));
        }
        let capacity_mah = t
            .capacity_mah
            .ok_or_else(|| "missing field `capacity_mah` (the rated capacity, mA h)".to_string())?;
        Ok(Self {
            name: t.name,
            default: t.default,
            cells_series: t.cells_series,
            cells_parallel: t.cells_parallel,
            capacity_mah,
            nominal_v: t.nominal_v,
            energy_wh: t.energy_wh,
            mass_kg: t.mass_kg,
            internal_resistance_ohm: t.internal_resistance_ohm,
            r1_ohm: t.r1_ohm,
            r2_ohm_a: t.r2_ohm_a,
            r3_ohm_a: t.r3_ohm_a,
            eq17_min_current_a: t.eq17_min_current_a,
            eq17_max_current_a: t.eq17_max_current_a,
            cutoff_cell_v: t.cutoff_cell_v,
            usable_fraction: t.usable_fraction,
            effective_capacity_fraction: t.effective_capacity_fraction,
            full_charge_cell_v: t.full_charge_cell_v,
            ocv_soc: t.ocv_soc,
            ocv_cell_v: t.ocv_cell_v,
            rc_resistance_ohm: t.rc_resistance_ohm,
            rc_time_constant_s: t.rc_time_constant_s,
            max_current_a: t.max_current_a,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn old_keys_name_the_new_ones() {
        let e = toml::from_str::<BatterySpec>("cells_series = 5\ncapacity_ah = 8.0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("capacity_mah = 8000"), "{e}");
        let e = toml::from_str::<BatterySpec>(
            "cells_series = 5\ncapacity_mah = 8000\nnominal_cell_v = 3.7\n",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("nominal_v = 18.5"), "{e}");
        let e = toml::from_str::<BatterySpec>("cells_series = 5\nvolts = 3\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("volts"), "{e}");
    }

    #[test]
    fn a_description_reads_back_the_same() {
        let text = "name = \"P\"\ncells_series = 6\ncapacity_mah = 4500.0\nnominal_v = 22.2\nenergy_wh = 99.9\nmass_kg = 0.6\ninternal_resistance_ohm = 0.048\ncutoff_cell_v = 3.0\n";
        let spec: BatterySpec = toml::from_str(text).unwrap();
        let again: BatterySpec = toml::from_str(&toml::to_string(&spec).unwrap()).unwrap();
        assert_eq!(spec, again);
    }

    #[test]
    fn the_seed_pack_takes_the_cell_voltage_from_the_pack_voltage_exactly() {
        // Five cells at 3.7 V: 18.5 / 5 is the double nearest 3.7, so the model is the one
        // built from the old per-cell key, bit for bit.
        let spec = BatterySpec {
            cells_series: 5,
            cells_parallel: 4,
            capacity_mah: 8000.0,
            nominal_v: Some(18.5),
            internal_resistance_ohm: Some(0.0699),
            effective_capacity_fraction: Some(0.9),
            ..BatterySpec::default()
        };
        let direct = Battery::new(crate::battery::seed_pack_constants(0.0699)).unwrap();
        assert_eq!(spec.to_seed_model().unwrap(), direct);
    }
}
