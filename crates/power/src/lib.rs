//! # aloft-power: the four-term multirotor power model
//!
//! A white-box model of the electrical power a multirotor draws in any flight state, after
//! "A Model of Quadrotor UAV Power Consumption and Its Performance Across a Range of Flight
//! Conditions" (the power seed, `shared/seeds/power-consumption-model.txt`). Equation numbers in
//! this crate are that paper's.
//!
//! `P_hat = (P_ind + P_par + P_pro + P_c) / eta` (7, 14) with
//! - induced power `P_ind = T (v_i + v_inf sin a)` (8), `v_i` from the quartic of eq (9)
//!   ([`induced`]), `vh` from eq (10);
//! - parasitic power `P_par = f_D v_inf` (11) with cubic drag (6) ([`drag`]);
//! - profile power `P_pro = kappa1 T^1.5 + kappa2 (v_inf cos a)^2 T^0.5` (12) ([`profile`]);
//! - climb power `P_c = v_z m g` (13) ([`climb`]);
//! - thrust `T = m g / (cos phi cos theta)` (5) for a point query, or given by the caller.
//!
//! Angle of attack: the paper's approximation (3)-(4) or exact geometry ([`angle_of_attack`]).
//!
//! ## Layout
//! One model per file; the machinery that makes them fast lives apart, in `kernels/`.
//! - [`four_term`]: the model, eqs (5), (7), (14): its types ([`FlightState`],
//!   [`FlightCondition`], [`PowerBreakdown`], [`Terms`], [`ModelOptions`], [`AoaInput`]), the
//!   plain evaluation and the terms;
//! - [`induced`]: induced velocity and power, eqs (8)-(10);
//! - `quartic.rs` (private): the solver of eq (9)'s normalised quartic (start, Halley steps, the
//!   branch-free fast path, the safeguarded fallback);
//! - [`drag`]: cubic drag (6) and parasitic power (11);
//! - [`profile`]: profile power (12);
//! - [`climb`]: climb power (13);
//! - [`angle_of_attack`]: the inflow from the paper's eqs (3)-(4) or exact geometry;
//! - [`vehicle`]: the validated vehicle, with the disk area of eq (10);
//! - [`efficiency`]: `eta` of eq (14) from measured power (section IV-E and a calibration);
//! - [`gradient`]: the analytic gradient of the electrical power (section VI-B);
//! - [`metrics`]: RMSE and NRMSE, as the paper's Table I scores a model;
//! - [`fit`]: identification: the lumped constants from measured power, drag (6) from the force
//!   balance;
//! - [`error`]: [`PowerError`] and [`FitError`];
//! - `kernels/` (private): the fast paths below, each beside the plain version it must equal.
//!
//! ## Fast paths
//! Each fast path does the plain version's IEEE operations in the same order and is tested
//! against it bit for bit (details in `kernels/mod.rs`, "advice for hackers"):
//! - [`PowerModel::evaluate`]: a run-time dispatched AVX2 build (`kernels/dispatch.rs`) of the
//!   plain `PowerModel::evaluate_inline` (`four_term.rs`); test
//!   `kernels::dispatch::tests::dispatched_point_queries_equal_the_baseline_build`.
//! - [`PowerModel::evaluate_batch`], [`PowerModel::evaluate_conditions`],
//!   [`PowerModel::electrical_of_conditions`]: passes over blocks, the quartic and the terms in
//!   vector lanes (`kernels/batch.rs`, `kernels/lanes.rs`), against [`PowerModel::evaluate`] and
//!   [`PowerModel::evaluate_condition`] one at a time; tests
//!   `kernels::batch::tests::batch_equals_single_evaluations_bit_for_bit` and
//!   `kernels::batch::tests::conditions_in_a_batch_equal_single_evaluations`.
//! - The quartic's branch-free `solve_normalised_fast` (`quartic.rs`, run in the lanes) against
//!   the checked `solve_normalised`; tests
//!   `quartic::tests::scalar_and_lane_solvers_return_the_same_root` and
//!   `quartic::tests::settled_first_step_meets_the_residual_bound`.
//! - `sin_cos` (`kernels/trig.rs`): polynomials within +-45 deg. Not a copy of a plain version
//!   but part of the model's numbers (every path uses it); held within 2 ulp of the standard
//!   library by `kernels::trig::tests`.
//!
//! ## Frames and units
//! SI everywhere, angles in radians, the unit in every name. Attitude is roll/pitch/yaw of a
//! forward-right-down body relative to north-east-down (positive pitch nose up, as the paper's
//! Fig. 2); vectors returned for missions are east-north-up. Vertical speed is positive up.
//!
//! The crate does no I/O: it takes plain data and returns results or a [`PowerError`].
//!
//! ```
//! use aloft_power::{DiskArea, FlightState, PowerModel, Vehicle, VehicleParams};
//! let vehicle = Vehicle::new(VehicleParams {
//!     mass_kg: 3.29, gravity_mps2: 9.8066, air_density_kg_m3: 1.225, rotor_count: 4,
//!     rotor_radius_m: 0.172, disk_area: DiskArea::OneRotor, mu1_n_s_per_m: 0.1816,
//!     mu2_n_s2_per_m2: -0.02326, mu3_n_s3_per_m3: 0.004045, kappa1_w_per_n1_5: 0.275,
//!     kappa2_w_s2_per_m2_n0_5: 0.0, efficiency: 0.8,
//!     mu2_x_n_s2_per_m2: None, mu2_y_n_s2_per_m2: None, efficiency_relative_sd: None,
//! })?;
//! let model = PowerModel::new(vehicle);
//! let p = model.evaluate(&FlightState::new(6.0, 0.0, -8f64.to_radians(), 0.0))?;
//! assert!(p.electrical_w > p.aero_w);
//! # Ok::<(), aloft_power::PowerError>(())
//! ```

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod angle_of_attack;
pub mod climb;
pub mod drag;
pub mod efficiency;
pub mod error;
pub mod fit;
pub mod four_term;
pub mod gradient;
pub mod induced;
mod kernels;
pub mod metrics;
pub mod profile;
mod quartic;
pub mod vehicle;

pub use angle_of_attack::{AoaModel, Inflow};
pub use drag::CubicDrag;
pub use efficiency::{calibrate_efficiency, efficiency_from_hover, mean_power_w};
pub use error::{FitError, PowerError, Result};
pub use fit::{
    fit_drag, fit_power_model, DragFit, FitOptions, FitParameter, FitSample, ForceSample, PowerFit,
};
pub use four_term::{
    AoaInput, FlightCondition, FlightState, ModelOptions, PowerBreakdown, PowerModel, Term, Terms,
};
pub use gradient::PowerGradient;
pub use metrics::{nrmse, rmse, Normalisation};
pub use vehicle::{DiskArea, Vehicle, VehicleParams};
