//! Steps 1-8 of the module's docs: polygon, angle and spacing to transects
//! (`SurveyComplexItem.cc` `_rebuildTransectsPhase1WorkerSinglePolygon` and the functions it
//! calls). The arithmetic follows QGroundControl's order of operations, so that the shared
//! survey is reproduced to the last bit.

use super::projection::{qt_at, qt_azimuth_deg, qt_distance_m, reverse, to_plane, Xy};
use super::{PointKind, QgcProjection, SurveyParams, Transect, TransectPoint};
use crate::geo::LatLon;

/// Added to the bounding box's larger side for the grid lines' length, m
/// (QGroundControl's "fudge factor").
const LINE_MARGIN_M: f64 = 2000.0;

/// A line of the plane from `a` to `b` (`QLineF`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Line {
    pub(crate) a: Xy,
    pub(crate) b: Xy,
}

/// The bounding box of the (closed) plane polygon: its centre and its larger side, m.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BoundingBox {
    pub(crate) centre: Xy,
    pub(crate) larger_side_m: f64,
}

/// Every transect: the first pass, then the refly pass at the angle plus 90 deg.
pub(super) fn all(p: &SurveyParams, projection: QgcProjection) -> Vec<Transect> {
    let mut out = one_pass(p, projection, false, None);
    if p.refly_90 {
        let last = out.last().and_then(|t| t.points.last()).map(|q| q.position);
        if let Some(last) = last {
            out.extend(one_pass(p, projection, true, Some(last)));
        }
    }
    out
}

/// One pass over the polygon, its transects in flying order with their extra points.
fn one_pass(
    p: &SurveyParams,
    projection: QgcProjection,
    refly: bool,
    previous_end: Option<LatLon>,
) -> Vec<Transect> {
    let pairs = plane_chords(p, projection, refly);
    let origin = p.polygon[0];
    let mut ends: Vec<[LatLon; 2]> = pairs
        .iter()
        .map(|l| {
            [
                reverse(l.a, origin, projection),
                reverse(l.b, origin, projection),
            ]
        })
        .collect();
    order_for_flight(&mut ends, p, previous_end);
    ends.iter().map(|e| with_extra_points(*e, p)).collect()
}

/// Steps 1-5: the chords of the grid lines across the polygon, in the plane, all one way.
pub(crate) fn plane_chords(p: &SurveyParams, projection: QgcProjection, refly: bool) -> Vec<Line> {
    let mut polygon = to_plane(&p.polygon, projection);
    polygon.push(polygon[0]);
    let bbox = bounding_box(&polygon);
    let angle_deg = grid_angle_deg(p.angle_deg) + if refly { 90.0 } else { 0.0 };
    let lines = grid_lines(bbox, p.spacing_m, angle_deg);
    let mut chords: Vec<Line> = lines.iter().filter_map(|l| chord(*l, &polygon)).collect();
    if chords.len() < 2 {
        chords = centre_chord(&lines, bbox, &polygon);
    }
    same_direction(&chords)
}

/// `_clampGridAngle90`: one step of 180 deg towards [-90, 90].
pub(crate) fn grid_angle_deg(angle_deg: f64) -> f64 {
    if angle_deg > 90.0 {
        angle_deg - 180.0
    } else if angle_deg < -90.0 {
        angle_deg + 180.0
    } else {
        angle_deg
    }
}

/// `QPolygonF::boundingRect` and `QRectF::center`.
pub(crate) fn bounding_box(polygon: &[Xy]) -> BoundingBox {
    let (mut x0, mut y0) = (f64::INFINITY, f64::INFINITY);
    let (mut x1, mut y1) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for q in polygon {
        (x0, x1) = (x0.min(q.x), x1.max(q.x));
        (y0, y1) = (y0.min(q.y), y1.max(q.y));
    }
    let (w, h) = (x1 - x0, y1 - y0);
    BoundingBox {
        centre: Xy {
            x: x0 + w / 2.0,
            y: y0 + h / 2.0,
        },
        larger_side_m: w.max(h),
    }
}

/// Step 3: lines of constant x every `spacing_m` across the widened box, rotated about its
/// centre clockwise by `angle_deg` (`_rotatePoint` with the angle negated).
pub(crate) fn grid_lines(bbox: BoundingBox, spacing_m: f64, angle_deg: f64) -> Vec<Line> {
    let width_m = bbox.larger_side_m + LINE_MARGIN_M;
    let half_m = width_m / 2.0;
    let c = bbox.centre;
    let mut x = c.x - half_m;
    let x_end = x + width_m;
    let mut lines = Vec::new();
    while x < x_end {
        let a = rotate(Xy { x, y: c.y - half_m }, c, angle_deg);
        let b = rotate(Xy { x, y: c.y + half_m }, c, angle_deg);
        lines.push(Line { a, b });
        x += spacing_m;
    }
    lines
}

/// `_rotatePoint`: `q` turned about `centre` by `-angle_deg` (counter-clockwise positive).
fn rotate(q: Xy, centre: Xy, angle_deg: f64) -> Xy {
    let radians = (std::f64::consts::PI / 180.0) * -angle_deg;
    let (dx, dy) = (q.x - centre.x, q.y - centre.y);
    Xy {
        x: (dx * radians.cos()) - (dy * radians.sin()) + centre.x,
        y: (dx * radians.sin()) + (dy * radians.cos()) + centre.y,
    }
}

/// `QLineF::intersects` (Graphics Gems III, "Faster line segment intersection"): the point of
/// `line` where it meets `edge`, when both segments contain it (ends included).
pub(crate) fn bounded_intersection(line: Line, edge: Line) -> Option<Xy> {
    let a = Xy {
        x: line.b.x - line.a.x,
        y: line.b.y - line.a.y,
    };
    let b = Xy {
        x: edge.a.x - edge.b.x,
        y: edge.a.y - edge.b.y,
    };
    let c = Xy {
        x: line.a.x - edge.a.x,
        y: line.a.y - edge.a.y,
    };
    let denominator = a.y * b.x - a.x * b.y;
    if denominator == 0.0 || !denominator.is_finite() {
        return None;
    }
    let reciprocal = 1.0 / denominator;
    let na = (b.y * c.x - b.x * c.y) * reciprocal;
    let nb = (a.x * c.y - a.y * c.x) * reciprocal;
    let inside = (0.0..=1.0).contains(&na) && (0.0..=1.0).contains(&nb);
    inside.then_some(Xy {
        x: line.a.x + a.x * na,
        y: line.a.y + a.y * na,
    })
}

/// Step 4 (`_intersectLinesWithPolygon`): the two hits of `line` on the closed polygon's edges
/// farthest apart, in the order found (`None` below two distinct hits).
fn chord(line: Line, closed: &[Xy]) -> Option<Line> {
    let mut hits: Vec<Xy> = Vec::new();
    for edge in closed.windows(2) {
        let edge = Line {
            a: edge[0],
            b: edge[1],
        };
        if let Some(q) = bounded_intersection(line, edge) {
            if !hits.iter().any(|h| fuzzy_same(*h, q)) {
                hits.push(q);
            }
        }
    }
    farthest_pair(&hits)
}

/// The first pair, in QGroundControl's loop order, of the largest distance (`None` when all
/// coincide or there are fewer than two).
fn farthest_pair(hits: &[Xy]) -> Option<Line> {
    let mut best: Option<Line> = None;
    let mut best_m = 0.0;
    for a in hits {
        for b in hits {
            let d = (b.x - a.x).hypot(b.y - a.y);
            if d > best_m {
                (best, best_m) = (Some(Line { a: *a, b: *b }), d);
            }
        }
    }
    best
}

/// `QPointF ==`: Qt's fuzzy comparison (relative 1e-12, or absolute 1e-12 against zero).
fn fuzzy_same(p: Xy, q: Xy) -> bool {
    fuzzy_eq(p.x, q.x) && fuzzy_eq(p.y, q.y)
}

/// `qFuzzyCompare`, or `qFuzzyIsNull` of the difference when either is zero.
fn fuzzy_eq(a: f64, b: f64) -> bool {
    if a == 0.0 || b == 0.0 {
        (a - b).abs() <= 1e-12
    } else {
        (a - b).abs() * 1e12 <= a.abs().min(b.abs())
    }
}

/// Fewer than two chords: the first grid line moved through the box centre, across the polygon.
fn centre_chord(lines: &[Line], bbox: BoundingBox, closed: &[Xy]) -> Vec<Line> {
    let Some(first) = lines.first() else {
        return Vec::new();
    };
    let mid = Xy {
        x: first.a.x + (first.b.x - first.a.x) * 0.5,
        y: first.a.y + (first.b.y - first.a.y) * 0.5,
    };
    let (dx, dy) = (bbox.centre.x - mid.x, bbox.centre.y - mid.y);
    let moved = Line {
        a: Xy {
            x: first.a.x + dx,
            y: first.a.y + dy,
        },
        b: Xy {
            x: first.b.x + dx,
            y: first.b.y + dy,
        },
    };
    chord(moved, closed).into_iter().collect()
}

/// Step 5 (`_adjustLineDirection`): chords whose `QLineF::angle` differs from the first's by
/// more than 1 deg are turned round.
fn same_direction(chords: &[Line]) -> Vec<Line> {
    let Some(first) = chords.first() else {
        return Vec::new();
    };
    let first_deg = qt_line_angle_deg(*first);
    chords
        .iter()
        .map(|l| {
            if (qt_line_angle_deg(*l) - first_deg).abs() > 1.0 {
                Line { a: l.b, b: l.a }
            } else {
                *l
            }
        })
        .collect()
}

/// `QLineF::angle`: deg in [0, 360), counter-clockwise from +x with y pointing down, 360 folded
/// to 0 by `qFuzzyCompare`.
fn qt_line_angle_deg(l: Line) -> f64 {
    let theta = (-(l.b.y - l.a.y)).atan2(l.b.x - l.a.x).to_degrees();
    let normalized = if theta < 0.0 { theta + 360.0 } else { theta };
    if fuzzy_eq(normalized, 360.0) {
        0.0
    } else {
        normalized
    }
}

/// Steps 6-7: entry corner, the refly pass's nearest start, alternate transects, lawnmower.
fn order_for_flight(ends: &mut Vec<[LatLon; 2]>, p: &SurveyParams, previous_end: Option<LatLon>) {
    if p.entry.reverses_points() {
        ends.iter_mut().for_each(|e| e.reverse());
    }
    if p.entry.reverses_order() {
        ends.reverse();
    }
    if let Some(from) = previous_end {
        nearest_start(ends, from);
    }
    if p.fly_alternate_transects {
        *ends = alternate(ends);
    }
    for e in ends.iter_mut().skip(1).step_by(2) {
        e.reverse();
    }
}

/// `_optimizeTransectsForShortestDistance`: reorder so that the pass starts at the end nearest
/// `from`. QGroundControl compares the first three candidates only (its loop stops before the
/// last transect's last point); kept, as it decides the drawing.
fn nearest_start(ends: &mut [[LatLon; 2]], from: LatLon) {
    let (Some(first), Some(last)) = (ends.first().copied(), ends.last().copied()) else {
        return;
    };
    let candidates = [first[0], first[1], last[0]].map(|q| qt_distance_m(q, from));
    let mut shortest = 0;
    for k in 1..3 {
        if candidates[k] < candidates[shortest] {
            shortest = k;
        }
    }
    if shortest > 1 {
        ends.reverse();
    }
    if shortest & 1 == 1 {
        ends.iter_mut().for_each(|e| e.reverse());
    }
}

/// Alternate transects: the even ones in order, then the odd ones backwards.
fn alternate(ends: &[[LatLon; 2]]) -> Vec<[LatLon; 2]> {
    let even = ends.iter().step_by(2);
    let odd = ends.iter().enumerate().rev().filter(|(k, _)| k % 2 == 1);
    even.copied().chain(odd.map(|(_, e)| *e)).collect()
}

/// Step 8: entry, hover points, exit, and the turnarounds before and after.
fn with_extra_points(ends: [LatLon; 2], p: &SurveyParams) -> Transect {
    let point = |position, kind| TransectPoint { position, kind };
    let mut points = vec![
        point(ends[0], PointKind::Entry),
        point(ends[1], PointKind::Exit),
    ];
    if p.trigger_distance_m != 0.0 && p.hover_and_capture {
        let length_m = qt_distance_m(ends[0], ends[1]);
        let azimuth_deg = qt_azimuth_deg(ends[0], ends[1]);
        if p.trigger_distance_m < length_m {
            let count = (length_m / p.trigger_distance_m).floor() as usize;
            for k in 0..count {
                let d = p.trigger_distance_m * (k + 1) as f64;
                let q = qt_at(ends[0], d, azimuth_deg);
                points.insert(1 + k, point(q, PointKind::HoverTrigger));
            }
        }
    }
    if p.turnaround_m > 0.0 {
        let before = qt_at(ends[0], -p.turnaround_m, qt_azimuth_deg(ends[0], ends[1]));
        let after = qt_at(ends[1], -p.turnaround_m, qt_azimuth_deg(ends[1], ends[0]));
        points.insert(0, point(before, PointKind::Turnaround));
        points.push(point(after, PointKind::Turnaround));
    }
    Transect { points }
}
