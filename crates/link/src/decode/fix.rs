//! Which positions the decoder believes: a fix must be on the Earth and within reach of the last
//! one believed.
//!
//! A MAVLink position is whatever its sender wrote: GLOBAL_POSITION_INT holds latitudes to
//! 214.7 deg (`i32::MAX` x 1e-7), altitudes to 2,147 km, and a GPS or EKF glitch can move the
//! vehicle by kilometres between two messages. Believed, such a fix puts the vehicle out of
//! reach of home and turns the advice to `land now`. So a fix is taken in two steps:
//!
//! 1. **On the Earth**: latitude within +-90 deg, longitude within +-180 deg,
//!    altitude above sea level within [`MIN_ALT_AMSL_M`] to [`MAX_ALT_AMSL_M`], height above home
//!    within +-[`MAX_RELATIVE_ALT_M`]; else the message is dropped at decode.
//! 2. **Within reach**: no further from the last fix believed than
//!    [`MAX_SPEED_MPS`] times the time between them plus [`FIX_SLACK_M`]; else it is a glitch,
//!    dropped too. The first fix of a flight becomes the origin (and home, until the vehicle
//!    sends one) only once the next fix agrees with it, so a bad first fix is replaced by the
//!    next instead of anchoring the flight.
//!
//! A home (HOME_POSITION) must be on the Earth too, and within [`MAX_HOME_DISTANCE_M`] of the
//! vehicle's believed position.

use aloft_logs::sample::GeoOrigin;
use mavlink::dialects::ardupilotmega::GLOBAL_POSITION_INT_DATA;

/// Degrees of a MAVLink `1e7 deg` integer.
pub(crate) const DEG_E7: f64 = 1e-7;

/// The fastest a believed fix may move from the last one, m/s.
///
/// aloft's own models take airspeeds up to 150 m/s (the power model's and the airframe's
/// limit); the fastest multirotor on record, a purpose-built racer, flew at 133 m/s (480 km/h,
/// 2024), and survey and delivery multirotors fly below 25 m/s. A fix that implies more than
/// 150 m/s over ground (the bound also holds the wind and the fastest record with room) is not
/// a flight but a glitch: the 214.7 deg latitude of a corrupt message, a GPS jump of kilometres.
pub const MAX_SPEED_MPS: f64 = 150.0;

/// How far two fixes may be apart whatever the time between them, m: GPS noise and a switch
/// of the position source move a fix by metres, and on a live link messages delayed in the
/// network arrive together (a burst of five fixes at 5 Hz of a vehicle at 20 m/s spans 20 m).
pub const FIX_SLACK_M: f64 = 30.0;

/// The lowest altitude above mean sea level a fix may have, m (the shore of the Dead Sea is at
/// -430 m; aloft's missions take a home from -500 m).
pub const MIN_ALT_AMSL_M: f64 = -500.0;

/// The highest altitude above mean sea level a fix may have, m (multirotors have flown over
/// Everest, 8,849 m; airliners cruise at 12 km).
pub const MAX_ALT_AMSL_M: f64 = 12_000.0;

/// The largest height above (or below) home a fix may have, m.
pub const MAX_RELATIVE_ALT_M: f64 = 10_000.0;

/// The farthest a home may be from the vehicle, m: a multirotor flies an hour at most, at 20 m/s
/// 72 km there and back, so it is never 100 km from its home; a home that far is a glitch.
pub const MAX_HOME_DISTANCE_M: f64 = 100_000.0;

/// Mean radius of the Earth, m (IUGG): the great-circle distance between fixes is within 0.5 %
/// of the ellipsoid's, which the bounds above do not need better.
const EARTH_RADIUS_M: f64 = 6_371_008.8;

/// A position fix on the Earth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Fix {
    /// Stream time of the fix, s.
    pub time_s: f64,
    pub lat_rad: f64,
    pub lon_rad: f64,
    /// Altitude above mean sea level, m.
    pub alt_m: f64,
    /// Height above home, m.
    pub relative_m: f64,
}

impl Fix {
    /// The fix of GLOBAL_POSITION_INT at `time_s`, `None` where it is not on the Earth (see the
    /// module docs). Latitude and longitude both 0 mean "no fix": the caller tells them apart.
    pub(crate) fn new(time_s: f64, p: &GLOBAL_POSITION_INT_DATA) -> Option<Self> {
        let (lat_deg, lon_deg) = (f64::from(p.lat) * DEG_E7, f64::from(p.lon) * DEG_E7);
        let alt_m = f64::from(p.alt) / 1000.0;
        let relative_m = f64::from(p.relative_alt) / 1000.0;
        let on_earth = on_earth(lat_deg, lon_deg, alt_m)
            && relative_m.abs() <= MAX_RELATIVE_ALT_M
            && time_s.is_finite();
        on_earth.then(|| Self {
            time_s,
            lat_rad: lat_deg.to_radians(),
            lon_rad: lon_deg.to_radians(),
            alt_m,
            relative_m,
        })
    }

    /// The fix as an origin of ENU positions.
    pub(crate) fn origin(&self) -> GeoOrigin {
        GeoOrigin {
            lat_rad: self.lat_rad,
            lon_rad: self.lon_rad,
            alt_m: self.alt_m,
        }
    }
}

/// Whether a latitude and longitude (deg) and an altitude above sea level (m) are on the Earth
/// as a multirotor flies it.
pub(crate) fn on_earth(lat_deg: f64, lon_deg: f64, alt_m: f64) -> bool {
    lat_deg.abs() <= 90.0
        && lon_deg.abs() <= 180.0
        && (MIN_ALT_AMSL_M..=MAX_ALT_AMSL_M).contains(&alt_m)
}

/// Great-circle distance between two points (rad), m, by the haversine formula (exact on the
/// sphere, well conditioned for small distances, across the antimeridian as anywhere).
pub(crate) fn ground_distance_m(lat1: f64, lon1: f64, lat2: f64, lon2: f64) -> f64 {
    let a = ((lat2 - lat1) / 2.0).sin().powi(2)
        + lat1.cos() * lat2.cos() * ((lon2 - lon1) / 2.0).sin().powi(2);
    2.0 * EARTH_RADIUS_M * a.sqrt().min(1.0).asin()
}

/// Whether `next` is within reach of `last`: the distance between them (over ground and in
/// height above home) is at most [`MAX_SPEED_MPS`] times the time between them plus
/// [`FIX_SLACK_M`].
pub(crate) fn reachable(last: &Fix, next: &Fix) -> bool {
    let ground_m = ground_distance_m(last.lat_rad, last.lon_rad, next.lat_rad, next.lon_rad);
    let distance_m = ground_m.hypot(next.relative_m - last.relative_m);
    let dt_s = (next.time_s - last.time_s).max(0.0);
    distance_m <= MAX_SPEED_MPS * dt_s + FIX_SLACK_M
}

/// A velocity (ENU, m/s) a multirotor can have: every component finite, the speed at most
/// [`MAX_SPEED_MPS`].
pub(crate) fn plausible_velocity(v: [f64; 3]) -> bool {
    let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    speed.is_finite() && speed <= MAX_SPEED_MPS
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gpi(lat: i32, lon: i32, alt: i32, relative_alt: i32) -> GLOBAL_POSITION_INT_DATA {
        GLOBAL_POSITION_INT_DATA {
            lat,
            lon,
            alt,
            relative_alt,
            ..GLOBAL_POSITION_INT_DATA::default()
        }
    }

    #[test]
    fn fixes_off_the_earth_are_refused() {
        // The edges are on the Earth.
        assert!(Fix::new(
            0.0,
            &gpi(900_000_000, 1_800_000_000, 12_000_000, 10_000_000)
        )
        .is_some());
        assert!(Fix::new(
            0.0,
            &gpi(-900_000_000, -1_800_000_000, -500_000, -10_000_000)
        )
        .is_some());
        for p in [
            gpi(i32::MAX, 85_456_000, 0, 0),
            gpi(900_000_001, 0, 0, 0),
            gpi(0, 1_800_000_001, 0, 0),
            gpi(0, i32::MIN, 0, 0),
            gpi(473_977_000, 85_456_000, 12_000_001, 0),
            gpi(473_977_000, 85_456_000, -500_001, 0),
            gpi(473_977_000, 85_456_000, 0, 10_000_001),
            gpi(473_977_000, 85_456_000, 0, i32::MIN),
        ] {
            assert_eq!(Fix::new(0.0, &p), None, "{p:?}");
        }
        assert_eq!(Fix::new(f64::NAN, &gpi(1, 1, 0, 0)), None);
    }

    /// Distances against values computed by hand on the sphere of radius 6,371,008.8 m: a degree
    /// of latitude is R pi / 180 = 111,195.08 m; a degree of longitude at 60 deg is half of it;
    /// a step across the antimeridian at the equator (179.9999 to -179.9999 deg) is 0.0002 deg.
    #[test]
    fn ground_distances_on_the_sphere() {
        let deg = std::f64::consts::PI / 180.0;
        let one_deg_m = EARTH_RADIUS_M * deg;
        assert!((one_deg_m - 111_195.08).abs() < 0.01);
        assert!((ground_distance_m(0.0, 0.0, deg, 0.0) - one_deg_m).abs() < 1e-6);
        let d = ground_distance_m(60.0 * deg, 0.0, 60.0 * deg, deg);
        // Along the parallel is a little longer than the great circle: 1e-4 relative covers it.
        assert!((d / (0.5 * one_deg_m) - 1.0).abs() < 1e-4, "{d}");
        let across = ground_distance_m(0.0, 179.9999 * deg, 0.0, -179.9999 * deg);
        assert!((across - 0.0002 * one_deg_m).abs() < 1e-3, "{across}");
    }

    #[test]
    fn reach_grows_with_time_at_the_bound() {
        let at = |time_s: f64, north_m: f64, up_m: f64| Fix {
            time_s,
            lat_rad: north_m / EARTH_RADIUS_M,
            lon_rad: 0.0,
            alt_m: 0.0,
            relative_m: up_m,
        };
        let start = at(0.0, 0.0, 0.0);
        // 1 s: 150 m + 30 m of slack; 10 s: 1,530 m.
        assert!(reachable(&start, &at(1.0, 179.0, 0.0)));
        assert!(!reachable(&start, &at(1.0, 181.0, 0.0)));
        assert!(reachable(&start, &at(10.0, 1_529.0, 0.0)));
        assert!(!reachable(&start, &at(10.0, 1_000.0, 1_200.0)));
        // At the same instant, the slack alone; an earlier time counts as the same instant.
        assert!(reachable(&start, &at(0.0, 29.0, 0.0)));
        assert!(!reachable(&start, &at(-5.0, 31.0, 0.0)));
        assert!(plausible_velocity([100.0, 100.0, 0.0]));
        assert!(!plausible_velocity([150.0, 0.0, 1.0]));
        assert!(!plausible_velocity([f64::NAN, 0.0, 0.0]));
    }
}
