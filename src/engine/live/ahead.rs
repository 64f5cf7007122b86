//! The rest of a flight followed live: the route ahead from the vehicle's present state, flown by
//! the planner in Monte-Carlo scenarios, and the advice.
//!
//! The route ahead, from where the vehicle is (at rest, in the air; on the ground: the whole
//! mission from home):
//! - flight mode `RTL`, `SMART_RTL` or `AUTO_RTL`: straight back to home and the landing;
//! - `LAND` or `PRECLAND`: the landing where it is;
//! - `AUTO` (ArduPilot) or `MISSION` (PX4) with a mission (`--mission`, or the one learned from
//!   the link): the mission from the item being flown (MISSION_CURRENT) to its end, then home and
//!   the landing if it does not end on the ground (a mission file without item numbers, aloft's
//!   TOML or JSON, is flown whole from where the vehicle is);
//! - any other mode (flown by hand or guided), or without a mission: home and the landing, what
//!   it costs to come back now.
//!
//! It is flown from the present state of charge, by the vehicle at the re-estimated efficiency,
//! in the present wind, in [`LIVE_SCENARIOS`] scenarios that draw the model error from the
//! estimate's own spread and the wind from its source's ([`wind_sd`]). The answer carries the
//! shares of the scenarios that land with the reserve, the rest's and, where the advice may need
//! it, a direct return's: the advice is made from them, with its hysteresis, in
//! [`super::advice`].

use aloft_missions::SourceFormat;
use aloft_planner::{geodesy::LocalFrame, HomeSpec, MissionSpec, SegmentSpec, WindSpec};

use super::advice::Shares;
use super::estimate::Ratio;
use super::failsafes::{LiveFailsafe, Watched};
use super::tracker::{wind_from_deg, Tracker, WindSource};
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_options::MissionOptions;
use crate::engine::uncertainty::scenario_stats::Percentiles;
use crate::engine::uncertainty::scenarios::{
    plan_scenarios_watched, ScenarioOptions, ScenarioWatch, Uncertainty,
};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// Scenarios per update (the figure: one update with them within 100 ms on 2 cores).
pub const LIVE_SCENARIOS: u32 = 200;

/// Time step the rest is flown at, s (coarser than a plan's 0.1 s: the rest is re-planned every
/// update, and its energy changes by less than 0.1 % between the two on the demo mission).
pub(crate) const LIVE_TIME_STEP_S: f64 = 0.5;

/// Spread of the wind, one standard deviation: speed (m/s) and direction (deg), by source. The
/// autopilot's estimate (ArduPilot's EKF) is steadier than one from the tilt, which also holds
/// the accelerations and the attitude's trim offsets; without either, the tilt's.
fn wind_sd(source: Option<WindSource>) -> (f64, f64) {
    match source {
        Some(WindSource::Autopilot) => (1.0, 15.0),
        Some(WindSource::Attitude) | None => (2.0, 30.0),
    }
}

/// Ground speed of a return where neither the mission nor the vehicle gives one, m/s (PX4's
/// `MPC_XY_CRUISE`; ArduPilot's `WPNAV_SPEED` is 10 m/s).
const RETURN_SPEED_MPS: f64 = 5.0;

/// Landing rate of the landing appended to a route and of `LAND`, m/s (ArduPilot's `LAND_SPEED`).
const LANDING_RATE_MPS: f64 = 0.5;

/// What the rest costs and what to do.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AheadAnswer {
    pub remaining_wh: Option<Percentiles>,
    pub landing_soc: Option<Percentiles>,
    pub duration_s: Option<Percentiles>,
    /// The rest's point of no return (p5 of the scenarios), s from now: `None` where the route
    /// can turn back everywhere.
    pub point_of_no_return_s: Option<f64>,
    /// The shares of the scenarios that land with the reserve (and before an acting failsafe),
    /// for the advice.
    pub shares: Shares,
    /// The failsafes watched and when each triggers on the rest.
    pub failsafes: Vec<LiveFailsafe>,
    /// The least voltage under load on the rest, V.
    pub least_voltage_v: Option<Percentiles>,
}

/// The pack's state and the failsafes watched, to fly the rest on.
#[derive(Clone, Copy)]
pub(crate) struct OnPack<'a> {
    pub filter: &'a aloft_packs::SocFilter,
    pub watched: &'a Watched,
}

/// What the scenarios of one route say: the planner's answer, and where the pack was followed,
/// the share that holds (lands with the reserve before any acting failsafe) and each
/// scenario's run.
struct Flown {
    u: Uncertainty,
    holds: f64,
    runs: Vec<Vec<f64>>,
}

/// The route ahead's inputs that do not change within a flight.
pub(crate) struct Ahead<'a> {
    pub vehicle: &'a Vehicle,
    pub battery: Option<String>,
    pub payload_kg: f64,
    pub reserve_percent: Option<f64>,
    pub speed_mps: Option<f64>,
    pub scenarios: u32,
}

impl Ahead<'_> {
    /// Fly the rest of the flight `t` describes, on `mission` where one is known.
    ///
    /// # Errors
    /// What makes the route itself wrong (a mission the vehicle cannot fly at all is not an
    /// error: its scenarios are infeasible).
    pub(crate) fn answer(
        &self,
        t: &Tracker,
        mission: Option<&Mission>,
        (soc, ratio): (f64, Ratio),
        pack: Option<OnPack<'_>>,
    ) -> Result<Option<AheadAnswer>, Error> {
        let vehicle = self.vehicle_at(ratio)?;
        let Some((rest, is_return)) = rest_spec(t, mission) else {
            return Ok(None);
        };
        let rest = self.fly(&vehicle, rest, t, (soc, ratio), pack)?;
        // A failsafe that acted already: the route no longer holds, a return is its answer
        // (where the rest is not one already).
        let acted = pack.is_some_and(|p| p.watched.acted()) && !is_return;
        let rest_holds = if acted { 0.0 } else { rest.holds };
        let back = match Shares::needs_back(rest_holds, t.in_air(), is_return) {
            true => {
                let back_spec = return_spec(t, mission);
                Some(self.fly(&vehicle, back_spec, t, (soc, ratio), pack)?.holds)
            }
            false => None,
        };
        let shares = Shares {
            rest: rest_holds,
            back,
            in_air: t.in_air(),
            rest_is_return: is_return,
        };
        let failsafes = pack.map_or_else(Vec::new, |p| p.watched.answer(&rest.runs));
        let mut least: Vec<f64> = rest
            .runs
            .iter()
            .filter_map(|r| r.last().copied())
            .filter(|v| v.is_finite())
            .collect();
        let u = rest.u;
        Ok(Some(AheadAnswer {
            remaining_wh: u.energy_wh,
            landing_soc: u.end_soc,
            duration_s: u.duration_s,
            point_of_no_return_s: u.point_of_no_return_s.p5,
            shares,
            failsafes,
            least_voltage_v: Percentiles::of(&mut least),
        }))
    }

    /// The vehicle at the re-estimated efficiency `eta_0 / r` (at most 1:
    /// [`super::estimate::flown_efficiency`]).
    fn vehicle_at(&self, ratio: Ratio) -> Result<Vehicle, Error> {
        match self.vehicle.efficiency() {
            Some(eta0) if (ratio.ratio - 1.0).abs() > 1e-12 => self
                .vehicle
                .with_efficiency(super::estimate::flown_efficiency(eta0, ratio.ratio)),
            _ => Ok(self.vehicle.clone()),
        }
    }

    /// The scenarios of `spec` from the present state, on the pack where it is followed.
    fn fly(
        &self,
        vehicle: &Vehicle,
        spec: MissionSpec,
        t: &Tracker,
        (soc, ratio): (f64, Ratio),
        pack: Option<OnPack<'_>>,
    ) -> Result<Flown, Error> {
        let mission = Mission::of_spec(spec, "ahead", SourceFormat::AloftToml);
        let (speed_sd, from_sd) = wind_sd(t.wind.map(|(_, source)| source));
        let wind = match t.wind {
            Some((w, _)) => WindSpec::uniform(w[0].hypot(w[1]), wind_from_deg(w)),
            None => WindSpec::uniform(0.0, 0.0),
        };
        let options = MissionOptions {
            battery: self.battery.clone(),
            payload_kg: Some(self.payload_kg),
            wind: Some(wind),
            reserve_percent: self.reserve_percent,
            start_percent: (100.0 * soc).clamp(0.1, 100.0),
            time_step_s: Some(LIVE_TIME_STEP_S),
            speed_mps: self.speed_mps,
            // The air the flight was decided to fly in (the vehicle is in it already).
            air: crate::engine::conditions::air::AirInput::of_density(vehicle.air_density_kg_m3()),
            ..MissionOptions::default()
        };
        let sc = ScenarioOptions {
            samples: self.scenarios,
            wind_speed_sd_mps: speed_sd,
            wind_from_sd_deg: from_sd,
            power_sd_percent: (100.0 * ratio.log_sd).clamp(0.0, 50.0),
            ..ScenarioOptions::default()
        };
        let watch = pack.map(|p| p.watched.ahead(p.filter, sc.seed));
        let (u, seen) = plan_scenarios_watched(
            vehicle,
            &mission,
            &options,
            &sc,
            watch.as_ref().map(|w| w as &dyn ScenarioWatch),
        )?;
        let Some(p) = pack else {
            let holds = u.p_feasible;
            return Ok(Flown {
                u,
                holds,
                runs: Vec::new(),
            });
        };
        // A scenario holds where it lands with the reserve before any failsafe that acts.
        let acting = p.watched.acting();
        let holding = seen
            .iter()
            .filter(|(feasible, run)| {
                *feasible
                    && !run
                        .iter()
                        .zip(&acting)
                        .any(|(time_s, acts)| *acts && time_s.is_finite())
            })
            .count();
        let holds = holding as f64 / seen.len().max(1) as f64;
        let runs = seen.into_iter().map(|(_, r)| r).collect();
        Ok(Flown { u, holds, runs })
    }
}

/// The route ahead (see the module docs) and whether it is a return already; `None` on the
/// ground without a mission (nothing to fly).
fn rest_spec(t: &Tracker, mission: Option<&Mission>) -> Option<(MissionSpec, bool)> {
    let mode = t.heartbeat.as_ref().map_or("", |h| h.mode.as_str());
    if !t.in_air() {
        return mission.map(|m| (m.spec().clone(), false));
    }
    Some(match mode {
        "RTL" | "SMART_RTL" | "AUTO_RTL" => (return_spec(t, mission), true),
        "LAND" | "PRECLAND" => {
            let mut spec = start_here(t, mission);
            spec.segments.push(landing());
            (spec, true)
        }
        "AUTO" | "MISSION" if mission.is_some() => (mission_rest(t, mission?), false),
        _ => (return_spec(t, mission), true),
    })
}

/// The mission from the item being flown, ending on the ground.
fn mission_rest(t: &Tracker, m: &Mission) -> MissionSpec {
    let mut spec = start_here(t, Some(m));
    let current = t.mission_current.unwrap_or(0);
    let segments = &m.spec().segments;
    // A mission without item numbers (an aloft TOML or JSON file) cannot be indexed by
    // MISSION_CURRENT: it is flown whole from where the vehicle is.
    let numbered = segments.iter().any(|s| s.item().is_some());
    let from = match numbered {
        true => segments
            .iter()
            .position(|s| s.item().is_some_and(|i| i >= current))
            .unwrap_or(segments.len()),
        false => 0,
    };
    spec.segments = segments[from..]
        .iter()
        // In the air already: a take-off item is the climb done.
        .filter(|s| !matches!(s, SegmentSpec::TakeOff { .. }))
        .cloned()
        .collect();
    // A descent under way below its height is done too (the landing after it is not).
    let up = spec.start_in_air_m.map_or(0.0, |p| p[2]);
    if let Some(SegmentSpec::Descent { altitude_m, .. }) = spec.segments.first() {
        if *altitude_m >= up {
            spec.segments.remove(0);
        }
    }
    match spec.segments.last() {
        Some(SegmentSpec::Landing { .. } | SegmentSpec::LoiterUntilReserve { .. }) => {}
        Some(SegmentSpec::Return { .. }) => spec.segments.push(landing()),
        _ => spec.segments.extend([back_home(), landing()]),
    }
    spec
}

/// Straight back to home from where the vehicle is, and the landing.
fn return_spec(t: &Tracker, mission: Option<&Mission>) -> MissionSpec {
    let mut spec = start_here(t, mission);
    if t.in_air() {
        spec.segments = vec![back_home(), landing()];
    }
    spec
}

/// The mission's settings (or none), starting in the air where the vehicle is, no segments.
fn start_here(t: &Tracker, mission: Option<&Mission>) -> MissionSpec {
    let mut spec = match mission {
        Some(m) => MissionSpec {
            segments: Vec::new(),
            ..m.spec().clone()
        },
        None => MissionSpec {
            name: "return".to_string(),
            home: HomeSpec::default(),
            ..MissionSpec::default()
        },
    };
    spec.allow_end_in_air = false;
    // A return needs a speed: the mission's, else the vehicle's cruise speed, else this.
    spec.default_speed_mps.get_or_insert(RETURN_SPEED_MPS);
    if t.in_air() {
        spec.start_in_air_m = Some(position_from_home(t, &spec.home));
    }
    spec
}

/// The vehicle's position from `home`, m (east, north, up; up at least 0.5 m): through the
/// geodetic origin of the stream where home is geodetic, else from the stream's home.
fn position_from_home(t: &Tracker, home: &HomeSpec) -> [f64; 3] {
    let pos = t.pos_enu.unwrap_or([0.0; 3]);
    let up = t.height_m().unwrap_or(pos[2]).max(0.5);
    match (t.origin, home.latitude_deg, home.longitude_deg) {
        (Some(o), Some(lat), Some(lon)) => {
            let o_en = LocalFrame::new(lat, lon)
                .to_local_m(o.lat_rad.to_degrees(), o.lon_rad.to_degrees());
            [o_en[0] + pos[0], o_en[1] + pos[1], up]
        }
        _ => {
            let h = t.home_enu.unwrap_or([0.0; 3]);
            [pos[0] - h[0], pos[1] - h[1], up]
        }
    }
}

fn back_home() -> SegmentSpec {
    SegmentSpec::Return {
        ground_speed_mps: None,
        altitude_m: None,
        item: None,
    }
}

fn landing() -> SegmentSpec {
    SegmentSpec::Landing {
        rate_mps: LANDING_RATE_MPS,
        payload_after_kg: None,
        item: None,
        ground_m: None,
    }
}
