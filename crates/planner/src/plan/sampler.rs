//! Pass A, the block sampler: kinematics, wind, air velocity, ground effect, trim, power and the
//! airframe's limits for each block of samples, in mission order.
//!
//! Nothing here depends on the pack, so pass A may run ahead of the pack pass on another thread
//! ([`super::feed`]); both walk the same blocks. Per block ([`PassA::fill`]):
//! 1. the air at each sample ([`PassA::sample_air`]): the trajectory's kinematics
//!    ([`BlockSampler`]), the wind at the position and time, `v_air = v_ground - wind`, the
//!    ground-effect factor at the rotor height;
//! 2. the trims ([`PassA::trim_samples`]): [`Powered::trim_block`], force balance for all, then
//!    the power model for all, both in vector lanes;
//! 3. the flight envelope ([`PassA::fly_at_the_edge`]): a sample beyond the airframe's tilt,
//!    thrust, airspeed, climb or descent limit is flown at the largest fraction `q` of its
//!    planned speed that is within them ([`crate::envelope`]), its step taking `h / q`; the
//!    time flown beyond the plan accumulates per piece ([`BlockA::late_s`]).
//!
//! What stops the flight (a wind grid left, a flight condition the power model rejects, a path
//! the vehicle cannot fly at any speed) stops the block at that sample and travels with it
//! ([`BlockA::pending`]), so the pack pass flies the samples before it first.
//!
//! # Hoisting of steady stretches
//! On a level line or a hold at cruise in a steady wind that depends on height alone, every input
//! of the trim has the same bits at every sample ([`steady_piece`]), so the trim is computed once
//! per stretch and reused for the blocks that lie wholly inside it; ground effect is computed once
//! per piece at a fixed height. The plain reference is every sample through the block path
//! (`plan_with(.., hoist = false, ..)`); the test
//! `hoisting_steady_stretches_matches_the_per_sample_report` proves the reports equal bit for bit.

use crate::aircraft::{Aircraft, Powered};
use crate::envelope::{Envelope, Limit};
use crate::error::PlannerError;
use crate::ground_effect::thrust_factor;
use crate::mission::Mission;
use crate::trajectory::{BlockSampler, Kinematics, Piece, Shape};
use crate::trim::Trim;
use crate::wind::Wind;

use super::report::{Shortfall, Stuck};
use super::BLOCK;

const ZERO_TRIM: Trim = Trim {
    thrust_n: 0.0,
    axis: [0.0; 3],
    airspeed_mps: 0.0,
    electrical_w: 0.0,
};

/// The height of a piece that stays at one height: a hold, an arc, or a level line (`dir_up = 0`,
/// so the height `start_up + 0 s` is the start height exactly at every sample).
fn fixed_height_m(piece: &Piece) -> Option<f64> {
    match piece.shape {
        Shape::Hold { pos_m } => Some(pos_m[2]),
        Shape::Arc(c) => Some(c.up_m),
        Shape::Line { start_m, dir } => (dir[2] == 0.0).then_some(start_m[2]),
    }
}

/// Whether every cruise sample of `piece` gives the trim the same inputs, bit for bit, in a wind
/// that depends on height alone and not on time: a hold (`s = 0` throughout), or a level line
/// (fixed height, so the same wind and ground effect; velocity `dir v_cruise`, acceleration
/// `dir 0`, heading fixed). An arc turns its velocity, so its trim changes along the circle in
/// any wind but calm; a line that climbs or descends changes height. Both take the per-sample
/// path.
fn steady_piece(piece: &Piece) -> bool {
    !matches!(piece.shape, Shape::Arc(_)) && fixed_height_m(piece).is_some()
}

/// A trim that marks a sample the power model rejected beyond the envelope: the edge step
/// slows it and trims it again.
const BEYOND: Trim = Trim {
    thrust_n: f64::INFINITY,
    axis: [0.0; 3],
    airspeed_mps: 0.0,
    electrical_w: 0.0,
};

/// What stops a flight in pass A: an error, or a path the vehicle cannot fly (an answer).
#[derive(Debug)]
pub(super) enum Stop {
    /// A wind grid left, a flight condition the power model rejects.
    Error(PlannerError),
    /// The vehicle cannot make headway or hold its position within its envelope.
    NoProgress(Shortfall),
}

/// Steps of a piece at time step `dt` and the step that divides it evenly, s.
pub(super) fn piece_steps(piece: &Piece, dt: f64) -> (usize, f64) {
    let dur = piece.duration_s();
    let n = ((dur / dt) - 1e-9).ceil().max(1.0) as usize;
    (n, dur / n as f64)
}
/// Pass A's results for one block: everything pass B reads.
pub(super) struct BlockA {
    /// First step of the block in its piece (a check that both passes walk the same blocks).
    pub(super) k0: usize,
    /// Steps in the block.
    pub(super) m: usize,
    /// Steps pass A completed: `m`, or the index of the step that raised `pending`.
    pub(super) valid: usize,
    /// What stopped pass A in this block.
    pub(super) pending: Option<Stop>,
    /// Whether the envelope slowed any step of the block.
    pub(super) slowed: bool,
    /// Duration of each step, s: the piece's `h`, or `h / q` where the envelope slowed it.
    pub(super) steps_s: [f64; BLOCK],
    /// Time flown beyond the plan in the piece up to each step's midpoint, s.
    pub(super) late_s: [f64; BLOCK],
    /// Time flown beyond the plan in the piece up to the block's end, s.
    pub(super) late_end_s: f64,
    /// The limit each slowed step was flown at (`None`: as planned).
    pub(super) limits: [Option<Limit>; BLOCK],
    pub(super) kins: [Kinematics; BLOCK],
    pub(super) winds: [[f64; 3]; BLOCK],
    pub(super) v_airs: [[f64; 3]; BLOCK],
    pub(super) accs: [[f64; 3]; BLOCK],
    pub(super) fwds: [[f64; 2]; BLOCK],
    pub(super) ges: [f64; BLOCK],
    pub(super) trims: [Trim; BLOCK],
}

impl BlockA {
    pub(super) const EMPTY: BlockA = BlockA {
        k0: 0,
        m: 0,
        valid: 0,
        pending: None,
        slowed: false,
        steps_s: [0.0; BLOCK],
        late_s: [0.0; BLOCK],
        late_end_s: 0.0,
        limits: [None; BLOCK],
        kins: [Kinematics::ZERO; BLOCK],
        winds: [[0.0; 3]; BLOCK],
        v_airs: [[0.0; 3]; BLOCK],
        accs: [[0.0; 3]; BLOCK],
        fwds: [[0.0; 2]; BLOCK],
        ges: [1.0; BLOCK],
        trims: [ZERO_TRIM; BLOCK],
    };
}

/// State of pass A within the piece it is on.
#[derive(Clone)]
struct PieceA {
    sampler: BlockSampler,
    n: usize,
    h: f64,
    /// Ground-effect factor when the piece stays at one height.
    piece_ge: Option<f64>,
    /// Whether the piece's cruise may reuse one trim (see `steady_piece`).
    steady: bool,
    steady_trim: Option<Trim>,
    /// Time flown beyond the plan in the piece so far, s.
    late_s: f64,
    /// The fraction of its planned speed the last slowed sample of the piece flew at: where the
    /// search of the next starts.
    last_fraction: Option<f64>,
}

/// Pass A: kinematics, wind, trim, power and the airframe's limits for every block of the mission
/// in order. Nothing here depends on the pack, so it may run ahead of pass B on another thread;
/// both walk the same blocks.
#[derive(Clone)]
pub(super) struct PassA<'p, 'a> {
    pieces: &'p [Piece],
    powered: &'p [Powered<'a>],
    wind: &'p Wind,
    uniform_wind: Option<[f64; 3]>,
    steady_wind: bool,
    hoist: bool,
    ground_effect: bool,
    r_rotor: f64,
    rotor_h: f64,
    envelope: Envelope,
    /// The largest steady level airspeed within the envelope per mass phase, m/s, and the
    /// limit that bounds it (for the message of a path that cannot be flown).
    max_airspeed: Vec<(f64, Limit)>,
    kinds: &'p [&'static str],
    dt: f64,
    /// Piece being walked, its next step and its start time (the flown time of the pieces
    /// before it).
    index: usize,
    k0: usize,
    t0: f64,
    piece: Option<PieceA>,
}

impl<'p, 'a> PassA<'p, 'a> {
    /// Pass A over `mission` at time step `dt`, with one powered vehicle per mass phase; `hoist`
    /// switches the hoisting of steady stretches (off: every sample takes the full path).
    pub(super) fn new(
        aircraft: &'p Aircraft,
        mission: &'p Mission,
        (powered, limits): (&'p [Powered<'a>], &super::Limits),
        wind: &'p Wind,
        ground_effect: bool,
        hoist: bool,
        dt: f64,
    ) -> Self {
        let airframe = aircraft.airframe();
        let uniform_wind = if wind.is_uniform() {
            wind.mean_at([0.0; 3])
        } else {
            None
        };
        PassA {
            pieces: mission.pieces(),
            powered,
            wind,
            uniform_wind,
            steady_wind: wind.is_steady_and_level_uniform(),
            hoist,
            ground_effect,
            r_rotor: aircraft.rotor_radius_m(),
            rotor_h: airframe.rotor_height_m(),
            envelope: limits.envelope,
            max_airspeed: limits.max_airspeed.clone(),
            kinds: mission.segment_kinds(),
            dt,
            index: 0,
            k0: 0,
            t0: 0.0,
            piece: None,
        }
    }

    /// Steps of the whole mission.
    pub(super) fn total_steps(&self) -> usize {
        self.pieces.iter().map(|p| piece_steps(p, self.dt).0).sum()
    }

    fn ground_factor(&self, up_m: f64) -> f64 {
        if self.ground_effect {
            thrust_factor(self.r_rotor, up_m + self.rotor_h)
        } else {
            1.0
        }
    }

    /// Fill `out` with the next block; `false` when the mission is done.
    pub(super) fn next_block(&mut self, out: &mut BlockA) -> bool {
        loop {
            let Some(piece) = self.pieces.get(self.index) else {
                return false;
            };
            if self.piece.is_none() {
                let (n, h) = piece_steps(piece, self.dt);
                // Ground effect depends on height alone: once per piece at a fixed height.
                let piece_ge = fixed_height_m(piece).map(|up| self.ground_factor(up));
                // Hoisting: on a constant-speed stretch of a level line or a hold, in a wind that
                // depends on height alone and not on time, every input of the trim has the same
                // value at every sample, bit for bit (see `steady_piece`), so the trim is computed
                // once per stretch and reused for the blocks that lie wholly inside it.
                self.piece = Some(PieceA {
                    sampler: BlockSampler::new(piece, h, BLOCK),
                    n,
                    h,
                    piece_ge,
                    steady: self.hoist && self.steady_wind && steady_piece(piece),
                    steady_trim: None,
                    late_s: 0.0,
                    last_fraction: None,
                });
            }
            let pa = self.piece.as_ref().expect("set above");
            if self.k0 < pa.n {
                break;
            }
            self.t0 += piece.duration_s() + pa.late_s;
            self.index += 1;
            self.k0 = 0;
            self.piece = None;
        }
        let piece = &self.pieces[self.index];
        let mut pa = self.piece.take().expect("set in the loop");
        self.fill(piece, &mut pa, out);
        self.k0 += out.m;
        self.piece = Some(pa);
        true
    }

    /// Pass A over the block at `self.k0` of `piece`: the air, the trims, the envelope.
    fn fill(&self, piece: &Piece, pa: &mut PieceA, out: &mut BlockA) {
        let m = (pa.n - self.k0).min(BLOCK);
        out.k0 = self.k0;
        out.m = m;
        out.pending = None;
        out.slowed = false;
        let valid = self.sample_air(pa, m, out);
        let valid = self.trim_samples(piece, pa, valid, out);
        out.valid = self.fly_at_the_edge(piece, pa, valid, out);
    }

    /// Pass A1: kinematics, wind, air velocity and ground effect of the block's `m` samples; the
    /// samples done (`m`, or the first outside a wind grid, with its error in `out.pending`).
    /// The wind of a block is taken at the times its steps would have with the time flown
    /// beyond the plan before the block (a step slowed within the block shifts the rest by less
    /// than that step's delay; only gusts change with time).
    fn sample_air(&self, pa: &mut PieceA, m: usize, out: &mut BlockA) -> usize {
        let (k0, h, t0, late) = (self.k0, pa.h, self.t0, pa.late_s);
        let mut valid = m;
        pa.sampler.fill(k0, &mut out.kins[..m]);
        for j in 0..m {
            let kin = &out.kins[j];
            let w = match self.uniform_wind {
                Some(w) => w,
                None => {
                    let t = t0 + ((k0 + j) as f64 + 0.5) * h + late;
                    match self.wind.at(kin.pos_m, t) {
                        Some(w) => w,
                        None => {
                            out.pending = Some(Stop::Error(outside(self.wind, t, kin.pos_m)));
                            valid = j;
                            break;
                        }
                    }
                }
            };
            out.winds[j] = w;
            out.v_airs[j] = [
                kin.vel_mps[0] - w[0],
                kin.vel_mps[1] - w[1],
                kin.vel_mps[2] - w[2],
            ];
            out.accs[j] = kin.acc_mps2;
            out.fwds[j] = kin.forward;
            out.ges[j] = match pa.piece_ge {
                Some(g) => g,
                None => self.ground_factor(kin.pos_m[2]),
            };
        }
        valid
    }

    /// Pass A2: trim and power of the first `valid` samples, or the steady stretch's trim when
    /// the block lies wholly inside it; the samples done.
    fn trim_samples(
        &self,
        piece: &Piece,
        pa: &mut PieceA,
        valid: usize,
        out: &mut BlockA,
    ) -> usize {
        let (k0, h) = (self.k0, pa.h);
        let mut valid = valid;
        let pw = &self.powered[piece.mass_phase];
        let (cruise_from, cruise_to) = (piece.profile.t_accel_end_s, piece.profile.t_cruise_end_s);
        let in_cruise = |k: usize| {
            let tm = (k as f64 + 0.5) * h;
            tm >= cruise_from && tm < cruise_to
        };
        match pa.steady_trim {
            Some(st) if pa.steady && valid > 0 && in_cruise(k0) && in_cruise(k0 + valid - 1) => {
                out.trims[..valid].fill(st);
            }
            _ => {
                valid = self.trim_block_or_mark(pw, valid, out);
                if pa.steady && pa.steady_trim.is_none() {
                    pa.steady_trim = (0..valid)
                        .find(|&j| in_cruise(k0 + j))
                        .map(|j| out.trims[j]);
                    // A stretch beyond the envelope is slowed sample by sample, not hoisted.
                    if let Some(st) = pa.steady_trim {
                        let v_up = out.kins[0].vel_mps[2];
                        if self.envelope.exceeded_by_trim(&st, v_up).is_some() {
                            pa.steady = false;
                            pa.steady_trim = None;
                        }
                    }
                }
            }
        }
        valid
    }

    /// [`Powered::trim_block`] of the first `valid` samples; a sample the power model rejects is
    /// marked [`BEYOND`] for the edge step when it is beyond the envelope (slowed, it may be a
    /// condition the model takes), else it stops the block with its error. The samples done.
    fn trim_block_or_mark(&self, pw: &Powered<'_>, valid: usize, out: &mut BlockA) -> usize {
        let mut from = 0;
        while from < valid {
            let Err((j, e)) = pw.trim_block(
                &out.accs[from..valid],
                &out.v_airs[from..valid],
                &out.fwds[from..valid],
                &out.ges[from..valid],
                &mut out.trims[from..valid],
            ) else {
                return valid;
            };
            let k = from + j;
            let kin = &out.kins[k];
            let beyond =
                self.envelope
                    .exceeded(pw, kin.acc_mps2, kin.vel_mps, out.winds[k], out.fwds[k]);
            if beyond.is_none() {
                out.pending = Some(Stop::Error(e));
                return k;
            }
            out.trims[k] = BEYOND;
            from = k + 1;
        }
        valid
    }

    /// Pass A3: the flight envelope over the first `valid` samples: each beyond it is flown at
    /// the largest fraction of its planned velocity within it (its step `h / q`), and the time
    /// flown beyond the plan accumulates; the samples done (up to the first the vehicle cannot
    /// fly at any speed, with its shortfall in `out.pending`).
    fn fly_at_the_edge(
        &self,
        piece: &Piece,
        pa: &mut PieceA,
        valid: usize,
        out: &mut BlockA,
    ) -> usize {
        let h = pa.h;
        let mut late = pa.late_s;
        let mut done = valid;
        for j in 0..valid {
            out.limits[j] = None;
            let v_up = out.kins[j].vel_mps[2];
            if self
                .envelope
                .exceeded_by_trim(&out.trims[j], v_up)
                .is_none()
            {
                out.steps_s[j] = h;
                out.late_s[j] = late;
                continue;
            }
            match self.slow_down(piece, j, out, pa.last_fraction) {
                Ok((q, limit)) => {
                    pa.last_fraction = Some(q);
                    let step = h / q;
                    out.late_s[j] = late + 0.5 * (step - h);
                    late += step - h;
                    out.steps_s[j] = step;
                    out.limits[j] = Some(limit);
                    out.slowed = true;
                }
                Err(stop) => {
                    let stop = match stop {
                        Stop::NoProgress(mut s) => {
                            if let Shortfall::NoProgress(stuck) = &mut s {
                                stuck.time_s = self.t0 + ((self.k0 + j) as f64 + 0.5) * h + late;
                            }
                            Stop::NoProgress(s)
                        }
                        e => e,
                    };
                    out.pending = Some(stop);
                    done = j;
                    break;
                }
            }
        }
        pa.late_s = late;
        out.late_end_s = late;
        done
    }

    /// Sample `j` of `out` flown at the edge: its velocity scaled by the largest fraction `q`
    /// within the envelope and its acceleration by `q^2`, trimmed again; `(q, the limit it
    /// flies at)`, or why it cannot be flown (the shortfall's time is set by the caller).
    fn slow_down(
        &self,
        piece: &Piece,
        j: usize,
        out: &mut BlockA,
        hint: Option<f64>,
    ) -> Result<(f64, Limit), Stop> {
        let pw = &self.powered[piece.mass_phase];
        let kin = out.kins[j];
        let wind = out.winds[j];
        // The margin at the planned speed is the trim's (a sample the power model rejected is
        // marked with an infinite thrust: beyond).
        let top = self.envelope.slack_of_trim(&out.trims[j], kin.vel_mps[2]);
        let edge = self.envelope.fastest_fraction_beyond(
            pw,
            (kin.acc_mps2, kin.vel_mps),
            (wind, out.fwds[j]),
            hint,
            top,
        );
        let (q, limit) = match edge {
            Ok(Some(edge)) => edge,
            // Within at the planned speed after all (a marked sample the model rejected).
            Ok(None) => (1.0, Limit::Tilt),
            Err(limit) => return Err(self.no_progress(piece, &kin, wind, limit)),
        };
        let k = &mut out.kins[j];
        k.vel_mps = kin.vel_mps.map(|v| v * q);
        k.acc_mps2 = kin.acc_mps2.map(|a| a * q * q);
        out.v_airs[j] = [
            k.vel_mps[0] - wind[0],
            k.vel_mps[1] - wind[1],
            k.vel_mps[2] - wind[2],
        ];
        out.accs[j] = k.acc_mps2;
        out.trims[j] = pw
            .trim(out.accs[j], out.v_airs[j], out.fwds[j], out.ges[j])
            .map_err(Stop::Error)?;
        Ok((q, limit))
    }

    /// The shortfall of a sample that cannot be flown at any speed within the envelope (its time
    /// set by the caller).
    fn no_progress(&self, piece: &Piece, kin: &Kinematics, wind: [f64; 3], limit: Limit) -> Stop {
        let (limit_value, limit_unit) = self.envelope.value_of(limit);
        let seg = piece.segment;
        Stop::NoProgress(Shortfall::NoProgress(Stuck {
            time_s: 0.0,
            segment: seg + 1,
            kind: self.kinds[seg],
            position_m: kin.pos_m,
            wind_mps: wind,
            moving: kin.vel_mps[0].hypot(kin.vel_mps[1]) > 0.0,
            limit,
            limit_value,
            limit_unit,
            max_airspeed_mps: self.max_airspeed[piece.mass_phase].0,
        }))
    }
}

/// The error of a sample outside the wind grid.
fn outside(wind: &Wind, t: f64, p: [f64; 3]) -> PlannerError {
    let (min_m, max_m) = match wind.mean() {
        crate::wind::MeanWind::Grid(g) => g.bounds_m(),
        _ => ([f64::NAN; 3], [f64::NAN; 3]),
    };
    PlannerError::OutsideWindGrid {
        time_s: t,
        east_m: p[0],
        north_m: p[1],
        up_m: p[2],
        min_m,
        max_m,
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_mission::m100_survey;
    use super::super::{plan_with, PlanOptions};
    use super::*;
    use crate::wind::{Gusts, Profile};

    #[test]
    fn hoisting_steady_stretches_matches_the_per_sample_report() {
        let (aircraft, battery, mission) = m100_survey();
        let power_law = Profile::PowerLaw {
            reference_height_m: 10.0,
            exponent: 1.0 / 7.0,
        };
        for wind in [
            Wind::calm(),
            Wind::constant(6.0, 250.0).unwrap(),
            Wind::profiled(5.0, 30.0, power_law).unwrap(),
            Wind::constant(4.0, 90.0)
                .unwrap()
                .with_gusts(Gusts::new(1.0, 3).unwrap()),
        ] {
            for ground_effect in [true, false] {
                let opts = PlanOptions {
                    time_step_s: 0.05,
                    record_samples: true,
                    ground_effect,
                    ..PlanOptions::default()
                };
                let fast =
                    plan_with(&aircraft, &battery, &mission, &wind, &opts, true, true).unwrap();
                let full =
                    plan_with(&aircraft, &battery, &mission, &wind, &opts, false, true).unwrap();
                assert!(fast.samples.len() > 1000);
                // The hoisted trim is the per-sample trim of identical inputs, computed by the
                // same block path: the reports are the same, bit for bit.
                assert_eq!(fast, full, "{wind:?} {ground_effect}");
            }
        }
    }

    #[test]
    fn block_trims_are_the_per_sample_trims_bit_for_bit() {
        // The fast path of pass A (`Powered::trim_block`: force balance in vector lanes, the power
        // model's batch path, and the hoisted trim of steady stretches) against its plain
        // reference, `Powered::trim` of each sample's own inputs: the same bits.
        let (aircraft, battery, mission) = m100_survey();
        let powered = [aircraft
            .at_mass(
                aircraft.airframe().mass_kg() + battery.mass_kg(),
                aloft_power::AoaModel::Geometric,
            )
            .unwrap()];
        assert_eq!(mission.payloads_kg().len(), 1);
        let winds = [
            Wind::calm(),
            Wind::constant(6.0, 250.0).unwrap(),
            Wind::constant(4.0, 90.0)
                .unwrap()
                .with_gusts(Gusts::new(1.0, 3).unwrap()),
        ];
        for wind in &winds {
            let limits = super::super::Limits::of(&aircraft, &powered);
            let mut pass = PassA::new(
                &aircraft,
                &mission,
                (&powered, &limits),
                wind,
                true,
                true,
                0.05,
            );
            let mut block = Box::new(BlockA::EMPTY);
            let mut samples = 0;
            while pass.next_block(&mut block) {
                assert!(block.pending.is_none());
                assert_eq!(block.valid, block.m);
                for j in 0..block.valid {
                    let want = powered[0]
                        .trim(block.accs[j], block.v_airs[j], block.fwds[j], block.ges[j])
                        .unwrap();
                    let got = block.trims[j];
                    let bits = |t: &Trim| {
                        (
                            t.thrust_n.to_bits(),
                            t.axis.map(f64::to_bits),
                            t.airspeed_mps.to_bits(),
                            t.electrical_w.to_bits(),
                        )
                    };
                    assert_eq!(bits(&got), bits(&want), "{wind:?}, sample {samples}");
                    samples += 1;
                }
            }
            assert_eq!(samples, pass.total_steps());
        }
    }
}
