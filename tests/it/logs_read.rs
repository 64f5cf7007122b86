//! CSV reading through profiles and column maps, on the small fixtures in `fixtures/logs/`
//! (made by the project, not copied from the data set): conversions to SI/ENU, time-base
//! reports, and the typed errors for bad input.

use std::path::{Path, PathBuf};

use aloft_logs::{read_log, Channel, ColumnMap, LogError, McapOptions, Profile};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/logs")
        .join(name)
}

fn read(name: &str, profile: Option<&Profile>) -> Result<aloft_logs::Log, LogError> {
    read_log(&fixture(name), profile, &McapOptions::default())
}

/// The fixture log `name` read through the fixture profile file `profile`.
fn read_with(name: &str, profile: &str) -> Result<aloft_logs::Log, LogError> {
    let profile = Profile::resolve(fixture(profile).to_str().unwrap()).unwrap();
    read(name, Some(&profile))
}

// Inputs are short decimals; conversions are one or two products, so 1e-9 bounds the rounding.
const TOL: f64 = 1e-9;

#[test]
fn kaist_layout_is_recognised_and_converted() {
    let log = read("kaist_small.csv", None).unwrap();
    assert_eq!(log.samples.len(), 20);
    assert!(log.time.is_clean());
    assert!((log.time.duration_s - 1.9).abs() < TOL);
    assert!((log.start_time_s - 1.0).abs() < TOL);
    let s = &log.samples[15];
    // NED (2, -1, -0.1) -> ENU (-1, 2, 0.1).
    let v = s.vel_enu_mps.unwrap();
    assert!((v[0] + 1.0).abs() < TOL && (v[1] - 2.0).abs() < TOL && (v[2] - 0.1).abs() < TOL);
    // power column is 10 V I: scaled by 0.1 it equals V I.
    let vi = s.voltage_v.unwrap() * s.current_a.unwrap();
    assert!(
        (s.power_w.unwrap() - vi).abs() < 0.01,
        "{} vs {vi}",
        s.power_w.unwrap()
    );
    // Geodetic origin at the first fix; altitude relative to it.
    assert!((s.pos_enu_m.unwrap()[2] - 1.5).abs() < 1e-6);
    assert!(s.pos_enu_m.unwrap()[0].abs() < TOL);
    assert!((log.origin.unwrap().alt_m - 50.0).abs() < TOL);
    assert_eq!(
        log.samples[0].attitude.unwrap().pitch_rad.to_bits(),
        0.0f64.to_bits()
    );
    assert!((s.attitude.unwrap().pitch_rad + 0.05).abs() < TOL);
    assert_eq!(
        log.channels(),
        vec![
            Channel::Position,
            Channel::Velocity,
            Channel::Acceleration,
            Channel::Attitude,
            Channel::Voltage,
            Channel::Current,
            Channel::Power,
            Channel::Charge
        ]
    );
    let (t, p) = log.power_series().unwrap();
    assert_eq!(t.len(), 20);
    assert!((p[0] - 48.0 * 25.0).abs() < TOL);
}

#[test]
fn user_map_converts_units_and_quaternion() {
    let log = read_with("custom.csv", "custom.toml").unwrap();
    assert_eq!(log.samples.len(), 10);
    let s = &log.samples[3];
    assert!((s.time_s - 0.15).abs() < TOL);
    let p = s.pos_enu_m.unwrap();
    assert!((p[0] - 3.0).abs() < TOL && (p[1] + 2.0).abs() < TOL && (p[2] - 10.03).abs() < TOL);
    assert!((s.voltage_v.unwrap() - 15.997).abs() < TOL);
    assert!((s.current_a.unwrap() - 12.3).abs() < TOL);
    // ROS quaternion: +90 deg about ENU up = nose north = aerospace heading 0 (quaternion given
    // to 9 decimals: 1e-8 rad).
    let a = s.attitude.unwrap();
    assert!(
        a.yaw_rad.abs() < 1e-8 && a.roll_rad.abs() < 1e-8 && a.pitch_rad.abs() < 1e-8,
        "{a:?}"
    );
    assert!(log.samples.iter().all(|s| s.vel_enu_mps.is_none()));
}

#[test]
fn gaps_and_backward_steps_are_reported_not_smoothed() {
    let log = read("kaist_gap_backwards.csv", Some(&Profile::Kaist)).unwrap();
    assert_eq!(log.samples.len(), 20, "no sample dropped");
    assert_eq!(log.time.gap_count, 1);
    assert_eq!(log.time.gaps[0].index, 12);
    assert!((log.time.gaps[0].to_s - log.time.gaps[0].from_s - 2.1).abs() < TOL);
    assert_eq!(log.time.non_monotonic_count, 1);
    assert_eq!(log.time.non_monotonic[0].index, 15);
    // File order kept: sample 15 is earlier than sample 14.
    assert!(log.samples[15].time_s < log.samples[14].time_s);
}

#[test]
fn missing_column_names_file_column_and_channel() {
    let e = read("kaist_missing_cur.csv", Some(&Profile::Kaist)).unwrap_err();
    match &e {
        LogError::ColumnMissing {
            path,
            column,
            channel,
            ..
        } => {
            assert!(path.ends_with("kaist_missing_cur.csv"));
            assert_eq!(column, "cur");
            assert_eq!(*channel, "current");
        }
        e => panic!("{e}"),
    }
    assert!(e.to_string().contains("kaist_missing_cur.csv"));
}

#[test]
fn header_only_log_is_empty() {
    let e = read("kaist_empty.csv", None).unwrap_err();
    assert!(matches!(e, LogError::Empty { .. }), "{e}");
    assert!(e.to_string().contains("kaist_empty.csv"));
}

#[test]
fn wrong_voltage_unit_is_caught_on_the_first_row() {
    let e = read_with("custom.csv", "custom_wrong_units.toml").unwrap_err();
    match e {
        LogError::Implausible {
            row,
            channel,
            value,
            ..
        } => {
            assert_eq!(row, 2);
            assert_eq!(channel, "voltage");
            assert!((value - 16000.0).abs() < TOL);
        }
        e => panic!("{e}"),
    }
}

#[test]
fn text_in_a_number_column_names_row_and_column() {
    let e = read_with("custom_bad_number.csv", "custom.toml").unwrap_err();
    match e {
        LogError::ParseValue {
            row, column, text, ..
        } => {
            assert_eq!(row, 6);
            assert_eq!(column, "amp_ma");
            assert_eq!(text, "twelve");
        }
        e => panic!("{e}"),
    }
}

#[test]
fn unknown_profile_and_unrecognised_layout() {
    let e = Profile::resolve("ardupilot").unwrap_err();
    assert!(e.to_string().contains("kaist, px4"), "{e}");
    // custom.csv without its map is not a layout aloft knows.
    let e = read("custom.csv", None).unwrap_err();
    assert!(matches!(e, LogError::UnsupportedFormat { .. }), "{e}");
    let e = read("does_not_exist.csv", None).unwrap_err();
    assert!(e.to_string().contains("does_not_exist.csv"), "{e}");
}

#[test]
fn kaist_map_round_trips_through_toml() {
    let text = toml::to_string(&ColumnMap::kaist()).unwrap();
    let back = ColumnMap::from_toml_str(&text, Path::new("kaist.toml")).unwrap();
    assert_eq!(back, ColumnMap::kaist());
}
