//! Climb power, eq (13) of the power seed: `P_c = v_z m g`.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `v_z` | vertical velocity, positive UP (a NED log's `v_down` needs a sign flip) | m/s |
//! | `m g` | weight | N |
//! | `P_c` | climb power: the rate of change of potential energy | W |
//!
//! Negative in descent: the model credits the potential energy released.

/// Climb power `P_c = v_z m g`, eq (13), W. `climb_rate_mps` is positive up.
#[inline]
pub fn climb_power_w(weight_n: f64, climb_rate_mps: f64) -> f64 {
    weight_n * climb_rate_mps
}

#[cfg(test)]
// Exact comparisons here check values that are exact by construction (zeros of removed terms and
// of zero airspeed, bit-identical results of the same arithmetic).
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn paper_val_eq13_sign() {
        assert!(climb_power_w(32.26, 2.0) > 0.0, "climbing costs power");
        assert!(climb_power_w(32.26, -2.0) < 0.0, "descending releases it");
        assert_eq!(climb_power_w(32.26, 0.0), 0.0);
        assert!((climb_power_w(32.26, 1.5) - 48.39).abs() < 1e-12);
    }
}
