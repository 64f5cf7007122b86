//! Trajectory pieces and their closed-form kinematics: position, ground velocity and acceleration
//! at any time, in east-north-up (ENU) metres.
//!
//! A mission compiles into pieces, each flown along its path with a trapezoidal speed profile
//! (constant acceleration `a` from the start speed up to the cruise speed `v`, cruise, constant
//! deceleration to the end speed), or triangular when the path is too short to reach `v`. Most
//! pieces run from rest to rest; the straight lines and arcs of a pass-through corner
//! (`mission/corners.rs`) start or end at the corner's speed:
//!
//! - [`Shape::Line`]: a straight path (legs, take-off, descent, landing);
//! - [`Shape::Arc`]: a circle at constant height (orbits); the acceleration adds the centripetal
//!   `v^2 / r` towards the centre to the tangential `dv/dt`;
//! - [`Shape::Hold`]: a fixed point for a time (hover, and the yaw turn at a waypoint).
//!
//! With `corners = "stop"` the vehicle stops at every waypoint (a multirotor's "stop and turn"
//! waypoint mode) and the path is exactly the mission's polyline; by default it passes through
//! waypoints without a hold on a circular arc (see `mission/corners.rs`).

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
    /// A circle at constant height.
    Arc(Circle),
    /// Fixed point.
    Hold {
        /// Position, ENU m.
        pos_m: [f64; 3],
    },
}

/// Circle of radius `radius_m` about `centre_m` at height `up_m`, starting at angle `phi0_rad`
/// (from east, anticlockwise); `sign` +1 anticlockwise, -1 clockwise seen from above.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    /// Centre, east and north, m.
    pub centre_m: [f64; 2],
    /// Radius, m.
    pub radius_m: f64,
    /// Height above home, m.
    pub up_m: f64,
    /// Start angle from east, anticlockwise, rad.
    pub phi0_rad: f64,
    /// +1 anticlockwise, -1 clockwise.
    pub sign: f64,
}

impl Circle {
    /// The point at the angle whose cosine and sine are `cp` and `sp`, ENU m.
    #[inline]
    pub fn point(&self, cp: f64, sp: f64) -> [f64; 3] {
        [
            self.centre_m[0] + self.radius_m * cp,
            self.centre_m[1] + self.radius_m * sp,
            self.up_m,
        ]
    }

    /// The unit tangent in the direction of travel at that angle, east and north.
    #[inline]
    pub fn tangent(&self, cp: f64, sp: f64) -> [f64; 2] {
        [-self.sign * sp, self.sign * cp]
    }
}

/// Trapezoidal speed profile along a path of length `length_m`: from `start_mps` up to the
/// peak, cruise, down to `end_mps` (both zero for a piece flown from rest to rest).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    /// Path length, m.
    pub length_m: f64,
    /// Speed at the start, m/s.
    pub start_mps: f64,
    /// Peak speed reached, m/s.
    pub peak_mps: f64,
    /// Speed at the end, m/s.
    pub end_mps: f64,
    /// Acceleration magnitude, m/s^2.
    pub accel_mps2: f64,
    /// End of the acceleration phase, s.
    pub t_accel_end_s: f64,
    /// End of the cruise phase, s.
    pub t_cruise_end_s: f64,
    /// Length of the deceleration phase, s.
    pub t_decel_s: f64,
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
            start_mps: 0.0,
            peak_mps: peak,
            end_mps: 0.0,
            accel_mps2,
            t_accel_end_s: t1,
            t_cruise_end_s: t2,
            t_decel_s: t1,
            duration_s: t2 + t1,
        }
    }

    /// Profile over `length_m` from `start_mps` to `end_mps` with cruise speed `speed_mps` and
    /// acceleration `accel_mps2`: the peak is the cruise speed, or (a triangle) the speed
    /// `sqrt((2 a L + v0^2 + v1^2) / 2)` where the path is too short to reach it. The caller
    /// keeps the end speeds reachable: `|v1^2 - v0^2| <= 2 a L` and both at most the cruise
    /// speed (within rounding; the profile clamps).
    pub fn between(
        length_m: f64,
        (start_mps, speed_mps, end_mps): (f64, f64, f64),
        accel_mps2: f64,
    ) -> Self {
        if start_mps <= 0.0 && end_mps <= 0.0 {
            return Self::rest_to_rest(length_m, speed_mps, accel_mps2);
        }
        if length_m <= 0.0 {
            return Self::hold(0.0);
        }
        let a = accel_mps2;
        let (v0, v1) = (start_mps.min(speed_mps), end_mps.min(speed_mps));
        let triangle = ((2.0 * a * length_m + v0 * v0 + v1 * v1) / 2.0).sqrt();
        let peak = speed_mps.min(triangle).max(v0).max(v1);
        let (t1, t3) = ((peak - v0) / a, (peak - v1) / a);
        let s_ramps = 0.5 * (v0 + peak) * t1 + 0.5 * (peak + v1) * t3;
        let cruise_s = ((length_m - s_ramps) / peak).max(0.0);
        Self {
            length_m,
            start_mps: v0,
            peak_mps: peak,
            end_mps: v1,
            accel_mps2: a,
            t_accel_end_s: t1,
            t_cruise_end_s: t1 + cruise_s,
            t_decel_s: t3,
            duration_s: t1 + cruise_s + t3,
        }
    }

    /// No motion for `duration_s`.
    pub fn hold(duration_s: f64) -> Self {
        Self {
            length_m: 0.0,
            start_mps: 0.0,
            peak_mps: 0.0,
            end_mps: 0.0,
            accel_mps2: 0.0,
            t_accel_end_s: 0.0,
            t_cruise_end_s: duration_s,
            t_decel_s: 0.0,
            duration_s,
        }
    }

    /// Path length `s`, speed `v` and tangential acceleration at time `t_s` in `[0, duration]`.
    ///
    /// With a start and end at rest (`v0 = v1 = 0`) every expression reduces to the rest-to-rest
    /// one bit for bit (`0 t + x = x`, `0 + x = x`).
    #[inline]
    pub fn at(&self, t_s: f64) -> (f64, f64, f64) {
        let a = self.accel_mps2;
        let v0 = self.start_mps;
        if t_s < self.t_accel_end_s {
            (v0 * t_s + 0.5 * a * t_s * t_s, v0 + a * t_s, a)
        } else if t_s < self.t_cruise_end_s {
            let s1 = 0.5 * (v0 + self.peak_mps) * self.t_accel_end_s;
            (
                s1 + self.peak_mps * (t_s - self.t_accel_end_s),
                self.peak_mps,
                0.0,
            )
        } else {
            let tau = (t_s - self.t_cruise_end_s).min(self.t_decel_s);
            let s2 = self.length_m - 0.5 * (self.peak_mps + self.end_mps) * self.t_decel_s;
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

impl Kinematics {
    /// All zero (the `Default`, usable in constants).
    pub const ZERO: Kinematics = Kinematics {
        pos_m: [0.0; 3],
        vel_mps: [0.0; 3],
        acc_mps2: [0.0; 3],
        forward: [0.0; 2],
    };
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
            Shape::Arc(c) => {
                let phi = c.phi0_rad + c.sign * s / c.radius_m;
                // libm's sincos (musl's kernels) is about twice as fast as std's, within 1 ulp.
                let (sp, cp) = libm::sincos(phi);
                // Unit tangent in the direction of travel, and the centripetal term towards the centre.
                let [tx, ty] = c.tangent(cp, sp);
                let ac = v * v / c.radius_m;
                Kinematics {
                    pos_m: c.point(cp, sp),
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

/// Samples a piece at the midpoints `(k + 1/2) h` of its steps, a block at a time.
///
/// Equal to [`Piece::at`] at every sample, except on the cruise of an arc: there the angle grows
/// by the same `delta = sign v h / r` each step, so the sample `j` of a block is the block's
/// first sample rotated by `j delta` (a table of `sincos(j delta)` made once per piece) instead
/// of a fresh `sincos` of an angle that reaches hundreds of radians on a long orbit. The
/// rotation agrees with `sincos` to a few units in the last place (tested below): about 1e-13 m
/// on a 300 m orbit.
#[derive(Debug, Clone)]
pub struct BlockSampler {
    piece: Piece,
    step_s: f64,
    /// `(cos, sin)` of `j delta`, when the piece is an arc with a cruise.
    rotation: Option<Vec<(f64, f64)>>,
}

impl BlockSampler {
    /// A sampler of `piece` at step `step_s`, for blocks of up to `block` samples.
    pub fn new(piece: &Piece, step_s: f64, block: usize) -> Self {
        let rotation = match piece.shape {
            Shape::Arc(c) if piece.profile.t_cruise_end_s > piece.profile.t_accel_end_s => {
                let delta = c.sign * piece.profile.peak_mps * step_s / c.radius_m;
                Some(
                    (0..block)
                        .map(|j| {
                            let (s, c) = libm::sincos(j as f64 * delta);
                            (c, s)
                        })
                        .collect(),
                )
            }
            _ => None,
        };
        Self {
            piece: *piece,
            step_s,
            rotation,
        }
    }

    /// Kinematics of steps `first, first + 1, ...` (one per element of `out`, at most the
    /// `block` given to [`Self::new`]).
    pub fn fill(&self, first: usize, out: &mut [Kinematics]) {
        let h = self.step_s;
        let p = &self.piece.profile;
        let t_first = (first as f64 + 0.5) * h;
        let t_last = ((first + out.len()) as f64 - 0.5) * h;
        if let (Some(rot), Shape::Arc(c)) = (&self.rotation, self.piece.shape) {
            if out.len() <= rot.len() && t_first >= p.t_accel_end_s && t_last < p.t_cruise_end_s {
                // The first sample as `Piece::at` computes it (the rotation by 0 is exact); the
                // rest rotated from it.
                let (s, v, _) = p.at(t_first);
                let (sp0, cp0) = libm::sincos(c.phi0_rad + c.sign * s / c.radius_m);
                let ac = v * v / c.radius_m;
                for (o, &(cj, sj)) in out.iter_mut().zip(rot) {
                    let cp = cp0 * cj - sp0 * sj;
                    let sp = sp0 * cj + cp0 * sj;
                    let [tx, ty] = c.tangent(cp, sp);
                    *o = Kinematics {
                        pos_m: c.point(cp, sp),
                        vel_mps: [tx * v, ty * v, 0.0],
                        acc_mps2: [-ac * cp, -ac * sp, 0.0],
                        forward: [tx, ty],
                    };
                }
                return;
            }
        }
        for (j, o) in out.iter_mut().enumerate() {
            *o = self.piece.at(((first + j) as f64 + 0.5) * h);
        }
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
            shape: Shape::Arc(Circle {
                centre_m: [10.0, -5.0],
                radius_m: 25.0,
                up_m: 30.0,
                phi0_rad: 0.3,
                sign: -1.0,
            }),
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

#[cfg(test)]
mod block_tests {
    use super::*;

    #[test]
    fn block_sampler_matches_piece_at_on_a_long_orbit() {
        // 3400 s of a 300 m orbit at 8 m/s: the angle reaches 90 rad.
        let piece = Piece {
            shape: Shape::Arc(Circle {
                centre_m: [600.0, 300.0],
                radius_m: 300.0,
                up_m: 40.0,
                phi0_rad: -1.5,
                sign: -1.0,
            }),
            profile: Profile::rest_to_rest(8.0 * 3400.0, 8.0, 2.0),
            segment: 0,
            mass_phase: 0,
            forward: [0.0, 1.0],
        };
        let n = (piece.duration_s() / 0.01).ceil() as usize;
        let h = piece.duration_s() / n as f64;
        let sampler = BlockSampler::new(&piece, h, 32);
        let mut out = [Kinematics::default(); 32];
        let mut k = 0;
        let mut worst = [0.0f64; 3];
        while k < n {
            let m = (n - k).min(32);
            sampler.fill(k, &mut out[..m]);
            for (j, got) in out[..m].iter().enumerate() {
                let want = piece.at(((k + j) as f64 + 0.5) * h);
                for c in 0..3 {
                    worst[0] = worst[0].max((got.pos_m[c] - want.pos_m[c]).abs());
                    worst[1] = worst[1].max((got.vel_mps[c] - want.vel_mps[c]).abs());
                    worst[2] = worst[2].max((got.acc_mps2[c] - want.acc_mps2[c]).abs());
                }
            }
            k += m;
        }
        // Both are rounded: `Piece::at` rounds an angle of up to 90 rad (ulp 1.4e-14 rad), the
        // rotation adds a few ulp of the unit vector. Measured about 3e-14 of the unit vector;
        // bounds at ten times that, times 300 m, 8 m/s, 0.21 m/s^2.
        assert!(
            worst[0] < 1e-10 && worst[1] < 3e-12 && worst[2] < 1e-13,
            "{worst:?}"
        );
    }
}
