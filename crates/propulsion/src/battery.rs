//! Lithium-polymer battery pack, propulsion seed eqs (16)-(17) and (29)-(31).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `V_f` | full-charge pack voltage, cells in series x 4.1 V (eq 30) | V |
//! | `V_0` | nominal pack voltage, cells in series x 3.7 V (eq 31) | V |
//! | `C_b` | rated capacity | A h |
//! | `C_e` | effective-capacity coefficient: fraction of `C_b` available before the voltage roll-off | - |
//! | `R_b` | internal resistance, constant or eq (17) | ohm |
//! | `I_ps` | pack current | A |
//! | `P_ps` | power delivered to the load (ESCs) | W |
//! | `P_t` | total power drawn from the cells, `P_t = V_f I_ps` (eq 30) | W |
//! | `D` | flight duration | min |
//!
//! Eq (29): `P_ps = P_t - I_ps^2 R_b`, so the current that delivers `P_ps` is the smaller root of
//! `R_b I^2 - V_f I + P_ps = 0`. There is no real root when `P_ps > V_f^2 / (4 R_b)`: the pack
//! cannot deliver that power, and [`Battery::current_for_power_a`] returns
//! [`PropulsionError::PowerExceedsPack`]. Heat in the pack is `I_ps^2 R_b`. Eq (31):
//! `D = 60 V_0 C_b C_e / (V_f I_ps)`.
//!
//! Internal resistance eq (17): `R_b(I) = r_1 + r_2 ln(I) / I + r_3 / I`. The seed notes it is
//! ill-behaved at small currents (the `1/I` terms diverge); it is used only within a stated
//! current range, and outside that range `R_b` is held at its value at the nearest end of the range.
//!
//! # Deviation
//! Clamping eq (17) outside its valid range is this crate's choice (the seed only says the model
//! is ill-behaved at small currents); [`Battery::resistance_in_valid_range`] reports whether a
//! current lies inside it.

use crate::error::{
    current_limit, finite, fraction, non_negative, positive, resistance, voltage, PropulsionError,
};

/// Full-charge cell voltage used by the seed (eq 30), V.
pub const SEED_FULL_CELL_V: f64 = 4.1;
/// Nominal cell voltage used by the seed (eq 31), V.
pub const SEED_NOMINAL_CELL_V: f64 = 3.7;

/// Internal-resistance model of a pack.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InternalResistance {
    /// Constant resistance, ohm.
    Constant {
        /// Pack resistance, ohm.
        resistance_ohm: f64,
    },
    /// Seed eq (17), `R_b(I) = r1 + r2 ln(I)/I + r3/I`, valid between two currents.
    Logarithmic(Eq17Resistance),
}

/// Seed eq (17), `R_b(I) = r1 + r2 ln(I)/I + r3/I`, with the currents between which it is trusted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eq17Resistance {
    /// `r_1`, ohm.
    pub r1_ohm: f64,
    /// `r_2`, ohm A (per unit of ln A).
    pub r2_ohm_a: f64,
    /// `r_3`, ohm A (i.e. V).
    pub r3_ohm_a: f64,
    /// Smallest current where eq (17) is trusted, A.
    pub min_current_a: f64,
    /// Largest current where eq (17) is trusted, A.
    pub max_current_a: f64,
}

impl InternalResistance {
    /// Resistance at `current_a`, ohm (clamped to the valid range for eq 17).
    pub fn at(&self, current_a: f64) -> f64 {
        match self {
            InternalResistance::Constant { resistance_ohm } => *resistance_ohm,
            InternalResistance::Logarithmic(eq17) => eq17.at(current_a),
        }
    }

    /// Check the model: a constant resistance must be finite and positive; eq (17) needs finite
    /// coefficients, a valid current range and a positive resistance over all of it.
    pub(crate) fn validate(&self) -> Result<(), PropulsionError> {
        match *self {
            InternalResistance::Constant { resistance_ohm } => {
                let r = resistance("battery internal_resistance_ohm", resistance_ohm)?;
                if r <= 0.0 {
                    return Err(PropulsionError::InvalidResistance {
                        name: "battery internal_resistance_ohm (must be > 0)",
                        resistance_ohm: r,
                    });
                }
                Ok(())
            }
            InternalResistance::Logarithmic(eq17) => eq17.validate(),
        }
    }
}

impl Eq17Resistance {
    /// Eq (17) at `current_a` without clamping: `r1 + r2 ln(I)/I + r3/I`, ohm.
    pub fn resistance_ohm(&self, current_a: f64) -> f64 {
        self.r1_ohm + self.r2_ohm_a * current_a.ln() / current_a + self.r3_ohm_a / current_a
    }

    /// Eq (17) at `current_a` clamped to the valid range, ohm.
    pub fn at(&self, current_a: f64) -> f64 {
        self.resistance_ohm(current_a.clamp(self.min_current_a, self.max_current_a))
    }

    /// Whether `current_a` lies where eq (17) is trusted.
    pub fn in_valid_range(&self, current_a: f64) -> bool {
        (self.min_current_a..=self.max_current_a).contains(&current_a)
    }

    /// Finite coefficients, a positive, finite and non-empty current range, and a positive
    /// resistance over all of it.
    fn validate(&self) -> Result<(), PropulsionError> {
        finite("battery r1_ohm", self.r1_ohm, "ohm or ohm A")?;
        finite("battery r2_ohm_a", self.r2_ohm_a, "ohm or ohm A")?;
        finite("battery r3_ohm_a", self.r3_ohm_a, "ohm or ohm A")?;
        self.check_range()?;
        self.check_positive()
    }

    /// The current range where eq (17) is trusted: positive, finite, and not empty.
    fn check_range(&self) -> Result<(), PropulsionError> {
        let (min_current_a, max_current_a) = (self.min_current_a, self.max_current_a);
        positive("battery eq17 min_current_a", min_current_a, "A")?;
        positive("battery eq17 max_current_a", max_current_a, "A")?;
        let expected = "a current above eq17 min_current_a";
        let ok = max_current_a > min_current_a;
        aloft_core::parameter(
            "battery eq17 max_current_a",
            max_current_a,
            "A",
            ok,
            expected,
        )?;
        Ok(())
    }

    /// Eq (17) must give a positive resistance over its valid range (checked at 65 currents).
    fn check_positive(&self) -> Result<(), PropulsionError> {
        let n = 64;
        for k in 0..=n {
            let span = self.max_current_a - self.min_current_a;
            let i = self.min_current_a + span * k as f64 / n as f64;
            let r = self.resistance_ohm(i);
            if r.is_nan() || r <= 0.0 {
                return Err(PropulsionError::InvalidResistance {
                    name: "battery eq17 resistance within its valid range",
                    resistance_ohm: r,
                });
            }
        }
        Ok(())
    }
}

/// A LiPo pack.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Battery {
    c: BatteryConstants,
    max_power_w: f64,
    current_at_max_power_a: f64,
}

/// The constants of a pack, as [`Battery::new`] checks them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BatteryConstants {
    /// Cells in series.
    pub cells_series: u32,
    /// Cells in parallel.
    pub cells_parallel: u32,
    /// Rated capacity of the pack, A h.
    pub capacity_ah: f64,
    /// Effective-capacity coefficient `C_e` of eq (31), in `(0, 1]`.
    pub effective_capacity: f64,
    /// Full-charge cell voltage, V (seed: 4.1 V).
    pub full_cell_v: f64,
    /// Nominal cell voltage, V (seed: 3.7 V).
    pub nominal_cell_v: f64,
    /// Internal resistance model.
    pub resistance: InternalResistance,
    /// Rated continuous current, A (`f64::INFINITY` for none).
    pub max_current_a: f64,
}

fn check_cell_counts(cells_series: u32, cells_parallel: u32) -> Result<(), PropulsionError> {
    if cells_series == 0 {
        return Err(PropulsionError::InvalidCount {
            name: "battery cells_series",
            count: cells_series,
            expected: "at least one cell in series",
        });
    }
    if cells_parallel == 0 {
        return Err(PropulsionError::InvalidCount {
            name: "battery cells_parallel",
            count: cells_parallel,
            expected: "at least one cell in parallel",
        });
    }
    Ok(())
}

/// Full-charge and nominal cell voltages: each valid, the nominal not above the full charge.
fn check_cell_voltages(
    full_cell_v: f64,
    nominal_cell_v: f64,
) -> Result<(f64, f64), PropulsionError> {
    let full_cell_v = voltage("battery full_charge_cell_v", full_cell_v)?;
    let nominal_cell_v = voltage("battery nominal_cell_v", nominal_cell_v)?;
    if nominal_cell_v > full_cell_v {
        return Err(PropulsionError::InvalidVoltage {
            name: "battery nominal_cell_v (above full_charge_cell_v)",
            voltage_v: nominal_cell_v,
        });
    }
    Ok((full_cell_v, nominal_cell_v))
}

impl Battery {
    /// A pack of `c.cells_series` x `c.cells_parallel` cells.
    ///
    /// # Errors
    /// Zero cell counts, non-positive capacity or voltages, nominal above full-charge voltage,
    /// `C_e` outside `(0, 1]`, negative resistance coefficients, an invalid eq (17) range.
    pub fn new(c: BatteryConstants) -> Result<Self, PropulsionError> {
        check_cell_counts(c.cells_series, c.cells_parallel)?;
        let capacity_ah = positive("battery capacity_ah", c.capacity_ah, "A h")?;
        let effective_capacity = fraction(
            "battery effective_capacity_fraction",
            c.effective_capacity,
            false,
            true,
        )?;
        let (full_cell_v, nominal_cell_v) = check_cell_voltages(c.full_cell_v, c.nominal_cell_v)?;
        c.resistance.validate()?;
        let max_current_a = current_limit("battery max_current_a", c.max_current_a)?;
        let c = BatteryConstants {
            capacity_ah,
            effective_capacity,
            full_cell_v,
            nominal_cell_v,
            max_current_a,
            ..c
        };
        let mut b = Self {
            c,
            max_power_w: 0.0,
            current_at_max_power_a: 0.0,
        };
        let (i_star, p_star) = b.find_max_power();
        b.current_at_max_power_a = i_star;
        b.max_power_w = p_star;
        Ok(b)
    }

    fn delivered_w(&self, current_a: f64) -> f64 {
        self.full_charge_v() * current_a - self.c.resistance.at(current_a) * current_a * current_a
    }

    fn find_max_power(&self) -> (f64, f64) {
        match self.c.resistance {
            InternalResistance::Constant { resistance_ohm } => {
                let vf = self.full_charge_v();
                (
                    vf / (2.0 * resistance_ohm),
                    vf * vf / (4.0 * resistance_ohm),
                )
            }
            InternalResistance::Logarithmic(_) => {
                // Coarse scan then golden-section refinement of the delivered power.
                let vf = self.full_charge_v();
                let r_lo = (0..=64)
                    .map(|k| self.c.resistance.at(1e-3 + k as f64 * 1e4 / 64.0))
                    .fold(f64::INFINITY, f64::min);
                let i_hi = vf / r_lo;
                let n = 400;
                let mut best = (0.0, 0.0);
                for k in 1..=n {
                    let i = i_hi * k as f64 / n as f64;
                    let p = self.delivered_w(i);
                    if p > best.1 {
                        best = (i, p);
                    }
                }
                let (mut a, mut b) = (
                    (best.0 - i_hi / n as f64).max(0.0),
                    (best.0 + i_hi / n as f64).min(i_hi),
                );
                let g = 0.618_033_988_749_895;
                for _ in 0..80 {
                    let c = b - g * (b - a);
                    let d = a + g * (b - a);
                    if self.delivered_w(c) > self.delivered_w(d) {
                        b = d;
                    } else {
                        a = c;
                    }
                }
                let i = 0.5 * (a + b);
                (i, self.delivered_w(i))
            }
        }
    }

    /// Cells in series.
    pub fn cells_series(&self) -> u32 {
        self.c.cells_series
    }

    /// Cells in parallel.
    pub fn cells_parallel(&self) -> u32 {
        self.c.cells_parallel
    }

    /// Rated capacity `C_b`, A h.
    pub fn capacity_ah(&self) -> f64 {
        self.c.capacity_ah
    }

    /// Effective-capacity coefficient `C_e`.
    pub fn effective_capacity(&self) -> f64 {
        self.c.effective_capacity
    }

    /// Full-charge pack voltage `V_f` (eq 30), V.
    pub fn full_charge_v(&self) -> f64 {
        self.c.cells_series as f64 * self.c.full_cell_v
    }

    /// Nominal pack voltage `V_0` (eq 31), V.
    pub fn nominal_v(&self) -> f64 {
        self.c.cells_series as f64 * self.c.nominal_cell_v
    }

    /// Internal-resistance model.
    pub fn internal_resistance(&self) -> InternalResistance {
        self.c.resistance
    }

    /// Internal resistance at `current_a`, ohm.
    pub fn resistance_ohm(&self, current_a: f64) -> f64 {
        self.c.resistance.at(current_a)
    }

    /// Whether `current_a` lies where the resistance model is trusted (always true for a
    /// constant resistance).
    pub fn resistance_in_valid_range(&self, current_a: f64) -> bool {
        match self.c.resistance {
            InternalResistance::Constant { .. } => true,
            InternalResistance::Logarithmic(eq17) => eq17.in_valid_range(current_a),
        }
    }

    /// Largest power the pack can deliver to its load, W (`V_f^2 / 4 R_b` for constant `R_b`).
    pub fn max_power_w(&self) -> f64 {
        self.max_power_w
    }

    /// Rated continuous current, A.
    pub fn max_current_a(&self) -> f64 {
        self.c.max_current_a
    }

    /// Eqs (29)-(30): the pack current that delivers `power_w` to the load, A.
    ///
    /// # Errors
    /// [`PropulsionError::PowerExceedsPack`] when no current delivers that power,
    /// [`PropulsionError::PackCurrentLimit`] when the current exceeds the pack rating,
    /// [`PropulsionError::InvalidParameter`] for a negative or non-finite power.
    pub fn current_for_power_a(&self, power_w: f64) -> Result<f64, PropulsionError> {
        let power_w = non_negative("power asked of the pack (power_w)", power_w, "W")?;
        if power_w > self.max_power_w {
            return Err(PropulsionError::PowerExceedsPack {
                power_w,
                max_power_w: self.max_power_w,
            });
        }
        let vf = self.full_charge_v();
        let i = match self.c.resistance {
            InternalResistance::Constant { resistance_ohm } => {
                // Smaller root of R I^2 - V_f I + P = 0, written in the cancellation-free form
                // 2P / (V_f + sqrt(V_f^2 - 4 R P)).
                let disc = (vf * vf - 4.0 * resistance_ohm * power_w).max(0.0);
                2.0 * power_w / (vf + disc.sqrt())
            }
            InternalResistance::Logarithmic(_) => {
                // Delivered power rises monotonically on [0, I*]: bisection.
                let below = |i| self.delivered_w(i) < power_w;
                let (a, b) = aloft_core::bisect(0.0, self.current_at_max_power_a, 60, below);
                0.5 * (a + b)
            }
        };
        if i > self.c.max_current_a {
            return Err(PropulsionError::PackCurrentLimit {
                current_a: i,
                limit_a: self.c.max_current_a,
            });
        }
        Ok(i)
    }

    /// Eq (30): total power drawn from the cells at `current_a`, `P_t = V_f I`, W.
    pub fn total_power_w(&self, current_a: f64) -> f64 {
        self.full_charge_v() * current_a
    }

    /// Heat dissipated in the pack at `current_a`, `I^2 R_b(I)`, W.
    pub fn heat_w(&self, current_a: f64) -> f64 {
        self.c.resistance.at(current_a) * current_a * current_a
    }

    /// Terminal voltage at `current_a` in the seed's model, `V_f - I R_b(I)`, V.
    pub fn terminal_v(&self, current_a: f64) -> f64 {
        self.full_charge_v() - self.c.resistance.at(current_a) * current_a
    }

    /// Eq (31): flight duration at a constant pack current, minutes.
    pub fn flight_duration_min(&self, current_a: f64) -> f64 {
        60.0 * self.nominal_v() * self.c.capacity_ah * self.c.effective_capacity
            / (self.full_charge_v() * current_a)
    }
}

/// Open-circuit (rest) voltage of a LiPo cell against state of charge.
///
/// Piecewise linear between tabulated points `(state of charge, cell voltage)`.
///
/// # Source and shape
/// The seeds give only two points (4.1 V "full charge" and 3.7 V "nominal" per cell). The
/// default curve, [`OcvCurve::typical_lipo`], is the rest-voltage table of a LiPo cell widely
/// reproduced by hobby-battery vendors (4.20 V at 100 %, a plateau of 3.75-3.85 V over the middle,
/// the knee below 10 % falling to 3.27 V at 0 %). It is a generic shape, not a measurement of any
/// pack in `../shared/data`; a measured curve can be supplied with [`OcvCurve::new`]. The seed's
/// 4.1 V "full charge" lies at about 90 % on this curve.
#[derive(Debug, Clone, PartialEq)]
pub struct OcvCurve {
    soc: Vec<f64>,
    cell_v: Vec<f64>,
}

impl OcvCurve {
    /// A curve from points with strictly increasing state of charge in `[0, 1]` and
    /// non-decreasing positive voltage.
    ///
    /// # Errors
    /// Fewer than two points, mismatched lengths, non-monotone or out-of-range values.
    pub fn new(soc: Vec<f64>, cell_v: Vec<f64>) -> Result<Self, PropulsionError> {
        if soc.len() != cell_v.len() {
            return Err(PropulsionError::LengthMismatch {
                what: "ocv cell_v",
                expected: soc.len(),
                found: cell_v.len(),
            });
        }
        if soc.len() < 2 {
            return Err(PropulsionError::InsufficientData {
                model: "open-circuit voltage curve",
                points: soc.len(),
                required: 2,
            });
        }
        for (k, (&s, &v)) in soc.iter().zip(&cell_v).enumerate() {
            fraction("ocv state_of_charge", s, true, true)?;
            voltage("ocv cell_v", v)?;
            if k > 0 && (s <= soc[k - 1] || v < cell_v[k - 1]) {
                return Err(aloft_core::InvalidParameter {
                    name: "ocv state_of_charge",
                    value: s,
                    unit: "(fraction)",
                    expected: "strictly increasing state of charge with non-decreasing voltage",
                }
                .into());
            }
        }
        Ok(Self { soc, cell_v })
    }

    /// The generic LiPo rest-voltage curve described in the type's docs.
    pub fn typical_lipo() -> Self {
        let soc = vec![
            0.0, 0.05, 0.10, 0.15, 0.20, 0.25, 0.30, 0.35, 0.40, 0.45, 0.50, 0.55, 0.60, 0.65,
            0.70, 0.75, 0.80, 0.85, 0.90, 0.95, 1.0,
        ];
        let cell_v = vec![
            3.27, 3.61, 3.69, 3.71, 3.73, 3.75, 3.77, 3.79, 3.80, 3.82, 3.84, 3.85, 3.87, 3.91,
            3.95, 3.98, 4.02, 4.08, 4.11, 4.15, 4.20,
        ];
        Self { soc, cell_v }
    }

    /// Cell rest voltage at state of charge `soc` (clamped to `[0, 1]`), V.
    pub fn cell_v(&self, soc: f64) -> f64 {
        let s = if soc.is_nan() {
            0.0
        } else {
            soc.clamp(self.soc[0], self.soc[self.soc.len() - 1])
        };
        // The first point at or above `s` (the points rise strictly: a binary search finds the
        // one a scan from the start would).
        let first = self.soc.partition_point(|&x| x < s);
        let k = match (first < self.soc.len()).then_some(first) {
            Some(0) | None => {
                return if s <= self.soc[0] {
                    self.cell_v[0]
                } else {
                    self.cell_v[self.cell_v.len() - 1]
                }
            }
            Some(k) => k,
        };
        let (s0, s1) = (self.soc[k - 1], self.soc[k]);
        let (v0, v1) = (self.cell_v[k - 1], self.cell_v[k]);
        v0 + (v1 - v0) * (s - s0) / (s1 - s0)
    }

    /// Pack rest voltage for `cells_series` cells, V.
    pub fn pack_v(&self, soc: f64, cells_series: u32) -> f64 {
        self.cell_v(soc) * cells_series as f64
    }

    /// State of charge at which the cell rest voltage equals `cell_v` (inverse of
    /// [`OcvCurve::cell_v`], the lowest such state of charge on a plateau), clamped to `[0, 1]`.
    pub fn soc_at(&self, cell_v: f64) -> f64 {
        if cell_v <= self.cell_v[0] {
            return self.soc[0];
        }
        for k in 1..self.soc.len() {
            if cell_v <= self.cell_v[k] {
                let (v0, v1) = (self.cell_v[k - 1], self.cell_v[k]);
                if v1 <= v0 {
                    return self.soc[k - 1];
                }
                return self.soc[k - 1]
                    + (self.soc[k] - self.soc[k - 1]) * (cell_v - v0) / (v1 - v0);
            }
        }
        self.soc[self.soc.len() - 1]
    }
}

/// The pack the crate's tests fly: 5S4P, 8 A h, `C_e` 0.9, the seed's cell voltages, a constant
/// `resistance_ohm`, no current limit.
#[cfg(test)]
pub(crate) fn seed_pack_constants(resistance_ohm: f64) -> BatteryConstants {
    BatteryConstants {
        cells_series: 5,
        cells_parallel: 4,
        capacity_ah: 8.0,
        effective_capacity: 0.9,
        full_cell_v: SEED_FULL_CELL_V,
        nominal_cell_v: SEED_NOMINAL_CELL_V,
        resistance: InternalResistance::Constant { resistance_ohm },
        max_current_a: f64::INFINITY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain lookup the binary search replaced: the first point at or above `s` by a scan.
    fn cell_v_by_scan(c: &OcvCurve, soc: f64) -> f64 {
        let s = soc.clamp(c.soc[0], c.soc[c.soc.len() - 1]);
        match c.soc.iter().position(|&x| x >= s) {
            Some(0) | None => {
                if s <= c.soc[0] {
                    c.cell_v[0]
                } else {
                    c.cell_v[c.cell_v.len() - 1]
                }
            }
            Some(k) => {
                let (s0, s1) = (c.soc[k - 1], c.soc[k]);
                let (v0, v1) = (c.cell_v[k - 1], c.cell_v[k]);
                v0 + (v1 - v0) * (s - s0) / (s1 - s0)
            }
        }
    }

    #[test]
    fn the_binary_search_looks_up_what_the_scan_did_bit_for_bit() {
        let c = OcvCurve::typical_lipo();
        for k in -100..=1100 {
            let soc = f64::from(k) / 1000.0;
            assert_eq!(
                c.cell_v(soc).to_bits(),
                cell_v_by_scan(&c, soc).to_bits(),
                "{soc}"
            );
        }
        for &soc in &c.soc {
            assert_eq!(c.cell_v(soc).to_bits(), cell_v_by_scan(&c, soc).to_bits());
        }
    }

    fn seed_pack(r: f64) -> Battery {
        Battery::new(seed_pack_constants(r)).unwrap()
    }

    #[test]
    fn eq29_30_current_delivers_the_power() {
        let b = seed_pack(0.07);
        for p in [10.0, 300.0, 745.0, 1400.0] {
            let i = b.current_for_power_a(p).unwrap();
            let delivered = b.total_power_w(i) - b.heat_w(i);
            // closed-form root; relative 1e-10 is rounding
            assert!((delivered / p - 1.0).abs() < 1e-10, "{p} {i}");
        }
    }

    #[test]
    fn power_beyond_the_pack_is_a_typed_error() {
        let b = seed_pack(0.07);
        // V_f^2 / (4 R) = 20.5^2 / 0.28 = 1500.9 W
        assert!((b.max_power_w() - 20.5 * 20.5 / 0.28).abs() < 1e-9);
        assert!(matches!(
            b.current_for_power_a(1600.0),
            Err(PropulsionError::PowerExceedsPack { .. })
        ));
        assert!(b.current_for_power_a(-1.0).is_err());
        assert!(b.current_for_power_a(f64::NAN).is_err());
    }

    #[test]
    fn eq17_pack_solves_and_reports_its_range() {
        let b = Battery::new(BatteryConstants {
            resistance: InternalResistance::Logarithmic(Eq17Resistance {
                r1_ohm: 0.05,
                r2_ohm_a: 0.02,
                r3_ohm_a: 0.3,
                min_current_a: 5.0,
                max_current_a: 60.0,
            }),
            ..seed_pack_constants(0.07)
        })
        .unwrap();
        let i = b.current_for_power_a(700.0).unwrap();
        // bisection to 60 halvings: far below 1e-6 W
        assert!((b.total_power_w(i) - b.heat_w(i) - 700.0).abs() < 1e-6);
        assert!(b.resistance_in_valid_range(i));
        assert!(!b.resistance_in_valid_range(1.0));
        assert!(b.current_for_power_a(b.max_power_w() * 1.01).is_err());
    }

    #[test]
    fn eq31_duration() {
        let b = seed_pack(0.07);
        // 60 * 18.5 * 8 * 0.9 / (20.5 * 42.5) = 9.173 min
        let d = b.flight_duration_min(42.5);
        assert!((d - 60.0 * 18.5 * 8.0 * 0.9 / (20.5 * 42.5)).abs() < 1e-12);
    }

    #[test]
    fn bad_battery_inputs() {
        let good = BatteryConstants {
            cells_parallel: 1,
            ..seed_pack_constants(0.07)
        };
        assert!(Battery::new(BatteryConstants {
            cells_series: 0,
            ..good
        })
        .is_err());
        assert!(Battery::new(BatteryConstants {
            capacity_ah: 0.0,
            ..good
        })
        .is_err());
        assert!(Battery::new(BatteryConstants {
            effective_capacity: 1.2,
            ..good
        })
        .is_err());
        assert!(matches!(
            Battery::new(BatteryConstants {
                full_cell_v: -4.1,
                ..good
            }),
            Err(PropulsionError::InvalidVoltage { .. })
        ));
        assert!(Battery::new(BatteryConstants {
            full_cell_v: 3.6,
            ..good
        })
        .is_err());
    }

    #[test]
    fn ocv_curve_is_monotone_and_invertible() {
        let c = OcvCurve::typical_lipo();
        let mut last = 0.0;
        for k in 0..=100 {
            let v = c.cell_v(k as f64 / 100.0);
            assert!(v >= last);
            last = v;
        }
        assert!((c.cell_v(1.0) - 4.2).abs() < 1e-12);
        assert!((c.cell_v(0.0) - 3.27).abs() < 1e-12);
        for s in [0.03, 0.33, 0.5, 0.77, 0.97] {
            // piecewise-linear inverse: exact up to rounding
            assert!((c.soc_at(c.cell_v(s)) - s).abs() < 1e-9, "{s}");
        }
        assert!(OcvCurve::new(vec![0.0, 0.5], vec![3.8, 3.7]).is_err());
    }
}
