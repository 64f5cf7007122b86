//! The C ABI called from Rust: results equal the Rust facade's, bad input is an error code with a
//! message, the last error is per thread, handles are shared between threads.

use std::ffi::{c_char, CStr, CString};
use std::ptr::null_mut;

use aloft::engine::{plan_mission, Mission, MissionOptions, Vehicle};
use aloft_ffi::*;

fn last_error() -> String {
    // SAFETY: never NULL, valid until the next aloft call on this thread; copied at once.
    unsafe { CStr::from_ptr(aloft_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

fn m100() -> *mut AloftVehicle {
    let mut v = null_mut();
    // SAFETY: a NUL-terminated name and a writable out pointer.
    assert_eq!(
        unsafe { aloft_vehicle_builtin(c"dji-m100".as_ptr(), &mut v) },
        AloftStatus::Ok
    );
    v
}

/// Take ownership of a string returned by aloft.
fn take(s: *mut c_char) -> String {
    assert!(!s.is_null());
    // SAFETY: a live string from aloft, read then freed once.
    let text = unsafe { CStr::from_ptr(s) }.to_str().unwrap().to_string();
    assert_eq!(unsafe { aloft_string_free(s) }, AloftStatus::Ok);
    text
}

#[test]
fn mission_json_equals_the_rust_facade_for_toml_json_and_null_missions() {
    let v = m100();
    let rust = plan_mission(
        &Vehicle::builtin("dji-m100").unwrap(),
        &Mission::demo(),
        &MissionOptions::default(),
    )
    .unwrap()
    .to_json()
    .unwrap();
    let toml = CString::new(aloft::engine::DEMO_MISSION).unwrap();
    let json = CString::new(Mission::demo().to_json().unwrap()).unwrap();
    for mission in [std::ptr::null(), toml.as_ptr(), json.as_ptr()] {
        let mut out = null_mut();
        // SAFETY: a live vehicle, NUL-terminated texts or NULL, a writable out pointer.
        let s = unsafe { aloft_mission_json(v, mission, c"{}".as_ptr(), &mut out) };
        assert_eq!(s, AloftStatus::Ok, "{}", last_error());
        let got = take(out);
        // The TOML text's origin differs from the demo's, but the file names the mission; the
        // JSON text's route says it was read from JSON.
        let got = got.replace(
            "\"source_format\": \"aloft_json\"",
            "\"source_format\": \"aloft_toml\"",
        );
        assert_eq!(got, rust);
    }
    // SAFETY: freed once.
    assert_eq!(unsafe { aloft_vehicle_free(v) }, AloftStatus::Ok);
}

#[test]
fn options_reach_the_planner() {
    let v = m100();
    let mut calm = null_mut();
    let mut windy = null_mut();
    // SAFETY: as above.
    unsafe {
        assert_eq!(
            aloft_mission_plan(
                v,
                std::ptr::null(),
                c"{\"payload_kg\": 0.5, \"wind\": {\"speed_mps\": 0, \"from_deg\": 0}}".as_ptr(),
                &mut calm
            ),
            AloftStatus::Ok
        );
        assert_eq!(
            aloft_mission_plan(
                v,
                std::ptr::null(),
                c"{\"payload_kg\": 0.5, \"wind\": {\"speed_mps\": 6, \"from_deg\": 90}}".as_ptr(),
                &mut windy,
            ),
            AloftStatus::Ok
        );
    }
    let (mut e_calm, mut e_windy) = (0.0, 0.0);
    let mut feasible = -1;
    // SAFETY: live plans and writable outs.
    unsafe {
        assert_eq!(aloft_plan_energy_wh(calm, &mut e_calm), AloftStatus::Ok);
        assert_eq!(aloft_plan_energy_wh(windy, &mut e_windy), AloftStatus::Ok);
        assert_eq!(aloft_plan_feasible(calm, &mut feasible), AloftStatus::Ok);
    }
    assert_eq!(feasible, 1);
    // A 6 m/s easterly (overriding the file's breeze) costs more than still air.
    assert!(e_windy > e_calm, "{e_windy} vs {e_calm}");
    let mut json = null_mut();
    // SAFETY: live plan, writable out.
    assert_eq!(unsafe { aloft_plan_json(calm, &mut json) }, AloftStatus::Ok);
    let summary: serde_json::Value = serde_json::from_str(&take(json)).unwrap();
    assert_eq!(summary["payload_kg"].as_f64(), Some(0.5));
    // SAFETY: each freed once; the vehicle may go first.
    unsafe {
        assert_eq!(aloft_vehicle_free(v), AloftStatus::Ok);
        assert_eq!(aloft_plan_free(calm), AloftStatus::Ok);
        assert_eq!(aloft_plan_free(windy), AloftStatus::Ok);
    }
}

#[test]
fn power_matches_the_rust_model() {
    let v = m100();
    let mut w = 0.0;
    // SAFETY: live vehicle, writable out.
    let s = unsafe { aloft_vehicle_power_w(v, 8.0, 0.0, -0.1, 0.5, &mut w) };
    assert_eq!(s, AloftStatus::Ok);
    let rust = Vehicle::builtin("dji-m100")
        .unwrap()
        .power(&aloft::power::FlightState::new(8.0, 0.0, -0.1, 0.5))
        .unwrap()
        .electrical_w;
    assert_eq!(w.to_bits(), rust.to_bits());
    let mut json = null_mut();
    // SAFETY: as above.
    let s = unsafe {
        aloft_vehicle_power_json(
            v,
            c"{\"airspeed_mps\": 8, \"pitch_deg\": -5.729577951308232, \"climb_rate_mps\": 0.5}"
                .as_ptr(),
            &mut json,
        )
    };
    assert_eq!(s, AloftStatus::Ok, "{}", last_error());
    let b: serde_json::Value = serde_json::from_str(&take(json)).unwrap();
    // -5.7296 deg is -0.1 rad to 1e-16: the same power to rounding.
    assert!((b["electrical_w"].as_f64().unwrap() - rust).abs() < 1e-9 * rust);
    // Both fly the M100's default take-off mass: 1755 g airframe + 600 g TB47D.
    assert!((b["takeoff_mass_kg"].as_f64().unwrap() - 2.355).abs() < 1e-12);
    assert_eq!(b["battery"].as_str(), Some("TB47D"));
    // Another pack and a payload, as `aloft power --battery TB48D --payload-kg 0.5`: thrust in
    // hover is (1.755 + 0.676 + 0.5) kg x g (the power seed's g = 9.8066).
    let mut json = null_mut();
    // SAFETY: as above.
    let s = unsafe {
        aloft_vehicle_power_json(
            v,
            c"{\"battery\": \"TB48D\", \"payload_kg\": 0.5}".as_ptr(),
            &mut json,
        )
    };
    assert_eq!(s, AloftStatus::Ok, "{}", last_error());
    let b: serde_json::Value = serde_json::from_str(&take(json)).unwrap();
    let mass = 1.755 + 0.676 + 0.5;
    assert!((b["takeoff_mass_kg"].as_f64().unwrap() - mass).abs() < 1e-12);
    assert!((b["thrust_n"].as_f64().unwrap() - mass * 9.8066).abs() < 1e-9);
    // SAFETY: as above.
    let s = unsafe { aloft_vehicle_power_json(v, c"{\"payload_kg\": 2}".as_ptr(), &mut json) };
    assert_eq!(s, AloftStatus::Mission, "{}", last_error());
    assert!(last_error().contains("3.600 kg limit"), "{}", last_error());
    // SAFETY: freed once.
    unsafe { aloft_vehicle_free(v) };
}

#[test]
fn endurance_json_has_the_cli_keys() {
    let v = m100();
    let mut json = null_mut();
    // SAFETY: as above.
    let s = unsafe {
        aloft_endurance_json(
            v,
            c"{\"orbit_radius_m\": 30, \"orbit_speed_mps\": 5}".as_ptr(),
            &mut json,
        )
    };
    assert_eq!(s, AloftStatus::Ok, "{}", last_error());
    let text = take(json);
    let keys: Vec<&str> = text
        .lines()
        .filter_map(|l| l.trim().strip_prefix('"')?.split('"').next())
        .collect();
    assert_eq!(
        keys,
        [
            "vehicle",
            "battery",
            "takeoff_mass_kg",
            "air_density_kg_m3",
            "density_source",
            "density_altitude_m",
            "hover_power_w",
            "hover_endurance_s",
            "max_endurance_speed_mps",
            "max_endurance_power_w",
            "max_endurance_s",
            "max_range_speed_mps",
            "max_range_ground_speed_mps",
            "max_range_power_w",
            "max_range_m",
            "orbit_power_w",
            "orbit_endurance_s"
        ]
    );
    // SAFETY: freed once.
    unsafe { aloft_vehicle_free(v) };
}

/// Each case (what, the status a call returned, the status wanted) failed as wanted, with a
/// message. The message is read after all the calls were made: it is the last one's.
fn assert_failures(cases: Vec<(&str, AloftStatus, AloftStatus)>) {
    for (what, got, want) in cases {
        let msg = last_error();
        assert_eq!(got, want, "{what}: {msg}");
        assert!(!msg.is_empty(), "{what}: no message");
    }
}

#[test]
fn null_pointers_are_an_error_code_and_a_message_never_a_crash() {
    let mut out = null_mut();
    // SAFETY: every pointer is NULL, a NUL-terminated string or a writable out; the NULL ones are
    // checked by the library before use.
    unsafe {
        assert_failures(vec![
            (
                "NULL name",
                aloft_vehicle_builtin(std::ptr::null(), &mut null_mut()),
                AloftStatus::NullPointer,
            ),
            (
                "NULL out",
                aloft_vehicle_from_toml(c"name = \"x\"".as_ptr(), std::ptr::null_mut()),
                AloftStatus::NullPointer,
            ),
            (
                "NULL plan",
                aloft_plan_json(std::ptr::null(), &mut out),
                AloftStatus::NullPointer,
            ),
        ]);
    }
    assert!(out.is_null(), "out pointers are NULL after a failure");
}

#[test]
fn invalid_utf8_is_an_error_code_and_a_message_never_a_crash() {
    let v = m100();
    let mut plan = null_mut();
    let mut out = null_mut();
    let bad_utf8 = [b'{', 0xc3, 0x28, 0];
    // SAFETY: every pointer is NULL, a NUL-terminated string, a live handle or a writable out;
    // the invalid UTF-8 is checked by the library before use.
    unsafe {
        assert_failures(vec![
            (
                "invalid UTF-8 mission",
                aloft_mission_plan(v, bad_utf8.as_ptr().cast(), std::ptr::null(), &mut plan),
                AloftStatus::InvalidUtf8,
            ),
            (
                "invalid UTF-8 options",
                aloft_mission_json(v, std::ptr::null(), bad_utf8.as_ptr().cast(), &mut out),
                AloftStatus::InvalidUtf8,
            ),
        ]);
        assert!(
            plan.is_null() && out.is_null(),
            "out pointers are NULL after a failure"
        );
        assert_eq!(aloft_vehicle_free(v), AloftStatus::Ok);
    }
}

#[test]
fn bad_missions_and_options_are_an_error_code_and_a_message_never_a_crash() {
    let v = m100();
    let mut out = null_mut();
    // SAFETY: every pointer is NULL, a NUL-terminated string, a live handle or a writable out.
    unsafe {
        assert_failures(vec![
            (
                "malformed JSON mission",
                aloft_mission_json(
                    v,
                    c"{\"segment\": [{\"kind\": \"leg\"".as_ptr(),
                    std::ptr::null(),
                    &mut out,
                ),
                AloftStatus::Parse,
            ),
            (
                "JSON mission with a bad segment",
                aloft_mission_json(
                    v,
                    c"{\"segment\": [{\"kind\": \"warp\"}]}".as_ptr(),
                    std::ptr::null(),
                    &mut out,
                ),
                AloftStatus::Parse,
            ),
            (
                "malformed TOML mission",
                aloft_mission_json(
                    v,
                    c"[[segment]\nkind = \"leg\"".as_ptr(),
                    std::ptr::null(),
                    &mut out,
                ),
                AloftStatus::Parse,
            ),
            (
                "mission that ends in the air",
                aloft_mission_json(
                    v,
                    c"[[segment]]\nkind = \"take-off\"\naltitude_m = 20.0\nclimb_rate_mps = 2.0\n"
                        .as_ptr(),
                    std::ptr::null(),
                    &mut out,
                ),
                AloftStatus::Mission,
            ),
            (
                "reserve out of range",
                aloft_mission_json(
                    v,
                    std::ptr::null(),
                    c"{\"reserve_percent\": 150}".as_ptr(),
                    &mut out,
                ),
                AloftStatus::InvalidInput,
            ),
            (
                "NaN in the options",
                aloft_mission_json(
                    v,
                    std::ptr::null(),
                    c"{\"payload_kg\": NaN}".as_ptr(),
                    &mut out,
                ),
                AloftStatus::Parse,
            ),
        ]);
        assert!(out.is_null(), "out pointers are NULL after a failure");
        assert_eq!(aloft_vehicle_free(v), AloftStatus::Ok);
    }
}

#[test]
fn wrong_handles_are_an_error_code_and_a_message_and_a_success_clears_it() {
    let v = m100();
    let mut out = null_mut();
    // SAFETY: every pointer is a live handle, a string aloft did not make or a writable out; the
    // wrong ones are checked by the library before use.
    unsafe {
        assert_failures(vec![
            (
                "vehicle passed as a plan",
                aloft_plan_json(v.cast(), &mut out),
                AloftStatus::BadHandle,
            ),
            (
                "foreign string freed",
                aloft_string_free(CString::new("mine").unwrap().into_raw()),
                AloftStatus::BadHandle,
            ),
        ]);
        assert!(out.is_null(), "out pointers are NULL after a failure");
        assert_eq!(aloft_vehicle_free(v), AloftStatus::Ok);
        assert_eq!(last_error(), "", "a success clears the message");
        assert_eq!(aloft_vehicle_free(v), AloftStatus::BadHandle);
        assert!(last_error().contains("not a live aloft vehicle"));
    }
}

#[test]
fn handles_are_shared_between_threads_and_errors_stay_per_thread() {
    struct Shared(*mut AloftVehicle);
    // SAFETY: the ABI documents vehicles as immutable and usable from any thread.
    unsafe impl Sync for Shared {}
    let v = Shared(m100());
    let energies: Vec<f64> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..4)
            .map(|k| {
                let v = &v;
                scope.spawn(move || {
                    if k == 0 {
                        // This thread fails; the others' messages must stay empty.
                        let s = unsafe {
                            aloft_mission_json(
                                v.0,
                                c"nonsense".as_ptr(),
                                std::ptr::null(),
                                &mut null_mut(),
                            )
                        };
                        assert_eq!(s, AloftStatus::Parse);
                        assert!(!last_error().is_empty());
                    }
                    let mut p = null_mut();
                    // SAFETY: a live vehicle shared read-only, a writable out.
                    let s = unsafe {
                        aloft_mission_plan(v.0, std::ptr::null(), std::ptr::null(), &mut p)
                    };
                    assert_eq!(s, AloftStatus::Ok);
                    assert_eq!(last_error(), "");
                    let mut e = 0.0;
                    unsafe {
                        assert_eq!(aloft_plan_energy_wh(p, &mut e), AloftStatus::Ok);
                        assert_eq!(aloft_plan_free(p), AloftStatus::Ok);
                    }
                    e
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(energies
        .iter()
        .all(|e| e.to_bits() == energies[0].to_bits()));
    // SAFETY: freed once, after every thread has finished.
    unsafe { aloft_vehicle_free(v.0) };
}

#[test]
fn static_strings_are_valid() {
    // SAFETY: library-owned static C strings.
    let version = unsafe { CStr::from_ptr(aloft_version()) }.to_str().unwrap();
    assert_eq!(version, env!("CARGO_PKG_VERSION"));
    let demo = unsafe { CStr::from_ptr(aloft_demo_mission_toml()) }
        .to_str()
        .unwrap();
    assert_eq!(demo, aloft::engine::DEMO_MISSION);
}

/// Issue 44: `start_voltage_v` in the options starts the mission from the pack's rested voltage
/// on its curve (the M100's 6S at 3.58 V a cell: 5 % x (3.58 - 3.27) / (3.61 - 3.27) on the
/// generic LiPo curve), as `aloft mission --start-voltage-v`; one off the curve is an error naming
/// it.
#[test]
fn a_rested_voltage_in_the_options_starts_the_mission_on_the_curve() {
    let v = m100();
    let mut out = null_mut();
    // SAFETY: a live vehicle, NULL mission, a NUL-terminated options text, an out pointer.
    let s = unsafe {
        aloft_mission_json(
            v,
            std::ptr::null(),
            c"{\"start_voltage_v\": 21.48}".as_ptr(),
            &mut out,
        )
    };
    assert_eq!(s, AloftStatus::Ok, "{}", last_error());
    let json: serde_json::Value = serde_json::from_str(&take(out)).unwrap();
    let want = 0.05 * (3.58 - 3.27) / (3.61 - 3.27);
    assert!(
        (json["start_soc"].as_f64().unwrap() - want).abs() < 1e-9,
        "{json}"
    );
    let mut out = null_mut();
    // SAFETY: as above.
    let s = unsafe {
        aloft_mission_json(
            v,
            std::ptr::null(),
            c"{\"start_voltage_v\": 5.0}".as_ptr(),
            &mut out,
        )
    };
    assert_ne!(s, AloftStatus::Ok);
    assert!(last_error().contains("start_voltage_v"), "{}", last_error());
    // SAFETY: freed once.
    assert_eq!(unsafe { aloft_vehicle_free(v) }, AloftStatus::Ok);
}
