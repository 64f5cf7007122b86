//! Benches of the terrain reader over the shared SRTM3 tile (`ALOFT_DATA_DIR`/terrain,
//! N44W072.hgt: the White Mountains).
//!
//! Target (issue 45): the least clearance of every leg of a 38 km survey, with a
//! terrain-following plan beside it, in at most 100 ms in release. The clearance's share:
//! `terrain/least_clearance/survey_38km`, 10 lines of 3.6 km 200 m apart over Mount Washington
//! and the 200 m legs between them (38.0 km in all), with the tile already held; and
//! `terrain/open_and_first_height/srtm3`, the directory opened and the tile read (2.9 MB)
//! for the first height, which a command pays once.
//!
//! Measured on the 2-core machine: 28.7 us for the survey's clearances, 19.3 us for its profiles,
//! 1.41 ms to open the directory and read the tile: the clearances are well under a thousandth of
//! the budget.

use std::hint::black_box;
use std::path::PathBuf;

use aloft_terrain::{PathPoint, Terrain};
use criterion::{criterion_group, criterion_main, Criterion};

#[path = "../../../tests/it/common/data.rs"]
mod data;

/// The survey's waypoints: 10 east-west lines of 3.6 km, 200 m apart, at 2,000 m AMSL, the
/// altitude changing by 10 m from line to line so that no two legs are alike.
fn survey() -> Vec<PathPoint> {
    let (lat0, lon0): (f64, f64) = (44.24, -71.33);
    let m_per_deg_lat = 111_195.0;
    let m_per_deg_lon = m_per_deg_lat * lat0.to_radians().cos();
    let mut points = Vec::new();
    for line in 0..10 {
        let lat = lat0 + f64::from(line) * 200.0 / m_per_deg_lat;
        let (a, b) = (lon0, lon0 + 3_600.0 / m_per_deg_lon);
        let (w, e) = if line % 2 == 0 { (a, b) } else { (b, a) };
        let alt = 2_000.0 + 10.0 * f64::from(line);
        for lon in [w, e] {
            points.push(PathPoint {
                latitude_deg: lat,
                longitude_deg: lon,
                altitude_amsl_m: alt,
            });
        }
    }
    points
}

fn terrain_dir() -> PathBuf {
    data::data_dir().join("terrain")
}

fn least_clearance(c: &mut Criterion) {
    let terrain = Terrain::open(&terrain_dir()).expect("the shared tile");
    let legs = survey();
    let total_m: f64 = legs
        .windows(2)
        .map(|w| {
            aloft_terrain::distance::haversine_m(
                (w[0].latitude_deg, w[0].longitude_deg),
                (w[1].latitude_deg, w[1].longitude_deg),
            )
        })
        .sum();
    assert!((total_m - 37_800.0).abs() < 300.0, "{total_m} m of legs");
    c.bench_function("terrain/least_clearance/survey_38km", |b| {
        b.iter(|| {
            let mut least = f64::INFINITY;
            for w in black_box(&legs).windows(2) {
                let c = terrain.least_clearance(w[0], w[1]).unwrap();
                least = least.min(c.clearance_m);
            }
            least
        })
    });
    c.bench_function("terrain/profile/survey_38km", |b| {
        b.iter(|| {
            let mut n = 0;
            for w in black_box(&legs).windows(2) {
                let from = (w[0].latitude_deg, w[0].longitude_deg);
                let to = (w[1].latitude_deg, w[1].longitude_deg);
                n += terrain.profile(from, to).unwrap().len();
            }
            n
        })
    });
}

fn open_and_first_height(c: &mut Criterion) {
    let dir = terrain_dir();
    c.bench_function("terrain/open_and_first_height/srtm3", |b| {
        b.iter(|| {
            let t = Terrain::open(black_box(&dir)).unwrap();
            t.height_m(44.2706, -71.3033).unwrap()
        })
    });
}

criterion_group!(benches, least_clearance, open_and_first_height);
criterion_main!(benches);
