//! Airframe: masses and the flight envelope (the `[airframe]` table of a vehicle file).

use serde::{Deserialize, Serialize};

use aloft_power::four_term::MAX_AIRSPEED_MPS;

use crate::error::{positive, within, PlannerError};

/// The `[airframe]` table: mass without battery and payload, and the limits a mission must stay
/// inside. Units are in the key names; unknown keys are rejected.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AirframeSpec {
    /// Mass without battery and payload, kg.
    pub mass_kg: f64,
    /// Largest take-off mass, kg.
    pub max_takeoff_mass_kg: f64,
    /// Largest total thrust, N (default: the thrust of level flight at the largest take-off mass
    /// and the largest tilt, `m_max g / cos(tilt_max)`, a lower bound of the true value).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_thrust_n: Option<f64>,
    /// Largest tilt of the thrust axis from the vertical, deg.
    pub max_tilt_deg: f64,
    /// Largest horizontal ground speed the autopilot commands, m/s (a faster planned speed is
    /// flown at it).
    pub max_speed_mps: f64,
    /// Largest horizontal airspeed, m/s (default: none; the tilt limit bounds the airspeed). A
    /// planned state beyond it is flown slower ([`crate::envelope`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_airspeed_mps: Option<f64>,
    /// Largest climb rate, m/s.
    pub max_climb_rate_mps: f64,
    /// Largest descent rate, m/s.
    pub max_descent_rate_mps: f64,
    /// Acceleration and deceleration along a horizontal path, m/s^2.
    pub acceleration_mps2: f64,
    /// Acceleration and deceleration along a vertical path, m/s^2.
    pub vertical_acceleration_mps2: f64,
    /// Yaw rate of the turn at a waypoint, deg/s.
    pub yaw_rate_deg_s: f64,
    /// Height of the rotor plane above the ground when landed, m (ground effect).
    pub rotor_height_m: f64,
    /// Acceptance radius of a waypoint, m: how far before it a pass-through corner may start
    /// (default 2 m, the PX4 and ArduPilot defaults; a mission leg may give its own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acceptance_radius_m: Option<f64>,
    /// Planning speed of the autopilot, m/s: the ground speed of mission legs that give none
    /// (default: the mission file's; `--speed` overrides both).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cruise_speed_mps: Option<f64>,
    /// Return-to-launch height of the autopilot, m: a return below it climbs to it first
    /// (default: the mission's, else none; `--rtl-altitude-m` overrides both).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtl_altitude_m: Option<f64>,
}

/// A validated airframe, angles in radians.
#[derive(Debug, Clone, PartialEq)]
pub struct Airframe {
    spec: AirframeSpec,
    max_tilt_rad: f64,
    yaw_rate_radps: f64,
}

/// Each value of the table with its unit and upper bound: positive, finite and within a
/// physical range (a value beyond it is a unit slip, not a multirotor; the speed limit is the
/// power model's).
type RangeCheck = (&'static str, f64, &'static str, f64, &'static str);

/// The range checks of the optional values of the table, when given.
fn optional_checks(
    spec: &AirframeSpec,
) -> [(&'static str, Option<f64>, &'static str, f64, &'static str); 4] {
    [
        (
            "airframe max_airspeed_mps",
            spec.max_airspeed_mps,
            "m/s",
            MAX_AIRSPEED_MPS,
            "at most 150 m/s",
        ),
        (
            "airframe acceptance_radius_m",
            spec.acceptance_radius_m,
            "m",
            1e3,
            "at most 1000 m",
        ),
        (
            "airframe cruise_speed_mps",
            spec.cruise_speed_mps,
            "m/s",
            MAX_AIRSPEED_MPS,
            "at most 150 m/s",
        ),
        (
            "airframe rtl_altitude_m",
            spec.rtl_altitude_m,
            "m",
            1e4,
            "at most 10000 m",
        ),
    ]
}

/// The range checks of [`Airframe::new`], one per value of the table.
fn range_checks(spec: &AirframeSpec) -> [RangeCheck; 10] {
    [
        (
            "airframe mass_kg",
            spec.mass_kg,
            "kg",
            1e4,
            "at most 10000 kg",
        ),
        (
            "airframe max_takeoff_mass_kg",
            spec.max_takeoff_mass_kg,
            "kg",
            1e4,
            "at most 10000 kg",
        ),
        (
            "airframe max_tilt_deg",
            spec.max_tilt_deg,
            "deg",
            90.0,
            "below 90 deg",
        ),
        (
            "airframe max_speed_mps",
            spec.max_speed_mps,
            "m/s",
            MAX_AIRSPEED_MPS,
            "at most 150 m/s",
        ),
        (
            "airframe max_climb_rate_mps",
            spec.max_climb_rate_mps,
            "m/s",
            100.0,
            "at most 100 m/s",
        ),
        (
            "airframe max_descent_rate_mps",
            spec.max_descent_rate_mps,
            "m/s",
            100.0,
            "at most 100 m/s",
        ),
        (
            "airframe acceleration_mps2",
            spec.acceleration_mps2,
            "m/s^2",
            100.0,
            "at most 100 m/s^2",
        ),
        (
            "airframe vertical_acceleration_mps2",
            spec.vertical_acceleration_mps2,
            "m/s^2",
            100.0,
            "at most 100 m/s^2",
        ),
        (
            "airframe yaw_rate_deg_s",
            spec.yaw_rate_deg_s,
            "deg/s",
            3600.0,
            "at most 3600 deg/s",
        ),
        (
            "airframe rotor_height_m",
            spec.rotor_height_m,
            "m",
            100.0,
            "at most 100 m",
        ),
    ]
}

impl Airframe {
    /// Validate the table.
    ///
    /// # Errors
    /// Any value non-positive or non-finite, a tilt limit of 90 deg or more, a largest take-off
    /// mass below the airframe mass, a thrust limit below the weight at the largest take-off mass.
    pub fn new(spec: AirframeSpec) -> Result<Self, PlannerError> {
        let checks = range_checks(&spec);
        for (name, value, unit, max, expected) in checks {
            positive(name, value, unit)?;
            if name != "airframe max_tilt_deg" {
                within(name, value, (0.0, max), unit, expected)?;
            }
        }
        if spec.max_tilt_deg >= 90.0 {
            return Err(aloft_core::InvalidParameter {
                name: "airframe max_tilt_deg",
                value: spec.max_tilt_deg,
                unit: "deg",
                expected: "below 90 deg",
            }
            .into());
        }
        if spec.max_takeoff_mass_kg < spec.mass_kg {
            return Err(aloft_core::InvalidParameter {
                name: "airframe max_takeoff_mass_kg",
                value: spec.max_takeoff_mass_kg,
                unit: "kg",
                expected: "at least the airframe mass",
            }
            .into());
        }
        for (name, value, unit, max, expected) in optional_checks(&spec) {
            if let Some(v) = value {
                positive(name, v, unit)?;
                within(name, v, (0.0, max), unit, expected)?;
            }
        }
        if let Some(t) = spec.max_thrust_n {
            positive("airframe max_thrust_n", t, "N")?;
            within("airframe max_thrust_n", t, (0.0, 1e7), "N", "at most 1e7 N")?;
        }
        Ok(Self {
            max_tilt_rad: spec.max_tilt_deg.to_radians(),
            yaw_rate_radps: spec.yaw_rate_deg_s.to_radians(),
            spec,
        })
    }

    /// The table it was built from.
    pub fn spec(&self) -> &AirframeSpec {
        &self.spec
    }
    /// Mass without battery and payload, kg.
    pub fn mass_kg(&self) -> f64 {
        self.spec.mass_kg
    }
    /// Largest take-off mass, kg.
    pub fn max_takeoff_mass_kg(&self) -> f64 {
        self.spec.max_takeoff_mass_kg
    }
    /// Largest total thrust for gravity `g_mps2`, N.
    pub fn max_thrust_n(&self, g_mps2: f64) -> f64 {
        self.spec
            .max_thrust_n
            .unwrap_or(self.spec.max_takeoff_mass_kg * g_mps2 / self.max_tilt_rad.cos())
    }
    /// Largest tilt, rad.
    pub fn max_tilt_rad(&self) -> f64 {
        self.max_tilt_rad
    }
    /// Largest horizontal speed, m/s.
    pub fn max_speed_mps(&self) -> f64 {
        self.spec.max_speed_mps
    }
    /// Largest horizontal airspeed, m/s, when the vehicle has one besides its tilt limit.
    pub fn max_airspeed_mps(&self) -> Option<f64> {
        self.spec.max_airspeed_mps
    }
    /// Largest climb rate, m/s.
    pub fn max_climb_rate_mps(&self) -> f64 {
        self.spec.max_climb_rate_mps
    }
    /// Largest descent rate, m/s.
    pub fn max_descent_rate_mps(&self) -> f64 {
        self.spec.max_descent_rate_mps
    }
    /// Horizontal acceleration, m/s^2.
    pub fn acceleration_mps2(&self) -> f64 {
        self.spec.acceleration_mps2
    }
    /// Vertical acceleration, m/s^2.
    pub fn vertical_acceleration_mps2(&self) -> f64 {
        self.spec.vertical_acceleration_mps2
    }
    /// Yaw rate, rad/s.
    pub fn yaw_rate_radps(&self) -> f64 {
        self.yaw_rate_radps
    }
    /// Rotor height above the ground when landed, m.
    pub fn rotor_height_m(&self) -> f64 {
        self.spec.rotor_height_m
    }
    /// Acceptance radius of a waypoint, m (the table's, else 2 m).
    pub fn acceptance_radius_m(&self) -> f64 {
        self.spec
            .acceptance_radius_m
            .unwrap_or(crate::mission::DEFAULT_ACCEPTANCE_RADIUS_M)
    }
}
