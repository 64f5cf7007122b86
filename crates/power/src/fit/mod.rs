//! Identification of the model's parameters from flight data, with argmin and nalgebra.
//!
//! - [`power`]: the lumped constants of the four-term model from measured electrical power
//!   (Gauss-Newton, analytic Jacobian, outlier rejection, standard errors, identifiability checks);
//! - [`drag`]: the cubic drag of eq (6) per unit mass from the force balance (attitude,
//!   acceleration and air velocity), as the power seed fits its drag (Fig. 3).

pub mod drag;
pub mod power;

pub use drag::{fit_drag, DragFit, ForceSample};
pub use power::{
    fit_power_model, FitOptions, FitParameter, FitSample, FittedParameter, PowerFit, ProgressFn,
};
