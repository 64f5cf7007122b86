//! What a `.plan` holds beside its mission: the geofence (`geoFence`) and the rally points
//! (`rallyPoints`), read so that a route can be checked against them and kept so that every file
//! written from the plan carries them as the operator drew them.
//!
//! QGroundControl's format (version 2, `GeoFenceController` and `RallyPointController`):
//! - `geoFence`: `{"version": 2, "polygons": [...], "circles": [...]}`; a polygon
//!   `{"inclusion": true, "polygon": [[lat, lon], ...], "version": 1}` (an inclusion fence keeps
//!   the vehicle inside, an exclusion fence out); a circle
//!   `{"inclusion": false, "circle": {"center": [lat, lon], "radius": r_m}, "version": 1}`; other
//!   keys (`breachReturn`) are kept as they are;
//! - `rallyPoints`: `{"version": 2, "points": [[lat, lon, alt_m], ...]}`, the altitude relative
//!   to home.
//!
//! A route is checked in the plane tangent at home ([`Airspace::local`], east and north in m):
//! the vehicle must stay inside every inclusion fence and outside every exclusion fence (the
//! fences of a `.plan` are one inclusion group, as MAVLink's fence items and the autopilots read
//! them), horizontally; [`LocalFence::first_breach`] finds where a straight stretch first leaves
//! or enters one (a point on a fence's edge is inside it).
//!
//! A `geoFence` of another version (QGroundControl's version 1 had no polygons list) or an empty
//! object holds no fence; the writer then writes the empty version 2 objects that QGroundControl
//! and MAVSDK require.

use aloft_planner::geodesy::LocalFrame;
use serde_json::{json, Map, Value};

use crate::error::{ImportError, Place};
use crate::geo::LatLon;
use crate::plan::bad_key;
use crate::plane::{inside, to_segment_m};

/// A fence polygon: the vehicle stays inside an inclusion polygon and out of an exclusion one.
#[derive(Debug, Clone, PartialEq)]
pub struct FencePolygon {
    /// Whether it is an inclusion fence (else an exclusion fence).
    pub inclusion: bool,
    /// Its vertices in order (closed implicitly), WGS-84 deg.
    pub vertices: Vec<LatLon>,
}

/// A fence circle: the vehicle stays inside an inclusion circle and out of an exclusion one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FenceCircle {
    /// Whether it is an inclusion fence (else an exclusion fence).
    pub inclusion: bool,
    /// Its centre, WGS-84 deg.
    pub centre: LatLon,
    /// Its radius, m.
    pub radius_m: f64,
}

/// A rally point: where the vehicle may return to instead of home.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RallyPoint {
    /// Where, WGS-84 deg.
    pub position: LatLon,
    /// Its altitude above home, m.
    pub altitude_m: f64,
}

/// A `.plan`'s geofence and rally points, read (for checks) and kept as given (for writers).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Airspace {
    /// The fence polygons, in file order.
    pub polygons: Vec<FencePolygon>,
    /// The fence circles, in file order.
    pub circles: Vec<FenceCircle>,
    /// The rally points, in file order.
    pub rally_points: Vec<RallyPoint>,
    /// The file's `geoFence` object, when it holds a fence.
    geo_fence: Option<Value>,
    /// The file's `rallyPoints` object, when it holds a point.
    rally: Option<Value>,
}

impl Airspace {
    /// Read the `geoFence` and `rallyPoints` of a `.plan`'s top level.
    ///
    /// # Errors
    /// A version 2 object whose fences or points are not as the module docs say (naming the
    /// key, e.g. `geoFence.polygons[1].polygon[3]`).
    pub fn read(root: &Map<String, Value>) -> Result<Self, ImportError> {
        let mut airspace = Self::default();
        if let Some(fence) = root.get("geoFence").and_then(version_2) {
            airspace.polygons = list(fence, "geoFence", "polygons", polygon)?;
            airspace.circles = list(fence, "geoFence", "circles", circle)?;
            if !(airspace.polygons.is_empty() && airspace.circles.is_empty()) {
                airspace.geo_fence = root.get("geoFence").cloned();
            }
        }
        if let Some(rally) = root.get("rallyPoints").and_then(version_2) {
            airspace.rally_points = list(rally, "rallyPoints", "points", rally_point)?;
            if !airspace.rally_points.is_empty() {
                airspace.rally = root.get("rallyPoints").cloned();
            }
        }
        Ok(airspace)
    }

    /// Whether there is neither fence nor rally point.
    pub fn is_empty(&self) -> bool {
        self.polygons.is_empty() && self.circles.is_empty() && self.rally_points.is_empty()
    }

    /// The `geoFence` to write: the file's own when it holds a fence, else an empty one.
    pub fn geo_fence_json(&self) -> Value {
        self.geo_fence
            .clone()
            .unwrap_or_else(|| json!({"version": 2, "circles": [], "polygons": []}))
    }

    /// The `rallyPoints` to write: the file's own when it holds a point, else an empty one.
    pub fn rally_points_json(&self) -> Value {
        self.rally
            .clone()
            .unwrap_or_else(|| json!({"version": 2, "points": []}))
    }
}

/// One fence in the plane tangent at home.
#[derive(Debug, Clone, PartialEq)]
enum Shape {
    /// A polygon's vertices, east and north, m.
    Polygon(Vec<[f64; 2]>),
    /// A circle's centre, east and north, m, and radius, m.
    Circle([f64; 2], f64),
}

/// A fence in the plane tangent at home: its shape, whether it is an inclusion fence, and its
/// name (`inclusion polygon 1`, `exclusion circle 2`: the kind and its place among the file's
/// polygons or circles, from 1).
#[derive(Debug, Clone, PartialEq)]
struct LocalShape {
    shape: Shape,
    inclusion: bool,
    name: String,
}

/// An [`Airspace`]'s fences in the plane tangent at home.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LocalFence {
    fences: Vec<LocalShape>,
}

/// Where a straight stretch first leaves an inclusion fence or enters an exclusion fence.
#[derive(Debug, Clone, PartialEq)]
pub struct Breach {
    /// How far along the stretch, 0 (its start) to 1 (its end).
    pub fraction: f64,
    /// The point, east and north of home, m.
    pub at_m: [f64; 2],
    /// The fence (`inclusion polygon 1`, `exclusion circle 2`).
    pub fence: String,
    /// Whether the stretch leaves an inclusion fence (else it enters an exclusion fence).
    pub leaves: bool,
}

impl Airspace {
    /// The fences in the plane tangent at home (`frame`).
    pub fn local(&self, frame: &LocalFrame) -> LocalFence {
        let to_m = |p: &LatLon| frame.to_local_m(p.latitude_deg, p.longitude_deg);
        let kind = |inclusion: bool| match inclusion {
            true => "inclusion",
            false => "exclusion",
        };
        let polygons = self.polygons.iter().enumerate().map(|(k, p)| LocalShape {
            shape: Shape::Polygon(p.vertices.iter().map(to_m).collect()),
            inclusion: p.inclusion,
            name: format!("{} polygon {}", kind(p.inclusion), k + 1),
        });
        let circles = self.circles.iter().enumerate().map(|(k, c)| LocalShape {
            shape: Shape::Circle(to_m(&c.centre), c.radius_m),
            inclusion: c.inclusion,
            name: format!("{} circle {}", kind(c.inclusion), k + 1),
        });
        LocalFence {
            fences: polygons.chain(circles).collect(),
        }
    }
}

impl LocalFence {
    /// Whether there is no fence.
    pub fn is_empty(&self) -> bool {
        self.fences.is_empty()
    }

    /// The first point of the stretch from `a` to `b` (east and north of home, m) outside an
    /// inclusion fence or inside an exclusion fence, if any.
    pub fn first_breach(&self, a: [f64; 2], b: [f64; 2]) -> Option<Breach> {
        self.fences
            .iter()
            .filter_map(|f| {
                let fraction = match &f.shape {
                    Shape::Polygon(v) => polygon_breach(v, f.inclusion, a, b),
                    Shape::Circle(c, r) => circle_breach(*c, *r, f.inclusion, a, b),
                }?;
                Some(Breach {
                    fraction,
                    at_m: [
                        a[0] + fraction * (b[0] - a[0]),
                        a[1] + fraction * (b[1] - a[1]),
                    ],
                    fence: f.name.clone(),
                    leaves: f.inclusion,
                })
            })
            .min_by(|x, y| x.fraction.total_cmp(&y.fraction))
    }
}

/// How far along `a`-`b` it first leaves (`inclusion`) or enters the polygon `v`.
fn polygon_breach(v: &[[f64; 2]], inclusion: bool, a: [f64; 2], b: [f64; 2]) -> Option<f64> {
    if inside_polygon(v, a) != inclusion {
        return Some(0.0);
    }
    // The first crossing of an edge (the stretch changes side there); a crossing that only
    // touches the edge and comes back is not a breach, checked at the middle of what follows.
    let mut crossings: Vec<f64> = (0..v.len())
        .filter_map(|k| crossing(a, b, v[k], v[(k + 1) % v.len()]))
        .collect();
    crossings.sort_by(f64::total_cmp);
    crossings.push(1.0);
    let mut from = 0.0;
    for t in crossings {
        let mid = 0.5 * (from + t);
        let p = [a[0] + mid * (b[0] - a[0]), a[1] + mid * (b[1] - a[1])];
        if inside_polygon(v, p) != inclusion {
            return Some(from);
        }
        from = t;
    }
    (inside_polygon(v, b) != inclusion).then_some(1.0)
}

/// How far along `a`-`b` it first leaves (`inclusion`) or enters the circle of centre `c` and
/// radius `r`.
fn circle_breach(c: [f64; 2], r: f64, inclusion: bool, a: [f64; 2], b: [f64; 2]) -> Option<f64> {
    let inside = |p: [f64; 2]| (p[0] - c[0]).hypot(p[1] - c[1]) <= r;
    if inside(a) != inclusion {
        return Some(0.0);
    }
    // |a + t d - c| = r: t^2 |d|^2 + 2 t d.(a - c) + |a - c|^2 - r^2 = 0.
    let d = [b[0] - a[0], b[1] - a[1]];
    let e = [a[0] - c[0], a[1] - c[1]];
    let qa = d[0] * d[0] + d[1] * d[1];
    let qb = 2.0 * (d[0] * e[0] + d[1] * e[1]);
    let qc = e[0] * e[0] + e[1] * e[1] - r * r;
    let disc = qb * qb - 4.0 * qa * qc;
    if qa <= 0.0 || disc <= 0.0 {
        return None;
    }
    let root = disc.sqrt();
    // Inside an inclusion circle the stretch leaves at the larger root; outside an exclusion
    // circle it enters at the smaller one.
    let t = match inclusion {
        true => (-qb + root) / (2.0 * qa),
        false => (-qb - root) / (2.0 * qa),
    };
    (t > 0.0 && t < 1.0)
        .then_some(t)
        .filter(|_| !inclusion || !inside(b))
}

/// Whether `q` is inside the polygon `v` (even-odd rule) or on its edge.
fn inside_polygon(v: &[[f64; 2]], q: [f64; 2]) -> bool {
    let on_edge = (0..v.len()).any(|k| to_segment_m(q, v[k], v[(k + 1) % v.len()]) < 1e-6);
    on_edge || inside(v, q)
}

/// Where along `a`-`b` it crosses the segment `p`-`n` (0 to 1), if it does.
fn crossing(a: [f64; 2], b: [f64; 2], p: [f64; 2], n: [f64; 2]) -> Option<f64> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let e = [n[0] - p[0], n[1] - p[1]];
    let den = d[0] * e[1] - d[1] * e[0];
    if den == 0.0 {
        return None;
    }
    let w = [p[0] - a[0], p[1] - a[1]];
    let t = (w[0] * e[1] - w[1] * e[0]) / den;
    let u = (w[0] * d[1] - w[1] * d[0]) / den;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then_some(t)
}

/// The object when it is a version 2 one.
fn version_2(v: &Value) -> Option<&Map<String, Value>> {
    let o = v.as_object()?;
    (o.get("version").and_then(Value::as_u64) == Some(2)).then_some(o)
}

/// The entries of the list `key` of `object` (none when absent), each read by `read`.
fn list<T>(
    object: &Map<String, Value>,
    parent: &str,
    key: &str,
    read: fn(&Value, &str) -> Result<T, ImportError>,
) -> Result<Vec<T>, ImportError> {
    let name = format!("{parent}.{key}");
    match object.get(key) {
        None => Ok(Vec::new()),
        Some(Value::Array(entries)) => entries
            .iter()
            .enumerate()
            .map(|(k, e)| read(e, &format!("{name}[{k}]")))
            .collect(),
        Some(other) => Err(bad_key(Place::File, None, &name, other, "a list")),
    }
}

/// `{"inclusion": bool, "polygon": [[lat, lon], ...]}`: at least three vertices.
fn polygon(v: &Value, name: &str) -> Result<FencePolygon, ImportError> {
    let inclusion = inclusion(v, name)?;
    let key = format!("{name}.polygon");
    let vertices = match v.get("polygon") {
        Some(Value::Array(points)) if points.len() >= 3 => points
            .iter()
            .enumerate()
            .map(|(k, p)| lat_lon(p, &format!("{key}[{k}]")))
            .collect::<Result<Vec<_>, _>>()?,
        other => {
            return Err(bad_key(
                Place::File,
                None,
                &key,
                other.unwrap_or(&Value::Null),
                "a list of at least three [latitude, longitude] points",
            ))
        }
    };
    Ok(FencePolygon {
        inclusion,
        vertices,
    })
}

/// `{"inclusion": bool, "circle": {"center": [lat, lon], "radius": r_m}}`.
fn circle(v: &Value, name: &str) -> Result<FenceCircle, ImportError> {
    let inclusion = inclusion(v, name)?;
    let key = format!("{name}.circle");
    let Some(c) = v.get("circle").and_then(Value::as_object) else {
        return Err(bad_key(
            Place::File,
            None,
            &key,
            v.get("circle").unwrap_or(&Value::Null),
            "an object with center and radius",
        ));
    };
    let centre = lat_lon(
        c.get("center").unwrap_or(&Value::Null),
        &format!("{key}.center"),
    )?;
    let radius = c.get("radius").unwrap_or(&Value::Null);
    let radius_m = match radius.as_f64() {
        Some(r) if r.is_finite() && r > 0.0 => r,
        _ => {
            return Err(bad_key(
                Place::File,
                None,
                &format!("{key}.radius"),
                radius,
                "a radius in m, positive and finite",
            ))
        }
    };
    Ok(FenceCircle {
        inclusion,
        centre,
        radius_m,
    })
}

/// `[lat, lon, alt_m]`.
fn rally_point(v: &Value, name: &str) -> Result<RallyPoint, ImportError> {
    let position = lat_lon(v, name)?;
    let altitude = v.get(2).unwrap_or(&Value::Null);
    match altitude.as_f64().filter(|a| a.is_finite()) {
        Some(altitude_m) => Ok(RallyPoint {
            position,
            altitude_m,
        }),
        None => Err(bad_key(
            Place::File,
            None,
            &format!("{name}[2]"),
            altitude,
            "an altitude in m above home",
        )),
    }
}

/// The fence's `inclusion`, a boolean.
fn inclusion(v: &Value, name: &str) -> Result<bool, ImportError> {
    let found = v.get("inclusion").unwrap_or(&Value::Null);
    found.as_bool().ok_or_else(|| {
        bad_key(
            Place::File,
            None,
            &format!("{name}.inclusion"),
            found,
            "true (inclusion) or false (exclusion)",
        )
    })
}

/// `[lat, lon, ...]` with a latitude in [-90, 90] and a longitude in [-180, 180].
fn lat_lon(v: &Value, name: &str) -> Result<LatLon, ImportError> {
    let latitude = v.get(0).and_then(Value::as_f64);
    let longitude = v.get(1).and_then(Value::as_f64);
    match (latitude, longitude) {
        (Some(la), Some(lo)) if (-90.0..=90.0).contains(&la) && (-180.0..=180.0).contains(&lo) => {
            Ok(LatLon::new(la, lo))
        }
        _ => Err(bad_key(
            Place::File,
            None,
            name,
            v,
            "[latitude, longitude] in degrees",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn root(text: &str) -> Map<String, Value> {
        serde_json::from_str(text).unwrap()
    }

    /// A 100 m square inclusion fence and a 10 m exclusion circle at (50, 50): a stretch across
    /// the square's east side leaves it at x = 100 (0.5 of the way from 50 to 150); one through
    /// the circle's centre from (20, 50) to (80, 50) enters it at x = 40 (a third of the way); one
    /// inside and clear of both holds; one that starts outside breaches at its start; a stretch
    /// along the edge is inside.
    #[test]
    fn a_stretch_breaches_where_it_leaves_or_enters_a_fence() {
        let frame = LocalFrame::new(47.0, 8.0);
        let deg = |e: f64, n: f64| {
            let [la, lo] = frame.to_lat_lon_deg(e, n);
            LatLon::new(la, lo)
        };
        let airspace = Airspace {
            polygons: vec![FencePolygon {
                inclusion: true,
                vertices: vec![
                    deg(0.0, 0.0),
                    deg(100.0, 0.0),
                    deg(100.0, 100.0),
                    deg(0.0, 100.0),
                ],
            }],
            circles: vec![FenceCircle {
                inclusion: false,
                centre: deg(50.0, 50.0),
                radius_m: 10.0,
            }],
            ..Airspace::default()
        };
        let fence = airspace.local(&frame);
        let b = fence.first_breach([50.0, 20.0], [150.0, 20.0]).unwrap();
        assert!((b.fraction - 0.5).abs() < 1e-6, "{b:?}");
        assert!((b.at_m[0] - 100.0).abs() < 1e-4 && b.leaves, "{b:?}");
        assert_eq!(b.fence, "inclusion polygon 1");
        let c = fence.first_breach([20.0, 50.0], [80.0, 50.0]).unwrap();
        assert!((c.fraction - 1.0 / 3.0).abs() < 1e-6, "{c:?}");
        assert_eq!(c.fence, "exclusion circle 1");
        assert!(!c.leaves);
        assert_eq!(fence.first_breach([10.0, 10.0], [90.0, 20.0]), None);
        let out = fence.first_breach([-5.0, 10.0], [10.0, 10.0]).unwrap();
        assert!(out.fraction.abs() < 1e-12);
        assert_eq!(fence.first_breach([0.0, 10.0], [0.0, 90.0]), None);
    }

    /// A concave "U" inclusion fence: a stretch from one arm to the other, both ends inside,
    /// leaves it across the notch (at x = 10 of a stretch from x = 5 to x = 25: a quarter).
    /// An exclusion polygon crossed right through (both ends outside) is entered at its edge.
    #[test]
    fn a_stretch_with_both_ends_inside_a_concave_fence_can_still_leave_it() {
        let u = vec![
            [0.0, 0.0],
            [30.0, 0.0],
            [30.0, 30.0],
            [20.0, 30.0],
            [20.0, 10.0],
            [10.0, 10.0],
            [10.0, 30.0],
            [0.0, 30.0],
        ];
        assert_eq!(
            polygon_breach(&u, true, [5.0, 20.0], [25.0, 20.0]),
            Some(0.25)
        );
        assert_eq!(polygon_breach(&u, true, [5.0, 5.0], [25.0, 5.0]), None);
        let square = vec![[40.0, 0.0], [50.0, 0.0], [50.0, 10.0], [40.0, 10.0]];
        let t = polygon_breach(&square, false, [30.0, 5.0], [60.0, 5.0]).unwrap();
        assert!((t - 1.0 / 3.0).abs() < 1e-12, "{t}");
    }

    /// QGroundControl's own shapes: an inclusion polygon, an exclusion circle, a rally point; the
    /// objects written back are the file's, `breachReturn` included.
    #[test]
    fn a_fence_and_rally_points_are_read_and_kept_as_given() {
        let r = root(
            r#"{"geoFence": {"version": 2, "breachReturn": [47.1, 8.1, 30],
                 "polygons": [{"inclusion": true, "version": 1,
                               "polygon": [[47.0, 8.0], [47.0, 8.01], [47.01, 8.01], [47.01, 8.0]]}],
                 "circles": [{"inclusion": false, "version": 1,
                              "circle": {"center": [47.005, 8.005], "radius": 25.5}}]},
                "rallyPoints": {"version": 2, "points": [[47.002, 8.003, 40.0]]}}"#,
        );
        let a = Airspace::read(&r).unwrap();
        assert_eq!(a.polygons.len(), 1);
        assert!(a.polygons[0].inclusion);
        assert_eq!(a.polygons[0].vertices.len(), 4);
        assert_eq!(a.polygons[0].vertices[2], LatLon::new(47.01, 8.01));
        assert_eq!(a.circles.len(), 1);
        assert!(!a.circles[0].inclusion);
        assert_eq!(a.circles[0].centre, LatLon::new(47.005, 8.005));
        assert!((a.circles[0].radius_m - 25.5).abs() < 1e-12);
        assert_eq!(a.rally_points.len(), 1);
        assert!((a.rally_points[0].altitude_m - 40.0).abs() < 1e-12);
        assert_eq!(a.geo_fence_json(), r["geoFence"]);
        assert_eq!(a.rally_points_json(), r["rallyPoints"]);
        assert!(!a.is_empty());
    }

    /// No fence (absent, empty, version 1 as older QGroundControl wrote, empty lists): the empty
    /// version 2 objects are written.
    #[test]
    fn without_a_fence_the_empty_objects_are_written() {
        for text in [
            r#"{}"#,
            r#"{"geoFence": {}, "rallyPoints": {}}"#,
            r#"{"geoFence": {"version": 1, "polygon": []}, "rallyPoints": {"version": 1, "points": []}}"#,
            r#"{"geoFence": {"version": 2, "circles": [], "polygons": []}, "rallyPoints": {"version": 2, "points": []}}"#,
        ] {
            let a = Airspace::read(&root(text)).unwrap();
            assert!(a.is_empty(), "{text}");
            assert_eq!(
                a.geo_fence_json(),
                json!({"version": 2, "circles": [], "polygons": []})
            );
            assert_eq!(a.rally_points_json(), json!({"version": 2, "points": []}));
        }
    }

    /// Each malformed value is refused naming its key.
    #[test]
    fn a_malformed_fence_names_its_key() {
        let cases = [
            (
                r#"{"geoFence": {"version": 2, "polygons": [{"inclusion": true, "polygon": [[47, 8], [47, 8.1]]}]}}"#,
                "geoFence.polygons[0].polygon",
            ),
            (
                r#"{"geoFence": {"version": 2, "polygons": [{"inclusion": true, "polygon": [[47, 8], [47, 8.1], [95, 8]]}]}}"#,
                "geoFence.polygons[0].polygon[2]",
            ),
            (
                r#"{"geoFence": {"version": 2, "polygons": [{"polygon": [[47, 8], [47, 8.1], [47.1, 8]]}]}}"#,
                "geoFence.polygons[0].inclusion",
            ),
            (
                r#"{"geoFence": {"version": 2, "circles": [{"inclusion": true, "circle": {"center": [47, 8], "radius": -3}}]}}"#,
                "geoFence.circles[0].circle.radius",
            ),
            (
                r#"{"geoFence": {"version": 2, "circles": "none"}}"#,
                "geoFence.circles",
            ),
            (
                r#"{"rallyPoints": {"version": 2, "points": [[47, 8]]}}"#,
                "rallyPoints.points[0][2]",
            ),
        ];
        for (text, key) in cases {
            let e = Airspace::read(&root(text)).unwrap_err().to_string();
            assert!(e.contains(key), "{text}: {e}");
        }
    }
}
