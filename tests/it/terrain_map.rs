//! Issue 45, item 5: the page's profile of the route over the ground, `profile` in the map answer
//! of `aloft serve --terrain DIR` (`POST /api/map`), over the shared SRTM3 tile
//! (`terrain/N44W072.hgt`):
//! - the ridge leg of `fixtures/missions/ridge-44n.toml`: the ground at every point is the tile's
//!   there (`aloft::terrain::Terrain::height_m`, and this test's own bilinear reading of the
//!   tile's bytes), the altitude is home's ground plus the leg's 63.6 m, the distance runs to the
//!   leg's length on a sphere; the least is the mission answer's `min_clearance_m`, in segment 2,
//!   where this test's own search (every metre along the leg) finds the closest pass, and no point
//!   in the air comes closer;
//! - a 310 km survey: thinned to at most `PROFILE_POINTS`, to the route's end, its least kept;
//! - without terrain: no `profile` key.
#![cfg(feature = "serve")]

use std::path::PathBuf;

use serde_json::Value;

use crate::common;
use crate::terrain_mission::tile_height_m;
use common::serve::Server;

/// The ridge mission's home and leg (`fixtures/missions/ridge-44n.toml`).
const HOME: (f64, f64) = (44.25, -71.93);
const TO_LON: f64 = -71.905;
const UP_M: f64 = 63.6;

/// The mean Earth radius, m: this test's leg lengths are on a sphere, the engine's east-north
/// frame on the ellipsoid (they differ by less than 0.5 % at 44° N).
const EARTH_RADIUS_M: f64 = 6_371_000.0;

fn tiles() -> PathBuf {
    common::data_dir().join("terrain")
}

fn tile_bytes() -> Vec<u8> {
    std::fs::read(tiles().join("N44W072.hgt")).unwrap()
}

/// `POST route` with `body`: 200 and its JSON.
fn post(server: &Server, route: &str, body: &[u8]) -> Value {
    let (code, text) = server.request("POST", route, None, body);
    assert_eq!(code, 200, "{route}: {text}");
    serde_json::from_str(&text).unwrap()
}

/// A series of the profile.
fn series(profile: &Value, key: &str) -> Vec<f64> {
    profile[key]
        .as_array()
        .unwrap_or_else(|| panic!("no {key} in {profile}"))
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

/// The profile's three series, checked to be of one length with distances never decreasing.
fn profile_series(map: &Value) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let p = &map["profile"];
    let (d, a, g) = (
        series(p, "distance_m"),
        series(p, "altitude_m"),
        series(p, "ground_m"),
    );
    assert!(d.len() >= 2 && a.len() == d.len() && g.len() == d.len());
    assert!(d.windows(2).all(|w| w[0] <= w[1]), "distances go back");
    assert!(d[0].abs() < 1e-9, "starts at {}", d[0]);
    (d, a, g)
}

/// The profile holds the least's own place: the chart's lines pass through it.
fn holds_the_least(d: &[f64], a: &[f64], g: &[f64], least_d_m: f64, least_m: f64) -> bool {
    (0..d.len()).any(|k| (d[k] - least_d_m).abs() < 1e-3 && (a[k] - g[k] - least_m).abs() < 1e-3)
}

#[test]
fn data_val_the_ridge_profile_is_the_tile_s_ground_under_the_leg_with_the_answer_s_least() {
    let terrain = tiles();
    let server = Server::start(&["--terrain", terrain.to_str().unwrap()]);
    let text = std::fs::read(common::fixture("missions", "ridge-44n.toml")).unwrap();
    let map = post(&server, "/api/map?file=ridge-44n.toml", &text);
    let answer = post(&server, "/api/mission?file=ridge-44n.toml", &text);
    let (d, a, g) = profile_series(&map);
    let n = d.len();
    // The leg is 2 km: sampled at the tile's spacing (66 m east-west at 44.25° N), 31 or more.
    assert!(n >= 31, "{n} points");
    let total_m = d[n - 1];
    let leg_m = (TO_LON - HOME.1).abs().to_radians() * EARTH_RADIUS_M * HOME.0.to_radians().cos();
    assert!(
        (total_m - leg_m).abs() < 0.005 * leg_m,
        "{total_m} m against {leg_m} m"
    );
    // The ground at each point: the leg is along 44.25° N, its longitude linear in the distance.
    let bytes = tile_bytes();
    let tile = aloft::terrain::Terrain::open(&terrain).unwrap();
    let lon_at = |d_m: f64| HOME.1 + (TO_LON - HOME.1) * d_m / total_m;
    for k in 0..n {
        let lon = lon_at(d[k]);
        let h = tile.height_m(HOME.0, lon).unwrap();
        // The path's ends come back from east-north metres to degrees (1e-9 deg, 0.1 mm).
        assert!((g[k] - h).abs() < 1e-3, "point {k}: {} against {h}", g[k]);
        let own = tile_height_m(&bytes, HOME.0, lon);
        assert!(
            (g[k] - own).abs() < 0.01,
            "point {k}: {} against {own}",
            g[k]
        );
    }
    // The altitude: home's ground plus 63.6 m along the leg; the take-off's foot at home and the
    // landing's on the ground at the leg's end.
    let home_ground_m = tile_height_m(&bytes, HOME.0, HOME.1);
    let leg_amsl_m = home_ground_m + UP_M;
    let off_leg: Vec<usize> = (0..n)
        .filter(|&k| (a[k] - leg_amsl_m).abs() > 0.01)
        .collect();
    assert_eq!(off_leg, vec![0, n - 1], "{a:?}");
    assert!((a[0] - home_ground_m).abs() < 0.01 && (a[n - 1] - g[n - 1]).abs() < 0.01);
    // The least: the answer's, in segment 2 (the leg).
    let least = &map["profile"]["least"];
    assert_eq!(least["segment"], 2, "{least}");
    let least_m = least["clearance_m"].as_f64().unwrap();
    let least_d_m = least["distance_m"].as_f64().unwrap();
    let summary_m = answer["min_clearance_m"].as_f64().unwrap();
    assert!(
        (least_m - summary_m).abs() < 1e-9,
        "{least_m} against {summary_m}"
    );
    // No point in the air comes closer (to the centimetre: the least is exact over the cells).
    for k in 1..n - 1 {
        assert!(a[k] - g[k] >= least_m - 0.01, "point {k}: {}", a[k] - g[k]);
    }
    assert!(holds_the_least(&d, &a, &g, least_d_m, least_m));
    // Where this test's own reading finds the closest pass, every metre along the leg (a ridge's
    // top between two metres is at most half a metre away: 0.2 m at a 40 % slope).
    let metres = total_m.floor() as usize;
    let (own_d_m, own_m) = (0..=metres)
        .map(|i| i as f64)
        .map(|x| (x, leg_amsl_m - tile_height_m(&bytes, HOME.0, lon_at(x))))
        .fold((0.0, f64::MAX), |m, p| if p.1 < m.1 { p } else { m });
    assert!((least_m - own_m).abs() < 0.2, "{least_m} against {own_m}");
    assert!(
        (least_d_m - own_d_m).abs() < 5.0,
        "{least_d_m} against {own_d_m}"
    );
}

#[test]
fn without_terrain_the_map_has_no_profile() {
    let server = Server::start(&[]);
    let text = std::fs::read(common::fixture("missions", "ridge-44n.toml")).unwrap();
    let map = post(&server, "/api/map?file=ridge-44n.toml", &text);
    assert!(map.get("segments").is_some() && map.get("profile").is_none());
}

/// A survey of 60 lines 5 km long, 80 m apart, 300 m over home (44.3° N 71.95° W): 310 km.
fn long_survey() -> String {
    let mut t = String::from(
        "name = \"long-survey\"\ndefault_speed_mps = 12.0\n\
         [home]\nlatitude_deg = 44.3\nlongitude_deg = -71.95\n\n\
         [[segment]]\nkind = \"take-off\"\naltitude_m = 300.0\nclimb_rate_mps = 3.0\n",
    );
    for k in 0..60 {
        let east = if k % 2 == 0 { 5000.0 } else { 0.0 };
        for north in [80.0 * k as f64, 80.0 * k as f64 + 80.0] {
            t.push_str(&format!(
                "\n[[segment]]\nkind = \"leg\"\neast_m = {east}\nnorth_m = {north}\naltitude_m = 300.0\n"
            ));
        }
    }
    t.push_str(
        "\n[[segment]]\nkind = \"return\"\n\n[[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n",
    );
    t
}

#[test]
fn data_val_a_long_survey_s_profile_is_thinned_to_the_bound_keeping_its_least() {
    let terrain = tiles();
    let server = Server::start(&["--terrain", terrain.to_str().unwrap()]);
    let text = long_survey();
    let map = post(&server, "/api/map?file=long.toml", text.as_bytes());
    let answer = post(&server, "/api/mission?file=long.toml", text.as_bytes());
    let (d, a, g) = profile_series(&map);
    let n = d.len();
    // 310 km at the tile's 66 m (east-west, at 44.3° N): over 4,000 points, thinned.
    assert!(n <= aloft::engine::PROFILE_POINTS, "{n} points");
    assert!(n >= 1_000, "{n} points");
    // To the route's end: its horizontal length from waypoint to waypoint less what its 120
    // turns cut (well under 0.2 %).
    let route_m = answer["route"]["horizontal_m"].as_f64().unwrap();
    assert!(
        (d[n - 1] - route_m).abs() < 0.002 * route_m,
        "{} against {route_m}",
        d[n - 1]
    );
    let least = &map["profile"]["least"];
    let least_m = least["clearance_m"].as_f64().unwrap();
    assert!((least_m - answer["min_clearance_m"].as_f64().unwrap()).abs() < 1e-9);
    assert!(holds_the_least(
        &d,
        &a,
        &g,
        least["distance_m"].as_f64().unwrap(),
        least_m
    ));
    // (No check that every point clears the least: an M100 runs out of battery 14 km in, and the
    // answer's segments, so its clearances, end there; the profile draws the whole route.)
}
