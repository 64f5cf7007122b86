//! The C programs of `examples/c/`, built with the system C compiler (`cc`) against the static
//! library of `aloft-ffi` and run:
//! - `mission.c` prints the energy of the built-in demonstration mission with the built-in M100;
//!   it must equal the CLI's (`aloft mission --format json`) to the last digit, and the summary
//!   JSON it prints must be the CLI's text byte for byte;
//! - `bad_input.c` feeds the ABI null pointers, invalid UTF-8, malformed TOML and JSON, double
//!   frees and foreign pointers; every call must return its error code with a message.
//!
//! The static library is built by a nested `cargo build -p aloft-ffi` into this test's target
//! directory and profile (a no-op when it is up to date).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The target directory and profile directory of this test binary (`<target>/<profile>/deps/..`).
fn target_dirs() -> (PathBuf, PathBuf) {
    let exe = std::env::current_exe().expect("test executable path");
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("<target>/<profile>/deps/<test>")
        .to_path_buf();
    let target_dir = profile_dir
        .parent()
        .expect("<target>/<profile>")
        .to_path_buf();
    (target_dir, profile_dir)
}

/// Build `libaloft_ffi.a` for this profile and return its path.
fn static_lib() -> PathBuf {
    let (target_dir, profile_dir) = target_dirs();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let mut cmd = Command::new(cargo);
    cmd.args([
        "build",
        "--quiet",
        "-p",
        "aloft-ffi",
        "--lib",
        "--target-dir",
    ])
    .arg(&target_dir)
    .current_dir(env!("CARGO_MANIFEST_DIR"));
    match profile_dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") => {}
        Some("release") => {
            cmd.arg("--release");
        }
        Some(other) => {
            cmd.args(["--profile", other]);
        }
        None => panic!("no profile directory in {}", profile_dir.display()),
    }
    let status = cmd.status().expect("run cargo build -p aloft-ffi");
    assert!(status.success(), "cargo build -p aloft-ffi failed");
    let lib = profile_dir.join("libaloft_ffi.a");
    assert!(lib.exists(), "{} not built", lib.display());
    lib
}

/// Compile `examples/c/<name>.c` against the static library; return the executable.
fn build_c(name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = static_lib();
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("aloft-c-{name}"));
    let status = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-g", "-I"])
        .arg(root.join("crates/ffi/include"))
        .arg(root.join(format!("examples/c/{name}.c")))
        .arg(&lib)
        // The system libraries Rust's std needs (`--print native-static-libs` on Linux).
        .args([
            "-lgcc_s",
            "-lutil",
            "-lrt",
            "-lpthread",
            "-lm",
            "-ldl",
            "-lc",
            "-o",
        ])
        .arg(&out)
        .status()
        .expect("run the system C compiler `cc`");
    assert!(status.success(), "cc failed on examples/c/{name}.c");
    out
}

fn value_of<'a>(text: &'a str, key: &str) -> &'a str {
    text.lines()
        .find_map(|l| l.strip_prefix(key))
        .unwrap_or_else(|| panic!("no line starting with '{key}' in:\n{text}"))
        .trim()
}

#[test]
fn c_example_energy_equals_the_cli_to_the_last_digit() {
    let exe = build_c("mission");
    let c = Command::new(&exe).output().expect("run the C example");
    let c_out = String::from_utf8(c.stdout).expect("UTF-8");
    assert_eq!(
        c.status.code(),
        Some(0),
        "C example failed: {c_out}{}",
        String::from_utf8_lossy(&c.stderr)
    );

    let cli = Command::new(env!("CARGO_BIN_EXE_aloft"))
        .args(["mission", "--format", "json"])
        .output()
        .expect("run aloft mission");
    assert_eq!(cli.status.code(), Some(0), "aloft mission failed");
    let cli_json = String::from_utf8(cli.stdout).expect("UTF-8");
    let cli_value: serde_json::Value = serde_json::from_str(&cli_json).expect("CLI JSON");
    let cli_energy = cli_value["energy_wh"].as_f64().expect("energy_wh");

    // %.17g round-trips a double: equal bits mean equal at every printed precision.
    let c_energy: f64 = value_of(&c_out, "energy_wh:").parse().expect("a number");
    assert_eq!(
        c_energy.to_bits(),
        cli_energy.to_bits(),
        "C {c_energy:e} vs CLI {cli_energy:e}"
    );
    // And as the CLI's table prints it.
    let table = Command::new(env!("CARGO_BIN_EXE_aloft"))
        .arg("mission")
        .output()
        .expect("run aloft mission");
    let table = String::from_utf8(table.stdout).expect("UTF-8");
    let cli_printed = value_of(&table, "  energy used")
        .trim_end_matches("Wh")
        .trim();
    assert_eq!(
        value_of(&c_out, "energy used:"),
        format!("{cli_printed} Wh")
    );

    // The summary JSON the C program printed is the CLI's, byte for byte.
    let c_json = &c_out[c_out.find('{').expect("JSON in the C output")..];
    assert_eq!(c_json, cli_json);
}

#[test]
fn c_bad_input_returns_error_codes_and_messages() {
    let exe = build_c("bad_input");
    let out = Command::new(&exe)
        .output()
        .expect("run the C bad-input program");
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "bad-input cases failed or crashed:\n{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("0 failure(s)"), "{text}");
    // Every case ran (a crash part-way would have stopped the list).
    assert_eq!(text.lines().filter(|l| l.starts_with("ok  ")).count(), 35);
}
