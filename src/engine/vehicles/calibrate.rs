//! A vehicle from its spec sheet (`aloft vehicles calibrate`), and the one-figure calibration of
//! the four-term model's efficiency on a published hover time, which the built-in vehicles use too.
//!
//! # What one hover time can fix
//! One published hover time is one number, so it fixes one constant. At hover every term of the
//! four-term model grows as `T^1.5 = (m g)^1.5` (induced `T vh` with `vh ~ sqrt(m)`, eq 10; profile
//! `kappa1 T^1.5`, eq 12), so the model's *shape* (how hover power grows with mass) comes from
//! momentum theory, and the figure fixes the *scale*: the efficiency `eta` of eq (14). The usable
//! energy fraction of the pack would scale every hover time by the same factor as `eta` (both
//! multiply the time), so the two cannot be told apart by hover times; aloft puts the whole factor
//! in `eta` and keeps the pack model's usable energy (open-circuit curve to the cut-off voltage,
//! resistive loss, [`aloft_planner::endurance_at_power_s`]) because that pack model is the one
//! missions, reserves and state-of-charge reports use.
//!
//! # Class defaults of a spec-sheet vehicle (each overridable where the spec allows)
//! - Disk area: all rotors (`N pi r^2`, momentum theory with the weight shared), sea-level ISA air
//!   (1.225 kg/m^3) and standard gravity: manufacturers' hover times are quoted at sea level.
//! - Profile power: 13.1 % of the ideal induced power at hover, the share of the power seed's
//!   M100 (`kappa1 = 0.275` with its one-disk eq (10): `kappa1 sqrt(2 rho pi r^2)` = 0.1312).
//! - Drag: the power seed's M100 polynomial (Fig. 3: `mu1..mu3` = 0.1816, -0.02326, 0.004045)
//!   scaled by the total rotor disk area against the M100's (4 rotors of 0.344 m), a proxy for frame
//!   size; `[drag]` in the spec replaces it.
//! - Flight envelope: the M100's published limits (35 deg tilt, 17 m/s, 5 m/s up, 4 m/s down) and
//!   its assumed waypoint accelerations (fixtures/vehicles/dji-m100.toml).
//! - Pack: cut-off 3.0 V per cell and 8 mohm per cell, divided among packs in parallel (the
//!   M100 file's assumptions); the generic LiPo open-circuit curve.

use serde::{Deserialize, Serialize};

use aloft_planner::{endurance_at_power_s, AirframeSpec, AoaModel, BatterySpec, Pack};
use aloft_power::{DiskArea, ModelOptions, VehicleParams};

use crate::error::Error;
use crate::vehicle::{VehicleFile, VehicleSource};

/// The power seed's M100 constants the class defaults are scaled from (section V, Fig. 3).
const SEED_KAPPA1: f64 = 0.275;
const SEED_ROTOR_RADIUS_M: f64 = 0.172;
const SEED_ROTORS: f64 = 4.0;
const SEED_MU: [f64; 3] = [0.1816, -0.02326, 0.004045];
/// ISA sea-level density, kg/m^3.
const SEA_LEVEL_DENSITY: f64 = 1.225;
/// Assumed DC resistance per cell, ohm (as the M100 file's packs).
const CELL_RESISTANCE_OHM: f64 = 0.008;
/// Assumed cut-off under load per cell, V (as the M100 file's packs).
const CUTOFF_CELL_V: f64 = 3.0;

/// A spec sheet: what a manufacturer publishes about a multirotor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpecSheet {
    /// Short name of the vehicle file to make.
    pub name: String,
    /// One line about the vehicle.
    #[serde(default)]
    pub description: String,
    /// Number of rotors.
    pub rotors: u32,
    /// Rotor (propeller) diameter, m.
    pub rotor_diameter_m: f64,
    /// Mass without batteries and payload, kg.
    pub frame_mass_kg: f64,
    /// Largest take-off mass, kg (default: the published hover's take-off mass).
    #[serde(default)]
    pub max_takeoff_mass_kg: Option<f64>,
    /// The pack(s).
    pub battery: SpecBattery,
    /// The one published hover time the model is calibrated on.
    pub published_hover: PublishedHover,
    /// Drag polynomial of eq (6), when known (default: the class default above).
    #[serde(default)]
    pub drag: Option<SpecDrag>,
}

/// The battery of a spec sheet: one pack's figures and how many fly in parallel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpecBattery {
    /// Pack name (default: `<count>x<capacity>mAh`).
    #[serde(default)]
    pub name: Option<String>,
    /// Cells in series.
    pub cells: u32,
    /// Rated capacity of one pack, mA h.
    pub capacity_mah: f64,
    /// Rated energy of one pack, W h.
    pub energy_wh: f64,
    /// Mass of one pack, kg.
    pub mass_kg: f64,
    /// Packs in parallel (default 1).
    #[serde(default = "one")]
    pub count: u32,
    /// Mass a multi-pack option adds besides the packs (a dual-battery kit), kg (default 0).
    #[serde(default)]
    pub mount_mass_kg: f64,
}

fn one() -> u32 {
    1
}

/// A published hover time and the take-off mass it was flown at.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PublishedHover {
    /// Take-off mass of the published figure (frame, packs, camera and payload), kg.
    pub takeoff_mass_kg: f64,
    /// Published hover time, min.
    pub minutes: f64,
    /// Where it was published.
    #[serde(default)]
    pub source: String,
}

/// Drag polynomial `f_D = mu1 v + mu2 v^2 + mu3 v^3` (eq 6).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpecDrag {
    /// N s/m.
    pub mu1_n_s_per_m: f64,
    /// N s^2/m^2.
    pub mu2_n_s2_per_m2: f64,
    /// N s^3/m^3.
    pub mu3_n_s3_per_m3: f64,
}

impl SpecSheet {
    /// Parse spec-sheet TOML; `origin` names it in errors.
    ///
    /// # Errors
    /// [`Error::SpecSheet`] for text that is not a spec sheet (a missing or unknown key, a value of
    /// the wrong type), naming the key.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, Error> {
        toml::from_str(text).map_err(|e| Error::SpecSheet {
            origin: origin.to_string(),
            key: missing_key(text, &e)
                .or_else(|| e.span().and_then(|s| place(text, s.start, e.message())))
                .unwrap_or_else(|| "(file)".to_string()),
            message: aloft_core::file_message(e.message()),
        })
    }
}

/// The dotted key a "missing field" error is about (`battery.cells`), from the message and the
/// table the error's span starts in.
fn missing_key(text: &str, e: &toml::de::Error) -> Option<String> {
    let field = e
        .message()
        .split("missing field `")
        .nth(1)?
        .split('`')
        .next()?;
    let table = e
        .span()
        .and_then(|s| text.get(s))
        .map(str::trim_start)
        .filter(|t| t.starts_with('['))
        .and_then(|t| t.lines().next())
        .map(|l| {
            l.trim()
                .trim_matches(|c| c == '[' || c == ']')
                .trim()
                .to_string()
        });
    Some(match table {
        Some(t) if !t.is_empty() => format!("{t}.{field}"),
        _ => field.to_string(),
    })
}

/// Where an error at byte `offset` is: the dotted key of its line, or for a key the spec sheet
/// does not have, its line number (the key is the file's text, not quoted: see
/// [`aloft_core::file_message`]).
fn place(text: &str, offset: usize, message: &str) -> Option<String> {
    if message.starts_with("unknown field") {
        let line = text.get(..offset)?.matches('\n').count() + 1;
        return Some(format!("line {line}"));
    }
    key_at(text, offset)
}

/// The dotted key (`battery.mass_kg`) of the `key = value` line holding byte `offset` of a TOML
/// text: the key before `=` under the last `[table]` header above it.
fn key_at(text: &str, offset: usize) -> Option<String> {
    let start = text.get(..offset)?.rfind('\n').map_or(0, |i| i + 1);
    let line = text[start..].lines().next()?;
    let key = line.split_once('=')?.0.trim();
    let table = text[..start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim());
    Some(match table {
        Some(t) if !t.is_empty() => format!("{t}.{key}"),
        _ => key.to_string(),
    })
}

/// The answer of [`calibrate_hover`]: the efficiency that reproduces a published hover time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HoverCalibration {
    /// Efficiency `eta` of eq (14).
    pub efficiency: f64,
    /// Electrical hover power at the calibration mass with that efficiency, W.
    pub hover_power_w: f64,
    /// The longest hover the pack could give at that mass with `eta = 1`, min.
    pub max_minutes_at_unit_efficiency: f64,
}

/// The efficiency `eta` for which the vehicle hovers `minutes` at `takeoff_mass_kg` on the pack
/// `battery` (the vehicle's default pack when `None`), through the same pack model and hover power
/// `aloft endurance` uses (flown to the empty point, no reserve).
///
/// Hover power scales as `1/eta` exactly (eq 14 divides every term), so the power the pack must
/// deliver for the hover time is found by bisection on [`endurance_at_power_s`] and
/// `eta = P(eta = 1) / P`.
///
/// # Errors
/// A vehicle without `[power]`, `[airframe]` or that pack; a hover time longer than the pack gives
/// at `eta = 1` or so short it needs `eta < 0.01` ([`Error::InvalidInput`] naming `minutes`).
pub fn calibrate_hover(
    file: &VehicleFile,
    battery: Option<&str>,
    takeoff_mass_kg: f64,
    minutes: f64,
) -> Result<HoverCalibration, Error> {
    IdealHover::of(file, battery, takeoff_mass_kg)?.calibrate(minutes)
}

/// The hover of a vehicle at one mass with `eta = 1`: its electrical power and the pack.
struct IdealHover {
    power_w: f64,
    pack: Pack,
}

impl IdealHover {
    fn of(file: &VehicleFile, battery: Option<&str>, takeoff_mass_kg: f64) -> Result<Self, Error> {
        let mut ideal = file.clone();
        if let Some(p) = ideal.power.as_mut() {
            p.efficiency = 1.0;
        }
        let (aircraft, _) = ideal.aircraft(ModelOptions::default())?;
        let pack = ideal.battery(battery)?;
        let power_w = aircraft
            .at_mass(takeoff_mass_kg, AoaModel::Geometric)
            .and_then(|p| p.level_power_w([0.0, 0.0], [0.0, 1.0]))
            .map_err(|e| Error::Planner(Box::new(e)))?;
        Ok(Self { power_w, pack })
    }

    /// Hover time on the pack at electrical power `power_w`, s.
    fn hover_s(&self, power_w: f64) -> f64 {
        endurance_at_power_s(&self.pack, power_w, 1.0, self.pack.empty_soc())
    }

    /// The longest hover the pack gives (`eta = 1`), min.
    fn longest_minutes(&self) -> f64 {
        self.hover_s(self.power_w) / 60.0
    }

    /// The efficiency that hovers `minutes`: bisection on the power (hover time falls as power
    /// rises), `eta = P(eta = 1) / P`.
    fn calibrate(&self, minutes: f64) -> Result<HoverCalibration, Error> {
        let (p1, target_s) = (self.power_w, minutes * 60.0);
        let bad = |expected: &'static str| Error::InvalidInput {
            name: "published hover minutes",
            value: minutes,
            unit: "min",
            expected,
        };
        if !(target_s > 0.0 && target_s.is_finite()) {
            return Err(bad("a positive, finite time"));
        }
        if self.hover_s(p1) < target_s {
            return Err(bad(
                "a time the pack can supply at this mass with an efficiency of at most 1",
            ));
        }
        if self.hover_s(p1 * 100.0) > target_s {
            return Err(bad(
                "a time the model reaches with an efficiency of at least 0.01",
            ));
        }
        let (mut lo, mut hi) = (p1, p1 * 100.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.hover_s(mid) > target_s {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-12 * hi {
                break;
            }
        }
        let p = 0.5 * (lo + hi);
        Ok(HoverCalibration {
            efficiency: p1 / p,
            hover_power_w: p,
            max_minutes_at_unit_efficiency: self.longest_minutes(),
        })
    }
}

/// A vehicle file made from a spec sheet ([`calibrate_spec`]), with what was calibrated and
/// what was assumed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpecCalibration {
    /// The vehicle file (`aloft vehicles calibrate -o`).
    #[serde(skip)]
    pub vehicle: VehicleFile,
    /// Vehicle name.
    pub name: String,
    /// The pack option it was calibrated with.
    pub battery: String,
    /// Take-off mass of the published hover, kg.
    pub takeoff_mass_kg: f64,
    /// Published hover time, min.
    pub published_minutes: f64,
    /// The calibration (before rounding `eta` to 4 digits in the file).
    #[serde(flatten)]
    pub calibration: HoverCalibration,
    /// Class defaults used, in words.
    pub defaults: Vec<String>,
}

impl SpecCalibration {
    /// Write the vehicle file ([`Self::to_toml`]) to `path` (`aloft vehicles calibrate -o`), in
    /// aloft's one way ([`crate::engine::basics::files::write_output`]): an existing file is replaced only with `force`.
    ///
    /// # Errors
    /// [`Error::Output`] naming the file when it exists (without `force`) or cannot be written.
    pub fn write_vehicle_file(&self, path: &std::path::Path, force: bool) -> Result<(), Error> {
        crate::engine::basics::files::write_output(path, self.to_toml()?.as_bytes(), force)
    }

    /// The vehicle file as TOML, headed by comments that say where each part came from.
    ///
    /// # Errors
    /// [`Error::OptionsFormat`] if serialisation fails (it does not for a checked vehicle).
    pub fn to_toml(&self) -> Result<String, Error> {
        let body = toml::to_string(&self.vehicle).map_err(|e| Error::OptionsFormat {
            what: "vehicle file",
            message: e.to_string(),
        })?;
        let mut head = format!(
            "# Made by `aloft vehicles calibrate` from the spec sheet of {}.\n\
             # efficiency: calibrated so the model hovers {} min at {} kg with {} (eta {:.6}).\n",
            comment_text(&self.name),
            self.published_minutes,
            self.takeoff_mass_kg,
            comment_text(&self.battery),
            self.calibration.efficiency
        );
        for d in &self.defaults {
            head.push_str(&format!("# default: {}\n", comment_text(d)));
        }
        Ok(format!("{head}\n{body}"))
    }
}

/// A vehicle file from a spec sheet: the four-term model with the sheet's rotors and masses, the
/// class defaults of the module documentation, and `eta` calibrated on the published hover.
///
/// # Errors
/// [`Error::SpecSheet`] naming the key of a value out of range (no rotors, a negative or zero
/// mass, a hover mass below frame plus packs, a hover time the pack could not supply at any
/// efficiency up to 1).
pub fn calibrate_spec(spec: &SpecSheet, origin: &str) -> Result<SpecCalibration, Error> {
    check_spec(spec, origin)?;
    let (mut file, defaults) = spec_vehicle(spec)?;
    let hover = &spec.published_hover;
    let ideal = IdealHover::of(&file, None, hover.takeoff_mass_kg)?;
    let calibration = ideal.calibrate(hover.minutes).map_err(|e| match e {
        Error::InvalidInput { expected, .. } => Error::SpecSheet {
            origin: origin.to_string(),
            key: "published_hover.minutes".to_string(),
            message: format!(
                "{} min is not {expected} (at most {:.1} min with eta = 1 at {} kg)",
                hover.minutes,
                ideal.longest_minutes(),
                hover.takeoff_mass_kg
            ),
        },
        other => other,
    })?;
    if let Some(p) = file.power.as_mut() {
        p.efficiency = (calibration.efficiency * 1e6).round() / 1e6;
    }
    let file = VehicleFile::from_toml_str(
        &toml::to_string(&file).map_err(|e| Error::OptionsFormat {
            what: "vehicle file",
            message: e.to_string(),
        })?,
        origin,
    )?;
    Ok(SpecCalibration {
        name: spec.name.clone(),
        battery: file.battery(None)?.name().to_string(),
        vehicle: file,
        takeoff_mass_kg: hover.takeoff_mass_kg,
        published_minutes: hover.minutes,
        calibration,
        defaults,
    })
}

/// [`calibrate_spec`] of the spec sheet at `path` (`aloft vehicles calibrate SPEC.toml`).
///
/// # Errors
/// The file's read error, and those of [`SpecSheet::from_toml`] and [`calibrate_spec`].
pub fn calibrate_spec_file(path: &std::path::Path) -> Result<SpecCalibration, Error> {
    let text = crate::engine::basics::files::read_text_file(path, "spec sheet")?;
    let origin = path.display().to_string();
    calibrate_spec(&SpecSheet::from_toml(&text, &origin)?, &origin)
}

/// Text for a TOML comment: anything that would end the comment line or reorder it (a control
/// character, a bidirectional override) escaped ([`crate::engine::basics::files::escaped`]), the line separators of
/// Unicode too.
fn comment_text(text: &str) -> String {
    crate::engine::basics::files::escaped(text)
        .replace('\u{2028}', "\\u{2028}")
        .replace('\u{2029}', "\\u{2029}")
}

/// `x` to 9 decimals: figures written to a file without binary noise (22.2, not 22.200000000000003).
fn round9(x: f64) -> f64 {
    (x * 1e9).round() / 1e9
}

/// Each value of a spec sheet against its physical range, naming the key of the first bad one.
fn check_spec(spec: &SpecSheet, origin: &str) -> Result<(), Error> {
    let fail = |key: &str, message: String| {
        Err(Error::SpecSheet {
            origin: origin.to_string(),
            key: key.to_string(),
            message,
        })
    };
    if !(1..=32).contains(&spec.rotors) {
        return fail(
            "rotors",
            format!("{} rotors: expected 1 to 32", spec.rotors),
        );
    }
    let b = &spec.battery;
    if !(1..=30).contains(&b.cells) {
        return fail(
            "battery.cells",
            format!("{} cells: expected 1 to 30", b.cells),
        );
    }
    if !(1..=64).contains(&b.count) {
        return fail(
            "battery.count",
            format!("{} packs: expected 1 to 64", b.count),
        );
    }
    let ranges: [(&str, f64, f64, f64, &str); 7] = [
        ("rotor_diameter_m", spec.rotor_diameter_m, 0.01, 5.0, "m"),
        ("frame_mass_kg", spec.frame_mass_kg, 0.01, 1000.0, "kg"),
        ("battery.capacity_mah", b.capacity_mah, 1.0, 1e7, "mAh"),
        ("battery.energy_wh", b.energy_wh, 0.01, 1e5, "Wh"),
        ("battery.mass_kg", b.mass_kg, 0.001, 500.0, "kg"),
        (
            "published_hover.takeoff_mass_kg",
            spec.published_hover.takeoff_mass_kg,
            0.01,
            2000.0,
            "kg",
        ),
        (
            "published_hover.minutes",
            spec.published_hover.minutes,
            0.1,
            1440.0,
            "min",
        ),
    ];
    for (key, value, lo, hi, unit) in ranges {
        if !(value >= lo && value <= hi) {
            return fail(key, format!("{value} {unit}: expected {lo} to {hi} {unit}"));
        }
    }
    if !(b.mount_mass_kg >= 0.0 && b.mount_mass_kg <= 100.0) {
        return fail(
            "battery.mount_mass_kg",
            format!("{} kg: expected 0 to 100 kg", b.mount_mass_kg),
        );
    }
    let volts = b.energy_wh / (b.capacity_mah / 1000.0) / f64::from(b.cells);
    if !(2.0..=4.5).contains(&volts) {
        return fail(
            "battery.energy_wh",
            format!(
                "{} Wh for {} mAh and {} cells is {volts:.2} V per cell: expected 2 to 4.5 V",
                b.energy_wh, b.capacity_mah, b.cells
            ),
        );
    }
    let empty = spec.frame_mass_kg + f64::from(b.count) * b.mass_kg + b.mount_mass_kg;
    if spec.published_hover.takeoff_mass_kg < empty - 1e-9 {
        return fail(
            "published_hover.takeoff_mass_kg",
            format!(
                "{} kg is less than the frame and packs ({empty:.3} kg)",
                spec.published_hover.takeoff_mass_kg
            ),
        );
    }
    if let Some(m) = spec.max_takeoff_mass_kg {
        if !(m >= spec.published_hover.takeoff_mass_kg && m <= 2000.0) {
            return fail(
                "max_takeoff_mass_kg",
                format!(
                    "{m} kg: expected at least the published hover's {} kg",
                    spec.published_hover.takeoff_mass_kg
                ),
            );
        }
    }
    Ok(())
}

/// The vehicle file of a spec sheet before calibration (`eta = 1`), and the defaults used.
fn spec_vehicle(spec: &SpecSheet) -> Result<(VehicleFile, Vec<String>), Error> {
    let mut defaults = Vec::new();
    let power = spec_power(spec, &mut defaults);
    let airframe = spec_airframe(spec, &mut defaults)?;
    defaults.push(format!(
        "pack: {} mohm per cell, cut-off {CUTOFF_CELL_V} V per cell, generic LiPo open-circuit curve",
        CELL_RESISTANCE_OHM * 1000.0
    ));
    let file = VehicleFile {
        name: spec.name.clone(),
        description: if spec.description.is_empty() {
            format!(
                "{} from its spec sheet (aloft vehicles calibrate)",
                spec.name
            )
        } else {
            spec.description.clone()
        },
        source: Some(spec_source(spec)),
        power: Some(power),
        propulsion: None,
        airframe: Some(airframe),
        batteries: vec![spec_pack(&spec.battery)],
    };
    Ok((file, defaults))
}

/// The four-term model of a spec sheet: its rotors, the class's profile share and drag.
fn spec_power(spec: &SpecSheet, defaults: &mut Vec<String>) -> VehicleParams {
    let radius = spec.rotor_diameter_m / 2.0;
    let all_disks = f64::from(spec.rotors) * std::f64::consts::PI * radius * radius;
    let seed_share = SEED_KAPPA1
        * (2.0 * SEA_LEVEL_DENSITY * std::f64::consts::PI * SEED_ROTOR_RADIUS_M.powi(2)).sqrt();
    let kappa1 = seed_share / (2.0 * SEA_LEVEL_DENSITY * all_disks).sqrt();
    defaults.push(format!(
        "profile power {:.1} % of the ideal induced power at hover (the power seed's M100): kappa1 = {kappa1:.4} W/N^1.5",
        seed_share * 100.0
    ));
    let drag = spec.drag.unwrap_or_else(|| {
        let scale = all_disks
            / (SEED_ROTORS * std::f64::consts::PI * SEED_ROTOR_RADIUS_M * SEED_ROTOR_RADIUS_M);
        defaults.push(format!(
            "drag: the power seed's M100 polynomial (Fig. 3) x {scale:.3}, its total rotor disk area against the M100's"
        ));
        SpecDrag {
            mu1_n_s_per_m: round9(SEED_MU[0] * scale),
            mu2_n_s2_per_m2: round9(SEED_MU[1] * scale),
            mu3_n_s3_per_m3: round9(SEED_MU[2] * scale),
        }
    });
    VehicleParams {
        mass_kg: spec.published_hover.takeoff_mass_kg,
        gravity_mps2: aloft_core::STANDARD_GRAVITY_MPS2,
        air_density_kg_m3: SEA_LEVEL_DENSITY,
        rotor_count: spec.rotors,
        rotor_radius_m: radius,
        disk_area: DiskArea::AllRotors,
        mu1_n_s_per_m: drag.mu1_n_s_per_m,
        mu2_n_s2_per_m2: drag.mu2_n_s2_per_m2,
        mu3_n_s3_per_m3: drag.mu3_n_s3_per_m3,
        kappa1_w_per_n1_5: round9(kappa1),
        kappa2_w_s2_per_m2_n0_5: 0.0,
        efficiency: 1.0,
        mu2_x_n_s2_per_m2: None,
        mu2_y_n_s2_per_m2: None,
        efficiency_relative_sd: None,
    }
}

/// The airframe of a spec sheet: its masses in the M100's envelope (its published limits and
/// assumed accelerations).
fn spec_airframe(spec: &SpecSheet, defaults: &mut Vec<String>) -> Result<AirframeSpec, Error> {
    let m100_envelope =
        VehicleFile::builtin("dji-m100")?
            .airframe
            .ok_or_else(|| Error::MissingTable {
                vehicle: "dji-m100".to_string(),
                table: "airframe",
                needed_for: "the class defaults of a spec sheet",
            })?;
    let hover_kg = spec.published_hover.takeoff_mass_kg;
    let max_takeoff = spec.max_takeoff_mass_kg.unwrap_or_else(|| {
        defaults.push(format!(
            "largest take-off mass: the published hover's {hover_kg} kg (max_takeoff_mass_kg not given)"
        ));
        hover_kg
    });
    defaults.push(
        "flight envelope: the M100's (35 deg tilt, 17 m/s, climb 5 m/s, descent 4 m/s, 2 m/s^2, rotors 0.30 m above the ground)"
            .to_string(),
    );
    Ok(AirframeSpec {
        mass_kg: spec.frame_mass_kg,
        max_takeoff_mass_kg: max_takeoff,
        max_thrust_n: None,
        cruise_speed_mps: None,
        rtl_altitude_m: None,
        ..m100_envelope
    })
}

/// The pack option of a spec sheet: `count` packs in parallel, the kit's mass included.
fn spec_pack(b: &SpecBattery) -> BatterySpec {
    let count = f64::from(b.count);
    BatterySpec {
        name: b
            .name
            .clone()
            .unwrap_or_else(|| format!("{}x{}mAh", b.count, b.capacity_mah)),
        default: true,
        cells_series: b.cells,
        capacity_mah: b.capacity_mah * count,
        nominal_v: Some(round9(b.energy_wh / (b.capacity_mah / 1000.0))),
        energy_wh: Some(round9(b.energy_wh * count)),
        mass_kg: Some(round9(b.mass_kg * count + b.mount_mass_kg)),
        internal_resistance_ohm: Some(CELL_RESISTANCE_OHM * f64::from(b.cells) / count),
        cutoff_cell_v: Some(CUTOFF_CELL_V),
        ..BatterySpec::default()
    }
}

/// The `[source]` of a spec-sheet vehicle: the sheet's figures and where they were published.
fn spec_source(spec: &SpecSheet) -> VehicleSource {
    let (b, hover) = (&spec.battery, &spec.published_hover);
    VehicleSource {
        figures: format!(
            "{} rotors of {} m; frame {} kg; {} pack(s) of {}S, {} mAh, {} Wh, {} kg; hover {} min at {} kg",
            spec.rotors,
            spec.rotor_diameter_m,
            spec.frame_mass_kg,
            b.count,
            b.cells,
            b.capacity_mah,
            b.energy_wh,
            b.mass_kg,
            hover.minutes,
            hover.takeoff_mass_kg
        ),
        calibrated_on: format!("hover {} min at {} kg", hover.minutes, hover.takeoff_mass_kg),
        published: if hover.source.is_empty() {
            "the spec sheet given to aloft vehicles calibrate".to_string()
        } else {
            hover.source.clone()
        },
    }
}
