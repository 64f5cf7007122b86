//! Column maps: which CSV column holds which channel, in which unit and frame.
//!
//! A map is written in TOML (or built in, see [`ColumnMap::kaist`]). Every value is converted to SI
//! as `si = raw * scale * unit_factor`, vectors to ENU, attitude to aerospace Euler angles
//! relative to NED. Example (the KAIST layout):
//!
//! ```toml
//! name = "kaist"
//! [time]
//! column = "timestamp"
//! unit = "us"
//! [voltage]
//! column = "vol"
//! unit = "V"
//! [current]
//! column = "cur"
//! unit = "A"
//! [power]          # the logged power is 10 x V x I
//! column = "power"
//! unit = "W"
//! scale = 0.1
//! [position]
//! type = "geodetic"
//! columns = ["lat", "log", "alt"]
//! angle_unit = "rad"
//! unit = "m"
//! [velocity]
//! columns = ["vel_x", "vel_y", "vel_z"]
//! frame = "ned"
//! unit = "m/s"
//! [attitude]
//! type = "euler"
//! columns = ["roll", "pitch", "yaw"]
//! unit = "rad"
//! ```
//!
//! Attitude may instead be `type = "quaternion"` with `columns = [w, x, y, z]` and
//! `frame = "ned"` (body FRD to NED, PX4) or `frame = "enu"` (body FLU to ENU, ROS). Positions may be
//! `type = "local"` with `columns = [x, y, z]` and a `frame`. Optional tables: `acceleration`,
//! `wind` (vectors like `velocity`), `charge` (remaining charge, `Ah` or `mAh`). Unknown keys are
//! rejected.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{LogError, Result};

/// Largest column-map file read, bytes (a map is a few hundred bytes).
pub const MAX_MAP_BYTES: u64 = 1 << 20;

/// Unit of a time column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum TimeUnit {
    /// Seconds.
    #[serde(rename = "s")]
    S,
    /// Milliseconds.
    #[serde(rename = "ms")]
    Ms,
    /// Microseconds.
    #[serde(rename = "us")]
    Us,
    /// Nanoseconds.
    #[serde(rename = "ns")]
    Ns,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn factor(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Ms => 1e-3,
            TimeUnit::Us => 1e-6,
            TimeUnit::Ns => 1e-9,
        }
    }
}

/// Unit of a scalar channel (voltage, current, power, charge).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ScalarUnit {
    /// Volt.
    V,
    /// Millivolt.
    #[serde(rename = "mV")]
    MilliV,
    /// Ampere.
    A,
    /// Milliampere.
    #[serde(rename = "mA")]
    MilliA,
    /// Centiampere (old PX4 and MAVLink current fields).
    #[serde(rename = "cA")]
    CentiA,
    /// Watt.
    W,
    /// Kilowatt.
    #[serde(rename = "kW")]
    KiloW,
    /// Ampere hour.
    #[serde(rename = "Ah")]
    AmpHour,
    /// Milliampere hour.
    #[serde(rename = "mAh")]
    MilliAmpHour,
}

impl ScalarUnit {
    /// SI units per unit and the SI unit's dimension name.
    fn factor_and_dimension(self) -> (f64, &'static str) {
        match self {
            ScalarUnit::V => (1.0, "voltage"),
            ScalarUnit::MilliV => (1e-3, "voltage"),
            ScalarUnit::A => (1.0, "current"),
            ScalarUnit::MilliA => (1e-3, "current"),
            ScalarUnit::CentiA => (1e-2, "current"),
            ScalarUnit::W => (1.0, "power"),
            ScalarUnit::KiloW => (1e3, "power"),
            ScalarUnit::AmpHour => (1.0, "charge"),
            ScalarUnit::MilliAmpHour => (1e-3, "charge"),
        }
    }
}

/// Unit of a length column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum LengthUnit {
    /// Metre.
    #[default]
    #[serde(rename = "m")]
    M,
    /// Centimetre.
    #[serde(rename = "cm")]
    Cm,
    /// Millimetre.
    #[serde(rename = "mm")]
    Mm,
    /// Foot.
    #[serde(rename = "ft")]
    Ft,
}

impl LengthUnit {
    /// Metres per unit.
    pub fn factor(self) -> f64 {
        match self {
            LengthUnit::M => 1.0,
            LengthUnit::Cm => 1e-2,
            LengthUnit::Mm => 1e-3,
            LengthUnit::Ft => 0.3048,
        }
    }
}

/// Unit of a speed or acceleration column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum RateUnit {
    /// Metre per second.
    #[serde(rename = "m/s")]
    MetrePerS,
    /// Centimetre per second.
    #[serde(rename = "cm/s")]
    CentimetrePerS,
    /// Kilometre per hour.
    #[serde(rename = "km/h")]
    KilometrePerH,
    /// Knot.
    #[serde(rename = "kn")]
    Knot,
    /// Metre per second squared (accelerations).
    #[serde(rename = "m/s^2")]
    MetrePerS2,
    /// Standard gravity (accelerations), [`aloft_core::STANDARD_GRAVITY_MPS2`] = 9.80665 m/s^2.
    #[serde(rename = "g")]
    G,
}

impl RateUnit {
    /// SI units per unit.
    pub fn factor(self) -> f64 {
        match self {
            RateUnit::MetrePerS | RateUnit::MetrePerS2 => 1.0,
            RateUnit::CentimetrePerS => 1e-2,
            RateUnit::KilometrePerH => 1.0 / 3.6,
            RateUnit::Knot => 1852.0 / 3600.0,
            RateUnit::G => aloft_core::STANDARD_GRAVITY_MPS2,
        }
    }
}

/// Unit of an angle column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum AngleUnit {
    /// Radian.
    #[default]
    #[serde(rename = "rad")]
    Rad,
    /// Degree.
    #[serde(rename = "deg")]
    Deg,
}

impl AngleUnit {
    /// Radians per unit.
    pub fn factor(self) -> f64 {
        match self {
            AngleUnit::Rad => 1.0,
            AngleUnit::Deg => std::f64::consts::PI / 180.0,
        }
    }
}

/// Frame of a vector or quaternion column set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Frame {
    /// North, east, down (quaternions: body FRD to NED).
    Ned,
    /// East, north, up (quaternions: body FLU to ENU).
    Enu,
}

/// The time column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeColumn {
    /// Column name.
    pub column: String,
    /// Unit.
    pub unit: TimeUnit,
}

/// A scalar column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScalarColumn {
    /// Column name.
    pub column: String,
    /// Unit.
    pub unit: ScalarUnit,
    /// Extra factor applied to the raw value (e.g. 0.1 for a power logged as 10 x V x I).
    #[serde(default = "one")]
    pub scale: f64,
}

fn one() -> f64 {
    1.0
}

/// Three vector columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VectorColumns {
    /// Column names of the three components, in the frame's axis order.
    pub columns: [String; 3],
    /// Frame of the components.
    pub frame: Frame,
    /// Unit.
    pub unit: RateUnit,
}

/// Position columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum PositionColumns {
    /// Local Cartesian position.
    Local {
        /// The three components in the frame's axis order.
        columns: [String; 3],
        /// Frame.
        frame: Frame,
        /// Unit.
        #[serde(default)]
        unit: LengthUnit,
    },
    /// Latitude, longitude, altitude; converted to ENU relative to the first fix.
    Geodetic {
        /// Latitude, longitude, altitude columns.
        columns: [String; 3],
        /// Unit of latitude and longitude.
        angle_unit: AngleUnit,
        /// Unit of altitude.
        #[serde(default)]
        unit: LengthUnit,
    },
}

/// Attitude columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum AttitudeColumns {
    /// Aerospace roll, pitch, yaw relative to NED.
    Euler {
        /// Roll, pitch, yaw columns.
        columns: [String; 3],
        /// Unit.
        unit: AngleUnit,
    },
    /// A quaternion `w, x, y, z`.
    Quaternion {
        /// w, x, y, z columns.
        columns: [String; 4],
        /// `ned`: body FRD to NED (PX4); `enu`: body FLU to ENU (ROS).
        frame: Frame,
    },
}

/// A column map: how to read one CSV layout into [`crate::Sample`]s.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnMap {
    /// A name for messages.
    #[serde(default)]
    pub name: String,
    /// Field delimiter (default `,`).
    #[serde(default = "comma")]
    pub delimiter: char,
    /// Time.
    pub time: TimeColumn,
    /// Battery voltage.
    pub voltage: Option<ScalarColumn>,
    /// Battery current (positive discharging).
    pub current: Option<ScalarColumn>,
    /// Electrical power.
    pub power: Option<ScalarColumn>,
    /// Remaining charge.
    pub charge: Option<ScalarColumn>,
    /// Position.
    pub position: Option<PositionColumns>,
    /// Ground velocity.
    pub velocity: Option<VectorColumns>,
    /// Acceleration.
    pub acceleration: Option<VectorColumns>,
    /// Attitude.
    pub attitude: Option<AttitudeColumns>,
    /// Wind velocity (velocity of the air).
    pub wind: Option<VectorColumns>,
}

fn comma() -> char {
    ','
}

fn cols3(a: &str, b: &str, c: &str) -> [String; 3] {
    [a.into(), b.into(), c.into()]
}

impl ColumnMap {
    /// A map with only a time column.
    pub fn new(name: &str, time_column: &str, unit: TimeUnit) -> Self {
        Self {
            name: name.into(),
            delimiter: ',',
            time: TimeColumn {
                column: time_column.into(),
                unit,
            },
            voltage: None,
            current: None,
            power: None,
            charge: None,
            position: None,
            velocity: None,
            acceleration: None,
            attitude: None,
            wind: None,
        }
    }

    /// The KAIST energy-drone layout (`ypkoo/new-energy-drone`): time in us, latitude and
    /// longitude in radians, NED velocities, Euler angles in radians, `power = 10 V I`,
    /// `capacity` in mAh. Accelerations are mapped as NED: their frame is undocumented, and on
    /// flight 2018-08-03 random5-1 they correlate with the derivative of the NED velocities
    /// (r = 0.63 north, 0.67 east), which a body frame at nearly constant heading would also give.
    pub fn kaist() -> Self {
        let scalar = |c: &str, unit, scale| ScalarColumn {
            column: c.into(),
            unit,
            scale,
        };
        Self {
            voltage: Some(scalar("vol", ScalarUnit::V, 1.0)),
            current: Some(scalar("cur", ScalarUnit::A, 1.0)),
            power: Some(scalar("power", ScalarUnit::W, 0.1)),
            charge: Some(scalar("capacity", ScalarUnit::MilliAmpHour, 1.0)),
            position: Some(PositionColumns::Geodetic {
                columns: cols3("lat", "log", "alt"),
                angle_unit: AngleUnit::Rad,
                unit: LengthUnit::M,
            }),
            velocity: Some(VectorColumns {
                columns: cols3("vel_x", "vel_y", "vel_z"),
                frame: Frame::Ned,
                unit: RateUnit::MetrePerS,
            }),
            acceleration: Some(VectorColumns {
                columns: cols3("acc_x", "acc_y", "acc_z"),
                frame: Frame::Ned,
                unit: RateUnit::MetrePerS2,
            }),
            attitude: Some(AttitudeColumns::Euler {
                columns: cols3("roll", "pitch", "yaw"),
                unit: AngleUnit::Rad,
            }),
            ..Self::new("kaist", "timestamp", TimeUnit::Us)
        }
    }

    /// PX4 `battery_status` table: voltage and current.
    pub fn px4_battery() -> Self {
        Self {
            voltage: Some(ScalarColumn {
                column: "voltage_v".into(),
                unit: ScalarUnit::V,
                scale: 1.0,
            }),
            current: Some(ScalarColumn {
                column: "current_a".into(),
                unit: ScalarUnit::A,
                scale: 1.0,
            }),
            ..Self::new("px4 battery_status", "timestamp", TimeUnit::Us)
        }
    }

    /// PX4 `vehicle_local_position` table: NED position, velocity, acceleration.
    pub fn px4_local_position() -> Self {
        Self {
            position: Some(PositionColumns::Local {
                columns: cols3("x", "y", "z"),
                frame: Frame::Ned,
                unit: LengthUnit::M,
            }),
            velocity: Some(VectorColumns {
                columns: cols3("vx", "vy", "vz"),
                frame: Frame::Ned,
                unit: RateUnit::MetrePerS,
            }),
            acceleration: Some(VectorColumns {
                columns: cols3("ax", "ay", "az"),
                frame: Frame::Ned,
                unit: RateUnit::MetrePerS2,
            }),
            ..Self::new("px4 vehicle_local_position", "timestamp", TimeUnit::Us)
        }
    }

    /// PX4 `vehicle_attitude` table: quaternion `q[0..3]` = w, x, y, z, body FRD to NED.
    pub fn px4_attitude() -> Self {
        Self {
            attitude: Some(AttitudeColumns::Quaternion {
                columns: ["q[0]".into(), "q[1]".into(), "q[2]".into(), "q[3]".into()],
                frame: Frame::Ned,
            }),
            ..Self::new("px4 vehicle_attitude", "timestamp", TimeUnit::Us)
        }
    }

    /// Parse a TOML map; `origin` names it in errors.
    pub fn from_toml_str(text: &str, origin: &Path) -> Result<Self> {
        let map: ColumnMap = toml::from_str(text).map_err(|e| LogError::MapFile {
            path: origin.to_path_buf(),
            message: aloft_core::file_message(&e.to_string()),
        })?;
        map.validate(origin)?;
        Ok(map)
    }

    /// Read and parse a TOML map file.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text =
            aloft_core::read_regular_text(path, MAX_MAP_BYTES).map_err(LogError::reading(path))?;
        Self::from_toml_str(&text, path)
    }

    /// Check scales and units: each scalar's unit must match its channel.
    pub fn validate(&self, origin: &Path) -> Result<()> {
        let bad = |message: String| LogError::MapFile {
            path: origin.to_path_buf(),
            message,
        };
        for (key, col, dim) in [
            ("voltage", &self.voltage, "voltage"),
            ("current", &self.current, "current"),
            ("power", &self.power, "power"),
            ("charge", &self.charge, "charge"),
        ] {
            if let Some(c) = col {
                let (_, d) = c.unit.factor_and_dimension();
                if d != dim {
                    return Err(bad(format!(
                        "[{key}] unit {:?} is a {d} unit, not a {dim} unit",
                        c.unit
                    )));
                }
                if !(c.scale.is_finite() && c.scale != 0.0) {
                    return Err(bad(format!(
                        "[{key}] scale {} must be finite and non-zero",
                        c.scale
                    )));
                }
            }
        }
        if let Some(v) = &self.velocity {
            if matches!(v.unit, RateUnit::MetrePerS2 | RateUnit::G) {
                return Err(bad(
                    "[velocity] unit must be a speed (m/s, cm/s, km/h, kn)".into()
                ));
            }
        }
        if let Some(v) = &self.wind {
            if matches!(v.unit, RateUnit::MetrePerS2 | RateUnit::G) {
                return Err(bad(
                    "[wind] unit must be a speed (m/s, cm/s, km/h, kn)".into()
                ));
            }
        }
        if let Some(v) = &self.acceleration {
            if !matches!(v.unit, RateUnit::MetrePerS2 | RateUnit::G) {
                return Err(bad("[acceleration] unit must be m/s^2 or g".into()));
            }
        }
        Ok(())
    }

    pub(crate) fn scalar_factor(c: &ScalarColumn) -> f64 {
        c.unit.factor_and_dimension().0 * c.scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn doc_example_parses_to_the_builtin_kaist_map_but_for_omitted_tables() {
        let text = r#"
name = "kaist"
[time]
column = "timestamp"
unit = "us"
[voltage]
column = "vol"
unit = "V"
[current]
column = "cur"
unit = "A"
[power]
column = "power"
unit = "W"
scale = 0.1
[position]
type = "geodetic"
columns = ["lat", "log", "alt"]
angle_unit = "rad"
unit = "m"
[velocity]
columns = ["vel_x", "vel_y", "vel_z"]
frame = "ned"
unit = "m/s"
[attitude]
type = "euler"
columns = ["roll", "pitch", "yaw"]
unit = "rad"
"#;
        let m = ColumnMap::from_toml_str(text, Path::new("x.toml")).unwrap();
        let k = ColumnMap::kaist();
        assert_eq!(m.voltage, k.voltage);
        assert_eq!(m.power, k.power);
        assert_eq!(m.position, k.position);
        assert_eq!(m.attitude, k.attitude);
        assert_eq!(m.velocity, k.velocity);
    }

    #[test]
    fn unknown_keys_and_mismatched_units_are_rejected() {
        let e = ColumnMap::from_toml_str(
            "[time]\ncolumn = \"t\"\nunit = \"us\"\ncolour = 3\n",
            Path::new("m.toml"),
        )
        .unwrap_err();
        // Named by its place, not its text (a file named as a map may be any file).
        let m = e.to_string();
        assert!(m.contains("line 4") && m.contains("unknown field"), "{m}");
        assert!(!m.contains("colour"), "{m}");
        let e = ColumnMap::from_toml_str(
            "[time]\ncolumn = \"t\"\nunit = \"us\"\n[voltage]\ncolumn = \"v\"\nunit = \"A\"\n",
            Path::new("m.toml"),
        )
        .unwrap_err();
        assert!(e.to_string().contains("not a voltage unit"), "{e}");
        let e = ColumnMap::from_toml_str(
            "[time]\ncolumn = \"t\"\nunit = \"hours\"\n",
            Path::new("m.toml"),
        )
        .unwrap_err();
        assert!(e.to_string().contains("m.toml"), "{e}");
    }
}
