//! How `aloft logbook add` reads a log: the logbook's own readers (PX4 ULog, ArduPilot
//! DataFlash, MCAP, CSV), and MAVLink telemetry logs (`.tlog`) through aloft-link, whose flight
//! ([`aloft_link::TlogFlight`]) becomes the figures of a `flights` row. The logbook crate does not
//! depend on aloft-link (the mavlink crate): the reading of a telemetry log produces a record the
//! logbook takes ([`aloft_logbook::Logbook::add_with`]).

use std::path::Path;

use aloft_logbook::{read_flight, FlightFacts, LogKind, ReadOptions};

/// The flight of the log at `path`, or why the logbook does not take it (in words, without the
/// path the readers lead with).
pub(super) fn read_log(path: &Path, options: &ReadOptions) -> Result<FlightFacts, String> {
    let tlog_named = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("tlog"));
    if tlog_named || aloft_logbook::log_kind(path) == LogKind::Tlog {
        read_tlog(path)
    } else {
        read_flight(path, options)
    }
}

fn read_tlog(path: &Path) -> Result<FlightFacts, String> {
    let name = path.display().to_string();
    let strip = |reason: String| {
        reason
            .strip_prefix(&format!("{name}: "))
            .map_or_else(|| reason.clone(), str::to_string)
    };
    let file = aloft_core::open_regular_file(path).map_err(|e| e.to_string())?;
    let f = aloft_link::read_tlog_flight(std::io::BufReader::with_capacity(1 << 16, file), &name)
        .map_err(|e| strip(e.to_string()))?;
    Ok(facts_of(&f))
}

/// The figures of a `flights` row from a telemetry log's flight (no pack analysis: a telemetry
/// stream is too sparse for current steps and rests).
fn facts_of(f: &aloft_link::TlogFlight) -> FlightFacts {
    FlightFacts {
        format: "tlog".to_string(),
        vehicle_id: f.vehicle_id.clone(),
        pack_id: f.pack_id.clone(),
        rated_capacity_mah: f.rated_capacity_mah,
        cells_series: None,
        start_unix_s: Some(f.start_unix_s),
        duration_s: f.duration_s,
        energy_wh: f.energy_wh,
        discharged_mah: f.discharged_mah,
        max_current_a: f.max_current_a,
        min_voltage_v: Some(f.min_voltage_v).filter(|v| v.is_finite()),
        mean_power_w: FlightFacts::mean_power_w(f.duration_s, f.energy_wh, f.discharged_mah),
        air_s: Some(f.air_s),
        high_voltage_v: Some(f.high_voltage_v).filter(|v| v.is_finite()),
        ..FlightFacts::default()
    }
}
