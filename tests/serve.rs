//! `aloft serve` on the loopback interface: its JSON API answers exactly as the command line's
//! `--format json` (the built-in vehicles, endurance, the demo and every shared mission file),
//! refuses options the command does not take (400), requests the engine refuses (422), a forged
//! `Host` (403) and an upload past the limit (413), and keeps serving after each.
#![cfg(feature = "serve")]

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};

use common::{aloft, data_dir};

/// A server on a free loopback port, stopped when dropped.
struct Server {
    child: Child,
    address: String,
}

impl Server {
    fn start(extra: &[&str]) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_aloft"))
            .args(["serve", "--listen", "127.0.0.1:0"])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("aloft serve starts");
        let mut line = String::new();
        BufReader::new(child.stdout.as_mut().unwrap())
            .read_line(&mut line)
            .expect("the URL line");
        let address = line
            .split("http://")
            .nth(1)
            .and_then(|r| r.split('/').next())
            .unwrap_or_else(|| panic!("no URL in {line:?}"))
            .to_string();
        Self { child, address }
    }

    /// One request (HTTP/1.1, the connection closed after it): status and body.
    fn request(&self, method: &str, path: &str, host: Option<&str>, body: &[u8]) -> (u16, String) {
        let mut s = TcpStream::connect(&self.address).expect("connect");
        let head = format!(
            "{method} {path} HTTP/1.1\r\nHost: {}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
            host.unwrap_or(&self.address),
            body.len()
        );
        s.write_all(head.as_bytes()).expect("request head");
        // The server may answer (413) and close before the whole body is read.
        let _ = s.write_all(body);
        let mut raw = Vec::new();
        let _ = s.read_to_end(&mut raw);
        let text = String::from_utf8_lossy(&raw).into_owned();
        let status: u16 = text
            .split(' ')
            .nth(1)
            .and_then(|c| c.parse().ok())
            .unwrap_or_else(|| panic!("no status in {text:?}"));
        let body = text
            .split_once("\r\n\r\n")
            .map_or("", |(_, b)| b)
            .to_string();
        (status, body)
    }

    fn get(&self, path: &str) -> (u16, String) {
        self.request("GET", path, None, b"")
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The command line's JSON text (its stdout without the final line break).
fn cli(args: &[&str]) -> String {
    let out = aloft(args);
    assert!(matches!(out.status.code(), Some(0 | 1)), "{args:?}");
    String::from_utf8(out.stdout)
        .unwrap()
        .trim_end()
        .to_string()
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
            _ => {
                // Refused by the command line: the same message, 422.
                assert_eq!(code, 422, "{name}: {body}");
                let message = String::from_utf8(out.stderr).unwrap();
                let message = message
                    .trim_end()
                    .strip_prefix("aloft: error: ")
                    .unwrap()
                    .to_string();
                let got: serde_json::Value = serde_json::from_str(&body).unwrap();
                assert_eq!(got["error"], message, "{name}");
            }
        }
    }
}

#[test]
fn the_api_refuses_bad_requests_and_keeps_serving() {
    let server = Server::start(&["--max-upload-mb", "1"]);
    let (code, body) = server.get("/api/endurance?bogus=1");
    assert_eq!(code, 400, "{body}");
    assert!(body.contains("unknown option 'bogus'"), "{body}");
    let (code, body) = server.request("POST", "/api/mission?file=x.toml", None, b"hello");
    assert_eq!(code, 422, "{body}");
    assert!(body.contains("x.toml"), "{body}");
    // A page elsewhere reaching the server by DNS rebinding.
    let (code, body) = server.request("GET", "/api/vehicles", Some("evil.example:80"), b"");
    assert_eq!(code, 403, "{body}");
    // Past the limit: 413, and the server goes on.
    let big = vec![b'#'; 2 << 20];
    let (code, _) = server.request("POST", "/api/mission", None, &big);
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
