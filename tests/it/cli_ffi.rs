//! One front door: the command line and the C ABI call the same engine, so for the same request
//! they print the same JSON, byte for byte (the CLI adds only a final newline). Each case is a
//! set of CLI flags and the C ABI's options document that asks for the same thing.

use crate::common;

use std::ffi::{c_char, CStr, CString};

use aloft_ffi::{
    aloft_endurance_json, aloft_mission_json, aloft_string_free, aloft_vehicle_builtin,
    aloft_vehicle_free, aloft_vehicle_power_json, AloftStatus, AloftVehicle,
};

/// The stdout of `aloft args` (exit 0 or 1) without its final newline.
fn cli(args: &[&str]) -> String {
    common::cli(args)
        .strip_suffix('\n')
        .expect("a final newline")
        .to_string()
}

/// A built-in vehicle through the C ABI, freed on drop.
struct CVehicle(*mut AloftVehicle);

impl CVehicle {
    fn builtin(name: &str) -> Self {
        let name = CString::new(name).unwrap();
        let mut v: *mut AloftVehicle = std::ptr::null_mut();
        // SAFETY: a NUL-terminated name and a writable out pointer.
        assert_eq!(
            unsafe { aloft_vehicle_builtin(name.as_ptr(), &mut v) },
            AloftStatus::Ok
        );
        Self(v)
    }
}

impl Drop for CVehicle {
    fn drop(&mut self) {
        // SAFETY: a live handle from aloft_vehicle_builtin, freed once.
        unsafe { aloft_vehicle_free(self.0) };
    }
}

/// Call an ABI function that writes a string, take the string and free it.
fn take(call: impl FnOnce(*mut *mut c_char) -> AloftStatus) -> String {
    let mut out: *mut c_char = std::ptr::null_mut();
    let status = call(&mut out);
    assert_eq!(status, AloftStatus::Ok);
    // SAFETY: aloft returned a NUL-terminated string, freed once below.
    let text = unsafe { CStr::from_ptr(out) }.to_str().unwrap().to_string();
    // SAFETY: as above.
    unsafe { aloft_string_free(out) };
    text
}

fn ffi_mission(vehicle: &CVehicle, mission: Option<&str>, options: &str) -> String {
    let mission = mission.map(|m| CString::new(m).unwrap());
    let options = CString::new(options).unwrap();
    take(|out| {
        // SAFETY: a live vehicle, NUL-terminated texts (or NULL for the demo), an out pointer.
        unsafe {
            aloft_mission_json(
                vehicle.0,
                mission.as_ref().map_or(std::ptr::null(), |m| m.as_ptr()),
                options.as_ptr(),
                out,
            )
        }
    })
}

#[test]
fn mission_answers_are_the_same_bytes() {
    let m100 = CVehicle::builtin("dji-m100");
    let example = std::fs::read_to_string("fixtures/missions/example.toml").unwrap();
    let grid = common::scratch("cli-ffi", "grid.csv");
    common::write_wind_grid(&grid, [1000.0, 200.0], "2,-1,0");
    let grid = grid.display().to_string();
    let cases: Vec<(Vec<&str>, Option<&str>, String)> = vec![
        (vec![], None, "{}".into()),
        (
            vec!["--payload-kg", "0.4", "--reserve-percent", "30", "--aoa", "paper"],
            None,
            r#"{"payload_kg": 0.4, "reserve_percent": 30, "aoa": "paper"}"#.into(),
        ),
        (
            vec!["--wind-speed", "5", "--wind-from", "200", "--wind-profile", "power-law"],
            None,
            r#"{"wind": {"speed_mps": 5, "from_deg": 200, "profile": "power-law", "reference_height_m": 10, "exponent": 0.14285714285714285}}"#.into(),
        ),
        (
            vec!["--wind-speed", "2", "--wind-from", "0", "--gust-std", "0.5", "--gust-seed", "7", "--no-ground-effect"],
            None,
            r#"{"wind": {"speed_mps": 2, "from_deg": 0}, "gusts": {"std_mps": 0.5, "seed": 7}, "ground_effect": false}"#.into(),
        ),
        (
            vec!["--wind-field", &grid, "--time-step", "0.05", "--start-percent", "90"],
            None,
            format!(r#"{{"wind_field": "{grid}", "time_step_s": 0.05, "start_percent": 90}}"#),
        ),
        (
            vec!["fixtures/missions/example.toml", "--battery", "TB48D"],
            Some(example.as_str()),
            r#"{"battery": "TB48D"}"#.into(),
        ),
        // Monte-Carlo scenarios (issue 17): the C ABI's `scenarios` object is `--samples` and the
        // spreads; both add the same `uncertainty`.
        (
            vec![
                "--samples", "40", "--seed", "7", "--wind-speed-sd", "1", "--wind-from-sd", "10",
                "--payload-sd-kg", "0.1", "--capacity-sd-percent", "4", "--time-step", "0.5",
            ],
            None,
            r#"{"time_step_s": 0.5, "scenarios": {"samples": 40, "seed": 7, "wind_speed_sd_mps": 1, "wind_from_sd_deg": 10, "payload_sd_kg": 0.1, "capacity_sd_percent": 4}}"#.into(),
        ),
        (
            vec![
                "--samples", "12", "--power-sd-percent", "0", "--wind-speed", "3", "--wind-from",
                "90", "--gust-std", "1", "--time-step", "0.5",
            ],
            None,
            r#"{"time_step_s": 0.5, "wind": {"speed_mps": 3, "from_deg": 90}, "gusts": {"std_mps": 1, "seed": 1}, "scenarios": {"samples": 12, "power_sd_percent": 0, "threads": 1}}"#.into(),
        ),
    ];
    for (flags, mission, options) in cases {
        let mut args = vec!["mission", "--format", "json"];
        args.extend(&flags);
        assert_eq!(
            cli(&args),
            ffi_mission(&m100, mission, &options),
            "aloft {args:?} against options {options}"
        );
    }
}

#[test]
fn endurance_and_power_answers_are_the_same_bytes() {
    let m100 = CVehicle::builtin("dji-m100");
    let cases: [(&[&str], &str); 3] = [
        (&[], "{}"),
        (
            &[
                "--wind-speed",
                "6",
                "--wind-from",
                "90",
                "--course",
                "45",
                "--reserve-percent",
                "20",
            ],
            r#"{"wind": {"speed_mps": 6, "from_deg": 90}, "course_deg": 45, "reserve_percent": 20}"#,
        ),
        (
            &[
                "--orbit-radius",
                "40",
                "--orbit-speed",
                "5",
                "--payload-kg",
                "0.3",
                "--aoa",
                "paper",
            ],
            r#"{"orbit_radius_m": 40, "orbit_speed_mps": 5, "payload_kg": 0.3, "aoa": "paper"}"#,
        ),
    ];
    for (flags, options) in cases {
        let mut args = vec!["endurance", "--format", "json"];
        args.extend(flags);
        let options_c = CString::new(options).unwrap();
        // SAFETY: a live vehicle, a NUL-terminated options document, an out pointer.
        let ffi = take(|out| unsafe { aloft_endurance_json(m100.0, options_c.as_ptr(), out) });
        assert_eq!(cli(&args), ffi, "aloft {args:?} against options {options}");
    }
    same_power_answer(
        &m100,
        &[
            "--airspeed",
            "7.5",
            "--roll",
            "2",
            "--pitch",
            "-9",
            "--climb-rate",
            "0.5",
        ],
        r#"{"airspeed_mps": 7.5, "roll_deg": 2, "pitch_deg": -9, "climb_rate_mps": 0.5}"#,
    );
    // The take-off mass's pack and payload, as the CLI's flags.
    let ffi = same_power_answer(
        &m100,
        &[
            "--airspeed",
            "4",
            "--battery",
            "2xTB47D",
            "--payload-kg",
            "0.2",
        ],
        r#"{"airspeed_mps": 4, "battery": "2xTB47D", "payload_kg": 0.2}"#,
    );
    assert!(ffi.contains("\"takeoff_mass_kg\": 3.315"), "{ffi}");
}

/// `aloft power flags --format json` and `aloft_vehicle_power_json` of `state` give the same
/// bytes; returns them.
fn same_power_answer(m100: &CVehicle, flags: &[&str], state: &str) -> String {
    let state = CString::new(state).unwrap();
    // SAFETY: a live vehicle, a NUL-terminated state document, an out pointer.
    let ffi = take(|out| unsafe { aloft_vehicle_power_json(m100.0, state.as_ptr(), out) });
    let mut args = vec!["power"];
    args.extend(flags);
    args.extend(["--format", "json"]);
    assert_eq!(cli(&args), ffi, "aloft {args:?} against state {state:?}");
    ffi
}
