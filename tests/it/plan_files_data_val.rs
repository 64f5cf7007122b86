//! `aloft plan` on the shared operator files (issue 33, "How it is checked"): every shared
//! `.plan` and `.waypoints` mission aloft reads, in still air and in 8 and 12 m/s winds from
//! several directions, at the default reserve and at a 70 % reserve that makes the survey need
//! several packs.
//!
//! For each plan:
//! - every file is in the input's format and, read back by `aloft mission` in the same
//!   conditions, keeps the reserve with the energy the plan gives its sortie (1e-9 relative);
//! - the plan needs no more batteries and no more energy than the mission as given;
//! - geometry, from the files' items alone (an independent reading of MAV_CMD semantics, not
//!   aloft's): every metre of the input's camera-on legs (DO_SET_CAM_TRIGG_DIST 206 with a
//!   distance in force) lies within 1.5 m of a camera-on leg of some sortie; a sortie that
//!   resumes flies out with the camera off (a 206 with 0 before its first waypoint), and every
//!   sortie stops the camera before its return to launch (QGroundControl #5737);
//! - a sortie file holds no DO_JUMP (loops are unrolled).
//!
//! A plan that cannot keep the reserve is exit 1 with a reason and no file written.

use crate::common;

use std::path::{Path, PathBuf};

use aloft_missions::{import, MissionItem};
use common::{run, scratch};
use serde_json::Value;

/// The winds: (speed m/s, from deg).
const WINDS: [(f64, f64); 5] = [
    (0.0, 0.0),
    (8.0, 0.0),
    (8.0, 135.0),
    (12.0, 270.0),
    (12.0, 45.0),
];

/// The shared planner files aloft plans (the VTOL ones are refused by `aloft mission` too).
fn shared_planner_files() -> Vec<PathBuf> {
    let files = common::files("missions", |n| {
        n.ends_with(".plan") || n.ends_with(".waypoints") || n.ends_with(".txt")
    });
    assert!(files.len() >= 10, "the shared missions: {files:?}");
    files
}

/// The shared mission file `name` (`missions/`), which must be there.
fn shared_mission(name: &str) -> PathBuf {
    let path = common::data_dir().join("missions").join(name);
    assert!(path.is_file(), "{name} in the shared missions");
    path
}

/// The shared survey `neilvaltec_test.plan` with its polygon scaled 2 times (about 20 km of
/// flight), written as the scratch file `name`.
fn survey_20km(name: &str) -> PathBuf {
    let file = scratch("plan-files", name);
    std::fs::write(
        &file,
        common::big_survey::scaled_survey(&shared_mission("neilvaltec_test.plan"), 2.0),
    )
    .unwrap();
    file
}

/// `aloft plan FILE -o DIR --format json EXTRA`: exit code, JSON, stderr.
fn plan(file: &Path, dir: &Path, extra: &[String]) -> (i32, Value, String) {
    let _ = std::fs::remove_dir_all(dir);
    let (f, d) = (file.display().to_string(), dir.display().to_string());
    let mut args = vec!["plan", f.as_str(), "-o", d.as_str(), "--format", "json"];
    args.extend(extra.iter().map(String::as_str));
    let (code, out, err) = run(&args);
    let json = serde_json::from_str(&out).unwrap_or(Value::Null);
    (code, json, err)
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// A leg flown with the camera on or off, in metres east and north of a reference point.
#[derive(Debug, Clone, Copy)]
struct Leg {
    from: [f64; 2],
    to: [f64; 2],
    camera: bool,
}

/// Metres east and north of `origin` (a local equirectangular projection: the surveys span a
/// few hundred metres, where it is within millimetres of the tangent plane).
fn local_m(origin: [f64; 2], lat: f64, lon: f64) -> [f64; 2] {
    const R: f64 = 6_371_008.8;
    let north = (lat - origin[0]).to_radians() * R;
    let east = (lon - origin[1]).to_radians() * R * origin[0].to_radians().cos();
    [east, north]
}

/// Whether a command flies to the position in its params 5 and 6.
fn flies_to(command: u32) -> bool {
    matches!(command, 16..=19 | 21 | 22 | 31 | 82)
}

/// The legs of `items` (in file order, home first), each with the camera state it is flown in
/// (the last DO_SET_CAM_TRIGG_DIST before it: on when its distance is positive), and the index
/// of each DO_SET_CAM_TRIGG_DIST and of the first return to launch.
fn legs(origin: [f64; 2], home: [f64; 2], items: &[MissionItem]) -> Vec<Leg> {
    let mut at = local_m(origin, home[0], home[1]);
    let mut camera = false;
    let mut out = Vec::new();
    for it in items {
        if it.command == 206 {
            camera = it.params[0] > 0.0;
        }
        let (lat, lon) = (it.params[4], it.params[5]);
        if flies_to(it.command) && lat.is_finite() && lon.is_finite() && (lat, lon) != (0.0, 0.0) {
            let to = local_m(origin, lat, lon);
            out.push(Leg {
                from: at,
                to,
                camera,
            });
            at = to;
        }
    }
    out
}

/// Distance from `p` to the segment `a`-`b`, m: to the line where the foot of the perpendicular
/// falls within the segment, else to the nearer end.
fn to_segment_m(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let length = (b[0] - a[0]).hypot(b[1] - a[1]);
    let (to_a, to_b) = (
        (p[0] - a[0]).hypot(p[1] - a[1]),
        (p[0] - b[0]).hypot(p[1] - b[1]),
    );
    let along = ((p[0] - a[0]) * (b[0] - a[0]) + (p[1] - a[1]) * (b[1] - a[1])) / length;
    match length > 0.0 && (0.0..=length).contains(&along) {
        true => ((p[0] - a[0]) * (b[1] - a[1]) - (p[1] - a[1]) * (b[0] - a[0])).abs() / length,
        false => to_a.min(to_b),
    }
}

/// Points every `step_m` along a leg, its ends included.
fn samples(leg: &Leg, step_m: f64) -> Vec<[f64; 2]> {
    let len = (leg.to[0] - leg.from[0]).hypot(leg.to[1] - leg.from[1]);
    let n = (len / step_m).ceil().max(1.0) as usize;
    (0..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            [
                leg.from[0] + t * (leg.to[0] - leg.from[0]),
                leg.from[1] + t * (leg.to[1] - leg.from[1]),
            ]
        })
        .collect()
}

/// The polygon (m about `home`) and line spacing (m) of each survey complex item of a `.plan`,
/// read from its JSON.
fn surveys(file: &Path, home: [f64; 2]) -> Vec<(Vec<[f64; 2]>, f64)> {
    let Ok(json) = serde_json::from_str::<Value>(&std::fs::read_to_string(file).unwrap()) else {
        return Vec::new();
    };
    let items = json["mission"]["items"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    items
        .iter()
        .filter(|i| i["complexItemType"] == "survey")
        .filter_map(|i| {
            // A polygon with a vertex that is not a number covers nothing to check.
            let polygon: Option<Vec<[f64; 2]>> = i["polygon"]
                .as_array()?
                .iter()
                .map(|v| Some(local_m(home, v[0].as_f64()?, v[1].as_f64()?)))
                .collect();
            let spacing = f(&i["TransectStyleComplexItem"]["CameraCalc"]["AdjustedFootprintSide"]);
            Some((polygon?, spacing))
        })
        .collect()
}

/// The points of a `step_m` grid inside `polygon` (even-odd rule).
fn grid_inside(polygon: &[[f64; 2]], step_m: f64) -> Vec<[f64; 2]> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in polygon {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let inside = |p: [f64; 2]| {
        let mut c = false;
        for (k, a) in polygon.iter().enumerate() {
            let b = polygon[(k + 1) % polygon.len()];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if p[0] < x {
                    c = !c;
                }
            }
        }
        c
    };
    let mut out = Vec::new();
    let mut y = lo[1] + 0.5 * step_m;
    while y < hi[1] {
        let mut x = lo[0] + 0.5 * step_m;
        while x < hi[0] {
            if inside([x, y]) {
                out.push([x, y]);
            }
            x += step_m;
        }
        y += step_m;
    }
    out
}

/// What one plan showed, for the totals the test asserts.
#[derive(Default)]
struct Seen {
    turned: usize,
    polygon_points: usize,
    plans: usize,
    split: usize,
    no_plan: usize,
    resumed_with_camera: usize,
    camera_m: f64,
}

/// Check the plan of `file` in `extra`'s conditions (module docs).
fn check(file: &Path, extra: &[String], seen: &mut Seen) {
    let name = file.file_name().unwrap().to_string_lossy().into_owned();
    let tag = format!("{name}{}", extra.join("_"));
    let dir = scratch("plan-files", &tag.replace(['-', ' ', '.'], ""));
    let (code, answer, err) = plan(file, &dir, extra);
    let input = import(&std::fs::read_to_string(file).unwrap()).unwrap();
    if code == 1 {
        assert_eq!(answer["feasible"], false, "{tag}: {answer}");
        assert!(!answer["reason"].as_str().unwrap_or("").is_empty(), "{tag}");
        assert!(
            !dir.exists() || std::fs::read_dir(&dir).unwrap().next().is_none(),
            "{tag}"
        );
        seen.no_plan += 1;
        return;
    }
    assert_eq!(code, 0, "{tag}: {err}");
    seen.plans += 1;
    let files = answer["files"].as_array().unwrap();
    let sorties = answer["sorties"].as_array().unwrap();
    assert_eq!(files.len(), sorties.len(), "{tag}");
    if files.len() > 1 {
        seen.split += 1;
    }
    // Cut for the forecast alone, no more than the mission as given (which is cut so); at a
    // confidence, every sortie lands with the reserve in that share of the plan's scenarios.
    let confidence = f(&answer["confidence"]);
    for s in sorties.iter().filter(|_| confidence > 0.5) {
        assert!(f(&s["p_reserve"]) >= confidence, "{tag}: {s}");
    }
    if let Some(given) = answer.get("as_given").filter(|_| confidence == 0.5) {
        assert!(
            answer["batteries"].as_u64() <= given["batteries"].as_u64(),
            "{tag}: {answer}"
        );
        assert!(
            f(&answer["energy_wh"]) <= f(&given["energy_wh"]) * (1.0 + 1e-9),
            "{tag}: {answer}"
        );
    }
    // The input's camera-on legs, in metres about its home.
    let home = [
        input.spec.home.latitude_deg.unwrap(),
        input.spec.home.longitude_deg.unwrap(),
    ];
    let ordered: Vec<MissionItem> = input.flown.iter().map(|x| input.items[x.item]).collect();
    let wanted: Vec<Leg> = legs(home, home, &ordered)
        .into_iter()
        .filter(|l| l.camera)
        .collect();
    let mut flown_on: Vec<Leg> = Vec::new();
    let ext = file
        .extension()
        .unwrap()
        .to_string_lossy()
        .replace("txt", "waypoints");
    for (k, (path, sortie)) in files.iter().zip(sorties).enumerate() {
        let path = path.as_str().unwrap();
        assert!(
            path.ends_with(&format!("-{}-of-{}.{ext}", k + 1, files.len())),
            "{path}"
        );
        // Read back by `aloft mission`: the reserve kept, the sortie's energy.
        common::flies_as_planned(path, &mission_flags(extra), sortie, 1e-9);
        // The items, read independently.
        let written = import(&std::fs::read_to_string(path).unwrap()).unwrap();
        let items = &written.items;
        assert!(
            items.iter().all(|i| i.command != 177),
            "{path}: a DO_JUMP left"
        );
        let rtl = items.iter().position(|i| i.command == 20);
        if let Some(rtl) = rtl {
            let last_trigger = items[..rtl].iter().rev().find(|i| i.command == 206);
            assert!(
                last_trigger.is_none_or(|i| i.params[0] == 0.0),
                "{path}: the camera triggers on the way home"
            );
        }
        let own = legs(home, home, items);
        // Camera-on legs at most the trigger distance per camera interval (2 s by default).
        let mut speed: Option<f64> = None;
        let mut trigger = 0.0;
        for it in items {
            match it.command {
                178 if it.params[0] <= 1.0 && it.params[1] > 0.0 => speed = Some(it.params[1]),
                206 => trigger = it.params[0],
                _ => {}
            }
            if flies_to(it.command) && trigger > 0.0 && it.command != 22 {
                if let Some(v) = speed.filter(|_| seen_changes(&answer)) {
                    assert!(
                        v <= trigger / 2.0 + 1e-9,
                        "{path}: {v} m/s with a photo every {trigger} m"
                    );
                }
            }
        }
        if k > 0 {
            let first_way = items.iter().position(|i| i.command == 16).unwrap();
            let trigger = items[..first_way].iter().rfind(|i| i.command == 206);
            assert!(
                trigger.is_some_and(|i| i.params[0] == 0.0),
                "{path}: a resumed sortie flies out with the camera off"
            );
            if own.iter().any(|l| l.camera) {
                seen.resumed_with_camera += 1;
            }
        }
        flown_on.extend(own.into_iter().filter(|l| l.camera));
    }
    // The polygons of the input's surveys covered: as many points of a 5 m grid inside each
    // lie within half a line spacing of a camera-on leg as in the input.
    for (polygon, spacing_m) in surveys(file, home) {
        let points = grid_inside(&polygon, 5.0);
        if points.is_empty() || spacing_m < 0.5 {
            // A degenerate polygon or spacing: its lines (the stored items) are checked one by
            // one below.
            continue;
        }
        let covered = |legs: &[Leg]| {
            points
                .iter()
                .filter(|p| {
                    legs.iter()
                        .any(|l| to_segment_m(**p, l.from, l.to) <= 0.5 * spacing_m + 0.5)
                })
                .count()
        };
        let (given, planned) = (covered(&wanted), covered(&flown_on));
        // A survey turned to the wind is drawn again as QGroundControl draws it, whose outer
        // lines and corners fall elsewhere: aloft keeps an angle only where it covers as many
        // points of its own 3 m grid, which on this 5 m grid is within 1 % (the shared survey
        // at 105 degrees: 3322 of 3356 points against 3330).
        let turned = answer["changes"]["angles"]
            .as_array()
            .is_some_and(|a| !a.is_empty());
        let allowed = if turned { points.len() / 100 } else { 0 };
        assert!(
            planned + allowed >= given && given > points.len() * 9 / 10,
            "{tag}: {planned} of {} grid points covered, {given} as given",
            points.len()
        );
        seen.polygon_points += points.len();
    }
    if answer["changes"]["angles"]
        .as_array()
        .is_some_and(|a| !a.is_empty())
    {
        assert!(
            seen.polygon_points > 0,
            "{tag}: a turned survey is checked on its polygon"
        );
        // The survey turned: its lines are not the input's (covered above).
        seen.turned += 1;
        return;
    }
    // Every metre of the input's camera-on legs is flown with the camera on.
    for leg in &wanted {
        for p in samples(leg, 2.0) {
            let d = flown_on
                .iter()
                .map(|l| to_segment_m(p, l.from, l.to))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d <= 1.5,
                "{tag}: a camera-on point {p:?} is {d:.2} m from every camera-on leg"
            );
        }
        seen.camera_m += (leg.to[0] - leg.from[0]).hypot(leg.to[1] - leg.from[1]);
    }
}

/// The flags of `extra` that `aloft mission` takes (those of the plan alone left out).
fn mission_flags(extra: &[String]) -> Vec<&str> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < extra.len() {
        match extra[k].as_str() {
            "--speeds" | "--overlap-m" | "--camera-interval-s" | "--max-speed" | "--confidence" => {
                k += 2
            }
            "--keep-angle" => k += 1,
            flag => {
                out.push(flag);
                k += 1;
            }
        }
    }
    out
}

/// The words of `text`, as a command's arguments.
fn flags(text: &str) -> Vec<String> {
    text.split_whitespace().map(String::from).collect()
}

/// Whether the plan changed any leg's speed.
fn seen_changes(answer: &Value) -> bool {
    answer["changes"]["speeds"]
        .as_array()
        .is_some_and(|a| !a.is_empty())
}

fn conditions(reserve: Option<f64>) -> Vec<Vec<String>> {
    WINDS
        .iter()
        .map(|&(speed, from)| {
            let mut v = Vec::new();
            if speed > 0.0 {
                v.extend(["--wind-speed".into(), speed.to_string()]);
                v.extend(["--wind-from".into(), from.to_string()]);
            }
            if let Some(r) = reserve {
                v.extend(["--reserve-percent".into(), r.to_string()]);
            }
            v
        })
        .collect()
}

#[test]
fn data_val_every_shared_planner_file_planned_in_wind_flies_its_files() {
    let mut seen = Seen::default();
    for file in shared_planner_files() {
        // The VTOL files are refused as `aloft mission` refuses them (exit 2, naming the item).
        let (code, _, err) = plan(file.as_path(), &scratch("plan-files", "probe"), &[]);
        if code == 2 {
            assert!(
                err.contains("VTOL") || err.contains("missing keys"),
                "{file:?}: {err}"
            );
            continue;
        }
        for extra in conditions(None) {
            check(&file, &extra, &mut seen);
        }
    }
    eprintln!(
        "plans {} (split {}), no plan {}, resumed with the camera {}, camera-on route {:.0} m",
        seen.plans, seen.split, seen.no_plan, seen.resumed_with_camera, seen.camera_m
    );
    // 39 of the 50 file-and-wind pairs have a plan at the default confidence: in the 12 m/s
    // winds, drawn with their 3 m/s spread, the M100 cannot hold its way in more than 5 % of the
    // scenarios on most files.
    assert!(seen.plans >= 38, "plans: {}", seen.plans);
}

/// The shared QGroundControl survey at a 70 % reserve: several packs, each resuming with the
/// camera on, the survey covered.
#[test]
fn data_val_the_shared_survey_split_in_wind_resumes_with_the_camera_and_covers_it() {
    let file = &shared_mission("neilvaltec_test.plan");
    let mut seen = Seen::default();
    // Cut for the forecast alone: at a 70 % reserve, 12 m/s winds drawn with their default
    // spread (3 m/s) leave no sortie that lands with it at a confidence of 95 %.
    for mut extra in conditions(Some(70.0)) {
        extra.extend(["--confidence".to_string(), "0.5".to_string()]);
        check(file, &extra, &mut seen);
    }
    eprintln!(
        "plans {} (split {}), resumed with the camera {}, camera-on route {:.0} m, turned {}, polygon points {}",
        seen.plans, seen.split, seen.resumed_with_camera, seen.camera_m, seen.turned, seen.polygon_points
    );
    assert_eq!(seen.plans, WINDS.len());
    assert!(seen.turned >= 1, "a wind turns the survey");
    assert_eq!(
        seen.split,
        WINDS.len(),
        "every wind needs several packs at 70 %"
    );
    assert!(
        seen.resumed_with_camera >= WINDS.len(),
        "{}",
        seen.resumed_with_camera
    );
}

/// A `.waypoints` mission with a DO_JUMP loop (three passes of a square): the sorties fly the
/// loop unrolled, with no DO_JUMP in any file, and cover every pass's legs.
#[test]
fn a_do_jump_loop_is_unrolled_into_the_sorties() {
    let home: (f64, f64) = (47.397742, 8.545594);
    let mut rows = vec![format!(
        "0\t1\t0\t16\t0\t0\t0\t0\t{}\t{}\t488.0\t1",
        home.0, home.1
    )];
    rows.push(format!(
        "1\t0\t3\t22\t0\t0\t0\t0\t{}\t{}\t30.0\t1",
        home.0, home.1
    ));
    rows.push("2\t0\t3\t206\t20\t0\t1\t0\t0\t0\t0\t1".into());
    let corners = [(0.0, 400.0), (400.0, 400.0), (400.0, 0.0), (0.0, 0.0)];
    for (k, (e, n)) in corners.iter().enumerate() {
        let lat = home.0 + n / 111_195.0;
        let lon = home.1 + e / (111_195.0 * home.0.to_radians().cos());
        rows.push(format!(
            "{}\t0\t3\t16\t0\t0\t0\t0\t{lat:.7}\t{lon:.7}\t30.0\t1",
            k + 3
        ));
    }
    // Back to item 3, twice more: three passes.
    rows.push("7\t0\t3\t177\t3\t2\t0\t0\t0\t0\t0\t1".into());
    rows.push("8\t0\t3\t206\t0\t0\t1\t0\t0\t0\t0\t1".into());
    rows.push("9\t0\t3\t20\t0\t0\t0\t0\t0\t0\t0\t1".into());
    let text = format!("QGC WPL 110\n{}\n", rows.join("\n"));
    let path = scratch("plan-files", "loop.waypoints");
    std::fs::write(&path, text).unwrap();
    let mut seen = Seen::default();
    for extra in [
        vec![],
        vec!["--reserve-percent".to_string(), "85".to_string()],
    ] {
        check(&path, &extra, &mut seen);
    }
    assert_eq!(seen.plans, 2);
    assert!(seen.split >= 1, "the 85 % reserve needs several packs");
    // Three passes of a 1.6 km square with the camera on.
    assert!(
        (seen.camera_m - 2.0 * 3.0 * 1600.0).abs() < 10.0,
        "{}",
        seen.camera_m
    );
}

/// The shared ArduPilot files at an 88 % reserve, where their routes need several packs: each
/// sortie keeps the reserve, the camera-on legs covered, nothing worse than as given. (They fly
/// in the air of their home altitude, 584 m: at 90 % one loiter-turns orbit can no longer be
/// flown out and back on one pack.)
#[test]
fn data_val_the_shared_waypoints_files_split_at_an_88_percent_reserve() {
    let mut seen = Seen::default();
    for name in [
        "ardupilot_DO_CHANGE_SPEED_mission.txt",
        "ardupilot_copter_loiterturns_mission.txt",
    ] {
        let file = &shared_mission(name);
        for (speed, from) in [(0.0, 0.0), (8.0, 90.0)] {
            let extra = flags(&format!(
                "--reserve-percent 88 --wind-speed {speed} --wind-from {from}"
            ));
            check(file, &extra, &mut seen);
        }
    }
    eprintln!(
        "plans {} (split {}), no plan {}",
        seen.plans, seen.split, seen.no_plan
    );
    assert_eq!(seen.plans + seen.no_plan, 4);
    assert!(seen.plans >= 3, "{}", seen.plans);
    assert_eq!(
        seen.split, seen.plans,
        "an 88 % reserve needs several packs"
    );
}

/// The shared survey on one pack with its own speeds in an 8 m/s northerly: turned to the wind
/// and written back as a survey complex item at its new angle (QGroundControl shows and edits
/// it), which `aloft mission` flies to the plan's energy; the polygon covered as before.
#[test]
fn data_val_a_survey_turned_on_one_pack_is_written_as_its_complex_item() {
    let file = &shared_mission("neilvaltec_test.plan");
    let extra = flags("--speeds keep --wind-speed 8 --wind-from 0");
    let mut seen = Seen::default();
    check(file, &extra, &mut seen);
    assert_eq!(seen.turned, 1, "the survey is turned");
    let dir = scratch("plan-files", "turned-one");
    let (code, answer, err) = plan(file, &dir, &extra);
    assert_eq!(code, 0, "{err}");
    assert_eq!(answer["batteries"], 1);
    let to = f(&answer["changes"]["angles"][0]["to_deg"]);
    let from = f(&answer["changes"]["angles"][0]["from_deg"]);
    assert!((to - from).abs() > 1.0);
    let written: Value = serde_json::from_str(
        &std::fs::read_to_string(answer["files"][0].as_str().unwrap()).unwrap(),
    )
    .unwrap();
    let items = written["mission"]["items"].as_array().unwrap();
    let surveys: Vec<&Value> = items
        .iter()
        .filter(|i| i["complexItemType"] == "survey")
        .collect();
    assert_eq!(surveys.len(), 1);
    assert_eq!(f(&surveys[0]["angle"]), to);
    // The same polygon, spacing and trigger distance as the input's.
    let input: Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
    let own = input["mission"]["items"]
        .as_array()
        .unwrap()
        .iter()
        .find(|i| i["complexItemType"] == "survey")
        .unwrap();
    assert_eq!(surveys[0]["polygon"], own["polygon"]);
    let camera = |v: &Value| v["TransectStyleComplexItem"]["CameraCalc"].clone();
    assert_eq!(camera(surveys[0]), camera(own));
    assert_eq!(
        items.last().unwrap()["command"],
        20,
        "a return to launch last"
    );
}

/// A survey that cannot be drawn again (a degenerate polygon, a 0 m line spacing, a vertex that
/// is not a number) is planned as its stored items, not turned, with a note naming the item and
/// the key; its files fly their sorties as every other.
#[test]
fn data_val_a_survey_that_cannot_be_drawn_again_is_flown_as_stored_and_said() {
    let file = &shared_mission("neilvaltec_test.plan");
    let source: Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
    type Spoil = fn(&mut Value);
    let variants: [(&str, Spoil, &str); 3] = [
        (
            "degenerate",
            |s| {
                let first = s["polygon"][0].clone();
                s["polygon"] = Value::Array(vec![first; 4]);
            },
            "key polygon is 1 distinct vertices",
        ),
        (
            "spacing0",
            |s| s["TransectStyleComplexItem"]["CameraCalc"]["AdjustedFootprintSide"] = 0.into(),
            "key TransectStyleComplexItem.CameraCalc.AdjustedFootprintSide is 0",
        ),
        (
            "nan",
            |s| s["polygon"][1][0] = Value::Null,
            "key polygon[1] is [null,",
        ),
    ];
    for (name, spoil, said) in variants {
        let mut plan_json = source.clone();
        let items = plan_json["mission"]["items"].as_array_mut().unwrap();
        let survey = items
            .iter_mut()
            .find(|i| i["complexItemType"] == "survey")
            .unwrap();
        spoil(survey);
        let path = scratch("plan-files", &format!("bad-{name}.plan"));
        std::fs::write(&path, serde_json::to_string(&plan_json).unwrap()).unwrap();
        let extra = flags("--wind-speed 8 --wind-from 0 --reserve-percent 70");
        let mut seen = Seen::default();
        check(&path, &extra, &mut seen);
        assert_eq!((seen.plans, seen.turned), (1, 0), "{name}");
        let dir = scratch("plan-files", &format!("bad-{name}-out"));
        let (code, answer, err) = plan(&path, &dir, &extra);
        assert_eq!(code, 0, "{name}: {err}");
        let notes = answer["notes"].to_string();
        assert!(
            notes.contains("item 3: ") && notes.contains(said),
            "{name}: {notes}"
        );
        assert_eq!(answer["changes"]["angles"], serde_json::json!([]), "{name}");
    }
}

/// A survey beyond one pack is turned to the wind where that saves energy, and a survey kept at
/// its angle says why: each angle is judged by the energy of the whole route (on one pack, a
/// route beyond it stops where the pack is empty, every angle cost that pack, and no survey of
/// several packs was ever turned). The shared survey's polygon scaled 2 times (about 20 km, two
/// packs at least), planned for the forecast alone in 8 m/s from 240 deg: turned, it takes no
/// more packs and less energy than with its angle kept; in still air the angle is kept, with
/// the angle tried and what it costs.
#[test]
fn data_val_a_survey_beyond_one_pack_is_turned_to_the_wind() {
    let file = survey_20km("survey-20km.plan");
    let wind = flags("--wind-speed 8 --wind-from 240 --confidence 0.5");
    let (code, turned, err) = plan(&file, &scratch("plan-files", "turned-20km"), &wind);
    assert_eq!(code, 0, "{err}");
    let angles = turned["changes"]["angles"].as_array().unwrap();
    assert_eq!(angles.len(), 1, "{}", turned["changes"]);
    assert!(f(&turned["batteries"]) >= 2.0, "{turned}");
    let mut kept_flags = wind.clone();
    kept_flags.push("--keep-angle".to_string());
    let (_, kept, _) = plan(&file, &scratch("plan-files", "kept-20km"), &kept_flags);
    assert!(f(&turned["batteries"]) <= f(&kept["batteries"]));
    assert!(
        f(&turned["energy_wh"]) < f(&kept["energy_wh"]),
        "{turned} {kept}"
    );
    let still = flags("--confidence 0.5");
    let (_, calm, _) = plan(&file, &scratch("plan-files", "calm-20km"), &still);
    let why = &calm["changes"]["angles_kept"];
    assert_eq!(calm["changes"]["angles"], serde_json::json!([]), "{calm}");
    assert_eq!(why.as_array().map_or(0, Vec::len), 1, "{}", calm["changes"]);
    assert!(why[0]["tried_deg"].is_number(), "{why}");
    assert!(why[0]["why"].as_str().unwrap().contains("Wh"), "{why}");
}

/// The operator's highest planned leg speed of a shared planner file, read from the raw file
/// (not through aloft's reader): each position item flown at the last DO_CHANGE_SPEED (178)
/// ground or air speed before it, else the planning speed (a `.plan`'s `hoverSpeed`; for a
/// `.waypoints` file ArduPilot's WPNAV_SPEED default, 10 m/s).
fn highest_planned_speed(file: &Path) -> f64 {
    let text = std::fs::read_to_string(file).unwrap();
    // (command, speed param) in file order.
    let (planning, rows): (f64, Vec<(u64, f64)>) = if text.starts_with("QGC WPL") {
        let rows = text
            .lines()
            .skip(1)
            .filter_map(|l| {
                let c: Vec<&str> = l.split_whitespace().collect();
                Some((c.get(3)?.parse().ok()?, c.get(5)?.parse().ok()?))
            })
            .collect();
        (10.0, rows)
    } else {
        let v: Value = serde_json::from_str(&text).unwrap();
        let m = &v["mission"];
        let mut rows = Vec::new();
        for it in m["items"].as_array().unwrap() {
            let inner = it["TransectStyleComplexItem"]["Items"].as_array();
            for s in inner.map_or_else(|| vec![it], |a| a.iter().collect()) {
                let p = s["params"].as_array();
                let speed = p
                    .and_then(|p| p.get(1))
                    .and_then(Value::as_f64)
                    .unwrap_or(0.0);
                rows.push((s["command"].as_u64().unwrap_or(0), speed));
            }
        }
        (m["hoverSpeed"].as_f64().unwrap_or(5.0), rows)
    };
    let mut in_force = planning;
    let mut highest: f64 = 0.0;
    for (command, speed) in rows {
        match command {
            178 if speed > 0.0 => in_force = speed,
            16 | 17 | 18 | 19 | 21 => highest = highest.max(in_force),
            _ => {}
        }
    }
    highest
}

/// Speeds an operator accepts: by default no leg of a shared file (all but the surveys) is
/// written faster than the file's own highest planned speed, read from the raw file; the
/// survey's camera legs at most its 25 m trigger distance over the 2 s camera interval.
#[test]
fn data_val_no_leg_is_written_faster_than_the_operator_planned() {
    for file in shared_planner_files() {
        let name = file.file_name().unwrap().to_string_lossy().to_string();
        let (code, answer, _) = plan(
            &file,
            &scratch("plan-files", "speeds"),
            &flags("--wind-speed 6 --wind-from 240 --confidence 0.5"),
        );
        if code != 0 {
            continue;
        }
        let highest = highest_planned_speed(&file);
        let survey = name == "neilvaltec_test.plan";
        let cap = if survey {
            highest.max(25.0 / 2.0)
        } else {
            highest
        };
        for c in answer["changes"]["speeds"].as_array().unwrap() {
            assert!(f(&c["to_mps"]) <= cap + 1e-9, "{name}: {c} above {cap} m/s");
        }
        eprintln!(
            "{name}: highest planned {highest} m/s, {} legs re-speeded",
            answer["changes"]["speeds"].as_array().unwrap().len()
        );
    }
}

/// The DO_CHANGE_SPEED ground speeds (param 2) of a `.plan`'s simple items, with the index of the
/// item each comes before, and the index of the first waypoint after the take-off.
fn speeds_and_resume(text: &str) -> (Vec<(usize, f64)>, Option<usize>) {
    let v: Value = serde_json::from_str(text).unwrap();
    let items = v["mission"]["items"].as_array().unwrap();
    let speeds = items
        .iter()
        .enumerate()
        .filter(|(_, it)| it["command"] == 178)
        .map(|(k, it)| (k, f(&it["params"][1])))
        .collect();
    let resume = items.iter().position(|it| it["command"] == 16);
    (speeds, resume)
}

/// A resumed sortie's fly-out, aloft's own leg, is written at its own speed only where it may
/// go faster than the operator planned: below the RTL altitude (none known by default) no faster
/// than the survey's `hoverSpeed` (5 m/s); with `--rtl-altitude-m 40` (the survey flies at
/// 50 m) at the speed of least energy in its wind, above 5 m/s and within the M100's 17 m/s,
/// set just before the resume waypoint, and the survey's own speed set again right after it
/// (among the items that restore what was in force there).
#[test]
fn data_val_a_resumed_sortie_flies_out_at_its_own_speed_above_the_rtl_altitude() {
    let file = survey_20km("survey-20km-fly-out.plan");
    for (extra, fast) in [("", false), (" --rtl-altitude-m 40", true)] {
        let flags = flags(&format!(
            "--wind-speed 8 --wind-from 240 --confidence 0.5 --keep-angle{extra}"
        ));
        let (code, answer, err) = plan(&file, &scratch("plan-files", "fly-out"), &flags);
        assert_eq!(code, 0, "{err}");
        let files = common::strs(&answer["files"]);
        assert!(files.len() >= 2, "{answer}");
        for later in &files[1..] {
            let (speeds, resume) = speeds_and_resume(&std::fs::read_to_string(later).unwrap());
            let resume = resume.unwrap();
            let before: Vec<f64> = speeds
                .iter()
                .filter(|(k, _)| *k < resume)
                .map(|s| s.1)
                .collect();
            let out = before.last().copied().unwrap_or(5.0);
            match fast {
                false => assert!(out <= 5.0 + 1e-9, "{later}: fly-out at {out}"),
                true => {
                    assert!(out > 5.0 && out <= 17.0, "{later}: fly-out at {out}");
                    // The route's speed set again among the items that restore its state.
                    assert!(
                        speeds.iter().any(|(k, _)| *k > resume && *k <= resume + 4),
                        "{later}: {speeds:?}, resume at {resume}"
                    );
                }
            }
        }
    }
}
