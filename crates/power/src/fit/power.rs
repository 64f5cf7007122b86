//! Identification of the power-model parameters from measured electrical power.
//!
//! # What the data can identify
//! Write `W = m g`, `c = cos(phi) cos(theta)` and `x = v_i / vh` (the normalised root of eq 9).
//! Eqs (5)-(14) divided by `eta` depend on the parameters only through six lumped constants:
//!
//! `P = K/c (vh x(Vn/vh, Vp/vh) + Vn) + k_p / c^1.5 + d1 v^2 + d2 v^3 + d3 v^4 + K v_z`
//!
//! With the geometric angle of attack the drag terms cancel: eq (8)'s `T Vn` already holds the
//! drag work through the measured attitude ([`crate::four_term`], "Deviation"), so power does not
//! identify drag. Fit drag from the force balance with [`super::drag`] instead; asking this fit
//! for a drag constant on geometric samples is refused ([`FitError::DragNotInPower`]).
//!
//! | constant | meaning | unit |
//! |---|---|---|
//! | `K = W / eta` | weight over efficiency | N |
//! | `vh` | hover induced velocity, eq (10) | m/s |
//! | `k_p = kappa1 W^1.5 / eta` | profile power at hover, electrical | W |
//! | `d_k = mu_k / eta` | electrical drag coefficients | N s^k/m^k |
//!
//! (`kappa2` is held at the template's value.) Mass, rotor radius and efficiency are not separately
//! identifiable from power: with the template's mass `m`, the fitted constants map back to
//! `eta = W/K`, the rotor radius from `vh` through eq (10), `mu_k = d_k eta` and
//! `kappa1 = k_p eta / W^1.5`. For a vehicle of known geometry `vh` is held fixed (and eta is then
//! the physical efficiency); for one of unknown mass or rotor size `vh` is freed.
//!
//! # Method
//! Nonlinear least squares on the residuals `P_model - P_measured`, all samples weighted equally,
//! by Gauss-Newton with a backtracking (Armijo) line search (argmin), with the analytic Jacobian
//! (implicit differentiation of the quartic for `x`). `K` and `vh` are fitted as logarithms (they
//! stay positive); the others are scaled to the mean measured power. Outliers: after a first fit,
//! samples whose residual is more than `outlier_sigma` robust standard deviations
//! (1.4826 x median absolute deviation) from the median residual are dropped and the fit is
//! repeated; the count is reported. Standard errors: `sigma^2 (J^T J)^-1` with
//! `sigma^2 = SSR/(n - p)` at the solution. A parameter is refused ([`FitError::NotIdentifiable`])
//! when its standard error exceeds `max_relative_std_error` times its magnitude, or the information
//! matrix is singular along it; drag coefficients and a free `vh` are refused up front when the
//! data has too little forward flight ([`FitError::NoForwardFlight`]).

use std::sync::Arc;

use argmin::core::{Executor, Jacobian, Operator, State};
use argmin::solver::gaussnewton::GaussNewtonLS;
use argmin::solver::linesearch::condition::ArmijoCondition;
use argmin::solver::linesearch::BacktrackingLineSearch;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::angle_of_attack::AoaModel;
use crate::error::FitError;
use crate::four_term::{resolve_point, FlightState};
use crate::quartic::solve_normalised;
use crate::vehicle::{DiskArea, Vehicle, VehicleParams};

/// One measured sample: the flight state and the measured electrical power.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitSample {
    /// Flight state (airspeed, attitude, climb rate, angle-of-attack model).
    pub state: FlightState,
    /// Measured electrical power, W.
    pub measured_power_w: f64,
    /// The sample's take-off mass over the template's (1: the template's mass). A flight that
    /// carried a payload flies at `mass_ratio` > 1: its thrust scales with the mass, `vh` with its
    /// square root (eq 10) and the profile power `kappa1 T^1.5` with its 1.5th power, so the
    /// lumped constants stay those of the template's mass (module docs).
    pub mass_ratio: f64,
}

impl FitSample {
    /// A sample of a flight at the template's mass.
    pub fn new(state: FlightState, measured_power_w: f64) -> Self {
        Self {
            state,
            measured_power_w,
            mass_ratio: 1.0,
        }
    }
}

/// A lumped constant of the fit (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FitParameter {
    /// `K = m g / eta`, N.
    WeightOverEfficiency,
    /// `vh`, m/s.
    HoverInducedVelocity,
    /// `k_p = kappa1 W^1.5 / eta`, W.
    Profile,
    /// `d1 = mu1 / eta`.
    Mu1,
    /// `d2 = mu2 / eta`.
    Mu2,
    /// `d3 = mu3 / eta`.
    Mu3,
}

impl FitParameter {
    /// All constants, in vector order.
    pub const ALL: [FitParameter; 6] = [
        FitParameter::WeightOverEfficiency,
        FitParameter::HoverInducedVelocity,
        FitParameter::Profile,
        FitParameter::Mu1,
        FitParameter::Mu2,
        FitParameter::Mu3,
    ];

    /// Name used in reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            FitParameter::WeightOverEfficiency => "weight_over_efficiency_n",
            FitParameter::HoverInducedVelocity => "hover_induced_velocity_mps",
            FitParameter::Profile => "profile_hover_w",
            FitParameter::Mu1 => "mu1_over_eta_n_s_per_m",
            FitParameter::Mu2 => "mu2_over_eta_n_s2_per_m2",
            FitParameter::Mu3 => "mu3_over_eta_n_s3_per_m3",
        }
    }

    /// Unit of the constant.
    pub fn unit(self) -> &'static str {
        match self {
            FitParameter::WeightOverEfficiency => "N",
            FitParameter::HoverInducedVelocity => "m/s",
            FitParameter::Profile => "W",
            FitParameter::Mu1 => "N s/m",
            FitParameter::Mu2 => "N s^2/m^2",
            FitParameter::Mu3 => "N s^3/m^3",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// A progress callback: iteration number and current cost (norm of the residuals, W).
pub type ProgressFn = Arc<dyn Fn(u64, f64) + Send + Sync>;

/// Options of [`fit_power_model`].
#[derive(Clone)]
pub struct FitOptions {
    /// The constants to fit; the others keep the template's values.
    pub free: Vec<FitParameter>,
    /// Outlier threshold in robust standard deviations; `None` keeps every sample.
    pub outlier_sigma: Option<f64>,
    /// Largest accepted standard error relative to the value.
    pub max_relative_std_error: f64,
    /// Gauss-Newton iteration limit per pass.
    pub max_iterations: u64,
    /// Airspeed above which a sample counts as forward flight, m/s.
    pub forward_flight_mps: f64,
    /// Called after each iteration.
    pub progress: Option<ProgressFn>,
}

impl std::fmt::Debug for FitOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FitOptions")
            .field("free", &self.free)
            .field("outlier_sigma", &self.outlier_sigma)
            .field("max_relative_std_error", &self.max_relative_std_error)
            .field("max_iterations", &self.max_iterations)
            .field("forward_flight_mps", &self.forward_flight_mps)
            .finish()
    }
}

impl FitOptions {
    /// Known mass and rotor size: fit `K` (hence eta), the profile constant and the drag.
    pub fn known_geometry() -> Self {
        Self {
            free: vec![
                FitParameter::WeightOverEfficiency,
                FitParameter::Profile,
                FitParameter::Mu1,
                FitParameter::Mu2,
                FitParameter::Mu3,
            ],
            outlier_sigma: Some(5.0),
            max_relative_std_error: 1.0,
            max_iterations: 50,
            forward_flight_mps: 3.0,
            progress: None,
        }
    }

    /// Unknown mass or rotor size: also free `vh`.
    pub fn unknown_geometry() -> Self {
        let mut o = Self::known_geometry();
        o.free.insert(1, FitParameter::HoverInducedVelocity);
        o
    }

    /// These options without `parameter` (held at the template's value).
    pub fn without(mut self, parameter: FitParameter) -> Self {
        self.free.retain(|&p| p != parameter);
        self
    }
}

/// One fitted constant with its standard error.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedParameter {
    /// Name (see [`FitParameter::name`]).
    pub name: &'static str,
    /// Fitted value.
    pub value: f64,
    /// Standard error from the Jacobian at the solution.
    pub std_error: f64,
    /// Unit.
    pub unit: &'static str,
}

/// The result of a fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PowerFit {
    /// The template's power parameters with the fitted values mapped back.
    pub vehicle: VehicleParams,
    /// The free constants with standard errors.
    pub parameters: Vec<FittedParameter>,
    /// Root-mean-square residual over the samples used, W.
    pub rmse_w: f64,
    /// RMSE over the mean measured power of the samples used (a fraction).
    pub nrmse: f64,
    /// Samples used in the final pass.
    pub samples_used: usize,
    /// Samples dropped as outliers.
    pub outliers_rejected: usize,
    /// Gauss-Newton iterations, both passes.
    pub iterations: u64,
}

/// Per-sample quantities that do not depend on the parameters.
#[derive(Debug, Clone, Copy)]
struct Pre {
    inv_c: f64,
    inv_c15: f64,
    vn: f64,
    vp: f64,
    v2: f64,
    v: f64,
    vz: f64,
    measured: f64,
    /// 1 with the paper's AoA (eq 11 adds drag work), 0 with the geometric one (drag work is in
    /// `T Vn` through the attitude).
    drag_weight: f64,
    /// Take-off mass over the template's ([`FitSample::mass_ratio`]), and its square root and
    /// 1.5th power.
    mass_ratio: f64,
    sqrt_mass_ratio: f64,
    mass_ratio_15: f64,
}

/// Full lumped parameter vector in [`FitParameter::ALL`] order.
type Lumped = [f64; 6];

fn model_and_gradient(p: &Lumped, s: &Pre, want_gradient: bool) -> Option<(f64, Lumped)> {
    let [k, vh, kp, d1, d2, d3] = *p;
    // This sample's mass: K and the climb work scale with it, vh with its square root, the
    // profile power with its 1.5th power; drag does not depend on mass.
    let (r, sqrt_r, r15) = (s.mass_ratio, s.sqrt_mass_ratio, s.mass_ratio_15);
    let vh_s = vh * sqrt_r;
    let a = s.vn / vh_s;
    let b = s.vp / vh_s;
    let x = solve_normalised(a, b)?;
    let v = s.v;
    let induced = vh_s * x + s.vn;
    let power = k * r * s.inv_c * induced
        + kp * r15 * s.inv_c15
        + s.drag_weight * s.v2 * (d1 + v * (d2 + v * d3))
        + k * r * s.vz;
    if !want_gradient {
        return Some((power, [0.0; 6]));
    }
    // x(a, b) from g = x^2((x+a)^2 + b^2) - 1 = 0.
    let sx = x + a;
    let q = sx * sx + b * b;
    let g_x = 2.0 * x * (q + x * sx);
    let dx_da = -(2.0 * x * x * sx) / g_x;
    let dx_db = -(2.0 * x * x * b) / g_x;
    let grad = [
        r * (s.inv_c * induced + s.vz),
        k * r * s.inv_c * (x - a * dx_da - b * dx_db) * sqrt_r,
        r15 * s.inv_c15,
        s.drag_weight * s.v2,
        s.drag_weight * s.v2 * v,
        s.drag_weight * s.v2 * v * v,
    ];
    Some((power, grad))
}

/// The least-squares problem in scaled coordinates `u`.
struct Problem<'a> {
    samples: &'a [Pre],
    base: Lumped,
    free: &'a [FitParameter],
    scale: Lumped,
    /// For the profile and drag constants that are held: their lumped value per unit `K`
    /// (`kappa1 W^0.5`, `mu_k / W`), so the physical `kappa1`, `mu_k` stay the template's while
    /// `K` (hence eta) moves. 0 for free constants and for `K`, `vh`.
    tie: Lumped,
}

impl Problem<'_> {
    /// Lumped parameters from the scaled free vector (K and vh as logarithms).
    fn lumped(&self, u: &DVector<f64>) -> Lumped {
        let mut p = self.base;
        for (j, &f) in self.free.iter().enumerate() {
            let i = f.index();
            p[i] = match f {
                FitParameter::WeightOverEfficiency | FitParameter::HoverInducedVelocity => {
                    self.base[i] * u[j].exp()
                }
                _ => u[j] * self.scale[i],
            };
        }
        let k = p[FitParameter::WeightOverEfficiency.index()];
        for (value, &tie) in p.iter_mut().zip(&self.tie).skip(2) {
            if tie != 0.0 {
                *value = tie * k;
            }
        }
        p
    }

    /// Residuals and (optionally) the Jacobian in `u`.
    fn evaluate(&self, u: &DVector<f64>, jacobian: bool) -> (DVector<f64>, Option<DMatrix<f64>>) {
        let p = self.lumped(u);
        let n = self.samples.len();
        let mut r = DVector::zeros(n);
        let mut j = jacobian.then(|| DMatrix::zeros(n, self.free.len()));
        for (i, s) in self.samples.iter().enumerate() {
            match model_and_gradient(&p, s, jacobian) {
                Some((power, grad)) => {
                    r[i] = power - s.measured;
                    if let Some(j) = j.as_mut() {
                        for (col, &f) in self.free.iter().enumerate() {
                            let k = f.index();
                            j[(i, col)] = match f {
                                FitParameter::WeightOverEfficiency => {
                                    // K also moves the held constants tied to it.
                                    let tied: f64 = (2..6).map(|t| grad[t] * self.tie[t]).sum();
                                    (grad[k] + tied) * p[k]
                                }
                                FitParameter::HoverInducedVelocity => grad[k] * p[k],
                                _ => grad[k] * self.scale[k],
                            };
                        }
                    }
                }
                // No root continuous with hover at these parameters: a large residual steers the
                // line search away.
                None => r[i] = 1e6 + s.measured.abs(),
            }
        }
        (r, j)
    }
}

impl Operator for Problem<'_> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, u: &Self::Param) -> Result<Self::Output, argmin::core::Error> {
        Ok(self.evaluate(u, false).0)
    }
}

impl Jacobian for Problem<'_> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, u: &Self::Param) -> Result<Self::Jacobian, argmin::core::Error> {
        Ok(self.evaluate(u, true).1.expect("requested"))
    }
}

/// Fit the free lumped constants of `options` to `samples`, starting from `template`.
pub fn fit_power_model(
    template: &Vehicle,
    samples: &[FitSample],
    options: &FitOptions,
) -> Result<PowerFit, FitError> {
    let pre = precompute_samples(samples)?;
    let mut free = options.free.clone();
    free.dedup();
    check_data_identifies(&pre, &free, options)?;
    let coordinates = Coordinates::new(template, &pre, &free);
    let solved = solve_with_outlier_pass(&coordinates, &free, pre, options)?;
    let solution = standard_errors(
        &coordinates.problem(&solved.used, &free),
        &solved.u,
        options.max_relative_std_error,
    )?;
    let vehicle = params_from_lumped(template, &solution.lumped)?;
    let n = solved.used.len();
    let mean_used = solved.used.iter().map(|s| s.measured).sum::<f64>() / n as f64;
    let rmse_w = (solution.ssr / n as f64).sqrt();
    Ok(PowerFit {
        vehicle,
        parameters: solution.parameters,
        rmse_w,
        nrmse: rmse_w / mean_used,
        samples_used: n,
        outliers_rejected: solved.outliers,
        iterations: solved.iterations,
    })
}

/// Validate every sample and precompute what does not depend on the parameters.
fn precompute_samples(samples: &[FitSample]) -> Result<Vec<Pre>, FitError> {
    samples
        .iter()
        .enumerate()
        .map(|(index, s)| precompute_sample(index, s))
        .collect()
}

/// [`Pre`] of one sample (`index` names it in errors): its attitude and inflow resolved as the
/// model resolves a point query, its measured power finite and positive.
fn precompute_sample(index: usize, s: &FitSample) -> Result<Pre, FitError> {
    let (tilt_cos, inflow, aoa) = resolve_point(&s.state).map_err(|e| FitError::BadSample {
        index,
        message: e.to_string(),
    })?;
    if !(s.measured_power_w.is_finite() && s.measured_power_w > 0.0) {
        return Err(FitError::BadSample {
            index,
            message: format!(
                "measured_power_w must be finite and positive, got {}",
                s.measured_power_w
            ),
        });
    }
    let r = s.mass_ratio;
    if !(r.is_finite() && r > 0.0) {
        return Err(FitError::BadSample {
            index,
            message: format!("mass_ratio must be finite and positive, got {r}"),
        });
    }
    let st = s.state;
    let v = st.airspeed_mps;
    Ok(Pre {
        inv_c: 1.0 / tilt_cos,
        inv_c15: tilt_cos.powf(-1.5),
        vn: inflow.normal_mps,
        vp: inflow.parallel_mps,
        v2: v * v,
        v,
        vz: st.climb_rate_mps,
        measured: s.measured_power_w,
        drag_weight: match aoa {
            AoaModel::Paper => 1.0,
            AoaModel::Geometric => 0.0,
        },
        mass_ratio: r,
        sqrt_mass_ratio: r.sqrt(),
        mass_ratio_15: r * r.sqrt(),
    })
}

/// Refuse up front what the data cannot identify: too few samples for the free constants, drag
/// from samples whose power does not hold it (geometric angle of attack), and drag or a free `vh`
/// without enough forward flight.
fn check_data_identifies(
    pre: &[Pre],
    free: &[FitParameter],
    options: &FitOptions,
) -> Result<(), FitError> {
    let required = 10 * free.len().max(1);
    if pre.len() < required {
        return Err(FitError::TooFewSamples {
            samples: pre.len(),
            parameters: free.len(),
            required,
        });
    }
    // Forward flight is needed for drag and for the speed dependence that separates vh from K.
    let above = pre
        .iter()
        .filter(|s| s.v > options.forward_flight_mps)
        .count();
    let drag_in_power = pre.iter().filter(|s| s.drag_weight > 0.0).count();
    for &f in free {
        let drag = matches!(f, FitParameter::Mu1 | FitParameter::Mu2 | FitParameter::Mu3);
        if drag && drag_in_power * 2 < pre.len() {
            return Err(FitError::DragNotInPower {
                parameter: f.name(),
                geometric: pre.len() - drag_in_power,
                total: pre.len(),
            });
        }
        let speed_dependent = matches!(
            f,
            FitParameter::Mu1
                | FitParameter::Mu2
                | FitParameter::Mu3
                | FitParameter::HoverInducedVelocity
        );
        if speed_dependent && (above < 20 || above * 20 < pre.len()) {
            return Err(FitError::NoForwardFlight {
                parameter: f.name(),
                above,
                total: pre.len(),
                airspeed_mps: options.forward_flight_mps,
            });
        }
    }
    Ok(())
}

/// The fixed parts of the least-squares problem: where it starts, how its free coordinates are
/// scaled, and how held constants follow `K` (see [`Problem`]).
#[derive(Debug, Clone, Copy)]
struct Coordinates {
    base: Lumped,
    scale: Lumped,
    tie: Lumped,
}

impl Coordinates {
    /// The template's lumped constants, the scales from the samples' power and speed, and the
    /// ties of the held constants.
    fn new(template: &Vehicle, pre: &[Pre], free: &[FitParameter]) -> Self {
        Self {
            base: lumped_of_template(template),
            scale: scales(pre),
            tie: ties_to_k(template, free),
        }
    }

    /// The problem over `samples` with these coordinates.
    fn problem<'a>(&self, samples: &'a [Pre], free: &'a [FitParameter]) -> Problem<'a> {
        Problem {
            samples,
            base: self.base,
            free,
            scale: self.scale,
            tie: self.tie,
        }
    }

    /// The starting point in scaled coordinates: the template's values.
    fn start(&self, free: &[FitParameter]) -> DVector<f64> {
        DVector::from_iterator(
            free.len(),
            free.iter().map(|f| match f {
                FitParameter::WeightOverEfficiency | FitParameter::HoverInducedVelocity => 0.0,
                _ => self.base[f.index()] / self.scale[f.index()],
            }),
        )
    }
}

/// The template's lumped constants (module docs): `K = W/eta`, `vh`, `k_p`, `d_k = mu_k/eta`.
fn lumped_of_template(template: &Vehicle) -> Lumped {
    let v = template;
    let eta = v.efficiency();
    let w = v.weight_n();
    let (mu1, mu2, mu3) = v.drag().coefficients();
    [
        w / eta,
        v.hover_induced_velocity_mps(),
        v.kappa1() * w.powf(1.5) / eta,
        mu1 / eta,
        mu2 / eta,
        mu3 / eta,
    ]
}

/// Scales of the linear constants: the mean measured power, per power of the top speed for drag.
fn scales(pre: &[Pre]) -> Lumped {
    let mean_power = pre.iter().map(|s| s.measured).sum::<f64>() / pre.len() as f64;
    let vmax = pre.iter().map(|s| s.v).fold(1.0, f64::max);
    [
        1.0,
        1.0,
        mean_power,
        mean_power / vmax.powi(2),
        mean_power / vmax.powi(3),
        mean_power / vmax.powi(4),
    ]
}

/// Held profile and drag constants keep their physical value when K is free (see
/// [`Problem::tie`]): their lumped value per unit `K`; 0 for the rest.
fn ties_to_k(template: &Vehicle, free: &[FitParameter]) -> Lumped {
    let v = template;
    let w = v.weight_n();
    let (mu1, mu2, mu3) = v.drag().coefficients();
    let mut tie: Lumped = [0.0; 6];
    if free.contains(&FitParameter::WeightOverEfficiency) {
        let physical = [0.0, 0.0, v.kappa1() * w.sqrt(), mu1 / w, mu2 / w, mu3 / w];
        for (i, f) in FitParameter::ALL.iter().enumerate().skip(2) {
            if !free.contains(f) {
                tie[i] = physical[i];
            }
        }
    }
    tie
}

/// Where the fit ended: the scaled free vector, the samples kept, how many were dropped as
/// outliers, and the Gauss-Newton iterations of both passes.
struct Solved {
    u: DVector<f64>,
    used: Vec<Pre>,
    outliers: usize,
    iterations: u64,
}

/// Fit all samples; with [`FitOptions::outlier_sigma`], drop the outliers once and fit again
/// from there.
fn solve_with_outlier_pass(
    coordinates: &Coordinates,
    free: &[FitParameter],
    samples: Vec<Pre>,
    options: &FitOptions,
) -> Result<Solved, FitError> {
    let mut iterations = 0;
    let mut u = coordinates.start(free);
    let mut used = samples;
    let mut outliers = 0;
    for pass in 0..2 {
        let (best, taken) =
            gauss_newton(coordinates.problem(&used, free), &u, iterations, options)?;
        iterations += taken;
        u = best;
        let Some(sigma) = options.outlier_sigma.filter(|_| pass == 0) else {
            break;
        };
        // Drop outliers once, then refit.
        let Some(keep) = without_outliers(&coordinates.problem(&used, free), &u, sigma) else {
            break;
        };
        outliers = used.len() - keep.len();
        used = keep;
    }
    Ok(Solved {
        u,
        used,
        outliers,
        iterations,
    })
}

/// One Gauss-Newton run (argmin, backtracking line search) from `u`: the best parameters and the
/// iterations taken. `done` counts the iterations of earlier passes, for the progress callback.
fn gauss_newton(
    problem: Problem<'_>,
    u: &DVector<f64>,
    done: u64,
    options: &FitOptions,
) -> Result<(DVector<f64>, u64), FitError> {
    let (r0, _) = problem.evaluate(u, false);
    // argmin's Gauss-Newton line search measures cost as |r| but passes the gradient of
    // |r|^2 / 2 (J^T r), so Armijo's sufficient decrease is scaled by |r|: a full Gauss-Newton
    // step passes only for c <= 1/(2|r|), and with c = 1e-4 a fit of large residuals stalls at
    // its start. A tiny c keeps the test as "the cost must fall".
    let linesearch =
        BacktrackingLineSearch::new(ArmijoCondition::new(1e-12).map_err(|e| FitError::Solver {
            message: e.to_string(),
        })?);
    let solver = GaussNewtonLS::new(linesearch)
        .with_tolerance(1e-10 * r0.norm().max(1e-300))
        .map_err(|e| FitError::Solver {
            message: e.to_string(),
        })?;
    let mut executor = Executor::new(problem, solver)
        .configure(|s| s.param(u.clone()).max_iters(options.max_iterations));
    if let Some(cb) = &options.progress {
        executor = executor.add_observer(
            ProgressObserver {
                callback: cb.clone(),
                offset: done,
            },
            argmin::core::observers::ObserverMode::Always,
        );
    }
    let result = executor.run().map_err(|e| FitError::Solver {
        message: e.to_string(),
    })?;
    let state = result.state();
    let taken = state.get_iter();
    let best = state
        .get_best_param()
        .cloned()
        .ok_or_else(|| FitError::Solver {
            message: "no parameter returned".to_string(),
        })?;
    Ok((best, taken))
}

/// The samples of `problem` whose residual at `u` lies within `sigma` robust standard deviations
/// of the median residual; `None` when none is dropped (or the residuals have no spread).
fn without_outliers(problem: &Problem<'_>, u: &DVector<f64>, sigma: f64) -> Option<Vec<Pre>> {
    let (r, _) = problem.evaluate(u, false);
    let residuals: Vec<f64> = r.iter().copied().collect();
    let (median, robust_sd) = super::median_and_robust_sd(&residuals);
    if robust_sd <= 0.0 {
        return None;
    }
    let keep: Vec<Pre> = problem
        .samples
        .iter()
        .zip(r.iter())
        .filter(|(_, &ri)| (ri - median).abs() <= sigma * robust_sd)
        .map(|(s, _)| *s)
        .collect();
    (keep.len() < problem.samples.len()).then_some(keep)
}

/// The fitted constants at the solution: all six lumped values, the free ones with standard
/// errors, and the sum of squared residuals.
struct Solution {
    lumped: Lumped,
    parameters: Vec<FittedParameter>,
    ssr: f64,
}

/// Standard errors at `u`, `sigma^2 (J^T J)^-1` with `sigma^2 = SSR/(n - p)`; refuses a free
/// constant whose standard error exceeds `max_relative_std_error` times its magnitude (or is
/// infinite: the information matrix is singular along it).
fn standard_errors(
    problem: &Problem<'_>,
    u: &DVector<f64>,
    max_relative_std_error: f64,
) -> Result<Solution, FitError> {
    let (r, j) = problem.evaluate(u, true);
    let j = j.expect("requested");
    let n = problem.samples.len();
    let dof = (n - problem.free.len()).max(1);
    let ssr = r.norm_squared();
    let sigma2 = ssr / dof as f64;
    let info = j.transpose() * &j;
    let lumped = problem.lumped(u);
    let covariance = info.clone().try_inverse();
    let mut parameters = Vec::new();
    for (col, &f) in problem.free.iter().enumerate() {
        let k = f.index();
        let value = lumped[k];
        let var_u = covariance.as_ref().map_or(f64::INFINITY, |c| c[(col, col)]);
        let se_u = (sigma2 * var_u).max(0.0).sqrt();
        let std_error = match f {
            FitParameter::WeightOverEfficiency | FitParameter::HoverInducedVelocity => value * se_u,
            _ => se_u * problem.scale[k],
        };
        if !std_error.is_finite() || std_error > max_relative_std_error * value.abs() {
            return Err(FitError::NotIdentifiable {
                parameter: f.name(),
                value,
                std_error,
                unit: f.unit(),
            });
        }
        parameters.push(FittedParameter {
            name: f.name(),
            value,
            std_error,
            unit: f.unit(),
        });
    }
    Ok(Solution {
        lumped,
        parameters,
        ssr,
    })
}

/// Map the lumped constants back to the template's parameters (module docs): `eta = W/K`, the
/// rotor radius from `vh` through eq (10), `kappa1 = k_p eta / W^1.5`, `mu_k = d_k eta`.
fn params_from_lumped(template: &Vehicle, lumped: &Lumped) -> Result<VehicleParams, FitError> {
    let v = template;
    let w = v.weight_n();
    let [k, vh, kp, d1, d2, d3] = *lumped;
    let efficiency = w / k;
    if efficiency > 1.0 {
        return Err(FitError::EfficiencyAboveOne {
            efficiency,
            mass_kg: v.mass_kg(),
        });
    }
    let mut params = v.params().clone();
    params.efficiency = efficiency;
    let area = w / (2.0 * params.air_density_kg_m3 * vh * vh);
    let disks = match params.disk_area {
        DiskArea::OneRotor => 1.0,
        DiskArea::AllRotors => f64::from(params.rotor_count),
    };
    params.rotor_radius_m = (area / (disks * std::f64::consts::PI)).sqrt();
    params.kappa1_w_per_n1_5 = kp * efficiency / w.powf(1.5);
    params.mu1_n_s_per_m = d1 * efficiency;
    params.mu2_n_s2_per_m2 = d2 * efficiency;
    params.mu3_n_s3_per_m3 = d3 * efficiency;
    Ok(params)
}

struct ProgressObserver {
    callback: ProgressFn,
    offset: u64,
}

impl<I: State<Float = f64>> argmin::core::observers::Observe<I> for ProgressObserver {
    fn observe_iter(
        &mut self,
        state: &I,
        _kv: &argmin::core::KV,
    ) -> Result<(), argmin::core::Error> {
        (self.callback)(self.offset + state.get_iter(), state.get_cost());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::four_term::AoaInput;
    use crate::four_term::PowerModel;
    use crate::vehicle::tests::m100_params;

    /// The M100 with its efficiency set to `efficiency`.
    fn m100_with_efficiency(efficiency: f64) -> Vehicle {
        Vehicle::new(VehicleParams {
            efficiency,
            ..m100_params()
        })
        .unwrap()
    }

    /// Synthetic flights of a vehicle: hover, forward flight 0-14 m/s with the pitch that balances
    /// drag, turns with roll, climbs and descents.
    fn flights(truth: &Vehicle, noise_w: f64) -> Vec<FitSample> {
        flights_with(truth, noise_w, false)
    }

    /// As [`flights`]; `geometric` selects the exact angle of attack (drag then not in power).
    fn flights_with(truth: &Vehicle, noise_w: f64, geometric: bool) -> Vec<FitSample> {
        let model = PowerModel::new(truth.clone());
        let mut out = Vec::new();
        let mut seed = 12345u64;
        let mut rand = || {
            // xorshift: reproducible noise without a dependency.
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 1_000_000) as f64 / 1_000_000.0 - 0.5
        };
        for i in 0..3000 {
            let v = 14.0 * (f64::from(i % 300) / 300.0);
            let pitch = -(truth.drag().force_n(v) / truth.weight_n()).atan() + 0.05 * rand();
            let roll = 0.3 * rand();
            let climb = if i % 7 == 0 { 2.0 * rand() } else { 0.0 };
            let direction = 0.2 * rand();
            let state = FlightState {
                aoa: if geometric {
                    AoaInput::Geometric {
                        air_direction_rad: direction,
                    }
                } else {
                    AoaInput::Paper
                },
                ..FlightState::new(v, roll, pitch, climb)
            };
            let p = model.evaluate(&state).unwrap().electrical_w;
            out.push(FitSample::new(state, p + noise_w * 2.0 * rand()));
        }
        out
    }

    /// Flights at two masses (the template's and 1.4 times it, a payload): with each sample's
    /// `mass_ratio` the fit lands on the truth (eq 10's `vh ~ sqrt(m)`, eq 12's `T^1.5`); one
    /// mass for all, it cannot.
    #[test]
    fn per_sample_mass_recovers_the_truth_where_one_mass_cannot() {
        let truth = m100_with_efficiency(0.7);
        let heavy = truth.with_mass(1.4 * truth.mass_kg()).unwrap();
        let light_data = flights(&truth, 0.0);
        let heavy_data = flights(&heavy, 0.0);
        let mut data: Vec<FitSample> = light_data.iter().step_by(2).copied().collect();
        data.extend(heavy_data.iter().step_by(2).map(|s| FitSample {
            mass_ratio: 1.4,
            ..*s
        }));
        let start = m100_with_efficiency(0.9);
        let fit = fit_power_model(&start, &data, &FitOptions::known_geometry()).unwrap();
        assert!(
            (fit.vehicle.efficiency - 0.7).abs() < 1e-6,
            "{:?}",
            fit.vehicle
        );
        assert!((fit.vehicle.kappa1_w_per_n1_5 - 0.275).abs() < 1e-5);
        assert!(fit.rmse_w < 1e-6, "{}", fit.rmse_w);
        let one_mass: Vec<FitSample> = data
            .iter()
            .map(|s| FitSample {
                mass_ratio: 1.0,
                ..*s
            })
            .collect();
        // One mass for all: the profile constant runs negative (refused) or the residual stays.
        if let Ok(blind) = fit_power_model(&start, &one_mass, &FitOptions::known_geometry()) {
            assert!(
                blind.rmse_w > 10.0,
                "one mass fits too well: {}",
                blind.rmse_w
            );
        }
        let bad = FitSample {
            mass_ratio: 0.0,
            ..data[0]
        };
        let e = fit_power_model(&start, &[bad; 100], &FitOptions::known_geometry()).unwrap_err();
        assert!(e.to_string().contains("mass_ratio"), "{e}");
    }

    #[test]
    fn recovers_the_parameters_of_a_known_vehicle() {
        let truth = m100_with_efficiency(0.7);
        let data = flights(&truth, 0.0);
        // Start from a wrong template: eta 0.9, drag doubled, profile halved.
        let start = Vehicle::new(VehicleParams {
            efficiency: 0.9,
            mu1_n_s_per_m: 0.36,
            mu3_n_s3_per_m3: 0.008,
            kappa1_w_per_n1_5: 0.14,
            ..m100_params()
        })
        .unwrap();
        let fit = fit_power_model(&start, &data, &FitOptions::known_geometry()).unwrap();
        let p = &fit.vehicle;
        // Noise-free synthetic data: the fit must land on the truth to solver precision.
        assert!((p.efficiency - 0.7).abs() < 1e-6, "{p:?}");
        assert!((p.mu1_n_s_per_m - 0.1816).abs() < 1e-5, "{p:?}");
        assert!((p.kappa1_w_per_n1_5 - 0.275).abs() < 1e-5, "{p:?}");
        assert!(fit.rmse_w < 1e-6, "{}", fit.rmse_w);
        assert_eq!(fit.outliers_rejected, 0);
    }

    #[test]
    fn unknown_geometry_recovers_vh_and_outliers_are_dropped() {
        let truth = Vehicle::new(m100_params()).unwrap();
        let mut data = flights(&truth, 2.0);
        for s in data.iter_mut().step_by(100) {
            s.measured_power_w += 300.0; // 30 gross outliers
        }
        let start = Vehicle::new(VehicleParams {
            rotor_radius_m: 0.25,
            ..m100_params()
        })
        .unwrap();
        let fit = fit_power_model(&start, &data, &FitOptions::unknown_geometry()).unwrap();
        assert_eq!(fit.outliers_rejected, 30);
        let vh = fit
            .parameters
            .iter()
            .find(|p| p.name == "hover_induced_velocity_mps")
            .unwrap();
        let true_vh = truth.hover_induced_velocity_mps();
        // Uniform noise of +-2 W on ~500 W: vh to within 3 standard errors, and the SE is small.
        assert!(
            (vh.value - true_vh).abs() < 3.0 * vh.std_error + 1e-9,
            "{vh:?} vs {true_vh}"
        );
        assert!(vh.std_error < 0.02 * true_vh);
        assert!(
            (fit.vehicle.rotor_radius_m - 0.172).abs() < 0.01,
            "{}",
            fit.vehicle.rotor_radius_m
        );
        // The noise is uniform on +-2 W: its RMS is 2/sqrt(3) = 1.155 W.
        assert!((fit.rmse_w - 1.155).abs() < 0.1, "{}", fit.rmse_w);
    }

    #[test]
    fn hover_only_data_refuses_drag() {
        let truth = Vehicle::new(m100_params()).unwrap();
        let data: Vec<FitSample> = flights(&truth, 1.0)
            .into_iter()
            .filter(|s| s.state.airspeed_mps < 1.0)
            .collect();
        let e = fit_power_model(&truth, &data, &FitOptions::known_geometry()).unwrap_err();
        assert!(
            matches!(
                e,
                FitError::NoForwardFlight {
                    parameter: "mu1_over_eta_n_s_per_m",
                    ..
                }
            ),
            "{e}"
        );
        // Without drag, the profile constant is collinear with K at constant thrust: refused too.
        let opts = FitOptions::known_geometry()
            .without(FitParameter::Mu1)
            .without(FitParameter::Mu2)
            .without(FitParameter::Mu3);
        let level: Vec<FitSample> = data
            .iter()
            .map(|s| FitSample {
                state: FlightState::new(s.state.airspeed_mps, 0.0, 0.0, 0.0),
                ..*s
            })
            .collect();
        let e = fit_power_model(&truth, &level, &opts).unwrap_err();
        assert!(matches!(e, FitError::NotIdentifiable { .. }), "{e}");
    }

    #[test]
    fn geometric_samples_identify_k_and_profile_but_refuse_drag() {
        let truth = m100_with_efficiency(0.7);
        let data = flights_with(&truth, 0.0, true);
        let e = fit_power_model(&truth, &data, &FitOptions::known_geometry()).unwrap_err();
        assert!(matches!(e, FitError::DragNotInPower { .. }), "{e}");
        let opts = FitOptions::known_geometry()
            .without(FitParameter::Mu1)
            .without(FitParameter::Mu2)
            .without(FitParameter::Mu3);
        let start = Vehicle::new(VehicleParams {
            efficiency: 0.9,
            kappa1_w_per_n1_5: 0.14,
            ..m100_params()
        })
        .unwrap();
        let fit = fit_power_model(&start, &data, &opts).unwrap();
        assert!(
            (fit.vehicle.efficiency - 0.7).abs() < 1e-6,
            "{:?}",
            fit.vehicle
        );
        assert!(
            (fit.vehicle.kappa1_w_per_n1_5 - 0.275).abs() < 1e-5,
            "{:?}",
            fit.vehicle
        );
    }

    #[test]
    fn held_constants_keep_their_physical_values_when_eta_moves() {
        // Regression: held drag and profile constants were held in lumped units (mu / eta), so
        // their physical values drifted with the fitted eta.
        let truth = m100_with_efficiency(0.7);
        let data = flights_with(&truth, 0.0, true);
        let start = m100_with_efficiency(0.95);
        let opts = FitOptions {
            free: vec![FitParameter::WeightOverEfficiency],
            ..FitOptions::known_geometry()
        };
        let fit = fit_power_model(&start, &data, &opts).unwrap();
        let (p, t) = (&fit.vehicle, truth.params());
        assert!((p.efficiency - 0.7).abs() < 1e-6, "{p:?}");
        assert!((p.mu1_n_s_per_m - t.mu1_n_s_per_m).abs() < 1e-12, "{p:?}");
        assert!(
            (p.mu3_n_s3_per_m3 - t.mu3_n_s3_per_m3).abs() < 1e-12,
            "{p:?}"
        );
        assert!(
            (p.kappa1_w_per_n1_5 - t.kappa1_w_per_n1_5).abs() < 1e-12,
            "{p:?}"
        );
    }

    #[test]
    fn bad_samples_are_named() {
        let truth = Vehicle::new(m100_params()).unwrap();
        let mut data = flights(&truth, 0.0);
        data[17].measured_power_w = f64::NAN;
        let e = fit_power_model(&truth, &data, &FitOptions::known_geometry()).unwrap_err();
        assert!(e.to_string().contains("sample 17"), "{e}");
        let e = fit_power_model(&truth, &data[20..40], &FitOptions::known_geometry()).unwrap_err();
        assert!(matches!(e, FitError::TooFewSamples { .. }), "{e}");
    }
}
