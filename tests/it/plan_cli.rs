//! `aloft plan` (issue 33): the missions to fly, one file per battery. Each file aloft writes is
//! read back by `aloft mission` in the same conditions and must keep the reserve with the energy
//! the plan says; the sorties cover the route; the plan never needs more batteries or energy
//! than the mission as given; bad input is exit 2 naming it, a route no pack can fly is exit 1
//! with no file written.

use crate::common;

use std::path::{Path, PathBuf};

use aloft_planner::mission_toml::{landing, leg, return_home, take_off};
use common::{aloft, run, scratch, survey_lines};
use serde_json::Value;

fn write_mission(name: &str, text: &str) -> PathBuf {
    let path = scratch("plan", name);
    std::fs::write(&path, text).unwrap();
    path
}

/// `aloft plan` of `mission` into a new folder: its JSON answer.
fn plan(mission: &Path, extra: &[&str]) -> (Value, PathBuf) {
    let dir = scratch(
        "plan",
        &format!("out-{}", extra.join("_").replace(['-', ' '], "")),
    );
    let _ = std::fs::remove_dir_all(&dir);
    let m = mission.display().to_string();
    let d = dir.display().to_string();
    let mut args = vec!["plan", m.as_str(), "-o", d.as_str(), "--format", "json"];
    args.extend_from_slice(extra);
    let (code, out, err) = run(&args);
    assert_eq!(code, 0, "aloft {args:?}: {err}");
    (serde_json::from_str(&out).unwrap(), dir)
}

/// `aloft mission FILE EXTRA --format json` of a written file.
/// `aloft mission FILE --format json` in the conditions of `extra` (a plan's flags; its
/// `--confidence` is the plan's alone).
fn fly(file: &str, extra: &[&str]) -> Value {
    let mut args = vec!["mission", file, "--format", "json"];
    let mut k = 0;
    while k < extra.len() {
        match extra[k] {
            "--confidence" => k += 2,
            flag => {
                args.push(flag);
                k += 1;
            }
        }
    }
    let out = aloft(&args);
    assert!(
        matches!(out.status.code(), Some(0 | 1)),
        "{}",
        common::stderr(&out)
    );
    serde_json::from_str(&common::stdout(&out)).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Every file flies to its sortie's answer and keeps the reserve; cut for the forecast alone
/// (`--confidence 0.5`, the nominal cut), the first pack is used to the reserve (it turns home
/// inside a leg) and the plan needs no more than the mission as given.
#[test]
fn each_file_flies_its_sortie_and_keeps_the_reserve() {
    let mission = write_mission("lines.toml", &survey_lines("lines", 24));
    for wind in [
        vec!["--confidence", "0.5"],
        vec![
            "--wind-speed",
            "6",
            "--wind-from",
            "90",
            "--confidence",
            "0.5",
        ],
        vec![
            "--wind-speed",
            "8",
            "--wind-from",
            "200",
            "--confidence",
            "0.5",
        ],
    ] {
        let (answer, _) = plan(&mission, &wind);
        let files = answer["files"].as_array().unwrap();
        let sorties = answer["sorties"].as_array().unwrap();
        assert_eq!(files.len(), sorties.len());
        assert_eq!(f(&answer["batteries"]) as usize, files.len());
        assert!(files.len() >= 2, "{answer}");
        let mut energy = 0.0;
        for (file, sortie) in files.iter().zip(sorties) {
            let flown = fly(file.as_str().unwrap(), &wind);
            assert_eq!(flown["feasible"], true, "{file}: {flown}");
            assert_eq!(flown["batteries_required"], 1, "{file}");
            // The same planner, the same conditions: the same flight.
            let (e, e_plan) = (f(&flown["energy_wh"]), f(&sortie["energy_wh"]));
            assert!(
                (e - e_plan).abs() < 1e-9 * e_plan,
                "{file}: {e} against {e_plan}"
            );
            assert!(f(&flown["end_soc"]) >= f(&flown["required_reserve_soc"]) - 1e-12);
            energy += e;
        }
        assert!((energy - f(&answer["energy_wh"])).abs() < 1e-6, "{wind:?}");
        // A pack turned home inside a leg lands within 1 % of the reserve (the cut is found to a
        // metre; 1 % of the pack is about 150 m of flight).
        let first = &sorties[0];
        if first.get("ends_inside_leg_fraction").is_some() {
            let flown = fly(files[0].as_str().unwrap(), &wind);
            let margin = f(&flown["end_soc"]) - f(&flown["required_reserve_soc"]);
            assert!((0.0..0.01).contains(&margin), "{wind:?}: {margin}");
        }
        let given = &answer["as_given"];
        assert!(
            f(&answer["batteries"]) <= f(&given["batteries"]),
            "{wind:?}"
        );
        assert!(
            f(&answer["energy_wh"]) <= f(&given["energy_wh"]) + 1e-9,
            "{wind:?}"
        );
    }
}

/// The sorties cover the route: the first starts with the mission's take-off; each later one
/// flies from home to the point `overlap_m` back along the route from where the last one turned
/// home; the last ends with the mission's way down.
#[test]
fn the_sorties_resume_where_the_last_turned_home_less_the_overlap() {
    let mission = write_mission("overlap.toml", &survey_lines("lines", 24));
    for overlap in ["0", "30"] {
        let (answer, _) = plan(&mission, &["--overlap-m", overlap, "--speeds", "keep"]);
        let files = common::strs(&answer["files"]);
        let read =
            |p: &str| -> toml::Table { std::fs::read_to_string(p).unwrap().parse().unwrap() };
        for pair in files.windows(2) {
            let (a, b) = (read(pair[0]), read(pair[1]));
            let a_segments = a["segment"].as_array().unwrap();
            let b_segments = b["segment"].as_array().unwrap();
            // The last leg before the way home (a return, a landing) ends where the pack turned.
            let turn = &a_segments[a_segments.len() - 3];
            let resume = &b_segments[1];
            assert_eq!(resume["kind"].as_str(), Some("leg"));
            let xy = |t: &toml::Value| {
                [
                    t["east_m"].as_float().unwrap(),
                    t["north_m"].as_float().unwrap(),
                ]
            };
            let (p, q) = (xy(turn), xy(resume));
            let gap = (p[0] - q[0]).hypot(p[1] - q[1]);
            let want: f64 = overlap.parse().unwrap();
            // Along a straight line the overlap is the distance; across a corner, less.
            assert!(
                gap <= want + 1e-6 && gap >= want.min(40.0) - 40.0 - 1e-6,
                "{gap}"
            );
            if want == 0.0 {
                assert!(gap < 1e-6, "{gap}");
            }
        }
        let first = read(files[0]);
        assert_eq!(first["segment"][0]["kind"].as_str(), Some("take-off"));
    }
}

/// Speeds for the wind: legs without a speed of their own change with `--speeds wind`, every leg
/// with `energy`, none with `keep`; no leg is given more than `--max-speed`, nor, by default
/// (`--speeds wind` without `--max-speed`), more than the operator's fastest planned speed (here
/// 8 m/s everywhere, below the wind's speed of least energy: no leg changes).
#[test]
fn speeds_follow_the_choice_and_the_cap() {
    let mut text = survey_lines("lines", 4);
    // The second leg without a speed of its own: it flies the planning speed.
    text = text.replacen("ground_speed_mps = 8.0\n", "", 2);
    let mission = write_mission("speeds.toml", &text);
    let wind = ["--wind-speed", "6", "--wind-from", "90"];
    let changed = |choice: &str, cap: Option<&str>| -> Vec<Value> {
        let mut extra: Vec<&str> = wind.to_vec();
        extra.extend(["--speeds", choice]);
        if let Some(c) = cap {
            extra.extend(["--max-speed", c]);
        }
        let (answer, _) = plan(&mission, &extra);
        answer["changes"]["speeds"].as_array().unwrap().clone()
    };
    assert!(changed("keep", None).is_empty());
    assert!(changed("wind", None).is_empty());
    let some = changed("wind", Some("12"));
    assert!(
        !some.is_empty()
            && some
                .iter()
                .all(|c| c.get("from_mps").is_none() && f(&c["to_mps"]) > 8.0),
        "{some:?}"
    );
    let all = changed("energy", None);
    assert!(all.len() > some.len(), "{all:?}");
    for c in changed("energy", Some("9")) {
        assert!(f(&c["to_mps"]) <= 9.0, "{c}");
    }
}

/// Bad input is exit 2 naming it; an existing file is not overwritten without `--force`; a leg
/// no pack can fly out and back is exit 1 with the reason and no file.
#[test]
fn bad_input_and_no_plan_are_refused() {
    let mission = write_mission("bad.toml", &survey_lines("lines", 4));
    let m = mission.display().to_string();
    let dir = scratch("plan", "bad-out").display().to_string();
    let _ = std::fs::remove_dir_all(&dir);
    for (args, needle) in [
        (vec!["--overlap-m", "-1"], "overlap_m"),
        (vec!["--max-speed", "0"], "max_speed"),
        (vec!["--speeds", "fast"], "speeds"),
    ] {
        let mut all = vec!["plan", m.as_str(), "-o", dir.as_str()];
        all.extend(args);
        let (code, _, err) = run(&all);
        assert_eq!(code, 2, "{all:?}: {err}");
        assert!(err.contains(needle) && err.lines().count() == 1, "{err}");
    }
    // A folder that cannot be made (a file is in the way).
    let file = scratch("plan", "a-file");
    std::fs::write(&file, "x").unwrap();
    let inside = file.join("out").display().to_string();
    let (code, _, err) = run(&["plan", &m, "-o", &inside]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("a-file"), "{err}");
    // Written once; again without --force: refused, naming the file; with it: written.
    assert_eq!(run(&["plan", &m, "-o", &dir]).0, 0);
    let (code, _, err) = run(&["plan", &m, "-o", &dir]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("bad-1-of-") && err.contains("--force"),
        "{err}"
    );
    assert_eq!(run(&["plan", &m, "-o", &dir, "--force"]).0, 0);
    // No temporary file is left beside them.
    let left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".toml"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    // A single leg of 30 km out: no pack flies it out and back.
    let far = format!(
        "name = \"far\"\n{}{}{}{}",
        take_off(40.0, 3.0),
        leg(30_000.0, 0.0, 10.0),
        return_home(10.0),
        landing(1.0)
    );
    let far = write_mission("far.toml", &far);
    let out_dir = scratch("plan", "far-out");
    let _ = std::fs::remove_dir_all(&out_dir);
    let (code, out, err) = run(&[
        "plan",
        far.to_str().unwrap(),
        "-o",
        out_dir.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert_eq!(code, 1, "{out} {err}");
    let answer: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(answer["feasible"], false);
    assert!(
        answer["reason"]
            .as_str()
            .unwrap()
            .contains("cannot fly there and back"),
        "{answer}"
    );
    assert!(!out_dir.exists());
}

/// A plan whose caller has given up (`aloft serve`'s client left) stops with
/// `Error::Cancelled` before its next candidate; the same request not cancelled is answered.
#[test]
fn a_cancelled_plan_stops() {
    use std::sync::atomic::AtomicBool;
    use std::sync::Arc;
    let mission =
        aloft::engine::Mission::from_text(&survey_lines("lines", 24), "lines.toml").unwrap();
    let vehicle = aloft::engine::Vehicle::builtin("dji-m100").unwrap();
    let mut request = aloft::engine::FlyPlanRequest::default();
    let plan = aloft::engine::plan_to_fly(&vehicle, &mission, &request).unwrap();
    assert!(plan.batteries >= 2);
    request.bounds.cancel = Some(Arc::new(AtomicBool::new(true)));
    let e = aloft::engine::plan_to_fly(&vehicle, &mission, &request).unwrap_err();
    assert!(matches!(e, aloft::Error::Cancelled), "{e}");
}

/// Issue 43 item 3: a `.waypoints` mission whose second waypoint is an unlimited loiter
/// (NAV_LOITER_UNLIM 17; the shared brucdeng file with row 2 changed), then three waypoints and
/// the operator's LAND. The written file keeps them in order with the LAND and no return to
/// launch (before: the route ended at the loiter, the four items dropped and an RTL written);
/// the notes say the loiter was planned at 60 s, and the plan flies as the same file with a
/// timed loiter there (NAV_LOITER_TIME 19 of 60 s: the same duration and energy, to 1e-9) and
/// longer than with `--loiter-unlimited-s 0` by the minute and the stop (60 to 65 s). A
/// negative time is refused naming the flag.
#[test]
fn data_val_the_items_after_an_unlimited_loiter_are_kept_with_the_landing() {
    let mission = write_mission("loiter_unlim.waypoints", &brucdeng_with_row_2(&["17"]));
    let timed = write_mission("loiter_time.waypoints", &brucdeng_with_row_2(&["19", "60"]));
    let (answer, dir) = plan(&mission, &[]);
    let notes = answer["notes"].to_string();
    assert!(
        notes.contains("LOITER_UNLIM: flown as a loiter of 60 s"),
        "{answer}"
    );
    let files = answer["files"].as_array().unwrap();
    let last = std::fs::read_to_string(files.last().unwrap().as_str().unwrap()).unwrap();
    let commands: Vec<&str> = last
        .lines()
        .skip(2)
        .map(|l| l.split('\t').nth(3).unwrap())
        .filter(|c| *c != "178")
        .collect();
    let tail: Vec<&str> = commands.iter().rev().take(5).rev().copied().collect();
    assert_eq!(tail, ["17", "16", "16", "16", "21"], "{last}");
    assert!(!commands.contains(&"20"), "{last}");
    let (as_timed, _) = plan(&timed, &[]);
    for key in ["duration_s", "energy_wh"] {
        assert!(
            (f(&answer[key]) - f(&as_timed[key])).abs() < 1e-9,
            "{key}: {answer} {as_timed}"
        );
    }
    let (none, _) = plan(&mission, &["--loiter-unlimited-s", "0"]);
    let longer_s = f(&answer["duration_s"]) - f(&none["duration_s"]);
    assert!((60.0..65.0).contains(&longer_s), "{longer_s} s");
    let _ = std::fs::remove_dir_all(&dir);
    let m = mission.display().to_string();
    let o = dir.display().to_string();
    let (code, _, err) = run(&["plan", &m, "-o", &o, "--loiter-unlimited-s", "-1"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("loiter_unlimited_s") || err.contains("loiter-unlimited-s"),
        "{err}"
    );
}

/// The shared brucdeng `.waypoints` file with row 2's command and first parameters replaced by
/// `fields` (command, then p1...).
fn brucdeng_with_row_2(fields: &[&str]) -> String {
    let source = common::data_dir().join("missions/brucdeng_aircart_mission.waypoints");
    std::fs::read_to_string(source)
        .unwrap()
        .lines()
        .map(|l| {
            let mut c: Vec<&str> = l.split('\t').collect();
            if c.first() == Some(&"2") {
                for (k, v) in fields.iter().enumerate() {
                    c[3 + k] = v;
                }
            }
            c.join("\t") + "\n"
        })
        .collect()
}
