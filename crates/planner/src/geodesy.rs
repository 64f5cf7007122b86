//! Latitude/longitude to a local east-north frame at the home point.
//!
//! Local tangent plane, small-distance form: `east = (lon - lon0) cos(lat0) N(lat0)`,
//! `north = (lat - lat0) M(lat0)` with the WGS-84 radii of curvature in the prime vertical `N` and
//! the meridian `M`. The error grows with the square of the distance from home (of the order of
//! 1 m at 10 km at mid latitudes); missions of a multirotor stay well inside that.
//!
//! Heights are not converted: mission altitudes are heights above the home point (flat ground).

/// WGS-84 semi-major axis, m.
const WGS84_A_M: f64 = 6_378_137.0;
/// WGS-84 first eccentricity squared.
const WGS84_E2: f64 = 6.694_379_990_14e-3;

/// A local east-north frame anchored at a latitude and longitude.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFrame {
    lat0_rad: f64,
    lon0_rad: f64,
    m_per_rad_east: f64,
    m_per_rad_north: f64,
}

impl LocalFrame {
    /// The frame at `latitude_deg`, `longitude_deg` (validated by the caller: finite, |lat| < 90).
    pub fn new(latitude_deg: f64, longitude_deg: f64) -> Self {
        let lat = latitude_deg.to_radians();
        let s2 = lat.sin().powi(2);
        let w = (1.0 - WGS84_E2 * s2).sqrt();
        let n = WGS84_A_M / w;
        let m = WGS84_A_M * (1.0 - WGS84_E2) / (w * w * w);
        Self {
            lat0_rad: lat,
            lon0_rad: longitude_deg.to_radians(),
            m_per_rad_east: n * lat.cos(),
            m_per_rad_north: m,
        }
    }

    /// East and north of a point from the frame's origin, m.
    pub fn to_local_m(&self, latitude_deg: f64, longitude_deg: f64) -> [f64; 2] {
        let mut dlon = longitude_deg.to_radians() - self.lon0_rad;
        // Across the antimeridian.
        if dlon > std::f64::consts::PI {
            dlon -= std::f64::consts::TAU;
        } else if dlon < -std::f64::consts::PI {
            dlon += std::f64::consts::TAU;
        }
        [
            dlon * self.m_per_rad_east,
            (latitude_deg.to_radians() - self.lat0_rad) * self.m_per_rad_north,
        ]
    }

    /// Latitude and longitude of the point `east_m`, `north_m` from the frame's origin, deg: the
    /// inverse of [`LocalFrame::to_local_m`] (longitude wrapped into `[-180, 180)`).
    pub fn to_lat_lon_deg(&self, east_m: f64, north_m: f64) -> [f64; 2] {
        let lat = (self.lat0_rad + north_m / self.m_per_rad_north).to_degrees();
        let lon = (self.lon0_rad + east_m / self.m_per_rad_east).to_degrees();
        [lat, (lon + 180.0).rem_euclid(360.0) - 180.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_arc_minute_of_latitude_is_about_a_nautical_mile() {
        // 1' of latitude at 45 deg is 1852.2 m on WGS-84 (the nautical mile is defined as 1852 m).
        let f = LocalFrame::new(45.0, 7.0);
        let [e, n] = f.to_local_m(45.0 + 1.0 / 60.0, 7.0);
        assert!(e.abs() < 1e-9 && (n - 1852.2).abs() < 1.0, "{n}");
        // 1' of longitude at 45 deg: N cos(lat) / 60 in rad = 1314.0 m.
        let [e, _] = f.to_local_m(45.0, 7.0 + 1.0 / 60.0);
        assert!((e - 1314.0).abs() < 1.0, "{e}");
    }

    #[test]
    fn lat_lon_of_a_local_point_is_the_inverse_of_the_frame() {
        let f = LocalFrame::new(47.397_742, 8.545_594);
        for (lat, lon) in [(47.40, 8.55), (47.39, 8.54), (47.397_742, 8.545_594)] {
            let [e, n] = f.to_local_m(lat, lon);
            let [la, lo] = f.to_lat_lon_deg(e, n);
            assert!(
                (la - lat).abs() < 1e-12 && (lo - lon).abs() < 1e-12,
                "{la} {lo}"
            );
        }
        // Across the antimeridian: 1 km east of 179.999 deg is in the western hemisphere.
        let f = LocalFrame::new(0.0, 179.999);
        let [_, lo] = f.to_lat_lon_deg(1000.0, 0.0);
        assert!(lo < -179.99 && lo > -180.0, "{lo}");
    }
}
