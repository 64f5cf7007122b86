//! The tiles held in memory: at most [`MAX_TILES_HELD`] and [`MAX_HELD_BYTES`], the least
//! recently used let go first (a caller that still uses one keeps it alive through its `Arc`
//! until it is done).

use std::sync::Arc;

use crate::grid::Grid;

/// The most tiles held at once: a path across the corner of four tiles, and as many again.
pub const MAX_TILES_HELD: usize = 8;

/// The most bytes of samples held at once (8 SRTM1 tiles are 415 MB; 8 SRTM3 tiles 46 MB); the
/// tile just loaded is held even when it alone is larger.
pub const MAX_HELD_BYTES: usize = 512 * 1024 * 1024;

/// Loaded tiles by their index in the directory's index, most recently used last.
#[derive(Debug, Default)]
pub(crate) struct Cache {
    held: Vec<(usize, Arc<Grid>)>,
}

fn bytes(g: &Grid) -> usize {
    g.samples.len() * std::mem::size_of::<f32>()
}

impl Cache {
    /// Tile `k`, if held (it becomes the most recently used).
    pub fn get(&mut self, k: usize) -> Option<Arc<Grid>> {
        let at = self.held.iter().position(|(i, _)| *i == k)?;
        let entry = self.held.remove(at);
        let grid = Arc::clone(&entry.1);
        self.held.push(entry);
        Some(grid)
    }

    /// Hold tile `k`, letting the least recently used go while over either bound.
    pub fn put(&mut self, k: usize, grid: Arc<Grid>) {
        self.held.push((k, grid));
        while self.held.len() > 1
            && (self.held.len() > MAX_TILES_HELD || self.held_bytes() > MAX_HELD_BYTES)
        {
            self.held.remove(0);
        }
    }

    /// Tiles held.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.held.len()
    }

    fn held_bytes(&self) -> usize {
        self.held.iter().map(|(_, g)| bytes(g)).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(samples: usize) -> Arc<Grid> {
        Arc::new(Grid::one_cell(vec![0.0; samples]))
    }

    #[test]
    fn the_least_recently_used_tile_goes_first() {
        let mut c = Cache::default();
        for k in 0..MAX_TILES_HELD {
            c.put(k, grid(4));
        }
        assert!(c.get(0).is_some()); // 0 is now the most recently used
        c.put(100, grid(4));
        assert_eq!(c.len(), MAX_TILES_HELD);
        assert!(c.get(1).is_none(), "1 was the least recently used");
        assert!(c.get(0).is_some() && c.get(100).is_some() && c.get(2).is_some());
    }

    #[test]
    fn bytes_bound_the_tiles_held_but_the_new_one_stays() {
        let mut c = Cache::default();
        let big = MAX_HELD_BYTES / 4 / 2 + 1; // a little over half the bytes
        c.put(1, grid(big));
        c.put(2, grid(big));
        assert_eq!(c.len(), 1);
        assert!(c.get(2).is_some());
    }
}
