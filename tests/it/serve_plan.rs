//! `POST /api/plan` of `aloft serve` (issue 33, item 5): the plan to fly on the page. Its answer
//! is `aloft plan --format json` with each file's text and each sortie's path; each text, read
//! back by `aloft mission` in the same conditions, flies to its sortie's energy and keeps the
//! reserve; each path lies on the file's own positions; the options are refused as the other
//! mission requests refuse theirs; no plan is an answer, as on the command line.
#![cfg(feature = "serve")]

use crate::common;

use std::io::Write;

use serde_json::Value;

use common::serve::{encoded, read_answer, Server};
use common::{data_dir, run, scratch};

/// The conditions of the plan: neilvaltec's survey at 70 % reserve in 8 m/s from the north, more
/// than one pack can fly.
const CONDITIONS: [&str; 6] = [
    "--reserve-percent",
    "70",
    "--wind-speed",
    "8",
    "--wind-from",
    "0",
];
const QUERY: &str = "reserve_percent=70&wind_speed=8&wind_from=0";

fn neilvaltec() -> (String, Vec<u8>) {
    let path = data_dir().join("missions/neilvaltec_test.plan");
    let bytes = std::fs::read(&path).unwrap();
    (path.display().to_string(), bytes)
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn array(v: &Value) -> &Vec<Value> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}"))
}

/// `POST /api/plan?QUERY` of the body: status and JSON.
fn plan(server: &Server, query: &str, body: &[u8]) -> (u16, Value) {
    let (code, text) = server.request("POST", &format!("/api/plan?{query}"), None, body);
    let json = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}"));
    (code, json)
}

/// Each sortie's text, written to a file and flown by `aloft mission` in the plan's conditions,
/// lands with the reserve on the energy the plan gives it (to 1e-6: the plan flies the file it
/// wrote, read back); the sorties add up to the plan and take no more than the mission as given;
/// the page is told nothing the command line does not answer (but the texts, which it writes,
/// and the paths).
#[test]
fn data_val_plan_texts_fly_to_their_sorties() {
    let server = Server::start(&[]);
    let (path, bytes) = neilvaltec();
    let (code, answer) = plan(&server, &format!("file={}&{QUERY}", encoded(&path)), &bytes);
    assert_eq!(code, 200, "{answer}");
    let sorties = array(&answer["sorties"]);
    let texts = array(&answer["texts"]);
    let files = array(&answer["files"]);
    let n = sorties.len();
    assert!(
        n >= 2,
        "{n} sorties: the conditions ask for more than one pack"
    );
    assert_eq!(answer["batteries"], n);
    assert_eq!((texts.len(), files.len()), (n, n));
    assert_eq!(array(&answer["maps"]).len(), n);
    let given = &answer["as_given"];
    assert!(given["batteries"].as_u64().unwrap() >= n as u64, "{given}");
    assert!(f(&given["energy_wh"]) >= f(&answer["energy_wh"]), "{given}");
    let (mut energy_wh, mut duration_s) = (0.0, 0.0);
    for (k, (sortie, text)) in sorties.iter().zip(texts).enumerate() {
        let name = sortie["file"].as_str().unwrap();
        // Named as the command line names them, in flight order; never written on the server.
        assert_eq!(name, format!("neilvaltec_test-{}-of-{n}.plan", k + 1));
        assert_eq!(
            (&text["file"], &files[k]),
            (&sortie["file"], &sortie["file"])
        );
        assert!(!std::path::Path::new(name).exists(), "{name} was written");
        let file = scratch("serve-plan", name);
        std::fs::write(&file, text["text"].as_str().unwrap()).unwrap();
        let flown = common::flies_as_planned(file.to_str().unwrap(), &CONDITIONS, sortie, 1e-6);
        assert!(
            f(&flown["end_soc"]) >= 0.70 - 1e-9,
            "{name}: {}",
            flown["end_soc"]
        );
        energy_wh += f(&sortie["energy_wh"]);
        duration_s += f(&sortie["duration_s"]);
    }
    assert!((energy_wh - f(&answer["energy_wh"])).abs() <= 1e-9 * energy_wh);
    assert!((duration_s - f(&answer["duration_s"])).abs() <= 1e-9 * duration_s);
    // The command line's answer, but for the files' folder (it writes them, the server does not).
    let dir = scratch("serve-plan", "cli");
    let mut args = vec![
        "plan",
        path.as_str(),
        "-o",
        dir.to_str().unwrap(),
        "--force",
        "--format",
        "json",
    ];
    args.extend_from_slice(&CONDITIONS);
    let (code, out, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    let mut cli: Value = serde_json::from_str(&out).unwrap();
    let base = |v: &mut Value| {
        let name = v.as_str().unwrap().rsplit('/').next().unwrap().to_string();
        *v = Value::String(name);
    };
    for (k, text) in texts.iter().enumerate() {
        base(&mut cli["files"][k]);
        base(&mut cli["sorties"][k]["file"]);
        let written = std::fs::read_to_string(dir.join(cli["files"][k].as_str().unwrap()));
        assert_eq!(written.unwrap(), text["text"].as_str().unwrap());
    }
    let mut page = answer.clone();
    let page_only = page.as_object_mut().unwrap();
    page_only.remove("texts");
    page_only.remove("maps");
    assert_eq!(page, cli);
}

/// A point's latitude and longitude, deg.
fn deg(p: &Value) -> [f64; 2] {
    [f(&p[0]), f(&p[1])]
}

/// The sorties' paths on the map, flown with stops at every waypoint: each leg ends on its item's
/// latitude and longitude as the sortie's own file gives them (within 1e-7 deg, 1 cm), the way
/// out starts at the file's home and the way home ends there; the way out of a sortie after the
/// first is its take-off and its transit; the route's legs are the file's items between them.
#[test]
fn data_val_plan_maps_lie_on_their_files() {
    let server = Server::start(&[]);
    let (_, bytes) = neilvaltec();
    let query = format!("file=neilvaltec_test.plan&{QUERY}&corners=stop");
    let (code, answer) = plan(&server, &query, &bytes);
    assert_eq!(code, 200, "{answer}");
    let close = |a: [f64; 2], b: [f64; 2], what: &str| {
        assert!(
            (a[0] - b[0]).abs() < 1e-7 && (a[1] - b[1]).abs() < 1e-7,
            "{what}: {a:?} against {b:?}"
        );
    };
    let mut legs = 0;
    for (k, (map, text)) in array(&answer["maps"])
        .iter()
        .zip(array(&answer["texts"]))
        .enumerate()
    {
        assert_eq!(map["file"], text["file"]);
        let file: Value = serde_json::from_str(text["text"].as_str().unwrap()).unwrap();
        let home = deg(&file["mission"]["plannedHomePosition"]);
        close(
            [
                f(&map["home"]["latitude_deg"]),
                f(&map["home"]["longitude_deg"]),
            ],
            home,
            "home",
        );
        let items = array(&file["mission"]["items"]);
        let position = |item: u64| -> [f64; 2] {
            let it = items.iter().find(|i| i["doJumpId"] == item).unwrap();
            [f(&it["params"][4]), f(&it["params"][5])]
        };
        let parts: Vec<&Vec<Value>> = ["way_out", "route", "way_home"]
            .iter()
            .map(|p| array(&map[*p]))
            .collect();
        let kinds = |p: &Vec<Value>| -> Vec<String> {
            p.iter()
                .map(|s| s["kind"].as_str().unwrap().to_string())
                .collect()
        };
        match k {
            0 => assert_eq!(kinds(parts[0]), ["take-off"]),
            _ => assert_eq!(kinds(parts[0]), ["take-off", "leg"]),
        }
        assert!(kinds(parts[2])
            .iter()
            .all(|k| ["return", "descent", "landing"].contains(&k.as_str())));
        assert!(kinds(parts[1]).iter().filter(|k| *k == "leg").count() >= 5);
        let first = &parts[0][0]["points_deg"][0];
        close(deg(first), home, "take-off");
        let last_seg = parts[2].last().unwrap();
        let last = array(&last_seg["points_deg"]).last().unwrap();
        close(deg(last), home, "landing");
        // Numbered as the file's segments, in order, with no segment left out.
        let indices: Vec<u64> = parts
            .iter()
            .flat_map(|p| p.iter().map(|s| s["index"].as_u64().unwrap()))
            .collect();
        assert_eq!(indices, (1..=indices.len() as u64).collect::<Vec<_>>());
        for s in parts.iter().flat_map(|p| p.iter()) {
            if s["kind"] != "leg" {
                continue;
            }
            let item = s["item"].as_u64().unwrap();
            let end = array(&s["points_deg"]).last().unwrap();
            close(
                deg(end),
                position(item),
                &format!("sortie {} item {item}", k + 1),
            );
            legs += 1;
        }
    }
    assert!(legs >= 52, "{legs} legs: the survey has 52 waypoints");
}

/// Metres per degree of latitude and of longitude at `lat_deg` on the WGS 84 ellipsoid (the
/// meridian and prime-vertical radii): the local tangent plane a planner file is flown in.
fn metres_per_deg(lat_deg: f64) -> (f64, f64) {
    let (a, e2) = (6_378_137.0_f64, 6.694_379_990_14e-3_f64);
    let s = lat_deg.to_radians().sin();
    let w = (1.0 - e2 * s * s).sqrt();
    let meridian = a * (1.0 - e2) / (w * w * w);
    let normal = a / w;
    (
        meridian.to_radians(),
        normal.to_radians() * lat_deg.to_radians().cos(),
    )
}

/// The farthest waypoint (MAV_CMD 16) of a `.plan` from its planned home, m, survey items
/// included.
fn farthest_waypoint_m(plan: &Value) -> f64 {
    let home = deg(&plan["mission"]["plannedHomePosition"]);
    let (m_lat, m_lon) = metres_per_deg(home[0]);
    let mut far: f64 = 0.0;
    let mut stack = vec![&plan["mission"]];
    while let Some(v) = stack.pop() {
        match v {
            Value::Object(o) => {
                if o.get("command").is_some_and(|c| c == 16) {
                    let p = &o["params"];
                    let (dn, de) = ((f(&p[4]) - home[0]) * m_lat, (f(&p[5]) - home[1]) * m_lon);
                    far = far.max(dn.hypot(de));
                }
                stack.extend(o.values());
            }
            Value::Array(a) => stack.extend(a),
            _ => {}
        }
    }
    far
}

/// No plan keeps a 99 % reserve: the answer of an infeasible mission (200), the command line's
/// (`aloft plan`, exit 1) to the byte; its reason names how far the route reaches, the farthest
/// waypoint of the file.
#[test]
fn data_val_no_plan_is_an_answer_with_its_reason() {
    let server = Server::start(&[]);
    let (path, bytes) = neilvaltec();
    let query = format!("file={}&reserve_percent=99", encoded(&path));
    let (code, text) = server.request("POST", &format!("/api/plan?{query}"), None, &bytes);
    assert_eq!(code, 200, "{text}");
    let answer: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(answer["feasible"], false, "{answer}");
    let reason = answer["reason"].as_str().unwrap();
    let reaches: f64 = reason
        .split(" m from home")
        .next()
        .and_then(|r| r.rsplit(' ').next())
        .and_then(|m| m.parse().ok())
        .unwrap_or_else(|| panic!("no distance in {reason:?}"));
    let far = farthest_waypoint_m(&serde_json::from_slice(&bytes).unwrap());
    // The reason's metres are rounded to one.
    assert!(
        (reaches - far).abs() <= 0.5 + 1e-6,
        "{reaches} m said, {far} m in the file"
    );
    let dir = scratch("serve-plan", "none");
    let (code, out, _) = run(&[
        "plan",
        &path,
        "--reserve-percent",
        "99",
        "-o",
        dir.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert_eq!(code, 1);
    assert_eq!(text, out.trim_end());
    assert!(!dir.exists(), "no file is written without a plan");
}

/// The options of `aloft plan` are refused as `/api/mission` refuses its own: a value that is not
/// one (400, naming the key), a value out of range (422, the command line's message), an option
/// `aloft plan` does not take (400), a file option naming no given file (400); a page of another
/// origin is refused (403), a body declared past the limit is refused before it is read (413),
/// the method must be POST (405); the server serves on.
#[test]
fn plan_requests_are_refused_as_mission_requests_are() {
    let server = Server::start(&[]);
    let error = |code: u16, query: &str, key: &str| {
        let (got, answer) = plan(&server, query, b"");
        assert_eq!(got, code, "{query}: {answer}");
        let message = answer["error"].as_str().unwrap();
        assert!(message.contains(key), "{query}: {message}");
    };
    error(400, "speeds=fastest", "'speeds' of POST /api/plan");
    error(400, "max_speed=abc", "'max_speed' of POST /api/plan");
    error(400, "overlap_m=nan", "'overlap_m' of POST /api/plan");
    error(
        400,
        "sweep_speed=10",
        "unknown option 'sweep_speed' for POST /api/plan",
    );
    error(400, "vehicle=/etc/passwd", "'vehicle' of POST /api/plan");
    // Out of range: the command line's own message.
    let (code, answer) = plan(&server, "overlap_m=-5", b"");
    assert_eq!(code, 422, "{answer}");
    let (exit, _, err) = run(&["plan", "--overlap-m", "-5", "-o", "/nonexistent/x"]);
    assert_eq!(exit, 2);
    let message = err.trim_end().strip_prefix("aloft: error: ").unwrap();
    assert_eq!(answer["error"], message);
    assert!(message.contains("overlap_m"), "{message}");
    // A page of another origin, or of another site.
    for header in ["Origin: http://evil.example", "Sec-Fetch-Site: cross-site"] {
        let a = server.send("POST", "/api/plan", &[header], b"");
        assert_eq!(a.status, 403, "{header}: {}", a.body);
        assert!(a.body.starts_with("{\"error\""), "{}", a.body);
    }
    // The page's own origin is served (the built-in demo, an empty body).
    let own = format!("Origin: http://{}", server.address);
    let a = server.send("POST", "/api/plan", &[&own], b"");
    assert_eq!(a.status, 200, "{}", a.body);
    let demo: Value = serde_json::from_str(&a.body).unwrap();
    assert_eq!(
        array(&demo["texts"]).len() as u64,
        demo["batteries"].as_u64().unwrap()
    );
    // Declared past the mission limit (32 MiB): refused before a byte of it is sent.
    let mut s = server.connect();
    let head = format!(
        "POST /api/plan HTTP/1.1\r\nHost: {}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
        server.address,
        40u64 << 20
    );
    s.write_all(head.as_bytes()).unwrap();
    let a = read_answer(&mut s);
    assert_eq!(a.status, 413, "{}", a.body);
    assert_eq!(server.get("/api/plan").0, 405);
    assert_eq!(server.get("/api/vehicles").0, 200);
}

/// Issue 41: the files of a plan are named after the upload's file name only, made safe (the
/// page zips them under these names): never the mission's own `name`, never a path, never
/// markup. Before, a mission without an extension named `../escaped` was answered as
/// `../escaped-1-of-1.toml`.
#[test]
fn plan_file_names_are_safe_whatever_the_upload_or_mission_is_called() {
    let server = Server::start(&[]);
    let mission = |name: &str| {
        format!(
            "name = {name:?}\ndefault_speed_mps = 8.0\n[[segment]]\nkind = \"take-off\"\naltitude_m = 20.0\nclimb_rate_mps = 2.0\n\
             [[segment]]\nkind = \"leg\"\neast_m = 300.0\nnorth_m = 0.0\n\
             [[segment]]\nkind = \"return\"\n[[segment]]\nkind = \"landing\"\nrate_mps = 1.0\n"
        )
    };
    for (file, inner, stem) in [
        ("mission", "../escaped", "mission"),
        ("../../etc/passwd", "/etc/passwd", "passwd"),
        (
            "<img src=x onerror=alert(1)>.toml",
            "<b>x</b>",
            "_img_src_x_onerror_alert_1__",
        ),
        ("..", "../x", "mission"),
    ] {
        let (code, answer) = plan(
            &server,
            &format!("file={}", encoded(file)),
            mission(inner).as_bytes(),
        );
        assert_eq!(code, 200, "{file}: {answer}");
        let files = array(&answer["files"]);
        assert_eq!(files.len(), 1, "{answer}");
        assert_eq!(
            files[0].as_str(),
            Some(format!("{stem}-1-of-1.toml").as_str()),
            "{file}"
        );
        for s in array(&answer["sorties"]) {
            assert_eq!(s["file"], files[0], "{file}");
        }
    }
}
