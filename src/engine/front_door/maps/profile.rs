//! The route over the ground as the page's profile chart draws it (`aloft serve --terrain DIR`):
//! along the planned path the map draws ([`segment_paths`]), the vehicle's altitude above mean
//! sea level and the ground under it, against the horizontal distance flown from home, with the
//! least clearance of the answer marked.
//!
//! The steps:
//! 1. [`route_profile`]: the tiles of the request's options (none: no profile), home on them
//!    ([`Ground::at_home`]).
//! 2. [`walk_route`]: every straight line of every segment's path (an arc's 36 chords, a hold's
//!    point), the ground under it from [`Terrain::profile`] (samples at the tile's spacing, both
//!    ends included, so the chart shows the ground between waypoints), the altitude linear along
//!    the line between its ends (as the clearance is judged: [`Ground::clearances`]), the
//!    distance the line's horizontal length in east-north metres. On the segment of the answer's
//!    least clearance, each line's least ([`Terrain::least_clearance`]) and where.
//! 3. [`decimate`]: at most [`PROFILE_POINTS`] points, so that a long survey's chart stays light
//!    (a 310 km survey over a 3 arc-second tile: 4,409 points, 2,616 kept).
//! 4. The least's own place put into the series (the chart's lines pass through it).

use serde::Serialize;

use aloft_terrain::Terrain;

use crate::engine::missions::ground::{judged, path_lines, Ground};
use crate::engine::missions::mission::Plan;
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_outputs::segment_paths;
use crate::error::Error;

/// Most points of a profile. A longer one is thinned in buckets of consecutive points, each
/// keeping its point closest to the ground, its highest ground and its lowest (see
/// [`TerrainProfile`]).
pub const PROFILE_POINTS: usize = 4_000;

/// Two points this close (horizontal distance and altitude, m) are one (the end of a line and
/// the start of the next; a segment's path starts where the one before ended).
const SAME_POINT_M: f64 = 1e-6;

/// The route over the ground along the planned path: one point per index of its three series,
/// which have equal lengths (at most [`PROFILE_POINTS`]). Distances never decrease; a vertical
/// part of the route (a take-off, a landing) is two points at one distance.
///
/// The ground is sampled along each straight line of the path at the tile's spacing (both ends
/// included). A profile longer than [`PROFILE_POINTS`] keeps its first and last points and, in
/// each of `(PROFILE_POINTS - 3) / 3` buckets of consecutive points between them, the point of
/// least height above the ground, the point of highest ground and the point of lowest ground: a
/// ridge, a valley and a close pass are never thinned away. The least clearance's own place is
/// then added (one more point at most).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TerrainProfile {
    /// Horizontal distance flown from home along the path, m.
    pub distance_m: Vec<f64>,
    /// The vehicle's altitude above mean sea level (home's ground on the tiles plus its height
    /// above home), m.
    pub altitude_m: Vec<f64>,
    /// The ground's height above mean sea level under it, m.
    pub ground_m: Vec<f64>,
    /// The answer's least clearance (the summary's `min_clearance_m`, over the segments judged)
    /// and where along the profile; absent when no segment is judged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub least: Option<ProfileLeast>,
}

/// The least clearance of a mission, placed on its profile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProfileLeast {
    /// Horizontal distance from home along the path, m.
    pub distance_m: f64,
    /// Height above the ground there, m (the summary's `min_clearance_m`).
    pub clearance_m: f64,
    /// Its segment, from 1 (the `index` of the mission answer's segments).
    pub segment: usize,
}

/// One point of a profile: distance, altitude and ground, m.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Point {
    distance_m: f64,
    altitude_m: f64,
    ground_m: f64,
}

impl Point {
    fn clearance_m(&self) -> f64 {
        self.altitude_m - self.ground_m
    }
}

/// The profile of `plan` (of `mission`) over the tiles of `terrain_dir`; none without tiles.
///
/// # Errors
/// The tiles' (a directory that cannot be read, no tile or a void under the route).
pub(in crate::engine) fn route_profile(
    plan: &Plan,
    mission: &Mission,
    terrain_dir: Option<&std::path::Path>,
) -> Result<Option<TerrainProfile>, Error> {
    let Some(dir) = terrain_dir else {
        return Ok(None);
    };
    let terrain = Terrain::open(dir)?;
    let ground = Ground::at_home(&terrain, mission.spec())?;
    let least_segment = least_segment(plan, &ground)?;
    let walked = walk_route(plan, &ground, &terrain, least_segment.map(|(k, _)| k))?;
    let mut points = decimate(walked.points, PROFILE_POINTS - 1);
    let least = match (least_segment, walked.least) {
        (Some((k, _)), Some(at)) => {
            insert_in_order(&mut points, at);
            Some(ProfileLeast {
                distance_m: at.distance_m,
                clearance_m: at.clearance_m(),
                segment: k + 1,
            })
        }
        _ => None,
    };
    Ok(Some(TerrainProfile {
        distance_m: points.iter().map(|p| p.distance_m).collect(),
        altitude_m: points.iter().map(|p| p.altitude_m).collect(),
        ground_m: points.iter().map(|p| p.ground_m).collect(),
        least,
    }))
}

/// The segment (of the planned route, from 0) whose clearance is the answer's least: the first
/// judged segment of least clearance, with that clearance, over the whole route as
/// `judge_clearances` judges it (past where a pack that falls short stops too).
///
/// # Errors
/// The tiles'.
fn least_segment(plan: &Plan, ground: &Ground<'_>) -> Result<Option<(usize, f64)>, Error> {
    let compiled = plan.compiled();
    let kinds = compiled.segment_kinds();
    let paths = segment_paths(compiled);
    let clearances = ground.clearances(&paths, plan.home_m(), kinds.len())?;
    let mut least: Option<(usize, f64)> = None;
    for (k, c) in clearances.iter().enumerate() {
        let Some(c) = c else { continue };
        let judged_here = judged(kinds[k], kinds.get(k + 1).copied());
        if judged_here && least.is_none_or(|(_, l)| c.clearance_m < l) {
            least = Some((k, c.clearance_m));
        }
    }
    Ok(least)
}

/// The points of a route walked over the ground, and the least clearance's place on the segment
/// asked for.
struct Walked {
    points: Vec<Point>,
    least: Option<Point>,
}

/// The ground and the altitude along every line of `plan`'s path; on segment `least_segment`
/// (from 0), the place of least clearance.
fn walk_route(
    plan: &Plan,
    ground: &Ground<'_>,
    terrain: &Terrain,
    least_segment: Option<usize>,
) -> Result<Walked, Error> {
    let origin_m = plan.home_m();
    let mut out = Walked {
        points: Vec::new(),
        least: None,
    };
    let mut flown_m = 0.0;
    for (k, path) in segment_paths(plan.compiled()) {
        for (a, b) in path_lines(&path) {
            let (pa, pb) = (
                ground.path_point(&a, origin_m),
                ground.path_point(&b, origin_m),
            );
            let horizontal_m = (b[0] - a[0]).hypot(b[1] - a[1]);
            let rise_m = pb.altitude_amsl_m - pa.altitude_amsl_m;
            let samples = terrain.profile(
                (pa.latitude_deg, pa.longitude_deg),
                (pb.latitude_deg, pb.longitude_deg),
            )?;
            // The line's length on the tiles' sphere: its samples' distances as fractions.
            let length_m = samples.last().map_or(0.0, |s| s.distance_m);
            let fraction = |d_m: f64| if length_m > 0.0 { d_m / length_m } else { 0.0 };
            for s in &samples {
                let f = fraction(s.distance_m);
                push(
                    &mut out.points,
                    Point {
                        distance_m: flown_m + f * horizontal_m,
                        altitude_m: pa.altitude_amsl_m + f * rise_m,
                        ground_m: s.height_m,
                    },
                );
            }
            // A vertical line has one sample: its top (or bottom) too.
            if let (1, Some(s)) = (samples.len(), samples.first()) {
                push(
                    &mut out.points,
                    Point {
                        distance_m: flown_m,
                        altitude_m: pb.altitude_amsl_m,
                        ground_m: s.height_m,
                    },
                );
            }
            if least_segment == Some(k) {
                let c = terrain.least_clearance(pa, pb)?;
                if out.least.is_none_or(|l| c.clearance_m < l.clearance_m()) {
                    out.least = Some(Point {
                        distance_m: flown_m + fraction(c.distance_m) * horizontal_m,
                        altitude_m: c.ground_m + c.clearance_m,
                        ground_m: c.ground_m,
                    });
                }
            }
            flown_m += horizontal_m;
        }
    }
    Ok(out)
}

/// `p` after the points, unless it is the last one again.
fn push(points: &mut Vec<Point>, p: Point) {
    let same = points.last().is_some_and(|q| {
        (q.distance_m - p.distance_m).abs() < SAME_POINT_M
            && (q.altitude_m - p.altitude_m).abs() < SAME_POINT_M
    });
    if !same {
        points.push(p);
    }
}

/// `p` among `points` (distances never decreasing) after those at or before its distance,
/// unless one there is the same point.
fn insert_in_order(points: &mut Vec<Point>, p: Point) {
    let k = points.partition_point(|q| q.distance_m <= p.distance_m);
    let same = |q: &Point| {
        (q.distance_m - p.distance_m).abs() < SAME_POINT_M
            && (q.altitude_m - p.altitude_m).abs() < SAME_POINT_M
    };
    let around = k.saturating_sub(1)..(k + 1).min(points.len());
    if !points[around].iter().any(same) {
        points.insert(k, p);
    }
}

/// At most `most` points (at least 5) of `points`: the first and the last, and in each of
/// `(most - 2) / 3` buckets of consecutive points between them its point of least clearance,
/// of highest ground and of lowest ground, in order.
fn decimate(points: Vec<Point>, most: usize) -> Vec<Point> {
    let most = most.max(5);
    if points.len() <= most {
        return points;
    }
    let inner = &points[1..points.len() - 1];
    let buckets = (most - 2) / 3;
    let mut out = Vec::with_capacity(most);
    out.push(points[0]);
    for b in 0..buckets {
        let bucket = &inner[b * inner.len() / buckets..(b + 1) * inner.len() / buckets];
        let least_by = |key: fn(&Point) -> f64| {
            (0..bucket.len()).min_by(|&i, &j| key(&bucket[i]).total_cmp(&key(&bucket[j])))
        };
        let mut kept: Vec<usize> = [
            least_by(Point::clearance_m),
            least_by(|p| -p.ground_m),
            least_by(|p| p.ground_m),
        ]
        .into_iter()
        .flatten()
        .collect();
        kept.sort_unstable();
        kept.dedup();
        out.extend(kept.into_iter().map(|k| bucket[k]));
    }
    out.extend(points.last().copied());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(distance_m: f64, altitude_m: f64, ground_m: f64) -> Point {
        Point {
            distance_m,
            altitude_m,
            ground_m,
        }
    }

    /// A long flat profile with one ridge, one valley and, elsewhere, one dip of the route:
    /// thinned to the bound, its ends, the ridge's top, the valley's floor and the closest pass
    /// are kept, in order.
    #[test]
    fn decimation_keeps_the_ends_the_ridge_the_valley_and_the_closest_pass() {
        let n = 100_000;
        let points: Vec<Point> = (0..n)
            .map(|k| {
                let d = k as f64;
                let ground = match k {
                    31_337 => 480.0,
                    55_555 => 320.0,
                    _ => 400.0,
                };
                let altitude = if k == 77_777 { 405.0 } else { 500.0 };
                point(d, altitude, ground)
            })
            .collect();
        let kept = decimate(points.clone(), PROFILE_POINTS - 1);
        assert!(kept.len() < PROFILE_POINTS, "{}", kept.len());
        assert!(kept.len() >= (PROFILE_POINTS - 3) / 3, "{}", kept.len());
        assert_eq!(kept.first(), points.first());
        assert_eq!(kept.last(), points.last());
        assert!(
            kept.iter().any(|p| p.ground_m > 479.0),
            "the ridge was lost"
        );
        assert!(
            kept.iter().any(|p| p.ground_m < 321.0),
            "the valley was lost"
        );
        assert!(kept.iter().any(|p| p.altitude_m < 406.0), "the close pass");
        assert!(kept.windows(2).all(|w| w[0].distance_m < w[1].distance_m));
        // A short profile is kept whole.
        let short = points[..500].to_vec();
        assert_eq!(decimate(short.clone(), PROFILE_POINTS - 1), short);
    }

    #[test]
    fn the_least_goes_in_at_its_distance_once() {
        let mut points = vec![point(0.0, 10.0, 0.0), point(10.0, 10.0, 0.0)];
        insert_in_order(&mut points, point(4.0, 10.0, 8.0));
        assert_eq!(points[1], point(4.0, 10.0, 8.0));
        insert_in_order(&mut points, point(4.0, 10.0, 8.0));
        assert_eq!(points.len(), 3);
        insert_in_order(&mut points, point(10.0, 10.0, 0.0));
        assert_eq!(points.len(), 3);
    }
}
