//! Checks of a mission's values and the point resolver. Each error names what it is about: the
//! segment (numbered from 1) and its kind, the key, the value with its unit, and what was expected.

use super::HomeSpec;
use crate::error::PlannerError;
use crate::geodesy::LocalFrame;

/// Largest magnitude of a mission's values in their units (a coordinate of 10,000 km, a hold of
/// 115 days): beyond it a value is a mistake, and the arithmetic of the flight would overflow.
pub const MAX_MISSION_VALUE: f64 = 1e7;

/// Longest a segment's piece of trajectory may take, s (31.7 years): a slower speed or longer
/// path than that is a mistake (a speed of 1e-320 m/s), and its steps could not be counted.
pub const MAX_PIECE_S: f64 = 1e9;

/// The range of a home point's ground altitude above mean sea level, m: from below the shore
/// of the Dead Sea (-430 m) to above the summit of Everest (8,849 m). The altitude is
/// informational (heights are above home), but a value outside it is a mistake, and one that is
/// not finite would be written back as `null`.
pub const HOME_AMSL_RANGE_M: (f64, f64) = (-500.0, 10_000.0);

/// The segment a check is about: its place in the mission (from 0) and its kind as written.
#[derive(Debug, Clone, Copy)]
pub(super) struct Seg {
    /// Index in the mission's segments, from 0 (errors number segments from 1).
    pub(super) index: usize,
    /// Kind as written in the file (`leg`, `orbit`, ...).
    pub(super) kind: &'static str,
    /// The operator's item number, when the segment came from a planner file.
    pub(super) item: Option<u32>,
}

impl Seg {
    /// The segment in words: `item 7 (leg)` for a segment from a planner file, else
    /// `segment 3 (leg)`.
    pub(super) fn name(self) -> String {
        match self.item {
            Some(i) => format!("item {i} ({})", self.kind),
            None => format!("segment {} ({})", self.index + 1, self.kind),
        }
    }

    /// A value of this segment is invalid in itself.
    pub(super) fn invalid(
        self,
        name: &'static str,
        value: f64,
        unit: &'static str,
        expected: &'static str,
    ) -> PlannerError {
        PlannerError::InvalidSegment {
            index: self.index + 1,
            kind: self.kind,
            item: self.item,
            name,
            value,
            unit,
            expected,
        }
    }

    /// This segment cannot be flown here, for `reason`.
    pub(super) fn out_of_order(self, reason: &'static str) -> PlannerError {
        PlannerError::SegmentOrder {
            index: self.index + 1,
            kind: self.kind,
            item: self.item,
            reason,
        }
    }

    /// `value` itself when it is positive and finite; heights (keys naming an altitude) say they
    /// must be above the ground.
    pub(super) fn positive(
        self,
        name: &'static str,
        value: f64,
        unit: &'static str,
    ) -> Result<f64, PlannerError> {
        if value.is_finite() && value > 0.0 && value <= MAX_MISSION_VALUE {
            Ok(value)
        } else if value.is_finite() && value > MAX_MISSION_VALUE {
            Err(self.invalid(name, value, unit, "at most 1e7 (a mistake beyond it)"))
        } else if name.contains("altitude") {
            Err(self.invalid(
                name,
                value,
                unit,
                "the height above home must be above the ground (positive)",
            ))
        } else {
            Err(self.invalid(name, value, unit, "must be positive and finite"))
        }
    }

    /// `value` itself when it is finite and within [`MAX_MISSION_VALUE`] of zero.
    pub(super) fn finite(
        self,
        name: &'static str,
        value: f64,
        unit: &'static str,
    ) -> Result<f64, PlannerError> {
        if value.is_finite() && value.abs() <= MAX_MISSION_VALUE {
            Ok(value)
        } else {
            Err(self.invalid(name, value, unit, "finite, within 1e7 of home's height"))
        }
    }

    /// A piece of this segment that takes `duration_s` can be flown: finite and at most
    /// [`MAX_PIECE_S`].
    pub(super) fn duration(self, duration_s: f64) -> Result<(), PlannerError> {
        if duration_s.is_finite() && duration_s <= MAX_PIECE_S {
            Ok(())
        } else {
            Err(PlannerError::SegmentTooLong {
                index: self.index + 1,
                kind: self.kind,
                item: self.item,
                duration_s,
                max_s: MAX_PIECE_S,
            })
        }
    }

    /// `value` is within the vehicle's `limit`.
    pub(super) fn within(
        self,
        name: &'static str,
        value: f64,
        limit: f64,
        unit: &'static str,
    ) -> Result<(), PlannerError> {
        // 1e-9 relative: a value typed equal to the limit passes despite rounding.
        if value > limit * (1.0 + 1e-9) {
            Err(PlannerError::Unreachable {
                index: self.index + 1,
                kind: self.kind,
                item: self.item,
                name,
                value,
                limit,
                unit,
            })
        } else {
            Ok(())
        }
    }

    /// The payload after this segment, when given: finite and not negative.
    pub(super) fn payload_after(
        self,
        payload_kg: Option<f64>,
    ) -> Result<Option<f64>, PlannerError> {
        match payload_kg {
            Some(v) if !(0.0..=MAX_MISSION_VALUE).contains(&v) => Err(self.invalid(
                "payload_after_kg",
                v,
                "kg",
                "must be finite, not negative and at most 1e7",
            )),
            other => Ok(other),
        }
    }
}

/// The home point in local metres: `east_m`/`north_m` when given (each defaults to 0), the origin
/// when the home is in latitude/longitude; height 0. The ground altitude, when given, is checked
/// against [`HOME_AMSL_RANGE_M`].
///
/// # Errors
/// [`PlannerError::InvalidParameter`] for a coordinate that is not finite, or a ground altitude
/// that is not finite or outside [`HOME_AMSL_RANGE_M`].
pub(super) fn home_position_m(home: &HomeSpec) -> Result<[f64; 3], PlannerError> {
    let home_m = [home.east_m.unwrap_or(0.0), home.north_m.unwrap_or(0.0), 0.0];
    for (v, name) in [(home_m[0], "home east_m"), (home_m[1], "home north_m")] {
        if !(v.is_finite() && v.abs() <= MAX_MISSION_VALUE) {
            return Err(aloft_core::InvalidParameter {
                name,
                value: v,
                unit: "m",
                expected: "a finite coordinate of at most 1e7 m in magnitude",
            }
            .into());
        }
    }
    let (lo, hi) = HOME_AMSL_RANGE_M;
    match home.altitude_amsl_m {
        // `contains` is false for NaN.
        Some(v) if !(lo..=hi).contains(&v) => Err(aloft_core::InvalidParameter {
            name: "home altitude_amsl_m",
            value: v,
            unit: "m",
            expected: "a finite ground altitude from -500 to 10000 m above mean sea level",
        }
        .into()),
        _ => Ok(home_m),
    }
}

/// Resolves points given in either local metres or latitude/longitude.
///
/// A point in latitude/longitude is placed from the last such point (the home at first) in the
/// local frame of that point, so each leg's length and direction are those of its own tangent
/// plane: a survey hundreds of kilometres from its home point keeps its legs' lengths, which one
/// flat frame at home would stretch (by about 2 % east-west 300 km north of home at 25 deg).
pub(super) struct Points {
    /// The last point given in latitude/longitude (the home at first): its latitude, longitude
    /// and local metres; none for a home in metres.
    last: Option<(f64, f64, [f64; 2])>,
}

impl Points {
    /// The resolver for a mission with this home point.
    ///
    /// # Errors
    /// [`PlannerError::InvalidParameter`] for a latitude/longitude that is out of range or not
    /// finite, or a home given both ways or by half a pair.
    pub(super) fn for_home(home: &HomeSpec) -> Result<Self, PlannerError> {
        let frame =
            match (
                home.east_m,
                home.north_m,
                home.latitude_deg,
                home.longitude_deg,
            ) {
                (None, None, Some(la), Some(lo)) => {
                    let ok = la.is_finite() && la.abs() < 90.0;
                    let expected = "a latitude within (-90, 90)";
                    aloft_core::parameter("home latitude_deg", la, "deg", ok, expected)?;
                    let ok = lo.is_finite() && lo.abs() <= 180.0;
                    let expected = "a longitude within [-180, 180]";
                    aloft_core::parameter("home longitude_deg", lo, "deg", ok, expected)?;
                    Some((la, lo))
                }
                (_, _, None, None) => None,
                _ => return Err(aloft_core::InvalidParameter {
                    name: "home latitude_deg",
                    value: home.latitude_deg.unwrap_or(f64::NAN),
                    unit: "deg",
                    expected:
                        "home as east_m/north_m or as latitude_deg/longitude_deg, not both or half",
                }
                .into()),
            };
        Ok(Self {
            last: frame.map(|(la, lo)| (la, lo, [0.0, 0.0])),
        })
    }

    /// The local east/north metres of a point given as `[east, north, latitude, longitude]`
    /// (exactly one pair), with the keys of those four in `names` for the errors.
    pub(super) fn resolve(
        &mut self,
        seg: Seg,
        given: [Option<f64>; 4],
        names: [&'static str; 4],
    ) -> Result<[f64; 2], PlannerError> {
        match given {
            [Some(e), Some(n), None, None] => {
                for (v, name) in [(e, names[0]), (n, names[1])] {
                    if !(v.is_finite() && v.abs() <= MAX_MISSION_VALUE) {
                        return Err(seg.invalid(name, v, "m", "must be finite, at most 1e7 m"));
                    }
                }
                Ok([e, n])
            }
            [None, None, Some(la), Some(lo)] => {
                self.last.ok_or(seg.out_of_order(
                    "a point in latitude/longitude needs the home point in latitude/longitude",
                ))?;
                if !(la.is_finite() && la.abs() < 90.0) {
                    return Err(seg.invalid(names[2], la, "deg", "must be within (-90, 90)"));
                }
                if !(lo.is_finite() && lo.abs() <= 180.0) {
                    return Err(seg.invalid(names[3], lo, "deg", "must be within [-180, 180]"));
                }
                Ok(self.chained(la, lo))
            }
            _ => Err(seg.out_of_order(
                "give the point as east_m and north_m, or as latitude_deg and longitude_deg (exactly one pair)",
            )),
        }
    }

    /// Local metres of a valid latitude/longitude: the last such point's, plus the offset in
    /// that point's tangent plane; it becomes the last point.
    fn chained(&mut self, la: f64, lo: f64) -> [f64; 2] {
        let Some((la0, lo0, at_m)) = self.last else {
            return [0.0, 0.0];
        };
        let d = LocalFrame::new(la0, lo0).to_local_m(la, lo);
        let here = [at_m[0] + d[0], at_m[1] + d[1]];
        self.last = Some((la, lo, here));
        here
    }
}
