//! Replay: the energy of a recorded flight predicted from its trajectory alone.
//!
//! Each point of the trajectory (time, ground velocity, acceleration, optionally the height above
//! the ground) is trimmed exactly as a mission sample is ([`crate::trim`]): air-relative velocity
//! `v_air = v_ground - wind`, thrust vector from the force balance
//! `T = m a + m g e_up + f_D(|v_air|) v_air / |v_air|`, and electrical power from the four-term
//! model (geometric angle of attack by default) or the propulsion chain. No power, attitude or
//! battery data enters: the prediction is what the planner would have said of the flight.
//!
//! Energy is the trapezoidal integral of the power over the points' times,
//! `E = sum (P_i + P_{i+1}) / 2 (t_{i+1} - t_i)`, so irregular log rates are handled.
//!
//! Heading: the logged yaw where the point has one ([`ReplayPoint::yaw_rad`]); else along the
//! horizontal ground velocity when it exceeds [`HEADING_MIN_SPEED_MPS`], else the previous heading
//! (north at the start). Only the paper's angle-of-attack model and body-axis drag use it; the
//! geometric angle of attack with the scalar drag of eq (6) is independent of heading.
//!
//! Ground effect (survey eq 35) applies where a point gives its height above the ground; a log
//! that does not know the ground (heights relative to an origin in flight) gives none.
//!
//! Acceleration: logs may carry it, but inertial accelerations are noisy and, since thrust is a
//! norm, zero-mean noise raises the mean thrust (`E|g + n| > |g|`). [`differentiate_velocity`]
//! gives the kinematic acceleration as a centred difference of the velocity over a window, a box
//! filter of the acceleration.

use serde::Serialize;

use crate::aircraft::{Aircraft, Powered};
use crate::airframe::{Airframe, AirframeSpec};
use crate::error::PlannerError;
use crate::ground_effect::thrust_factor;
use crate::trim::{Trim, TRIM_BLOCK};
use crate::wind::Wind;

/// Horizontal ground speed above which the heading follows the track, m/s.
pub const HEADING_MIN_SPEED_MPS: f64 = 0.5;

/// One point of a recorded trajectory.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReplayPoint {
    /// Time, s (strictly increasing along the trajectory).
    pub time_s: f64,
    /// Ground velocity, ENU m/s.
    pub vel_enu_mps: [f64; 3],
    /// Acceleration over the ground (kinematic, without gravity), ENU m/s^2.
    pub acc_enu_mps2: [f64; 3],
    /// Position, ENU m (for a wind that varies in space; the height is the up component).
    pub pos_enu_m: [f64; 3],
    /// Height of the vehicle above the ground, m, when known (ground effect).
    pub height_above_ground_m: Option<f64>,
    /// Measured wind (velocity of the air), ENU m/s, when the log has it: used instead of the
    /// wind model at this point.
    pub wind_enu_mps: Option<[f64; 3]>,
    /// Logged heading (yaw, clockwise from north), rad, when the log has the attitude: the
    /// heading of the trim at this point (body-axis drag and the paper's angle of attack use it).
    /// `None`: the heading follows the track.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yaw_rad: Option<f64>,
}

/// The predicted energy of a trajectory.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReplayReport {
    /// First to last point, s.
    pub duration_s: f64,
    /// Predicted electrical energy, W h.
    pub energy_wh: f64,
    /// Mean predicted power, W.
    pub mean_power_w: f64,
    /// Peak predicted power, W.
    pub peak_power_w: f64,
    /// Mean thrust, N.
    pub mean_thrust_n: f64,
    /// Predicted electrical power at each point, W.
    pub power_w: Vec<f64>,
}

/// An aircraft for replaying logs of a vehicle known only by its power model (a `[power]` table
/// from a fit, no airframe): the four-term model at the vehicle's own mass, with an envelope that
/// does not limit anything (replay checks no limits) and a rotor height of one rotor radius for
/// ground effect.
///
/// # Errors
/// None in practice (the envelope is valid by construction); the type is the constructors'.
pub fn power_only_aircraft(
    vehicle: aloft_power::Vehicle,
    options: aloft_power::ModelOptions,
) -> Result<Aircraft, PlannerError> {
    let m = vehicle.mass_kg();
    let airframe = Airframe::new(AirframeSpec {
        mass_kg: m,
        max_takeoff_mass_kg: m,
        max_thrust_n: None,
        max_tilt_deg: 89.0,
        max_speed_mps: 100.0,
        max_airspeed_mps: None,
        max_climb_rate_mps: 100.0,
        max_descent_rate_mps: 100.0,
        acceleration_mps2: 100.0,
        vertical_acceleration_mps2: 100.0,
        yaw_rate_deg_s: 1000.0,
        rotor_height_m: vehicle.params().rotor_radius_m,
        acceptance_radius_m: None,
        cruise_speed_mps: None,
        rtl_altitude_m: None,
    })?;
    Ok(Aircraft::four_term(airframe, vehicle, options))
}

/// Acceleration as the centred difference of the velocity over `window_s`:
/// `a(t) = (v(t + w/2) - v(t - w/2)) / w` with `v` interpolated linearly and the window shortened
/// (one-sided) at the ends. `times_s` must be increasing.
///
/// # Errors
/// A non-positive window, fewer than two points, slices of different lengths.
pub fn differentiate_velocity(
    times_s: &[f64],
    vel_mps: &[[f64; 3]],
    window_s: f64,
) -> Result<Vec<[f64; 3]>, PlannerError> {
    crate::error::positive("acceleration_window_s", window_s, "s")?;
    if times_s.len() != vel_mps.len() || times_s.len() < 2 {
        return Err(aloft_core::InvalidParameter {
            name: "trajectory points",
            value: times_s.len().min(vel_mps.len()) as f64,
            unit: "",
            expected: "at least two, with a velocity for every time",
        }
        .into());
    }
    let (t0, t1) = (times_s[0], times_s[times_s.len() - 1]);
    let at = |t: f64| -> [f64; 3] {
        let i = times_s
            .partition_point(|&x| x <= t)
            .clamp(1, times_s.len() - 1);
        let (ta, tb) = (times_s[i - 1], times_s[i]);
        let w = if tb > ta { (t - ta) / (tb - ta) } else { 0.0 };
        let (a, b) = (vel_mps[i - 1], vel_mps[i]);
        [
            a[0] + w * (b[0] - a[0]),
            a[1] + w * (b[1] - a[1]),
            a[2] + w * (b[2] - a[2]),
        ]
    };
    Ok(times_s
        .iter()
        .map(|&t| {
            let lo = (t - 0.5 * window_s).max(t0);
            let hi = (t + 0.5 * window_s).min(t1);
            if hi <= lo {
                return [0.0; 3];
            }
            let (a, b) = (at(lo), at(hi));
            let d = hi - lo;
            [(b[0] - a[0]) / d, (b[1] - a[1]) / d, (b[2] - a[2]) / d]
        })
        .collect())
}

/// Predict the electrical energy of a recorded trajectory with the aircraft at one mass
/// (see the module docs).
///
/// # Errors
/// Fewer than two points, times that are not finite and strictly increasing, a point outside a
/// gridded wind, a flight condition the power model rejects (non-finite velocity or
/// acceleration).
pub fn replay(
    pw: &Powered<'_>,
    points: &[ReplayPoint],
    wind: &Wind,
) -> Result<ReplayReport, PlannerError> {
    let n = points.len() as f64;
    aloft_core::parameter(
        "trajectory points",
        n,
        "",
        points.len() >= 2,
        "at least two",
    )?;
    if let Some(w) = points
        .windows(2)
        .find(|w| !(w[0].time_s.is_finite() && w[1].time_s > w[0].time_s))
    {
        return Err(aloft_core::InvalidParameter {
            name: "time_s",
            value: w[1].time_s,
            unit: "s",
            expected: "finite times, each later than the one before",
        }
        .into());
    }
    let aircraft = pw.aircraft();
    let r_rotor = aircraft.rotor_radius_m();
    let rotor_h = aircraft.airframe().rotor_height_m();
    let mut power_w = Vec::with_capacity(points.len());
    let mut thrust_sum = 0.0;
    let mut heading = [0.0, 1.0];
    let mut acc = [[0.0; 3]; TRIM_BLOCK];
    let mut v_air = [[0.0; 3]; TRIM_BLOCK];
    let mut fwd = [[0.0; 2]; TRIM_BLOCK];
    let mut ge = [1.0; TRIM_BLOCK];
    let mut trims = [Trim {
        thrust_n: 0.0,
        axis: [0.0; 3],
        airspeed_mps: 0.0,
        electrical_w: 0.0,
    }; TRIM_BLOCK];
    for chunk in points.chunks(TRIM_BLOCK) {
        for (j, p) in chunk.iter().enumerate() {
            let w = match p.wind_enu_mps {
                Some(w) => Some(w),
                None => wind.at(p.pos_enu_m, p.time_s),
            }
            .ok_or(PlannerError::OutsideWindGrid {
                time_s: p.time_s,
                east_m: p.pos_enu_m[0],
                north_m: p.pos_enu_m[1],
                up_m: p.pos_enu_m[2],
                min_m: [f64::NAN; 3],
                max_m: [f64::NAN; 3],
            })?;
            let v = p.vel_enu_mps;
            let vh = v[0].hypot(v[1]);
            if let Some(yaw) = p.yaw_rad.filter(|y| y.is_finite()) {
                let (e, n) = yaw.sin_cos();
                heading = [e, n];
            } else if vh > HEADING_MIN_SPEED_MPS {
                heading = [v[0] / vh, v[1] / vh];
            }
            acc[j] = p.acc_enu_mps2;
            v_air[j] = [v[0] - w[0], v[1] - w[1], v[2] - w[2]];
            fwd[j] = heading;
            ge[j] = p
                .height_above_ground_m
                .map_or(1.0, |h| thrust_factor(r_rotor, h.max(0.0) + rotor_h));
        }
        let n = chunk.len();
        pw.trim_block(&acc[..n], &v_air[..n], &fwd[..n], &ge[..n], &mut trims[..n])
            .map_err(|(_, e)| e)?;
        for t in &trims[..n] {
            power_w.push(t.electrical_w);
            thrust_sum += t.thrust_n;
        }
    }
    let times: Vec<f64> = points.iter().map(|p| p.time_s).collect();
    let duration_s = times[times.len() - 1] - times[0];
    let energy_j = aloft_core::trapezoid(&times, &power_w);
    Ok(ReplayReport {
        duration_s,
        energy_wh: energy_j / 3600.0,
        mean_power_w: energy_j / duration_s,
        peak_power_w: power_w.iter().copied().fold(0.0, f64::max),
        mean_thrust_n: thrust_sum / points.len() as f64,
        power_w,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission::MissionSpec;
    use crate::mission_toml::{landing, leg, orbit, return_home, take_off, OrbitFor};
    use crate::plan::{plan, PlanOptions};
    use crate::test_support::{m100_aircraft, tb47d};
    use aloft_power::AoaModel;

    fn m100() -> Aircraft {
        m100_aircraft()
    }

    #[test]
    fn replaying_a_planned_mission_gives_its_energy() {
        // The planner's own samples (midpoints of its steps) replayed: the same trim at the same
        // points, integrated by the trapezoid instead of the midpoint rule. The two rules differ
        // only at the pieces' ends (a few of 2,000 steps): well within 0.5 %.
        let aircraft = m100();
        let battery = crate::Pack::new(&tb47d()).unwrap();
        let text = [
            take_off(20.0, 2.0),
            leg(300.0, 100.0, 8.0),
            orbit([300.0, 150.0], 50.0, 6.0, "clockwise", OrbitFor::Laps(1.0)),
            return_home(8.0),
            landing(1.0),
        ]
        .concat();
        let mission = MissionSpec::from_toml_str(&text)
            .unwrap()
            .compile(aircraft.airframe(), battery.mass_kg(), None)
            .unwrap();
        let wind = Wind::constant(5.0, 250.0).unwrap();
        let opts = PlanOptions {
            record_samples: true,
            ground_effect: false,
            point_of_no_return: false,
            ..PlanOptions::default()
        };
        let r = plan(&aircraft, &battery, &mission, &wind, &opts).unwrap();
        let points: Vec<ReplayPoint> = r
            .samples
            .iter()
            .map(|s| ReplayPoint {
                time_s: s.time_s,
                vel_enu_mps: [s.vel_east_mps, s.vel_north_mps, s.vel_up_mps],
                acc_enu_mps2: [s.acc_east_mps2, s.acc_north_mps2, s.acc_up_mps2],
                pos_enu_m: [s.east_m, s.north_m, s.up_m],
                height_above_ground_m: None,
                wind_enu_mps: None,
                yaw_rad: None,
            })
            .collect();
        let pw = aircraft
            .at_mass(r.takeoff_mass_kg, AoaModel::Geometric)
            .unwrap();
        let rep = replay(&pw, &points, &wind).unwrap();
        for (s, p) in r.samples.iter().zip(&rep.power_w) {
            // the same trim of the same inputs (heading aside, unused by the geometric AoA)
            assert!((s.power_w - p).abs() < 1e-9 * p, "{} vs {p}", s.power_w);
        }
        // The replay spans first to last midpoint: half a step less at each end.
        let planned_wh = r.energy_wh
            - 0.5 * opts.time_step_s * (r.samples[0].power_w + r.samples.last().unwrap().power_w)
                / 3600.0;
        let err = (rep.energy_wh - planned_wh).abs() / planned_wh;
        assert!(err < 5e-3, "{} vs {planned_wh}", rep.energy_wh);
    }

    #[test]
    fn differentiated_velocity_recovers_a_constant_acceleration_and_smooths_noise() {
        let t: Vec<f64> = (0..200).map(|k| k as f64 * 0.1).collect();
        let v: Vec<[f64; 3]> = t.iter().map(|&t| [2.0 * t, -t, 0.5]).collect();
        let a = differentiate_velocity(&t, &v, 0.5).unwrap();
        for x in &a {
            // linear velocity: the difference quotient is exact to rounding
            assert!((x[0] - 2.0).abs() < 1e-9 && (x[1] + 1.0).abs() < 1e-9 && x[2].abs() < 1e-9);
        }
        // Alternating +-0.1 m/s noise at 10 Hz: a 0.1 s difference sees +-2 m/s^2, a 1 s window
        // at most 0.2 m/s^2 (the end samples' difference over 1 s).
        let vn: Vec<[f64; 3]> = t
            .iter()
            .enumerate()
            .map(|(k, _)| [if k % 2 == 0 { 0.1 } else { -0.1 }, 0.0, 0.0])
            .collect();
        let a1 = differentiate_velocity(&t, &vn, 1.0).unwrap();
        assert!(a1[50..150].iter().all(|x| x[0].abs() <= 0.2 + 1e-9));
        assert!(differentiate_velocity(&t, &v, 0.0).is_err());
        assert!(differentiate_velocity(&t[..1], &v[..1], 1.0).is_err());
    }

    #[test]
    fn bad_trajectories_are_errors() {
        let aircraft = m100();
        let pw = aircraft.at_mass(2.4, AoaModel::Geometric).unwrap();
        let p = ReplayPoint {
            time_s: 0.0,
            vel_enu_mps: [0.0; 3],
            acc_enu_mps2: [0.0; 3],
            pos_enu_m: [0.0; 3],
            height_above_ground_m: None,
            wind_enu_mps: None,
            yaw_rad: None,
        };
        assert!(replay(&pw, &[p], &Wind::calm()).is_err());
        assert!(replay(&pw, &[p, p], &Wind::calm()).is_err());
        let mut q = p;
        q.time_s = 1.0;
        q.vel_enu_mps[0] = f64::NAN;
        assert!(replay(&pw, &[p, q], &Wind::calm()).is_err());
        q.vel_enu_mps[0] = 3.0;
        let r = replay(&pw, &[p, q], &Wind::calm()).unwrap();
        assert!(r.energy_wh > 0.0 && r.duration_s > 0.99);
    }
}
