//! The geometry of turning a survey: which grid angles to try, and how much of the polygon a
//! survey's camera-on lines cover, so that a turned survey is kept only when it covers the
//! polygon as the operator's does.
//!
//! Coverage is counted on a [`COVERAGE_GRID_M`] grid in the plane tangent at the polygon's
//! first vertex (x east, y north, m): a grid point inside the polygon (even-odd rule) is covered
//! when it lies within half a line spacing (plus [`COVERAGE_TOLERANCE_M`]) of a camera-on
//! stretch of a transect (entry to exit, and the turnarounds where the camera triggers through
//! them).

use aloft_planner::geodesy::LocalFrame;
use aloft_planner::Wind;

use super::{PointKind, QgcProjection, Survey, SurveyParams};
use crate::geo::LatLon;
use crate::plane::inside;

/// The step of the candidate grid angles, deg.
pub const ANGLE_STEP_DEG: f64 = 15.0;

/// The grid on which coverage is counted, m.
pub const COVERAGE_GRID_M: f64 = 3.0;

/// How far beyond half a line spacing a point still counts as covered, m (what two tangent
/// planes' geodesy leaves over a survey's extent).
pub const COVERAGE_TOLERANCE_M: f64 = 0.5;

/// The most grid points counted in one polygon (a large survey is counted on a coarser grid).
const MAX_GRID_POINTS: f64 = 1e6;

impl Survey {
    /// How many points of a [`COVERAGE_GRID_M`] grid inside the survey's polygon lie within half
    /// a line spacing of a camera-on stretch of its transects (module docs); `None` for a survey
    /// without transects.
    pub fn covered_points(&self) -> Option<usize> {
        let p = self.params();
        let origin = p.polygon.first()?;
        let frame = LocalFrame::new(origin.latitude_deg, origin.longitude_deg);
        let local = |q: &LatLon| frame.to_local_m(q.latitude_deg, q.longitude_deg);
        let polygon: Vec<[f64; 2]> = p.polygon.iter().map(local).collect();
        let mut lines: Vec<([f64; 2], [f64; 2])> = Vec::new();
        for t in self.transects(QgcProjection::default()) {
            let on: Vec<[f64; 2]> = t
                .points
                .iter()
                .filter(|q| p.camera_in_turnaround || q.kind != PointKind::Turnaround)
                .map(|q| local(&q.position))
                .collect();
            lines.extend(on.windows(2).map(|w| (w[0], w[1])));
        }
        if lines.is_empty() {
            return None;
        }
        let reach_m = 0.5 * p.spacing_m + COVERAGE_TOLERANCE_M;
        let near = Reach::of(&lines, reach_m);
        let covered = grid_inside(&polygon, COVERAGE_GRID_M)
            .filter(|q| near.any_within(*q))
            .count();
        Some(covered)
    }
}

/// The camera-on stretches of a survey with what the coverage count asks of each, computed
/// once: whether a grid point lies within `reach_m` of any ([`Reach::any_within`]), as
/// `to_segment_m` measures it, without a square root and skipping the stretches whose box
/// (widened by the reach) the point lies outside (the count is the plain one's:
/// `covered_count_is_the_plain_count` below).
struct Reach {
    lines: Vec<Stretch>,
    reach2_m2: f64,
}

/// A camera-on stretch as [`Reach`] measures it.
#[derive(Debug, Clone, Copy)]
struct Stretch {
    /// Its start, m.
    a: [f64; 2],
    /// Its direction: end minus start, m.
    d: [f64; 2],
    /// Its squared length, m^2.
    len2: f64,
    /// Its box widened by the reach: west, south, east, north, m.
    bounds: [f64; 4],
}

impl Reach {
    fn of(lines: &[([f64; 2], [f64; 2])], reach_m: f64) -> Self {
        let lines = lines
            .iter()
            .map(|&(a, b)| {
                let d = [b[0] - a[0], b[1] - a[1]];
                let bounds = [
                    a[0].min(b[0]) - reach_m,
                    a[1].min(b[1]) - reach_m,
                    a[0].max(b[0]) + reach_m,
                    a[1].max(b[1]) + reach_m,
                ];
                Stretch {
                    a,
                    d,
                    len2: d[0] * d[0] + d[1] * d[1],
                    bounds,
                }
            })
            .collect();
        Self {
            lines,
            reach2_m2: reach_m * reach_m,
        }
    }

    /// Whether `q` lies within the reach of a stretch.
    fn any_within(&self, q: [f64; 2]) -> bool {
        self.lines.iter().any(|&Stretch { a, d, len2, bounds }| {
            if q[0] < bounds[0] || q[1] < bounds[1] || q[0] > bounds[2] || q[1] > bounds[3] {
                return false;
            }
            let t = match len2 > 0.0 {
                true => (((q[0] - a[0]) * d[0] + (q[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0),
                false => 0.0,
            };
            let (x, y) = (q[0] - a[0] - t * d[0], q[1] - a[1] - t * d[1]);
            x * x + y * y <= self.reach2_m2
        })
    }
}

/// The grid angles worth trying for a survey, deg in [0, 180), without repeats and without its
/// own angle: every [`ANGLE_STEP_DEG`] of a half turn, and along and across the wind at the
/// survey's first vertex and height ([`wind_bearing_deg`]).
pub fn candidate_angles(survey: &SurveyParams, wind: &Wind) -> Vec<f64> {
    let mut out: Vec<f64> = (0..)
        .map(|k| f64::from(k) * ANGLE_STEP_DEG)
        .take_while(|a| *a < 180.0)
        .collect();
    if let Some(bearing) = wind_bearing_deg(survey, wind) {
        out.push(bearing.rem_euclid(180.0));
        out.push((bearing + 90.0).rem_euclid(180.0));
    }
    let own = survey.angle_deg.rem_euclid(180.0);
    // Angles closer than 1e-9 deg are one angle (far below the file's precision).
    out.retain(|a| (a - own).abs() > 1e-9);
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    out
}

/// The bearing the wind blows towards at the survey's first vertex and height (at least 1 m),
/// deg clockwise from north; `None` in still air there (below 1e-6 m/s).
pub fn wind_bearing_deg(survey: &SurveyParams, wind: &Wind) -> Option<f64> {
    let w = wind.mean_at([0.0, 0.0, survey.altitude_m.max(1.0)])?;
    (w[0].hypot(w[1]) > 1e-6).then(|| w[0].atan2(w[1]).to_degrees())
}

/// The points of a `step_m` grid inside `polygon` (even-odd rule), at cell centres, the step
/// widened so that at most about [`MAX_GRID_POINTS`] cells span the polygon's bounding box.
fn grid_inside(polygon: &[[f64; 2]], step_m: f64) -> impl Iterator<Item = [f64; 2]> + '_ {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for q in polygon {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let area_m2 = (hi[0] - lo[0]).max(0.0) * (hi[1] - lo[1]).max(0.0);
    let step_m = step_m.max((area_m2 / MAX_GRID_POINTS).sqrt());
    let nx = ((hi[0] - lo[0]) / step_m).floor().max(0.0) as usize;
    let ny = ((hi[1] - lo[1]) / step_m).floor().max(0.0) as usize;
    (0..ny)
        .flat_map(move |j| (0..nx).map(move |i| (i, j)))
        .map(move |(i, j)| {
            [
                lo[0] + (i as f64 + 0.5) * step_m,
                lo[1] + (j as f64 + 0.5) * step_m,
            ]
        })
        .filter(move |q| inside(polygon, *q))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plane::to_segment_m;
    use crate::survey::tests::{params, survey};

    /// A 205 m (east) by 120 m (north) rectangle at 47 N, north-south lines 30 m apart:
    /// QGroundControl puts them 20, 50, ... 200 m east of the west side (the survey module's
    /// tests).
    fn rectangle_survey() -> Survey {
        survey(params())
    }

    /// Lines at x = 20, 50, ... 200 m reach 15 + 0.5 m either side: the whole rectangle but
    /// the strip x < 4.5 m along its west side. On a 3 m grid (68 x 40 cells) that strip is the
    /// column at x = 1.5 m and perhaps the one at 4.5 m (on the edge of the reach): 40 or 80
    /// points of about 2720 uncovered.
    #[test]
    fn covered_points_leave_out_the_strip_beyond_half_a_spacing() {
        let s = rectangle_survey();
        let p = s.params();
        let frame = LocalFrame::new(p.polygon[0].latitude_deg, p.polygon[0].longitude_deg);
        let polygon: Vec<[f64; 2]> = p
            .polygon
            .iter()
            .map(|q| frame.to_local_m(q.latitude_deg, q.longitude_deg))
            .collect();
        let total = grid_inside(&polygon, COVERAGE_GRID_M).count();
        assert!((2650..=2790).contains(&total), "{total}");
        let covered = s.covered_points().unwrap();
        let uncovered = total - covered;
        assert!((35..=85).contains(&uncovered), "{uncovered} of {total}");
    }

    /// A wind from the north blows towards 180 deg; from 100 deg, towards 280 deg.
    #[test]
    fn the_wind_bearing_is_where_it_blows_towards() {
        let p = SurveyParams::default();
        let north = Wind::constant(8.0, 0.0).unwrap();
        let b = wind_bearing_deg(&p, &north).unwrap();
        assert!((b.rem_euclid(360.0) - 180.0).abs() < 1e-9, "{b}");
        let east_ish = Wind::constant(8.0, 100.0).unwrap();
        let b = wind_bearing_deg(&p, &east_ish).unwrap();
        assert!((b.rem_euclid(360.0) - 280.0).abs() < 1e-9, "{b}");
        assert!(wind_bearing_deg(&p, &Wind::calm()).is_none());
    }

    /// Twelve steps of 15 deg in a half turn, less the survey's own angle (0): 11. A wind from
    /// the north adds along (0, its own) and across (90, a step): none new. From 100 deg it
    /// adds 100 and 10: 13, sorted, all in [0, 180).
    #[test]
    fn candidate_angles_are_the_steps_and_the_wind_without_repeats() {
        let p = SurveyParams::default();
        let north = candidate_angles(&p, &Wind::constant(8.0, 0.0).unwrap());
        let steps: Vec<f64> = (1..12).map(|k| f64::from(k) * 15.0).collect();
        assert_eq!(north.len(), steps.len());
        assert!(north.iter().zip(&steps).all(|(a, b)| (a - b).abs() < 1e-9));
        let other = candidate_angles(&p, &Wind::constant(8.0, 100.0).unwrap());
        assert_eq!(other.len(), 13, "{other:?}");
        assert!(other.iter().any(|a| (a - 100.0).abs() < 1e-9));
        assert!(other.iter().any(|a| (a - 10.0).abs() < 1e-9));
        assert!(other.windows(2).all(|w| w[0] < w[1]));
        assert!(other.iter().all(|a| (0.0..180.0).contains(a)));
    }

    /// A 30 m square on a 3 m grid: 10 x 10 cell centres, all inside.
    #[test]
    fn grid_inside_a_square_counts_its_cells() {
        let square = [[0.0, 0.0], [30.0, 0.0], [30.0, 30.0], [0.0, 30.0]];
        assert_eq!(grid_inside(&square, 3.0).count(), 100);
    }

    /// The right triangle (0,0), (30,0), (0,30) on a 3 m grid: the cell centre (i+0.5, j+0.5)*3
    /// is inside when i + j + 1 < 10, i.e. i + j <= 8: 9 + 8 + ... + 1 = 45 cells (the 10 on the
    /// hypotenuse, i + j = 9, fall exactly on it at x + y = 30 and count as outside or inside by
    /// the even-odd rule's half-open edges; none of them is below it).
    #[test]
    fn grid_inside_a_triangle_counts_the_cells_below_its_hypotenuse() {
        let triangle = [[0.0, 0.0], [30.0, 0.0], [0.0, 30.0]];
        let n = grid_inside(&triangle, 3.0).count();
        assert!((45..=55).contains(&n), "{n}");
        let strictly_below = grid_inside(&triangle, 3.0)
            .filter(|q| q[0] + q[1] < 30.0 - 1e-9)
            .count();
        assert_eq!(strictly_below, 45);
    }

    /// The grid widens for a large polygon: a 10 km square holds about a million points, not
    /// eleven million.
    #[test]
    fn grid_inside_a_large_square_is_bounded() {
        let big = [[0.0, 0.0], [1e4, 0.0], [1e4, 1e4], [0.0, 1e4]];
        assert_eq!(grid_inside(&big, 3.0).count(), 1_000_000);
    }

    /// A concave "L": a point in the notch is outside.
    #[test]
    fn inside_follows_the_even_odd_rule_in_a_notch() {
        let l = [
            [0.0, 0.0],
            [20.0, 0.0],
            [20.0, 10.0],
            [10.0, 10.0],
            [10.0, 20.0],
            [0.0, 20.0],
        ];
        assert!(inside(&l, [5.0, 15.0]));
        assert!(inside(&l, [15.0, 5.0]));
        assert!(!inside(&l, [15.0, 15.0]));
        assert!(!inside(&l, [-1.0, 5.0]));
    }

    /// Distances to a segment: beside it (perpendicular), beyond its ends (to the end), and to
    /// a segment of no length (to its point); a 3-4-5 triangle gives exact values.
    #[test]
    fn to_segment_measures_to_the_nearest_point_of_the_segment() {
        let (a, b) = ([0.0, 0.0], [10.0, 0.0]);
        assert!((to_segment_m([5.0, 3.0], a, b) - 3.0).abs() < 1e-12);
        assert!((to_segment_m([13.0, 4.0], a, b) - 5.0).abs() < 1e-12);
        assert!((to_segment_m([-3.0, -4.0], a, b) - 5.0).abs() < 1e-12);
        assert!((to_segment_m([3.0, 4.0], a, a) - 5.0).abs() < 1e-12);
    }

    /// The count of [`Reach::any_within`] is the plain one's (every stretch measured with
    /// [`to_segment_m`]) on a survey-like set of stretches over a grid of 10,000 points whose
    /// spacing puts many at the reach's edge, at ten reaches.
    #[test]
    fn covered_count_is_the_plain_count() {
        let lines: Vec<([f64; 2], [f64; 2])> = (0..12)
            .map(|k| {
                let y = 25.0 * f64::from(k) + 0.1 * f64::from(k % 3);
                ([0.0 + f64::from(k), y], [290.0 - f64::from(k), y + 3.0])
            })
            .collect();
        let points: Vec<[f64; 2]> = (0..100)
            .flat_map(|j| (0..100).map(move |i| [3.0 * f64::from(i), 3.0 * f64::from(j)]))
            .collect();
        for k in 0..10 {
            let reach_m = 10.0 + 0.5 * f64::from(k);
            let near = Reach::of(&lines, reach_m);
            let fast = points.iter().filter(|q| near.any_within(**q)).count();
            let plain = points
                .iter()
                .filter(|q| {
                    lines
                        .iter()
                        .any(|(a, b)| to_segment_m(**q, *a, *b) <= reach_m)
                })
                .count();
            assert_eq!(fast, plain, "reach {reach_m}");
            assert!(plain > 1000 && plain < 10_000, "{plain}");
        }
    }
}
