//! The return check: the point of no return (the design is in the module docs of
//! [`mod@crate::plan`], "Point of no return").
//!
//! [`ReturnCheck::due`] says whether a check is due (airborne, `pnr_interval_s` after the last,
//! none failed yet); [`ReturnCheck::check`] prices the straight return home from the present
//! position and state of charge: the best-range leg home in the mean wind ([`ReturnCache`], one
//! [`crate::queries::best_range`] per 0.5 deg of bearing, mass phase and wind), then the vertical
//! descent over home, both within the flight envelope (a return the vehicle cannot fly against the
//! wind, or a descent in a wind it cannot hover in, fails the check). The point of no return is the last position that passed before the first
//! that failed.

use crate::aircraft::Powered;
use crate::battery::Pack;
use crate::envelope::Envelope;
use crate::queries::best_range;

use super::Limits;
use crate::wind::Wind;

use super::report::{PlanOptions, PointOfNoReturn};

/// Bearing bins of the return cache (0.5 deg each).
const BEARING_BINS: usize = 720;

/// Cached return cost per bearing bin for one mass phase and wind.
struct ReturnCache {
    /// The steady airspeed limit of the envelope per mass phase, m/s.
    max_airspeed_mps: Vec<f64>,
    phase: usize,
    wind: [f64; 2],
    bins: Vec<Option<(f64, f64)>>,
}

impl ReturnCache {
    /// Empty the cache unless it holds mass phase `phase` and a mean wind within 1 cm/s of `wh`.
    fn keep_for(&mut self, phase: usize, wh: [f64; 2]) {
        // A cache entry is valid for this mass phase and a mean wind within 1 cm/s.
        if self.phase != phase
            || !((self.wind[0] - wh[0]).abs() < 0.01 && (self.wind[1] - wh[1]).abs() < 0.01)
        {
            self.phase = phase;
            self.wind = wh;
            self.bins.iter_mut().for_each(|b| *b = None);
        }
    }

    /// (power W, ground speed m/s) of the best-range leg home along `d` (east, north, m) in the
    /// mean wind `wh`; `None` when there is none.
    fn leg_home(&mut self, pw: &Powered<'_>, wh: [f64; 2], d: [f64; 2]) -> Option<(f64, f64)> {
        let bearing = d[0].atan2(d[1]).rem_euclid(std::f64::consts::TAU);
        let bin = ((bearing / std::f64::consts::TAU * BEARING_BINS as f64) as usize)
            .min(BEARING_BINS - 1);
        match self.bins[bin] {
            Some(v) => Some(v),
            None => {
                let b = (bin as f64 + 0.5) / BEARING_BINS as f64 * std::f64::consts::TAU;
                let course = [b.sin(), b.cos()];
                // Within the vehicle's speed and the envelope's steady airspeed at this mass.
                let max_air = pw
                    .aircraft()
                    .airframe()
                    .max_speed_mps()
                    .min(self.max_airspeed_mps[self.phase]);
                match best_range(pw, course, wh, max_air) {
                    Ok(r) => {
                        self.bins[bin] = Some((r.power_w, r.ground_speed_mps));
                        self.bins[bin]
                    }
                    Err(_) => None,
                }
            }
        }
    }
}

/// The checks of one run and what they found.
pub(super) struct ReturnCheck<'p> {
    envelope: Envelope,
    battery: &'p Pack,
    wind: &'p Wind,
    home: [f64; 3],
    /// State of charge the return must land at or above: empty point plus reserve.
    floor_soc: f64,
    descent_rate: f64,
    /// Pack capacity, A s.
    charge_as: f64,
    interval_s: f64,
    next_check: f64,
    last_ok: Option<PointOfNoReturn>,
    pnr: Option<PointOfNoReturn>,
    done: bool,
    cache: ReturnCache,
}

impl<'p> ReturnCheck<'p> {
    /// The checks to `home` with `battery` in `wind`, down to `floor_soc`, descending at
    /// `descent_rate` m/s; none when `options` ask for no point of no return.
    pub(super) fn new(
        limits: &Limits,
        battery: &'p Pack,
        wind: &'p Wind,
        home: [f64; 3],
        options: &PlanOptions,
        floor_soc: f64,
        descent_rate: f64,
    ) -> Self {
        ReturnCheck {
            envelope: limits.envelope,
            battery,
            wind,
            home,
            floor_soc,
            descent_rate,
            charge_as: battery.capacity_ah() * 3600.0,
            interval_s: options.pnr_interval_s,
            next_check: 0.0,
            last_ok: None,
            pnr: None,
            done: !options.point_of_no_return,
            cache: ReturnCache {
                max_airspeed_mps: limits.max_airspeed.iter().map(|a| a.0).collect(),
                phase: usize::MAX,
                wind: [f64::NAN; 2],
                bins: vec![None; BEARING_BINS],
            },
        }
    }

    /// Whether a check is due at mission time `t` s at position `pos` (airborne, an interval
    /// after the last, and no point of no return found yet).
    #[inline]
    pub(super) fn due(&self, t: f64, pos: [f64; 3]) -> bool {
        !self.done && t >= self.next_check && pos[2] > 0.0
    }

    /// Check the return from `here` with the pack at `soc`, flying with `pw` of mass phase
    /// `phase`.
    pub(super) fn check(
        &mut self,
        pw: &Powered<'_>,
        phase: usize,
        here: PointOfNoReturn,
        soc: f64,
    ) {
        self.next_check = here.time_s + self.interval_s;
        if self.can_return(pw, phase, here.position_m, soc) {
            self.last_ok = Some(here);
        } else {
            self.pnr = Some(self.last_ok.unwrap_or(PointOfNoReturn {
                time_s: 0.0,
                segment: 1,
                position_m: self.home,
            }));
            self.done = true;
        }
    }

    /// The point of no return found, if any.
    pub(super) fn point_of_no_return(&self) -> Option<PointOfNoReturn> {
        self.pnr
    }

    /// Whether a straight return from `pos` lands with the state of charge at or above the floor.
    fn can_return(&mut self, pw: &Powered<'_>, phase: usize, pos: [f64; 3], soc: f64) -> bool {
        let w = match self.wind.mean_at(pos) {
            Some(w) => w,
            None => return false,
        };
        let wh = [w[0], w[1]];
        self.cache.keep_for(phase, wh);
        let home = self.home;
        let d = [home[0] - pos[0], home[1] - pos[1]];
        let dist = d[0].hypot(d[1]);
        // (power W, ground speed m/s) of the horizontal leg.
        let leg = if dist > 1.0 {
            match self.cache.leg_home(pw, wh, d) {
                Some(v) => Some(v),
                None => return false,
            }
        } else {
            None
        };
        let descent_rate = self.descent_rate;
        // Descent over home: air velocity is minus the wind, vertical -rate; it must be within
        // the envelope (a wind the vehicle cannot hover in leaves no way down).
        let descent_w = match pw.trim(
            [0.0; 3],
            [-wh[0], -wh[1], -descent_rate - w[2]],
            [0.0, 1.0],
            1.0,
        ) {
            Ok(t) if self.envelope.exceeded_by_trim(&t, -descent_rate).is_none() => t.electrical_w,
            _ => return false,
        };
        let descent_s = pos[2] / descent_rate;
        let battery = self.battery;
        let charge = |s: f64| -> Option<f64> {
            let mut q = 0.0;
            if let Some((p, vg)) = leg {
                q += battery.draw(p, s)?.current_a * dist / vg;
            }
            q += battery.draw(descent_w, s)?.current_a * descent_s;
            Some(q)
        };
        let charge_as = self.charge_as;
        let Some(q0) = charge(soc) else { return false };
        let mid = soc - 0.5 * q0 / charge_as;
        let Some(q) = charge(mid) else { return false };
        soc - q / charge_as >= self.floor_soc
    }
}
