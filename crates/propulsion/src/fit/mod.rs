//! Identification of model parameters from measured data with argmin (Nelder-Mead on plain
//! `Vec<f64>`). The data comes in as slices; reading files is the caller's job.
//!
//! * [`propeller`]: propeller coefficients from static tables (UIUC) and thrust-stand runs;
//! * [`motor`]: Kv, resistance and no-load current (or `K_1`, `K_2` of eq 8) from thrust-stand runs;
//! * [`battery`]: `r_1..r_3` of eq (17) from current / voltage-drop pairs;
//! * [`inertia`]: rotor inertia (and ESC delay) from a measured step response.
//!
//! Every result reports its root-mean-square residual.

pub mod battery;
pub mod inertia;
pub mod motor;
pub mod propeller;

use crate::error::PropulsionError;
use argmin::core::{CostFunction, Error as ArgminError, Executor, State};
use argmin::solver::neldermead::NelderMead;

struct Objective<F> {
    f: F,
}

impl<F: Fn(&[f64]) -> f64> CostFunction for Objective<F> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Self::Param) -> Result<Self::Output, ArgminError> {
        let c = (self.f)(p);
        // Nelder-Mead needs ordered costs: map non-finite values to a huge finite cost.
        Ok(if c.is_finite() { c } else { f64::MAX / 4.0 })
    }
}

/// Minimises `f` with Nelder-Mead from `x0`, initial simplex `x0 + step_i e_i`, restarting once
/// from the best point (a standard guard against premature simplex collapse).
pub(crate) fn minimize<F: Fn(&[f64]) -> f64>(
    model: &'static str,
    f: F,
    x0: &[f64],
    step: &[f64],
    max_iters: u64,
) -> Result<(Vec<f64>, f64), PropulsionError> {
    let mut x = x0.to_vec();
    let mut best = f64::INFINITY;
    let objective = Objective { f };
    for round in 0..2 {
        let scale = if round == 0 { 1.0 } else { 0.1 };
        let mut simplex = vec![x.clone()];
        for (i, s) in step.iter().enumerate() {
            let mut v = x.clone();
            v[i] += s * scale;
            simplex.push(v);
        }
        let solver = NelderMead::new(simplex)
            .with_sd_tolerance(1e-14)
            .map_err(|_| PropulsionError::FitDidNotConverge { model })?;
        let res = Executor::new(Objective { f: &objective.f }, solver)
            .configure(|s| s.max_iters(max_iters))
            .run()
            .map_err(|_| PropulsionError::FitDidNotConverge { model })?;
        let state = res.state();
        let p = state
            .get_best_param()
            .cloned()
            .ok_or(PropulsionError::FitDidNotConverge { model })?;
        let c = state.get_best_cost();
        if c.is_finite() && c <= best {
            best = c;
            x = p;
        }
    }
    if !best.is_finite() || x.iter().any(|v| !v.is_finite()) {
        return Err(PropulsionError::FitDidNotConverge { model });
    }
    Ok((x, best))
}

/// Checks equal lengths and finite values.
pub(crate) fn check_columns(
    model: &'static str,
    columns: &[(&'static str, &[f64])],
    required: usize,
) -> Result<usize, PropulsionError> {
    let n = columns[0].1.len();
    for (name, c) in columns {
        if c.len() != n {
            return Err(PropulsionError::LengthMismatch {
                what: name,
                expected: n,
                found: c.len(),
            });
        }
        if let Some((index, &value)) = c.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(PropulsionError::NonFiniteData {
                what: name,
                index,
                value,
            });
        }
    }
    if n < required {
        return Err(PropulsionError::InsufficientData {
            model,
            points: n,
            required,
        });
    }
    Ok(n)
}

/// Root mean square of residuals.
pub fn rmse(residuals: impl IntoIterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for r in residuals {
        s += r * r;
        n += 1;
    }
    if n == 0 {
        0.0
    } else {
        (s / n as f64).sqrt()
    }
}
