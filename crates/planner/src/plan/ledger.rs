//! The energy ledger: what the pack pass books, step by step, per segment and per mission.
//!
//! Per step ([`Ledger::book`]): the electrical energy `P h` into the segment's tally, the heat
//! `I^2 R h` in the pack, the peaks of power and current, the lowest terminal voltage; when asked,
//! the sample of the time series ([`Ledger::record`]). Per piece flown ([`Ledger::close`]) or cut
//! short where the pack fails ([`Ledger::stop_at`]): its duration,
//! distance, energy, peak power and the state of charge it ends at. At the end
//! ([`Ledger::report`]): the reserve left, the shortfall if any, and the [`MissionReport`].

use crate::aircraft::Powered;
use crate::error::PlannerError;
use crate::mission::Mission;
use crate::pack_cursor::PackStep;
use crate::trajectory::Piece;
use crate::trim::attitude_rad;

use super::report::{
    EdgeReport, MissionReport, PlanOptions, PointOfNoReturn, Sample, SegmentReport, Shortfall,
};
use super::sampler::BlockA;

/// Totals of one segment.
#[derive(Default, Clone, Copy)]
struct SegmentTotals {
    duration_s: f64,
    distance_m: f64,
    energy_j: f64,
    peak_w: f64,
    end_soc: f64,
    reached: bool,
    /// Time flown beyond the plan, s.
    late_s: f64,
    /// The slowest step flown at the edge of the envelope.
    edge: Option<EdgeStep>,
}

/// A step flown at the edge of the envelope, as the ledger keeps the slowest of a segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct EdgeStep {
    /// The limit it flew at.
    pub(super) limit: crate::envelope::Limit,
    /// Speed along the path flown, m/s.
    pub(super) speed_mps: f64,
    /// Speed along the path planned, m/s.
    pub(super) planned_mps: f64,
    /// Whether the step is in the piece's cruise (not a speed change at its ends).
    pub(super) cruise: bool,
    /// Wind, m/s.
    pub(super) wind_mps: [f64; 3],
    /// Height above home, m.
    pub(super) up_m: f64,
}

impl EdgeStep {
    /// Whether `self` is a slower cruise than `other` (a cruise step before any speed change).
    fn slower_than(&self, other: &EdgeStep) -> bool {
        match (self.cruise, other.cruise) {
            (true, false) => true,
            (false, true) => false,
            _ => self.speed_mps < other.speed_mps,
        }
    }
}

/// The energy and peak power of the piece being flown, booked into its segment when the piece
/// ends.
#[derive(Clone, Copy)]
pub(super) struct PieceTally {
    segment: usize,
    energy_j: f64,
    peak_w: f64,
}

/// The accumulators of a run, per segment and per mission.
pub(super) struct Ledger<'p> {
    kinds: &'p [&'static str],
    items: &'p [Option<u32>],
    segments: Vec<SegmentTotals>,
    /// State of charge where the flight ended (the start until then).
    soc: f64,
    energy_j: f64,
    heat_j: f64,
    min_v: f64,
    peak_w: f64,
    peak_a: f64,
    shortfall: Option<Shortfall>,
    /// Pack resistance, ohm (for the heat).
    r_pack: f64,
    start_soc: f64,
    empty_soc: f64,
    required_soc: f64,
}

impl<'p> Ledger<'p> {
    /// An empty ledger for `mission` from `options.start_soc`, with a pack of resistance `r_pack`
    /// that is empty at `empty_soc` and must keep `required_soc` above it.
    pub(super) fn new(
        mission: &'p Mission,
        options: &PlanOptions,
        r_pack: f64,
        empty_soc: f64,
        required_soc: f64,
    ) -> Self {
        let kinds = mission.segment_kinds();
        Ledger {
            kinds,
            items: mission.segment_items(),
            segments: vec![SegmentTotals::default(); kinds.len()],
            soc: options.start_soc,
            energy_j: 0.0,
            heat_j: 0.0,
            min_v: f64::INFINITY,
            peak_w: 0.0,
            peak_a: 0.0,
            shortfall: None,
            r_pack,
            start_soc: options.start_soc,
            empty_soc,
            required_soc,
        }
    }

    /// Kind of segment `segment` (from 0).
    #[inline]
    pub(super) fn kind(&self, segment: usize) -> &'static str {
        self.kinds[segment]
    }

    /// Start booking a piece of `segment` (from 0).
    pub(super) fn open(&mut self, segment: usize) -> PieceTally {
        let a = &mut self.segments[segment];
        a.reached = true;
        PieceTally {
            segment,
            energy_j: 0.0,
            peak_w: a.peak_w,
        }
    }

    /// Book one step of `h` seconds at electrical power `power_w` with the pack's `step`.
    #[inline]
    pub(super) fn book(&mut self, tally: &mut PieceTally, power_w: f64, h: f64, step: &PackStep) {
        tally.energy_j += power_w * h;
        self.heat_j += step.current_a * step.current_a * self.r_pack * h;
        tally.peak_w = tally.peak_w.max(power_w);
        self.peak_a = self.peak_a.max(step.current_a);
        self.min_v = self.min_v.min(step.terminal_v);
    }

    /// Sample `j` of `block` (pass A's values, the pack's `step`) at mission time `t` in segment
    /// `segment` (from 0), with the four terms of the power model when it has them.
    pub(super) fn sample(
        pw: &Powered<'_>,
        block: &BlockA,
        j: usize,
        t: f64,
        segment: usize,
        step: &PackStep,
    ) -> Result<Sample, PlannerError> {
        let (kin, w, trim) = (block.kins[j], block.winds[j], block.trims[j]);
        let (roll, pitch, yaw) = attitude_rad(trim.axis, kin.forward);
        let terms = pw.power_terms(block.accs[j], block.v_airs[j], block.fwds[j], block.ges[j])?;
        Ok(Sample {
            time_s: t,
            segment: segment + 1,
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
            power_w: trim.electrical_w,
            current_a: step.current_a,
            voltage_v: step.terminal_v,
            soc: step.soc_after,
            induced_w: terms.map(|b| b.induced_w),
            parasitic_w: terms.map(|b| b.parasitic_w),
            profile_w: terms.map(|b| b.profile_w),
            acceleration_w: terms.map(|b| b.acceleration_w),
            climb_w: terms.map(|b| b.climb_w),
        })
    }

    /// A step of segment `segment` (from 0) flown at the edge of the envelope: kept when it is
    /// the segment's slowest.
    pub(super) fn note_edge(&mut self, segment: usize, step: EdgeStep) {
        let a = &mut self.segments[segment];
        if a.edge.is_none_or(|e| step.slower_than(&e)) {
            a.edge = Some(step);
        }
    }

    /// The piece flown to its end, `late_s` beyond its planned time, leaving the pack at `soc`.
    pub(super) fn close(&mut self, tally: PieceTally, piece: &Piece, late_s: f64, soc: f64) {
        let planned = piece.duration_s();
        self.book_piece(tally, (planned, late_s), piece.profile.length_m, soc);
    }

    /// The flight ends `at_s` s into `piece` by its plan, after `late_s` flown beyond the plan
    /// (`why`), with the pack at `soc`: before a step the pack cannot deliver (`at_s` its start)
    /// or after the step in which the pack fails (`at_s` its end). The piece's steps flown until
    /// then are booked (their energy, peak and time).
    pub(super) fn stop_at(
        &mut self,
        tally: PieceTally,
        piece: &Piece,
        (at_s, late_s): (f64, f64),
        soc: f64,
        why: Shortfall,
    ) {
        self.shortfall = Some(why);
        self.book_piece(tally, (at_s, late_s), piece.profile.at(at_s).0, soc);
    }

    /// Book a piece's duration (planned and flown beyond the plan), distance, energy and peak
    /// into its segment and the mission.
    fn book_piece(
        &mut self,
        tally: PieceTally,
        (planned_s, late_s): (f64, f64),
        distance_m: f64,
        soc: f64,
    ) {
        let a = &mut self.segments[tally.segment];
        a.duration_s += planned_s + late_s;
        a.late_s += late_s;
        a.distance_m += distance_m;
        a.energy_j += tally.energy_j;
        a.peak_w = tally.peak_w;
        a.end_soc = soc;
        self.energy_j += tally.energy_j;
        self.peak_w = self.peak_w.max(tally.peak_w);
        self.soc = soc;
    }

    /// The report of the run: the reserve left, a shortfall if any, per-segment statistics.
    pub(super) fn report(
        mut self,
        takeoff_mass_kg: f64,
        point_of_no_return: Option<PointOfNoReturn>,
    ) -> MissionReport {
        let (soc, empty, required) = (self.soc, self.empty_soc, self.required_soc);
        let duration_s: f64 = self.segments.iter().map(|a| a.duration_s).sum();
        let reserve_soc = (soc - empty).max(0.0);
        if self.shortfall.is_none() && reserve_soc < required {
            self.shortfall = Some(Shortfall::Reserve {
                reserve_soc,
                required_soc: required,
            });
        }
        let segments = self.segment_reports();
        MissionReport {
            feasible: self.shortfall.is_none(),
            shortfall: self.shortfall,
            takeoff_mass_kg,
            duration_s,
            distance_m: segments.iter().map(|s| s.distance_m).sum(),
            energy_wh: self.energy_j / 3600.0,
            pack_heat_wh: self.heat_j / 3600.0,
            start_soc: self.start_soc,
            end_soc: soc.max(0.0),
            min_voltage_v: if self.min_v.is_finite() {
                self.min_v
            } else {
                0.0
            },
            peak_power_w: self.peak_w,
            peak_current_a: self.peak_a,
            empty_soc: empty,
            reserve_soc,
            required_reserve_soc: required,
            point_of_no_return,
            segments,
            samples: Vec::new(),
        }
    }

    /// Statistics of the segments reached, in order.
    fn segment_reports(&self) -> Vec<SegmentReport> {
        self.segments
            .iter()
            .enumerate()
            .filter(|(_, a)| a.reached)
            .map(|(i, a)| SegmentReport {
                index: i + 1,
                kind: self.kinds[i],
                item: self.items.get(i).copied().flatten(),
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
                time_lost_s: a.late_s,
                edge: a.edge.map(|e| EdgeReport {
                    limit: e.limit,
                    slowest_mps: e.cruise.then_some(e.speed_mps),
                    planned_mps: e.planned_mps,
                    wind_mps: e.wind_mps,
                    up_m: e.up_m,
                }),
            })
            .collect::<Vec<_>>()
    }
}
