//! The MAVLink commands (MAV_CMD) the importers know: their ids, names and what they cost.
//! Ids and parameter meanings from the MAVLink common message set (`common.xml`).

use std::fmt;

/// MAV_CMD_NAV_WAYPOINT: fly to a position; p1 hold s, p2 acceptance radius m.
pub const NAV_WAYPOINT: u32 = 16;
/// MAV_CMD_NAV_LOITER_UNLIM: loiter at a position until the operator intervenes.
pub const NAV_LOITER_UNLIM: u32 = 17;
/// MAV_CMD_NAV_LOITER_TURNS: p1 turns about a position, p3 radius m (negative: counter-clockwise).
pub const NAV_LOITER_TURNS: u32 = 18;
/// MAV_CMD_NAV_LOITER_TIME: loiter at a position for p1 s.
pub const NAV_LOITER_TIME: u32 = 19;
/// MAV_CMD_NAV_RETURN_TO_LAUNCH: back over the launch point and land.
pub const NAV_RETURN_TO_LAUNCH: u32 = 20;
/// MAV_CMD_NAV_LAND: land at a position (lat/lon 0: here).
pub const NAV_LAND: u32 = 21;
/// MAV_CMD_NAV_TAKEOFF: take off to p7.
pub const NAV_TAKEOFF: u32 = 22;
/// MAV_CMD_NAV_LOITER_TO_ALT: to a position, then climb or descend to p7 there.
pub const NAV_LOITER_TO_ALT: u32 = 31;
/// MAV_CMD_NAV_SPLINE_WAYPOINT: a waypoint on a spline through its neighbours; p1 hold s.
pub const NAV_SPLINE_WAYPOINT: u32 = 82;
/// MAV_CMD_NAV_VTOL_TAKEOFF.
pub const NAV_VTOL_TAKEOFF: u32 = 84;
/// MAV_CMD_NAV_VTOL_LAND.
pub const NAV_VTOL_LAND: u32 = 85;
/// MAV_CMD_NAV_DELAY: wait p1 s (-1: until a time of day).
pub const NAV_DELAY: u32 = 93;
/// MAV_CMD_CONDITION_DELAY: wait p1 s.
pub const CONDITION_DELAY: u32 = 112;
/// MAV_CMD_DO_JUMP: p1 target, p2 repeat count.
pub const DO_JUMP: u32 = 177;
/// MAV_CMD_DO_CHANGE_SPEED: p1 speed type (0 air, 1 ground, 2 climb, 3 descent), p2 speed m/s
/// (-1 no change, -2 back to the default).
pub const DO_CHANGE_SPEED: u32 = 178;
/// MAV_CMD_DO_GRIPPER: p1 gripper, p2 action (0 release, 1 grab).
pub const DO_GRIPPER: u32 = 211;
/// MAV_CMD_DO_VTOL_TRANSITION.
pub const DO_VTOL_TRANSITION: u32 = 3000;

/// What an item does to the flight.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    /// Moves, climbs, lands or holds the vehicle: becomes segments.
    Flown,
    /// Changes how the rest is flown (speed, jump, payload).
    Command,
    /// Costs nothing aloft models (camera, gimbal, region of interest, mode, servo, fence).
    Free,
    /// Refused: aloft models multirotors.
    Vtol,
    /// Not known: warned, never silently skipped.
    Unknown,
}

/// The role of a command.
pub(crate) fn role(command: u32) -> Role {
    match command {
        NAV_WAYPOINT | NAV_LOITER_UNLIM | NAV_LOITER_TURNS | NAV_LOITER_TIME
        | NAV_RETURN_TO_LAUNCH | NAV_LAND | NAV_TAKEOFF | NAV_LOITER_TO_ALT
        | NAV_SPLINE_WAYPOINT | NAV_DELAY | CONDITION_DELAY => Role::Flown,
        DO_JUMP | DO_CHANGE_SPEED | DO_GRIPPER => Role::Command,
        NAV_VTOL_TAKEOFF | NAV_VTOL_LAND | DO_VTOL_TRANSITION => Role::Vtol,
        c if free_name(c).is_some() => Role::Free,
        _ => Role::Unknown,
    }
}

/// Names of the commands that cost nothing aloft models.
fn free_name(command: u32) -> Option<&'static str> {
    Some(match command {
        80 => "NAV_ROI",
        113 => "CONDITION_DISTANCE",
        114 => "CONDITION_CHANGE_ALT",
        115 => "CONDITION_YAW",
        176 => "DO_SET_MODE",
        181 => "DO_SET_RELAY",
        182 => "DO_REPEAT_RELAY",
        183 => "DO_SET_SERVO",
        184 => "DO_REPEAT_SERVO",
        189 => "DO_LAND_START",
        195 => "DO_SET_ROI_LOCATION",
        196 => "DO_SET_ROI_WPNEXT_OFFSET",
        197 => "DO_SET_ROI_NONE",
        198 => "DO_SET_ROI_SYSID",
        200 => "DO_CONTROL_VIDEO",
        201 => "DO_SET_ROI",
        202 => "DO_DIGICAM_CONFIGURE",
        203 => "DO_DIGICAM_CONTROL",
        204 => "DO_MOUNT_CONFIGURE",
        205 => "DO_MOUNT_CONTROL",
        206 => "DO_SET_CAM_TRIGG_DIST",
        207 => "DO_FENCE_ENABLE",
        214 => "DO_SET_CAM_TRIGG_INTERVAL",
        530 => "SET_CAMERA_MODE",
        531 => "SET_CAMERA_ZOOM",
        532 => "SET_CAMERA_FOCUS",
        1000 => "DO_GIMBAL_MANAGER_PITCHYAW",
        1001 => "DO_GIMBAL_MANAGER_CONFIGURE",
        2000 => "IMAGE_START_CAPTURE",
        2001 => "IMAGE_STOP_CAPTURE",
        2003 => "DO_TRIGGER_CONTROL",
        2500 => "VIDEO_START_CAPTURE",
        2501 => "VIDEO_STOP_CAPTURE",
        _ => return None,
    })
}

/// The MAVLink name of a command (without `MAV_CMD_`), when aloft knows it.
pub(crate) fn name(command: u32) -> Option<&'static str> {
    Some(match command {
        NAV_WAYPOINT => "NAV_WAYPOINT",
        NAV_LOITER_UNLIM => "NAV_LOITER_UNLIM",
        NAV_LOITER_TURNS => "NAV_LOITER_TURNS",
        NAV_LOITER_TIME => "NAV_LOITER_TIME",
        NAV_RETURN_TO_LAUNCH => "NAV_RETURN_TO_LAUNCH",
        NAV_LAND => "NAV_LAND",
        NAV_TAKEOFF => "NAV_TAKEOFF",
        NAV_LOITER_TO_ALT => "NAV_LOITER_TO_ALT",
        NAV_SPLINE_WAYPOINT => "NAV_SPLINE_WAYPOINT",
        NAV_VTOL_TAKEOFF => "NAV_VTOL_TAKEOFF",
        NAV_VTOL_LAND => "NAV_VTOL_LAND",
        NAV_DELAY => "NAV_DELAY",
        CONDITION_DELAY => "CONDITION_DELAY",
        DO_JUMP => "DO_JUMP",
        DO_CHANGE_SPEED => "DO_CHANGE_SPEED",
        DO_GRIPPER => "DO_GRIPPER",
        DO_VTOL_TRANSITION => "DO_VTOL_TRANSITION",
        c => return free_name(c),
    })
}

/// `command 22 (NAV_TAKEOFF)`, or `command 31000` for a command aloft does not know.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CommandName(pub(crate) u32);

impl fmt::Display for CommandName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match name(self.0) {
            Some(n) => write!(f, "command {} {n}", self.0),
            None => write!(f, "command {}", self.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_command_has_one_role_and_the_known_ones_a_name() {
        for c in [16, 17, 18, 19, 20, 21, 22, 31, 82, 93, 112] {
            assert_eq!(role(c), Role::Flown, "{c}");
            assert!(name(c).is_some());
        }
        for c in [177, 178, 211] {
            assert_eq!(role(c), Role::Command, "{c}");
        }
        for c in [84, 85, 3000] {
            assert_eq!(role(c), Role::Vtol, "{c}");
        }
        for c in [
            530, 2000, 2001, 2003, 203, 206, 201, 195, 196, 197, 176, 205,
        ] {
            assert_eq!(role(c), Role::Free, "{c}");
        }
        assert_eq!(role(31000), Role::Unknown);
        assert_eq!(CommandName(22).to_string(), "command 22 NAV_TAKEOFF");
        assert_eq!(CommandName(31000).to_string(), "command 31000");
    }
}
