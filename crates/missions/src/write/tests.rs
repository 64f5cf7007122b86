//! The writers' format and refusals, on missions built here.

use serde_json::{json, Value};

use super::*;
use crate::{read_plan, read_waypoints, write_plan, Airspace, PlanHeader};

const NAN: f64 = f64::NAN;

fn item(seq: u32, frame: u32, command: u32, params: [f64; 7]) -> MissionItem {
    MissionItem {
        seq,
        frame,
        command,
        params,
    }
}

fn home() -> Home {
    Home {
        latitude_deg: 47.397_742_1,
        longitude_deg: 8.545_594_3,
        altitude_amsl_m: Some(488.123),
    }
}

fn header() -> PlanHeader {
    PlanHeader {
        firmware_type: Some(12),
        vehicle_type: Some(2),
        cruise_speed_mps: Some(15.0),
        hover_speed_mps: Some(5.5),
        global_plan_altitude_mode: None,
    }
}

/// Take-off, a waypoint with yaw not set (QGroundControl's), a camera mode item with no
/// position, a waypoint at awkward coordinates, a return.
fn mission() -> Vec<MissionEntry> {
    vec![
        item(1, 3, 22, [0.0, 0.0, 0.0, NAN, 0.0, 0.0, 30.0]),
        item(2, 3, 16, [0.0, 0.0, 0.0, NAN, 47.398_1, 8.545_6, 30.0]),
        item(3, 2, 530, [0.0, 2.0, NAN, NAN, NAN, NAN, NAN]),
        item(
            4,
            3,
            16,
            [-0.0, 0.1, 0.0, 0.0, -0.000_000_1, 179.999_999_99, 1e-7],
        ),
        item(5, 2, 20, [0.0; 7]),
    ]
    .into_iter()
    .map(MissionEntry::Item)
    .collect()
}

/// A survey complex item storing `n` waypoints numbered from `first`.
fn survey(first: u32, n: u32) -> Value {
    let items: Vec<Value> = (first..first + n)
        .map(|k| {
            json!({"type": "SimpleItem", "command": 16, "frame": 3, "autoContinue": true,
                "doJumpId": k, "params": [0, 0, 0, null, 47.4 + f64::from(k) * 1e-4, 8.5, 40]})
        })
        .collect();
    json!({"type": "ComplexItem", "complexItemType": "survey", "version": 5,
        "TransectStyleComplexItem": {"Items": items}})
}

fn err(r: Result<String, ImportError>) -> String {
    r.unwrap_err().to_string()
}

/// The bits of each parameter, NaN as one value.
fn bits(items: &[MissionItem]) -> Vec<(u32, u32, u32, [u64; 7])> {
    items
        .iter()
        .map(|i| (i.seq, i.frame, i.command, i.params.map(f64::to_bits)))
        .collect()
}

fn items_of(entries: &[MissionEntry]) -> Vec<MissionItem> {
    entries
        .iter()
        .filter_map(|e| match e {
            MissionEntry::Item(i) => Some(*i),
            MissionEntry::Survey(_) => None,
        })
        .collect()
}

#[test]
fn a_plan_has_the_keys_qgroundcontrol_and_mavsdk_require() {
    let mut entries = mission();
    entries.insert(2, MissionEntry::Survey(survey(3, 4)));
    let text = write_plan(&header(), &home(), &entries, &Airspace::default()).unwrap();
    let root: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(
        (&root["fileType"], &root["version"], &root["groundStation"]),
        (&json!("Plan"), &json!(1), &json!("aloft"))
    );
    assert_eq!(
        root["geoFence"],
        json!({"version": 2, "circles": [], "polygons": []})
    );
    assert_eq!(root["rallyPoints"], json!({"version": 2, "points": []}));
    let m = &root["mission"];
    assert_eq!((&m["version"], &m["firmwareType"]), (&json!(2), &json!(12)));
    assert_eq!(
        (&m["cruiseSpeed"], &m["hoverSpeed"]),
        (&json!(15), &json!(5.5))
    );
    assert!(m.get("globalPlanAltitudeMode").is_none());
    assert_eq!(
        m["plannedHomePosition"],
        json!([47.397_742_1, 8.545_594_3, 488.123])
    );
    let items = m["items"].as_array().unwrap();
    assert_eq!(items.len(), 6);
    assert_eq!(items[2], survey(3, 4), "the survey verbatim");
    // doJumpId: the sequence number, the survey's four stored items counted.
    let ids: Vec<&Value> = items.iter().map(|i| &i["doJumpId"]).collect();
    assert_eq!(ids[..2], [&json!(1), &json!(2)]);
    assert_eq!(ids[3..], [&json!(7), &json!(8), &json!(9)]);
    for i in items.iter().filter(|i| i["type"] == "SimpleItem") {
        assert_eq!(i["params"].as_array().unwrap().len(), 7);
        assert_eq!(i["autoContinue"], json!(true));
    }
    assert_eq!(
        items[3]["params"],
        json!([0, 2, null, null, null, null, null])
    );
    assert_eq!(
        items[4]["params"],
        json!([-0.0, 0.1, 0, 0, -1e-7, 179.99999999, 1e-7])
    );
    assert!(text.ends_with("}\n") && text.contains("\n    \"mission\": {"));
}

#[test]
fn a_plan_reads_back_to_the_last_bit() {
    let entries = mission();
    let text = write_plan(&header(), &home(), &entries, &Airspace::default()).unwrap();
    let back = read_plan(&text).unwrap();
    assert_eq!(bits(&back.items), bits(&items_of(&entries)));
    assert_eq!(back.home, Some(home()));
    assert_eq!(back.plan.unwrap().header, header());
    // Without a header or a home altitude: firmwareType 0, the optional keys left out.
    let bare = Home {
        altitude_amsl_m: None,
        ..home()
    };
    let text = write_plan(
        &PlanHeader::default(),
        &bare,
        &entries,
        &Airspace::default(),
    )
    .unwrap();
    let root: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(root["mission"]["firmwareType"], json!(0));
    assert_eq!(root["mission"]["plannedHomePosition"][2], Value::Null);
    assert!(root["mission"].get("hoverSpeed").is_none());
    assert_eq!(read_plan(&text).unwrap().home, Some(bare));
}

#[test]
fn waypoints_rows_are_mission_planner_s_with_nan_parameters_written_nan() {
    let text = write_waypoints(&home(), &mission()).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[..2],
        [
            "QGC WPL 110",
            "0\t1\t0\t16\t0\t0\t0\t0\t47.3977421\t8.5455943\t488.123\t1"
        ]
    );
    assert_eq!(
        lines[1 + 2],
        "2\t0\t3\t16\t0\t0\t0\tNaN\t47.3981\t8.5456\t30\t1"
    );
    // An item without a position: its unset latitude, longitude, altitude are 0.
    assert_eq!(lines[1 + 3], "3\t0\t2\t530\t0\t2\tNaN\tNaN\t0\t0\t0\t1");
    assert_eq!(
        lines[1 + 4],
        "4\t0\t3\t16\t-0\t0.1\t0\t0\t-0.0000001\t179.99999999\t0.0000001\t1"
    );
    assert!(lines
        .iter()
        .all(|l| l.split('\t').count() == 12 || *l == lines[0]));
    assert!(text.ends_with("\t1\n"));
    // Read back: every value to the last bit, NaN P1-P4 as not set; the camera item's
    // position 0 (not set, as written).
    let back = read_waypoints(&text).unwrap();
    let mut want = items_of(&mission());
    want[2].params[4..].copy_from_slice(&[0.0; 3]);
    assert_eq!(bits(&back.items), bits(&want));
    assert_eq!(back.home, Some(home()));
}

#[test]
fn a_do_jump_is_refused_by_both_writers_naming_the_item() {
    let mut entries = mission();
    entries.insert(
        3,
        MissionEntry::Item(item(9, 2, 177, [2.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0])),
    );
    let want = "item 9: command 177 DO_JUMP is refused: the writers write jump-free missions";
    let e = err(write_plan(
        &header(),
        &home(),
        &entries,
        &Airspace::default(),
    ));
    assert!(e.starts_with(want), "{e}");
    let e = err(write_waypoints(&home(), &entries));
    assert!(e.starts_with(want), "{e}");
}

#[test]
fn a_survey_is_refused_in_waypoints_and_must_be_a_survey_in_a_plan() {
    let mut entries = mission();
    entries.insert(2, MissionEntry::Survey(survey(3, 4)));
    let e = err(write_waypoints(&home(), &entries));
    assert!(
        e.starts_with(
            "item 3: ComplexItem survey is refused: a .waypoints file holds mission items only"
        ),
        "{e}"
    );
    let mut corridor = survey(3, 4);
    corridor["complexItemType"] = json!("CorridorScan");
    entries[2] = MissionEntry::Survey(corridor);
    let e = err(write_plan(
        &header(),
        &home(),
        &entries,
        &Airspace::default(),
    ));
    assert!(e.starts_with("item 3: key (survey entry) is {"), "{e}");
}

#[test]
fn nan_coordinates_and_infinite_values_are_refused() {
    for (k, key) in [
        (4, "param5 (latitude)"),
        (5, "param6 (longitude)"),
        (6, "param7 (altitude)"),
    ] {
        let mut entries = mission();
        if let MissionEntry::Item(i) = &mut entries[1] {
            i.params[k] = NAN;
        }
        let want = format!("item 2 (command 16 NAV_WAYPOINT): {key} = NaN is invalid");
        for e in [
            err(write_plan(
                &header(),
                &home(),
                &entries,
                &Airspace::default(),
            )),
            err(write_waypoints(&home(), &entries)),
        ] {
            assert!(e.starts_with(&want), "{e}");
        }
    }
    let mut entries = mission();
    if let MissionEntry::Item(i) = &mut entries[2] {
        i.params[0] = f64::INFINITY;
    }
    let e = err(write_plan(
        &header(),
        &home(),
        &entries,
        &Airspace::default(),
    ));
    assert!(e.starts_with("item 3 (command 530"), "{e}");
    assert!(e.contains("param1 = inf is invalid"), "{e}");
    // The home: coordinates set and in range; an altitude for a .waypoints home row.
    let nowhere = Home {
        latitude_deg: NAN,
        ..home()
    };
    let e = err(write_plan(
        &header(),
        &nowhere,
        &mission(),
        &Airspace::default(),
    ));
    assert_eq!(
        e,
        "home: latitude = NaN is invalid: expected a latitude within (-90, 90) degrees"
    );
    let east = Home {
        longitude_deg: 181.0,
        ..home()
    };
    assert!(err(write_waypoints(&east, &mission())).starts_with("home: longitude = 181"));
    let unknown = Home {
        altitude_amsl_m: None,
        ..home()
    };
    let e = err(write_waypoints(&unknown, &mission()));
    assert!(
        e.starts_with("home: altitude above mean sea level = NaN"),
        "{e}"
    );
    let mut slow = header();
    slow.hover_speed_mps = Some(0.0);
    let e = err(write_plan(&slow, &home(), &mission(), &Airspace::default()));
    assert!(e.starts_with("file: key mission.hoverSpeed is 0"), "{e}");
}

/// A file without a home row is written back without one; with one, its home is row 0.
#[test]
fn write_like_source_keeps_a_file_s_own_home_row_or_its_absence() {
    let t = "QGC WPL 110\n0\t0\t3\t22\t0\t0\t0\t0\t37.40306\t-122.0779\t10\t1\n\
             1\t0\t3\t16\t0\t0\t0\t0\t37.40326\t-122.0777\t20\t1\n2\t0\t3\t21\t0\t0\t0\t0\t0\t0\t0\t1\n";
    let i = read_waypoints(t).unwrap();
    assert_eq!(i.home, None);
    let written = write_like_source(&i).unwrap();
    assert_eq!(written, t);
    let back = read_waypoints(&written).unwrap();
    assert_eq!(back.spec, i.spec);
    assert_eq!(back.warnings, i.warnings);
}
