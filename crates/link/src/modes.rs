//! Flight mode names from HEARTBEAT `custom_mode`: ArduCopter's mode numbers, PX4's main and sub
//! modes (bytes 2 and 3 of `custom_mode`), else `custom N`.

use mavlink::dialects::ardupilotmega::{MavAutopilot, MavType};

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

/// Whether ArduPilot on this vehicle type runs ArduCopter (rotorcraft that are not VTOL planes).
fn is_copter(vehicle_type: MavType) -> bool {
    matches!(
        vehicle_type,
        MavType::MAV_TYPE_QUADROTOR
            | MavType::MAV_TYPE_COAXIAL
            | MavType::MAV_TYPE_HELICOPTER
            | MavType::MAV_TYPE_HEXAROTOR
            | MavType::MAV_TYPE_OCTOROTOR
            | MavType::MAV_TYPE_TRICOPTER
            | MavType::MAV_TYPE_DODECAROTOR
            | MavType::MAV_TYPE_DECAROTOR
            | MavType::MAV_TYPE_GENERIC_MULTIROTOR
    )
}

/// The flight mode's name: ArduCopter's for ArduPilot rotorcraft, PX4's for PX4, `custom N`
/// otherwise (other ArduPilot vehicles, unknown numbers).
pub fn mode_name(autopilot: MavAutopilot, vehicle_type: MavType, custom_mode: u32) -> String {
    let known = match autopilot {
        MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA if is_copter(vehicle_type) => {
            lookup(&ARDUCOPTER, custom_mode)
        }
        MavAutopilot::MAV_AUTOPILOT_PX4 => px4(custom_mode),
        _ => None,
    };
    known.map_or_else(|| format!("custom {custom_mode}"), str::to_owned)
}

fn px4(custom_mode: u32) -> Option<&'static str> {
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
    fn arducopter_px4_and_unknown_modes() {
        let apm = MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA;
        let quad = MavType::MAV_TYPE_QUADROTOR;
        assert_eq!(mode_name(apm, quad, 3), "AUTO");
        assert_eq!(mode_name(apm, quad, 21), "SMART_RTL");
        assert_eq!(mode_name(apm, quad, 8), "custom 8");
        // ArduPlane numbers mean other modes: not named.
        assert_eq!(
            mode_name(apm, MavType::MAV_TYPE_FIXED_WING, 10),
            "custom 10"
        );
        let px4 = MavAutopilot::MAV_AUTOPILOT_PX4;
        assert_eq!(mode_name(px4, quad, (4 << 16) | (4 << 24)), "MISSION");
        assert_eq!(mode_name(px4, quad, 3 << 16), "POSCTL");
        assert_eq!(mode_name(px4, quad, (3 << 16) | (1 << 24)), "ORBIT");
        assert_eq!(mode_name(px4, quad, 6 << 16), "OFFBOARD");
        assert_eq!(
            mode_name(px4, quad, 77 << 16),
            format!("custom {}", 77 << 16)
        );
        let generic = MavAutopilot::MAV_AUTOPILOT_GENERIC;
        assert_eq!(mode_name(generic, quad, 3), "custom 3");
    }
}
