//! `aloft serve` holds (issue 41): the server's part of each finding of the review that attacked
//! it again, as a test that failed on the server before the fix. The page's own part (markup in
//! names shown as text in a real browser) is in `tests/browser/run.mjs`.
#![cfg(all(feature = "serve", unix))]

mod common;

use std::io::Write;
use std::time::{Duration, Instant};

use aloft_planner::mission_toml::{landing, leg, return_home, take_off};
use common::scratch;
use common::serve::Server;

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
    std::thread::sleep(Duration::from_millis(2000));
    let busy_s = server.cpu_s();
    assert!(busy_s > 0.5, "the plan did not start: {busy_s} s of CPU");
    drop(s);
    std::thread::sleep(Duration::from_secs(2));
    let after = server.cpu_s();
    std::thread::sleep(Duration::from_secs(3));
    let spent = server.cpu_s() - after;
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
