//! What a mission request asks: the options of `aloft mission` (pack, payload, wind, gusts,
//! reserve, start charge, time step, model choices, planning speed, return height, corners).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use aloft_planner::{CornerMode, WindSpec};
use aloft_power::AoaModel;

use crate::engine::basics::step_meter::StepMeter;
use crate::engine::conditions::air::AirInput;
use crate::error::Error;

/// The least clearance over the ground of a route flown over terrain, m (the default:
/// a mission that passes closer than 10 m to the ground outside take-off and landing is
/// infeasible).
pub const DEFAULT_MIN_CLEARANCE_M: f64 = 10.0;

/// Options of [`plan_mission`]: the options of `aloft mission` (JSON keys as the field names;
/// every key optional, unknown keys rejected).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MissionOptions {
    /// Pack pack by name (default: the vehicle's default pack).
    pub battery: Option<String>,
    /// Payload at take-off, kg (overrides the mission file's).
    pub payload_kg: Option<f64>,
    /// Wind, as a mission file's `[wind]` table (overrides the mission file's; default: the
    /// mission file's, else still air).
    pub wind: Option<WindSpec>,
    /// Gridded wind field: a CSV file with columns `x_m,y_m,z_m,u_mps,v_mps,w_mps` (east, north,
    /// up), interpolated trilinearly; it replaces `wind` and the mission file's wind.
    pub wind_field: Option<PathBuf>,
    /// Seeded gusts added to whichever wind the mission flies in.
    pub gusts: Option<GustSpec>,
    /// Reserve required at landing, percent of the usable capacity (default: the mission's, else 20).
    pub reserve_percent: Option<f64>,
    /// State of charge at take-off, percent (default 100).
    pub start_percent: f64,
    /// The pack's rested voltage before take-off, V: the state of charge at take-off is its
    /// place on the pack's open-circuit curve (in place of `start_percent`, which must then be
    /// left at 100).
    pub start_voltage_v: Option<f64>,
    /// Sampling step, s (default: the mission's, else 0.1).
    pub time_step_s: Option<f64>,
    /// Angle-of-attack model (default geometric).
    pub aoa: AoaModel,
    /// Ground effect near the ground, survey eq (35) (default true).
    pub ground_effect: bool,
    /// Keep every sample in the [`Plan`] (needed by [`Plan::remaining`]; default false).
    pub record_samples: bool,
    /// Planning speed, m/s: the ground speed of the legs, orbits and returns that give none
    /// (overrides the vehicle's `cruise_speed_mps` and the mission's default, e.g. a `.plan`'s
    /// `hoverSpeed`).
    pub speed_mps: Option<f64>,
    /// Lowest height of a return to home, m (overrides the vehicle's and the mission's).
    pub rtl_altitude_m: Option<f64>,
    /// Corners: `pass` (through waypoints without a hold, as autopilots fly) or `stop`
    /// (overrides the mission's; default pass).
    pub corners: Option<CornerMode>,
    /// The day's air (elevation, temperature, humidity, QNH): see [`AirInput`] for the
    /// precedence (default: the mission's home altitude in ISA air, else the vehicle file's
    /// density).
    pub air: AirInput,
    /// The autopilot's low-voltage failsafe, pack volts: the answer says when the predicted
    /// terminal voltage under load first falls below it (default: the pack file's `[failsafe]`).
    pub low_voltage_v: Option<f64>,
    /// The autopilot's critical-voltage failsafe, pack volts (as `low_voltage_v`).
    pub critical_voltage_v: Option<f64>,
    /// A directory of elevation tiles (SRTM `.hgt`, `.hgt.zip`, GeoTIFF): the answer gives each
    /// segment's least height above the ground, terrain-frame items are flown over it, and a
    /// route closer than `min_clearance_m` is infeasible (default none: a flat Earth).
    pub terrain: Option<PathBuf>,
    /// The least height above the ground any segment in the air may pass, take-off and landing
    /// excepted, m (default [`DEFAULT_MIN_CLEARANCE_M`]; with `terrain` only).
    pub min_clearance_m: Option<f64>,
    /// The budget of planner steps of the request these options are part of, when its caller
    /// bounds its work (`aloft serve`; not in the JSON; default none: unbounded, as the planner's
    /// own limit on one flight allows).
    #[serde(skip)]
    pub meter: Option<StepMeter>,
}

impl Default for MissionOptions {
    fn default() -> Self {
        Self {
            battery: None,
            payload_kg: None,
            wind: None,
            wind_field: None,
            gusts: None,
            low_voltage_v: None,
            critical_voltage_v: None,
            terrain: None,
            min_clearance_m: None,
            reserve_percent: None,
            start_percent: 100.0,
            start_voltage_v: None,
            time_step_s: None,
            aoa: AoaModel::Geometric,
            ground_effect: true,
            record_samples: false,
            speed_mps: None,
            rtl_altitude_m: None,
            corners: None,
            air: AirInput::default(),
            meter: None,
        }
    }
}

impl MissionOptions {
    /// Options from JSON text, e.g. `{"payload_kg": 0.5, "wind": {"speed_mps": 5, "from_deg": 270}}`.
    ///
    /// # Errors
    /// [`Error::OptionsFormat`] for malformed JSON or unknown keys.
    pub fn from_json(text: &str) -> Result<Self, Error> {
        serde_json::from_str(text).map_err(|e| Error::OptionsFormat {
            what: "mission options",
            message: e.to_string(),
        })
    }
}

/// Seeded gusts added to a mission's wind: a standard deviation per horizontal axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GustSpec {
    /// Standard deviation per horizontal axis, m/s.
    pub std_mps: f64,
    /// Seed of the gust sequence (default 1).
    #[serde(default = "default_seed")]
    pub seed: u64,
}

fn default_seed() -> u64 {
    1
}
