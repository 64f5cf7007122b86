//! The four-term power model, eqs (5), (7) and (14) of the power seed.
//!
//! `P_req = P_ind + P_par + P_pro + P_c` (7) and `P_hat = P_req / eta` (14), with thrust
//! `T = m g / (cos(phi) cos(theta))` (5) for a point query in steady level flight. The planner
//! supplies its own thrust from the force balance through [`FlightCondition`].
//!
//! # Ablation and the hybrid model
//! [`Terms`] removes any subset of the four terms (the rows of the paper's Table I); a removed term
//! reports 0 W and is left out of the totals. [`ModelOptions::profile_cutoff_mps`] drops the profile
//! term above a chosen airspeed: the hybrid the paper's conclusion suggests, since `P_pro` degraded
//! its estimate at 8 m/s.
//!
//! # Deviation: the geometric angle of attack and eq (8)
//! Eq (8), `P_ind = T (v_i + v_inf sin a)`, is momentum theory's rotor power: its `T Vn` part is
//! the work thrust does along the freestream. By the force balance `T = m a + m g + D`, that work
//! is the drag work `D v`, plus (in unsteady flight) the rate of kinetic energy `m a . v`, plus
//! (with axial flow) the climb work. The paper can add `P_par` (11) on top because its
//! approximation `sin a = sin(phi) sin(theta)` makes `T Vn` nearly vanish (exactly zero for a
//! single-axis tilt). With the exact geometry `T Vn = D v` in steady level flight, and adding
//! eq (11) would count the drag work twice (35 W aerodynamic at 10 m/s for the M100).
//!
//! So with [`AoaModel::Geometric`] aloft books eq (8) as three terms that add up to it:
//! `induced_w = T v_i`, `parasitic_w = D v` (eq 11) and `acceleration_w = T Vn - D v`, the work
//! that goes into accelerating the vehicle (zero in steady flight; it is what an attitude that does
//! not balance the drag implies). Their sum is `T (v_i + Vn)`: drag work is counted once, and
//! the power of manoeuvres is kept. With [`AoaModel::Paper`] eq (8) is used as printed and
//! `acceleration_w` is 0. The inflow `Vn` excludes the vertical air speed (the caller passes the
//! horizontal air velocity), so eq (13) carries the climb work once. Removing the induced term
//! (ablation) removes `acceleration_w` with it, as eq (8) contains both.
//!
//! # The plain evaluation and its fast paths
//! This file is the model as it reads: the types, the plain evaluation of a point query
//! (`PowerModel::evaluate_inline`: thrust and inflow, the quartic, the terms) and of a resolved
//! condition ([`PowerModel::evaluate_condition`]), and the terms themselves. The public
//! [`PowerModel::evaluate`] (a run-time dispatched build of `evaluate_inline`) and the batch
//! entry points ([`PowerModel::evaluate_batch`], [`PowerModel::evaluate_conditions`],
//! [`PowerModel::electrical_of_conditions`]) are `impl PowerModel` blocks in `kernels/`, each
//! tested bit for bit against the plain path here.
//!
//! # Deviation: no regeneration
//! Eq (14) can go negative in a steep descent where the climb term outweighs the others; a
//! multirotor's ESCs do not regenerate, so `electrical_w` is floored at 0 (the aerodynamic total
//! `aero_w` keeps its sign).

use serde::Serialize;

use crate::angle_of_attack::{AoaModel, Inflow};
use crate::climb::climb_power_w;
use crate::error::{finite, non_negative, within, PowerError, Result};
use crate::induced::{induced_power_of_root_w, induced_velocity_mps};
use crate::kernels::trig::{sin_cos, sin_cos_pair};
use crate::profile::profile_power_w;
use crate::quartic::solve_normalised;
use crate::vehicle::Vehicle;

/// One of the four terms of eq (7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Term {
    /// Induced power, eq (8).
    Induced,
    /// Parasitic power, eq (11).
    Parasitic,
    /// Profile power, eq (12).
    Profile,
    /// Climb power, eq (13).
    Climb,
}

impl Term {
    /// All four terms in the paper's order.
    pub const ALL: [Term; 4] = [Term::Induced, Term::Parasitic, Term::Profile, Term::Climb];

    /// The lower-case name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Term::Induced => "induced",
            Term::Parasitic => "parasitic",
            Term::Profile => "profile",
            Term::Climb => "climb",
        }
    }
}

impl std::str::FromStr for Term {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "induced" | "ind" => Ok(Term::Induced),
            "parasitic" | "par" => Ok(Term::Parasitic),
            "profile" | "pro" => Ok(Term::Profile),
            "climb" | "c" => Ok(Term::Climb),
            other => Err(format!(
                "unknown power term '{other}' (expected induced, parasitic, profile or climb)"
            )),
        }
    }
}

/// Which of the four terms are included.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Terms {
    /// Include induced power.
    pub induced: bool,
    /// Include parasitic power.
    pub parasitic: bool,
    /// Include profile power.
    pub profile: bool,
    /// Include climb power.
    pub climb: bool,
}

impl Default for Terms {
    fn default() -> Self {
        Self::ALL
    }
}

impl Terms {
    /// The full model.
    pub const ALL: Terms = Terms {
        induced: true,
        parasitic: true,
        profile: true,
        climb: true,
    };

    /// These terms with `term` removed.
    pub fn without(mut self, term: Term) -> Self {
        match term {
            Term::Induced => self.induced = false,
            Term::Parasitic => self.parasitic = false,
            Term::Profile => self.profile = false,
            Term::Climb => self.climb = false,
        }
        self
    }

    /// The full model with every term in `removed` taken out.
    pub fn all_but(removed: &[Term]) -> Self {
        removed.iter().fold(Self::ALL, |t, &r| t.without(r))
    }

    /// Whether `term` is included.
    pub fn includes(&self, term: Term) -> bool {
        match term {
            Term::Induced => self.induced,
            Term::Parasitic => self.parasitic,
            Term::Profile => self.profile,
            Term::Climb => self.climb,
        }
    }
}

/// Options of the model beyond the vehicle: ablation and the hybrid profile cutoff.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ModelOptions {
    /// Terms included.
    pub terms: Terms,
    /// Hybrid model: drop the profile term when the airspeed exceeds this value, m/s.
    pub profile_cutoff_mps: Option<f64>,
}

/// How the angle of attack of a point query is found.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum AoaInput {
    /// The paper's approximation (3)-(4) from roll and pitch.
    #[default]
    Paper,
    /// Exact geometry for horizontal air-relative motion in the direction `air_direction_rad`
    /// from the nose (0 = forward, +pi/2 = to the right).
    Geometric {
        /// Direction of the air-relative velocity from the nose, rad.
        air_direction_rad: f64,
    },
}

/// A point query in steady level flight: the paper's inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightState {
    /// Airspeed `v_inf >= 0` (horizontal, as the paper assumes), m/s.
    pub airspeed_mps: f64,
    /// Roll `phi`, rad (positive right side down).
    pub roll_rad: f64,
    /// Pitch `theta`, rad (positive nose up).
    pub pitch_rad: f64,
    /// Vertical speed, positive up, m/s (enters only the climb term, eq (13)).
    pub climb_rate_mps: f64,
    /// Angle-of-attack model.
    pub aoa: AoaInput,
}

impl FlightState {
    /// Level, unaccelerated flight state with the paper's angle of attack.
    pub fn new(airspeed_mps: f64, roll_rad: f64, pitch_rad: f64, climb_rate_mps: f64) -> Self {
        Self {
            airspeed_mps,
            roll_rad,
            pitch_rad,
            climb_rate_mps,
            aoa: AoaInput::Paper,
        }
    }
}

/// A fully resolved flight condition: thrust and inflow already known (the planner's input).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FlightCondition {
    /// Total thrust `T`, N.
    pub thrust_n: f64,
    /// Airspeed `v_inf`, the norm of the air-relative velocity, m/s.
    pub airspeed_mps: f64,
    /// The freestream decomposed on the rotor disk.
    pub inflow: Inflow,
    /// Vertical speed, positive up, m/s.
    pub climb_rate_mps: f64,
    /// How the inflow was found: with [`AoaModel::Geometric`] eq (8)'s `T Vn` work term is left
    /// to eqs (11) and (13) (see the module docs).
    pub aoa: AoaModel,
}

/// Every term of the model at one flight condition. Field names are the JSON contract.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct PowerBreakdown {
    /// Total thrust `T`, N.
    pub thrust_n: f64,
    /// Induced velocity `v_i`, eq (9), m/s.
    pub induced_velocity_mps: f64,
    /// Hover induced velocity `vh`, eq (10), m/s.
    pub hover_induced_velocity_mps: f64,
    /// Induced power, eq (8), W (0 when removed).
    pub induced_w: f64,
    /// Parasitic power, eq (11), W (0 when removed).
    pub parasitic_w: f64,
    /// Profile power, eq (12), W (0 when removed or above the hybrid cutoff).
    pub profile_w: f64,
    /// Work of accelerating the vehicle, `T Vn - D v`, with the geometric angle of attack (0 with
    /// the paper's, and in steady flight), W. Part of eq (8); see the module docs.
    pub acceleration_w: f64,
    /// Climb power, eq (13), W (0 when removed; negative in descent).
    pub climb_w: f64,
    /// Aerodynamic total `P_req`, eq (7), W.
    pub aero_w: f64,
    /// Electrical estimate `P_hat = P_req / eta`, eq (14), floored at 0, W.
    pub electrical_w: f64,
}

/// The four-term power model of one vehicle with its options.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerModel {
    vehicle: Vehicle,
    options: ModelOptions,
}

/// Largest tilt a point query accepts: `cos(phi) cos(theta)` must exceed this.
const MIN_TILT_COSINE: f64 = 1e-9;

impl PowerModel {
    /// The full model for `vehicle`.
    pub fn new(vehicle: Vehicle) -> Self {
        Self {
            vehicle,
            options: ModelOptions::default(),
        }
    }

    /// The model with these options; a hybrid cutoff must be finite and not negative.
    pub fn with_options(vehicle: Vehicle, options: ModelOptions) -> Result<Self> {
        if let Some(cut) = options.profile_cutoff_mps {
            non_negative("profile_cutoff_mps", cut)?;
        }
        Ok(Self { vehicle, options })
    }

    /// The vehicle.
    pub fn vehicle(&self) -> &Vehicle {
        &self.vehicle
    }

    /// The options.
    pub fn options(&self) -> &ModelOptions {
        &self.options
    }

    /// Thrust in steady level flight, eq (5): `T = m g / (cos(phi) cos(theta))`, N.
    ///
    /// Errors on non-finite angles and on a tilt of 90 deg or more.
    #[inline]
    pub fn level_flight_thrust_n(&self, roll_rad: f64, pitch_rad: f64) -> Result<f64> {
        let tilt_cos = check_attitude(roll_rad, pitch_rad)?;
        Ok(self.vehicle.weight_n() / tilt_cos)
    }

    /// The plain evaluation of a point query: the body of [`Self::evaluate`], inlined into each
    /// instruction-set build of it (`kernels/dispatch.rs`).
    #[inline(always)]
    pub(crate) fn evaluate_inline(&self, state: &FlightState) -> Result<PowerBreakdown> {
        let c = self.point_condition(state)?;
        let x = self.induced_velocity(&c)?;
        Ok(self.assemble(&c, x))
    }

    /// Validate a point query and resolve it: thrust from eq (5), inflow from the AoA model.
    #[inline(always)]
    pub(crate) fn point_condition(&self, state: &FlightState) -> Result<FlightCondition> {
        let (tilt_cos, inflow, aoa) = resolve_point(state)?;
        Ok(FlightCondition {
            thrust_n: self.vehicle.weight_n() / tilt_cos,
            airspeed_mps: state.airspeed_mps,
            inflow,
            climb_rate_mps: state.climb_rate_mps,
            aoa,
        })
    }

    /// Evaluate a resolved flight condition (thrust and inflow given).
    #[inline]
    pub fn evaluate_condition(&self, c: &FlightCondition) -> Result<PowerBreakdown> {
        check_condition(c)?;
        let x = self.induced_velocity(c)?;
        Ok(self.assemble(c, x))
    }

    /// Induced velocity of eq (9) for a resolved condition, as `x = v_i / vh`.
    #[inline(always)]
    pub(crate) fn induced_velocity(&self, c: &FlightCondition) -> Result<f64> {
        let v = &self.vehicle;
        if c.inflow.normal_mps.is_finite() && c.inflow.parallel_mps >= 0.0 {
            let a = c.inflow.normal_mps * v.inverse_hover_induced_velocity();
            let b = c.inflow.parallel_mps * v.inverse_hover_induced_velocity();
            if let Some(x) = solve_normalised(a, b) {
                return Ok(x);
            }
        }
        // Non-finite or negative inflow, or no root continuous with hover: the checked solver
        // builds the typed error with the values.
        let vh = v.hover_induced_velocity_mps();
        induced_velocity_mps(c.inflow.normal_mps, c.inflow.parallel_mps, vh).map(|vi| vi / vh)
    }

    /// The four terms and totals, eqs (7), (8), (11)-(14), for a resolved condition and the
    /// normalised induced velocity `x = v_i / vh`.
    #[inline(always)]
    pub(crate) fn assemble(&self, c: &FlightCondition, x: f64) -> PowerBreakdown {
        self.terms_at(
            c.thrust_n,
            c.airspeed_mps,
            c.inflow.normal_mps,
            c.inflow.parallel_mps,
            c.climb_rate_mps,
            c.aoa == AoaModel::Geometric,
            x,
        )
    }

    /// [`Self::assemble`] from the condition's fields. Written with selects, not branches, so the
    /// block kernels (`kernels/lanes.rs`) run it in vector lanes.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn terms_at(
        &self,
        thrust_n: f64,
        airspeed_mps: f64,
        normal_mps: f64,
        parallel_mps: f64,
        climb_rate_mps: f64,
        geometric: bool,
        x: f64,
    ) -> PowerBreakdown {
        let v = &self.vehicle;
        let vh = v.hover_induced_velocity_mps();
        let terms = &self.options.terms;
        let only = |on: bool, w: f64| if on { w } else { 0.0 };
        let drag_work_w = v.drag().parasitic_power_w(airspeed_mps);
        // Eq (8) as printed with the paper's inflow; with the geometric one its T Vn part is the
        // drag work (booked by eq 11) plus the acceleration work (see the module docs).
        let induced_w = only(
            terms.induced,
            induced_power_of_root_w(thrust_n, x, vh, only(!geometric, normal_mps)),
        );
        let acceleration_w = only(
            terms.induced & geometric,
            thrust_n * normal_mps - drag_work_w,
        );
        let parasitic_w = only(terms.parasitic, drag_work_w);
        let cutoff = self.options.profile_cutoff_mps.unwrap_or(f64::INFINITY);
        let profile_w = only(
            terms.profile & (airspeed_mps <= cutoff),
            profile_power_w(v.kappa1(), v.kappa2(), thrust_n, parallel_mps),
        );
        let climb_w = only(terms.climb, climb_power_w(v.weight_n(), climb_rate_mps));
        // The induced term, known last, is added last.
        let aero_w = ((acceleration_w + parasitic_w) + (profile_w + climb_w)) + induced_w;
        PowerBreakdown {
            thrust_n,
            induced_velocity_mps: x * vh,
            hover_induced_velocity_mps: vh,
            induced_w,
            parasitic_w,
            profile_w,
            acceleration_w,
            climb_w,
            aero_w,
            electrical_w: aero_w.max(0.0) * v.inverse_efficiency(),
        }
    }
}

/// Largest airspeed the model takes, m/s: beyond the fastest multirotor flown (about 130 m/s), so
/// a value above it is a mistake, not a flight (and would overflow the cubic drag of eq (6)).
pub const MAX_AIRSPEED_MPS: f64 = 150.0;

/// Largest vertical speed the model takes, up or down, m/s.
pub const MAX_CLIMB_RATE_MPS: f64 = 100.0;

/// Validate a resolved condition's thrust, airspeed and climb rate (the inflow is checked by the
/// solver).
#[inline(always)]
pub(crate) fn check_condition(c: &FlightCondition) -> Result<()> {
    // One test on the hot path; the checks that name the value only when it fails.
    let valid = (0.0..f64::INFINITY).contains(&c.thrust_n)
        & (0.0..=MAX_AIRSPEED_MPS).contains(&c.airspeed_mps)
        & (c.climb_rate_mps.abs() <= MAX_CLIMB_RATE_MPS);
    if valid {
        Ok(())
    } else {
        condition_error(c)
    }
}

/// The error naming the first invalid value of a condition [`check_condition`] rejected.
#[cold]
#[inline(never)]
fn condition_error(c: &FlightCondition) -> Result<()> {
    finite("thrust_n", c.thrust_n)?;
    non_negative("thrust_n", c.thrust_n)?;
    check_speeds(c.airspeed_mps, c.climb_rate_mps)
}

/// The airspeed (finite, not negative, at most [`MAX_AIRSPEED_MPS`]) and the climb rate (finite,
/// at most [`MAX_CLIMB_RATE_MPS`] either way), naming the bad value.
fn check_speeds(airspeed_mps: f64, climb_rate_mps: f64) -> Result<()> {
    finite("airspeed_mps", airspeed_mps)?;
    non_negative("airspeed_mps", airspeed_mps)?;
    within("airspeed_mps", airspeed_mps, 0.0, MAX_AIRSPEED_MPS)?;
    finite("climb_rate_mps", climb_rate_mps)?;
    within(
        "climb_rate_mps",
        climb_rate_mps,
        -MAX_CLIMB_RATE_MPS,
        MAX_CLIMB_RATE_MPS,
    )?;
    Ok(())
}

/// Validate a point query and resolve what does not depend on the vehicle: `cos(phi) cos(theta)`
/// (eq 5's divisor), the inflow of the selected angle-of-attack model, and that model.
#[inline(always)]
pub(crate) fn resolve_point(state: &FlightState) -> Result<(f64, Inflow, AoaModel)> {
    let ((sr, cr), (sp, cp)) = sin_cos_pair(state.roll_rad, state.pitch_rad);
    let tilt_cos = cr * cp;
    let v = state.airspeed_mps;
    // One test on the hot path: the tilt is below 90 deg (false for NaN angles), the airspeed is
    // finite and not negative, the climb rate finite. The checks that name the value run only
    // when it fails.
    let valid = (tilt_cos > MIN_TILT_COSINE)
        & (0.0..=MAX_AIRSPEED_MPS).contains(&v)
        & (state.climb_rate_mps.abs() <= MAX_CLIMB_RATE_MPS);
    if !valid {
        check_point(state)?;
    }
    Ok(match state.aoa {
        AoaInput::Paper => (
            tilt_cos,
            Inflow {
                normal_mps: v * sr * sp,
                parallel_mps: v * tilt_cos,
            },
            AoaModel::Paper,
        ),
        AoaInput::Geometric { air_direction_rad } => {
            finite("air_direction_rad", air_direction_rad)?;
            let (sb, cb) = sin_cos(air_direction_rad);
            // Closed form of angle_of_attack::body_relative_inflow (tested equal there).
            let normal = -v * (cb * cr * sp - sb * sr);
            (
                tilt_cos,
                Inflow {
                    normal_mps: normal,
                    parallel_mps: (v * v - normal * normal).max(0.0).sqrt(),
                },
                AoaModel::Geometric,
            )
        }
    })
}

/// The checks of a point query's attitude, airspeed and climb rate that name the offending value
/// (the cold path of [`resolve_point`]).
#[cold]
#[inline(never)]
fn check_point(state: &FlightState) -> Result<()> {
    check_attitude(state.roll_rad, state.pitch_rad)?;
    check_speeds(state.airspeed_mps, state.climb_rate_mps)
}

/// Validate roll and pitch; return `cos(phi) cos(theta)`.
#[inline]
pub(crate) fn check_attitude(roll_rad: f64, pitch_rad: f64) -> Result<f64> {
    finite("roll_rad", roll_rad)?;
    finite("pitch_rad", pitch_rad)?;
    let tilt_cos = roll_rad.cos() * pitch_rad.cos();
    if tilt_cos <= MIN_TILT_COSINE {
        return Err(PowerError::TiltTooLarge {
            tilt_deg: tilt_cos.clamp(-1.0, 1.0).acos().to_degrees(),
            roll_deg: roll_rad.to_degrees(),
            pitch_deg: pitch_rad.to_degrees(),
        });
    }
    Ok(tilt_cos)
}

#[cfg(test)]
// Exact comparisons here check values that are exact by construction (zeros of removed terms and
// of zero airspeed, bit-identical results of the same arithmetic).
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use crate::vehicle::tests::m100_params;

    fn m100() -> Vehicle {
        Vehicle::new(m100_params()).unwrap()
    }

    #[test]
    fn paper_val_hover_by_hand() {
        // Hover: T = m g, v_i = vh, P_ind = T vh (eq 8), P_par = 0 (eq 11), P_pro = kappa1 T^1.5,
        // P_c = 0; eq (10) vh = sqrt(m g / (2 rho pi r^2)).
        let model = PowerModel::new(m100());
        let p = model
            .evaluate(&FlightState::new(0.0, 0.0, 0.0, 0.0))
            .unwrap();
        let w = 3.29 * 9.8066;
        let vh = (w / (2.0 * 1.225 * std::f64::consts::PI * 0.172 * 0.172)).sqrt();
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        assert!(rel(p.thrust_n, w) < 1e-15);
        assert!(rel(p.hover_induced_velocity_mps, vh) < 1e-14);
        assert!(rel(p.induced_velocity_mps, vh) < 1e-14);
        assert!(rel(p.induced_w, w * vh) < 1e-14);
        assert_eq!(p.parasitic_w, 0.0);
        assert!(rel(p.profile_w, 0.275 * w.powf(1.5)) < 1e-14);
        assert_eq!(p.climb_w, 0.0);
        assert!(rel(p.electrical_w, (w * vh + 0.275 * w.powf(1.5)) / 0.8) < 1e-14);
    }

    #[test]
    fn paper_val_eq5_thrust_grows_with_tilt() {
        let model = PowerModel::new(m100());
        let (r, q) = (0.2f64, -0.3f64);
        let t = model.level_flight_thrust_n(r, q).unwrap();
        assert!((t - 3.29 * 9.8066 / (r.cos() * q.cos())).abs() < 1e-12);
    }

    #[test]
    fn ablation_removes_exactly_one_term() {
        let full = PowerModel::new(m100());
        let s = FlightState::new(6.0, 0.05, -0.15, 0.5);
        let p = full.evaluate(&s).unwrap();
        for term in Term::ALL {
            let m = PowerModel::with_options(
                m100(),
                ModelOptions {
                    terms: Terms::ALL.without(term),
                    profile_cutoff_mps: None,
                },
            )
            .unwrap();
            let q = m.evaluate(&s).unwrap();
            let removed = match term {
                Term::Induced => p.induced_w,
                Term::Parasitic => p.parasitic_w,
                Term::Profile => p.profile_w,
                Term::Climb => p.climb_w,
            };
            assert!(removed.abs() > 1.0, "{term:?} contributes at this state");
            assert!((p.aero_w - q.aero_w - removed).abs() < 1e-9, "{term:?}");
        }
    }

    #[test]
    fn hybrid_drops_profile_above_cutoff() {
        let m = PowerModel::with_options(
            m100(),
            ModelOptions {
                terms: Terms::ALL,
                profile_cutoff_mps: Some(7.0),
            },
        )
        .unwrap();
        let slow = m.evaluate(&FlightState::new(6.0, 0.0, -0.1, 0.0)).unwrap();
        let fast = m.evaluate(&FlightState::new(8.0, 0.0, -0.1, 0.0)).unwrap();
        assert!(slow.profile_w > 0.0);
        assert_eq!(fast.profile_w, 0.0);
    }

    #[test]
    fn bad_states_are_typed_errors() {
        let m = PowerModel::new(m100());
        let cases = [
            (FlightState::new(-1.0, 0.0, 0.0, 0.0), "airspeed_mps"),
            (FlightState::new(f64::NAN, 0.0, 0.0, 0.0), "airspeed_mps"),
            (FlightState::new(1.0, 1.6, 0.0, 0.0), "tilt"),
            (FlightState::new(1.0, 0.0, f64::INFINITY, 0.0), "pitch_rad"),
            (FlightState::new(1.0, 0.0, 0.0, f64::NAN), "climb_rate_mps"),
        ];
        for (s, name) in cases {
            let e = m.evaluate(&s).unwrap_err().to_string();
            assert!(e.contains(name), "{e} should name {name}");
        }
    }

    #[test]
    fn geometric_aoa_counts_drag_work_once() {
        // Steady level flight along the nose: the pitch balances drag, tan(theta) = f_D / (m g).
        let m = PowerModel::new(m100());
        let v = 10.0;
        let pitch = -(m.vehicle().drag().force_n(v) / m.vehicle().weight_n()).atan();
        let geo = FlightState {
            aoa: AoaInput::Geometric {
                air_direction_rad: 0.0,
            },
            ..FlightState::new(v, 0.0, pitch, 0.0)
        };
        let g = m.evaluate(&geo).unwrap();
        let p = m.evaluate(&FlightState::new(v, 0.0, pitch, 0.0)).unwrap();
        // T Vn equals the drag work here; the geometric induced term leaves it to eq (11).
        let t_vn = g.thrust_n * (-v * pitch.sin());
        assert!(
            (t_vn - g.parasitic_w).abs() < 1e-9 * g.parasitic_w,
            "{t_vn} vs {}",
            g.parasitic_w
        );
        assert!((g.induced_w - g.thrust_n * g.induced_velocity_mps).abs() < 1e-9 * g.induced_w);
        // The paper's approximation has Vn = 0 for a pure pitch: eq (8) is then T v_i as well, so
        // the two differ only through v_i (the exact Vn lowers it).
        assert!((p.induced_w - p.thrust_n * p.induced_velocity_mps).abs() < 1e-9 * p.induced_w);
        assert!(g.induced_velocity_mps < p.induced_velocity_mps);
    }

    #[test]
    fn electrical_never_negative_in_fast_descent() {
        let m = PowerModel::new(m100());
        let p = m.evaluate(&FlightState::new(0.0, 0.0, 0.0, -40.0)).unwrap();
        assert!(p.aero_w < 0.0);
        assert_eq!(p.electrical_w, 0.0);
    }
}
