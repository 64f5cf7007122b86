//! The aircraft as the planner flies it: airframe limits, drag, and the source of electrical
//! power (the four-term model, or the propulsion chain per rotor).

use aloft_power::{AoaModel, CubicDrag, ModelOptions, PowerModel, Vehicle};
use aloft_propulsion::PropulsionSystem;

use crate::airframe::Airframe;
use crate::error::{positive, PlannerError};

/// Where the electrical power of a flight condition comes from.
// The four-term variant holds the vehicle inline (about 250 bytes with the optional body-axis
// drag and efficiency spread): it is the common case, built once per aircraft, and boxing it
// would put an indirection on the trim's hot path for nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum PowerSource {
    /// The four-term model (power seed eqs 3-14) of a vehicle; its mass is replaced by the
    /// mission's mass at each phase.
    FourTerm {
        /// The vehicle (drag, rotors, efficiency).
        vehicle: Vehicle,
        /// Ablation and hybrid options.
        options: ModelOptions,
    },
    /// The propulsion chain (propulsion seed): thrust per rotor -> rotor speed -> motor current ->
    /// supply power (eq 28) summed over the rotors. The chain has no inflow model: forward flight
    /// costs only the thrust it needs.
    Chain(Box<PropulsionSystem>),
}

/// A vehicle ready to fly missions.
#[derive(Debug, Clone, PartialEq)]
pub struct Aircraft {
    airframe: Airframe,
    source: PowerSource,
    drag: CubicDrag,
    rotor_radius_m: f64,
    rotor_count: u32,
    gravity_mps2: f64,
    /// Scale of the propulsion chain's electrical power (a model error; 1 unless set by
    /// [`Aircraft::with_power_scale`]). The four-term model carries its scale in its vehicle.
    chain_power_scale: f64,
}

impl Aircraft {
    /// An aircraft powered by the four-term model of `vehicle`, whose drag and rotor radius it
    /// uses.
    pub fn four_term(airframe: Airframe, vehicle: Vehicle, options: ModelOptions) -> Self {
        Self {
            drag: *vehicle.drag(),
            rotor_radius_m: vehicle.params().rotor_radius_m,
            rotor_count: vehicle.params().rotor_count,
            gravity_mps2: vehicle.gravity_mps2(),
            chain_power_scale: 1.0,
            airframe,
            source: PowerSource::FourTerm { vehicle, options },
        }
    }

    /// An aircraft powered by the propulsion chain, with the given drag law (use
    /// `CubicDrag::new(0, 0, 0)` when none is known, and say so).
    ///
    /// # Errors
    /// A non-positive rotor radius.
    pub fn propulsion_chain(
        airframe: Airframe,
        system: PropulsionSystem,
        drag: CubicDrag,
        rotor_radius_m: f64,
    ) -> Result<Self, PlannerError> {
        positive("rotor_radius_m", rotor_radius_m, "m")?;
        Ok(Self {
            drag,
            rotor_radius_m,
            rotor_count: system.rotor_count(),
            gravity_mps2: system.gravity_mps2(),
            chain_power_scale: 1.0,
            airframe,
            source: PowerSource::Chain(Box::new(system)),
        })
    }

    /// The same aircraft with its electrical power scaled by `scale` (a model error drawn by a
    /// Monte-Carlo scenario), in every flight condition and query.
    ///
    /// For the four-term model it is [`Vehicle::with_power_scale`] (exactly the efficiency
    /// `eta / s` for every term); for the propulsion chain, the supply power of the rotors and
    /// the climb power are summed and then scaled, as a pack would see a chain whose losses are
    /// off by that factor. With `scale = 1` every power is the unscaled aircraft's bit for bit.
    ///
    /// # Errors
    /// A scale that is not positive and finite, or above 100.
    pub fn with_power_scale(&self, scale: f64) -> Result<Self, PlannerError> {
        positive("power_scale", scale, "")?;
        crate::error::within("power_scale", scale, (0.0, 100.0), "", "at most 100")?;
        let mut a = self.clone();
        match &mut a.source {
            PowerSource::FourTerm { vehicle, .. } => *vehicle = vehicle.with_power_scale(scale)?,
            PowerSource::Chain(_) => a.chain_power_scale = scale,
        }
        Ok(a)
    }

    /// The scale of the propulsion chain's electrical power (1 unless set).
    pub(crate) fn chain_power_scale(&self) -> f64 {
        self.chain_power_scale
    }

    /// The airframe.
    pub fn airframe(&self) -> &Airframe {
        &self.airframe
    }
    /// The power source.
    pub fn source(&self) -> &PowerSource {
        &self.source
    }
    /// The drag law.
    pub fn drag(&self) -> &CubicDrag {
        &self.drag
    }
    /// Rotor radius, m.
    pub fn rotor_radius_m(&self) -> f64 {
        self.rotor_radius_m
    }
    /// Number of rotors.
    pub fn rotor_count(&self) -> u32 {
        self.rotor_count
    }
    /// Gravity, m/s^2.
    pub fn gravity_mps2(&self) -> f64 {
        self.gravity_mps2
    }

    /// The highest level ground speed, in still air and at `mass_kg`, that the aircraft can reach
    /// and hold within its tilt limit while accelerating at its airframe's horizontal
    /// acceleration: the largest `v` (at most the airframe's maximum speed) for which
    /// `m a + f_D(u) <= m g tan(tilt_max - 0.25 deg)` at every `u <= v` (the thrust tilt of
    /// level flight, `tan(tilt) = (m a + f_D) / (m g)`, with a quarter degree of margin for the
    /// midpoint sampling). Planner files written for other vehicles are clamped to it.
    pub fn tilt_limited_speed_mps(&self, mass_kg: f64) -> f64 {
        let af = &self.airframe;
        let tan_max = (af.max_tilt_rad() - 0.25f64.to_radians()).max(0.0).tan();
        let budget_n = mass_kg * (self.gravity_mps2 * tan_max - af.acceleration_mps2());
        let step = 0.01;
        let n = (af.max_speed_mps() / step).ceil() as usize;
        let mut highest_drag_n: f64 = 0.0;
        let mut reachable = 0.0;
        for k in 1..=n {
            let u = (k as f64 * step).min(af.max_speed_mps());
            highest_drag_n = highest_drag_n.max(self.drag.force_n(u));
            if highest_drag_n > budget_n {
                break;
            }
            reachable = u;
        }
        reachable
    }

    /// The power evaluator at a total mass.
    ///
    /// # Errors
    /// A mass the power model rejects.
    pub fn at_mass(&self, mass_kg: f64, aoa: AoaModel) -> Result<Powered<'_>, PlannerError> {
        positive("mass_kg", mass_kg, "kg")?;
        let engine = match &self.source {
            PowerSource::FourTerm { vehicle, options } => Engine::FourTerm(
                PowerModel::with_options(vehicle.with_mass(mass_kg)?, *options)?,
            ),
            PowerSource::Chain(system) => Engine::Chain(system),
        };
        Ok(Powered {
            aircraft: self,
            mass_kg,
            weight_n: mass_kg * self.gravity_mps2,
            engine,
            aoa,
        })
    }
}

/// The evaluator behind [`Powered`].
// Inline for the same reason as `PowerSource`: the model is read on every trim.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub(crate) enum Engine<'a> {
    FourTerm(PowerModel),
    Chain(&'a PropulsionSystem),
}

/// An aircraft at one mass: evaluates electrical power for a flight condition.
#[derive(Debug, Clone)]
pub struct Powered<'a> {
    pub(crate) aircraft: &'a Aircraft,
    pub(crate) mass_kg: f64,
    pub(crate) weight_n: f64,
    pub(crate) engine: Engine<'a>,
    pub(crate) aoa: AoaModel,
}

impl Powered<'_> {
    /// Total mass, kg.
    pub fn mass_kg(&self) -> f64 {
        self.mass_kg
    }
    /// The aircraft.
    pub fn aircraft(&self) -> &Aircraft {
        self.aircraft
    }
}
