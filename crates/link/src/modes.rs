//! Flight mode names from HEARTBEAT `custom_mode`: ArduCopter's mode numbers, PX4's main and sub
//! modes (bytes 2 and 3 of `custom_mode`), else `custom N`; the tables are aloft-logs'
//! ([`aloft_logs::modes`]).

use aloft_logs::modes::{arducopter_mode, px4_mode};
use mavlink::dialects::ardupilotmega::{MavAutopilot, MavType};

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
            arducopter_mode(custom_mode)
        }
        MavAutopilot::MAV_AUTOPILOT_PX4 => px4_mode(custom_mode),
        _ => None,
    };
    known.map_or_else(|| format!("custom {custom_mode}"), str::to_owned)
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
