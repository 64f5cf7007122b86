//! Endurance and range queries: hover, best-endurance speed, best-range speed along a course in
//! wind, orbit endurance, and the classic power curve.
//!
//! Steady level flight at airspeed `v_a`, heading along the ground track. Along a course with unit
//! vector `c` in a horizontal wind `w` (along-track part `w_t`, cross-track `w_c`), the air
//! velocity is `v_g c - w` with the ground speed `v_g = sqrt(v_a^2 - w_c^2) + w_t` (the vehicle
//! crabs into the cross wind). Then:
//!
//! - endurance at power `P`: the time the pack takes to go from the start state of charge to the
//!   empty point plus the reserve, `sum dQ / I(P, s)` with `I` from [`Pack::draw`];
//! - best endurance: `argmin_v P(v)` (in the air mass; wind does not change it);
//! - best range along the course: `argmin_v P(v) / v_g(v)` (energy per metre over the ground),
//!   range = endurance at that power x `v_g`;
//! - orbit endurance: the mean power over one lap at constant ground speed (in wind the airspeed
//!   changes around the circle), and the endurance at that power.
//!
//! The minimisations bracket the minimum on a 40-point scan and refine with Brent's method
//! (argmin's `BrentOpt`, "Algorithms for minimization without derivatives", 1973).

use argmin::core::{CostFunction, Executor};
use argmin::solver::brent::BrentOpt;
use serde::Serialize;

use crate::aircraft::Powered;
use crate::battery::Pack;
use crate::envelope::Envelope;
use crate::error::PlannerError;

/// Points of the bracketing scan.
const SCAN_POINTS: usize = 40;
/// Penalty of a speed that cannot be flown (no headway or rejected by the model), larger than any
/// real cost.
const PENALTY: f64 = 1e30;

/// The best speed for range along a course.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BestRange {
    /// Airspeed, m/s.
    pub airspeed_mps: f64,
    /// Ground speed along the course, m/s.
    pub ground_speed_mps: f64,
    /// Electrical power, W.
    pub power_w: f64,
    /// Electrical energy per metre over the ground, J/m.
    pub energy_per_m_j: f64,
}

/// Electrical power flying along `course` (unit east/north) at airspeed `airspeed_mps` in the
/// horizontal wind `wind_mps`; `None` when the airspeed cannot make headway (or the cross wind
/// exceeds it). Returns `(power_w, ground_speed_mps)`.
pub fn power_along_course(
    p: &Powered<'_>,
    course: [f64; 2],
    wind_mps: [f64; 2],
    airspeed_mps: f64,
) -> Option<(f64, f64)> {
    let w_t = wind_mps[0] * course[0] + wind_mps[1] * course[1];
    let w_c = wind_mps[0] * course[1] - wind_mps[1] * course[0];
    let s = airspeed_mps * airspeed_mps - w_c * w_c;
    if s < 0.0 {
        return None;
    }
    let vg = s.sqrt() + w_t;
    if vg <= 0.0 {
        return None;
    }
    let air = [vg * course[0] - wind_mps[0], vg * course[1] - wind_mps[1]];
    p.level_power_w(air, course).ok().map(|pw| (pw, vg))
}

struct Cost<'b> {
    f: &'b dyn Fn(f64) -> f64,
}

impl CostFunction for Cost<'_> {
    type Param = f64;
    type Output = f64;
    fn cost(&self, x: &f64) -> Result<f64, argmin::core::Error> {
        Ok((self.f)(*x))
    }
}

/// Minimise `f` on `[lo, hi]`: scan, then Brent in the bracket around the best scanned point.
/// Returns `(x, f(x))`.
pub fn minimise(f: &dyn Fn(f64) -> f64, lo: f64, hi: f64) -> (f64, f64) {
    let step = (hi - lo) / (SCAN_POINTS - 1) as f64;
    let (mut best_k, mut best) = (0, f64::INFINITY);
    for k in 0..SCAN_POINTS {
        let v = f(lo + step * k as f64);
        if v < best {
            best = v;
            best_k = k;
        }
    }
    let a = lo + step * best_k.saturating_sub(1) as f64;
    let b = (lo + step * (best_k + 1) as f64).min(hi);
    let x0 = lo + step * best_k as f64;
    if best >= PENALTY || b <= a {
        return (x0, best);
    }
    let solver = BrentOpt::new(a, b).set_tolerance(1e-8, 1e-6);
    let run = Executor::new(Cost { f }, solver)
        .configure(|s| s.max_iters(100))
        .run();
    match run {
        Ok(r) => {
            let st = r.state();
            match (st.best_param, st.best_cost) {
                (Some(x), c) if c <= best => (x, c),
                _ => (x0, best),
            }
        }
        Err(_) => (x0, best),
    }
}

/// Best-range airspeed along `course` in the horizontal wind `wind_mps`, searched over
/// `(0, max_airspeed_mps]`. Callers keep the search within the flight envelope by capping
/// `max_airspeed_mps` at its steady airspeed ([`crate::Envelope::max_level_airspeed_mps`]):
/// steady level flight at an airspeed is within the tilt, thrust and airspeed limits exactly
/// when the airspeed is within that cap, whatever the course and wind (the drag depends on the
/// airspeed alone; with body-axis drag, heading along the course in a cross wind, nearly).
///
/// # Errors
/// [`PlannerError::NoHeadway`] when no airspeed in the range makes headway.
pub fn best_range(
    p: &Powered<'_>,
    course: [f64; 2],
    wind_mps: [f64; 2],
    max_airspeed_mps: f64,
) -> Result<BestRange, PlannerError> {
    let lo = 0.1;
    let f = |v: f64| match power_along_course(p, course, wind_mps, v) {
        Some((pw, vg)) => pw / vg,
        None => PENALTY,
    };
    let (v, cost) = minimise(&f, lo, max_airspeed_mps);
    match power_along_course(p, course, wind_mps, v) {
        Some((pw, vg)) if cost < PENALTY => Ok(BestRange {
            airspeed_mps: v,
            ground_speed_mps: vg,
            power_w: pw,
            energy_per_m_j: pw / vg,
        }),
        _ => Err(PlannerError::NoHeadway {
            min_mps: lo,
            max_mps: max_airspeed_mps,
        }),
    }
}

/// [`best_range`] within the vehicle's speed and its envelope's steady airspeed (the limits
/// [`endurance`] searches within): the ground speed along `course` that costs least energy per
/// metre in the horizontal wind `wind_mps`.
///
/// # Errors
/// As [`best_range`].
pub fn best_range_within_limits(
    p: &Powered<'_>,
    course: [f64; 2],
    wind_mps: [f64; 2],
) -> Result<BestRange, PlannerError> {
    best_range(p, course, wind_mps, max_airspeed_mps(p))
}

/// The most airspeed the searches take: the vehicle's speed, capped by its envelope's steady
/// airspeed at the mass flown.
fn max_airspeed_mps(p: &Powered<'_>) -> f64 {
    let envelope = Envelope::of(p.aircraft().airframe(), p.aircraft().gravity_mps2());
    p.aircraft()
        .airframe()
        .max_speed_mps()
        .min(envelope.max_level_airspeed_mps(p).0)
}

/// Time the pack delivers a constant `power_w` from `start_soc` down to `stop_soc`, s; stops early
/// at the cut-off voltage; 0 when the pack cannot deliver the power at all.
///
/// The state of charge is stepped on the nodes of the open-circuit table (0.5 %) and the current
/// taken at each sub-interval's midpoint; with no resistance `1/I = V_oc/P` is linear on each
/// sub-interval and the midpoint rule is exact.
pub fn endurance_at_power_s(battery: &Pack, power_w: f64, start_soc: f64, stop_soc: f64) -> f64 {
    if power_w.is_nan() || power_w.is_infinite() {
        return 0.0;
    }
    if power_w <= 0.0 {
        // Nothing is drawn: the pack lasts for ever (the model floors power at 0 W in steep
        // descents; no query asks for it).
        return f64::INFINITY;
    }
    if start_soc <= stop_soc {
        return 0.0;
    }
    let charge_as = battery.capacity_ah() * 3600.0;
    let node = 0.005;
    let mut t = 0.0;
    let mut hi = start_soc;
    while hi > stop_soc {
        // Next node below hi (or stop_soc).
        let k = ((hi / node) - 1e-9).floor();
        let lo = (k * node).max(stop_soc);
        let mid = 0.5 * (hi + lo);
        match battery.draw(power_w, mid) {
            Some(d) if d.terminal_v >= battery.cutoff_v() => {
                t += (hi - lo) * charge_as / d.current_a;
            }
            _ => break,
        }
        hi = lo;
    }
    t
}

/// The answers of `aloft endurance`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EnduranceReport {
    /// Hover power in the given wind, W.
    pub hover_power_w: f64,
    /// Hover endurance, s.
    pub hover_endurance_s: f64,
    /// Best-endurance airspeed, m/s.
    pub max_endurance_speed_mps: f64,
    /// Power at the best-endurance airspeed, W.
    pub max_endurance_power_w: f64,
    /// Endurance at the best-endurance airspeed, s.
    pub max_endurance_s: f64,
    /// Best-range airspeed along the course, m/s.
    pub max_range_speed_mps: f64,
    /// Ground speed along the course at the best-range airspeed, m/s.
    pub max_range_ground_speed_mps: f64,
    /// Power at the best-range airspeed, W.
    pub max_range_power_w: f64,
    /// Range along the course, m.
    pub max_range_m: f64,
    /// Mean power on the orbit, W (when an orbit was asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orbit_power_w: Option<f64>,
    /// Endurance on the orbit, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orbit_endurance_s: Option<f64>,
}

/// Inputs of [`endurance`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnduranceQuery {
    /// Horizontal wind, east and north, m/s.
    pub wind_mps: [f64; 2],
    /// Course for the range query, unit east/north.
    pub course: [f64; 2],
    /// State of charge at the start.
    pub start_soc: f64,
    /// Reserve, fraction of the usable capacity.
    pub reserve_fraction: f64,
    /// Orbit radius and ground speed, m and m/s.
    pub orbit: Option<(f64, f64)>,
}

/// State of charge at which the queries stop: the empty point plus the reserve.
pub fn stop_soc(battery: &Pack, reserve_fraction: f64) -> f64 {
    battery.empty_soc() + reserve_fraction * battery.usable_fraction()
}

/// Mean electrical power on a circle of radius `radius_m` at ground speed `speed_mps` in the
/// horizontal wind, W (72 points around the circle, centripetal acceleration included).
///
/// Where the circle is tighter than the vehicle can turn at that speed, or the wind at some
/// point of it asks more than its envelope allows, that part of the circle is flown slower, at
/// the limit, as a mission's orbit is ([`crate::envelope`]): a point flown at the fraction `q`
/// of the speed takes `1 / q` of the time, so the mean is `sum(P_i / q_i) / sum(1 / q_i)`.
///
/// # Errors
/// A radius or speed that is not positive and finite, a speed beyond the vehicle's maximum, a
/// wind in which the vehicle cannot hold the circle at any speed ([`PlannerError::NoHeadway`]),
/// a flight condition the model rejects.
pub fn orbit_power_w(
    p: &Powered<'_>,
    radius_m: f64,
    speed_mps: f64,
    wind_mps: [f64; 2],
) -> Result<f64, PlannerError> {
    crate::error::positive("orbit radius_m", radius_m, "m")?;
    crate::error::positive("orbit ground_speed_mps", speed_mps, "m/s")?;
    let airframe = p.aircraft.airframe();
    if speed_mps > airframe.max_speed_mps() {
        return Err(aloft_core::InvalidParameter {
            name: "orbit ground_speed_mps",
            value: speed_mps,
            unit: "m/s",
            expected: "at most the vehicle's maximum speed",
        }
        .into());
    }
    let envelope = Envelope::of(airframe, p.aircraft().gravity_mps2());
    let ac = speed_mps * speed_mps / radius_m;
    let wind = [wind_mps[0], wind_mps[1], 0.0];
    let n = 72;
    let (mut energy, mut time) = (0.0, 0.0);
    for k in 0..n {
        let phi = std::f64::consts::TAU * (k as f64 + 0.5) / n as f64;
        let (s, c) = phi.sin_cos();
        let fwd = [-s, c];
        let acc = [-ac * c, -ac * s, 0.0];
        let vel = [fwd[0] * speed_mps, fwd[1] * speed_mps, 0.0];
        let q = match envelope.fastest_fraction(p, (acc, vel), wind, fwd, None) {
            Ok(None) => 1.0,
            Ok(Some((q, _))) => q,
            // The wind alone is beyond the vehicle, or the circle is too tight to turn at even
            // a hundredth of the speed.
            Err(_) if envelope.exceeded(p, [0.0; 3], [0.0; 3], wind, fwd).is_some() => {
                return Err(PlannerError::NoHeadway {
                    min_mps: speed_mps * crate::envelope::MIN_FRACTION,
                    max_mps: speed_mps,
                })
            }
            Err(_) => {
                return Err(aloft_core::InvalidParameter {
                    name: "orbit radius_m",
                    value: radius_m,
                    unit: "m",
                    expected: "a circle the vehicle can turn within its tilt limit at 1 % of the speed or more",
                }.into())
            }
        };
        let trim = p.trim(
            acc.map(|a| a * q * q),
            [vel[0] * q - wind[0], vel[1] * q - wind[1], 0.0],
            fwd,
            1.0,
        )?;
        energy += trim.electrical_w / q;
        time += 1.0 / q;
    }
    Ok(energy / time)
}

/// All the endurance queries for one vehicle at one mass.
///
/// # Errors
/// A course that is not a unit vector, a start state of charge outside `(0, 1]`, a reserve outside
/// `[0, 1)`, no headway along the course, an orbit the model rejects.
pub fn endurance(
    p: &Powered<'_>,
    battery: &Pack,
    q: &EnduranceQuery,
) -> Result<EnduranceReport, PlannerError> {
    let norm = q.course[0].hypot(q.course[1]);
    // A unit vector to 1e-6 (course vectors come from sin/cos of an angle).
    if norm.is_nan() || (norm - 1.0).abs() >= 1e-6 {
        return Err(aloft_core::InvalidParameter {
            name: "course (unit vector norm)",
            value: norm,
            unit: "",
            expected: "a unit vector",
        }
        .into());
    }
    let ok = q.start_soc > 0.0 && q.start_soc <= 1.0;
    aloft_core::parameter("start_soc", q.start_soc, "", ok, "a fraction in (0, 1]")?;
    crate::error::reserve_fraction(q.reserve_fraction)?;
    let stop = stop_soc(battery, q.reserve_fraction);
    // The searches stay within the vehicle's speed and its envelope's steady airspeed.
    let vmax = max_airspeed_mps(p);
    let hover_power_w = p.level_power_w([-q.wind_mps[0], -q.wind_mps[1]], q.course)?;
    let hover_endurance_s = endurance_at_power_s(battery, hover_power_w, q.start_soc, stop);
    // Best endurance: in the air mass, so along any heading in still air.
    let fe = |v: f64| p.level_power_w([0.0, v], [0.0, 1.0]).unwrap_or(PENALTY);
    let (ve, pe) = minimise(&fe, 0.0, vmax);
    let br = best_range(p, q.course, q.wind_mps, vmax)?;
    let range_t = endurance_at_power_s(battery, br.power_w, q.start_soc, stop);
    let (orbit_power_w, orbit_endurance_s) = match q.orbit {
        Some((r, v)) => {
            let pw = orbit_power_w(p, r, v, q.wind_mps)?;
            (
                Some(pw),
                Some(endurance_at_power_s(battery, pw, q.start_soc, stop)),
            )
        }
        None => (None, None),
    };
    Ok(EnduranceReport {
        hover_power_w,
        hover_endurance_s,
        max_endurance_speed_mps: ve,
        max_endurance_power_w: pe,
        max_endurance_s: endurance_at_power_s(battery, pe, q.start_soc, stop),
        max_range_speed_mps: br.airspeed_mps,
        max_range_ground_speed_mps: br.ground_speed_mps,
        max_range_power_w: br.power_w,
        max_range_m: range_t * br.ground_speed_mps,
        orbit_power_w,
        orbit_endurance_s,
    })
}

/// One row of the power curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SweepRow {
    /// Airspeed, m/s.
    pub airspeed_mps: f64,
    /// Ground speed along the course, m/s (absent when no headway).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ground_speed_mps: Option<f64>,
    /// Electrical power in level flight, W.
    pub power_w: f64,
    /// Endurance at that power, s.
    pub endurance_s: f64,
    /// Range along the course, m (absent when no headway).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_m: Option<f64>,
}

/// The power curve: power, endurance and range against airspeed from 0 to `max_airspeed_mps` in
/// `step_mps` steps.
///
/// # Errors
/// A non-positive step or maximum, more than 10 000 rows, a condition the model rejects.
pub fn sweep_speed(
    p: &Powered<'_>,
    battery: &Pack,
    q: &EnduranceQuery,
    max_airspeed_mps: f64,
    step_mps: f64,
) -> Result<Vec<SweepRow>, PlannerError> {
    crate::error::positive("sweep step_mps", step_mps, "m/s")?;
    crate::error::positive("sweep max_airspeed_mps", max_airspeed_mps, "m/s")?;
    let n = (max_airspeed_mps / step_mps + 1e-9).floor() as usize + 1;
    let expected = "a step giving at most 10 000 rows";
    aloft_core::parameter("sweep step_mps", step_mps, "m/s", n <= 10_000, expected)?;
    let stop = stop_soc(battery, q.reserve_fraction);
    let mut rows = Vec::with_capacity(n);
    for k in 0..n {
        let v = k as f64 * step_mps;
        let pw = p.level_power_w([0.0, v], [0.0, 1.0])?;
        let endurance_s = endurance_at_power_s(battery, pw, q.start_soc, stop);
        let along = power_along_course(p, q.course, q.wind_mps, v);
        rows.push(SweepRow {
            airspeed_mps: v,
            ground_speed_mps: along.map(|a| a.1),
            power_w: pw,
            endurance_s,
            range_m: along
                .map(|(pa, vg)| endurance_at_power_s(battery, pa, q.start_soc, stop) * vg),
        });
    }
    Ok(rows)
}
