//! A DataFlash log replayed as `aloft live` events: its samples, and its mode, arming and mission
//! records as a link would send them (`aloft_logs::flight_events`), checked against the records
//! as pymavlink 2.4.50 prints them (`MODE`, `ARM`, `CMD`, the first `ATT`).

use crate::common;

use aloft_logs::flight_events::dataflash_events;
use aloft_logs::telemetry::Event;
use common::data_dir;

fn events(file: &str) -> Vec<aloft_logs::telemetry::Telemetry> {
    let path = data_dir().join("flight_logs").join(file);
    let log = aloft_logs::read_log(&path, None, &Default::default()).unwrap();
    let reader = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
    dataflash_events(reader, log.start_time_s)
}

/// `sitl_ac47_00000002.BIN`: GUIDED at 42.661 s of boot (before the first ATT at 42.743 s, so at
/// 0), LAND at 55.670 s, disarmed (ARM, ArmState 0, and EV 11) at 68.153 s.
#[test]
fn data_val_dataflash_modes_and_arming_as_heartbeats() {
    let e = events("sitl_ac47_00000002.BIN");
    let beats: Vec<(f64, String, bool)> = e
        .iter()
        .filter_map(|t| match &t.event {
            Event::Heartbeat(h) => Some((t.time_s, h.mode.clone(), h.armed)),
            _ => None,
        })
        .collect();
    println!("{beats:?}");
    assert_eq!(beats[0].1, "GUIDED");
    assert!(beats[0].0 < 1e-9 && beats[0].2);
    let land = beats.iter().find(|b| b.1 == "LAND").unwrap();
    assert!((land.0 - (55.670223 - 42.742896)).abs() < 1e-3, "{land:?}");
    assert!(land.2, "armed while landing: {land:?}");
    let last = beats.last().unwrap();
    assert!(
        !last.2 && (last.0 - (68.152728 - 42.742896)).abs() < 1e-3,
        "{last:?}"
    );
}

/// `beastayyg_sample.bin`: the mission written at once (4 items, then 5 after an upload), and
/// each item as it starts (`MissionCurrent`): 1 at 214.279 s of boot, 2 at 216.737 s.
#[test]
fn data_val_dataflash_mission_and_items_flown() {
    let e = events("beastayyg_sample.bin");
    let missions: Vec<usize> = e
        .iter()
        .filter_map(|t| match &t.event {
            Event::Mission(m) => Some(m.len()),
            _ => None,
        })
        .collect();
    assert_eq!(missions.first(), Some(&4), "{missions:?}");
    let current: Vec<(f64, u32)> = e
        .iter()
        .filter_map(|t| match t.event {
            Event::MissionCurrent(s) => Some((t.time_s, s)),
            _ => None,
        })
        .collect();
    println!("{missions:?} {current:?}");
    assert_eq!(current[0].1, 1);
    assert!(
        (current[0].0 - (214.279446 - 208.67442)).abs() < 1e-3,
        "{current:?}"
    );
    assert_eq!(current[1].1, 2);
}

/// `aloft live --replay sitl_ac47_00000002.BIN` sends the log's 28 battery parameters (`BAT*`,
/// as pymavlink 2.4.50 lists its `PARM` records) before its first record: `BATT_LOW_VOLT` 10.5 V
/// and `BATT_CAPACITY` 3300 mA h among them.
#[test]
fn data_val_a_replayed_log_sends_its_battery_parameters_first() {
    let path = data_dir()
        .join("flight_logs")
        .join("sitl_ac47_00000002.BIN");
    let source = aloft::engine::LiveSource::Replay {
        logs: aloft::engine::FlightLogs {
            logs: vec![path],
            ..Default::default()
        },
        speed: None,
    };
    let mut events = source.open().unwrap();
    let mut parameters = std::collections::BTreeMap::new();
    while let Some(t) = events.next_event().unwrap() {
        match t.event {
            Event::Parameter { name, value } => {
                parameters.insert(name, value);
            }
            Event::Origin(_) => {}
            _ => break,
        }
    }
    assert_eq!(parameters.len(), 28, "{parameters:?}");
    assert!(parameters.keys().all(|k| k.starts_with("BAT")));
    assert_eq!(parameters.get("BATT_LOW_VOLT"), Some(&10.5));
    assert_eq!(parameters.get("BATT_CAPACITY"), Some(&3300.0));
}
