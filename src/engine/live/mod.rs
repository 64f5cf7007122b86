//! `aloft live`: following a flight as it flies and answering, at every update, what the rest of
//! it costs and whether it can be flown.
//!
//! Two ways in:
//! - [`follow_live`]: any [`TelemetrySource`] (a MAVLink link or telemetry log through the
//!   `aloft-link` crate, a flight log replayed as events): the events folded into the flight's
//!   state, the state of charge from the vehicle's reports, else its rested voltage, else a full
//!   pack ([`charge`](self::charge)), the charge drawn from the autopilot's count where it is
//!   believed ([`count`](self::count)), the efficiency re-estimated from measured against
//!   predicted power ([`estimate`](self::estimate)), the wind from the autopilot or the tilt, and
//!   the rest of the route flown from the present state in Monte-Carlo scenarios
//!   ([`ahead`](self::ahead)), with the advice and its hysteresis ([`advice`](self::advice)); on
//!   a link, the answer sent back ([`LiveReplies`]: values, aloft's own battery, texts).
//! - [`replay_live`]: the validation route (`--route log`), a flight log replayed with the rest of
//!   the logged path as the route ahead, so each prediction is checked against the energy the
//!   log measured from then to the end.

use serde::Serialize;

use aloft_logs::frame::enu_to_geodetic;
use aloft_logs::telemetry::TelemetrySource;

use crate::engine::basics::finite::finite;
use crate::engine::conditions::air::AirInput;
use crate::engine::missions::mission_file::Mission;
use crate::engine::uncertainty::scenario_stats::Percentiles;
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

mod advice;
mod ahead;
mod charge;
mod count;
mod estimate;
pub(crate) mod estimator;
mod failsafes;
mod pack_state;
mod record;
mod replay;
mod replay_failsafes;
mod replies;
mod sources;
mod tracker;

pub use ahead::LIVE_SCENARIOS;
pub use failsafes::{LiveFailsafe, TimeBand};
pub use record::LiveRecorder;
pub use replay::{
    replay_live, FailsafeCheck, FailsafeCheckpoint, LiveCheck, LiveCheckpoint, LiveReplayRequest,
};
pub use replies::{LiveReplies, DEFAULT_BATTERY_ID, DEFAULT_DISPLAY_COMPONENT_ID};
pub use sources::LiveSource;

use advice::AdviceHold;
use ahead::{Ahead, AheadAnswer};
use charge::{Charge, Drawn};
use count::ChargeCount;
use failsafes::Watched;
use pack_state::{report_kind, PackState};
use tracker::Tracker;

/// One update: a line of `aloft live --format json`. Fields that are not known yet (no fix, no
/// battery, no mission) are left out, as everywhere in aloft's JSON.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct LiveUpdate {
    /// Time since the start of the stream, s.
    pub time_s: f64,
    /// In the air.
    pub in_air: bool,
    /// Flight mode, by the autopilot's name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode: Option<String>,
    /// The mission item being flown (MISSION_CURRENT).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mission_item: Option<u32>,
    /// Where the vehicle is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position: Option<Position>,
    /// State of charge now, 0-1: the vehicle's report, else the rested voltage before take-off
    /// on the pack's open-circuit curve, else a full pack at the start, less the charge drawn
    /// since ([`charge`](self::charge); the `note` says where the report is not believed or a
    /// full pack is assumed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub soc: Option<f64>,
    /// The state of charge's band from the estimator, 0-1.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub soc_band: Option<SocBand>,
    /// The autopilot's own state of charge as it last reported it, 0-1 (beside `soc`, which is
    /// aloft's estimate).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reported_soc: Option<f64>,
    /// The pack's voltage as measured now, V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub voltage_v: Option<f64>,
    /// The pack's current as measured now, A (positive discharging).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub current_a: Option<f64>,
    /// The autopilot's count of the charge drawn, A h, where it is believed
    /// ([`count`](self::count)); sent as aloft's BATTERY_STATUS `current_consumed`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub charge_drawn_ah: Option<f64>,
    /// Electrical energy used so far, Wh (measured; the model's without power data).
    pub energy_used_wh: f64,
    /// Measured electrical power now, W.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power_w: Option<f64>,
    /// Whether the source measures power (without it the prediction is the model's alone).
    pub power_available: bool,
    /// The efficiency the rest is predicted with (re-estimated in flight), in (0, 1].
    pub efficiency: f64,
    /// Wind speed, m/s (horizontal).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wind_mps: Option<f64>,
    /// Direction the wind blows from, deg clockwise from north.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wind_from_deg: Option<f64>,
    /// Energy to finish the route and land, Wh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub remaining_wh: Option<Percentiles>,
    /// State of charge at landing, 0-1.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub landing_soc: Option<Percentiles>,
    /// The point of no return, s from now (negative once passed); left out where the route can
    /// turn back everywhere.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub point_of_no_return_s: Option<f64>,
    /// The failsafes the vehicle watches and when each triggers on the rest of the route.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub failsafes: Vec<LiveFailsafe>,
    /// The least voltage under load on the rest of the route, V (the pack's circuit as the
    /// filter holds it, under the planned current).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub least_voltage_v: Option<Percentiles>,
    /// What to do: `continue`, `return now` or `land now`; on the ground, `continue` or `do not
    /// take off`. A graver advice at once, a milder one once it has held
    /// ([`advice`](self::advice)).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub advice: Option<&'static str>,
    /// The naive rate: mean measured power so far times the route's remaining time, Wh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub naive_remaining_wh: Option<f64>,
    /// Validation mode: the energy the log measured from now to the end, Wh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub measured_remaining_wh: Option<f64>,
    /// The link has gone quiet: the figures are the last estimate's.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub link_lost: bool,
    /// Why the route ahead has no answer (the planner's message), that the efficiency was held
    /// at 1, where the state of charge comes from when it is not the vehicle's report, and once,
    /// a step back of a telemetry log's clock or a count of the charge drawn not believed;
    /// several joined by `; `.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A band of the state of charge, 0-1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SocBand {
    /// 5th percentile.
    pub p5: f64,
    /// 95th percentile.
    pub p95: f64,
}

/// Where the vehicle is: from home (else the stream's first fix), and geodetic where the source
/// has a fix.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Position {
    /// East of home, m.
    pub east_m: f64,
    /// North of home, m.
    pub north_m: f64,
    /// Height above home, m.
    pub up_m: f64,
    /// Latitude, deg (WGS-84).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub latitude_deg: Option<f64>,
    /// Longitude, deg (WGS-84).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub longitude_deg: Option<f64>,
}

/// A flight followed live.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveRequest {
    /// Pack flown (default: the vehicle's).
    pub battery: Option<String>,
    /// Payload, kg.
    pub payload_kg: f64,
    /// An update every this many seconds of the stream's time.
    pub every_s: f64,
    /// The mission, where it is not learned from the link (`--mission FILE`).
    pub mission: Option<Mission>,
    /// Reserve required at landing, percent of the usable capacity (default: the mission's,
    /// else 20).
    pub reserve_percent: Option<f64>,
    /// Planning speed of the legs that give none, m/s.
    pub speed_mps: Option<f64>,
    /// Scenarios per update (default [`LIVE_SCENARIOS`]).
    pub scenarios: u32,
    /// The autopilot's low-voltage failsafe, pack volts, judged on the voltage under load
    /// averaged over 5 s (`--low-voltage-v`: in place of the vehicle's `BATT_LOW_VOLT`).
    pub low_voltage_v: Option<f64>,
    /// The critical-voltage failsafe, pack volts (`--critical-voltage-v`).
    pub critical_voltage_v: Option<f64>,
    /// The pack file's `[failsafe]` (low, critical; pack volts), watched where the flags give
    /// none.
    pub pack_failsafe_v: [Option<f64>; 2],
    /// The pack's rested voltage before take-off, V (`--start-voltage-v`): the state of charge
    /// starts from it on the pack's curve, before any the stream gives.
    pub start_voltage_v: Option<f64>,
    /// The day's air (default: the mission's home altitude in ISA air, else the vehicle file's
    /// density).
    pub air: AirInput,
    /// The BATTERY_STATUS id aloft's own battery is sent under on a link (default
    /// [`DEFAULT_BATTERY_ID`]).
    pub battery_id: u8,
}

impl LiveRequest {
    /// A request with the defaults: the vehicle's pack, no payload, an update a second.
    pub fn new() -> Self {
        Self {
            battery: None,
            payload_kg: 0.0,
            every_s: 1.0,
            mission: None,
            reserve_percent: None,
            speed_mps: None,
            scenarios: LIVE_SCENARIOS,
            low_voltage_v: None,
            critical_voltage_v: None,
            pack_failsafe_v: [None, None],
            start_voltage_v: None,
            air: AirInput::default(),
            battery_id: DEFAULT_BATTERY_ID,
        }
    }
}

impl Default for LiveRequest {
    fn default() -> Self {
        Self::new()
    }
}

/// How a followed stream ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveSummary {
    /// Updates made.
    pub updates: usize,
    /// Span of the stream, s.
    pub duration_s: f64,
    /// Restarts of the vehicle seen.
    pub reboots: u32,
    /// Missions received (uploads and downloads).
    pub missions: u32,
    /// What the source passed over (damaged frames, bytes skipped).
    pub skipped: String,
}

/// Follow `source` to its end: an update every `every_s` seconds of its time to `emit`, and on a
/// link the answer sent back through [`TelemetrySource::reply`] ([`LiveReplies`]).
///
/// Steps per event: fold it into the flight's state; at an update, the state of charge, the
/// efficiency's estimate, then the route ahead and the advice, then the replies.
///
/// # Errors
/// A vehicle without a power model, an update interval that is not positive, a `--mission` the
/// vehicle cannot plan at all, a source that fails (a file that cannot be read), and `emit`'s
/// own error.
pub fn follow_live(
    vehicle: &Vehicle,
    request: &LiveRequest,
    source: &mut dyn TelemetrySource,
    emit: &mut dyn FnMut(&LiveUpdate) -> Result<(), Error>,
) -> Result<LiveSummary, Error> {
    check_every(request.every_s)?;
    // The flight's air: the given day, else the mission's home altitude, else the vehicle's.
    let home_amsl_m = request
        .mission
        .as_ref()
        .and_then(|m| m.spec().home.altitude_amsl_m);
    let air = crate::engine::conditions::air::resolve_air(&request.air, home_amsl_m, vehicle)?;
    let vehicle = &vehicle.in_air(air.air_density_kg_m3)?;
    let mut follower = LiveSession::new(vehicle, request)?;
    let mut updates = 0;
    let (mut first_s, mut next_s) = (None, f64::NEG_INFINITY);
    let mut last: Option<LiveUpdate> = None;
    let mut replies = LiveReplies::new(request.battery_id);
    while let Some(event) = source.next_event().map_err(Error::Link)? {
        follower.apply(&event);
        let now = follower.tracker.now_s;
        first_s.get_or_insert(now);
        let lost = follower.tracker.link_lost;
        if now < next_s && !lost {
            continue;
        }
        next_s = now + request.every_s;
        let update = match (lost, &last) {
            // The last estimate, said to be old.
            (true, Some(prev)) => LiveUpdate {
                time_s: now,
                link_lost: true,
                ..prev.clone()
            },
            _ => follower.update(),
        };
        let update = finite(update, "live", || "the live update".to_string())?;
        for reply in replies.replies(last.as_ref(), &update) {
            source.reply(&reply).map_err(Error::Link)?;
        }
        emit(&update)?;
        updates += 1;
        last = Some(update);
    }
    Ok(LiveSummary {
        updates,
        duration_s: follower.tracker.now_s - first_s.unwrap_or(0.0),
        reboots: follower.tracker.reboots,
        missions: follower.tracker.mission.as_ref().map_or(0, |(_, n)| *n),
        skipped: source.skipped(),
    })
}

/// An update interval must be positive and finite.
pub(crate) fn check_every(every_s: f64) -> Result<(), Error> {
    if every_s.is_finite() && every_s > 0.0 {
        return Ok(());
    }
    Err(Error::InvalidInput {
        name: "every",
        value: every_s,
        unit: "s",
        expected: "a positive number of seconds",
    })
}

/// A flight followed event by event: [`follow_live`]'s state, for a caller that feeds the events
/// itself ([`LiveSession::apply`]) and asks for an answer when it wants one
/// ([`LiveSession::update`]).
pub struct LiveSession<'a> {
    tracker: Tracker,
    ahead: Ahead<'a>,
    /// The state of charge and where it comes from.
    charge: Charge,
    /// The autopilot's count of the charge drawn, believed or not.
    count: ChargeCount,
    /// The state of charge's filter.
    pack_state: PackState,
    /// The failsafes watched (from the vehicle's parameters and the flags), or why not; `None`
    /// before they are built (at the start, after a restart).
    watched: Option<Result<Option<Watched>, String>>,
    /// The flags' voltage thresholds.
    thresholds: Vec<aloft_packs::VoltageThreshold>,
    /// The rested voltage given (`--start-voltage-v`), V.
    start_voltage_v: Option<f64>,
    /// The advice given, for its hysteresis.
    advice: AdviceHold,
    eta0: f64,
    given_mission: Option<&'a Mission>,
    /// The mission learned from the source (or why it cannot be read), by the upload it came
    /// from.
    learned: Option<(u32, Result<Mission, String>)>,
    /// The last point of no return, s of the stream, to say how long ago it passed.
    point_of_no_return_at: Option<f64>,
    /// The answer on the ground, while nothing it depends on changes.
    on_ground: Option<(GroundKey, AheadAnswer)>,
    /// The rest's duration at the last update (p50), s: the horizon of the ratio's drift.
    rest_s: f64,
}

/// The flags' voltage failsafes (`--low-voltage-v`, `--critical-voltage-v`), as the failsafes'
/// monitor takes them.
/// The flags' (`[low, critical]`, pack volts), else the pack file's `[failsafe]` (`pack`).
pub(crate) fn thresholds(
    flags: [Option<f64>; 2],
    pack: [Option<f64>; 2],
) -> Vec<aloft_packs::VoltageThreshold> {
    use aloft_packs::{FailsafeKind, VoltageThreshold};
    let kinds = [
        (FailsafeKind::Low, "--low-voltage-v"),
        (FailsafeKind::Critical, "--critical-voltage-v"),
    ];
    kinds
        .into_iter()
        .zip(flags.into_iter().zip(pack))
        .filter_map(|((kind, flag), (given, file))| {
            let (voltage_v, source) = match (given, file) {
                (Some(v), _) => (v, flag),
                (None, Some(v)) => (v, "[failsafe]"),
                (None, None) => return None,
            };
            Some(VoltageThreshold {
                kind,
                voltage_v,
                source: source.to_string(),
            })
        })
        .collect()
}

/// A disagreement between the vehicle's report and the estimate the note explains, state of
/// charge (0-1).
const DISAGREE: f64 = 0.10;

/// The rest's duration before the first answer, s.
const DEFAULT_REST_S: f64 = 300.0;

/// What an answer on the ground depends on: the mission's upload, the state of charge (0.5 %
/// steps), the wind (0.5 m/s steps).
type GroundKey = (u32, i64, [i64; 2]);

impl<'a> LiveSession<'a> {
    /// A session for `vehicle` as `request` asks (its `every_s` is the caller's to keep).
    ///
    /// # Errors
    /// A vehicle without a power model or without a pack (by name, or a default).
    pub fn new(vehicle: &'a Vehicle, request: &'a LiveRequest) -> Result<Self, Error> {
        let (model, mass) =
            vehicle.power_model_with(request.battery.as_deref(), request.payload_kg)?;
        let pack = vehicle.battery(request.battery.as_deref())?;
        if let Some(v) = request.start_voltage_v {
            let options = crate::engine::missions::mission_options::MissionOptions {
                start_voltage_v: Some(v),
                ..Default::default()
            };
            crate::engine::missions::mission::start_soc(&options, &pack)?;
        }
        let drag = vehicle
            .aircraft()
            .ok()
            .map(|a| (*a.drag(), mass.total_kg * a.gravity_mps2()));
        let prior_sd = estimate::prior_sd(&model);
        let eta0 = model.vehicle().efficiency();
        Ok(Self {
            tracker: Tracker::new(model, drag, prior_sd),
            ahead: Ahead {
                vehicle,
                battery: request.battery.clone(),
                payload_kg: request.payload_kg,
                reserve_percent: request.reserve_percent,
                speed_mps: request.speed_mps,
                scenarios: request.scenarios,
            },
            count: ChargeCount::new(pack.capacity_ah()),
            pack_state: PackState::new(&pack),
            watched: None,
            thresholds: thresholds(
                [request.low_voltage_v, request.critical_voltage_v],
                request.pack_failsafe_v,
            ),
            charge: Charge::new(pack),
            advice: AdviceHold::default(),
            eta0,
            given_mission: request.mission.as_ref(),
            start_voltage_v: request.start_voltage_v,
            learned: None,
            point_of_no_return_at: None,
            on_ground: None,
            rest_s: DEFAULT_REST_S,
        })
    }

    /// What was drawn from the pack so far: the autopilot's count where it is believed, and
    /// the energy used.
    fn drawn(&self) -> Drawn {
        Drawn {
            consumed_ah: self.count.believed_ah(),
            energy_wh: self.tracker.energy_used_wh(),
        }
    }

    /// The state of charge now: the filter's ([`pack_state`](self::pack_state)), else what
    /// [`charge`](self::charge) makes of the reports.
    fn soc(&self) -> f64 {
        match self.pack_state.estimate() {
            Some(e) => e.soc,
            None => self.charge.soc(self.drawn()).0,
        }
    }

    /// Read the mission the source sent, once per upload (a mission aloft cannot read is kept as
    /// its message).
    fn learn_mission(&mut self) {
        if let Some((items, upload)) = &self.tracker.mission {
            if self.learned.as_ref().is_none_or(|(u, _)| u != upload) {
                let m = Mission::from_items(items, "the mission on the link")
                    .map_err(|e| e.to_string());
                self.learned = Some((*upload, m));
            }
        }
    }

    /// Fold one event in.
    pub fn apply(&mut self, event: &aloft_logs::telemetry::Telemetry) {
        use aloft_logs::telemetry::Event;
        self.tracker.apply(event);
        self.apply_count(&event.event);
        let in_air = self.tracker.in_air();
        let drawn = self.drawn();
        let c = &mut self.charge;
        match &event.event {
            // Another flight, maybe another pack: nothing reported holds, no advice either.
            Event::Reboot => {
                *c = Charge::new(c.pack().clone());
                self.pack_state = PackState::new(c.pack());
                self.advice = AdviceHold::default();
            }
            Event::Battery(b) => {
                if let Some(soc) = b.soc {
                    c.report(soc, in_air, drawn);
                }
            }
            Event::Sample(s) => {
                if let (Some(v), false) = (s.voltage_v, in_air) {
                    let disarmed = self.tracker.heartbeat.as_ref().is_some_and(|h| !h.armed);
                    c.voltage(self.tracker.now_s, v, s.current_a, disarmed, drawn);
                }
                if let Some(soc) = s.soc {
                    c.report(soc, in_air, drawn);
                }
            }
            _ => {}
        }
        if in_air {
            c.in_air();
        }
        self.follow_pack(event, drawn);
        self.follow_failsafes(event);
    }

    /// The failsafes watched: built from the vehicle's parameters as they arrive (and the
    /// flags'), their monitor fed each measured sample.
    fn follow_failsafes(&mut self, event: &aloft_logs::telemetry::Telemetry) {
        use aloft_logs::telemetry::Event;
        let t = &self.tracker;
        if matches!(event.event, Event::Reboot) {
            self.watched = None;
        }
        let stale = match &self.watched {
            None => true,
            Some(Ok(Some(w))) => !w.is_of(&t.parameters),
            Some(_) => matches!(event.event, Event::Parameter { .. }),
        };
        if stale {
            let cells = self.charge.pack().cells_series();
            self.watched = Some(Watched::new(&t.parameters, cells, &self.thresholds));
        }
        if let (Event::Sample(s), Some(Ok(Some(w)))) = (&event.event, &mut self.watched) {
            if let Some(v) = s.voltage_v.filter(|v| v.is_finite() && *v > 0.0) {
                let drawn_mah = self.count.believed_ah().map(|a| 1000.0 * a);
                w.sample(t.now_s, v, s.current_a, drawn_mah);
            }
        }
    }

    /// The filter of the state of charge ([`pack_state`](self::pack_state)): started from the
    /// evidence before take-off, then fed each sample and report.
    fn follow_pack(&mut self, event: &aloft_logs::telemetry::Telemetry, drawn: Drawn) {
        use aloft_logs::telemetry::Event;
        let t = &self.tracker;
        let kind = report_kind(&t.parameters);
        let p = &mut self.pack_state;
        if !p.running() {
            // In the air already (a stream that starts there): the sample's voltage under load
            // where nothing better is known.
            let loaded = match &event.event {
                Event::Sample(s) if t.in_air() => s.voltage_v.zip(s.current_a),
                _ => None,
            };
            let start = match self.start_voltage_v {
                Some(v) => pack_state::Start::Rested(v),
                None => self.charge.start(drawn),
            };
            p.start_from(start, kind, loaded);
            // In the air from a full pack assumed, wait a little for a voltage or a report
            // (a stream's first samples may carry only the motion).
            let waits = start == pack_state::Start::Full
                && loaded.is_none()
                && t.air_s < pack_state::START_WAIT_S;
            if t.in_air() && !waits {
                p.in_air();
            }
        }
        let now = t.now_s;
        let believed = self.charge.last_report_believed();
        match &event.event {
            Event::Sample(s) => {
                let measured = (s.voltage_v, s.current_a, s.electrical_power_w());
                p.sample(now, measured, t.energy_used_wh());
                if let Some(soc) = s.soc {
                    p.report(now, soc, believed, kind);
                }
            }
            Event::Battery(b) => {
                if let Some(soc) = b.soc {
                    p.report(now, soc, believed, kind);
                }
            }
            _ => {}
        }
    }

    /// What the note says where the vehicle's report and the estimate disagree by more than
    /// [`DISAGREE`], and why they may.
    fn disagreement_note(&self) -> Option<String> {
        let estimate = self.pack_state.estimate()?;
        let reported = self.pack_state.reported()?;
        if (reported - estimate.soc).abs() <= DISAGREE {
            return None;
        }
        let why = match report_kind(&self.tracker.parameters) {
            aloft_packs::ReportKind::Voltage => {
                "PX4 without BAT1_CAPACITY reads its charge from the voltage under load, which \
                 sags with the current"
            }
            _ => {
                "an autopilot counts the charge drawn from the capacity it is given, from a pack \
                 it takes as full at boot"
            }
        };
        Some(format!(
            "the vehicle reports {:.0} % where the pack's circuit and the charge drawn say {:.0} % \
             ({:.0}-{:.0} %): {why}",
            100.0 * reported,
            100.0 * estimate.soc,
            100.0 * estimate.p5,
            100.0 * estimate.p95
        ))
    }

    /// Where a PX4 failsafe, acting on PX4's own estimate, comes before home: when, what PX4's
    /// estimate says now and what the pack holds (`PX4 triggers its low-battery failsafe
    /// (BAT_LOW_THR 15 %) in 3:10 (p50) although the pack holds 31 %: its own estimate says
    /// 22 %`).
    fn px4_note(&self, failsafes: &[LiveFailsafe], soc: f64) -> Option<String> {
        let Some(Ok(Some(w))) = &self.watched else {
            return None;
        };
        let px4 = w.px4_remaining()?;
        let f = failsafes
            .iter()
            .find(|f| f.unit == "fraction" && f.before_home)?;
        let when = match f.time_s.and_then(|t| t.p50) {
            Some(t) if t > 0.0 => format!("in {} (p50)", replies::clock(t)),
            Some(_) => "now".to_string(),
            None => "before the landing (p5)".to_string(),
        };
        Some(format!(
            "PX4 triggers its {} battery failsafe ({} {:.0} %) {when} although the pack holds \
             {:.0} %: its own estimate says {:.0} %",
            f.kind,
            f.source,
            100.0 * f.threshold,
            100.0 * soc,
            100.0 * px4
        ))
    }

    /// The autopilot's count and the current it is judged by ([`count`](self::count)); a
    /// restart starts the count over.
    fn apply_count(&mut self, event: &aloft_logs::telemetry::Event) {
        use aloft_logs::telemetry::Event;
        let now = self.tracker.now_s;
        match event {
            Event::Reboot => self.count = ChargeCount::new(self.charge.pack().capacity_ah()),
            Event::Sample(s) => {
                if let Some(i) = s.current_a {
                    self.count.current(now, i);
                }
            }
            Event::Battery(b) => {
                if let Some(c) = b.consumed_ah {
                    self.count.count(now, c);
                }
            }
            _ => {}
        }
    }

    /// The answer now: the state of charge, the efficiency's estimate, the route ahead in
    /// scenarios and the advice. A mission learned from the link that aloft cannot read, a route
    /// the planner refuses, and, once, a step back of a telemetry log's clock or a count of the
    /// charge drawn not believed since the last answer are said in the update's `note`.
    pub fn update(&mut self) -> LiveUpdate {
        let mut update = self.answer();
        let once = [self.tracker.clock_note.take(), self.count.take_note()];
        update.note = once
            .into_iter()
            .chain([update.note])
            .flatten()
            .reduce(|a, b| format!("{a}; {b}"));
        update
    }

    /// [`LiveSession::update`] but for the clock's note.
    fn answer(&mut self) -> LiveUpdate {
        let soc = self.soc();
        let t = &self.tracker;
        let rest_s = self.rest_s;
        // Without power the estimator has no samples: the fitted model and its spread.
        let ratio = t.estimator.ratio(rest_s);
        let in_air = t.in_air();
        let wind = t.wind.map(|(w, _)| w);
        let key: GroundKey = (
            t.mission.as_ref().map_or(0, |(_, n)| *n),
            (soc * 200.0).round() as i64,
            wind.map_or([0, 0], |w| {
                [(w[0] * 2.0).round() as i64, (w[1] * 2.0).round() as i64]
            }),
        );
        let cached = match (&self.on_ground, in_air) {
            (Some((k, a)), false) if *k == key => Some(a.clone()),
            _ => None,
        };
        let (answer, note) = match cached {
            Some(a) => (Some(a), None),
            None => {
                // The mission flown: `--mission`, else the last one the source sent; one aloft
                // cannot read is said in the note, not an error.
                self.learn_mission();
                let mission = match (self.given_mission, &self.learned) {
                    (Some(m), _) => Some(m),
                    (None, Some((_, Ok(m)))) => Some(m),
                    (None, Some((_, Err(e)))) => {
                        let note = Some(e.clone());
                        return self.answer_update(soc, ratio, None, note);
                    }
                    (None, None) => None,
                };
                let pack = match (self.pack_state.filter(), &self.watched) {
                    (Some(filter), Some(Ok(Some(watched)))) => {
                        Some(ahead::OnPack { filter, watched })
                    }
                    _ => None,
                };
                match self
                    .ahead
                    .answer(&self.tracker, mission, (soc, ratio), pack)
                {
                    Ok(a) => (a, None),
                    Err(e) => (None, Some(aloft_core::one_line(&e.to_string()))),
                }
            }
        };
        if let (Some(a), false) = (&answer, in_air) {
            self.on_ground = Some((key, a.clone()));
        }
        if let Some(d) = answer.as_ref().and_then(|a| a.duration_s) {
            self.rest_s = d.p50;
        }
        let note = match (note, self.eta0 / ratio.ratio > 1.0) {
            (None, true) => Some(estimate::EFFICIENCY_HELD_NOTE.to_string()),
            (note, _) => note,
        };
        self.answer_update(soc, ratio, answer, note)
    }

    /// The update from the state and the route ahead's answer.
    fn answer_update(
        &mut self,
        soc: f64,
        ratio: estimate::Ratio,
        answer: Option<AheadAnswer>,
        note: Option<String>,
    ) -> LiveUpdate {
        let t = &self.tracker;
        let now = t.now_s;
        let pnr = answer.as_ref().and_then(|a| a.point_of_no_return_s);
        let point_of_no_return_s = match pnr {
            Some(p) if p > 0.0 => {
                self.point_of_no_return_at = Some(now + p);
                Some(p)
            }
            // Passed: how long ago, where it was seen ahead before.
            Some(_) => Some(
                self.point_of_no_return_at
                    .map_or(0.0, |at| (at - now).min(0.0)),
            ),
            None => None,
        };
        let naive = (t.power_available() && t.air_s >= estimate::MIN_WINDOW_S)
            .then_some(())
            .and_then(|()| answer.as_ref()?.duration_s)
            .map(|d| t.air_measured_j / t.air_s * d.p50 / 3600.0);
        let wind = t.wind.map(|(w, _)| w);
        let watched_note = self
            .watched
            .as_ref()
            .and_then(|w| w.as_ref().err().cloned());
        let foreign_note = self.pack_state.foreign_v().map(|v| {
            format!(
                "the pack's voltage ({v:.1} V) is not a voltage of the {}-cell pack of the \
                 vehicle file: the state of charge is the vehicle's report, less the charge drawn",
                self.charge.pack().cells_series()
            )
        });
        let px4_note = answer
            .as_ref()
            .and_then(|a| self.px4_note(&a.failsafes, soc));
        // Where the state of charge started, where the evidence before take-off is not what
        // `charge` says of it: the rested voltage given, or the first voltage in the air.
        let charge_note = match (self.start_voltage_v, self.pack_state.start()) {
            (Some(_), _) => None,
            (None, Some(pack_state::Start::Loaded)) => Some(
                "no state of charge from the vehicle before take-off: the flight starts from its \
                 first voltage under load in the air, within 15 points"
                    .to_string(),
            ),
            _ => self.charge.note(),
        };
        let note = [
            note,
            charge_note,
            self.disagreement_note(),
            watched_note,
            foreign_note,
            px4_note,
        ]
        .into_iter()
        .flatten()
        .reduce(|a, b| format!("{a}; {b}"));
        // Nothing from the pack yet on the ground (no report, no rested voltage, no power
        // measured): the assumed full pack is not shown as the vehicle's state (the note says
        // what is assumed).
        let shown = !self.charge.assumed_full() || t.power_available() || t.in_air();
        LiveUpdate {
            time_s: now,
            in_air: t.in_air(),
            mode: t.heartbeat.as_ref().map(|h| h.mode.clone()),
            mission_item: t.mission_current,
            position: position(t),
            soc: shown.then_some(soc),
            soc_band: self
                .pack_state
                .estimate()
                .filter(|_| shown)
                .map(|e| SocBand {
                    p5: e.p5,
                    p95: e.p95,
                }),
            reported_soc: self.pack_state.reported(),
            voltage_v: t.voltage_v,
            current_a: t.current_a,
            charge_drawn_ah: self.count.believed_ah(),
            energy_used_wh: t.energy_used_wh(),
            power_w: t.power_w,
            power_available: t.power_available(),
            efficiency: estimate::flown_efficiency(self.eta0, ratio.ratio),
            wind_mps: wind.map(|w| w[0].hypot(w[1])),
            wind_from_deg: wind.map(tracker::wind_from_deg),
            remaining_wh: answer.as_ref().and_then(|a| a.remaining_wh),
            landing_soc: answer.as_ref().and_then(|a| a.landing_soc),
            point_of_no_return_s,
            failsafes: answer
                .as_ref()
                .map_or_else(Vec::new, |a| a.failsafes.clone()),
            least_voltage_v: answer.as_ref().and_then(|a| a.least_voltage_v),
            advice: answer
                .as_ref()
                .map(|a| self.advice.advise(now, &a.shares).as_str()),
            naive_remaining_wh: naive,
            measured_remaining_wh: None,
            link_lost: false,
            note,
        }
    }
}

/// The vehicle's position from home, geodetic where the stream has an origin.
fn position(t: &Tracker) -> Option<Position> {
    let p = t.pos_enu?;
    let h = t.home_enu.unwrap_or([0.0; 3]);
    let geo = t.origin.map(|o| enu_to_geodetic(&o, p));
    Some(Position {
        east_m: p[0] - h[0],
        north_m: p[1] - h[1],
        up_m: p[2] - h[2],
        latitude_deg: geo.map(|g| g.0.to_degrees()),
        longitude_deg: geo.map(|g| g.1.to_degrees()),
    })
}
