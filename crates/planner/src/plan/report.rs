//! What a planning run is asked and what it answers: the options, the report per mission and
//! per segment, the time series, why a mission falls short, the point of no return.

use aloft_power::AoaModel;
use serde::Serialize;

use crate::airframe::Airframe;
use crate::battery::Pack;
use crate::envelope::Limit;
use crate::error::PlannerError;
use crate::wind::speed_and_from_deg;

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
    /// Keep every sample in the report (default false: the hot loop stores nothing). To stream
    /// the samples instead, fly with [`super::plan_into`] and a [`SampleSink`].
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
    /// Most steps a flight may take (default [`DEFAULT_MAX_SAMPLES`]): a flight that would take
    /// more stops with [`PlannerError::TooManySamples`], which says the time step to use instead.
    /// The limit bounds the time of a run whatever its inputs (a tiny time step, a huge hold).
    pub max_samples: u64,
}

/// The default limit on the steps of one flight: ten million, 11.6 days of flight at the default
/// 0.1 s step, a 24-hour flight at 10 ms; about half a second of planning (several seconds when
/// every sample is written out).
pub const DEFAULT_MAX_SAMPLES: u64 = 10_000_000;

/// Where the samples of a flight go as they are flown, one at a time, so that memory does not grow
/// with the flight (a file writer, a decimating plot buffer), or all of them (`Vec<Sample>`).
pub trait SampleSink {
    /// Whether the sink takes samples at all (the flight then does not compute them).
    fn wants_samples(&self) -> bool {
        true
    }
    /// Take the next sample, in time order; an error stops the flight and is returned.
    ///
    /// # Errors
    /// Whatever the sink cannot do (a file that cannot be written), as
    /// [`PlannerError::Output`].
    fn take(&mut self, sample: &Sample) -> Result<(), PlannerError>;
}

impl SampleSink for Vec<Sample> {
    fn take(&mut self, sample: &Sample) -> Result<(), PlannerError> {
        self.push(*sample);
        Ok(())
    }
}

/// A sink that takes no samples.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoSamples;

impl SampleSink for NoSamples {
    fn wants_samples(&self) -> bool {
        false
    }
    fn take(&mut self, _sample: &Sample) -> Result<(), PlannerError> {
        Ok(())
    }
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
            max_samples: DEFAULT_MAX_SAMPLES,
        }
    }
}

/// One sample of the time series (at the midpoint of an integration step).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
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
    /// The operator's mission item number, when the mission came from a planner file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub item: Option<u32>,
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
    /// Time flown beyond the plan because the envelope slowed the vehicle, s (0 when flown as
    /// planned).
    pub time_lost_s: f64,
    /// How the segment was flown at the edge of the envelope, when it was.
    pub edge: Option<EdgeReport>,
}

/// How a segment was flown at the edge of the flight envelope: the slowest it went and why.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EdgeReport {
    /// The limit the vehicle flew at there.
    pub limit: Limit,
    /// The slowest speed along the path at cruise, m/s (`None` when only the speed changes at
    /// the segment's ends were slowed).
    pub slowest_mps: Option<f64>,
    /// The planned speed there, m/s.
    pub planned_mps: f64,
    /// The wind there (east, north, up), m/s.
    pub wind_mps: [f64; 3],
    /// Height above home there, m.
    pub up_m: f64,
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
    /// The vehicle cannot fly the path here within its envelope: it cannot make headway along
    /// the track against the wind, or cannot hold its position (a wind or a load beyond it).
    NoProgress(Stuck),
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
            Shortfall::NoProgress(stuck) => {
                f.write_str(if stuck.moving {
                    "the vehicle cannot make headway along the track "
                } else {
                    "the vehicle cannot hold its position "
                })?;
                at(f, stuck.time_s, stuck.segment, stuck.kind, stuck.position_m)?;
                write!(f, ": {}", stuck.why("the vehicle"))
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

/// Where and why the vehicle cannot fly on ([`Shortfall::NoProgress`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stuck {
    /// Mission time, s.
    pub time_s: f64,
    /// Segment number, from 1.
    pub segment: usize,
    /// Segment kind.
    pub kind: &'static str,
    /// Position, ENU m.
    pub position_m: [f64; 3],
    /// The wind there (east, north, up), m/s.
    pub wind_mps: [f64; 3],
    /// Whether the path moves over the ground there (else the vehicle holds a point or climbs
    /// or descends in place).
    pub moving: bool,
    /// The limit that binds.
    pub limit: Limit,
    /// The limit's value, in `limit_unit`.
    pub limit_value: f64,
    /// The unit of `limit_value`.
    pub limit_unit: &'static str,
    /// The largest airspeed of steady level flight within the envelope at this mass, m/s.
    pub max_airspeed_mps: f64,
}

impl Stuck {
    /// Why, in words, with the vehicle called `vehicle` (`the vehicle`, its name).
    pub fn why<'a>(&'a self, vehicle: &'a str) -> NoProgressWhy<'a> {
        NoProgressWhy {
            vehicle,
            wind_mps: self.wind_mps,
            limit: self.limit,
            limit_value: self.limit_value,
            limit_unit: self.limit_unit,
            max_airspeed_mps: self.max_airspeed_mps,
        }
    }
}

/// Why a path cannot be flown, in words: the wind and what the vehicle can fly against (the
/// tail of [`Shortfall::NoProgress`]'s message, which the engine reuses with the item number).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoProgressWhy<'a> {
    /// The vehicle in words (`the vehicle`, its name).
    pub vehicle: &'a str,
    /// The wind (east, north, up), m/s.
    pub wind_mps: [f64; 3],
    /// The limit that binds.
    pub limit: Limit,
    /// Its value, in `limit_unit`.
    pub limit_value: f64,
    /// Its unit.
    pub limit_unit: &'a str,
    /// The largest steady level airspeed within the envelope, m/s.
    pub max_airspeed_mps: f64,
}

impl std::fmt::Display for NoProgressWhy<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (speed, from_deg) = speed_and_from_deg(self.wind_mps);
        write!(
            f,
            "the wind there is {speed:.1} m/s from {from_deg:.0} deg; "
        )?;
        if self.max_airspeed_mps < 0.05 {
            write!(
                f,
                "{} cannot hover within its {} limit of {:.2} {}",
                self.vehicle, self.limit, self.limit_value, self.limit_unit
            )
        } else {
            write!(
                f,
                "{} flies at most {:.1} m/s of airspeed within its {} limit of {:.2} {}",
                self.vehicle, self.max_airspeed_mps, self.limit, self.limit_value, self.limit_unit
            )
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

/// The options of a run once checked: the numbers the loop runs with.
#[derive(Debug, Clone, Copy)]
pub(super) struct CheckedOptions {
    /// Largest sampling step, s.
    pub(super) time_step_s: f64,
    /// Descent rate of the priced return, m/s.
    pub(super) return_descent_rate_mps: f64,
}

impl PlanOptions {
    /// Check the options against the pack and the airframe, in the order the errors are reported.
    pub(super) fn check(
        &self,
        battery: &Pack,
        airframe: &Airframe,
    ) -> Result<CheckedOptions, PlannerError> {
        let dt = crate::error::positive("time_step_s", self.time_step_s, "s")?;
        crate::error::reserve_fraction(self.reserve_fraction)?;
        let ok = self.start_soc > battery.empty_soc() && self.start_soc <= 1.0;
        let expected = "a fraction in (empty point, 1]";
        aloft_core::parameter("start_soc", self.start_soc, "", ok, expected)?;
        crate::error::positive("pnr_interval_s", self.pnr_interval_s, "s")?;
        let return_rate = match self.return_descent_rate_mps {
            Some(r) => crate::error::positive("return_descent_rate_mps", r, "m/s")?,
            None => airframe.max_descent_rate_mps().min(2.0),
        };
        Ok(CheckedOptions {
            time_step_s: dt,
            return_descent_rate_mps: return_rate,
        })
    }
}
