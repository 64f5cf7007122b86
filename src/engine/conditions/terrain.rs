//! The ground under a flight: elevation tiles read offline (`aloft-terrain`), the directory
//! chosen once for every command, and heights at places as the command line answers them.
//!
//! | request | answer |
//! |---|---|
//! | `--terrain DIR`, else the `ALOFT_TERRAIN` environment variable → [`from_flag_or_env`] | a [`Terrain`] (or none: a flat Earth) |
//! | a [`Terrain`] and places → [`heights`] | [`Heights`]: `{"heights": [{latitude_deg, longitude_deg, height_m}]}` |
//!
//! Heights are metres above the EGM96 geoid (SRTM's datum, the AMSL of autopilots), bilinear
//! between the tile's samples. A place over no tile or on a void has no height: it is an error
//! that names the place ([`TerrainError::NoTile`], [`TerrainError::Void`]), never sea level.

use std::path::{Path, PathBuf};

use serde::Serialize;

pub use aloft_terrain::{
    Clearance, Crs, GeoTiffProblem, GroundSample, PathPoint, Terrain, TerrainError, MAX_HELD_BYTES,
    MAX_PROFILE_SAMPLES, MAX_TILES_HELD,
};

use crate::error::Error;

/// The environment variable that names the terrain directory when no `--terrain` is given.
pub const TERRAIN_ENV: &str = "ALOFT_TERRAIN";

/// The terrain of a command: the directory `flag` (`--terrain DIR`), else the one the
/// `ALOFT_TERRAIN` environment variable names (when set and not empty), opened; `None` when
/// neither is given (the command flies over a flat Earth).
///
/// # Errors
/// [`Error::Terrain`]: the directory cannot be read, holds no tile, or holds a tile that cannot
/// be read (each names the file).
pub fn from_flag_or_env(flag: Option<&Path>) -> Result<Option<Terrain>, Error> {
    let dir = match flag {
        Some(d) => Some(d.to_path_buf()),
        None => std::env::var_os(TERRAIN_ENV)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from),
    };
    Ok(dir.map(|d| Terrain::open(&d)).transpose()?)
}

/// The ground's height at one place.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Height {
    /// Latitude, deg.
    pub latitude_deg: f64,
    /// Longitude, deg.
    pub longitude_deg: f64,
    /// Height above the EGM96 geoid, m.
    pub height_m: f64,
}

/// The heights at places, in the order asked (the JSON of `aloft terrain --format json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Heights {
    /// One height per place.
    pub heights: Vec<Height>,
}

/// The ground's height at each of `points` ((latitude, longitude), deg), in order.
///
/// # Errors
/// [`Error::Terrain`] for the first place that has no height ([`TerrainError::NoTile`],
/// [`TerrainError::Void`]: the input is valid but has no answer), that is not a place
/// ([`TerrainError::NotAPlace`]), or whose tile cannot be read.
pub fn heights(terrain: &Terrain, points: &[(f64, f64)]) -> Result<Heights, Error> {
    let heights = points
        .iter()
        .map(|&(latitude_deg, longitude_deg)| {
            Ok(Height {
                latitude_deg,
                longitude_deg,
                height_m: terrain.height_m(latitude_deg, longitude_deg)?,
            })
        })
        .collect::<Result<Vec<_>, Error>>()?;
    Ok(Heights { heights })
}

/// Whether `e` is a place without an answer (no tile, a void): a valid question the tiles
/// cannot answer, as opposed to a bad input or an unreadable tile.
pub fn is_no_ground(e: &Error) -> bool {
    matches!(
        e,
        Error::Terrain(TerrainError::NoTile { .. } | TerrainError::Void { .. })
    )
}
