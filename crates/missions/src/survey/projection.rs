//! The plane of the survey algorithm, and Qt's sphere.
//!
//! QGroundControl projects the polygon onto a plane tangent at its first vertex
//! (`QGCGeo.cc` `convertGeoToNed` / `convertNedToGeo`) and has done so three ways; which one
//! drew a file decides where its lines are. The grid starts 1000 m beyond the polygon's box in
//! plane metres, so a plane scaled by 0.1 % (the two spheres) moves the lines by about 0.1 % of
//! 1 km plus the polygon's size: 1.8 m (1.6e-5 deg) on the shared survey. The turnaround and
//! hover points are placed with `QGeoCoordinate` (Qt's sphere of 6371.0072 km) in every
//! version.

use crate::geo::LatLon;

/// WGS-84 semi-major axis, m.
const A_M: f64 = 6_378_137.0;
/// WGS-84 flattening.
const F: f64 = 1.0 / 298.257_223_563;
/// WGS-84 first eccentricity squared.
const E2: f64 = F * (2.0 - F);
/// QGroundControl's `CONSTANTS_RADIUS_OF_EARTH`, m.
const QGC_RADIUS_M: f64 = 6_371_000.0;
/// Qt's `qgeocoordinate_EARTH_MEAN_RADIUS`, m (`QGeoCoordinate` distances and azimuths).
const QT_RADIUS_M: f64 = 6_371_007.2;

/// The tangent-plane projection of a QGroundControl version (`QGCGeo.cc`, by its history).
///
/// Which release carries which could not be read from the source history alone (the mirror
/// has no tags); the dates are those of the commits on QGroundControl's master branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum QgcProjection {
    /// Azimuthal equidistant on a sphere of 6 371 000 m: master until 2024-03 (commit
    /// `dacd3c2b4`), the releases up to v4.3. The shared survey `neilvaltec_test.plan` was
    /// drawn with it (reproduced to the last bit).
    #[default]
    SphereMean,
    /// Azimuthal equidistant on a sphere of the WGS-84 semi-major axis, 6 378 137 m: master from
    /// 2024-03 to 2026-01.
    SphereEquatorial,
    /// GeographicLib `LocalCartesian` on the WGS-84 ellipsoid (east-north-up through
    /// earth-centred coordinates, height 0): master since 2026-01 (commit `e42a131e4`).
    LocalCartesian,
}

/// A point of the tangent plane, m: x east, y north.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Xy {
    /// East, m.
    pub(crate) x: f64,
    /// North, m.
    pub(crate) y: f64,
}

/// The polygon in the plane tangent at its first vertex (which is (0, 0) exactly, as
/// QGroundControl sets it).
pub(crate) fn to_plane(polygon: &[LatLon], projection: QgcProjection) -> Vec<Xy> {
    let origin = polygon[0];
    let mut plane = vec![Xy::default()];
    plane.extend(polygon[1..].iter().map(|p| forward(*p, origin, projection)));
    plane
}

/// `p` in the plane tangent at `origin`, m.
pub(crate) fn forward(p: LatLon, origin: LatLon, projection: QgcProjection) -> Xy {
    match projection {
        QgcProjection::SphereMean => sphere_forward(p, origin, QGC_RADIUS_M),
        QgcProjection::SphereEquatorial => sphere_forward(p, origin, A_M),
        QgcProjection::LocalCartesian => local_cartesian_forward(p, origin),
    }
}

/// The point at `xy` of the plane tangent at `origin`.
pub(crate) fn reverse(xy: Xy, origin: LatLon, projection: QgcProjection) -> LatLon {
    match projection {
        QgcProjection::SphereMean => sphere_reverse(xy, origin, QGC_RADIUS_M),
        QgcProjection::SphereEquatorial => sphere_reverse(xy, origin, A_M),
        QgcProjection::LocalCartesian => local_cartesian_reverse(xy, origin),
    }
}

/// Area of a plane polygon (shoelace, either orientation), m^2.
pub(crate) fn area_m2(plane: &[Xy]) -> f64 {
    let n = plane.len();
    let twice: f64 = (0..n)
        .map(|k| {
            let (a, b) = (plane[k], plane[(k + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum();
    twice.abs() / 2.0
}

/// Azimuthal equidistant projection on a sphere of `radius_m` (`convertGeoToNed` before 2026).
/// The arc cosine's argument is kept within [-1, 1] (rounding near the tangent point).
fn sphere_forward(p: LatLon, origin: LatLon, radius_m: f64) -> Xy {
    if p == origin {
        return Xy::default();
    }
    let (lat, lon) = (p.latitude_deg.to_radians(), p.longitude_deg.to_radians());
    let (lat0, lon0) = (
        origin.latitude_deg.to_radians(),
        origin.longitude_deg.to_radians(),
    );
    let (sin_lat, cos_lat) = lat.sin_cos();
    let cos_dlon = (lon - lon0).cos();
    let (sin_lat0, cos_lat0) = lat0.sin_cos();
    let c = (sin_lat0 * sin_lat + cos_lat0 * cos_lat * cos_dlon)
        .clamp(-1.0, 1.0)
        .acos();
    let k = if c.abs() < f64::EPSILON {
        1.0
    } else {
        c / c.sin()
    };
    Xy {
        x: k * cos_lat * (lon - lon0).sin() * radius_m,
        y: k * (cos_lat0 * sin_lat - sin_lat0 * cos_lat * cos_dlon) * radius_m,
    }
}

/// The inverse of [`sphere_forward`] (`convertNedToGeo` before 2026).
fn sphere_reverse(xy: Xy, origin: LatLon, radius_m: f64) -> LatLon {
    let (x_rad, y_rad) = (xy.y / radius_m, xy.x / radius_m); // north, east
    let c = (x_rad * x_rad + y_rad * y_rad).sqrt();
    let (sin_c, cos_c) = c.sin_cos();
    let (lat0, lon0) = (
        origin.latitude_deg.to_radians(),
        origin.longitude_deg.to_radians(),
    );
    let (sin_lat0, cos_lat0) = lat0.sin_cos();
    let (lat, lon) = if c.abs() > f64::EPSILON {
        (
            (cos_c * sin_lat0 + (x_rad * sin_c * cos_lat0) / c).asin(),
            lon0 + (y_rad * sin_c).atan2(c * cos_lat0 * cos_c - x_rad * sin_lat0 * sin_c),
        )
    } else {
        (lat0, lon0)
    };
    LatLon {
        latitude_deg: lat.to_degrees(),
        longitude_deg: lon.to_degrees(),
    }
}

/// Earth-centred, earth-fixed coordinates of a point at height 0 on the WGS-84 ellipsoid, m.
fn ecef_m(p: LatLon) -> [f64; 3] {
    let (sin_lat, cos_lat) = p.latitude_deg.to_radians().sin_cos();
    let (sin_lon, cos_lon) = p.longitude_deg.to_radians().sin_cos();
    let n = A_M / (1.0 - E2 * sin_lat * sin_lat).sqrt();
    [
        n * cos_lat * cos_lon,
        n * cos_lat * sin_lon,
        n * (1.0 - E2) * sin_lat,
    ]
}

/// The rows of the rotation from earth-centred axes to east, north, up at `origin`.
fn enu_rows(origin: LatLon) -> [[f64; 3]; 3] {
    let (sin_lat, cos_lat) = origin.latitude_deg.to_radians().sin_cos();
    let (sin_lon, cos_lon) = origin.longitude_deg.to_radians().sin_cos();
    [
        [-sin_lon, cos_lon, 0.0],
        [-sin_lat * cos_lon, -sin_lat * sin_lon, cos_lat],
        [cos_lat * cos_lon, cos_lat * sin_lon, sin_lat],
    ]
}

/// GeographicLib `LocalCartesian::Forward` at height 0 (east and north kept).
fn local_cartesian_forward(p: LatLon, origin: LatLon) -> Xy {
    let (a, o) = (ecef_m(p), ecef_m(origin));
    let d = [a[0] - o[0], a[1] - o[1], a[2] - o[2]];
    let r = enu_rows(origin);
    let dot = |row: [f64; 3]| row[0] * d[0] + row[1] * d[1] + row[2] * d[2];
    Xy {
        x: dot(r[0]),
        y: dot(r[1]),
    }
}

/// GeographicLib `LocalCartesian::Reverse` of (east, north, up 0): the point of the tangent
/// plane, then its latitude and longitude on the ellipsoid.
fn local_cartesian_reverse(xy: Xy, origin: LatLon) -> LatLon {
    let (o, r) = (ecef_m(origin), enu_rows(origin));
    let ecef: [f64; 3] = std::array::from_fn(|k| o[k] + r[0][k] * xy.x + r[1][k] * xy.y);
    geodetic(ecef)
}

/// Latitude and longitude of earth-centred coordinates (Bowring's iteration to convergence:
/// within 1e-14 deg of GeographicLib's closed form for the heights of a tangent plane a few
/// kilometres across).
fn geodetic(ecef: [f64; 3]) -> LatLon {
    let [x, y, z] = ecef;
    let p = x.hypot(y);
    let mut lat = z.atan2(p * (1.0 - E2));
    for _ in 0..8 {
        let sin_lat = lat.sin();
        let n = A_M / (1.0 - E2 * sin_lat * sin_lat).sqrt();
        let h = p / lat.cos() - n;
        lat = z.atan2(p * (1.0 - E2 * n / (n + h)));
    }
    LatLon {
        latitude_deg: lat.to_degrees(),
        longitude_deg: y.atan2(x).to_degrees(),
    }
}

/// `QGeoCoordinate::distanceTo`: haversine on Qt's sphere, m.
pub(crate) fn qt_distance_m(a: LatLon, b: LatLon) -> f64 {
    let dlat = (b.latitude_deg - a.latitude_deg).to_radians();
    let dlon = (b.longitude_deg - a.longitude_deg).to_radians();
    let h_lat = (dlat / 2.0).sin().powi(2);
    let h_lon = (dlon / 2.0).sin().powi(2);
    let y = h_lat + a.latitude_deg.to_radians().cos() * b.latitude_deg.to_radians().cos() * h_lon;
    2.0 * y.sqrt().asin() * QT_RADIUS_M
}

/// `QGeoCoordinate::azimuthTo`: initial great-circle azimuth, deg in [0, 360).
pub(crate) fn qt_azimuth_deg(a: LatLon, b: LatLon) -> f64 {
    let dlon = (b.longitude_deg - a.longitude_deg).to_radians();
    let (lat1, lat2) = (a.latitude_deg.to_radians(), b.latitude_deg.to_radians());
    let y = dlon.sin() * lat2.cos();
    let x = lat1.cos() * lat2.sin() - lat1.sin() * lat2.cos() * dlon.cos();
    let azimuth = y.atan2(x).to_degrees() + 360.0;
    let whole = azimuth.trunc();
    (whole + 360.0).rem_euclid(360.0) + (azimuth - whole)
}

/// `QGeoCoordinate::atDistanceAndAzimuth`: the point `distance_m` from `a` along the great
/// circle of initial azimuth `azimuth_deg` (a negative distance goes the other way).
pub(crate) fn qt_at(a: LatLon, distance_m: f64, azimuth_deg: f64) -> LatLon {
    let (sin_lat, cos_lat) = a.latitude_deg.to_radians().sin_cos();
    let azimuth = azimuth_deg.to_radians();
    let ratio = distance_m / QT_RADIUS_M;
    let (sin_r, cos_r) = ratio.sin_cos();
    let lat = (sin_lat * cos_r + cos_lat * sin_r * azimuth.cos()).asin();
    let lon = a.longitude_deg.to_radians()
        + (azimuth.sin() * sin_r * cos_lat).atan2(cos_r - sin_lat * lat.sin());
    let mut longitude_deg = lon.to_degrees();
    if longitude_deg > 180.0 {
        longitude_deg -= 360.0;
    } else if longitude_deg < -180.0 {
        longitude_deg += 360.0;
    }
    LatLon {
        latitude_deg: lat.to_degrees(),
        longitude_deg,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(latitude_deg: f64, longitude_deg: f64) -> LatLon {
        LatLon::new(latitude_deg, longitude_deg)
    }

    /// Forward then reverse returns the point. The spheres' projections are exact inverses:
    /// 1e-12 deg (0.1 um) is rounding. QGroundControl's `LocalCartesian` reverse drops the
    /// up coordinate (about -d^2 / 2R, 0.9 m at 3.4 km) and keeps the latitude and longitude of
    /// the point so raised, which lies about d^3 / 2R^2 (0.5 mm, 4e-9 deg) off the original:
    /// 1e-8 deg.
    #[test]
    fn every_projection_round_trips() {
        let origin = p(47.3, 8.5);
        for (projection, tolerance_deg) in [
            (QgcProjection::SphereMean, 1e-12),
            (QgcProjection::SphereEquatorial, 1e-12),
            (QgcProjection::LocalCartesian, 1e-8),
        ] {
            for q in [p(47.31, 8.52), p(47.28, 8.47), p(47.3, 8.5), p(47.33, 8.5)] {
                let back = reverse(forward(q, origin, projection), origin, projection);
                let d = (back.latitude_deg - q.latitude_deg)
                    .abs()
                    .max((back.longitude_deg - q.longitude_deg).abs());
                assert!(d < tolerance_deg, "{projection:?} {q:?} {d}");
            }
        }
    }

    /// The local-Cartesian plane against the geodesic (`geo.rs`, Vincenty): a point 2 km away
    /// lies at its geodesic distance within 1 mm (the plane's departure from the ellipsoid is
    /// of order d^3 / R^2, 0.2 um here, plus Vincenty's sub-millimetre).
    #[test]
    fn local_cartesian_distances_are_geodesic_distances() {
        let origin = p(25.05, 121.55);
        let q = p(25.062, 121.563);
        let xy = forward(q, origin, QgcProjection::LocalCartesian);
        let d = crate::geo::distance_m(origin, q);
        assert!((xy.x.hypot(xy.y) - d).abs() < 1e-3, "{xy:?} {d}");
    }

    /// Qt's sphere: 1 deg of latitude is R pi / 180; the azimuth east is 90; a negative distance
    /// goes backwards. 1e-9: rounding.
    #[test]
    fn qt_sphere_helpers_agree_with_the_sphere() {
        let a = p(10.0, 20.0);
        let d = qt_distance_m(a, p(11.0, 20.0));
        assert!((d - QT_RADIUS_M * 1f64.to_radians()).abs() < 1e-6, "{d}");
        assert!((qt_azimuth_deg(a, p(10.0, 20.1)) - 90.0).abs() < 0.01);
        assert!((qt_azimuth_deg(a, p(9.9, 20.0)) - 180.0).abs() < 1e-9);
        let back = qt_at(a, -1000.0, 0.0);
        assert!((qt_distance_m(a, back) - 1000.0).abs() < 1e-6);
        assert!(back.latitude_deg < a.latitude_deg);
    }
}
