//! Distances along the ground: the haversine on the sphere of the mean Earth radius.
//!
//! aloft-missions measures legs on the WGS-84 ellipsoid (Vincenty), but this crate depends on
//! aloft-core only; the sphere differs from the ellipsoid by at most 0.5 % of a leg's length
//! (about 0.2 % at mid-latitudes), and a path's clearance is found where it is, whatever its
//! length: only the reported `distance_m` of that place carries the difference.

/// Mean Earth radius (IUGG, `(2a + b) / 3`), m.
pub const MEAN_RADIUS_M: f64 = 6_371_008.8;

/// Great-circle distance between two points on the sphere of [`MEAN_RADIUS_M`] (haversine), m.
pub fn haversine_m(from: (f64, f64), to: (f64, f64)) -> f64 {
    let (p1, p2) = (from.0.to_radians(), to.0.to_radians());
    let dp = p2 - p1;
    let dl = (to.1 - from.1).to_radians();
    let h = (dp / 2.0).sin().powi(2) + p1.cos() * p2.cos() * (dl / 2.0).sin().powi(2);
    2.0 * MEAN_RADIUS_M * h.clamp(0.0, 1.0).sqrt().asin()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_degree_of_latitude_and_of_longitude_at_60_degrees() {
        // pi R / 180 = 111,195.08 m; along the 60th parallel the great circle between two
        // points 1 deg apart is a little shorter than half of that (the parallel's own length).
        let deg = std::f64::consts::PI * MEAN_RADIUS_M / 180.0;
        assert!((haversine_m((44.0, -72.0), (45.0, -72.0)) - deg).abs() < 1e-6);
        let d = haversine_m((60.0, 0.0), (60.0, 1.0));
        assert!(d < deg / 2.0 && d > deg / 2.0 - 5.0, "{d}");
        assert!(haversine_m((44.0, -72.0), (44.0, -72.0)).abs() < 1e-12);
    }
}
