//! `aloft pack fit`: a pack file from the pack's own logs.
//!
//! Each log is read for its battery records ([`aloft_logs::read_battery_log`]) and analysed
//! ([`aloft_packs::analyse_with`]); the flights combine into one pack:
//!
//! - `internal_resistance_ohm`: the median over the flights of each flight's step estimate (a
//!   flight without enough current steps gives none); without any, the median of the
//!   autopilot's own estimates; without that, the `--battery` pack's, with a note.
//! - `capacity_mah`: the median of the capacities estimated between two rests; else
//!   `--capacity-mah`, the `--battery` pack's, or the logs' rated capacity (`BAT1_CAPACITY`,
//!   `BATT_CAPACITY`), in that order.
//! - `cells_series`: `--cells`, the `--battery` pack's, else the logs'.
//! - what logs cannot give (mass, nominal voltage, cut-off, usable fraction): the flags, else the
//!   `--battery` pack of the vehicle, else the documented defaults [`DEFAULT_NOMINAL_CELL_V`]
//!   (nominal voltage), [`DEFAULT_CUTOFF_CELL_V`] (cut-off) and a usable fraction of 1; the
//!   mass has no default.
//! - `[failsafe]`: ArduPilot's `BATT_LOW_VOLT` / `BATT_CRT_VOLT` as logged (the last log's).
//! - `ocv_soc`, `ocv_cell_v`: the pack's own open-circuit curve ([`aloft_packs::flight_ocv`],
//!   [`aloft_packs::combine_flight_ocv`]) on the capacity and resistance written, where the logs
//!   carry the pack's gauge or start rested and cover enough charge; the generic curve outside
//!   what they measured (`[fitted]` `ocv_measured_soc`). Otherwise the `--battery` pack's curve
//!   (or none: the generic one) is kept and the answer says why (`ocv_refused`).
//! - `rc_resistance_ohm`, `rc_time_constant_s`: the RC pair of the pack's equivalent circuit
//!   ([`aloft_packs::rc_from_flight`], [`aloft_packs::rc_of_flights`]) where at least three
//!   flights identify one and agree. Otherwise, beside a curve fitted here (under load, `V + I R`:
//!   it holds the pack's mean polarisation already), a pair of no resistance, so that the
//!   state-of-charge filter does not count that sag twice; beside none, no pair (the filter keeps
//!   its default and learns its resistance in flight). The answer says why (`rc_refused`).
//!
//! A log that cannot be read is an error naming it (exit 2); a log without battery records or
//! without current is skipped with its reason; with none usable the answer has no pack (exit 1).

use std::path::PathBuf;

use serde::Serialize;

use aloft_logs::BatterySample;
use aloft_logs::{read_battery_log, OpenOptions, Profile};
use aloft_packs::{analyse_with, FittedOcv, PackOptions, PackReport};

use crate::engine::basics::files::{check_output, write_output};
use crate::engine::basics::finite::finite;
use crate::engine::basics::logs::SkippedLog;
use crate::engine::packs::pack_file::{Failsafe, PackFile};
use crate::engine::vehicles::vehicle::Vehicle;
use crate::error::Error;

/// Nominal cell voltage of a LiPo cell when nothing gives the pack's, V.
pub const DEFAULT_NOMINAL_CELL_V: f64 = 3.7;
/// Cut-off cell voltage under load when nothing gives the pack's, V.
pub const DEFAULT_CUTOFF_CELL_V: f64 = 3.3;

/// What `aloft pack fit` is asked.
#[derive(Debug, Clone, Default)]
pub struct PackFitRequest {
    /// The logs.
    pub logs: Vec<PathBuf>,
    /// CSV profile (`kaist`, `px4`) or column-map file.
    pub profile: Option<String>,
    /// The battery instance of ULog / DataFlash logs.
    pub battery_instance: u8,
    /// The vehicle whose `--battery` pack gives the keys the logs cannot.
    pub vehicle: Option<Vehicle>,
    /// That pack's name.
    pub battery: Option<String>,
    /// The pack's name in the file (default: the `--battery` pack's, else the logged serial,
    /// else `fitted`).
    pub name: Option<String>,
    /// Cells in series.
    pub cells_series: Option<u32>,
    /// Rated capacity, mA h (used when no capacity is estimated, and for cycles).
    pub capacity_mah: Option<f64>,
    /// Pack mass, kg.
    pub mass_kg: Option<f64>,
    /// Nominal pack voltage, V.
    pub nominal_v: Option<f64>,
    /// Cut-off cell voltage under load, V.
    pub cutoff_cell_v: Option<f64>,
    /// Usable fraction of the capacity.
    pub usable_fraction: Option<f64>,
    /// Where to write the pack file.
    pub output: Option<PathBuf>,
    /// Replace an existing `output` (a regular file or a link itself; never a device, a FIFO or
    /// a folder). Without it an existing file is kept and the fit refused before any log is read.
    pub force: bool,
}

/// What `aloft pack fit` answers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PackFitAnswer {
    /// Each usable log's analysis.
    pub logs: Vec<PackReport>,
    /// Logs left out.
    pub skipped: Vec<SkippedLog>,
    /// The pack's internal resistance written, Ω.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub internal_resistance_ohm: Option<f64>,
    /// Where it came from: `current steps`, `autopilot`, `--battery pack`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub internal_resistance_source: Option<String>,
    /// The autopilot's own estimate over the flights (median), Ω.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub autopilot_internal_resistance_ohm: Option<f64>,
    /// Capacity estimated between rests (median over the flights), mA h.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacity_mah: Option<f64>,
    /// Capacity written, mA h.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pack_capacity_mah: Option<f64>,
    /// Charge drawn over all the logs, mA h.
    pub discharged_mah: f64,
    /// Discharged charge / rated charge over all the logs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub equivalent_cycles: Option<f64>,
    /// The pack's own open-circuit curve written, and the part of it the logs measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ocv: Option<FittedOcv>,
    /// Why no open-circuit curve was fitted, in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ocv_refused: Option<String>,
    /// The RC pair written: resistance (ohm) and time constant (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rc_resistance_ohm: Option<f64>,
    /// The RC pair's time constant written, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rc_time_constant_s: Option<f64>,
    /// Why no RC pair was written, in words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rc_refused: Option<String>,
    /// The pack written (none when no log was usable).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pack: Option<PackFile>,
    /// Its TOML text.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pack_toml: Option<String>,
    /// The file written (empty when none).
    pub output: String,
    /// Notes for the reader.
    pub notes: Vec<String>,
}

/// Read, analyse and combine the logs into a pack (see the module docs).
///
/// # Errors
/// A log that cannot be read ([`Error::LogFile`], naming it), an unknown `--battery` pack, a key no
/// source gives ([`Error::PackKeyMissing`]), a pack the planner refuses, an output that cannot be
/// written.
pub fn fit_pack(request: &PackFitRequest) -> Result<PackFitAnswer, Error> {
    check_capacity(request.capacity_mah)?;
    if let Some(path) = &request.output {
        check_output(path, request.force)?;
    }
    let base = base_pack(request)?;
    let options = PackOptions {
        rated_capacity_mah: request
            .capacity_mah
            .or(base.as_ref().map(|b| b.capacity_mah)),
        cells_series: request
            .cells_series
            .or(base.as_ref().map(|b| b.cells_series)),
    };
    let analysed = analyse_logs(request, &options)?;
    let mut answer = combine(analysed.logs, analysed.skipped, &options, base.as_ref());
    answer.notes.extend(analysed.notes);
    if answer.logs.is_empty() {
        return Ok(answer);
    }
    let mut spec = pack_spec(
        request,
        &mut answer,
        &options,
        base.as_ref(),
        analysed.serial,
    )?;
    fit_curve(&mut spec, &mut answer, &analysed.records);
    fit_rc(&mut spec, &mut answer, &analysed.records);
    let failsafe = analysed.failsafe;
    let pack = PackFile {
        battery: spec,
        failsafe: (failsafe != Failsafe::default()).then_some(failsafe),
        fitted: Some(fitted_table(&answer)),
    };
    let text = pack.to_toml()?;
    // What is written must load: the same checks as --battery pack.toml.
    let origin = request.output.as_ref().map_or_else(
        || "the fitted pack".to_string(),
        |p| p.display().to_string(),
    );
    let pack = PackFile::from_toml_str(&text, &origin)?;
    if let Some(path) = &request.output {
        write_output(path, text.as_bytes(), request.force)?;
        answer.output = path.display().to_string();
    }
    answer.pack = Some(pack);
    answer.pack_toml = Some(text);
    finite(answer, "pack fit", || format!("logs {:?}", request.logs))
}

/// A given capacity is a pack's: from 10 to 1e7 mA h (below, a unit slip).
///
/// # Errors
/// [`Error::InvalidInput`] naming `--capacity-mah`, its value and its range.
fn check_capacity(capacity_mah: Option<f64>) -> Result<(), Error> {
    let (min, max) = aloft_core::BATTERY_CAPACITY_RANGE_MAH;
    match capacity_mah.filter(|c| !(min..=max).contains(c)) {
        Some(c) => Err(Error::InvalidInput {
            name: "--capacity-mah",
            value: c,
            unit: "mA h",
            expected: "a pack's capacity, from 10 to 1e7 mA h",
        }),
        None => Ok(()),
    }
}

/// The `--battery` pack of the request's vehicle, which gives the keys the logs cannot.
///
/// # Errors
/// A pack the vehicle does not have (its message lists its packs).
fn base_pack(request: &PackFitRequest) -> Result<Option<aloft_planner::BatterySpec>, Error> {
    let (Some(v), Some(b)) = (&request.vehicle, &request.battery) else {
        return Ok(None);
    };
    v.file()
        .batteries
        .iter()
        .find(|s| s.name.eq_ignore_ascii_case(b))
        .cloned()
        .map(Some)
        .ok_or_else(|| {
            v.battery(Some(b)).err().unwrap_or(Error::PackKeyMissing {
                key: "name",
                hint: "no such pack",
            })
        })
}

/// The logs analysed one by one, the skipped ones with their reasons, and what they say of the
/// pack besides (the failsafes, the last log's; the first serial logged).
struct Analysed {
    logs: Vec<PackReport>,
    skipped: Vec<SkippedLog>,
    failsafe: Failsafe,
    serial: Option<String>,
    /// What the logs' readers noted (a capacity parameter no pack has), each after its log's
    /// name.
    notes: Vec<String>,
    /// Each analysed log's records, in the order of `logs`.
    records: Vec<Vec<BatterySample>>,
}

/// Read and analyse each log: one that reads but holds no battery record (no power sensor) or
/// no current is skipped, not an error.
///
/// # Errors
/// A log that cannot be read ([`Error::LogFile`], naming it); a profile that cannot be read.
fn analyse_logs(request: &PackFitRequest, options: &PackOptions) -> Result<Analysed, Error> {
    let profile = request
        .profile
        .as_deref()
        .map(Profile::resolve)
        .transpose()?;
    let mut open = OpenOptions::default();
    open.binary.battery_instance = request.battery_instance;
    let mut out = Analysed {
        logs: Vec::new(),
        skipped: Vec::new(),
        failsafe: Failsafe::default(),
        serial: None,
        notes: Vec::new(),
        records: Vec::new(),
    };
    for path in &request.logs {
        let file = path.display().to_string();
        let log = match read_battery_log(path, profile.as_ref(), &open) {
            Ok(l) => l,
            Err(aloft_logs::LogError::NoBatteryData { reason, .. }) => {
                out.skipped.push(SkippedLog { file, reason });
                continue;
            }
            Err(e) => return Err(Error::LogFile(Box::new(e))),
        };
        if let Some(note) = &log.capacity_note {
            let name = path
                .file_name()
                .map_or(file.clone(), |n| n.to_string_lossy().into_owned());
            out.notes.push(format!("{name}: {note}"));
        }
        if !log.has_current() {
            out.skipped.push(SkippedLog {
                file,
                reason: "no current is logged (voltage only): nothing to fit a pack on".into(),
            });
            continue;
        }
        match analyse_with(&log, options) {
            Ok(r) => {
                let f = &mut out.failsafe;
                f.low_voltage_v = r.low_voltage_failsafe_v.or(f.low_voltage_v);
                f.critical_voltage_v = r.critical_voltage_failsafe_v.or(f.critical_voltage_v);
                out.serial = out.serial.or(r.pack_id.clone());
                out.logs.push(r);
                out.records.push(log.samples);
            }
            Err(e) => out.skipped.push(SkippedLog {
                file,
                reason: e.to_string(),
            }),
        }
    }
    Ok(out)
}

/// The flights combined (module docs): the resistance and where it comes from, the capacity
/// estimated between rests, the charge drawn and the equivalent cycles.
fn combine(
    logs: Vec<PackReport>,
    skipped: Vec<SkippedLog>,
    options: &PackOptions,
    base: Option<&aloft_planner::BatterySpec>,
) -> PackFitAnswer {
    let mut notes = Vec::new();
    let flights = aloft_packs::combine_flights(&logs, options.rated_capacity_mah);
    let (step_r, autopilot_r) = (
        flights.step_resistance_ohm,
        flights.autopilot_resistance_ohm,
    );
    let (resistance, source) = match (
        step_r,
        autopilot_r,
        base.and_then(|b| b.internal_resistance_ohm),
    ) {
        (Some(r), _, _) => (Some(r), Some("current steps")),
        (None, Some(r), _) => {
            notes.push("no log has enough current steps: the autopilot's own resistance estimate is written".into());
            (Some(r), Some("autopilot"))
        }
        (None, None, Some(r)) => {
            notes.push("no log has enough current steps or an autopilot estimate: the --battery pack's resistance is kept".into());
            (Some(r), Some("--battery pack"))
        }
        _ => (None, None),
    };
    PackFitAnswer {
        internal_resistance_ohm: resistance,
        internal_resistance_source: source.map(str::to_string),
        autopilot_internal_resistance_ohm: autopilot_r,
        capacity_mah: flights.capacity_mah,
        pack_capacity_mah: None,
        discharged_mah: flights.discharged_mah,
        equivalent_cycles: flights.equivalent_cycles,
        ocv: None,
        ocv_refused: None,
        rc_resistance_ohm: None,
        rc_time_constant_s: None,
        rc_refused: None,
        pack: None,
        pack_toml: None,
        output: String::new(),
        notes,
        logs,
        skipped,
    }
}

/// The pack's `[battery]` keys from the combined flights, the flags, the `--battery` pack and
/// the documented defaults (module docs); sets the answer's capacity.
///
/// # Errors
/// [`Error::PackKeyMissing`] for a key no source gives.
fn pack_spec(
    request: &PackFitRequest,
    answer: &mut PackFitAnswer,
    options: &PackOptions,
    base: Option<&aloft_planner::BatterySpec>,
    serial: Option<String>,
) -> Result<aloft_planner::BatterySpec, Error> {
    let resistance = answer.internal_resistance_ohm.ok_or(Error::PackKeyMissing {
        key: "internal_resistance_ohm",
        hint: "no log has enough current steps or an autopilot estimate; give --battery NAME to keep its pack's",
    })?;
    let cells = options
        .cells_series
        .or_else(|| answer.logs.iter().find_map(|r| r.cells_series))
        .ok_or(Error::PackKeyMissing {
            key: "cells_series",
            hint: "the logs do not say it: give --cells N or --battery NAME",
        })?;
    let rated = options.rated_capacity_mah.or_else(|| {
        aloft_packs::median_finite(answer.logs.iter().filter_map(|r| r.rated_capacity_mah))
    });
    let capacity_mah = answer
        .capacity_mah
        .or(rated)
        .ok_or(Error::PackKeyMissing {
            key: "capacity_mah",
            hint: "no capacity could be estimated between rests and no rated capacity is logged: give --capacity-mah or --battery NAME",
        })?;
    answer.pack_capacity_mah = Some(capacity_mah);
    let mass_kg =
        request
            .mass_kg
            .or(base.and_then(|b| b.mass_kg))
            .ok_or(Error::PackKeyMissing {
                key: "mass_kg",
                hint: "logs do not weigh packs: give --mass-kg or --battery NAME",
            })?;
    let nominal_v = request
        .nominal_v
        .or(base.and_then(|b| b.nominal_v))
        .unwrap_or(DEFAULT_NOMINAL_CELL_V * f64::from(cells));
    let mut spec = base.cloned().unwrap_or_default();
    spec.name = request
        .name
        .clone()
        .or(base.map(|b| b.name.clone()))
        .or(serial)
        .unwrap_or_else(|| "fitted".to_string());
    spec.default = false;
    spec.cells_series = cells;
    spec.capacity_mah = capacity_mah;
    spec.nominal_v = Some(nominal_v);
    spec.energy_wh = Some(capacity_mah / 1000.0 * nominal_v);
    spec.mass_kg = Some(mass_kg);
    spec.internal_resistance_ohm = Some(resistance);
    // The fitted constant resistance replaces a current-dependent eq (17) one.
    (spec.r1_ohm, spec.r2_ohm_a, spec.r3_ohm_a) = (None, None, None);
    (spec.eq17_min_current_a, spec.eq17_max_current_a) = (None, None);
    spec.cutoff_cell_v = request
        .cutoff_cell_v
        .or(spec.cutoff_cell_v)
        .or(Some(DEFAULT_CUTOFF_CELL_V));
    if let Some(u) = request.usable_fraction {
        spec.usable_fraction = u;
    }
    Ok(spec)
}

/// The pack's own open-circuit curve from the logs' records on the capacity and resistance of
/// `spec` (module docs): written into `spec` and the answer, or the reason there is none in the
/// answer (the `--battery` pack's curve, if any, kept).
fn fit_curve(
    spec: &mut aloft_planner::BatterySpec,
    answer: &mut PackFitAnswer,
    records: &[Vec<BatterySample>],
) {
    let r_ohm = spec.internal_resistance_ohm.unwrap_or(f64::NAN);
    let mut flights = Vec::new();
    let mut refused = Vec::new();
    for (report, samples) in answer.logs.iter().zip(records) {
        match aloft_packs::flight_ocv(samples, Some(spec.cells_series), spec.capacity_mah, r_ohm) {
            Ok(f) => flights.push(f),
            Err(e) => refused.push(format!("{}: {e}", file_name(&report.source))),
        }
    }
    match aloft_packs::combine_flight_ocv(&flights) {
        Ok(fitted) => {
            answer.notes.push(format!(
                "open-circuit curve fitted on {} log(s) from {:.1} to {:.1} % of charge ({}); the generic LiPo curve joined outside",
                fitted.flights,
                100.0 * fitted.measured_from_soc,
                100.0 * fitted.measured_to_soc,
                flights[0].anchor.words(),
            ));
            if !refused.is_empty() {
                answer.notes.push(format!(
                    "open-circuit curve: log(s) left out: {}",
                    refused.join("; ")
                ));
            }
            spec.ocv_soc = Some(fitted.soc.clone());
            spec.ocv_cell_v = Some(fitted.cell_v.clone());
            answer.ocv = Some(fitted);
        }
        Err(e) => {
            let why = if refused.is_empty() {
                e.to_string()
            } else {
                refused.join("; ")
            };
            let kept = if spec.ocv_soc.is_some() {
                "the --battery pack's curve is kept"
            } else {
                "the generic LiPo curve is flown"
            };
            answer
                .notes
                .push(format!("no open-circuit curve fitted ({kept}): {why}"));
            answer.ocv_refused = Some(why);
        }
    }
}

/// The RC pair from the flights' records, on the resistance written (module docs).
fn fit_rc(
    spec: &mut aloft_planner::BatterySpec,
    answer: &mut PackFitAnswer,
    records: &[Vec<BatterySample>],
) {
    let r0_ohm = spec.internal_resistance_ohm.unwrap_or(f64::NAN);
    let flights: Vec<aloft_packs::RcEstimate> = records
        .iter()
        .filter_map(|samples| aloft_packs::rc_from_flight(samples, r0_ohm))
        .collect();
    let tau_default = aloft_packs::soc_filter::DEFAULT_RC_TIME_CONSTANT_S;
    match aloft_packs::rc_of_flights(&flights) {
        Ok((tau_s, r_ohm)) => {
            spec.rc_resistance_ohm = Some(r_ohm);
            spec.rc_time_constant_s = Some(tau_s);
            answer.rc_resistance_ohm = Some(r_ohm);
            answer.rc_time_constant_s = Some(tau_s);
        }
        // The curve fitted here is the voltage under load less `I R`: it holds the pack's mean
        // polarisation, which an RC pair beside it would count again.
        Err(why) if answer.ocv.is_some() => {
            spec.rc_resistance_ohm = Some(0.0);
            spec.rc_time_constant_s = Some(tau_default);
            answer.rc_resistance_ohm = Some(0.0);
            answer.rc_time_constant_s = Some(tau_default);
            answer.notes.push(format!(
                "no RC pair identified ({why}): the open-circuit curve fitted under load holds the \
                 pack's mean polarisation, so the pair written has no resistance"
            ));
            answer.rc_refused = Some(why);
        }
        Err(why) => {
            answer.notes.push(format!(
                "no RC pair written (the state-of-charge filter's default, {tau_default} s, is \
                 flown and its resistance learned in flight): {why}"
            ));
            answer.rc_refused = Some(why);
        }
    }
}

/// A log's file name (its source as given when it has none).
fn file_name(source: &str) -> String {
    std::path::Path::new(source)
        .file_name()
        .map_or_else(|| source.to_string(), |n| n.to_string_lossy().into_owned())
}

/// The `[fitted]` table: the logs, steps and the autopilot's figures.
fn fitted_table(a: &PackFitAnswer) -> toml::Table {
    let mut t = toml::Table::new();
    let strings =
        |v: Vec<String>| toml::Value::Array(v.into_iter().map(toml::Value::String).collect());
    let floats = |v: Vec<f64>| toml::Value::Array(v.into_iter().map(toml::Value::Float).collect());
    t.insert(
        "logs".into(),
        strings(a.logs.iter().map(|r| r.source.clone()).collect()),
    );
    t.insert(
        "steps".into(),
        toml::Value::Integer(
            a.logs
                .iter()
                .filter_map(|r| r.resistance.as_ref())
                .map(|r| r.steps as i64)
                .sum(),
        ),
    );
    t.insert(
        "resistance_per_log_ohm".into(),
        floats(
            a.logs
                .iter()
                .filter_map(|r| r.internal_resistance_ohm)
                .collect(),
        ),
    );
    if let Some(s) = &a.internal_resistance_source {
        t.insert(
            "internal_resistance_source".into(),
            toml::Value::String(s.clone()),
        );
    }
    if let Some(r) = a.autopilot_internal_resistance_ohm {
        t.insert(
            "autopilot_internal_resistance_ohm".into(),
            toml::Value::Float(r),
        );
    }
    if let Some(c) = a.capacity_mah {
        t.insert("capacity_estimated_mah".into(), toml::Value::Float(c));
    }
    t.insert(
        "discharged_mah".into(),
        toml::Value::Float(a.discharged_mah),
    );
    if let Some(o) = &a.ocv {
        t.insert(
            "ocv_measured_soc".into(),
            floats(vec![o.measured_from_soc, o.measured_to_soc]),
        );
        t.insert("ocv_logs".into(), toml::Value::Integer(o.flights as i64));
    }
    if let Some(why) = &a.rc_refused {
        t.insert("rc_refused".into(), toml::Value::String(why.clone()));
    }
    if let Some(why) = &a.ocv_refused {
        t.insert("ocv_refused".into(), toml::Value::String(why.clone()));
    }
    if !a.skipped.is_empty() {
        t.insert(
            "skipped".into(),
            strings(
                a.skipped
                    .iter()
                    .map(|s| format!("{}: {}", s.file, s.reason))
                    .collect(),
            ),
        );
    }
    t
}
