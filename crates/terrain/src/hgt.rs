//! SRTM `.hgt` tiles: the name is the south-west corner (`N44W072.hgt` covers 44-45 N,
//! 72-71 W), the size decides the grid (1201 x 1201 samples 3 arc-seconds apart, or 3601 x 3601
//! at 1 arc-second), each sample a big-endian signed 16-bit height in metres above the EGM96
//! geoid, north row first and west sample first, -32768 a void.
//!
//! Decoding is from bytes handed in ([`decode`]); the files are opened by the index.

use crate::georef::Georef;

/// The value of a void sample.
pub const VOID: i16 = -32768;

/// The two SRTM grids, samples per side.
pub const SIDES: [usize; 2] = [1201, 3601];

/// Bytes of a tile of `side` x `side` samples.
pub const fn bytes_of_side(side: usize) -> u64 {
    2 * (side as u64) * (side as u64)
}

/// The side of the grid a file of `size_bytes` holds, if it is an SRTM size.
pub fn side_of_size(size_bytes: u64) -> Option<usize> {
    SIDES.into_iter().find(|&s| bytes_of_side(s) == size_bytes)
}

/// The south-west corner of a tile from its file name (`N44W072.hgt`, any case), deg.
pub fn corner_of_name(name: &str) -> Option<(i32, i32)> {
    let lower = name.to_ascii_lowercase();
    let stem = lower.strip_suffix(".hgt")?;
    let b = stem.as_bytes();
    if b.len() != 7 || !b[1..3].iter().chain(&b[4..7]).all(u8::is_ascii_digit) {
        return None;
    }
    let lat: i32 = stem[1..3].parse().ok()?;
    let lon: i32 = stem[4..7].parse().ok()?;
    let lat = match b[0] {
        b'n' if lat <= 89 => lat,
        b's' if (1..=90).contains(&lat) => -lat,
        _ => return None,
    };
    let lon = match b[3] {
        b'e' if lon <= 179 => lon,
        b'w' if (1..=180).contains(&lon) => -lon,
        _ => return None,
    };
    Some((lat, lon))
}

/// Where the samples of the tile with south-west corner `corner` and `side` samples a side lie.
pub fn georef(corner: (i32, i32), side: usize) -> Georef {
    Georef {
        north_deg: f64::from(corner.0 + 1),
        west_deg: f64::from(corner.1),
        per_deg_lat: (side - 1) as f64,
        per_deg_lon: (side - 1) as f64,
        rows: side,
        cols: side,
        margin_px: 0.0,
    }
}

/// The heights of a tile's bytes, row by row from the north, voids as NaN (the caller checked
/// the length: `bytes.len()` is even).
pub fn decode(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(2)
        .map(|b| match i16::from_be_bytes([b[0], b[1]]) {
            VOID => f32::NAN,
            h => f32::from(h),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_south_west_corners_in_any_case() {
        assert_eq!(corner_of_name("N44W072.hgt"), Some((44, -72)));
        assert_eq!(corner_of_name("n44w072.HGT"), Some((44, -72)));
        assert_eq!(corner_of_name("S01E000.hgt"), Some((-1, 0)));
        assert_eq!(corner_of_name("S90W180.hgt"), Some((-90, -180)));
        assert_eq!(corner_of_name("N89E179.hgt"), Some((89, 179)));
        for bad in [
            "N90E000.hgt",
            "S00E000.hgt",
            "N44E180.hgt",
            "N44W000.hgt",
            "N44W72.hgt",
            "X44W072.hgt",
            "N44W072.hg",
            "N4aW072.hgt",
            "dem.hgt",
            "N44W072_1.hgt",
        ] {
            assert_eq!(corner_of_name(bad), None, "{bad}");
        }
    }

    #[test]
    fn sizes_are_the_two_srtm_grids() {
        assert_eq!(side_of_size(2_884_802), Some(1201));
        assert_eq!(side_of_size(25_934_402), Some(3601));
        assert_eq!(side_of_size(2_884_800), None);
    }

    #[test]
    fn samples_are_big_endian_with_voids_as_nan() {
        let h = decode(&[0x01, 0x55, 0xff, 0xfe, 0x80, 0x00]);
        assert_eq!(h[..2], [341.0, -2.0]);
        assert!(h[2].is_nan());
    }
}
