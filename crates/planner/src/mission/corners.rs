//! Pass-through corners: how an autopilot flies through a waypoint that has no hold.
//!
//! With `corners = "pass"` (the default), two level straight legs that meet at a waypoint
//! without a hold, a payload change or a change of height are joined by a circular arc tangent
//! to both, flown at a constant corner speed (legs that climb or descend, as a route that
//! follows the ground, are flown through where they go straight on in plan view, at the slower
//! leg's speed, and stop where they turn); the yaw turn in place of the stop-and-turn mode
//! goes. PX4's multicopter trajectory generator and ArduPilot's S-curve navigation both start
//! the turn within the waypoint's acceptance radius and slow to a speed that the turn's
//! lateral acceleration allows; this model keeps those two limits and a circle for the turn:
//!
//! | symbol | meaning | from |
//! |---|---|---|
//! | `theta` | heading change at the waypoint, rad | the two legs |
//! | `R_acc` | acceptance radius, m | the leg's `acceptance_radius_m`, else the airframe's (default 2 m, PX4's `NAV_ACC_RAD` and ArduPilot's `WPNAV_RADIUS` defaults) |
//! | `d` | where the arc leaves and joins the legs, from the waypoint, m | `d = min(R_acc, L_in / 2, L_out / 2)` |
//! | `r` | arc radius, m | `r = d / tan(theta / 2)` |
//! | `a_lat` | lateral acceleration limit, m/s^2 | the airframe's `acceleration_mps2`, at most `g tan(max tilt)` |
//! | `v_c` | corner speed, m/s | `min(sqrt(a_lat r), v_in, v_out)` |
//!
//! The legs are then flown with a trapezoidal profile from the speed of the corner before to the
//! speed of the corner after (rest at a stop); where a leg is too short to reach the next corner's
//! speed, that speed is lowered (a forward and a backward pass over the chain, as a velocity
//! planner does). A corner whose speed would be under [`MIN_CORNER_SPEED_MPS`] (a turn of nearly
//! 180 deg, or a tiny acceptance radius) is flown as a stop. Straight-through waypoints
//! (`theta = 0`) keep the speed with no arc.
//!
//! # Deviation
//! Autopilots blend the legs with jerk-limited curves (PX4) or S-curves (ArduPilot) whose shape
//! depends on many parameters; a circle at the corner speed has the same peak lateral
//! acceleration and cuts the corner by the same order of distance, which is what the energy of a
//! turn depends on. The heading follows the track through the turn (no yaw in place).

use aloft_core::STANDARD_GRAVITY_MPS2;

use crate::airframe::Airframe;
use crate::trajectory::{Circle, Piece, Profile, Shape};

/// Slowest corner flown through, m/s: a slower one is a stop-and-turn.
pub const MIN_CORNER_SPEED_MPS: f64 = 0.5;

/// Acceptance radius of a waypoint when neither the leg nor the airframe gives one, m.
pub const DEFAULT_ACCEPTANCE_RADIUS_M: f64 = 2.0;

/// What a compiled piece is to the corner pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Role {
    /// A level straight leg (or return) at a cruise speed and acceleration, ending at a waypoint
    /// with this acceptance radius.
    Level {
        /// Cruise speed along the line, m/s.
        cruise_mps: f64,
        /// Acceleration along the line, m/s^2.
        accel_mps2: f64,
        /// Acceptance radius of the waypoint it ends at, m.
        acceptance_m: f64,
    },
    /// The yaw turn in place before a path.
    Yaw,
    /// Anything else (vertical lines, holds, orbits, sloped lines): the vehicle stops there.
    Other,
}

/// One corner: the end of line `a`, the start of line `b` (with the yaw between them, if any).
#[derive(Debug, Clone, Copy)]
struct Corner {
    a: usize,
    b: usize,
    /// Where the arc leaves line `a` and joins line `b`, from the waypoint, m.
    cut_m: f64,
    /// The arc's radius, m (0 for a straight-through waypoint).
    radius_m: f64,
    /// Corner speed, m/s.
    speed_mps: f64,
}

/// The pieces with every eligible corner flown through (see the module docs); `roles` is
/// parallel to `pieces`.
pub(super) fn pass_through(pieces: Vec<Piece>, roles: &[Role], airframe: &Airframe) -> Vec<Piece> {
    let a_lat = airframe
        .acceleration_mps2()
        .min(STANDARD_GRAVITY_MPS2 * airframe.max_tilt_rad().tan());
    let mut corners = find_corners(&pieces, roles, a_lat);
    if corners.is_empty() {
        return pieces;
    }
    reachable_speeds(&pieces, roles, &mut corners);
    rebuild(pieces, roles, &corners)
}

/// Every waypoint where two level lines meet (a yaw between them at most), of consecutive
/// segments, at one height and in one mass phase, with its geometric corner speed; corners too
/// slow to fly through are left out (stops).
fn find_corners(pieces: &[Piece], roles: &[Role], a_lat: f64) -> Vec<Corner> {
    let mut corners = Vec::new();
    for a in 0..pieces.len() {
        let Role::Level {
            cruise_mps: v_in,
            acceptance_m,
            ..
        } = roles[a]
        else {
            continue;
        };
        let b = match roles.get(a + 1) {
            Some(Role::Yaw) => a + 2,
            _ => a + 1,
        };
        let Some(&Role::Level {
            cruise_mps: v_out, ..
        }) = roles.get(b)
        else {
            continue;
        };
        let (pa, pb) = (&pieces[a], &pieces[b]);
        let (Shape::Line { dir: u, .. }, Shape::Line { dir: w, .. }) = (pa.shape, pb.shape) else {
            continue;
        };
        let level = u[2].abs() < 1e-9 && w[2].abs() < 1e-9;
        let same_height = level && (pa.end_m()[2] - pb.end_m()[2]).abs() < 1e-6;
        if pa.segment == pb.segment || pa.mass_phase != pb.mass_phase {
            continue;
        }
        let theta = turn_rad([u[0], u[1]], [w[0], w[1]]);
        // Lines that climb or descend (a route over the ground) are flown through only where
        // they go straight on in plan view: no arc, the slower line's speed at the joint.
        if !same_height && theta >= 1e-6 {
            continue;
        }
        let (l_in, l_out) = (pa.profile.length_m, pb.profile.length_m);
        let cut_m = acceptance_m.min(l_in / 2.0).min(l_out / 2.0);
        let (radius_m, v_geo) = if theta < 1e-6 {
            (0.0, f64::INFINITY)
        } else {
            let r = cut_m / (theta / 2.0).tan();
            (r, (a_lat * r).sqrt())
        };
        let speed_mps = v_geo.min(v_in).min(v_out);
        if speed_mps >= MIN_CORNER_SPEED_MPS {
            corners.push(Corner {
                a,
                b,
                cut_m: if radius_m > 0.0 { cut_m } else { 0.0 },
                radius_m,
                speed_mps,
            });
        }
    }
    corners
}

/// Lower corner speeds until every line can reach the next corner's speed from the last one's
/// within its length (forward pass), and slow down to it (backward pass).
fn reachable_speeds(pieces: &[Piece], roles: &[Role], corners: &mut [Corner]) {
    // What is left of each line once its corners' cuts are off, and its acceleration.
    let mut left_m: Vec<f64> = pieces.iter().map(|p| p.profile.length_m).collect();
    for c in corners.iter() {
        left_m[c.a] -= c.cut_m;
        left_m[c.b] -= c.cut_m;
    }
    let line = |i: usize| -> (f64, f64) {
        let accel = match roles[i] {
            Role::Level { accel_mps2, .. } => accel_mps2,
            _ => 0.0,
        };
        (accel, left_m[i].max(0.0))
    };
    // Corners are in piece order; the corner before corner k shares its line when its `b` is
    // corner k's `a`.
    for k in 0..corners.len() {
        let (accel, len) = line(corners[k].a);
        let v_start = match k.checked_sub(1) {
            Some(j) if corners[j].b == corners[k].a => corners[j].speed_mps,
            _ => 0.0,
        };
        let reach = (v_start * v_start + 2.0 * accel * len).sqrt();
        corners[k].speed_mps = corners[k].speed_mps.min(reach);
    }
    for k in (0..corners.len()).rev() {
        let (accel, len) = line(corners[k].b);
        let v_end = match corners.get(k + 1) {
            Some(n) if n.a == corners[k].b => n.speed_mps,
            _ => 0.0,
        };
        let reach = (v_end * v_end + 2.0 * accel * len).sqrt();
        corners[k].speed_mps = corners[k].speed_mps.min(reach);
    }
}

/// The new piece list: lines shortened by their corners' cuts and flown between the corner
/// speeds, an arc at each corner (in the incoming line's segment), the yaws at corners gone.
fn rebuild(pieces: Vec<Piece>, roles: &[Role], corners: &[Corner]) -> Vec<Piece> {
    let mut out = Vec::with_capacity(pieces.len() + corners.len());
    let mut next = corners.iter().peekable();
    let mut before: Option<&Corner> = None;
    for (i, piece) in pieces.iter().enumerate() {
        if let Some(c) = before {
            if i < c.b && roles[i] == Role::Yaw {
                continue;
            }
        }
        let entering = before.filter(|c| c.b == i);
        let leaving = next.peek().copied().filter(|c| c.a == i);
        if entering.is_none() && leaving.is_none() {
            out.push(*piece);
            continue;
        }
        out.extend(cut_line(piece, roles[i], entering, leaving));
        if let Some(c) = leaving {
            out.extend(corner_arc(piece, &pieces[c.b], c));
            before = Some(c);
            next.next();
        }
    }
    out
}

/// Line `piece` without the cuts of the corners it enters from and leaves into, flown from the
/// one corner's speed to the other's (none when nothing of it is left).
fn cut_line(
    piece: &Piece,
    role: Role,
    entering: Option<&Corner>,
    leaving: Option<&Corner>,
) -> Option<Piece> {
    let (
        Shape::Line { start_m, dir },
        Role::Level {
            cruise_mps,
            accel_mps2,
            ..
        },
    ) = (piece.shape, role)
    else {
        return Some(*piece);
    };
    let (cut0, v0) = entering.map_or((0.0, 0.0), |c| (c.cut_m, c.speed_mps));
    let (cut1, v1) = leaving.map_or((0.0, 0.0), |c| (c.cut_m, c.speed_mps));
    let len = piece.profile.length_m - cut0 - cut1;
    if len <= 1e-9 {
        return None;
    }
    Some(Piece {
        shape: Shape::Line {
            start_m: [
                start_m[0] + dir[0] * cut0,
                start_m[1] + dir[1] * cut0,
                start_m[2] + dir[2] * cut0,
            ],
            dir,
        },
        profile: Profile::between(len, (v0, cruise_mps, v1), accel_mps2),
        ..*piece
    })
}

/// The arc of corner `c` from line `a` to line `b`, at the corner speed (none for a
/// straight-through waypoint).
fn corner_arc(a: &Piece, b: &Piece, c: &Corner) -> Option<Piece> {
    let (Shape::Line { dir: u, .. }, Shape::Line { dir: w, .. }) = (a.shape, b.shape) else {
        return None;
    };
    if c.radius_m <= 0.0 {
        return None;
    }
    let waypoint = a.end_m();
    let (u, w) = ([u[0], u[1]], [w[0], w[1]]);
    let sign = if u[0] * w[1] - u[1] * w[0] > 0.0 {
        1.0
    } else {
        -1.0
    };
    let start = [waypoint[0] - c.cut_m * u[0], waypoint[1] - c.cut_m * u[1]];
    // The centre lies on the inner side of the incoming line, one radius from the arc's start.
    let normal = [-sign * u[1], sign * u[0]];
    let centre_m = [
        start[0] + c.radius_m * normal[0],
        start[1] + c.radius_m * normal[1],
    ];
    let phi0_rad = (start[1] - centre_m[1]).atan2(start[0] - centre_m[0]);
    let length_m = c.radius_m * turn_rad(u, w);
    let v = c.speed_mps;
    Some(Piece {
        shape: Shape::Arc(Circle {
            centre_m,
            radius_m: c.radius_m,
            up_m: waypoint[2],
            phi0_rad,
            sign,
        }),
        profile: Profile::between(length_m, (v, v, v), 1.0),
        segment: a.segment,
        mass_phase: a.mass_phase,
        forward: u,
    })
}

/// Heading change (absolute, rad) from `from` to `to` (unit east-north vectors).
pub(super) fn turn_rad(from: [f64; 2], to: [f64; 2]) -> f64 {
    let cross = from[0] * to[1] - from[1] * to[0];
    let dot = from[0] * to[0] + from[1] * to[1];
    cross.atan2(dot).abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission::{CornerMode, MissionSpec};
    use crate::test_support::m100_airframe;

    /// A lawn-mower survey at 20 m: `lines` lines of 300 m joined by 40 m turnarounds, at 8 m/s,
    /// then a second's hover, home and down.
    fn lawn_mower(lines: usize, corners: CornerMode) -> MissionSpec {
        let mut text = String::from(
            "[[segment]]\nkind = \"take-off\"\naltitude_m = 20.0\nclimb_rate_mps = 2.0\n",
        );
        let leg = |e: f64, n: f64| {
            format!("[[segment]]\nkind = \"leg\"\neast_m = {e}\nnorth_m = {n}\nground_speed_mps = 8.0\n")
        };
        text += &leg(0.0, 100.0);
        for k in 0..lines {
            let e = 40.0 * k as f64;
            let (from, to) = if k % 2 == 0 {
                (100.0, 400.0)
            } else {
                (400.0, 100.0)
            };
            if k > 0 {
                text += &leg(e, from);
            }
            text += &leg(e, to);
        }
        // A hold before the way home: the return's corner is not part of the survey's.
        text += "[[segment]]\nkind = \"hover\"\nduration_s = 1.0\n";
        text += "[[segment]]\nkind = \"return\"\nground_speed_mps = 8.0\n";
        text += "[[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n";
        let mut spec = MissionSpec::from_toml_str(&text).unwrap();
        spec.corners = Some(corners);
        spec
    }

    #[test]
    fn a_rest_to_rest_profile_between_rests_is_the_same_bits() {
        for (l, v, a) in [(100.0, 8.0, 2.0), (5.0, 8.0, 2.0), (16.0, 8.0, 2.0)] {
            let p = Profile::rest_to_rest(l, v, a);
            assert_eq!(Profile::between(l, (0.0, v, 0.0), a), p);
        }
    }

    #[test]
    fn a_profile_between_speeds_covers_its_length_and_meets_them() {
        // (length, v0, cruise, v1, a): trapezoids and triangles, up and down.
        for (l, v0, v, v1, a) in [
            (100.0, 2.0, 8.0, 3.0, 2.0),
            (10.0, 2.0, 8.0, 3.0, 2.0),
            (3.0, 2.0, 8.0, 4.0, 2.0),
            (50.0, 8.0, 8.0, 0.0, 2.0),
            (50.0, 0.0, 8.0, 8.0, 2.0),
        ] {
            let p = Profile::between(l, (v0, v, v1), a);
            let (s0, u0, _) = p.at(0.0);
            let (s1, u1, _) = p.at(p.duration_s);
            // Closed forms: exact up to rounding.
            assert!(s0.abs() < 1e-12 && (u0 - v0).abs() < 1e-12, "{p:?}");
            assert!((s1 - l).abs() < 1e-9 && (u1 - v1).abs() < 1e-9, "{p:?}");
            assert!(p.peak_mps <= v + 1e-12);
            // Speed never negative, path never backwards.
            let mut last = 0.0;
            for k in 0..=1000 {
                let (s, u, _) = p.at(p.duration_s * k as f64 / 1000.0);
                assert!(u >= -1e-12 && s >= last - 1e-12, "{p:?} at {k}");
                last = s;
            }
        }
    }

    /// Time of one 90 deg corner in the window of `x_m` either side of its waypoint, stop and
    /// turn (decelerate to rest, yaw, accelerate) against pass-through (decelerate to the corner
    /// speed, the arc, accelerate), from the module's formulas written out here.
    fn corner_window_s(x_m: f64) -> (f64, f64) {
        let (v, a, yaw_radps) = (8.0f64, 2.0f64, 60f64.to_radians());
        let theta = std::f64::consts::FRAC_PI_2;
        let d = DEFAULT_ACCEPTANCE_RADIUS_M;
        let r = d / (theta / 2.0).tan();
        let v_c = (a * r).sqrt(); // a_lat = 2 m/s^2 < g tan 35 deg
        let stop = 2.0 * (v / a + (x_m - v * v / (2.0 * a)) / v) + theta / yaw_radps;
        let pass = 2.0 * ((v - v_c) / a + (x_m - d - (v * v - v_c * v_c) / (2.0 * a)) / v)
            + r * theta / v_c;
        (stop, pass)
    }

    #[test]
    fn a_lawn_mower_survey_flies_faster_through_its_corners_by_what_the_model_says() {
        let airframe = m100_airframe();
        let time = |lines, mode| {
            lawn_mower(lines, mode)
                .compile(&airframe, 0.68, None)
                .unwrap()
                .duration_s()
        };
        // Each turnaround line adds two 90 deg corners whose windows (20 m either side) tile
        // the 40 m line and reach 20 m into the long ones (which need 17 m to slow to 2 m/s).
        let (stop, pass) = corner_window_s(20.0);
        let saved = |lines| time(lines, CornerMode::Stop) - time(lines, CornerMode::Pass);
        let per_line = saved(5) - saved(4);
        assert!(
            (per_line - 2.0 * (stop - pass)).abs() < 1e-9,
            "{per_line} s a line against {} s",
            2.0 * (stop - pass)
        );
        // 2.18 s a corner at 8 m/s: 10.5 s stop and turn, 8.32 s through the arc at 2 m/s.
        assert!((stop - pass - 2.179).abs() < 1e-3, "{stop} {pass}");
        assert!(saved(4) > 6.0 * (stop - pass));
    }

    #[test]
    fn a_square_flown_at_speed_slows_at_its_corners() {
        let airframe = m100_airframe();
        let mut spec = lawn_mower(2, CornerMode::Pass);
        spec.segments.truncate(5); // take-off, to the start, three sides
        spec.allow_end_in_air = true;
        let mission = spec.compile(&airframe, 0.68, None).unwrap();
        let arcs: Vec<_> = mission
            .pieces()
            .iter()
            .filter_map(|p| match p.shape {
                Shape::Arc(c) => Some((c.radius_m, p.profile.peak_mps)),
                _ => None,
            })
            .collect();
        // Two 90 deg corners between the sides, none where the take-off's vertical line ends.
        assert_eq!(arcs.len(), 2, "{arcs:?}");
        for (r, v) in arcs {
            assert!((r - 2.0).abs() < 1e-9 && (v - 2.0).abs() < 1e-9, "{r} {v}");
        }
        // The speed along the path: cruise on the sides, 2 m/s in the corners, never a stop
        // between the first side's start and the last side's end.
        // (The take-off and the first leg start from rest and the last side ends at rest.)
        let n = mission.pieces().len();
        let pieces = &mission.pieces()[2..n - 1];
        let speeds: Vec<f64> = pieces
            .iter()
            .flat_map(|p| (1..100).map(move |k| p.at(p.duration_s() * k as f64 / 100.0)))
            .map(|k| k.vel_mps[0].hypot(k.vel_mps[1]))
            .collect();
        let lowest = speeds.iter().copied().fold(f64::INFINITY, f64::min);
        assert!((lowest - 2.0).abs() < 1e-9, "{lowest}");
        assert!(speeds.iter().any(|&v| (v - 8.0).abs() < 1e-12));
    }

    #[test]
    fn a_reversal_is_a_stop_and_a_straight_waypoint_keeps_the_speed() {
        let airframe = m100_airframe();
        let text = |second: (f64, f64)| {
            format!(
                "[[segment]]\nkind = \"take-off\"\naltitude_m = 20.0\nclimb_rate_mps = 2.0\n\
                 [[segment]]\nkind = \"leg\"\neast_m = 0.0\nnorth_m = 100.0\nground_speed_mps = 8.0\n\
                 [[segment]]\nkind = \"leg\"\neast_m = {}\nnorth_m = {}\nground_speed_mps = 8.0\n\
                 [[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n",
                second.0, second.1
            )
        };
        let duration = |second, mode| {
            let mut spec = MissionSpec::from_toml_str(&text(second)).unwrap();
            spec.corners = Some(mode);
            spec.compile(&airframe, 0.68, None).unwrap().duration_s()
        };
        // Back the way it came: the corner speed would be 0; flown as a stop and turn.
        let back = (0.0, 0.0);
        assert!(
            (duration(back, CornerMode::Pass) - duration(back, CornerMode::Stop)).abs() < 1e-12
        );
        // Straight on: one 200 m leg's time, 200/8 + 8/2 = 29 s, instead of two 100 m legs'.
        let on = (0.0, 200.0);
        let saved = duration(on, CornerMode::Stop) - duration(on, CornerMode::Pass);
        assert!(
            (saved - 2.0 * (100.0 / 8.0 + 4.0) + 29.0).abs() < 1e-9,
            "{saved}"
        );
    }
}
