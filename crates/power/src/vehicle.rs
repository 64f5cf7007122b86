//! The vehicle as the four-term power model sees it: mass, air, rotors, drag, profile and efficiency.

use aloft_core::{ISA_SEA_LEVEL_DENSITY_KG_M3, STANDARD_GRAVITY_MPS2};
use serde::{Deserialize, Serialize};

use crate::drag::CubicDrag;
use crate::error::{finite, non_negative, positive, within, PowerError, Result};
use crate::induced::hover_induced_velocity_mps;

/// The physical ranges of a vehicle's parameters: a value outside them is a mistake (a unit slip,
/// a typo), not a multirotor, and would overflow the model's arithmetic. Generous: the largest
/// multirotors flown weigh a few hundred kilograms and carry rotors a few metres across; the
/// smallest weigh about a gram. The lower bounds keep the model finite: a mass of 1e-320 kg, an
/// efficiency of 1e-308 or a gravity of 1e-9 m/s^2 passed a positivity check and made the power
/// infinite or NaN (fuzz findings, `fixtures/fuzz/vehicle-toml/`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParameterLimits {
    /// Smallest mass, kg (a gram).
    pub min_mass_kg: f64,
    /// Largest mass, kg.
    pub mass_kg: f64,
    /// Smallest gravity, m/s^2 (Titan's is 1.35).
    pub min_gravity_mps2: f64,
    /// Largest gravity, m/s^2 (Jupiter's cloud tops, 24.8).
    pub gravity_mps2: f64,
    /// Smallest overall efficiency (measured multirotors are 0.3 to 0.8).
    pub min_efficiency: f64,
    /// Largest air density, kg/m^3.
    pub air_density_kg_m3: f64,
    /// Largest rotor radius, m.
    pub rotor_radius_m: f64,
    /// Most rotors.
    pub rotor_count: f64,
    /// Largest profile coefficient, either kappa (units of their keys).
    pub kappa: f64,
    /// Largest drag coefficient in magnitude, mu1, mu2, mu3 (units of their keys).
    pub drag: f64,
}

/// The limits [`Vehicle::new`] applies.
pub const PARAMETER_LIMITS: ParameterLimits = ParameterLimits {
    min_mass_kg: 1e-3,
    mass_kg: 10_000.0,
    min_gravity_mps2: 1.0,
    gravity_mps2: 30.0,
    min_efficiency: 0.01,
    air_density_kg_m3: 10.0,
    rotor_radius_m: 20.0,
    rotor_count: 64.0,
    kappa: 100.0,
    drag: 1_000.0,
};

/// Which rotor disk area the hover induced velocity of eq (10) divides the weight by.
///
/// Eq (10) of the power seed, `vh = sqrt(m g / (2 rho pi r^2))`, uses the area of ONE rotor:
/// that is the paper's definition, and its efficiency `eta` (measured ideal over measured hover
/// power) absorbs the factor. Momentum theory for `N` rotors sharing the weight uses all `N` disks,
/// which gives a `vh` smaller by `sqrt(N)`. The choice changes what `eta` means, so a vehicle file
/// states it explicitly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DiskArea {
    /// The paper's eq (10): the area of one rotor disk, `pi r^2`.
    OneRotor,
    /// Momentum theory with the weight shared by all rotors: `N pi r^2`.
    AllRotors,
}

/// Power-model parameters as written in a vehicle file (the `[power]` table).
///
/// Units are in the key names. Unknown keys are rejected. Turn it into a validated [`Vehicle`]
/// with [`Vehicle::new`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleParams {
    /// Take-off mass `m`, kg.
    pub mass_kg: f64,
    /// Gravitational acceleration `g`, m/s^2.
    #[serde(default = "default_gravity")]
    pub gravity_mps2: f64,
    /// Air density `rho`, kg/m^3.
    #[serde(default = "default_density")]
    pub air_density_kg_m3: f64,
    /// Number of rotors `N`.
    pub rotor_count: u32,
    /// Rotor radius `r`, m.
    pub rotor_radius_m: f64,
    /// Disk area used by eq (10).
    pub disk_area: DiskArea,
    /// Linear drag coefficient `mu1` of eq (6), N s/m.
    pub mu1_n_s_per_m: f64,
    /// Quadratic drag coefficient `mu2` of eq (6), N s^2/m^2.
    pub mu2_n_s2_per_m2: f64,
    /// Cubic drag coefficient `mu3` of eq (6), N s^3/m^3.
    pub mu3_n_s3_per_m3: f64,
    /// Profile coefficient `kappa1` of eq (12), W/N^1.5.
    pub kappa1_w_per_n1_5: f64,
    /// Profile coefficient `kappa2` of eq (12), W s^2/(m^2 N^0.5).
    #[serde(default)]
    pub kappa2_w_s2_per_m2_n0_5: f64,
    /// Overall efficiency `eta` of eq (14): aerodynamic over electrical power, 0 < eta <= 1.
    pub efficiency: f64,
    /// Body-axis drag (optional, both or neither): the quadratic coefficient `mu2` of eq (6)
    /// along the body's forward axis, N s^2/m^2. With [`Self::mu2_y_n_s2_per_m2`] the drag
    /// force is `D_b = (mu1 + mu2_b v + mu3 v^2) v_b` per horizontal body axis `b`, the frontal
    /// area differing by axis; see [`crate::drag`]. Absent: the scalar law of eq (6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu2_x_n_s2_per_m2: Option<f64>,
    /// Body-axis drag: the quadratic coefficient `mu2` along the body's right axis, N s^2/m^2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu2_y_n_s2_per_m2: Option<f64>,
    /// Relative standard deviation of the efficiency between flights (optional, a fraction:
    /// 0.02 is 2 %), written by `aloft fit` from the spread of the fitted flights: the prior
    /// uncertainty an in-flight re-calibration weighs its estimate against.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub efficiency_relative_sd: Option<f64>,
}

impl VehicleParams {
    /// The same vehicle in air of density `rho_kg_m3`: the constants, stated at this table's
    /// `air_density_kg_m3` (`rho_ref`), carried to the new air term by term with `s = rho /
    /// rho_ref`, at fixed thrust:
    ///
    /// | term | scaling | why |
    /// |---|---|---|
    /// | induced, eqs (8)-(10) | through `vh = sqrt(m g / (2 rho A))`: `rho^-1/2` in hover | momentum theory; nothing to change but `rho` |
    /// | profile `kappa1 T^1.5`, eq (12) | `kappa1 s^-1/2` | a fixed-pitch rotor at fixed thrust spins faster in thin air: `T = C_T rho A (Omega R)^2` gives `Omega R ∝ rho^-1/2`, and the blade profile power `rho A (Omega R)^3 delta s / 8 ∝ T^1.5 rho^-1/2` |
    /// | profile `kappa2 V^2 T^0.5`, eq (12) | `kappa2 s^1/2` | the advance-ratio part `rho A (Omega R) V^2 ∝ T^0.5 rho^1/2 V^2` |
    /// | parasitic, eq (6) (`mu1`, `mu2`, `mu3`, body axes) | `mu s` | body drag is dynamic pressure times an area: `∝ rho` at a given airspeed |
    /// | efficiency `eta`, eq (14) | unchanged | a ratio of powers (motor and rotor efficiencies shift with Reynolds number and load: ignored) |
    ///
    /// So the whole hover power at a fixed mass scales as `sqrt(rho_ref / rho)` (1.161 at 3000 m
    /// ISA), not only its induced part, and forward flight gains less (its drag power falls).
    /// `s = 1` returns the table bit for bit. The result is not validated here: build a
    /// [`Vehicle`] from it.
    // Exact comparison: the same density returns the same table, bit for bit.
    #[allow(clippy::float_cmp)]
    pub fn in_air(&self, rho_kg_m3: f64) -> Self {
        if rho_kg_m3 == self.air_density_kg_m3 {
            return self.clone();
        }
        let s = rho_kg_m3 / self.air_density_kg_m3;
        let root = s.sqrt();
        Self {
            air_density_kg_m3: rho_kg_m3,
            kappa1_w_per_n1_5: self.kappa1_w_per_n1_5 / root,
            kappa2_w_s2_per_m2_n0_5: self.kappa2_w_s2_per_m2_n0_5 * root,
            mu1_n_s_per_m: self.mu1_n_s_per_m * s,
            mu2_n_s2_per_m2: self.mu2_n_s2_per_m2 * s,
            mu3_n_s3_per_m3: self.mu3_n_s3_per_m3 * s,
            mu2_x_n_s2_per_m2: self.mu2_x_n_s2_per_m2.map(|m| m * s),
            mu2_y_n_s2_per_m2: self.mu2_y_n_s2_per_m2.map(|m| m * s),
            ..self.clone()
        }
    }
}

/// Standard gravity (aloft-core's), the default when a vehicle file does not give one, m/s^2.
fn default_gravity() -> f64 {
    STANDARD_GRAVITY_MPS2
}
/// ISA sea-level density (aloft-core's), the default when a vehicle file does not give one,
/// kg/m^3.
fn default_density() -> f64 {
    ISA_SEA_LEVEL_DENSITY_KG_M3
}

/// A validated vehicle: every parameter finite and physical, with derived constants cached.
///
/// Built by [`Vehicle::new`]; a `Vehicle` that exists is valid.
#[derive(Debug, Clone, PartialEq)]
pub struct Vehicle {
    params: VehicleParams,
    drag: CubicDrag,
    weight_n: f64,
    disk_area_m2: f64,
    hover_induced_mps: f64,
    inv_hover_induced: f64,
    inv_efficiency: f64,
    /// Scale of the electrical power (model error), 1 unless set by [`Vehicle::with_power_scale`].
    power_scale: f64,
}

impl Vehicle {
    /// Validate the parameters and build the vehicle.
    ///
    /// Rejects NaN and infinities, non-positive mass, gravity, density, radius and efficiency,
    /// values outside [`PARAMETER_LIMITS`] (mass 1 g to 10 t, gravity 1 to 30 m/s^2, efficiency
    /// 0.01 to 1), zero rotors, negative `kappa1`/`kappa2`, and drag coefficients that give a
    /// negative drag force anywhere in 0-60 m/s.
    pub fn new(params: VehicleParams) -> Result<Self> {
        let limits = &PARAMETER_LIMITS;
        within(
            "mass_kg",
            positive("mass_kg", params.mass_kg)?,
            limits.min_mass_kg,
            limits.mass_kg,
        )?;
        let g = positive("gravity_mps2", params.gravity_mps2)?;
        within(
            "gravity_mps2",
            g,
            limits.min_gravity_mps2,
            limits.gravity_mps2,
        )?;
        let rho = positive("air_density_kg_m3", params.air_density_kg_m3)?;
        within("air_density_kg_m3", rho, 0.0, limits.air_density_kg_m3)?;
        let r = positive("rotor_radius_m", params.rotor_radius_m)?;
        within("rotor_radius_m", r, 0.0, limits.rotor_radius_m)?;
        if params.rotor_count == 0 {
            return Err(PowerError::NoRotor { rotor_count: 0 });
        }
        let n = f64::from(params.rotor_count);
        within("rotor_count", n, 1.0, limits.rotor_count)?;
        let k1 = non_negative("kappa1_w_per_n1_5", params.kappa1_w_per_n1_5)?;
        within("kappa1_w_per_n1_5", k1, 0.0, limits.kappa)?;
        let k2 = non_negative("kappa2_w_s2_per_m2_n0_5", params.kappa2_w_s2_per_m2_n0_5)?;
        within("kappa2_w_s2_per_m2_n0_5", k2, 0.0, limits.kappa)?;
        for (name, mu) in [
            ("mu1_n_s_per_m", params.mu1_n_s_per_m),
            ("mu2_n_s2_per_m2", params.mu2_n_s2_per_m2),
            ("mu3_n_s3_per_m3", params.mu3_n_s3_per_m3),
        ] {
            within(name, finite(name, mu)?, -limits.drag, limits.drag)?;
        }
        positive("efficiency", params.efficiency)?;
        within("efficiency", params.efficiency, limits.min_efficiency, 1.0)?;
        let drag = CubicDrag::new(
            params.mu1_n_s_per_m,
            params.mu2_n_s2_per_m2,
            params.mu3_n_s3_per_m3,
        )?;
        let drag = body_axis_drag(&params, drag)?;
        if let Some(sd) = params.efficiency_relative_sd {
            within(
                "efficiency_relative_sd",
                non_negative("efficiency_relative_sd", sd)?,
                0.0,
                1.0,
            )?;
        }
        let weight_n = params.mass_kg * params.gravity_mps2;
        let one_disk_m2 = std::f64::consts::PI * params.rotor_radius_m * params.rotor_radius_m;
        let disk_area_m2 = match params.disk_area {
            DiskArea::OneRotor => one_disk_m2,
            DiskArea::AllRotors => one_disk_m2 * f64::from(params.rotor_count),
        };
        let hover_induced_mps =
            hover_induced_velocity_mps(weight_n, params.air_density_kg_m3, disk_area_m2);
        finite("hover_induced_velocity_mps", hover_induced_mps)?;
        let inv_efficiency = 1.0 / params.efficiency;
        Ok(Self {
            params,
            drag,
            weight_n,
            disk_area_m2,
            hover_induced_mps,
            inv_hover_induced: 1.0 / hover_induced_mps,
            inv_efficiency,
            power_scale: 1.0,
        })
    }

    /// The same vehicle with another take-off mass (payload change), validated; its power scale
    /// is kept.
    pub fn with_mass(&self, mass_kg: f64) -> Result<Self> {
        Self::new(VehicleParams {
            mass_kg,
            ..self.params.clone()
        })?
        .with_power_scale(self.power_scale)
    }

    /// The same vehicle with another efficiency (a re-calibration), validated; its power scale
    /// is kept.
    pub fn with_efficiency(&self, efficiency: f64) -> Result<Self> {
        Self::new(VehicleParams {
            efficiency,
            ..self.params.clone()
        })?
        .with_power_scale(self.power_scale)
    }

    /// The same vehicle with its electrical power scaled by `scale` (a model error drawn by a
    /// Monte-Carlo scenario): `P_hat = s P_req / eta`.
    ///
    /// Every term of eq (7) (induced, parasitic, profile, climb, and the planner's acceleration
    /// work) is summed into `P_req` before the one division by `eta` of eq (14), so a scale `s`
    /// is exactly the efficiency `eta / s` for every term, and for the electrical power of every
    /// flight condition. It is kept apart from `eta` so that `eta / s` may exceed 1 (a vehicle
    /// that draws less than its model says) and so that [`Self::efficiency`] stays the vehicle
    /// file's. Implemented as the factor `s` on the cached `1 / eta`: with `s = 1` every power is
    /// the unscaled vehicle's bit for bit.
    ///
    /// # Errors
    /// A scale that is not positive and finite, or above 100.
    pub fn with_power_scale(&self, scale: f64) -> Result<Self> {
        within("power_scale", positive("power_scale", scale)?, 0.0, 100.0)?;
        Ok(Self {
            inv_efficiency: (1.0 / self.params.efficiency) * scale,
            power_scale: scale,
            ..self.clone()
        })
    }

    /// The scale of the electrical power (1 unless set by [`Self::with_power_scale`]).
    pub fn power_scale(&self) -> f64 {
        self.power_scale
    }

    /// The parameters this vehicle was built from.
    pub fn params(&self) -> &VehicleParams {
        &self.params
    }
    /// Mass `m`, kg.
    pub fn mass_kg(&self) -> f64 {
        self.params.mass_kg
    }
    /// Gravitational acceleration `g`, m/s^2.
    pub fn gravity_mps2(&self) -> f64 {
        self.params.gravity_mps2
    }
    /// Weight `m g`, N.
    pub fn weight_n(&self) -> f64 {
        self.weight_n
    }
    /// Air density `rho`, kg/m^3.
    pub fn air_density_kg_m3(&self) -> f64 {
        self.params.air_density_kg_m3
    }
    /// The disk area eq (10) uses (see [`DiskArea`]), m^2.
    pub fn disk_area_m2(&self) -> f64 {
        self.disk_area_m2
    }
    /// Hover induced velocity `vh` of eq (10), m/s.
    pub fn hover_induced_velocity_mps(&self) -> f64 {
        self.hover_induced_mps
    }
    /// `1 / vh`, s/m (cached for the hot path).
    pub fn inverse_hover_induced_velocity(&self) -> f64 {
        self.inv_hover_induced
    }
    /// `s / eta` with the power scale `s` (1 unless set by [`Self::with_power_scale`]; cached for
    /// the hot path).
    pub fn inverse_efficiency(&self) -> f64 {
        self.inv_efficiency
    }
    /// Ideal hover power `m g vh`, W (the numerator of the paper's efficiency).
    pub fn ideal_hover_power_w(&self) -> f64 {
        self.weight_n * self.hover_induced_mps
    }
    /// The cubic drag law of eq (6).
    pub fn drag(&self) -> &CubicDrag {
        &self.drag
    }
    /// Profile coefficient `kappa1`, W/N^1.5.
    pub fn kappa1(&self) -> f64 {
        self.params.kappa1_w_per_n1_5
    }
    /// Profile coefficient `kappa2`, W s^2/(m^2 N^0.5).
    pub fn kappa2(&self) -> f64 {
        self.params.kappa2_w_s2_per_m2_n0_5
    }
    /// Overall efficiency `eta` of eq (14).
    pub fn efficiency(&self) -> f64 {
        self.params.efficiency
    }
}

/// The scalar law `drag` with the body-axis coefficients of `params`, when given (both or
/// neither).
fn body_axis_drag(params: &VehicleParams, drag: CubicDrag) -> Result<CubicDrag> {
    let limit = PARAMETER_LIMITS.drag;
    match (params.mu2_x_n_s2_per_m2, params.mu2_y_n_s2_per_m2) {
        (None, None) => Ok(drag),
        (Some(x), Some(y)) => {
            within(
                "mu2_x_n_s2_per_m2",
                finite("mu2_x_n_s2_per_m2", x)?,
                -limit,
                limit,
            )?;
            within(
                "mu2_y_n_s2_per_m2",
                finite("mu2_y_n_s2_per_m2", y)?,
                -limit,
                limit,
            )?;
            drag.with_body_axes(x, y)
        }
        (Some(_), None) => Err(PowerError::LoneBodyAxisDrag {
            given: "mu2_x_n_s2_per_m2",
            missing: "mu2_y_n_s2_per_m2",
        }),
        (None, Some(_)) => Err(PowerError::LoneBodyAxisDrag {
            given: "mu2_y_n_s2_per_m2",
            missing: "mu2_x_n_s2_per_m2",
        }),
    }
}

#[cfg(test)]
// Exact comparisons here check values that are exact by construction (zeros of removed terms and
// of zero airspeed, bit-identical results of the same arithmetic).
#[allow(clippy::float_cmp)]
pub(crate) mod tests {
    use super::*;

    /// The power seed's M100 (eta 0.8 for round numbers): the parameters every test module uses.
    pub(crate) fn m100_params() -> VehicleParams {
        VehicleParams {
            mass_kg: 3.29,
            gravity_mps2: 9.8066,
            air_density_kg_m3: 1.225,
            rotor_count: 4,
            rotor_radius_m: 0.172,
            disk_area: DiskArea::OneRotor,
            mu1_n_s_per_m: 0.1816,
            mu2_n_s2_per_m2: -0.02326,
            mu3_n_s3_per_m3: 0.004045,
            kappa1_w_per_n1_5: 0.275,
            kappa2_w_s2_per_m2_n0_5: 0.0,
            efficiency: 0.8,
            mu2_x_n_s2_per_m2: None,
            mu2_y_n_s2_per_m2: None,
            efficiency_relative_sd: None,
        }
    }

    /// The air a vehicle flies in, term by term (`VehicleParams::in_air`), at 3000 m ISA
    /// (0.9091 kg/m^3, PX4's check value): at a fixed mass the induced power of hover eq (8)-(10)
    /// and the profile power `kappa1 T^1.5` of eq (12) each grow by `sqrt(rho0 / rho)` (1.161),
    /// so the whole hover power does; the parasitic power of eq (11) at a given airspeed falls by
    /// `rho / rho0`; the in-plane profile term `kappa2` grows by `sqrt(rho / rho0)` at fixed
    /// thrust and speed; the climb power of eq (13) does not move.
    #[test]
    fn each_term_carries_density_as_the_physics_says() {
        use crate::four_term::{FlightState, PowerModel};
        let rho0: f64 = 1.225;
        let rho: f64 = 0.9091;
        let ratio = (rho0 / rho).sqrt();
        let mut p = m100_params();
        p.kappa2_w_s2_per_m2_n0_5 = 0.01;
        let sea = PowerModel::new(Vehicle::new(p.clone()).unwrap());
        let high = PowerModel::new(Vehicle::new(p.in_air(rho)).unwrap());
        let hover = FlightState::new(0.0, 0.0, 0.0, 0.0);
        let (a, b) = (
            sea.evaluate(&hover).unwrap(),
            high.evaluate(&hover).unwrap(),
        );
        // Relative 1e-12: the same arithmetic in another order.
        let close = |x: f64, y: f64| ((x / y) - 1.0).abs() < 1e-12;
        assert!(close(b.induced_w / a.induced_w, ratio));
        assert!(close(b.profile_w / a.profile_w, ratio));
        assert!(close(b.electrical_w / a.electrical_w, ratio));
        assert!((ratio - 1.161).abs() < 0.001);
        // Forward flight: thrust and inflow differ with the air, so compare the terms' laws at
        // one thrust and speed. Parasitic power is the drag law at the airspeed, eq (11).
        let v = 10.0;
        let drag = |p: &VehicleParams| {
            p.mu1_n_s_per_m * v + p.mu2_n_s2_per_m2 * v * v + p.mu3_n_s3_per_m3 * v * v * v
        };
        let thin = p.in_air(rho);
        assert!(close(drag(&thin) / drag(&p), rho / rho0));
        let t = 40.0_f64;
        let in_plane = |p: &VehicleParams| p.kappa2_w_s2_per_m2_n0_5 * v * v * t.sqrt();
        assert!(close(in_plane(&thin) / in_plane(&p), (rho / rho0).sqrt()));
        let climb = FlightState::new(0.0, 0.0, 0.0, 2.0);
        let (c, d) = (
            sea.evaluate(&climb).unwrap(),
            high.evaluate(&climb).unwrap(),
        );
        assert!(close(c.climb_w, d.climb_w));
        // The same air is the same table, bit for bit; there and back is the table again.
        assert_eq!(p.in_air(rho0), p);
        let back = thin.in_air(rho0);
        assert!(close(back.kappa1_w_per_n1_5, p.kappa1_w_per_n1_5));
        assert!(close(back.mu3_n_s3_per_m3, p.mu3_n_s3_per_m3));
    }

    type Mutation = fn(&mut VehicleParams);

    #[test]
    fn rejects_each_bad_parameter_with_its_name() {
        let cases: Vec<(Mutation, &str)> = vec![
            (|p| p.mass_kg = -1.0, "mass_kg"),
            (|p| p.mass_kg = f64::NAN, "mass_kg"),
            (|p| p.gravity_mps2 = 0.0, "gravity_mps2"),
            (|p| p.air_density_kg_m3 = f64::INFINITY, "air_density_kg_m3"),
            (|p| p.rotor_radius_m = 0.0, "rotor_radius_m"),
            (|p| p.rotor_count = 0, "rotor_count"),
            (|p| p.kappa1_w_per_n1_5 = -0.1, "kappa1_w_per_n1_5"),
            (|p| p.efficiency = 1.5, "efficiency"),
            (|p| p.efficiency = 0.0, "efficiency"),
            (|p| p.mu2_n_s2_per_m2 = -1.0, "drag"),
        ];
        for (mutate, name) in cases {
            let mut p = m100_params();
            mutate(&mut p);
            let err = Vehicle::new(p).expect_err(name);
            assert!(err.to_string().contains(name), "{err} should name {name}");
        }
    }

    /// Fuzz findings `fixtures/fuzz/vehicle-toml/*.bin`: each value passed validation and made
    /// the power model infinite or NaN.
    #[test]
    fn tiny_mass_efficiency_and_gravity_are_refused_with_key_and_range() {
        let cases: Vec<(Mutation, &str)> = vec![
            (|p| p.mass_kg = 1e-320, "mass_kg"),
            (|p| p.mass_kg = 1e-4, "mass_kg"),
            (|p| p.efficiency = 1e-320, "efficiency"),
            (|p| p.efficiency = 2.2250738585072014e-308, "efficiency"),
            (|p| p.efficiency = 0.009, "efficiency"),
            (|p| p.gravity_mps2 = 1e-9, "gravity_mps2"),
            (|p| p.gravity_mps2 = 0.5, "gravity_mps2"),
            (|p| p.gravity_mps2 = 31.0, "gravity_mps2"),
        ];
        for (mutate, name) in cases {
            let mut p = m100_params();
            mutate(&mut p);
            let err = Vehicle::new(p).expect_err(name);
            assert!(
                matches!(err, PowerError::OutOfRange { .. }),
                "{name}: {err:?}"
            );
            assert!(err.to_string().contains(name), "{err} should name {name}");
        }
        // The bounds themselves are vehicles, and their hover power is finite.
        for mutate in [
            (|p| p.mass_kg = 1e-3) as Mutation,
            |p| p.efficiency = 0.01,
            |p| p.gravity_mps2 = 1.0,
            |p| p.gravity_mps2 = 30.0,
        ] {
            let mut p = m100_params();
            mutate(&mut p);
            let v = Vehicle::new(p).unwrap();
            assert!(v.ideal_hover_power_w().is_finite());
        }
    }

    #[test]
    fn all_rotor_disks_lower_vh_by_sqrt_n() {
        let one = Vehicle::new(m100_params()).unwrap();
        let all = Vehicle::new(VehicleParams {
            disk_area: DiskArea::AllRotors,
            ..m100_params()
        })
        .unwrap();
        let ratio = one.hover_induced_velocity_mps() / all.hover_induced_velocity_mps();
        // Exact algebra: only rounding differs.
        assert!((ratio - 2.0).abs() < 1e-12, "ratio {ratio}");
    }

    #[test]
    fn unknown_keys_are_rejected() {
        let text = "mass_kg = 1.0\nrotor_count = 4\nrotor_radius_m = 0.1\ndisk_area = \"one-rotor\"\nmu1_n_s_per_m = 0.1\nmu2_n_s2_per_m2 = 0.0\nmu3_n_s3_per_m3 = 0.0\nkappa1_w_per_n1_5 = 0.1\nefficiency = 0.7\nmass_lb = 3.0\n";
        let err = toml_like_parse(text);
        assert!(err.contains("mass_lb"), "{err}");
    }

    #[test]
    fn a_power_scale_is_the_efficiency_eta_over_s_for_every_term() {
        use crate::{FlightState, PowerModel};
        let v = Vehicle::new(m100_params()).unwrap();
        // A scale of 1 is the vehicle itself, bit for bit (and survives a change of mass).
        assert_eq!(v.with_power_scale(1.0).unwrap(), Vehicle { ..v.clone() });
        assert_eq!(
            v.with_mass(4.0).unwrap().inverse_efficiency().to_bits(),
            v.with_power_scale(1.0)
                .unwrap()
                .with_mass(4.0)
                .unwrap()
                .inverse_efficiency()
                .to_bits()
        );
        let states = [
            FlightState::new(0.0, 0.0, 0.0, 0.0),
            FlightState::new(8.0, 0.05, -0.15, 0.0),
            FlightState::new(4.0, 0.0, -0.05, 2.0),
            FlightState::new(12.0, -0.1, -0.25, -1.5),
        ];
        for s in [0.9, 1.03, 1.25] {
            let scaled = PowerModel::new(v.with_power_scale(s).unwrap().with_mass(3.5).unwrap());
            let by_eta =
                PowerModel::new(v.with_mass(3.5).unwrap().with_efficiency(0.8 / s).unwrap());
            for st in &states {
                let a = scaled.evaluate(st).unwrap();
                let b = by_eta.evaluate(st).unwrap();
                // s / eta against 1 / (eta / s): two roundings apart, a few ulp.
                assert!(
                    (a.electrical_w / b.electrical_w - 1.0).abs() < 1e-15,
                    "{s} {st:?}"
                );
            }
        }
        assert!(v.with_power_scale(0.0).is_err());
        assert!(v.with_power_scale(f64::NAN).is_err());
    }

    #[test]
    fn body_axis_drag_needs_both_keys_and_old_files_write_no_new_keys() {
        let mut p = m100_params();
        p.mu2_x_n_s2_per_m2 = Some(0.01);
        let e = Vehicle::new(p.clone()).unwrap_err();
        assert!(matches!(e, PowerError::LoneBodyAxisDrag { .. }), "{e}");
        p.mu2_y_n_s2_per_m2 = Some(-1.0);
        // Negative drag sideways at low speed: refused as the scalar law would be.
        assert!(Vehicle::new(p.clone()).is_err());
        p.mu2_y_n_s2_per_m2 = Some(0.02);
        let v = Vehicle::new(p).unwrap();
        assert_eq!(v.drag().body_axes(), Some([0.01, 0.02]));
        let mut q = m100_params();
        q.efficiency_relative_sd = Some(-0.1);
        assert!(Vehicle::new(q).is_err());
        let json = serde_json::to_string(&m100_params()).unwrap();
        assert!(
            !json.contains("mu2_x") && !json.contains("efficiency_relative_sd"),
            "{json}"
        );
    }

    // The crate does not depend on toml; serde's own test format is enough to show the attribute works.
    fn toml_like_parse(text: &str) -> String {
        let mut map = serde_json::Map::new();
        for line in text.lines() {
            let (k, v) = line.split_once(" = ").unwrap();
            let value: serde_json::Value = serde_json::from_str(v).unwrap();
            map.insert(k.to_string(), value);
        }
        serde_json::from_value::<VehicleParams>(serde_json::Value::Object(map))
            .unwrap_err()
            .to_string()
    }
}
