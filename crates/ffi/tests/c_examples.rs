//! The C programs of `examples/c/`, built with the system C compiler (`cc`) against the static
//! library cargo built for this test (`<target>/<profile>/deps/libaloft_ffi.a`: the same build of
//! the library the Rust tests of this crate link, so no second build of the engine with other
//! features) and run:
//! - `mission.c` prints the energy of the built-in demonstration mission with the built-in M100;
//!   it must equal the engine's to the last digit, and the summary JSON it prints must be the
//!   engine's text byte for byte (`tests/it/engine_cli.rs` holds the CLI's `aloft mission
//!   --format json` to the same text);
//! - `bad_input.c` feeds the ABI null pointers, invalid UTF-8, malformed TOML and JSON, double
//!   frees and foreign pointers; every call must return its error code with a message.

use std::path::{Path, PathBuf};
use std::process::Command;

use aloft::engine::{plan_mission, Mission, MissionOptions, Vehicle};

/// `libaloft_ffi.a` of this build: beside this test executable (`<profile>/deps/`).
fn static_lib() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let lib = exe
        .parent()
        .expect("<target>/<profile>/deps/<test>")
        .join("libaloft_ffi.a");
    assert!(
        lib.exists(),
        "{} not built (crate-type staticlib in crates/ffi/Cargo.toml)",
        lib.display()
    );
    lib
}

/// Compile `examples/c/<name>.c` against the static library; return the executable.
fn build_c(name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
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
fn c_example_energy_equals_the_engine_to_the_last_digit() {
    let exe = build_c("mission");
    let c = Command::new(&exe).output().expect("run the C example");
    let c_out = String::from_utf8(c.stdout).expect("UTF-8");
    assert_eq!(
        c.status.code(),
        Some(0),
        "C example failed: {c_out}{}",
        String::from_utf8_lossy(&c.stderr)
    );

    let plan = plan_mission(
        &Vehicle::builtin("dji-m100").expect("built-in M100"),
        &Mission::demo(),
        &MissionOptions::default(),
    )
    .expect("the demonstration mission plans");
    let engine_json = plan.to_json().expect("summary JSON") + "\n";
    let engine_value: serde_json::Value = serde_json::from_str(&engine_json).expect("JSON");
    let engine_energy = engine_value["energy_wh"].as_f64().expect("energy_wh");

    // %.17g round-trips a double: equal bits mean equal at every printed precision.
    let c_energy: f64 = value_of(&c_out, "energy_wh:").parse().expect("a number");
    assert_eq!(
        c_energy.to_bits(),
        engine_energy.to_bits(),
        "C {c_energy:e} vs engine {engine_energy:e}"
    );
    // And rounded as the CLI's table prints it (`{:.1}`).
    assert_eq!(
        value_of(&c_out, "energy used:"),
        format!("{engine_energy:.1} Wh")
    );

    // The summary JSON the C program printed is the engine's, byte for byte.
    let c_json = &c_out[c_out.find('{').expect("JSON in the C output")..];
    assert_eq!(c_json, engine_json);
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
