//! A path that keeps its height over the ground, as QGroundControl bakes one.
//!
//! QGroundControl cannot send terrain-frame items to PX4, so for a survey that follows terrain it
//! writes AMSL waypoints (`TransectStyleComplexItem`, read for its semantics): a waypoint at every
//! terrain sample along each line (`_addInterstitialTerrainPoints`), the climbs and descents
//! between them limited to the vehicle's rates at the survey's speed (`_adjustForMaxRates`: a
//! climb too steep raises the point before it, a descent too steep the point after it), then
//! the added points thinned (`_adjustForTolerance`: an added point is kept only when its altitude
//! differs from the last kept point's by more than the tolerance; the lines' own ends are always
//! kept). [`follow_ground`] does the same on the ground profiles the caller hands it (sans-I/O:
//! the tiles are read by `aloft-terrain`), and it is what aloft flies for a terrain-frame item
//! (frame 10/11: ArduPilot keeps its height over its own terrain data between the waypoints) and
//! what `aloft plan --follow-terrain` writes.
//!
//! Two differences from QGroundControl's loops, both on the safe side: the rate limits are
//! applied exactly (QGroundControl lets 0.1 m/s through), and in one backward pass for the
//! climbs and one forward pass for the descents, which reach the fixed point its repeated passes
//! converge to (each only raises points).

use aloft_logs::telemetry::MissionItem;

/// A point of a ground profile: where, how far along the line, and the ground's height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundPoint {
    /// Distance from the line's start, m.
    pub distance_m: f64,
    /// Latitude, deg.
    pub latitude_deg: f64,
    /// Longitude, deg.
    pub longitude_deg: f64,
    /// The ground's height above mean sea level, m.
    pub ground_m: f64,
}

/// One straight line to follow: its ground profile (both ends included, distances from the
/// line's start, increasing) and the heights above the ground at its two ends (the heights in
/// between are interpolated along it).
#[derive(Debug, Clone, Copy)]
pub struct FollowLine<'a> {
    /// The ground under the line.
    pub profile: &'a [GroundPoint],
    /// Height above the ground at the start, m.
    pub start_above_m: f64,
    /// Height above the ground at the end, m.
    pub end_above_m: f64,
}

/// How the path may climb, descend and be thinned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Following {
    /// An added point is kept only when its altitude differs from the last kept point's by more
    /// than this, m (QGroundControl's `TerrainAdjustTolerance`, default 10 m; 0 drops only the
    /// added points level with the last kept one, a negative tolerance keeps every sample).
    pub tolerance_m: f64,
    /// The fastest climb, m/s (0: not limited; QGroundControl's `TerrainAdjustMaxClimbRate`).
    pub max_climb_rate_mps: f64,
    /// The fastest descent, m/s, positive (0: not limited; `TerrainAdjustMaxDescentRate`).
    pub max_descent_rate_mps: f64,
    /// The speed along the lines, m/s (the rates are judged at it).
    pub speed_mps: f64,
}

impl Default for Following {
    /// QGroundControl's defaults: a 10 m tolerance, rates not limited, 5 m/s.
    fn default() -> Self {
        Self {
            tolerance_m: 10.0,
            max_climb_rate_mps: 0.0,
            max_descent_rate_mps: 0.0,
            speed_mps: 5.0,
        }
    }
}

/// A point of the path that follows the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FollowPoint {
    /// Latitude, deg.
    pub latitude_deg: f64,
    /// Longitude, deg.
    pub longitude_deg: f64,
    /// Altitude above mean sea level, m.
    pub altitude_amsl_m: f64,
    /// Which line it ends or lies on (0 for the first point).
    pub line: usize,
    /// An added point (a terrain sample inside a line), not a line's end.
    pub added: bool,
}

/// The path over `lines` (each starting where the one before ended): the first line's start,
/// then for each line the terrain samples inside it and its end, with altitudes `ground +
/// height above`, the rates of `following` applied, the added points thinned.
pub fn follow_ground(lines: &[FollowLine<'_>], following: &Following) -> Vec<FollowPoint> {
    let mut path = interstitial_points(lines);
    let distances = along_m(lines);
    limit_rates(&mut path, &distances, following);
    thin(&path, following.tolerance_m)
}

/// Every terrain sample of every line, with its altitude (`_addInterstitialTerrainPoints`).
fn interstitial_points(lines: &[FollowLine<'_>]) -> Vec<FollowPoint> {
    let mut path = Vec::with_capacity(lines.iter().map(|l| l.profile.len()).sum::<usize>() + 1);
    for (k, line) in lines.iter().enumerate() {
        let (Some(first), Some(last)) = (line.profile.first(), line.profile.last()) else {
            continue;
        };
        let length_m = last.distance_m - first.distance_m;
        let skip = usize::from(!path.is_empty());
        let n = line.profile.len();
        for (i, g) in line.profile.iter().enumerate().skip(skip) {
            let f = if length_m > 0.0 {
                (g.distance_m - first.distance_m) / length_m
            } else {
                1.0
            };
            let above_m = line.start_above_m + f * (line.end_above_m - line.start_above_m);
            path.push(FollowPoint {
                latitude_deg: g.latitude_deg,
                longitude_deg: g.longitude_deg,
                altitude_amsl_m: g.ground_m + above_m,
                line: k,
                added: i > 0 && i + 1 < n,
            });
        }
    }
    path
}

/// The distance of each point of [`interstitial_points`] from the path's start, m.
fn along_m(lines: &[FollowLine<'_>]) -> Vec<f64> {
    let mut out = Vec::new();
    let mut offset_m = 0.0;
    for line in lines {
        let Some(first) = line.profile.first() else {
            continue;
        };
        let skip = usize::from(!out.is_empty());
        out.extend(
            line.profile
                .iter()
                .skip(skip)
                .map(|g| offset_m + g.distance_m - first.distance_m),
        );
        offset_m = out.last().copied().unwrap_or(offset_m);
    }
    out
}

/// The climbs and descents limited to the rates at the speed (`_adjustForMaxRates`).
fn limit_rates(path: &mut [FollowPoint], along_m: &[f64], following: &Following) {
    if following.speed_mps <= 0.0 || path.len() < 2 {
        return;
    }
    let seconds = |i: usize| (along_m[i + 1] - along_m[i]) / following.speed_mps;
    if following.max_climb_rate_mps > 0.0 {
        // A climb too steep raises the point before it: from the end backwards.
        for i in (0..path.len() - 1).rev() {
            let floor_m = path[i + 1].altitude_amsl_m - following.max_climb_rate_mps * seconds(i);
            if path[i].altitude_amsl_m < floor_m {
                path[i].altitude_amsl_m = floor_m;
            }
        }
    }
    if following.max_descent_rate_mps > 0.0 {
        // A descent too steep raises the point after it: from the start forwards.
        for i in 0..path.len() - 1 {
            let floor_m = path[i].altitude_amsl_m - following.max_descent_rate_mps * seconds(i);
            if path[i + 1].altitude_amsl_m < floor_m {
                path[i + 1].altitude_amsl_m = floor_m;
            }
        }
    }
}

/// The added points within `tolerance_m` of the last kept point dropped
/// (`_adjustForTolerance`); the lines' ends always kept.
fn thin(path: &[FollowPoint], tolerance_m: f64) -> Vec<FollowPoint> {
    let mut kept: Vec<FollowPoint> = Vec::with_capacity(path.len());
    for p in path {
        let keep = match kept.last() {
            None => true,
            Some(last) => {
                !p.added || (p.altitude_amsl_m - last.altitude_amsl_m).abs() > tolerance_m
            }
        };
        if keep {
            kept.push(*p);
        }
    }
    kept
}

/// How a mission that follows the ground is written for its autopilot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FollowFrames {
    /// Altitudes above mean sea level (frame 0, or 5 for an `_INT` item), with a waypoint at every
    /// terrain sample kept between the operator's: what QGroundControl writes for PX4, which
    /// cannot fly the terrain frame.
    Amsl,
    /// The terrain frame (10, or 11 for an `_INT` item), the height above the ground: ArduPilot
    /// keeps it between the waypoints from its own terrain data.
    Terrain,
}

/// The commands whose altitude is a height to fly at (the take-off, the landing and the return
/// keep theirs).
fn flies_at_height(command: u32) -> bool {
    use crate::commands::*;
    matches!(
        command,
        NAV_WAYPOINT
            | NAV_SPLINE_WAYPOINT
            | NAV_LOITER_UNLIM
            | NAV_LOITER_TURNS
            | NAV_LOITER_TIME
            | NAV_LOITER_TO_ALT
    )
}

/// The items of a mission rewritten to keep `height_m` above the ground: every waypoint or
/// loiter in a frame relative to home (3 or 6) with a position is flown `height_m` above the
/// ground under it, in `frames`; with [`FollowFrames::Amsl`] the terrain samples kept between
/// consecutive positions (as [`follow_ground`] keeps them, with `following`) become waypoints of
/// their own, without a hold. Other items are kept as they are; the items are numbered again
/// from 1 (`seq`). `ground` gives the ground profile of the straight line between two places
/// (latitude, longitude), both ends included, and its height at a place; `home` is where the
/// vehicle starts.
///
/// # Errors
/// `ground`'s.
pub fn follow_items<E>(
    items: &[MissionItem],
    home: (f64, f64),
    height_m: f64,
    frames: FollowFrames,
    following: &Following,
    mut ground: impl FnMut((f64, f64), (f64, f64)) -> Result<Vec<GroundPoint>, E>,
) -> Result<Vec<MissionItem>, E> {
    let mut out = Vec::with_capacity(items.len());
    let mut here = home;
    for item in items {
        let [.., lat, lon, _] = item.params;
        let placed = lat.is_finite() && lon.is_finite() && !(lat == 0.0 && lon == 0.0);
        let relative = matches!(item.frame, 3 | 6);
        if !(placed && relative && flies_at_height(item.command)) {
            if placed && crate::items::has_position(item.command) {
                here = (lat, lon);
            }
            out.push(*item);
            continue;
        }
        let profile = ground(here, (lat, lon))?;
        let int = item.frame == 6;
        match frames {
            FollowFrames::Amsl => {
                let line = FollowLine {
                    profile: &profile,
                    start_above_m: height_m,
                    end_above_m: height_m,
                };
                let path = follow_ground(&[line], following);
                for p in path.iter().filter(|p| p.added) {
                    out.push(MissionItem {
                        seq: 0,
                        frame: if int { 5 } else { 0 },
                        command: crate::commands::NAV_WAYPOINT,
                        params: [
                            0.0,
                            0.0,
                            0.0,
                            f64::NAN,
                            p.latitude_deg,
                            p.longitude_deg,
                            p.altitude_amsl_m,
                        ],
                    });
                }
                let end_m = profile.last().map_or(0.0, |g| g.ground_m) + height_m;
                let mut own = *item;
                own.frame = if int { 5 } else { 0 };
                own.params[6] = end_m;
                out.push(own);
            }
            FollowFrames::Terrain => {
                let mut own = *item;
                own.frame = if int { 11 } else { 10 };
                own.params[6] = height_m;
                out.push(own);
            }
        }
        here = (lat, lon);
    }
    for (k, item) in out.iter_mut().enumerate() {
        item.seq = u32::try_from(k + 1).unwrap_or(u32::MAX);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight line north along 44 N, one sample every `step_m`, ground from `ground`.
    fn line(n: usize, step_m: f64, ground: impl Fn(f64) -> f64) -> Vec<GroundPoint> {
        (0..n)
            .map(|i| {
                let d = i as f64 * step_m;
                GroundPoint {
                    distance_m: d,
                    latitude_deg: 44.0 + d / 111_000.0,
                    longitude_deg: -71.5,
                    ground_m: ground(d),
                }
            })
            .collect()
    }

    fn no_thinning() -> Following {
        Following {
            tolerance_m: -1.0,
            ..Following::default()
        }
    }

    #[test]
    fn every_sample_is_a_point_at_the_height_above_it() {
        let ground = line(11, 90.0, |d| 300.0 + 0.1 * d);
        let path = follow_ground(
            &[FollowLine {
                profile: &ground,
                start_above_m: 50.0,
                end_above_m: 50.0,
            }],
            &no_thinning(),
        );
        assert_eq!(path.len(), 11);
        for (p, g) in path.iter().zip(&ground) {
            assert!((p.altitude_amsl_m - (g.ground_m + 50.0)).abs() < 1e-9);
        }
        assert!(!path[0].added && !path[10].added && path[1..10].iter().all(|p| p.added));
    }

    #[test]
    fn lines_share_their_joint_and_the_height_is_interpolated_between_the_ends() {
        let a = line(5, 100.0, |_| 200.0);
        let b = line(3, 100.0, |_| 200.0);
        let path = follow_ground(
            &[
                FollowLine {
                    profile: &a,
                    start_above_m: 40.0,
                    end_above_m: 80.0,
                },
                FollowLine {
                    profile: &b,
                    start_above_m: 80.0,
                    end_above_m: 80.0,
                },
            ],
            &no_thinning(),
        );
        // 5 + 3 - 1 points: the joint once.
        assert_eq!(path.len(), 7);
        let alts: Vec<f64> = path.iter().map(|p| p.altitude_amsl_m).collect();
        assert_eq!(alts, vec![240.0, 250.0, 260.0, 270.0, 280.0, 280.0, 280.0]);
        assert_eq!(path[4].line, 0);
        assert!(!path[4].added);
        assert_eq!(path[5].line, 1);
    }

    #[test]
    fn a_cliff_is_climbed_before_it_at_the_rate_and_descended_after_it() {
        // Flat at 100 m, a 60 m step up at 500 m for 200 m, then down again.
        let ground = line(11, 100.0, |d| {
            if (500.0..=700.0).contains(&d) {
                160.0
            } else {
                100.0
            }
        });
        let following = Following {
            tolerance_m: -1.0,
            max_climb_rate_mps: 2.0,
            max_descent_rate_mps: 1.0,
            speed_mps: 10.0,
        };
        let path = follow_ground(
            &[FollowLine {
                profile: &ground,
                start_above_m: 30.0,
                end_above_m: 30.0,
            }],
            &following,
        );
        // 100 m at 10 m/s is 10 s: at most 20 m up and 10 m down between samples.
        for w in path.windows(2) {
            let dz = w[1].altitude_amsl_m - w[0].altitude_amsl_m;
            assert!((-10.0 - 1e-9..=20.0 + 1e-9).contains(&dz), "{dz}");
        }
        // Never below the followed height.
        for (p, g) in path.iter().zip(&ground) {
            assert!(p.altitude_amsl_m >= g.ground_m + 30.0 - 1e-9);
        }
        // The climb starts two samples before the cliff: 150 at 300 m, 170 at 400 m, 190 on it.
        let alts: Vec<f64> = path.iter().map(|p| p.altitude_amsl_m).collect();
        assert_eq!(&alts[1..6], &[130.0, 130.0, 150.0, 170.0, 190.0]);
        // And the descent after it 10 m a sample until the end.
        assert_eq!(&alts[7..], &[190.0, 180.0, 170.0, 160.0]);
    }

    #[test]
    fn added_points_within_the_tolerance_are_dropped_but_the_ends_stay() {
        // Ground rising 4 m a sample: with a 10 m tolerance every third added point is kept.
        let ground = line(10, 30.0, |d| 100.0 + 4.0 * d / 30.0);
        let path = follow_ground(
            &[FollowLine {
                profile: &ground,
                start_above_m: 20.0,
                end_above_m: 20.0,
            }],
            &Following::default(),
        );
        let alts: Vec<f64> = path.iter().map(|p| p.altitude_amsl_m - 120.0).collect();
        // 0 kept (start), 4 and 8 dropped, 12 kept, 16, 20 dropped, 24 kept, 28, 32 dropped
        // but 36 is the end.
        assert_eq!(alts, vec![0.0, 12.0, 24.0, 36.0]);
    }

    #[test]
    fn an_empty_profile_is_passed_over() {
        let path = follow_ground(
            &[FollowLine {
                profile: &[],
                start_above_m: 1.0,
                end_above_m: 1.0,
            }],
            &Following::default(),
        );
        assert!(path.is_empty());
    }

    fn item(seq: u32, frame: u32, command: u32, lat: f64, lon: f64, alt: f64) -> MissionItem {
        MissionItem {
            seq,
            frame,
            command,
            params: [0.0, 0.0, 0.0, f64::NAN, lat, lon, alt],
        }
    }

    /// Ground rising 10 m every 100 m northwards from 500 m at 44 N.
    fn slope(from: (f64, f64), to: (f64, f64)) -> Result<Vec<GroundPoint>, ()> {
        let n = 11;
        let d_m = (to.0 - from.0) * 111_000.0;
        Ok((0..n)
            .map(|i| {
                let f = i as f64 / (n - 1) as f64;
                let lat = from.0 + f * (to.0 - from.0);
                GroundPoint {
                    distance_m: f * d_m,
                    latitude_deg: lat,
                    longitude_deg: from.1 + f * (to.1 - from.1),
                    ground_m: 500.0 + 0.1 * (lat - 44.0) * 111_000.0,
                }
            })
            .collect())
    }

    #[test]
    fn relative_waypoints_are_written_over_the_ground_for_each_autopilot() {
        let items = [
            item(1, 3, 22, 0.0, 0.0, 40.0),
            item(2, 3, 16, 44.01, -71.0, 40.0),
            item(3, 3, 178, 0.0, 0.0, 0.0),
            item(4, 3, 20, 0.0, 0.0, 0.0),
        ];
        let home = (44.0, -71.0);
        let amsl = follow_items(
            &items,
            home,
            50.0,
            FollowFrames::Amsl,
            &Following::default(),
            slope,
        )
        .unwrap();
        // 1110 m north, 111 m up: 9 samples inside, 11.1 m apart in height; a 10 m tolerance
        // keeps each: 9 waypoints added before the operator's.
        let added: Vec<&MissionItem> = amsl.iter().filter(|i| i.command == 16).collect();
        assert_eq!(added.len(), 10, "{amsl:?}");
        assert!(amsl
            .iter()
            .filter(|i| i.command == 16)
            .all(|i| i.frame == 0));
        let last = added.last().unwrap();
        assert!((last.params[6] - (500.0 + 0.1 * 1110.0 + 50.0)).abs() < 1e-6);
        assert_eq!(
            (amsl[0].command, amsl[0].frame, amsl[0].params[6]),
            (22, 3, 40.0)
        );
        assert_eq!(
            amsl.iter().map(|i| i.seq).collect::<Vec<_>>(),
            (1..=amsl.len() as u32).collect::<Vec<_>>()
        );
        let terrain = follow_items(
            &items,
            home,
            50.0,
            FollowFrames::Terrain,
            &Following::default(),
            slope,
        )
        .unwrap();
        assert_eq!(terrain.len(), 4);
        assert_eq!((terrain[1].frame, terrain[1].params[6]), (10, 50.0));
        assert_eq!(terrain[2].command, 178);
    }
}
