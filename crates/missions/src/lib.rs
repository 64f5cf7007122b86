//! # aloft-missions: the missions operators already have
//!
//! Reads QGroundControl `.plan` files and Mission Planner / ArduPilot `.waypoints` files
//! ("QGC WPL 110") into the same [`MissionSpec`] that aloft's own TOML and JSON missions produce,
//! computes the planned [`RouteFigures`] of any mission spec, and writes both formats ([`mod@write`]).
//!
//! Sans-I/O: every function takes the text (or bytes) handed to it and returns data or an
//! [`ImportError`]; opening files is the caller's job, so the readers can be fuzzed and embedded.
//!
//! - `detect.rs`: [`detect`], which format a text is, from its content (not its file name);
//! - `plan.rs`: [`read_plan`], the `.plan` reader (JSON; `fileType` "Plan", mission version 2,
//!   SimpleItems in the V1, V2 and V3 item layouts, surveys and corridor scans flattened);
//! - `wpl.rs`: [`read_waypoints`], the `.waypoints` reader (12 tab-separated fields, home row);
//! - `raw_item.rs`: a mission item as both readers hand it on;
//! - `items.rs`: the MAVLink command semantics both readers share (its docs hold the table of
//!   what aloft flies for each command), `jumps.rs` the DO_JUMP unrolling;
//! - `route.rs`: [`route_figures`], the planned horizontal path, climb, descent and holds of a
//!   mission spec, whatever its source;
//! - `geo.rs`: per-leg distances on the WGS-84 ellipsoid;
//! - [`follow_terrain`]: a path that keeps its height over the ground, as QGroundControl bakes a
//!   terrain-following survey (on ground profiles the caller reads);
//! - [`survey`]: a QGroundControl survey's description, and its transects and items regenerated
//!   exactly as QGroundControl draws them (also at a new grid angle, for a writer);
//! - [`kept`]: what the readers keep besides the spec ([`Imported::home`], [`Imported::items`],
//!   [`Imported::plan`], [`Imported::flown`]): enough to write the file again, and to go from a
//!   segment back to its item;
//! - [`mod@write`]: the writers, [`write_plan`] (`.plan`), [`write_waypoints`] (`.waypoints`) and
//!   [`write_like_source`]; text out, read back by aloft and by MAVSDK and pymavlink in the tests.
//!
//! ## Frame and units
//! Positions are WGS-84 latitude/longitude in degrees (as the files hold them); heights are
//! metres above the home point (the launch point), as in the mission spec. SI units elsewhere,
//! with the unit in every name.
//!
//! ## Item numbers
//! Every segment made from an item carries the item's number (`item`): in a `.plan` the MAVLink
//! mission sequence number that QGroundControl shows and uploads (home is 0, the first item 1,
//! the items of a survey numbered in sequence); in a `.waypoints` file the INDEX column.
//!
//! ```
//! let text = "QGC WPL 110\n\
//!     0\t1\t0\t16\t0\t0\t0\t0\t-35.3632\t149.1652\t584\t1\n\
//!     1\t0\t3\t22\t0\t0\t0\t0\t0\t0\t20\t1\n\
//!     2\t0\t3\t16\t0\t0\t0\t0\t-35.3622\t149.1652\t20\t1\n\
//!     3\t0\t3\t20\t0\t0\t0\t0\t0\t0\t0\t1\n";
//! let imported = aloft_missions::import(text)?;
//! assert_eq!(imported.format, aloft_missions::SourceFormat::QgcWpl);
//! assert!((imported.route.horizontal_m - 2.0 * 111.0).abs() < 1.0);
//! assert_eq!(imported.route.climb_m, 20.0);
//! # Ok::<(), aloft_missions::ImportError>(())
//! ```

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

mod commands;
mod detect;
mod error;
mod fence;
pub mod follow_terrain;
mod geo;
mod items;
mod jumps;
pub mod kept;
mod notes;
mod plan;
mod plane;
mod raw_item;
mod route;
pub mod survey;
mod wpl;
pub mod write;

use serde::{Deserialize, Serialize};

pub use aloft_logs::telemetry::MissionItem;
pub use aloft_planner::{HomeSpec, MissionSpec, SegmentSpec};
pub use detect::detect;
pub use error::{ImportError, Place};
pub use fence::{Airspace, Breach, FenceCircle, FencePolygon, LocalFence, RallyPoint};
pub use geo::{distance_m, great_circle_m, LatLon, MEAN_RADIUS_M};
pub use items::{ReadOptions, MIN_HEIGHT_M};
pub use jumps::MAX_REPEATED_ITEMS;
pub use kept::{FlownItem, Home, ItemOrigin, PlanFile, PlanHeader};
pub use plan::{read_plan, read_plan_with};
pub use route::{route_figures, RouteFigures};
pub use wpl::{read_items, read_items_with, read_waypoints, read_waypoints_with};
pub use write::{
    plan_entries, write_like_source, write_plan, write_waypoint_rows, write_waypoints, MissionEntry,
};

/// The format a mission text is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceFormat {
    /// QGroundControl `.plan` (JSON with a `fileType` key).
    QgcPlan,
    /// Mission Planner / ArduPilot `.waypoints` ("QGC WPL 110").
    QgcWpl,
    /// aloft's own mission file in TOML.
    #[default]
    AloftToml,
    /// aloft's own mission file in JSON.
    AloftJson,
    /// Mission items as a MAVLink link or log carries them ([`read_items`]).
    MavlinkItems,
}

impl SourceFormat {
    /// The name in the JSON answer (`qgc_plan`, `qgc_wpl`, `aloft_toml`, `aloft_json`).
    pub fn as_str(self) -> &'static str {
        match self {
            SourceFormat::QgcPlan => "qgc_plan",
            SourceFormat::QgcWpl => "qgc_wpl",
            SourceFormat::MavlinkItems => "mavlink_items",
            SourceFormat::AloftToml => "aloft_toml",
            SourceFormat::AloftJson => "aloft_json",
        }
    }
}

/// The items of a planner file by what they do (each item once, as written: a jump repeated is
/// counted once). `total` is the sum of the others.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ItemCounts {
    /// Mission items read (home excluded; a survey's items one by one).
    pub total: usize,
    /// Items that move, climb, land or hold the vehicle (they become segments).
    pub flown: usize,
    /// DO_CHANGE_SPEED, DO_JUMP and DO_GRIPPER: change how the rest is flown.
    pub commands: usize,
    /// Camera, gimbal, region-of-interest, mode, servo and fence items: cost nothing.
    pub free: usize,
    /// Commands aloft does not know (each named in a warning).
    pub unknown: usize,
    /// Items never reached (after a RETURN_TO_LAUNCH or LOITER_UNLIM, or jumped over).
    pub unreachable: usize,
}

/// A planner file read: the mission spec, its route figures and what the reader noticed.
#[derive(Debug, Clone, PartialEq)]
pub struct Imported {
    /// The mission, ready for the planner (`clamp_speeds` and `allow_end_in_air` set, the
    /// planning speed in `default_speed_mps`).
    pub spec: MissionSpec,
    /// The planned route's figures (with the warnings and the item counts).
    pub route: RouteFigures,
    /// The file's format.
    pub format: SourceFormat,
    /// What the reader adjusted or could not model, one line each naming the items.
    pub warnings: Vec<String>,
    /// The items by role.
    pub counted: ItemCounts,
    /// The surveys of a `.plan`, in file order, each with its description or why it cannot be
    /// regenerated ([`survey`]); empty for other formats. The segments fly the items stored in
    /// the file either way.
    pub surveys: Vec<survey::ImportedSurvey>,
    /// The home as the file gives it (`plannedHomePosition`, the `.waypoints` home row, a
    /// link's item 0 when it is a home row), where it has one; `spec.home` is where aloft puts
    /// home (the first position of a file without a usable home row).
    pub home: Option<Home>,
    /// The file's mission items in file order (home excluded), as a `.waypoints` row or a
    /// MAVLink item holds them: `seq` is the item's number (the `item` of its segments), NaN a
    /// parameter not set. A `.plan`'s surveys and corridor scans are flattened, their stored
    /// items numbered in sequence; a DO_JUMP's p1 is the target as the file names it (a
    /// `doJumpId` in a `.plan`, a row INDEX in a `.waypoints` file).
    pub items: Vec<MissionItem>,
    /// A `.plan`'s header and the entry each item came from; none for other formats.
    pub plan: Option<PlanFile>,
    /// The items in flying order (DO_JUMPs unrolled, up to where the route ends), each with the
    /// range of `spec.segments` it produced: the ranges follow each other and cover every
    /// segment ([`kept`] lists the segments the reader adds, and to which item).
    pub flown: Vec<FlownItem>,
}

impl Imported {
    /// The item flown that produced segment `segment` of `spec.segments` (its entry of
    /// [`Imported::flown`]: the item's index in [`Imported::items`] and its range), none past
    /// the last segment. A repeated item (in a DO_JUMP loop) is found at the pass that made the
    /// segment.
    pub fn flown_item(&self, segment: usize) -> Option<&FlownItem> {
        let k = self.flown.partition_point(|f| f.segments.end <= segment);
        self.flown.get(k).filter(|f| f.segments.contains(&segment))
    }
}

/// Read a planner file (`.plan` or `.waypoints`) recognised from its content.
///
/// # Errors
/// [`ImportError::UnknownFormat`] for anything else (aloft's own TOML or JSON included), and the
/// readers' errors.
pub fn import(text: &str) -> Result<Imported, ImportError> {
    import_with(text, ReadOptions::default())
}

/// [`import`] with `options`.
///
/// # Errors
/// As [`import`].
pub fn import_with(text: &str, options: ReadOptions) -> Result<Imported, ImportError> {
    match detect(text) {
        SourceFormat::QgcPlan => read_plan_with(text, options),
        SourceFormat::QgcWpl => read_waypoints_with(text, options),
        SourceFormat::AloftToml | SourceFormat::AloftJson | SourceFormat::MavlinkItems => {
            Err(ImportError::UnknownFormat)
        }
    }
}

/// [`import`] of bytes, which must be UTF-8.
///
/// # Errors
/// [`ImportError::NotText`] naming the first invalid byte, and as [`import`].
pub fn import_bytes(bytes: &[u8]) -> Result<Imported, ImportError> {
    let text = std::str::from_utf8(bytes).map_err(|e| ImportError::NotText {
        offset: e.valid_up_to(),
    })?;
    import(text)
}

/// The spec, route and warnings of a translation of `items`; `home` as the file gives it.
fn assemble(
    translation: items::Translation,
    source: &items::Source,
    (items, home): (&[raw_item::RawItem], Option<Home>),
    format: SourceFormat,
    description: String,
) -> Imported {
    let spec = MissionSpec {
        description,
        home: HomeSpec {
            latitude_deg: Some(source.home.latitude_deg),
            longitude_deg: Some(source.home.longitude_deg),
            altitude_amsl_m: source.home_amsl_m,
            ..HomeSpec::default()
        },
        default_speed_mps: Some(source.default_speed_mps),
        clamp_speeds: true,
        allow_end_in_air: true,
        segments: translation.segments,
        ..MissionSpec::default()
    };
    let mut route = route_figures(&spec, format, translation.notes);
    route.items = Some(translation.counts);
    Imported {
        warnings: route.warnings.clone(),
        spec,
        route,
        format,
        counted: translation.counts,
        surveys: Vec::new(),
        home,
        items: items.iter().map(raw_item::RawItem::mission_item).collect(),
        plan: None,
        flown: translation.flown,
    }
}

#[cfg(test)]
mod proptests {
    use proptest::prelude::*;

    use super::*;

    /// A command from those with meaning and a few without.
    fn command() -> impl Strategy<Value = u32> {
        prop::sample::select(vec![
            16, 17, 18, 19, 20, 21, 22, 31, 82, 93, 112, 177, 178, 211, 530, 206, 84, 9999,
        ])
    }

    /// A parameter: ordinary, zero, or extreme.
    fn value() -> impl Strategy<Value = f64> {
        prop_oneof![
            -200.0..200.0f64,
            Just(0.0),
            Just(-1.0),
            Just(-2.0),
            Just(1e300),
            Just(-1e-300),
        ]
    }

    proptest! {
        /// Any `.waypoints` rows: an answer or an error, never a panic; the figures of an
        /// answer are finite and not negative.
        #[test]
        fn waypoints_of_any_values_never_panic_and_give_finite_figures(
            rows in prop::collection::vec(
                (0u32..12, prop::sample::select(vec![0u32, 2, 3, 5, 6, 10, 1]), command(),
                 prop::array::uniform7(value())),
                0..12,
            )
        ) {
            let mut t = String::from("QGC WPL 110\n0\t1\t0\t16\t0\t0\t0\t0\t47.0\t8.0\t400\t1\n");
            for (k, (index, frame, cmd, p)) in rows.iter().enumerate() {
                let index = if k % 3 == 0 { *index } else { k as u32 + 1 };
                t += &format!(
                    "{index}\t0\t{frame}\t{cmd}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t1\n",
                    p[0], p[1], p[2], p[3], p[4], p[5], p[6]
                );
            }
            if let Ok(i) = import(&t) {
                let r = &i.route;
                for v in [r.horizontal_m, r.climb_m, r.descent_m, r.hold_s] {
                    prop_assert!(v.is_finite() && v >= 0.0, "{r:?}");
                }
                prop_assert!(!i.spec.segments.is_empty());
            }
        }

        /// Any bytes: never a panic.
        #[test]
        fn any_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
            let _ = import_bytes(&bytes);
            let mut plan = b"{\"fileType\":\"Plan\",\"mission\":".to_vec();
            plan.extend(&bytes);
            let _ = import_bytes(&plan);
        }
    }
}
