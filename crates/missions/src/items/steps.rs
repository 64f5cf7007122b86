//! The steps the commands share: where an item sends the vehicle, climbing first when it is on
//! the ground, flying there, holding, landing, and what is left at the end.

use aloft_planner::mission::MAX_SEGMENTS;
use aloft_planner::SegmentSpec;

use super::{Autopilot, Flight, Target, Translation, LAND_SLOW_HEIGHT_M, MIN_HEIGHT_M};
use crate::commands::{role, CommandName, Role};
use crate::error::{ImportError, Place};
use crate::geo::LatLon;
use crate::notes::places_text;
use crate::raw_item::RawItem;
use crate::ItemCounts;

/// MAV_FRAME values with a position: 0 GLOBAL and 5 GLOBAL_INT (AMSL), 3 GLOBAL_RELATIVE_ALT
/// and 6 GLOBAL_RELATIVE_ALT_INT, 10 GLOBAL_TERRAIN_ALT and 11 GLOBAL_TERRAIN_ALT_INT.
const POSITION_FRAMES: &str =
    "0 or 5 (AMSL), 3 or 6 (relative to home), 10 or 11 (terrain, flown as relative)";

/// Heights closer than this are the same, m (a micrometre: the same value as written).
const SAME_HEIGHT_M: f64 = 1e-6;

impl Flight<'_> {
    /// The point and height `item` sends the vehicle to.
    pub(super) fn target(&mut self, item: &RawItem) -> Result<Target, ImportError> {
        self.check_position_frame(item)?;
        let point = self.point(item);
        let height_m = self.height(item)?;
        Ok(Target { point, height_m })
    }

    /// The item's frame can carry a position; frame 2 (MISSION) only when its point is "here".
    pub(super) fn check_position_frame(&self, item: &RawItem) -> Result<(), ImportError> {
        match item.frame {
            0 | 3 | 5 | 6 | 10 | 11 => Ok(()),
            2 if self.point(item).is_none() => Ok(()),
            frame => Err(ImportError::UnsupportedFrame {
                at: item.at,
                command: item.command,
                frame,
                expected: POSITION_FRAMES,
            }),
        }
    }

    /// The item's point; none ("here") when latitude and longitude are both 0 or not set.
    pub(super) fn point(&self, item: &RawItem) -> Option<LatLon> {
        let [.., lat, lon, _] = item.params;
        if lat.is_nan() || lon.is_nan() || (lat == 0.0 && lon == 0.0) {
            None
        } else {
            Some(LatLon {
                latitude_deg: lat,
                longitude_deg: lon,
            })
        }
    }

    /// The item's height above home from its frame and p7; none for the present height.
    fn height(&mut self, item: &RawItem) -> Result<Option<f64>, ImportError> {
        let alt = item.params[6];
        if alt.is_nan() || (alt == 0.0 && self.source.autopilot == Autopilot::ArduPilot) {
            return Ok(None);
        }
        let height_m = match item.frame {
            0 | 5 => {
                let home = self.source.home_amsl_m.ok_or(ImportError::NoHome {
                    at: item.at,
                    hint: "an altitude above mean sea level (frame 0) needs the home's altitude (a home row)",
                })?;
                // Over terrain the ground under the route is judged by the caller: an altitude
                // below home's (down a valley) is flown as it is.
                if self.source.options.terrain {
                    return Ok(Some(alt - home));
                }
                if alt < home {
                    self.notes.add(
                        item.at,
                        format!("altitude {alt} m above mean sea level is below home ({home} m)"),
                    );
                }
                alt - home
            }
            10 | 11 => {
                if !self.source.options.terrain {
                    self.notes.add(
                        item.at,
                        "terrain-relative altitude (frame 10/11) flown as relative to home (aloft has no terrain model)",
                    );
                }
                alt
            }
            // 3 and 6: relative to home; 2 carries no altitude.
            2 => return Ok(None),
            _ => alt,
        };
        Ok(Some(self.above_ground(item, height_m)))
    }

    /// `height_m` when it is above the ground, else [`MIN_HEIGHT_M`] with a warning.
    fn above_ground(&mut self, item: &RawItem, height_m: f64) -> f64 {
        if height_m >= MIN_HEIGHT_M {
            return height_m;
        }
        self.notes.add(
            item.at,
            format!(
                "height {} m above home is not above the ground: flown at {MIN_HEIGHT_M} m",
                round_cm(height_m)
            ),
        );
        MIN_HEIGHT_M
    }

    /// The height of a take-off from the ground: the target's, else [`MIN_HEIGHT_M`].
    pub(super) fn ground_height(&mut self, item: &RawItem, height_m: Option<f64>) -> f64 {
        match height_m {
            Some(h) => h,
            None => self.above_ground(item, 0.0),
        }
    }

    /// On the ground, a vertical take-off to the target's height first (warned).
    pub(super) fn climb_if_landed(
        &mut self,
        item: &RawItem,
        target: Target,
    ) -> Result<(), ImportError> {
        if self.airborne {
            return Ok(());
        }
        let height_m = self.ground_height(item, target.height_m);
        self.notes.add(
            item.at,
            format!(
                "{} on the ground without a take-off before it: a vertical take-off is added",
                CommandName(item.command)
            ),
        );
        self.vertical_take_off(item, height_m)
    }

    /// A vertical take-off to `height_m` at the autopilot's rate: the vehicle is then airborne
    /// at that height.
    pub(super) fn vertical_take_off(
        &mut self,
        item: &RawItem,
        height_m: f64,
    ) -> Result<(), ImportError> {
        self.push(
            item,
            SegmentSpec::TakeOff {
                altitude_m: height_m,
                climb_rate_mps: self.source.autopilot.take_off_rate_mps(),
                item: Some(item.number),
            },
        )?;
        self.airborne = true;
        self.height_m = height_m;
        Ok(())
    }

    /// A leg to the target, unless it is here at the present height.
    pub(super) fn fly_to(
        &mut self,
        item: &RawItem,
        target: Target,
        acceptance_m: Option<f64>,
    ) -> Result<(), ImportError> {
        let moves = target.point.is_some_and(|p| p != self.here)
            || target
                .height_m
                .is_some_and(|h| (h - self.height_m).abs() > SAME_HEIGHT_M);
        if moves || acceptance_m.is_some() {
            self.fly_to_always(item, target, acceptance_m)?;
        }
        Ok(())
    }

    /// A leg to the target (of no length when it is here).
    pub(super) fn fly_to_always(
        &mut self,
        item: &RawItem,
        target: Target,
        acceptance_m: Option<f64>,
    ) -> Result<(), ImportError> {
        let to = target.point.unwrap_or(self.here);
        let height_m = target.height_m.unwrap_or(self.height_m);
        self.push(
            item,
            SegmentSpec::Leg {
                east_m: None,
                north_m: None,
                latitude_deg: Some(to.latitude_deg),
                longitude_deg: Some(to.longitude_deg),
                altitude_m: Some(height_m),
                ground_speed_mps: self.speed_mps,
                payload_after_kg: None,
                acceptance_radius_m: acceptance_m,
                item: Some(item.number),
            },
        )?;
        self.here = to;
        self.height_m = height_m;
        Ok(())
    }

    /// A hover of `seconds` when it is positive.
    pub(super) fn hover(&mut self, item: &RawItem, seconds: f64) -> Result<(), ImportError> {
        if seconds > 0.0 {
            self.push(
                item,
                SegmentSpec::Hover {
                    duration_s: seconds,
                    payload_after_kg: None,
                    item: Some(item.number),
                },
            )?;
        }
        Ok(())
    }

    /// Down at the autopilot's descent rate to [`LAND_SLOW_HEIGHT_M`], then at its landing rate.
    pub(super) fn descend_and_land(&mut self, item: &RawItem) -> Result<(), ImportError> {
        let autopilot = self.source.autopilot;
        if self.height_m > LAND_SLOW_HEIGHT_M {
            self.push(
                item,
                SegmentSpec::Descent {
                    altitude_m: LAND_SLOW_HEIGHT_M,
                    rate_mps: autopilot.descent_rate_mps(),
                    item: Some(item.number),
                },
            )?;
        }
        self.push(
            item,
            SegmentSpec::Landing {
                rate_mps: autopilot.landing_rate_mps(),
                payload_after_kg: None,
                item: Some(item.number),
                ground_m: None,
            },
        )?;
        self.airborne = false;
        self.height_m = 0.0;
        Ok(())
    }

    /// One more segment, within the planner's limit.
    pub(super) fn push(&mut self, item: &RawItem, segment: SegmentSpec) -> Result<(), ImportError> {
        if self.segments.len() == MAX_SEGMENTS {
            return Err(ImportError::TooManyItems {
                at: item.at,
                limit: MAX_SEGMENTS,
            });
        }
        self.segments.push(segment);
        Ok(())
    }

    /// The translation: segments, counts and warnings, with what was never reached and whether
    /// the route ends in the air.
    pub(super) fn finish(
        mut self,
        items: &[RawItem],
        end: Option<(Place, &'static str)>,
    ) -> Result<Translation, ImportError> {
        let unreached: Vec<Place> = items
            .iter()
            .zip(&self.reached)
            .filter(|(_, r)| !**r)
            .map(|(x, _)| x.at)
            .collect();
        if !unreached.is_empty() {
            let why = match end {
                Some((at, what)) => format!("the route ends at {at} with {what}"),
                None => "jumped over".to_string(),
            };
            self.notes.add(
                Place::File,
                format!("{} never flown: {why}", places_text(&unreached)),
            );
        }
        if self.airborne && end.is_none() {
            self.notes.add(
                Place::File,
                "the route ends in the air: no LAND or RETURN_TO_LAUNCH item",
            );
        }
        if self.segments.is_empty() {
            return Err(ImportError::NothingToFly { items: items.len() });
        }
        let counts = count(items, &self.reached);
        Ok(Translation {
            segments: self.segments,
            counts,
            notes: self.notes.finish(),
            flown: self.flown,
        })
    }
}

/// The items by role: flown, commands, free, unknown, never reached.
fn count(items: &[RawItem], reached: &[bool]) -> ItemCounts {
    let mut c = ItemCounts {
        total: items.len(),
        ..ItemCounts::default()
    };
    for (item, &r) in items.iter().zip(reached) {
        let slot = match (r, role(item.command)) {
            (false, _) => &mut c.unreachable,
            (true, Role::Flown) => &mut c.flown,
            (true, Role::Command) => &mut c.commands,
            (true, Role::Free) => &mut c.free,
            (true, Role::Unknown | Role::Vtol) => &mut c.unknown,
        };
        *slot += 1;
    }
    c
}

/// `x` rounded to centimetres, for messages.
fn round_cm(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}
