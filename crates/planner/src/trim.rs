//! Trim: the thrust vector from the force balance, the attitude it implies, and the electrical
//! power of the flight condition.
//!
//! Force balance in ENU (Newton, the survey seed's eq 16 without the rotational part):
//!
//! `m a = T + m g + F_D(v_air)`, so `T = m a + m g e_up + f_D(|v_air|) v_air / |v_air|`
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `m` | total mass (airframe, battery, payload) | kg |
//! | `a` | acceleration over the ground (the trajectory's, centripetal included) | m/s^2 |
//! | `T` | thrust vector along the rotor axis | N |
//! | `v_air` | velocity of the vehicle relative to the air, `v_ground - wind` | m/s |
//! | `f_D` | cubic drag of power seed eq (6) | N |
//!
//! With body-axis drag (`aloft_power::drag`, "Deviation") the horizontal drag is split along the
//! heading and its right, `k_x v_f f + k_y v_r r`, so the heading matters: missions head along
//! the track, replays along the logged yaw.
//!
//! The attitude follows from the thrust axis `t = T / |T|` with the heading along the track:
//! with `f`, `r` the forward and right horizontal unit vectors, `sin(roll) = t.r`,
//! `tan(pitch) = -t.f / t.up` (Z-Y-X Euler angles of a forward-right-down body, as in
//! `aloft_power::angle_of_attack`).
//!
//! # Inflow and the climb term: no double counting
//! The four-term model gets the thrust `|T|` (scaled for ground effect), the HORIZONTAL air
//! velocity `v_h` and the vertical air speed `v_z` separately:
//! - geometric angle of attack (default): `Vn = v_h . t`, `Vp = |v_h - Vn t|`, airspeed `|v_h|`;
//! - the paper's eqs (3)-(4): `Vn = |v_h| sin(roll) sin(pitch)`, `Vp = |v_h| cos(roll) cos(pitch)`;
//! - climb power, eq (13): `P_c = m g v_z` with `v_z` the vertical speed relative to the air.
//!
//! Physically the axial flow of a climb enters the rotor inflow (`Vn` would include `v_z`); but
//! then `T (v_i + Vn)` of eq (8) already contains `T v_z ~ m g v_z`, which eq (13) adds again.
//! The paper keeps climb in its own term (its `Vn` is built from level-flight attitude only), so
//! the planner passes only the horizontal air velocity to the inflow and lets eq (13) carry the
//! climb, once. The vertical air speed still enters the drag in the force balance. Using the air-
//! relative `v_z` (not the ground's) in eq (13) makes a rising air mass lift the vehicle for free,
//! as it physically does; with no vertical wind the two are the same.
//!
//! With the geometric angle of attack in steady level flight `T Vn = T . v_h = f_D |v_h|`: eq (8)'s
//! work term is the parasitic power once more. The power model therefore takes `P_ind = T v_i`
//! with the geometric inflow (see `aloft_power::four_term`, "Deviation"), so drag work is counted
//! once, by eq (11).

use aloft_power::{AoaModel, FlightCondition, Inflow, PowerBreakdown};

use multiversion::multiversion;

use crate::aircraft::{Engine, Powered};
use crate::error::PlannerError;

/// Largest block [`Powered::trim_block`] takes.
pub const TRIM_BLOCK: usize = 64;

/// Result of a trim.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trim {
    /// Thrust magnitude (in ground effect: the thrust made, not the out-of-ground-effect
    /// equivalent), N.
    pub thrust_n: f64,
    /// Unit thrust axis, ENU.
    pub axis: [f64; 3],
    /// Horizontal airspeed, m/s.
    pub airspeed_mps: f64,
    /// Electrical power, W.
    pub electrical_w: f64,
}

/// Roll, pitch and yaw of a thrust axis with the nose along `forward` (east, north), rad.
///
/// Yaw is clockwise from north.
pub fn attitude_rad(axis: [f64; 3], forward: [f64; 2]) -> (f64, f64, f64) {
    let t_f = axis[0] * forward[0] + axis[1] * forward[1];
    let t_r = axis[0] * forward[1] - axis[1] * forward[0];
    let roll = t_r.clamp(-1.0, 1.0).asin();
    let pitch = (-t_f).atan2(axis[2]);
    (roll, pitch, forward[0].atan2(forward[1]))
}

/// Bank angle: tilt of the thrust axis in the vertical plane across the track,
/// `atan2(t.r, t.up)`, rad (positive to the right).
pub fn bank_rad(axis: [f64; 3], forward: [f64; 2]) -> f64 {
    let t_r = axis[0] * forward[1] - axis[1] * forward[0];
    t_r.atan2(axis[2])
}

/// Thrust, axis and inflow of one sample before the power model (shared by [`Powered::trim`]
/// and [`Powered::trim_block`], so both do the same arithmetic).
#[derive(Debug, Clone, Copy, Default)]
struct Balance {
    thrust_n: f64,
    axis: [f64; 3],
    airspeed_mps: f64,
    inflow: Inflow,
}

/// [`Powered::balance`] of every sample of a block (slices of one length): a loop with no
/// data-dependent branch, which the compiler runs in vector lanes (see `aloft_power`'s batch
/// module: the same arithmetic as one sample at a time, bit for bit, on any instruction set).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+fma", "x86_64+avx2+fma"))]
fn balance_block<'a>(
    powered: &Powered<'a>,
    acc_mps2: &[[f64; 3]],
    vel_air_mps: &[[f64; 3]],
    forward: &[[f64; 2]],
    out: &mut [Balance],
) {
    for (j, b) in out.iter_mut().enumerate() {
        *b = powered.balance(acc_mps2[j], vel_air_mps[j], forward[j]);
    }
}

impl Powered<'_> {
    /// The force balance and the inflow of one sample.
    #[inline(always)]
    fn balance(&self, acc_mps2: [f64; 3], vel_air_mps: [f64; 3], forward: [f64; 2]) -> Balance {
        let m = self.mass_kg;
        let [vx, vy, vz] = vel_air_mps;
        let speed = (vx * vx + vy * vy + vz * vz).sqrt();
        // f_D(v) / v = mu1 + mu2 v + mu3 v^2 (eq 6 divided by v): no division on the hot path,
        // and 0 N of drag at zero airspeed since f_D(0) = 0 multiplies v_air = 0.
        let drag = self.aircraft.drag();
        let (mu1, mu2, mu3) = drag.coefficients();
        let k = mu1 + speed * (mu2 + speed * mu3);
        let (tx, ty) = match drag.body_axes() {
            None => (m * acc_mps2[0] + k * vx, m * acc_mps2[1] + k * vy),
            // Body-axis drag: the air velocity split along the heading `f` and its right
            // `r = (f_n, -f_e)`, each with its own coefficient (aloft_power::drag).
            Some(_) => {
                let [kx, ky, _] = drag.axis_coefficients(speed);
                let [fe, fn_] = forward;
                let v_f = vx * fe + vy * fn_;
                let v_r = vx * fn_ - vy * fe;
                (
                    m * acc_mps2[0] + kx * v_f * fe + ky * v_r * fn_,
                    m * acc_mps2[1] + kx * v_f * fn_ - ky * v_r * fe,
                )
            }
        };
        let tz = m * acc_mps2[2] + self.weight_n + k * vz;
        let thrust = (tx * tx + ty * ty + tz * tz).sqrt();
        let inv = 1.0 / thrust;
        let axis = [tx * inv, ty * inv, tz * inv];
        let vh2 = vx * vx + vy * vy;
        let vh = vh2.sqrt();
        let inflow = match self.aoa {
            AoaModel::Geometric => {
                let normal = vx * axis[0] + vy * axis[1];
                Inflow {
                    normal_mps: normal,
                    parallel_mps: (vh2 - normal * normal).max(0.0).sqrt(),
                }
            }
            AoaModel::Paper => {
                let t_f = axis[0] * forward[0] + axis[1] * forward[1];
                let t_r = axis[0] * forward[1] - axis[1] * forward[0];
                let cos_roll = (1.0 - t_r * t_r).max(0.0).sqrt();
                Inflow {
                    normal_mps: if cos_roll > 0.0 {
                        vh * t_r * (-t_f / cos_roll)
                    } else {
                        0.0
                    },
                    parallel_mps: vh * axis[2].max(0.0),
                }
            }
        };
        Balance {
            thrust_n: thrust,
            axis,
            airspeed_mps: vh,
            inflow,
        }
    }

    /// The force balance alone (no power model): thrust, N, the unit thrust axis (ENU) and the
    /// horizontal airspeed, m/s, exactly as [`Self::trim`] computes them. The flight envelope
    /// ([`crate::envelope`]) searches on it.
    #[inline]
    pub(crate) fn thrust_axis(
        &self,
        acc_mps2: [f64; 3],
        vel_air_mps: [f64; 3],
        forward: [f64; 2],
    ) -> (f64, [f64; 3], f64) {
        let b = self.balance(acc_mps2, vel_air_mps, forward);
        (b.thrust_n, b.axis, b.airspeed_mps)
    }

    /// Electrical power of a balanced sample with vertical air speed `vz` and ground-effect
    /// factor `ground_factor`, W.
    #[inline(always)]
    fn power_of(&self, b: &Balance, vz: f64, ground_factor: f64) -> Result<f64, PlannerError> {
        Ok(match &self.engine {
            Engine::FourTerm(model) => {
                model
                    .evaluate_condition(&FlightCondition {
                        thrust_n: b.thrust_n * ground_factor,
                        airspeed_mps: b.airspeed_mps,
                        inflow: b.inflow,
                        climb_rate_mps: vz,
                        aoa: self.aoa,
                    })?
                    .electrical_w
            }
            Engine::Chain(system) => {
                let n = f64::from(system.rotor_count());
                let rotor = system.rotor_at_thrust(b.thrust_n * ground_factor / n)?;
                let supply = rotor.supply_power_w * n;
                // Climb: the paper's eq (13) through the chain's shaft-to-supply efficiency.
                let climb = if rotor.efficiency > 0.0 {
                    self.weight_n * vz / rotor.efficiency
                } else {
                    0.0
                };
                // The model-error scale (1 unless a scenario draws one: then bit for bit).
                (supply + climb).max(0.0) * self.aircraft.chain_power_scale()
            }
        })
    }

    /// Trim for acceleration `acc_mps2` and air-relative velocity `vel_air_mps` (ENU), heading
    /// along `forward`, with the ground-effect factor `ground_factor` = `T_inf / T` (1 away from
    /// the ground).
    ///
    /// # Errors
    /// A flight condition the power model rejects (non-finite values), or a thrust the propulsion
    /// chain cannot make.
    #[inline]
    pub fn trim(
        &self,
        acc_mps2: [f64; 3],
        vel_air_mps: [f64; 3],
        forward: [f64; 2],
        ground_factor: f64,
    ) -> Result<Trim, PlannerError> {
        let b = self.balance(acc_mps2, vel_air_mps, forward);
        let electrical_w = self.power_of(&b, vel_air_mps[2], ground_factor)?;
        Ok(Trim {
            thrust_n: b.thrust_n,
            axis: b.axis,
            airspeed_mps: b.airspeed_mps,
            electrical_w,
        })
    }

    /// The four terms of the power model at a trim (same inputs as [`Self::trim`]); `None` when
    /// the power comes from the propulsion chain, which has no such terms.
    ///
    /// # Errors
    /// As [`Self::trim`].
    pub fn power_terms(
        &self,
        acc_mps2: [f64; 3],
        vel_air_mps: [f64; 3],
        forward: [f64; 2],
        ground_factor: f64,
    ) -> Result<Option<PowerBreakdown>, PlannerError> {
        let b = self.balance(acc_mps2, vel_air_mps, forward);
        Ok(match &self.engine {
            Engine::FourTerm(model) => Some(model.evaluate_condition(&FlightCondition {
                thrust_n: b.thrust_n * ground_factor,
                airspeed_mps: b.airspeed_mps,
                inflow: b.inflow,
                climb_rate_mps: vel_air_mps[2],
                aoa: self.aoa,
            })?),
            Engine::Chain(_) => None,
        })
    }

    /// [`Self::trim`] for a block of samples (all slices of the length of `out`, at most
    /// [`TRIM_BLOCK`]): the same arithmetic, bit for bit, arranged in two passes (force balance,
    /// then power) so that the CPU overlaps the independent samples instead of waiting on each
    /// one's chain of square roots and divisions.
    ///
    /// # Errors
    /// The index of the first sample [`Self::trim`] rejects, with its error; the samples before
    /// it are written.
    pub fn trim_block(
        &self,
        acc_mps2: &[[f64; 3]],
        vel_air_mps: &[[f64; 3]],
        forward: &[[f64; 2]],
        ground_factor: &[f64],
        out: &mut [Trim],
    ) -> Result<(), (usize, PlannerError)> {
        let n = out.len();
        assert!(
            n <= TRIM_BLOCK
                && acc_mps2.len() == n
                && vel_air_mps.len() == n
                && forward.len() == n
                && ground_factor.len() == n,
            "trim_block: slices of one length up to TRIM_BLOCK"
        );
        let mut balances = [Balance::default(); TRIM_BLOCK];
        balance_block(self, acc_mps2, vel_air_mps, forward, &mut balances[..n]);
        if let Engine::FourTerm(model) = &self.engine {
            // The whole block through the power model's batch path (vector lanes); on an error,
            // the per-sample loop below finds and reports the failing sample.
            let mut conditions = [FlightCondition::default(); TRIM_BLOCK];
            for j in 0..n {
                let b = &balances[j];
                conditions[j] = FlightCondition {
                    thrust_n: b.thrust_n * ground_factor[j],
                    airspeed_mps: b.airspeed_mps,
                    inflow: b.inflow,
                    climb_rate_mps: vel_air_mps[j][2],
                    aoa: self.aoa,
                };
            }
            let mut watts = [0.0; TRIM_BLOCK];
            if model
                .electrical_of_conditions(&conditions[..n], &mut watts[..n])
                .is_ok()
            {
                for j in 0..n {
                    let b = &balances[j];
                    out[j] = Trim {
                        thrust_n: b.thrust_n,
                        axis: b.axis,
                        airspeed_mps: b.airspeed_mps,
                        electrical_w: watts[j],
                    };
                }
                return Ok(());
            }
        }
        for j in 0..n {
            let b = &balances[j];
            let electrical_w = self
                .power_of(b, vel_air_mps[j][2], ground_factor[j])
                .map_err(|e| (j, e))?;
            out[j] = Trim {
                thrust_n: b.thrust_n,
                axis: b.axis,
                airspeed_mps: b.airspeed_mps,
                electrical_w,
            };
        }
        Ok(())
    }

    /// Electrical power in steady level flight with horizontal air velocity `vel_air_mps`
    /// (east, north) and the heading `forward`, out of ground effect, W.
    ///
    /// # Errors
    /// As [`Self::trim`].
    pub fn level_power_w(
        &self,
        vel_air_mps: [f64; 2],
        forward: [f64; 2],
    ) -> Result<f64, PlannerError> {
        Ok(self
            .trim(
                [0.0; 3],
                [vel_air_mps[0], vel_air_mps[1], 0.0],
                forward,
                1.0,
            )?
            .electrical_w)
    }
}

#[cfg(test)]
mod tests {
    use crate::aircraft::Aircraft;
    use crate::test_support::{m100_aircraft, m100_airframe, m100_vehicle_params};
    use aloft_power::AoaModel;

    /// The M100 with body-axis drag `[mu2_x, mu2_y]`.
    fn with_axes(mu2: [f64; 2]) -> Aircraft {
        // test_support's M100 with the two keys added.
        let vehicle = aloft_power::Vehicle::new(aloft_power::VehicleParams {
            mu2_x_n_s2_per_m2: Some(mu2[0]),
            mu2_y_n_s2_per_m2: Some(mu2[1]),
            ..m100_vehicle_params()
        })
        .unwrap();
        Aircraft::four_term(m100_airframe(), vehicle, Default::default())
    }

    #[test]
    fn equal_body_axes_trim_as_the_scalar_law() {
        let scalar = m100_aircraft();
        let mu2 = scalar.drag().coefficients().1;
        let axes = with_axes([mu2, mu2]);
        let (a, b) = (
            scalar.at_mass(3.29, AoaModel::Geometric).unwrap(),
            axes.at_mass(3.29, AoaModel::Geometric).unwrap(),
        );
        for (vel, fwd) in [
            ([6.0, 2.0, 0.5], [0.6, 0.8]),
            ([-3.0, 7.0, 0.0], [1.0, 0.0]),
        ] {
            let ta = a.trim([0.3, -0.2, 0.0], vel, fwd, 1.0).unwrap();
            let tb = b.trim([0.3, -0.2, 0.0], vel, fwd, 1.0).unwrap();
            // The same force, split along two axes and summed: equal to rounding.
            assert!((ta.thrust_n - tb.thrust_n).abs() < 1e-9, "{ta:?} {tb:?}");
            assert!((ta.electrical_w - tb.electrical_w).abs() < 1e-6);
        }
    }

    #[test]
    fn a_larger_side_area_costs_power_only_flying_sideways() {
        let mu2 = m100_aircraft().drag().coefficients().1;
        let axes = with_axes([mu2, mu2 + 0.05]);
        let scalar = m100_aircraft();
        let (s, b) = (
            scalar.at_mass(3.29, AoaModel::Geometric).unwrap(),
            axes.at_mass(3.29, AoaModel::Geometric).unwrap(),
        );
        // Flying north at 10 m/s: nose first (forward north), then sideways (forward east).
        let forward = b.level_power_w([0.0, 10.0], [0.0, 1.0]).unwrap();
        let sideways = b.level_power_w([0.0, 10.0], [1.0, 0.0]).unwrap();
        let reference = s.level_power_w([0.0, 10.0], [0.0, 1.0]).unwrap();
        assert!(
            (forward - reference).abs() < 1e-6,
            "{forward} vs {reference}"
        );
        assert!(sideways > forward + 1.0, "{sideways} vs {forward}");
    }
}
