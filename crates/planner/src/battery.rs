//! Battery pack for mission integration: charge counting, open-circuit voltage, internal
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

use aloft_propulsion::OcvCurve;
use multiversion::multiversion;
use serde::{Deserialize, Serialize};

use crate::error::PlannerError;

fn default_usable() -> f64 {
    1.0
}

/// A `[[battery]]` table of a vehicle file. Units are in the key names; unknown keys are rejected.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BatterySpec {
    /// Name used on the command line (`--battery`).
    pub name: String,
    /// The vehicle's default pack (at most one per vehicle; else the first).
    #[serde(default)]
    pub default: bool,
    /// Cells in series.
    pub cells_series: u32,
    /// Rated capacity, mA h.
    pub capacity_mah: f64,
    /// Rated (nominal) pack voltage, V.
    pub nominal_v: f64,
    /// Rated energy, W h (checked against `capacity x nominal voltage` within 1 %).
    pub energy_wh: f64,
    /// Pack mass, kg.
    pub mass_kg: f64,
    /// Pack internal resistance, ohm (0 allowed: an ideal source).
    pub internal_resistance_ohm: f64,
    /// Cut-off voltage per cell under load, V.
    pub cutoff_cell_v: f64,
    /// Fraction of the rated capacity that may be drawn, in `(0, 1]` (default 1).
    #[serde(default = "default_usable")]
    pub usable_fraction: f64,
    /// Open-circuit curve: state-of-charge points in `[0, 1]`, increasing (default: typical LiPo).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ocv_soc: Option<Vec<f64>>,
    /// Open-circuit curve: cell voltage at each `ocv_soc` point, V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ocv_cell_v: Option<Vec<f64>>,
    /// Rated continuous current, A (default: no limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_current_a: Option<f64>,
}

/// Points of the uniform open-circuit table (0.5 % of state of charge apart).
const OCV_TABLE_POINTS: usize = 201;

/// A validated pack.
#[derive(Debug, Clone, PartialEq)]
pub struct Battery {
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
}

/// One step of [`PackCursor::draw_block`]: the draw and the state of charge after it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PackStep {
    /// Pack current, A.
    pub current_a: f64,
    /// Terminal voltage, V.
    pub terminal_v: f64,
    /// State of charge after the step.
    pub soc_after: f64,
}

/// The pack's answer to a power demand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PackDraw {
    /// Pack current, A.
    pub current_a: f64,
    /// Terminal voltage, V.
    pub terminal_v: f64,
}

impl BatterySpec {
    /// Validate and build the pack model.
    ///
    /// # Errors
    /// Zero cells, non-positive capacity, voltage, energy or mass, a rated energy that disagrees
    /// with capacity x voltage by more than 1 %, a negative resistance, a cut-off outside the
    /// open-circuit curve, a usable fraction outside `(0, 1]`, an invalid curve.
    pub fn to_battery(&self) -> Result<Battery, PlannerError> {
        let bad = |key: &'static str, value: f64, unit: &'static str, expected: &'static str| {
            PlannerError::InvalidBattery {
                name: self.name.clone(),
                key,
                value,
                unit,
                expected,
            }
        };
        let pos = |key, v: f64, unit| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(bad(key, v, unit, "a positive finite number"))
            }
        };
        if self.cells_series == 0 {
            return Err(bad("cells_series", 0.0, "", "at least one cell"));
        }
        let capacity_ah = pos("capacity_mah", self.capacity_mah, "mA h")? / 1000.0;
        let nominal_v = pos("nominal_v", self.nominal_v, "V")?;
        let energy_wh = pos("energy_wh", self.energy_wh, "W h")?;
        let mass_kg = pos("mass_kg", self.mass_kg, "kg")?;
        // Rated energy is printed rounded; 1 % covers rounding of three significant figures.
        if (energy_wh / (capacity_ah * nominal_v) - 1.0).abs() > 0.01 {
            return Err(bad(
                "energy_wh",
                energy_wh,
                "W h",
                "within 1 % of capacity x nominal voltage",
            ));
        }
        let r = self.internal_resistance_ohm;
        if !(r.is_finite() && r >= 0.0) {
            return Err(bad(
                "internal_resistance_ohm",
                r,
                "ohm",
                "a finite resistance, not negative",
            ));
        }
        let u = self.usable_fraction;
        if !(u.is_finite() && u > 0.0 && u <= 1.0) {
            return Err(bad("usable_fraction", u, "", "a fraction in (0, 1]"));
        }
        let curve = match (&self.ocv_soc, &self.ocv_cell_v) {
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
        let cells = f64::from(self.cells_series);
        let cut = self.cutoff_cell_v;
        if !(cut.is_finite() && cut > 0.0 && cut < curve.cell_v(1.0)) {
            return Err(bad(
                "cutoff_cell_v",
                cut,
                "V",
                "positive and below the full-charge cell voltage",
            ));
        }
        let max_current_a = match self.max_current_a {
            Some(i) => pos("max_current_a", i, "A")?,
            None => f64::INFINITY,
        };
        let ocv_table_v = (0..OCV_TABLE_POINTS)
            .map(|k| cells * curve.cell_v(k as f64 / (OCV_TABLE_POINTS - 1) as f64))
            .collect();
        Ok(Battery {
            name: self.name.clone(),
            cells_series: self.cells_series,
            capacity_ah,
            nominal_v,
            energy_wh,
            mass_kg,
            resistance_ohm: r,
            cutoff_v: cut * cells,
            usable_fraction: u,
            max_current_a,
            ocv_table_v,
        })
    }
}

impl Battery {
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

    /// Current and terminal voltage when the load draws `power_w` at state of charge `soc`;
    /// `None` when the pack cannot deliver that power (`V_oc^2 < 4 R P`).
    #[inline]
    pub fn draw(&self, power_w: f64, soc: f64) -> Option<PackDraw> {
        self.draw_at_ocv(power_w, self.ocv_v(soc))
    }

    #[inline]
    fn draw_at_ocv(&self, power_w: f64, v_oc: f64) -> Option<PackDraw> {
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

    /// A cursor that follows the state of charge from `soc` through a discharge, giving the same
    /// draws as [`Self::draw`] bit for bit with a shorter chain from one step to the next (the
    /// table interval is kept between steps instead of being found again).
    pub fn cursor(&self, soc: f64) -> PackCursor {
        let mut c = PackCursor {
            soc,
            k: 0,
            x_lo: f64::INFINITY,
            x_hi: f64::NEG_INFINITY,
        };
        c.locate();
        c
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
}

/// State of charge during a discharge, with the open-circuit table interval it lies in
/// (see [`Battery::cursor`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PackCursor {
    soc: f64,
    /// Table interval `[k, k + 1]` of `x = soc (points - 1)` while `x_lo <= x < x_hi`.
    k: usize,
    x_lo: f64,
    x_hi: f64,
}

impl PackCursor {
    /// Present state of charge.
    #[inline]
    pub fn soc(&self) -> f64 {
        self.soc
    }

    /// Take `delta_soc` (a fraction of the capacity) from the pack.
    #[inline]
    pub fn discharge(&mut self, delta_soc: f64) {
        self.soc -= delta_soc;
    }

    fn locate(&mut self) {
        let n = (OCV_TABLE_POINTS - 1) as f64;
        let x = self.soc.clamp(0.0, 1.0) * n;
        self.k = (x as usize).min(OCV_TABLE_POINTS - 2);
        // Valid while the unclamped x stays in [k, k + 1) (the last interval closed at 1), which is
        // where `Battery::ocv_v` picks the same k with a clamp that does nothing.
        self.x_lo = if self.soc >= 0.0 {
            self.k as f64
        } else {
            f64::INFINITY
        };
        self.x_hi = if self.k == OCV_TABLE_POINTS - 2 {
            n
        } else {
            self.k as f64 + 1.0
        };
    }

    /// Open-circuit voltage at the present state of charge, V: equal to
    /// `battery.ocv_v(self.soc())`, bit for bit.
    #[inline]
    pub fn ocv_v(&mut self, battery: &Battery) -> f64 {
        let n = (OCV_TABLE_POINTS - 1) as f64;
        let mut x = self.soc * n;
        // The last interval is closed: `x_hi = n` is inside it.
        if !(x >= self.x_lo && (x < self.x_hi || (x <= n && self.k == OCV_TABLE_POINTS - 2))) {
            self.locate();
            if !(self.soc >= 0.0 && self.soc <= 1.0) {
                return battery.ocv_v(self.soc);
            }
            x = self.soc * n;
        }
        let t = &battery.ocv_table_v;
        let k = self.k;
        t[k] + (t[k + 1] - t[k]) * (x - k as f64)
    }

    /// Current and terminal voltage when the load draws `power_w` now: equal to
    /// `battery.draw(power_w, self.soc())`, bit for bit.
    #[inline]
    pub fn draw(&mut self, battery: &Battery, power_w: f64) -> Option<PackDraw> {
        let v_oc = self.ocv_v(battery);
        battery.draw_at_ocv(power_w, v_oc)
    }

    /// Draw `power_w[j]` for each step `j` in turn, taking `current * charge_per_amp` after each:
    /// the same as [`Self::draw`] then [`Self::discharge`] step by step, bit for bit. Writes each
    /// step to `out` (at least as long as `power_w`) and returns how many steps were drawn: all of
    /// them, or the index of the first the pack cannot deliver (the cursor then stands before it).
    ///
    /// # Why it is faster
    /// Step by step, each state of charge waits for the one before through a square root and a
    /// division. Here a whole block is solved at once by fixed-point sweeps: currents of every step
    /// from the present guess of the states of charge (independent steps, run in vector lanes),
    /// then the states of charge from the currents (a chain of subtractions only). The sweeps
    /// converge fast (the current barely depends on the state of charge within a block); a block is
    /// accepted only when a sweep reproduces the previous sweep's currents exactly, which makes the
    /// states of charge satisfy the step-by-step recurrence exactly. A block that does not settle
    /// within a few sweeps, reaches beyond the open-circuit table's interval below its start's, or
    /// contains a step the pack cannot deliver is flown step by step.
    pub fn draw_block(
        &mut self,
        battery: &Battery,
        power_w: &[f64],
        charge_per_amp: f64,
        out: &mut [PackStep],
    ) -> usize {
        let m = power_w.len();
        assert!(out.len() >= m, "draw_block: out shorter than power_w");
        let mut done = 0;
        while done < m {
            let end = (done + LANES).min(m);
            if !self.sweep_block(
                battery,
                &power_w[done..end],
                charge_per_amp,
                &mut out[done..end],
            ) {
                for j in done..end {
                    let Some(d) = self.draw(battery, power_w[j]) else {
                        return j;
                    };
                    self.discharge(d.current_a * charge_per_amp);
                    out[j] = PackStep {
                        current_a: d.current_a,
                        terminal_v: d.terminal_v,
                        soc_after: self.soc,
                    };
                }
            }
            done = end;
        }
        m
    }

    /// The fixed-point sweeps of [`Self::draw_block`] over up to [`LANES`] steps; `false` (with
    /// the cursor unchanged) when the block must be flown step by step.
    fn sweep_block(
        &mut self,
        battery: &Battery,
        power_w: &[f64],
        charge_per_amp: f64,
        out: &mut [PackStep],
    ) -> bool {
        const MAX_SWEEPS: usize = 8;
        let m = power_w.len();
        if m < 2 {
            return false;
        }
        // Locate the interval of the block's start (as the first draw would).
        let v0 = self.ocv_v(battery);
        if !(self.soc >= 0.0 && self.soc <= 1.0) {
            return false;
        }
        // A discharge moves down the table: the block's lanes may use the start's interval k or
        // the one below it (the step-by-step cursor relocates to it at the crossing).
        let t = &battery.ocv_table_v;
        let k = self.k;
        let below = k.saturating_sub(1);
        let lanes = Lanes {
            k: k as f64,
            t_k: [t[k], t[k + 1]],
            below: below as f64,
            t_below: [t[below], t[below + 1]],
            resistance_ohm: battery.resistance_ohm,
        };
        let mut p = [0.0; LANES];
        p[..m].copy_from_slice(power_w);
        // First guess: every step at the first step's current.
        let Some(first) = battery.draw_at_ocv(power_w[0], v0) else {
            return false;
        };
        // The states of charge from the currents: the step-by-step chain's subtractions.
        let chain = |current: &[f64; LANES], soc: &mut [f64; LANES + 1]| {
            for j in 0..m {
                soc[j + 1] = soc[j] - current[j] * charge_per_amp;
            }
        };
        let mut current = [first.current_a; LANES];
        let mut soc = [self.soc; LANES + 1];
        chain(&current, &mut soc);
        let mut previous = [f64::NAN; LANES];
        let mut terminal = [0.0; LANES];
        for _ in 0..MAX_SWEEPS {
            if !currents_of_lanes(&lanes, &p, &soc, &mut current, &mut terminal) {
                return false;
            }
            // The same bits, not merely equal values: the recurrence holds exactly.
            if current[..m]
                .iter()
                .zip(&previous[..m])
                .all(|(a, b)| a.to_bits() == b.to_bits())
            {
                for j in 0..m {
                    out[j] = PackStep {
                        current_a: current[j],
                        terminal_v: terminal[j],
                        soc_after: soc[j + 1],
                    };
                }
                self.soc = soc[m];
                return true;
            }
            chain(&current, &mut soc);
            previous = current;
        }
        false
    }
}

/// Steps per sweep block of [`PackCursor::draw_block`].
const LANES: usize = 64;

/// What the lanes of a sweep share: two neighbouring intervals of the open-circuit table (the
/// block start's, `[k, k + 1]`, and the one below) and the resistance.
struct Lanes {
    k: f64,
    t_k: [f64; 2],
    below: f64,
    t_below: [f64; 2],
    resistance_ohm: f64,
}

/// The draw of every lane at its state of charge `soc[j]`: the arithmetic of `Battery::ocv_v`
/// (which [`PackCursor::ocv_v`] reproduces) and `Battery::draw_at_ocv`, operation for operation,
/// with no data-dependent branch (so in vector lanes; see `aloft_power`'s batch module). `false`
/// when a lane's state of charge leaves [0, 1] or the two intervals, or the pack cannot deliver
/// its power (unused lanes hold 0 W at the block's start, which always pass).
// The interval indices compared exactly are integers held in floats.
#[allow(clippy::float_cmp)]
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+fma", "x86_64+avx2+fma"))]
fn currents_of_lanes(
    lanes: &Lanes,
    power_w: &[f64; LANES],
    soc: &[f64; LANES + 1],
    current_a: &mut [f64; LANES],
    terminal_v: &mut [f64; LANES],
) -> bool {
    let n = (OCV_TABLE_POINTS - 1) as f64;
    // Plain values, so the selects below pick between registers (not between addresses, which
    // the compiler would turn into gathers).
    let (k_at, [t_at0, t_at1]) = (lanes.k, lanes.t_k);
    let (k_below, [t_below0, t_below1]) = (lanes.below, lanes.t_below);
    let mut ok = true;
    for j in 0..LANES {
        let x = soc[j] * n;
        // Battery::ocv_v's interval, min(floor(x), n - 1), as a float.
        let kx = x.floor().min(n - 1.0);
        let at_k = kx == k_at;
        let inside = (soc[j] >= 0.0) & (soc[j] <= 1.0) & (at_k | (kx == k_below));
        let k = if at_k { k_at } else { k_below };
        let t0 = if at_k { t_at0 } else { t_below0 };
        let t1 = if at_k { t_at1 } else { t_below1 };
        let v_oc = t0 + (t1 - t0) * (x - k);
        let disc = v_oc * v_oc - 4.0 * lanes.resistance_ohm * power_w[j];
        let i = 2.0 * power_w[j] / (v_oc + disc.sqrt());
        current_a[j] = i;
        terminal_v[j] = v_oc - i * lanes.resistance_ohm;
        ok &= inside & (disc >= 0.0);
    }
    ok
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::tb47d;

    #[test]
    #[allow(clippy::float_cmp)] // the cursor promises the same bits as `draw`
    fn cursor_draws_what_draw_draws_bit_for_bit_across_a_discharge() {
        let b = tb47d().to_battery().unwrap();
        let mut c = b.cursor(1.0);
        let mut soc = 1.0;
        let mut k = 0;
        while soc > 0.02 {
            let p = 150.0 + 100.0 * (k as f64 * 0.01).sin();
            let d = b.draw(p, soc).unwrap();
            let e = c.draw(&b, p).unwrap();
            assert_eq!(d.current_a, e.current_a, "soc {soc}");
            assert_eq!(d.terminal_v, e.terminal_v);
            let dq = d.current_a * 0.37 / (b.capacity_ah() * 3600.0);
            soc -= dq;
            c.discharge(dq);
            k += 1;
        }
        assert!(k > 1000);
        // Outside [0, 1] the cursor falls back to the clamped table, as `ocv_v` does.
        let mut c = b.cursor(-0.01);
        assert_eq!(c.ocv_v(&b), b.ocv_v(-0.01));
    }

    /// Step by step with `draw` and `discharge`: the reference `draw_block` must reproduce.
    fn step_by_step(b: &Battery, soc: f64, power: &[f64], dq: f64) -> (Vec<PackStep>, f64) {
        let mut c = b.cursor(soc);
        let mut steps = Vec::new();
        for &p in power {
            let Some(d) = c.draw(b, p) else { break };
            c.discharge(d.current_a * dq);
            steps.push(PackStep {
                current_a: d.current_a,
                terminal_v: d.terminal_v,
                soc_after: c.soc(),
            });
        }
        (steps, c.soc())
    }

    #[test]
    fn draw_block_is_the_step_by_step_discharge_bit_for_bit() {
        let b = tb47d().to_battery().unwrap();
        // Small steps (a 10 ms sample), large ones (1 s, so blocks cross table intervals and
        // need many sweeps), and a power that jumps.
        for dq in [0.01 / (4.5 * 3600.0), 1.0 / (4.5 * 3600.0)] {
            let power: Vec<f64> = (0..3000)
                .map(|k| {
                    let k = f64::from(k);
                    150.0
                        + 60.0 * (k * 0.013).sin()
                        + if (k as u32 / 97) % 2 == 0 { 0.0 } else { 120.0 }
                })
                .collect();
            let (expected, end) = step_by_step(&b, 0.97, &power, dq);
            let mut c = b.cursor(0.97);
            let mut got = vec![PackStep::default(); power.len()];
            let drawn = c.draw_block(&b, &power, dq, &mut got);
            assert_eq!(drawn, expected.len());
            for (j, (g, e)) in got.iter().zip(&expected).enumerate() {
                assert_eq!(g.current_a.to_bits(), e.current_a.to_bits(), "step {j}");
                assert_eq!(g.terminal_v.to_bits(), e.terminal_v.to_bits(), "step {j}");
                assert_eq!(g.soc_after.to_bits(), e.soc_after.to_bits(), "step {j}");
            }
            assert_eq!(c.soc().to_bits(), end.to_bits());
        }
        // The sweeps themselves settle a 10 ms block (not only the step-by-step fallback).
        let dq = 0.01 / (4.5 * 3600.0);
        let power: Vec<f64> = (0..64).map(|k| 180.0 + f64::from(k)).collect();
        let mut c = b.cursor(0.6);
        let mut got = [PackStep::default(); 64];
        assert!(c.sweep_block(&b, &power, dq, &mut got));
        let (expected, end) = step_by_step(&b, 0.6, &power, dq);
        assert!(got.iter().zip(&expected).all(|(g, e)| g == e));
        assert_eq!(c.soc().to_bits(), end.to_bits());
        // A demand beyond V_oc^2 / 4R stops the block there, with the cursor before that step.
        let dq = 0.01 / (4.5 * 3600.0);
        let mut power = vec![200.0; 100];
        power[70] = 5000.0;
        let (expected, end) = step_by_step(&b, 0.8, &power, dq);
        let mut c = b.cursor(0.8);
        let mut got = vec![PackStep::default(); power.len()];
        assert_eq!(c.draw_block(&b, &power, dq, &mut got), 70);
        assert_eq!(expected.len(), 70);
        assert_eq!(c.soc().to_bits(), end.to_bits());
        // Running empty mid-block: the steps past 0 % are still the step-by-step ones.
        let (expected, _) = step_by_step(&b, 0.0005, &[300.0; 64], 1.0 / (4.5 * 3600.0));
        let mut c = b.cursor(0.0005);
        let mut got = [PackStep::default(); 64];
        assert_eq!(
            c.draw_block(&b, &[300.0; 64], 1.0 / (4.5 * 3600.0), &mut got),
            expected.len()
        );
        for (g, e) in got.iter().zip(&expected) {
            assert_eq!(g.current_a.to_bits(), e.current_a.to_bits());
        }
    }

    #[test]
    fn draw_delivers_the_power() {
        let b = tb47d().to_battery().unwrap();
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
        let b = tb47d().to_battery().unwrap();
        let c = OcvCurve::typical_lipo();
        for s in [0.0, 0.03, 0.5, 0.77, 1.0] {
            // the table holds the curve's nodes (every 5 %) exactly, so linear interpolation agrees
            assert!((b.ocv_v(s) - 6.0 * c.cell_v(s)).abs() < 1e-12, "{s}");
        }
        // mean rest voltage 3.858 V per cell: 6 x 3.858 x 4.5 = 104.2 W h
        assert!((b.rest_energy_wh(1.0, 0.0) - 6.0 * 3.85825 * 4.5).abs() < 1e-6);
    }

    #[test]
    fn bad_packs_are_named() {
        let mut s = tb47d();
        s.energy_wh = 120.0;
        let e = s.to_battery().unwrap_err().to_string();
        assert!(e.contains("energy_wh") && e.contains("120"), "{e}");
        let mut s = tb47d();
        s.usable_fraction = 1.5;
        assert!(s.to_battery().unwrap_err().to_string().contains("usable"));
        let mut s = tb47d();
        s.internal_resistance_ohm = -0.1;
        assert!(s.to_battery().is_err());
        let mut s = tb47d();
        s.cutoff_cell_v = 4.5;
        assert!(s.to_battery().is_err());
    }
}
