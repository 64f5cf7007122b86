//! `aloft serve` holds (issue 41): the server's part of each finding of the review that attacked
//! it again, as a test that failed on the server before the fix. The page's own part (markup in
//! names shown as text in a real browser) is in `tests/browser/run.mjs`.
#![cfg(all(feature = "serve", unix))]

use crate::common;

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use aloft_planner::mission_toml::{landing, leg, return_home, take_off};
use common::serve::{Answer, Server};
use common::{fixture, scratch};

/// The command line's JSON answer (stdout without its final line break).
fn cli(args: &[&str]) -> String {
    common::cli(args).trim_end().to_string()
}

/// A long survey in code: `lines` passes of 180 m at 8 m/s between east 20 m and 200 m, 10 m
/// apart (north 20 m to 210 m, then again), at 40 m; a return and a landing.
fn long_survey(lines: usize) -> String {
    let mut text = String::from("name = \"long survey\"\n[home]\neast_m = 0.0\nnorth_m = 0.0\n");
    text.push_str(&take_off(40.0, 3.0));
    for i in 0..lines {
        let north_m = 20.0 + (i % 20) as f64 * 10.0;
        let (a, b) = if i % 2 == 0 {
            (20.0, 200.0)
        } else {
            (200.0, 20.0)
        };
        text.push_str(&leg(a, north_m, 8.0));
        text.push_str(&leg(b, north_m, 8.0));
    }
    text.push_str(&return_home(8.0));
    text.push_str(&landing(1.0));
    text
}

/// A CSP's directives: each name with its sources.
fn directives(csp: &str) -> Vec<(String, Vec<String>)> {
    csp.split(';')
        .filter_map(|d| {
            let mut words = d.split_whitespace();
            let name = words.next()?.to_ascii_lowercase();
            Some((name, words.map(str::to_string).collect()))
        })
        .collect()
}

/// The sources of directive `name` (`None` when the policy does not give it).
fn sources<'a>(policy: &'a [(String, Vec<String>)], name: &str) -> Option<&'a [String]> {
    policy
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, s)| s.as_slice())
}

/// The policy of an answer, checked: no inline script, no plugin, no `<base>`, no framing, and
/// the page's content type not sniffed.
fn checked_policy(what: &str, a: &Answer) -> Vec<(String, Vec<String>)> {
    assert_eq!(
        a.header("x-content-type-options"),
        Some("nosniff"),
        "{what}: {:?}",
        a.headers
    );
    let csp = a
        .header("content-security-policy")
        .unwrap_or_else(|| panic!("{what}: no Content-Security-Policy in {:?}", a.headers));
    let policy = directives(csp);
    for (name, expected) in [
        ("default-src", "'self'"),
        ("script-src", "'self'"),
        ("object-src", "'none'"),
        ("base-uri", "'none'"),
        ("frame-ancestors", "'none'"),
    ] {
        assert_eq!(
            sources(&policy, name),
            Some([expected.to_string()].as_slice()),
            "{what}: {name} in {csp}"
        );
    }
    assert!(!csp.contains("unsafe-eval"), "{what}: {csp}");
    policy
}

/// Finding 1 (item 2): the page ran a file's name as markup; nothing told the browser that the
/// page runs no inline script, so any missed spot ran. Every answer, the page's files and the
/// API's (errors too), carries a Content-Security-Policy that forbids inline script, and
/// `nosniff`.
#[test]
fn every_answer_carries_a_policy_without_inline_script() {
    let server = Server::start(&[]);
    let evil_host = "Host: evil.example:80".to_string();
    let cases: [(&str, &str, Vec<&str>, u16); 10] = [
        ("GET", "/", vec![], 200),
        ("GET", "/app.js", vec![], 200),
        ("GET", "/style.css", vec![], 200),
        ("GET", "/vendor/leaflet/leaflet.js", vec![], 200),
        ("GET", "/api/config", vec![], 200),
        ("GET", "/api/vehicles", vec![], 200),
        ("POST", "/api/mission", vec![], 200),
        ("GET", "/no/such.js", vec![], 404),
        ("GET", "/api/mission", vec![], 405),
        ("GET", "/", vec![evil_host.as_str()], 403),
    ];
    for (method, path, extra, status) in cases {
        let what = format!("{method} {path} {extra:?}");
        let a = server.send(method, path, &extra, b"");
        assert_eq!(a.status, status, "{what}: {}", a.body);
        let policy = checked_policy(&what, &a);
        // No tile layer: images are the page's own (and the empty icon, a data: URL).
        let img = sources(&policy, "img-src").unwrap_or(&[]);
        assert!(
            img.iter().all(|s| s == "'self'" || s == "data:"),
            "{what}: img-src {img:?}"
        );
    }
    // A tile layer's server is the one other place images come from.
    let tiles = Server::start(&[
        "--tiles",
        "https://tiles.example.org/{z}/{x}/{y}.png",
        "--attribution",
        "example tiles",
    ]);
    let a = tiles.send("GET", "/", &[], b"");
    let policy = checked_policy("GET / with --tiles", &a);
    let img = sources(&policy, "img-src").unwrap_or(&[]);
    assert!(
        img.contains(&"'self'".to_string())
            && img.contains(&"https://tiles.example.org".to_string()),
        "img-src {img:?}"
    );
}

/// The page's own files hold no inline script, no inline event handler, and no markup built from
/// strings (`innerHTML` and its kin): a value reaches the page as text only.
#[test]
fn the_page_has_no_inline_script_and_builds_no_markup_from_strings() {
    let web = Path::new(env!("CARGO_MANIFEST_DIR")).join("web");
    let html = std::fs::read_to_string(web.join("index.html")).unwrap();
    let lower = html.to_ascii_lowercase();
    for (at, _) in lower.match_indices("<script") {
        let tag = &lower[at..at + lower[at..].find('>').unwrap()];
        assert!(tag.contains(" src="), "an inline script: {tag}");
    }
    // An attribute `on...=` inside a tag.
    let handler = lower.split('<').skip(1).find_map(|tag| {
        let tag = tag.split('>').next().unwrap_or("");
        tag.split_whitespace()
            .skip(1)
            .find(|a| a.starts_with("on") && a.contains('='))
            .map(str::to_string)
    });
    assert_eq!(handler, None, "an inline event handler in index.html");
    let scripts = page_scripts(&web);
    assert!(scripts.len() > 1, "the page's scripts: {scripts:?}");
    for path in scripts {
        let js = std::fs::read_to_string(&path).unwrap();
        for sink in [
            "innerHTML",
            "outerHTML",
            "insertAdjacentHTML",
            "document.write",
            "eval(",
            "new Function",
        ] {
            assert!(!js.contains(sink), "{} uses {sink}", path.display());
        }
    }
}

/// The page's own scripts: every `.js` file under `web/` but the vendored libraries
/// (`web/vendor/`), sorted.
fn page_scripts(web: &Path) -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                if path.file_name() != Some("vendor".as_ref()) {
                    walk(&path, out);
                }
            } else if path.extension() == Some("js".as_ref()) {
                out.push(path);
            }
        }
    }
    let mut out = Vec::new();
    walk(web, &mut out);
    out.sort();
    out
}

/// The modules a script imports (`import ... from './x.js'`, `import './x.js'`), as paths of
/// the server's from the script's own (`/js/map.js`).
fn imports_of(script_url: &str, js: &str) -> Vec<String> {
    let dir = &script_url[..script_url.rfind('/').unwrap() + 1];
    js.lines()
        .map(str::trim_start)
        .filter(|l| l.starts_with("import ") || l.starts_with("} from "))
        .filter_map(|l| {
            let quoted = l.rsplit_once(" from ").map_or(&l[7..], |(_, q)| q).trim();
            let quote = quoted.chars().next()?;
            let rest = quoted.strip_prefix(quote)?;
            Some(rest[..rest.find(quote)?].to_string())
        })
        .map(|spec| {
            let mut parts: Vec<&str> = dir.split('/').filter(|p| !p.is_empty()).collect();
            for part in spec.split('/') {
                match part {
                    "." => {}
                    ".." => {
                        parts.pop();
                    }
                    p => parts.push(p),
                }
            }
            format!("/{}", parts.join("/"))
        })
        .collect()
}

/// Issue 42 (item 2): the page is ES modules, served as they are. `index.html` loads one entry
/// as a module (`type="module"`; the other scripts are the vendored libraries); each module it
/// reaches through its imports is served (200) as `text/javascript` (a browser refuses a module
/// of any other type) under the policy that forbids inline script; every script of the page's
/// own is reached from the entry, and each is under 400 lines.
#[test]
fn the_page_is_modules_served_as_javascript_under_the_policy() {
    let web = Path::new(env!("CARGO_MANIFEST_DIR")).join("web");
    let html = std::fs::read_to_string(web.join("index.html")).unwrap();
    let lower = html.to_ascii_lowercase();
    let mut entries = Vec::new();
    for (at, _) in lower.match_indices("<script") {
        let tag = &html[at..at + html[at..].find('>').unwrap()];
        let src = tag.split("src=\"").nth(1).and_then(|s| s.split('"').next());
        let src = src.unwrap_or_else(|| panic!("a script without src: {tag}"));
        if tag.contains("type=\"module\"") {
            entries.push(src.to_string());
        } else {
            assert!(
                src.starts_with("/vendor/"),
                "a classic script of the page's own: {tag}"
            );
        }
    }
    assert_eq!(entries.len(), 1, "the page's module entries: {entries:?}");
    let server = Server::start(&[]);
    let mut reached: Vec<String> = Vec::new();
    let mut queue = entries;
    while let Some(url) = queue.pop() {
        if reached.contains(&url) {
            continue;
        }
        let a = server.send("GET", &url, &[], b"");
        assert_eq!(a.status, 200, "GET {url}: {}", a.body);
        let kind = a.header("content-type").unwrap_or_default();
        assert!(
            kind.starts_with("text/javascript"),
            "GET {url}: Content-Type {kind}"
        );
        checked_policy(&format!("GET {url}"), &a);
        let on_disk = std::fs::read_to_string(web.join(&url[1..])).unwrap();
        assert_eq!(a.body, on_disk, "GET {url} is not web{url} as it is");
        queue.extend(imports_of(&url, &a.body));
        reached.push(url);
    }
    for path in page_scripts(&web) {
        let url = format!("/{}", path.strip_prefix(&web).unwrap().to_str().unwrap());
        assert!(
            reached.contains(&url),
            "{url} is not reached from the entry: {reached:?}"
        );
        let lines = std::fs::read_to_string(&path).unwrap().lines().count();
        assert!(lines < 400, "{url}: {lines} lines");
    }
    eprintln!(
        "the page's modules: {} reached from the entry",
        reached.len()
    );
}

/// Finding 6 (item 4): `/api/plan` went on computing after its client left (102 s of CPU for a
/// request abandoned after 1 s). The plan stops within a flight of its client leaving.
#[test]
fn a_plan_whose_client_left_stops() {
    let server = Server::start(&["--max-request-steps", "1000000000000"]);
    // 1,000 passes of 180 m at 8 m/s: 6 h of flight, 30 packs; at a 10 ms step, minutes of a
    // core for the plan.
    let body = long_survey(1000);
    let mut s = server.connect();
    let head = format!(
        "POST /api/plan?file=long.toml&time_step=0.01 HTTP/1.1\r\nHost: {}\r\nContent-Length: {}\r\n\r\n",
        server.address,
        body.len()
    );
    s.write_all(head.as_bytes()).unwrap();
    s.write_all(body.as_bytes()).unwrap();
    let (busy_s, spent) =
        server.cpu_after_the_client_left(s, Duration::from_secs(2), Duration::from_secs(2));
    eprintln!(
        "a plan whose client left: {busy_s:.2} s of CPU in its first 2 s, {spent:.2} s in 3 s from 2 s after"
    );
    assert!(spent < 0.5, "{spent} s of CPU in 3 s after the client left");
    assert_eq!(server.get("/api/vehicles").0, 200);
}

/// Finding 6 (item 4): `--max-request-steps` did not bound `/api/plan`. A plan that would fly
/// more steps is refused (422) naming the bound; one within it is answered as the command line
/// answers it.
#[test]
fn a_plan_past_the_step_bound_is_refused_naming_it() {
    let server = Server::start(&["--max-request-steps", "1000000"]);
    // 200 passes of 180 m at 8 m/s: 4,500 s of flight, 450,000 steps of 10 ms for one flight
    // of the whole route. The plan flies it whole at least three times (the mission as given
    // before its candidates, and the first sortie's trial of each of the two candidates cut
    // into sorties, inside legs and at whole items): 1,350,000 steps at least.
    let body = long_survey(200);
    let started = Instant::now();
    let (code, answer) = server.request(
        "POST",
        "/api/plan?file=long.toml&time_step=0.01",
        None,
        body.as_bytes(),
    );
    let took = started.elapsed();
    eprintln!("a plan past the bound: {code} in {took:?}: {answer}");
    assert_eq!(code, 422, "{answer}");
    let message: serde_json::Value = serde_json::from_str(&answer).unwrap();
    let message = message["error"].as_str().unwrap_or_default();
    assert!(
        message.contains("1000000 planner steps") && message.contains("time step"),
        "{message}"
    );
    // The demo, 400 s of flight at 0.1 s, takes a few dozen flights of 4,000 steps.
    let (code, answer) = server.request("POST", "/api/plan?reserve_percent=70", None, b"");
    assert_eq!(code, 200, "{answer}");
    let plan: serde_json::Value = serde_json::from_str(&answer).unwrap();
    let dir = scratch("serve-hold", "demo-plan");
    let _ = std::fs::remove_dir_all(&dir);
    let cli: serde_json::Value = serde_json::from_str(&cli(&[
        "plan",
        "--reserve-percent",
        "70",
        "-o",
        dir.to_str().unwrap(),
        "--format",
        "json",
    ]))
    .unwrap();
    assert!(cli["batteries"].as_u64().is_some_and(|b| b >= 2), "{cli}");
    for key in ["batteries", "energy_wh", "duration_s", "sorties"] {
        let strip =
            |v: &serde_json::Value| v.to_string().replace(&format!("{}/", dir.display()), "");
        assert_eq!(strip(&plan[key]), strip(&cli[key]), "{key}");
    }
}

/// The M100's vehicle file, renamed `name`.
fn renamed_m100(name: &str) -> String {
    let text = std::fs::read_to_string(fixture("vehicles", "dji-m100.toml")).unwrap();
    let quoted = serde_json::to_string(name).unwrap();
    let text = text.replacen("name = \"dji-m100\"", &format!("name = {quoted}"), 1);
    assert!(text.contains(&quoted));
    text
}

/// The names of `GET /api/vehicles`.
fn listed(server: &Server) -> Vec<String> {
    let (code, body) = server.get("/api/vehicles");
    assert_eq!(code, 200);
    let list: serde_json::Value = serde_json::from_str(&body).unwrap();
    common::strs_of(&list, "name")
        .into_iter()
        .map(str::to_string)
        .collect()
}

/// Finding 11 (item 11): names that look like a built-in's or a given vehicle's (another case,
/// a space before or after, U+2010 HYPHEN for `-`, a zero width space, a right-to-left override
/// that shows `dji-m100` backwards) were kept beside it, so that the page listed two vehicles
/// that read the same. They clash, or are refused; a vehicle sent under its own name again
/// replaces it.
#[test]
fn look_alike_vehicle_names_clash_or_are_refused() {
    let given = scratch("serve-hold", "my-quad.toml");
    std::fs::write(&given, renamed_m100("my-quad")).unwrap();
    let server = Server::start(&["--vehicle", given.to_str().unwrap()]);
    let before = listed(&server);
    assert!(before.iter().any(|n| n == "my-quad"), "{before:?}");
    let send = |name: &str| {
        server.request(
            "POST",
            "/api/vehicles?file=sent.toml",
            None,
            renamed_m100(name).as_bytes(),
        )
    };
    for name in [
        "DJI-M100",
        "dji-m100 ",
        " dji-m100",
        "dji\u{2010}m100",
        "dji-m\u{200B}100",
        "\u{202E}001m-ijd",
        "My-Quad",
        "my-quad\u{00A0}",
        "my\u{2010}quad",
        "my-\u{200B}quad",
        "quad\u{200E}",
        "\u{FF4D}y-quad",
    ] {
        let (code, body) = send(name);
        assert_eq!(code, 422, "{name:?}: {body}");
        assert!(body.contains("sent.toml"), "{name:?}: {body}");
    }
    assert_eq!(listed(&server), before);
    // Sent ones keep to the rule among themselves; the same name again replaces the vehicle.
    assert_eq!(send("Field-Quad").0, 200);
    let (code, body) = send("field-quad");
    assert_eq!(code, 422, "{body}");
    assert_eq!(send("Field-Quad").0, 200);
    let names = listed(&server);
    assert_eq!(names.len(), before.len() + 1, "{names:?}");

    // The files given on the command line keep the same rules: a name that looks like a
    // built-in's is listed under the name the file was given with, as the built-in's own name
    // is; a name no vehicle may have stops the server at its start.
    let upper = scratch("serve-hold", "upper.toml");
    std::fs::write(&upper, renamed_m100("DJI-M100")).unwrap();
    let server = Server::start(&["--vehicle", upper.to_str().unwrap()]);
    let names = listed(&server);
    assert!(
        !names.iter().any(|n| n == "DJI-M100")
            && names.iter().any(|n| n == upper.to_str().unwrap()),
        "{names:?}"
    );
    for (file, name) in [("zwsp.toml", "my-\u{200B}quad"), ("space.toml", "my-quad ")] {
        let path = scratch("serve-hold", file);
        std::fs::write(&path, renamed_m100(name)).unwrap();
        let (code, err) = start_outcome(&["--vehicle", path.to_str().unwrap()]);
        assert_eq!(code, Some(2), "{name:?}: {err}");
        assert!(err.contains(file) && err.lines().count() == 1, "{err}");
    }
}

/// `aloft serve --listen 127.0.0.1:0 ARGS`: its exit code and stderr when it ends within 10 s,
/// else `None` (a server that started) and it is stopped.
fn start_outcome(args: &[&str]) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_aloft"))
        .args(["serve", "--listen", "127.0.0.1:0"])
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let Some(status) = common::ended_within(&mut child, Duration::from_secs(10)) else {
        common::stop(&mut child);
        return (None, "still serving after 10 s".to_string());
    };
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    (status.code(), err)
}

/// The longest run of `c` in `text`.
fn longest_run(text: &str, c: char) -> usize {
    text.split(|x| x != c).map(str::len).max().unwrap_or(0)
}

/// Finding 11 (item 11): an error quoted a bad value whole (3,000 characters of it, back to the
/// page that sent it). Every error quotes at most 80 characters of any value.
#[test]
fn errors_quote_at_most_80_characters_of_a_value() {
    let server = Server::start(&[]);
    let long = |c: char| c.to_string().repeat(3000);
    let plan = b"{ not a plan".as_slice();
    let cases: Vec<(&str, String, &[u8], char, u16)> = vec![
        (
            "POST",
            format!("/api/plan?speeds={}", long('w')),
            b"",
            'w',
            400,
        ),
        (
            "POST",
            format!("/api/plan?max_speed=1{}", long('0')),
            b"",
            '0',
            400,
        ),
        (
            "POST",
            format!("/api/plan?overlap_m={}", long('9')),
            b"",
            '9',
            400,
        ),
        (
            "POST",
            format!("/api/plan?vehicle={}", long('v')),
            b"",
            'v',
            400,
        ),
        ("POST", format!("/api/plan?{}=1", long('k')), b"", 'k', 400),
        (
            "POST",
            format!("/api/plan?file={}.plan", long('f')),
            plan,
            'f',
            422,
        ),
        (
            "POST",
            format!("/api/mission?battery={}", long('b')),
            b"",
            'b',
            422,
        ),
        (
            "GET",
            format!("/api/endurance?payload_kg={}", long('x')),
            b"",
            'x',
            400,
        ),
        ("GET", format!("/{}", long('p')), b"", 'p', 404),
        ("GET", format!("/api/files/{}", long('n')), b"", 'n', 404),
        ("GET", format!("/api/logbook/{}", long('l')), b"", 'l', 404),
        ("PUT", format!("/api/{}", long('m')), b"", 'm', 405),
    ];
    for (method, target, body, c, status) in cases {
        let a = server.send(method, &target, &[], body);
        let what = format!("{method} {}...", &target[..target.len().min(30)]);
        assert_eq!(a.status, status, "{what}: {}", a.body);
        assert!(a.body.starts_with("{\"error\""), "{what}: {}", a.body);
        let run = longest_run(&a.body, c);
        assert!(
            run <= 80,
            "{what}: {run} characters of the value quoted: {}",
            a.body
        );
    }
}

/// Finding 11 (item 11): of two `Host` headers the first was checked and the request served; a
/// proxy or cache may read the other. A request with more than one is 400.
#[test]
fn a_request_with_two_host_headers_is_refused() {
    let server = Server::start(&[]);
    let own = format!("Host: {}", server.address);
    for second in [own.clone(), "Host: evil.example:80".to_string()] {
        let a = server.send(
            "GET",
            "/api/vehicles",
            &[own.as_str(), second.as_str()],
            b"",
        );
        assert_eq!(a.status, 400, "{second}: {}", a.body);
        assert!(a.body.contains("Host"), "{}", a.body);
    }
    assert_eq!(
        server
            .send("GET", "/api/vehicles", &[own.as_str()], b"")
            .status,
        200
    );
}

/// A pack file of the user's (a 6S 5700 mAh pack named `served`, its failsafes set).
fn pack_file() -> PathBuf {
    let pack = scratch("serve-hold", "served.toml");
    std::fs::write(
        &pack,
        "[battery]\nname = \"served\"\ncells_series = 6\ncapacity_mah = 5700.0\nnominal_v = 22.8\n\
         energy_wh = 129.96\nmass_kg = 0.676\ninternal_resistance_ohm = 0.04\ncutoff_cell_v = 3.0\n\
         \n[failsafe]\nlow_voltage_v = 21.0\ncritical_voltage_v = 20.4\n",
    )
    .unwrap();
    pack
}

/// Finding 10 (item 10): `serve --battery pack.toml` was ignored (the page flew the vehicle's
/// own pack). The server's default vehicle flies the pack given, as `aloft mission --battery`
/// does; a value that is neither one of its packs nor a pack file stops the server at its start.
#[test]
fn serve_battery_flies_that_pack_or_is_refused() {
    let pack = pack_file();
    let pack_s = pack.to_str().unwrap();
    let server = Server::start(&["--battery", pack_s]);
    let (code, body) = server.request("POST", "/api/mission", None, b"");
    assert_eq!(code, 200, "{body}");
    let answer: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(answer["battery"], "served", "{body}");
    assert_eq!(
        body,
        cli(&["mission", "--battery", pack_s, "--format", "json"])
    );
    let (_, endurance) = server.get("/api/endurance");
    assert_eq!(
        endurance,
        cli(&["endurance", "--battery", pack_s, "--format", "json"])
    );
    let config: serde_json::Value = serde_json::from_str(&server.get("/api/config").1).unwrap();
    assert_eq!(config["default_battery"], "served", "{config}");
    let (_, vehicles) = server.get("/api/vehicles");
    let vehicles: serde_json::Value = serde_json::from_str(&vehicles).unwrap();
    let m100 = vehicles
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["name"] == "dji-m100")
        .unwrap();
    assert!(
        m100["batteries"]
            .as_array()
            .unwrap()
            .iter()
            .any(|b| b == "served"),
        "{m100}"
    );
    // Another vehicle asked for by name flies its own pack.
    let (_, inspire) = server.request("POST", "/api/mission?vehicle=dji-inspire1", None, b"");
    assert_eq!(
        inspire,
        cli(&["mission", "--vehicle", "dji-inspire1", "--format", "json"])
    );
    drop(server);

    // A pack of the vehicle's, by name.
    let server = Server::start(&["--battery", "TB48D"]);
    let (_, body) = server.request("POST", "/api/mission", None, b"");
    assert_eq!(
        body,
        cli(&["mission", "--battery", "TB48D", "--format", "json"])
    );
    drop(server);

    for bad in ["no-such-pack", "/no/such/pack.toml"] {
        let (code, err) = start_outcome(&["--battery", bad]);
        assert_eq!(code, Some(2), "--battery {bad}: {err}");
        assert!(err.contains(bad) && err.lines().count() == 1, "{err}");
    }
}
