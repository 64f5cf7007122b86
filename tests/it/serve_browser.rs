//! The page of `aloft serve` in a real browser: Debian's `chromium` driven by Playwright
//! (`tests/browser/run.mjs`, `playwright-core` pinned in `tests/browser/package.json`; it
//! downloads no browser). The script starts its own servers on loopback and stops them; this
//! test runs it with the binary under test and stops it if it hangs.
//!
//! It needs `/usr/bin/chromium` and `npm ci` in `tests/browser` (`.ci/run` installs both). Without
//! them the test says so and passes, unless `ALOFT_BROWSER_TESTS=require` (set by `.ci/run`),
//! where it fails.
#![cfg(all(feature = "serve", unix))]

use crate::common;

use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Longest the browser run may take before it is stopped and failed.
const DEADLINE: Duration = Duration::from_secs(600);

#[test]
fn the_page_works_in_a_real_browser() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/browser");
    let chromium = Path::new("/usr/bin/chromium");
    let ready = chromium.exists() && dir.join("node_modules/playwright-core").exists();
    if !ready {
        let required = std::env::var("ALOFT_BROWSER_TESTS").is_ok_and(|v| v == "require");
        assert!(
            !required,
            "ALOFT_BROWSER_TESTS=require, but /usr/bin/chromium or tests/browser/node_modules is missing"
        );
        eprintln!(
            "skipped: the browser tests need /usr/bin/chromium and `npm ci` in tests/browser"
        );
        return;
    }
    // In a process group of its own, so that a run stopped at the deadline takes its servers and
    // its browser with it.
    let mut child = Command::new("node")
        .process_group(0)
        .arg("run.mjs")
        .current_dir(&dir)
        .env("ALOFT_BIN", env!("CARGO_BIN_EXE_aloft"))
        .env("ALOFT_DATA_DIR", common::data_dir())
        .stdin(Stdio::null())
        .spawn()
        .expect("node runs tests/browser/run.mjs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("waiting for node") {
            break status;
        }
        if start.elapsed() > DEADLINE {
            let group = format!("-{}", child.id());
            let _ = Command::new("kill").args(["-KILL", "--", &group]).status();
            let _ = child.kill();
            let _ = child.wait();
            panic!("the browser tests ran past {DEADLINE:?} and were stopped");
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    assert!(status.success(), "the browser tests failed: {status}");
}
