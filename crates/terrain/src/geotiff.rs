//! Single-band GeoTIFF elevation files in geographic WGS 84, read with the `tiff` crate.
//!
//! The georeference is a pixel scale with a tie point (ModelPixelScaleTag 33550,
//! ModelTiepointTag 33922) or a transformation without rotation (ModelTransformationTag 34264).
//! The GeoKeyDirectory (34735) must say geographic (GTModelTypeGeoKey 1024 = 2) on WGS 84
//! (GeographicTypeGeoKey 2048 = 4326, or a user-defined system on the WGS 84 datum,
//! GeogGeodeticDatumGeoKey 2050 = 6326), angles in degrees and heights in metres; anything else
//! is refused naming the system. A pixel is an area (GTRasterTypeGeoKey 1025 = 1, the default:
//! its sample lies at its centre, half a pixel in from the tie point) or a point (1025 = 2: the
//! sample lies on the tie point). Samples are i16, u16, i32, f32 or f64; GDAL_NODATA (42113) and
//! NaN are voids. Heights are taken as stored: metres above the geoid of the file's maker.
//!
//! [`read_header`] reads the tags only (the index reads every file's header when a directory is
//! opened); [`decode`] reads the samples (when the tile is first used).

use std::io::{Read, Seek};

use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;

use crate::error::{Crs, GeoTiffProblem};
use crate::georef::Georef;

/// The most samples aloft holds for one GeoTIFF (6,000 x 6,000: a degree at 0.6 arc-second, or
/// a Copernicus GLO-30 tile of 3,600 x 3,600 with room): 144 MB as the f32 grid aloft keeps.
pub const MAX_TILE_SAMPLES: u64 = 36_000_000;

const GEO_KEY_DIRECTORY: u16 = 34735;
const GT_MODEL_TYPE: u16 = 1024;
const GT_RASTER_TYPE: u16 = 1025;
const GEOGRAPHIC_TYPE: u16 = 2048;
const GEOG_GEODETIC_DATUM: u16 = 2050;
const GEOG_ANGULAR_UNITS: u16 = 2054;
const PROJECTED_CS_TYPE: u16 = 3072;
const VERTICAL_UNITS: u16 = 4099;
const USER_DEFINED: u16 = 32767;
const EPSG_WGS84: u16 = 4326;
const DATUM_WGS84: u16 = 6326;
const UNIT_METRE: u16 = 9001;
const UNIT_DEGREE: u16 = 9102;

/// What a GeoTIFF's tags say.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Header {
    /// Where its samples lie.
    pub georef: Georef,
    /// The value of a void sample, if the file has one.
    pub nodata: Option<f64>,
}

/// Why a GeoTIFF's header is not read: a problem of the file, or a reference system other than
/// WGS 84.
#[derive(Debug)]
pub enum HeaderError {
    /// A file aloft cannot read.
    Problem(GeoTiffProblem),
    /// A reference system other than geographic WGS 84.
    Projection(Crs),
}

impl From<GeoTiffProblem> for HeaderError {
    fn from(p: GeoTiffProblem) -> Self {
        HeaderError::Problem(p)
    }
}

impl From<tiff::TiffError> for HeaderError {
    fn from(e: tiff::TiffError) -> Self {
        HeaderError::Problem(GeoTiffProblem::Decode(e))
    }
}

/// The decoder's limits: the largest grid aloft holds, in f64 (the widest sample type).
fn limits() -> Limits {
    let mut l = Limits::default();
    l.decoding_buffer_size = (MAX_TILE_SAMPLES * 8) as usize;
    l
}

/// Read the header of a GeoTIFF of `size_bytes` bytes: its grid, georeference, reference system
/// and no-data value, and that its image data lies within the file.
pub fn read_header<R: Read + Seek>(reader: R, size_bytes: u64) -> Result<Header, HeaderError> {
    let mut dec = Decoder::new(reader)?.with_limits(limits());
    let (width, height) = dec.dimensions()?;
    check_layout(&mut dec, width, height)?;
    check_within(&mut dec, size_bytes)?;
    let keys = geo_keys(&mut dec)?;
    check_crs(&keys)?;
    let pixel_is_point = key(&keys, GT_RASTER_TYPE) == Some(2);
    let georef = georeference(&mut dec, width, height, pixel_is_point)?;
    let nodata = nodata(&mut dec)?;
    Ok(Header { georef, nodata })
}

/// One band of a sample type aloft reads, at least 2 x 2 and at most [`MAX_TILE_SAMPLES`].
fn check_layout<R: Read + Seek>(
    dec: &mut Decoder<R>,
    width: u32,
    height: u32,
) -> Result<(), GeoTiffProblem> {
    let bands = dec
        .find_tag_unsigned::<u16>(Tag::SamplesPerPixel)?
        .unwrap_or(1);
    if bands != 1 {
        return Err(GeoTiffProblem::Bands { bands });
    }
    let bits = dec
        .find_tag_unsigned_vec::<u16>(Tag::BitsPerSample)?
        .and_then(|v| v.first().copied())
        .unwrap_or(1);
    let format = dec
        .find_tag_unsigned_vec::<u16>(Tag::SampleFormat)?
        .and_then(|v| v.first().copied())
        .unwrap_or(1);
    if !matches!(
        (bits, format),
        (16, 1) | (16, 2) | (32, 2) | (32, 3) | (64, 3)
    ) {
        return Err(GeoTiffProblem::SampleType { bits, format });
    }
    if width < 2 || height < 2 {
        return Err(GeoTiffProblem::TooSmall { width, height });
    }
    let samples = u64::from(width) * u64::from(height);
    if samples > MAX_TILE_SAMPLES {
        return Err(GeoTiffProblem::TooLarge {
            samples,
            max_samples: MAX_TILE_SAMPLES,
        });
    }
    Ok(())
}

/// Every strip or tile of the image lies within the file's `size_bytes` (a truncated file is
/// said when the directory is opened, not when the tile is first used).
fn check_within<R: Read + Seek>(
    dec: &mut Decoder<R>,
    size_bytes: u64,
) -> Result<(), GeoTiffProblem> {
    let (offsets, counts) = match dec.find_tag_unsigned_vec::<u64>(Tag::StripOffsets)? {
        Some(o) => (o, dec.find_tag_unsigned_vec::<u64>(Tag::StripByteCounts)?),
        None => (
            dec.find_tag_unsigned_vec::<u64>(Tag::TileOffsets)?
                .unwrap_or_default(),
            dec.find_tag_unsigned_vec::<u64>(Tag::TileByteCounts)?,
        ),
    };
    let counts = counts.unwrap_or_default();
    let needed_bytes = offsets
        .iter()
        .zip(&counts)
        .map(|(o, c)| o.saturating_add(*c))
        .max()
        .unwrap_or(0);
    if needed_bytes > size_bytes {
        return Err(GeoTiffProblem::Truncated {
            needed_bytes,
            size_bytes,
        });
    }
    Ok(())
}

/// The GeoKeys of the directory (34735) as (key, value) pairs of the keys stored in the
/// directory itself (the ones aloft reads all are).
fn geo_keys<R: Read + Seek>(dec: &mut Decoder<R>) -> Result<Vec<(u16, u16)>, GeoTiffProblem> {
    let dir = dec
        .find_tag_unsigned_vec::<u16>(Tag::Unknown(GEO_KEY_DIRECTORY))?
        .ok_or(GeoTiffProblem::NoGeoKeys)?;
    // Header: version, revision, minor revision, number of keys; then 4 shorts a key: id,
    // location (0: the value is the fourth short), count, value.
    let n = usize::from(*dir.get(3).ok_or(GeoTiffProblem::NoGeoKeys)?);
    Ok(dir[4..]
        .chunks_exact(4)
        .take(n)
        .filter(|k| k[1] == 0)
        .map(|k| (k[0], k[3]))
        .collect())
}

/// The value of a GeoKey.
fn key(keys: &[(u16, u16)], id: u16) -> Option<u16> {
    keys.iter().find(|k| k.0 == id).map(|k| k.1)
}

/// Geographic WGS 84 in degrees with heights in metres, or why not.
fn check_crs(keys: &[(u16, u16)]) -> Result<(), HeaderError> {
    match key(keys, GT_MODEL_TYPE) {
        Some(2) => {}
        Some(1) => {
            let epsg = key(keys, PROJECTED_CS_TYPE).unwrap_or(USER_DEFINED);
            return Err(HeaderError::Projection(Crs::Projected { epsg }));
        }
        Some(3) => return Err(HeaderError::Projection(Crs::Geocentric)),
        other => {
            let model_type = other.unwrap_or(0);
            return Err(HeaderError::Projection(Crs::Model { model_type }));
        }
    }
    let epsg = key(keys, GEOGRAPHIC_TYPE).unwrap_or(USER_DEFINED);
    let wgs84_datum = key(keys, GEOG_GEODETIC_DATUM) == Some(DATUM_WGS84);
    if epsg != EPSG_WGS84 && !(epsg == USER_DEFINED && wgs84_datum) {
        return Err(HeaderError::Projection(Crs::Geographic { epsg }));
    }
    for (k, want) in [
        (GEOG_ANGULAR_UNITS, UNIT_DEGREE),
        (VERTICAL_UNITS, UNIT_METRE),
    ] {
        if let Some(code) = key(keys, k).filter(|&c| c != want) {
            return Err(GeoTiffProblem::Unit { key: k, code }.into());
        }
    }
    Ok(())
}

/// Where the samples lie, from the pixel scale and tie point or the transformation.
fn georeference<R: Read + Seek>(
    dec: &mut Decoder<R>,
    width: u32,
    height: u32,
    pixel_is_point: bool,
) -> Result<Georef, GeoTiffProblem> {
    let f64s = |dec: &mut Decoder<R>, tag| -> Result<Option<Vec<f64>>, GeoTiffProblem> {
        Ok(match dec.find_tag(tag)? {
            Some(v) => Some(v.into_f64_vec()?),
            None => None,
        })
    };
    let scale = f64s(dec, Tag::ModelPixelScaleTag)?;
    let tie = f64s(dec, Tag::ModelTiepointTag)?;
    let matrix = f64s(dec, Tag::ModelTransformationTag)?;
    // (raster i, raster j, model x, model y) of one tie, and the pixel size in x and y.
    let (tie, size) = match (scale, tie, matrix) {
        (Some(s), Some(t), _) if s.len() >= 2 && t.len() == 6 => {
            ([t[0], t[1], t[3], t[4]], [s[0], s[1]])
        }
        (Some(_), Some(t), _) if t.len() > 6 => return Err(GeoTiffProblem::Rotated),
        (_, _, Some(m)) if m.len() == 16 => {
            // x = m0 i + m1 j + m3, y = m4 i + m5 j + m7: north-up without rotation has m1 = m4 = 0.
            let tol = 1e-12 * (m[0].abs() + m[5].abs());
            if m[1].abs() > tol || m[4].abs() > tol {
                return Err(GeoTiffProblem::Rotated);
            }
            ([0.0, 0.0, m[3], m[7]], [m[0], -m[5]])
        }
        _ => return Err(GeoTiffProblem::NoGeoreference),
    };
    let ok = |v: f64| v.is_finite() && v > 0.0;
    if !ok(size[0]) || !ok(size[1]) || !tie.iter().all(|v| v.is_finite()) {
        return Err(GeoTiffProblem::PixelSize {
            x_deg: size[0],
            y_deg: size[1],
        });
    }
    // The sample of pixel (i, j) lies at its centre (area) or on its corner (point).
    let centre = if pixel_is_point { 0.0 } else { 0.5 };
    Ok(Georef {
        west_deg: tie[2] + (centre - tie[0]) * size[0],
        north_deg: tie[3] - (centre - tie[1]) * size[1],
        per_deg_lon: 1.0 / size[0],
        per_deg_lat: 1.0 / size[1],
        rows: height as usize,
        cols: width as usize,
        margin_px: centre,
    })
}

/// The no-data value of GDAL_NODATA (42113), if set.
fn nodata<R: Read + Seek>(dec: &mut Decoder<R>) -> Result<Option<f64>, GeoTiffProblem> {
    let Some(v) = dec.find_tag(Tag::GdalNodata)? else {
        return Ok(None);
    };
    let text = v.into_string()?;
    let t = text.trim_matches(|c: char| c.is_whitespace() || c == '\0');
    t.parse::<f64>()
        .map(Some)
        .map_err(|_| GeoTiffProblem::NoData {
            text: t.to_string(),
        })
}

/// The samples of a GeoTIFF whose header is `header`, row by row from the north, voids (the
/// no-data value, NaN) as NaN.
// A no-data value marks samples by equality: it is the exact value written in them.
#[allow(clippy::float_cmp)]
pub fn decode<R: Read + Seek>(reader: R, header: &Header) -> Result<Vec<f32>, GeoTiffProblem> {
    let mut dec = Decoder::new(reader)?.with_limits(limits());
    let nodata = header.nodata;
    // Integer samples are compared with the no-data value as numbers; float samples in their
    // own precision (GDAL writes an f32 file's no-data as the f32 value printed in full).
    let void_f64 = |v: f64| nodata.is_some_and(|n| v == n);
    let samples: Vec<f32> = match dec.read_image()? {
        DecodingResult::I16(v) => ints(&v, void_f64),
        DecodingResult::U16(v) => ints(&v, void_f64),
        DecodingResult::I32(v) => ints(&v, void_f64),
        DecodingResult::F32(v) => {
            let n32 = nodata.map(|n| n as f32);
            v.iter()
                .map(|&s| if Some(s) == n32 { f32::NAN } else { s })
                .collect()
        }
        DecodingResult::F64(v) => v
            .iter()
            .map(|&s| if void_f64(s) { f32::NAN } else { s as f32 })
            .collect(),
        _ => return Err(GeoTiffProblem::SampleType { bits: 0, format: 0 }),
    };
    let expected = (header.georef.rows * header.georef.cols) as u64;
    if samples.len() as u64 != expected {
        return Err(GeoTiffProblem::SampleCount {
            expected,
            got: samples.len() as u64,
        });
    }
    Ok(samples)
}

/// Integer samples as f32 (exact below 2^24: heights in metres), the no-data value as NaN.
fn ints<T: Copy + Into<f64>>(v: &[T], void: impl Fn(f64) -> bool) -> Vec<f32> {
    v.iter()
        .map(|&s| {
            let h: f64 = s.into();
            if void(h) {
                f32::NAN
            } else {
                h as f32
            }
        })
        .collect()
}
