//! Fixed-pitch propeller in hover (static) conditions.
//!
//! Two coefficient conventions are in use and both are supported:
//!
//! * **Propeller tables** (UIUC, APC, thrust stands):
//!   `C_T = T / (rho n^2 D^4)`, `C_P = P / (rho n^3 D^5)`, with `n` in rev/s and `D` the diameter.
//! * **Rotor convention** of the propulsion seed, eqs (21)-(22):
//!   `C_T = T / (rho pi R^4 Omega^2)`, `C_Q = Q / (rho pi R^5 Omega^2)`, with `R` the radius and
//!   `Omega` in rad/s.
//!
//! With `Omega = 2 pi n` and `D = 2 R`:
//!
//! ```text
//! C_T(rotor) = C_T(prop) * 4 / pi^3
//! C_Q(rotor) = C_P(prop) * 4 / pi^4     (Q = P / Omega)
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `T` | thrust | N |
//! | `Q` | shaft torque | N m |
//! | `P` | shaft power | W |
//! | `rho` | air density | kg/m^3 |
//! | `n` | rotor speed | rev/s |
//! | `Omega` | rotor speed | rad/s |
//! | `D`, `R` | diameter, radius | m |
//!
//! Valid at zero advance ratio (hover); the coefficients of a real propeller vary with Reynolds
//! number, which [`Propeller`] can represent as a linear dependence on rotor speed when a table
//! supports it (see [`crate::fit::propeller`]).
//!
//! The seed's installed-efficiency reduction (propulsion seed, "Mission Planning": an 11 %
//! reduction obtained by comparing flight tests with the thrust stand) is applied as an
//! adjustment of the nominal thrust: the installed rotor makes `(1 - loss)` of the stand thrust
//! at the same speed, so the stand must produce `T / (1 - loss)`.

use crate::error::{finite, fraction, positive, PropulsionError};
use std::f64::consts::PI;

/// Metres per inch.
pub const M_PER_IN: f64 = 0.0254;

/// Converts a propeller-table thrust coefficient `T/(rho n^2 D^4)` to the rotor convention of
/// propulsion seed eq (21), `T/(rho pi R^4 Omega^2)`.
pub fn ct_prop_to_rotor(ct_prop: f64) -> f64 {
    ct_prop * 4.0 / PI.powi(3)
}

/// Converts a rotor-convention thrust coefficient (seed eq 21) to the propeller-table convention.
pub fn ct_rotor_to_prop(ct_rotor: f64) -> f64 {
    ct_rotor * PI.powi(3) / 4.0
}

/// Converts a propeller-table power coefficient `P/(rho n^3 D^5)` to the rotor-convention torque
/// coefficient of propulsion seed eq (22), `Q/(rho pi R^5 Omega^2)`.
pub fn cp_prop_to_cq_rotor(cp_prop: f64) -> f64 {
    cp_prop * 4.0 / PI.powi(4)
}

/// Converts a rotor-convention torque coefficient (seed eq 22) to a propeller-table power
/// coefficient.
pub fn cq_rotor_to_cp_prop(cq_rotor: f64) -> f64 {
    cq_rotor * PI.powi(4) / 4.0
}

/// Converts rpm to rad/s.
pub fn rpm_to_radps(rpm: f64) -> f64 {
    rpm * 2.0 * PI / 60.0
}

/// Converts rad/s to rpm.
pub fn radps_to_rpm(radps: f64) -> f64 {
    radps * 60.0 / (2.0 * PI)
}

/// A fixed-pitch propeller described by propeller-table coefficients.
///
/// `C_T(N) = ct + ct_per_krpm * N / 1000` and likewise for `C_P` (N in rpm); the slopes are zero
/// unless a table shows a Reynolds-number effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Propeller {
    diameter_m: f64,
    ct: f64,
    cp: f64,
    ct_per_krpm: f64,
    cp_per_krpm: f64,
    installed_thrust_loss: f64,
}

impl Propeller {
    /// A propeller with constant propeller-table coefficients `C_T`, `C_P` and no installation
    /// loss.
    ///
    /// # Errors
    /// Non-positive or non-finite diameter or coefficients.
    pub fn new(diameter_m: f64, ct: f64, cp: f64) -> Result<Self, PropulsionError> {
        Ok(Self {
            diameter_m: positive("propeller diameter_m", diameter_m, "m")?,
            ct: positive("thrust_coefficient_ct", ct, "(-)")?,
            cp: positive("power_coefficient_cp", cp, "(-)")?,
            ct_per_krpm: 0.0,
            cp_per_krpm: 0.0,
            installed_thrust_loss: 0.0,
        })
    }

    /// A propeller from rotor-convention coefficients of seed eqs (21)-(22).
    ///
    /// # Errors
    /// As [`Propeller::new`].
    pub fn from_rotor_coefficients(
        radius_m: f64,
        ct_rotor: f64,
        cq_rotor: f64,
    ) -> Result<Self, PropulsionError> {
        let radius_m = positive("rotor radius_m", radius_m, "m")?;
        Self::new(
            2.0 * radius_m,
            ct_rotor_to_prop(ct_rotor),
            cq_rotor_to_cp_prop(cq_rotor),
        )
    }

    /// Adds a linear dependence of the coefficients on rotor speed (Reynolds effect), per 1000 rpm.
    ///
    /// # Errors
    /// Non-finite slopes, or slopes that make a coefficient non-positive at 0 rpm.
    pub fn with_speed_dependence(
        mut self,
        ct_per_krpm: f64,
        cp_per_krpm: f64,
    ) -> Result<Self, PropulsionError> {
        finite("ct_per_krpm", ct_per_krpm, "1/krpm")?;
        finite("cp_per_krpm", cp_per_krpm, "1/krpm")?;
        self.ct_per_krpm = ct_per_krpm;
        self.cp_per_krpm = cp_per_krpm;
        Ok(self)
    }

    /// Sets the installed-thrust loss (seed: 0.11).
    ///
    /// # Errors
    /// A loss outside `[0, 1)`.
    pub fn with_installed_loss(mut self, loss: f64) -> Result<Self, PropulsionError> {
        self.installed_thrust_loss = fraction("installed_thrust_loss_fraction", loss, true, false)?;
        Ok(self)
    }

    /// Diameter, m.
    pub fn diameter_m(&self) -> f64 {
        self.diameter_m
    }

    /// Installed-thrust loss fraction.
    pub fn installed_thrust_loss(&self) -> f64 {
        self.installed_thrust_loss
    }

    /// Propeller-table thrust coefficient at `speed_rpm`.
    pub fn ct_at(&self, speed_rpm: f64) -> f64 {
        self.ct + self.ct_per_krpm * speed_rpm / 1000.0
    }

    /// Propeller-table power coefficient at `speed_rpm`.
    pub fn cp_at(&self, speed_rpm: f64) -> f64 {
        self.cp + self.cp_per_krpm * speed_rpm / 1000.0
    }

    /// Rotor-convention thrust coefficient (seed eq 21) at `speed_rpm`.
    pub fn ct_rotor_at(&self, speed_rpm: f64) -> f64 {
        ct_prop_to_rotor(self.ct_at(speed_rpm))
    }

    /// Rotor-convention torque coefficient (seed eq 22) at `speed_rpm`.
    pub fn cq_rotor_at(&self, speed_rpm: f64) -> f64 {
        cp_prop_to_cq_rotor(self.cp_at(speed_rpm))
    }

    /// Static (stand) thrust, N, at `speed_rpm`: `T = C_T rho n^2 D^4`.
    pub fn thrust_n(&self, speed_rpm: f64, rho_kg_m3: f64) -> f64 {
        let n = speed_rpm / 60.0;
        self.ct_at(speed_rpm) * rho_kg_m3 * n * n * self.diameter_m.powi(4)
    }

    /// Shaft power, W, at `speed_rpm`: `P = C_P rho n^3 D^5`.
    pub fn shaft_power_w(&self, speed_rpm: f64, rho_kg_m3: f64) -> f64 {
        let n = speed_rpm / 60.0;
        self.cp_at(speed_rpm) * rho_kg_m3 * n * n * n * self.diameter_m.powi(5)
    }

    /// Shaft torque, N m, at `speed_rpm`: `Q = P / (2 pi n) = C_P rho n^2 D^5 / (2 pi)`.
    pub fn torque_nm(&self, speed_rpm: f64, rho_kg_m3: f64) -> f64 {
        let n = speed_rpm / 60.0;
        self.cp_at(speed_rpm) * rho_kg_m3 * n * n * self.diameter_m.powi(5) / (2.0 * PI)
    }

    /// Stand thrust the propeller must make so that the installed rotor makes `thrust_n`.
    pub fn stand_thrust_n(&self, installed_thrust_n: f64) -> f64 {
        installed_thrust_n / (1.0 - self.installed_thrust_loss)
    }

    /// Rotor speed, rpm, at which the propeller makes `stand_thrust_n` on the stand.
    ///
    /// Closed form for constant coefficients; with a speed dependence, a few Newton steps on
    /// `C_T(N) rho (N/60)^2 D^4 = T` starting from the constant-coefficient speed.
    ///
    /// # Errors
    /// Negative or non-finite thrust, or a density that is not positive.
    pub fn speed_for_thrust_rpm(
        &self,
        stand_thrust_n: f64,
        rho_kg_m3: f64,
    ) -> Result<f64, PropulsionError> {
        if !(stand_thrust_n.is_finite() && stand_thrust_n >= 0.0) {
            return Err(PropulsionError::InvalidThrust {
                thrust_n: stand_thrust_n,
            });
        }
        let rho_kg_m3 = positive("air_density_kg_m3", rho_kg_m3, "kg/m^3")?;
        let k = rho_kg_m3 * self.diameter_m.powi(4) / 3600.0;
        let mut n_rpm = (stand_thrust_n / (self.ct * k)).sqrt();
        if self.ct_per_krpm != 0.0 {
            for _ in 0..8 {
                let f = self.ct_at(n_rpm) * k * n_rpm * n_rpm - stand_thrust_n;
                let df = k
                    * (2.0 * self.ct_at(n_rpm) * n_rpm + self.ct_per_krpm / 1000.0 * n_rpm * n_rpm);
                if df <= 0.0 {
                    break;
                }
                n_rpm -= f / df;
            }
            if !(n_rpm.is_finite() && n_rpm >= 0.0 && self.ct_at(n_rpm) > 0.0) {
                return Err(aloft_core::InvalidParameter {
                    name: "ct_per_krpm",
                    value: self.ct_per_krpm,
                    unit: "1/krpm",
                    expected: "a speed dependence that keeps C_T positive at the operating speed",
                }
                .into());
            }
        }
        Ok(n_rpm)
    }

    /// Figure of merit `FM = C_T^1.5 / (sqrt(pi/2) C_P)` at `speed_rpm` (propeller convention):
    /// ideal induced power over shaft power.
    pub fn figure_of_merit(&self, speed_rpm: f64) -> f64 {
        self.ct_at(speed_rpm).powf(1.5) / ((PI / 2.0).sqrt() * self.cp_at(speed_rpm))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative tolerance for identities that are exact in real arithmetic (a few ulps).
    const EXACT: f64 = 1e-12;

    #[test]
    fn rotor_and_table_conventions_give_the_same_thrust_and_torque() {
        let p = Propeller::new(0.3556, 0.11, 0.045).unwrap();
        let rho = 1.2;
        let rpm = 6000.0;
        let omega = rpm_to_radps(rpm);
        let r = p.diameter_m() / 2.0;
        let t_rotor = p.ct_rotor_at(rpm) * rho * PI * r.powi(4) * omega * omega;
        let q_rotor = p.cq_rotor_at(rpm) * rho * PI * r.powi(5) * omega * omega;
        assert!((t_rotor / p.thrust_n(rpm, rho) - 1.0).abs() < EXACT);
        assert!((q_rotor / p.torque_nm(rpm, rho) - 1.0).abs() < EXACT);
        // power = torque * omega
        assert!((p.torque_nm(rpm, rho) * omega / p.shaft_power_w(rpm, rho) - 1.0).abs() < EXACT);
    }

    #[test]
    fn conversions_round_trip() {
        assert!((ct_rotor_to_prop(ct_prop_to_rotor(0.1)) - 0.1).abs() < EXACT);
        assert!((cq_rotor_to_cp_prop(cp_prop_to_cq_rotor(0.04)) - 0.04).abs() < EXACT);
        let a = Propeller::from_rotor_coefficients(0.2, 0.012, 0.0011).unwrap();
        assert!((a.ct_rotor_at(0.0) - 0.012).abs() < EXACT);
        assert!((a.cq_rotor_at(0.0) - 0.0011).abs() < EXACT);
    }

    #[test]
    fn speed_for_thrust_inverts_thrust() {
        let p = Propeller::new(0.254, 0.1, 0.04)
            .unwrap()
            .with_speed_dependence(0.002, 0.0005)
            .unwrap();
        for t in [0.5, 3.0, 10.0, 25.0] {
            let n = p.speed_for_thrust_rpm(t, 1.225).unwrap();
            // Newton converges quadratically; 1e-9 relative is far below any data accuracy.
            assert!((p.thrust_n(n, 1.225) / t - 1.0).abs() < 1e-9, "t={t} n={n}");
        }
        assert_eq!(
            p.speed_for_thrust_rpm(0.0, 1.225).unwrap().to_bits(),
            0f64.to_bits()
        );
    }

    #[test]
    fn bad_inputs_are_typed_errors() {
        assert!(matches!(
            Propeller::new(0.0, 0.1, 0.04),
            Err(PropulsionError::InvalidParameter(_))
        ));
        assert!(Propeller::new(0.3, f64::NAN, 0.04).is_err());
        assert!(Propeller::new(0.3, 0.1, 0.04)
            .unwrap()
            .with_installed_loss(1.0)
            .is_err());
        let p = Propeller::new(0.3, 0.1, 0.04).unwrap();
        assert!(matches!(
            p.speed_for_thrust_rpm(-1.0, 1.2),
            Err(PropulsionError::InvalidThrust { .. })
        ));
        assert!(p.speed_for_thrust_rpm(1.0, 0.0).is_err());
    }
}
