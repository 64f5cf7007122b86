//! The state of a flight followed live: every [`Telemetry`] event folded into what the last
//! messages said (position, velocity, attitude, power, battery, mode, mission), the energy so far
//! and the efficiency estimate. Memory is bounded whatever the flight's length.

use std::collections::BTreeMap;

use aloft_core::Trapezoid;
use aloft_logs::frame::euler_to_mat_ned_frd;
use aloft_logs::sample::{Attitude, GeoOrigin, Sample};
use aloft_logs::telemetry::{Event, Heartbeat, MissionItem, Telemetry};
use aloft_power::{CubicDrag, PowerModel};

use super::estimate::RatioEstimator;

/// Oldest motion (velocity, attitude) a power sample is paired with, s.
const MOTION_FRESH_S: f64 = 2.0;

/// Time constant of the wind estimated from the attitude, s (a low-pass over a few turns of a
/// survey: the tilt of one instant also holds the acceleration).
const WIND_TIME_CONSTANT_S: f64 = 20.0;

/// Longest gap between power samples that is integrated over, s: across a longer one (a log
/// that stops, a vehicle switched off between flights) the energy is not known and not counted.
const MAX_GAP_S: f64 = 5.0;

/// An energy by the trapezoid rule over power samples, not across gaps longer than
/// [`MAX_GAP_S`].
#[derive(Debug, Clone, Default)]
struct Energy {
    banked_j: f64,
    run: Trapezoid,
}

impl Energy {
    fn push(&mut self, time_s: f64, power_w: f64) {
        if self.run.last().is_some_and(|(t, _)| time_s - t > MAX_GAP_S) {
            self.banked_j += self.run.integral();
            self.run = Trapezoid::new();
        }
        self.run.push(time_s, power_w);
    }

    fn last(&self) -> Option<(f64, f64)> {
        self.run.last()
    }

    fn integral(&self) -> f64 {
        self.banked_j + self.run.integral()
    }
}

/// Highest airspeed the wind from the tilt is solved for, m/s.
const MAX_AIRSPEED_MPS: f64 = 50.0;

/// Height above home, or ground speed, above which an armed vehicle with no landed state is
/// taken to be in the air, m and m/s.
const AIRBORNE_M: f64 = 1.0;

/// Where the wind comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum WindSource {
    /// The autopilot's own estimate (ArduPilot's WIND).
    Autopilot,
    /// Estimated here from the ground velocity and the tilt (the model's force balance).
    Attitude,
}

/// What the last messages said, and what was learned of the flight so far.
#[derive(Debug, Clone)]
pub(crate) struct Tracker {
    model: PowerModel,
    /// Drag law and weight for the wind from the tilt (a vehicle with an airframe).
    drag: Option<(CubicDrag, f64)>,
    prior_sd: f64,
    pub now_s: f64,
    pub origin: Option<GeoOrigin>,
    pub home_enu: Option<[f64; 3]>,
    pub pos_enu: Option<[f64; 3]>,
    vel: Option<([f64; 3], f64)>,
    att: Option<(Attitude, f64)>,
    pub power_w: Option<f64>,
    /// The pack's last measured voltage (V) and current (A).
    pub voltage_v: Option<f64>,
    pub current_a: Option<f64>,
    landed: Option<bool>,
    pub heartbeat: Option<Heartbeat>,
    /// The mission as the vehicle holds it, and how many times one arrived (a re-upload).
    pub mission: Option<(Vec<MissionItem>, u32)>,
    pub mission_current: Option<u32>,
    pub wind: Option<([f64; 2], WindSource)>,
    wind_time_s: f64,
    /// Measured energy since the start, J; the model's for a source without power.
    measured_j: Energy,
    model_j: Energy,
    pub estimator: RatioEstimator,
    /// Time in the air so far, s, and the measured energy over it, J.
    pub air_s: f64,
    pub air_measured_j: f64,
    last_in_air_s: Option<f64>,
    pub link_lost: bool,
    pub reboots: u32,
    /// A step back of the source's clock not yet said in an update.
    pub clock_note: Option<String>,
    /// The vehicle's parameters heard so far (its failsafes' thresholds), by name; kept across
    /// a restart (the same vehicle).
    pub parameters: BTreeMap<String, f64>,
}

impl Tracker {
    /// A tracker predicting with `model` (at the flown mass); `drag` and the weight (N) estimate
    /// the wind from the tilt; `prior_sd` is the fitted model's relative spread.
    pub(crate) fn new(model: PowerModel, drag: Option<(CubicDrag, f64)>, prior_sd: f64) -> Self {
        Self {
            model,
            drag,
            prior_sd,
            now_s: 0.0,
            origin: None,
            home_enu: None,
            pos_enu: None,
            vel: None,
            att: None,
            power_w: None,
            voltage_v: None,
            current_a: None,
            landed: None,
            heartbeat: None,
            mission: None,
            mission_current: None,
            wind: None,
            wind_time_s: 0.0,
            measured_j: Energy::default(),
            model_j: Energy::default(),
            estimator: RatioEstimator::new(prior_sd),
            air_s: 0.0,
            air_measured_j: 0.0,
            last_in_air_s: None,
            link_lost: false,
            reboots: 0,
            clock_note: None,
            parameters: BTreeMap::new(),
        }
    }

    /// Fold one event in.
    pub(crate) fn apply(&mut self, t: &Telemetry) {
        let time_s = t.time_s.max(self.now_s);
        if !matches!(t.event, Event::LinkLost { .. }) {
            self.link_lost = false;
        }
        self.count_air_time(time_s);
        self.now_s = time_s;
        match &t.event {
            Event::Sample(s) => self.sample(time_s, s),
            Event::Origin(o) => self.origin = Some(*o),
            Event::Home(h) => self.home_enu = Some(*h),
            Event::Heartbeat(h) => self.heartbeat = Some(h.clone()),
            // The charge's and the count's to judge (`super::charge`, `super::count`).
            Event::Battery(_) | Event::Speeds { .. } => {}
            Event::MissionCurrent(seq) => self.mission_current = Some(*seq),
            Event::Mission(items) => {
                let uploads = self.mission.as_ref().map_or(0, |(_, n)| *n) + 1;
                self.mission = Some((items.clone(), uploads));
            }
            Event::Reboot => self.reboot(),
            Event::LinkLost { .. } => self.link_lost = true,
            Event::ClockBack { back_s } => {
                self.clock_note = Some(format!(
                    "the telemetry log's clock stepped back {back_s:.0} s at {time_s:.1} s: its \
                     times go on from before the step"
                ));
            }
            Event::Parameter { name, value } => {
                if value.is_finite() {
                    self.parameters.insert(name.clone(), *value);
                }
            }
        }
    }

    /// A restart of the vehicle: what was learned of the flight no longer holds (the mission
    /// is sent again by the source).
    fn reboot(&mut self) {
        let fresh = Self::new(self.model.clone(), self.drag, self.prior_sd);
        let reboots = self.reboots + 1;
        let now_s = self.now_s;
        let parameters = std::mem::take(&mut self.parameters);
        *self = Self {
            now_s,
            reboots,
            parameters,
            ..fresh
        };
    }

    fn count_air_time(&mut self, time_s: f64) {
        // Not across a gap in the stream (as the energy).
        if let Some(since) = self.last_in_air_s.filter(|t| time_s - t <= MAX_GAP_S) {
            self.air_s += (time_s - since).max(0.0);
        }
        self.last_in_air_s = self.in_air().then_some(time_s);
    }

    fn sample(&mut self, time_s: f64, s: &Sample) {
        if let Some(v) = s.voltage_v.filter(|v| v.is_finite() && *v > 0.0) {
            self.voltage_v = Some(v);
        }
        if let Some(i) = s.current_a.filter(|i| i.is_finite()) {
            self.current_a = Some(i);
        }
        if let Some(p) = s.pos_enu_m {
            self.pos_enu = Some(p);
        }
        if let Some(v) = s.vel_enu_mps {
            self.vel = Some((v, time_s));
            self.wind_from_tilt(time_s);
        }
        if let Some(a) = s.attitude {
            self.att = Some((a, time_s));
            if self.power_w.is_none() && self.in_air() {
                if let Some(p) = self.predicted_w(time_s) {
                    self.model_j.push(time_s, p);
                }
            }
        }
        if let Some(w) = s.wind_enu_mps {
            self.wind = Some(([w[0], w[1]], WindSource::Autopilot));
        }
        if let Some(l) = s.landed {
            self.landed = Some(l);
        }
        if let Some(p) = s
            .electrical_power_w()
            .filter(|p| p.is_finite() && *p >= 0.0)
        {
            self.power(time_s, p);
        }
    }

    fn power(&mut self, time_s: f64, measured_w: f64) {
        if self.measured_j.last().is_some_and(|(t, _)| time_s <= t) {
            return;
        }
        let bridged = self
            .measured_j
            .last()
            .filter(|(t0, _)| time_s - t0 <= MAX_GAP_S);
        if let Some((t0, p0)) = bridged.filter(|_| self.in_air()) {
            self.air_measured_j += 0.5 * (p0 + measured_w) * (time_s - t0);
        }
        self.measured_j.push(time_s, measured_w);
        self.power_w = Some(measured_w);
        if self.in_air() {
            if let Some(predicted) = self.predicted_w(time_s) {
                self.estimator.push(time_s, measured_w, predicted);
            }
        }
    }

    /// The model's electrical power at the last motion, W, if it is recent.
    fn predicted_w(&self, time_s: f64) -> Option<f64> {
        let (vel, tv) = self.vel?;
        let (att, ta) = self.att?;
        if time_s - tv > MOTION_FRESH_S || time_s - ta > MOTION_FRESH_S {
            return None;
        }
        let wind = self.wind.map_or([0.0; 2], |(w, _)| w);
        let state = crate::identify::motion_state(vel, &att, [wind[0], wind[1], 0.0])?;
        self.model
            .evaluate(&state)
            .ok()
            .map(|p| p.electrical_w)
            .filter(|p| p.is_finite())
    }

    /// Without the autopilot's wind: the air velocity from the tilt (the horizontal thrust
    /// balances the drag, `f_D(v_air) = m g tan(tilt)`, along the tilt), the wind the ground
    /// velocity less it, low-passed over [`WIND_TIME_CONSTANT_S`].
    fn wind_from_tilt(&mut self, time_s: f64) {
        if matches!(self.wind, Some((_, WindSource::Autopilot))) || !self.in_air() {
            return;
        }
        let (Some((drag, weight_n)), Some((vel, _)), Some((att, ta))) =
            (self.drag, self.vel, self.att)
        else {
            return;
        };
        if time_s - ta > MOTION_FRESH_S {
            return;
        }
        let Some(air) = air_velocity_from_tilt(&att, &drag, weight_n) else {
            return;
        };
        let w = [vel[0] - air[0], vel[1] - air[1]];
        let dt = (time_s - self.wind_time_s).max(0.0);
        self.wind_time_s = time_s;
        self.wind = Some(match self.wind {
            Some((old, WindSource::Attitude)) => {
                let a = 1.0 - (-dt / WIND_TIME_CONSTANT_S).exp();
                (
                    [old[0] + a * (w[0] - old[0]), old[1] + a * (w[1] - old[1])],
                    WindSource::Attitude,
                )
            }
            _ => (w, WindSource::Attitude),
        });
    }

    /// In the air: the landed state where the autopilot sends it, else armed (or no heartbeat)
    /// and above [`AIRBORNE_M`] over home or moving faster than it.
    pub(crate) fn in_air(&self) -> bool {
        let armed = self.heartbeat.as_ref().is_none_or(|h| h.armed);
        if !armed {
            return false;
        }
        if let Some(landed) = self.landed {
            return !landed;
        }
        let up = self.height_m().unwrap_or(0.0);
        let speed = self.vel.map_or(0.0, |(v, _)| v[0].hypot(v[1]));
        up > AIRBORNE_M || speed > AIRBORNE_M
    }

    /// Height above home (else above the stream's origin), m.
    pub(crate) fn height_m(&self) -> Option<f64> {
        let p = self.pos_enu?;
        Some(p[2] - self.home_enu.map_or(0.0, |h| h[2]))
    }

    /// Whether the source measures power.
    pub(crate) fn power_available(&self) -> bool {
        self.measured_j.last().is_some()
    }

    /// Energy used so far, Wh: measured, else the model's at the re-estimated efficiency.
    pub(crate) fn energy_used_wh(&self) -> f64 {
        match self.power_available() {
            true => self.measured_j.integral() / 3600.0,
            false => self.model_j.integral() / 3600.0,
        }
    }
}

/// Where a wind (the air's velocity, ENU m/s) blows from, deg clockwise from north.
pub(crate) fn wind_from_deg(w: [f64; 2]) -> f64 {
    (-w[0]).atan2(-w[1]).to_degrees().rem_euclid(360.0)
}

/// The velocity of the air relative to the vehicle's ground track, ENU m/s (horizontal), from
/// its attitude: the horizontal component of the thrust balances the drag in steady flight, so
/// the air comes along the tilt at the speed where `f_D(v) = W tan(tilt)`. `None` beyond the
/// drag law's range (50 m/s) or where the vehicle is upside down.
pub(crate) fn air_velocity_from_tilt(
    att: &Attitude,
    drag: &CubicDrag,
    weight_n: f64,
) -> Option<[f64; 2]> {
    let r = euler_to_mat_ned_frd(att);
    // The thrust, up the body: minus body z in NED.
    let (north, east, down) = (-r[0][2], -r[1][2], -r[2][2]);
    if down >= -1e-3 {
        return None;
    }
    let horizontal = north.hypot(east);
    let force_n = weight_n * horizontal / -down;
    if horizontal < 1e-9 {
        return Some([0.0, 0.0]);
    }
    let v = drag.airspeed_for_force(force_n, MAX_AIRSPEED_MPS)?;
    Some([v * east / horizontal, v * north / horizontal])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: a vehicle tilted nose down by `atan(f_D(v) / W)`, heading `psi`, flies
    /// through the air at `v` along its heading (the horizontal thrust balances the drag); yawed
    /// and rolled instead of pitched, the same along its right side.
    #[test]
    fn the_air_velocity_from_the_tilt_balances_the_drag() {
        let drag = CubicDrag::new(0.1816, -0.02326, 0.004045).unwrap();
        let weight_n = 2.355 * 9.80665;
        for (v, psi_deg) in [(5.0_f64, 0.0_f64), (8.0, 90.0), (3.0, 225.0)] {
            let tilt = (drag.force_n(v) / weight_n).atan();
            let psi = psi_deg.to_radians();
            let att = Attitude {
                roll_rad: 0.0,
                pitch_rad: -tilt,
                yaw_rad: psi,
            };
            let air = air_velocity_from_tilt(&att, &drag, weight_n).unwrap();
            // ENU: east = v sin(psi), north = v cos(psi).
            assert!((air[0] - v * psi.sin()).abs() < 1e-9, "{air:?}");
            assert!((air[1] - v * psi.cos()).abs() < 1e-9, "{air:?}");
            // Rolled right by the same tilt, heading north: the air comes from the right (east).
            let rolled = Attitude {
                roll_rad: tilt,
                pitch_rad: 0.0,
                yaw_rad: 0.0,
            };
            let air = air_velocity_from_tilt(&rolled, &drag, weight_n).unwrap();
            assert!((air[0] - v).abs() < 1e-9 && air[1].abs() < 1e-9, "{air:?}");
        }
        // Upside down: no answer.
        let flipped = Attitude {
            roll_rad: 3.0,
            pitch_rad: 0.0,
            yaw_rad: 0.0,
        };
        assert_eq!(air_velocity_from_tilt(&flipped, &drag, weight_n), None);
    }
}
