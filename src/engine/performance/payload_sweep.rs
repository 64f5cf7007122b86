//! Endurance against payload, one curve per battery pack, as manufacturers chart it
//! (`aloft endurance --payload-sweep START:STOP:STEP`): the answers of [`endurance`] at each
//! payload of a [`PayloadSweep`], for the options' pack or every pack of the vehicle.
//!
//! No physics of its own: every row is [`endurance`] at that payload and pack (the same answer,
//! bit for bit, as `aloft endurance --payload-kg P --battery B`). A pack's curve stops at the
//! first payload whose take-off mass exceeds the airframe's limit, and a note says where.

use std::fmt;

use serde::Serialize;

use aloft_planner::EnduranceReport;

use crate::engine::basics::finite::finite;
use crate::engine::performance::endurance::{endurance, EnduranceOptions, EnduranceSummary};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::{Error, SweepProblem};

/// The most payloads a sweep may have.
pub const MAX_PAYLOAD_POINTS: usize = 1000;

/// The payloads of a sweep, kg: `START, START + STEP, ...` up to `STOP` inclusive (within
/// `STEP x 1e-9`, so `0:1:0.1` ends at 1 despite rounding). Valid once built: finite,
/// `0 <= START <= STOP`, `STEP > 0`, at most [`MAX_PAYLOAD_POINTS`] payloads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PayloadSweep {
    start_kg: f64,
    stop_kg: f64,
    step_kg: f64,
    /// Steps from START to the last payload.
    steps: usize,
}

/// Tolerance of the last payload, in steps: `STOP` counts as reached when `START + n STEP`
/// misses it by at most this fraction of a step (the rounding of decimal steps such as 0.1 is
/// about 1e-16 of a step; 1e-9 is far above it and far below any step a user means).
const STOP_TOLERANCE_STEPS: f64 = 1e-9;

impl PayloadSweep {
    /// A sweep from `start_kg` to `stop_kg` in steps of `step_kg`.
    ///
    /// # Errors
    /// [`Error::PayloadSweep`] naming what is wrong (a value that is not finite, a negative
    /// START, STOP below START, a STEP that is not positive, too many payloads).
    pub fn new(start_kg: f64, stop_kg: f64, step_kg: f64) -> Result<Self, Error> {
        let problem = |problem| Error::PayloadSweep {
            text: format!("{start_kg}:{stop_kg}:{step_kg}"),
            problem,
        };
        for (field, value_kg) in [("START", start_kg), ("STOP", stop_kg), ("STEP", step_kg)] {
            if !value_kg.is_finite() {
                return Err(problem(SweepProblem::NotFinite { field, value_kg }));
            }
        }
        if start_kg < 0.0 {
            return Err(problem(SweepProblem::NegativeStart { start_kg }));
        }
        if stop_kg < start_kg {
            return Err(problem(SweepProblem::StopBelowStart { start_kg, stop_kg }));
        }
        if step_kg <= 0.0 {
            return Err(problem(SweepProblem::StepNotPositive { step_kg }));
        }
        let steps = ((stop_kg - start_kg) / step_kg + STOP_TOLERANCE_STEPS).floor();
        // Checked as a float first: 0:1e9:1e-9 would be 1e18 payloads.
        if steps + 1.0 > MAX_PAYLOAD_POINTS as f64 {
            return Err(problem(SweepProblem::TooManyPoints {
                points: steps + 1.0,
                max: MAX_PAYLOAD_POINTS,
            }));
        }
        Ok(Self {
            start_kg,
            stop_kg,
            step_kg,
            // In [0, MAX_PAYLOAD_POINTS) by the checks above.
            steps: steps as usize,
        })
    }

    /// A sweep from its text `START:STOP:STEP` in kg (`0:1:0.25`), as `--payload-sweep` takes
    /// it.
    ///
    /// # Errors
    /// [`Error::PayloadSweep`]: not three numbers, and what [`PayloadSweep::new`] refuses.
    pub fn parse(text: &str) -> Result<Self, Error> {
        let problem = |problem| Error::PayloadSweep {
            text: text.to_string(),
            problem,
        };
        let fields: Vec<&str> = text.split(':').map(str::trim).collect();
        let [start, stop, step] = fields.as_slice() else {
            return Err(problem(SweepProblem::Format));
        };
        let number = |field: &'static str, s: &str| {
            s.parse::<f64>().map_err(|_| {
                problem(SweepProblem::NotANumber {
                    field,
                    text: s.to_string(),
                })
            })
        };
        let (start, stop, step) = (
            number("START", start)?,
            number("STOP", stop)?,
            number("STEP", step)?,
        );
        Self::new(start, stop, step).map_err(|e| match e {
            Error::PayloadSweep { problem: p, .. } => problem(p),
            other => other,
        })
    }

    /// The first payload, kg.
    pub fn start_kg(&self) -> f64 {
        self.start_kg
    }

    /// The last payload asked for, kg.
    pub fn stop_kg(&self) -> f64 {
        self.stop_kg
    }

    /// The step, kg.
    pub fn step_kg(&self) -> f64 {
        self.step_kg
    }

    /// The payloads, kg, in increasing order: `START + i STEP` rounded to 12 significant digits
    /// (so a step of 0.1 gives 0.3, not 0.30000000000000004; a microgram in a kilogram is far
    /// below anything a mass is known to), the last one `STOP` itself when it is reached.
    pub fn payloads_kg(&self) -> Vec<f64> {
        (0..=self.steps)
            .map(|i| {
                let p = self.start_kg + i as f64 * self.step_kg;
                if i == self.steps
                    && (p - self.stop_kg).abs() <= STOP_TOLERANCE_STEPS * self.step_kg
                {
                    self.stop_kg
                } else {
                    twelve_digits(p)
                }
            })
            .collect()
    }
}

/// `x` rounded to 12 significant digits.
fn twelve_digits(x: f64) -> f64 {
    format!("{x:.11e}").parse().unwrap_or(x)
}

impl fmt::Display for PayloadSweep {
    /// `START:STOP:STEP`, as `--payload-sweep` takes it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.start_kg, self.stop_kg, self.step_kg)
    }
}

/// One payload with one pack: the answers of [`endurance`] there.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PayloadRow {
    /// Pack name.
    pub battery: String,
    /// Payload, kg.
    pub payload_kg: f64,
    /// Take-off mass (airframe + pack + payload), kg.
    pub takeoff_mass_kg: f64,
    /// The endurance queries' answers at this payload (flattened: `hover_power_w`,
    /// `hover_endurance_s`, `max_endurance_speed_mps`, `max_endurance_s`, `max_range_speed_mps`,
    /// `max_range_m`, ...).
    #[serde(flatten)]
    pub report: EnduranceReport,
}

/// A pack of the sweep and how much payload it leaves room for.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweptPack {
    /// Pack name.
    pub name: String,
    /// Rated energy, Wh.
    pub energy_wh: f64,
    /// Pack mass, kg.
    pub mass_kg: f64,
    /// The largest payload within the maximum take-off mass with this pack, kg (negative when
    /// the airframe and the pack alone exceed it).
    pub max_payload_kg: f64,
}

/// The answer of [`payload_sweep`]: the JSON of `aloft endurance --payload-sweep --format json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PayloadCurve {
    /// Vehicle name.
    pub vehicle: String,
    /// The wind, in words.
    pub wind: String,
    /// Course of the range query, degrees clockwise from north.
    pub course_deg: f64,
    /// Reserve kept, percent of the usable capacity.
    pub reserve_percent: f64,
    /// The airframe's maximum take-off mass, kg.
    pub max_takeoff_mass_kg: f64,
    /// The packs swept, in the order of the rows.
    pub batteries: Vec<SweptPack>,
    /// One row per pack and payload that fits, pack by pack, payloads increasing.
    pub rows: Vec<PayloadRow>,
    /// Where a pack's curve stops (the maximum take-off mass), and notes on the vehicle's model.
    pub notes: Vec<String>,
}

impl PayloadCurve {
    /// The rows of one pack, payloads increasing.
    pub fn rows_of<'a>(&'a self, battery: &'a str) -> impl Iterator<Item = &'a PayloadRow> + 'a {
        self.rows.iter().filter(move |r| r.battery == battery)
    }

    /// Append the answer of [`endurance`] at `payload_kg` (the wind's words from the first).
    fn push(&mut self, payload_kg: f64, summary: EnduranceSummary) {
        if self.wind.is_empty() {
            self.wind = summary.context.wind;
        }
        self.rows.push(PayloadRow {
            battery: summary.battery,
            payload_kg,
            takeoff_mass_kg: summary.takeoff_mass_kg,
            report: summary.report,
        });
    }
}

/// Hover endurance, best endurance and best range against payload: [`endurance`] at each payload
/// of `sweep`, with the options' pack or, when they name none, with every pack of the vehicle (the
/// default first), in the options' wind, course and reserve. A pack's curve stops at the first
/// payload above the maximum take-off mass, with a note.
///
/// # Errors
/// A payload in the options (the sweep sets it), no payload of the sweep within the maximum
/// take-off mass with any pack ([`Error::SweepTooHeavy`]), and what [`endurance`] refuses.
pub fn payload_sweep(
    vehicle: &Vehicle,
    options: &EnduranceOptions,
    sweep: &PayloadSweep,
) -> Result<PayloadCurve, Error> {
    if options.payload_kg.abs() > 0.0 {
        return Err(Error::Contradiction {
            message: format!(
                "a payload sweep sets the payload: payload_kg = {} kg cannot be given with it",
                options.payload_kg
            ),
        });
    }
    let (vehicle, _air) = crate::engine::conditions::air::vehicle_air(vehicle, &options.air)?;
    let vehicle = &vehicle;
    let airframe = vehicle.aircraft()?.airframe();
    let mut curve = PayloadCurve {
        vehicle: vehicle.name().to_string(),
        wind: String::new(),
        course_deg: options.course_deg,
        reserve_percent: options.reserve_percent,
        max_takeoff_mass_kg: airframe.max_takeoff_mass_kg(),
        batteries: Vec::new(),
        rows: Vec::new(),
        notes: vehicle.notes(),
    };
    let payloads = sweep.payloads_kg();
    for name in pack_names(vehicle, options)? {
        let pack = vehicle.battery(Some(&name))?;
        let swept = SweptPack {
            max_payload_kg: airframe.max_takeoff_mass_kg() - airframe.mass_kg() - pack.mass_kg(),
            name,
            energy_wh: pack.rated_energy_wh(),
            mass_kg: pack.mass_kg(),
        };
        let pack_options = EnduranceOptions {
            battery: Some(swept.name.clone()),
            ..options.clone()
        };
        let stop = sweep_pack(vehicle, &pack_options, &payloads, &mut curve)?;
        if let Some(too_heavy_kg) = stop {
            curve.notes.push(limit_note(&swept, &curve, too_heavy_kg));
        }
        curve.batteries.push(swept);
    }
    if curve.rows.is_empty() {
        return Err(Error::SweepTooHeavy {
            start_kg: sweep.start_kg(),
            max_takeoff_mass_kg: curve.max_takeoff_mass_kg,
            max_payload_kg: curve
                .batteries
                .iter()
                .map(|b| b.max_payload_kg)
                .fold(f64::NEG_INFINITY, f64::max),
        });
    }
    finite(curve, "payload sweep", || {
        format!(
            "vehicle {} with {options:?}, payloads {sweep} kg",
            vehicle.name()
        )
    })
}

/// The packs to sweep: the options' (by its name in the vehicle file), else every pack, the
/// default first.
fn pack_names(vehicle: &Vehicle, options: &EnduranceOptions) -> Result<Vec<String>, Error> {
    match options.battery.as_deref() {
        Some(name) => Ok(vec![vehicle.battery(Some(name))?.name().to_string()]),
        None => {
            // The vehicle's own error when it has no pack at all.
            vehicle.battery(None)?;
            Ok(vehicle
                .file()
                .battery_names()
                .into_iter()
                .map(str::to_string)
                .collect())
        }
    }
}

/// Append the rows of one pack (the options name it) to `curve`, payload by payload; returns the
/// first payload above the maximum take-off mass, where the pack's curve stops, if any.
fn sweep_pack(
    vehicle: &Vehicle,
    options: &EnduranceOptions,
    payloads_kg: &[f64],
    curve: &mut PayloadCurve,
) -> Result<Option<f64>, Error> {
    for &payload_kg in payloads_kg {
        let at = EnduranceOptions {
            payload_kg,
            ..options.clone()
        };
        match endurance(vehicle, &at) {
            Ok(summary) => curve.push(payload_kg, summary),
            Err(Error::TooHeavy { .. }) => return Ok(Some(payload_kg)),
            Err(e) => return Err(e),
        }
    }
    Ok(None)
}

/// The note where a pack's curve stops at `too_heavy_kg`.
fn limit_note(pack: &SweptPack, curve: &PayloadCurve, too_heavy_kg: f64) -> String {
    let limit = format!("{:.3} kg maximum take-off mass", curve.max_takeoff_mass_kg);
    if pack.max_payload_kg < 0.0 {
        return format!(
            "{}: the airframe with this {:.3} kg pack alone exceeds the {limit}; no payload swept",
            pack.name, pack.mass_kg
        );
    }
    let last = curve.rows_of(&pack.name).last().map(|r| r.payload_kg);
    let stops = match last {
        Some(p) => format!("the curve stops at {p} kg"),
        None => format!("no payload of the sweep (from {too_heavy_kg} kg) fits"),
    };
    format!(
        "{}: payloads above {:.3} kg exceed the {limit}; {stops}",
        pack.name, pack.max_payload_kg
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m100() -> Vehicle {
        Vehicle::builtin("dji-m100").unwrap()
    }

    fn problem(e: Error) -> SweepProblem {
        match e {
            Error::PayloadSweep { problem, .. } => problem,
            other => panic!("not a sweep error: {other}"),
        }
    }

    #[test]
    fn payloads_include_stop_despite_decimal_rounding() {
        let s = PayloadSweep::parse("0:1:0.1").unwrap();
        let p = s.payloads_kg();
        assert_eq!(p.len(), 11);
        // Exact: the rounding to 12 digits gives the decimal a user typed.
        assert_eq!(p[3].to_bits(), 0.3f64.to_bits());
        assert_eq!(p[10].to_bits(), 1.0f64.to_bits());
        // A STOP between steps is not reached: 0, 0.4, 0.8.
        assert_eq!(
            PayloadSweep::parse("0:1:0.4").unwrap().payloads_kg().len(),
            3
        );
        // START = STOP is one payload.
        assert_eq!(
            PayloadSweep::parse("0.5:0.5:1").unwrap().payloads_kg(),
            vec![0.5]
        );
    }

    #[test]
    fn invalid_sweeps_say_what_is_wrong() {
        let p = |t: &str| problem(PayloadSweep::parse(t).unwrap_err());
        assert!(matches!(p("0:1"), SweepProblem::Format));
        assert!(matches!(
            p("a:b:c"),
            SweepProblem::NotANumber { field: "START", .. }
        ));
        assert!(matches!(
            p("0:1:nan"),
            SweepProblem::NotFinite { field: "STEP", .. }
        ));
        assert!(matches!(p("-1:1:0.5"), SweepProblem::NegativeStart { .. }));
        assert!(matches!(p("1:0:0.1"), SweepProblem::StopBelowStart { .. }));
        assert!(matches!(p("0:1:0"), SweepProblem::StepNotPositive { .. }));
        assert!(matches!(
            p("0:1:-0.1"),
            SweepProblem::StepNotPositive { .. }
        ));
        assert!(matches!(
            p("0:1e9:1e-9"),
            SweepProblem::TooManyPoints {
                max: MAX_PAYLOAD_POINTS,
                ..
            }
        ));
        // 1000 payloads is the limit, 1001 one too many.
        assert!(PayloadSweep::parse("0:999:1").is_ok());
        assert!(PayloadSweep::parse("0:1000:1").is_err());
        let text = PayloadSweep::parse("1:0:0.1").unwrap_err().to_string();
        assert!(
            text.contains("1:0:0.1") && text.contains("below START"),
            "{text}"
        );
    }

    #[test]
    fn every_pack_is_swept_default_first_and_the_named_pack_alone() {
        let v = m100();
        let sweep = PayloadSweep::parse("0:0.3:0.15").unwrap();
        let all = payload_sweep(&v, &EnduranceOptions::default(), &sweep).unwrap();
        let names: Vec<&str> = all.batteries.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, v.file().battery_names());
        assert_eq!(all.rows.len(), 3 * names.len());
        let one = EnduranceOptions {
            battery: Some("tb48d".into()),
            ..EnduranceOptions::default()
        };
        let tb48d = payload_sweep(&v, &one, &sweep).unwrap();
        assert_eq!(tb48d.batteries.len(), 1);
        assert!(tb48d.rows.iter().all(|r| r.battery == "TB48D"));
        // The same rows as in the sweep of every pack.
        let from_all: Vec<&PayloadRow> = all.rows_of("TB48D").collect();
        assert_eq!(from_all, tb48d.rows.iter().collect::<Vec<_>>());
    }

    #[test]
    fn a_payload_in_the_options_is_refused() {
        let options = EnduranceOptions {
            payload_kg: 0.5,
            ..EnduranceOptions::default()
        };
        let sweep = PayloadSweep::parse("0:1:0.5").unwrap();
        let e = payload_sweep(&m100(), &options, &sweep).unwrap_err();
        assert!(matches!(e, Error::Contradiction { .. }), "{e}");
    }

    #[test]
    fn a_sweep_entirely_above_the_limit_is_an_error_naming_it() {
        let sweep = PayloadSweep::parse("50:60:1").unwrap();
        let e = payload_sweep(&m100(), &EnduranceOptions::default(), &sweep).unwrap_err();
        assert!(matches!(e, Error::SweepTooHeavy { .. }), "{e}");
        assert!(
            e.to_string().contains("3.600 kg maximum take-off mass"),
            "{e}"
        );
    }
}
