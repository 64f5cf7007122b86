//! # aloft-terrain: the ground under a flight, offline
//!
//! A reader crate like aloft-logs: it reads elevation tiles from a directory it is handed and
//! answers heights; it never fetches anything. [`Terrain::open`] indexes a directory (SRTM tiles
//! by their names, GeoTIFFs by their headers); a tile's samples are read when it is first used,
//! and at most [`MAX_TILES_HELD`] tiles ([`MAX_HELD_BYTES`] of samples) are held at once, the
//! least recently used let go first. A [`Terrain`] is cheap to clone and `Send + Sync`: clones
//! share the index and the tiles held.
//!
//! | question | call | answer |
//! |---|---|---|
//! | the ground at a place | [`Terrain::height_m`] | metres above the EGM96 geoid, bilinear between the four samples around it |
//! | how fine the tile is there | [`Terrain::spacing_m`] | the smaller of its north-south and east-west sample spacing, m |
//! | the ground along a path | [`Terrain::profile`] | [`GroundSample`]s at most that spacing apart, both ends included |
//! | how close a path comes to the ground | [`Terrain::least_clearance`] | [`Clearance`]: the least height of a path above the bilinear ground, where, and the ground there |
//!
//! ## Formats
//! - SRTM `.hgt`: 1201 x 1201 (3 arc-second) or 3601 x 3601 (1 arc-second) big-endian
//!   i16, named by the south-west corner, -32768 a void.
//! - `.hgt.zip`: a zip holding one `.hgt`, read with the `zip` crate (pinned to 7.3.0, the newest
//!   for Rust 1.85, without default features: stored and deflated entries through flate2's
//!   pure-Rust backend). The crate reads the central directory, so the tile's name and size are
//!   checked when the directory is opened, and it checks the entry's CRC; a hand-written reader
//!   over flate2 would have to do both again.
//! - Single-band GeoTIFF in geographic WGS 84, read with the `tiff` crate (0.11.3,
//!   uncompressed, LZW and deflate): i16, u16, i32, f32, f64 samples; any other reference system
//!   is refused, naming it.
//!
//! Every error names the file ([`TerrainError::Io`], [`TerrainError::WrongSize`],
//! [`TerrainError::BadName`], [`TerrainError::Zip`], [`TerrainError::GeoTiff`],
//! [`TerrainError::Projection`]) or the place ([`TerrainError::Void`], [`TerrainError::NoTile`]):
//! a void or a place off every tile is never taken as sea level.
//!
//! ## Frame and units
//! Latitude and longitude in degrees on WGS 84; heights in metres as the tiles store them (SRTM:
//! above the EGM96 geoid, the frame of AMSL altitudes); distances along a path on the sphere of
//! the mean Earth radius ([`distance`]); paths linear in latitude and longitude, altitude linear
//! in distance ([`walk`](crate::Terrain::least_clearance)).
//!
//! ## Fast path
//! [`Terrain::least_clearance`] walks the grid cells the path crosses and solves each cell's
//! clearance exactly (a quadratic along a line over a bilinear cell), with the tile found once
//! per run of the path over it and nothing allocated per cell. It is tested against the plain
//! version, [`Terrain::height_m`] sampled every metre along the path: the walk's answer is never
//! above the samples' least and within centimetres of it.

#![deny(missing_docs)]
#![deny(clippy::float_cmp)]

mod cache;
pub mod distance;
mod error;
mod georef;
mod geotiff;
mod grid;
mod hgt;
mod hgt_zip;
mod index;
mod walk;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

pub use cache::{MAX_HELD_BYTES, MAX_TILES_HELD};
pub use error::{Crs, GeoTiffProblem, TerrainError};

use cache::Cache;
use grid::Grid;
use index::Index;
use walk::{Altitude, Least, Line, Run};

/// The most samples one profile holds (32 MB of [`GroundSample`]s: 1,000 km at 1 m spacing).
pub const MAX_PROFILE_SAMPLES: u64 = 1_000_000;

/// A directory of elevation tiles, loaded on first use, at most [`MAX_TILES_HELD`] (8) tiles
/// held (and at most [`MAX_HELD_BYTES`] of samples: bounded memory). `Send + Sync`; clones share
/// the index and the tiles held.
#[derive(Clone, Debug)]
pub struct Terrain {
    inner: Arc<Inner>,
}

#[derive(Debug)]
struct Inner {
    dir: PathBuf,
    index: Index,
    cache: Mutex<Cache>,
}

/// The ground at one place along a path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundSample {
    /// Distance from the path's start, m.
    pub distance_m: f64,
    /// Latitude, deg.
    pub latitude_deg: f64,
    /// Longitude, deg.
    pub longitude_deg: f64,
    /// The ground's height above the geoid, m.
    pub height_m: f64,
}

/// One end of a path through the air.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathPoint {
    /// Latitude, deg.
    pub latitude_deg: f64,
    /// Longitude, deg.
    pub longitude_deg: f64,
    /// Altitude above mean sea level (the geoid), m.
    pub altitude_amsl_m: f64,
}

/// The least height of a path above the ground, and where it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearance {
    /// The path's altitude less the ground's height there, m (negative: the path is under
    /// the ground).
    pub clearance_m: f64,
    /// Latitude of the place, deg.
    pub latitude_deg: f64,
    /// Longitude of the place, deg.
    pub longitude_deg: f64,
    /// Distance of the place from the path's start, m.
    pub distance_m: f64,
    /// The ground's height there, m.
    pub ground_m: f64,
}

/// A place given in degrees, checked.
fn place(latitude_deg: f64, longitude_deg: f64) -> Result<(f64, f64), TerrainError> {
    let ok = latitude_deg.abs() <= 90.0 && longitude_deg.abs() <= 180.0;
    match ok {
        true => Ok((latitude_deg, longitude_deg)),
        false => Err(TerrainError::NotAPlace {
            latitude_deg,
            longitude_deg,
        }),
    }
}

impl Terrain {
    /// Index the elevation tiles of `dir` (SRTM `.hgt` and `.hgt.zip` by their names and sizes,
    /// GeoTIFF `.tif`/`.tiff` by their headers; other files and folders are passed over).
    ///
    /// # Errors
    /// The directory cannot be read or holds no tile ([`TerrainError::NoTiles`]); a tile is
    /// misnamed, of the wrong size, a damaged archive or GeoTIFF, or in another projection.
    pub fn open(dir: &Path) -> Result<Terrain, TerrainError> {
        let index = Index::open(dir)?;
        Ok(Terrain {
            inner: Arc::new(Inner {
                dir: dir.to_path_buf(),
                index,
                cache: Mutex::new(Cache::default()),
            }),
        })
    }

    /// The directory the tiles were read from.
    pub fn dir(&self) -> &Path {
        &self.inner.dir
    }

    /// The tile files indexed, finest first.
    pub fn tile_files(&self) -> impl Iterator<Item = &Path> {
        self.inner.index.tiles.iter().map(|t| t.path.as_path())
    }

    /// The samples of tile `k`, from memory or read now.
    fn grid(&self, k: usize) -> Result<Arc<Grid>, TerrainError> {
        let mut cache = self
            .inner
            .cache
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some(g) = cache.get(k) {
            return Ok(g);
        }
        let g = Arc::new(self.inner.index.load(k)?);
        cache.put(k, Arc::clone(&g));
        Ok(g)
    }

    /// The finest tile under a place.
    fn tile_at(&self, latitude_deg: f64, longitude_deg: f64) -> Result<usize, TerrainError> {
        let (latitude_deg, longitude_deg) = place(latitude_deg, longitude_deg)?;
        self.inner
            .index
            .tiles_at(latitude_deg, longitude_deg)
            .next()
            .ok_or(TerrainError::NoTile {
                latitude_deg,
                longitude_deg,
            })
    }

    /// The void error at a place of tile `k`.
    fn void(&self, k: usize, (latitude_deg, longitude_deg): (f64, f64)) -> TerrainError {
        TerrainError::Void {
            latitude_deg,
            longitude_deg,
            file: self.inner.index.tiles[k].path.clone(),
        }
    }

    /// The ground's height at a place, m above the EGM96 geoid (as the tile stores it): the
    /// bilinear interpolation of the four samples around it, a sample's own value on a grid
    /// point.
    ///
    /// # Errors
    /// [`TerrainError::NoTile`] off every tile, [`TerrainError::Void`] where a sample it weighs
    /// is a void, [`TerrainError::NotAPlace`]; reading the tile ([`TerrainError::Io`], ...).
    pub fn height_m(&self, latitude_deg: f64, longitude_deg: f64) -> Result<f64, TerrainError> {
        let k = self.tile_at(latitude_deg, longitude_deg)?;
        self.grid(k)?
            .height_m(latitude_deg, longitude_deg)
            .ok_or_else(|| self.void(k, (latitude_deg, longitude_deg)))
    }

    /// The sample spacing of the tile at a place, m: the smaller of its north-south and
    /// east-west spacing (on a 3 arc-second tile at 44.5° N, 66.1 m east-west).
    ///
    /// # Errors
    /// [`TerrainError::NoTile`], [`TerrainError::NotAPlace`].
    pub fn spacing_m(&self, latitude_deg: f64, longitude_deg: f64) -> Result<f64, TerrainError> {
        let k = self.tile_at(latitude_deg, longitude_deg)?;
        Ok(self.inner.index.tiles[k].georef.spacing_m(latitude_deg))
    }

    /// The straight path between two places, checked.
    fn line(from: (f64, f64), to: (f64, f64)) -> Result<Line, TerrainError> {
        Ok(Line::new(place(from.0, from.1)?, place(to.0, to.1)?))
    }

    /// The ground along the straight path from `from` to `to` ((latitude, longitude), deg):
    /// samples evenly spaced at most the finest [`spacing_m`](Self::spacing_m) of the tiles
    /// under the path apart, both ends included (one sample when the ends are one place).
    ///
    /// # Errors
    /// As [`height_m`](Self::height_m) for any place on the path (the first one without an
    /// answer is named); [`TerrainError::ProfileTooLong`] beyond [`MAX_PROFILE_SAMPLES`].
    pub fn profile(
        &self,
        from: (f64, f64),
        to: (f64, f64),
    ) -> Result<Vec<GroundSample>, TerrainError> {
        let line = Self::line(from, to)?;
        let runs = self.runs(&line)?;
        let intervals = self.profile_intervals(&line, &runs)?;
        let mut out = Vec::with_capacity(intervals + 1);
        for (r, run) in runs.iter().enumerate() {
            let grid = self.grid(run.tile)?;
            let last_run = r + 1 == runs.len();
            for i in sample_range(run, intervals, last_run) {
                let t = if intervals == 0 {
                    0.0
                } else {
                    i as f64 / intervals as f64
                };
                let (latitude_deg, longitude_deg) = line.at(t);
                let height_m = walk::run_height(&grid, run, t)
                    .ok_or_else(|| self.void(run.tile, (latitude_deg, longitude_deg)))?;
                out.push(GroundSample {
                    distance_m: t * line.length_m,
                    latitude_deg,
                    longitude_deg,
                    height_m,
                });
            }
        }
        Ok(out)
    }

    /// The runs of a path over the tiles.
    fn runs(&self, line: &Line) -> Result<Vec<Run>, TerrainError> {
        let mut runs = Vec::new();
        walk::for_each_run(&self.inner.index, line, |run| {
            runs.push(run);
            Ok::<(), TerrainError>(())
        })?;
        Ok(runs)
    }

    /// How many equal intervals a profile of the path has: its length over the finest spacing
    /// of the tiles under it (taken at the run's end nearer a pole), rounded up.
    fn profile_intervals(&self, line: &Line, runs: &[Run]) -> Result<usize, TerrainError> {
        let spacing_m = runs
            .iter()
            .map(|r| {
                let lat = line.at(r.t0).0.abs().max(line.at(r.t1).0.abs());
                self.inner.index.tiles[r.tile].georef.spacing_m(lat)
            })
            .fold(f64::INFINITY, f64::min);
        let n = (line.length_m / spacing_m).ceil();
        if n + 1.0 > MAX_PROFILE_SAMPLES as f64 {
            return Err(TerrainError::ProfileTooLong {
                distance_m: line.length_m,
                spacing_m,
                samples: n as u64 + 1,
                max_samples: MAX_PROFILE_SAMPLES,
            });
        }
        Ok(n as usize)
    }

    /// The least clearance of the straight path from `from` to `to`, its altitude linear in the
    /// distance between the ends' altitudes, over the bilinear ground: exact over every cell the
    /// path crosses, not only at samples (see [`walk`](crate)).
    ///
    /// # Errors
    /// As [`profile`](Self::profile) (a void or no tile anywhere under the path, named by its
    /// place); [`TerrainError::NotAnAltitude`].
    pub fn least_clearance(
        &self,
        from: PathPoint,
        to: PathPoint,
    ) -> Result<Clearance, TerrainError> {
        for alt in [from.altitude_amsl_m, to.altitude_amsl_m] {
            if !alt.is_finite() {
                return Err(TerrainError::NotAnAltitude {
                    altitude_amsl_m: alt,
                });
            }
        }
        let line = Self::line(
            (from.latitude_deg, from.longitude_deg),
            (to.latitude_deg, to.longitude_deg),
        )?;
        let alt = Altitude {
            alt0_m: from.altitude_amsl_m,
            dalt_m: to.altitude_amsl_m - from.altitude_amsl_m,
        };
        let mut least = Least::NONE;
        walk::for_each_run(&self.inner.index, &line, |run| {
            let grid = self.grid(run.tile)?;
            walk::run_least(&grid, &run, alt, &mut least)
                .map_err(|walk::VoidAt(t)| self.void(run.tile, line.at(t)))
        })?;
        let (latitude_deg, longitude_deg) = line.at(least.t);
        Ok(Clearance {
            clearance_m: least.clearance_m,
            latitude_deg,
            longitude_deg,
            distance_m: least.t * line.length_m,
            ground_m: least.ground_m,
        })
    }
}

/// The profile samples (of `intervals` equal intervals) that fall on a run: those at or after
/// its start and before its end, and its end too on the last run.
fn sample_range(run: &Run, intervals: usize, last_run: bool) -> std::ops::Range<usize> {
    if intervals == 0 {
        return 0..1;
    }
    let n = intervals as f64;
    let first = (run.t0 * n).ceil() as usize;
    let end = match last_run {
        true => intervals + 1,
        false => ((run.t1 * n).ceil() as usize).min(intervals + 1),
    };
    first..end.max(first)
}

// What a caller shares between threads.
const _: () = {
    const fn send_sync<T: Send + Sync>() {}
    send_sync::<Terrain>();
    send_sync::<TerrainError>();
};
