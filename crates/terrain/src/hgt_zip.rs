//! `.hgt.zip`: a zip archive holding one SRTM `.hgt` tile (as SRTM tiles are usually shipped),
//! read with the `zip` crate (stored or deflated entries). The corner comes from the name of the
//! `.hgt` inside (`N44W072.SRTMGL1.hgt.zip` holds `N44W072.hgt`), the grid from its size.

use std::io::{Read, Seek};
use std::path::{Path, PathBuf};

use zip::ZipArchive;

use crate::error::TerrainError;
use crate::hgt;

/// The `.hgt` entry of an archive: its index, corner and side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Entry {
    /// Index in the archive.
    pub index: usize,
    /// South-west corner, deg.
    pub corner: (i32, i32),
    /// Samples a side.
    pub side: usize,
}

fn zip_error(file: &Path) -> impl FnOnce(zip::result::ZipError) -> TerrainError + '_ {
    move |source| TerrainError::Zip {
        file: file.to_path_buf(),
        source,
    }
}

/// The one `.hgt` tile the archive at `file` holds (read from its central directory only).
pub fn find_entry<R: Read + Seek>(reader: R, file: &Path) -> Result<Entry, TerrainError> {
    let mut archive = ZipArchive::new(reader).map_err(zip_error(file))?;
    let tiles: Vec<usize> = (0..archive.len())
        .filter(|&i| {
            archive
                .name_for_index(i)
                .is_some_and(|n| n.to_ascii_lowercase().ends_with(".hgt"))
        })
        .collect();
    let [index] = tiles[..] else {
        return Err(TerrainError::ZipContents {
            file: file.to_path_buf(),
            hgt_entries: tiles.len(),
        });
    };
    let entry = archive.by_index_raw(index).map_err(zip_error(file))?;
    let name = entry.name().to_string();
    let shown = entry_path(file, &name);
    let base = name.rsplit(['/', '\\']).next().unwrap_or(&name);
    let corner = hgt::corner_of_name(base).ok_or_else(|| TerrainError::BadName {
        file: shown.clone(),
    })?;
    let side = hgt::side_of_size(entry.size()).ok_or(TerrainError::WrongSize {
        file: shown,
        size_bytes: entry.size(),
    })?;
    Ok(Entry {
        index,
        corner,
        side,
    })
}

/// The archive's path and the entry's name, as errors show them (`N44W072.hgt.zip/N44W072.hgt`).
fn entry_path(file: &Path, name: &str) -> PathBuf {
    let mut s = file.as_os_str().to_owned();
    s.push("/");
    s.push(name);
    PathBuf::from(s)
}

/// The bytes of the archive's entry `entry`, which must inflate to exactly the tile's size.
pub fn read_entry<R: Read + Seek>(
    reader: R,
    file: &Path,
    entry: Entry,
) -> Result<Vec<u8>, TerrainError> {
    let mut archive = ZipArchive::new(reader).map_err(zip_error(file))?;
    let mut zf = archive.by_index(entry.index).map_err(zip_error(file))?;
    let expected = hgt::bytes_of_side(entry.side);
    let mut bytes = Vec::with_capacity(expected as usize);
    (&mut zf)
        .take(expected + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| zip_error(file)(zip::result::ZipError::Io(e)))?;
    if bytes.len() as u64 != expected {
        return Err(TerrainError::WrongSize {
            file: entry_path(file, zf.name()),
            size_bytes: bytes.len() as u64,
        });
    }
    Ok(bytes)
}
