//! The shared real SRTM3 tile, N44W072.hgt (the White Mountains; `ALOFT_DATA_DIR`/terrain):
//! heights against its raw bytes read here, srtm.py's check values, Mount Washington's summit,
//! the zipped tile, GDAL where it is installed, and the least clearance against dense sampling.

mod common;

use aloft_terrain::{PathPoint, Terrain};
use common::{n44w072_place, shared_terrain, write_zip, Raw};

fn shared() -> Terrain {
    Terrain::open(&shared_terrain()).unwrap_or_else(|e| panic!("{e}"))
}

/// Grid points spread over the tile (a fixed linear congruential sequence), corners included.
fn grid_points() -> Vec<(usize, usize)> {
    let mut v = vec![(0, 0), (0, 1200), (1200, 0), (1200, 1200), (875, 836)];
    let mut x: u64 = 12345;
    for _ in 0..400 {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        v.push(((x >> 33) as usize % 1201, (x >> 13) as usize % 1201));
    }
    v
}

/// At every grid point the height is the tile's own sample, exactly (the bytes read here at
/// offset 2 * (row * 1201 + col)).
#[test]
fn data_val_heights_are_the_raw_samples_at_grid_points() {
    let (t, raw) = (shared(), Raw::shared());
    for (r, c) in grid_points() {
        let (lat, lon) = n44w072_place(r, c);
        let h = t.height_m(lat, lon).unwrap();
        assert_eq!(
            h.to_bits(),
            f64::from(raw.at(r, c)).to_bits(),
            "({r}, {c}) {h}"
        );
    }
}

/// Between grid points: the bilinear interpolation computed here by hand from the raw samples.
#[test]
fn data_val_heights_between_samples_are_bilinear() {
    let (t, raw) = (shared(), Raw::shared());
    for (r, c) in grid_points() {
        let (r, c) = (r.min(1199), c.min(1199));
        for (fu, fw) in [(0.3, 0.7), (0.5, 0.5), (0.9, 0.1)] {
            let lat = 45.0 - (r as f64 + fw) / 1200.0;
            let lon = -72.0 + (c as f64 + fu) / 1200.0;
            let h = |dr, dc| f64::from(raw.at(r + dr, c + dc));
            let want = (1.0 - fu) * (1.0 - fw) * h(0, 0)
                + fu * (1.0 - fw) * h(0, 1)
                + (1.0 - fu) * fw * h(1, 0)
                + fu * fw * h(1, 1);
            let got = t.height_m(lat, lon).unwrap();
            // The place in degrees carries ~1e-13 deg of rounding: 1e-9 samples of a cell
            // whose corners differ by at most a few hundred metres.
            assert!((got - want).abs() < 1e-6, "({r}, {c}) {got} vs {want}");
        }
    }
}

/// srtm.py's tests for this tile: exactly 341 m at 44 N 72 W (its south-west corner), and
/// 801-814 m at (44.1756325, -71.5965699).
#[test]
fn data_val_srtm_py_check_values() {
    let t = shared();
    assert_eq!(t.height_m(44.0, -72.0).unwrap().to_bits(), 341f64.to_bits());
    let h = t.height_m(44.1756325, -71.5965699).unwrap();
    assert!((801.0..=814.0).contains(&h), "{h}");
}

/// Mount Washington's summit, 1,917 m (NGS survey; NAVD88, within a metre of the EGM96 geoid
/// SRTM uses there) at 44.2706 N, 71.3033 W. The tile's bilinear height there is 1,907.1 m: its
/// four samples are 1,898-1,908 m, since a 3 arc-second sample (92 m x 66 m) averages the radar
/// return over its cell and flattens a summit. SRTM's absolute height error is 16 m at 90 %
/// (the mission's specification; Rodriguez et al. 2005, "An assessment of the SRTM topographic
/// products", JPL D-31639, found it met): the bound. A summit cannot read above its survey height by more
/// than that either.
#[test]
fn data_val_mount_washington_within_srtm_accuracy() {
    let h = shared().height_m(44.2706, -71.3033).unwrap();
    assert!((1917.0 - 16.0..=1917.0 + 16.0).contains(&h), "{h}");
    // And it is lower than the summit, as a smoothed summit must be (1,907.1 m computed by hand
    // from the samples 1908, 1898, 1906, 1901 at fractions 0.04 east, 0.28 south).
    assert!((h - 1907.096).abs() < 0.01, "{h}");
}

/// The tile zipped (deflated, written here) gives the same heights as the tile.
#[test]
fn data_val_zipped_tile_gives_the_same_heights() {
    let dir = tempfile::tempdir().unwrap();
    let raw = Raw::shared();
    write_zip(&dir.path().join("N44W072.hgt.zip"), "N44W072.hgt", &raw.0);
    let (zipped, plain) = (Terrain::open(dir.path()).unwrap(), shared());
    for (r, c) in grid_points() {
        // Inside the cell south-east of the grid point.
        let (lat, lon) = n44w072_place(r.min(1199), c.min(1199));
        let (lat, lon) = (lat - 0.3 / 1200.0, lon + 0.6 / 1200.0);
        let (a, b) = (
            zipped.height_m(lat, lon).unwrap(),
            plain.height_m(lat, lon).unwrap(),
        );
        assert_eq!(a.to_bits(), b.to_bits(), "({lat}, {lon})");
    }
}

/// GDAL's `gdallocationinfo -wgs84 -valonly` reads the same sample at the same place. GDAL is a
/// reference only where it is installed (not on aloft's machines by default): without it the
/// test says so and checks nothing.
#[test]
fn data_val_gdallocationinfo_agrees_where_gdal_is_installed() {
    let file = shared_terrain().join("N44W072.hgt");
    let probe = std::process::Command::new("gdallocationinfo")
        .arg("--version")
        .output();
    if probe.is_err() {
        eprintln!("gdallocationinfo is not installed: the GDAL cross-check did not run");
        return;
    }
    let t = shared();
    for (r, c) in grid_points().into_iter().take(60) {
        // GDAL reads an .hgt as pixel-is-area cells centred on the samples and answers the
        // sample of the cell a place falls in: ask at the sample's own place.
        let (lat, lon) = n44w072_place(r, c);
        let out = std::process::Command::new("gdallocationinfo")
            .args(["-wgs84", "-valonly"])
            .arg(&file)
            .args([lon.to_string(), lat.to_string()])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        let gdal: f64 = text.trim().parse().unwrap_or_else(|_| panic!("{text:?}"));
        let ours = t.height_m(lat, lon).unwrap();
        assert_eq!(
            ours.to_bits(),
            gdal.to_bits(),
            "({lat}, {lon}): {ours} vs GDAL {gdal}"
        );
    }
}

/// The least clearance found by walking the cells is the least of the clearance sampled every
/// metre along the path (the plain version, `height_m` at each place), never above it and
/// within centimetres of it; and never above the least over the path's profile.
#[test]
fn data_val_least_clearance_matches_dense_sampling() {
    let t = shared();
    let legs = [
        ((44.25, -71.35, 2100.0), (44.29, -71.26, 2100.0)),
        ((44.2706, -71.40, 1500.0), (44.2706, -71.20, 2300.0)),
        ((44.10, -71.30, 1000.0), (44.35, -71.31, 1000.0)),
        ((44.20, -71.60, 900.0), (44.21, -71.58, 1200.0)),
    ];
    for (a, b) in legs {
        let at = |p: (f64, f64, f64)| PathPoint {
            latitude_deg: p.0,
            longitude_deg: p.1,
            altitude_amsl_m: p.2,
        };
        let c = t.least_clearance(at(a), at(b)).unwrap();
        let length_m = aloft_terrain::distance::haversine_m((a.0, a.1), (b.0, b.1));
        let n = length_m.ceil() as usize;
        let mut least = f64::INFINITY;
        for i in 0..=n {
            let f = i as f64 / n as f64;
            let (lat, lon) = (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1));
            let alt = a.2 + f * (b.2 - a.2);
            least = least.min(alt - t.height_m(lat, lon).unwrap());
        }
        assert!(c.clearance_m <= least + 1e-6, "{c:?} vs sampled {least}");
        assert!(c.clearance_m >= least - 0.05, "{c:?} vs sampled {least}");
        // The place it names has that clearance.
        let f = c.distance_m / length_m;
        let ground = t.height_m(c.latitude_deg, c.longitude_deg).unwrap();
        assert!(
            (ground - c.ground_m).abs() < 1e-6,
            "{c:?}: ground there {ground}"
        );
        assert!((a.2 + f * (b.2 - a.2) - ground - c.clearance_m).abs() < 1e-6);
        let profile = t.profile((a.0, a.1), (b.0, b.1)).unwrap();
        let profile_least = profile
            .iter()
            .map(|s| a.2 + s.distance_m / length_m * (b.2 - a.2) - s.height_m)
            .fold(f64::INFINITY, f64::min);
        assert!(c.clearance_m <= profile_least + 1e-6);
    }
}
