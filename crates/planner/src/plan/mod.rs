//! Flying a mission: sample the trajectory, trim each sample in the wind, draw the power from the
//! pack, and summarise.
//!
//! # The loop, in the order data flows
//! [`plan`] checks the [`PlanOptions`], builds the vehicle at the mass of each mass phase, and
//! flies the mission in blocks of 64 steps through two passes:
//! 1. **sample** (`sampler.rs`, pass A): for each block the kinematics, the wind and the air
//!    velocity, ground effect, the trims and the electrical power (in vector lanes), and the
//!    airframe's limits; steady stretches reuse one trim;
//! 2. **feed** (`feed.rs`): hands the blocks to pass B from a second thread, or runs pass A in
//!    line when pass B asks; the only part that knows about threads;
//! 3. **draw** (`PackPass`, here): pass B, the pack over the block
//!    ([`PackCursor::draw_block`](crate::PackCursor::draw_block), exactly the step-by-step chain
//!    of states of charge), then each step in order: booked, stopped where the pack fails,
//!    checked for the way home;
//! 4. **book** (`ledger.rs`): energy, heat, peaks, lowest voltage and state of charge per segment
//!    and per mission, and at the end the [`MissionReport`];
//! 5. **check the way home** (`return_check.rs`): the point of no return;
//!
//! and `report.rs` holds what a run is asked and answers ([`PlanOptions`], [`MissionReport`],
//! [`SegmentReport`], [`Sample`], [`Shortfall`], [`PointOfNoReturn`]).
//!
//! # Integration
//! Each trajectory piece of duration `D` is cut into `n = ceil(D / dt)` equal steps of
//! `h = D / n <= dt` and every quantity is evaluated at the step's midpoint (midpoint rule:
//! energy `sum P h`, charge `sum I h`). Pieces end exactly on a step, so the mission's duration is
//! exact and the error is second order in `h` except at the few instants where the acceleration
//! jumps.
//!
//! Per sample: wind at the position and time, `v_air = v_ground - wind`, trim (thrust vector from
//! the force balance, [`crate::trim`]), ground effect (survey eq 35, [`crate::ground_effect`]) at
//! the rotor height `altitude + rotor_height_m`, electrical power, pack current and terminal
//! voltage ([`crate::battery`]), state of charge.
//!
//! # Evaluation order
//! Steps are evaluated in blocks of 64. Pass A: kinematics, wind and air velocity for the block,
//! then the trims ([`Powered::trim_block`]: force balance for all, then the power model for all,
//! both in vector lanes) and the airframe's limits. Pass B: the pack over the block
//! ([`PackCursor::draw_block`](crate::PackCursor::draw_block), exactly the step-by-step chain of
//! states of charge), then the bookkeeping of each step in order. Pass A does not depend on the
//! pack, so on a mission of 4096 steps or more it runs on a second thread, blocks ahead of pass B
//! ([`PlanOptions::second_thread`]); the report is the same bit for bit (tested). An error found
//! in pass A (a thrust beyond the airframe, a wind grid left) is raised only after pass B has
//! flown the samples before it, so a battery that fails first is still reported as the result.
//!
//! The results are those of the sample-by-sample loop: the trims and the pack bit for bit, orbit
//! positions to 1e-13 m (a rotation table replaces `sincos` of a large angle on an arc's cruise,
//! [`crate::trajectory::BlockSampler`]), the pack's charge step to one rounding (`I (h / Q)`
//! instead of `I h / Q`). On a level line or a hold at cruise in a steady wind that depends on
//! height alone the trim is computed once per stretch (its inputs are the same bits at every
//! step); ground effect once per piece at a fixed height. A unit test checks that this hoisting
//! leaves the report unchanged, bit for bit, every sample included.
//!
//! # The flight envelope
//! A sample that asks for more tilt, thrust, airspeed, climb or descent rate than the airframe
//! has is flown as an autopilot flies it: along the same path, slower, at the largest fraction
//! `q` of its planned velocity within the limits ([`crate::envelope`], found in pass A). Its step
//! takes `h / q`; the time flown beyond the plan accumulates through the piece and the mission
//! (samples keep their real times), and each segment reports it with the slowest speed it was
//! held to and the limit ([`SegmentReport::time_lost_s`], [`SegmentReport::edge`]). A mission
//! flown within the envelope takes exactly the steps and times it took before the envelope
//! existed: a step's time is `t0 + (k + 1/2) h + 0`, bit for bit.
//!
//! # Feasibility
//! The mission is infeasible (a valid result, not an error) when the pack cannot deliver the power,
//! the current exceeds the pack's rating, the terminal voltage falls below the cut-off, the usable
//! charge runs out, the vehicle lands with less than the reserve, or it cannot fly the path at
//! any speed within its envelope (it cannot make headway against the wind, or hold its position:
//! [`Shortfall::NoProgress`]). The simulation stops there and reports the time, segment and
//! position.
//!
//! # Point of no return
//! Every `pnr_interval_s` while airborne the planner prices a straight return: fly home at the
//! best-range airspeed for the home bearing in the mean wind at the present position
//! ([`crate::queries::best_range`], cached per 0.5 deg of bearing), then descend vertically at
//! `return_descent_rate_mps`. The charge it needs is taken at the pack's present state (current
//! at the midpoint state of charge of the return). The point of no return is the last check
//! before the first one at which the return would end below the reserve; it is absent when every
//! check passes.
//!
//! The checks run every `pnr_interval_s` (1 s), not every step: between two checks the vehicle
//! moves at most `max_speed x 1 s` and the return it would fly changes by that much, so the point
//! of no return is known to the interval, which is the resolution it is reported at. On the
//! one-hour bench mission the checks take about 1 ms of the 14 ms a single thread needs (108
//! bearing bins priced, 3609 checks), which the second thread hides (bench
//! `planner/mission/one_hour` against `one_hour_without_pnr`).

mod feed;
mod ledger;
mod report;
mod return_check;
mod sampler;
#[cfg(test)]
mod test_mission;

use std::ops::ControlFlow;

use crate::aircraft::{Aircraft, Powered};
use crate::battery::Pack;
use crate::envelope::Envelope;
use crate::error::PlannerError;
use crate::mission::Mission;
use crate::pack_cursor::{PackCursor, PackStep};
use crate::trajectory::Piece;
use crate::wind::Wind;

use ledger::{EdgeStep, Ledger, PieceTally};
use report::CheckedOptions;
use return_check::ReturnCheck;
use sampler::{piece_steps, BlockA, PassA, Stop};

pub use report::{
    EdgeReport, MissionReport, NoProgressWhy, NoSamples, PlanOptions, PointOfNoReturn, Sample,
    SampleSink, SegmentReport, Shortfall, Stuck, DEFAULT_MAX_SAMPLES,
};

/// The airframe's envelope and, per mass phase, its steady airspeed limit and the limit that
/// bounds it: computed once per flight for the sampler and the return check.
pub(super) struct Limits {
    pub(super) envelope: Envelope,
    pub(super) max_airspeed: Vec<(f64, crate::envelope::Limit)>,
}

impl Limits {
    pub(super) fn of(aircraft: &Aircraft, powered: &[Powered<'_>]) -> Self {
        let envelope = Envelope::of(aircraft.airframe(), aircraft.gravity_mps2());
        let max_airspeed = powered
            .iter()
            .map(|pw| envelope.max_level_airspeed_mps(pw))
            .collect();
        Self {
            envelope,
            max_airspeed,
        }
    }
}

/// Steps per block of the two-pass loop: small enough for the block to stay in the L1 cache,
/// large enough that the loop overhead of a pass is negligible.
const BLOCK: usize = 64;

/// Fly `mission` with `aircraft` and `battery` in `wind`; the report holds every sample when
/// [`PlanOptions::record_samples`] asks for them.
///
/// # Errors
/// Invalid options, a thrust or tilt beyond the airframe's limit, a wind grid that does not cover
/// the route, a flight condition the power model rejects, a flight longer than
/// [`PlanOptions::max_samples`] steps.
pub fn plan(
    aircraft: &Aircraft,
    battery: &Pack,
    mission: &Mission,
    wind: &Wind,
    options: &PlanOptions,
) -> Result<MissionReport, PlannerError> {
    plan_with(
        aircraft,
        battery,
        mission,
        wind,
        options,
        true,
        options.second_thread,
    )
}

/// [`plan`] with every sample handed to `sink` as it is flown (memory does not grow with the
/// flight); the report's `samples` stay empty.
///
/// # Errors
/// As [`plan`], and what the sink returns.
pub fn plan_into(
    aircraft: &Aircraft,
    battery: &Pack,
    mission: &Mission,
    wind: &Wind,
    options: &PlanOptions,
    sink: &mut dyn SampleSink,
) -> Result<MissionReport, PlannerError> {
    let threads = (true, options.second_thread);
    fly(aircraft, battery, mission, wind, options, threads, sink)
}

/// [`plan`], with the hoisting of steady stretches switchable (off: every sample takes the full
/// path; the tests prove both give the same report) and the second thread allowed or not.
pub(crate) fn plan_with(
    aircraft: &Aircraft,
    battery: &Pack,
    mission: &Mission,
    wind: &Wind,
    options: &PlanOptions,
    hoist: bool,
    parallel: bool,
) -> Result<MissionReport, PlannerError> {
    let threads = (hoist, parallel);
    let mut samples = Vec::new();
    let sink: &mut dyn SampleSink = if options.record_samples {
        &mut samples
    } else {
        &mut NoSamples
    };
    let mut report = fly(aircraft, battery, mission, wind, options, threads, sink)?;
    report.samples = samples;
    Ok(report)
}

/// The steps of a flight: check the options, the vehicle per mass phase, pass A (the sampler),
/// pass B (the pack pass), fed in line or from a second thread, and the report.
fn fly(
    aircraft: &Aircraft,
    battery: &Pack,
    mission: &Mission,
    wind: &Wind,
    options: &PlanOptions,
    (hoist, parallel): (bool, bool),
    sink: &mut dyn SampleSink,
) -> Result<MissionReport, PlannerError> {
    let checked = options.check(battery, aircraft.airframe())?;
    let powered = powered_by_mass_phase(aircraft, battery, mission, options)?;
    let limits = Limits::of(aircraft, &powered);
    let dt = checked.time_step_s;
    let pass_a = PassA::new(
        aircraft,
        mission,
        (&powered, &limits),
        wind,
        options.ground_effect,
        hoist,
        dt,
    );
    let mut pass_b = PackPass::new(
        battery,
        mission,
        (&powered, &limits),
        wind,
        options,
        &checked,
    );
    // An error found in pass A (a thrust beyond the airframe, a wind grid left) is raised only
    // after pass B has flown the samples before it, so a battery that fails first is still
    // reported as the result.
    let threaded = feed::second_thread(parallel, pass_a.total_steps());
    feed::run(pass_a, threaded, |blocks| pass_b.fly(blocks, sink))?;
    Ok(pass_b.report())
}

/// The vehicle at the take-off mass of each mass phase of the mission (airframe, pack, payload).
fn powered_by_mass_phase<'a>(
    aircraft: &'a Aircraft,
    battery: &Pack,
    mission: &Mission,
    options: &PlanOptions,
) -> Result<Vec<Powered<'a>>, PlannerError> {
    let base_mass = aircraft.airframe().mass_kg() + battery.mass_kg();
    mission
        .payloads_kg()
        .iter()
        .map(|p| aircraft.at_mass(base_mass + p, options.aoa))
        .collect::<Result<_, _>>()
}

/// Pass B, the pack pass: the pack over each block pass A hands over, then each step in order,
/// booked in the ledger, stopped where the pack fails, checked for the way home.
struct PackPass<'p, 'a> {
    mission: &'p Mission,
    powered: &'p [Powered<'a>],
    battery: &'p Pack,
    dt: f64,
    /// Steps flown so far, and the most allowed.
    steps_flown: u64,
    max_steps: u64,
    /// Pack capacity, A s.
    charge_as: f64,
    max_current_a: f64,
    cutoff_v: f64,
    empty_soc: f64,
    cursor: PackCursor,
    steps: [PackStep; BLOCK],
    ledger: Ledger<'p>,
    way_home: ReturnCheck<'p>,
}

/// The piece pass B is flying: its vehicle, start time, step, charge per ampere and step, the
/// step its next block starts at, the time flown beyond its plan before that block, and its
/// tally.
struct PieceRun<'r, 'a> {
    piece: &'r Piece,
    pw: &'r Powered<'a>,
    t0: f64,
    h: f64,
    dq: f64,
    k0: usize,
    late_s: f64,
    tally: PieceTally,
}

impl<'p, 'a> PackPass<'p, 'a> {
    fn new(
        battery: &'p Pack,
        mission: &'p Mission,
        (powered, limits): (&'p [Powered<'a>], &Limits),
        wind: &'p Wind,
        options: &PlanOptions,
        checked: &CheckedOptions,
    ) -> Self {
        let empty = battery.empty_soc();
        let required = options.reserve_fraction * battery.usable_fraction();
        let dt = checked.time_step_s;
        let r_pack = battery.resistance_ohm();
        PackPass {
            mission,
            powered,
            battery,
            dt,
            steps_flown: 0,
            max_steps: options.max_samples,
            charge_as: battery.capacity_ah() * 3600.0,
            max_current_a: battery.max_current_a(),
            cutoff_v: battery.cutoff_v(),
            empty_soc: empty,
            cursor: battery.cursor(options.start_soc),
            steps: [PackStep::default(); BLOCK],
            ledger: Ledger::new(mission, options, r_pack, empty, required),
            way_home: ReturnCheck::new(
                limits,
                battery,
                wind,
                mission.home_m(),
                options,
                empty + required,
                checked.return_descent_rate_mps,
            ),
        }
    }

    /// Fly the mission's pieces in order on the blocks of `feed`, until the end or the pack fails.
    fn fly(
        &mut self,
        feed: &mut feed::Feed<'_, '_>,
        sink: &mut dyn SampleSink,
    ) -> Result<(), PlannerError> {
        let mut t0 = 0.0;
        for piece in self.mission.pieces() {
            match self.fly_piece(feed, piece, t0, sink)? {
                ControlFlow::Break(()) => break,
                ControlFlow::Continue(late_s) => t0 += piece.duration_s() + late_s,
            }
        }
        Ok(())
    }

    /// Fly `piece`, which starts at mission time `t0`, block by block: the time flown beyond its
    /// plan, or `Break` where the pack fails or the vehicle cannot fly on.
    fn fly_piece(
        &mut self,
        feed: &mut feed::Feed<'_, '_>,
        piece: &'p Piece,
        t0: f64,
        sink: &mut dyn SampleSink,
    ) -> Result<ControlFlow<(), f64>, PlannerError> {
        let (n, h) = piece_steps(piece, self.dt);
        let mut run = PieceRun {
            piece,
            pw: &self.powered[piece.mass_phase],
            t0,
            h,
            // Charge per ampere and step as a fraction of the capacity: a product on the pack's
            // step-to-step chain instead of a division.
            dq: h / self.charge_as,
            k0: 0,
            late_s: 0.0,
            tally: self.ledger.open(piece.segment),
        };
        while run.k0 < n {
            let block = feed.next();
            debug_assert_eq!(block.k0, run.k0);
            let pending = block.pending.take();
            if self.fly_block(block, &mut run, sink)?.is_break() {
                return Ok(ControlFlow::Break(()));
            }
            match pending {
                None => {}
                Some(Stop::Error(e)) => return Err(e),
                Some(Stop::NoProgress(why)) => {
                    // The vehicle cannot fly the step after the last one flown: the flight ends
                    // there, an answer.
                    let start_s = (run.k0 + block.valid) as f64 * run.h;
                    let at = (start_s, block.late_end_s);
                    let soc = self.cursor.soc();
                    self.ledger.stop_at(run.tally, piece, at, soc, why);
                    return Ok(ControlFlow::Break(()));
                }
            }
            run.k0 += block.m;
            run.late_s = block.late_end_s;
        }
        self.ledger
            .close(run.tally, piece, run.late_s, self.cursor.soc());
        Ok(ControlFlow::Continue(run.late_s))
    }

    /// The pack over `block` (its state of charge chains one step to the next; `draw_block`
    /// solves the block's chain at once, bit for bit the step-by-step result), then each step in
    /// order: booked, checked against the pack's limits, checked for the way home.
    fn fly_block(
        &mut self,
        block: &BlockA,
        run: &mut PieceRun<'_, '_>,
        sink: &mut dyn SampleSink,
    ) -> Result<ControlFlow<()>, PlannerError> {
        self.count_steps(block.valid, run.t0 + run.k0 as f64 * run.h)?;
        let record = sink.wants_samples();
        let seg = run.piece.segment;
        let soc_at_block = self.cursor.soc();
        let drawn = self.draw_block(block, run.dq);
        // The piece's tally in a local for the loop, stored back at the block's end.
        let mut tally = run.tally;
        for j in 0..block.valid {
            let tm = ((run.k0 + j) as f64 + 0.5) * run.h;
            let pos = block.kins[j].pos_m;
            // The flown time: the plan's, and the time flown beyond it so far in the piece.
            let t = run.t0 + tm + block.late_s[j];
            let h = block.steps_s[j];
            let p = block.trims[j].electrical_w;
            let Some(draw) = self.delivered(j, drawn) else {
                let soc = if j == 0 {
                    soc_at_block
                } else {
                    self.steps[j - 1].soc_after
                };
                let why = Shortfall::PackLimit {
                    time_s: t,
                    segment: seg + 1,
                    kind: self.ledger.kind(seg),
                    position_m: pos,
                    power_w: p,
                };
                let start_s = tm - 0.5 * run.h;
                let late = block.late_s[j] - 0.5 * (h - run.h);
                self.ledger
                    .stop_at(tally, run.piece, (start_s, late), soc, why);
                return Ok(ControlFlow::Break(()));
            };
            self.ledger.book(&mut tally, p, h, &draw);
            if block.slowed {
                self.note_edge(block, j, run, tm);
            }
            if record {
                sink.take(&Ledger::sample(run.pw, block, j, t, seg, &draw)?)?;
            }
            if let Some(why) = self.pack_failure(&draw, t, seg, pos) {
                let end_s = tm + 0.5 * run.h;
                let late = block.late_s[j] + 0.5 * (h - run.h);
                self.ledger
                    .stop_at(tally, run.piece, (end_s, late), draw.soc_after, why);
                return Ok(ControlFlow::Break(()));
            }
            if self.way_home.due(t, pos) {
                let here = PointOfNoReturn {
                    time_s: t,
                    segment: seg + 1,
                    position_m: pos,
                };
                let phase = run.piece.mass_phase;
                self.way_home.check(run.pw, phase, here, draw.soc_after);
            }
        }
        run.tally = tally;
        Ok(ControlFlow::Continue(()))
    }

    /// Step `j` of `block`, `tm` s into its piece by the plan, into the ledger's record of the
    /// segment's slowest step at the edge of the envelope, when the envelope slowed it.
    fn note_edge(&mut self, block: &BlockA, j: usize, run: &PieceRun<'_, '_>, tm: f64) {
        let Some(limit) = block.limits[j] else {
            return;
        };
        let kin = &block.kins[j];
        let v = kin.vel_mps;
        let speed_mps = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let profile = &run.piece.profile;
        self.ledger.note_edge(
            run.piece.segment,
            EdgeStep {
                limit,
                speed_mps,
                // The step took h / q instead of h: the planned speed was the flown one / q.
                planned_mps: speed_mps * block.steps_s[j] / run.h,
                cruise: tm >= profile.t_accel_end_s && tm < profile.t_cruise_end_s,
                wind_mps: block.winds[j],
                up_m: kin.pos_m[2],
            },
        );
    }

    /// Count `steps` more steps from mission time `t_s`; more than [`PlanOptions::max_samples`]
    /// in all is an error that says the time step to use instead.
    fn count_steps(&mut self, steps: usize, t_s: f64) -> Result<(), PlannerError> {
        self.steps_flown += steps as u64;
        if self.steps_flown <= self.max_steps {
            return Ok(());
        }
        let duration_s = self.mission.duration_s();
        Err(PlannerError::TooManySamples {
            limit: self.max_steps,
            time_step_s: self.dt,
            flown_s: t_s,
            suggested_time_step_s: duration_s / self.max_steps as f64,
        })
    }

    /// Draw the power of `block`'s steps from the pack, `dq` of the capacity per ampere and step,
    /// into `self.steps`; the steps drawn (all, or up to the first the pack cannot deliver).
    fn draw_block(&mut self, block: &BlockA, dq: f64) -> usize {
        let valid = block.valid;
        let mut powers = [0.0; BLOCK];
        for (p, t) in powers.iter_mut().zip(&block.trims[..valid]) {
            *p = t.electrical_w;
        }
        if block.slowed {
            // Steps of their own durations: step by step, each its own charge per ampere.
            let mut dqs = [0.0; BLOCK];
            for (d, h) in dqs.iter_mut().zip(&block.steps_s[..valid]) {
                *d = h / self.charge_as;
            }
            return self.cursor.draw_each(
                self.battery,
                &powers[..valid],
                &dqs[..valid],
                &mut self.steps[..valid],
            );
        }
        self.cursor
            .draw_block(self.battery, &powers[..valid], dq, &mut self.steps[..valid])
    }

    /// Step `j` of the block drawn, when the pack delivered it within its rated current.
    #[inline]
    fn delivered(&self, j: usize, drawn: usize) -> Option<PackStep> {
        match self.steps.get(j) {
            Some(d) if j < drawn && d.current_a <= self.max_current_a => Some(*d),
            _ => None,
        }
    }

    /// Why the pack fails after `draw` at mission time `t` at `pos` in segment `seg` (from 0): the
    /// terminal voltage below the cut-off, or the usable charge spent; `None` while it holds.
    #[inline]
    fn pack_failure(
        &self,
        draw: &PackStep,
        t: f64,
        seg: usize,
        pos: [f64; 3],
    ) -> Option<Shortfall> {
        let soc_now = draw.soc_after;
        if !(draw.terminal_v < self.cutoff_v || soc_now <= self.empty_soc) {
            return None;
        }
        let kind = self.ledger.kind(seg);
        Some(if draw.terminal_v < self.cutoff_v {
            Shortfall::CutOffVoltage {
                time_s: t,
                segment: seg + 1,
                kind,
                position_m: pos,
                voltage_v: draw.terminal_v,
                cutoff_v: self.cutoff_v,
            }
        } else {
            Shortfall::BatteryEmpty {
                time_s: t,
                segment: seg + 1,
                kind,
                position_m: pos,
            }
        })
    }

    /// The report of the run.
    fn report(self) -> MissionReport {
        let pnr = self.way_home.point_of_no_return();
        self.ledger.report(self.powered[0].mass_kg(), pnr)
    }
}

#[cfg(test)]
mod tests {
    use super::test_mission::{m100, m100_survey};
    use super::*;
    use crate::ground_effect::thrust_factor;
    use crate::test_support::compile_mission;
    use aloft_power::AoaModel;

    #[test]
    fn block_passes_match_the_sample_by_sample_trim() {
        // The block path against `Powered::trim` and `Pack::draw` called per sample, over the
        // recorded samples of a survey in wind.
        let (aircraft, battery, mission) = m100_survey();
        let wind = Wind::constant(6.0, 250.0).unwrap();
        let opts = PlanOptions {
            time_step_s: 0.05,
            record_samples: true,
            ..PlanOptions::default()
        };
        let r = plan(&aircraft, &battery, &mission, &wind, &opts).unwrap();
        let pw = aircraft
            .at_mass(r.takeoff_mass_kg, AoaModel::Geometric)
            .unwrap();
        let r_rotor = aircraft.rotor_radius_m();
        let mut soc_before = opts.start_soc;
        for s in &r.samples {
            let w = wind.at([s.east_m, s.north_m, s.up_m], s.time_s).unwrap();
            let fwd_rad = s.yaw_deg.to_radians();
            let trim = pw
                .trim(
                    [s.acc_east_mps2, s.acc_north_mps2, s.acc_up_mps2],
                    [
                        s.vel_east_mps - w[0],
                        s.vel_north_mps - w[1],
                        s.vel_up_mps - w[2],
                    ],
                    [fwd_rad.sin(), fwd_rad.cos()],
                    thrust_factor(r_rotor, s.up_m + aircraft.airframe().rotor_height_m()),
                )
                .unwrap();
            // Orbit positions come from a rotation (1e-13 m), headings through degrees: 1e-9
            // relative is far below any physical difference and far above rounding.
            assert!(
                (trim.electrical_w - s.power_w).abs() < 1e-9 * s.power_w,
                "t = {}: {} vs {}",
                s.time_s,
                trim.electrical_w,
                s.power_w
            );
            // The pack at the state of charge before the step: the same current to rounding.
            let d = battery.draw(s.power_w, soc_before).unwrap();
            assert!((d.current_a - s.current_a).abs() < 1e-12 * s.current_a);
            assert!(s.soc < soc_before);
            soc_before = s.soc;
        }
    }

    #[test]
    fn a_pack_that_cannot_deliver_books_the_energy_flown_before_it_stops() {
        // Regression: a flight stopped by the pack's current limit lost the energy of the piece it
        // was flying (neither its segment nor the mission total booked it).
        let (aircraft, _) = m100();
        let mut spec = crate::test_support::tb48d();
        // A slow climb and the hover draw about 12 A; the fast leg draws more, part-way along it.
        spec.max_current_a = Some(13.5);
        let battery = Pack::new(&spec).unwrap();
        let fast_leg = r#"
            [[segment]]
            kind = "take-off"
            altitude_m = 20.0
            climb_rate_mps = 0.5
            [[segment]]
            kind = "hover"
            duration_s = 10.0
            [[segment]]
            kind = "leg"
            east_m = 1500.0
            north_m = 0.0
            ground_speed_mps = 16.0
            [[segment]]
            kind = "landing"
            rate_mps = 1.0
        "#;
        let mission = compile_mission(fast_leg, &aircraft, &battery);
        let opts = PlanOptions {
            record_samples: true,
            ..PlanOptions::default()
        };
        let r = plan(&aircraft, &battery, &mission, &Wind::calm(), &opts).unwrap();
        let Some(Shortfall::PackLimit {
            time_s, segment, ..
        }) = r.shortfall
        else {
            panic!(
                "expected the pack's current limit to stop the flight: {:?}",
                r.shortfall
            );
        };
        let last = r.segments.last().unwrap();
        assert_eq!(last.index, segment);
        // The segment's energy and time are those of its samples flown (midpoint rule: each
        // sample stands for its step; the steps of one piece are equal).
        let flown: Vec<&Sample> = r.samples.iter().filter(|s| s.segment == segment).collect();
        assert!(!flown.is_empty());
        assert!(last.energy_wh > 0.0, "{last:?}");
        let mean_w = flown.iter().map(|s| s.power_w).sum::<f64>() / flown.len() as f64;
        // 2 %: the segment's mean weights each piece by its time, the samples' by their count.
        assert!(
            (last.mean_power_w / mean_w - 1.0).abs() < 0.02,
            "{} vs {mean_w}",
            last.mean_power_w
        );
        // The mission's energy is the sum of its segments' (no piece left out), and the flight
        // ended before the failing step.
        let sum: f64 = r.segments.iter().map(|s| s.energy_wh).sum();
        assert!(
            (r.energy_wh - sum).abs() < 1e-9 * sum,
            "{} vs {sum}",
            r.energy_wh
        );
        assert!(r.duration_s <= time_s && r.duration_s > time_s - opts.time_step_s);
    }

    #[test]
    fn a_leg_steeper_than_the_climb_limit_is_flown_at_the_limit() {
        // 30 m up over 20 m east, asked at 10 m/s over the ground (15 m/s up): the M100's climb
        // limit is 5 m/s, so the leg is flown with its vertical speed at 5 m/s and its ground
        // speed at 5 x 20 / 30 = 3.33 m/s where the plan asks for more.
        let (aircraft, battery) = m100();
        let text = &crate::test_support::steep_leg();
        let mission = compile_mission(text, &aircraft, &battery);
        let opts = PlanOptions {
            record_samples: true,
            ..PlanOptions::default()
        };
        let r = plan(&aircraft, &battery, &mission, &Wind::calm(), &opts).unwrap();
        assert!(r.feasible, "{:?}", r.shortfall);
        let leg: Vec<&Sample> = r.samples.iter().filter(|s| s.segment == 2).collect();
        let top = leg.iter().map(|s| s.vel_up_mps).fold(0.0, f64::max);
        // The bisection stops within 1e-9 of the fraction; the rate check allows 1e-9 relative.
        assert!((top - 5.0).abs() < 1e-6, "{top}");
        let fast = leg.iter().find(|s| s.vel_up_mps > 5.0 - 1e-6).unwrap();
        assert!(
            (fast.vel_east_mps - 5.0 * 20.0 / 30.0).abs() < 1e-6,
            "{fast:?}"
        );
        let seg = &r.segments[1];
        assert!(seg.time_lost_s > 0.1, "{seg:?}");
        assert_eq!(seg.edge.unwrap().limit, crate::envelope::Limit::Climb);
        // The segment's time is its samples' steps: the planned piece plus the time lost.
        let planned: f64 = mission
            .pieces()
            .iter()
            .filter(|p| p.segment == 1)
            .map(|p| p.duration_s())
            .sum();
        assert!((seg.duration_s - planned - seg.time_lost_s).abs() < 1e-9);
    }
}
