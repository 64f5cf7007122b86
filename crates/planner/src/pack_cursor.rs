//! The pack cursor: the pack model of [`crate::battery`] followed through a discharge, fast.
//!
//! [`Pack::draw`] is the plain reference: the open-circuit voltage at the state of charge (a
//! table lookup), the current that delivers the power, the terminal voltage. A mission calls it
//! once per sample with the state of charge the step before left, so each step waits on the one
//! before through a square root and a division. Two fast paths make that chain shorter, each
//! giving the reference's results bit for bit:
//!
//! - [`PackCursor`] keeps the table interval of the present state of charge between steps instead
//!   of finding it again ([`PackCursor::draw`], [`PackCursor::ocv_v`]); tested against
//!   [`Pack::draw`] over a whole discharge
//!   (`cursor_draws_what_draw_draws_bit_for_bit_across_a_discharge`).
//! - [`PackCursor::draw_block`] solves a block of up to 64 steps at once by fixed-point sweeps in
//!   vector lanes, and accepts a block only when a sweep reproduces the previous one's currents
//!   bit for bit (so the states of charge satisfy the step-by-step recurrence exactly); any other
//!   block is flown step by step. Tested against [`PackCursor::draw`] then
//!   [`PackCursor::discharge`] step by step (`draw_block_is_the_step_by_step_discharge_bit_for_bit`).

use multiversion::multiversion;

use crate::battery::{Pack, PackDraw, OCV_TABLE_POINTS};

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

/// State of charge during a discharge, with the open-circuit table interval it lies in
/// (see [`Pack::cursor`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PackCursor {
    soc: f64,
    /// Table interval `[k, k + 1]` of `x = soc (points - 1)` while `x_lo <= x < x_hi`.
    k: usize,
    x_lo: f64,
    x_hi: f64,
}

impl Pack {
    /// A cursor that follows the state of charge from `soc` through a discharge, giving the same
    /// draws as [`Self::draw`] bit for bit with a shorter chain from one step to the next (the
    /// table interval is kept between steps instead of being found again).
    pub fn cursor(&self, soc: f64) -> PackCursor {
        PackCursor::new(soc)
    }
}

impl PackCursor {
    /// A cursor at `soc`, located in its table interval ([`Pack::cursor`]).
    pub(crate) fn new(soc: f64) -> Self {
        let mut c = PackCursor {
            soc,
            k: 0,
            x_lo: f64::INFINITY,
            x_hi: f64::NEG_INFINITY,
        };
        c.locate();
        c
    }

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
        // where `Pack::ocv_v` picks the same k with a clamp that does nothing.
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
    pub fn ocv_v(&mut self, battery: &Pack) -> f64 {
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
        let t = battery.ocv_table_v();
        let k = self.k;
        t[k] + (t[k + 1] - t[k]) * (x - k as f64)
    }

    /// Current and terminal voltage when the load draws `power_w` now: equal to
    /// `battery.draw(power_w, self.soc())`, bit for bit.
    #[inline]
    pub fn draw(&mut self, battery: &Pack, power_w: f64) -> Option<PackDraw> {
        let v_oc = self.ocv_v(battery);
        battery.draw_at_ocv(power_w, v_oc)
    }

    /// One step: [`Self::draw`] of `power_w`, then [`Self::discharge`] of
    /// `current * charge_per_amp`; `None` (nothing taken) when the pack cannot deliver it.
    #[inline]
    fn step(&mut self, battery: &Pack, power_w: f64, charge_per_amp: f64) -> Option<PackStep> {
        let d = self.draw(battery, power_w)?;
        self.discharge(d.current_a * charge_per_amp);
        Some(PackStep {
            current_a: d.current_a,
            terminal_v: d.terminal_v,
            soc_after: self.soc,
        })
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
        battery: &Pack,
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
                    let Some(step) = self.step(battery, power_w[j], charge_per_amp) else {
                        return j;
                    };
                    out[j] = step;
                }
            }
            done = end;
        }
        m
    }

    /// Draw `power_w[j]` for each step `j` in turn, taking `current * charge_per_amp[j]` after
    /// each: [`Self::draw`] then [`Self::discharge`] step by step, for steps of different
    /// durations (the steps the flight envelope slowed). Writes each step to `out` and returns
    /// how many were drawn: all, or the index of the first the pack cannot deliver.
    pub fn draw_each(
        &mut self,
        battery: &Pack,
        power_w: &[f64],
        charge_per_amp: &[f64],
        out: &mut [PackStep],
    ) -> usize {
        for (j, (&p, &dq)) in power_w.iter().zip(charge_per_amp).enumerate() {
            let Some(step) = self.step(battery, p, dq) else {
                return j;
            };
            out[j] = step;
        }
        power_w.len()
    }

    /// The fixed-point sweeps of [`Self::draw_block`] over up to [`LANES`] steps; `false` (with
    /// the cursor unchanged) when the block must be flown step by step.
    fn sweep_block(
        &mut self,
        battery: &Pack,
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
        let t = battery.ocv_table_v();
        let k = self.k;
        let below = k.saturating_sub(1);
        let lanes = Lanes {
            k: k as f64,
            t_k: [t[k], t[k + 1]],
            below: below as f64,
            t_below: [t[below], t[below + 1]],
            resistance_ohm: battery.resistance_ohm(),
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

/// The draw of every lane at its state of charge `soc[j]`: the arithmetic of `Pack::ocv_v`
/// (which [`PackCursor::ocv_v`] reproduces) and `Pack::draw_at_ocv`, operation for operation,
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
        // Pack::ocv_v's interval, min(floor(x), n - 1), as a float.
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
        let b = Pack::new(&tb47d()).unwrap();
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
    fn step_by_step(b: &Pack, soc: f64, power: &[f64], dq: f64) -> (Vec<PackStep>, f64) {
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
        let b = Pack::new(&tb47d()).unwrap();
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
}
