//! The vector lanes of the four-term model's batch evaluations (their entry points are in
//! `batch.rs`).
//!
//! [`crate::PowerModel::evaluate_batch`], [`crate::PowerModel::evaluate_conditions`] and
//! [`crate::PowerModel::electrical_of_conditions`] work in blocks of [`CHUNK`] resolved conditions,
//! laid out one array per field ([`Block`]). The kernels here run the quartic's branch-free fast
//! path (and for the electrical power the terms too) over a whole block with no data-dependent
//! branch, so the compiler turns the loop into vector code: one lane per condition, 2 lanes with
//! the baseline x86-64 SSE2, 4 with AVX2, 8 with AVX-512. `multiversion` compiles the same source
//! once per instruction set and picks at run time the best the CPU has. Every lane does the same
//! IEEE operations as the scalar code (Rust never fuses a multiply and an add on its own), so the
//! results do not depend on the instruction set.
//!
//! The kernels index their arrays by lane (one lane, one index), hence
//! `clippy::needless_range_loop` is allowed here.
//!
//! A lane the fast path cannot settle (a NaN root: the vortex-ring side of the quartic, or a root
//! the fixed Halley steps did not reach) is left to the caller, which runs the safeguarded scalar
//! solver for it.

#![allow(clippy::needless_range_loop)]

use multiversion::multiversion;

use crate::angle_of_attack::AoaModel;
use crate::four_term::{FlightCondition, PowerModel};
use crate::quartic::solve_normalised_fast;

/// Conditions per block.
pub(crate) const CHUNK: usize = 64;

/// A block of resolved conditions, one array per field (the layout vector lanes load).
#[derive(Debug, Clone)]
pub(crate) struct Block {
    thrust_n: [f64; CHUNK],
    airspeed_mps: [f64; CHUNK],
    normal_mps: [f64; CHUNK],
    parallel_mps: [f64; CHUNK],
    climb_rate_mps: [f64; CHUNK],
    geometric: [bool; CHUNK],
}

impl Block {
    /// A block of hover conditions (harmless values for the lanes a short block leaves unused).
    pub(crate) fn new() -> Self {
        Self {
            thrust_n: [0.0; CHUNK],
            airspeed_mps: [0.0; CHUNK],
            normal_mps: [0.0; CHUNK],
            parallel_mps: [0.0; CHUNK],
            climb_rate_mps: [0.0; CHUNK],
            geometric: [false; CHUNK],
        }
    }

    /// Put `c` in lane `j`.
    #[inline(always)]
    pub(crate) fn set(&mut self, j: usize, c: &FlightCondition) {
        self.thrust_n[j] = c.thrust_n;
        self.airspeed_mps[j] = c.airspeed_mps;
        self.normal_mps[j] = c.inflow.normal_mps;
        self.parallel_mps[j] = c.inflow.parallel_mps;
        self.climb_rate_mps[j] = c.climb_rate_mps;
        self.geometric[j] = c.aoa == AoaModel::Geometric;
    }
}

/// The normalised induced velocity `v_i / vh` of every lane, NaN where the fast path leaves the
/// root to the safeguarded solver.
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+fma", "x86_64+avx2+fma"))]
pub(crate) fn roots_of_block(model: &PowerModel, block: &Block, roots: &mut [f64; CHUNK]) {
    let inv_vh = model.vehicle().inverse_hover_induced_velocity();
    for j in 0..CHUNK {
        roots[j] =
            solve_normalised_fast(block.normal_mps[j] * inv_vh, block.parallel_mps[j] * inv_vh);
    }
}

/// [`roots_of_block`] and the electrical power of every lane (NaN where the root is).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+fma", "x86_64+avx2+fma"))]
pub(crate) fn electrical_of_block(
    model: &PowerModel,
    block: &Block,
    roots: &mut [f64; CHUNK],
    electrical_w: &mut [f64; CHUNK],
) {
    let inv_vh = model.vehicle().inverse_hover_induced_velocity();
    for j in 0..CHUNK {
        let x = solve_normalised_fast(block.normal_mps[j] * inv_vh, block.parallel_mps[j] * inv_vh);
        roots[j] = x;
        electrical_w[j] = model
            .terms_at(
                block.thrust_n[j],
                block.airspeed_mps[j],
                block.normal_mps[j],
                block.parallel_mps[j],
                block.climb_rate_mps[j],
                block.geometric[j],
                x,
            )
            .electrical_w;
    }
}
