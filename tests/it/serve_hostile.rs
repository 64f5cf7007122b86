//! `aloft serve` against a hostile or careless client (issue 32): each finding of the review that
//! tried it as one, as a test that failed on the server before the fix. Memory and CPU are the
//! server process's own (`/proc/PID/status`, `/proc/PID/stat`), measured, not assumed.
#![cfg(feature = "serve")]

use crate::common;

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use common::serve::{encoded, parse_answer, read_answer, Answer, Server};
use common::{data_dir, fixture, scratch};

/// The command line's JSON answer (stdout without its final line break).
fn cli(args: &[&str]) -> String {
    common::cli(args).trim_end().to_string()
}

/// A vehicle file of the user's: the M100's, renamed.
fn my_vehicle() -> String {
    let text = std::fs::read_to_string(fixture("vehicles", "dji-m100.toml")).unwrap();
    let text = text.replacen("name = \"dji-m100\"", "name = \"my-quad\"", 1);
    assert!(text.contains("name = \"my-quad\""));
    let path = scratch("serve-hostile", "my-quad.toml");
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// Finding 1: options that name a file read any path and quoted it. A request may name a
/// built-in or a file given to the server, nothing else; what it is told of another path does
/// not depend on whether that path exists.
#[test]
fn a_request_names_no_file_of_the_server() {
    let vehicle = my_vehicle();
    let wind = scratch("serve-hostile", "wind.csv");
    common::write_wind_grid(&wind, [3000.0, 500.0], "1.5,1.0,0");
    let wind = wind.display().to_string();
    let map = fixture("logs", "custom.toml").display().to_string();
    let server = Server::start(&[&vehicle, &wind, &map]);
    let passwd = std::fs::read_to_string("/etc/passwd").unwrap_or_default();
    let first = passwd.lines().next().unwrap_or("root:x:0:0").to_string();
    for (method, path) in [
        ("POST", "/api/mission?wind_field=/etc/passwd"),
        ("POST", "/api/mission?vehicle=/etc/passwd"),
        ("POST", "/api/map?vehicle=/proc/self/environ"),
        ("POST", "/api/plan?wind_field=/etc/passwd"),
        ("GET", "/api/endurance?vehicle=/etc/passwd"),
        ("POST", "/api/log/info?profile=/etc/passwd"),
        ("POST", "/api/mission?vehicle=../../../../etc/passwd"),
    ] {
        let (code, body) = server.request(method, path, None, b"");
        assert_eq!(code, 400, "{path}: {body}");
        assert!(
            !body.contains(&first) && !body.contains("PATH="),
            "{path}: {body}"
        );
        assert!(body.contains("given to aloft serve"), "{path}: {body}");
        // The same answer for a path that does not exist: no oracle of what the server holds.
        let (code2, body2) =
            server.request(method, &path.replace("/etc/passwd", "/no/such"), None, b"");
        assert_eq!(code2, code, "{path}");
        assert_eq!(body2.replace("/no/such", "/etc/passwd"), body, "{path}");
    }
    // The files given are named as given (a vehicle also by its own name), and answer as the
    // command line does with the same files.
    let expected = cli(&["mission", "--vehicle", &vehicle, "--format", "json"]);
    for name in ["my-quad", vehicle.as_str()] {
        let (code, body) = server.request(
            "POST",
            &format!("/api/mission?vehicle={}", encoded(name)),
            None,
            b"",
        );
        assert_eq!((code, body), (200, expected.clone()), "{name}");
    }
    let (code, body) = server.request(
        "POST",
        &format!("/api/mission?wind_field={}", encoded(&wind)),
        None,
        b"",
    );
    assert_eq!(code, 200, "{body}");
    assert_eq!(
        body,
        cli(&["mission", "--wind-field", &wind, "--format", "json"])
    );
    let log = std::fs::read(fixture("logs", "custom.csv")).unwrap();
    let (code, body) = server.request(
        "POST",
        &format!("/api/log/info?file=custom.csv&profile={}", encoded(&map)),
        None,
        &log,
    );
    assert_eq!(code, 200, "{body}");
    let custom = fixture("logs", "custom.csv").display().to_string();
    let expected = cli(&[
        "log",
        "info",
        &custom,
        "--profile",
        &map,
        "--format",
        "json",
    ]);
    let strip = |t: &str| t.replace(&custom, "custom.csv");
    assert_eq!(strip(&body), strip(&expected));
    // The page is told what was given.
    let config: serde_json::Value = serde_json::from_str(&server.get("/api/config").1).unwrap();
    let kinds = common::strs_of(&config["files"], "kind");
    assert_eq!(kinds, ["vehicle", "wind_field", "column_map"]);
}

/// Finding 2: a mission body was held whole and parsed into a tree (a 100 MB TOML took
/// 7.8 GB). Mission bodies are refused past 32 MiB, by their declared length before a byte is
/// read (no `100 Continue`), and a text of millions of values is refused before it is parsed.
#[test]
fn mission_bodies_are_bounded_before_they_are_read_and_parsed() {
    let server = Server::start(&[]);
    // Declared too large: 413 at once, without asking for the body.
    let mut s = server.connect();
    let head = format!(
        "POST /api/mission HTTP/1.1\r\nHost: {}\r\nContent-Length: {}\r\nExpect: 100-continue\r\n\r\n",
        server.address,
        100 << 20
    );
    s.write_all(head.as_bytes()).unwrap();
    let mut first = [0u8; 12];
    s.read_exact(&mut first).unwrap();
    assert_eq!(
        &first,
        b"HTTP/1.1 413",
        "{}",
        String::from_utf8_lossy(&first)
    );
    let mut rest = Vec::new();
    let _ = s.read_to_end(&mut rest);
    let a = parse_answer(&[first.as_slice(), &rest].concat());
    assert!(
        a.body.starts_with("{\"error\"") && a.body.contains("32 MiB"),
        "{}",
        a.body
    );
    // Sent in chunks without a length: refused when it passes the limit.
    let mut s = server.connect();
    let head = format!(
        "POST /api/mission HTTP/1.1\r\nHost: {}\r\nTransfer-Encoding: chunked\r\n\r\n",
        server.address
    );
    s.write_all(head.as_bytes()).unwrap();
    let chunk = vec![b'#'; 1 << 20];
    for _ in 0..40 {
        let framed = [format!("{:x}\r\n", chunk.len()).as_bytes(), &chunk, b"\r\n"].concat();
        if s.write_all(&framed).is_err() {
            break;
        }
    }
    let _ = s.write_all(b"0\r\n\r\n");
    assert_eq!(read_answer(&mut s).status, 413);
    // Within the limit, the worst a parser can be given: 30 MiB of nothing but values, as TOML
    // and as a .plan's JSON; and a valid mission of a million values' worth of text.
    let toml = format!("name = \"x\"\nfoo = [{}1]\n", "1,".repeat(15 << 20));
    let plan = format!(
        "{{\"fileType\": \"Plan\", \"mission\": {{\"items\": [{}1]}}}}",
        "1,".repeat(15 << 20)
    );
    for (name, body) in [("x.toml", toml), ("x.plan", plan)] {
        let (code, answer) = server.request(
            "POST",
            &format!("/api/mission?file={name}"),
            None,
            body.as_bytes(),
        );
        assert_eq!(code, 422, "{name}: {answer}");
        assert!(answer.contains("values"), "{name}: {answer}");
    }
    let peak_mb = server.status_kb("VmHWM") / 1024;
    eprintln!("mission bodies: the server's peak resident memory {peak_mb} MB");
    // Before: 2.4 GB for the TOML alone. The bodies themselves are 30 MiB each.
    assert!(peak_mb < 400, "the server's peak memory: {peak_mb} MB");
    assert_eq!(server.get("/api/vehicles").0, 200);
}

/// Finding 3: `threads=1024` made a state-of-charge fan per thread (1.2 GB). Threads are at
/// most one per core, and the answer does not depend on them.
#[test]
fn the_threads_a_request_asks_for_do_not_multiply_its_memory() {
    let server = Server::start(&[]);
    let (code, many) = server.request("POST", "/api/map?samples=256&threads=1024", None, b"");
    assert_eq!(code, 200, "{many}");
    let (_, one) = server.request("POST", "/api/map?samples=256&threads=1", None, b"");
    assert_eq!(many, one);
    let peak_mb = server.status_kb("VmHWM") / 1024;
    eprintln!("threads=1024: the server's peak resident memory {peak_mb} MB");
    assert!(peak_mb < 250, "the server's peak memory: {peak_mb} MB");
}

/// Finding 4: any web page could make the server work (no Origin check), work went on when the
/// client left, and one request could ask for hours of it.
#[test]
fn a_page_elsewhere_cannot_make_it_work_and_work_nobody_waits_for_stops() {
    let server = Server::start(&["--max-request-steps", "200000"]);
    let own = format!("Origin: http://{}", server.address);
    // A cross-site form post (text/plain needs no preflight): refused.
    let form = ["Origin: http://evil.example", "Content-Type: text/plain"];
    assert_eq!(server.send("POST", "/api/mission", &form, b"").status, 403);
    assert_eq!(
        server
            .send("POST", "/api/mission", &["Origin: null"], b"")
            .status,
        403
    );
    let site = ["Sec-Fetch-Site: cross-site"];
    assert_eq!(server.send("GET", "/api/endurance", &site, b"").status, 403);
    // The page's own, and clients that are not browsers: served.
    assert_eq!(
        server
            .send("POST", "/api/mission", &[own.as_str()], b"")
            .status,
        200
    );
    assert_eq!(server.send("POST", "/api/mission", &[], b"").status, 200);
    // The demo is about 4,000 steps at 0.1 s: 200,000 steps hold about 50 scenarios.
    let (code, body) = server.request("POST", "/api/mission?samples=100000", None, b"");
    assert_eq!(code, 422, "{body}");
    let most: u32 = body
        .split("at most ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no 'at most N' in {body}"));
    assert!((30..=60).contains(&most), "{body}");
    let ok = server.request("POST", &format!("/api/mission?samples={most}"), None, b"");
    assert_eq!(ok.0, 200, "{}", ok.1);
    let over = server.request(
        "POST",
        &format!("/api/mission?samples={}", most + 1),
        None,
        b"",
    );
    assert_eq!(over.0, 422, "{}", over.1);

    // A client that leaves: its work stops (here 100,000 scenarios, minutes of a core).
    let unbounded = Server::start(&["--max-request-steps", "1000000000000"]);
    let mut s = unbounded.connect();
    let head = format!(
        "POST /api/mission?samples=100000&threads=1 HTTP/1.1\r\nHost: {}\r\nContent-Length: 0\r\n\r\n",
        unbounded.address
    );
    s.write_all(head.as_bytes()).unwrap();
    let (busy_s, spent) =
        unbounded.cpu_after_the_client_left(s, Duration::from_millis(1500), Duration::from_secs(1));
    eprintln!(
        "a client that left: {busy_s:.2} s of CPU in its first 1.5 s, {spent:.2} s in 3 s after"
    );
    assert!(spent < 0.5, "{spent} s of CPU in 3 s after the client left");
}

/// Finding 5: 520 concurrent Monte-Carlo requests left `GET /api/vehicles` unanswered for 20 s.
/// Engine work is bounded to twice the cores; beyond, 503 with Retry-After; the cheap answers do
/// not wait behind it.
#[test]
fn engine_work_is_bounded_and_the_cheap_answers_do_not_wait() {
    let server = Server::start(&[]);
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let n = 6 * cores + 4;
    let address = server.address.clone();
    let requests: Vec<_> = (0..n)
        .map(|_| {
            let address = address.clone();
            std::thread::spawn(move || {
                let mut s = TcpStream::connect(&address).unwrap();
                let head = format!(
                    "POST /api/mission?samples=1500 HTTP/1.1\r\nHost: {address}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
                );
                s.write_all(head.as_bytes()).unwrap();
                read_answer(&mut s)
            })
        })
        .collect();
    std::thread::sleep(Duration::from_millis(300));
    let started = Instant::now();
    let (code, _) = server.get("/api/vehicles");
    let waited = started.elapsed();
    eprintln!("{n} concurrent requests: /api/vehicles answered in {waited:?}");
    assert_eq!(code, 200);
    assert!(
        waited < Duration::from_secs(1),
        "/api/vehicles took {waited:?}"
    );
    let answers: Vec<Answer> = requests.into_iter().map(|t| t.join().unwrap()).collect();
    let busy: Vec<&Answer> = answers.iter().filter(|a| a.status == 503).collect();
    let served = answers.iter().filter(|a| a.status == 200).count();
    eprintln!(
        "{n} concurrent requests: {served} served, {} busy (503)",
        busy.len()
    );
    assert_eq!(busy.len() + served, n, "{answers:?}");
    assert!(
        served >= 2 * cores && !busy.is_empty(),
        "{served} served, {} busy",
        busy.len()
    );
    for a in busy {
        assert_eq!(a.header("retry-after"), Some("1"));
        assert!(a.body.starts_with("{\"error\""), "{}", a.body);
    }
}

/// Finding 6: slow headers, half-sent bodies and idle connections stayed open for ever, and
/// enough of them left the server answering nobody.
#[test]
fn connections_do_not_stay_open_for_ever() {
    let server = Server::start(&[]);
    let closed_within = |s: &mut TcpStream, limit: Duration| {
        s.set_read_timeout(Some(limit)).unwrap();
        let started = Instant::now();
        let mut buf = Vec::new();
        let _ = s.read_to_end(&mut buf);
        (
            started.elapsed() < limit,
            String::from_utf8_lossy(&buf).into_owned(),
        )
    };
    // Headers that never end.
    let mut slow = server.connect();
    slow.write_all(b"GET /api/vehicles HTTP/1.1\r\nHost: ")
        .unwrap();
    // An idle keep-alive connection after one answer.
    let mut idle = server.connect();
    let head = format!(
        "GET /api/config HTTP/1.1\r\nHost: {}\r\n\r\n",
        server.address
    );
    idle.write_all(head.as_bytes()).unwrap();
    // A body that stops.
    let mut half = server.connect();
    let head = format!(
        "POST /api/mission HTTP/1.1\r\nHost: {}\r\nContent-Length: 1000\r\n\r\nname = ",
        server.address
    );
    half.write_all(head.as_bytes()).unwrap();
    // Six hundred idle connections: those beyond the cap are closed at once, so the server keeps
    // its files.
    let crowd: Vec<TcpStream> = (0..600).map(|_| server.connect()).collect();
    std::thread::sleep(Duration::from_millis(500));
    let files = server.open_files();
    eprintln!("600 idle connections: the server holds {files} files");
    assert!(files < 320, "the server holds {files} files");
    let (closed, _) = closed_within(&mut slow, Duration::from_secs(15));
    assert!(closed, "slow headers kept open");
    let (closed, text) = closed_within(&mut idle, Duration::from_secs(15));
    assert!(
        closed && text.starts_with("HTTP/1.1 200"),
        "idle kept open: {text}"
    );
    // Once the idle ones are closed, the server answers again.
    assert_eq!(server.get("/api/vehicles").0, 200);
    let (closed, text) = closed_within(&mut half, Duration::from_secs(40));
    assert!(
        closed && text.starts_with("HTTP/1.1 408"),
        "half-sent body: {text}"
    );
    drop(crowd);
}

/// The server's folder of uploads: the new `aloft-serve-*` in the temporary directory.
fn uploads_folder(before: &[std::path::PathBuf]) -> std::path::PathBuf {
    let now = temp_folders();
    let mut new: Vec<_> = now.into_iter().filter(|p| !before.contains(p)).collect();
    assert_eq!(new.len(), 1, "{new:?}");
    new.pop().unwrap()
}

fn temp_folders() -> Vec<std::path::PathBuf> {
    std::fs::read_dir(std::env::temp_dir())
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("aloft-serve-"))
                && p.is_dir()
        })
        .collect()
}

/// Finding 7: uploads went to a predictable folder other users could read, through a link
/// planted there, and stayed after the server. They go to a private folder, each to a new file,
/// removed with the server on SIGTERM and Ctrl-C (SIGINT).
#[test]
fn uploads_go_to_a_private_folder_and_go_with_the_server() {
    use std::os::unix::fs::PermissionsExt;
    for signal in ["-TERM", "-INT"] {
        let before = temp_folders();
        let server = Server::start(&[]);
        let folder = uploads_folder(&before);
        let mode = std::fs::metadata(&folder).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o700, "{folder:?}");
        // The old predictable place, a link planted to a file of the test's: not written.
        let target = scratch("serve-hostile", &format!("victim{signal}"));
        std::fs::write(&target, "untouched").unwrap();
        let planted = std::env::temp_dir().join(format!("aloft-serve-{}-0", server.child.id()));
        let _ = std::fs::remove_file(&planted);
        std::os::unix::fs::symlink(&target, &planted).unwrap();
        let log =
            std::fs::read(data_dir().join("flight_logs/pyulog_sample_log_small.ulg")).unwrap();
        let (code, body) = server.request("POST", "/api/log/info?file=x.ulg", None, &log);
        assert_eq!(code, 200, "{body}");
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "untouched");
        let _ = std::fs::remove_file(&planted);
        // Names that are no file name: 400.
        for name in ["a%00b.ulg".to_string(), "x".repeat(300)] {
            let (code, body) =
                server.request("POST", &format!("/api/log/info?file={name}"), None, &log);
            assert_eq!(code, 400, "{body}");
        }
        // Nothing is left after an answer, nor after the server.
        assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 0);
        let mut server = server;
        let killed = std::process::Command::new("kill")
            .args([signal, &server.child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = server.child.wait().unwrap();
        assert_eq!(status.code(), Some(0), "{signal}: {status:?}");
        assert!(!folder.exists(), "{signal}: {folder:?} left");
    }
}

/// Finding 11, the server's papercuts: on `0.0.0.0` every browser was refused (only
/// `Host: 0.0.0.0:PORT` passed); a request naming another server in its target was served; the
/// map left out its band when the battery ran out.
#[test]
fn every_interface_answers_its_own_names_only() {
    let server = Server::start_on("0.0.0.0:0", &[]);
    let port = server.port();
    let machine = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap();
    let machine = machine.trim();
    for host in [
        format!("127.0.0.1:{port}"),
        format!("localhost:{port}"),
        format!("{machine}:{port}"),
    ] {
        let a = server.send("GET", "/api/vehicles", &[&format!("Host: {host}")], b"");
        assert_eq!(a.status, 200, "{host}: {}", a.body);
    }
    for host in [
        format!("evil.example:{port}"),
        format!("127.0.0.1:{}", port ^ 1),
    ] {
        let a = server.send("GET", "/api/vehicles", &[&format!("Host: {host}")], b"");
        assert_eq!(a.status, 403, "{host}");
    }
    let a = server.send(
        "GET",
        "http://evil.example/api/vehicles",
        &[&format!("Host: 127.0.0.1:{port}")],
        b"",
    );
    assert_eq!(a.status, 403, "{}", a.body);
    // A mission whose packs run out: its band is drawn down to where they do.
    let (code, body) = server.request("POST", "/api/map?samples=20&start_percent=12", None, b"");
    assert_eq!(code, 200, "{body}");
    let map: serde_json::Value = serde_json::from_str(&body).unwrap();
    let p50 = map["band"]["p50"]
        .as_array()
        .unwrap_or_else(|| panic!("no band: {body}"));
    assert!(!p50.is_empty());
}

/// A repeatable choice (xorshift64).
struct Draw(u64);

impl Draw {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn pick<'a, T>(&mut self, from: &'a [T]) -> &'a T {
        &from[(self.next() % from.len() as u64) as usize]
    }
}

/// A soak of hostile requests, where one case each is too narrow: 1,000 drawn from a seeded
/// generator (methods, paths, every option of the commands with values that are not numbers,
/// huge, negative or paths of the server, forged origins, bodies of random bytes and cut plans).
/// Every answer is a documented status with the JSON error, the server serves the next, and its
/// memory does not grow with the requests.
#[test]
fn a_soak_of_hostile_requests_gets_documented_answers_and_flat_memory() {
    use aloft::engine::flags::{EnduranceFlags, LogInfoFlags, MissionScenarioFlags};
    use aloft::engine::keywords;
    let server = Server::start(&["--max-upload-mb", "1", "--max-request-steps", "2000000"]);
    let mut options = keywords::<MissionScenarioFlags>(&[]);
    options.extend(keywords::<EnduranceFlags>(&[]));
    options.extend(keywords::<LogInfoFlags>(&[]));
    options.extend(["file".to_string(), "bogus".to_string()]);
    let values = [
        "abc",
        "-1",
        "1e308",
        "nan",
        "",
        "/etc/passwd",
        "../../x",
        "0",
        "7",
        "0.5",
        "true",
        "%00",
        "%ff",
        "270",
        "dji-m100",
        "kaist",
    ];
    let paths = [
        "/api/mission",
        "/api/map",
        "/api/endurance",
        "/api/log/info",
        "/api/config",
        "/api/vehicles",
        "/api/files/0",
        "/api/live",
        "/",
        "/x/../../etc/passwd",
    ];
    let origins = [
        None,
        Some("Origin: http://evil.example".to_string()),
        Some(format!("Origin: http://{}", server.address)),
        Some("Sec-Fetch-Site: cross-site".to_string()),
    ];
    let plan = std::fs::read(data_dir().join("missions/kasperg3_mission.plan")).unwrap();
    let mut draw = Draw(0x2545_F491_4F6C_DD1D);
    let mut rss_after_warmup = 0;
    for k in 0..1000 {
        let method = *draw.pick(&["GET", "POST", "POST", "PUT"]);
        let mut target = draw.pick(&paths).to_string();
        for i in 0..draw.next() % 4 {
            let sep = if i == 0 { '?' } else { '&' };
            target.push_str(&format!(
                "{sep}{}={}",
                draw.pick(&options),
                draw.pick(&values)
            ));
        }
        let body: Vec<u8> = match draw.next() % 3 {
            0 => Vec::new(),
            1 => (0..draw.next() % 4096).map(|_| draw.next() as u8).collect(),
            _ => plan[..(draw.next() % plan.len() as u64) as usize].to_vec(),
        };
        let header = draw.pick(&origins).clone();
        let extra: Vec<&str> = header.iter().map(String::as_str).collect();
        let a = server.send(method, &target, &extra, &body);
        assert!(
            matches!(
                a.status,
                200 | 400 | 403 | 404 | 405 | 408 | 413 | 422 | 503
            ),
            "{method} {target}: {} {}",
            a.status,
            a.body
        );
        if a.status >= 400 {
            assert!(
                a.body.starts_with("{\"error\""),
                "{method} {target}: {}",
                a.body
            );
        }
        if k == 199 {
            rss_after_warmup = server.status_kb("VmRSS");
        }
    }
    assert_eq!(server.get("/api/vehicles").0, 200);
    let growth_mb = server.status_kb("VmRSS").saturating_sub(rss_after_warmup) / 1024;
    eprintln!("soak: resident memory grew {growth_mb} MB over 800 requests after the first 200");
    assert!(growth_mb < 30, "resident memory grew {growth_mb} MB");
}
