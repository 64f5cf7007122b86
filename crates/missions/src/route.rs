//! The route figures of a mission spec: the file's own geometry, whatever the file's format.
//!
//! - `horizontal_m`: straight lines from the launch point (home) through every position in
//!   flying order (a leg's waypoint, an orbit's centre, home for a return), plus each orbit's
//!   circles (laps x 2 pi r, or its ground speed x its time); distances per leg on the WGS-84
//!   ellipsoid between latitude/longitude points, in the plane between local points (a mix is
//!   placed in the planner's tangent frame at home);
//! - `climb_m`, `descent_m`: the sums of the planned height changes, the take-off from the ground
//!   and the landing to it included; a return flies at its own height (the segment's, else the
//!   present height or the file's RTL altitude when higher), then down;
//! - `hold_s`: the hovers (holds, loiter times, delays).
//!
//! It is not the flown path (corners, the transit to an orbit's circle, an RTL altitude from the
//! vehicle or the command line change that, not these figures). A route that ends in the air
//! adds no return. Values that are not finite in the spec are passed over (the planner refuses
//! them); the figures are always finite.

use serde::{Deserialize, Serialize};

use aloft_planner::geodesy::LocalFrame;
use aloft_planner::{MissionSpec, SegmentSpec};

use crate::geo::{distance_m, LatLon};
use crate::{ItemCounts, SourceFormat};

/// The planned route of a mission (the `route` of `aloft mission --format json`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RouteFigures {
    /// The mission file's format: `qgc_plan`, `qgc_wpl`, `aloft_toml`, `aloft_json`.
    pub source_format: SourceFormat,
    /// Planned horizontal path, m.
    pub horizontal_m: f64,
    /// Sum of the planned climbs, m.
    pub climb_m: f64,
    /// Sum of the planned descents, m.
    pub descent_m: f64,
    /// Timed holds and delays, s.
    pub hold_s: f64,
    /// The items of a planner file by role (absent for aloft's own files).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub items: Option<ItemCounts>,
    /// What the reader adjusted or could not model.
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// A position: latitude/longitude, or local east/north metres.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Pos {
    Geo(LatLon),
    Local([f64; 2]),
}

/// The route figures of `spec`, read from `format`, with the reader's `warnings`.
pub fn route_figures(
    spec: &MissionSpec,
    source_format: SourceFormat,
    warnings: Vec<String>,
) -> RouteFigures {
    let mut walk = Walk::new(spec);
    for (k, s) in spec.segments.iter().enumerate() {
        walk.segment(k, s);
    }
    let mut warnings = warnings;
    warnings.extend(walk.notes);
    let mut figures = RouteFigures {
        source_format,
        horizontal_m: walk.horizontal_m,
        climb_m: walk.climb_m,
        descent_m: walk.descent_m,
        hold_s: walk.hold_s,
        items: None,
        warnings,
    };
    for v in [
        &mut figures.horizontal_m,
        &mut figures.climb_m,
        &mut figures.descent_m,
        &mut figures.hold_s,
    ] {
        if !v.is_finite() {
            *v = 0.0;
            figures
                .warnings
                .push("a route figure overflowed and is given as 0".to_string());
        }
    }
    figures
}

/// The walk along the spec's segments.
struct Walk {
    home: Pos,
    frame: Option<LocalFrame>,
    here: Pos,
    height_m: f64,
    rtl_altitude_m: Option<f64>,
    default_speed_mps: Option<f64>,
    horizontal_m: f64,
    climb_m: f64,
    descent_m: f64,
    hold_s: f64,
    notes: Vec<String>,
}

impl Walk {
    fn new(spec: &MissionSpec) -> Self {
        let h = &spec.home;
        let home = match point([h.east_m, h.north_m, h.latitude_deg, h.longitude_deg]) {
            Some(p) => p,
            None => Pos::Local([0.0, 0.0]),
        };
        let frame = match home {
            Pos::Geo(g) => Some(LocalFrame::new(g.latitude_deg, g.longitude_deg)),
            Pos::Local(_) => None,
        };
        Self {
            home,
            frame,
            here: home,
            height_m: 0.0,
            rtl_altitude_m: spec.rtl_altitude_m.filter(|v| v.is_finite()),
            default_speed_mps: spec.default_speed_mps.filter(|v| v.is_finite()),
            horizontal_m: 0.0,
            climb_m: 0.0,
            descent_m: 0.0,
            hold_s: 0.0,
            notes: Vec::new(),
        }
    }

    fn segment(&mut self, k: usize, s: &SegmentSpec) {
        match s {
            SegmentSpec::TakeOff { altitude_m, .. } => self.climb_or_descend_to(Some(*altitude_m)),
            SegmentSpec::Leg { altitude_m, .. } => {
                self.move_to(point(s.point()));
                self.climb_or_descend_to(*altitude_m);
            }
            SegmentSpec::Orbit { .. } => self.orbit(k, s),
            SegmentSpec::Hover { duration_s, .. } => {
                if duration_s.is_finite() && *duration_s > 0.0 {
                    self.hold_s += duration_s;
                }
            }
            SegmentSpec::Return { altitude_m, .. } => {
                let up = altitude_m.or_else(|| self.rtl_altitude_m.map(|r| r.max(self.height_m)));
                self.climb_or_descend_to(up);
                self.move_to(Some(self.home));
            }
            SegmentSpec::Descent { altitude_m, .. } => self.climb_or_descend_to(Some(*altitude_m)),
            SegmentSpec::Landing { ground_m, .. } => {
                self.climb_or_descend_to(Some(ground_m.unwrap_or(0.0)))
            }
            SegmentSpec::LoiterUntilReserve { .. } => {}
        }
    }

    /// An orbit: to its centre, to its height, then its circles.
    fn orbit(&mut self, k: usize, s: &SegmentSpec) {
        let SegmentSpec::Orbit {
            altitude_m,
            radius_m,
            ground_speed_mps,
            laps,
            duration_s,
            ..
        } = s
        else {
            return;
        };
        self.move_to(point(s.point()));
        self.climb_or_descend_to(*altitude_m);
        let circle_m = std::f64::consts::TAU * radius_m.abs();
        let speed = ground_speed_mps.or(self.default_speed_mps);
        let arc_m = match (laps, duration_s, speed) {
            (Some(l), _, _) => l * circle_m,
            (None, Some(t), Some(v)) => t * v,
            _ => {
                self.notes.push(format!(
                    "segment {} (orbit): a time on the circle without a speed: its arc is not in horizontal_m",
                    k + 1
                ));
                0.0
            }
        };
        if arc_m.is_finite() && arc_m > 0.0 {
            self.horizontal_m += arc_m;
        }
    }

    /// Horizontally to `to` (none: stay).
    fn move_to(&mut self, to: Option<Pos>) {
        let Some(to) = to else { return };
        if let Some(d) = self.distance_m(self.here, to) {
            self.horizontal_m += d;
        }
        self.here = to;
    }

    /// Vertically to `height_m` (none or not finite: stay).
    fn climb_or_descend_to(&mut self, height_m: Option<f64>) {
        let Some(h) = height_m.filter(|h| h.is_finite()) else {
            return;
        };
        if h > self.height_m {
            self.climb_m += h - self.height_m;
        } else {
            self.descent_m += self.height_m - h;
        }
        self.height_m = h;
    }

    /// The distance between two positions; none for a point in latitude/longitude beside a
    /// home in local metres (a spec the planner refuses).
    fn distance_m(&self, a: Pos, b: Pos) -> Option<f64> {
        match (a, b) {
            (Pos::Geo(a), Pos::Geo(b)) => Some(distance_m(a, b)),
            (Pos::Local(a), Pos::Local(b)) => Some((b[0] - a[0]).hypot(b[1] - a[1])),
            (Pos::Geo(g), Pos::Local(l)) | (Pos::Local(l), Pos::Geo(g)) => {
                let f = self.frame?;
                let m = f.to_local_m(g.latitude_deg, g.longitude_deg);
                Some((m[0] - l[0]).hypot(m[1] - l[1]))
            }
        }
        .filter(|d| d.is_finite())
    }
}

/// The position given as `[east, north, latitude, longitude]`: exactly one finite pair, a
/// latitude/longitude within range; none otherwise.
fn point(given: [Option<f64>; 4]) -> Option<Pos> {
    let ok = |v: f64, max: f64| v.is_finite() && v.abs() <= max;
    match given {
        [Some(e), Some(n), None, None] if ok(e, 1e7) && ok(n, 1e7) => Some(Pos::Local([e, n])),
        [None, None, Some(la), Some(lo)] if ok(la, 90.0) && ok(lo, 180.0) => {
            Some(Pos::Geo(LatLon {
                latitude_deg: la,
                longitude_deg: lo,
            }))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use aloft_planner::mission_toml::{
        at_altitude, hover, landing, leg, orbit, return_home, take_off, OrbitFor::Laps,
    };

    fn toml(text: &str) -> RouteFigures {
        let spec = MissionSpec::from_toml_str(text).unwrap();
        route_figures(&spec, SourceFormat::AloftToml, Vec::new())
    }

    /// A local square with an orbit and a hover, by hand: 200 out, the orbit's centre 100 m on
    /// (plus 1.5 laps of r = 25), a hover of 30 s, home 223.6 m back; 30 m up, 10 m more on the
    /// way, 40 m down.
    #[test]
    fn the_figures_of_a_local_mission_are_its_lines_circles_and_heights() {
        let r = toml(
            &[
                take_off(30.0, 2.0),
                leg(200.0, 0.0, 8.0),
                at_altitude(
                    orbit([200.0, 100.0], 25.0, 4.0, "clockwise", Laps(1.5)),
                    40.0,
                ),
                hover(30.0),
                return_home(8.0),
                landing(1.0),
            ]
            .concat(),
        );
        let expected = 200.0 + 100.0 + 1.5 * std::f64::consts::TAU * 25.0 + 200f64.hypot(100.0);
        // Sums of a handful of exact terms: rounding only.
        assert!((r.horizontal_m - expected).abs() < 1e-9, "{r:?}");
        assert!((r.climb_m - 40.0).abs() < 1e-12);
        assert!((r.descent_m - 40.0).abs() < 1e-12);
        assert!((r.hold_s - 30.0).abs() < 1e-12);
        assert_eq!(r.source_format, SourceFormat::AloftToml);
        assert!(r.items.is_none());
    }

    #[test]
    fn a_return_climbs_to_the_files_rtl_altitude_and_bad_values_are_passed_over() {
        // A leg to a point that is not a number: passed over by the figures.
        let nan_leg =
            "[[segment]]\nkind = \"leg\"\neast_m = nan\nnorth_m = 0.0\nground_speed_mps = 8.0\n";
        let return_without_speed = "[[segment]]\nkind = \"return\"\n";
        let r = toml(
            &[
                "rtl_altitude_m = 50.0\n",
                &take_off(20.0, 2.0),
                nan_leg,
                return_without_speed,
                &landing(1.0),
            ]
            .concat(),
        );
        assert!((r.climb_m - 50.0).abs() < 1e-12, "{r:?}");
        assert!((r.descent_m - 50.0).abs() < 1e-12);
        assert!(r.horizontal_m.abs() < 1e-12);
    }

    #[test]
    fn the_json_keys_are_the_contract() {
        let r = RouteFigures {
            source_format: SourceFormat::QgcWpl,
            items: Some(ItemCounts::default()),
            ..RouteFigures::default()
        };
        let v: serde_json::Value = serde_json::to_value(&r).unwrap();
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
        for k in [
            "source_format",
            "horizontal_m",
            "climb_m",
            "descent_m",
            "hold_s",
            "items",
            "warnings",
        ] {
            assert!(keys.contains(&k), "{k} in {keys:?}");
        }
        assert_eq!(v["source_format"], "qgc_wpl");
    }
}
