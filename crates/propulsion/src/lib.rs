//! `aloft-propulsion`: the propulsion chain of an electric multirotor — propeller, brushless
//! motor, ESC, LiPo pack — from a required thrust to pack current, heat and flight duration, plus
//! rotor transients and identification of the model parameters from measured data.
//!
//! Sources (kept in `../shared/seeds/`):
//! * `propulsion-system-design.txt` ("Design of an Electric Propulsion System for a Quadrotor
//!   UAV", DOI 10.2514/1.38409), called *the propulsion seed*; equation numbers without a prefix
//!   refer to it;
//! * `rotor-transient-response.txt` ("Analysis of the Transient Response of UAV Rotors"), called
//!   *the transient seed*.
//!
//! Conventions: SI `f64` everywhere inside with the unit in the name (`thrust_n`, `speed_rpm`,
//! `speed_radps`, `capacity_ah`); rotor speeds are in rpm where the seed works in rpm (motor,
//! propeller, operating point) and in rad/s for the transient model. The crate does no I/O and
//! never prints; every constructor validates its input and returns [`PropulsionError`].
//! There are no frames: every quantity is a magnitude along the rotor axis.
//!
//! Models, one per file: [`propeller`], [`motor`], [`esc`], [`battery`], [`operating_point`],
//! [`transient`]; serde input specs in [`spec`]; parameter identification with argmin in [`fit`].

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod battery;
pub mod battery_spec;
pub mod error;
pub mod esc;
pub mod fit;
pub mod motor;
pub mod operating_point;
pub mod propeller;
pub mod spec;
pub mod transient;

pub use battery::{Battery, BatteryConstants, Eq17Resistance, InternalResistance, OcvCurve};
pub use battery_spec::BatterySpec;
pub use error::PropulsionError;
pub use esc::Esc;
pub use motor::{Motor, RotationalLoss};
pub use operating_point::{mass_range_kg, HoverResult, PropulsionSystem, RotorOperatingPoint};
pub use propeller::Propeller;
pub use spec::{rotor_step_response, PropulsionSpec, RotorSpec};
pub use transient::{
    EscProtocol, RotorConstants, RotorTransient, RotorTransientResult, StepMetrics, StepResponse,
};
