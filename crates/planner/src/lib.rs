//! # aloft-planner: missions, wind, trim, energy and battery
//!
//! Flies a multirotor mission in a wind field sample by sample and says what it costs: energy per
//! segment, how the battery ends, whether the reserve holds, where the point of no return lies.
//! Also answers the endurance and range queries of one vehicle (hover, best-endurance speed,
//! best-range speed along a course in wind, orbit endurance, the power curve).
//!
//! ## Frame and units
//! Missions are in east-north-up (ENU) metres about the home point, heights above home on flat
//! ground; latitude/longitude are converted to that local frame ([`geodesy`]). SI units with the
//! unit in every name; angles are radians inside and degrees in files. Wind directions are the
//! direction the wind blows FROM, clockwise from north.
//!
//! ## Models, one per file
//! - [`mission`]: the mission spec (what every mission source produces, the mission file) and its
//!   compilation into trajectory pieces; [`mission_toml`], its segments as TOML text for the
//!   missions tests and benches write in code;
//! - [`trajectory`]: closed-form kinematics (trapezoidal speed, lines, arcs, holds);
//! - [`wind`]: constant, power-law and logarithmic profiles, gridded field, seeded gusts;
//! - [`trim`]: thrust vector from the force balance, attitude, electrical power;
//! - [`envelope`]: the flight envelope (tilt, thrust, airspeed, climb and descent rates) as a
//!   limit the vehicle flies at: where the plan asks for more, the same path slower;
//! - [`ground_effect`]: survey seed eq (35);
//! - [`battery`]: the pack model: charge counting, open-circuit voltage, resistance, cut-off;
//! - [`pack_cursor`]: the pack model followed through a discharge, a block of steps at a time;
//! - [`mod@plan`]: the sampled flight, feasibility, point of no return, summary, in named parts
//!   (`plan/`, in the order data flows): `sampler.rs` (pass A: kinematics, wind, trim, power and
//!   limits of each block of samples), `feed.rs` (the blocks to the pack pass, from a second
//!   thread or in line), the pack pass itself in `mod.rs`, `ledger.rs` (energy, heat, peaks,
//!   voltage and state of charge per segment and per mission), `return_check.rs` (the point of no
//!   return), `report.rs` (the options and the report types);
//! - [`queries`]: endurance and range;
//! - [`mod@replay`]: the energy of a recorded trajectory through the same physics;
//! - [`sorties`]: a route cut into sorties: where a sortie may end, the mission it flies, how far
//!   back the next resumes, and the searches for the farthest end a trial flight still holds.
//!
//! ## Fast paths
//! A mission of an hour at 10 ms is 360,000 samples, so the loop has fast paths. Each is kept
//! beside a plain reference and tested against it bit for bit:
//! - **Block trims in vector lanes**: [`Powered::trim_block`] runs the force balance of a block
//!   of samples in `trim::balance_block` (`#[multiversion]` AVX2 and AVX-512 builds), then the
//!   four-term model's batch path. Reference: [`Powered::trim`] of each sample. Test:
//!   `plan::sampler::tests::block_trims_are_the_per_sample_trims_bit_for_bit` (every sample of a
//!   survey in calm, steady and gusty wind); the batch power path on its own in `aloft-power`,
//!   `four_term::tests::conditions_in_a_batch_equal_single_evaluations`.
//! - **Hoisting of steady stretches** (`plan/sampler.rs`): on a level line or a hold at cruise in
//!   a steady wind that depends on height alone, one trim per stretch, and ground effect once per
//!   piece at a fixed height. Reference: every sample through the block path
//!   (`plan_with(.., hoist = false, ..)`). Test:
//!   `plan::sampler::tests::hoisting_steady_stretches_matches_the_per_sample_report` (the whole
//!   report, samples included, in four winds, with and without ground effect).
//! - **The pack cursor** ([`pack_cursor`]): [`PackCursor::draw`] keeps the open-circuit table's
//!   interval between steps. Reference: [`Pack::draw`]. Test:
//!   `pack_cursor::tests::cursor_draws_what_draw_draws_bit_for_bit_across_a_discharge`.
//!   [`PackCursor::draw_block`] solves a block of 64 steps by fixed-point sweeps in vector lanes
//!   (`#[multiversion]`), accepted only when a sweep gives the previous sweep's currents bit for
//!   bit, else flown step by step. Reference: [`PackCursor::draw`] then
//!   [`PackCursor::discharge`], step by step. Test:
//!   `pack_cursor::tests::draw_block_is_the_step_by_step_discharge_bit_for_bit`.
//! - **The second thread** (`plan/feed.rs`, [`PlanOptions::second_thread`]): pass A runs on a
//!   scoped thread ahead of the pack pass on missions of 4096 steps or more. Reference: pass A in
//!   line. Test: `plan::feed::tests::pass_a_on_its_own_thread_gives_the_same_report` (a mission
//!   that completes, one whose pack runs out, one that pass A stops with an error).
//!
//! Two departures from the sample-by-sample loop are not bit for bit, and are bounded instead: on
//! an arc's cruise [`trajectory::BlockSampler`] turns the position by a rotation table instead of
//! `sincos` of a large angle (positions to 1e-10 m over 3400 s of orbit,
//! `trajectory::block_tests::block_sampler_matches_piece_at_on_a_long_orbit`), and the pack's
//! charge step is `I (h / Q)` instead of `I h / Q`; the plan's samples agree with per-sample
//! [`Powered::trim`] and [`Pack::draw`] to 1e-9 relative
//! (`plan::tests::block_passes_match_the_sample_by_sample_trim`).
//!
//! The power comes from `aloft-power` (the four-term model of the power seed) or from the
//! propulsion chain of `aloft-propulsion`. The crate does no I/O: it takes text or data and
//! returns results or a [`PlannerError`].
//!
//! ```
//! use aloft_planner::*;
//! # fn main() -> Result<(), PlannerError> {
//! let airframe = Airframe::new(AirframeSpec {
//!     mass_kg: 1.755, max_takeoff_mass_kg: 3.6, max_thrust_n: None, max_tilt_deg: 35.0,
//!     max_speed_mps: 17.0, max_airspeed_mps: None, max_climb_rate_mps: 5.0,
//!     max_descent_rate_mps: 4.0,
//!     acceleration_mps2: 2.0, vertical_acceleration_mps2: 1.5, yaw_rate_deg_s: 60.0,
//!     rotor_height_m: 0.3,
//!     acceptance_radius_m: None,
//!     cruise_speed_mps: None,
//!     rtl_altitude_m: None,
//! })?;
//! let vehicle = aloft_power::Vehicle::new(aloft_power::VehicleParams {
//!     mass_kg: 3.29, gravity_mps2: 9.8066, air_density_kg_m3: 1.225, rotor_count: 4,
//!     rotor_radius_m: 0.172, disk_area: aloft_power::DiskArea::OneRotor,
//!     mu1_n_s_per_m: 0.1816, mu2_n_s2_per_m2: -0.02326, mu3_n_s3_per_m3: 0.004045,
//!     kappa1_w_per_n1_5: 0.275, kappa2_w_s2_per_m2_n0_5: 0.0, efficiency: 0.9703,
//!     mu2_x_n_s2_per_m2: None, mu2_y_n_s2_per_m2: None, efficiency_relative_sd: None,
//! })?;
//! let aircraft = Aircraft::four_term(airframe, vehicle, Default::default());
//! let battery = Pack::new(&BatterySpec {
//!     name: "TB47D".into(), default: true, cells_series: 6, capacity_mah: 4500.0,
//!     nominal_v: Some(22.2), energy_wh: Some(99.9), mass_kg: Some(0.6),
//!     internal_resistance_ohm: Some(0.048), cutoff_cell_v: Some(3.0),
//!     ..BatterySpec::default()
//! })?;
//! let mission = MissionSpec::from_toml_str(r#"
//!     [[segment]]
//!     kind = "take-off"
//!     altitude_m = 20.0
//!     climb_rate_mps = 2.0
//!     [[segment]]
//!     kind = "leg"
//!     east_m = 300.0
//!     north_m = 0.0
//!     ground_speed_mps = 8.0
//!     [[segment]]
//!     kind = "return"
//!     ground_speed_mps = 8.0
//!     [[segment]]
//!     kind = "landing"
//!     rate_mps = 1.0
//! "#)?.compile(aircraft.airframe(), battery.mass_kg(), None)?;
//! let report = plan(&aircraft, &battery, &mission, &Wind::constant(5.0, 270.0)?,
//!                   &PlanOptions::default())?;
//! assert!(report.feasible && report.energy_wh > 0.0);
//! # Ok(()) }
//! ```

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod aircraft;
pub mod airframe;
pub mod battery;
pub mod envelope;
pub mod error;
pub mod geodesy;
pub mod ground_effect;
pub mod mission;
pub mod mission_toml;
pub mod pack_cursor;
pub mod percentiles;
pub mod plan;
pub mod queries;
pub mod replay;
pub mod sorties;
pub mod trajectory;
pub mod trim;
pub mod wind;

pub use aircraft::{Aircraft, PowerSource, Powered};
pub use airframe::{Airframe, AirframeSpec};
pub use aloft_power::AoaModel;
pub use battery::{BatterySpec, Pack, PackDraw};
pub use envelope::{Envelope, Limit};
pub use error::PlannerError;
pub use mission::{
    CornerMode, HomeSpec, Mission, MissionSpec, OrbitDirection, SegmentSpec, WindProfileKind,
    WindSpec,
};
pub use pack_cursor::{PackCursor, PackStep};
pub use percentiles::Percentiles;
pub use plan::{
    plan, plan_into, EdgeReport, MissionReport, NoProgressWhy, NoSamples, PlanOptions,
    PointOfNoReturn, Sample, SampleSink, SegmentReport, Shortfall, Stuck, DEFAULT_MAX_SAMPLES,
};
pub use queries::{
    best_range, best_range_within_limits, endurance, endurance_at_power_s, orbit_power_w,
    sweep_speed, BestRange, EnduranceQuery, EnduranceReport, SweepRow,
};
pub use replay::{differentiate_velocity, power_only_aircraft, replay, ReplayPoint, ReplayReport};
pub use trim::{attitude_rad, bank_rad, Trim, TRIM_BLOCK};
pub use wind::{Gusts, MeanWind, Profile as WindProfile, Wind, WindGrid};

#[cfg(test)]
mod test_support;
