//! A QGroundControl survey regenerated as QGroundControl draws it: its description read from a
//! `.plan` complex item, its transects, the mission items QGroundControl uploads for them, and
//! the complex item's JSON written back with a new grid angle.
//!
//! Sans-I/O like the rest of the crate: JSON values and numbers in, values out.
//!
//! ## The description
//! [`SurveyParams`] is what a `survey` complex item (versions 4 and 5) says: the polygon, the
//! grid angle, the entry corner, the turnaround distance, the camera options and, from
//! `CameraCalc`, the altitude, its mode, the line spacing (`AdjustedFootprintSide`) and the
//! trigger distance (`AdjustedFootprintFrontal`). [`Survey::new`] validates it (a survey that
//! exists can be regenerated); [`Survey::from_complex_item`] reads it from the JSON, naming the
//! item and the key of anything refused. The `.plan` reader keeps it for each survey in
//! [`crate::Imported::surveys`] (it still flies the items stored in the file).
//!
//! ## The algorithm, step by step (QGroundControl, `src/MissionManager`)
//! 1. Project the polygon onto a plane tangent at its **first vertex** (x east, y north, m):
//!    `SurveyComplexItem.cc` `_rebuildTransectsPhase1WorkerSinglePolygon` with
//!    `QGCGeo.cc` `convertGeoToNed` (see [`QgcProjection`]: the projection changed twice).
//! 2. The grid angle is brought into [-90, 90] by one step of 180 deg (`_clampGridAngle90`); the
//!    refly pass adds 90.
//! 3. The polygon's bounding box; lines of constant x every `spacing_m`, from
//!    `centre.x - W/2` while below `centre.x + W/2`, `W = max(width, height) + 2000 m`, each from
//!    `centre.y - W/2` to `centre.y + W/2`; each end rotated about the box centre by the angle
//!    clockwise (0 deg: north-south lines, 90 deg: east-west). The lines' phase comes from the
//!    box centre: there is no half-spacing inset.
//! 4. Each line against every polygon edge (bounded intersections, the closing edge included);
//!    with two or more hits, the two **farthest apart** are the transect
//!    (`_intersectLinesWithPolygon`). Fewer than two transects: one line through the box centre.
//! 5. Orientation: a transect whose direction differs from the first's by more than 1 deg is
//!    turned round (`_adjustLineDirection`); back to latitude/longitude.
//! 6. Entry corner (`_adjustTransectsToEntryPointLocation`): bottom corners reverse the points of
//!    each transect, right corners the order of the transects. The refly pass then starts from
//!    the end nearest the first pass's last point (`_optimizeTransectsForShortestDistance`).
//! 7. Alternate transects when asked (even lines out, odd lines back), then the lawnmower:
//!    every second transect reversed.
//! 8. Per transect: entry and exit; with hover-and-capture a point every trigger distance in
//!    between; with a turnaround distance, a point that far before the entry and after the exit
//!    along the transect (`QGeoCoordinate::atDistanceAndAzimuth`, a sphere of 6371.0072 km).
//! 9. The items (`TransectStyleComplexItem.cc` `_buildAndAppendMissionItems`): every point a
//!    NAV_WAYPOINT (16) at `DistanceToSurface` in the frame of `DistanceMode` (1: 3, 2: 0, 4: 10),
//!    p1 hold (4 s with hover-and-capture), p4 yaw not set. Camera with images in turnarounds: the
//!    first turnaround and every entry followed by DO_SET_CAM_TRIGG_DIST (206, p1 the distance,
//!    p3 1: one shot now), the last turnaround by 206 with 0; without images in turnarounds,
//!    entry 206(distance) and exit 206(0) on each transect; hover-and-capture: each photo point
//!    held 4 s and followed by IMAGE_START_CAPTURE (2000, one photo). Item numbers (`doJumpId`)
//!    follow from the survey's first item.
//! 10. `CameraShots` as QGroundControl recomputes it after a rebuild (`_recalcCameraShots`).
//!
//! ## Frame and units
//! Positions are WGS-84 latitude/longitude in degrees; the plane of the algorithm is the one
//! of [`QgcProjection`], x east and y north in metres; angles in degrees as in the file (the grid
//! angle is an azimuth from north, clockwise); distances in metres; heights as the file's
//! `DistanceMode` says.
//!
//! ## Where it departs from QGroundControl, and why
//! - Concave polygons: none. The farthest pair of hits bridges a notch exactly as QGroundControl
//!   does (the transect flies and photographs outside the area); polygon splitting is compiled
//!   out of QGroundControl, and `splitConcavePolygons` is written `false`.
//! - A line spacing below 0.5 m is refused, not replaced: QGroundControl replaces it by
//!   100 km (a single transect), below 0.5 m until 2025-09 and below 0.3 m since, so a spacing
//!   there means different surveys to different versions, none of which is the operator's.
//! - `DistanceMode` 3 (altitudes computed above terrain) is read, and its transects drawn, but
//!   its items are refused: QGroundControl computes their altitudes from terrain tiles.
//! - `MAV_CMD_CONDITION_GATE` (QGroundControl's plan setting, off by default) is not written.
//! - The cosine of the angle from the tangent point is kept within [-1, 1] before its arc
//!   cosine, where QGroundControl would give NaN for a vertex a few nanometres from the first.
//! - Only the multirotor pattern: fixed-wing turn segments are not modelled (aloft flies
//!   multirotors); alternate transects are supported as QGroundControl reads them.

mod coverage;
mod json;
mod projection;
mod transects;
mod write;

#[cfg(test)]
mod tests;

use crate::error::{ImportError, Place};
use crate::geo::LatLon;

pub use coverage::{
    candidate_angles, wind_bearing_deg, ANGLE_STEP_DEG, COVERAGE_GRID_M, COVERAGE_TOLERANCE_M,
};
pub use projection::QgcProjection;
pub(crate) use write::number_json;
pub use write::reangle_survey_item;

/// Smallest line spacing regenerated, m (see the module's deviations).
pub const MIN_SPACING_M: f64 = 0.5;

/// Largest distance of a vertex from the first, m: the survey of one multirotor, in one tangent
/// plane; it also bounds the number of grid lines (at most 104 000 at the smallest spacing).
pub const MAX_EXTENT_M: f64 = 50_000.0;

/// Smallest polygon area, m^2: below it (collinear or repeated vertices) there is nothing to
/// survey at any spacing aloft regenerates.
pub const MIN_AREA_M2: f64 = 1.0;

/// QGroundControl's hover time at each photo point with hover-and-capture, s
/// (`_hoverAndCaptureDelaySeconds`).
pub const HOVER_AND_CAPTURE_S: f64 = 4.0;

/// Where the first transect starts (`entryLocation`; QGroundControl's names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EntryCorner {
    /// 0: the lines in their generated order and direction.
    #[default]
    TopLeft,
    /// 1: the order of the lines reversed.
    TopRight,
    /// 2: the points of each line reversed.
    BottomLeft,
    /// 3: both.
    BottomRight,
}

impl EntryCorner {
    /// The corner of `entryLocation` 0-3.
    pub fn from_index(index: u64) -> Option<Self> {
        [
            Self::TopLeft,
            Self::TopRight,
            Self::BottomLeft,
            Self::BottomRight,
        ]
        .get(usize::try_from(index).ok()?)
        .copied()
    }

    /// Whether the points of each transect are reversed (bottom corners).
    fn reverses_points(self) -> bool {
        matches!(self, Self::BottomLeft | Self::BottomRight)
    }

    /// Whether the order of the transects is reversed (right corners).
    fn reverses_order(self) -> bool {
        matches!(self, Self::TopRight | Self::BottomRight)
    }
}

/// What the survey's altitude is relative to (`CameraCalc.DistanceMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DistanceMode {
    /// 1: above home; items in frame 3 (GLOBAL_RELATIVE_ALT).
    #[default]
    Relative,
    /// 2: above mean sea level; items in frame 0 (GLOBAL).
    Amsl,
    /// 3: above terrain, each item's AMSL altitude computed by QGroundControl from terrain tiles
    /// (frame 0); its items cannot be regenerated here.
    CalcAboveTerrain,
    /// 4: above terrain in the vehicle (frame 10, GLOBAL_TERRAIN_ALT).
    TerrainFrame,
}

impl DistanceMode {
    /// The mode of `DistanceMode` 1-4.
    pub fn from_index(index: u64) -> Option<Self> {
        match index {
            1 => Some(Self::Relative),
            2 => Some(Self::Amsl),
            3 => Some(Self::CalcAboveTerrain),
            4 => Some(Self::TerrainFrame),
            _ => None,
        }
    }

    /// The MAV_FRAME of the survey's items.
    pub fn frame(self) -> u32 {
        match self {
            Self::Relative => 3,
            Self::Amsl | Self::CalcAboveTerrain => 0,
            Self::TerrainFrame => 10,
        }
    }
}

/// A survey as its `.plan` complex item describes it (unvalidated; see [`Survey::new`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SurveyParams {
    /// The MAVLink sequence number of the survey's first item (home 0, the first item 1): its
    /// items are numbered from it, and errors name it.
    pub first_item: u32,
    /// The survey area (`polygon`), not closed; the first vertex is the tangent point.
    pub polygon: Vec<LatLon>,
    /// Grid angle (`angle`): the transects' azimuth from north, clockwise, deg, in [-360, 360].
    pub angle_deg: f64,
    /// Entry corner (`entryLocation`).
    pub entry: EntryCorner,
    /// Fly every second transect out and the others back (`flyAlternateTransects`).
    pub fly_alternate_transects: bool,
    /// Extension before and after each transect (`TurnAroundDistance`), m; 0: none.
    pub turnaround_m: f64,
    /// Keep the camera triggering through the turnarounds (`CameraTriggerInTurnAround`).
    pub camera_in_turnaround: bool,
    /// Stop, hover and take each photo (`HoverAndCapture`).
    pub hover_and_capture: bool,
    /// Fly the grid again at the angle plus 90 deg (`Refly90Degrees`).
    pub refly_90: bool,
    /// Altitude of the items (`CameraCalc.DistanceToSurface`), m in `altitude_mode`.
    pub altitude_m: f64,
    /// What the altitude is relative to (`CameraCalc.DistanceMode`).
    pub altitude_mode: DistanceMode,
    /// Distance between transects (`CameraCalc.AdjustedFootprintSide`), m.
    pub spacing_m: f64,
    /// Distance between photos (`CameraCalc.AdjustedFootprintFrontal`), m; 0: no camera.
    pub trigger_distance_m: f64,
    /// The camera's shortest time between photos (`CameraCalc.MinTriggerInterval`), s, when the
    /// item names a camera.
    pub min_trigger_interval_s: Option<f64>,
}

/// A validated survey description: every one can be regenerated.
#[derive(Debug, Clone, PartialEq)]
pub struct Survey {
    params: SurveyParams,
}

/// The role of a point of a transect (QGroundControl's `CoordType`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointKind {
    /// The extension before the entry or after the exit.
    Turnaround,
    /// Where the transect enters the polygon.
    Entry,
    /// A photo point between entry and exit (hover-and-capture).
    HoverTrigger,
    /// Where the transect leaves the polygon.
    Exit,
}

/// One point of a transect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransectPoint {
    /// Where, deg.
    pub position: LatLon,
    /// Its role.
    pub kind: PointKind,
}

/// One transect in flying order: `[turnaround,] entry, [hover points,] exit[, turnaround]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Transect {
    /// Its points.
    pub points: Vec<TransectPoint>,
}

/// A survey regenerated: what QGroundControl stores in `TransectStyleComplexItem`.
#[derive(Debug, Clone, PartialEq)]
pub struct Regenerated {
    /// The transects of the first pass, then those of the refly pass.
    pub transects: Vec<Transect>,
    /// Every point of the transects in order (`VisualTransectPoints`).
    pub visual_points: Vec<LatLon>,
    /// The mission items as `.plan` SimpleItems (`Items`), numbered from the first item.
    pub items: Vec<serde_json::Value>,
    /// QGroundControl's photo count estimate (`CameraShots`).
    pub camera_shots: u64,
}

impl Survey {
    /// Validate a description.
    ///
    /// # Errors
    /// [`ImportError::BadKey`] naming the survey's first item and the `.plan` key: a polygon of
    /// fewer than 3 distinct vertices, of less than [`MIN_AREA_M2`], beyond [`MAX_EXTENT_M`] or
    /// with a coordinate that is not finite or out of range (latitude within (-90, 90)); an
    /// angle that is not finite or beyond [-360, 360]; a spacing that is not finite or below
    /// [`MIN_SPACING_M`]; a turnaround, trigger distance or trigger interval that is negative
    /// or not finite; an altitude that is not finite.
    pub fn new(params: SurveyParams) -> Result<Self, ImportError> {
        let at = Place::Item(params.first_item);
        check_numbers(&params, at)?;
        check_polygon(&params.polygon, at)?;
        Ok(Self { params })
    }

    /// The description.
    pub fn params(&self) -> &SurveyParams {
        &self.params
    }

    /// The same survey at another grid angle, deg.
    ///
    /// # Errors
    /// As [`Survey::new`] for the angle.
    pub fn with_angle(&self, angle_deg: f64) -> Result<Self, ImportError> {
        Self::new(SurveyParams {
            angle_deg,
            ..self.params.clone()
        })
    }

    /// The transects as QGroundControl draws them with `projection` (steps 1-8 of the module's
    /// docs). Empty only when not even the line through the box centre crosses the polygon
    /// twice (a self-touching polygon can do that; [`Survey::regenerate`] refuses it).
    pub fn transects(&self, projection: QgcProjection) -> Vec<Transect> {
        transects::all(&self.params, projection)
    }

    /// The transects, the items and the photo count (steps 1-10).
    ///
    /// # Errors
    /// [`ImportError::Refused`] for `DistanceMode` 3 (altitudes from terrain tiles), and when no
    /// transect crosses the polygon.
    pub fn regenerate(&self, projection: QgcProjection) -> Result<Regenerated, ImportError> {
        write::regenerate(self, projection)
    }
}

/// A `.plan` survey as the reader found it.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedSurvey {
    /// The sequence number of its first item (as in the reader's segments and warnings).
    pub first_item: u32,
    /// How many items it stores (`TransectStyleComplexItem.Items`).
    pub item_count: usize,
    /// Its description, or why it cannot be regenerated (the reader flies the stored items
    /// either way).
    pub survey: Result<Survey, ImportError>,
    /// The complex item as the file holds it: what [`reangle_survey_item`] takes, and what
    /// [`crate::write_like_source`] writes back verbatim.
    pub complex_item: serde_json::Value,
}

/// A refused value of the description, as [`ImportError::BadKey`].
fn bad(at: Place, key: &str, found: impl ToString, expected: &'static str) -> ImportError {
    ImportError::BadKey {
        at,
        command: None,
        key: key.to_string(),
        found: found.to_string(),
        expected,
    }
}

/// The numbers of the description: finite and in range.
fn check_numbers(p: &SurveyParams, at: Place) -> Result<(), ImportError> {
    use aloft_core::Num;
    let checks: [(&str, f64, bool, &'static str); 5] = [
        ("angle", p.angle_deg, p.angle_deg.abs() <= 360.0, "a grid angle in degrees within [-360, 360]"),
        (
            "TransectStyleComplexItem.CameraCalc.AdjustedFootprintSide",
            p.spacing_m,
            p.spacing_m >= MIN_SPACING_M,
            "a line spacing of at least 0.5 m (QGroundControl replaces a smaller one by 100 km: a single transect)",
        ),
        ("TransectStyleComplexItem.TurnAroundDistance", p.turnaround_m, p.turnaround_m >= 0.0, "a distance in m, 0 or more"),
        (
            "TransectStyleComplexItem.CameraCalc.AdjustedFootprintFrontal",
            p.trigger_distance_m,
            p.trigger_distance_m >= 0.0,
            "a trigger distance in m, 0 (no camera) or more",
        ),
        ("TransectStyleComplexItem.CameraCalc.DistanceToSurface", p.altitude_m, p.altitude_m.abs() <= 1e6, "an altitude in m within 1e6"),
    ];
    for (key, value, ok, expected) in checks {
        if !(value.is_finite() && ok) {
            return Err(bad(at, key, Num(value), expected));
        }
    }
    match p.min_trigger_interval_s {
        Some(s) if !(s.is_finite() && s >= 0.0) => Err(bad(
            at,
            "TransectStyleComplexItem.CameraCalc.MinTriggerInterval",
            Num(s),
            "a time in s, 0 or more",
        )),
        _ => Ok(()),
    }
}

/// The polygon: coordinates in range, 3 distinct vertices, an area, within the extent.
fn check_polygon(polygon: &[LatLon], at: Place) -> Result<(), ImportError> {
    for (k, v) in polygon.iter().enumerate() {
        let ok = v.latitude_deg.abs() < 90.0 && v.longitude_deg.abs() <= 180.0;
        if !ok {
            let found = format!("[{}, {}]", v.latitude_deg, v.longitude_deg);
            let key = format!("polygon[{k}]");
            return Err(bad(
                at,
                &key,
                found,
                "[latitude within (-90, 90), longitude within [-180, 180]] in degrees",
            ));
        }
    }
    let mut distinct: Vec<LatLon> = Vec::new();
    for v in polygon {
        if !distinct.contains(v) {
            distinct.push(*v);
        }
    }
    if distinct.len() < 3 {
        let found = format!("{} distinct vertices", distinct.len());
        return Err(bad(at, "polygon", found, "at least 3 distinct vertices"));
    }
    let plane = projection::to_plane(polygon, QgcProjection::SphereMean);
    let extent_m = plane.iter().map(|p| p.x.hypot(p.y)).fold(0.0, f64::max);
    if extent_m > MAX_EXTENT_M {
        let found = format!("a vertex {} m from the first", extent_m.round());
        return Err(bad(
            at,
            "polygon",
            found,
            "every vertex within 50 km of the first",
        ));
    }
    let area_m2 = projection::area_m2(&plane);
    if area_m2 < MIN_AREA_M2 {
        let found = format!("an area of {} m^2", aloft_core::Num(area_m2));
        return Err(bad(
            at,
            "polygon",
            found,
            "a polygon enclosing at least 1 m^2",
        ));
    }
    Ok(())
}
