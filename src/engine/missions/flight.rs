//! One planning run's fixed parts (aircraft, pack, wind, planner options) and the flight of a
//! mission spec with them: the main plan flies through it, and so do the searches that re-plan
//! parts of a route (the loiter until the reserve, the sorties).

use aloft_planner::sorties::first_speed;
use aloft_planner::{
    Aircraft, Mission as Compiled, MissionReport, MissionSpec, NoSamples, Pack, PlanOptions,
    PlannerError, SampleSink, SegmentSpec, Wind,
};

use crate::engine::basics::step_meter::StepMeter;

/// Descent rate of the landing after a return home that aloft adds (a loiter's, a sortie's), m/s
/// (or the airframe's limit if lower): an autopilot's gentle landing.
const LANDING_RATE_MPS: f64 = 1.0;

/// What every flight of one request shares.
pub(in crate::engine) struct Flight<'a> {
    /// The aircraft flown.
    pub(in crate::engine) aircraft: &'a Aircraft,
    /// The pack.
    pub(in crate::engine) pack: &'a Pack,
    /// The wind.
    pub(in crate::engine) wind: &'a Wind,
    /// The planner's options.
    pub(in crate::engine) options: PlanOptions,
    /// The request's budget of steps, when its caller bounds it: each flight flies within what
    /// is left and is counted ([`StepMeter`]).
    pub(in crate::engine) meter: Option<StepMeter>,
}

impl<'a> Flight<'a> {
    /// The same flight with the reserve `reserve_fraction` (a sortie cut with a margin), its
    /// steps counted in the same budget.
    pub(in crate::engine) fn with_reserve(&self, reserve_fraction: f64) -> Flight<'a> {
        Flight {
            aircraft: self.aircraft,
            pack: self.pack,
            wind: self.wind,
            options: PlanOptions {
                reserve_fraction,
                ..self.options
            },
            meter: self.meter.clone(),
        }
    }
}

impl Flight<'_> {
    /// Compile `spec` (its take-off payload overridden by `payload_kg` when given).
    ///
    /// # Errors
    /// As [`MissionSpec::compile`].
    pub(in crate::engine) fn compile(
        &self,
        spec: &MissionSpec,
        payload_kg: Option<f64>,
    ) -> Result<Compiled, PlannerError> {
        let airframe = self.aircraft.airframe();
        // Speeds of a planner file are clamped to what the vehicle can hold within its tilt
        // limit at take-off (with the payload and the pack), in still air.
        let clamp_to_mps = spec.clamp_speeds.then(|| {
            let payload = payload_kg.unwrap_or(spec.payload_kg).max(0.0);
            let mass = airframe.mass_kg() + self.pack.mass_kg() + payload;
            self.aircraft.tilt_limited_speed_mps(mass)
        });
        spec.compile_clamped(airframe, self.pack.mass_kg(), payload_kg, clamp_to_mps)
    }

    /// Fly a compiled mission, handing each sample to `sink`.
    ///
    /// # Errors
    /// As [`aloft_planner::plan_into`].
    pub(in crate::engine) fn fly_into(
        &self,
        compiled: &Compiled,
        sink: &mut dyn SampleSink,
    ) -> Result<MissionReport, PlannerError> {
        self.metered(|options| {
            aloft_planner::plan_into(self.aircraft, self.pack, compiled, self.wind, options, sink)
        })
    }

    /// Fly a compiled mission, keeping the samples when the options ask.
    ///
    /// # Errors
    /// As [`aloft_planner::plan`].
    pub(in crate::engine) fn fly(
        &self,
        compiled: &Compiled,
    ) -> Result<MissionReport, PlannerError> {
        self.metered(|options| {
            aloft_planner::plan(self.aircraft, self.pack, compiled, self.wind, options)
        })
    }

    /// A flight with the planner's options, within the request's budget and counted in it when
    /// there is one.
    fn metered(
        &self,
        fly: impl FnOnce(&PlanOptions) -> Result<MissionReport, PlannerError>,
    ) -> Result<MissionReport, PlannerError> {
        let Some(meter) = &self.meter else {
            return fly(&self.options);
        };
        let options = meter.within(&self.options);
        let flown = fly(&options);
        meter.count(&flown, &options, self.options.max_samples);
        flown
    }

    /// Compile and fly `spec` (take-off payload `payload_kg` when given) for its report alone:
    /// a trial of a search.
    ///
    /// # Errors
    /// As [`Flight::compile`] and [`Flight::fly_into`].
    pub(in crate::engine) fn trial(
        &self,
        spec: &MissionSpec,
        payload_kg: Option<f64>,
    ) -> Result<MissionReport, PlannerError> {
        let compiled = self.compile(spec, payload_kg)?;
        self.fly_into(&compiled, &mut NoSamples)
    }

    /// The way home aloft adds to a route it cuts short (a loiter's end, a sortie's): a return
    /// at the mission's planning speed (else the first speed the route gives, so that a mission
    /// with a speed on every leg returns at it) and a landing at 1 m/s (or the airframe's limit).
    pub(in crate::engine) fn way_home(&self, spec: &MissionSpec) -> [SegmentSpec; 2] {
        let ground_speed_mps = match spec.default_speed_mps {
            Some(_) => None,
            None => first_speed(&spec.segments),
        };
        let rate_mps = LANDING_RATE_MPS.min(self.aircraft.airframe().max_descent_rate_mps());
        [
            SegmentSpec::Return {
                ground_speed_mps,
                altitude_m: None,
                item: None,
            },
            SegmentSpec::Landing {
                rate_mps,
                payload_after_kg: None,
                item: None,
                ground_m: None,
            },
        ]
    }
}

impl Flight<'_> {
    /// `spec` as flown to the ground: a mission that ends in the air (no landing or return
    /// after its last item, common in QGroundControl surveys, whose vehicle comes home by its
    /// own mission-end action) gets the way home an autopilot flies then, a return to home at
    /// the RTL altitude and a landing ([`Flight::way_home`]), with a note that says so; other
    /// missions, and a route that ends in a loiter until the reserve (which prices its own way
    /// home), are flown as they are.
    pub(in crate::engine) fn home_at_mission_end(
        &self,
        mut spec: MissionSpec,
    ) -> (MissionSpec, Option<String>) {
        if !ends_in_the_air(&spec.segments) {
            return (spec, None);
        }
        let last = spec.segments.len();
        let name = match spec.segments.last().and_then(SegmentSpec::item) {
            Some(i) => format!("item {i}"),
            None => format!("segment {last}"),
        };
        let rtl = spec
            .rtl_altitude_m
            .map_or("at its height".to_string(), |h| {
                format!("at {h} m or higher")
            });
        let home = self.way_home(&spec);
        let rate = match home[1] {
            SegmentSpec::Landing { rate_mps, .. } => rate_mps,
            _ => LANDING_RATE_MPS,
        };
        spec.segments.extend(home);
        let note = format!(
            "the mission ends in the air after {name}: priced with the way home an autopilot flies at mission end, a return to home {rtl} and a landing at {rate} m/s (segments {} and {})",
            last + 1,
            last + 2
        );
        (spec, Some(note))
    }
}

/// Whether the vehicle is still in the air after the last of `segments` (a take-off not
/// followed by a landing); a route that ends in a loiter until the reserve is not counted.
pub(in crate::engine) fn ends_in_the_air(segments: &[SegmentSpec]) -> bool {
    let mut airborne = false;
    for s in segments {
        match s {
            SegmentSpec::TakeOff { .. } => airborne = true,
            SegmentSpec::Landing { .. } => airborne = false,
            SegmentSpec::LoiterUntilReserve { .. } => return false,
            _ => {}
        }
    }
    airborne
}
