//! Compilation of a [`MissionSpec`] into the trajectory pieces of a [`Mission`].

use super::checks::{bad_seg, seg_limit, seg_payload, seg_positive, Points};
use super::{Mission, MissionSpec, OrbitDirection, SegmentSpec};
use crate::airframe::Airframe;
use crate::error::PlannerError;
use crate::geodesy::LocalFrame;
use crate::trajectory::{Piece, Profile, Shape};

/// Heading change (absolute, rad) from `from` to `to` (unit east-north vectors).
fn turn_rad(from: [f64; 2], to: [f64; 2]) -> f64 {
    let cross = from[0] * to[1] - from[1] * to[0];
    let dot = from[0] * to[0] + from[1] * to[1];
    cross.atan2(dot).abs()
}
impl MissionSpec {
    /// Validate and compile for `airframe`. `payload_kg` overrides the file's take-off payload.
    ///
    /// # Errors
    /// No segments; a segment with a negative, zero or non-finite value where a positive one is
    /// needed; an altitude below the ground; a speed, rate or turn load beyond the airframe's
    /// limits; segments in an order that cannot be flown (a leg before take-off, ending in the air);
    /// a take-off mass above the airframe's limit.
    pub fn compile(
        &self,
        airframe: &Airframe,
        battery_mass_kg: f64,
        payload_kg: Option<f64>,
    ) -> Result<Mission, PlannerError> {
        if self.segments.is_empty() {
            return Err(PlannerError::EmptyMission);
        }
        let frame =
            match (
                self.home.east_m,
                self.home.north_m,
                self.home.latitude_deg,
                self.home.longitude_deg,
            ) {
                (None, None, Some(la), Some(lo)) => {
                    if !(la.is_finite() && la.abs() < 90.0 && lo.is_finite()) {
                        return Err(PlannerError::InvalidParameter {
                            name: "home latitude_deg",
                            value: la,
                            unit: "deg",
                            expected: "a latitude within (-90, 90) and a finite longitude",
                        });
                    }
                    Some(LocalFrame::new(la, lo))
                }
                (_, _, None, None) => None,
                _ => return Err(PlannerError::InvalidParameter {
                    name: "home latitude_deg",
                    value: self.home.latitude_deg.unwrap_or(f64::NAN),
                    unit: "deg",
                    expected:
                        "home as east_m/north_m or as latitude_deg/longitude_deg, not both or half",
                }),
            };
        let home = [
            self.home.east_m.unwrap_or(0.0),
            self.home.north_m.unwrap_or(0.0),
            0.0,
        ];
        for (v, name) in [(home[0], "home east_m"), (home[1], "home north_m")] {
            if !v.is_finite() {
                return Err(PlannerError::InvalidParameter {
                    name,
                    value: v,
                    unit: "m",
                    expected: "a finite coordinate",
                });
            }
        }
        let points = Points { frame };
        let start_payload = payload_kg.unwrap_or(self.payload_kg);
        crate::error::non_negative("payload_kg", start_payload, "kg")?;
        let mut payloads = vec![start_payload];
        let check_mass = |payload: f64| -> Result<(), PlannerError> {
            let m = airframe.mass_kg() + battery_mass_kg + payload;
            if m > airframe.max_takeoff_mass_kg() * (1.0 + 1e-9) {
                return Err(PlannerError::Unreachable {
                    index: 0,
                    kind: "mission",
                    name: "take-off mass (airframe + battery + payload)",
                    value: m,
                    limit: airframe.max_takeoff_mass_kg(),
                    unit: "kg",
                });
            }
            Ok(())
        };
        check_mass(start_payload)?;

        let mut pieces = Vec::new();
        let mut kinds = Vec::new();
        let mut pos = home;
        let mut airborne = false;
        let mut heading = [0.0, 1.0];
        let a_h = airframe.acceleration_mps2();
        let a_v = airframe.vertical_acceleration_mps2();
        let g = 9.80665;
        let max_centripetal = g * airframe.max_tilt_rad().tan();

        for (i, seg) in self.segments.iter().enumerate() {
            let kind = seg.kind();
            kinds.push(kind);
            let phase = payloads.len() - 1;
            let push = |pieces: &mut Vec<Piece>, shape, profile: Profile, fwd| {
                if profile.duration_s > 0.0 {
                    pieces.push(Piece {
                        shape,
                        profile,
                        segment: i,
                        mass_phase: phase,
                        forward: fwd,
                    });
                }
            };
            let need_air = |airborne: bool| {
                if airborne {
                    Ok(())
                } else {
                    Err(PlannerError::SegmentOrder {
                        index: i + 1,
                        kind,
                        reason: "the vehicle is on the ground: take off first",
                    })
                }
            };
            // A straight path from `pos` to `to` with a horizontal ground speed; yaws first.
            let straight = |pieces: &mut Vec<Piece>,
                            pos: &mut [f64; 3],
                            heading: &mut [f64; 2],
                            to: [f64; 3],
                            speed: f64|
             -> Result<(), PlannerError> {
                let d = [to[0] - pos[0], to[1] - pos[1], to[2] - pos[2]];
                let h = d[0].hypot(d[1]);
                let len = (h * h + d[2] * d[2]).sqrt();
                if len < 1e-9 {
                    return Ok(());
                }
                let (path_speed, path_acc) = if h > 1e-9 {
                    let fwd = [d[0] / h, d[1] / h];
                    let turn = turn_rad(*heading, fwd);
                    if turn > 1e-6 {
                        push(
                            pieces,
                            Shape::Hold { pos_m: *pos },
                            Profile::hold(turn / airframe.yaw_rate_radps()),
                            *heading,
                        );
                    }
                    *heading = fwd;
                    let vz = speed * d[2].abs() / h;
                    let (vlim, name) = if d[2] >= 0.0 {
                        (airframe.max_climb_rate_mps(), "climb rate of the leg")
                    } else {
                        (airframe.max_descent_rate_mps(), "descent rate of the leg")
                    };
                    seg_limit(i, kind, name, vz, vlim, "m/s")?;
                    let acc = if d[2].abs() > 1e-9 {
                        (a_h * len / h).min(a_v * len / d[2].abs())
                    } else {
                        a_h
                    };
                    (speed * len / h, acc)
                } else {
                    // Vertical leg: the ground speed does not apply; use the rate limit.
                    let v = if d[2] > 0.0 {
                        airframe.max_climb_rate_mps()
                    } else {
                        airframe.max_descent_rate_mps()
                    };
                    (v, a_v)
                };
                push(
                    pieces,
                    Shape::Line {
                        start_m: *pos,
                        dir: [d[0] / len, d[1] / len, d[2] / len],
                    },
                    Profile::rest_to_rest(len, path_speed, path_acc),
                    *heading,
                );
                *pos = to;
                Ok(())
            };
            let vertical = |pieces: &mut Vec<Piece>,
                            pos: &mut [f64; 3],
                            heading: [f64; 2],
                            to_z: f64,
                            rate: f64| {
                let len = (to_z - pos[2]).abs();
                if len > 0.0 {
                    push(
                        pieces,
                        Shape::Line {
                            start_m: *pos,
                            dir: [0.0, 0.0, (to_z - pos[2]).signum()],
                        },
                        Profile::rest_to_rest(len, rate, a_v),
                        heading,
                    );
                }
                pos[2] = to_z;
            };
            let mut payload_after = None;
            match *seg {
                SegmentSpec::TakeOff {
                    altitude_m,
                    climb_rate_mps,
                } => {
                    if airborne {
                        return Err(PlannerError::SegmentOrder {
                            index: i + 1,
                            kind,
                            reason: "the vehicle is already in the air",
                        });
                    }
                    seg_positive(i, kind, "altitude_m", altitude_m, "m")?;
                    seg_positive(i, kind, "climb_rate_mps", climb_rate_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "climb_rate_mps",
                        climb_rate_mps,
                        airframe.max_climb_rate_mps(),
                        "m/s",
                    )?;
                    vertical(&mut pieces, &mut pos, heading, altitude_m, climb_rate_mps);
                    airborne = true;
                }
                SegmentSpec::Leg {
                    east_m,
                    north_m,
                    latitude_deg,
                    longitude_deg,
                    altitude_m,
                    ground_speed_mps,
                    payload_after_kg,
                } => {
                    need_air(airborne)?;
                    let [e, n] = points.resolve(
                        i,
                        kind,
                        east_m,
                        north_m,
                        latitude_deg,
                        longitude_deg,
                        ["east_m", "north_m", "latitude_deg", "longitude_deg"],
                    )?;
                    let z = altitude_m.unwrap_or(pos[2]);
                    seg_positive(i, kind, "altitude_m", z, "m")?;
                    seg_positive(i, kind, "ground_speed_mps", ground_speed_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "ground_speed_mps",
                        ground_speed_mps,
                        airframe.max_speed_mps(),
                        "m/s",
                    )?;
                    straight(
                        &mut pieces,
                        &mut pos,
                        &mut heading,
                        [e, n, z],
                        ground_speed_mps,
                    )?;
                    payload_after = seg_payload(i, kind, payload_after_kg)?;
                }
                SegmentSpec::Return { ground_speed_mps } => {
                    need_air(airborne)?;
                    seg_positive(i, kind, "ground_speed_mps", ground_speed_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "ground_speed_mps",
                        ground_speed_mps,
                        airframe.max_speed_mps(),
                        "m/s",
                    )?;
                    let to = [home[0], home[1], pos[2]];
                    straight(&mut pieces, &mut pos, &mut heading, to, ground_speed_mps)?;
                }
                SegmentSpec::Orbit {
                    centre_east_m,
                    centre_north_m,
                    centre_latitude_deg,
                    centre_longitude_deg,
                    altitude_m,
                    radius_m,
                    ground_speed_mps,
                    direction,
                    laps,
                    duration_s,
                } => {
                    need_air(airborne)?;
                    let c = points.resolve(
                        i,
                        kind,
                        centre_east_m,
                        centre_north_m,
                        centre_latitude_deg,
                        centre_longitude_deg,
                        [
                            "centre_east_m",
                            "centre_north_m",
                            "centre_latitude_deg",
                            "centre_longitude_deg",
                        ],
                    )?;
                    seg_positive(i, kind, "radius_m", radius_m, "m")?;
                    seg_positive(i, kind, "ground_speed_mps", ground_speed_mps, "m/s")?;
                    let z = altitude_m.unwrap_or(pos[2]);
                    seg_positive(i, kind, "altitude_m", z, "m")?;
                    seg_limit(
                        i,
                        kind,
                        "ground_speed_mps",
                        ground_speed_mps,
                        airframe.max_speed_mps(),
                        "m/s",
                    )?;
                    // Centripetal load in still air: v^2 / r <= g tan(tilt_max).
                    seg_limit(
                        i,
                        kind,
                        "centripetal acceleration v^2/r",
                        ground_speed_mps * ground_speed_mps / radius_m,
                        max_centripetal,
                        "m/s^2",
                    )?;
                    let length = match (laps, duration_s) {
                        (Some(l), None) => {
                            seg_positive(i, kind, "laps", l, "")? * std::f64::consts::TAU * radius_m
                        }
                        (None, Some(d)) => {
                            let d = seg_positive(i, kind, "duration_s", d, "s")?;
                            // Trapezoid time L / v + v / a = d.
                            let l = ground_speed_mps * (d - ground_speed_mps / a_h);
                            if l <= 0.0 {
                                return Err(bad_seg(
                                    i,
                                    kind,
                                    "duration_s",
                                    d,
                                    "s",
                                    "too short to reach the orbit speed and stop again",
                                ));
                            }
                            l
                        }
                        _ => {
                            return Err(PlannerError::SegmentOrder {
                                index: i + 1,
                                kind,
                                reason: "give exactly one of laps and duration_s",
                            })
                        }
                    };
                    // Transit to the nearest point of the circle.
                    let rel = [pos[0] - c[0], pos[1] - c[1]];
                    let dist = rel[0].hypot(rel[1]);
                    let phi0 = if dist > 1e-9 {
                        rel[1].atan2(rel[0])
                    } else {
                        0.0
                    };
                    let entry = [
                        c[0] + radius_m * phi0.cos(),
                        c[1] + radius_m * phi0.sin(),
                        z,
                    ];
                    straight(&mut pieces, &mut pos, &mut heading, entry, ground_speed_mps)?;
                    let sign = match direction {
                        OrbitDirection::CounterClockwise => 1.0,
                        OrbitDirection::Clockwise => -1.0,
                    };
                    let tangent = [-sign * phi0.sin(), sign * phi0.cos()];
                    let turn = turn_rad(heading, tangent);
                    if turn > 1e-6 {
                        push(
                            &mut pieces,
                            Shape::Hold { pos_m: pos },
                            Profile::hold(turn / airframe.yaw_rate_radps()),
                            heading,
                        );
                    }
                    let arc = Piece {
                        shape: Shape::Arc {
                            centre_m: c,
                            radius_m,
                            up_m: z,
                            phi0_rad: phi0,
                            sign,
                        },
                        profile: Profile::rest_to_rest(length, ground_speed_mps, a_h),
                        segment: i,
                        mass_phase: phase,
                        forward: tangent,
                    };
                    pos = arc.end_m();
                    let end = arc.at(arc.duration_s());
                    // Heading at the end: the tangent there.
                    heading = end.forward;
                    pieces.push(arc);
                }
                SegmentSpec::Hover {
                    duration_s,
                    payload_after_kg,
                } => {
                    need_air(airborne)?;
                    seg_positive(i, kind, "duration_s", duration_s, "s")?;
                    push(
                        &mut pieces,
                        Shape::Hold { pos_m: pos },
                        Profile::hold(duration_s),
                        heading,
                    );
                    payload_after = seg_payload(i, kind, payload_after_kg)?;
                }
                SegmentSpec::Descent {
                    altitude_m,
                    rate_mps,
                } => {
                    need_air(airborne)?;
                    seg_positive(i, kind, "altitude_m", altitude_m, "m")?;
                    seg_positive(i, kind, "rate_mps", rate_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "rate_mps",
                        rate_mps,
                        airframe.max_descent_rate_mps(),
                        "m/s",
                    )?;
                    if altitude_m >= pos[2] {
                        return Err(bad_seg(
                            i,
                            kind,
                            "altitude_m",
                            altitude_m,
                            "m",
                            "a descent must end below the present height",
                        ));
                    }
                    vertical(&mut pieces, &mut pos, heading, altitude_m, rate_mps);
                }
                SegmentSpec::Landing {
                    rate_mps,
                    payload_after_kg,
                } => {
                    need_air(airborne)?;
                    seg_positive(i, kind, "rate_mps", rate_mps, "m/s")?;
                    seg_limit(
                        i,
                        kind,
                        "rate_mps",
                        rate_mps,
                        airframe.max_descent_rate_mps(),
                        "m/s",
                    )?;
                    vertical(&mut pieces, &mut pos, heading, 0.0, rate_mps);
                    airborne = false;
                    payload_after = seg_payload(i, kind, payload_after_kg)?;
                }
            }
            if let Some(p) = payload_after {
                check_mass(p)?;
                payloads.push(p);
            }
        }
        if airborne {
            return Err(PlannerError::SegmentOrder {
                index: self.segments.len(),
                kind: self.segments[self.segments.len() - 1].kind(),
                reason: "the mission ends in the air: add a landing",
            });
        }
        Ok(Mission {
            name: self.name.clone(),
            home_m: home,
            pieces,
            kinds,
            payloads_kg: payloads,
        })
    }
}
