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
//! A `geoFence` of another version (QGroundControl's version 1 had no polygons list) or an empty
//! object holds no fence; the writer then writes the empty version 2 objects that QGroundControl
//! and MAVSDK require.

use serde_json::{json, Map, Value};

use crate::error::{ImportError, Place};
use crate::geo::LatLon;
use crate::plan::bad_key;

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
