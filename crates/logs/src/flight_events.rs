//! The flight's events a DataFlash log records beside its samples, as `aloft live` takes them
//! from a link ([`crate::telemetry`]): the flight mode and arming as [`Event::Heartbeat`], the
//! mission as [`Event::Mission`], the item being flown as [`Event::MissionCurrent`].
//!
//! | record | event |
//! |---|---|
//! | `MODE` (`ModeNum`, else `Mode`) | [`Event::Heartbeat`]: the mode by ArduCopter's name ([`crate::modes`]), armed as last seen (armed before any record says: ArduPilot logs while armed by default) |
//! | `ARM` (`ArmState`), `EV` 10 (armed) and 11 (disarmed) | [`Event::Heartbeat`] with the last mode |
//! | `CMD` written together (within [`DUMP_GAP_S`] of each other: the mission as loaded, or at arming) | [`Event::Mission`] once every item of `CTot` is there |
//! | `CMD` alone (ArduCopter writes each command as it starts) | [`Event::MissionCurrent`] (`CNum`) |
//!
//! Times are the records' boot times ([`Record::time_s`]) less `start_time_s`, the log's first sample
//! ([`crate::Log::start_time_s`]), so they line up with the samples. The events of a log are few
//! (a mode change, a mission); at most [`MAX_EVENTS`] are kept.

use std::collections::BTreeMap;
use std::io::Read;

use crate::dataflash::{DataflashRecords, Record};
use crate::modes::arducopter_mode;
use crate::telemetry::{Event, Heartbeat, MissionItem, Telemetry};

/// `CMD` records closer than this are one mission written at once, s.
pub const DUMP_GAP_S: f64 = 0.05;

/// Most events kept from one log.
pub const MAX_EVENTS: usize = 100_000;

/// Most items of one mission (as MAVLink links: [`u16`] sequence numbers, far fewer in practice).
const MAX_ITEMS: u32 = 10_000;

/// MAV_TYPE of the heartbeats (a quadrotor: aloft flies multirotors, and the DataFlash log of an
/// ArduCopter does not say which frame).
const QUADROTOR: u8 = 2;

/// The flight events of the DataFlash log `reader` (see the module docs), in time order.
pub fn dataflash_events<R: Read>(reader: R, start_time_s: f64) -> Vec<Telemetry> {
    let mut f = Folder {
        start_time_s,
        // ArduPilot logs while armed unless told otherwise (`LOG_DISARMED`): armed until an
        // `ARM` or `EV` says so (where the vehicle is on the ground, its landed state says it).
        armed: true,
        mode: None,
        run: Vec::new(),
        items: BTreeMap::new(),
        out: Vec::new(),
    };
    for r in DataflashRecords::new(reader) {
        if f.out.len() >= MAX_EVENTS {
            break;
        }
        f.record(&r);
    }
    f.flush_run();
    f.out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    f.out
}

/// The state of the pass over the records.
struct Folder {
    start_time_s: f64,
    armed: bool,
    mode: Option<String>,
    /// `CMD` records written together so far: (time, item).
    run: Vec<(f64, MissionItem, u32)>,
    /// The mission's items by number, and how many it has.
    items: BTreeMap<u32, MissionItem>,
    out: Vec<Telemetry>,
}

fn value(r: &Record, name: &str) -> Option<f64> {
    r.values
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| *v)
        .filter(|v| v.is_finite())
}

impl Folder {
    fn time_s(&self, r: &Record) -> Option<f64> {
        Some((r.time_s? - self.start_time_s).max(0.0))
    }

    fn record(&mut self, r: &Record) {
        let Some(t) = self.time_s(r) else {
            return;
        };
        if r.name != "CMD"
            || self
                .run
                .last()
                .is_some_and(|(t0, _, _)| t - t0 > DUMP_GAP_S)
        {
            self.flush_run();
        }
        match r.name.as_str() {
            "MODE" => {
                if let Some(n) = value(r, "ModeNum").or_else(|| value(r, "Mode")) {
                    let n = n as u32;
                    self.mode = Some(
                        arducopter_mode(n).map_or_else(|| format!("custom {n}"), str::to_owned),
                    );
                    self.heartbeat(t);
                }
            }
            "ARM" => {
                if let Some(s) = value(r, "ArmState") {
                    self.armed = s != 0.0;
                    self.heartbeat(t);
                }
            }
            "EV" => match value(r, "Id").map(|id| id as u32) {
                Some(10) => {
                    self.armed = true;
                    self.heartbeat(t);
                }
                Some(11) => {
                    self.armed = false;
                    self.heartbeat(t);
                }
                _ => {}
            },
            "CMD" => {
                if let Some(item) = cmd_item(r) {
                    let total = value(r, "CTot").map_or(0, |n| n as u32).min(MAX_ITEMS);
                    self.run.push((t, item, total));
                }
            }
            _ => {}
        }
    }

    fn heartbeat(&mut self, t: f64) {
        self.out.push(Telemetry {
            time_s: t,
            event: Event::Heartbeat(Heartbeat {
                armed: self.armed,
                mode: self.mode.clone().unwrap_or_else(|| "unknown".to_string()),
                vehicle_type: QUADROTOR,
            }),
        });
    }

    /// The `CMD` records written together: a mission (two or more), or the item starting (one).
    fn flush_run(&mut self) {
        let run = std::mem::take(&mut self.run);
        match run.as_slice() {
            [] => {}
            [(t, item, _)] => {
                self.items.insert(item.seq, *item);
                self.out.push(Telemetry {
                    time_s: *t,
                    event: Event::MissionCurrent(item.seq),
                });
            }
            [.., (t, _, total)] => {
                self.items.retain(|seq, _| seq < total);
                for (_, item, _) in &run {
                    if item.seq < *total {
                        self.items.insert(item.seq, *item);
                    }
                }
                if *total > 0 && self.items.len() == *total as usize {
                    self.out.push(Telemetry {
                        time_s: *t,
                        event: Event::Mission(self.items.values().copied().collect()),
                    });
                }
            }
        }
    }
}

/// A `CMD` record as a mission item (`.waypoints` fields: latitude and longitude in degrees,
/// altitude in metres).
fn cmd_item(r: &Record) -> Option<MissionItem> {
    let seq = value(r, "CNum")?;
    let command = value(r, "CId")?;
    if !(0.0..f64::from(MAX_ITEMS)).contains(&seq) || !(0.0..65_536.0).contains(&command) {
        return None;
    }
    let p = |name: &str| value(r, name).unwrap_or(0.0);
    Some(MissionItem {
        seq: seq as u32,
        frame: value(r, "Frame").map_or(0, |f| f as u32),
        command: command as u32,
        params: [
            p("Prm1"),
            p("Prm2"),
            p("Prm3"),
            p("Prm4"),
            p("Lat"),
            p("Lng"),
            p("Alt"),
        ],
    })
}
