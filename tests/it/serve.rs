//! `aloft serve` on the loopback interface: its JSON API answers exactly as the command line's
//! `--format json` (the built-in vehicles, endurance, the demo and every shared mission file),
//! refuses options the command does not take (400), requests the engine refuses (422), a forged
//! `Host` (403) and an upload past the limit (413), and keeps serving after each.
#![cfg(feature = "serve")]

use crate::common;

use std::io::{BufRead, BufReader, Write};
use std::net::TcpStream;

use common::serve::{encoded, Server};
use common::{aloft, data_dir};

/// The command line's JSON text (its stdout without the final line break).
fn cli(args: &[&str]) -> String {
    common::cli(args).trim_end().to_string()
}

/// A request the command line refuses (`out`, exit 2) is refused alike: 422 with its message.
fn assert_refused_alike(out: &std::process::Output, (code, body): (u16, &str), what: &str) {
    assert_eq!(code, 422, "{what}: {body}");
    let message = common::stderr(out);
    let message = message.trim_end().strip_prefix("aloft: error: ").unwrap();
    let got: serde_json::Value = serde_json::from_str(body).unwrap();
    assert_eq!(got["error"], message, "{what}");
}

#[test]
fn the_api_answers_as_the_command_line() {
    let server = Server::start(&[]);
    assert_eq!(
        server.get("/api/vehicles"),
        (200, cli(&["vehicles", "--format", "json"]))
    );
    let (code, body) = server.get("/api/endurance?payload_kg=0.5&wind_speed=4&wind_from=270");
    assert_eq!(code, 200);
    let expected = cli(&[
        "endurance",
        "--payload-kg",
        "0.5",
        "--wind-speed",
        "4",
        "--wind-from",
        "270",
        "--format",
        "json",
    ]);
    assert_eq!(body, expected);
    // The built-in demo (an empty body), with options.
    let (code, body) = server.request(
        "POST",
        "/api/mission?payload_kg=0.3&reserve_percent=25",
        None,
        b"",
    );
    assert_eq!(code, 200);
    let expected = cli(&[
        "mission",
        "--payload-kg",
        "0.3",
        "--reserve-percent",
        "25",
        "--format",
        "json",
    ]);
    assert_eq!(body, expected);
    // Every shared mission file, named as the command line is given it.
    let dir = data_dir().join("missions");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "README.md")
        .collect();
    names.sort();
    assert_eq!(names.len(), 12);
    for name in names {
        let path = dir.join(&name).display().to_string();
        let out = aloft(&["mission", &path, "--format", "json"]);
        let bytes = std::fs::read(&path).unwrap();
        let (code, body) =
            server.request("POST", &format!("/api/mission?file={path}"), None, &bytes);
        match out.status.code() {
            Some(0 | 1) => {
                assert_eq!(code, 200, "{name}: {body}");
                assert_eq!(
                    body,
                    String::from_utf8(out.stdout).unwrap().trim_end(),
                    "{name}"
                );
            }
            // Refused by the command line: the same message, 422.
            _ => assert_refused_alike(&out, (code, &body), &name),
        }
    }
}

#[test]
fn the_api_refuses_bad_requests_and_keeps_serving() {
    let server = Server::start(&["--max-upload-mb", "1"]);
    let (code, body) = server.get("/api/endurance?bogus=1");
    assert_eq!(code, 400, "{body}");
    assert!(body.contains("unknown option 'bogus'"), "{body}");
    let (code, body) = server.get("/api/endurance?payload_kg=abc");
    assert_eq!(code, 400, "{body}");
    let got: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(
        got["error"],
        "invalid value 'abc' for 'payload_kg' of GET /api/endurance: not a number"
    );
    let (code, body) = server.get("/api/files/abc");
    assert_eq!(code, 404, "{body}");
    assert!(body.starts_with("{\"error\""), "{body}");
    let (code, body) = server.request("POST", "/api/mission?file=x.toml", None, b"hello");
    assert_eq!(code, 422, "{body}");
    assert!(body.contains("x.toml"), "{body}");
    // A page elsewhere reaching the server by DNS rebinding.
    let (code, body) = server.request("GET", "/api/vehicles", Some("evil.example:80"), b"");
    assert_eq!(code, 403, "{body}");
    // Past the limit (a log's, --max-upload-mb): 413, and the server goes on.
    let big = vec![b'#'; 2 << 20];
    let (code, _) = server.request("POST", "/api/log/info?file=big.bin", None, &big);
    assert_eq!(code, 413);
    let (code, _) = server.get("/api/vehicles");
    assert_eq!(code, 200);
    // `localhost` is the server too.
    let port = server.address.rsplit(':').next().unwrap().to_string();
    let (code, _) = server.request(
        "GET",
        "/api/vehicles",
        Some(&format!("localhost:{port}")),
        b"",
    );
    assert_eq!(code, 200);
}

/// Every shared flight log, sent as the body of `POST /api/log/info` and named as the command
/// line is given it: the command line's answer, or its message with 422 where it refuses the
/// file.
#[test]
fn every_shared_log_answers_as_the_command_line() {
    let server = Server::start(&[]);
    let mut logs = Vec::new();
    for sub in [
        "flight_logs",
        "mcap_foreign",
        "px4_flugdrohne/ulg",
        "kaist_energy_drone",
        "telemetry",
    ] {
        logs.extend(common::files(sub, |n| n != "README.md"));
    }
    assert_eq!(logs.len(), 29);
    let mut answered = 0;
    for log in &logs {
        let path = log.display().to_string();
        let out = aloft(&["log", "info", &path, "--format", "json"]);
        let bytes = std::fs::read(log).unwrap();
        let (code, body) = server.request(
            "POST",
            &format!("/api/log/info?file={}", encoded(&path)),
            None,
            &bytes,
        );
        if out.status.code() == Some(0) {
            assert_eq!(code, 200, "{path}: {body}");
            assert_eq!(body, common::stdout(&out).trim_end(), "{path}");
            answered += 1;
        } else {
            assert_refused_alike(&out, (code, &body), &path);
        }
    }
    // The flight logs all read; the 5 telemetry logs are for `aloft live`.
    assert_eq!(answered, 24);
    // With an option, and one the command does not take.
    let log = &common::files("kaist_energy_drone", |n| n.ends_with(".csv"))[0];
    let path = log.display().to_string();
    let bytes = std::fs::read(log).unwrap();
    let (code, body) = server.request(
        "POST",
        &format!("/api/log/info?file={path}&max_lag=5"),
        None,
        &bytes,
    );
    assert_eq!(code, 200, "{body}");
    assert_eq!(
        body,
        cli(&["log", "info", &path, "--max-lag", "5", "--format", "json"])
    );
    let (code, body) = server.request("POST", "/api/log/info?bogus=1", None, &bytes);
    assert_eq!(code, 400, "{body}");
}

/// An upload past the limit to `/api/log/info` (streamed to its file, not held) gets 413.
#[test]
fn a_log_past_the_upload_limit_is_refused() {
    let server = Server::start(&["--max-upload-mb", "1"]);
    let big = vec![0u8; 3 << 20];
    let (code, body) = server.request("POST", "/api/log/info?file=big.bin", None, &big);
    assert_eq!(code, 413, "{body}");
    assert!(body.contains("1 MiB"), "{body}");
    assert_eq!(server.get("/api/vehicles").0, 200);
}

/// The page's map: each leg of a QGroundControl plan flown with stops ends on its item's
/// latitude and longitude as the file gives them (within 1e-7 deg, 1 cm); the segments are the
/// mission answer's; the state of charge runs from the start to the answer's end; the band of
/// the scenarios is ordered.
#[test]
fn the_map_holds_the_route_of_the_file() {
    let server = Server::start(&[]);
    let path = data_dir().join("missions/kasperg3_mission.plan");
    let bytes = std::fs::read(&path).unwrap();
    let query = "file=k.plan&corners=stop&samples=40";
    let (code, body) = server.request("POST", &format!("/api/map?{query}"), None, &bytes);
    assert_eq!(code, 200, "{body}");
    let map: serde_json::Value = serde_json::from_str(&body).unwrap();
    let (code, body) = server.request("POST", &format!("/api/mission?{query}"), None, &bytes);
    assert_eq!(code, 200, "{body}");
    let answer: serde_json::Value = serde_json::from_str(&body).unwrap();
    // The items' positions, from the file itself.
    let plan: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
    let items = plan["mission"]["items"].as_array().unwrap();
    let home = &plan["mission"]["plannedHomePosition"];
    assert_eq!(map["home"]["latitude_deg"], home[0]);
    assert_eq!(map["home"]["longitude_deg"], home[1]);
    let mut legs = 0;
    for s in map["segments"].as_array().unwrap() {
        if s["kind"] != "leg" {
            continue;
        }
        let item = s["item"].as_u64().unwrap() as usize;
        let p = &items[item - 1]["params"];
        let end = s["points_deg"].as_array().unwrap().last().unwrap();
        for (got, want) in [(&end[0], &p[4]), (&end[1], &p[5])] {
            let (g, w) = (got.as_f64().unwrap(), want.as_f64().unwrap());
            assert!((g - w).abs() < 1e-7, "item {item}: {g} against {w}");
        }
        legs += 1;
    }
    assert!(legs >= 10, "{legs}");
    // One path per segment of the answer, in its order.
    let indices = |v: &serde_json::Value| -> Vec<u64> {
        v["segments"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["index"].as_u64().unwrap())
            .collect()
    };
    assert_eq!(indices(&map), indices(&answer));
    let soc = map["battery"]["soc"].as_array().unwrap();
    assert_eq!(soc[0], answer["start_soc"]);
    assert_eq!(soc[soc.len() - 1], answer["end_soc"]);
    let band = &map["band"];
    let col = |k: &str| -> Vec<f64> {
        band[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (p5, p50, p95) = (col("p5"), col("p50"), col("p95"));
    assert!(p5.len() > 100);
    assert!((0..p5.len()).all(|k| p5[k] <= p50[k] && p50[k] <= p95[k]));
    // The demo has no geographic home: metres only.
    let (code, body) = server.request("POST", "/api/map", None, b"");
    assert_eq!(code, 200, "{body}");
    let demo: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert!(demo.get("home").is_none() && demo.get("band").is_none());
    assert!(demo["segments"][1].get("points_deg").is_none());
}

/// The files given on the command line: listed, a mission's text served, a log's `log info`
/// answered as the command line's; a file that is neither is bad input (exit 2, named).
#[test]
fn the_files_given_are_served() {
    let demo = common::fixture("missions", "demo-survey.toml");
    let log = data_dir().join("flight_logs/pyulog_sample_log_small.ulg");
    let (demo, log) = (demo.display().to_string(), log.display().to_string());
    let server = Server::start(&[&demo, &log]);
    let (code, body) = server.get("/api/config");
    assert_eq!(code, 200);
    let config: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(config["files"][0]["kind"], "mission");
    assert_eq!(config["files"][0]["name"], demo.as_str());
    assert_eq!(config["files"][1]["kind"], "log");
    assert_eq!(config["live"], false);
    assert!(config.get("tiles").is_none());
    assert_eq!(
        server.get("/api/files/0"),
        (200, std::fs::read_to_string(&demo).unwrap())
    );
    assert_eq!(
        server.get("/api/files/1/info"),
        (200, cli(&["log", "info", &log, "--format", "json"]))
    );
    assert_eq!(server.get("/api/files/1").0, 404);
    assert_eq!(server.get("/api/files/7").0, 404);
    // The page and its files; anything else is 404.
    let (code, page) = server.get("/");
    assert_eq!(code, 200);
    assert!(page.contains("id=\"map\"") && page.contains("id=\"segments\""));
    assert_eq!(server.get("/vendor/leaflet/leaflet.js").0, 200);
    assert_eq!(server.get("/no/such/file.js").0, 404);
    // Bad input at start: exit 2, one line naming the file or the value.
    let bad = common::scratch("serve", "bad.plan");
    std::fs::write(&bad, "{ not a plan").unwrap();
    let (code, _, err) = common::run(&["serve", "--listen", "127.0.0.1:0", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("bad.plan") && err.lines().count() == 1,
        "{err}"
    );
    let (code, _, err) = common::run(&["serve", "--listen", "127.0.0.1:0", "/no/such/file.csv"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("/no/such/file.csv"), "{err}");
    let (code, _, err) = common::run(&[
        "serve",
        "--tiles",
        "https://t.example/a.png",
        "--attribution",
        "x",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--tiles"), "{err}");
    let (code, _, err) = common::run(&["serve", "--tiles", "https://t.example/{z}/{x}/{y}.png"]);
    assert_eq!(code, 2, "{err}");
    // With a tile layer, the page is told it.
    let server = Server::start(&[
        "--tiles",
        "https://tiles.example/{z}/{x}/{y}.png",
        "--attribution",
        "(c) Example",
    ]);
    let config: serde_json::Value = serde_json::from_str(&server.get("/api/config").1).unwrap();
    assert_eq!(config["tiles"], "https://tiles.example/{z}/{x}/{y}.png");
    assert_eq!(config["attribution"], "(c) Example");
}

/// `aloft serve --tlog`: the updates streamed to the page are `aloft live`'s lines (each one
/// received equals the command line's line of the same time), and the stream ends with the
/// flight's summary.
#[test]
fn the_live_feed_streams_the_updates_of_aloft_live() {
    let tlog = data_dir().join("telemetry/kudrone_guided_sitl.tlog");
    let tlog = tlog.display().to_string();
    let server = Server::start(&["--tlog", &tlog, "--speed", "40"]);
    let config: serde_json::Value = serde_json::from_str(&server.get("/api/config").1).unwrap();
    assert_eq!(config["live"], true);
    let mut s = TcpStream::connect(&server.address).expect("connect");
    let head = format!(
        "GET /api/live HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n\r\n",
        server.address
    );
    s.write_all(head.as_bytes()).unwrap();
    let mut events: Vec<(String, String)> = Vec::new();
    let mut kind = String::new();
    for line in BufReader::new(s).lines() {
        let line = line.unwrap();
        if let Some(k) = line.strip_prefix("event: ") {
            kind = k.to_string();
        } else if let Some(d) = line.strip_prefix("data: ") {
            events.push((kind.clone(), d.to_string()));
            if kind == "end" {
                break;
            }
        }
    }
    let expected = cli(&[
        "live", "--tlog", &tlog, "--speed", "max", "--format", "json",
    ]);
    let lines: Vec<&str> = expected.lines().collect();
    let updates: Vec<&String> = events
        .iter()
        .filter(|(k, _)| k == "update")
        .map(|(_, d)| d)
        .collect();
    assert!(updates.len() >= 20, "{} updates", updates.len());
    for u in &updates {
        assert!(lines.contains(&u.as_str()), "not a line of aloft live: {u}");
    }
    let (kind, end) = events.last().unwrap();
    assert_eq!(kind, "end");
    let end: serde_json::Value = serde_json::from_str(end).unwrap();
    let cli_end: serde_json::Value = serde_json::from_str(lines[lines.len() - 1]).unwrap();
    assert_eq!(end["summary"], cli_end["summary"]);
    // Without a flight: 404.
    let plain = Server::start(&[]);
    assert_eq!(plain.get("/api/live").0, 404);
}

/// No request takes the server down or gets a server error: wrong methods, options that are not
/// numbers or not finite, bytes that are not text, names that climb out of the upload folder, a
/// long query, and 200 truncations of a real plan file; the server answers each with a 4xx or an
/// answer, and serves the next.
#[test]
fn no_request_takes_the_server_down() {
    let server = Server::start(&["--max-upload-mb", "1"]);
    let long = format!("/api/endurance?payload_kg={}", "9".repeat(100_000));
    let requests: Vec<(&str, &str, Vec<u8>)> = vec![
        ("GET", "/api/mission", vec![]),
        ("POST", "/api/endurance", vec![]),
        ("GET", "/api/endurance?wind_speed=nan&wind_from=0", vec![]),
        ("GET", "/api/endurance?wind_speed=inf&wind_from=0", vec![]),
        ("GET", "/api/endurance?payload_kg=-1", vec![]),
        ("GET", "/api/endurance?payload_kg=1e400", vec![]),
        ("GET", "/api/endurance?payload_sweep=0:1:0", vec![]),
        ("GET", "/api/endurance?vehicle=/etc/passwd", vec![]),
        (
            "POST",
            "/api/mission?file=%ff%fe",
            vec![0xff, 0xfe, 0x00, 0x80],
        ),
        ("POST", "/api/map?corners=sideways", vec![]),
        ("POST", "/api/mission?samples=0", vec![]),
        (
            "POST",
            "/api/log/info?file=../../../../tmp/escape.bin",
            b"x".to_vec(),
        ),
        ("POST", "/api/log/info?file=..", vec![0u8; 1000]),
        ("POST", "/api/log/info", vec![]),
        ("GET", "/%00", vec![]),
        ("GET", "/../Cargo.toml", vec![]),
        ("GET", "/vendor/../../Cargo.toml", vec![]),
        ("GET", "/api/files/99999999999999999999999", vec![]),
        ("GET", "/api/live", vec![]),
        ("GET", long.as_str(), vec![]),
    ];
    for (method, path, body) in &requests {
        let (code, answer) = server.request(method, path, None, body);
        assert!(
            (200..500).contains(&code),
            "{method} {}: {code} {answer}",
            &path[..path.len().min(80)]
        );
    }
    assert!(!std::path::Path::new("/tmp/escape.bin").exists());
    // No file outside the page's.
    for path in ["/../Cargo.toml", "/vendor/../../Cargo.toml"] {
        assert_eq!(server.get(path).0, 404, "{path}");
    }
    let plan = std::fs::read(data_dir().join("missions/kasperg3_mission.plan")).unwrap();
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    for _ in 0..200 {
        // xorshift: a repeatable choice of where to cut.
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let cut = (state % plan.len() as u64) as usize;
        let (code, answer) =
            server.request("POST", "/api/mission?file=cut.plan", None, &plan[..cut]);
        assert!(matches!(code, 200 | 422), "cut at {cut}: {code} {answer}");
    }
    assert_eq!(server.get("/api/vehicles").0, 200);
}

/// A vehicle file of the user's in the scratch folder as `file`: `aloft vehicles template`,
/// named `name` inside.
fn template_vehicle(file: &str, name: &str) -> String {
    let text = common::ok_stdout(&["vehicles", "template"]);
    let text = text.replacen("name = \"my-quad\"", &format!("name = \"{name}\""), 1);
    assert!(text.contains(&format!("name = \"{name}\"")));
    let path = common::scratch("serve-vehicles", file);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// JSON text, parsed.
fn parsed(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("{e}: {text}"))
}

/// The keys of a JSON object, sorted.
fn keys(v: &serde_json::Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
    k.sort();
    k
}

/// `aloft serve --vehicle FILE...` (issue 35 item 5): the vehicle files given (with `--vehicle`
/// and positionally) are in `/api/vehicles` after the built-ins, as `aloft vehicles` lists one;
/// the first `--vehicle` is the default of the page (`/api/config`) and of requests that name
/// none; a request names a given vehicle by its own name or the name it was given with, and is
/// answered as the command line with that file.
#[test]
fn vehicles_given_are_listed_and_flown_as_the_command_line_flies_them() {
    let quad = template_vehicle("my-quad.toml", "my-quad");
    let m600 = std::fs::read_to_string(common::fixture("vehicles", "dji-m600.toml")).unwrap();
    let m600 = m600.replacen("name = \"dji-m600\"", "name = \"my-m600\"", 1);
    let m600_path = common::scratch("serve-vehicles", "my-m600.toml");
    std::fs::write(&m600_path, m600).unwrap();
    let m600_path = m600_path.display().to_string();
    let server = Server::start(&[&m600_path, "--vehicle", &quad, "dji-inspire1"]);
    let config = parsed(&server.get("/api/config").1);
    assert_eq!(config["default_vehicle"], "my-quad");
    let kinds = common::strs_of(&config["files"], "kind");
    assert_eq!(kinds, ["vehicle", "vehicle"]);
    // The list: the built-ins as `aloft vehicles` lists them, then the files given.
    let (code, body) = server.get("/api/vehicles");
    assert_eq!(code, 200, "{body}");
    let listed = parsed(&body);
    let listed = listed.as_array().unwrap();
    let builtins = parsed(&cli(&["vehicles", "--format", "json"]));
    let builtins = builtins.as_array().unwrap();
    assert_eq!(&listed[..builtins.len()], builtins.as_slice());
    let names: Vec<&str> = listed[builtins.len()..]
        .iter()
        .map(|v| v["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["my-m600", "my-quad"]);
    let mine = &listed[builtins.len() + 1];
    // The shape of a built-in's entry (the template has no [source], which is left out).
    let mut shape = keys(&builtins[0]);
    shape.retain(|k| k != "source");
    assert_eq!(keys(mine), shape);
    assert_eq!(mine["batteries"], serde_json::json!(["3S-5000"]));
    assert_eq!(mine["models"], serde_json::json!(["power"]));
    let endurance = parsed(&cli(&["endurance", "--vehicle", &quad, "--format", "json"]));
    assert_eq!(mine["takeoff_mass_kg"], endurance["takeoff_mass_kg"]);
    // Flown by its own name, by the name it was given with, and by default: the command line's
    // answer with the file, the same options.
    let expected = parsed(&cli(&[
        "mission",
        "--vehicle",
        &quad,
        "--payload-kg",
        "0.1",
        "--wind-speed",
        "3",
        "--wind-from",
        "90",
        "--format",
        "json",
    ]));
    assert_eq!(expected["vehicle"], "my-quad");
    let options = "payload_kg=0.1&wind_speed=3&wind_from=90";
    for vehicle in [Some("my-quad"), Some(quad.as_str()), None] {
        let query = match vehicle {
            Some(v) => format!("vehicle={}&{options}", encoded(v)),
            None => options.to_string(),
        };
        let (code, body) = server.request("POST", &format!("/api/mission?{query}"), None, b"");
        assert_eq!(code, 200, "{vehicle:?}: {body}");
        assert_eq!(parsed(&body), expected, "{vehicle:?}");
    }
    // The positional file by its own name, the built-in given with --vehicle by its name.
    let (code, body) = server.get("/api/endurance?vehicle=my-m600&payload_kg=1");
    assert_eq!(code, 200, "{body}");
    let expected = cli(&[
        "endurance",
        "--vehicle",
        &m600_path,
        "--payload-kg",
        "1",
        "--format",
        "json",
    ]);
    assert_eq!(parsed(&body), parsed(&expected));
    let (code, body) = server.request("POST", "/api/mission?vehicle=dji-inspire1", None, b"");
    assert_eq!(code, 200, "{body}");
    let expected = cli(&["mission", "--vehicle", "dji-inspire1", "--format", "json"]);
    assert_eq!(parsed(&body), parsed(&expected));
    // Bad input at start: exit 2, one line naming the file.
    let bad = common::scratch("serve-vehicles", "bad-vehicle.toml");
    std::fs::write(&bad, "name = 3\n").unwrap();
    let bad = bad.display().to_string();
    for file in [bad.as_str(), "/no/such/vehicle.toml"] {
        let (code, _, err) = common::run(&["serve", "--listen", "127.0.0.1:0", "--vehicle", file]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(file) && err.lines().count() == 1, "{err}");
    }
    // A mission taken by --vehicle from the files after it says so.
    let demo = common::fixture("missions", "demo-survey.toml");
    let demo = demo.display().to_string();
    let (code, _, err) = common::run(&[
        "serve",
        "--listen",
        "127.0.0.1:0",
        "--vehicle",
        &quad,
        &demo,
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("a mission, not a vehicle file"), "{err}");
}

/// `POST /api/vehicles` (a vehicle file dropped on the page): kept under its own name, answered
/// with its entry, then flown by that name as the command line flies the file; a bad file is
/// 422 with the command line's message, a body past 256 KiB 413, a name that is a built-in's or
/// a given vehicle's 422 naming the clash, a page of another origin 403; the same name again
/// replaces the vehicle; past 32 vehicles sent the oldest is forgotten.
#[test]
fn a_vehicle_file_sent_is_kept_and_flown_by_its_name() {
    let quad = template_vehicle("my-quad.toml", "my-quad");
    let sent = template_vehicle("sent.toml", "sent-quad");
    let server = Server::start(&["--vehicle", &quad]);
    let text = std::fs::read(&sent).unwrap();
    let (code, body) = server.request("POST", "/api/vehicles?file=sent.toml", None, &text);
    assert_eq!(code, 200, "{body}");
    let entry = parsed(&body);
    assert_eq!(entry["name"], "sent-quad");
    let listed = parsed(&server.get("/api/vehicles").1);
    let listed = listed.as_array().unwrap();
    assert_eq!(listed.last().unwrap(), &entry);
    assert_eq!(
        listed.iter().filter(|v| v["name"] == "sent-quad").count(),
        1
    );
    // Flown by its name as the command line flies the file.
    let expected = cli(&[
        "mission",
        "--vehicle",
        &sent,
        "--reserve-percent",
        "25",
        "--format",
        "json",
    ]);
    let (code, body) = server.request(
        "POST",
        "/api/mission?vehicle=sent-quad&reserve_percent=25",
        None,
        b"",
    );
    assert_eq!(code, 200, "{body}");
    assert_eq!(parsed(&body), parsed(&expected));
    let (code, body) = server.get("/api/endurance?vehicle=sent-quad");
    assert_eq!(code, 200, "{body}");
    let expected = cli(&["endurance", "--vehicle", &sent, "--format", "json"]);
    assert_eq!(parsed(&body), parsed(&expected));
    for route in ["/api/map", "/api/plan"] {
        let (code, body) = server.request("POST", &format!("{route}?vehicle=sent-quad"), None, b"");
        assert_eq!(code, 200, "{route}: {body}");
    }
    // A bad file: 422, the command line's one line (the file named as it was sent).
    let bad = common::scratch("serve-vehicles", "typo.toml");
    let typo =
        String::from_utf8(text.clone())
            .unwrap()
            .replacen("max_tilt_deg", "max_tilt_degs", 1);
    std::fs::write(&bad, &typo).unwrap();
    let bad = bad.display().to_string();
    let out = aloft(&["endurance", "--vehicle", &bad, "--format", "json"]);
    let (code, body) = server.request(
        "POST",
        &format!("/api/vehicles?file={}", encoded(&bad)),
        None,
        typo.as_bytes(),
    );
    assert_refused_alike(&out, (code, &body), "typo.toml");
    assert!(!parsed(&body)["error"].as_str().unwrap().contains('\n'));
    let (code, body) = server.request("POST", "/api/vehicles?file=x.toml", None, &[0xff, 0xfe]);
    assert_eq!(code, 422, "{body}");
    assert!(body.contains("x.toml: not UTF-8 text"), "{body}");
    // Past the limit.
    let mut big = text.clone();
    big.extend(std::iter::repeat_n(b'#', 300 << 10));
    let (code, body) = server.request("POST", "/api/vehicles?file=big.toml", None, &big);
    assert_eq!(code, 413, "{body}");
    assert!(body.contains("256 KiB"), "{body}");
    // A name of a built-in or of a vehicle given: 422 naming the clash; nothing kept.
    let text_named = |name: &str| {
        String::from_utf8(text.clone()).unwrap().replacen(
            "name = \"sent-quad\"",
            &format!("name = \"{name}\""),
            1,
        )
    };
    for (name, clash) in [
        ("dji-m100", "is a built-in vehicle's"),
        ("my-quad", "given to aloft serve on its command line"),
        (quad.as_str(), "given to aloft serve on its command line"),
    ] {
        let (code, body) = server.request(
            "POST",
            "/api/vehicles?file=clash.toml",
            None,
            text_named(&name.replace('\\', "\\\\")).as_bytes(),
        );
        assert_eq!(code, 422, "{name}: {body}");
        assert!(
            body.contains(clash) && body.contains("clash.toml"),
            "{body}"
        );
    }
    let (code, body) = server.get("/api/endurance?vehicle=dji-m100");
    assert_eq!((code, body), (200, cli(&["endurance", "--format", "json"])));
    // An option it does not take; a page of another origin.
    let (code, body) = server.request("POST", "/api/vehicles?payload_kg=1", None, &text);
    assert_eq!(code, 400, "{body}");
    let evil = text_named("evil-quad");
    let a = server.send(
        "POST",
        "/api/vehicles?file=evil.toml",
        &["Origin: http://evil.example"],
        evil.as_bytes(),
    );
    assert_eq!(a.status, 403, "{}", a.body);
    let (code, _) = server.request("POST", "/api/mission?vehicle=evil-quad", None, b"");
    assert_eq!(code, 400);
    // The same name again replaces it (here a heavier airframe).
    let heavier =
        String::from_utf8(text.clone())
            .unwrap()
            .replacen("mass_kg = 0.95", "mass_kg = 1.05", 1);
    assert_ne!(heavier.as_bytes(), text.as_slice());
    let (code, body) = server.request(
        "POST",
        "/api/vehicles?file=sent.toml",
        None,
        heavier.as_bytes(),
    );
    assert_eq!(code, 200, "{body}");
    let mass = parsed(&body)["takeoff_mass_kg"].as_f64().unwrap();
    let before = entry["takeoff_mass_kg"].as_f64().unwrap();
    // 0.1 kg heavier, to the rounding of sums of decimals.
    assert!((mass - before - 0.1).abs() < 1e-9, "{mass} {before}");
    let listed = parsed(&server.get("/api/vehicles").1);
    let sent_names = |listed: &serde_json::Value| -> Vec<String> {
        listed
            .as_array()
            .unwrap()
            .iter()
            .skip(builtin_and_given())
            .map(|v| v["name"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(sent_names(&listed), ["sent-quad"]);
    // Past 32 vehicles sent, the oldest is forgotten.
    for k in 0..32 {
        let (code, body) = server.request(
            "POST",
            &format!("/api/vehicles?file=v{k}.toml"),
            None,
            text_named(&format!("v{k}")).as_bytes(),
        );
        assert_eq!(code, 200, "v{k}: {body}");
    }
    let names = sent_names(&parsed(&server.get("/api/vehicles").1));
    let expected: Vec<String> = (0..32).map(|k| format!("v{k}")).collect();
    assert_eq!(names, expected);
    let (code, body) = server.request("POST", "/api/mission?vehicle=sent-quad", None, b"");
    assert_eq!(code, 400, "{body}");
    assert!(body.contains("sent-quad"), "{body}");
    let (code, body) = server.request("POST", "/api/mission?vehicle=v31", None, b"");
    assert_eq!(code, 200, "{body}");
}

/// The built-ins and the one vehicle given in [`a_vehicle_file_sent_is_kept_and_flown_by_its_name`].
fn builtin_and_given() -> usize {
    parsed(&cli(&["vehicles", "--format", "json"]))
        .as_array()
        .unwrap()
        .len()
        + 1
}
