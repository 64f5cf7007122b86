//! The errors of the tile reader: each names the file, or the place that has no answer.

use std::path::PathBuf;

use aloft_core::Num;

/// Why a terrain directory cannot be read, or a place has no height.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TerrainError {
    /// A file or the directory cannot be read.
    #[error("terrain tiles: {}: {source}", .file.display())]
    Io {
        /// The file or directory.
        file: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// A directory with no elevation tile in it.
    #[error("terrain directory {}: no elevation tile in it (SRTM .hgt or .hgt.zip named by their south-west corner, such as N44W072.hgt; GeoTIFF .tif or .tiff)", .dir.display())]
    NoTiles {
        /// The directory.
        dir: PathBuf,
    },
    /// An SRTM tile whose size is neither of the two SRTM grids.
    #[error("terrain file {}: {size_bytes} bytes, not an SRTM tile: expected {} bytes (1201 x 1201 samples, 3 arc-second) or {} bytes (3601 x 3601, 1 arc-second)", .file.display(), crate::hgt::bytes_of_side(1201), crate::hgt::bytes_of_side(3601))]
    WrongSize {
        /// The file (for a `.hgt.zip`, the archive and its entry).
        file: PathBuf,
        /// Its size, bytes.
        size_bytes: u64,
    },
    /// An SRTM tile whose name is not a south-west corner.
    #[error("terrain file {}: the name is not a south-west corner such as N44W072.hgt (N00-N89 or S01-S90, then E000-E179 or W001-W180)", .file.display())]
    BadName {
        /// The file (for a `.hgt.zip`, the archive and its entry).
        file: PathBuf,
    },
    /// A `.hgt.zip` that cannot be read as a zip archive, or whose tile cannot be inflated.
    #[error("terrain file {}: not a readable zip archive: {source}", .file.display())]
    Zip {
        /// The archive.
        file: PathBuf,
        /// What the zip reader said.
        source: zip::result::ZipError,
    },
    /// A `.hgt.zip` that does not hold exactly one `.hgt` tile.
    #[error("terrain file {}: the archive holds {hgt_entries} .hgt file(s), not one", .file.display())]
    ZipContents {
        /// The archive.
        file: PathBuf,
        /// How many `.hgt` entries it holds.
        hgt_entries: usize,
    },
    /// A GeoTIFF that aloft cannot read as a single-band north-up elevation grid.
    #[error("terrain file {}: {problem}", .file.display())]
    GeoTiff {
        /// The file.
        file: PathBuf,
        /// What is wrong with it.
        problem: GeoTiffProblem,
    },
    /// A GeoTIFF in a coordinate reference system other than geographic WGS 84.
    #[error("terrain file {}: its coordinates are in {crs}; aloft reads elevation in geographic WGS 84 (EPSG:4326) only: reproject it, e.g. `gdalwarp -t_srs EPSG:4326`", .file.display())]
    Projection {
        /// The file.
        file: PathBuf,
        /// The reference system it declares.
        crs: Crs,
    },
    /// A place where the tile has no data (an SRTM void, a GeoTIFF's no-data value).
    #[error("no height at {}, {}: the tile {} has no data there (a void)", Num(*.latitude_deg), Num(*.longitude_deg), .file.display())]
    Void {
        /// Latitude, deg.
        latitude_deg: f64,
        /// Longitude, deg.
        longitude_deg: f64,
        /// The tile.
        file: PathBuf,
    },
    /// A place no tile of the directory covers.
    #[error("no height at {}, {}: no elevation tile of the terrain directory covers it", Num(*.latitude_deg), Num(*.longitude_deg))]
    NoTile {
        /// Latitude, deg.
        latitude_deg: f64,
        /// Longitude, deg.
        longitude_deg: f64,
    },
    /// A latitude or longitude that is not a place (not finite, latitude beyond ±90°, longitude
    /// beyond ±180°).
    #[error("{}, {} is not a place: latitude must be within -90 to 90 deg and longitude within -180 to 180 deg", Num(*.latitude_deg), Num(*.longitude_deg))]
    NotAPlace {
        /// Latitude, deg.
        latitude_deg: f64,
        /// Longitude, deg.
        longitude_deg: f64,
    },
    /// An altitude of a path point that is not finite.
    #[error("the altitude {} m of a path point is not a number", Num(*.altitude_amsl_m))]
    NotAnAltitude {
        /// The altitude, m.
        altitude_amsl_m: f64,
    },
    /// A profile that would hold more samples than one answer may.
    #[error("a ground profile of {} m at {} m spacing is {samples} samples, more than the {max_samples} one profile may hold", Num(*.distance_m), Num(*.spacing_m))]
    ProfileTooLong {
        /// The path's length, m.
        distance_m: f64,
        /// The sample spacing, m.
        spacing_m: f64,
        /// Samples it would take.
        samples: u64,
        /// The most one profile holds.
        max_samples: u64,
    },
}

/// What is wrong with a GeoTIFF elevation file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GeoTiffProblem {
    /// The TIFF decoder failed (a damaged or truncated file, a compression aloft does not read).
    #[error("not a readable TIFF: {0}")]
    Decode(#[from] tiff::TiffError),
    /// Its strips or tiles reach beyond the end of the file.
    #[error("truncated: its image data needs {needed_bytes} bytes, the file has {size_bytes}")]
    Truncated {
        /// Bytes the image data needs.
        needed_bytes: u64,
        /// Bytes in the file.
        size_bytes: u64,
    },
    /// No GeoKeyDirectory (tag 34735): the reference system is unknown.
    #[error("no GeoKeyDirectory (tag 34735): its coordinate reference system is unknown")]
    NoGeoKeys,
    /// Neither a pixel scale and tie point (tags 33550, 33922) nor a transformation (34264).
    #[error("no georeference: neither ModelPixelScale (33550) with ModelTiepoint (33922) nor ModelTransformation (34264)")]
    NoGeoreference,
    /// A rotated or sheared grid (a transformation with off-diagonal terms), or ground control
    /// points without a pixel scale.
    #[error("a rotated or warped grid: aloft reads north-up grids only")]
    Rotated,
    /// A pixel size that is not positive and finite (a south-up or empty grid).
    #[error("pixel size {} x {} deg: aloft reads north-up grids with a positive pixel size", Num(*.x_deg), Num(*.y_deg))]
    PixelSize {
        /// East-west pixel size, deg.
        x_deg: f64,
        /// North-south pixel size, deg (positive for a north-up grid).
        y_deg: f64,
    },
    /// More than one band.
    #[error("{bands} bands: aloft reads single-band elevation files")]
    Bands {
        /// Samples per pixel.
        bands: u16,
    },
    /// A sample type other than i16, u16, i32, f32 or f64.
    #[error("{bits}-bit samples of format {format} (1 unsigned, 2 signed, 3 float): aloft reads i16, u16, i32, f32 and f64")]
    SampleType {
        /// Bits per sample.
        bits: u16,
        /// SampleFormat tag value.
        format: u16,
    },
    /// Fewer than two rows or columns: nothing to interpolate between.
    #[error("{width} x {height} samples: at least 2 x 2 are needed")]
    TooSmall {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
    },
    /// More samples than aloft holds for one tile.
    #[error("{samples} samples, more than the {max_samples} aloft holds for one tile: cut it into tiles (gdal_retile.py)")]
    TooLarge {
        /// Samples in the file.
        samples: u64,
        /// The most aloft reads.
        max_samples: u64,
    },
    /// Heights in a unit other than metres (VerticalUnitsGeoKey 4099), or angles other than
    /// degrees (GeogAngularUnitsGeoKey 2054).
    #[error("unit code {code} in GeoKey {key}: aloft reads heights in metres (9001) and angles in degrees (9102)")]
    Unit {
        /// The GeoKey.
        key: u16,
        /// Its EPSG unit code.
        code: u16,
    },
    /// A GDAL_NODATA tag (42113) that is not a number.
    #[error("GDAL_NODATA (tag 42113) {text:?} is not a number")]
    NoData {
        /// The tag's text.
        text: String,
    },
    /// An image whose decoded size is not its declared size.
    #[error("{got} samples decoded, {expected} declared")]
    SampleCount {
        /// Samples declared (width x height).
        expected: u64,
        /// Samples decoded.
        got: u64,
    },
}

/// A coordinate reference system a GeoTIFF declares, as its GeoKeys give it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Crs {
    /// A projected system (ProjectedCSTypeGeoKey 3072), by its EPSG code (32767: user-defined).
    Projected {
        /// The EPSG code.
        epsg: u16,
    },
    /// A geographic system other than WGS 84 (GeographicTypeGeoKey 2048).
    Geographic {
        /// The EPSG code (32767: user-defined, on a datum other than WGS 84).
        epsg: u16,
    },
    /// A geocentric (earth-centred cartesian) system.
    Geocentric,
    /// A model type other than projected, geographic or geocentric (GTModelTypeGeoKey 1024).
    Model {
        /// The model type.
        model_type: u16,
    },
}

impl std::fmt::Display for Crs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Crs::Projected { epsg: 32767 } => write!(f, "a user-defined projected system"),
            Crs::Projected { epsg } => write!(f, "the projected system EPSG:{epsg}"),
            Crs::Geographic { epsg: 32767 } => {
                write!(
                    f,
                    "a user-defined geographic system on a datum other than WGS 84"
                )
            }
            Crs::Geographic { epsg } => write!(f, "the geographic system EPSG:{epsg}"),
            Crs::Geocentric => write!(f, "a geocentric system"),
            Crs::Model { model_type } => write!(f, "model type {model_type}"),
        }
    }
}
