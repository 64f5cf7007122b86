//! The batch entry points of [`PowerModel`]: many evaluations in passes over blocks of
//! [`CHUNK`] conditions, the quartic and the terms in vector lanes ([`super::lanes`]).
//!
//! Each returns what the single evaluations ([`PowerModel::evaluate`],
//! [`PowerModel::evaluate_condition`]) return, bit for bit (tests below); see the advice in
//! [`super`].

use super::lanes::{electrical_of_block, roots_of_block, Block, CHUNK};
use crate::error::{PowerError, Result};
use crate::four_term::{check_condition, FlightCondition, FlightState, PowerBreakdown, PowerModel};

impl PowerModel {
    /// Evaluate many point queries into `out` (same length), stopping at the first invalid state.
    ///
    /// Returns the first invalid state's error; `Ok(())` means every element of `out` was written.
    /// Results are identical to [`Self::evaluate`]; the work is arranged in passes over chunks so
    /// the CPU overlaps independent states (the throughput path).
    pub fn evaluate_batch(&self, states: &[FlightState], out: &mut [PowerBreakdown]) -> Result<()> {
        check_lengths(states.len(), out.len())?;
        let mut conditions = [FlightCondition::default(); CHUNK];
        let mut block = Block::new();
        for (sc, oc) in states.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
            // Pass 1: validation, trigonometry, thrust and inflow.
            for (j, (s, c)) in sc.iter().zip(conditions.iter_mut()).enumerate() {
                *c = self.point_condition(s)?;
                block.set(j, c);
            }
            // Passes 2 and 3: the quartic over the block in vector lanes, then the terms.
            self.terms_of_block(&conditions, &block, oc)?;
        }
        Ok(())
    }

    /// Evaluate many resolved conditions into `out` (same length): [`Self::evaluate_condition`]
    /// arranged in passes for throughput, as [`Self::evaluate_batch`]. Returns the first invalid
    /// condition's error; `Ok(())` means every element of `out` was written.
    pub fn evaluate_conditions(
        &self,
        conditions: &[FlightCondition],
        out: &mut [PowerBreakdown],
    ) -> Result<()> {
        by_blocks(conditions, out, |cc, block, oc| {
            self.terms_of_block(cc, block, oc)
        })
    }

    /// The roots of a block in vector lanes (`kernels/lanes.rs`), then the terms of each
    /// condition of `conditions` (the block's, in order) into `out`.
    #[inline(always)]
    fn terms_of_block(
        &self,
        conditions: &[FlightCondition],
        block: &Block,
        out: &mut [PowerBreakdown],
    ) -> Result<()> {
        let mut roots = [0.0f64; CHUNK];
        roots_of_block(self, block, &mut roots);
        for ((c, &x), o) in conditions.iter().zip(roots.iter()).zip(out.iter_mut()) {
            *o = self.assemble(c, self.root_or_safeguarded(c, x)?);
        }
        Ok(())
    }

    /// [`Self::evaluate_conditions`] keeping only the electrical power, W: the terms too run in
    /// vector lanes (the planner's path).
    pub fn electrical_of_conditions(
        &self,
        conditions: &[FlightCondition],
        out: &mut [f64],
    ) -> Result<()> {
        let mut roots = [0.0f64; CHUNK];
        let mut watts = [0.0f64; CHUNK];
        by_blocks(conditions, out, |cc, block, oc| {
            electrical_of_block(self, block, &mut roots, &mut watts);
            for (((c, &x), &w), o) in cc
                .iter()
                .zip(roots.iter())
                .zip(watts.iter())
                .zip(oc.iter_mut())
            {
                *o = if x.is_nan() {
                    self.assemble(c, self.root_or_safeguarded(c, x)?)
                        .electrical_w
                } else {
                    w
                };
            }
            Ok(())
        })
    }

    /// A block root `x = v_i / vh`, or the safeguarded solver's where the fast path left it (NaN).
    #[inline(always)]
    fn root_or_safeguarded(&self, c: &FlightCondition, x: f64) -> Result<f64> {
        if x.is_nan() {
            self.induced_velocity(c)
        } else {
            Ok(x)
        }
    }
}

/// The passes over resolved conditions: `conditions` and `out` (checked to be of one length)
/// [`CHUNK`] at a time, each block of conditions validated and laid out in the lanes of one
/// [`Block`] before `each` writes its outputs; stops at the first error.
#[inline(always)]
fn by_blocks<T>(
    conditions: &[FlightCondition],
    out: &mut [T],
    mut each: impl FnMut(&[FlightCondition], &Block, &mut [T]) -> Result<()>,
) -> Result<()> {
    check_lengths(conditions.len(), out.len())?;
    let mut block = Block::new();
    for (cc, oc) in conditions.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
        load_block(cc, &mut block)?;
        each(cc, &block, oc)?;
    }
    Ok(())
}

/// Validate up to [`CHUNK`] resolved conditions and lay them out in `block`'s lanes.
#[inline(always)]
fn load_block(conditions: &[FlightCondition], block: &mut Block) -> Result<()> {
    for (j, c) in conditions.iter().enumerate() {
        check_condition(c)?;
        block.set(j, c);
    }
    Ok(())
}

/// A batch's output must have the length of its input.
fn check_lengths(input_len: usize, output_len: usize) -> Result<()> {
    if input_len == output_len {
        Ok(())
    } else {
        Err(PowerError::SeriesLength {
            estimate_len: output_len,
            measured_len: input_len,
        })
    }
}

#[cfg(test)]
// Exact comparisons here check bit-identical results of the same arithmetic.
#[allow(clippy::float_cmp)]
mod tests {
    use crate::angle_of_attack::{AoaModel, Inflow};
    use crate::four_term::{FlightCondition, PowerModel};
    use crate::kernels::test_states::{m100, varied_states};

    #[test]
    fn batch_equals_single_evaluations_bit_for_bit() {
        let m = PowerModel::new(m100());
        let states = varied_states(1000, 30.0, 0.7, 2.0, 3);
        let mut out = vec![m.evaluate(&states[0]).unwrap(); states.len()];
        m.evaluate_batch(&states, &mut out).unwrap();
        for (s, o) in states.iter().zip(&out) {
            // Both paths return the first Halley iterate that meets the residual bound, and the
            // vector lanes do the scalar code's IEEE operations: the same bits.
            let single = m.evaluate(s).unwrap();
            assert_eq!(single, *o, "{s:?}");
        }
        // A bad state stops the batch with its error.
        let mut bad = states.clone();
        bad[700].roll_rad = f64::NAN;
        assert!(m.evaluate_batch(&bad, &mut out).is_err());
        assert!(
            m.evaluate_batch(&states[..3], &mut out).is_err(),
            "length mismatch"
        );
    }

    #[test]
    fn conditions_in_a_batch_equal_single_evaluations() {
        let m = PowerModel::new(m100());
        let conditions: Vec<FlightCondition> = (0..500)
            .map(|i| {
                let f = f64::from(i) / 500.0;
                let v = 20.0 * f;
                let tilt = 0.6 * f;
                FlightCondition {
                    thrust_n: m.vehicle().weight_n() / tilt.cos(),
                    airspeed_mps: v,
                    // Every 7th a slow descent through the disk (Vn < 0, Vp small): the quartic
                    // has three positive roots there and the fast path steps aside.
                    inflow: if i % 7 == 0 {
                        Inflow {
                            normal_mps: -4.0 * f,
                            parallel_mps: 0.1 * f,
                        }
                    } else {
                        Inflow {
                            normal_mps: v * tilt.sin(),
                            parallel_mps: v * tilt.cos(),
                        }
                    },
                    climb_rate_mps: 0.5 * (f * 9.0).sin(),
                    aoa: if i % 2 == 0 {
                        AoaModel::Geometric
                    } else {
                        AoaModel::Paper
                    },
                }
            })
            .collect();
        let mut out = vec![m.evaluate_condition(&conditions[0]).unwrap(); conditions.len()];
        m.evaluate_conditions(&conditions, &mut out).unwrap();
        let mut watts = vec![0.0; conditions.len()];
        m.electrical_of_conditions(&conditions, &mut watts).unwrap();
        let mut left_to_the_safeguarded_solver = 0;
        for ((c, o), w) in conditions.iter().zip(&out).zip(&watts) {
            // The same bits as one at a time: the same iterate, the same IEEE operations in the
            // vector lanes (which here run AVX2 or AVX-512 where the CPU has them).
            let single = m.evaluate_condition(c).unwrap();
            assert_eq!(single, *o, "{c:?}");
            assert_eq!(single.electrical_w.to_bits(), w.to_bits(), "{c:?}");
            let vh = m.vehicle().hover_induced_velocity_mps();
            if crate::quartic::solve_normalised_fast(
                c.inflow.normal_mps / vh,
                c.inflow.parallel_mps / vh,
            )
            .is_nan()
            {
                left_to_the_safeguarded_solver += 1;
            }
        }
        // The descents below reach the lanes the fast path leaves out.
        assert!(
            left_to_the_safeguarded_solver > 10,
            "{left_to_the_safeguarded_solver}"
        );
        let mut bad = conditions.clone();
        bad[300].thrust_n = f64::NAN;
        let e = m.evaluate_conditions(&bad, &mut out).unwrap_err();
        assert!(e.to_string().contains("thrust_n"), "{e}");
        let e = m.electrical_of_conditions(&bad, &mut watts).unwrap_err();
        assert!(e.to_string().contains("thrust_n"), "{e}");
        assert!(m.electrical_of_conditions(&bad[..3], &mut watts).is_err());
    }
}
