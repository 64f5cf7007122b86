//! Electronic speed controller, propulsion seed eq (5) and Fig. 3.
//!
//! The ESC consumes a constant electronics power `P_e` and has a switch resistance `R_e` that is
//! added to the armature resistance: `R_m = R_a + R_e`. Eq (5): the power available to the motor
//! is `P_m = V_ps I_ps - P_e`.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `P_e` | electronics power | W |
//! | `R_e` | switch resistance | ohm |
//! | `V_ps`, `I_ps` | supply voltage and current | V, A |

use crate::error::{non_negative, resistance, PropulsionError};

/// An ESC with constant electronics power and switch resistance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Esc {
    electronics_power_w: f64,
    resistance_ohm: f64,
}

impl Esc {
    /// # Errors
    /// Negative or non-finite power or resistance.
    pub fn new(electronics_power_w: f64, resistance_ohm: f64) -> Result<Self, PropulsionError> {
        Ok(Self {
            electronics_power_w: non_negative("esc electronics_power_w", electronics_power_w, "W")?,
            resistance_ohm: resistance("esc resistance_ohm", resistance_ohm)?,
        })
    }

    /// An ideal ESC (no electronics power, no switch resistance).
    pub fn ideal() -> Self {
        Self {
            electronics_power_w: 0.0,
            resistance_ohm: 0.0,
        }
    }

    /// Electronics power `P_e`, W.
    pub fn electronics_power_w(&self) -> f64 {
        self.electronics_power_w
    }

    /// Switch resistance `R_e`, ohm.
    pub fn resistance_ohm(&self) -> f64 {
        self.resistance_ohm
    }

    /// Eq (5): power available to the motor, `P_m = V_ps I_ps - P_e`, W.
    pub fn motor_power_w(&self, supply_voltage_v: f64, supply_current_a: f64) -> f64 {
        supply_voltage_v * supply_current_a - self.electronics_power_w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq5_subtracts_electronics_power() {
        let e = Esc::new(2.0, 0.005).unwrap();
        // 20 V x 10 A - 2 W = 198 W, exactly representable
        assert!((e.motor_power_w(20.0, 10.0) - 198.0).abs() < 1e-12);
        assert!(Esc::new(-1.0, 0.0).is_err());
        assert!(matches!(
            Esc::new(1.0, f64::NAN),
            Err(PropulsionError::InvalidResistance { .. })
        ));
    }
}
