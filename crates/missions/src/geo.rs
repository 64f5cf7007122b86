//! Distances between latitude/longitude points, one leg at a time, on the WGS-84 ellipsoid.
//!
//! Vincenty's inverse formula (T. Vincenty, "Direct and inverse solutions of geodesics on the
//! ellipsoid with application of nested equations", Survey Review 23(176), 1975, eqs 13-18 and
//! the iteration of section 4): sub-millimetre on any leg a multirotor flies. It does not
//! converge for nearly antipodal points (beyond any multirotor's range); there, the great circle
//! on the sphere of the mean Earth radius is used (within 0.5 % of the ellipsoid).
//!
//! Each leg is measured on its own, so a survey hundreds of kilometres from its home point is
//! measured as accurately as one beside it (one flat frame at home would not be).

/// WGS-84 semi-major axis, m.
const A_M: f64 = 6_378_137.0;
/// WGS-84 flattening.
const F: f64 = 1.0 / 298.257_223_563;
/// WGS-84 semi-minor axis, m.
const B_M: f64 = A_M * (1.0 - F);
/// Mean Earth radius (IUGG, `(2a + b) / 3`), m: the sphere of the fallback.
pub const MEAN_RADIUS_M: f64 = 6_371_008.8;

/// A point on the ellipsoid, degrees (validated by the caller: finite, |lat| <= 90).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatLon {
    /// Latitude, deg.
    pub latitude_deg: f64,
    /// Longitude, deg.
    pub longitude_deg: f64,
}

impl LatLon {
    /// The point at `latitude_deg`, `longitude_deg`.
    pub fn new(latitude_deg: f64, longitude_deg: f64) -> Self {
        Self {
            latitude_deg,
            longitude_deg,
        }
    }
}

/// Length of the geodesic from `a` to `b` on the WGS-84 ellipsoid, m.
pub fn distance_m(a: LatLon, b: LatLon) -> f64 {
    if a == b {
        return 0.0;
    }
    vincenty_m(a, b).unwrap_or_else(|| great_circle_m(a, b))
}

/// Great-circle distance on the sphere of [`MEAN_RADIUS_M`] (haversine), m.
pub fn great_circle_m(a: LatLon, b: LatLon) -> f64 {
    let (p1, p2) = (a.latitude_deg.to_radians(), b.latitude_deg.to_radians());
    let dp = p2 - p1;
    let dl = (b.longitude_deg - a.longitude_deg).to_radians();
    let h = (dp / 2.0).sin().powi(2) + p1.cos() * p2.cos() * (dl / 2.0).sin().powi(2);
    2.0 * MEAN_RADIUS_M * h.clamp(0.0, 1.0).sqrt().asin()
}

/// Vincenty's inverse; `None` when the iteration does not converge (nearly antipodal points).
fn vincenty_m(a: LatLon, b: LatLon) -> Option<f64> {
    let u1 = ((1.0 - F) * a.latitude_deg.to_radians().tan()).atan();
    let u2 = ((1.0 - F) * b.latitude_deg.to_radians().tan()).atan();
    let l = wrap_pi((b.longitude_deg - a.longitude_deg).to_radians());
    let (su1, cu1, su2, cu2) = (u1.sin(), u1.cos(), u2.sin(), u2.cos());
    let mut lambda = l;
    for _ in 0..200 {
        let (sl, cl) = lambda.sin_cos();
        let sin_sigma = ((cu2 * sl).powi(2) + (cu1 * su2 - su1 * cu2 * cl).powi(2)).sqrt();
        if sin_sigma == 0.0 {
            return Some(0.0); // coincident points
        }
        let cos_sigma = su1 * su2 + cu1 * cu2 * cl;
        let sigma = sin_sigma.atan2(cos_sigma);
        let sin_alpha = cu1 * cu2 * sl / sin_sigma;
        let cos2_alpha = 1.0 - sin_alpha * sin_alpha;
        // On the equator cos^2(alpha) = 0 and the term vanishes.
        let cos_2sm = if cos2_alpha > 0.0 {
            cos_sigma - 2.0 * su1 * su2 / cos2_alpha
        } else {
            0.0
        };
        let c = F / 16.0 * cos2_alpha * (4.0 + F * (4.0 - 3.0 * cos2_alpha));
        let previous = lambda;
        lambda = l
            + (1.0 - c)
                * F
                * sin_alpha
                * (sigma
                    + c * sin_sigma * (cos_2sm + c * cos_sigma * (-1.0 + 2.0 * cos_2sm * cos_2sm)));
        if (lambda - previous).abs() < 1e-12 {
            return Some(ellipsoid_length_m(
                cos2_alpha, sigma, sin_sigma, cos_sigma, cos_2sm,
            ));
        }
    }
    None
}

/// The geodesic's length from the converged auxiliary angles (Vincenty eqs 3, 4, 6, 19).
fn ellipsoid_length_m(
    cos2_alpha: f64,
    sigma: f64,
    sin_sigma: f64,
    cos_sigma: f64,
    cos_2sm: f64,
) -> f64 {
    let u2 = cos2_alpha * (A_M * A_M - B_M * B_M) / (B_M * B_M);
    let big_a = 1.0 + u2 / 16384.0 * (4096.0 + u2 * (-768.0 + u2 * (320.0 - 175.0 * u2)));
    let big_b = u2 / 1024.0 * (256.0 + u2 * (-128.0 + u2 * (74.0 - 47.0 * u2)));
    let delta_sigma = big_b
        * sin_sigma
        * (cos_2sm
            + big_b / 4.0
                * (cos_sigma * (-1.0 + 2.0 * cos_2sm * cos_2sm)
                    - big_b / 6.0
                        * cos_2sm
                        * (-3.0 + 4.0 * sin_sigma * sin_sigma)
                        * (-3.0 + 4.0 * cos_2sm * cos_2sm)));
    B_M * big_a * (sigma - delta_sigma)
}

/// An angle in (-pi, pi].
fn wrap_pi(x: f64) -> f64 {
    let t = x.rem_euclid(std::f64::consts::TAU);
    if t > std::f64::consts::PI {
        t - std::f64::consts::TAU
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(latitude_deg: f64, longitude_deg: f64) -> LatLon {
        LatLon::new(latitude_deg, longitude_deg)
    }

    /// Vincenty's own test line (Survey Review 1975, and Geoscience Australia's worked example):
    /// Flinders Peak to Buninyong, 54 972.271 m. 1 mm: the published figure's last digit.
    #[test]
    fn flinders_peak_to_buninyong_is_vincentys_figure() {
        let flinders = p(
            -(37.0 + 57.0 / 60.0 + 3.72030 / 3600.0),
            144.0 + 25.0 / 60.0 + 29.52440 / 3600.0,
        );
        let buninyong = p(
            -(37.0 + 39.0 / 60.0 + 10.15610 / 3600.0),
            143.0 + 55.0 / 60.0 + 35.38390 / 3600.0,
        );
        let d = distance_m(flinders, buninyong);
        assert!((d - 54_972.271).abs() < 1e-3, "{d}");
    }

    /// One degree of longitude on the equator is a / 360 x 2 pi (the equator is a circle of
    /// radius a); 1 um: rounding only.
    #[test]
    fn a_degree_on_the_equator_is_the_semi_major_axis_arc() {
        let d = distance_m(p(0.0, 10.0), p(0.0, 11.0));
        assert!((d - A_M * 1f64.to_radians()).abs() < 1e-6, "{d}");
        // Across the antimeridian the short way.
        let e = distance_m(p(0.0, 179.5), p(0.0, -179.5));
        assert!((e - A_M * 1f64.to_radians()).abs() < 1e-6, "{e}");
    }

    /// Nearly antipodal points fall back to the sphere; the result is finite and close to half
    /// the meridian (20 004 km), within the sphere's 0.5 %.
    #[test]
    fn antipodes_fall_back_to_the_great_circle() {
        let d = distance_m(p(0.0, 0.0), p(0.5, 179.7));
        assert!(d.is_finite());
        assert!((d / 20_004_000.0 - 1.0).abs() < 5e-3, "{d}");
        assert!(distance_m(p(45.0, 7.0), p(45.0, 7.0)).abs() < 1e-12);
    }

    /// Sphere and ellipsoid agree within 0.5 % on short legs at any latitude.
    #[test]
    fn sphere_and_ellipsoid_agree_on_short_legs() {
        for lat in [-80.0, -35.0, 0.0, 25.0, 55.0, 85.0] {
            let (a, b) = (p(lat, 10.0), p(lat + 0.003, 10.004));
            let (e, s) = (distance_m(a, b), great_circle_m(a, b));
            assert!((e / s - 1.0).abs() < 5e-3, "{lat}: {e} {s}");
        }
    }
}
