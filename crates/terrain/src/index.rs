//! The tiles of a directory, by the area each covers: SRTM tiles by their names (and sizes),
//! GeoTIFFs by their headers. Nothing but headers is read when a directory is opened; a tile's
//! samples are read by [`Index::load`] when it is first used.
//!
//! Files are recognised by their names, in any case: `.hgt`, `.hgt.zip`, `.tif`, `.tiff`.
//! Other files, folders and hidden files (`.` first, such as macOS's `._N44W072.hgt`) are
//! passed over; folders are not searched.

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use aloft_core::open_regular_file;

use crate::error::TerrainError;
use crate::georef::{Bounds, Georef, EDGE_DEG};
use crate::grid::Grid;
use crate::{geotiff, hgt, hgt_zip};

/// How a tile's samples are stored.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Source {
    /// An SRTM `.hgt` file.
    Hgt,
    /// The `.hgt` inside a `.hgt.zip`.
    HgtZip(hgt_zip::Entry),
    /// A GeoTIFF.
    GeoTiff(geotiff::Header),
}

/// One tile of the directory.
#[derive(Debug, Clone)]
pub(crate) struct Tile {
    /// The file.
    pub path: PathBuf,
    /// Where its samples lie.
    pub georef: Georef,
    /// The area it covers.
    pub bounds: Bounds,
    source: Source,
}

/// The tiles of a directory, finest first, and which of them touch each degree square.
#[derive(Debug)]
pub(crate) struct Index {
    /// The tiles, the finest grid first (then by path).
    pub tiles: Vec<Tile>,
    /// Degree squares (floor of latitude, floor of longitude) to the tiles that touch them, in
    /// the order of `tiles`.
    squares: HashMap<(i32, i32), Vec<usize>>,
}

fn io_error(file: &Path) -> impl FnOnce(std::io::Error) -> TerrainError + '_ {
    move |source| TerrainError::Io {
        file: file.to_path_buf(),
        source,
    }
}

/// The kind of tile a file name says, if any.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Hgt,
    HgtZip,
    GeoTiff,
}

fn kind_of(name: &str) -> Option<Kind> {
    let lower = name.to_ascii_lowercase();
    if lower.starts_with('.') {
        None
    } else if lower.ends_with(".hgt") {
        Some(Kind::Hgt)
    } else if lower.ends_with(".hgt.zip") {
        Some(Kind::HgtZip)
    } else if lower.ends_with(".tif") || lower.ends_with(".tiff") {
        Some(Kind::GeoTiff)
    } else {
        None
    }
}

impl Index {
    /// Index the tiles of `dir`.
    pub fn open(dir: &Path) -> Result<Index, TerrainError> {
        let mut tiles = Vec::new();
        for (path, kind) in tile_files(dir)? {
            tiles.push(index_tile(&path, kind)?);
        }
        if tiles.is_empty() {
            return Err(TerrainError::NoTiles {
                dir: dir.to_path_buf(),
            });
        }
        tiles.sort_by(|a, b| {
            a.georef
                .step_deg()
                .total_cmp(&b.georef.step_deg())
                .then_with(|| a.path.cmp(&b.path))
        });
        let mut squares: HashMap<(i32, i32), Vec<usize>> = HashMap::new();
        for (k, t) in tiles.iter().enumerate() {
            let b = t.bounds;
            let lat = square(b.south_deg - EDGE_DEG)..=square(b.north_deg + EDGE_DEG);
            for la in lat {
                for lo in square(b.west_deg - EDGE_DEG)..=square(b.east_deg + EDGE_DEG) {
                    squares.entry((la, lo)).or_default().push(k);
                }
            }
        }
        Ok(Index { tiles, squares })
    }

    /// The tiles that cover a point (edges included), finest first.
    pub fn tiles_at(
        &self,
        latitude_deg: f64,
        longitude_deg: f64,
    ) -> impl Iterator<Item = usize> + '_ {
        let key = (square(latitude_deg), square(longitude_deg));
        self.squares
            .get(&key)
            .map(Vec::as_slice)
            .unwrap_or_default()
            .iter()
            .copied()
            .filter(move |&k| self.tiles[k].bounds.contains(latitude_deg, longitude_deg))
    }

    /// Read the samples of tile `k`.
    pub fn load(&self, k: usize) -> Result<Grid, TerrainError> {
        let t = &self.tiles[k];
        let file = open_regular_file(&t.path).map_err(io_error(&t.path))?;
        let samples = match t.source {
            Source::Hgt => hgt::decode(&read_hgt(file, &t.path, t.georef.rows)?),
            Source::HgtZip(entry) => {
                hgt::decode(&hgt_zip::read_entry(BufReader::new(file), &t.path, entry)?)
            }
            Source::GeoTiff(header) => {
                geotiff::decode(BufReader::new(file), &header).map_err(|problem| {
                    TerrainError::GeoTiff {
                        file: t.path.clone(),
                        problem,
                    }
                })?
            }
        };
        Ok(Grid {
            georef: t.georef,
            samples,
        })
    }
}

/// The degree square a coordinate falls in.
fn square(deg: f64) -> i32 {
    deg.floor() as i32
}

/// The files of `dir` whose names say a tile, sorted by name.
fn tile_files(dir: &Path) -> Result<Vec<(PathBuf, Kind)>, TerrainError> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io_error(dir))? {
        let entry = entry.map_err(io_error(dir))?;
        let name = entry.file_name();
        let Some(kind) = name.to_str().and_then(kind_of) else {
            continue;
        };
        let path = entry.path();
        // Links are followed; folders named like tiles are passed over.
        if std::fs::metadata(&path).is_ok_and(|m| m.is_dir()) {
            continue;
        }
        files.push((path, kind));
    }
    files.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(files)
}

/// A tile's entry in the index, from its name and size (SRTM) or its header (GeoTIFF).
fn index_tile(path: &Path, kind: Kind) -> Result<Tile, TerrainError> {
    let file = open_regular_file(path).map_err(io_error(path))?;
    let size_bytes = file.metadata().map_err(io_error(path))?.len();
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let (georef, source) = match kind {
        Kind::Hgt => {
            let corner = hgt::corner_of_name(name).ok_or_else(|| TerrainError::BadName {
                file: path.to_path_buf(),
            })?;
            let side = hgt::side_of_size(size_bytes).ok_or_else(|| TerrainError::WrongSize {
                file: path.to_path_buf(),
                size_bytes,
            })?;
            (hgt::georef(corner, side), Source::Hgt)
        }
        Kind::HgtZip => {
            let entry = hgt_zip::find_entry(BufReader::new(file), path)?;
            (hgt::georef(entry.corner, entry.side), Source::HgtZip(entry))
        }
        Kind::GeoTiff => {
            let header =
                geotiff::read_header(BufReader::new(file), size_bytes).map_err(|e| match e {
                    geotiff::HeaderError::Problem(problem) => TerrainError::GeoTiff {
                        file: path.to_path_buf(),
                        problem,
                    },
                    geotiff::HeaderError::Projection(crs) => TerrainError::Projection {
                        file: path.to_path_buf(),
                        crs,
                    },
                })?;
            (header.georef, Source::GeoTiff(header))
        }
    };
    Ok(Tile {
        path: path.to_path_buf(),
        bounds: georef.bounds(),
        georef,
        source,
    })
}

/// The bytes of an SRTM tile of `side` samples a side, which must be exactly its size (the file
/// may have changed since it was indexed).
fn read_hgt(file: File, path: &Path, side: usize) -> Result<Vec<u8>, TerrainError> {
    let expected = hgt::bytes_of_side(side);
    let mut bytes = Vec::with_capacity(expected as usize);
    file.take(expected + 1)
        .read_to_end(&mut bytes)
        .map_err(io_error(path))?;
    if bytes.len() as u64 != expected {
        return Err(TerrainError::WrongSize {
            file: path.to_path_buf(),
            size_bytes: bytes.len() as u64,
        });
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_are_known_by_their_names_in_any_case() {
        assert_eq!(kind_of("N44W072.hgt"), Some(Kind::Hgt));
        assert_eq!(kind_of("n44w072.HGT"), Some(Kind::Hgt));
        assert_eq!(kind_of("N44W072.hgt.zip"), Some(Kind::HgtZip));
        assert_eq!(kind_of("dem.TIFF"), Some(Kind::GeoTiff));
        assert_eq!(kind_of("dem.tif"), Some(Kind::GeoTiff));
        assert_eq!(kind_of("._N44W072.hgt"), None);
        assert_eq!(kind_of("README.txt"), None);
        assert_eq!(kind_of("N44W072.zip"), None);
    }
}
