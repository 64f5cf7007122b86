//! Identification of the model's parameters from flight data, with argmin and nalgebra.
//!
//! - [`power`]: the lumped constants of the four-term model from measured electrical power
//!   (Gauss-Newton, analytic Jacobian, outlier rejection, standard errors, identifiability checks);
//! - [`drag`]: the cubic drag of eq (6) per unit mass from the force balance (attitude,
//!   acceleration and air velocity), as the power seed fits its drag (Fig. 3);
//! - [`body_drag`]: the quadratic drag coefficient per body axis (forward, right) from the same
//!   force balance, kept only where the data separates the two;
//! - [`bounded`]: both fits kept physical (efficiency at most 1, drag never negative) and
//!   limited to what the data identifies, saying which constants were fitted and which kept.

pub mod body_drag;
pub mod bounded;
pub mod drag;
pub mod power;

pub use body_drag::{fit_body_axis_drag, BodyAxisDragFit, BodyAxisRefusal};
pub use bounded::{
    fit_drag_bounded, fit_power_model_bounded, BoundedDragFit, BoundedPowerFit, KeptParameter,
};
pub use drag::{fit_drag, DragFit, ForceSample};
pub use power::{
    fit_power_model, FitOptions, FitParameter, FitSample, FittedParameter, PowerFit, ProgressFn,
};

/// Median and robust standard deviation (1.4826 times the median absolute deviation) of
/// `values`: the outlier rule of both fits.
pub(crate) fn median_and_robust_sd(values: &[f64]) -> (f64, f64) {
    let mut sorted = values.to_vec();
    let median = median_of(&mut sorted);
    let mut deviations: Vec<f64> = values.iter().map(|x| (x - median).abs()).collect();
    (median, 1.4826 * median_of(&mut deviations))
}

/// The rows whose residual lies within `outlier_sigma` robust standard deviations of the median
/// residual: all of them when the residuals have no spread. The drag fits' one pass of outlier
/// rejection.
pub(crate) fn within_robust_sd<T: Copy>(
    rows: &[T],
    residuals: &[f64],
    outlier_sigma: f64,
) -> Vec<T> {
    let (median, robust_sd) = median_and_robust_sd(residuals);
    rows.iter()
        .zip(residuals)
        .filter(|(_, r)| robust_sd <= 0.0 || (**r - median).abs() <= outlier_sigma * robust_sd)
        .map(|(row, _)| *row)
        .collect()
}

/// Median of `v` (sorts it); 0 when empty.
fn median_of(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}
