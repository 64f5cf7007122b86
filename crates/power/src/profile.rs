//! Profile power, eq (12) of the power seed.
//!
//! `P_pro = kappa1 T^(3/2) + kappa2 (v_inf cos(alpha))^2 T^(1/2)`; the paper writes the in-plane
//! airspeed as `v_inf cos(phi) cos(theta)` (its approximation (3)), aloft uses `Vp` from whichever
//! angle-of-attack model is selected.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `T` | total thrust | N |
//! | `Vp` | freestream in the rotor plane | m/s |
//! | `kappa1` | profile coefficient | W/N^1.5 |
//! | `kappa2` | in-plane profile coefficient (the paper, after Liu et al., takes it as 0) | W s^2/(m^2 N^0.5) |
//!
//! The paper's M100 value `kappa1 = 0.275` was found following Liu et al.; its Table I shows the term
//! degrades the estimate at 8 m/s, which motivates the hybrid model (term dropped above a cutoff
//! airspeed, see [`crate::ModelOptions`]).

/// Profile power `P_pro`, eq (12), W.
#[inline]
pub fn profile_power_w(kappa1: f64, kappa2: f64, thrust_n: f64, parallel_mps: f64) -> f64 {
    let sqrt_t = thrust_n.sqrt();
    kappa1 * thrust_n * sqrt_t + kappa2 * parallel_mps * parallel_mps * sqrt_t
}

#[cfg(test)]
// Exact comparisons here check values that are exact by construction (zeros of removed terms and
// of zero airspeed, bit-identical results of the same arithmetic).
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn paper_val_eq12_by_hand() {
        // kappa1 T^1.5 with T = 32.26 N: 0.275 * 32.26^1.5 = 0.275 * 183.23... computed two ways.
        let t: f64 = 32.26;
        let expected = 0.275 * t.powf(1.5) + 0.1 * 4.0f64.powi(2) * t.powf(0.5);
        let got = profile_power_w(0.275, 0.1, t, 4.0);
        assert!(
            (got - expected).abs() < 1e-12 * expected,
            "{got} vs {expected}"
        );
    }

    #[test]
    fn zero_coefficients_give_zero() {
        assert_eq!(profile_power_w(0.0, 0.0, 30.0, 5.0), 0.0);
    }
}
