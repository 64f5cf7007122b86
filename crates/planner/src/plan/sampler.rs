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
//! 3. the airframe's limits ([`PassA::within_limits`]).
//!
//! An error (a wind grid left, a flight condition the power model rejects, a thrust or tilt
//! beyond the airframe) stops the block at that sample and travels with it ([`BlockA::pending`]),
//! so the pack pass flies the samples before it first.
//!
//! # Hoisting of steady stretches
//! On a level line or a hold at cruise in a steady wind that depends on height alone, every input
//! of the trim has the same bits at every sample ([`steady_piece`]), so the trim is computed once
//! per stretch and reused for the blocks that lie wholly inside it; ground effect is computed once
//! per piece at a fixed height. The plain reference is every sample through the block path
//! (`plan_with(.., hoist = false, ..)`); the test
//! `hoisting_steady_stretches_matches_the_per_sample_report` proves the reports equal bit for bit.

use crate::aircraft::{Aircraft, Powered};
use crate::error::PlannerError;
use crate::ground_effect::thrust_factor;
use crate::mission::Mission;
use crate::trajectory::{BlockSampler, Kinematics, Piece, Shape};
use crate::trim::Trim;
use crate::wind::Wind;

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
        Shape::Arc { up_m, .. } => Some(up_m),
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
    !matches!(piece.shape, Shape::Arc { .. }) && fixed_height_m(piece).is_some()
}

/// The error of a sample whose trim is beyond the airframe's thrust or tilt.
#[cold]
#[inline(never)]
fn beyond_limit(
    trim: &Trim,
    t: f64,
    seg: usize,
    kind: &'static str,
    pos: [f64; 3],
    max_thrust: f64,
    airframe: &crate::airframe::Airframe,
) -> PlannerError {
    let thrust = trim.thrust_n > max_thrust;
    PlannerError::BeyondVehicleLimit {
        time_s: t,
        index: seg + 1,
        kind,
        east_m: pos[0],
        north_m: pos[1],
        up_m: pos[2],
        name: if thrust { "thrust" } else { "tilt" },
        value: if thrust {
            trim.thrust_n
        } else {
            trim.axis[2].clamp(-1.0, 1.0).acos().to_degrees()
        },
        limit: if thrust {
            max_thrust
        } else {
            airframe.max_tilt_rad().to_degrees()
        },
        unit: if thrust { "N" } else { "deg" },
    }
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
    /// The error that stopped pass A in this block.
    pub(super) pending: Option<PlannerError>,
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
    max_thrust: f64,
    cos_tilt_max: f64,
    kinds: &'p [&'static str],
    airframe: &'p crate::airframe::Airframe,
    dt: f64,
    /// Piece being walked, its next step and its start time.
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
        powered: &'p [Powered<'a>],
        wind: &'p Wind,
        ground_effect: bool,
        hoist: bool,
        dt: f64,
    ) -> Self {
        let airframe = aircraft.airframe();
        let g = aircraft.gravity_mps2();
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
            max_thrust: airframe.max_thrust_n(g),
            cos_tilt_max: airframe.max_tilt_rad().cos(),
            kinds: mission.segment_kinds(),
            airframe,
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
                });
            }
            let pa = self.piece.as_ref().expect("set above");
            if self.k0 < pa.n {
                break;
            }
            self.t0 += piece.duration_s();
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

    /// Pass A over the block at `self.k0` of `piece`: the air, the trims, the limits.
    fn fill(&self, piece: &Piece, pa: &mut PieceA, out: &mut BlockA) {
        let m = (pa.n - self.k0).min(BLOCK);
        out.k0 = self.k0;
        out.m = m;
        out.pending = None;
        let valid = self.sample_air(pa, m, out);
        let valid = self.trim_samples(piece, pa, valid, out);
        out.valid = self.within_limits(piece, pa, valid, out);
    }

    /// Pass A1: kinematics, wind, air velocity and ground effect of the block's `m` samples; the
    /// samples done (`m`, or the first outside a wind grid, with its error in `out.pending`).
    fn sample_air(&self, pa: &mut PieceA, m: usize, out: &mut BlockA) -> usize {
        let (k0, h, t0) = (self.k0, pa.h, self.t0);
        let mut valid = m;
        pa.sampler.fill(k0, &mut out.kins[..m]);
        for j in 0..m {
            let kin = &out.kins[j];
            let w = match self.uniform_wind {
                Some(w) => w,
                None => {
                    let t = t0 + ((k0 + j) as f64 + 0.5) * h;
                    match self.wind.at(kin.pos_m, t) {
                        Some(w) => w,
                        None => {
                            out.pending = Some(outside(self.wind, t, kin.pos_m));
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
                if let Err((j, e)) = pw.trim_block(
                    &out.accs[..valid],
                    &out.v_airs[..valid],
                    &out.fwds[..valid],
                    &out.ges[..valid],
                    &mut out.trims[..valid],
                ) {
                    valid = j;
                    out.pending = Some(e);
                }
                if pa.steady && pa.steady_trim.is_none() {
                    pa.steady_trim = (0..valid)
                        .find(|&j| in_cruise(k0 + j))
                        .map(|j| out.trims[j]);
                }
            }
        }
        valid
    }

    /// Pass A3: the airframe's thrust and tilt over the first `valid` samples; the samples within
    /// them (the first beyond, with its error in `out.pending`).
    fn within_limits(&self, piece: &Piece, pa: &PieceA, valid: usize, out: &mut BlockA) -> usize {
        let (k0, h, t0) = (self.k0, pa.h, self.t0);
        let seg = piece.segment;
        for j in 0..valid {
            let trim = &out.trims[j];
            if trim.thrust_n > self.max_thrust || trim.axis[2] < self.cos_tilt_max {
                let t = t0 + ((k0 + j) as f64 + 0.5) * h;
                out.pending = Some(beyond_limit(
                    trim,
                    t,
                    seg,
                    self.kinds[seg],
                    out.kins[j].pos_m,
                    self.max_thrust,
                    self.airframe,
                ));
                return j;
            }
        }
        valid
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
    use super::super::test_mission::{m100, SURVEY};
    use super::super::{plan_with, PlanOptions};
    use super::*;
    use crate::mission::MissionSpec;
    use crate::wind::{Gusts, Profile};

    #[test]
    fn hoisting_steady_stretches_matches_the_per_sample_report() {
        let (aircraft, battery) = m100();
        let mission = MissionSpec::from_toml_str(SURVEY)
            .unwrap()
            .compile(aircraft.airframe(), battery.mass_kg(), None)
            .unwrap();
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
        let (aircraft, battery) = m100();
        let mission = MissionSpec::from_toml_str(SURVEY)
            .unwrap()
            .compile(aircraft.airframe(), battery.mass_kg(), None)
            .unwrap();
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
            let mut pass = PassA::new(&aircraft, &mission, &powered, wind, true, true, 0.05);
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
