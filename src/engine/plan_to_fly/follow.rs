//! `aloft plan --follow-terrain HEIGHT`: the operator's relative-frame mission written again to
//! keep HEIGHT above the ground (with `--terrain`), before it is planned.
//!
//! The steps: the planner file's items ([`aloft_missions::follow_terrain::follow_items`]: each
//! waypoint and loiter relative to home flown HEIGHT above the ground under it; for PX4, which
//! cannot fly the terrain frame, above mean sea level with a waypoint at every terrain sample
//! kept between, as QGroundControl bakes a terrain-following survey; for ArduPilot, the terrain
//! frame), its home at the tile's ground, written in the file's own format (a `.plan`'s surveys
//! as their stored items) and read again. The plan then flies, cuts and writes that mission: its
//! files carry the frames written here.

use aloft_missions::follow_terrain::{follow_items, FollowFrames, Following};
use aloft_missions::{Home, MissionEntry, SourceFormat};

use crate::engine::missions::ground::ground_points;
use crate::engine::missions::mission_file::Mission;
use crate::engine::missions::mission_options::MissionOptions;
use crate::error::Error;

/// The highest height above the ground a mission may be written to follow, m.
pub const MAX_FOLLOW_HEIGHT_M: f64 = 10_000.0;

/// `mission` written to keep `height_m` above the ground of `options`' terrain in `frames`.
///
/// # Errors
/// [`Error::InvalidInput`] for a height out of range or no terrain; [`Error::MissionFormat`] for
/// a mission that is not a planner file; the tiles' (no ground under the route); the writer's.
pub(in crate::engine) fn follow_terrain(
    mission: &Mission,
    options: &MissionOptions,
    height_m: f64,
    frames: FollowFrames,
) -> Result<Mission, Error> {
    if !(height_m.is_finite() && height_m > 0.0 && height_m <= MAX_FOLLOW_HEIGHT_M) {
        return Err(Error::InvalidInput {
            name: "follow_terrain",
            value: height_m,
            unit: "m",
            expected: "a height above the ground, above 0 and at most 10000 m",
        });
    }
    let Some(dir) = &options.terrain else {
        return Err(Error::InvalidInput {
            name: "follow_terrain",
            value: height_m,
            unit: "m",
            expected: "the ground's tiles too (--terrain DIR, or ALOFT_TERRAIN)",
        });
    };
    let Some(kept) = mission.kept() else {
        return Err(Error::MissionFormat {
            origin: mission.origin().to_string(),
            message: "--follow-terrain writes planner files: give a .plan or a .waypoints mission"
                .to_string(),
        });
    };
    let terrain = aloft_terrain::Terrain::open(dir)?;
    let home = kept.home.unwrap_or(Home {
        latitude_deg: mission.spec().home.latitude_deg.unwrap_or(f64::NAN),
        longitude_deg: mission.spec().home.longitude_deg.unwrap_or(f64::NAN),
        altitude_amsl_m: None,
    });
    let ground_m = terrain.height_m(home.latitude_deg, home.longitude_deg)?;
    let home = Home {
        altitude_amsl_m: Some(ground_m),
        ..home
    };
    let profile = |a, b| ground_points(&terrain, a, b);
    let items = follow_items(
        &kept.items,
        (home.latitude_deg, home.longitude_deg),
        height_m,
        frames,
        &Following::default(),
        profile,
    )?;
    let entries: Vec<MissionEntry> = items.into_iter().map(MissionEntry::Item).collect();
    let in_file = |source| Error::MissionImport {
        origin: mission.origin().to_string(),
        source,
    };
    let text = match (kept.format, &kept.plan) {
        (SourceFormat::QgcPlan, Some(plan)) => {
            aloft_missions::write_plan(&plan.header, &home, &entries, &plan.airspace)
        }
        _ => aloft_missions::write_waypoints(&home, &entries),
    }
    .map_err(in_file)?;
    Mission::from_text(&text, mission.origin())?.read_with(mission.read_options())
}
