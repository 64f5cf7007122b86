//! The twelve real mission files in `ALOFT_DATA_DIR/missions` (QGroundControl `.plan`,
//! Mission Planner / ArduPilot `.waypoints`; never copied into the repository), each with its
//! documented answer: a refusal naming the item, or route figures and a flight through
//! `aloft::engine::plan_mission` with the dji-m100.
//!
//! The expected route figures are computed here, from the raw file values parsed in this test
//! (serde_json for a `.plan`, tab splitting for a `.waypoints`), with this test's own distance:
//! per leg, the plane tangent at the leg's mid-latitude with the WGS-84 radii of curvature
//! (`east = dlon N cos(lat)`, `north = dlat M`). Its error against the true geodesic is of the
//! order of `(d / R)^2`, below 2e-7 for these legs (the longest, 2.6 km); aloft measures legs with
//! Vincenty's formula, so the tolerance is 1e-4 relative (a tenth of a metre on a kilometre).
//! Heights are sums of exact file values: 1e-9 m.

use crate::common;
use common::{assert_warned, data_dir};

use std::path::PathBuf;

use aloft::engine::{
    plan_mission, ItemCounts, Mission, MissionOptions, Plan, SourceFormat, Vehicle,
};
use serde_json::Value;

fn path(name: &str) -> PathBuf {
    data_dir().join("missions").join(name)
}

fn text(name: &str) -> String {
    std::fs::read_to_string(path(name)).unwrap()
}

fn load(name: &str) -> Mission {
    Mission::load(Some(&path(name))).unwrap()
}

// ---- This test's own geometry ----

/// WGS-84 semi-major axis, m, and first eccentricity squared.
const A_M: f64 = 6_378_137.0;
const E2: f64 = 6.694_379_990_14e-3;

/// A point, degrees.
type Ll = (f64, f64);

/// One leg in the plane tangent at its mid-latitude (see the module docs).
fn leg_m(a: Ll, b: Ll) -> f64 {
    let lat = (0.5 * (a.0 + b.0)).to_radians();
    let w = (1.0 - E2 * lat.sin().powi(2)).sqrt();
    let n = A_M / w;
    let m = A_M * (1.0 - E2) / (w * w * w);
    let east = (b.1 - a.1).to_radians() * n * lat.cos();
    let north = (b.0 - a.0).to_radians() * m;
    east.hypot(north)
}

/// The length of the polyline through `points`, m.
fn path_m(points: &[Ll]) -> f64 {
    points.windows(2).map(|w| leg_m(w[0], w[1])).sum()
}

fn close(actual: f64, expected: f64, rel: f64, what: &str) {
    assert!(
        (actual - expected).abs() <= rel * expected.abs() + 1e-9,
        "{what}: aloft {actual}, expected {expected}"
    );
}

/// The route figures against the expected path, climb, descent and hold.
fn check_route(m: &Mission, points: &[Ll], extra_m: f64, climb_m: f64, descent_m: f64) {
    let r = m.route();
    close(
        r.horizontal_m,
        path_m(points) + extra_m,
        1e-4,
        "horizontal_m",
    );
    close(r.climb_m, climb_m, 1e-12, "climb_m");
    close(r.descent_m, descent_m, 1e-12, "descent_m");
    close(r.hold_s, 0.0, 0.0, "hold_s");
}

// ---- Raw file values ----

/// The `.plan` `name` as aloft loads it, and its raw values: home and items as [`plan_items`].
fn plan_file(name: &str) -> (Mission, Ll, Vec<Value>) {
    let (home, items) = plan_items(name);
    (load(name), home, items)
}

/// A `.plan`: its home `[lat, lon]` and its items flattened (surveys' stored items in order).
fn plan_items(name: &str) -> (Ll, Vec<Value>) {
    let v: Value = serde_json::from_str(&text(name)).unwrap();
    let m = &v["mission"];
    let h = &m["plannedHomePosition"];
    let mut out = Vec::new();
    for it in m["items"].as_array().unwrap() {
        match it["TransectStyleComplexItem"]["Items"].as_array() {
            Some(inner) => out.extend(inner.iter().cloned()),
            None => out.push(it.clone()),
        }
    }
    ((h[0].as_f64().unwrap(), h[1].as_f64().unwrap()), out)
}

fn command(item: &Value) -> u64 {
    item["command"].as_u64().unwrap()
}

fn latlon(item: &Value) -> Ll {
    let p = &item["params"];
    (p[4].as_f64().unwrap(), p[5].as_f64().unwrap())
}

/// A `.waypoints` file's rows: 12 numbers each.
fn wpl_rows(name: &str) -> Vec<Vec<f64>> {
    text(name)
        .lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<f64> = l
                .trim_end()
                .split('\t')
                .map(|x| x.parse().unwrap())
                .collect();
            assert_eq!(f.len(), 12);
            f
        })
        .collect()
}

fn row_ll(r: &[f64]) -> Ll {
    (r[8], r[9])
}

// ---- Flying ----

fn m100() -> Vehicle {
    Vehicle::builtin("dji-m100").unwrap()
}

fn fly(vehicle: &Vehicle, m: &Mission) -> Plan {
    plan_mission(vehicle, m, &MissionOptions::default()).unwrap()
}

/// Every segment carries an item number, and in order they are `items`, but for the way home a
/// route that ends in the air is flown with (a return and a landing of no item, and a warning
/// that says so); the answer's route is the mission's; energy and time are positive; a feasible
/// plan takes one battery.
fn check_flight(plan: &Plan, m: &Mission, items: &[u32]) {
    let s = plan.summary();
    let ends_in_air = m
        .route()
        .warnings
        .iter()
        .any(|w| w.contains("the route ends in the air"));
    let (own, added) = s
        .segments
        .split_at(s.segments.len() - if ends_in_air { 2 } else { 0 });
    let got: Vec<u32> = own.iter().map(|x| x.item.expect("an item")).collect();
    assert_eq!(got, items);
    if ends_in_air {
        let kinds: Vec<(&str, Option<u32>)> =
            added.iter().map(|x| (x.kind.as_str(), x.item)).collect();
        assert_eq!(kinds, [("return", None), ("landing", None)]);
        assert_warned(&s.warnings, "priced with the way home an autopilot flies");
    }
    assert_eq!(&s.route, m.route());
    assert!(s.energy_wh > 0.0 && s.duration_s > 0.0);
    if s.feasible {
        assert_eq!(s.batteries_required, Some(1));
    }
}

fn counts(total: usize, flown: usize, commands: usize, free: usize) -> Option<ItemCounts> {
    Some(ItemCounts {
        total,
        flown,
        commands,
        free,
        unknown: 0,
        unreachable: 0,
    })
}

// ---- The files ----

/// Survey v5 over a concave polygon: TAKEOFF to 50 m at home, 52 survey waypoints at 50 m
/// interleaved with 15 camera triggers (and a camera mode item first), RTL.
#[test]
fn data_val_neilvaltec_survey_plan() {
    let (m, home, items) = plan_file("neilvaltec_test.plan");
    assert_eq!(m.route().source_format, SourceFormat::QgcPlan);
    let wps: Vec<(u32, Ll)> = (1u32..)
        .zip(&items)
        .filter(|(_, it)| command(it) == 16)
        .map(|(k, it)| (k, latlon(it)))
        .collect();
    assert_eq!(wps.len(), 52);
    let mut points = vec![home];
    points.extend(wps.iter().map(|w| w.1));
    points.push(home);
    check_route(&m, &points, 0.0, 50.0, 50.0);
    assert_eq!(m.route().items, counts(70, 54, 0, 16));
    assert!(m.route().warnings.is_empty(), "{:?}", m.route().warnings);
    assert_eq!(m.spec().default_speed_mps, Some(5.0), "hoverSpeed");
    // Item numbers: the take-off is item 2, each waypoint its place in the flattened list (QGC's
    // doJumpId agrees), the RTL item 70 (return, descent below 10 m, landing).
    for (k, it) in (1u32..).zip(&items) {
        assert_eq!(it["doJumpId"].as_u64(), Some(u64::from(k)));
    }
    let mut expected = vec![2];
    expected.extend(wps.iter().map(|w| w.0));
    expected.extend([70, 70, 70]);
    let plan = fly(&m100(), &m);
    check_flight(&plan, &m, &expected);
    let s = plan.summary();
    println!(
        "neilvaltec: feasible {}, {:.1} Wh, {:.0} s",
        s.feasible, s.energy_wh, s.duration_s
    );
    // With 1 kg of payload one pack is not enough: sorties in item order, covering the route.
    let heavy = MissionOptions {
        payload_kg: Some(1.0),
        ..MissionOptions::default()
    };
    let p = plan_mission(&m100(), &m, &heavy).unwrap();
    let h = p.summary();
    assert!(!h.feasible);
    let n = h.batteries_required.expect("split into sorties");
    assert!(n >= 2 && n as usize == h.sorties.len(), "{n}");
    assert_eq!(h.sorties[0].first_item, Some(2));
    assert_eq!(h.sorties[h.sorties.len() - 1].last_item, Some(70));
    for w in h.sorties.windows(2) {
        assert!(w[0].last_item < w[1].first_item);
    }
}

/// PX4 test field: TAKEOFF 20 m at home, 5 waypoints at 20 m, RTL in frame 2.
#[test]
fn data_val_kasperg3_uas_test_plan() {
    let (m, home, items) = plan_file("kasperg3_uas_test_plan.plan");
    let mut points = vec![home];
    points.extend(items.iter().filter(|i| command(i) == 16).map(latlon));
    points.push(home);
    assert_eq!(points.len(), 7);
    check_route(&m, &points, 0.0, 20.0, 20.0);
    assert_eq!(m.route().items, counts(7, 7, 0, 0));
    let plan = fly(&m100(), &m);
    check_flight(&plan, &m, &[1, 2, 3, 4, 5, 6, 7, 7, 7]);
    assert!(plan.summary().feasible);
}

/// ArduPilot, 14 waypoints at 50 m, no take-off, no landing: a vertical take-off is added at
/// home and the route ends in the air (no return).
#[test]
fn data_val_kasperg3_mission_ends_in_the_air() {
    let (m, home, items) = plan_file("kasperg3_mission.plan");
    let mut points = vec![home];
    points.extend(items.iter().map(latlon));
    assert_eq!(points.len(), 15);
    check_route(&m, &points, 0.0, 50.0, 0.0);
    assert_eq!(m.route().items, counts(14, 14, 0, 0));
    let w = m.route().warnings.join("\n");
    assert!(
        w.contains("item 1: command 16 NAV_WAYPOINT on the ground"),
        "{w}"
    );
    assert!(w.contains("ends in the air"), "{w}");
    let plan = fly(&m100(), &m);
    // The added take-off carries item 1; a waypoint that repeats the point before it (the
    // first is home itself) is a leg of no length, which the planner does not report.
    let mut expected = vec![1];
    let mut previous = home;
    for (k, it) in (1u32..).zip(&items) {
        if latlon(it) != previous {
            expected.push(k);
        }
        previous = latlon(it);
    }
    assert_eq!(expected.len(), 12);
    check_flight(&plan, &m, &expected);
    // The way home is flown from the last waypoint: its return covers the distance from there
    // to home (the leg in the tangent plane, as the route figures), and it lands 50 m. With
    // pass-through corners the corner at the last waypoint cuts it short; stopping there, not.
    let stop = aloft::engine::MissionOptions {
        corners: Some(aloft::engine::CornerMode::Stop),
        ..Default::default()
    };
    let plan = aloft::engine::plan_mission(&m100(), &m, &stop).unwrap();
    let segs = &plan.summary().segments;
    let (ret, land) = (&segs[segs.len() - 2], &segs[segs.len() - 1]);
    let back = leg_m(latlon(items.last().unwrap()), home);
    close(ret.distance_m, back, 1e-3, "return distance");
    close(land.distance_m, 50.0, 1e-9, "landing distance");
    assert_eq!(plan.summary().batteries_required, Some(1));
}

/// A waypoint at 5 m, LAND mid-mission, DO_GRIPPER on the ground, a waypoint at 10 m: a second
/// take-off from the landing point; the payload is released at the landing.
#[test]
fn data_val_px4_triangle_gripper_delivery() {
    let (m, home, items) = plan_file("px4_triangle_gripper_package_delivery.plan");
    let points = [
        home,
        latlon(&items[0]),
        latlon(&items[1]),
        latlon(&items[3]),
    ];
    check_route(&m, &points, 0.0, 5.0 + 10.0, 5.0);
    assert_eq!(m.route().items, counts(4, 3, 1, 0));
    let release = m.spec().segments.iter().find_map(|s| match s {
        aloft_planner::SegmentSpec::Landing {
            payload_after_kg, ..
        } => *payload_after_kg,
        _ => None,
    });
    assert_eq!(release, Some(0.0));
    let options = MissionOptions {
        payload_kg: Some(0.5),
        ..MissionOptions::default()
    };
    let plan = plan_mission(&m100(), &m, &options).unwrap();
    // Take-off (item 1), leg 1, leg to the landing point (2), landing (2), take-off (4), leg 4.
    check_flight(&plan, &m, &[1, 1, 2, 2, 4, 4]);
    assert_eq!(plan.summary().payload_kg, 0.5);
}

/// Hand-made: vehicleType 1, TAKEOFF to 45.258 m at a point 1.2 km from home (PX4 climbs at
/// home, then flies there), a waypoint at 0 m (flown at 1 m), DO_CHANGE_SPEED 25 m/s (beyond
/// the M100: clamped), LAND at a point.
#[test]
fn data_val_droneicarus_hand_made_plan() {
    let (m, home, items) = plan_file("droneicarus_test7-Mission_avec_parametre.plan");
    let takeoff = items[0]["params"][6].as_f64().unwrap();
    let points = [
        home,
        latlon(&items[0]),
        latlon(&items[1]),
        latlon(&items[3]),
    ];
    assert!(path_m(&points) > 7_000.0);
    check_route(&m, &points, 0.0, takeoff, takeoff);
    assert_eq!(m.route().items, counts(4, 3, 1, 0));
    let w = m.route().warnings.join("\n");
    assert!(w.contains("vehicleType 1"), "{w}");
    assert!(w.contains("item 2: height 0 m above home is not above the ground: flown at 1 m"));
    let plan = fly(&m100(), &m);
    // Take-off and the leg to its point (1), the waypoint (2), the leg to the landing point at
    // 1 m and the landing (4; below 10 m there is no separate descent).
    check_flight(&plan, &m, &[1, 1, 2, 4, 4]);
    let s = plan.summary();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("item 4") && w.contains("25 m/s")),
        "{:?}",
        s.warnings
    );
}

/// Malformed and VTOL: refused, naming the item and the missing keys.
#[test]
fn data_val_wolkstein_malformed_vtol_plan_is_refused() {
    let e = Mission::load(Some(&path("wolkstein_vtol_mission.plan"))).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains(
            "item 1 (command 22 NAV_TAKEOFF): missing keys \"type\", \"frame\", \"autoContinue\""
        ),
        "{msg}"
    );
}

/// QGC WPL 110 with DO_CHANGE_SPEED (ground speed) 15, 10 and 17 m/s between waypoints.
#[test]
fn data_val_ardupilot_do_change_speed_waypoints() {
    let name = "ardupilot_DO_CHANGE_SPEED_mission.txt";
    let rows = wpl_rows(name);
    let m = load(name);
    assert_eq!(m.route().source_format, SourceFormat::QgcWpl);
    let home = row_ll(&rows[0]);
    let wps: Vec<&Vec<f64>> = rows.iter().filter(|r| r[3] == 16.0 && r[0] > 0.0).collect();
    let mut points = vec![home];
    points.extend(wps.iter().map(|r| row_ll(r)));
    points.push(home);
    // Take-off to 20 m, then 20, 14, 18, 20 m, home at 20 m and down.
    let heights: Vec<f64> = wps.iter().map(|r| r[10]).collect();
    assert_eq!(heights, [20.0, 14.0, 18.0, 20.0]);
    check_route(&m, &points, 0.0, 20.0 + 4.0 + 2.0, 6.0 + 20.0);
    assert_eq!(m.route().items, counts(9, 6, 3, 0));
    // The speeds the legs after each DO_CHANGE_SPEED fly, in the spec.
    let speeds: Vec<Option<f64>> = m
        .spec()
        .segments
        .iter()
        .filter_map(|s| match s {
            aloft_planner::SegmentSpec::Leg {
                ground_speed_mps, ..
            } => Some(*ground_speed_mps),
            _ => None,
        })
        .collect();
    assert_eq!(speeds, [None, Some(15.0), Some(10.0), Some(17.0)]);
    let plan = fly(&m100(), &m);
    check_flight(&plan, &m, &[1, 2, 4, 6, 8, 9, 9, 9]);
}

/// The stock M100 cannot hold 17 m/s within its 35 deg tilt limit (by its own drag model it
/// needs 35.1 deg at 17 m/s in still air, and 35.4 deg accelerating to 16 m/s at 2 m/s^2): a
/// planner file asking for more is flown at the highest speed it can reach within the limit,
/// with a warning. That speed is found here independently, by bisection on the level-flight
/// tilt `tan(tilt) = (m a + f_D(v)) / (m g)` with the vehicle file's constants (2.355 kg, drag
/// of power seed Fig. 3 scaled to the air of the file's home altitude, 2 m/s^2) and the
/// planner's quarter degree of margin; the planner scans in 0.01 m/s steps, so the two agree to
/// 0.01 m/s.
#[test]
fn speeds_beyond_the_tilt_limit_fly_at_the_tilt_limited_speed() {
    let (m, g, a) = (2.355f64, 9.80665f64, 2.0f64);
    let budget = m * g * (35.0f64 - 0.25).to_radians().tan() - m * a;
    for file in [
        "ardupilot_DO_CHANGE_SPEED_mission.txt",
        "droneicarus_test7-Mission_avec_parametre.plan",
    ] {
        let mission = load(file);
        // The mission flies in ISA air at its home altitude (issue 34): body drag scales with
        // the density, rho = p / (R T) with T = 288.15 - 0.0065 h, p = 101325 (T/288.15)^5.2559.
        let h = mission.spec().home.altitude_amsl_m.unwrap_or(0.0);
        let t = 288.15 - 0.0065 * h;
        let rho = 101_325.0 * (t / 288.15f64).powf(9.80665 / (287.053 * 0.0065)) / (287.053 * t);
        let drag = |v: f64| rho / 1.225 * v * (0.1816 + v * (-0.02326 + v * 0.004045));
        let (lo, _) = aloft_core::bisect(0.0, 17.0, 60, |v| drag(v) <= budget);
        let plan = fly(&m100(), &mission);
        let warning = plan
            .summary()
            .warnings
            .iter()
            .find(|w| w.contains("tilt limit"))
            .unwrap_or_else(|| panic!("{file}: no clamp warning in {:?}", plan.summary().warnings));
        let flown: f64 = warning
            .rsplit("flown at ")
            .next()
            .and_then(|x| x.trim_end_matches(" m/s").parse().ok())
            .unwrap();
        assert!(
            flown <= lo && lo - flown < 0.01 + 1e-9,
            "{file}: {flown} against {lo}"
        );
    }
}

/// CRLF; LOITER_TURNS at home at the present height (lat/lon 0, altitude 0), then 2 turns of
/// 5 m at 25 m and 1 turn of 10 m at 30 m; LAND here.
#[test]
fn data_val_ardupilot_loiter_turns_waypoints() {
    let name = "ardupilot_copter_loiterturns_mission.txt";
    assert!(text(name).contains("\r\n"));
    let rows = wpl_rows(name);
    let m = load(name);
    let home = row_ll(&rows[0]);
    let points = [home, row_ll(&rows[3]), row_ll(&rows[4])];
    let tau = std::f64::consts::TAU;
    let circles = 1.0 * tau * 5.0 + 2.0 * tau * 5.0 + 1.0 * tau * 10.0;
    check_route(&m, &points, circles, 30.0, 30.0);
    assert_eq!(m.route().items, counts(5, 5, 0, 0));
    let plan = fly(&m100(), &m);
    check_flight(&plan, &m, &[1, 2, 3, 4, 5, 5]);
    assert!(plan.summary().feasible);
}

/// Mission Planner export: home AMSL 0, four waypoints in frame 0 at 5 m AMSL (5 m above home),
/// no take-off (added), no landing (ends in the air).
#[test]
fn data_val_uas_lol_mission3_amsl_waypoints() {
    let name = "uas_lol_mission3.waypoints";
    let rows = wpl_rows(name);
    let m = load(name);
    assert!(rows[1..].iter().all(|r| r[2] == 0.0 && r[10] == 5.0));
    let points: Vec<Ll> = rows.iter().map(|r| row_ll(r)).collect();
    check_route(&m, &points, 0.0, 5.0, 0.0);
    assert_eq!(m.route().items, counts(4, 4, 0, 0));
    let plan = fly(&m100(), &m);
    check_flight(&plan, &m, &[1, 1, 2, 3, 4]);
}

/// TAKEOFF here to 5 m, two waypoints, RTL carrying lat/lon 0 and an unused altitude.
#[test]
fn data_val_uas_lol_mission6_waypoints() {
    let name = "uas_lol_mission6.waypoints";
    let rows = wpl_rows(name);
    let m = load(name);
    let home = row_ll(&rows[0]);
    let points = [home, row_ll(&rows[2]), row_ll(&rows[3]), home];
    check_route(&m, &points, 0.0, 5.0, 5.0);
    let plan = fly(&m100(), &m);
    check_flight(&plan, &m, &[1, 2, 3, 4, 4]);
    assert!(plan.summary().feasible);
}

/// Quadplane: NAV_VTOL_TAKEOFF at row 1: refused naming the row and the command.
#[test]
fn data_val_uas_lol_mission8_vtol_is_refused_naming_the_row() {
    let e = Mission::load(Some(&path("uas_lol_mission8.waypoints"))).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("row 1: command 84 NAV_VTOL_TAKEOFF is refused"),
        "{msg}"
    );
}

/// Script-written: row 0 is a TAKEOFF (not a home row) and is flown as item 0; home is its
/// position; a square at 20 m; LAND.
#[test]
fn data_val_brucdeng_takeoff_in_row_0() {
    let name = "brucdeng_aircart_mission.waypoints";
    let rows = wpl_rows(name);
    assert_eq!(rows[0][3], 22.0);
    let m = load(name);
    let points: Vec<Ll> = rows[1..6].iter().map(|r| row_ll(r)).collect();
    check_route(&m, &points, 0.0, 20.0, 20.0);
    assert_eq!(m.route().items, counts(7, 7, 0, 0));
    let plan = fly(&m100(), &m);
    check_flight(&plan, &m, &[0, 1, 2, 3, 4, 5, 6, 6]);
    assert!(plan.summary().feasible);
}

/// Every file in the folder has a test above (a new file fails here until it gets one).
#[test]
fn data_val_every_shared_mission_file_is_covered() {
    let mut names: Vec<String> = std::fs::read_dir(data_dir().join("missions"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "README.md")
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "ardupilot_DO_CHANGE_SPEED_mission.txt",
            "ardupilot_copter_loiterturns_mission.txt",
            "brucdeng_aircart_mission.waypoints",
            "droneicarus_test7-Mission_avec_parametre.plan",
            "kasperg3_mission.plan",
            "kasperg3_uas_test_plan.plan",
            "neilvaltec_test.plan",
            "px4_triangle_gripper_package_delivery.plan",
            "uas_lol_mission3.waypoints",
            "uas_lol_mission6.waypoints",
            "uas_lol_mission8.waypoints",
            "wolkstein_vtol_mission.plan",
        ]
    );
}
