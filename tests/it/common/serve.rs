//! `aloft serve` as the tests run it: a server on a free loopback port, stopped when dropped,
//! plain HTTP/1.1 requests written by hand (so that a test can send what no client library
//! would), and the server process's own figures (`/proc/PID/status`, `/proc/PID/stat`).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

/// A server on a free loopback port, stopped when dropped.
pub struct Server {
    pub child: Child,
    pub address: String,
}

/// An answer: status, headers (lower-case names) and body.
#[derive(Debug)]
pub struct Answer {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: String,
}

impl Answer {
    /// The value of header `name` (lower case).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

impl Server {
    /// `aloft serve --listen 127.0.0.1:0 EXTRA...`, once it has printed its URL.
    pub fn start(extra: &[&str]) -> Self {
        Self::start_on("127.0.0.1:0", extra)
    }

    /// `aloft serve --listen LISTEN EXTRA...`.
    pub fn start_on(listen: &str, extra: &[&str]) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_aloft"))
            .args(["serve", "--listen", listen])
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

    /// The port it listens on.
    pub fn port(&self) -> u16 {
        self.address.rsplit(':').next().unwrap().parse().unwrap()
    }

    /// A connection to it.
    pub fn connect(&self) -> TcpStream {
        let s = TcpStream::connect(self.address.replace("0.0.0.0", "127.0.0.1")).expect("connect");
        s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        s
    }

    /// One request of `method`, `path`, extra header lines and a body (the connection closed
    /// after it; `Host` is the server's address unless `extra` gives one).
    pub fn send(&self, method: &str, path: &str, extra: &[&str], body: &[u8]) -> Answer {
        let mut s = self.connect();
        let host = match extra
            .iter()
            .any(|h| h.to_ascii_lowercase().starts_with("host:"))
        {
            true => String::new(),
            false => format!("Host: {}\r\n", self.address),
        };
        let mut head = format!("{method} {path} HTTP/1.1\r\n{host}");
        for h in extra {
            head.push_str(h);
            head.push_str("\r\n");
        }
        head.push_str(&format!(
            "Content-Length: {}\r\nConnection: close\r\n\r\n",
            body.len()
        ));
        s.write_all(head.as_bytes()).expect("request head");
        // The server may answer (413) and close before the whole body is read.
        let _ = s.write_all(body);
        read_answer(&mut s)
    }

    /// [`Self::send`] without extra headers: status and body.
    pub fn request(
        &self,
        method: &str,
        path: &str,
        host: Option<&str>,
        body: &[u8],
    ) -> (u16, String) {
        let host = host.map(|h| format!("Host: {h}"));
        let extra: Vec<&str> = host.iter().map(String::as_str).collect();
        let a = self.send(method, path, &extra, body);
        (a.status, a.body)
    }

    pub fn get(&self, path: &str) -> (u16, String) {
        self.request("GET", path, None, b"")
    }

    /// A line of the server's `/proc/PID/status` (`VmHWM`, `VmRSS`), kB.
    pub fn status_kb(&self, key: &str) -> u64 {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).unwrap();
        status
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{key}:")))
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no {key} in the server's status"))
    }

    /// The CPU time the server has used, s (user + system, `/proc/PID/stat`).
    pub fn cpu_s(&self) -> f64 {
        let stat = std::fs::read_to_string(format!("/proc/{}/stat", self.child.id())).unwrap();
        // The fields after the command's name in parentheses: utime and stime are the 12th and
        // 13th of them.
        let after = stat.rsplit_once(')').unwrap().1;
        let fields: Vec<&str> = after.split_whitespace().collect();
        let ticks: f64 = fields[11].parse::<f64>().unwrap() + fields[12].parse::<f64>().unwrap();
        // Clock ticks per second: 100 on Linux (USER_HZ).
        ticks / 100.0
    }

    /// The CPU the server spends on a request whose client leaves, s: in the first `working` of
    /// the request sent on `client` (which must be more than 0.5 s: the work started), then in
    /// 3 s from `settle` after the client left (`client` is closed here).
    pub fn cpu_after_the_client_left(
        &self,
        client: TcpStream,
        working: Duration,
        settle: Duration,
    ) -> (f64, f64) {
        std::thread::sleep(working);
        let busy_s = self.cpu_s();
        assert!(busy_s > 0.5, "the work did not start: {busy_s} s of CPU");
        drop(client);
        std::thread::sleep(settle);
        let after = self.cpu_s();
        std::thread::sleep(Duration::from_secs(3));
        (busy_s, self.cpu_s() - after)
    }

    /// Open files of the server.
    pub fn open_files(&self) -> usize {
        std::fs::read_dir(format!("/proc/{}/fd", self.child.id())).map_or(0, |d| d.count())
    }
}

/// The answer on a connection: read to its end (the server closes it after the answer).
pub fn read_answer(s: &mut TcpStream) -> Answer {
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    parse_answer(&raw)
}

/// An answer's status, headers and body from its bytes (a body sent in chunks is joined).
pub fn parse_answer(raw: &[u8]) -> Answer {
    let text = String::from_utf8_lossy(raw).into_owned();
    let (head, body) = text.split_once("\r\n\r\n").unwrap_or((&text, ""));
    let mut lines = head.lines();
    let status: u16 = lines
        .next()
        .and_then(|l| l.split(' ').nth(1))
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status in {text:?}"));
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(n, v)| (n.trim().to_ascii_lowercase(), v.trim().to_string()))
        .collect();
    let chunked = headers
        .iter()
        .any(|(n, v)| n == "transfer-encoding" && v.contains("chunked"));
    let body = if chunked {
        unchunked(body)
    } else {
        body.to_string()
    };
    Answer {
        status,
        headers,
        body,
    }
}

/// A chunked body's data.
fn unchunked(mut body: &str) -> String {
    let mut out = String::new();
    while let Some((size, rest)) = body.split_once("\r\n") {
        let Ok(n) = usize::from_str_radix(size.trim(), 16) else {
            break;
        };
        if n == 0 || rest.len() < n {
            break;
        }
        out.push_str(&rest[..n]);
        body = rest[n..].trim_start_matches("\r\n");
    }
    out
}

/// A server is stopped as a user stops it ([`super::stop`]), so that it removes its private
/// folder of uploads.
impl Drop for Server {
    fn drop(&mut self) {
        super::stop(&mut self.child);
    }
}

/// `text` as a query value (percent-encoded but for unreserved characters and `/`).
pub fn encoded(text: &str) -> String {
    text.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'~' | b'/' => {
                (b as char).to_string()
            }
            _ => format!("%{b:02X}"),
        })
        .collect()
}
