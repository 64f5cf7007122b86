//! The flight envelope as a limit the vehicle flies at.
//!
//! A multirotor's position controller does not refuse a leg that asks for more than the vehicle
//! has: it saturates the tilt (PX4's `MPC_TILTMAX_AIR`, ArduPilot's `ANGLE_MAX`), the climb and
//! descent rates and the thrust, and the vehicle keeps its track but flies it slower (into a
//! strong wind, it loses ground speed). The planner does the same, sample by sample.
//!
//! # Limits
//! A flight state (acceleration `a`, ground velocity `v`, wind `w`, air velocity `v - w`) is
//! within the envelope when the force balance of [`crate::trim`] gives
//!
//! | limit | condition | from |
//! |---|---|---|
//! | tilt | `t_up >= cos(tilt_max)` (the thrust axis within the tilt limit of the vertical) | `max_tilt_deg` |
//! | thrust | `|T| <= T_max` | `max_thrust_n` |
//! | airspeed | horizontal `|v - w| <= v_air,max` | `max_airspeed_mps` (none by default) |
//! | climb | `v_up <= v_climb,max` | `max_climb_rate_mps` |
//! | descent | `-v_up <= v_descent,max` | `max_descent_rate_mps` |
//!
//! # Flying at the edge
//! Where a sample of the planned trajectory is outside the envelope, the vehicle flies the same
//! path slower: the sample's velocity is scaled by `q` and its acceleration by `q^2` (the same
//! path at `1 / q` of the time: a tangential acceleration `dv/dt` and a centripetal `v^2 / r`
//! both scale by `q^2`), with the largest `q` in `(0, 1]` that is within the envelope
//! ([`Envelope::fastest_fraction`]). The step then takes `h / q` instead of `h`. The largest
//! fraction is found on the force balance alone (no power model): a scan of 16 fractions from
//! the top, then bisection to 1e-9 between the largest that holds and the one above it. In level
//! flight the airspeed `|q v - w|` is convex in `q` and the tilt grows with the airspeed, so the
//! fractions that hold form one interval and the scan finds its top.
//!
//! This is quasi-steady: the speed follows the limit at each sample, without the time the
//! vehicle would take to slow down or speed up between two samples of different limits. The
//! energy of those transitions is left out (they are a few seconds at the ends of a limited
//! stretch).
//!
//! # No progress
//! When no fraction of at least [`MIN_FRACTION`] holds, the vehicle cannot fly the path at all
//! there: it cannot make headway along the track against the wind, or it cannot hold its
//! position (a hover in a wind beyond what it can fly against, a thrust beyond its limit). The
//! mission is then infeasible at that point ([`crate::Shortfall::NoProgress`]), not wrong.
//!
//! # The steady airspeed limit
//! [`Envelope::max_level_airspeed_mps`] is the largest airspeed of steady level flight within the
//! envelope at one mass (the answer a message gives: "flies at most 15.1 m/s of airspeed within
//! its 35 deg tilt limit"), found the same way over airspeeds up to the power model's 150 m/s.

use serde::{Deserialize, Serialize};

use crate::aircraft::Powered;
use crate::airframe::Airframe;
use crate::trim::Trim;

/// The smallest fraction of the planned speed the vehicle is flown at: below it (an 8 m/s leg
/// flown at 8 cm/s) the path is one it cannot fly, and the mission is infeasible there.
pub const MIN_FRACTION: f64 = 0.01;

/// Fractions of the scan of [`Envelope::fastest_fraction`] (besides 0 and 1).
const SCAN: usize = 16;

/// Bisection steps after the scan: the fraction to `2^-40 / 16`, far below any physical effect.
const BISECTIONS: usize = 40;

/// The largest airspeed [`Envelope::max_level_airspeed_mps`] considers, m/s: the power model's
/// range.
const MAX_AIRSPEED_SEARCHED_MPS: f64 = 150.0;

/// A limit of the flight envelope (in JSON: `tilt`, `thrust`, `airspeed`, `climb`, `descent`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Limit {
    /// The tilt of the thrust axis from the vertical.
    Tilt,
    /// The total thrust.
    Thrust,
    /// The horizontal airspeed.
    Airspeed,
    /// The climb rate.
    Climb,
    /// The descent rate.
    Descent,
}

impl Limit {
    /// The limit's name in messages and JSON (`tilt`, `thrust`, `airspeed`, `climb`, `descent`).
    pub fn name(self) -> &'static str {
        match self {
            Limit::Tilt => "tilt",
            Limit::Thrust => "thrust",
            Limit::Airspeed => "airspeed",
            Limit::Climb => "climb rate",
            Limit::Descent => "descent rate",
        }
    }
}

impl std::fmt::Display for Limit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The limits of one airframe, ready to check flight states against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    cos_tilt_max: f64,
    max_tilt_deg: f64,
    max_thrust_n: f64,
    max_airspeed_mps: f64,
    max_climb_mps: f64,
    max_descent_mps: f64,
}

impl Envelope {
    /// The envelope of `airframe` under gravity `g_mps2` (which sets the default thrust limit).
    pub fn of(airframe: &Airframe, g_mps2: f64) -> Self {
        Self {
            cos_tilt_max: airframe.max_tilt_rad().cos(),
            max_tilt_deg: airframe.max_tilt_rad().to_degrees(),
            max_thrust_n: airframe.max_thrust_n(g_mps2),
            max_airspeed_mps: airframe.max_airspeed_mps().unwrap_or(f64::INFINITY),
            max_climb_mps: airframe.max_climb_rate_mps(),
            max_descent_mps: airframe.max_descent_rate_mps(),
        }
    }

    /// The value of `limit` and its unit, for messages (`35.0`, `deg`).
    pub fn value_of(&self, limit: Limit) -> (f64, &'static str) {
        match limit {
            Limit::Tilt => (self.max_tilt_deg, "deg"),
            Limit::Thrust => (self.max_thrust_n, "N"),
            Limit::Airspeed => (self.max_airspeed_mps, "m/s"),
            Limit::Climb => (self.max_climb_mps, "m/s"),
            Limit::Descent => (self.max_descent_mps, "m/s"),
        }
    }

    /// The first limit a trimmed state exceeds (its thrust and axis from the force balance, its
    /// horizontal airspeed, and `v_up_mps` the vertical ground speed); `None` within all.
    #[inline]
    pub fn exceeded_by(
        &self,
        thrust_n: f64,
        axis_up: f64,
        airspeed_mps: f64,
        v_up_mps: f64,
    ) -> Option<Limit> {
        // 1e-9 relative on the rates: a rate typed equal to the limit is within it.
        if axis_up < self.cos_tilt_max {
            Some(Limit::Tilt)
        } else if thrust_n > self.max_thrust_n {
            Some(Limit::Thrust)
        } else if airspeed_mps > self.max_airspeed_mps {
            Some(Limit::Airspeed)
        } else if v_up_mps > self.max_climb_mps * (1.0 + 1e-9) {
            Some(Limit::Climb)
        } else if -v_up_mps > self.max_descent_mps * (1.0 + 1e-9) {
            Some(Limit::Descent)
        } else {
            None
        }
    }

    /// [`Self::exceeded_by`] of a trim and its vertical ground speed.
    #[inline]
    pub fn exceeded_by_trim(&self, trim: &Trim, v_up_mps: f64) -> Option<Limit> {
        self.exceeded_by(trim.thrust_n, trim.axis[2], trim.airspeed_mps, v_up_mps)
    }

    /// The first limit the state (acceleration, ground velocity, wind, heading) exceeds with
    /// `pw`; `None` within all.
    pub fn exceeded(
        &self,
        pw: &Powered<'_>,
        acc_mps2: [f64; 3],
        vel_mps: [f64; 3],
        wind_mps: [f64; 3],
        forward: [f64; 2],
    ) -> Option<Limit> {
        let v_air = [
            vel_mps[0] - wind_mps[0],
            vel_mps[1] - wind_mps[1],
            vel_mps[2] - wind_mps[2],
        ];
        let (thrust_n, axis, airspeed_mps) = pw.thrust_axis(acc_mps2, v_air, forward);
        if !(thrust_n.is_finite() && axis[2].is_finite()) {
            return Some(Limit::Thrust);
        }
        self.exceeded_by(thrust_n, axis[2], airspeed_mps, vel_mps[2])
    }

    /// The largest fraction `q` in `(0, 1)` of the planned velocity `vel_mps` (and `q^2` of the
    /// planned acceleration `acc_mps2`) that is within the envelope in the wind `wind_mps`, with
    /// the limit the vehicle then flies at; `Ok(None)` when the planned state is within it;
    /// `Err` with the limit that binds when no fraction of at least [`MIN_FRACTION`] is (the
    /// path cannot be flown here).
    pub fn fastest_fraction(
        &self,
        pw: &Powered<'_>,
        acc_mps2: [f64; 3],
        vel_mps: [f64; 3],
        wind_mps: [f64; 3],
        forward: [f64; 2],
    ) -> Result<Option<(f64, Limit)>, Limit> {
        let beyond = |q: f64| {
            self.exceeded(
                pw,
                acc_mps2.map(|a| a * q * q),
                vel_mps.map(|v| v * q),
                wind_mps,
                forward,
            )
        };
        let Some(mut limit) = beyond(1.0) else {
            return Ok(None);
        };
        // The scan from the top: the largest fraction that holds, and the one above it (with
        // the limit it exceeds).
        let mut above = 1.0;
        let mut holds = None;
        for k in (1..SCAN).rev() {
            let q = k as f64 / SCAN as f64;
            match beyond(q) {
                None => {
                    holds = Some(q);
                    break;
                }
                Some(l) => {
                    above = q;
                    limit = l;
                }
            }
        }
        let mut lo = match holds {
            Some(q) => q,
            None => {
                // Below the scan: the smallest fraction allowed, else the path cannot be flown.
                let limit = beyond(MIN_FRACTION);
                match limit {
                    None => MIN_FRACTION,
                    Some(l) => {
                        return Err(self.binding_at_rest(pw, wind_mps, forward).unwrap_or(l))
                    }
                }
            }
        };
        let mut hi = above;
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            match beyond(mid) {
                None => lo = mid,
                Some(l) => {
                    hi = mid;
                    limit = l;
                }
            }
        }
        Ok(Some((lo, limit)))
    }

    /// The limit a hold in the wind exceeds (the vehicle still over the ground), if any: the
    /// reason a path cannot be flown when even its slowest fraction fails is usually that the
    /// wind alone is beyond the vehicle.
    fn binding_at_rest(
        &self,
        pw: &Powered<'_>,
        wind_mps: [f64; 3],
        forward: [f64; 2],
    ) -> Option<Limit> {
        self.exceeded(pw, [0.0; 3], [0.0; 3], wind_mps, forward)
    }

    /// The largest airspeed of steady level flight within the envelope with `pw`, m/s, and the
    /// limit that bounds it (heading into the air velocity); 0 when not even a hover in still
    /// air is within it.
    pub fn max_level_airspeed_mps(&self, pw: &Powered<'_>) -> (f64, Limit) {
        let beyond = |v: f64| self.exceeded(pw, [0.0; 3], [0.0, v, 0.0], [0.0; 3], [0.0, 1.0]);
        if let Some(l) = beyond(0.0) {
            return (0.0, l);
        }
        // A scan of 150 points (1 m/s) from the bottom for the first airspeed beyond, then
        // bisection below it (drag laws need not be monotonic over the whole range).
        let points = MAX_AIRSPEED_SEARCHED_MPS as usize;
        let mut lo = 0.0;
        let mut hi_limit = None;
        for k in 1..=points {
            let v = k as f64;
            match beyond(v) {
                None => lo = v,
                Some(l) => {
                    hi_limit = Some((v, l));
                    break;
                }
            }
        }
        let Some((mut hi, limit)) = hi_limit else {
            return (MAX_AIRSPEED_SEARCHED_MPS, Limit::Airspeed);
        };
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if beyond(mid).is_none() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (lo, limit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::m100_aircraft;
    use aloft_core::STANDARD_GRAVITY_MPS2;
    use aloft_power::AoaModel;

    /// The airspeed at which the M100's cubic drag tilts the thrust to `tilt_deg` in level
    /// flight, `f_D(v) = m g tan(tilt)` with `f_D = mu1 v + mu2 v^2 + mu3 v^3` (power seed eq 6,
    /// Fig. 3's constants), by bisection on the polynomial itself: independent of the planner's
    /// force balance.
    fn drag_limited_airspeed(mass_kg: f64, g: f64, tilt_deg: f64) -> f64 {
        let (mu1, mu2, mu3) = (0.1816, -0.02326, 0.004045);
        let target = mass_kg * g * tilt_deg.to_radians().tan();
        let f = |v: f64| mu1 * v + mu2 * v * v + mu3 * v * v * v - target;
        let (mut lo, mut hi) = (0.0, 100.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if f(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    #[test]
    fn the_steady_airspeed_limit_is_where_drag_tilts_the_thrust_to_the_limit() {
        let aircraft = m100_aircraft();
        let env = Envelope::of(aircraft.airframe(), aircraft.gravity_mps2());
        for mass in [2.355, 3.29] {
            let pw = aircraft.at_mass(mass, AoaModel::Geometric).unwrap();
            let (v, limit) = env.max_level_airspeed_mps(&pw);
            let want = drag_limited_airspeed(mass, aircraft.gravity_mps2(), 35.0);
            assert_eq!(limit, Limit::Tilt);
            // Both bisect to far below a micrometre per second.
            assert!((v - want).abs() < 1e-6, "{mass} kg: {v} vs {want}");
        }
    }

    #[test]
    fn into_a_headwind_the_fastest_fraction_flies_at_the_tilt_limited_airspeed() {
        // Level cruise north at 12 m/s into a 10 m/s wind from the north: 22 m/s of airspeed
        // is beyond the tilt limit; the vehicle holds `v_g = A - 10` with A the drag-limited
        // airspeed (no acceleration, no cross wind), so q = (A - 10) / 12.
        let aircraft = m100_aircraft();
        let env = Envelope::of(aircraft.airframe(), aircraft.gravity_mps2());
        let pw = aircraft.at_mass(2.355, AoaModel::Geometric).unwrap();
        let a = drag_limited_airspeed(2.355, aircraft.gravity_mps2(), 35.0);
        let (q, limit) = env
            .fastest_fraction(
                &pw,
                [0.0; 3],
                [0.0, 12.0, 0.0],
                [0.0, -10.0, 0.0],
                [0.0, 1.0],
            )
            .unwrap()
            .unwrap();
        assert_eq!(limit, Limit::Tilt);
        assert!(
            (12.0 * q - (a - 10.0)).abs() < 1e-6,
            "{} vs {}",
            12.0 * q,
            a - 10.0
        );
        // A cross wind of 6 m/s: the vehicle crabs, v_g = sqrt(A^2 - 36) (along-track wind 0).
        let (q, _) = env
            .fastest_fraction(&pw, [0.0; 3], [0.0, 20.0, 0.0], [6.0, 0.0, 0.0], [0.0, 1.0])
            .unwrap()
            .unwrap();
        let want = (a * a - 36.0).sqrt();
        assert!((20.0 * q - want).abs() < 1e-6, "{} vs {want}", 20.0 * q);
    }

    #[test]
    fn a_wind_beyond_the_vehicle_cannot_be_flown_against_or_hovered_in() {
        let aircraft = m100_aircraft();
        let env = Envelope::of(aircraft.airframe(), aircraft.gravity_mps2());
        let pw = aircraft.at_mass(2.355, AoaModel::Geometric).unwrap();
        let a = drag_limited_airspeed(2.355, STANDARD_GRAVITY_MPS2, 35.0);
        let wind = [0.0, -(a + 1.0), 0.0];
        assert_eq!(
            env.fastest_fraction(&pw, [0.0; 3], [0.0, 8.0, 0.0], wind, [0.0, 1.0]),
            Err(Limit::Tilt)
        );
        assert_eq!(
            env.fastest_fraction(&pw, [0.0; 3], [0.0; 3], wind, [0.0, 1.0]),
            Err(Limit::Tilt)
        );
        // Within it: a hover holds (fraction 1 of nothing).
        let calm = [0.0, -(a - 1.0), 0.0];
        assert_eq!(
            env.fastest_fraction(&pw, [0.0; 3], [0.0; 3], calm, [0.0, 1.0]),
            Ok(None)
        );
    }

    #[test]
    fn a_climb_beyond_the_rate_limit_is_flown_at_the_limit() {
        let aircraft = m100_aircraft();
        let env = Envelope::of(aircraft.airframe(), aircraft.gravity_mps2());
        let pw = aircraft.at_mass(2.355, AoaModel::Geometric).unwrap();
        let max = aircraft.airframe().max_climb_rate_mps();
        let (q, limit) = env
            .fastest_fraction(&pw, [0.0; 3], [0.0, 0.0, 2.0 * max], [0.0; 3], [0.0, 1.0])
            .unwrap()
            .unwrap();
        assert_eq!(limit, Limit::Climb);
        assert!((q - 0.5).abs() < 1e-9, "{q}");
        let (q, limit) = env
            .fastest_fraction(&pw, [0.0; 3], [0.0, 0.0, -3.0 * max], [0.0; 3], [0.0, 1.0])
            .unwrap()
            .unwrap();
        assert_eq!(limit, Limit::Descent);
        let descent = aircraft.airframe().max_descent_rate_mps();
        // Within the 1e-9 relative tolerance of the rate check.
        assert!((3.0 * max * q - descent).abs() < 1e-8, "{q}");
    }
}
