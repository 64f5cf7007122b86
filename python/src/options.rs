//! Keyword arguments of the Python functions, named like the CLI's flags in snake_case, turned
//! into the engine's requests.
//!
//! The mapping mirrors `src/cli/*.rs` (`MissionArgs::options`, `SteadyWindArgs::spec`,
//! `MissionWindArgs::gusts`, `EnduranceArgs::options`, `FlightLogArgs::logs`,
//! `ReadOptions::options`): the same defaults, the same pairs that need each other. It is the
//! only thing replicated here; every answer comes from the engine's entry points. The CLI's
//! mapping lives in the CLI crate, not in `aloft::engine`, so it cannot be shared yet (tests
//! compare the answers with the CLI's).

use std::collections::BTreeMap;
use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use aloft::engine::{
    AoaModel, CornerMode, EnduranceOptions, FlightLogs, GustSpec, LogReadOptions, MissionOptions,
    PayloadSweep, ScenarioOptions, WindProfileKind, WindSpec,
};

use crate::aloft_error;

/// The keyword arguments of one call, taken one by one; what is left at the end is an error
/// naming the key (the hook for options the engine adds later, e.g. Monte-Carlo sampling).
pub struct Kwargs<'py> {
    function: &'static str,
    known: Vec<&'static str>,
    values: BTreeMap<String, Bound<'py, PyAny>>,
}

impl<'py> Kwargs<'py> {
    /// The options of `function` (None values count as not given, as an absent flag).
    pub fn new(function: &'static str, dict: Option<&Bound<'py, PyDict>>) -> PyResult<Self> {
        let mut values = BTreeMap::new();
        if let Some(d) = dict {
            for (k, v) in d.iter() {
                if !v.is_none() {
                    values.insert(k.extract::<String>()?, v);
                }
            }
        }
        Ok(Self {
            function,
            known: Vec::new(),
            values,
        })
    }

    fn take(&mut self, key: &'static str) -> Option<Bound<'py, PyAny>> {
        self.known.push(key);
        self.values.remove(key)
    }

    fn invalid(&self, key: &str, value: &Bound<'py, PyAny>, why: &str) -> PyErr {
        let shown = value
            .repr()
            .map(|r| r.to_string())
            .unwrap_or_else(|_| "?".to_string());
        aloft_error(format!(
            "invalid value {shown} for '{key}' of aloft.{}: {why}",
            self.function
        ))
    }

    /// A finite number (the CLI refuses `nan`, `inf` for every numeric flag).
    pub fn f64(&mut self, key: &'static str) -> PyResult<Option<f64>> {
        let Some(v) = self.take(key) else {
            return Ok(None);
        };
        if v.is_instance_of::<pyo3::types::PyBool>() {
            return Err(self.invalid(key, &v, "not a number"));
        }
        match v.extract::<f64>() {
            Ok(x) if x.is_finite() => Ok(Some(x)),
            Ok(_) => Err(self.invalid(key, &v, "not a finite number")),
            Err(_) => Err(self.invalid(key, &v, "not a number")),
        }
    }

    /// A number with the CLI's default.
    pub fn f64_or(&mut self, key: &'static str, default: f64) -> PyResult<f64> {
        Ok(self.f64(key)?.unwrap_or(default))
    }

    /// A text.
    pub fn string(&mut self, key: &'static str) -> PyResult<Option<String>> {
        let Some(v) = self.take(key) else {
            return Ok(None);
        };
        v.extract::<String>()
            .map(Some)
            .map_err(|_| self.invalid(key, &v, "not a string"))
    }

    /// A path (str or os.PathLike).
    pub fn path(&mut self, key: &'static str) -> PyResult<Option<PathBuf>> {
        let Some(v) = self.take(key) else {
            return Ok(None);
        };
        v.extract::<PathBuf>()
            .map(Some)
            .map_err(|_| self.invalid(key, &v, "not a path"))
    }

    /// A switch (`no_ground_effect=True` as the flag `--no-ground-effect`).
    pub fn flag(&mut self, key: &'static str) -> PyResult<bool> {
        let Some(v) = self.take(key) else {
            return Ok(false);
        };
        v.extract::<bool>()
            .map_err(|_| self.invalid(key, &v, "not True or False"))
    }

    /// A non-negative integer up to `max`.
    pub fn int(&mut self, key: &'static str, max: u64) -> PyResult<Option<u64>> {
        let Some(v) = self.take(key) else {
            return Ok(None);
        };
        if v.is_instance_of::<pyo3::types::PyBool>() {
            return Err(self.invalid(key, &v, "not an integer"));
        }
        match v.extract::<u64>() {
            Ok(x) if x <= max => Ok(Some(x)),
            _ => Err(self.invalid(key, &v, &format!("not an integer from 0 to {max}"))),
        }
    }

    /// A list of texts: a list, a tuple, or one comma-separated text (as the CLI's flag).
    pub fn strings(&mut self, key: &'static str) -> PyResult<Option<Vec<String>>> {
        let Some(v) = self.take(key) else {
            return Ok(None);
        };
        if let Ok(s) = v.extract::<String>() {
            return Ok(Some(s.split(',').map(str::to_string).collect()));
        }
        v.extract::<Vec<String>>()
            .map(Some)
            .map_err(|_| self.invalid(key, &v, "not a list of strings"))
    }

    /// A word of a kebab-case engine enum (`geometric`, `power-law`, `stop`), read as the files
    /// and the CLI read it.
    pub fn word<T: serde::de::DeserializeOwned>(
        &mut self,
        key: &'static str,
        choices: &str,
    ) -> PyResult<Option<T>> {
        let Some(v) = self.take(key) else {
            return Ok(None);
        };
        let Ok(s) = v.extract::<String>() else {
            return Err(self.invalid(key, &v, &format!("expected one of {choices}")));
        };
        serde_json::from_value(serde_json::Value::String(s))
            .map(Some)
            .map_err(|_| self.invalid(key, &v, &format!("expected one of {choices}")))
    }

    /// The angle-of-attack model (`geometric` or `paper`).
    pub fn aoa(&mut self) -> PyResult<Option<AoaModel>> {
        self.word("aoa", "'geometric', 'paper'")
    }

    /// Require `b` whenever `a` is given (clap's `requires`).
    pub fn needs(&self, a: (&str, bool), b: (&str, bool)) -> PyResult<()> {
        if a.1 && !b.1 {
            return Err(aloft_error(format!(
                "the option '{}' of aloft.{} needs '{}' too",
                a.0, self.function, b.0
            )));
        }
        Ok(())
    }

    /// Refuse `b` whenever `a` is given (clap's `conflicts_with`).
    pub fn excludes(&self, a: (&str, bool), b: (&str, bool)) -> PyResult<()> {
        if a.1 && b.1 {
            return Err(aloft_error(format!(
                "the option '{}' of aloft.{} cannot be used with '{}'",
                a.0, self.function, b.0
            )));
        }
        Ok(())
    }

    /// A payload sweep: the CLI's text `"START:STOP:STEP"` (kg) or a tuple or list of three
    /// numbers, checked by the engine (the message says what is wrong).
    pub fn payload_sweep(&mut self, key: &'static str) -> PyResult<Option<PayloadSweep>> {
        let Some(v) = self.take(key) else {
            return Ok(None);
        };
        let numbers = v.extract::<Vec<f64>>().ok();
        let sweep = if let Ok(text) = v.extract::<String>() {
            PayloadSweep::parse(&text)
        } else if let Some([start, stop, step]) = numbers.as_deref() {
            PayloadSweep::new(*start, *stop, *step)
        } else {
            return Err(self.invalid(
                key,
                &v,
                "expected 'START:STOP:STEP' or (START, STOP, STEP) in kg",
            ));
        };
        sweep.map(Some).map_err(|e| match e {
            aloft::Error::PayloadSweep { problem, .. } => {
                self.invalid(key, &v, &problem.to_string())
            }
            other => aloft_error(other.to_string()),
        })
    }

    /// Refuse the old name `old` of the option `new`, saying what it is now (a clear error,
    /// never a silent alias).
    pub fn renamed(&self, old: &str, new: &str, what: &str) -> PyResult<()> {
        if self.values.contains_key(old) {
            return Err(aloft_error(format!(
                "'{old}' of aloft.{} is now '{new}' ({what})",
                self.function
            )));
        }
        Ok(())
    }

    /// Refuse a key that is left over: unknown here (or not yet known to this version).
    pub fn finish(self) -> PyResult<()> {
        if let Some(key) = self.values.keys().next() {
            let mut known = self.known.clone();
            known.sort_unstable();
            return Err(aloft_error(format!(
                "unknown option '{key}' for aloft.{}; known options: {}",
                self.function,
                known.join(", ")
            )));
        }
        Ok(())
    }
}

/// `--wind-speed`, `--wind-from`, `--wind-profile` and the profile's parameters
/// (`SteadyWindArgs::spec` of the CLI).
fn steady_wind(k: &mut Kwargs<'_>) -> PyResult<Option<WindSpec>> {
    let speed = k.f64("wind_speed")?;
    let from = k.f64("wind_from")?;
    let profile: Option<WindProfileKind> =
        k.word("wind_profile", "'uniform', 'power-law', 'log'")?;
    let reference = k.f64_or("wind_reference_height", 10.0)?;
    let exponent = k.f64_or("wind_exponent", 1.0 / 7.0)?;
    let roughness = k.f64_or("wind_roughness", 0.03)?;
    k.needs(
        ("wind_speed", speed.is_some()),
        ("wind_from", from.is_some()),
    )?;
    k.needs(
        ("wind_from", from.is_some()),
        ("wind_speed", speed.is_some()),
    )?;
    k.needs(
        ("wind_profile", profile.is_some()),
        ("wind_speed", speed.is_some()),
    )?;
    let Some((speed_mps, from_deg)) = speed.zip(from) else {
        return Ok(None);
    };
    let profile = profile.unwrap_or_default();
    let uses = |p: WindProfileKind| profile == p;
    let profiled = !uses(WindProfileKind::Uniform);
    Ok(Some(WindSpec {
        speed_mps,
        from_deg,
        profile,
        reference_height_m: profiled.then_some(reference),
        exponent: uses(WindProfileKind::PowerLaw).then_some(exponent),
        roughness_m: uses(WindProfileKind::Log).then_some(roughness),
        gust_std_mps: None,
        gust_seed: None,
    }))
}

/// The vehicle option of every command (default: the CLI's default vehicle).
pub fn vehicle(k: &mut Kwargs<'_>) -> PyResult<String> {
    Ok(k.string("vehicle")?
        .unwrap_or_else(|| aloft::engine::DEFAULT_VEHICLE.to_string()))
}

/// The options of `aloft mission` (`MissionArgs::options` of the CLI).
// `..MissionOptions::default()` keeps this compiling when the engine adds options (Monte-Carlo
// sampling is on its way); until then it has nothing to fill.
#[allow(clippy::needless_update)]
/// The Monte-Carlo options (`samples`, `seed`, `wind_speed_sd`, `wind_from_sd`,
/// `payload_sd_kg`, `capacity_sd_percent`, `power_sd_percent`, `threads`), as the CLI's
/// `--samples N` and its spreads: none without `samples`, and the spreads need it. The engine
/// checks the ranges (its messages name the option).
pub fn scenarios(k: &mut Kwargs<'_>) -> PyResult<Option<ScenarioOptions>> {
    let samples = k.int("samples", u64::from(u32::MAX))?;
    let defaults = ScenarioOptions::default();
    let seed = k.int("seed", u64::MAX)?;
    let spreads = [
        k.f64("wind_speed_sd")?,
        k.f64("wind_from_sd")?,
        k.f64("payload_sd_kg")?,
        k.f64("capacity_sd_percent")?,
        k.f64("power_sd_percent")?,
    ];
    let threads = k.int("threads", 1024)?;
    let Some(samples) = samples else {
        if seed.is_some() || threads.is_some() || spreads.iter().any(Option::is_some) {
            return Err(aloft_error(
                "the scenario options (seed, spreads, threads) of aloft.mission need 'samples'",
            ));
        }
        return Ok(None);
    };
    let [wind_speed, wind_from, payload, capacity, power] = spreads;
    Ok(Some(ScenarioOptions {
        samples: samples as u32,
        seed: seed.unwrap_or(defaults.seed),
        wind_speed_sd_mps: wind_speed.unwrap_or(defaults.wind_speed_sd_mps),
        wind_from_sd_deg: wind_from.unwrap_or(defaults.wind_from_sd_deg),
        payload_sd_kg: payload.unwrap_or(defaults.payload_sd_kg),
        capacity_sd_percent: capacity.unwrap_or(defaults.capacity_sd_percent),
        power_sd_percent: power.unwrap_or(defaults.power_sd_percent),
        threads: threads.map_or(defaults.threads, |t| t as usize),
        soc_fan: false,
    }))
}

pub fn mission(k: &mut Kwargs<'_>) -> PyResult<MissionOptions> {
    let wind = steady_wind(k)?;
    let wind_field = k.path("wind_field")?;
    if wind_field.is_some() && wind.is_some() {
        return Err(aloft_error(
            "the option 'wind_field' of aloft.mission cannot be used with 'wind_speed'",
        ));
    }
    let gust_std = k.f64("gust_std")?;
    let gust_seed = k.int("gust_seed", u64::MAX)?.unwrap_or(1);
    Ok(MissionOptions {
        battery: k.string("battery")?,
        payload_kg: k.f64("payload_kg")?,
        wind,
        wind_field,
        gusts: gust_std.map(|std_mps| GustSpec {
            std_mps,
            seed: gust_seed,
        }),
        reserve_percent: k.f64("reserve_percent")?,
        start_percent: k.f64_or("start_percent", 100.0)?,
        time_step_s: k.f64("time_step")?,
        aoa: k.aoa()?.unwrap_or(AoaModel::Geometric),
        ground_effect: !k.flag("no_ground_effect")?,
        record_samples: false,
        speed_mps: k.f64("speed")?,
        rtl_altitude_m: k.f64("rtl_altitude_m")?,
        corners: k.word::<CornerMode>("corners", "'pass', 'stop'")?,
    })
}

/// What `aloft endurance` answers: the queries at one payload, the power curve
/// (`--sweep-speed`), or endurance against payload (`--payload-sweep`).
pub enum EnduranceCurve {
    /// The endurance queries.
    None,
    /// The power curve in steps of this many m/s.
    Speed(f64),
    /// Endurance against payload.
    Payload(PayloadSweep),
}

/// The options of `aloft endurance` (`EnduranceArgs::options` of the CLI) and its
/// `--sweep-speed` or `--payload-sweep` (which, as there, exclude each other and a payload).
pub fn endurance(k: &mut Kwargs<'_>) -> PyResult<(EnduranceOptions, EnduranceCurve)> {
    let wind = steady_wind(k)?;
    let orbit_radius_m = k.f64("orbit_radius")?;
    let orbit_speed_mps = k.f64("orbit_speed")?;
    k.needs(
        ("orbit_radius", orbit_radius_m.is_some()),
        ("orbit_speed", orbit_speed_mps.is_some()),
    )?;
    k.needs(
        ("orbit_speed", orbit_speed_mps.is_some()),
        ("orbit_radius", orbit_radius_m.is_some()),
    )?;
    let payload_kg = k.f64("payload_kg")?;
    let sweep_speed = k.f64("sweep_speed")?;
    let payload_sweep = k.payload_sweep("payload_sweep")?;
    if payload_sweep.is_some() {
        k.excludes(
            ("payload_sweep", true),
            ("sweep_speed", sweep_speed.is_some()),
        )?;
        k.excludes(
            ("payload_sweep", true),
            ("payload_kg", payload_kg.is_some()),
        )?;
    }
    let curve = match (sweep_speed, payload_sweep) {
        (_, Some(sweep)) => EnduranceCurve::Payload(sweep),
        (Some(step), None) => EnduranceCurve::Speed(step),
        (None, None) => EnduranceCurve::None,
    };
    let options = EnduranceOptions {
        battery: k.string("battery")?,
        payload_kg: payload_kg.unwrap_or(0.0),
        wind,
        course_deg: k.f64_or("course", 0.0)?,
        reserve_percent: k.f64_or("reserve_percent", 0.0)?,
        orbit_radius_m,
        orbit_speed_mps,
        aoa: k.aoa()?.unwrap_or(AoaModel::Geometric),
    };
    Ok((options, curve))
}

/// The read options of `aloft log info` (`ReadOptions::options` of the CLI).
pub fn log_read(k: &mut Kwargs<'_>) -> PyResult<LogReadOptions> {
    Ok(LogReadOptions {
        profile: k.string("profile")?,
        topics: k.strings("topics")?.unwrap_or_default(),
        header_time: k.flag("header_time")?,
        battery_current_positive: k.flag("battery_current_positive")?,
        battery_instance: battery_instance(k)?,
    })
}

/// The logs of `aloft fit` and `aloft validate` (`FlightLogArgs::logs` of the CLI).
pub fn flight_logs(k: &mut Kwargs<'_>, logs: Vec<PathBuf>) -> PyResult<FlightLogs> {
    if logs.is_empty() {
        return Err(aloft_error(format!(
            "aloft.{} needs at least one log",
            k.function
        )));
    }
    Ok(FlightLogs {
        logs,
        profile: k.string("profile")?,
        aoa: k.aoa()?.unwrap_or(AoaModel::Geometric),
        lag_s: k.f64("lag")?,
        max_lag_s: k.f64_or("max_lag", 10.0)?,
        battery_instance: battery_instance(k)?,
    })
}

/// `--battery-instance` (0 to 255, default 0).
fn battery_instance(k: &mut Kwargs<'_>) -> PyResult<u8> {
    let n = k.int("battery_instance", u64::from(u8::MAX))?.unwrap_or(0);
    Ok(u8::try_from(n).unwrap_or(u8::MAX))
}
