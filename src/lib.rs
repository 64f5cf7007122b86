//! # aloft
//!
//! What a multirotor flight costs in energy and whether it can be flown. This crate is the facade
//! over the model crates and the home of the vehicle file format; the `aloft` binary is a thin
//! command line over it.
//!
//! - [`power`]: the four-term power model (`aloft-power`).
//! - [`propulsion`]: the propulsion chain (`aloft-propulsion`).
//! - [`vehicle`]: vehicle files (TOML) and the built-in vehicles.
//! - [`engine`]: the embedding facade for ground stations (vehicles, power, missions, endurance,
//!   in-flight efficiency re-estimate); the C ABI of `aloft-ffi` wraps it.
//! - [`identify`]: flight logs to the power model: lag alignment, fit samples, validation.
//! - [`terrain`]: the ground under a flight from elevation tiles read offline (`aloft-terrain`).
//!
//! ```
//! // The power seed's M100 at the paper's 3.29 kg hovers on 400-600 W (its Fig. 4).
//! let file = aloft::vehicle::VehicleFile::builtin("dji-m100-paper")?;
//! let model = aloft::power::PowerModel::new(file.power_vehicle()?);
//! let hover = model.evaluate(&aloft::power::FlightState::new(0.0, 0.0, 0.0, 0.0))?;
//! assert!(hover.electrical_w > 400.0 && hover.electrical_w < 600.0);
//! // The aircraft missions fly: airframe + pack + payload (DJI: 2355 g with the TB47D).
//! let m100 = aloft::engine::Vehicle::builtin("dji-m100")?;
//! assert!((m100.takeoff_mass(Some("TB47D"), 0.0)?.total_kg - 2.355).abs() < 1e-12);
//! # Ok::<(), aloft::Error>(())
//! ```

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod engine;
pub mod error;
pub mod identify;
pub mod recalibration;
pub mod vehicle;

pub use aloft_power as power;
pub use aloft_propulsion as propulsion;
pub use engine::terrain;
pub use engine::{
    endurance, mission_summary, plan_mission, plan_mission_in, EnduranceOptions, EnduranceSummary,
    InFlightEstimator, Mission, MissionOptions, MissionSummary, Plan, Vehicle,
};
pub use error::Error;
