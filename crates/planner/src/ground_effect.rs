//! Ground effect, survey seed eq (35) (Cheeseman and Bennett):
//!
//! `T / T_inf = 1 / (1 - (R / 4 z)^2)`
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `T` | thrust in ground effect | N |
//! | `T_inf` | thrust out of ground effect at the same power | N |
//! | `R` | rotor radius | m |
//! | `z` | height of the rotor above the ground | m |
//!
//! The planner needs the power for a required thrust `T`, so it evaluates the power model at the
//! out-of-ground-effect thrust that takes the same power, `T_inf = T (1 - (R / 4 z)^2)`.
//!
//! Valid where the seed says the formula is used: it predicts 1.6 % at `z = 2 R` and is negligible
//! above one diameter. It diverges at `z = R / 4`; the planner holds `z` at or above
//! [`MIN_HEIGHT_OVER_RADIUS`] `R` (a rotor sits higher than that above its landing gear on any
//! multirotor), where the factor is 0.9375.

/// Smallest `z / R` the formula is evaluated at.
pub const MIN_HEIGHT_OVER_RADIUS: f64 = 1.0;

/// `T_inf / T = 1 - (R / 4 z)^2` at rotor height `rotor_height_m` above the ground, in `(0, 1]`.
#[inline]
pub fn thrust_factor(rotor_radius_m: f64, rotor_height_m: f64) -> f64 {
    let z = rotor_height_m.max(MIN_HEIGHT_OVER_RADIUS * rotor_radius_m);
    let q = rotor_radius_m / (4.0 * z);
    1.0 - q * q
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_val_survey_eq35_two_radii_gives_1_6_percent() {
        // Survey text under eq (35): "for z/R = 2 the predicted ratio ... is just 1.016".
        let ratio = 1.0 / thrust_factor(0.172, 0.344);
        assert!((ratio - 1.016).abs() < 0.0005, "{ratio}"); // 1/(1 - 1/64) = 1.01587
                                                            // far from the ground the factor tends to 1
        assert!(1.0 - thrust_factor(0.172, 30.0) < 1e-5);
        // clamped below one radius
        assert!((thrust_factor(0.172, 0.0) - (1.0 - 1.0 / 16.0)).abs() < 1e-15);
    }
}
