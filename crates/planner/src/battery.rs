//! Pack pack for mission integration: charge counting, open-circuit voltage, internal
//! resistance, usable fraction, cut-off voltage.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `Q` | rated capacity | A h |
//! | `s` | state of charge, remaining charge over `Q` | - |
//! | `V_oc(s)` | open-circuit (rest) voltage of the pack, cells in series x cell curve | V |
//! | `R` | pack internal resistance (constant) | ohm |
//! | `P` | power the load (ESCs, avionics) draws at the pack terminals | W |
//! | `I` | pack current | A |
//! | `V_t` | terminal voltage `V_oc - I R` | V |
//!
//! The current that delivers `P` is the smaller root of `R I^2 - V_oc I + P = 0`,
//! `I = 2 P / (V_oc + sqrt(V_oc^2 - 4 R P))` (the form of the propulsion seed's eqs 29-30 with the
//! full-charge voltage replaced by the open-circuit voltage at the present state of charge; with
//! `R = 0` it is `P / V_oc`). No real root means the pack cannot deliver `P`. The state of charge
//! falls by `I dt / (3600 Q)` per step (charge counting).
//!
//! The pack is empty when the state of charge reaches `1 - usable_fraction` or the terminal
//! voltage falls below the cut-off (`cutoff_cell_v` per cell), whichever comes first.
//!
//! # Open-circuit curve
//! By default the generic LiPo rest-voltage curve of `aloft_propulsion::OcvCurve::typical_lipo`
//! (4.20 V full, mean 3.858 V per cell), not scaled: a 6S 4.5 Ah pack then holds 104.2 Wh at rest
//! voltage, of which the resistance loses a few per cent at hover currents, which brings the
//! delivered energy close to the rated `nominal_v x capacity` (99.9 Wh for DJI's TB47D). A measured
//! curve can be given in the battery table.
//!
//! # Deviation
//! The propulsion seed's pack model uses the full-charge voltage throughout a flight (eq 30); the
//! planner follows the state of charge on the open-circuit curve instead, which is what makes the
//! terminal voltage fall along a mission.
//!
//! # Fast path
//! [`Pack::draw`] is the plain model. A mission draws from the pack through a [`PackCursor`]
//! ([`crate::pack_cursor`]), which gives the same draws bit for bit with a shorter chain from one
//! step to the next, and solves a block of steps at once.
//!
//! [`PackCursor`]: crate::pack_cursor::PackCursor

use aloft_propulsion::OcvCurve;

use crate::error::PlannerError;

pub use aloft_propulsion::BatterySpec;

/// Points of the uniform open-circuit table (0.5 % of state of charge apart).
pub(crate) const OCV_TABLE_POINTS: usize = 201;

/// A validated pack.
#[derive(Debug, Clone, PartialEq)]
pub struct Pack {
    name: String,
    cells_series: u32,
    capacity_ah: f64,
    nominal_v: f64,
    energy_wh: f64,
    mass_kg: f64,
    resistance_ohm: f64,
    cutoff_v: f64,
    usable_fraction: f64,
    max_current_a: f64,
    /// Pack open-circuit voltage at `k / (OCV_TABLE_POINTS - 1)`, V.
    ocv_table_v: Vec<f64>,
    /// The RC pair of the equivalent circuit where the pack file gives one: resistance (ohm)
    /// and time constant (s).
    rc_pair: Option<(f64, f64)>,
}

/// The pack's answer to a power demand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PackDraw {
    /// Pack current, A.
    pub current_a: f64,
    /// Terminal voltage, V.
    pub terminal_v: f64,
}

/// The pack model.
impl Pack {
    /// Pack open-circuit voltage at state of charge `soc` (clamped to `[0, 1]`), V.
    #[inline]
    pub fn ocv_v(&self, soc: f64) -> f64 {
        let n = (OCV_TABLE_POINTS - 1) as f64;
        let x = soc.clamp(0.0, 1.0) * n;
        // x in [0, n]; the last interval is closed at its upper end.
        let k = (x as usize).min(OCV_TABLE_POINTS - 2);
        let f = x - k as f64;
        let t = &self.ocv_table_v;
        t[k] + (t[k + 1] - t[k]) * f
    }

    /// The state of charge at which the pack's open-circuit voltage is `ocv_v` (V): the inverse
    /// of [`Self::ocv_v`] (the lowest such state of charge on a plateau), clamped to `[0, 1]`
    /// (below the empty pack's voltage 0, above the full one's 1; NaN gives 0). What a pack's
    /// rested voltage says of its charge; check the voltage against `ocv_v(0.0)` and
    /// `ocv_v(1.0)` where a value outside them means another pack.
    pub fn soc_at_ocv_v(&self, ocv_v: f64) -> f64 {
        let t = &self.ocv_table_v;
        let Some(k) = t.iter().position(|&v| v >= ocv_v) else {
            return if ocv_v.is_nan() { 0.0 } else { 1.0 };
        };
        if k == 0 {
            return 0.0;
        }
        // t[k - 1] < ocv_v <= t[k]: the interval rises.
        let f = (ocv_v - t[k - 1]) / (t[k] - t[k - 1]);
        ((k - 1) as f64 + f) / (OCV_TABLE_POINTS - 1) as f64
    }

    /// Current and terminal voltage when the load draws `power_w` at state of charge `soc`;
    /// `None` when the pack cannot deliver that power (`V_oc^2 < 4 R P`).
    #[inline]
    pub fn draw(&self, power_w: f64, soc: f64) -> Option<PackDraw> {
        self.draw_at_ocv(power_w, self.ocv_v(soc))
    }

    /// [`Self::draw`] at the open-circuit voltage `v_oc` (V) found by the caller.
    #[inline]
    pub(crate) fn draw_at_ocv(&self, power_w: f64, v_oc: f64) -> Option<PackDraw> {
        let disc = v_oc * v_oc - 4.0 * self.resistance_ohm * power_w;
        if disc < 0.0 {
            return None;
        }
        let current_a = 2.0 * power_w / (v_oc + disc.sqrt());
        Some(PackDraw {
            current_a,
            terminal_v: v_oc - current_a * self.resistance_ohm,
        })
    }

    /// Energy the pack can deliver from `from_soc` down to `to_soc` with no resistive loss
    /// (integral of the open-circuit voltage over the charge), W h.
    pub fn rest_energy_wh(&self, from_soc: f64, to_soc: f64) -> f64 {
        // Trapezoidal rule on a fine grid of the piecewise-linear table: exact to rounding when the
        // grid includes the table's nodes; 2000 steps keep the error below 1e-6 relative otherwise.
        let n = 2000;
        let (a, b) = (to_soc.clamp(0.0, 1.0), from_soc.clamp(0.0, 1.0));
        if b <= a {
            return 0.0;
        }
        let h = (b - a) / n as f64;
        let mut sum = 0.5 * (self.ocv_v(a) + self.ocv_v(b));
        for k in 1..n {
            sum += self.ocv_v(a + k as f64 * h);
        }
        sum * h * self.capacity_ah
    }

    /// Pack open-circuit voltage at `k / (OCV_TABLE_POINTS - 1)`, V.
    #[inline]
    pub(crate) fn ocv_table_v(&self) -> &[f64] {
        &self.ocv_table_v
    }

    /// The cell's open-circuit curve this pack flies on (its table, per cell): what a state of
    /// charge estimator reads the voltage through.
    pub fn ocv_curve(&self) -> OcvCurve {
        let n = self.ocv_table_v.len();
        let cells = f64::from(self.cells_series);
        let soc = (0..n).map(|k| k as f64 / (n - 1) as f64).collect();
        let cell_v = self.ocv_table_v.iter().map(|v| v / cells).collect();
        OcvCurve::new(soc, cell_v).unwrap_or_else(|_| OcvCurve::typical_lipo())
    }
}

/// What the pack is.
impl Pack {
    /// Name of the pack.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Cells in series.
    pub fn cells_series(&self) -> u32 {
        self.cells_series
    }
    /// Rated capacity, A h.
    pub fn capacity_ah(&self) -> f64 {
        self.capacity_ah
    }
    /// Rated nominal voltage, V.
    pub fn nominal_v(&self) -> f64 {
        self.nominal_v
    }
    /// Rated energy, W h.
    pub fn rated_energy_wh(&self) -> f64 {
        self.energy_wh
    }
    /// Pack mass, kg.
    pub fn mass_kg(&self) -> f64 {
        self.mass_kg
    }
    /// Internal resistance, ohm.
    pub fn resistance_ohm(&self) -> f64 {
        self.resistance_ohm
    }
    /// Pack cut-off voltage under load, V.
    pub fn cutoff_v(&self) -> f64 {
        self.cutoff_v
    }
    /// Usable fraction of the capacity.
    pub fn usable_fraction(&self) -> f64 {
        self.usable_fraction
    }
    /// State of charge at which the usable charge is exhausted, `1 - usable_fraction`.
    pub fn empty_soc(&self) -> f64 {
        1.0 - self.usable_fraction
    }
    /// The RC pair of the pack's equivalent circuit, where the pack file gives one: resistance
    /// (ohm) and time constant (s).
    pub fn rc_pair(&self) -> Option<(f64, f64)> {
        self.rc_pair
    }
    /// Rated continuous current, A (infinite when none is given).
    pub fn max_current_a(&self) -> f64 {
        self.max_current_a
    }

    /// The same pack with another internal resistance (what-if studies and tests).
    ///
    /// # Errors
    /// A negative or non-finite resistance.
    pub fn with_resistance(&self, resistance_ohm: f64) -> Result<Self, PlannerError> {
        if !(resistance_ohm.is_finite() && resistance_ohm >= 0.0) {
            return Err(PlannerError::InvalidBattery {
                name: self.name.clone(),
                key: "internal_resistance_ohm",
                value: resistance_ohm,
                unit: "ohm",
                expected: "a finite resistance, not negative",
            });
        }
        Ok(Self {
            resistance_ohm,
            ..self.clone()
        })
    }
}

impl Pack {
    /// The same pack with its capacity (and rated energy) multiplied by `factor`: a pack's health,
    /// or a Monte-Carlo scenario's draw of it. Mass, voltages and resistance are kept. With
    /// `factor = 1` the pack is this one bit for bit.
    ///
    /// # Errors
    /// A factor that is not positive and finite, or a capacity beyond 1e7 mA h.
    pub fn with_capacity_factor(&self, factor: f64) -> Result<Self, PlannerError> {
        let capacity_ah = self.capacity_ah * factor;
        if !(factor.is_finite() && factor > 0.0 && capacity_ah * 1000.0 <= 1e7) {
            return Err(PlannerError::InvalidBattery {
                name: self.name.clone(),
                key: "capacity factor",
                value: factor,
                unit: "",
                expected: "a positive finite factor, the capacity at most 1e7 mA h",
            });
        }
        Ok(Self {
            capacity_ah,
            energy_wh: self.energy_wh * factor,
            ..self.clone()
        })
    }
}

impl Pack {
    /// The pack a mission flies with, from its description: validated, with its open-circuit table.
    ///
    /// # Errors
    /// Zero cells, non-positive capacity, voltage, energy or mass, a rated energy that disagrees
    /// with capacity x voltage by more than 1 %, a negative resistance, a cut-off outside the
    /// open-circuit curve, a usable fraction outside `(0, 1]`, an invalid curve.
    pub fn new(spec: &BatterySpec) -> Result<Pack, PlannerError> {
        let bad = |key: &'static str, value: f64, unit: &'static str, expected: &'static str| {
            PlannerError::InvalidBattery {
                name: spec.name.clone(),
                key,
                value,
                unit,
                expected,
            }
        };
        let need = |key: &'static str, value: Option<f64>| {
            value.ok_or_else(|| PlannerError::MissingBatteryKey {
                name: spec.name.clone(),
                key,
            })
        };
        // Positive, finite and at most 1e7 in its unit (10,000 A h, 10 MW h): beyond that a value
        // is a unit slip, not a pack.
        let pos = |key, v: f64, unit| {
            if v.is_finite() && v > 0.0 && v <= 1e7 {
                Ok(v)
            } else {
                Err(bad(key, v, unit, "a positive finite number up to 1e7"))
            }
        };
        if spec.cells_series == 0 {
            return Err(bad("cells_series", 0.0, "", "at least one cell"));
        }
        // A pack holds at least 10 mA h: below it the value is a unit slip or an unset
        // parameter (a logged BAT1_CAPACITY of 1e-38 made a pack that flew 0.0 min).
        let (min_mah, max_mah) = aloft_core::BATTERY_CAPACITY_RANGE_MAH;
        if !(min_mah..=max_mah).contains(&spec.capacity_mah) {
            return Err(bad(
                "capacity_mah",
                spec.capacity_mah,
                "mA h",
                "a capacity from 10 to 1e7 mA h (a smaller pack is a unit slip)",
            ));
        }
        let capacity_ah = spec.capacity_mah / 1000.0;
        let nominal_v = pos("nominal_v", need("nominal_v", spec.nominal_v)?, "V")?;
        let energy_wh = pos("energy_wh", need("energy_wh", spec.energy_wh)?, "W h")?;
        let mass_kg = pos("mass_kg", need("mass_kg", spec.mass_kg)?, "kg")?;
        // Rated energy is printed rounded; 1 % covers rounding of three significant figures.
        if (energy_wh / (capacity_ah * nominal_v) - 1.0).abs() > 0.01 {
            return Err(bad(
                "energy_wh",
                energy_wh,
                "W h",
                "within 1 % of capacity x nominal voltage",
            ));
        }
        let r = need("internal_resistance_ohm", spec.internal_resistance_ohm)?;
        if !(r.is_finite() && (0.0..=1e3).contains(&r)) {
            return Err(bad(
                "internal_resistance_ohm",
                r,
                "ohm",
                "a finite resistance from 0 to 1000 ohm",
            ));
        }
        let u = spec.usable_fraction;
        if !(u.is_finite() && u > 0.0 && u <= 1.0) {
            return Err(bad("usable_fraction", u, "", "a fraction in (0, 1]"));
        }
        let curve = match (&spec.ocv_soc, &spec.ocv_cell_v) {
            (None, None) => OcvCurve::typical_lipo(),
            (Some(s), Some(v)) => OcvCurve::new(s.clone(), v.clone())?,
            (Some(_), None) | (None, Some(_)) => {
                return Err(bad(
                    "ocv_soc/ocv_cell_v",
                    f64::NAN,
                    "",
                    "both keys or neither",
                ))
            }
        };
        let cells = f64::from(spec.cells_series);
        let cut = need("cutoff_cell_v", spec.cutoff_cell_v)?;
        if !(cut.is_finite() && cut > 0.0 && cut < curve.cell_v(1.0)) {
            return Err(bad(
                "cutoff_cell_v",
                cut,
                "V",
                "positive and below the full-charge cell voltage",
            ));
        }
        let max_current_a = match spec.max_current_a {
            Some(i) => pos("max_current_a", i, "A")?,
            None => f64::INFINITY,
        };
        let ocv_table_v = (0..OCV_TABLE_POINTS)
            .map(|k| cells * curve.cell_v(k as f64 / (OCV_TABLE_POINTS - 1) as f64))
            .collect();
        let rc_pair = match (spec.rc_resistance_ohm, spec.rc_time_constant_s) {
            // No resistance is a pair that holds no sag (a curve fitted under load holds it).
            (Some(r), Some(tau)) if r.is_finite() && (0.0..=1e7).contains(&r) => {
                Some((r, pos("rc_time_constant_s", tau, "s")?))
            }
            (Some(r), Some(_)) => {
                return Err(bad(
                    "rc_resistance_ohm",
                    r,
                    "ohm",
                    "zero or positive, finite",
                ))
            }
            (None, None) => None,
            (Some(r), None) => {
                return Err(bad(
                    "rc_resistance_ohm",
                    r,
                    "ohm",
                    "given with rc_time_constant_s",
                ))
            }
            (None, Some(t)) => {
                return Err(bad(
                    "rc_time_constant_s",
                    t,
                    "s",
                    "given with rc_resistance_ohm",
                ))
            }
        };
        Ok(Pack {
            name: spec.name.clone(),
            cells_series: spec.cells_series,
            capacity_ah,
            nominal_v,
            energy_wh,
            mass_kg,
            resistance_ohm: r,
            cutoff_v: cut * cells,
            usable_fraction: u,
            max_current_a,
            ocv_table_v,
            rc_pair,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::tb47d;

    #[test]
    fn draw_delivers_the_power() {
        let b = Pack::new(&tb47d()).unwrap();
        for (p, s) in [(50.0, 0.9), (450.0, 0.5), (900.0, 0.1)] {
            let d = b.draw(p, s).unwrap();
            // terminal power equals demand up to rounding of the closed-form root
            assert!((d.current_a * d.terminal_v / p - 1.0).abs() < 1e-12);
            assert!(d.terminal_v < b.ocv_v(s));
        }
        // V_oc^2 / 4R at 100 %: 25.2^2 / 0.192 = 3307.5 W; beyond it there is no root.
        assert!(b.draw(3400.0, 1.0).is_none());
    }

    #[test]
    fn ocv_table_matches_the_curve() {
        let b = Pack::new(&tb47d()).unwrap();
        let c = OcvCurve::typical_lipo();
        for s in [0.0, 0.03, 0.5, 0.77, 1.0] {
            // the table holds the curve's nodes (every 5 %) exactly, so linear interpolation agrees
            assert!((b.ocv_v(s) - 6.0 * c.cell_v(s)).abs() < 1e-12, "{s}");
        }
        // mean rest voltage 3.858 V per cell: 6 x 3.858 x 4.5 = 104.2 W h
        assert!((b.rest_energy_wh(1.0, 0.0) - 6.0 * 3.85825 * 4.5).abs() < 1e-6);
    }

    /// The rested voltage's state of charge is the inverse of the open-circuit curve, and
    /// clamped outside it.
    #[test]
    fn the_state_of_charge_at_a_rest_voltage_inverts_the_curve() {
        let b = Pack::new(&tb47d()).unwrap();
        for s in [0.0, 0.03, 0.335, 0.5, 0.77, 0.999, 1.0] {
            // Linear interpolation of one table, inverted: rounding only.
            assert!((b.soc_at_ocv_v(b.ocv_v(s)) - s).abs() < 1e-12, "{s}");
        }
        // 6 x 3.80 V is 40 % on the generic LiPo curve.
        assert!((b.soc_at_ocv_v(22.8) - 0.40).abs() < 1e-12);
        // Clamped to the ends: exact.
        for (v, soc) in [(10.0, 0.0), (30.0, 1.0), (f64::NAN, 0.0)] {
            assert!((b.soc_at_ocv_v(v) - soc).abs() < 1e-15, "{v}");
        }
    }

    #[test]
    fn a_capacity_factor_scales_the_charge_and_one_is_the_pack_itself() {
        let b = Pack::new(&tb47d()).unwrap();
        assert_eq!(b.with_capacity_factor(1.0).unwrap(), b);
        let h = b.with_capacity_factor(0.8).unwrap();
        // 4.5 A h x 0.8 and 99.9 Wh x 0.8, one rounding each.
        assert!((h.capacity_ah() - 3.6).abs() < 1e-12);
        assert!((h.rated_energy_wh() - 79.92).abs() < 1e-12);
        assert!((h.rest_energy_wh(1.0, 0.0) / b.rest_energy_wh(1.0, 0.0) - 0.8).abs() < 1e-12);
        assert!(b.with_capacity_factor(0.0).is_err());
        assert!(b.with_capacity_factor(f64::NAN).is_err());
    }

    #[test]
    fn bad_packs_are_named() {
        let mut s = tb47d();
        s.energy_wh = Some(120.0);
        let e = Pack::new(&s).unwrap_err().to_string();
        assert!(e.contains("energy_wh") && e.contains("120"), "{e}");
        let mut s = tb47d();
        s.usable_fraction = 1.5;
        assert!(Pack::new(&s).unwrap_err().to_string().contains("usable"));
        let mut s = tb47d();
        s.internal_resistance_ohm = Some(-0.1);
        assert!(Pack::new(&s).is_err());
        let mut s = tb47d();
        s.cutoff_cell_v = Some(4.5);
        assert!(Pack::new(&s).is_err());
    }
}
