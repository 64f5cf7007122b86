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
//! fraction is found on the force balance alone (no power model): a bracket from the previous
//! sample's fraction (or a scan of 16 fractions from the top), then the root of the margin to
//! the limits by regula falsi (Illinois), to 1e-10. In level flight the airspeed `|q v - w|` is
//! convex in `q` and the tilt grows with the airspeed, so the fractions that hold form one
//! interval and the search finds its top.
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

/// Width of the bracket at which the search of the edge stops: far below any physical effect.
const TOLERANCE: f64 = 1e-10;

/// Most steps of the search within a bracket (it takes 4 to 10 on a smooth margin; the Illinois
/// halving keeps it from stalling at a kink, where two limits meet).
const MAX_STEPS: usize = 100;

/// The largest airspeed [`Envelope::max_level_airspeed_mps`] considers, m/s: the power model's
/// range.
const MAX_AIRSPEED_SEARCHED_MPS: f64 = 150.0;

/// A fraction of the planned speed, its margin and the limit the margin belongs to.
type Probe = (f64, f64, Limit);

/// A bracket of the edge: a fraction within the envelope and one beyond it (above), with their
/// margins; `None` when no fraction of at least [`MIN_FRACTION`] is within. `top` is the margin
/// of the fraction 1 (beyond).
fn bracket(
    slack: &impl Fn(f64) -> (f64, Limit),
    top: (f64, Limit),
    hint: Option<f64>,
) -> Option<(Probe, Probe)> {
    let mut hi = (1.0, top.0, top.1);
    // Around the hint: most samples of a slowed stretch fly within a thousandth of the one
    // before, faster or slower.
    if let Some(h) = hint.filter(|h| *h >= MIN_FRACTION && *h < 1.0) {
        let (sh, lh) = slack(h);
        if sh >= 0.0 {
            let up = (h + 1e-3).min(1.0);
            if up < 1.0 {
                let (su, lu) = slack(up);
                if su < 0.0 {
                    return Some(((h, sh, lh), (up, su, lu)));
                }
                return Some(((up, su, lu), hi));
            }
            return Some(((h, sh, lh), hi));
        }
        hi = (h, sh, lh);
        let down = h - 1e-3;
        if down >= MIN_FRACTION {
            let (sd, ld) = slack(down);
            if sd >= 0.0 {
                return Some(((down, sd, ld), hi));
            }
            hi = (down, sd, ld);
        }
    }
    // The scan from the top, below what is known to be beyond.
    let grid = (1..SCAN).rev().map(|k| k as f64 / SCAN as f64);
    for q in grid.chain([MIN_FRACTION]) {
        if q >= hi.0 {
            continue;
        }
        let (s, l) = slack(q);
        if s >= 0.0 {
            return Some(((q, s, l), hi));
        }
        hi = (q, s, l);
    }
    None
}

/// The edge within a bracket `[lo, hi]` (`lo` within, `hi` beyond) by regula falsi with the
/// Illinois modification, to 1e-10 (of a fraction, or in m/s of an airspeed): the last value
/// within and the limit the last one beyond exceeded.
fn illinois(slack: &impl Fn(f64) -> (f64, Limit), lo: Probe, hi: Probe) -> (f64, Limit) {
    let ((mut a, mut fa, _), (mut b, mut fb, mut limit)) = (lo, hi);
    // Which end the last step moved: +1 the low one, -1 the high one.
    let mut side = 0;
    for _ in 0..MAX_STEPS {
        if b - a <= TOLERANCE {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
        }
        let (fc, lc) = slack(c);
        if fc >= 0.0 {
            (a, fa) = (c, fc);
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            (b, fb, limit) = (c, fc, lc);
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    (a, limit)
}

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
    /// The rates as checked: 1e-9 relative above the limits, so that a rate typed equal to a
    /// limit is within it despite rounding.
    climb_checked_mps: f64,
    descent_checked_mps: f64,
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
            climb_checked_mps: airframe.max_climb_rate_mps() * (1.0 + 1e-9),
            descent_checked_mps: airframe.max_descent_rate_mps() * (1.0 + 1e-9),
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
        if axis_up < self.cos_tilt_max {
            Some(Limit::Tilt)
        } else if thrust_n > self.max_thrust_n {
            Some(Limit::Thrust)
        } else if airspeed_mps > self.max_airspeed_mps {
            Some(Limit::Airspeed)
        } else if v_up_mps > self.climb_checked_mps {
            Some(Limit::Climb)
        } else if -v_up_mps > self.descent_checked_mps {
            Some(Limit::Descent)
        } else {
            None
        }
    }

    /// How far within the envelope a trimmed state is: the smallest of the limits' margins,
    /// each scaled to be dimensionless (tilt `t_up - cos(tilt_max)`, the others `(limit -
    /// value) / limit`), and the limit it belongs to. Negative exactly where
    /// [`Self::exceeded_by`] names a limit (each margin is a difference of the same two numbers
    /// that it compares, times a positive constant, so it has the comparison's sign), and
    /// continuous in the state, so the search can find its root.
    fn slack(&self, thrust_n: f64, axis_up: f64, airspeed_mps: f64, v_up_mps: f64) -> (f64, Limit) {
        if !(thrust_n.is_finite() && axis_up.is_finite()) {
            return (-1.0, Limit::Thrust);
        }
        // The smallest margin; its name is the first limit exceeded in the order of
        // `exceeded_by` (tilt, thrust, airspeed, climb, descent) when any is.
        let tilt = axis_up - self.cos_tilt_max;
        let mut worst = (tilt, Limit::Tilt);
        let mut named = tilt < 0.0;
        let mut take = |margin: f64, limit: Limit| {
            if margin < worst.0 {
                worst.0 = margin;
                if !named {
                    worst.1 = limit;
                }
            }
            named |= margin < 0.0;
        };
        take(
            (self.max_thrust_n - thrust_n) / self.max_thrust_n,
            Limit::Thrust,
        );
        if self.max_airspeed_mps.is_finite() {
            take(
                (self.max_airspeed_mps - airspeed_mps) / self.max_airspeed_mps,
                Limit::Airspeed,
            );
        }
        take(
            (self.climb_checked_mps - v_up_mps) / self.max_climb_mps,
            Limit::Climb,
        );
        take(
            (self.descent_checked_mps + v_up_mps) / self.max_descent_mps,
            Limit::Descent,
        );
        worst
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
    /// path cannot be flown here). `hint` is a guess of the fraction (the previous sample's),
    /// which shortens the search when it is close; the answer does not depend on it beyond the
    /// search's tolerance, 1e-10.
    ///
    /// The search: a bracket `[lo, hi]` with `lo` within the envelope and `hi` beyond (tried
    /// first around the hint, else from a scan of 16 fractions from the top), then the root of
    /// the margin ([`Self::slack`]) between them by regula falsi with the Illinois modification
    /// (superlinear, and never leaving the bracket); the answer is the bracket's `lo`.
    pub fn fastest_fraction(
        &self,
        pw: &Powered<'_>,
        state: ([f64; 3], [f64; 3]),
        wind_mps: [f64; 3],
        forward: [f64; 2],
        hint: Option<f64>,
    ) -> Result<Option<(f64, Limit)>, Limit> {
        let air = (wind_mps, forward);
        let top = self.margin(pw, state, air, 1.0);
        self.fastest_fraction_beyond(pw, state, air, hint, top)
    }

    /// [`Self::fastest_fraction`] with the margin at the planned speed given (`top`, from the
    /// state's trim when it has one: [`Self::slack_of_trim`], which spares the search one force
    /// balance).
    pub(crate) fn fastest_fraction_beyond(
        &self,
        pw: &Powered<'_>,
        state: ([f64; 3], [f64; 3]),
        (wind_mps, forward): ([f64; 3], [f64; 2]),
        hint: Option<f64>,
        top: (f64, Limit),
    ) -> Result<Option<(f64, Limit)>, Limit> {
        if top.0 >= 0.0 {
            return Ok(None);
        }
        let slack = |q: f64| self.margin(pw, state, (wind_mps, forward), q);
        let Some((lo, hi)) = bracket(&slack, top, hint) else {
            return Err(self.binding_at_rest(pw, wind_mps, forward).unwrap_or(top.1));
        };
        Ok(Some(illinois(&slack, lo, hi)))
    }

    /// The margin ([`Self::slack`]) of the planned state (acceleration, ground velocity) flown
    /// at the fraction `q` of its speed in the wind, heading along `forward`.
    #[inline]
    fn margin(
        &self,
        pw: &Powered<'_>,
        (acc_mps2, vel_mps): ([f64; 3], [f64; 3]),
        (wind_mps, forward): ([f64; 3], [f64; 2]),
        q: f64,
    ) -> (f64, Limit) {
        let vel = vel_mps.map(|v| v * q);
        let v_air = [
            vel[0] - wind_mps[0],
            vel[1] - wind_mps[1],
            vel[2] - wind_mps[2],
        ];
        let (thrust_n, axis, airspeed_mps) =
            pw.thrust_axis(acc_mps2.map(|a| a * q * q), v_air, forward);
        self.slack(thrust_n, axis[2], airspeed_mps, vel[2])
    }

    /// The margin of a trimmed state with vertical ground speed `v_up_mps` ([`Self::slack`]).
    pub(crate) fn slack_of_trim(&self, trim: &Trim, v_up_mps: f64) -> (f64, Limit) {
        self.slack(trim.thrust_n, trim.axis[2], trim.airspeed_mps, v_up_mps)
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
        // Level, unaccelerated, heading into the air velocity, at airspeed `v`.
        let at = |v: f64| self.margin(pw, ([0.0; 3], [0.0, v, 0.0]), ([0.0; 3], [0.0, 1.0]), 1.0);
        let rest = at(0.0);
        if rest.0 < 0.0 {
            return (0.0, rest.1);
        }
        // A scan in steps of 2.5 m/s from the bottom for the first airspeed beyond (drag laws
        // need not be monotonic over the whole range; none turns within 2.5 m/s), then the edge
        // below it by regula falsi, as for a fraction of the speed.
        let mut lo = (0.0, rest.0, rest.1);
        for k in 1..=(MAX_AIRSPEED_SEARCHED_MPS / 2.5) as usize {
            let v = k as f64 * 2.5;
            let (m, l) = at(v);
            if m < 0.0 {
                return illinois(&at, lo, (v, m, l));
            }
            lo = (v, m, l);
        }
        (MAX_AIRSPEED_SEARCHED_MPS, Limit::Airspeed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aircraft::Aircraft;
    use crate::test_support::m100_aircraft;
    use aloft_core::STANDARD_GRAVITY_MPS2;
    use aloft_power::AoaModel;

    /// The envelope of `aircraft` and the aircraft at 2.355 kg (the M100 with a TB47D).
    fn envelope_at_2355(aircraft: &Aircraft) -> (Envelope, Powered<'_>) {
        let env = Envelope::of(aircraft.airframe(), aircraft.gravity_mps2());
        (env, aircraft.at_mass(2.355, AoaModel::Geometric).unwrap())
    }

    /// The airspeed at which the M100's cubic drag tilts the thrust to `tilt_deg` in level
    /// flight, `f_D(v) = m g tan(tilt)` with `f_D = mu1 v + mu2 v^2 + mu3 v^3` (power seed eq 6,
    /// Fig. 3's constants), by bisection on the polynomial itself: independent of the planner's
    /// force balance.
    fn drag_limited_airspeed(mass_kg: f64, g: f64, tilt_deg: f64) -> f64 {
        let (mu1, mu2, mu3) = (0.1816, -0.02326, 0.004045);
        let target = mass_kg * g * tilt_deg.to_radians().tan();
        let f = |v: f64| mu1 * v + mu2 * v * v + mu3 * v * v * v - target;
        aloft_core::bisect(0.0, 100.0, 200, |v| f(v) < 0.0).0
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
        let (env, pw) = envelope_at_2355(&aircraft);
        let a = drag_limited_airspeed(2.355, aircraft.gravity_mps2(), 35.0);
        let (q, limit) = env
            .fastest_fraction(
                &pw,
                ([0.0; 3], [0.0, 12.0, 0.0]),
                [0.0, -10.0, 0.0],
                [0.0, 1.0],
                None,
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
            .fastest_fraction(
                &pw,
                ([0.0; 3], [0.0, 20.0, 0.0]),
                [6.0, 0.0, 0.0],
                [0.0, 1.0],
                None,
            )
            .unwrap()
            .unwrap();
        let want = (a * a - 36.0).sqrt();
        assert!((20.0 * q - want).abs() < 1e-6, "{} vs {want}", 20.0 * q);
    }

    #[test]
    fn a_wind_beyond_the_vehicle_cannot_be_flown_against_or_hovered_in() {
        let aircraft = m100_aircraft();
        let (env, pw) = envelope_at_2355(&aircraft);
        let a = drag_limited_airspeed(2.355, STANDARD_GRAVITY_MPS2, 35.0);
        let wind = [0.0, -(a + 1.0), 0.0];
        assert_eq!(
            env.fastest_fraction(&pw, ([0.0; 3], [0.0, 8.0, 0.0]), wind, [0.0, 1.0], None),
            Err(Limit::Tilt)
        );
        assert_eq!(
            env.fastest_fraction(&pw, ([0.0; 3], [0.0; 3]), wind, [0.0, 1.0], None),
            Err(Limit::Tilt)
        );
        // Within it: a hover holds (fraction 1 of nothing).
        let calm = [0.0, -(a - 1.0), 0.0];
        assert_eq!(
            env.fastest_fraction(&pw, ([0.0; 3], [0.0; 3]), calm, [0.0, 1.0], None),
            Ok(None)
        );
    }

    #[test]
    fn a_climb_beyond_the_rate_limit_is_flown_at_the_limit() {
        let aircraft = m100_aircraft();
        let (env, pw) = envelope_at_2355(&aircraft);
        let max = aircraft.airframe().max_climb_rate_mps();
        let (q, limit) = env
            .fastest_fraction(
                &pw,
                ([0.0; 3], [0.0, 0.0, 2.0 * max]),
                [0.0; 3],
                [0.0, 1.0],
                None,
            )
            .unwrap()
            .unwrap();
        assert_eq!(limit, Limit::Climb);
        assert!((q - 0.5).abs() < 1e-9, "{q}");
        let (q, limit) = env
            .fastest_fraction(
                &pw,
                ([0.0; 3], [0.0, 0.0, -3.0 * max]),
                [0.0; 3],
                [0.0, 1.0],
                None,
            )
            .unwrap()
            .unwrap();
        assert_eq!(limit, Limit::Descent);
        let descent = aircraft.airframe().max_descent_rate_mps();
        // Within the 1e-9 relative tolerance of the rate check.
        assert!((3.0 * max * q - descent).abs() < 1e-8, "{q}");
    }

    /// The plain reference of the search: bisection on [`Envelope::exceeded`] from the top of a
    /// fine scan, 60 halvings.
    fn fastest_by_bisection(
        env: &Envelope,
        pw: &Powered<'_>,
        (acc, vel): ([f64; 3], [f64; 3]),
        wind: [f64; 3],
        fwd: [f64; 2],
    ) -> Option<f64> {
        let beyond =
            |q: f64| env.exceeded(pw, acc.map(|a| a * q * q), vel.map(|v| v * q), wind, fwd);
        let lo = (1..=1000)
            .rev()
            .map(|k| k as f64 / 1000.0)
            .find(|&q| beyond(q).is_none())?;
        let hi = (lo + 1e-3).min(1.0);
        Some(aloft_core::bisect(lo, hi, 45, |q| beyond(q).is_none()).0)
    }

    #[test]
    fn the_search_finds_the_edge_the_plain_bisection_finds_with_and_without_a_hint() {
        let aircraft = m100_aircraft();
        let (env, pw) = envelope_at_2355(&aircraft);
        // States around a circle and along lines, in winds from every side, with climbs and
        // centripetal accelerations: a deterministic sweep (no random seed to reproduce).
        let mut checked = 0;
        for k in 0..360 {
            let phi = (k as f64).to_radians() * 7.0;
            let (s, c) = phi.sin_cos();
            let speed = 6.0 + (k % 7) as f64 * 2.0;
            let vel = [c * speed, s * speed, ((k % 5) as f64 - 2.0) * 2.0];
            let acc = [-c * (k % 3) as f64 * 2.0, -s * (k % 3) as f64 * 2.0, 0.0];
            let w = 8.0 + (k % 11) as f64;
            let wind = [-w * (phi * 0.3).cos(), -w * (phi * 0.3).sin(), 0.0];
            let fwd = [c, s];
            let plain = fastest_by_bisection(&env, &pw, (acc, vel), wind, fwd);
            let fast = env.fastest_fraction(&pw, (acc, vel), wind, fwd, None);
            let hinted = fast.ok().flatten().map(|(q, _)| {
                env.fastest_fraction(&pw, (acc, vel), wind, fwd, Some(q * 0.9995))
                    .unwrap()
                    .unwrap()
                    .0
            });
            match (plain, fast) {
                (Some(p), Ok(Some((q, _)))) if p < 1.0 => {
                    // Both stop within 1e-10 of the edge, on its inside.
                    assert!((p - q).abs() < 1e-9, "{k}: {p} vs {q}");
                    assert!((hinted.unwrap() - q).abs() < 1e-9, "{k}: hinted");
                    assert!(env
                        .exceeded(&pw, acc.map(|a| a * q * q), vel.map(|v| v * q), wind, fwd)
                        .is_none());
                    checked += 1;
                }
                (Some(p), Ok(None)) => assert!(p >= 1.0, "{k}"),
                (None, Err(_)) => {}
                // Under the 1e-3 scan of the reference only the MIN_FRACTION floor can differ.
                (None, Ok(Some((q, _)))) => assert!(q < 1e-3, "{k}: {q}"),
                (p, q) => panic!("{k}: {p:?} vs {q:?}"),
            }
        }
        assert!(checked > 100, "{checked}");
    }
}
