use super::*;
use mavlink::dialects::ardupilotmega::{
    MavBatteryFunction, MavFrame, MavState, EXTENDED_SYS_STATE_DATA, MISSION_COUNT_DATA,
    MISSION_CURRENT_DATA, SYSTEM_TIME_DATA, VFR_HUD_DATA,
};

/// Unit conversions are exact or within a few ulps of f32 -> f64 conversion; 1e-9 covers them.
const TOL: f64 = 1e-9;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

fn h(system_id: u32, component_id: u8) -> MavHeader {
    MavHeader {
        system_id,
        component_id,
        sequence: 0,
    }
}

const VEHICLE: (u32, u8) = (1, 1);

fn hb(autopilot: MavAutopilot, mavtype: MavType, armed: bool, custom_mode: u32) -> MavMessage {
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode,
        mavtype,
        autopilot,
        base_mode: if armed {
            MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED | MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        } else {
            MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        },
        system_status: MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    })
}

fn copter_hb(armed: bool, mode: u32) -> MavMessage {
    hb(
        MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA,
        MavType::MAV_TYPE_QUADROTOR,
        armed,
        mode,
    )
}

/// A decoder that knows the vehicle (1, 1).
fn decoder() -> Decoder {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    d.push(0.0, &h(1, 1), &copter_hb(false, 0), &mut out);
    d
}

fn events(d: &mut Decoder, t: f64, header: MavHeader, msg: MavMessage) -> Vec<Telemetry> {
    let mut out = Vec::new();
    d.push(t, &header, &msg, &mut out);
    out
}

fn samples(ev: &[Telemetry]) -> Vec<Sample> {
    ev.iter()
        .filter_map(|t| match &t.event {
            Event::Sample(s) => Some(*s),
            _ => None,
        })
        .collect()
}

fn gpi(time_boot_ms: u32, lat: i32, lon: i32, alt: i32, relative_alt: i32) -> MavMessage {
    MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
        time_boot_ms,
        lat,
        lon,
        alt,
        relative_alt,
        vx: 100,
        vy: -200,
        vz: 50,
        hdg: 0,
    })
}

#[test]
fn the_vehicle_is_the_first_autopilot_heartbeat_not_a_gcs_or_companion() {
    let mut d = Decoder::new();
    let gcs = hb(
        MavAutopilot::MAV_AUTOPILOT_INVALID,
        MavType::MAV_TYPE_GCS,
        false,
        0,
    );
    assert!(events(&mut d, 0.0, h(255, 190), gcs).is_empty());
    let companion = hb(
        MavAutopilot::MAV_AUTOPILOT_INVALID,
        MavType::MAV_TYPE_ONBOARD_CONTROLLER,
        false,
        0,
    );
    assert!(events(&mut d, 0.1, h(1, 240), companion).is_empty());
    assert_eq!(d.vehicle(), None);
    let ev = events(&mut d, 0.2, h(1, 1), copter_hb(true, 3));
    assert_eq!(d.vehicle(), Some(VEHICLE));
    assert_eq!(
        ev[0].event,
        Event::Heartbeat(Heartbeat {
            armed: true,
            mode: "AUTO".into(),
            vehicle_type: 2,
        })
    );
    // A second autopilot, and another component of the vehicle's system, are not the vehicle.
    assert!(events(&mut d, 0.3, h(2, 1), copter_hb(false, 5)).is_empty());
    let time = MavMessage::SYSTEM_TIME(SYSTEM_TIME_DATA {
        time_unix_usec: 0,
        time_boot_ms: 0,
    });
    assert!(events(&mut d, 0.4, h(1, 240), time).is_empty());
    assert_eq!(d.vehicle_messages(), 1);
}

#[test]
fn sys_status_volts_amps_and_soc_with_their_not_sent_values() {
    let mut d = decoder();
    let status = |mv: u16, ca: i16, pct: i8| {
        MavMessage::SYS_STATUS(SYS_STATUS_DATA {
            voltage_battery: mv,
            current_battery: ca,
            battery_remaining: pct,
            ..SYS_STATUS_DATA::default()
        })
    };
    let ev = events(&mut d, 1.0, h(1, 1), status(12_450, 5_500, 99));
    let s = samples(&ev);
    assert!(close(s[0].voltage_v.unwrap(), 12.45, TOL));
    assert!(close(s[0].current_a.unwrap(), 55.0, TOL));
    assert_eq!(
        ev[1].event,
        Event::Battery(BatteryState {
            soc: Some(0.99),
            consumed_ah: None
        })
    );
    // Phoenix's log: no power module (0 V, -1, -1): nothing.
    assert!(events(&mut d, 2.0, h(1, 1), status(0, -1, -1)).is_empty());
    let ev = events(&mut d, 3.0, h(1, 1), status(u16::MAX, 100, -1));
    assert_eq!(samples(&ev)[0].voltage_v, None);
    assert_eq!(ev.len(), 1);
}

#[test]
fn battery_status_sums_cells_and_reads_consumed_charge() {
    let mut d = decoder();
    let mut voltages = [u16::MAX; 10];
    voltages[..3].copy_from_slice(&[4_100, 4_050, 4_000]);
    let msg = MavMessage::BATTERY_STATUS(BATTERY_STATUS_DATA {
        current_consumed: 2_060,
        voltages,
        current_battery: 1_234,
        id: 0,
        battery_function: MavBatteryFunction::MAV_BATTERY_FUNCTION_ALL,
        battery_remaining: 20,
        ..BATTERY_STATUS_DATA::default()
    });
    let ev = events(&mut d, 1.0, h(1, 1), msg.clone());
    let s = samples(&ev)[0];
    assert!(close(s.voltage_v.unwrap(), 12.15, TOL));
    assert!(close(s.current_a.unwrap(), 12.34, TOL));
    let Event::Battery(b) = &ev[1].event else {
        panic!("{ev:?}")
    };
    assert!(close(b.consumed_ah.unwrap(), 2.06, TOL));
    assert!(close(b.soc.unwrap(), 0.2, TOL));
    // -1 is "not sent"; any other count is passed on as it is, a negative one too (a wrapped
    // counter: `aloft live` judges it and says so, rather than keep the last count silently).
    let MavMessage::BATTERY_STATUS(mut counted) = msg.clone() else {
        unreachable!()
    };
    for (mah, want) in [(-1, None), (i32::MIN, Some(-2_147_483.648)), (0, Some(0.0))] {
        counted.current_consumed = mah;
        let ev = events(
            &mut d,
            1.5,
            h(1, 1),
            MavMessage::BATTERY_STATUS(counted.clone()),
        );
        let Event::Battery(b) = &ev[1].event else {
            panic!("{ev:?}")
        };
        assert_eq!(b.consumed_ah, want, "{mah}");
    }
    // A second battery is not the flight pack.
    let MavMessage::BATTERY_STATUS(mut second) = msg else {
        unreachable!()
    };
    second.id = 1;
    assert!(events(&mut d, 2.0, h(1, 1), MavMessage::BATTERY_STATUS(second)).is_empty());
}

#[test]
fn the_first_fix_confirmed_is_the_origin_and_positions_are_enu_from_it() {
    let mut d = decoder();
    // No fix yet: velocity only, no origin.
    let ev = events(&mut d, 1.0, h(1, 1), gpi(1_000, 0, 0, 0, 0));
    assert_eq!(ev.len(), 1);
    let s = samples(&ev)[0];
    assert_eq!(s.pos_enu_m, None);
    // vx north 1 m/s, vy east -2 m/s, vz down 0.5 m/s.
    let v = s.vel_enu_mps.unwrap();
    assert!(close(v[0], -2.0, TOL) && close(v[1], 1.0, TOL) && close(v[2], -0.5, TOL));
    // The first fix waits for the next to confirm it: velocity only.
    let ev = events(
        &mut d,
        2.0,
        h(1, 1),
        gpi(2_000, 473_977_000, 85_456_000, 488_000, 1_500),
    );
    assert_eq!(ev.len(), 1, "{ev:?}");
    assert_eq!(samples(&ev)[0].pos_enu_m, None);
    assert_eq!(d.origin(), None);
    // 1e-4 deg north (11.1 m) and 10 m higher above home a second later: within reach, so the
    // first fix is the origin and this one is ENU from it.
    let ev = events(
        &mut d,
        3.0,
        h(1, 1),
        gpi(3_000, 473_978_000, 85_456_000, 498_000, 11_500),
    );
    let Event::Origin(o) = ev[0].event else {
        panic!("{ev:?}")
    };
    assert!(close(o.lat_rad.to_degrees(), 47.3977, TOL));
    assert!(close(o.alt_m, 488.0, TOL));
    assert_eq!(ev.len(), 2, "the origin is sent once");
    let p = samples(&ev)[0].pos_enu_m.unwrap();
    // 1e-4 deg of latitude at 47.398 deg is 11.11786 m by the series for the length of a degree
    // of latitude (111132.954 - 559.822 cos 2phi + 1.175 cos 4phi m); 1 mm covers the series'
    // truncation and the tangent plane.
    assert!(close(p[0], 0.0, 1e-6) && close(p[1], 11.11786, 1e-3) && close(p[2], 10.0, TOL));
    let ev = events(
        &mut d,
        4.0,
        h(1, 1),
        gpi(4_000, 473_977_000, 85_456_000, 488_000, 1_500),
    );
    assert_eq!(ev.len(), 1, "the origin is sent once");
    assert_eq!(samples(&ev)[0].pos_enu_m, Some([0.0, 0.0, 0.0]));
    assert!(d.fixes().is_empty());
}

/// The two fixes of `lat` (1e-7 deg) a second apart from `t`: the origin set there.
fn origin_at(d: &mut Decoder, t: f64, lat: i32) -> Vec<Telemetry> {
    let boot = (t * 1000.0) as u32;
    let mut ev = events(d, t, h(1, 1), gpi(boot, lat, 85_456_000, 488_000, 0));
    ev.extend(events(
        d,
        t + 1.0,
        h(1, 1),
        gpi(boot + 1_000, lat, 85_456_000, 488_000, 0),
    ));
    assert!(d.origin().is_some(), "{ev:?}");
    ev
}

/// Positions of the samples of `ev`.
fn positions(ev: &[Telemetry]) -> Vec<[f64; 3]> {
    samples(ev).iter().filter_map(|s| s.pos_enu_m).collect()
}

/// Latitude 214.7 deg (`i32::MAX`), longitude -214.7 deg, an altitude of 2,147 km: dropped whole
/// (no sample, the velocity neither), counted; the vehicle stays where it was.
#[test]
fn fixes_off_the_earth_are_dropped() {
    let mut d = decoder();
    origin_at(&mut d, 1.0, 473_977_000);
    let off = [
        gpi(3_000, i32::MAX, 85_456_000, 488_000, 0),
        gpi(3_200, 473_977_000, i32::MIN, 488_000, 0),
        gpi(3_400, 473_977_000, 85_456_000, i32::MAX, 0),
        gpi(3_600, 473_977_000, 85_456_000, 488_000, i32::MIN),
    ];
    for (k, p) in off.into_iter().enumerate() {
        let ev = events(&mut d, 3.0 + 0.2 * k as f64, h(1, 1), p);
        assert!(ev.is_empty(), "{ev:?}");
    }
    assert_eq!(d.fixes().off_earth, 4);
    let ev = events(
        &mut d,
        4.0,
        h(1, 1),
        gpi(4_000, 473_977_000, 85_456_000, 488_000, 0),
    );
    assert_eq!(positions(&ev), [[0.0, 0.0, 0.0]]);
}

/// A fix 1 km away 1 s after the last believed (1,000 m > 150 m/s x 1 s + 30 m) is a glitch:
/// dropped, counted; the same place 10 s after the last believed fix (1,530 m of reach) is
/// believed.
#[test]
fn a_jump_beyond_reach_is_a_glitch_until_time_makes_it_reachable() {
    let mut d = decoder();
    origin_at(&mut d, 1.0, 473_977_000);
    // 0.009 deg of latitude: 1,000.8 m (111,195 m a degree on the sphere; 0.3 % more on the
    // ellipsoid at 47 deg does not matter against the 180 m of reach).
    let far = 473_977_000 + 90_000;
    let ev = events(
        &mut d,
        3.0,
        h(1, 1),
        gpi(3_000, far, 85_456_000, 488_000, 0),
    );
    assert!(ev.is_empty(), "{ev:?}");
    assert_eq!(d.fixes().out_of_reach, 1);
    // Back where it was: believed.
    let ev = events(
        &mut d,
        3.2,
        h(1, 1),
        gpi(3_200, 473_977_000, 85_456_000, 488_000, 0),
    );
    assert_eq!(positions(&ev), [[0.0, 0.0, 0.0]]);
    let ev = events(
        &mut d,
        13.2,
        h(1, 1),
        gpi(13_200, far, 85_456_000, 488_000, 0),
    );
    let north = positions(&ev)[0][1];
    assert!((north - 1_000.8).abs() < 5.0, "{north}");
    // A climb of 1 km in a second is out of reach too.
    let ev = events(
        &mut d,
        14.2,
        h(1, 1),
        gpi(14_200, far, 85_456_000, 488_000, 1_000_000),
    );
    assert!(ev.is_empty(), "{ev:?}");
}

/// A first fix 0.5 deg (56 km) away from the next ones: it does not become the origin; the next
/// two, which agree, do.
#[test]
fn a_bad_first_fix_is_not_the_origin() {
    let mut d = decoder();
    let bad = events(
        &mut d,
        1.0,
        h(1, 1),
        gpi(1_000, 478_977_000, 85_456_000, 488_000, 0),
    );
    assert!(positions(&bad).is_empty());
    let ev = events(
        &mut d,
        1.2,
        h(1, 1),
        gpi(1_200, 473_977_000, 85_456_000, 488_000, 0),
    );
    assert!(positions(&ev).is_empty() && d.origin().is_none(), "{ev:?}");
    let ev = events(
        &mut d,
        1.4,
        h(1, 1),
        gpi(1_400, 473_977_000, 85_456_000, 488_000, 0),
    );
    let Event::Origin(o) = ev[0].event else {
        panic!("{ev:?}")
    };
    assert!(close(o.lat_rad.to_degrees(), 47.3977, TOL));
    assert_eq!(positions(&ev), [[0.0, 0.0, 0.0]]);
    assert_eq!(d.fixes().out_of_reach, 1);
}

/// Homes off the Earth or over 100 km from the vehicle are dropped; a home 1 km away is taken.
#[test]
fn homes_off_the_earth_or_far_from_the_vehicle_are_dropped() {
    let mut d = decoder();
    origin_at(&mut d, 1.0, 473_977_000);
    let home = |latitude: i32, altitude: i32| {
        MavMessage::HOME_POSITION(HOME_POSITION_DATA {
            latitude,
            longitude: 85_456_000,
            altitude,
            ..HOME_POSITION_DATA::default()
        })
    };
    for bad in [
        home(i32::MAX, 488_000),
        home(473_977_000, i32::MAX),
        // 1 deg north: 111 km.
        home(483_977_000, 488_000),
    ] {
        assert!(events(&mut d, 3.0, h(1, 1), bad).is_empty());
    }
    assert_eq!(d.fixes().homes, 3);
    let ev = events(&mut d, 3.0, h(1, 1), home(473_977_000 + 90_000, 488_000));
    let Event::Home(enu) = ev[0].event else {
        panic!("{ev:?}")
    };
    assert!((enu[1] - 1_000.8).abs() < 5.0, "{enu:?}");
}

/// A velocity faster than 150 m/s is dropped from the sample, the position kept.
#[test]
fn velocities_beyond_any_multirotor_are_dropped() {
    let mut d = decoder();
    origin_at(&mut d, 1.0, 473_977_000);
    let fast = MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
        time_boot_ms: 3_000,
        lat: 473_977_000,
        lon: 85_456_000,
        alt: 488_000,
        vx: i16::MAX,
        ..GLOBAL_POSITION_INT_DATA::default()
    });
    let s = samples(&events(&mut d, 3.0, h(1, 1), fast))[0];
    assert_eq!((s.vel_enu_mps, s.pos_enu_m), (None, Some([0.0, 0.0, 0.0])));
    assert_eq!(d.fixes().velocities, 1);
}

/// After a silence the source took out of its times ([`Decoder::gap`]), the vehicle may have
/// moved as far as the silence allows.
#[test]
fn a_gap_taken_out_of_the_times_still_counts_for_reach() {
    let mut d = decoder();
    origin_at(&mut d, 1.0, 473_977_000);
    d.gap(60.0);
    // 1 km 0.2 s later by the stream's times, 60.2 s later in fact.
    let ev = events(
        &mut d,
        2.2,
        h(1, 1),
        gpi(62_200, 473_977_000 + 90_000, 85_456_000, 488_000, 0),
    );
    assert_eq!(positions(&ev).len(), 1, "{ev:?}");
}

#[test]
fn home_before_the_first_fix_is_sent_after_the_origin_and_home_moves_shift_up() {
    let mut d = decoder();
    let home = |altitude: i32| {
        MavMessage::HOME_POSITION(HOME_POSITION_DATA {
            latitude: 473_977_000,
            longitude: 85_456_000,
            altitude,
            ..HOME_POSITION_DATA::default()
        })
    };
    assert!(events(&mut d, 0.5, h(1, 1), home(488_000)).is_empty());
    // The first fix 2 m above home, confirmed by the next.
    let fix = gpi(1_000, 473_977_000, 85_456_000, 490_000, 2_000);
    assert!(positions(&events(&mut d, 1.0, h(1, 1), fix.clone())).is_empty());
    let ev = events(&mut d, 1.2, h(1, 1), fix);
    assert!(matches!(ev[0].event, Event::Origin(_)));
    let Event::Home(home_enu) = ev[1].event else {
        panic!("{ev:?}")
    };
    assert!(close(home_enu[0], 0.0, TOL) && close(home_enu[2], -2.0, TOL));
    // Home moved 1 m up (armed elsewhere): relative_alt drops by 1 m, up stays.
    let ev = events(&mut d, 2.0, h(1, 1), home(489_000));
    let Event::Home(home_enu) = ev[0].event else {
        panic!("{ev:?}")
    };
    assert!(close(home_enu[2], -1.0, TOL));
    let ev = events(
        &mut d,
        3.0,
        h(1, 1),
        gpi(3_000, 473_977_000, 85_456_000, 490_000, 1_000),
    );
    assert!(close(samples(&ev)[0].pos_enu_m.unwrap()[2], 0.0, TOL));
}

#[test]
fn attitude_wind_speeds_and_landed() {
    let mut d = decoder();
    let att = MavMessage::ATTITUDE(ATTITUDE_DATA {
        time_boot_ms: 10,
        roll: 0.1,
        pitch: -0.2,
        yaw: 3.5,
        ..ATTITUDE_DATA::default()
    });
    let a = samples(&events(&mut d, 1.0, h(1, 1), att))[0]
        .attitude
        .unwrap();
    // f32 inputs: 1e-6 rad.
    assert!(close(a.roll_rad, 0.1, 1e-6) && close(a.pitch_rad, -0.2, 1e-6));
    assert!(close(a.yaw_rad, 3.5 - 2.0 * PI, 1e-6));
    let wind = |direction, speed, speed_z| {
        MavMessage::WIND(WIND_DATA {
            direction,
            speed,
            speed_z,
        })
    };
    // From the north at 5 m/s: the air moves south.
    let w = samples(&events(&mut d, 2.0, h(1, 1), wind(0.0, 5.0, 0.0)))[0]
        .wind_enu_mps
        .unwrap();
    assert!(close(w[0], 0.0, 1e-6) && close(w[1], -5.0, 1e-6) && close(w[2], 0.0, TOL));
    // From the east, sinking air (NED z positive down).
    let w = samples(&events(&mut d, 3.0, h(1, 1), wind(90.0, 4.0, 1.0)))[0]
        .wind_enu_mps
        .unwrap();
    assert!(close(w[0], -4.0, 1e-6) && close(w[1], 0.0, 1e-6) && close(w[2], -1.0, TOL));
    assert!(events(&mut d, 3.5, h(1, 1), wind(f32::NAN, 4.0, 0.0)).is_empty());
    let hud = MavMessage::VFR_HUD(VFR_HUD_DATA {
        airspeed: 7.5,
        groundspeed: 6.25,
        ..VFR_HUD_DATA::default()
    });
    assert_eq!(
        events(&mut d, 4.0, h(1, 1), hud)[0].event,
        Event::Speeds {
            airspeed_mps: 7.5,
            groundspeed_mps: 6.25
        }
    );
    let landed = |state| {
        MavMessage::EXTENDED_SYS_STATE(EXTENDED_SYS_STATE_DATA {
            landed_state: state,
            ..EXTENDED_SYS_STATE_DATA::default()
        })
    };
    let on_ground = landed(MavLandedState::MAV_LANDED_STATE_ON_GROUND);
    assert_eq!(
        samples(&events(&mut d, 5.0, h(1, 1), on_ground))[0].landed,
        Some(true)
    );
    let taking_off = landed(MavLandedState::MAV_LANDED_STATE_TAKEOFF);
    assert_eq!(
        samples(&events(&mut d, 6.0, h(1, 1), taking_off))[0].landed,
        Some(false)
    );
    let undefined = landed(MavLandedState::MAV_LANDED_STATE_UNDEFINED);
    assert!(events(&mut d, 7.0, h(1, 1), undefined).is_empty());
}

#[test]
fn time_never_goes_back() {
    let mut d = decoder();
    let current = |seq| {
        MavMessage::MISSION_CURRENT(MISSION_CURRENT_DATA {
            seq,
            ..MISSION_CURRENT_DATA::default()
        })
    };
    let times: Vec<f64> = [5.0, 4.0, f64::NAN, 6.0, -1.0]
        .iter()
        .flat_map(|&t| events(&mut d, t, h(1, 1), current(1)))
        .map(|t| t.time_s)
        .collect();
    assert_eq!(times, [5.0, 5.0, 5.0, 6.0, 6.0]);
}

#[test]
fn a_reboot_starts_the_flight_over_and_repeats_the_mission() {
    let mut d = decoder();
    let item = |seq| {
        MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
            seq,
            frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
            x: 473_977_000,
            y: 85_456_000,
            z: 20.0,
            target_system: 255,
            ..MISSION_ITEM_INT_DATA::default()
        })
    };
    let count = MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
        count: 2,
        target_system: 255,
        ..MISSION_COUNT_DATA::default()
    });
    events(&mut d, 1.0, h(1, 1), count);
    events(&mut d, 1.1, h(1, 1), item(0));
    let ev = events(&mut d, 1.2, h(1, 1), item(1));
    let Event::Mission(m) = &ev[0].event else {
        panic!("{ev:?}")
    };
    assert!(close(m[1].params[4], 47.3977, TOL) && close(m[1].params[6], 20.0, TOL));
    events(
        &mut d,
        2.0,
        h(1, 1),
        gpi(60_000, 473_977_000, 85_456_000, 0, 0),
    );
    // Back by 2 s: messages out of order, not a restart (the fix confirms the origin).
    let ev = events(
        &mut d,
        3.0,
        h(1, 1),
        gpi(58_000, 473_977_000, 85_456_000, 0, 0),
    );
    assert!(
        matches!(
            ev[..],
            [
                Telemetry {
                    event: Event::Origin(_),
                    ..
                },
                Telemetry {
                    event: Event::Sample(_),
                    ..
                }
            ]
        ),
        "{ev:?}"
    );
    let ev = events(
        &mut d,
        4.0,
        h(1, 1),
        gpi(1_500, 473_978_000, 85_456_000, 0, 0),
    );
    assert_eq!(ev[0].event, Event::Reboot);
    assert!(matches!(&ev[1].event, Event::Mission(m) if m.len() == 2));
    assert_eq!(d.origin(), None);
    // The first fix after the restart, confirmed by the next, is the new origin.
    let ev = events(
        &mut d,
        4.2,
        h(1, 1),
        gpi(1_700, 473_978_000, 85_456_000, 0, 0),
    );
    let Event::Origin(o) = ev[0].event else {
        panic!("{ev:?}")
    };
    assert!(close(o.lat_rad.to_degrees(), 47.3978, TOL));
}

#[test]
fn an_upload_by_the_ground_station_is_the_mission_and_fences_are_not() {
    let mut d = decoder();
    let count = |mission_type| {
        MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: 1,
            target_system: 1,
            target_component: 1,
            mission_type,
            opaque_id: 0,
        })
    };
    let item = |mission_type| {
        MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
            seq: 0,
            frame: MavFrame::MAV_FRAME_LOCAL_NED,
            x: 12_345,
            y: -20_000,
            z: -3.0,
            target_system: 1,
            mission_type,
            ..MISSION_ITEM_INT_DATA::default()
        })
    };
    let fence = MavMissionType::MAV_MISSION_TYPE_FENCE;
    assert!(events(&mut d, 1.0, h(255, 190), count(fence)).is_empty());
    assert!(events(&mut d, 1.1, h(255, 190), item(fence)).is_empty());
    let mission = MavMissionType::MAV_MISSION_TYPE_MISSION;
    assert!(events(&mut d, 1.2, h(255, 190), count(mission)).is_empty());
    let ev = events(&mut d, 1.3, h(255, 190), item(mission));
    let Event::Mission(m) = &ev[0].event else {
        panic!("{ev:?}")
    };
    // Local frame: metres x 1e4.
    assert!(close(m[0].params[4], 1.2345, TOL) && close(m[0].params[5], -2.0, TOL));
    assert_eq!(d.mission().map(<[MissionItem]>::len), Some(1));
}

fn param(name: &str, raw: f32, kind: MavParamType) -> MavMessage {
    MavMessage::PARAM_VALUE(mavlink::dialects::ardupilotmega::PARAM_VALUE_DATA {
        param_value: raw,
        param_count: 900,
        param_index: 7,
        param_id: name.into(),
        param_type: kind,
    })
}

fn parameters(ev: &[Telemetry]) -> Vec<(String, f64)> {
    ev.iter()
        .filter_map(|t| match &t.event {
            Event::Parameter { name, value } => Some((name.clone(), *value)),
            _ => None,
        })
        .collect()
}

/// ArduPilot casts every parameter to the float (BATT_FS_LOW_ACT INT8 2 is 2.0); PX4 copies an
/// integer's bytes (BAT1_N_CELLS INT32 3 is the float whose bits are 3), and a float is the
/// float on both. The bits below are built here from the integers, not taken from aloft.
#[test]
fn parameter_values_are_decoded_as_each_autopilot_encodes_them() {
    use MavParamType as T;
    let mut ardu = decoder();
    let ev = events(
        &mut ardu,
        1.0,
        h(1, 1),
        param("BATT_FS_LOW_ACT", 2.0, T::MAV_PARAM_TYPE_INT8),
    );
    assert_eq!(parameters(&ev), [("BATT_FS_LOW_ACT".to_string(), 2.0)]);
    let ev = events(
        &mut ardu,
        1.0,
        h(1, 1),
        param("BATT_LOW_VOLT", 10.5, T::MAV_PARAM_TYPE_REAL32),
    );
    assert_eq!(parameters(&ev), [("BATT_LOW_VOLT".to_string(), 10.5)]);

    let mut px4 = Decoder::new();
    let px4_hb = hb(
        MavAutopilot::MAV_AUTOPILOT_PX4,
        MavType::MAV_TYPE_QUADROTOR,
        false,
        0,
    );
    events(&mut px4, 0.0, h(1, 1), px4_hb);
    let cells = f32::from_bits(3_u32);
    let ev = events(
        &mut px4,
        1.0,
        h(1, 1),
        param("BAT1_N_CELLS", cells, T::MAV_PARAM_TYPE_INT32),
    );
    assert_eq!(parameters(&ev), [("BAT1_N_CELLS".to_string(), 3.0)]);
    // A negative INT32 (COM_LOW_BAT_ACT is small, so a made-up -5) is its two's complement.
    let minus5 = f32::from_bits((-5_i32) as u32);
    let ev = events(
        &mut px4,
        1.0,
        h(1, 1),
        param("X_NEG", minus5, T::MAV_PARAM_TYPE_INT32),
    );
    assert_eq!(parameters(&ev), [("X_NEG".to_string(), -5.0)]);
    let ev = events(
        &mut px4,
        1.0,
        h(1, 1),
        param("BAT_LOW_THR", 0.15, T::MAV_PARAM_TYPE_REAL32),
    );
    assert!(close(parameters(&ev)[0].1, 0.15, 1e-7));
    // A name of 16 characters has no NUL; it is read whole.
    let ev = events(
        &mut px4,
        1.0,
        h(1, 1),
        param("ABCDEFGHIJKLMNOP", 1.0, T::MAV_PARAM_TYPE_REAL32),
    );
    assert_eq!(parameters(&ev)[0].0, "ABCDEFGHIJKLMNOP");
}

/// 64-bit types do not fit the float, a value that is not finite is no value, another
/// component's parameter is not the vehicle's.
#[test]
fn parameters_that_cannot_be_read_are_not_sent() {
    use MavParamType as T;
    let mut d = decoder();
    for msg in [
        param("A", 1.0, T::MAV_PARAM_TYPE_INT64),
        param("B", 1.0, T::MAV_PARAM_TYPE_REAL64),
        param("C", f32::NAN, T::MAV_PARAM_TYPE_REAL32),
        param("", 1.0, T::MAV_PARAM_TYPE_REAL32),
    ] {
        assert!(parameters(&events(&mut d, 1.0, h(1, 1), msg)).is_empty());
    }
    let other = events(
        &mut d,
        1.0,
        h(1, 100),
        param("BATT_LOW_VOLT", 10.5, T::MAV_PARAM_TYPE_REAL32),
    );
    assert!(parameters(&other).is_empty());
}
