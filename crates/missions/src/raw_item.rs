//! A mission item as the readers hand it on: what both formats store of it, before it is flown.

use crate::error::Place;

/// One mission item as both formats store it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawItem {
    /// Where it is, for messages (an item of a `.plan`, a row of a `.waypoints` file).
    pub(crate) at: Place,
    /// The operator's item number (MAVLink sequence number; a `.waypoints` INDEX).
    pub(crate) number: u32,
    /// MAV_CMD.
    pub(crate) command: u32,
    /// MAV_FRAME.
    pub(crate) frame: u32,
    /// p1-p4, latitude, longitude, altitude; NaN when not set.
    pub(crate) params: [f64; 7],
    /// A `.plan`'s `doJumpId`.
    pub(crate) jump_id: Option<i64>,
}

impl RawItem {
    /// The item as a MAVLink item (`seq` its number).
    pub(crate) fn mission_item(&self) -> aloft_logs::telemetry::MissionItem {
        aloft_logs::telemetry::MissionItem {
            seq: self.number,
            frame: self.frame,
            command: self.command,
            params: self.params,
        }
    }
}
