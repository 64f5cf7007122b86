//! Flight mode names by number: ArduCopter's modes (HEARTBEAT `custom_mode`, DataFlash `MODE`
//! `ModeNum`) and PX4's main and sub modes (bytes 2 and 3 of `custom_mode`). One table for every
//! source of `aloft live`: MAVLink links and telemetry logs (`aloft-link`), DataFlash replays
//! ([`crate::flight_events`]).

/// ArduCopter's modes by number (`ArduCopter/mode.h`, `enum class Number`; the same as the
/// ardupilotmega dialect's `COPTER_MODE`).
const ARDUCOPTER: [(u32, &str); 26] = [
    (0, "STABILIZE"),
    (1, "ACRO"),
    (2, "ALT_HOLD"),
    (3, "AUTO"),
    (4, "GUIDED"),
    (5, "LOITER"),
    (6, "RTL"),
    (7, "CIRCLE"),
    (9, "LAND"),
    (11, "DRIFT"),
    (13, "SPORT"),
    (14, "FLIP"),
    (15, "AUTOTUNE"),
    (16, "POSHOLD"),
    (17, "BRAKE"),
    (18, "THROW"),
    (19, "AVOID_ADSB"),
    (20, "GUIDED_NOGPS"),
    (21, "SMART_RTL"),
    (22, "FLOWHOLD"),
    (23, "FOLLOW"),
    (24, "ZIGZAG"),
    (25, "SYSTEMID"),
    (26, "AUTOROTATE"),
    (27, "AUTO_RTL"),
    (28, "TURTLE"),
];

/// PX4's main modes (`px4_custom_mode.h`, `PX4_CUSTOM_MAIN_MODE_*`).
const PX4_MAIN: [(u32, &str); 10] = [
    (1, "MANUAL"),
    (2, "ALTCTL"),
    (3, "POSCTL"),
    (4, "AUTO"),
    (5, "ACRO"),
    (6, "OFFBOARD"),
    (7, "STABILIZED"),
    (8, "RATTITUDE"),
    (9, "SIMPLE"),
    (10, "TERMINATION"),
];

/// PX4's AUTO sub-modes (`PX4_CUSTOM_SUB_MODE_AUTO_*`), by the names QGroundControl and
/// pymavlink show.
const PX4_AUTO: [(u32, &str); 9] = [
    (1, "READY"),
    (2, "TAKEOFF"),
    (3, "LOITER"),
    (4, "MISSION"),
    (5, "RTL"),
    (6, "LAND"),
    (8, "FOLLOWME"),
    (9, "PRECLAND"),
    (10, "VTOL_TAKEOFF"),
];

const PX4_MAIN_AUTO: u32 = 4;
const PX4_MAIN_POSCTL: u32 = 3;
const PX4_POSCTL_ORBIT: u32 = 1;

fn lookup(table: &[(u32, &'static str)], n: u32) -> Option<&'static str> {
    table.iter().find(|(k, _)| *k == n).map(|(_, name)| *name)
}

/// ArduCopter's mode `n` by name, `None` for a number it does not have.
pub fn arducopter_mode(n: u32) -> Option<&'static str> {
    lookup(&ARDUCOPTER, n)
}

/// PX4's mode of a HEARTBEAT `custom_mode` by name (the sub mode in AUTO), `None` where unknown.
pub fn px4_mode(custom_mode: u32) -> Option<&'static str> {
    let main = (custom_mode >> 16) & 0xFF;
    let sub = (custom_mode >> 24) & 0xFF;
    match main {
        PX4_MAIN_AUTO => lookup(&PX4_AUTO, sub),
        PX4_MAIN_POSCTL if sub == PX4_POSCTL_ORBIT => Some("ORBIT"),
        _ => lookup(&PX4_MAIN, main),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arducopter_and_px4_modes_by_number() {
        assert_eq!(arducopter_mode(3), Some("AUTO"));
        assert_eq!(arducopter_mode(21), Some("SMART_RTL"));
        assert_eq!(arducopter_mode(8), None);
        assert_eq!(px4_mode((4 << 16) | (4 << 24)), Some("MISSION"));
        assert_eq!(px4_mode((3 << 16) | (1 << 24)), Some("ORBIT"));
        assert_eq!(px4_mode(77 << 16), None);
    }
}
