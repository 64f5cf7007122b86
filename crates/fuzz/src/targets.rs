//! The table of fuzz targets: one entry per parser, each calling the engine as the command line
//! does and computing the answer the command line would print.
//!
//! A new parser joins by one more [`Target`] in [`TARGETS`]: a name, its format, a function that
//! gives its seeds and a function that runs one input and returns the [`Outcome`].

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use aloft::engine::{
    calibrate_spec, convert_log, endurance, hover, log_info, plan_mission, power_csv, power_model,
    power_point, EnduranceOptions, FlightStateDeg, HoverRequest, LiveRequest, LiveSession,
    LogReadOptions, Mission, MissionOptions, PowerModelQuery, PowerQuery, SpecSheet, Vehicle,
};
use aloft::power::{ModelOptions, PowerModel};
use aloft_planner::Aircraft;

use crate::check::{Outcome, Problem};
use crate::inputs::{scratch, MAP_SEPARATOR, TABLE_SEPARATOR};
use crate::mutate::Format;
use crate::rng::fnv1a;
use crate::seeds;

/// One parser under fuzzing.
#[derive(Debug, Clone, Copy)]
pub struct Target {
    /// Name on the command line and directory of its findings (`fixtures/fuzz/<name>/`).
    pub name: &'static str,
    /// What it runs, in words.
    pub about: &'static str,
    /// The kind of bytes it reads (which structure-aware mutations apply).
    pub format: Format,
    /// Its seeds: fixtures of the repository and inputs made by aloft itself.
    pub seeds: fn() -> Vec<Vec<u8>>,
    /// Run one input.
    pub run: fn(&[u8]) -> Outcome,
}

/// Every target.
pub const TARGETS: &[Target] = &[
    Target {
        name: "vehicle-toml",
        about: "Vehicle::from_toml, then power_point at hover and in forward flight, hover \
                (propulsion), endurance on every 8th input",
        format: Format::Text,
        seeds: seeds::vehicles,
        run: vehicle_toml,
    },
    Target {
        name: "spec-sheet",
        about: "SpecSheet::from_toml and calibrate_spec (aloft vehicles calibrate), the vehicle \
                file it writes read back with Vehicle::from_toml, endurance on every 8th input",
        format: Format::Text,
        seeds: seeds::spec_sheets,
        run: spec_sheet,
    },
    Target {
        name: "mission-toml",
        about: "Mission::from_toml, then compile and plan_mission with dji-m100",
        format: Format::Text,
        seeds: seeds::missions_toml,
        run: mission_toml,
    },
    Target {
        name: "mission-json",
        about: "Mission::from_json, then compile and plan_mission with dji-m100",
        format: Format::Text,
        seeds: seeds::missions_json,
        run: mission_json,
    },
    Target {
        name: "power-csv",
        about: "power_csv with the dji-m100 power model (aloft power --states)",
        format: Format::Text,
        seeds: seeds::power_csv,
        run: power_csv_target,
    },
    Target {
        name: "log-csv",
        about: "log_info of a CSV log (layout recognised, else the kaist profile), a lag search \
                on every 4th input, convert_log and log_info of the MCAP on every 8th",
        format: Format::Text,
        seeds: seeds::log_csv,
        run: log_csv,
    },
    Target {
        name: "column-map",
        about: "log_info of a CSV log through a column-map TOML (input: map, separator line, CSV)",
        format: Format::Text,
        seeds: seeds::column_map,
        run: column_map,
    },
    Target {
        name: "px4-csv",
        about: "log_info of PX4 ulog2csv tables (local position, battery, attitude; input: the \
                three tables between separator lines), recognised by their names",
        format: Format::Text,
        seeds: seeds::px4_csv,
        run: px4_csv,
    },
    Target {
        name: "mcap",
        about: "log_info of an MCAP log (options varied by input), a lag search on every 4th",
        format: Format::Mcap,
        seeds: seeds::mcap,
        run: mcap,
    },
    Target {
        name: "qgc-plan",
        about: "Mission::from_text of a QGroundControl .plan (content detection), then compile \
                and plan_mission with dji-m100",
        format: Format::Text,
        seeds: seeds::qgc_plan_files,
        run: planner_file,
    },
    Target {
        name: "qgc-wpl",
        about: "Mission::from_text of a QGC WPL 110 .waypoints (content detection), then \
                compile and plan_mission with dji-m100",
        format: Format::Text,
        seeds: seeds::qgc_wpl_files,
        run: planner_file,
    },
    Target {
        name: "ulog",
        about: "aloft_logs::read_ulog of the bytes; log_info of them written to a file on \
                every 8th input",
        format: Format::Ulog,
        seeds: seeds::ulog,
        run: ulog,
    },
    Target {
        name: "dataflash",
        about: "aloft_logs::read_dataflash of the bytes; log_info of them written to a file on \
                every 8th input",
        format: Format::Dataflash,
        seeds: seeds::dataflash,
        run: dataflash,
    },
    Target {
        name: "tlog",
        about: "aloft_link::TlogSource of the bytes (frames, the vehicle's events: times never \
                back, values finite); the frames' bytes and the skipped ones add up on every \
                4th input",
        format: Format::Tlog,
        seeds: seeds::tlog,
        run: tlog,
    },
];

/// A target by name.
pub fn target(name: &str) -> Option<&'static Target> {
    TARGETS.iter().find(|t| t.name == name)
}

/// The lag search window of `log info --max-lag` on every 4th log input, s (the seeds are 0.5
/// to 2 s long, and a search needs a log of twice its window).
pub const LAG_WINDOW_S: f64 = 0.2;

/// Most steps one fuzzed flight is planned with: a longer mission is planned with a coarser time
/// step (duration / this), so that one input stays fast.
pub const MAX_PLAN_STEPS: f64 = 2_000.0;

fn write_scratch(name: &str, data: &[u8]) -> PathBuf {
    let path = scratch(name);
    // A failed write shows up as the engine's read error, which is checked like any other.
    let _ = std::fs::write(&path, data);
    path
}

/// The vehicle missions and power batches are run with.
fn m100() -> &'static Vehicle {
    static V: OnceLock<Vehicle> = OnceLock::new();
    V.get_or_init(|| Vehicle::builtin("dji-m100").expect("dji-m100 is built in"))
}

fn accepted() -> Outcome {
    Outcome {
        accepted: true,
        ..Outcome::default()
    }
}

fn vehicle_toml(data: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(data);
    let v = match Vehicle::from_toml(&text, "fuzz-vehicle.toml") {
        Ok(v) => v,
        Err(e) => return Outcome::refused("vehicle", &e),
    };
    let mut o = accepted();
    o.step("power at hover", &power_point(&v, &PowerQuery::default()));
    let forward = PowerQuery {
        state: FlightStateDeg {
            airspeed_mps: 12.0,
            pitch_deg: -10.0,
            climb_rate_mps: 1.0,
            ..FlightStateDeg::default()
        },
        gradient: true,
        ..PowerQuery::default()
    };
    o.step("power in forward flight", &power_point(&v, &forward));
    o.step("hover", &hover(&v, HoverRequest::Payload(0.0)));
    if fnv1a(data) % 8 == 0 {
        o.step("endurance", &endurance(&v, &EnduranceOptions::default()));
    }
    o
}

fn spec_sheet(data: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(data);
    let spec = match SpecSheet::from_toml(&text, "fuzz-spec.toml") {
        Ok(s) => s,
        Err(e) => return Outcome::refused("spec sheet", &e),
    };
    let c = match calibrate_spec(&spec, "fuzz-spec.toml") {
        Ok(c) => c,
        Err(e) => return Outcome::refused("spec sheet", &e),
    };
    let mut o = accepted();
    o.json("calibration", &c);
    // A vehicle file aloft wrote must read back: a refusal here is a broken round trip.
    match c
        .to_toml()
        .and_then(|t| Vehicle::from_toml(&t, "fuzz-calibrated.toml"))
    {
        Ok(v) => {
            if fnv1a(data) % 8 == 0 {
                o.step("endurance", &endurance(&v, &EnduranceOptions::default()));
            }
        }
        Err(e) => o.broken.push(Problem {
            check: "round-trip",
            detail: format!("the calibrated vehicle file does not read back: {e}"),
        }),
    }
    o
}

fn mission_toml(data: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(data);
    mission(Mission::from_toml(&text, "fuzz-mission.toml"))
}

fn mission_json(data: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(data);
    mission(Mission::from_json(&text, "fuzz-mission.json"))
}

/// A planner file (`.plan` or `.waypoints`), told by its content as `aloft mission` tells it.
fn planner_file(data: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(data);
    mission(Mission::from_text(&text, "fuzz-planner-file"))
}

/// A parsed mission: compiled for dji-m100, planned (with a coarser step when it would take
/// more than [`MAX_PLAN_STEPS`]), and, when it plans, its JSON read back to the same mission.
fn mission(parsed: Result<Mission, aloft::Error>) -> Outcome {
    let m = match parsed {
        Ok(m) => m,
        Err(e) => return Outcome::refused("mission", &e),
    };
    let mut o = accepted();
    let v = m100();
    let mut options = MissionOptions::default();
    if let Some(duration_s) = compiled_duration_s(&m) {
        let step_s = m.spec().time_step_s.unwrap_or(0.1);
        if step_s > 0.0 && step_s.is_finite() && duration_s / step_s > MAX_PLAN_STEPS {
            options.time_step_s = Some((duration_s / MAX_PLAN_STEPS).max(1.0));
        }
    }
    // A mission that does not compile is refused by the engine at the same step (cheaply).
    match plan_mission(v, &m, &options) {
        Ok(plan) => {
            o.json("mission", plan.summary());
            round_trip(&m, &mut o);
        }
        Err(e) => o.refuse("plan", &e),
    }
    o
}

/// The duration of the mission compiled for dji-m100 and its default pack, if it compiles.
fn compiled_duration_s(m: &Mission) -> Option<f64> {
    static AIRCRAFT: OnceLock<Option<(Aircraft, f64)>> = OnceLock::new();
    let (aircraft, pack_kg) = AIRCRAFT
        .get_or_init(|| {
            let v = m100();
            let (a, _) = v.file().aircraft(ModelOptions::default()).ok()?;
            Some((a, v.battery(None).ok()?.mass_kg()))
        })
        .as_ref()?;
    let c = m.spec().compile(aircraft.airframe(), *pack_kg, None).ok()?;
    Some(c.duration_s())
}

/// A mission that plans survives its JSON (what a ground station sends back) unchanged.
fn round_trip(m: &Mission, o: &mut Outcome) {
    let back = m.to_json().and_then(|j| Mission::from_json(&j, m.origin()));
    match back {
        // The spec, not the whole mission: the route's source format says which text it was.
        Ok(b) if b.spec() == m.spec() => {}
        Ok(_) => o.broken.push(Problem {
            check: "json-round-trip",
            detail: "the mission read back from its JSON differs".into(),
        }),
        Err(e) => o.broken.push(Problem {
            check: "json-round-trip",
            detail: format!(
                "its JSON does not read back: {}",
                aloft::engine::error_line(&e)
            ),
        }),
    }
}

fn power_csv_target(data: &[u8]) -> Outcome {
    static MODEL: OnceLock<PowerModel> = OnceLock::new();
    let model = MODEL.get_or_init(|| {
        power_model(m100(), &PowerModelQuery::default()).expect("dji-m100 has a model")
    });
    let mut out = Vec::new();
    match power_csv(model, data, &mut out, "fuzz-states.csv") {
        Ok(_) => {
            let mut o = accepted();
            o.answers.push(crate::check::Answer::Csv {
                what: "power csv",
                text: String::from_utf8_lossy(&out).into_owned(),
                computed: aloft::engine::POWER_KEYS.len(),
            });
            o
        }
        Err(e) => Outcome::refused("power csv", &e),
    }
}

/// `log_info` of `path` (and the lag search within +-`max_lag` s when given), as `aloft log info`.
fn info(o: &mut Outcome, path: &Path, options: &LogReadOptions, max_lag: Option<f64>) -> bool {
    match log_info(path, options, max_lag) {
        Ok(i) => {
            o.json("log info", &i);
            true
        }
        Err(e) => {
            o.refuse("log info", &e);
            false
        }
    }
}

fn log_csv(data: &[u8]) -> Outcome {
    let path = write_scratch("log.csv", data);
    let h = fnv1a(data);
    let lag = (h % 4 == 0).then_some(LAG_WINDOW_S);
    let mut options = LogReadOptions::default();
    let mut o = Outcome::default();
    let first = log_info(&path, &options, lag);
    let unrecognised = matches!(&first, Err(e) if e.to_string().contains("layout not recognised"));
    if unrecognised {
        options.profile = Some("kaist".into());
        o.accepted = info(&mut o, &path, &options, lag);
    } else {
        o.step("log info", &first);
        o.accepted = first.is_ok();
    }
    if o.accepted && h % 8 == 1 {
        convert_and_read_back(&mut o, &path, &options);
    }
    o
}

/// `aloft convert` of an accepted log, and `log info` of the MCAP it wrote: aloft reads what it
/// writes, with the same number of samples.
fn convert_and_read_back(o: &mut Outcome, path: &Path, options: &LogReadOptions) {
    let out = scratch("converted.mcap");
    match convert_log(path, options, &out, true) {
        Ok(c) => {
            o.json("convert", &c);
            let source = log_info(path, options, None).map(|i| (i.duration_s, i.samples));
            match (log_info(&out, &LogReadOptions::default(), None), source) {
                (Ok(i), Ok((d, n)))
                    if (i.duration_s - d).abs() <= 1e-6 * d.abs().max(1.0) && i.samples == n =>
                {
                    o.json("log info of the MCAP", &i);
                }
                (Ok(i), Ok((d, n))) => o.broken.push(Problem {
                    check: "mcap-round-trip",
                    detail: format!(
                        "{n} samples over {d} s converted, {} over {} s read back",
                        i.samples, i.duration_s
                    ),
                }),
                (Err(e), _) => o.broken.push(Problem {
                    check: "mcap-round-trip",
                    detail: format!(
                        "aloft cannot read the MCAP it wrote: {}",
                        aloft::engine::error_line(&e)
                    ),
                }),
                (_, Err(e)) => o.refuse("log info", &e),
            }
        }
        // An empty log is refused by convert; anything else is checked as a refusal.
        Err(e) => o.refuse("convert", &e),
    }
}

fn column_map(data: &[u8]) -> Outcome {
    let (map, csv) = match data
        .windows(MAP_SEPARATOR.len())
        .position(|w| w == MAP_SEPARATOR)
    {
        Some(k) => (&data[..k], &data[k + MAP_SEPARATOR.len()..]),
        None => (data, seeds::CUSTOM_CSV),
    };
    let map_path = write_scratch("map.toml", map);
    let csv_path = write_scratch("mapped.csv", csv);
    let options = LogReadOptions {
        profile: Some(map_path.display().to_string()),
        ..LogReadOptions::default()
    };
    let lag = (fnv1a(data) % 4 == 0).then_some(LAG_WINDOW_S);
    let mut o = Outcome::default();
    o.accepted = info(&mut o, &csv_path, &options, lag);
    o
}

/// The parts of `data` between `separator`s.
fn split<'a>(data: &'a [u8], separator: &[u8]) -> Vec<&'a [u8]> {
    let mut parts = Vec::new();
    let mut rest = data;
    while let Some(k) = rest.windows(separator.len()).position(|w| w == separator) {
        parts.push(&rest[..k]);
        rest = &rest[k + separator.len()..];
    }
    parts.push(rest);
    parts
}

fn px4_csv(data: &[u8]) -> Outcome {
    let parts = split(data, TABLE_SEPARATOR);
    let mut first = PathBuf::new();
    for (k, topic) in aloft_logs::px4::PX4_TOPICS.iter().enumerate() {
        // A table the input does not have (its separator was mutated away) is empty.
        let path = write_scratch(
            &format!("flight_{topic}_0.csv"),
            parts.get(k).copied().unwrap_or_default(),
        );
        if k == 0 {
            first = path;
        }
    }
    let lag = (fnv1a(data) % 4 == 0).then_some(LAG_WINDOW_S);
    let mut o = Outcome::default();
    o.accepted = info(&mut o, &first, &LogReadOptions::default(), lag);
    o
}

fn mcap(data: &[u8]) -> Outcome {
    let path = write_scratch("log.mcap", data);
    let h = fnv1a(data);
    let options = LogReadOptions {
        header_time: h & 2 != 0,
        battery_current_positive: h & 4 != 0,
        topics: if h % 16 == 3 {
            vec!["/battery".into(), "/vehicle/pose".into()]
        } else {
            Vec::new()
        },
        ..LogReadOptions::default()
    };
    let lag = (h % 4 == 0).then_some(LAG_WINDOW_S);
    let mut o = Outcome::default();
    o.accepted = info(&mut o, &path, &options, lag);
    o
}

/// A binary log read from bytes: what the reader found, each optional figure only when present
/// (so a `null` is a number that was not finite).
fn binary_answer(o: &mut Outcome, what: &'static str, log: &aloft_logs::BinaryLog) {
    let s = &log.summary;
    let mut a = serde_json::Map::new();
    a.insert("samples".into(), log.log.samples.len().into());
    a.insert("bytes".into(), s.bytes.into());
    a.insert("bytes_skipped".into(), s.bytes_skipped.into());
    a.insert("warnings".into(), s.warnings.len().into());
    a.insert("battery_valid".into(), s.battery.valid.into());
    a.insert("battery_energy_j".into(), json_f64(s.battery.energy_j));
    a.insert("base_span_s".into(), json_f64(s.base_span_s));
    a.insert("start_time_s".into(), json_f64(log.log.start_time_s));
    let optional = [
        ("energy_wh", s.energy_wh()),
        ("battery_capacity_ah", s.battery_capacity_ah),
        ("air_density_kg_m3", s.air_density_kg_m3),
        ("in_air_s", s.in_air_s),
        ("battery_first_s", s.battery.first_s),
        ("battery_last_s", s.battery.last_s),
    ];
    for (k, v) in optional {
        if let Some(v) = v {
            a.insert(k.into(), json_f64(v));
        }
    }
    if let Some(last) = log.log.samples.last() {
        a.insert("last_time_s".into(), json_f64(last.time_s));
    }
    o.json(what, &a);
}

/// A number as JSON: `null` when it is not finite (which the checks report).
fn json_f64(v: f64) -> serde_json::Value {
    serde_json::Number::from_f64(v).map_or(serde_json::Value::Null, serde_json::Value::Number)
}

/// A binary log: read from the bytes (the reader refuses only what is not such a log), and on
/// every 8th input `log_info` of the bytes written to `file` (the engine's path, as `aloft log
/// info` runs it).
fn binary_log(
    data: &[u8],
    file: &str,
    read: fn(&[u8]) -> aloft_logs::Result<aloft_logs::BinaryLog>,
) -> Outcome {
    let mut o = Outcome::default();
    match read(data) {
        Ok(log) => {
            o.accepted = true;
            binary_answer(&mut o, "binary log", &log);
        }
        Err(e) => {
            let e = aloft::Error::from(e);
            o.refuse("binary log", &e);
        }
    }
    if fnv1a(data) % 8 == 0 {
        let path = write_scratch(file, data);
        info(&mut o, &path, &LogReadOptions::default(), None);
    }
    o
}

fn ulog(data: &[u8]) -> Outcome {
    binary_log(data, "log.ulg", |d| {
        aloft_logs::read_ulog(d, &aloft_logs::BinaryOptions::default())
    })
}

fn dataflash(data: &[u8]) -> Outcome {
    binary_log(data, "log.bin", |d| {
        aloft_logs::read_dataflash(d, &aloft_logs::BinaryOptions::default())
    })
}

/// The numbers aloft computed in an event (mission parameters are passed as sent, NaN meaning
/// "not set" in MAVLink, so they are not among them), and the event's kind.
fn event_numbers(e: &aloft_link::Event) -> (&'static str, Vec<f64>) {
    use aloft_link::Event;
    match e {
        Event::Sample(s) => {
            let mut v: Vec<f64> = [s.pos_enu_m, s.vel_enu_mps, s.acc_enu_mps2, s.wind_enu_mps]
                .into_iter()
                .flatten()
                .flatten()
                .collect();
            v.extend(
                [s.voltage_v, s.current_a, s.power_w, s.charge_ah, s.soc]
                    .into_iter()
                    .flatten(),
            );
            if let Some(a) = s.attitude {
                v.extend([a.roll_rad, a.pitch_rad, a.yaw_rad]);
            }
            v.push(s.time_s);
            ("sample", v)
        }
        Event::Origin(o) => ("origin", vec![o.lat_rad, o.lon_rad, o.alt_m]),
        Event::Home(h) => ("home", h.to_vec()),
        Event::Heartbeat(_) => ("heartbeat", Vec::new()),
        Event::Battery(b) => (
            "battery",
            [b.soc, b.consumed_ah].into_iter().flatten().collect(),
        ),
        Event::Speeds {
            airspeed_mps,
            groundspeed_mps,
        } => ("speeds", vec![*airspeed_mps, *groundspeed_mps]),
        Event::MissionCurrent(_) => ("mission-current", Vec::new()),
        Event::Mission(m) => ("mission", vec![m.len() as f64]),
        Event::Reboot => ("reboot", Vec::new()),
        Event::LinkLost { silent_s } => ("link-lost", vec![*silent_s]),
        Event::ClockBack { back_s } => ("clock-back", vec![*back_s]),
        Event::Parameter { value, .. } => ("parameter", vec![*value]),
    }
}

/// The BATTERY_STATUS `aloft live` would send after `u`: its percentage within 0-100 or -1, its
/// time not negative.
fn check_battery_reply(u: &aloft::engine::LiveUpdate, o: &mut Outcome) {
    let mut replies = aloft::engine::LiveReplies::new(aloft::engine::DEFAULT_BATTERY_ID);
    for r in replies.replies(None, u) {
        let aloft_link::Reply::Battery(b) = r else {
            continue;
        };
        let aloft_link::mavlink::dialects::ardupilotmega::MavMessage::BATTERY_STATUS(m) =
            aloft_link::battery_status(&b)
        else {
            continue;
        };
        if !(-1..=100).contains(&m.battery_remaining) || m.time_remaining < 0 {
            o.broken.push(Problem {
                check: "live-battery-status",
                detail: format!("{m:?} from {b:?}"),
            });
        }
    }
}

/// A telemetry log: every event of [`aloft_link::TlogSource`], with its invariants checked (time
/// finite and never going back, computed values finite, all bytes read), and the answer the
/// counts of events by kind; on every 4th input the frames of [`aloft_link::TlogReader`] and the
/// skipped bytes add up to the input. Every event is folded into an `aloft live` session, and on
/// every 8th input the session answers (4 scenarios): its numbers finite.
fn tlog(data: &[u8]) -> Outcome {
    let mut o = Outcome::default();
    let request = LiveRequest {
        scenarios: 4,
        ..LiveRequest::new()
    };
    let mut session = LiveSession::new(m100(), &request).ok();
    let mut source = aloft_link::TlogSource::new(data, "fuzz.tlog");
    let mut kinds: std::collections::BTreeMap<&'static str, u64> = Default::default();
    let (mut last_s, mut largest) = (0.0f64, 0.0f64);
    loop {
        let t = match source.next_telemetry() {
            Ok(Some(t)) => t,
            Ok(None) => break,
            // Bytes without a single frame: bad input, said as such.
            Err(aloft_link::LinkError::NothingReadable { .. }) => break,
            Err(e) => {
                o.broken.push(Problem {
                    check: "tlog-read",
                    detail: format!("a read error on bytes in memory: {e}"),
                });
                break;
            }
        };
        if !(t.time_s.is_finite() && t.time_s >= last_s) {
            o.broken.push(Problem {
                check: "tlog-time",
                detail: format!("time {} after {last_s}", t.time_s),
            });
        }
        last_s = last_s.max(t.time_s);
        if let Some(s) = &mut session {
            s.apply(&t);
        }
        let (kind, numbers) = event_numbers(&t.event);
        *kinds.entry(kind).or_default() += 1;
        if let Some(v) = numbers.iter().find(|v| !v.is_finite()) {
            o.broken.push(Problem {
                check: "tlog-non-finite",
                detail: format!("{v} in {:?}", t.event),
            });
        }
        largest = numbers.iter().fold(largest, |m, v| m.max(v.abs()));
    }
    let stats = *source.stats();
    if stats.bytes != data.len() as u64 || stats.bytes_skipped > stats.bytes {
        o.broken.push(Problem {
            check: "tlog-bytes",
            detail: format!("{} bytes in, {stats:?}", data.len()),
        });
    }
    if fnv1a(data) % 4 == 0 {
        let mut reader = aloft_link::TlogReader::new(data, "fuzz.tlog");
        let framed: u64 = reader.by_ref().flatten().map(|f| f.len as u64).sum();
        if framed + reader.stats().bytes_skipped != data.len() as u64 {
            o.broken.push(Problem {
                check: "tlog-framing",
                detail: format!("{framed} framed + {:?} != {}", reader.stats(), data.len()),
            });
        }
    }
    o.accepted = stats.frames > 0;
    let mut answer = serde_json::Map::new();
    if let Some(s) = session.as_mut().filter(|_| fnv1a(data) % 8 == 1) {
        let u = s.update();
        let band = |b: Option<aloft::engine::Percentiles>| {
            b.map_or_else(Vec::new, |b| vec![b.p5, b.p50, b.p95])
        };
        let mut numbers = vec![u.energy_used_wh, u.efficiency, u.time_s];
        numbers.extend(band(u.remaining_wh));
        numbers.extend(band(u.landing_soc));
        numbers.extend(
            u.soc
                .iter()
                .chain(&u.point_of_no_return_s)
                .chain(&u.power_w),
        );
        if numbers.iter().any(|x| !x.is_finite()) {
            o.broken.push(Problem {
                check: "live-non-finite",
                detail: format!("{u:?}"),
            });
        }
        answer.insert("live_advice".into(), u.advice.unwrap_or("-").into());
        check_battery_reply(&u, &mut o);
    }
    answer.insert("frames".into(), stats.frames.into());
    answer.insert("bad_frames".into(), stats.bad_frames().into());
    answer.insert("bytes_skipped".into(), stats.bytes_skipped.into());
    answer.insert("last_time_s".into(), json_f64(last_s));
    answer.insert("largest".into(), json_f64(largest));
    for (k, n) in kinds {
        answer.insert(k.into(), n.into());
    }
    o.json("tlog", &answer);
    o
}
