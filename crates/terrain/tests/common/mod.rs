//! Tiles the tests write: SRTM tiles from a function of (row, col), GeoTIFFs with the `tiff`
//! crate's encoder and the GeoTIFF tags set by hand, zip archives with the `zip` crate's writer;
//! the shared real tile and its raw samples, read here independently of the crate.
#![allow(dead_code)] // not every test file uses every helper

use std::io::Write;
use std::path::{Path, PathBuf};

use tiff::encoder::colortype::ColorType;
use tiff::encoder::TiffEncoder;
use tiff::tags::Tag;

#[path = "../../../../tests/it/common/data.rs"]
mod data;

/// The shared terrain folder (`ALOFT_DATA_DIR`/terrain).
pub fn shared_terrain() -> PathBuf {
    data::data_dir().join("terrain")
}

/// The raw samples of the shared N44W072.hgt: sample (row, col) at byte offset
/// 2 * (row * 1201 + col), big-endian i16.
pub struct Raw(pub Vec<u8>);

impl Raw {
    pub fn shared() -> Raw {
        Raw(std::fs::read(shared_terrain().join("N44W072.hgt")).unwrap())
    }

    pub fn at(&self, row: usize, col: usize) -> i16 {
        let k = 2 * (row * 1201 + col);
        i16::from_be_bytes([self.0[k], self.0[k + 1]])
    }
}

/// The place of sample (row, col) of N44W072, (lat, lon) in degrees.
pub fn n44w072_place(row: usize, col: usize) -> (f64, f64) {
    (45.0 - row as f64 / 1200.0, -72.0 + col as f64 / 1200.0)
}

/// Write an SRTM3 tile (1201 x 1201) named `name` into `dir`, sample (row, col) = `h(row, col)`.
pub fn write_hgt(dir: &Path, name: &str, h: impl Fn(usize, usize) -> i16) -> PathBuf {
    let mut bytes = Vec::with_capacity(2 * 1201 * 1201);
    for r in 0..1201 {
        for c in 0..1201 {
            bytes.extend_from_slice(&h(r, c).to_be_bytes());
        }
    }
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Write `bytes` as the one entry `entry` of a deflated zip at `path`.
pub fn write_zip(path: &Path, entry: &str, bytes: &[u8]) {
    let file = std::fs::File::create(path).unwrap();
    let mut z = zip::ZipWriter::new(file);
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    z.start_file(entry, options).unwrap();
    z.write_all(bytes).unwrap();
    z.finish().unwrap();
}

/// How a test GeoTIFF is georeferenced.
#[derive(Clone, Debug)]
pub struct GeoTags {
    /// ModelPixelScale (x, y) and ModelTiepoint (i, j, x, y); or a ModelTransformation.
    pub scale_tie: Option<([f64; 2], [f64; 4])>,
    pub transform: Option<[f64; 16]>,
    /// GeoKeys as (id, value).
    pub keys: Vec<(u16, u16)>,
    pub nodata: Option<String>,
}

impl GeoTags {
    /// Geographic WGS 84, pixel-is-area, north-west corner at (north, west), square pixels of
    /// `step` degrees.
    pub fn wgs84(north: f64, west: f64, step: f64) -> GeoTags {
        GeoTags {
            scale_tie: Some(([step, step], [0.0, 0.0, west, north])),
            transform: None,
            keys: vec![(1024, 2), (1025, 1), (2048, 4326)],
            nodata: None,
        }
    }
}

/// Write a single-band GeoTIFF of `width` x `height` samples of colour type `C` at `path`.
pub fn write_geotiff<C: ColorType>(
    path: &Path,
    width: u32,
    height: u32,
    data: &[C::Inner],
    tags: &GeoTags,
) where
    [C::Inner]: tiff::encoder::TiffValue,
{
    let file = std::fs::File::create(path).unwrap();
    let mut enc = TiffEncoder::new(file).unwrap();
    let mut image = enc.new_image::<C>(width, height).unwrap();
    let e = image.encoder();
    if let Some((scale, tie)) = tags.scale_tie {
        e.write_tag(Tag::ModelPixelScaleTag, &[scale[0], scale[1], 0.0][..])
            .unwrap();
        e.write_tag(
            Tag::ModelTiepointTag,
            &[tie[0], tie[1], 0.0, tie[2], tie[3], 0.0][..],
        )
        .unwrap();
    }
    if let Some(m) = tags.transform {
        e.write_tag(Tag::ModelTransformationTag, &m[..]).unwrap();
    }
    if !tags.keys.is_empty() {
        let mut dir: Vec<u16> = vec![1, 1, 0, tags.keys.len() as u16];
        for &(id, v) in &tags.keys {
            dir.extend_from_slice(&[id, 0, 1, v]);
        }
        e.write_tag(Tag::GeoKeyDirectoryTag, &dir[..]).unwrap();
    }
    if let Some(n) = &tags.nodata {
        e.write_tag(Tag::GdalNodata, n.as_str()).unwrap();
    }
    image.write_data(data).unwrap();
}
