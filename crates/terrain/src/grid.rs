//! A loaded tile: its samples and where they lie; bilinear heights.
//!
//! The height at a point is the bilinear interpolation of the four samples around it (Press et
//! al., *Numerical Recipes*, 3rd ed., eq. 3.6.5), as GDAL's bilinear resampling and srtm.py's
//! interpolation do: with `u`, `w` the point's fractions of a cell east and south of its
//! north-west sample,
//!
//! `h = (1-u)(1-w) h00 + u (1-w) h01 + (1-u) w h10 + u w h11`.
//!
//! On a grid point the height is that sample exactly. A void sample makes every point whose
//! height it weighs a void; a point on a grid line next to a void (its weight 0) keeps its
//! height. Points in the half-pixel margin of an area raster take the edge samples' heights.

use crate::georef::Georef;

/// A coordinate this close to a whole number of samples, in samples, is taken as on it (1e-7
/// samples is 9 micrometres on a 3 arc-second grid): a grid point given in degrees lands there
/// exactly, so its height is the sample's, bit for bit.
const SNAP_PX: f64 = 1e-7;

/// A tile's samples in memory (row by row from the north, voids as NaN).
pub(crate) struct Grid {
    /// Where the samples lie.
    pub georef: Georef,
    /// `rows * cols` heights, m.
    pub samples: Vec<f32>,
}

impl std::fmt::Debug for Grid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Grid")
            .field("georef", &self.georef)
            .field("samples", &self.samples.len())
            .finish()
    }
}

/// The cell a coordinate falls in along one axis and its fraction across it, the coordinate
/// clamped to the grid (the margin of an area raster) and snapped to whole samples.
#[inline]
pub(crate) fn cell(coord: f64, n: usize) -> (usize, f64) {
    let last = (n - 1) as f64;
    let mut c = coord.clamp(0.0, last);
    let r = c.round();
    if (c - r).abs() < SNAP_PX {
        c = r;
    }
    let i = (c.floor() as usize).min(n - 2);
    (i, c - i as f64)
}

impl Grid {
    /// The four samples of the cell whose north-west sample is `(row, col)`: north-west,
    /// north-east, south-west, south-east.
    #[inline]
    pub fn corners(&self, row: usize, col: usize) -> [f64; 4] {
        let n = self.georef.cols;
        let k = row * n + col;
        let s = &self.samples;
        [
            f64::from(s[k]),
            f64::from(s[k + 1]),
            f64::from(s[k + n]),
            f64::from(s[k + n + 1]),
        ]
    }

    /// The bilinear height at a point inside the tile's bounds, m; `None` on a void.
    pub fn height_m(&self, latitude_deg: f64, longitude_deg: f64) -> Option<f64> {
        let g = &self.georef;
        let (col, u) = cell(g.x(longitude_deg), g.cols);
        let (row, w) = cell(g.y(latitude_deg), g.rows);
        bilinear_weighted(self.corners(row, col), u, w)
    }
}

/// The bilinear interpolation at fractions `u` (east), `w` (south) of a cell; `None` when a
/// sample with a weight is a void.
#[inline]
pub(crate) fn bilinear_weighted(h: [f64; 4], u: f64, w: f64) -> Option<f64> {
    let v = bilinear(h, u, w);
    if !v.is_nan() {
        return Some(v);
    }
    let weights = [(1.0 - u) * (1.0 - w), u * (1.0 - w), (1.0 - u) * w, u * w];
    let mut sum = 0.0;
    for (hk, wk) in h.iter().zip(weights) {
        if wk != 0.0 {
            if hk.is_nan() {
                return None;
            }
            sum += wk * hk;
        }
    }
    Some(sum)
}

/// The bilinear interpolation at fractions `u`, `w` of a cell (NaN if any sample is).
#[inline]
pub(crate) fn bilinear(h: [f64; 4], u: f64, w: f64) -> f64 {
    let north = h[0] + u * (h[1] - h[0]);
    let south = h[2] + u * (h[3] - h[2]);
    north + w * (south - north)
}

#[cfg(test)]
impl Grid {
    /// A test tile of one cell a degree square, its north-west corner at 1 deg N 0 deg E, with
    /// `samples` (2 x 2: NW, NE, SW, SE; more only to weigh in memory).
    pub(crate) fn one_cell(samples: Vec<f32>) -> Grid {
        Grid {
            georef: Georef {
                north_deg: 1.0,
                west_deg: 0.0,
                per_deg_lat: 1.0,
                per_deg_lon: 1.0,
                rows: 2,
                cols: 2,
                margin_px: 0.0,
            },
            samples,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(samples: Vec<f32>) -> Grid {
        Grid {
            georef: Georef {
                north_deg: 1.0,
                west_deg: 0.0,
                per_deg_lat: 2.0,
                per_deg_lon: 2.0,
                rows: 3,
                cols: 3,
                margin_px: 0.0,
            },
            samples,
        }
    }

    #[test]
    fn bilinear_matches_a_hand_computation() {
        // Cell (0, 0): 10 at NW, 20 NE, 30 SW, 60 SE. At u = 0.25, w = 0.5:
        // 0.75*0.5*10 + 0.25*0.5*20 + 0.75*0.5*30 + 0.25*0.5*60 = 3.75 + 2.5 + 11.25 + 7.5 = 25.
        let g = grid(vec![10.0, 20.0, 0.0, 30.0, 60.0, 0.0, 0.0, 0.0, 0.0]);
        let h = g.height_m(1.0 - 0.25, 0.125).unwrap();
        assert!((h - 25.0).abs() < 1e-12, "{h}");
    }

    #[test]
    fn a_void_voids_the_points_it_weighs_and_no_other() {
        let nan = f32::NAN;
        let g = grid(vec![10.0, 20.0, 40.0, 30.0, nan, 50.0, 1.0, 2.0, 3.0]);
        // Inside the cell with the void at its SE corner.
        assert_eq!(g.height_m(0.75, 0.25), None);
        // On the north edge of that cell: the void has no weight.
        let h = g.height_m(1.0, 0.25).unwrap();
        assert!((h - 15.0).abs() < 1e-12, "{h}");
        // On the void itself.
        assert_eq!(g.height_m(0.5, 0.5), None);
    }

    #[test]
    fn coordinates_snap_to_grid_points_and_clamp_to_the_grid() {
        assert_eq!(cell(1.0 - 1e-9, 3), (1, 0.0));
        assert_eq!(cell(2.0, 3), (1, 1.0));
        assert_eq!(cell(-0.4, 3), (0, 0.0));
        assert_eq!(cell(2.4, 3), (1, 1.0));
        let (i, f) = cell(0.5, 3);
        assert!(i == 0 && (f - 0.5).abs() < 1e-15);
    }
}
