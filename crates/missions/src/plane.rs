//! Geometry in a tangent plane (east and north, m): the few tests a survey's coverage and a
//! route's fence checks share.

/// Whether `q` is inside `polygon` (even-odd rule; a point on an edge may count either way).
pub(crate) fn inside(polygon: &[[f64; 2]], q: [f64; 2]) -> bool {
    let mut c = false;
    for (k, a) in polygon.iter().enumerate() {
        let b = polygon[(k + 1) % polygon.len()];
        if (a[1] > q[1]) != (b[1] > q[1]) {
            let x = a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if q[0] < x {
                c = !c;
            }
        }
    }
    c
}

/// Distance from `q` to the segment `a`-`b`, m.
pub(crate) fn to_segment_m(q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let t = match len2 > 0.0 {
        true => (((q[0] - a[0]) * d[0] + (q[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0),
        false => 0.0,
    };
    (q[0] - a[0] - t * d[0]).hypot(q[1] - a[1] - t * d[1])
}
