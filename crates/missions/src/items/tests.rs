//! The semantics of each command, through the `.waypoints` reader (rows are easy to write) and,
//! where the formats differ, the `.plan` reader.

use aloft_planner::{OrbitDirection, SegmentSpec};

use crate::{read_plan, read_waypoints, Imported, SourceFormat};

/// Home at (-35, 149), 100 m above mean sea level.
const HOME: &str = "0\t1\t0\t16\t0\t0\t0\t0\t-35.0\t149.0\t100.0\t1";

/// A row: INDEX, frame, command, p1-p4, lat, lon, alt.
fn row(index: u32, frame: u32, command: u32, p: [f64; 4], lat: f64, lon: f64, alt: f64) -> String {
    format!(
        "{index}\t0\t{frame}\t{command}\t{}\t{}\t{}\t{}\t{lat}\t{lon}\t{alt}\t1",
        p[0], p[1], p[2], p[3]
    )
}

fn wpl(rows: &[String]) -> Imported {
    let mut t = format!("QGC WPL 110\n{HOME}\n");
    for r in rows {
        t += r;
        t += "\n";
    }
    read_waypoints(&t).unwrap()
}

fn take_off(alt: f64) -> String {
    row(1, 3, 22, [0.0; 4], 0.0, 0.0, alt)
}

fn items(i: &Imported) -> Vec<Option<u32>> {
    i.spec.segments.iter().map(SegmentSpec::item).collect()
}

fn kinds(i: &Imported) -> Vec<&'static str> {
    i.spec.segments.iter().map(SegmentSpec::kind).collect()
}

fn warned(i: &Imported, what: &str) -> bool {
    i.warnings.iter().any(|w| w.contains(what))
}

#[test]
fn nav_waypoint_holds_p1_and_keeps_its_acceptance_radius() {
    let i = wpl(&[
        take_off(20.0),
        row(2, 3, 16, [12.0, 3.0, 0.0, 0.0], -35.001, 149.0, 20.0),
    ]);
    assert_eq!(kinds(&i), ["take-off", "leg", "hover"]);
    assert_eq!(items(&i), [Some(1), Some(2), Some(2)]);
    match &i.spec.segments[1] {
        SegmentSpec::Leg {
            latitude_deg,
            altitude_m,
            acceptance_radius_m,
            ground_speed_mps,
            ..
        } => {
            assert_eq!(*latitude_deg, Some(-35.001));
            assert_eq!(*altitude_m, Some(20.0));
            assert_eq!(*acceptance_radius_m, Some(3.0));
            assert_eq!(*ground_speed_mps, None, "the planning speed");
        }
        s => panic!("{s:?}"),
    }
    assert_eq!(
        i.spec.segments[2],
        SegmentSpec::Hover {
            duration_s: 12.0,
            payload_after_kg: None,
            item: Some(2)
        }
    );
    assert!((i.route.hold_s - 12.0).abs() < 1e-12);
    assert_eq!(i.format, SourceFormat::QgcWpl);
    assert!(i.spec.clamp_speeds && i.spec.allow_end_in_air);
}

#[test]
fn take_off_is_vertical_and_px4_then_flies_to_its_position() {
    // ArduPilot (.waypoints): the take-off's position is not flown.
    let ap = wpl(&[row(1, 3, 22, [0.0; 4], -35.01, 149.0, 30.0)]);
    assert_eq!(kinds(&ap), ["take-off"]);
    // PX4 (.plan): climb at home, then to the take-off point.
    let px4 = read_plan(&plan_with(&[simple(
        22,
        3,
        [0.0, 0.0, 0.0, 0.0, -35.01, 149.0, 30.0],
    )]))
    .unwrap();
    assert_eq!(kinds(&px4), ["take-off", "leg"]);
    assert_eq!(items(&px4), [Some(1), Some(1)]);
    assert!(
        (px4.route.horizontal_m - 1109.0).abs() < 2.0,
        "{}",
        px4.route.horizontal_m
    );
    // In the air a take-off is a waypoint.
    let again = wpl(&[
        take_off(20.0),
        row(2, 3, 22, [0.0; 4], -35.001, 149.0, 25.0),
    ]);
    assert_eq!(kinds(&again), ["take-off", "leg"]);
    assert!(warned(
        &again,
        "row 2: TAKEOFF in the air flown as a waypoint"
    ));
}

#[test]
fn land_mid_mission_then_a_waypoint_takes_off_again_from_the_landing_point() {
    let i = wpl(&[
        take_off(30.0),
        row(2, 3, 21, [0.0; 4], -35.001, 149.0, 0.0),
        row(3, 3, 16, [0.0; 4], -35.002, 149.0, 15.0),
        row(4, 0, 20, [0.0; 4], 0.0, 0.0, 0.0),
    ]);
    assert_eq!(
        kinds(&i),
        [
            "take-off", "leg", "descent", "landing", "take-off", "leg", "return", "descent",
            "landing"
        ]
    );
    assert_eq!(items(&i), [1, 2, 2, 2, 3, 3, 4, 4, 4].map(Some));
    // Climb 30 + 15; descent 30 at the landing, 15 at home.
    assert!((i.route.climb_m - 45.0).abs() < 1e-12);
    assert!((i.route.descent_m - 45.0).abs() < 1e-12);
    assert!(warned(
        &i,
        "row 3: command 16 NAV_WAYPOINT on the ground without a take-off"
    ));
    // ArduPilot descends at 1.5 m/s to 10 m, lands at 0.5 m/s.
    assert_eq!(
        i.spec.segments[2],
        SegmentSpec::Descent {
            altitude_m: 10.0,
            rate_mps: 1.5,
            item: Some(2)
        }
    );
    assert_eq!(
        i.spec.segments[3],
        SegmentSpec::Landing {
            rate_mps: 0.5,
            payload_after_kg: None,
            item: Some(2),
            ground_m: None,
        }
    );
}

#[test]
fn return_to_launch_ends_the_route_and_what_follows_is_never_flown() {
    let i = wpl(&[
        take_off(8.0),
        row(2, 0, 20, [0.0; 4], 0.0, 0.0, 0.0),
        row(3, 3, 16, [0.0; 4], -35.002, 149.0, 15.0),
        row(4, 2, 530, [0.0; 4], 0.0, 0.0, 0.0),
    ]);
    assert_eq!(kinds(&i), ["take-off", "return", "landing"]);
    assert_eq!(
        i.spec.segments[1],
        SegmentSpec::Return {
            ground_speed_mps: None,
            altitude_m: None,
            item: Some(2)
        }
    );
    let c = i.counted;
    assert_eq!((c.total, c.flown, c.unreachable), (4, 2, 2));
    assert!(warned(
        &i,
        "rows 3-4 never flown: the route ends at row 2 with the RETURN_TO_LAUNCH"
    ));
}

#[test]
fn loiter_time_and_delays_hover_and_delays_on_the_ground_cost_nothing() {
    let i = wpl(&[
        row(1, 2, 93, [5.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0),
        take_off(10.0),
        row(2, 3, 19, [30.0, 0.0, 0.0, 0.0], -35.001, 149.0, 10.0),
        row(3, 2, 112, [7.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0),
        row(4, 2, 93, [4.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0),
    ]);
    assert_eq!(kinds(&i), ["take-off", "leg", "hover", "hover", "hover"]);
    assert_eq!(items(&i), [1, 2, 2, 3, 4].map(Some));
    assert!((i.route.hold_s - 41.0).abs() < 1e-12);
    assert!(warned(&i, "row 1: delay on the ground: no energy"));
}

#[test]
fn loiter_turns_is_an_orbit_at_the_circle_rate_and_negative_radius_turns_left() {
    let i = wpl(&[
        take_off(20.0),
        row(2, 3, 18, [2.0, 0.0, -10.0, 0.0], -35.001, 149.0, 25.0),
        row(3, 3, 18, [1.0, 0.0, 500.0, 0.0], 0.0, 0.0, 0.0),
    ]);
    match &i.spec.segments[1] {
        SegmentSpec::Orbit {
            radius_m,
            laps,
            direction,
            ground_speed_mps,
            altitude_m,
            item,
            ..
        } => {
            assert_eq!(
                (*radius_m, *laps, *direction),
                (10.0, Some(2.0), OrbitDirection::CounterClockwise)
            );
            // 20 deg/s on 10 m.
            assert!((ground_speed_mps.unwrap() - 10.0 * 20f64.to_radians()).abs() < 1e-12);
            assert_eq!((*altitude_m, *item), (Some(25.0), Some(2)));
        }
        s => panic!("{s:?}"),
    }
    match &i.spec.segments[2] {
        SegmentSpec::Orbit {
            direction,
            ground_speed_mps,
            centre_latitude_deg,
            altitude_m,
            ..
        } => {
            assert_eq!(*direction, OrbitDirection::Clockwise);
            // 20 deg/s on 500 m is 175 m/s: capped at the planning speed (10 m/s).
            assert_eq!(*ground_speed_mps, Some(10.0));
            // Here: the previous centre, at the present height (ArduPilot's altitude 0).
            assert_eq!((*centre_latitude_deg, *altitude_m), (Some(-35.001), None));
        }
        s => panic!("{s:?}"),
    }
    let tau = std::f64::consts::TAU;
    let line = crate::distance_m(
        crate::LatLon {
            latitude_deg: -35.0,
            longitude_deg: 149.0,
        },
        crate::LatLon {
            latitude_deg: -35.001,
            longitude_deg: 149.0,
        },
    );
    let expected = line + 2.0 * tau * 10.0 + tau * 500.0;
    assert!(
        (i.route.horizontal_m - expected).abs() < 1e-6,
        "{}",
        i.route.horizontal_m
    );
}

#[test]
fn loiter_to_alt_flies_level_then_vertically() {
    let i = wpl(&[
        take_off(20.0),
        row(2, 3, 31, [0.0; 4], -35.001, 149.0, 60.0),
    ]);
    assert_eq!(kinds(&i), ["take-off", "leg", "leg"]);
    match (&i.spec.segments[1], &i.spec.segments[2]) {
        (
            SegmentSpec::Leg { altitude_m: a, .. },
            SegmentSpec::Leg {
                altitude_m: b,
                latitude_deg,
                ..
            },
        ) => {
            assert_eq!(
                (*a, *b, *latitude_deg),
                (Some(20.0), Some(60.0), Some(-35.001))
            );
        }
        s => panic!("{s:?}"),
    }
}

#[test]
fn loiter_unlimited_ends_the_route_with_a_loiter_until_the_reserve() {
    let i = wpl(&[
        take_off(20.0),
        row(2, 3, 17, [0.0; 4], -35.001, 149.0, 20.0),
        row(3, 3, 16, [0.0; 4], -35.002, 149.0, 20.0),
    ]);
    assert_eq!(kinds(&i), ["take-off", "leg", "loiter-until-reserve"]);
    assert_eq!(items(&i), [1, 2, 2].map(Some));
    assert!(warned(&i, "row 2: LOITER_UNLIM: the route ends here"));
    assert!(warned(
        &i,
        "row 3 never flown: the route ends at row 2 with the LOITER_UNLIM"
    ));
    assert_eq!(i.counted.unreachable, 1);
}

/// Issue 43 item 3: with `loiter_unlimited_s` (`aloft plan`), the unlimited loiter is a hover
/// of that long at its point and the items after it are flown: the waypoint after it and the
/// landing, nothing unreachable.
#[test]
fn loiter_unlimited_for_a_stated_time_goes_on_with_the_items_after_it() {
    let rows = [
        take_off(20.0),
        row(2, 3, 17, [0.0; 4], -35.001, 149.0, 20.0),
        row(3, 3, 16, [0.0; 4], -35.002, 149.0, 20.0),
        row(4, 3, 21, [0.0; 4], -35.002, 149.0, 0.0),
    ];
    let text = format!("QGC WPL 110\n{HOME}\n{}\n", rows.join("\n"));
    let options = crate::ReadOptions {
        loiter_unlimited_s: Some(90.0),
        ..crate::ReadOptions::default()
    };
    let i = crate::read_waypoints_with(&text, options).unwrap();
    assert_eq!(items(&i), [1, 2, 2, 3, 4, 4].map(Some), "{:?}", kinds(&i));
    assert_eq!(
        kinds(&i),
        ["take-off", "leg", "hover", "leg", "descent", "landing"]
    );
    match i.spec.segments[2] {
        SegmentSpec::Hover { duration_s, .. } => assert!((duration_s - 90.0).abs() < 1e-12),
        ref s => panic!("{s:?}"),
    }
    assert!(warned(&i, "row 2: LOITER_UNLIM: flown as a loiter of 90 s"));
    assert_eq!(i.counted.unreachable, 0);
}

#[test]
fn spline_waypoints_are_flown_straight_with_a_note() {
    let i = wpl(&[
        take_off(20.0),
        row(2, 3, 82, [0.0; 4], -35.001, 149.0, 20.0),
    ]);
    assert_eq!(kinds(&i), ["take-off", "leg"]);
    assert!(warned(
        &i,
        "row 2: SPLINE_WAYPOINT flown as a straight waypoint"
    ));
}

#[test]
fn do_change_speed_sets_the_following_legs_and_minus_one_and_minus_two_keep_and_reset() {
    let wp = |k: u32, lat: f64| row(k, 3, 16, [0.0; 4], lat, 149.0, 20.0);
    let speed = |k: u32, kind: f64, v: f64| row(k, 2, 178, [kind, v, -1.0, 0.0], 0.0, 0.0, 0.0);
    let i = wpl(&[
        take_off(20.0),
        speed(2, 1.0, 12.0),
        wp(3, -35.001),
        speed(4, 1.0, -1.0),
        wp(5, -35.002),
        speed(6, 0.0, 7.0),
        wp(7, -35.003),
        speed(8, 2.0, 3.0),
        wp(9, -35.004),
        speed(10, 1.0, -2.0),
        wp(11, -35.005),
    ]);
    let speeds: Vec<Option<f64>> = i
        .spec
        .segments
        .iter()
        .filter_map(|s| match s {
            SegmentSpec::Leg {
                ground_speed_mps, ..
            } => Some(*ground_speed_mps),
            _ => None,
        })
        .collect();
    assert_eq!(speeds, [Some(12.0), Some(12.0), Some(7.0), Some(7.0), None]);
    assert!(warned(
        &i,
        "row 6: DO_CHANGE_SPEED of the airspeed (p1 0) flown as ground speed"
    ));
    assert!(warned(
        &i,
        "row 8: DO_CHANGE_SPEED of the climb or descent speed"
    ));
    assert_eq!(i.counted.commands, 5);
}

#[test]
fn do_jump_repeats_by_row_index_in_waypoints_and_by_do_jump_id_in_a_plan() {
    let i = wpl(&[
        take_off(20.0),
        row(2, 3, 16, [0.0; 4], -35.001, 149.0, 20.0),
        row(3, 3, 16, [0.0; 4], -35.002, 149.0, 20.0),
        row(4, 2, 177, [2.0, 2.0, 0.0, 0.0], 0.0, 0.0, 0.0),
    ]);
    assert_eq!(items(&i), [1, 2, 3, 2, 3, 2, 3].map(Some));
    assert_eq!(i.counted.commands, 1);
    // In a plan the target is a doJumpId (here 20 on item 2).
    let mut a = simple(16, 3, [0.0, 0.0, 0.0, 0.0, -35.001, 149.0, 20.0]);
    a["doJumpId"] = 20.into();
    let b = simple(16, 3, [0.0, 0.0, 0.0, 0.0, -35.002, 149.0, 20.0]);
    let jump = simple(177, 2, [20.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let p = read_plan(&plan_with(&[
        simple(22, 3, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 20.0]),
        a,
        b,
        jump,
    ]))
    .unwrap();
    assert_eq!(items(&p), [1, 2, 3, 2, 3].map(Some));
}

/// The flying order unrolls the jump (indices into the items, repeated), each item with the
/// segments it made; the take-off the reader adds after a landing and the return's descent and
/// landing are in their item's range; what follows the return is not flown.
#[test]
fn the_flying_order_gives_each_item_flown_its_segments() {
    let i = wpl(&[
        take_off(20.0),
        row(2, 3, 16, [0.0; 4], -35.001, 149.0, 20.0),
        row(3, 2, 178, [1.0, 4.0, 0.0, 0.0], 0.0, 0.0, 0.0),
        row(4, 2, 177, [2.0, 1.0, 0.0, 0.0], 0.0, 0.0, 0.0),
        row(5, 3, 21, [0.0; 4], 0.0, 0.0, 0.0),
        row(6, 3, 16, [0.0; 4], -35.002, 149.0, 15.0),
        row(7, 0, 20, [0.0; 4], 0.0, 0.0, 0.0),
        row(8, 3, 16, [0.0; 4], -35.003, 149.0, 15.0),
    ]);
    let flown: Vec<(usize, std::ops::Range<usize>)> = i
        .flown
        .iter()
        .map(|f| (f.item, f.segments.clone()))
        .collect();
    #[rustfmt::skip]
    assert_eq!(flown, [
        (0, 0..1), (1, 1..2), (2, 2..2), (3, 2..2), // take-off, leg, speed, jump
        (1, 2..3), (2, 3..3), (3, 3..3),            // the loop once more
        (4, 3..5),                                  // land: descent, landing
        (5, 5..7),                                  // take-off added, leg
        (6, 7..10),                                 // return, descent, landing
    ]);
    assert_eq!(i.items[5].seq, 6);
    assert_eq!(items(&i)[5..7], [Some(6), Some(6)]);
    // From a segment back to its item: the leg of the second pass is the item at index 1.
    assert_eq!(i.flown_item(2), Some(&i.flown[4]));
    assert_eq!(i.flown_item(6).map(|f| i.items[f.item].seq), Some(6));
    assert_eq!(i.flown_item(10), None);
    assert_eq!(i.items.len(), 8, "row 8 kept, never flown");
}

#[test]
fn a_gripper_release_drops_the_payload_after_the_last_segment_flown() {
    let i = wpl(&[
        take_off(20.0),
        row(2, 3, 16, [0.0; 4], -35.001, 149.0, 20.0),
        row(3, 2, 211, [1.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0),
    ]);
    match &i.spec.segments[1] {
        SegmentSpec::Leg {
            payload_after_kg, ..
        } => assert_eq!(*payload_after_kg, Some(0.0)),
        s => panic!("{s:?}"),
    }
    // Right after a take-off: a leg of no length carries the release and the gripper's item.
    let j = wpl(&[
        take_off(20.0),
        row(2, 2, 211, [1.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0),
    ]);
    assert_eq!(kinds(&j), ["take-off", "leg"]);
    assert_eq!(items(&j), [Some(1), Some(2)]);
    let grab = wpl(&[
        take_off(20.0),
        row(2, 2, 211, [1.0, 1.0, 0.0, 0.0], 0.0, 0.0, 0.0),
    ]);
    assert!(warned(&grab, "row 2: DO_GRIPPER grab"));
}

#[test]
fn heights_come_from_the_frame_and_p7() {
    let i = wpl(&[
        take_off(20.0),
        // AMSL 130 m with home at 100 m: 30 m.
        row(2, 0, 16, [0.0; 4], -35.001, 149.0, 130.0),
        // Terrain frame: relative, warned.
        row(3, 10, 16, [0.0; 4], -35.002, 149.0, 40.0),
        // AMSL below home: warned, flown at the minimum height.
        row(4, 0, 16, [0.0; 4], -35.003, 149.0, 90.0),
    ]);
    let heights: Vec<Option<f64>> = i
        .spec
        .segments
        .iter()
        .filter_map(|s| match s {
            SegmentSpec::Leg { altitude_m, .. } => Some(*altitude_m),
            _ => None,
        })
        .collect();
    assert_eq!(heights, [Some(30.0), Some(40.0), Some(crate::MIN_HEIGHT_M)]);
    assert!(warned(
        &i,
        "row 3: terrain-relative altitude (frame 10/11) flown as relative"
    ));
    assert!(warned(
        &i,
        "row 4: altitude 90 m above mean sea level is below home (100 m)"
    ));
    assert!(warned(
        &i,
        "row 4: height -10 m above home is not above the ground: flown at 1 m"
    ));
}

#[test]
fn latitude_and_longitude_0_mean_here() {
    let i = wpl(&[
        take_off(20.0),
        row(2, 3, 16, [0.0; 4], -35.001, 149.0, 20.0),
        row(3, 3, 19, [5.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0),
        row(4, 3, 21, [0.0; 4], 0.0, 0.0, 0.0),
    ]);
    // The loiter holds where the waypoint left it; the landing lands there.
    assert_eq!(
        kinds(&i),
        ["take-off", "leg", "hover", "descent", "landing"]
    );
}

#[test]
fn camera_and_mode_items_are_counted_and_unknown_commands_warned_by_item_and_id() {
    let i = wpl(&[
        row(1, 2, 530, [0.0; 4], 0.0, 0.0, 0.0),
        take_off(20.0),
        row(2, 2, 2000, [0.0; 4], 0.0, 0.0, 0.0),
        row(3, 2, 206, [25.0, 0.0, 1.0, 0.0], 0.0, 0.0, 0.0),
        row(4, 2, 31000, [0.0; 4], 0.0, 0.0, 0.0),
        row(5, 2, 205, [0.0; 4], 0.0, 0.0, 0.0),
    ]);
    assert_eq!(kinds(&i), ["take-off"]);
    assert_eq!(
        (i.counted.free, i.counted.unknown, i.counted.flown),
        (4, 1, 1)
    );
    assert!(
        warned(&i, "row 4: unknown command 31000: not flown"),
        "{:?}",
        i.warnings
    );
}

#[test]
fn position_items_need_a_position_frame_and_values_in_range() {
    let bad = |r: String| {
        let t = format!("QGC WPL 110\n{HOME}\n{}\n{r}\n", take_off(10.0));
        read_waypoints(&t).unwrap_err().to_string()
    };
    let e = bad(row(2, 1, 16, [0.0; 4], 10.0, 10.0, 10.0));
    assert!(
        e.starts_with("row 2 (command 16 NAV_WAYPOINT): frame 1 is not supported"),
        "{e}"
    );
    let e = bad(row(2, 2, 16, [0.0; 4], 10.0, 10.0, 10.0));
    assert!(
        e.starts_with("row 2 (command 16 NAV_WAYPOINT): frame 2"),
        "{e}"
    );
    let e = bad(row(2, 3, 16, [0.0; 4], 91.0, 10.0, 10.0));
    assert_eq!(e, "row 2 (command 16 NAV_WAYPOINT): param5 (latitude) = 91 is invalid: expected a latitude within (-90, 90) degrees");
    let e = bad(row(2, 3, 16, [0.0; 4], 1e300, 10.0, 10.0));
    assert!(
        e.contains("row 2") && e.contains("param5 (latitude) = 1e300"),
        "{e}"
    );
    let e = bad(row(2, 3, 16, [0.0; 4], 10.0, -181.0, 10.0));
    assert!(
        e.contains("row 2") && e.contains("param6 (longitude)"),
        "{e}"
    );
    let e = bad(row(2, 3, 84, [0.0; 4], 10.0, 10.0, 10.0));
    assert!(
        e.starts_with("row 2: command 84 NAV_VTOL_TAKEOFF is refused"),
        "{e}"
    );
    let e = bad(row(2, 3, 3000, [0.0; 4], 0.0, 0.0, 0.0));
    assert!(
        e.starts_with("row 2: command 3000 DO_VTOL_TRANSITION is refused"),
        "{e}"
    );
}

#[test]
fn a_jump_loop_beyond_the_limit_is_refused_naming_the_row() {
    let t = format!(
        "QGC WPL 110\n{HOME}\n{}\n{}\n{}\n",
        take_off(10.0),
        row(2, 3, 16, [0.0; 4], -35.001, 149.0, 10.0),
        row(3, 2, 177, [2.0, 50_000.0, 0.0, 0.0], 0.0, 0.0, 0.0)
    );
    let e = read_waypoints(&t).unwrap_err().to_string();
    assert!(
        e.starts_with("row ") && e.contains("repeat more than 20000 items"),
        "{e}"
    );
    let endless = t.replace("50000", "-1");
    let e = read_waypoints(&endless).unwrap_err().to_string();
    assert!(
        e.starts_with("row 3 (command 177 DO_JUMP): param2 repeat count -1"),
        "{e}"
    );
}

#[test]
fn a_file_with_nothing_that_flies_is_refused() {
    let t = format!(
        "QGC WPL 110\n{HOME}\n{}\n",
        row(1, 2, 530, [0.0; 4], 0.0, 0.0, 0.0)
    );
    let e = read_waypoints(&t).unwrap_err();
    assert_eq!(
        e.to_string(),
        "no mission item that flies (1 items read): nothing to plan"
    );
}

// ---- .plan helpers ----

/// A SimpleItem.
pub(crate) fn simple(command: u32, frame: u32, params: [f64; 7]) -> serde_json::Value {
    serde_json::json!({
        "type": "SimpleItem",
        "command": command,
        "frame": frame,
        "params": params,
        "autoContinue": true,
    })
}

/// A PX4 plan with home at (-35, 149, 100 m AMSL) and `items`.
pub(crate) fn plan_with(items: &[serde_json::Value]) -> String {
    serde_json::json!({
        "fileType": "Plan",
        "version": 1,
        "mission": {
            "version": 2,
            "firmwareType": 12,
            "vehicleType": 2,
            "hoverSpeed": 5,
            "plannedHomePosition": [-35.0, 149.0, 100.0],
            "items": items,
        },
    })
    .to_string()
}
