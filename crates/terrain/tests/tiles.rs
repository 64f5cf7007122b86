//! Tiles written by the tests with known values: every format and sample type, the grid's
//! placement (pixel-is-area and pixel-is-point), paths across tiles, and every bad input named
//! in one line.

mod common;

use std::path::Path;

use aloft_terrain::{Crs, GeoTiffProblem, PathPoint, Terrain, TerrainError};
use common::{write_geotiff, write_hgt, write_zip, GeoTags};
use tiff::encoder::colortype::{Gray16, Gray32Float, Gray64Float, GrayI16, GrayI32};

/// The values of the 4 x 3 test grids (row by row from the north).
const VALUES: [i16; 12] = [100, 110, 120, 130, 200, 215, 230, 245, 300, 320, 340, 360];

/// The place of sample (row, col) of a pixel-is-area grid with its north-west corner at 10 N,
/// 20 E and 0.1 deg pixels: the pixel's centre.
fn centre(row: usize, col: usize) -> (f64, f64) {
    (
        10.0 - 0.05 - 0.1 * row as f64,
        20.0 + 0.05 + 0.1 * col as f64,
    )
}

fn open(dir: &Path) -> Terrain {
    Terrain::open(dir).unwrap_or_else(|e| panic!("{e}"))
}

fn assert_close(got: f64, want: f64, tol: f64, what: &str) {
    assert!((got - want).abs() <= tol, "{what}: {got}, expected {want}");
}

/// Each sample type reads its values: at every pixel centre the height is the sample's.
#[test]
fn geotiffs_of_every_sample_type_read_their_values() {
    let dir = tempfile::tempdir().unwrap();
    let tags = GeoTags::wgs84(10.0, 20.0, 0.1);
    let p = |name: &str| dir.path().join(name);
    write_geotiff::<GrayI16>(&p("i16.tif"), 4, 3, &VALUES, &tags);
    let as_u16: Vec<u16> = VALUES.iter().map(|&v| v as u16).collect();
    let as_i32: Vec<i32> = VALUES.iter().map(|&v| i32::from(v)).collect();
    let as_f32: Vec<f32> = VALUES.iter().map(|&v| f32::from(v) + 0.25).collect();
    let as_f64: Vec<f64> = VALUES.iter().map(|&v| f64::from(v) - 0.5).collect();
    for (name, offset) in [
        ("i16.tif", 0.0),
        ("u16.tif", 0.0),
        ("i32.tif", 0.0),
        ("f32.tif", 0.25),
        ("f64.tif", -0.5),
    ] {
        let one = tempfile::tempdir().unwrap();
        let path = one.path().join(name);
        match name {
            "i16.tif" => std::fs::copy(p("i16.tif"), &path).map(|_| ()).unwrap(),
            "u16.tif" => write_geotiff::<Gray16>(&path, 4, 3, &as_u16, &tags),
            "i32.tif" => write_geotiff::<GrayI32>(&path, 4, 3, &as_i32, &tags),
            "f32.tif" => write_geotiff::<Gray32Float>(&path, 4, 3, &as_f32, &tags),
            _ => write_geotiff::<Gray64Float>(&path, 4, 3, &as_f64, &tags),
        }
        let t = open(one.path());
        for row in 0..3 {
            for col in 0..4 {
                let (lat, lon) = centre(row, col);
                let want = f64::from(VALUES[row * 4 + col]) + offset;
                assert_close(t.height_m(lat, lon).unwrap(), want, 1e-9, name);
            }
        }
        // Between samples: bilinear. Halfway between (0,0) and (1,1): the mean of the four.
        let want = (100.0 + 110.0 + 200.0 + 215.0) / 4.0 + offset;
        assert_close(t.height_m(9.9, 20.1).unwrap(), want, 1e-9, name);
        // Spacing: 0.1 deg is 11.1 km north-south, cos(10 deg) of it east-west.
        let ns = 6_371_008.8 * std::f64::consts::PI / 180.0 * 0.1;
        assert_close(
            t.spacing_m(9.9, 20.1).unwrap(),
            ns * 9.9f64.to_radians().cos(),
            1e-6,
            name,
        );
    }
}

/// Pixel-is-area puts a sample at its pixel's centre, half a pixel in from the tie point;
/// pixel-is-point puts it on the tie point: the same file read both ways differs by half a
/// pixel.
#[test]
fn pixel_is_point_puts_the_sample_on_the_tie_point() {
    let area = tempfile::tempdir().unwrap();
    let point = tempfile::tempdir().unwrap();
    let mut tags = GeoTags::wgs84(10.0, 20.0, 0.1);
    write_geotiff::<GrayI16>(&area.path().join("a.tif"), 4, 3, &VALUES, &tags);
    tags.keys = vec![(1024, 2), (1025, 2), (2048, 4326)];
    write_geotiff::<GrayI16>(&point.path().join("p.tif"), 4, 3, &VALUES, &tags);
    let (a, p) = (open(area.path()), open(point.path()));
    // On the tie point: the point raster's first sample; the area raster's margin, which holds
    // the edge sample.
    assert_close(p.height_m(10.0, 20.0).unwrap(), 100.0, 1e-9, "point at tie");
    assert_close(a.height_m(10.0, 20.0).unwrap(), 100.0, 1e-9, "area at tie");
    // At the first pixel's centre: the area raster's first sample; for the point raster the
    // middle of its first cell, the mean of four samples.
    assert_close(
        a.height_m(9.95, 20.05).unwrap(),
        100.0,
        1e-9,
        "area at centre",
    );
    let mean = (100.0 + 110.0 + 200.0 + 215.0) / 4.0;
    assert_close(
        p.height_m(9.95, 20.05).unwrap(),
        mean,
        1e-9,
        "point at centre",
    );
    // The point raster covers 10 to 9.8 N; the area raster's samples run from 9.95 to 9.75 N
    // and it covers half a pixel more, to 9.7 N, where the last row's heights hold (300 and
    // 320 at 20.05 and 20.15 E: 310 between them).
    assert!(matches!(
        p.height_m(9.72, 20.1),
        Err(TerrainError::NoTile { .. })
    ));
    assert_close(a.height_m(9.72, 20.1).unwrap(), 310.0, 1e-9, "area margin");
}

/// A ModelTransformation without rotation reads as the same grid as scale and tie point; one
/// with rotation is refused.
#[test]
fn a_transformation_reads_as_scale_and_tie_and_a_rotation_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut tags = GeoTags::wgs84(0.0, 0.0, 0.0);
    tags.scale_tie = None;
    let m = [
        0.1, 0.0, 0.0, 20.0, 0.0, -0.1, 0.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ];
    tags.transform = Some(m);
    write_geotiff::<GrayI16>(&dir.path().join("m.tif"), 4, 3, &VALUES, &tags);
    let t = open(dir.path());
    let (lat, lon) = centre(2, 3);
    assert_close(t.height_m(lat, lon).unwrap(), 360.0, 1e-9, "transform");
    let mut rotated = m;
    rotated[1] = 0.01;
    tags.transform = Some(rotated);
    let r = tempfile::tempdir().unwrap();
    write_geotiff::<GrayI16>(&r.path().join("r.tif"), 4, 3, &VALUES, &tags);
    let e = Terrain::open(r.path()).unwrap_err();
    assert!(
        matches!(
            &e,
            TerrainError::GeoTiff {
                problem: GeoTiffProblem::Rotated,
                ..
            }
        ),
        "{e}"
    );
    one_line_naming(&e, "r.tif");
}

/// GDAL_NODATA marks voids, in integer and float files; a point that weighs a void has no
/// height, one on a grid line beside it keeps its own.
#[test]
fn gdal_nodata_is_a_void() {
    let dir = tempfile::tempdir().unwrap();
    let mut tags = GeoTags::wgs84(10.0, 20.0, 0.1);
    tags.nodata = Some("-9999".to_string());
    let mut values: Vec<f32> = VALUES.iter().map(|&v| f32::from(v)).collect();
    values[5] = -9999.0; // (1, 1)
    write_geotiff::<Gray32Float>(&dir.path().join("v.tif"), 4, 3, &values, &tags);
    let t = open(dir.path());
    let (lat, lon) = centre(1, 1);
    let e = t.height_m(lat, lon).unwrap_err();
    assert!(matches!(e, TerrainError::Void { .. }), "{e}");
    one_line_naming(&e, "v.tif");
    // Between (0,1) and (1,1): weighs the void.
    assert!(t.height_m(9.9, centre(0, 1).1).is_err());
    // On the row of (0,*), between (0,1) and (0,2): the void has no weight.
    let (lat0, _) = centre(0, 0);
    assert_close(
        t.height_m(lat0, 20.2).unwrap(),
        115.0,
        1e-9,
        "beside the void",
    );
    // A profile and a clearance over the void say so, naming the place.
    let e = t.profile(centre(1, 0), centre(1, 3)).unwrap_err();
    assert!(matches!(e, TerrainError::Void { .. }), "{e}");
}

/// A GeoTIFF in UTM zone 19N (EPSG:32619) is refused, naming the file and the system; so is one
/// on another datum, and one without GeoKeys.
#[test]
fn a_geotiff_in_another_projection_is_refused_naming_it() {
    type Case = (&'static str, Vec<(u16, u16)>, Crs);
    let cases: [Case; 3] = [
        (
            "utm.tif",
            vec![(1024, 1), (3072, 32619)],
            Crs::Projected { epsg: 32619 },
        ),
        (
            "nad27.tif",
            vec![(1024, 2), (2048, 4267)],
            Crs::Geographic { epsg: 4267 },
        ),
        ("geocentric.tif", vec![(1024, 3)], Crs::Geocentric),
    ];
    for (name, keys, crs) in cases {
        let dir = tempfile::tempdir().unwrap();
        let mut tags = GeoTags::wgs84(4_900_000.0, 300_000.0, 30.0);
        tags.keys = keys;
        write_geotiff::<GrayI16>(&dir.path().join(name), 4, 3, &VALUES, &tags);
        let e = Terrain::open(dir.path()).unwrap_err();
        match &e {
            TerrainError::Projection { crs: got, .. } => assert_eq!(*got, crs, "{name}"),
            other => panic!("{name}: {other}"),
        }
        one_line_naming(&e, name);
    }
    let dir = tempfile::tempdir().unwrap();
    let msg = {
        let mut tags = GeoTags::wgs84(4_900_000.0, 300_000.0, 30.0);
        tags.keys = vec![(1024, 1), (3072, 32619)];
        write_geotiff::<GrayI16>(&dir.path().join("utm.tif"), 4, 3, &VALUES, &tags);
        Terrain::open(dir.path()).unwrap_err().to_string()
    };
    assert!(msg.contains("EPSG:32619"), "{msg}");
    let dir = tempfile::tempdir().unwrap();
    let mut tags = GeoTags::wgs84(10.0, 20.0, 0.1);
    tags.keys.clear();
    write_geotiff::<GrayI16>(&dir.path().join("nokeys.tif"), 4, 3, &VALUES, &tags);
    let e = Terrain::open(dir.path()).unwrap_err();
    assert!(
        matches!(
            &e,
            TerrainError::GeoTiff {
                problem: GeoTiffProblem::NoGeoKeys,
                ..
            }
        ),
        "{e}"
    );
}

/// A GeoTIFF cut short is refused when the directory is opened, naming the file.
#[test]
fn a_truncated_geotiff_is_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.tif");
    let values: Vec<f32> = (0..64 * 64).map(|k| k as f32).collect();
    write_geotiff::<Gray32Float>(&path, 64, 64, &values, &GeoTags::wgs84(10.0, 20.0, 0.01));
    open(dir.path());
    let bytes = std::fs::read(&path).unwrap();
    for keep in [bytes.len() / 2, bytes.len() - 100, 10] {
        std::fs::write(&path, &bytes[..keep]).unwrap();
        let e = Terrain::open(dir.path()).unwrap_err();
        assert!(matches!(e, TerrainError::GeoTiff { .. }), "{keep}: {e}");
        one_line_naming(&e, "cut.tif");
    }
}

/// The message of `e` is one line and names `what`.
fn one_line_naming(e: &TerrainError, what: &str) {
    let m = e.to_string();
    assert!(!m.contains('\n'), "{m}");
    assert!(m.contains(what), "{m} does not name {what}");
}

/// SRTM tiles that are cut short, of another size, misnamed, or zips that are damaged or hold
/// no single tile: each refused when the directory is opened, in one line naming the file.
#[test]
fn bad_srtm_tiles_are_refused_naming_the_file() {
    type Case = (&'static str, Box<dyn Fn(&Path)>, &'static str);
    let cases: [Case; 6] = [
        (
            "truncated",
            Box::new(|d: &Path| {
                let p = write_hgt(d, "N00E000.hgt", |_, _| 1);
                let b = std::fs::read(&p).unwrap();
                std::fs::write(&p, &b[..b.len() - 2]).unwrap();
            }),
            "N00E000.hgt: 2884800 bytes",
        ),
        (
            "wrong size",
            Box::new(|d: &Path| std::fs::write(d.join("N00E000.hgt"), [0u8; 1000]).unwrap()),
            "1000 bytes, not an SRTM tile: expected 2884802 bytes (1201 x 1201",
        ),
        (
            "bad name",
            Box::new(|d: &Path| std::fs::write(d.join("dem.hgt"), [0u8; 1000]).unwrap()),
            "dem.hgt: the name is not a south-west corner",
        ),
        (
            "corrupt zip",
            Box::new(|d: &Path| {
                std::fs::write(d.join("N00E000.hgt.zip"), b"PK\x03\x04 no").unwrap()
            }),
            "N00E000.hgt.zip: not a readable zip archive",
        ),
        (
            "zip of no tile",
            Box::new(|d: &Path| write_zip(&d.join("N00E000.hgt.zip"), "readme.txt", b"hello")),
            "N00E000.hgt.zip: the archive holds 0 .hgt file(s)",
        ),
        (
            "zip of a misnamed tile",
            Box::new(|d: &Path| write_zip(&d.join("N00E000.hgt.zip"), "tile.hgt", &[0u8; 10])),
            "N00E000.hgt.zip/tile.hgt: the name is not",
        ),
    ];
    for (what, make, says) in cases {
        let dir = tempfile::tempdir().unwrap();
        make(dir.path());
        let e = Terrain::open(dir.path()).unwrap_err();
        let m = e.to_string();
        assert!(!m.contains('\n'), "{what}: {m}");
        assert!(m.contains(says), "{what}: {m}");
    }
}

/// A zip whose deflated data is damaged is found when the tile is read, and said naming it.
#[test]
fn a_zip_damaged_inside_is_said_when_its_tile_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let bytes: Vec<u8> = (0..2 * 1201 * 1201u64)
        .map(|k| (k * 7919 % 251) as u8)
        .collect();
    let path = dir.path().join("N00E000.hgt.zip");
    write_zip(&path, "N00E000.hgt", &bytes);
    let mut z = std::fs::read(&path).unwrap();
    // The deflated data starts after the 30-byte local header and the 11-byte name.
    for b in &mut z[41..200] {
        *b ^= 0x5a;
    }
    std::fs::write(&path, &z).unwrap();
    let t = open(dir.path());
    let e = t.height_m(0.5, 0.5).unwrap_err();
    assert!(matches!(e, TerrainError::Zip { .. }), "{e}");
    one_line_naming(&e, "N00E000.hgt.zip");
}

#[test]
fn a_directory_without_tiles_or_missing_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("README.txt"), "not a tile").unwrap();
    std::fs::create_dir(dir.path().join("N00E000.hgt")).unwrap(); // a folder, passed over
    let e = Terrain::open(dir.path()).unwrap_err();
    assert!(matches!(e, TerrainError::NoTiles { .. }), "{e}");
    one_line_naming(&e, &dir.path().display().to_string());
    let missing = dir.path().join("no-such-dir");
    let e = Terrain::open(&missing).unwrap_err();
    assert!(matches!(e, TerrainError::Io { .. }), "{e}");
    one_line_naming(&e, "no-such-dir");
}

/// Two tiles side by side holding the plane h = 2400 lat + 1200 lon (deg): bilinear
/// interpolation reproduces a plane exactly, so every answer has a closed form.
fn plane_tiles(dir: &Path) {
    write_hgt(dir, "N00E000.hgt", |r, c| (2 * (1200 - r) + c) as i16);
    write_hgt(dir, "n00e001.hgt", |r, c| {
        (2 * (1200 - r) + c + 1200) as i16
    });
}

fn plane(lat: f64, lon: f64) -> f64 {
    2400.0 * lat + 1200.0 * lon
}

#[test]
fn heights_profiles_and_clearances_over_two_tiles_follow_the_plane() {
    let dir = tempfile::tempdir().unwrap();
    plane_tiles(dir.path());
    let t = open(dir.path());
    for (lat, lon) in [
        (0.5, 0.5),
        (0.123, 1.987),
        (1.0, 1.0),
        (0.0, 2.0),
        (0.77, 1.0),
    ] {
        assert_close(
            t.height_m(lat, lon).unwrap(),
            plane(lat, lon),
            1e-9,
            "plane",
        );
    }
    // A path from one tile to the other; the ground rises along it, so the least clearance of
    // a level path is at its end.
    let (from, to) = ((0.5, 0.5), (0.6, 1.5));
    let p = t.profile(from, to).unwrap();
    let length_m = aloft_terrain::distance::haversine_m(from, to);
    let spacing = t.spacing_m(0.6, 1.5).unwrap();
    assert_eq!(p.len(), (length_m / spacing).ceil() as usize + 1);
    assert_close(p[0].distance_m, 0.0, 0.0, "start");
    assert_close(p.last().unwrap().distance_m, length_m, 1e-6, "end");
    assert_close(p.last().unwrap().latitude_deg, 0.6, 1e-12, "end lat");
    for w in p.windows(2) {
        assert!(w[1].distance_m - w[0].distance_m <= spacing + 1e-9);
    }
    for s in &p {
        let want = plane(s.latitude_deg, s.longitude_deg);
        assert_close(s.height_m, want, 1e-6, "profile on the plane");
    }
    let at = |lat, lon, alt| PathPoint {
        latitude_deg: lat,
        longitude_deg: lon,
        altitude_amsl_m: alt,
    };
    let c = t
        .least_clearance(at(0.5, 0.5, 5000.0), at(0.6, 1.5, 5000.0))
        .unwrap();
    assert_close(c.clearance_m, 5000.0 - plane(0.6, 1.5), 1e-6, "level path");
    assert_close(c.distance_m, length_m, 1e-6, "at the end");
    assert_close(c.ground_m, plane(0.6, 1.5), 1e-6, "ground there");
    // Climbing faster than the ground: the least clearance is at the start.
    let c = t
        .least_clearance(at(0.5, 0.5, 2000.0), at(0.6, 1.5, 9000.0))
        .unwrap();
    assert_close(c.clearance_m, 2000.0 - plane(0.5, 0.5), 1e-6, "climbing");
    assert_close(c.distance_m, 0.0, 1e-6, "at the start");
    // Along the edge between the tiles and ending on the north edge of both.
    let c = t
        .least_clearance(at(0.2, 1.0, 3000.0), at(1.0, 1.0, 3000.0))
        .unwrap();
    assert_close(c.clearance_m, 3000.0 - plane(1.0, 1.0), 1e-6, "edge");
}

/// A path that leaves the tiles names the first place past their edge; a point off every tile
/// is no tile, never sea level.
#[test]
fn places_off_the_tiles_are_named() {
    let dir = tempfile::tempdir().unwrap();
    plane_tiles(dir.path());
    let t = open(dir.path());
    let e = t.height_m(0.5, 2.5).unwrap_err();
    assert!(matches!(e, TerrainError::NoTile { .. }), "{e}");
    assert!(e.to_string().contains("2.5"), "{e}");
    let e = t.profile((0.5, 1.5), (0.5, 2.5)).unwrap_err();
    match e {
        TerrainError::NoTile {
            latitude_deg,
            longitude_deg,
        } => {
            assert_close(latitude_deg, 0.5, 1e-12, "lat");
            // A metre past the edge at 2 E.
            assert!(
                longitude_deg > 2.0 && longitude_deg < 2.0 + 2e-5,
                "{longitude_deg}"
            );
        }
        other => panic!("{other}"),
    }
    let e = t.height_m(91.0, 0.0).unwrap_err();
    assert!(matches!(e, TerrainError::NotAPlace { .. }), "{e}");
    assert!(t.height_m(f64::NAN, 0.0).is_err());
}

/// A void in an SRTM tile (-32768) makes the points around it voids, named with the tile, and
/// a path over it too.
#[test]
fn an_srtm_void_is_said_with_its_place_and_tile() {
    let dir = tempfile::tempdir().unwrap();
    write_hgt(dir.path(), "N00E000.hgt", |r, c| match (r, c) {
        (600, 600) => -32768,
        _ => 50,
    });
    let t = open(dir.path());
    let e = t.height_m(0.5, 0.5).unwrap_err();
    assert!(matches!(e, TerrainError::Void { .. }), "{e}");
    one_line_naming(&e, "N00E000.hgt");
    assert!(t.height_m(0.5 + 0.4 / 1200.0, 0.5).is_err());
    assert_close(
        t.height_m(0.5 + 1.0 / 1200.0, 0.5).unwrap(),
        50.0,
        0.0,
        "next row",
    );
    let at = |lat, lon| PathPoint {
        latitude_deg: lat,
        longitude_deg: lon,
        altitude_amsl_m: 100.0,
    };
    let e = t.least_clearance(at(0.4, 0.4), at(0.6, 0.6)).unwrap_err();
    match &e {
        TerrainError::Void {
            latitude_deg,
            longitude_deg,
            ..
        } => {
            assert!((latitude_deg - 0.5).abs() < 2.0 / 1200.0, "{e}");
            assert!((longitude_deg - 0.5).abs() < 2.0 / 1200.0, "{e}");
        }
        other => panic!("{other}"),
    }
    // A path beside the void is answered.
    let c = t.least_clearance(at(0.4, 0.4), at(0.4, 0.6)).unwrap();
    assert_close(c.clearance_m, 50.0, 1e-9, "beside the void");
}

/// A Terrain is shared between threads: each gets the same heights.
#[test]
fn terrain_is_shared_between_threads() {
    let dir = tempfile::tempdir().unwrap();
    plane_tiles(dir.path());
    let t = open(dir.path());
    let handles: Vec<_> = (0..4)
        .map(|k| {
            let t = t.clone();
            std::thread::spawn(move || {
                let lon = 0.1 + 0.45 * f64::from(k);
                t.height_m(0.3, lon).unwrap() - plane(0.3, lon)
            })
        })
        .collect();
    for h in handles {
        assert_close(h.join().unwrap(), 0.0, 1e-9, "thread");
    }
}
