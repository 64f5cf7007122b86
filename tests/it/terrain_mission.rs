//! Issue 45: every answer knows the ground. Missions built here over the shared SRTM3 tile
//! (`terrain/N44W072.hgt`, the White Mountains) and over tiles written here (a constant slope):
//! - a leg that passes a ridge 3 m above it is infeasible (exit 1) naming the segment, the place
//!   and the clearance; the expected ridge is found by this test's own reading of the tile's
//!   bytes (bilinear, sampled every metre along the leg), not by aloft;
//! - a terrain-frame (MAVLink frame 10) leg up a constant slope follows the ground: its climb is
//!   the slope's rise, and its extra energy over the same leg on flat ground is the climb power
//!   of the model integrated over the profile (for a constant slope, the climb rate is constant:
//!   the power of `aloft power` at that climb rate times the leg's time);
//! - bad input: a mission in metres from home with terrain (exit 2, one line), a mission over no
//!   tile (exit 2 naming the place).

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common;

use common::{aloft, stderr, stdout};
use serde_json::Value;

/// The shared tile's directory.
fn tiles() -> PathBuf {
    common::data_dir().join("terrain")
}

/// The shared tile's height at `(lat, lon)`, bilinear between its four samples (this test's
/// own reading: 1201 x 1201 big-endian i16, north row first, 3 arc-seconds apart).
pub(crate) fn tile_height_m(bytes: &[u8], lat: f64, lon: f64) -> f64 {
    let n = 1201usize;
    let raw = |r: usize, c: usize| {
        let k = 2 * (r * n + c);
        f64::from(i16::from_be_bytes([bytes[k], bytes[k + 1]]))
    };
    let y = (45.0 - lat) * 1200.0;
    let x = (lon + 72.0) * 1200.0;
    let (r, c) = (
        (y.floor() as usize).min(1199),
        (x.floor() as usize).min(1199),
    );
    let (fy, fx) = (y - r as f64, x - c as f64);
    raw(r, c) * (1.0 - fx) * (1.0 - fy)
        + raw(r, c + 1) * fx * (1.0 - fy)
        + raw(r + 1, c) * (1.0 - fx) * fy
        + raw(r + 1, c + 1) * fx * fy
}

/// A mission file placed by latitude and longitude: take off at home to `up_m`, one leg east at
/// `up_m` to `to_lon`, land.
fn east_leg_toml(home: (f64, f64), to_lon: f64, up_m: f64) -> String {
    format!(
        "name = \"ridge\"\n\
         [home]\nlatitude_deg = {}\nlongitude_deg = {}\n\n\
         [[segment]]\nkind = \"take-off\"\naltitude_m = {up_m}\nclimb_rate_mps = 3.0\n\n\
         [[segment]]\nkind = \"leg\"\nlatitude_deg = {}\nlongitude_deg = {to_lon}\n\
         altitude_m = {up_m}\nground_speed_mps = 8.0\n\n\
         [[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n",
        home.0, home.1, home.0
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// `aloft mission MISSION --terrain TERRAIN EXTRA...`.
fn over_terrain(mission: &Path, terrain: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        OsStr::new("mission"),
        mission.as_os_str(),
        OsStr::new("--terrain"),
        terrain.as_os_str(),
    ];
    args.extend(extra.iter().map(OsStr::new));
    aloft(&args)
}

#[test]
fn data_val_a_leg_3_m_over_a_ridge_is_infeasible_naming_the_place() {
    let bytes = std::fs::read(tiles().join("N44W072.hgt")).unwrap();
    // West to east along 44.25 N: a ridge about 60 m above both ends.
    let home = (44.25, -71.93);
    let to_lon = -71.905;
    let home_ground = tile_height_m(&bytes, home.0, home.1);
    let (ridge_lon, ridge_m) = (0..=2000)
        .map(|k| home.1 + (to_lon - home.1) * f64::from(k) / 2000.0)
        .map(|lon| (lon, tile_height_m(&bytes, home.0, lon)))
        .fold((0.0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a });
    assert!(ridge_m - home_ground > 40.0, "{ridge_m} over {home_ground}");
    let up_m = ridge_m + 3.0 - home_ground;
    let tmp = tempfile::tempdir().unwrap();
    let mission = write(tmp.path(), "ridge.toml", &east_leg_toml(home, to_lon, up_m));
    let terrain = tiles();
    let out = over_terrain(&mission, &terrain, &["--format", "json"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["feasible"], false);
    let reason = v["reason"].as_str().unwrap();
    assert!(reason.starts_with("segment 2 (leg) passes"), "{reason}");
    let leg = &v["segments"][1];
    let c = leg["min_clearance_m"].as_f64().unwrap();
    // Sampled at the tile's spacing, a peak between samples can be missed by a little.
    assert!((2.0..=4.5).contains(&c), "{c}");
    let at_lon = leg["min_clearance_at"]["longitude_deg"].as_f64().unwrap();
    let metres_per_deg = 111_320.0 * home.0.to_radians().cos();
    assert!(
        (at_lon - ridge_lon).abs() * metres_per_deg < 100.0,
        "{at_lon} vs the ridge at {ridge_lon}"
    );
    assert!((v["min_clearance_m"].as_f64().unwrap() - c).abs() < 1e-9);
    // The take-off starts on the ground: reported, not judged.
    assert!(v["segments"][0]["min_clearance_m"].as_f64().unwrap() < 1.0);
    // The table says it too.
    let table = over_terrain(&mission, &terrain, &[]);
    assert_eq!(table.status.code(), Some(1));
    assert!(
        stdout(&table).contains("least clearance: "),
        "{}",
        stdout(&table)
    );
    // The verdict says why (it said FEASIBLE when only the pack was judged).
    assert!(
        stdout(&table).contains("NOT FEASIBLE: segment 2 (leg) passes "),
        "{}",
        stdout(&table)
    );

    // 10 m higher it passes the default 10 m, and a lower limit lets the 3 m pass.
    let higher = write(
        tmp.path(),
        "higher.toml",
        &east_leg_toml(home, to_lon, up_m + 10.0),
    );
    let out = over_terrain(&higher, &terrain, &[]);
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
    let out = over_terrain(&mission, &terrain, &["--min-clearance-m", "2"]);
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
}

/// A 3 arc-second tile named `name` whose ground rises northwards by `rise_m_per_row` metres a
/// row from `base_m` at its south edge (a constant slope north-south, level east-west).
fn sloped_tile(dir: &Path, name: &str, base_m: f64, rise_m_per_row: f64) {
    let n = 1201usize;
    let mut bytes = Vec::with_capacity(2 * n * n);
    for r in 0..n {
        let h = base_m + rise_m_per_row * (n - 1 - r) as f64;
        let v = h.round() as i16;
        for _ in 0..n {
            bytes.extend_from_slice(&v.to_be_bytes());
        }
    }
    std::fs::write(dir.join(name), bytes).unwrap();
}

/// A `.waypoints` mission at N10 E010 (home on the ground at `home_amsl_m`): take off to 30 m,
/// fly north `rows` rows of the tile at 8 m/s, 30 m above `frame` (3 relative, 10 terrain), land.
fn north_waypoints(frame: u32, rows: f64, home_amsl_m: f64) -> String {
    let lat0 = 10.1;
    let lat1 = lat0 + rows / 1200.0;
    format!(
        "QGC WPL 110\n\
         0\t1\t0\t16\t0\t0\t0\t0\t{lat0}\t10.5\t{home_amsl_m}\t1\n\
         1\t0\t3\t22\t0\t0\t0\t0\t0\t0\t30\t1\n\
         2\t0\t3\t178\t1\t8\t-1\t0\t0\t0\t0\t1\n\
         3\t0\t{frame}\t16\t0\t0\t0\t0\t{lat1}\t10.5\t30\t1\n\
         4\t0\t3\t21\t0\t0\t0\t0\t{lat1}\t10.5\t0\t1\n"
    )
}

/// The same flight as an aloft mission: one straight leg climbing `rise_m` on the way, at a
/// constant climb rate (what the model's climb power is, integrated over a constant slope).
fn north_slanted_toml(rows: f64, rise_m: f64) -> String {
    let lat0 = 10.1;
    let lat1 = lat0 + rows / 1200.0;
    format!(
        "name = \"slanted\"\n\
         [home]\nlatitude_deg = {lat0}\nlongitude_deg = 10.5\n\n\
         [[segment]]\nkind = \"take-off\"\naltitude_m = 30.0\nclimb_rate_mps = 2.5\n\n\
         [[segment]]\nkind = \"leg\"\nlatitude_deg = {lat1}\nlongitude_deg = 10.5\n\
         altitude_m = {}\nground_speed_mps = 8.0\n\n\
         [[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n",
        30.0 + rise_m
    )
}

#[test]
fn a_terrain_frame_leg_up_a_slope_climbs_with_the_ground_and_pays_the_climb_power() {
    let tmp = tempfile::tempdir().unwrap();
    let tiles = tmp.path().join("tiles");
    std::fs::create_dir(&tiles).unwrap();
    // 5 m a row (92.6 m north-south): a 5.4 % slope; 60 rows north is 300 m up.
    sloped_tile(&tiles, "N10E010.hgt", 100.0, 5.0);
    let (rows, rise_m) = (60.0, 300.0);
    // Home is row 1080 from the north: 100 + 5 x 120 = 700 m.
    let terrain = write(
        tmp.path(),
        "terrain.waypoints",
        &north_waypoints(10, rows, 700.0),
    );
    let relative = write(
        tmp.path(),
        "relative.waypoints",
        &north_waypoints(3, rows, 700.0),
    );
    let slanted = write(
        tmp.path(),
        "slanted.toml",
        &north_slanted_toml(rows, rise_m),
    );
    let json = |mission: &Path| -> Value {
        let out = over_terrain(mission, &tiles, &["--format", "json"]);
        assert!(matches!(out.status.code(), Some(0 | 1)), "{}", stderr(&out));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let over = json(&terrain);
    let flat = json(&relative);
    let straight = json(&slanted);
    assert_eq!(over["feasible"], true, "{}", over["reason"]);
    // Frame 10 keeps 30 m over the ground: the route climbs the slope's rise on the way.
    let climb =
        over["route"]["climb_m"].as_f64().unwrap() - flat["route"]["climb_m"].as_f64().unwrap();
    assert!((climb - rise_m).abs() < 1.0, "{climb} vs {rise_m}");
    // And never comes closer than 30 m, less the tile's whole-metre rounding.
    let least = over["min_clearance_m"].as_f64().unwrap();
    assert!((least - 30.0).abs() < 1.5, "{least}");
    // The relative leg keeps 30 m above home: the ground rises into it (exit 1, said).
    assert_eq!(flat["feasible"], false);
    assert!(flat["min_clearance_m"].as_f64().unwrap() < 0.0);
    // The leg over the ground costs what one straight leg climbing the same rise at a constant
    // rate costs (the climb power of the model over a constant slope), within 1 %.
    let leg_wh = |v: &Value, item: Option<u64>| -> f64 {
        v["segments"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|s| s["kind"] == "leg" && s["item"].as_u64() == item)
            .map(|s| s["energy_wh"].as_f64().unwrap())
            .sum()
    };
    let followed_wh = leg_wh(&over, Some(3));
    let straight_wh = leg_wh(&straight, None);
    let flat_wh = leg_wh(&flat, Some(3));
    assert!(
        (followed_wh - straight_wh).abs() < 0.01 * straight_wh,
        "followed {followed_wh} Wh vs one straight climbing leg {straight_wh} Wh"
    );
    // And the climb is not free: more than the same leg level.
    assert!(
        followed_wh > flat_wh + 1.0,
        "{followed_wh} vs level {flat_wh}"
    );
    // The warning that frame 10 is flown as relative to home is gone.
    let warnings = over["route"]["warnings"].to_string();
    assert!(
        !warnings.contains("aloft has no terrain model"),
        "{warnings}"
    );
}

#[test]
fn terrain_for_a_mission_in_metres_is_one_line_and_a_mission_off_the_tiles_names_the_place() {
    let terrain = tiles();
    // The built-in demo is placed in metres from home.
    let out = aloft(&[
        "mission".as_ref(),
        "--terrain".as_ref(),
        terrain.as_os_str(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("latitude and longitude"), "{err}");
    // A mission at 10 N, 10 E over a directory holding only N44W072.
    let tmp = tempfile::tempdir().unwrap();
    let far = write(
        tmp.path(),
        "far.toml",
        &east_leg_toml((10.0, 10.0), 10.01, 30.0),
    );
    let out = over_terrain(&far, &terrain, &[]);
    assert_eq!(out.status.code(), Some(2), "{}", stdout(&out));
    let err = stderr(&out);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("10"), "{err}");
}

/// A QGroundControl `.plan` for PX4 in the relative frame: take off to 50 m at (44.25, -71.93),
/// east 2 km over the ridge of `ridge-44n`, north 1.1 km down a valley, return.
fn relative_plan() -> String {
    let item = |seq: u32, command: u32, lat: f64, lon: f64, alt: f64| {
        format!(
            "{{\"type\": \"SimpleItem\", \"autoContinue\": true, \"command\": {command}, \
             \"doJumpId\": {seq}, \"frame\": 3, \"params\": [0, 0, 0, null, {lat}, {lon}, {alt}]}}"
        )
    };
    let items = [
        item(1, 22, 44.25, -71.93, 50.0),
        item(2, 16, 44.25, -71.905, 50.0),
        item(3, 16, 44.26, -71.905, 50.0),
        item(4, 20, 0.0, 0.0, 0.0),
    ];
    format!(
        "{{\"fileType\": \"Plan\", \"version\": 1, \"groundStation\": \"QGroundControl\", \
         \"geoFence\": {{\"version\": 2, \"circles\": [], \"polygons\": []}}, \
         \"rallyPoints\": {{\"version\": 2, \"points\": []}}, \
         \"mission\": {{\"version\": 2, \"firmwareType\": 12, \"vehicleType\": 2, \
         \"cruiseSpeed\": 15, \"hoverSpeed\": 8, \"plannedHomePosition\": [44.25, -71.93, 357], \
         \"items\": [{}]}}}}",
        items.join(", ")
    )
}

#[test]
fn data_val_plan_follow_terrain_writes_a_mission_that_keeps_its_height_and_mavsdk_reads_it() {
    let bytes = std::fs::read(tiles().join("N44W072.hgt")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let source = write(tmp.path(), "over.plan", &relative_plan());
    let terrain = tiles();
    let plan = |extra: &[&str], out: &str| {
        let mut args: Vec<std::ffi::OsString> = vec![
            "plan".into(),
            source.clone().into(),
            "--terrain".into(),
            terrain.clone().into(),
            "--follow-terrain".into(),
            "50".into(),
            "--output".into(),
            tmp.path().join(out).into(),
            // The forecast's cut: the 17-minute route uses 77 % of the pack, which a 95 %
            // confidence in the day's scenarios would split; the terrain is what is tested.
            "--confidence".into(),
            "0.5".into(),
        ];
        args.extend(extra.iter().map(Into::into));
        aloft(&args)
    };
    // The return flies home at the last waypoint's height, 63 m below home, into the hill: no
    // plan, naming the return.
    let out = plan(&[], "low");
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stdout(&out).contains("return) passes"), "{}", stdout(&out));
    // Returning at 120 m above home it holds.
    let out = plan(&["--rtl-altitude-m", "120"], "px4");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        stdout(&out),
        stderr(&out)
    );
    let written = tmp.path().join("px4/over-1-of-1.plan");
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&written).unwrap()).unwrap();
    let items = v["mission"]["items"].as_array().unwrap();
    let waypoints: Vec<&Value> = items.iter().filter(|i| i["command"] == 16).collect();
    // The ground changes along both legs: waypoints added where it does (more than the 2).
    assert!(waypoints.len() > 8, "{}", waypoints.len());
    for w in &waypoints {
        assert_eq!(w["frame"], 0, "{w}");
        let p = w["params"].as_array().unwrap();
        let (lat, lon, alt) = (
            p[4].as_f64().unwrap(),
            p[5].as_f64().unwrap(),
            p[6].as_f64().unwrap(),
        );
        // 50 m above this test's own reading of the tile.
        let want = tile_height_m(&bytes, lat, lon) + 50.0;
        assert!((alt - want).abs() < 1e-6, "{lat}, {lon}: {alt} vs {want}");
    }
    // Flown as written: never closer than 50 m less the 10 m thinning tolerance (and the
    // bilinear ground's bends between two kept samples).
    let out = over_terrain(
        &written,
        &terrain,
        &["--rtl-altitude-m", "120", "--format", "json"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let m: Value = serde_json::from_slice(&out.stdout).unwrap();
    let least = m["min_clearance_m"].as_f64().unwrap();
    assert!((30.0..=50.5).contains(&least), "{least}");
    // For ArduPilot: the terrain frame, 50 m, no waypoint added.
    let out = plan(
        &["--rtl-altitude-m", "120", "--autopilot", "ardupilot"],
        "ap",
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v: Value = serde_json::from_str(
        &std::fs::read_to_string(tmp.path().join("ap/over-1-of-1.plan")).unwrap(),
    )
    .unwrap();
    let wps: Vec<&Value> = v["mission"]["items"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|i| i["command"] == 16)
        .collect();
    assert_eq!(wps.len(), 2);
    assert!(wps
        .iter()
        .all(|w| w["frame"] == 10 && w["params"][6] == 50.0));
    // MAVSDK's QGroundControl importer reads the PX4 file: the same items, frames and altitudes.
    if !crate::missions_writers::python_ready("mavsdk, pymavlink") {
        return;
    }
    let read = crate::missions_writers::readers(&[
        "mavsdk".into(),
        "--autopilot".into(),
        "px4".into(),
        written.display().to_string(),
    ]);
    let got = read["files"][written.display().to_string()]
        .as_array()
        .unwrap()
        .clone();
    assert_eq!(got.len(), items.len(), "{read}");
    for (g, w) in got.iter().zip(items) {
        assert_eq!(g["command"], w["command"]);
        assert_eq!(g["frame"], w["frame"]);
        let want_z = w["params"][6].as_f64().unwrap_or(0.0);
        assert!(
            (g["z"].as_f64().unwrap() - want_z).abs() < 1e-3,
            "{g} vs {w}"
        );
    }
}

#[test]
fn data_val_a_pack_that_runs_out_before_the_ridge_still_has_the_ridge_judged() {
    // Two legs along 44.25 N: the first ends before the ridge of `ridge-44n`, the second passes
    // it 2.6 m up. From 3 % the pack runs out on the first leg, where the answer's segments end;
    // the ridge on the second is still judged (it was not when only the answer's segments were).
    let text = east_leg_toml((44.25, -71.93), -71.905, 63.6).replace(
        "[[segment]]\nkind = \"leg\"",
        "[[segment]]\nkind = \"leg\"\nlatitude_deg = 44.25\nlongitude_deg = -71.925\naltitude_m = 63.6\nground_speed_mps = 8.0\n\n[[segment]]\nkind = \"leg\"",
    );
    let tmp = tempfile::tempdir().unwrap();
    let mission = write(tmp.path(), "two.toml", &text);
    let terrain = tiles();
    let out = over_terrain(
        &mission,
        &terrain,
        &["--start-percent", "3", "--format", "json"],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        v["segments"].as_array().unwrap().len() <= 2,
        "{}",
        v["segments"]
    );
    let reason = v["reason"].as_str().unwrap();
    assert!(
        reason.starts_with("segment 3 (leg) passes 2.6 m"),
        "{reason}"
    );
    assert!((v["min_clearance_m"].as_f64().unwrap() - 2.6).abs() < 0.05);
}
