//! Frame conversions: NED and ENU vectors, attitude quaternions of both conventions, geodetic to
//! local ENU.
//!
//! Conventions:
//! - aloft's [`Attitude`] is the aerospace Z-Y-X Euler set of the body frame FRD (x forward,
//!   y right, z down) relative to NED.
//! - PX4 quaternions (`vehicle_attitude.q`, w,x,y,z) rotate FRD body vectors into NED.
//! - ROS quaternions (REP-103) rotate FLU body vectors (x forward, y left, z up) into ENU.
//!
//! With `P` the ENU<->NED axis swap and `F = diag(1, -1, -1)` the FLU<->FRD flip,
//! `R_ned_frd = P R_enu_flu F` (both `P` and `F` are their own inverses).

use crate::sample::{Attitude, GeoOrigin};

/// A 3x3 rotation matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// NED vector to ENU.
pub fn ned_to_enu(v: [f64; 3]) -> [f64; 3] {
    [v[1], v[0], -v[2]]
}

/// ENU vector to NED (the same swap).
pub fn enu_to_ned(v: [f64; 3]) -> [f64; 3] {
    [v[1], v[0], -v[2]]
}

/// Rotation matrix of a unit quaternion `(w, x, y, z)` (Hamilton, active: body to world).
/// The quaternion is normalised first; a zero quaternion gives `None`.
pub fn quat_to_mat(q: [f64; 4]) -> Option<Mat3> {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if !(n.is_finite() && n > 1e-9) {
        return None;
    }
    let [w, x, y, z] = [q[0] / n, q[1] / n, q[2] / n, q[3] / n];
    Some([
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ])
}

/// Unit quaternion `(w, x, y, z)` of a rotation matrix (Shepperd's method), with `w >= 0`.
pub fn mat_to_quat(r: &Mat3) -> [f64; 4] {
    let tr = r[0][0] + r[1][1] + r[2][2];
    let q = if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        [
            0.25 * s,
            (r[2][1] - r[1][2]) / s,
            (r[0][2] - r[2][0]) / s,
            (r[1][0] - r[0][1]) / s,
        ]
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt() * 2.0;
        [
            (r[2][1] - r[1][2]) / s,
            0.25 * s,
            (r[0][1] + r[1][0]) / s,
            (r[0][2] + r[2][0]) / s,
        ]
    } else if r[1][1] > r[2][2] {
        let s = (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt() * 2.0;
        [
            (r[0][2] - r[2][0]) / s,
            (r[0][1] + r[1][0]) / s,
            0.25 * s,
            (r[1][2] + r[2][1]) / s,
        ]
    } else {
        let s = (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt() * 2.0;
        [
            (r[1][0] - r[0][1]) / s,
            (r[0][2] + r[2][0]) / s,
            (r[1][2] + r[2][1]) / s,
            0.25 * s,
        ]
    };
    if q[0] < 0.0 {
        [-q[0], -q[1], -q[2], -q[3]]
    } else {
        q
    }
}

/// `a b`.
pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut c = [[0.0; 3]; 3];
    for (i, row) in c.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// `r v`.
pub fn mat_vec(r: &Mat3, v: [f64; 3]) -> [f64; 3] {
    [
        r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
        r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
        r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2],
    ]
}

/// ENU <-> NED axis swap `P`.
const P: Mat3 = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]];
/// FLU <-> FRD flip `F`.
const F: Mat3 = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];

/// Aerospace Euler angles of a body-FRD-to-NED rotation matrix.
pub fn mat_ned_frd_to_euler(r: &Mat3) -> Attitude {
    Attitude {
        roll_rad: r[2][1].atan2(r[2][2]),
        pitch_rad: (-r[2][0]).clamp(-1.0, 1.0).asin(),
        yaw_rad: r[1][0].atan2(r[0][0]),
    }
}

/// Body-FRD-to-NED rotation matrix of aerospace Euler angles: `Rz(yaw) Ry(pitch) Rx(roll)`.
pub fn euler_to_mat_ned_frd(a: &Attitude) -> Mat3 {
    let (sr, cr) = a.roll_rad.sin_cos();
    let (sp, cp) = a.pitch_rad.sin_cos();
    let (sy, cy) = a.yaw_rad.sin_cos();
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// Attitude from a PX4-style quaternion `(w, x, y, z)`, body FRD to NED.
pub fn attitude_from_ned_frd_quat(q: [f64; 4]) -> Option<Attitude> {
    quat_to_mat(q).map(|r| mat_ned_frd_to_euler(&r))
}

/// Body-FRD-to-NED matrix of a ROS quaternion `(w, x, y, z)` (body FLU to ENU).
pub fn ros_quat_to_mat_ned_frd(q: [f64; 4]) -> Option<Mat3> {
    quat_to_mat(q).map(|r| mat_mul(&mat_mul(&P, &r), &F))
}

/// Attitude from a ROS quaternion `(w, x, y, z)`, body FLU to ENU.
pub fn attitude_from_enu_flu_quat(q: [f64; 4]) -> Option<Attitude> {
    ros_quat_to_mat_ned_frd(q).map(|r| mat_ned_frd_to_euler(&r))
}

/// ROS quaternion `(w, x, y, z)` (body FLU to ENU) of an attitude; what Foxglove displays.
pub fn attitude_to_enu_flu_quat(a: &Attitude) -> [f64; 4] {
    let r = euler_to_mat_ned_frd(a);
    mat_to_quat(&mat_mul(&mat_mul(&P, &r), &F))
}

/// WGS84 semi-major axis, m.
const WGS84_A_M: f64 = 6_378_137.0;
/// WGS84 first eccentricity squared.
const WGS84_E2: f64 = 6.694_379_990_14e-3;

/// Local ENU position of a geodetic point relative to `origin`, by the tangent-plane
/// (equirectangular) approximation with the WGS84 meridian and prime-vertical radii at the origin.
/// The error grows with the square of the distance: below 1 m within 10 km.
pub fn geodetic_to_enu(origin: &GeoOrigin, lat_rad: f64, lon_rad: f64, alt_m: f64) -> [f64; 3] {
    let s = origin.lat_rad.sin();
    let w = (1.0 - WGS84_E2 * s * s).sqrt();
    let n = WGS84_A_M / w; // prime vertical radius
    let m = WGS84_A_M * (1.0 - WGS84_E2) / (w * w * w); // meridian radius
    [
        (lon_rad - origin.lon_rad) * (n + origin.alt_m) * origin.lat_rad.cos(),
        (lat_rad - origin.lat_rad) * (m + origin.alt_m),
        alt_m - origin.alt_m,
    ]
}

/// The geodetic point of a local ENU position relative to `origin`: the inverse of
/// [`geodetic_to_enu`] (latitude and longitude in rad, altitude in m).
pub fn enu_to_geodetic(origin: &GeoOrigin, enu_m: [f64; 3]) -> (f64, f64, f64) {
    let s = origin.lat_rad.sin();
    let w = (1.0 - WGS84_E2 * s * s).sqrt();
    let n = WGS84_A_M / w;
    let m = WGS84_A_M * (1.0 - WGS84_E2) / (w * w * w);
    (
        origin.lat_rad + enu_m[1] / (m + origin.alt_m),
        origin.lon_rad + enu_m[0] / ((n + origin.alt_m) * origin.lat_rad.cos()),
        origin.alt_m + enu_m[2],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn enu_to_geodetic_inverts_geodetic_to_enu() {
        let origin = GeoOrigin {
            lat_rad: 36.37_f64.to_radians(),
            lon_rad: 127.36_f64.to_radians(),
            alt_m: 60.0,
        };
        let (lat, lon, alt) = enu_to_geodetic(&origin, [812.5, -301.25, 42.0]);
        let back = geodetic_to_enu(&origin, lat, lon, alt);
        for (a, b) in back.iter().zip([812.5, -301.25, 42.0]) {
            assert!((a - b).abs() < 1e-9, "{back:?}");
        }
    }

    // Angles are recovered to 1e-9 rad: well above the f64 rounding of a few trig calls.
    const TOL: f64 = 1e-9;

    #[test]
    fn level_north_is_ros_yaw_ninety_degrees() {
        let a = Attitude {
            roll_rad: 0.0,
            pitch_rad: 0.0,
            yaw_rad: 0.0,
        };
        let q = attitude_to_enu_flu_quat(&a);
        // Rotation of +90 deg about ENU z: (cos 45, 0, 0, sin 45).
        let h = std::f64::consts::FRAC_1_SQRT_2;
        for (got, want) in q.iter().zip([h, 0.0, 0.0, h]) {
            assert!((got - want).abs() < TOL, "{q:?}");
        }
    }

    #[test]
    fn ros_round_trip_of_euler() {
        for &(r, p, y) in &[(0.1, -0.2, 0.3), (-0.5, 0.4, -2.9), (0.0, 1.2, FRAC_PI_2)] {
            let a = Attitude {
                roll_rad: r,
                pitch_rad: p,
                yaw_rad: y,
            };
            let b = attitude_from_enu_flu_quat(attitude_to_enu_flu_quat(&a)).unwrap();
            assert!((a.roll_rad - b.roll_rad).abs() < TOL);
            assert!((a.pitch_rad - b.pitch_rad).abs() < TOL);
            assert!((a.yaw_rad - b.yaw_rad).abs() < TOL);
            let c = attitude_from_ned_frd_quat(mat_to_quat(&euler_to_mat_ned_frd(&a))).unwrap();
            assert!((a.yaw_rad - c.yaw_rad).abs() < TOL);
        }
    }

    #[test]
    fn positive_pitch_raises_the_nose_in_enu() {
        // Heading east (yaw 90 deg), nose up 0.3 rad: the body x axis in ENU points east and up.
        let a = Attitude {
            roll_rad: 0.0,
            pitch_rad: 0.3,
            yaw_rad: FRAC_PI_2,
        };
        let q = attitude_to_enu_flu_quat(&a);
        let r = quat_to_mat(q).unwrap();
        let nose = mat_vec(&r, [1.0, 0.0, 0.0]);
        assert!((nose[0] - 0.3f64.cos()).abs() < TOL);
        assert!(nose[1].abs() < TOL);
        assert!((nose[2] - 0.3f64.sin()).abs() < TOL);
    }

    #[test]
    fn geodetic_one_milliradian_north_is_about_6_4_km() {
        let o = GeoOrigin {
            lat_rad: 0.634769,
            lon_rad: 2.223,
            alt_m: 0.0,
        };
        let p = geodetic_to_enu(&o, o.lat_rad + 1e-3, o.lon_rad, 10.0);
        // Meridian radius near 36 deg N is about 6.357e6 m: 1 mrad is 6357 m (+-5 m).
        assert!((p[1] - 6357.0).abs() < 5.0, "{p:?}");
        assert!(p[0].abs() < TOL);
        assert!((p[2] - 10.0).abs() < TOL);
    }
}
