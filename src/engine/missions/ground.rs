//! The ground under a mission (`--terrain DIR`): the terrain-frame legs flown over it, and each
//! segment's least height above it along its whole path.
//!
//! The steps, for a mission placed by latitude and longitude:
//! 1. [`Ground::at_home`]: home's ground on the tiles. The vehicle's heights "relative to home"
//!    start where it stands, on that ground; a file's own home altitude (a QGroundControl
//!    `plannedHomePosition`, a `.waypoints` home row) is what its planner assumed, said when it
//!    differs from the tile's by more than [`HOME_DISAGREES_M`], and the items above mean sea
//!    level (frame 0/5: flown to their altitude whatever home is) are placed from the tile's.
//! 2. [`Ground::follow`]: every leg made by a terrain-frame item (MAVLink frame 10/11, the height
//!    above the ground under the vehicle) flown over the ground as ArduPilot flies it: a leg to
//!    each terrain sample where the height changes ([`aloft_missions::follow_terrain`], as
//!    QGroundControl bakes a terrain-following survey, at the tile's spacing), so that the climbs
//!    and descents along the way are flown and cost their energy; a landing lands on the ground
//!    where it is.
//! 3. [`Ground::clearances`]: each segment's least height above the ground along its planned
//!    path (every line of it walked cell by cell over the tile's bilinear ground, exactly, not
//!    only at its ends), and where; the mission's steps (`mission.rs`, `judge_clearances`) judge
//!    them against the least clearance ([`judged`]: every segment in the air but the take-off
//!    and the landing).
//!
//! The tiles' heights are above the EGM96 geoid, which is what autopilots and planners call
//! "above mean sea level" (the GPS's geoid height); the clearance is that height's difference.

use aloft_missions::follow_terrain::{
    follow_ground, FollowLine, FollowPoint, Following, GroundPoint,
};
use aloft_planner::geodesy::LocalFrame;
use aloft_planner::{MissionSpec, SegmentSpec};
use aloft_terrain::{PathPoint, Terrain};
use serde::{Deserialize, Serialize};

use crate::error::Error;

/// The planned home's altitude and the tile's ground under it may differ by this much before it
/// is said, m (the issue's; SRTM's absolute accuracy is 16 m at 90 %).
pub const HOME_DISAGREES_M: f64 = 30.0;

/// A point on the ground, degrees (where a clearance is least, a map's home).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GroundAt {
    /// Latitude, deg.
    pub latitude_deg: f64,
    /// Longitude, deg.
    pub longitude_deg: f64,
}

/// The altitude frame of the item a segment was made from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(in crate::engine) enum Frame {
    /// Above home (frame 3/6, aloft's own missions).
    #[default]
    Relative,
    /// Above mean sea level (frame 0/5).
    Amsl,
    /// Above the ground under the vehicle (frame 10/11).
    Terrain,
}

impl Frame {
    /// The frame of a MAVLink `frame` value.
    pub(in crate::engine) fn of_mavlink(frame: u32) -> Self {
        match frame {
            0 | 5 => Frame::Amsl,
            10 | 11 => Frame::Terrain,
            _ => Frame::Relative,
        }
    }
}

/// A segment's least height above the ground and where it occurs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentClearance {
    /// The least height above the ground along the segment, m.
    pub clearance_m: f64,
    /// Where.
    pub at: GroundAt,
}

/// The ground under one mission: the tiles and home on them.
pub(in crate::engine) struct Ground<'a> {
    terrain: &'a Terrain,
    frame: LocalFrame,
    home: [f64; 2],
    /// Home's ground above mean sea level on the tiles, m.
    home_amsl_m: f64,
    /// How much higher the file's home altitude is than the tile's, m (0 without one): added to
    /// the heights of the items above mean sea level, which the reader placed from the file's.
    file_home_above_m: f64,
    /// What the reader of the ground said (a home that disagrees with the tile).
    pub(in crate::engine) notes: Vec<String>,
}

impl<'a> Ground<'a> {
    /// Home on the tiles.
    ///
    /// # Errors
    /// [`Error::TerrainNeedsPlace`] for a mission placed in metres from home; the tile's errors
    /// (no tile under home, a void there, a bad tile).
    pub(in crate::engine) fn at_home(
        terrain: &'a Terrain,
        spec: &MissionSpec,
    ) -> Result<Self, Error> {
        let (Some(lat), Some(lon)) = (spec.home.latitude_deg, spec.home.longitude_deg) else {
            return Err(Error::TerrainNeedsPlace);
        };
        let tile_m = terrain.height_m(lat, lon)?;
        let mut notes = Vec::new();
        let file_m = spec.home.altitude_amsl_m.filter(|a| a.is_finite());
        if let Some(file_m) = file_m {
            if (file_m - tile_m).abs() > HOME_DISAGREES_M {
                notes.push(format!(
                    "the planned home's altitude ({file_m:.1} m above mean sea level) is {:.1} m \
                     {} the ground under it on the terrain tiles ({tile_m:.1} m): the vehicle's \
                     heights above home are counted from the tile's",
                    (file_m - tile_m).abs(),
                    if file_m > tile_m { "above" } else { "below" }
                ));
            }
        }
        Ok(Self {
            terrain,
            frame: LocalFrame::new(lat, lon),
            home: [lat, lon],
            home_amsl_m: tile_m,
            file_home_above_m: file_m.map_or(0.0, |f| f - tile_m),
            notes,
        })
    }

    /// `spec` with the legs of the segments in [`Frame::Terrain`] (`frames`, by segment number
    /// from 0) flown over the ground, the heights of those in [`Frame::Amsl`] placed from the
    /// tile's home, its landings on the ground where they are, and heights at or below home's
    /// allowed; a return flies at least at `rtl_altitude_m` (the request's, else the file's).
    /// Also: for each segment of `spec`, how many it became.
    ///
    /// # Errors
    /// The tiles' (no tile or a void under the route).
    pub(in crate::engine) fn follow(
        &self,
        spec: &MissionSpec,
        frames: &[Frame],
        rtl_altitude_m: Option<f64>,
    ) -> Result<(MissionSpec, Vec<usize>), Error> {
        let terrain_legs: Vec<bool> = frames.iter().map(|f| *f == Frame::Terrain).collect();
        let mut out = spec.clone();
        out.over_terrain = true;
        // The day's air is taken at home's altitude: the tile's where the file gives none.
        out.home.altitude_amsl_m.get_or_insert(self.home_amsl_m);
        out.segments = Vec::with_capacity(spec.segments.len());
        // For each segment of `spec`, how many it became.
        let mut made = Vec::with_capacity(spec.segments.len());
        let mut walk = Walk::at_home(self);
        walk.rtl_altitude_m = rtl_altitude_m.or(spec.rtl_altitude_m);
        let mut k = 0;
        while k < spec.segments.len() {
            if !terrain_legs.get(k).copied().unwrap_or(false) || !is_leg(&spec.segments[k]) {
                let amsl = frames.get(k) == Some(&Frame::Amsl);
                let mut s = self.on_the_ground(&spec.segments[k], &walk, amsl)?;
                // The descent of a landing (to the height where it slows) is above the ground
                // it lands on.
                if let (
                    SegmentSpec::Descent { altitude_m, .. },
                    Some(SegmentSpec::Landing { .. }),
                ) = (&mut s, spec.segments.get(k + 1))
                {
                    let [lat, lon] = walk.here;
                    *altitude_m += self.terrain.height_m(lat, lon)? - self.home_amsl_m;
                    // A vehicle already at or below it (in the ground: its clearance says so)
                    // descends a centimetre.
                    *altitude_m = altitude_m.min(walk.up_m - 0.01);
                }
                walk.segment(&s, self);
                out.segments.push(s);
                made.push(1);
                k += 1;
                continue;
            }
            // A run of terrain legs, followed together (the thinning runs along it).
            let end = (k..spec.segments.len())
                .find(|&j| {
                    !(terrain_legs.get(j).copied().unwrap_or(false) && is_leg(&spec.segments[j]))
                })
                .unwrap_or(spec.segments.len());
            let legs = &spec.segments[k..end];
            let followed = self.follow_run(legs, &walk)?;
            for sub in followed {
                made.push(sub.len());
                for s in sub {
                    walk.segment(&s, self);
                    out.segments.push(s);
                }
            }
            k = end;
        }
        Ok((out, made))
    }

    /// A segment that is not followed: a landing lands on the ground where it is; a height
    /// above mean sea level (`amsl`) is placed from the tile's home.
    fn on_the_ground(
        &self,
        s: &SegmentSpec,
        walk: &Walk,
        amsl: bool,
    ) -> Result<SegmentSpec, Error> {
        let mut s = s.clone();
        match &mut s {
            SegmentSpec::Landing { ground_m, .. } => {
                let [lat, lon] = walk.here;
                // A vehicle in the ground (its clearance says so) lands where it is.
                let g = self.terrain.height_m(lat, lon)? - self.home_amsl_m;
                *ground_m = Some(g.min(walk.up_m));
            }
            SegmentSpec::Leg { altitude_m, .. }
            | SegmentSpec::Orbit { altitude_m, .. }
            | SegmentSpec::Return { altitude_m, .. }
                if amsl =>
            {
                if let Some(a) = altitude_m {
                    *a += self.file_home_above_m;
                }
            }
            SegmentSpec::TakeOff { altitude_m, .. } | SegmentSpec::Descent { altitude_m, .. }
                if amsl =>
            {
                *altitude_m += self.file_home_above_m;
            }
            _ => {}
        }
        Ok(s)
    }

    /// The legs of one run over the ground: for each leg, the legs to the terrain samples kept
    /// inside it, then the leg itself at its height above the ground at its end.
    fn follow_run(
        &self,
        legs: &[SegmentSpec],
        walk: &Walk,
    ) -> Result<Vec<Vec<SegmentSpec>>, Error> {
        let mut profiles = Vec::with_capacity(legs.len());
        let mut from = walk.here;
        let mut above_m = walk.up_m + self.home_amsl_m - self.terrain.height_m(from[0], from[1])?;
        let mut ends = Vec::with_capacity(legs.len());
        for leg in legs {
            let to = self.point_of(leg).unwrap_or(from);
            let profile = ground_points(self.terrain, (from[0], from[1]), (to[0], to[1]))?;
            let end_above_m = leg_altitude_m(leg).unwrap_or(above_m);
            ends.push((above_m, end_above_m));
            profiles.push(profile);
            above_m = end_above_m;
            from = to;
        }
        let lines: Vec<FollowLine<'_>> = profiles
            .iter()
            .zip(&ends)
            .map(|(p, &(start_above_m, end_above_m))| FollowLine {
                profile: p,
                start_above_m,
                end_above_m,
            })
            .collect();
        let following = Following {
            tolerance_m: 0.0,
            ..Following::default()
        };
        let path = follow_ground(&lines, &following);
        // The path's first point is where the vehicle is; each later point ends a leg: a kept
        // sample inside line `i`, or line `i`'s own end.
        Ok(legs
            .iter()
            .enumerate()
            .map(|(i, leg)| {
                path.iter()
                    .skip(1)
                    .filter(|p| p.line == i)
                    .map(|p| self.leg_to(leg, p))
                    .collect()
            })
            .collect())
    }

    /// `leg` ending at `p` (a kept terrain sample: the leg's speed, no payload change; the
    /// line's end: the leg itself), its height above home.
    fn leg_to(&self, leg: &SegmentSpec, p: &FollowPoint) -> SegmentSpec {
        let mut s = leg.clone();
        if let SegmentSpec::Leg {
            east_m,
            north_m,
            latitude_deg,
            longitude_deg,
            altitude_m,
            payload_after_kg,
            acceptance_radius_m,
            ..
        } = &mut s
        {
            *altitude_m = Some(p.altitude_amsl_m - self.home_amsl_m);
            if p.added {
                *east_m = None;
                *north_m = None;
                *latitude_deg = Some(p.latitude_deg);
                *longitude_deg = Some(p.longitude_deg);
                *payload_after_kg = None;
                *acceptance_radius_m = None;
            }
        }
        s
    }

    /// A leg's waypoint, degrees.
    fn point_of(&self, leg: &SegmentSpec) -> Option<[f64; 2]> {
        let SegmentSpec::Leg {
            east_m,
            north_m,
            latitude_deg,
            longitude_deg,
            ..
        } = leg
        else {
            return None;
        };
        match (latitude_deg, longitude_deg, east_m, north_m) {
            (Some(la), Some(lo), _, _) => Some([*la, *lo]),
            (_, _, Some(e), Some(n)) => Some(self.frame.to_lat_lon_deg(*e, *n)),
            _ => None,
        }
    }

    /// A point of a planned path (east, north, up of `origin_m`, m, as the map draws it) on the
    /// ground's terms: latitude, longitude and altitude above mean sea level (home's ground on
    /// the tiles plus the height above home).
    pub(in crate::engine) fn path_point(&self, p: &[f64; 3], origin_m: [f64; 3]) -> PathPoint {
        let [la, lo] = self
            .frame
            .to_lat_lon_deg(p[0] - origin_m[0], p[1] - origin_m[1]);
        PathPoint {
            latitude_deg: la,
            longitude_deg: lo,
            altitude_amsl_m: self.home_amsl_m + p[2] - origin_m[2],
        }
    }

    /// Each segment's least height above the ground along `paths` (east, north, up of
    /// `origin_m`, segment numbers from 0, as the map draws them), and where.
    ///
    /// # Errors
    /// The tiles' (no tile or a void under the route).
    pub(in crate::engine) fn clearances(
        &self,
        paths: &[(usize, Vec<[f64; 3]>)],
        origin_m: [f64; 3],
        segments: usize,
    ) -> Result<Vec<Option<SegmentClearance>>, Error> {
        let mut out = vec![None; segments];
        for (k, points) in paths {
            let at = |p: &[f64; 3]| self.path_point(p, origin_m);
            let mut least: Option<SegmentClearance> = None;
            for (a, b) in path_lines(points) {
                let c = self.terrain.least_clearance(at(&a), at(&b))?;
                if least.is_none_or(|l| c.clearance_m < l.clearance_m) {
                    least = Some(SegmentClearance {
                        clearance_m: c.clearance_m,
                        at: GroundAt {
                            latitude_deg: c.latitude_deg,
                            longitude_deg: c.longitude_deg,
                        },
                    });
                }
            }
            if let Some(slot) = out.get_mut(*k) {
                *slot = least;
            }
        }
        Ok(out)
    }
}

/// The ground under the straight line from `a` to `b` (latitude, longitude), as the follower
/// of [`aloft_missions::follow_terrain`] takes it.
///
/// # Errors
/// The tiles' (no tile or a void under the line).
pub(in crate::engine) fn ground_points(
    terrain: &Terrain,
    a: (f64, f64),
    b: (f64, f64),
) -> Result<Vec<GroundPoint>, Error> {
    Ok(terrain
        .profile(a, b)?
        .into_iter()
        .map(|g| GroundPoint {
            distance_m: g.distance_m,
            latitude_deg: g.latitude_deg,
            longitude_deg: g.longitude_deg,
            ground_m: g.height_m,
        })
        .collect())
}

/// The straight lines of a segment's path, in order: each pair of its points, or its one point
/// as a line of no length (a hold).
pub(in crate::engine) fn path_lines(
    points: &[[f64; 3]],
) -> impl Iterator<Item = ([f64; 3], [f64; 3])> + '_ {
    let pairs = points.windows(2).map(|w| (w[0], w[1]));
    let single = (points.len() == 1).then(|| (points[0], points[0]));
    pairs.chain(single)
}

/// A leg (not a take-off, orbit or return).
fn is_leg(s: &SegmentSpec) -> bool {
    matches!(s, SegmentSpec::Leg { .. })
}

/// A leg's height.
fn leg_altitude_m(s: &SegmentSpec) -> Option<f64> {
    match s {
        SegmentSpec::Leg { altitude_m, .. } => *altitude_m,
        _ => None,
    }
}

/// Where the vehicle is after each segment: degrees, and height above home.
struct Walk {
    here: [f64; 2],
    up_m: f64,
    /// The mission's lowest return height, m.
    rtl_altitude_m: Option<f64>,
}

impl Walk {
    fn at_home(ground: &Ground<'_>) -> Self {
        Self {
            here: ground.home,
            up_m: 0.0,
            rtl_altitude_m: None,
        }
    }

    /// After `s` (an orbit ends near its centre: the next leg's profile starts there).
    fn segment(&mut self, s: &SegmentSpec, ground: &Ground<'_>) {
        match s {
            SegmentSpec::TakeOff { altitude_m, .. } | SegmentSpec::Descent { altitude_m, .. } => {
                self.up_m = *altitude_m;
            }
            SegmentSpec::Leg { altitude_m, .. } => {
                if let Some(p) = ground.point_of(s) {
                    self.here = p;
                }
                self.up_m = altitude_m.unwrap_or(self.up_m);
            }
            SegmentSpec::Orbit { altitude_m, .. } => {
                if let Some(c) = orbit_centre(s, ground) {
                    self.here = c;
                }
                self.up_m = altitude_m.unwrap_or(self.up_m);
            }
            SegmentSpec::Return { altitude_m, .. } => {
                // As the planner flies it: the segment's height, else at least the RTL altitude.
                self.here = ground.home;
                self.up_m = altitude_m
                    .or(self.rtl_altitude_m.map(|r| r.max(self.up_m)))
                    .unwrap_or(self.up_m);
            }
            SegmentSpec::Landing { ground_m, .. } => self.up_m = ground_m.unwrap_or(0.0),
            _ => {}
        }
    }
}

/// An orbit's centre, degrees.
fn orbit_centre(s: &SegmentSpec, ground: &Ground<'_>) -> Option<[f64; 2]> {
    let SegmentSpec::Orbit {
        centre_east_m,
        centre_north_m,
        centre_latitude_deg,
        centre_longitude_deg,
        ..
    } = s
    else {
        return None;
    };
    match (
        centre_latitude_deg,
        centre_longitude_deg,
        centre_east_m,
        centre_north_m,
    ) {
        (Some(la), Some(lo), _, _) => Some([*la, *lo]),
        (_, _, Some(e), Some(n)) => Some(ground.frame.to_lat_lon_deg(*e, *n)),
        _ => None,
    }
}

/// Whether a segment of `kind` (followed by one of `next`) is judged against the least
/// clearance: every segment in the air but the take-off and the landing, which start or end on
/// the ground, with the descent that begins a landing (to the height where it slows).
pub(in crate::engine) fn judged(kind: &str, next: Option<&str>) -> bool {
    let landing = matches!(kind, "take-off" | "landing");
    let descent_to_land = kind == "descent" && next == Some("landing");
    !(landing || descent_to_land)
}
