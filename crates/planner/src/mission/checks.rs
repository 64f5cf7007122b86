//! Checks of one segment's values, and the point resolver: each error names the segment (from 1),
//! its kind, the key, the value and what was expected.

use crate::error::PlannerError;
use crate::geodesy::LocalFrame;

pub(super) fn bad_seg(
    index: usize,
    kind: &'static str,
    name: &'static str,
    value: f64,
    unit: &'static str,
    expected: &'static str,
) -> PlannerError {
    PlannerError::InvalidSegment {
        index: index + 1,
        kind,
        name,
        value,
        unit,
        expected,
    }
}

pub(super) fn seg_positive(
    i: usize,
    kind: &'static str,
    name: &'static str,
    v: f64,
    unit: &'static str,
) -> Result<f64, PlannerError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else if name.contains("altitude") {
        Err(bad_seg(
            i,
            kind,
            name,
            v,
            unit,
            "the height above home must be above the ground (positive)",
        ))
    } else {
        Err(bad_seg(
            i,
            kind,
            name,
            v,
            unit,
            "must be positive and finite",
        ))
    }
}

pub(super) fn seg_limit(
    i: usize,
    kind: &'static str,
    name: &'static str,
    v: f64,
    limit: f64,
    unit: &'static str,
) -> Result<(), PlannerError> {
    // 1e-9 relative: a value typed equal to the limit passes despite rounding.
    if v > limit * (1.0 + 1e-9) {
        Err(PlannerError::Unreachable {
            index: i + 1,
            kind,
            name,
            value: v,
            limit,
            unit,
        })
    } else {
        Ok(())
    }
}

pub(super) fn seg_payload(
    i: usize,
    kind: &'static str,
    p: Option<f64>,
) -> Result<Option<f64>, PlannerError> {
    match p {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err(bad_seg(
            i,
            kind,
            "payload_after_kg",
            v,
            "kg",
            "must be finite and not negative",
        )),
        other => Ok(other),
    }
}

/// Resolves points given in either local metres or latitude/longitude.
pub(super) struct Points {
    pub(super) frame: Option<LocalFrame>,
}

impl Points {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn resolve(
        &self,
        i: usize,
        kind: &'static str,
        east: Option<f64>,
        north: Option<f64>,
        lat: Option<f64>,
        lon: Option<f64>,
        names: [&'static str; 4],
    ) -> Result<[f64; 2], PlannerError> {
        match (east, north, lat, lon) {
            (Some(e), Some(n), None, None) => {
                for (v, name) in [(e, names[0]), (n, names[1])] {
                    if !v.is_finite() {
                        return Err(bad_seg(i, kind, name, v, "m", "must be finite"));
                    }
                }
                Ok([e, n])
            }
            (None, None, Some(la), Some(lo)) => {
                let frame = self.frame.ok_or(PlannerError::SegmentOrder {
                    index: i + 1,
                    kind,
                    reason: "a point in latitude/longitude needs the home point in latitude/longitude",
                })?;
                if !(la.is_finite() && la.abs() < 90.0) {
                    return Err(bad_seg(i, kind, names[2], la, "deg", "must be within (-90, 90)"));
                }
                if !lo.is_finite() {
                    return Err(bad_seg(i, kind, names[3], lo, "deg", "must be finite"));
                }
                Ok(frame.to_local_m(la, lo))
            }
            _ => Err(PlannerError::SegmentOrder {
                index: i + 1,
                kind,
                reason: "give the point as east_m and north_m, or as latitude_deg and longitude_deg (exactly one pair)",
            }),
        }
    }
}
