//! # kernels: the power model's fast paths, apart from the physics they speed up
//!
//! Advice for hackers. Nothing in this module changes a number: each fast path here does the
//! same IEEE operations, in the same order, as a plain reference in the model files
//! (`four_term.rs`, `quartic.rs`), which is written to be read, and a test holds the two to the
//! same bits. Rust never reassociates or fuses floating-point operations on its own, so the same
//! operations in the same order give the same bits on every instruction set; that is what every
//! kernel here relies on. To change the physics, change the plain reference, then the fast path
//! until its test passes again. To make something faster, keep the operations and their order,
//! and keep the `#[inline(always)]` on the plain pieces the kernels inline (`point_condition`,
//! `assemble`, `terms_at`, `induced_velocity`, the quartic's functions): each instruction-set
//! build needs its own inlined copy.
//!
//! ## The fast paths
//! - **Run-time dispatched single evaluation** (`dispatch.rs`). [`crate::PowerModel::evaluate`]
//!   calls `evaluate_point`, which `multiversion` compiles twice from the same source (baseline
//!   x86-64 and AVX2+FMA) and dispatches once, at the first call, to the best the CPU has. Fast
//!   because the AVX2 build's three-operand instructions leave out the baseline build's register
//!   copies (about a tenth faster). Plain reference: `PowerModel::evaluate_inline` in
//!   `four_term.rs`, compiled for the baseline target. Test:
//!   `kernels::dispatch::tests::dispatched_point_queries_equal_the_baseline_build` (every field's
//!   bits, and the same errors, over 3000 states).
//! - **Vector lanes** (`lanes.rs`). `roots_of_block` runs the quartic's branch-free
//!   `solve_normalised_fast` over a [`lanes::Block`] of [`lanes::CHUNK`] conditions stored one
//!   array per field; `electrical_of_block` also runs the terms (`PowerModel::terms_at`, written
//!   with selects). With no data-dependent branch the loops become vector code, one lane per
//!   condition (2 lanes with SSE2, 4 with AVX2, 8 with AVX-512, dispatched by `multiversion`).
//!   A lane the fast path cannot settle comes back NaN and goes to the checked scalar solver.
//!   Plain reference: `quartic::solve_normalised`. Tests:
//!   `quartic::tests::scalar_and_lane_solvers_return_the_same_root` and
//!   `quartic::tests::settled_first_step_meets_the_residual_bound`.
//! - **Batch entry points** (`batch.rs`). [`crate::PowerModel::evaluate_batch`],
//!   [`crate::PowerModel::evaluate_conditions`] and
//!   [`crate::PowerModel::electrical_of_conditions`] work in passes over chunks (validate and
//!   resolve, roots in the lanes, then the terms), so the CPU overlaps independent conditions.
//!   Plain reference: [`crate::PowerModel::evaluate`] and
//!   [`crate::PowerModel::evaluate_condition`], one at a time. Tests:
//!   `kernels::batch::tests::batch_equals_single_evaluations_bit_for_bit` and
//!   `kernels::batch::tests::conditions_in_a_batch_equal_single_evaluations` (which also holds
//!   `electrical_of_conditions` to `evaluate_condition`'s `electrical_w`).
//! - **sin and cos** (`trig.rs`). `sin_cos` and `sin_cos_pair`: degree-5 polynomials within
//!   +-45 deg by Estrin's scheme, two angles in one register; libm's `sincos` outside. Unlike the
//!   others this kernel is not held to a reference bit for bit: it is part of the model's
//!   numbers, since every evaluation path (the plain one too) takes its sines and cosines from
//!   it. Tests `kernels::trig::tests::*` hold it within 2 ulp of the standard library's.
//!
//! Not here: the quartic's settled first step (`quartic::SETTLED_RESIDUAL`) is part of the
//! checked solver itself, so it lives with the solver in `quartic.rs`.
//!
//! ## Dependencies
//! The kernels use the model's types and its plain pieces (`four_term.rs`, `quartic.rs`); the
//! model uses nothing from here but `trig`, a leaf that imports nothing from the crate.

mod batch;
mod dispatch;
mod lanes;
pub(crate) mod trig;

#[cfg(test)]
mod test_states {
    use crate::four_term::{AoaInput, FlightState};
    use crate::vehicle::tests::m100_params;
    use crate::vehicle::Vehicle;

    pub(super) fn m100() -> Vehicle {
        Vehicle::new(m100_params()).unwrap()
    }

    /// `n` point queries spread over airspeed (0 to `max_speed`), roll and pitch (within
    /// `max_tilt`) and climb rate (within `max_climb`), every `geometric_every`-th with the exact
    /// angle of attack.
    pub(super) fn varied_states(
        n: u32,
        max_speed: f64,
        max_tilt: f64,
        max_climb: f64,
        geometric_every: u32,
    ) -> Vec<FlightState> {
        (0..n)
            .map(|i| {
                let f = f64::from(i) / f64::from(n);
                let mut s = FlightState::new(
                    max_speed * f,
                    (f * 97.0).sin() * max_tilt,
                    (f * 53.0).cos() * max_tilt,
                    max_climb * (2.0 * f - 1.0),
                );
                if i % geometric_every == 0 {
                    s.aoa = AoaInput::Geometric {
                        air_direction_rad: f * 7.0 - 3.5,
                    };
                }
                s
            })
            .collect()
    }
}
