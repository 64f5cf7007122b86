//! What the readers keep of a planner file besides its mission spec, so that it can be written
//! again ([`mod@crate::write`]) and a segment traced back to the item that made it.
//!
//! - [`Home`]: the home as the file gives it (`plannedHomePosition`, a `.waypoints` home row);
//! - [`crate::Imported::items`]: the file's mission items in file order, as MAVLink items;
//! - [`PlanFile`]: a `.plan`'s header ([`PlanHeader`]) and the top-level entry each item came
//!   from ([`ItemOrigin`]);
//! - [`FlownItem`]: the flying order (DO_JUMPs unrolled), each item flown with the range of
//!   `spec.segments` it produced.
//!
//! ## The segment ranges
//! The ranges of [`crate::Imported::flown`] follow each other: the first starts at segment 0,
//! each starts where the one before ends, and the last ends at `spec.segments.len()`, so every
//! segment belongs to exactly one item flown, and its `item` is that item's number. Items that
//! fly nothing (camera, speed and jump items, a LAND on the ground) have an empty range. The
//! segments the reader adds itself are in the range of the item that made it add them, and carry
//! its number:
//! - the vertical take-off before a position item flown from the ground without a take-off
//!   before it (warned), and the climb of a NAV_TAKEOFF;
//! - the descent and landing after a RETURN_TO_LAUNCH or LAND, and the return over home;
//! - the leg of no length that carries a DO_GRIPPER release after a take-off, orbit or return;
//! - the loiter until the reserve after a LOITER_UNLIM, where the route ends.
//!
//! The route ends at a RETURN_TO_LAUNCH or LOITER_UNLIM: the items after it are not in
//! [`crate::Imported::flown`] (nor counted as flown).

use std::ops::Range;

/// A home position as the file gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Home {
    /// Latitude, deg (WGS-84).
    pub latitude_deg: f64,
    /// Longitude, deg (WGS-84).
    pub longitude_deg: f64,
    /// Altitude above mean sea level, m; none where the file gives none (a `.plan`'s
    /// `plannedHomePosition` altitude `null`).
    pub altitude_amsl_m: Option<f64>,
}

/// The mission keys of a `.plan` besides its items and home, where the file has them (a key of
/// another type is as absent).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanHeader {
    /// `firmwareType`: MAV_AUTOPILOT (3 ArduPilot, 12 PX4).
    pub firmware_type: Option<u32>,
    /// `vehicleType`: MAV_TYPE of the planner's vehicle (2 quadrotor).
    pub vehicle_type: Option<u32>,
    /// `cruiseSpeed`: the fixed-wing planning speed, m/s.
    pub cruise_speed_mps: Option<f64>,
    /// `hoverSpeed`: the multirotor planning speed, m/s.
    pub hover_speed_mps: Option<f64>,
    /// `globalPlanAltitudeMode`: QGroundControl's altitude mode of new items.
    pub global_plan_altitude_mode: Option<i64>,
}

/// The top-level entry of a `.plan`'s `mission.items` an item came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ItemOrigin {
    /// A SimpleItem: entry `entry` of `mission.items`.
    Simple {
        /// Its index in `mission.items`.
        entry: usize,
    },
    /// One of the stored items of a survey complex item.
    Survey {
        /// The complex item's index in `mission.items`.
        entry: usize,
        /// The survey's index in [`crate::Imported::surveys`].
        survey: usize,
    },
    /// One of the stored items of a corridor scan complex item.
    CorridorScan {
        /// The complex item's index in `mission.items`.
        entry: usize,
    },
}

/// A `.plan`'s header and where each of its items came from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlanFile {
    /// The mission keys.
    pub header: PlanHeader,
    /// For each of [`crate::Imported::items`], its entry.
    pub origins: Vec<ItemOrigin>,
    /// Its geofence and rally points.
    pub airspace: crate::Airspace,
}

/// One item as it is flown: its index in [`crate::Imported::items`] and the segments it made.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FlownItem {
    /// Index in [`crate::Imported::items`] (not the item's number: see its `seq`).
    pub item: usize,
    /// The range of `spec.segments` it produced (empty for an item that flies nothing).
    pub segments: Range<usize>,
}
