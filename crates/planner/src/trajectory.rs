//! Trajectory pieces and their closed-form kinematics: position, ground velocity and acceleration
//! at any time, in east-north-up (ENU) metres.
//!
//! A mission compiles into pieces, each flown from rest to rest along its path with a trapezoidal
//! speed profile (constant acceleration `a` up to the cruise speed `v`, cruise, constant
//! deceleration), or triangular when the path is too short to reach `v`:
//!
//! - [`Shape::Line`]: a straight path (legs, take-off, descent, landing);
//! - [`Shape::Arc`]: a circle at constant height (orbits); the acceleration adds the centripetal
//!   `v^2 / r` towards the centre to the tangential `dv/dt`;
//! - [`Shape::Hold`]: a fixed point for a time (hover, and the yaw turn at a waypoint).
//!
//! Stopping at every waypoint is the planner's choice (a multirotor's "stop and turn" waypoint
//! mode): it makes every speed change cost time and the thrust of the acceleration, and keeps the
//! path exactly the mission's polyline.

/// Path geometry of one piece.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Straight line from `start_m` along the unit vector `dir`.
    Line {
        /// Start point, ENU m.
        start_m: [f64; 3],
        /// Unit direction, ENU.
        dir: [f64; 3],
    },
    /// Circle of radius `radius_m` about `centre_m` at height `up_m`, starting at angle `phi0_rad`
    /// (from east, anticlockwise); `sign` +1 anticlockwise, -1 clockwise seen from above.
    Arc {
        /// Centre, east and north, m.
        centre_m: [f64; 2],
        /// Radius, m.
        radius_m: f64,
        /// Height above home, m.
        up_m: f64,
        /// Start angle from east, anticlockwise, rad.
        phi0_rad: f64,
        /// +1 anticlockwise, -1 clockwise.
        sign: f64,
    },
    /// Fixed point.
    Hold {
        /// Position, ENU m.
        pos_m: [f64; 3],
    },
}

/// Trapezoidal speed profile along a path of length `length_m`, from rest to rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    /// Path length, m.
    pub length_m: f64,
    /// Peak speed reached, m/s.
    pub peak_mps: f64,
    /// Acceleration magnitude, m/s^2.
    pub accel_mps2: f64,
    /// End of the acceleration phase, s.
    pub t_accel_end_s: f64,
    /// End of the cruise phase, s.
    pub t_cruise_end_s: f64,
    /// Total duration, s.
    pub duration_s: f64,
}

impl Profile {
    /// Rest-to-rest profile over `length_m` with cruise speed `speed_mps` and acceleration
    /// `accel_mps2` (all positive, validated by the caller).
    pub fn rest_to_rest(length_m: f64, speed_mps: f64, accel_mps2: f64) -> Self {
        if length_m <= 0.0 {
            return Self::hold(0.0);
        }
        let (peak, t1, t2) = if length_m >= speed_mps * speed_mps / accel_mps2 {
            let t1 = speed_mps / accel_mps2;
            (speed_mps, t1, t1 + (length_m - speed_mps * t1) / speed_mps)
        } else {
            let peak = (accel_mps2 * length_m).sqrt();
            let t1 = peak / accel_mps2;
            (peak, t1, t1)
        };
        Self {
            length_m,
            peak_mps: peak,
            accel_mps2,
            t_accel_end_s: t1,
            t_cruise_end_s: t2,
            duration_s: t2 + t1,
        }
    }

    /// No motion for `duration_s`.
    pub fn hold(duration_s: f64) -> Self {
        Self {
            length_m: 0.0,
            peak_mps: 0.0,
            accel_mps2: 0.0,
            t_accel_end_s: 0.0,
            t_cruise_end_s: duration_s,
            duration_s,
        }
    }

    /// Path length `s`, speed `v` and tangential acceleration at time `t_s` in `[0, duration]`.
    #[inline]
    pub fn at(&self, t_s: f64) -> (f64, f64, f64) {
        let a = self.accel_mps2;
        if t_s < self.t_accel_end_s {
            (0.5 * a * t_s * t_s, a * t_s, a)
        } else if t_s < self.t_cruise_end_s {
            let s1 = 0.5 * self.peak_mps * self.t_accel_end_s;
            (
                s1 + self.peak_mps * (t_s - self.t_accel_end_s),
                self.peak_mps,
                0.0,
            )
        } else {
            let tau = (t_s - self.t_cruise_end_s).min(self.t_accel_end_s);
            let s2 = self.length_m - 0.5 * self.peak_mps * self.t_accel_end_s;
            (
                s2 + self.peak_mps * tau - 0.5 * a * tau * tau,
                self.peak_mps - a * tau,
                -a,
            )
        }
    }
}

/// Kinematic state at one instant, ENU.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Kinematics {
    /// Position, m.
    pub pos_m: [f64; 3],
    /// Ground velocity, m/s.
    pub vel_mps: [f64; 3],
    /// Acceleration, m/s^2.
    pub acc_mps2: [f64; 3],
    /// Unit horizontal direction of travel (the heading along the track), east and north.
    pub forward: [f64; 2],
}

/// One piece of a compiled mission.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// Geometry.
    pub shape: Shape,
    /// Speed profile.
    pub profile: Profile,
    /// Index of the mission segment this piece belongs to (from 0).
    pub segment: usize,
    /// Index of the mass phase (payload changes start a new one).
    pub mass_phase: usize,
    /// Heading to hold when the path gives none (vertical lines, holds), east and north.
    pub forward: [f64; 2],
}

impl Piece {
    /// Kinematics at time `t_s` from the start of the piece.
    #[inline]
    pub fn at(&self, t_s: f64) -> Kinematics {
        let (s, v, at) = self.profile.at(t_s);
        match self.shape {
            Shape::Line { start_m, dir } => Kinematics {
                pos_m: [
                    start_m[0] + dir[0] * s,
                    start_m[1] + dir[1] * s,
                    start_m[2] + dir[2] * s,
                ],
                vel_mps: [dir[0] * v, dir[1] * v, dir[2] * v],
                acc_mps2: [dir[0] * at, dir[1] * at, dir[2] * at],
                forward: self.forward,
            },
            Shape::Arc {
                centre_m,
                radius_m,
                up_m,
                phi0_rad,
                sign,
            } => {
                let phi = phi0_rad + sign * s / radius_m;
                // libm's sincos (musl's kernels) is about twice as fast as std's, within 1 ulp.
                let (sp, cp) = libm::sincos(phi);
                // Unit tangent in the direction of travel, and the centripetal term towards the centre.
                let tx = -sign * sp;
                let ty = sign * cp;
                let ac = v * v / radius_m;
                Kinematics {
                    pos_m: [
                        centre_m[0] + radius_m * cp,
                        centre_m[1] + radius_m * sp,
                        up_m,
                    ],
                    vel_mps: [tx * v, ty * v, 0.0],
                    acc_mps2: [tx * at - ac * cp, ty * at - ac * sp, 0.0],
                    forward: [tx, ty],
                }
            }
            Shape::Hold { pos_m } => Kinematics {
                pos_m,
                vel_mps: [0.0; 3],
                acc_mps2: [0.0; 3],
                forward: self.forward,
            },
        }
    }

    /// Duration, s.
    pub fn duration_s(&self) -> f64 {
        self.profile.duration_s
    }

    /// Position at the end of the piece.
    pub fn end_m(&self) -> [f64; 3] {
        self.at(self.profile.duration_s).pos_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_covers_the_length_and_ends_at_rest() {
        for (l, v, a) in [(100.0, 8.0, 2.0), (5.0, 8.0, 2.0), (16.0, 8.0, 2.0)] {
            let p = Profile::rest_to_rest(l, v, a);
            let (s, vv, _) = p.at(p.duration_s);
            // closed form: exact to rounding
            assert!((s - l).abs() < 1e-9 && vv.abs() < 1e-9, "{l} {s} {vv}");
            assert!(p.peak_mps <= v + 1e-12);
        }
        // 100 m at 8 m/s, 2 m/s^2: 4 s (16 m) up, 4 s (16 m) down, 68 m / 8 = 8.5 s cruise
        let p = Profile::rest_to_rest(100.0, 8.0, 2.0);
        assert!((p.duration_s - 16.5).abs() < 1e-12);
    }

    #[test]
    fn arc_acceleration_is_centripetal_at_cruise() {
        let piece = Piece {
            shape: Shape::Arc {
                centre_m: [10.0, -5.0],
                radius_m: 25.0,
                up_m: 30.0,
                phi0_rad: 0.3,
                sign: -1.0,
            },
            profile: Profile::rest_to_rest(500.0, 5.0, 1.0),
            segment: 0,
            mass_phase: 0,
            forward: [0.0, 1.0],
        };
        let k = piece.at(20.0);
        let r = [k.pos_m[0] - 10.0, k.pos_m[1] + 5.0];
        assert!((r[0].hypot(r[1]) - 25.0).abs() < 1e-9);
        // acceleration points to the centre with magnitude v^2/r = 1 m/s^2
        let a = k.acc_mps2;
        assert!((a[0].hypot(a[1]) - 1.0).abs() < 1e-12);
        assert!((a[0] * r[0] + a[1] * r[1]) < 0.0);
        // velocity is tangent: clockwise means r x v points down
        let cross = r[0] * k.vel_mps[1] - r[1] * k.vel_mps[0];
        assert!(cross < 0.0);
    }
}
