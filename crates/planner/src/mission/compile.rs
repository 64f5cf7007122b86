//! Compilation of a [`MissionSpec`] into the trajectory pieces of a [`Mission`].
//!
//! [`MissionSpec::compile`] checks the mission as a whole (segments, home, take-off payload and
//! mass), then folds the segments through a [`Compiler`], which keeps where the vehicle is and
//! compiles each segment kind in its own method. Shared steps (the yaw turn before a path, a
//! straight path, a vertical one) are methods too, so a new kind is one more method built from
//! them and one more arm in [`Compiler::segment`].

use super::checks::{home_position_m, Points, Seg};
use super::corners::{pass_through, turn_rad, Role};
use super::{CornerMode, Mission, MissionSpec, OrbitDirection, SegmentSpec};
use crate::airframe::Airframe;
use crate::error::PlannerError;
use crate::trajectory::{Circle, Piece, Profile, Shape};

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
        self.compile_clamped(airframe, battery_mass_kg, payload_kg, None)
    }

    /// [`MissionSpec::compile`], with the speeds of a mission that clamps them
    /// ([`MissionSpec::clamp_speeds`]: a planner file written for another vehicle) clamped to
    /// `clamp_to_mps` where that is below the airframe's maximum speed (the speed the vehicle
    /// can hold within its tilt limit: [`crate::Aircraft::tilt_limited_speed_mps`]).
    ///
    /// # Errors
    /// As [`MissionSpec::compile`].
    pub fn compile_clamped(
        &self,
        airframe: &Airframe,
        battery_mass_kg: f64,
        payload_kg: Option<f64>,
        clamp_to_mps: Option<f64>,
    ) -> Result<Mission, PlannerError> {
        if self.segments.is_empty() {
            return Err(PlannerError::EmptyMission);
        }
        if self.segments.len() > MAX_SEGMENTS {
            return Err(PlannerError::TooManySegments {
                segments: self.segments.len(),
                limit: MAX_SEGMENTS,
            });
        }
        let points = Points::for_home(&self.home)?;
        let home_m = home_position_m(&self.home)?;
        let start_payload_kg = payload_kg.unwrap_or(self.payload_kg);
        crate::error::non_negative("payload_kg", start_payload_kg, "kg")?;
        let mut compiler =
            Compiler::new(airframe, battery_mass_kg, points, home_m, start_payload_kg)?;
        compiler.rtl_altitude_m = self.rtl_altitude_m;
        compiler.allow_end_in_air = self.allow_end_in_air;
        compiler.over_terrain = self.over_terrain;
        compiler.default_speed_mps = self.default_speed_mps;
        compiler.clamp_speeds = self.clamp_speeds;
        compiler.clamp_to_mps = clamp_to_mps;
        compiler.corners = self.corners.unwrap_or_default();
        if let Some(start_m) = self.start_in_air_m {
            compiler.start_in_air(start_m)?;
        }
        for (index, segment) in self.segments.iter().enumerate() {
            compiler.segment(index, segment)?;
        }
        compiler.finish(&self.name)
    }
}

/// Most segments a mission may have: a survey of thousands of waypoints is well below it, and the
/// compiled mission's memory (a few kilobytes a segment with its report) stays bounded.
pub const MAX_SEGMENTS: usize = 50_000;

/// Keys of a leg's waypoint, in the order [`Points::resolve`] takes them.
const WAYPOINT_KEYS: [&str; 4] = ["east_m", "north_m", "latitude_deg", "longitude_deg"];

/// Keys of an orbit's centre, in the order [`Points::resolve`] takes them.
const CENTRE_KEYS: [&str; 4] = [
    "centre_east_m",
    "centre_north_m",
    "centre_latitude_deg",
    "centre_longitude_deg",
];

/// Turns the segments of one mission, in order, into trajectory pieces for one airframe.
struct Compiler<'a> {
    /// The vehicle's limits and rates.
    airframe: &'a Airframe,
    /// Battery mass, kg (for the take-off mass check).
    battery_mass_kg: f64,
    /// Resolves waypoints and centres to local metres.
    points: Points,
    /// Home, ENU m (height 0).
    home_m: [f64; 3],
    /// The segment being compiled (before the first, a placeholder that names the mission).
    seg: Seg,
    /// Where the vehicle is, ENU m.
    pos_m: [f64; 3],
    /// Where its nose points: unit east-north vector.
    heading: [f64; 2],
    /// In the air (between a take-off and a landing).
    airborne: bool,
    /// The pieces so far.
    pieces: Vec<Piece>,
    /// What each piece is to the corner pass.
    roles: Vec<Role>,
    /// How waypoints without a hold are flown.
    corners: CornerMode,
    /// The acceptance radius of the present leg's waypoint, m (the leg's own, when it gives
    /// one).
    acceptance_m: Option<f64>,
    /// The kind of each segment so far.
    kinds: Vec<&'static str>,
    /// The payload of each mass phase so far, kg (a phase ends where a segment changes it).
    payloads_kg: Vec<f64>,
    /// The operator's item number of each segment so far.
    items: Vec<Option<u32>>,
    /// Lowest height of a return to home, m.
    rtl_altitude_m: Option<f64>,
    /// The route ended in a loiter until the reserve.
    loiter_until_reserve: bool,
    /// A mission may end in the air.
    allow_end_in_air: bool,
    /// Heights are judged against the terrain, not home's height.
    over_terrain: bool,
    /// Ground speed of segments that give none, m/s.
    default_speed_mps: Option<f64>,
    /// Speeds beyond the vehicle's are flown at its maximum (with a warning).
    clamp_speeds: bool,
    /// The speed clamped speeds are flown at when below the airframe's maximum, m/s.
    clamp_to_mps: Option<f64>,
    /// What the compiler adjusted, for the reader.
    warnings: Vec<String>,
}

/// Vertical rate of a return's climb or descent to its height, m/s (or the airframe's limit if
/// lower): a gentle autopilot rate.
const RTL_VERTICAL_RATE_MPS: f64 = 2.5;

impl<'a> Compiler<'a> {
    /// A vehicle on the ground at home, nose north, with the take-off payload (checked against
    /// the take-off mass limit).
    fn new(
        airframe: &'a Airframe,
        battery_mass_kg: f64,
        points: Points,
        home_m: [f64; 3],
        start_payload_kg: f64,
    ) -> Result<Self, PlannerError> {
        let compiler = Self {
            airframe,
            battery_mass_kg,
            points,
            home_m,
            seg: Seg {
                index: 0,
                kind: "mission",
                item: None,
            },
            pos_m: home_m,
            heading: [0.0, 1.0],
            airborne: false,
            pieces: Vec::new(),
            roles: Vec::new(),
            corners: CornerMode::default(),
            acceptance_m: None,
            kinds: Vec::new(),
            payloads_kg: vec![start_payload_kg],
            items: Vec::new(),
            rtl_altitude_m: None,
            loiter_until_reserve: false,
            allow_end_in_air: false,
            over_terrain: false,
            default_speed_mps: None,
            clamp_speeds: false,
            clamp_to_mps: None,
            warnings: Vec::new(),
        };
        compiler.check_take_off_mass(start_payload_kg)?;
        Ok(compiler)
    }

    /// Start in the air at rest, `start_m` (east, north, up) from home: the rest of a flight in
    /// progress.
    fn start_in_air(&mut self, start_m: [f64; 3]) -> Result<(), PlannerError> {
        for (name, value) in [("start_east_m", start_m[0]), ("start_north_m", start_m[1])] {
            aloft_core::parameter(name, value, "m", value.is_finite(), "a finite number")?;
        }
        crate::error::positive("start_up_m", start_m[2], "m")?;
        self.pos_m = [
            self.home_m[0] + start_m[0],
            self.home_m[1] + start_m[1],
            self.home_m[2] + start_m[2],
        ];
        self.airborne = true;
        Ok(())
    }

    /// Compile segment `index` (from 0): the one place each kind is sent to its method.
    fn segment(&mut self, index: usize, spec: &SegmentSpec) -> Result<(), PlannerError> {
        self.seg = Seg {
            index,
            kind: spec.kind(),
            item: spec.item(),
        };
        self.kinds.push(spec.kind());
        self.items.push(spec.item());
        if self.loiter_until_reserve {
            return Err(self
                .seg
                .out_of_order("a loiter until the reserve ends the route: nothing can follow it"));
        }
        match *spec {
            SegmentSpec::TakeOff {
                altitude_m,
                climb_rate_mps,
                item: _,
            } => self.take_off(altitude_m, climb_rate_mps),
            SegmentSpec::Leg {
                altitude_m,
                ground_speed_mps,
                payload_after_kg,
                acceptance_radius_m,
                ..
            } => self.leg_to(
                acceptance_radius_m,
                spec.point(),
                altitude_m,
                ground_speed_mps,
                payload_after_kg,
            ),
            SegmentSpec::Return {
                ground_speed_mps,
                altitude_m,
                item: _,
            } => self.return_home(ground_speed_mps, altitude_m),
            SegmentSpec::Orbit {
                altitude_m,
                radius_m,
                ground_speed_mps,
                direction,
                laps,
                duration_s,
                ..
            } => self.orbit(
                spec.point(),
                altitude_m,
                radius_m,
                ground_speed_mps,
                direction,
                (laps, duration_s),
            ),
            SegmentSpec::Hover {
                duration_s,
                payload_after_kg,
                item: _,
            } => self.hover(duration_s, payload_after_kg),
            SegmentSpec::Descent {
                altitude_m,
                rate_mps,
                item: _,
            } => self.descent(altitude_m, rate_mps),
            SegmentSpec::Landing {
                rate_mps,
                payload_after_kg,
                item: _,
                ground_m,
            } => self.landing(rate_mps, payload_after_kg, ground_m),
            SegmentSpec::LoiterUntilReserve { item: _ } => self.loiter_until_reserve(),
        }
    }

    /// The compiled mission, once the vehicle is back on the ground.
    fn finish(self, name: &str) -> Result<Mission, PlannerError> {
        if self.airborne && !(self.allow_end_in_air || self.loiter_until_reserve) {
            return Err(self
                .seg
                .out_of_order("the mission ends in the air: add a landing"));
        }
        Ok(Mission {
            name: name.to_string(),
            home_m: self.home_m,
            pieces: match self.corners {
                CornerMode::Pass => pass_through(self.pieces, &self.roles, self.airframe),
                CornerMode::Stop => self.pieces,
            },
            kinds: self.kinds,
            payloads_kg: self.payloads_kg,
            items: self.items,
            ends_in_air: self.airborne,
            loiter_until_reserve: self.loiter_until_reserve,
            warnings: self.warnings,
        })
    }

    // ---- One method per segment kind ----

    /// `take-off`: a vertical climb from the ground.
    fn take_off(&mut self, altitude_m: f64, climb_rate_mps: f64) -> Result<(), PlannerError> {
        let seg = self.seg;
        if self.airborne {
            return Err(seg.out_of_order("the vehicle is already in the air"));
        }
        seg.positive("altitude_m", altitude_m, "m")?;
        // A rate beyond the vehicle's is flown at its limit (the envelope slows the climb).
        seg.positive("climb_rate_mps", climb_rate_mps, "m/s")?;
        self.vertical_to(altitude_m, climb_rate_mps)?;
        self.airborne = true;
        Ok(())
    }

    /// `leg` with the waypoint's acceptance radius (for a pass-through corner).
    fn leg_to(
        &mut self,
        acceptance_radius_m: Option<f64>,
        waypoint: [Option<f64>; 4],
        altitude_m: Option<f64>,
        ground_speed_mps: Option<f64>,
        payload_after_kg: Option<f64>,
    ) -> Result<(), PlannerError> {
        if let Some(r) = acceptance_radius_m {
            self.seg.positive("acceptance_radius_m", r, "m")?;
            self.seg.within("acceptance_radius_m", r, 1e3, "m")?;
        }
        self.acceptance_m = acceptance_radius_m;
        let flown = self.leg(waypoint, altitude_m, ground_speed_mps, payload_after_kg);
        self.acceptance_m = None;
        flown
    }

    /// `leg`: yaw, then straight to a waypoint at a horizontal ground speed.
    fn leg(
        &mut self,
        waypoint: [Option<f64>; 4],
        altitude_m: Option<f64>,
        ground_speed_mps: Option<f64>,
        payload_after_kg: Option<f64>,
    ) -> Result<(), PlannerError> {
        let seg = self.seg;
        self.need_air()?;
        let [east_m, north_m] = self.points.resolve(seg, waypoint, WAYPOINT_KEYS)?;
        let up_m = self.height("altitude_m", altitude_m.unwrap_or(self.pos_m[2]))?;
        let ground_speed_mps = self.ground_speed(ground_speed_mps)?;
        self.straight_to([east_m, north_m, up_m], ground_speed_mps)?;
        self.change_payload(payload_after_kg)
    }

    /// `return`: yaw, then straight back over home at the present height.
    fn return_home(
        &mut self,
        ground_speed_mps: Option<f64>,
        altitude_m: Option<f64>,
    ) -> Result<(), PlannerError> {
        let seg = self.seg;
        self.need_air()?;
        let ground_speed_mps = self.ground_speed(ground_speed_mps)?;
        // The height of the return: the segment's, else at least the mission's RTL altitude.
        let up_m = match (altitude_m, self.rtl_altitude_m) {
            (Some(a), _) => self.height("altitude_m", a)?,
            (None, Some(rtl)) => self.pos_m[2].max(seg.positive("rtl_altitude_m", rtl, "m")?),
            (None, None) => self.pos_m[2],
        };
        if up_m > self.pos_m[2] {
            let rate = self
                .airframe
                .max_climb_rate_mps()
                .min(RTL_VERTICAL_RATE_MPS);
            self.vertical_to(up_m, rate)?;
        } else if up_m < self.pos_m[2] {
            let rate = self
                .airframe
                .max_descent_rate_mps()
                .min(RTL_VERTICAL_RATE_MPS);
            self.vertical_to(up_m, rate)?;
        }
        let to_m = [self.home_m[0], self.home_m[1], up_m];
        self.straight_to(to_m, ground_speed_mps)
    }

    /// `loiter-until-reserve`: the route ends here, in the air; the vehicle hovers until the pack
    /// must fly home (the planner reports how long).
    fn loiter_until_reserve(&mut self) -> Result<(), PlannerError> {
        self.need_air()?;
        self.loiter_until_reserve = true;
        Ok(())
    }

    /// `orbit`: a straight transit to the nearest point of the circle, a yaw to its tangent, then
    /// the arc (`laps_or_duration_s`: exactly one of the laps and the time on the circle).
    fn orbit(
        &mut self,
        centre: [Option<f64>; 4],
        altitude_m: Option<f64>,
        radius_m: f64,
        ground_speed_mps: Option<f64>,
        direction: OrbitDirection,
        laps_or_duration_s: (Option<f64>, Option<f64>),
    ) -> Result<(), PlannerError> {
        let seg = self.seg;
        self.need_air()?;
        let centre_m = self.points.resolve(seg, centre, CENTRE_KEYS)?;
        seg.positive("radius_m", radius_m, "m")?;
        let ground_speed_mps = self.ground_speed(ground_speed_mps)?;
        let up_m = self.height("altitude_m", altitude_m.unwrap_or(self.pos_m[2]))?;
        // A circle too tight for the speed (v^2 / r beyond what the tilt allows with the drag) is
        // flown at the speed the vehicle can turn it at: the envelope slows it.
        let length_m = self.orbit_length_m(radius_m, ground_speed_mps, laps_or_duration_s)?;
        let phi0_rad = self.transit_to_circle(centre_m, radius_m, up_m, ground_speed_mps)?;
        let sign = match direction {
            OrbitDirection::CounterClockwise => 1.0,
            OrbitDirection::Clockwise => -1.0,
        };
        let tangent = [-sign * phi0_rad.sin(), sign * phi0_rad.cos()];
        self.yaw_to(tangent)?;
        self.fly_arc(
            Shape::Arc(Circle {
                centre_m,
                radius_m,
                up_m,
                phi0_rad,
                sign,
            }),
            Profile::rest_to_rest(
                length_m,
                ground_speed_mps,
                self.airframe.acceleration_mps2(),
            ),
            tangent,
        );
        Ok(())
    }

    /// `hover`: hold in place.
    fn hover(
        &mut self,
        duration_s: f64,
        payload_after_kg: Option<f64>,
    ) -> Result<(), PlannerError> {
        self.need_air()?;
        self.seg.positive("duration_s", duration_s, "s")?;
        self.push(
            Shape::Hold { pos_m: self.pos_m },
            Profile::hold(duration_s),
            self.heading,
            Role::Other,
        )?;
        self.change_payload(payload_after_kg)
    }

    /// `descent`: vertical, to a lower height.
    fn descent(&mut self, altitude_m: f64, rate_mps: f64) -> Result<(), PlannerError> {
        let seg = self.seg;
        self.need_air()?;
        self.height("altitude_m", altitude_m)?;
        // A rate beyond the vehicle's is flown at its limit (the envelope slows the descent).
        seg.positive("rate_mps", rate_mps, "m/s")?;
        if altitude_m >= self.pos_m[2] {
            return Err(seg.invalid(
                "altitude_m",
                altitude_m,
                "m",
                "a descent must end below the present height",
            ));
        }
        self.vertical_to(altitude_m, rate_mps)?;
        Ok(())
    }

    /// `landing`: vertical, to the ground.
    fn landing(
        &mut self,
        rate_mps: f64,
        payload_after_kg: Option<f64>,
        ground_m: Option<f64>,
    ) -> Result<(), PlannerError> {
        let seg = self.seg;
        self.need_air()?;
        // A rate beyond the vehicle's is flown at its limit (the envelope slows the descent).
        seg.positive("rate_mps", rate_mps, "m/s")?;
        let mut ground_m = seg.finite("ground_m", ground_m.unwrap_or(0.0), "m")?;
        // Over terrain a vehicle below the ground it lands on has flown into it: the caller's
        // clearance says so; it lands where it is.
        if self.over_terrain {
            ground_m = ground_m.min(self.pos_m[2]);
        }
        if ground_m > self.pos_m[2] {
            return Err(seg.invalid(
                "ground_m",
                ground_m,
                "m",
                "the ground where it lands is above the vehicle",
            ));
        }
        self.vertical_to(ground_m, rate_mps)?;
        self.airborne = false;
        self.change_payload(payload_after_kg)
    }

    // ---- Steps the kinds share ----

    /// A height to fly at: above home's (positive), or over terrain any finite height (the
    /// ground under it is judged by the caller).
    fn height(&self, key: &'static str, up_m: f64) -> Result<f64, PlannerError> {
        if self.over_terrain {
            self.seg.finite(key, up_m, "m")
        } else {
            self.seg.positive(key, up_m, "m")
        }
    }

    /// Every kind but a take-off needs the vehicle in the air.
    fn need_air(&self) -> Result<(), PlannerError> {
        if self.airborne {
            Ok(())
        } else {
            Err(self
                .seg
                .out_of_order("the vehicle is on the ground: take off first"))
        }
    }

    /// The ground speed of this segment: its own, else the mission's default; positive, and
    /// flown at the vehicle's maximum (with a warning) when beyond it, as an autopilot limits
    /// its commanded speed (for a planner file, at the speed it can reach within its tilt
    /// limit in still air when that is lower).
    fn ground_speed(&mut self, ground_speed_mps: Option<f64>) -> Result<f64, PlannerError> {
        let seg = self.seg;
        let v = ground_speed_mps.or(self.default_speed_mps).ok_or(
            seg.out_of_order("give ground_speed_mps, or a default_speed_mps for the mission"),
        )?;
        seg.positive("ground_speed_mps", v, "m/s")?;
        let max = self.airframe.max_speed_mps();
        let clamp = match self.clamp_speeds {
            true => self.clamp_to_mps.map_or(max, |c| c.min(max)),
            false => max,
        };
        // 1e-9 relative: a value typed equal to the limit is within it despite rounding.
        if v > clamp * (1.0 + 1e-9) {
            let why = if clamp < max {
                format!("beyond the {clamp:.2} m/s the vehicle can reach within its tilt limit")
            } else {
                format!("beyond the vehicle's {max} m/s")
            };
            self.warnings.push(format!(
                "{}: ground speed {v} m/s is {why}: flown at {clamp:.2} m/s",
                seg.name()
            ));
            return Ok(clamp);
        }
        Ok(v)
    }

    /// The payload changes after this segment when `payload_after_kg` is given: a new mass phase,
    /// within the take-off mass limit.
    fn change_payload(&mut self, payload_after_kg: Option<f64>) -> Result<(), PlannerError> {
        if let Some(p) = self.seg.payload_after(payload_after_kg)? {
            self.check_take_off_mass(p)?;
            self.payloads_kg.push(p);
        }
        Ok(())
    }

    /// Airframe, battery and `payload_kg` together are within the maximum take-off mass.
    fn check_take_off_mass(&self, payload_kg: f64) -> Result<(), PlannerError> {
        let m = self.airframe.mass_kg() + self.battery_mass_kg + payload_kg;
        if m > self.airframe.max_takeoff_mass_kg() * (1.0 + 1e-9) {
            return Err(PlannerError::Unreachable {
                index: 0,
                kind: "mission",
                item: None,
                name: "take-off mass (airframe + battery + payload)",
                value: m,
                limit: self.airframe.max_takeoff_mass_kg(),
                unit: "kg",
            });
        }
        Ok(())
    }

    /// The mass phase pieces are in now: the number of payload changes so far.
    fn mass_phase(&self) -> usize {
        self.payloads_kg.len() - 1
    }

    /// Add a piece of the present segment, unless it takes no time; it plays `role` in the
    /// corner pass.
    fn push(
        &mut self,
        shape: Shape,
        profile: Profile,
        forward: [f64; 2],
        role: Role,
    ) -> Result<(), PlannerError> {
        self.seg.duration(profile.duration_s)?;
        if profile.duration_s > 0.0 {
            self.pieces.push(Piece {
                shape,
                profile,
                segment: self.seg.index,
                mass_phase: self.mass_phase(),
                forward,
            });
            self.roles.push(role);
        }
        Ok(())
    }

    /// Yaw in place, hovering at the airframe's yaw rate, until the nose points along `to` (a
    /// unit east-north vector). Turns under 1e-6 rad take no piece.
    fn yaw_to(&mut self, to: [f64; 2]) -> Result<(), PlannerError> {
        let turn = turn_rad(self.heading, to);
        if turn > 1e-6 {
            self.push(
                Shape::Hold { pos_m: self.pos_m },
                Profile::hold(turn / self.airframe.yaw_rate_radps()),
                self.heading,
                Role::Yaw,
            )?;
        }
        self.heading = to;
        Ok(())
    }

    /// A straight path from here to `to_m` with a horizontal ground speed, from rest to rest;
    /// yaws first when the path has a horizontal part. Nothing when `to_m` is here.
    fn straight_to(&mut self, to_m: [f64; 3], ground_speed_mps: f64) -> Result<(), PlannerError> {
        let pos = self.pos_m;
        let d = [to_m[0] - pos[0], to_m[1] - pos[1], to_m[2] - pos[2]];
        let h = d[0].hypot(d[1]);
        let len = (h * h + d[2] * d[2]).sqrt();
        if len < 1e-9 {
            return Ok(());
        }
        let (path_speed, path_acc) = if h > 1e-9 {
            self.yaw_to([d[0] / h, d[1] / h])?;
            self.sloped_speed_and_acceleration(d, h, len, ground_speed_mps)?
        } else {
            // Vertical leg: the ground speed does not apply; use the rate limit.
            let v = if d[2] > 0.0 {
                self.airframe.max_climb_rate_mps()
            } else {
                self.airframe.max_descent_rate_mps()
            };
            (v, self.airframe.vertical_acceleration_mps2())
        };
        // A leg or return with a horizontal part may be flown through a corner at either end
        // (a turn only between level lines at one height: see `corners.rs`).
        let role = match self.seg.kind {
            "leg" | "return" if h > 1e-9 => Role::Level {
                cruise_mps: path_speed,
                accel_mps2: path_acc,
                acceptance_m: self
                    .acceptance_m
                    .unwrap_or(self.airframe.acceptance_radius_m()),
            },
            _ => Role::Other,
        };
        self.push(
            Shape::Line {
                start_m: pos,
                dir: [d[0] / len, d[1] / len, d[2] / len],
            },
            Profile::rest_to_rest(len, path_speed, path_acc),
            self.heading,
            role,
        )?;
        self.pos_m = to_m;
        Ok(())
    }

    /// Speed and acceleration along a path `d` (m) with horizontal length `h` and length `len`
    /// flown at a horizontal ground speed, within both acceleration limits. A vertical rate
    /// beyond the climb or descent limit is flown at the limit (the envelope slows the leg).
    fn sloped_speed_and_acceleration(
        &mut self,
        d: [f64; 3],
        h: f64,
        len: f64,
        ground_speed_mps: f64,
    ) -> Result<(f64, f64), PlannerError> {
        let a_h = self.airframe.acceleration_mps2();
        let a_v = self.airframe.vertical_acceleration_mps2();
        let acc = if d[2].abs() > 1e-9 {
            (a_h * len / h).min(a_v * len / d[2].abs())
        } else {
            a_h
        };
        Ok((ground_speed_mps * len / h, acc))
    }

    /// A vertical path from here to height `to_z_m` at `rate_mps`, from rest to rest.
    fn vertical_to(&mut self, to_z_m: f64, rate_mps: f64) -> Result<(), PlannerError> {
        let pos = self.pos_m;
        let len = (to_z_m - pos[2]).abs();
        if len > 0.0 {
            self.push(
                Shape::Line {
                    start_m: pos,
                    dir: [0.0, 0.0, (to_z_m - pos[2]).signum()],
                },
                Profile::rest_to_rest(len, rate_mps, self.airframe.vertical_acceleration_mps2()),
                self.heading,
                Role::Other,
            )?;
        }
        self.pos_m[2] = to_z_m;
        Ok(())
    }

    /// Length of an orbit's arc, m: `laps` whole circles, or what a trapezoid speed profile
    /// covers in `duration_s` (exactly one of the two).
    fn orbit_length_m(
        &self,
        radius_m: f64,
        ground_speed_mps: f64,
        (laps, duration_s): (Option<f64>, Option<f64>),
    ) -> Result<f64, PlannerError> {
        let seg = self.seg;
        match (laps, duration_s) {
            (Some(l), None) => Ok(seg.positive("laps", l, "")? * std::f64::consts::TAU * radius_m),
            (None, Some(d)) => {
                let d = seg.positive("duration_s", d, "s")?;
                // Trapezoid time L / v + v / a = d.
                let l =
                    ground_speed_mps * (d - ground_speed_mps / self.airframe.acceleration_mps2());
                if l <= 0.0 {
                    return Err(seg.invalid(
                        "duration_s",
                        d,
                        "s",
                        "too short to reach the orbit speed and stop again",
                    ));
                }
                Ok(l)
            }
            _ => Err(seg.out_of_order("give exactly one of laps and duration_s")),
        }
    }

    /// Straight from here to the nearest point of the circle (centre `centre_m`, radius
    /// `radius_m`, height `up_m`); returns that point's angle from east, rad (0 from the centre).
    fn transit_to_circle(
        &mut self,
        centre_m: [f64; 2],
        radius_m: f64,
        up_m: f64,
        ground_speed_mps: f64,
    ) -> Result<f64, PlannerError> {
        let rel = [self.pos_m[0] - centre_m[0], self.pos_m[1] - centre_m[1]];
        let dist = rel[0].hypot(rel[1]);
        let phi0_rad = if dist > 1e-9 {
            rel[1].atan2(rel[0])
        } else {
            0.0
        };
        let entry_m = [
            centre_m[0] + radius_m * phi0_rad.cos(),
            centre_m[1] + radius_m * phi0_rad.sin(),
            up_m,
        ];
        self.straight_to(entry_m, ground_speed_mps)?;
        Ok(phi0_rad)
    }

    /// Fly an arc piece (always added, whatever its duration); the vehicle ends at its end,
    /// heading along the tangent there.
    fn fly_arc(&mut self, shape: Shape, profile: Profile, forward: [f64; 2]) {
        let arc = Piece {
            shape,
            profile,
            segment: self.seg.index,
            mass_phase: self.mass_phase(),
            forward,
        };
        self.pos_m = arc.end_m();
        self.heading = arc.at(arc.duration_s()).forward;
        self.pieces.push(arc);
        self.roles.push(Role::Other);
    }
}
