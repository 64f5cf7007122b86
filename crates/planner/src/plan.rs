//! Flying a mission: sample the trajectory, trim each sample in the wind, draw the power from the
//! pack, and summarise.
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
//! ([`crate::battery::PackCursor::draw_block`], exactly the step-by-step chain of states of
//! charge), then the bookkeeping of each step in order. Pass A does not depend on the pack, so on
//! a mission of 4096 steps or more it runs on a second thread, blocks ahead of pass B
//! ([`PlanOptions::second_thread`]); the report is the same bit for bit (tested).
//!
//! The results are those of the sample-by-sample loop: the trims and the pack bit for bit, orbit
//! positions to 1e-13 m (a rotation table replaces `sincos` of a large angle on an arc's cruise,
//! [`crate::trajectory::BlockSampler`]), the pack's charge step to one rounding (`I (h / Q)`
//! instead of `I h / Q`). On a level line or a hold at cruise in a steady wind that depends on
//! height alone the trim is computed once per stretch (its inputs are the same bits at every
//! step); ground effect once per piece at a fixed height. A unit test checks that this hoisting
//! leaves the report unchanged, bit for bit, every sample included.
//!
//! # Feasibility
//! The mission is infeasible (a valid result, not an error) when the pack cannot deliver the power,
//! the current exceeds the pack's rating, the terminal voltage falls below the cut-off, the usable
//! charge runs out, or the vehicle lands with less than the reserve. The simulation stops where
//! the battery fails and reports the time, segment and position. Asking for more thrust or tilt
//! than the airframe has is an error ([`PlannerError::BeyondVehicleLimit`]): the mission cannot be
//! flown at all as written.
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

use aloft_power::AoaModel;
use serde::Serialize;

use crate::aircraft::{Aircraft, Powered};
use crate::battery::{Battery, PackStep};
use crate::error::PlannerError;
use crate::ground_effect::thrust_factor;
use crate::mission::Mission;
use crate::queries::best_range;
use crate::trajectory::{BlockSampler, Kinematics, Piece, Shape};
use crate::trim::{attitude_rad, Trim};
use crate::wind::Wind;

/// Options of a planning run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanOptions {
    /// Largest sampling step, s (default 0.1).
    pub time_step_s: f64,
    /// Angle-of-attack model (default geometric).
    pub aoa: AoaModel,
    /// Apply ground effect near the ground (default true).
    pub ground_effect: bool,
    /// Reserve required at landing, fraction of the usable capacity (default 0.2).
    pub reserve_fraction: f64,
    /// State of charge at take-off (default 1).
    pub start_soc: f64,
    /// Keep every sample for a time series (default false: the hot loop stores nothing).
    pub record_samples: bool,
    /// Compute the point of no return (default true).
    pub point_of_no_return: bool,
    /// Interval of the point-of-no-return checks, s (default 1).
    pub pnr_interval_s: f64,
    /// Descent rate of the priced return, m/s (default: 2 m/s or the airframe's limit if lower).
    pub return_descent_rate_mps: Option<f64>,
    /// On a mission of 4096 steps or more, and a CPU with two cores or more, compute kinematics,
    /// trim and power on a second thread ahead of the pack (default true). The report is the same
    /// bit for bit either way.
    pub second_thread: bool,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            time_step_s: 0.1,
            aoa: AoaModel::Geometric,
            ground_effect: true,
            reserve_fraction: 0.2,
            start_soc: 1.0,
            record_samples: false,
            point_of_no_return: true,
            pnr_interval_s: 1.0,
            return_descent_rate_mps: None,
            second_thread: true,
        }
    }
}

/// One sample of the time series (at the midpoint of an integration step).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sample {
    /// Mission time, s.
    pub time_s: f64,
    /// Segment number, from 1.
    pub segment: usize,
    /// East, m.
    pub east_m: f64,
    /// North, m.
    pub north_m: f64,
    /// Height above home, m.
    pub up_m: f64,
    /// Ground velocity east, m/s.
    pub vel_east_mps: f64,
    /// Ground velocity north, m/s.
    pub vel_north_mps: f64,
    /// Ground velocity up, m/s.
    pub vel_up_mps: f64,
    /// Acceleration east, m/s^2.
    pub acc_east_mps2: f64,
    /// Acceleration north, m/s^2.
    pub acc_north_mps2: f64,
    /// Acceleration up, m/s^2.
    pub acc_up_mps2: f64,
    /// Wind east, m/s.
    pub wind_east_mps: f64,
    /// Wind north, m/s.
    pub wind_north_mps: f64,
    /// Horizontal airspeed, m/s.
    pub airspeed_mps: f64,
    /// Thrust, N.
    pub thrust_n: f64,
    /// Roll, deg.
    pub roll_deg: f64,
    /// Pitch, deg.
    pub pitch_deg: f64,
    /// Heading, deg clockwise from north.
    pub yaw_deg: f64,
    /// Electrical power, W.
    pub power_w: f64,
    /// Pack current, A.
    pub current_a: f64,
    /// Pack terminal voltage, V.
    pub voltage_v: f64,
    /// State of charge after the step.
    pub soc: f64,
    /// Induced power, eq (8), W (four-term model only).
    pub induced_w: Option<f64>,
    /// Parasitic power, eq (11), W (four-term model only).
    pub parasitic_w: Option<f64>,
    /// Profile power, eq (12), W (four-term model only).
    pub profile_w: Option<f64>,
    /// Work of accelerating the vehicle with the geometric angle of attack, W (four-term model
    /// only).
    pub acceleration_w: Option<f64>,
    /// Climb power, eq (13), W (four-term model only).
    pub climb_w: Option<f64>,
}

/// Statistics of one mission segment.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SegmentReport {
    /// Segment number, from 1.
    pub index: usize,
    /// Kind (`take-off`, `leg`, `orbit`, `hover`, `return`, `descent`, `landing`).
    pub kind: &'static str,
    /// Duration flown, s.
    pub duration_s: f64,
    /// Path length flown, m.
    pub distance_m: f64,
    /// Electrical energy, W h.
    pub energy_wh: f64,
    /// Mean electrical power, W.
    pub mean_power_w: f64,
    /// Peak electrical power, W.
    pub peak_power_w: f64,
    /// State of charge at the end of the segment.
    pub end_soc: f64,
}

/// Why a valid mission cannot be flown with this pack.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "cause", rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Shortfall {
    /// The usable charge ran out in flight.
    BatteryEmpty {
        /// Mission time, s.
        time_s: f64,
        /// Segment number, from 1.
        segment: usize,
        /// Segment kind.
        kind: &'static str,
        /// Position, ENU m.
        position_m: [f64; 3],
    },
    /// The terminal voltage fell below the cut-off.
    CutOffVoltage {
        /// Mission time, s.
        time_s: f64,
        /// Segment number, from 1.
        segment: usize,
        /// Segment kind.
        kind: &'static str,
        /// Position, ENU m.
        position_m: [f64; 3],
        /// Terminal voltage, V.
        voltage_v: f64,
        /// Cut-off, V.
        cutoff_v: f64,
    },
    /// The pack cannot deliver the power (`V_oc^2 < 4 R P`) or its rated current.
    PackLimit {
        /// Mission time, s.
        time_s: f64,
        /// Segment number, from 1.
        segment: usize,
        /// Segment kind.
        kind: &'static str,
        /// Position, ENU m.
        position_m: [f64; 3],
        /// Power asked, W.
        power_w: f64,
    },
    /// The mission lands with less than the reserve.
    Reserve {
        /// Usable charge left at landing, fraction of capacity.
        reserve_soc: f64,
        /// Reserve required, fraction of capacity.
        required_soc: f64,
    },
}

impl std::fmt::Display for Shortfall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let at = |f: &mut std::fmt::Formatter<'_>, t: f64, seg: usize, kind: &str, p: [f64; 3]| {
            write!(
                f,
                "at t = {t:.1} s ({}:{:04.1}) in segment {seg} ({kind}), {:.0} m east, {:.0} m north, {:.0} m up",
                (t / 60.0).floor(),
                t % 60.0,
                p[0],
                p[1],
                p[2]
            )
        };
        match self {
            Shortfall::BatteryEmpty {
                time_s,
                segment,
                kind,
                position_m,
            } => {
                write!(f, "the battery runs out ")?;
                at(f, *time_s, *segment, kind, *position_m)
            }
            Shortfall::CutOffVoltage {
                time_s,
                segment,
                kind,
                position_m,
                voltage_v,
                cutoff_v,
            } => {
                write!(
                    f,
                    "the pack voltage falls to {voltage_v:.2} V, below the {cutoff_v:.2} V cut-off, "
                )?;
                at(f, *time_s, *segment, kind, *position_m)
            }
            Shortfall::PackLimit {
                time_s,
                segment,
                kind,
                position_m,
                power_w,
            } => {
                write!(
                    f,
                    "the pack cannot deliver {power_w:.0} W (its power or current limit) "
                )?;
                at(f, *time_s, *segment, kind, *position_m)
            }
            Shortfall::Reserve {
                reserve_soc,
                required_soc,
            } => write!(
                f,
                "it lands with {:.1} % of the capacity usable, below the required reserve of {:.1} %",
                reserve_soc * 100.0,
                required_soc * 100.0
            ),
        }
    }
}

/// The point of no return.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PointOfNoReturn {
    /// Mission time, s.
    pub time_s: f64,
    /// Segment number, from 1.
    pub segment: usize,
    /// Position, ENU m.
    pub position_m: [f64; 3],
}

/// The result of a planning run.
#[derive(Debug, Clone, PartialEq)]
pub struct MissionReport {
    /// Whether the mission can be flown with the reserve.
    pub feasible: bool,
    /// Why not.
    pub shortfall: Option<Shortfall>,
    /// Take-off mass, kg.
    pub takeoff_mass_kg: f64,
    /// Duration flown, s.
    pub duration_s: f64,
    /// Path length flown, m.
    pub distance_m: f64,
    /// Electrical energy delivered to the load, W h.
    pub energy_wh: f64,
    /// Heat in the pack's internal resistance, W h.
    pub pack_heat_wh: f64,
    /// State of charge at take-off.
    pub start_soc: f64,
    /// State of charge at the end.
    pub end_soc: f64,
    /// Lowest terminal voltage, V.
    pub min_voltage_v: f64,
    /// Peak electrical power, W.
    pub peak_power_w: f64,
    /// Peak pack current, A.
    pub peak_current_a: f64,
    /// State of charge at which the usable charge is exhausted (`1 - usable_fraction`).
    pub empty_soc: f64,
    /// Usable charge left at the end, fraction of capacity (`end_soc - empty_soc`).
    pub reserve_soc: f64,
    /// Reserve required, fraction of capacity.
    pub required_reserve_soc: f64,
    /// Point of no return, when some part of the mission is past it.
    pub point_of_no_return: Option<PointOfNoReturn>,
    /// Per segment, in order (segments not reached are absent).
    pub segments: Vec<SegmentReport>,
    /// Samples, when recorded.
    pub samples: Vec<Sample>,
}

#[derive(Default, Clone, Copy)]
struct Acc {
    duration_s: f64,
    distance_m: f64,
    energy_j: f64,
    peak_w: f64,
    end_soc: f64,
    reached: bool,
}

/// Cached return cost per bearing bin for one mass phase and wind.
struct ReturnCache {
    phase: usize,
    wind: [f64; 2],
    bins: Vec<Option<(f64, f64)>>,
}

const BEARING_BINS: usize = 720;

/// Fly `mission` with `aircraft` and `battery` in `wind`.
///
/// # Errors
/// Invalid options, a thrust or tilt beyond the airframe's limit, a wind grid that does not cover
/// the route, a flight condition the power model rejects.
pub fn plan(
    aircraft: &Aircraft,
    battery: &Battery,
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

/// Steps per block of the two-pass loop: small enough for the block to stay in the L1 cache,
/// large enough that the loop overhead of a pass is negligible.
const BLOCK: usize = 64;

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
fn piece_steps(piece: &Piece, dt: f64) -> (usize, f64) {
    let dur = piece.duration_s();
    let n = ((dur / dt) - 1e-9).ceil().max(1.0) as usize;
    (n, dur / n as f64)
}

/// Missions with at least this many steps run pass A on a second thread (below it, starting the
/// thread costs more than it saves).
const THREADED_FROM_STEPS: usize = 4096;

/// Blocks handed from pass A's thread to pass B at a time.
const BLOCKS_PER_CHUNK: usize = 32;

/// Pass A's results for one block: everything pass B reads.
struct BlockA {
    /// First step of the block in its piece (a check that both passes walk the same blocks).
    k0: usize,
    /// Steps in the block.
    m: usize,
    /// Steps pass A completed: `m`, or the index of the step that raised `pending`.
    valid: usize,
    /// The error that stopped pass A in this block.
    pending: Option<PlannerError>,
    kins: [Kinematics; BLOCK],
    winds: [[f64; 3]; BLOCK],
    v_airs: [[f64; 3]; BLOCK],
    accs: [[f64; 3]; BLOCK],
    fwds: [[f64; 2]; BLOCK],
    ges: [f64; BLOCK],
    trims: [Trim; BLOCK],
}

impl BlockA {
    const EMPTY: BlockA = BlockA {
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

/// Pass A of [`plan_with`]: kinematics, wind, trim, power and the airframe's limits for every
/// block of the mission in order. Nothing here depends on the pack, so it may run ahead of pass B
/// on another thread; both walk the same blocks.
#[derive(Clone)]
struct PassA<'p, 'a> {
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

impl PassA<'_, '_> {
    fn ground_factor(&self, up_m: f64) -> f64 {
        if self.ground_effect {
            thrust_factor(self.r_rotor, up_m + self.rotor_h)
        } else {
            1.0
        }
    }

    /// Fill `out` with the next block; `false` when the mission is done.
    fn next_block(&mut self, out: &mut BlockA) -> bool {
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

    /// Pass A over the block at `self.k0` of `piece`.
    fn fill(&self, piece: &Piece, pa: &mut PieceA, out: &mut BlockA) {
        let (k0, h, t0) = (self.k0, pa.h, self.t0);
        let m = (pa.n - k0).min(BLOCK);
        let seg = piece.segment;
        let pw = &self.powered[piece.mass_phase];
        let (cruise_from, cruise_to) = (piece.profile.t_accel_end_s, piece.profile.t_cruise_end_s);
        let in_cruise = |k: usize| {
            let tm = (k as f64 + 0.5) * h;
            tm >= cruise_from && tm < cruise_to
        };
        out.k0 = k0;
        out.m = m;
        out.pending = None;
        // Pass A1: kinematics, wind, air velocity, ground effect.
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
        // Pass A2: trim and power.
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
        // Pass A3: the airframe's limits.
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
                valid = j;
                break;
            }
        }
        out.valid = valid;
    }
}

/// Where pass B takes its blocks from: pass A run in line, or pass A's thread. (One per plan, so
/// the size of the in-line variant does not matter.)
#[allow(clippy::large_enum_variant)]
enum Feed<'p, 'a> {
    Inline {
        pass: PassA<'p, 'a>,
        block: Box<BlockA>,
    },
    Threaded {
        full: std::sync::mpsc::Receiver<(Vec<BlockA>, usize)>,
        empty: std::sync::mpsc::Sender<Vec<BlockA>>,
        chunk: Vec<BlockA>,
        len: usize,
        next: usize,
    },
}

impl<'p, 'a: 'p> Feed<'p, 'a> {
    /// Start pass A on a thread of `scope`, handing chunks of blocks over a channel (and getting
    /// the used chunks back, so no block is copied or reallocated).
    /// `None` when the thread cannot be started (pass A then runs in line).
    fn threaded<'s>(scope: &'s std::thread::Scope<'s, '_>, mut pass: PassA<'p, 'a>) -> Option<Self>
    where
        'p: 's,
    {
        let (full_tx, full) = std::sync::mpsc::sync_channel::<(Vec<BlockA>, usize)>(2);
        let (empty, empty_rx) = std::sync::mpsc::channel::<Vec<BlockA>>();
        let worker = std::thread::Builder::new().name("aloft-pass-a".into());
        let started = worker.spawn_scoped(scope, move || loop {
            let mut chunk = empty_rx.try_recv().unwrap_or_else(|_| {
                std::iter::repeat_with(|| BlockA::EMPTY)
                    .take(BLOCKS_PER_CHUNK)
                    .collect()
            });
            let mut len = 0;
            while len < BLOCKS_PER_CHUNK && pass.next_block(&mut chunk[len]) {
                len += 1;
            }
            // Pass B hung up (it stopped early) or the mission is done.
            if full_tx.send((chunk, len)).is_err() || len < BLOCKS_PER_CHUNK {
                return;
            }
        });
        started.ok().map(|_| Feed::Threaded {
            full,
            empty,
            chunk: Vec::new(),
            len: 0,
            next: 0,
        })
    }

    /// The next block; pass B asks only for blocks the mission has.
    fn next(&mut self) -> &mut BlockA {
        match self {
            Feed::Inline { pass, block } => {
                let more = pass.next_block(block);
                debug_assert!(more, "pass B asked past the mission's end");
                block
            }
            Feed::Threaded {
                full,
                empty,
                chunk,
                len,
                next,
            } => {
                if *next == *len {
                    let used = std::mem::take(chunk);
                    if !used.is_empty() {
                        // Pass A may have finished: then nobody takes it back.
                        let _ = empty.send(used);
                    }
                    (*chunk, *len) = full.recv().expect("pass A's thread ended early");
                    *next = 0;
                }
                *next += 1;
                &mut chunk[*next - 1]
            }
        }
    }
}

/// [`plan`], with the hoisting of steady stretches switchable (off: every sample takes the full
/// path; the tests prove both give the same report).
pub(crate) fn plan_with(
    aircraft: &Aircraft,
    battery: &Battery,
    mission: &Mission,
    wind: &Wind,
    options: &PlanOptions,
    hoist: bool,
    parallel: bool,
) -> Result<MissionReport, PlannerError> {
    let dt = crate::error::positive("time_step_s", options.time_step_s, "s")?;
    if !(options.reserve_fraction >= 0.0 && options.reserve_fraction < 1.0) {
        return Err(PlannerError::InvalidParameter {
            name: "reserve_fraction",
            value: options.reserve_fraction,
            unit: "",
            expected: "a fraction in [0, 1)",
        });
    }
    if !(options.start_soc > battery.empty_soc() && options.start_soc <= 1.0) {
        return Err(PlannerError::InvalidParameter {
            name: "start_soc",
            value: options.start_soc,
            unit: "",
            expected: "a fraction in (empty point, 1]",
        });
    }
    crate::error::positive("pnr_interval_s", options.pnr_interval_s, "s")?;
    let airframe = aircraft.airframe();
    let g = aircraft.gravity_mps2();
    let return_rate = match options.return_descent_rate_mps {
        Some(r) => crate::error::positive("return_descent_rate_mps", r, "m/s")?,
        None => airframe.max_descent_rate_mps().min(2.0),
    };
    let base_mass = airframe.mass_kg() + battery.mass_kg();
    let powered: Vec<Powered<'_>> = mission
        .payloads_kg()
        .iter()
        .map(|p| aircraft.at_mass(base_mass + p, options.aoa))
        .collect::<Result<_, _>>()?;
    let max_thrust = airframe.max_thrust_n(g);
    let cos_tilt_max = airframe.max_tilt_rad().cos();
    let charge_as = battery.capacity_ah() * 3600.0;
    let empty = battery.empty_soc();
    let required = options.reserve_fraction * battery.usable_fraction();
    let r_rotor = aircraft.rotor_radius_m();
    let rotor_h = airframe.rotor_height_m();
    let uniform_wind = if wind.is_uniform() {
        wind.mean_at([0.0; 3])
    } else {
        None
    };
    let kinds = mission.segment_kinds();
    let home = mission.home_m();
    let max_current = battery.max_current_a();
    let cutoff_v = battery.cutoff_v();
    let r_pack = battery.resistance_ohm();

    let mut acc = vec![Acc::default(); kinds.len()];
    let mut soc = options.start_soc;
    let mut energy_j = 0.0;
    let mut heat_j = 0.0;
    let mut min_v = f64::INFINITY;
    let mut peak_w: f64 = 0.0;
    let mut peak_a: f64 = 0.0;
    let mut t0 = 0.0;
    let mut shortfall = None;
    let mut samples = Vec::new();
    if options.record_samples {
        samples.reserve((mission.duration_s() / dt) as usize + mission.pieces().len());
    }
    let mut next_check = 0.0;
    let mut last_ok: Option<PointOfNoReturn> = None;
    let mut pnr: Option<PointOfNoReturn> = None;
    let mut pnr_done = !options.point_of_no_return;
    let mut cache = ReturnCache {
        phase: usize::MAX,
        wind: [f64::NAN; 2],
        bins: vec![None; BEARING_BINS],
    };

    // Work is done in blocks of up to BLOCK steps: pass A ([`PassA`]) evaluates kinematics, wind,
    // trim and power for a block (independent samples, so the CPU overlaps them); pass B runs the
    // pack, whose state of charge chains one step to the next. On a long mission pass A runs on a
    // second thread, blocks ahead of pass B. An error found in pass A (a thrust beyond the
    // airframe, a wind grid left) is raised only after pass B has flown the samples before it, so
    // a battery that fails first is still reported as the result.
    let pass_a = PassA {
        pieces: mission.pieces(),
        powered: &powered,
        wind,
        uniform_wind,
        steady_wind: wind.is_steady_and_level_uniform(),
        hoist,
        ground_effect: options.ground_effect,
        r_rotor,
        rotor_h,
        max_thrust,
        cos_tilt_max,
        kinds,
        airframe,
        dt,
        index: 0,
        k0: 0,
        t0: 0.0,
        piece: None,
    };
    let total_steps: usize = mission.pieces().iter().map(|p| piece_steps(p, dt).0).sum();
    let threaded = parallel
        && total_steps >= THREADED_FROM_STEPS
        && std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2);
    let mut steps = [PackStep::default(); BLOCK];
    let mut cursor = battery.cursor(soc);
    std::thread::scope(|scope| -> Result<(), PlannerError> {
        let started = if threaded {
            Feed::threaded(scope, pass_a.clone())
        } else {
            None
        };
        let mut feed = started.unwrap_or_else(|| Feed::Inline {
            pass: pass_a,
            block: Box::new(BlockA::EMPTY),
        });
        'pieces: for piece in mission.pieces() {
            let pw = &powered[piece.mass_phase];
            let seg = piece.segment;
            let dur = piece.duration_s();
            let (n, h) = piece_steps(piece, dt);
            let a = &mut acc[seg];
            a.reached = true;
            let mut seg_energy = 0.0;
            let mut seg_peak = a.peak_w;
            // Charge per ampere and step as a fraction of the capacity: a product on the pack's
            // step-to-step chain instead of a division.
            let dq = h / charge_as;
            let mut k0 = 0;
            while k0 < n {
                let block = feed.next();
                debug_assert_eq!(block.k0, k0);
                let m = block.m;
                let valid = block.valid;
                let pending = block.pending.take();
                let BlockA {
                    ref kins,
                    ref winds,
                    ref v_airs,
                    ref accs,
                    ref fwds,
                    ref ges,
                    ref trims,
                    ..
                } = *block;
                // Pass B: the pack. Its state of charge chains one step to the next; draw_block
                // solves the block's chain at once (bit for bit the step-by-step result), then the
                // loop below books each step in order.
                let soc_at_block = cursor.soc();
                let mut powers = [0.0; BLOCK];
                for (p, t) in powers.iter_mut().zip(&trims[..valid]) {
                    *p = t.electrical_w;
                }
                let drawn = cursor.draw_block(battery, &powers[..valid], dq, &mut steps[..valid]);
                for j in 0..valid {
                    let tm = ((k0 + j) as f64 + 0.5) * h;
                    let kin = kins[j];
                    let w = winds[j];
                    let trim = trims[j];
                    let t = t0 + tm;
                    let p = trim.electrical_w;
                    let draw = match steps.get(j) {
                        Some(d) if j < drawn && d.current_a <= max_current => *d,
                        _ => {
                            shortfall = Some(Shortfall::PackLimit {
                                time_s: t,
                                segment: seg + 1,
                                kind: kinds[seg],
                                position_m: kin.pos_m,
                                power_w: p,
                            });
                            a.duration_s += tm;
                            a.distance_m += piece.profile.at(tm).0;
                            soc = if j == 0 {
                                soc_at_block
                            } else {
                                steps[j - 1].soc_after
                            };
                            break 'pieces;
                        }
                    };
                    let soc_now = draw.soc_after;
                    seg_energy += p * h;
                    heat_j += draw.current_a * draw.current_a * r_pack * h;
                    seg_peak = seg_peak.max(p);
                    peak_a = peak_a.max(draw.current_a);
                    min_v = min_v.min(draw.terminal_v);
                    if options.record_samples {
                        let (roll, pitch, yaw) = attitude_rad(trim.axis, kin.forward);
                        let terms = pw.power_terms(accs[j], v_airs[j], fwds[j], ges[j])?;
                        samples.push(Sample {
                            time_s: t,
                            segment: seg + 1,
                            east_m: kin.pos_m[0],
                            north_m: kin.pos_m[1],
                            up_m: kin.pos_m[2],
                            vel_east_mps: kin.vel_mps[0],
                            vel_north_mps: kin.vel_mps[1],
                            vel_up_mps: kin.vel_mps[2],
                            acc_east_mps2: kin.acc_mps2[0],
                            acc_north_mps2: kin.acc_mps2[1],
                            acc_up_mps2: kin.acc_mps2[2],
                            wind_east_mps: w[0],
                            wind_north_mps: w[1],
                            airspeed_mps: trim.airspeed_mps,
                            thrust_n: trim.thrust_n,
                            roll_deg: roll.to_degrees(),
                            pitch_deg: pitch.to_degrees(),
                            yaw_deg: yaw.to_degrees().rem_euclid(360.0),
                            power_w: p,
                            current_a: draw.current_a,
                            voltage_v: draw.terminal_v,
                            soc: soc_now,
                            induced_w: terms.map(|b| b.induced_w),
                            parasitic_w: terms.map(|b| b.parasitic_w),
                            profile_w: terms.map(|b| b.profile_w),
                            acceleration_w: terms.map(|b| b.acceleration_w),
                            climb_w: terms.map(|b| b.climb_w),
                        });
                    }
                    if draw.terminal_v < cutoff_v || soc_now <= empty {
                        shortfall = Some(if draw.terminal_v < cutoff_v {
                            Shortfall::CutOffVoltage {
                                time_s: t,
                                segment: seg + 1,
                                kind: kinds[seg],
                                position_m: kin.pos_m,
                                voltage_v: draw.terminal_v,
                                cutoff_v,
                            }
                        } else {
                            Shortfall::BatteryEmpty {
                                time_s: t,
                                segment: seg + 1,
                                kind: kinds[seg],
                                position_m: kin.pos_m,
                            }
                        });
                        a.duration_s += tm + 0.5 * h;
                        a.distance_m += piece.profile.at(tm + 0.5 * h).0;
                        a.energy_j += seg_energy;
                        a.peak_w = seg_peak;
                        a.end_soc = soc_now;
                        energy_j += seg_energy;
                        peak_w = peak_w.max(seg_peak);
                        soc = soc_now;
                        break 'pieces;
                    }
                    if !pnr_done && t >= next_check && kin.pos_m[2] > 0.0 {
                        next_check = t + options.pnr_interval_s;
                        let here = PointOfNoReturn {
                            time_s: t,
                            segment: seg + 1,
                            position_m: kin.pos_m,
                        };
                        let ok = can_return(
                            pw,
                            battery,
                            wind,
                            &mut cache,
                            piece.mass_phase,
                            kin.pos_m,
                            home,
                            soc_now,
                            empty + required,
                            return_rate,
                            charge_as,
                        );
                        if ok {
                            last_ok = Some(here);
                        } else {
                            pnr = Some(last_ok.unwrap_or(PointOfNoReturn {
                                time_s: 0.0,
                                segment: 1,
                                position_m: home,
                            }));
                            pnr_done = true;
                        }
                    }
                }
                if let Some(e) = pending {
                    return Err(e);
                }
                k0 += m;
            }
            soc = cursor.soc();
            a.duration_s += dur;
            a.distance_m += piece.profile.length_m;
            a.energy_j += seg_energy;
            a.peak_w = seg_peak;
            a.end_soc = soc;
            energy_j += seg_energy;
            peak_w = peak_w.max(seg_peak);
            t0 += dur;
        }
        Ok(())
    })?;

    let duration_s: f64 = acc.iter().map(|a| a.duration_s).sum();
    let reserve_soc = (soc - empty).max(0.0);
    if shortfall.is_none() && reserve_soc < required {
        shortfall = Some(Shortfall::Reserve {
            reserve_soc,
            required_soc: required,
        });
    }
    let segments = acc
        .iter()
        .enumerate()
        .filter(|(_, a)| a.reached)
        .map(|(i, a)| SegmentReport {
            index: i + 1,
            kind: kinds[i],
            duration_s: a.duration_s,
            distance_m: a.distance_m,
            energy_wh: a.energy_j / 3600.0,
            mean_power_w: if a.duration_s > 0.0 {
                a.energy_j / a.duration_s
            } else {
                0.0
            },
            peak_power_w: a.peak_w,
            end_soc: a.end_soc,
        })
        .collect::<Vec<_>>();
    Ok(MissionReport {
        feasible: shortfall.is_none(),
        shortfall,
        takeoff_mass_kg: powered[0].mass_kg(),
        duration_s,
        distance_m: segments.iter().map(|s| s.distance_m).sum(),
        energy_wh: energy_j / 3600.0,
        pack_heat_wh: heat_j / 3600.0,
        start_soc: options.start_soc,
        end_soc: soc.max(0.0),
        min_voltage_v: if min_v.is_finite() { min_v } else { 0.0 },
        peak_power_w: peak_w,
        peak_current_a: peak_a,
        empty_soc: empty,
        reserve_soc,
        required_reserve_soc: required,
        point_of_no_return: pnr,
        segments,
        samples,
    })
}

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

/// Whether a straight return from `pos` lands with the state of charge at or above `floor_soc`.
#[allow(clippy::too_many_arguments)]
fn can_return(
    pw: &Powered<'_>,
    battery: &Battery,
    wind: &Wind,
    cache: &mut ReturnCache,
    phase: usize,
    pos: [f64; 3],
    home: [f64; 3],
    soc: f64,
    floor_soc: f64,
    descent_rate: f64,
    charge_as: f64,
) -> bool {
    let w = match wind.mean_at(pos) {
        Some(w) => w,
        None => return false,
    };
    let wh = [w[0], w[1]];
    // A cache entry is valid for this mass phase and a mean wind within 1 cm/s.
    if cache.phase != phase
        || !((cache.wind[0] - wh[0]).abs() < 0.01 && (cache.wind[1] - wh[1]).abs() < 0.01)
    {
        cache.phase = phase;
        cache.wind = wh;
        cache.bins.iter_mut().for_each(|b| *b = None);
    }
    let d = [home[0] - pos[0], home[1] - pos[1]];
    let dist = d[0].hypot(d[1]);
    // (power W, ground speed m/s) of the horizontal leg.
    let leg = if dist > 1.0 {
        let bearing = d[0].atan2(d[1]).rem_euclid(std::f64::consts::TAU);
        let bin = ((bearing / std::f64::consts::TAU * BEARING_BINS as f64) as usize)
            .min(BEARING_BINS - 1);
        match cache.bins[bin] {
            Some(v) => Some(v),
            None => {
                let b = (bin as f64 + 0.5) / BEARING_BINS as f64 * std::f64::consts::TAU;
                let course = [b.sin(), b.cos()];
                let max_air = pw.aircraft().airframe().max_speed_mps();
                match best_range(pw, course, wh, max_air) {
                    Ok(r) => {
                        cache.bins[bin] = Some((r.power_w, r.ground_speed_mps));
                        cache.bins[bin]
                    }
                    Err(_) => return false,
                }
            }
        }
    } else {
        None
    };
    // Descent over home: air velocity is minus the wind, vertical -rate.
    let descent_w = match pw.trim(
        [0.0; 3],
        [-wh[0], -wh[1], -descent_rate - w[2]],
        [0.0, 1.0],
        1.0,
    ) {
        Ok(t) => t.electrical_w,
        Err(_) => return false,
    };
    let descent_s = pos[2] / descent_rate;
    let charge = |s: f64| -> Option<f64> {
        let mut q = 0.0;
        if let Some((p, vg)) = leg {
            q += battery.draw(p, s)?.current_a * dist / vg;
        }
        q += battery.draw(descent_w, s)?.current_a * descent_s;
        Some(q)
    };
    let Some(q0) = charge(soc) else { return false };
    let mid = soc - 0.5 * q0 / charge_as;
    let Some(q) = charge(mid) else { return false };
    soc - q / charge_as >= floor_soc
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission::MissionSpec;
    use crate::test_support::{m100_aircraft, tb48d};
    use crate::wind::{Gusts, Profile};

    fn m100() -> (Aircraft, Battery) {
        (m100_aircraft(), tb48d().to_battery().unwrap())
    }

    const SURVEY: &str = r#"
        [[segment]]
        kind = "take-off"
        altitude_m = 30.0
        climb_rate_mps = 2.0
        [[segment]]
        kind = "leg"
        east_m = 400.0
        north_m = 0.0
        ground_speed_mps = 9.0
        [[segment]]
        kind = "hover"
        duration_s = 20.0
        [[segment]]
        kind = "leg"
        east_m = 400.0
        north_m = 250.0
        altitude_m = 45.0
        ground_speed_mps = 7.0
        [[segment]]
        kind = "orbit"
        centre_east_m = 400.0
        centre_north_m = 150.0
        radius_m = 100.0
        ground_speed_mps = 6.0
        direction = "clockwise"
        laps = 1.0
        [[segment]]
        kind = "return"
        ground_speed_mps = 9.0
        [[segment]]
        kind = "landing"
        rate_mps = 1.0
    "#;

    #[test]
    fn pass_a_on_its_own_thread_gives_the_same_report() {
        // At a 10 ms step the survey has over 4096 steps, so `plan` runs pass A on a second
        // thread; the report must be the in-line one exactly, samples included, whether the
        // mission completes, the pack runs out part-way, or pass A meets an error.
        let (aircraft, battery) = m100();
        let mission = MissionSpec::from_toml_str(SURVEY)
            .unwrap()
            .compile(aircraft.airframe(), battery.mass_kg(), None)
            .unwrap();
        let steps: usize = mission
            .pieces()
            .iter()
            .map(|p| piece_steps(p, 0.01).0)
            .sum();
        assert!(steps >= THREADED_FROM_STEPS, "{steps}");
        let mut errors = 0;
        for (start_soc, wind_mps) in [(1.0, 6.0), (0.12, 6.0), (1.0, 16.0)] {
            let wind = Wind::constant(wind_mps, 250.0).unwrap();
            let opts = PlanOptions {
                time_step_s: 0.01,
                record_samples: true,
                start_soc,
                ..PlanOptions::default()
            };
            let threaded = plan_with(&aircraft, &battery, &mission, &wind, &opts, true, true);
            let inline = plan_with(&aircraft, &battery, &mission, &wind, &opts, true, false);
            match (threaded, inline) {
                (Ok(t), Ok(i)) => {
                    assert_eq!(t, i, "start {start_soc}, wind {wind_mps}");
                    if start_soc < 1.0 {
                        assert!(!t.feasible && t.samples.len() < steps);
                    }
                }
                (Err(t), Err(i)) => {
                    // 16 m/s is beyond the M100's tilt on the upwind leg.
                    assert!(wind_mps > 10.0 && t.to_string().contains("tilt"), "{t}");
                    assert_eq!(t.to_string(), i.to_string());
                    errors += 1;
                }
                (t, i) => panic!("threaded {t:?} against in line {i:?}"),
            }
        }
        assert_eq!(errors, 1);
    }

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
    fn block_passes_match_the_sample_by_sample_trim() {
        // The block path against `Powered::trim` and `Battery::draw` called per sample, over the
        // recorded samples of a survey in wind.
        let (aircraft, battery) = m100();
        let mission = MissionSpec::from_toml_str(SURVEY)
            .unwrap()
            .compile(aircraft.airframe(), battery.mass_kg(), None)
            .unwrap();
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
}
