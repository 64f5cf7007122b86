//! Where a tile's samples lie: a north-up grid of sample points in latitude and longitude.
//!
//! Row 0 is the northernmost, column 0 the westernmost; sample `(row, col)` lies at
//! `north_deg - row / per_deg_lat`, `west_deg + col / per_deg_lon`. An SRTM tile's samples run
//! edge to edge (its last row and column repeat the neighbour's first). A GeoTIFF whose pixels
//! are areas (PixelIsArea, the default) has its samples at the pixel centres and covers half a
//! pixel more on every side: there the height is the edge sample's (`margin_px` = 0.5).

use crate::distance::MEAN_RADIUS_M;

/// How close to a tile's edge, deg, a point counts as on it (1e-9 deg is 0.1 mm): the end of
/// one run of a path is the start of the next, computed in floating point.
pub(crate) const EDGE_DEG: f64 = 1e-9;

/// A north-up grid of sample points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Georef {
    /// Latitude of row 0, deg.
    pub north_deg: f64,
    /// Longitude of column 0, deg.
    pub west_deg: f64,
    /// Rows per degree of latitude.
    pub per_deg_lat: f64,
    /// Columns per degree of longitude.
    pub per_deg_lon: f64,
    /// Rows (at least 2).
    pub rows: usize,
    /// Columns (at least 2).
    pub cols: usize,
    /// How far the tile covers beyond its outer samples, in pixels (0 or 0.5).
    pub margin_px: f64,
}

/// A tile's coverage, deg (edges included).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Bounds {
    pub south_deg: f64,
    pub north_deg: f64,
    pub west_deg: f64,
    pub east_deg: f64,
}

impl Bounds {
    /// Whether the point is inside or on the edge (within [`EDGE_DEG`]).
    pub fn contains(&self, latitude_deg: f64, longitude_deg: f64) -> bool {
        latitude_deg >= self.south_deg - EDGE_DEG
            && latitude_deg <= self.north_deg + EDGE_DEG
            && longitude_deg >= self.west_deg - EDGE_DEG
            && longitude_deg <= self.east_deg + EDGE_DEG
    }
}

impl Georef {
    /// The area the tile answers for.
    pub fn bounds(&self) -> Bounds {
        let m_lat = self.margin_px / self.per_deg_lat;
        let m_lon = self.margin_px / self.per_deg_lon;
        Bounds {
            north_deg: self.north_deg + m_lat,
            south_deg: self.north_deg - (self.rows - 1) as f64 / self.per_deg_lat - m_lat,
            west_deg: self.west_deg - m_lon,
            east_deg: self.west_deg + (self.cols - 1) as f64 / self.per_deg_lon + m_lon,
        }
    }

    /// Column coordinate of a longitude (fractional; not clamped).
    #[inline]
    pub fn x(&self, longitude_deg: f64) -> f64 {
        (longitude_deg - self.west_deg) * self.per_deg_lon
    }

    /// Row coordinate of a latitude (fractional; not clamped).
    #[inline]
    pub fn y(&self, latitude_deg: f64) -> f64 {
        (self.north_deg - latitude_deg) * self.per_deg_lat
    }

    /// The sample spacing at `latitude_deg`, m: the smaller of the north-south and the east-west
    /// spacing on the sphere of the mean Earth radius. The east-west spacing shrinks with the
    /// cosine of the latitude; it is taken as at least 1 % of the north-south one (within 0.6°
    /// of a pole), so that a path there is not cut into millions of samples.
    pub fn spacing_m(&self, latitude_deg: f64) -> f64 {
        let m_per_deg = MEAN_RADIUS_M * std::f64::consts::PI / 180.0;
        let ns = m_per_deg / self.per_deg_lat;
        let ew = m_per_deg / self.per_deg_lon * latitude_deg.to_radians().cos();
        ns.min(ew.max(0.01 * ns))
    }

    /// The width of one sample in degrees of latitude and longitude (the finer, for ordering
    /// overlapping tiles).
    pub fn step_deg(&self) -> f64 {
        (1.0 / self.per_deg_lat).min(1.0 / self.per_deg_lon)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn srtm3() -> Georef {
        Georef {
            north_deg: 45.0,
            west_deg: -72.0,
            per_deg_lat: 1200.0,
            per_deg_lon: 1200.0,
            rows: 1201,
            cols: 1201,
            margin_px: 0.0,
        }
    }

    #[test]
    fn an_srtm_tile_covers_its_degree_edge_to_edge() {
        let b = srtm3().bounds();
        // 1200 steps of 1/1200 deg: exact in binary to well below EDGE_DEG.
        assert!((b.south_deg - 44.0).abs() < 1e-12 && (b.east_deg + 71.0).abs() < 1e-12);
        assert!(b.contains(44.0, -72.0) && b.contains(45.0, -71.0));
        assert!(!b.contains(43.9999, -71.5) && !b.contains(44.5, -70.9999));
    }

    #[test]
    fn an_area_raster_covers_half_a_pixel_beyond_its_samples() {
        let g = Georef {
            margin_px: 0.5,
            per_deg_lat: 10.0,
            per_deg_lon: 10.0,
            rows: 3,
            cols: 3,
            ..srtm3()
        };
        let b = g.bounds();
        // Samples at 45.0, 44.9, 44.8 N: the pixels' areas run from 45.05 to 44.75.
        assert!((b.north_deg - 45.05).abs() < 1e-12 && (b.south_deg - 44.75).abs() < 1e-12);
        assert!((b.west_deg + 72.05).abs() < 1e-12 && (b.east_deg + 71.75).abs() < 1e-12);
    }

    #[test]
    fn spacing_is_the_smaller_of_north_south_and_east_west() {
        // 3 arc-seconds: 6371008.8 * pi / 180 / 1200 = 92.66 m north-south; east-west times
        // cos(44.5 deg) = 66.09 m.
        let s = srtm3().spacing_m(44.5);
        let ns = 6_371_008.8 * std::f64::consts::PI / 180.0 / 1200.0;
        assert!((ns - 92.662).abs() < 1e-3, "{ns}");
        assert!((s - ns * 44.5f64.to_radians().cos()).abs() < 1e-9, "{s}");
        assert!((s - 66.09).abs() < 0.01, "{s}");
        // At the equator both are 92.66 m; at the pole the floor holds.
        assert!((srtm3().spacing_m(0.0) - ns).abs() < 1e-9);
        assert!((srtm3().spacing_m(90.0) - 0.01 * ns).abs() < 1e-9);
    }
}
