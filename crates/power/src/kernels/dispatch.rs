//! The run-time dispatched build of the single evaluation [`PowerModel::evaluate`]: the plain
//! `PowerModel::evaluate_inline` (`four_term.rs`) compiled once per instruction set; see the
//! advice in [`super`].

use crate::error::Result;
use crate::four_term::{FlightState, PowerBreakdown, PowerModel};

impl PowerModel {
    /// Evaluate a point query: thrust from eq (5), inflow from the selected angle-of-attack model.
    ///
    /// On x86-64 CPUs with AVX2 this runs a build of the same code for that instruction set
    /// (chosen once, at the first call): its three-operand instructions leave out the register
    /// copies of the baseline build, about a tenth faster. The results are the same bits.
    #[inline]
    pub fn evaluate(&self, state: &FlightState) -> Result<PowerBreakdown> {
        evaluate_point(self, state)
    }
}

/// [`PowerModel::evaluate`], dispatched at run time to a build for the best instruction set the
/// CPU has. Each build performs the same IEEE operations (Rust never fuses a multiply and an add
/// on its own), so the results do not depend on the build (test
/// `dispatched_point_queries_equal_the_baseline_build`).
#[multiversion::multiversion(targets("x86_64+avx2+fma"))]
fn evaluate_point(model: &PowerModel, state: &FlightState) -> Result<PowerBreakdown> {
    model.evaluate_inline(state)
}

#[cfg(test)]
// Exact comparisons here check bit-identical results of the same arithmetic.
#[allow(clippy::float_cmp)]
mod tests {
    use crate::four_term::PowerModel;
    use crate::kernels::test_states::{m100, varied_states};

    #[test]
    fn dispatched_point_queries_equal_the_baseline_build() {
        // `evaluate` runs the AVX2 build on CPUs that have it; `evaluate_inline` called here is
        // compiled for the baseline target. Same bits, and the same errors.
        let m = PowerModel::new(m100());
        let mut checked = 0;
        for (i, mut s) in varied_states(3000, 35.0, 1.2, 3.0, 4)
            .into_iter()
            .enumerate()
        {
            // Attitudes beyond 45 deg (libm's sin and cos) and some invalid airspeeds too.
            if i % 97 == 0 {
                s.airspeed_mps = -1.0;
            }
            match (m.evaluate(&s), m.evaluate_inline(&s)) {
                (Ok(p), Ok(q)) => {
                    for (x, y) in [
                        (p.electrical_w, q.electrical_w),
                        (p.aero_w, q.aero_w),
                        (p.induced_w, q.induced_w),
                        (p.induced_velocity_mps, q.induced_velocity_mps),
                        (p.profile_w, q.profile_w),
                        (p.thrust_n, q.thrust_n),
                    ] {
                        assert_eq!(x.to_bits(), y.to_bits(), "{s:?}");
                    }
                    assert_eq!(p, q);
                    checked += 1;
                }
                (Err(e), Err(g)) => assert_eq!(e.to_string(), g.to_string()),
                (p, q) => panic!("{s:?}: {p:?} vs {q:?}"),
            }
        }
        assert!(checked > 2500, "{checked}");
    }
}
