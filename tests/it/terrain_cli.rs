//! `aloft terrain LAT,LON... --terrain DIR`: heights against the shared tile's raw bytes (read
//! here), the three formats, the terrain directory from `ALOFT_TERRAIN`, and the input contract:
//! exit 2 with one line naming a bad place, directory or tile; exit 1 with one line naming a
//! place that has no height (over no tile, on a void), nothing on stdout.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::data_dir;

fn terrain_dir() -> PathBuf {
    data_dir().join("terrain")
}

/// `aloft args` with `ALOFT_TERRAIN` as given (unset when `None`): exit code, stdout, stderr.
fn run_env(args: &[&str], env: Option<&Path>) -> (i32, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_aloft"));
    c.args(args).env_remove("ALOFT_TERRAIN");
    if let Some(dir) = env {
        c.env("ALOFT_TERRAIN", dir);
    }
    let out = c.output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// The sample (row, col) of N44W072.hgt, read from its bytes at 2 * (row * 1201 + col).
fn raw_sample(row: usize, col: usize) -> f64 {
    let bytes = std::fs::read(terrain_dir().join("N44W072.hgt")).unwrap();
    let k = 2 * (row * 1201 + col);
    f64::from(i16::from_be_bytes([bytes[k], bytes[k + 1]]))
}

/// The heights at grid points are the tile's samples; srtm.py's 341 m at 44 N 72 W; the JSON
/// keys are the documented ones.
#[test]
fn data_val_terrain_json_heights_are_the_tiles_samples() {
    let grid = [(0, 0), (875, 836), (1200, 0), (600, 1200), (37, 911)];
    let points: Vec<String> = grid
        .iter()
        .map(|&(r, c)| format!("{},{}", 45.0 - r as f64 / 1200.0, -72.0 + c as f64 / 1200.0))
        .collect();
    let dir = terrain_dir();
    let mut args = vec![
        "terrain",
        "--terrain",
        dir.to_str().unwrap(),
        "--format",
        "json",
    ];
    args.extend(points.iter().map(String::as_str));
    let (code, out, err) = run_env(&args, None);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let heights = v["heights"].as_array().unwrap();
    assert_eq!(heights.len(), grid.len());
    for (h, &(r, c)) in heights.iter().zip(&grid) {
        let mut keys: Vec<&str> = h.as_object().unwrap().keys().map(String::as_str).collect();
        keys.sort_unstable();
        assert_eq!(keys, ["height_m", "latitude_deg", "longitude_deg"]);
        let got = h["height_m"].as_f64().unwrap();
        assert_eq!(got.to_bits(), raw_sample(r, c).to_bits(), "({r}, {c})");
    }
    assert_eq!(
        heights[2]["height_m"].as_f64().unwrap().to_bits(),
        341f64.to_bits()
    );
}

/// The table and the CSV say the same heights: Mount Washington's bilinear height, 1,907.1 m
/// (by hand: samples 1908, 1898, 1906, 1901 at fractions 0.04 east and 0.28 south).
#[test]
fn data_val_terrain_table_and_csv() {
    let dir = terrain_dir();
    let d = dir.to_str().unwrap();
    let (code, out, err) = run_env(&["terrain", "44.2706,-71.3033", "--terrain", d], None);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("44.270600    -71.303300   1907.1 m"), "{out}");
    let (code, out, _) = run_env(
        &[
            "terrain",
            "44.2706,-71.3033",
            "--terrain",
            d,
            "--format",
            "csv",
        ],
        None,
    );
    assert_eq!(code, 0);
    let mut lines = out.lines();
    assert_eq!(lines.next(), Some("latitude_deg,longitude_deg,height_m"));
    let row: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|f| f.parse().unwrap())
        .collect();
    assert!((row[2] - 1907.096).abs() < 1e-3, "{row:?}");
}

/// `ALOFT_TERRAIN` names the directory when `--terrain` is not given; `--terrain` wins over it.
#[test]
fn data_val_terrain_directory_from_the_environment() {
    let dir = terrain_dir();
    let (code, out, err) = run_env(&["terrain", "44,-72", "--format", "csv"], Some(&dir));
    assert_eq!(code, 0, "{err}");
    assert!(out.ends_with(",341\n"), "{out}");
    let empty = crate::common::scratch("terrain-env", "empty");
    std::fs::create_dir_all(&empty).unwrap();
    let (code, _, err) = run_env(
        &["terrain", "44,-72", "--terrain", dir.to_str().unwrap()],
        Some(&empty),
    );
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = run_env(&["terrain", "44,-72"], Some(&empty));
    assert_eq!(code, 2);
    assert!(err.contains("no elevation tile in it"), "{err}");
}

/// One stderr line, exit 2, naming what is wrong.
fn bad_input(args: &[&str], names: &str) {
    let (code, out, err) = run_env(args, None);
    assert_eq!(code, 2, "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    assert!(err.contains(names), "{args:?}: {err} does not name {names}");
    assert!(out.is_empty(), "{out}");
}

#[test]
fn terrain_bad_input_is_exit_2_naming_it() {
    let dir = terrain_dir();
    let d = dir.to_str().unwrap();
    bad_input(&["terrain", "44.27,x", "--terrain", d], "44.27,x");
    bad_input(
        &["terrain", "44.27,x", "--terrain", d],
        "longitude 'x' is not a number",
    );
    bad_input(
        &["terrain", "91,-72", "--terrain", d],
        "latitude 91 is outside -90 to 90",
    );
    bad_input(&["terrain", "44.3", "--terrain", d], "'44.3'");
    bad_input(
        &["terrain", "44.3,-71.3", "--terrain", "/no/such/dir"],
        "/no/such/dir",
    );
    bad_input(
        &["terrain", "44.3,-71.3"],
        "give --terrain DIR or set ALOFT_TERRAIN",
    );
    let bad = crate::common::scratch("terrain-bad", "tiles");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::write(bad.join("dem.hgt"), [0u8; 100]).unwrap();
    bad_input(
        &["terrain", "44.3,-71.3", "--terrain", bad.to_str().unwrap()],
        "dem.hgt: the name is not a south-west corner",
    );
}

/// A place off every tile, or on a void, has no height: exit 1, one line naming the place,
/// nothing on stdout (never sea level).
#[test]
fn terrain_a_place_without_ground_is_exit_1_naming_it() {
    let dir = terrain_dir();
    let d = dir.to_str().unwrap();
    let (code, out, err) = run_env(
        &["terrain", "44.3,-71.3", "46.5,-72.25", "--terrain", d],
        None,
    );
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty(), "{out}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("46.5, -72.25") && err.contains("no elevation tile"),
        "{err}"
    );
    // A tile with a void at its centre sample (row 600, column 600: 0.5 N, 0.5 E).
    let void_dir = crate::common::scratch("terrain-void", "tiles");
    std::fs::create_dir_all(&void_dir).unwrap();
    let mut bytes = Vec::with_capacity(2 * 1201 * 1201);
    for k in 0..1201 * 1201 {
        let h: i16 = if k == 600 * 1201 + 600 { -32768 } else { 120 };
        bytes.extend_from_slice(&h.to_be_bytes());
    }
    std::fs::write(void_dir.join("N00E000.hgt"), bytes).unwrap();
    let v = void_dir.to_str().unwrap();
    let (code, out, err) = run_env(&["terrain", "0.5,0.5", "--terrain", v], None);
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty(), "{out}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("0.5, 0.5") && err.contains("void") && err.contains("N00E000.hgt"),
        "{err}"
    );
    // Away from the void (between rows 598 and 599, north of it): the tile's height.
    let (code, out, err) = run_env(
        &["terrain", "0.501,0.5", "--terrain", v, "--format", "csv"],
        None,
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.ends_with(",120\n"), "{out}");
}
