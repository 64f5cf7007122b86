//! No message quotes the content of a file aloft could not read: a file named where a vehicle, a
//! mission, a wind field, a log, a column map, a rotor or a spec sheet is expected, that is none of
//! them (a password file, a process environment, a line of text, a one-line CSV), is refused
//! (exit 2) naming the file and what it expected, never a line of it. A server that reads a file
//! on a request's behalf would otherwise tell its content to whoever asked (issue 32, finding 1).

use crate::common;

use std::path::PathBuf;

use common::{data_dir, run, scratch};

/// Files that are none of what aloft reads, each with a marker no message may carry.
fn secrets() -> Vec<(PathBuf, &'static str)> {
    let shapes: [(&str, &str, Vec<u8>); 8] = [
        (
            "passwd",
            "SECRETPASSWD",
            b"root:x:0:0:SECRETPASSWD:/root:/bin/bash\ndaemon:x:1:1::/:/bin/sh\n".to_vec(),
        ),
        (
            "environ",
            "SECRETENVIRON",
            b"PATH=/usr/bin\0TOKEN=SECRETENVIRON\0HOME=/root\0".to_vec(),
        ),
        (
            "header.csv",
            "SECRETHEADER",
            b"SECRETHEADER,b,c\n1,2,3\n4,5,6\n".to_vec(),
        ),
        (
            "line.toml",
            "SECRETTOML",
            b"SECRETTOML something that is not toml at all\n".to_vec(),
        ),
        (
            "line.plan",
            "SECRETPLAN",
            b"SECRETPLAN this is not JSON\n".to_vec(),
        ),
        (
            "line.waypoints",
            "SECRETWPL",
            b"SECRETWPL 110\n0\t1\t0\t16\t0\t0\t0\t0\t1\t2\t3\t1\n".to_vec(),
        ),
        ("line.json", "SECRETJSON", b"[SECRETJSON]\n".to_vec()),
        ("key.csv", "SECRETKEY", b"SECRETKEY=1\nother=2\n".to_vec()),
    ];
    shapes
        .into_iter()
        .map(|(name, marker, bytes)| {
            let path = scratch("disclosure", name);
            std::fs::write(&path, bytes).unwrap();
            (path, marker)
        })
        .collect()
}

/// The commands that read a named file, with `{}` where the file goes.
fn commands() -> Vec<Vec<String>> {
    let kaist = common::files("kaist_energy_drone", |n| n.ends_with(".csv"))[0]
        .display()
        .to_string();
    let ulog = data_dir()
        .join("flight_logs/pyulog_sample_log_small.ulg")
        .display()
        .to_string();
    let out = scratch("disclosure", "out").display().to_string();
    let lines: [&str; 22] = [
        "mission {}",
        "mission --vehicle {}",
        "mission --wind-field {}",
        "mission --replay {}",
        "mission --replay KAIST --profile {}",
        "endurance --vehicle {}",
        "power --vehicle {}",
        "power --input {}",
        "propulsion --vehicle {}",
        "rotor --rotor {}",
        "fit --log {} --vehicle-template dji-m100 -o OUT",
        "fit --log KAIST --vehicle-template {} -o OUT",
        "fit --log KAIST --profile {} --vehicle-template dji-m100 -o OUT",
        "validate --log {} --vehicle dji-m100",
        "validate --log KAIST --vehicle {}",
        "live --replay {}",
        "live --tlog {} --speed max",
        "live --replay ULOG --mission {}",
        "live --replay ULOG --vehicle {}",
        "log info {}",
        "convert {} -o OUT",
        "vehicles calibrate {} -o OUT",
    ];
    lines
        .iter()
        .map(|l| {
            l.split(' ')
                .map(|w| match w {
                    "KAIST" => kaist.clone(),
                    "ULOG" => ulog.clone(),
                    "OUT" => out.clone(),
                    w => w.to_string(),
                })
                .collect()
        })
        .collect()
}

#[test]
fn no_message_quotes_a_file_that_is_not_what_was_expected() {
    let secrets = secrets();
    let mut leaks = Vec::new();
    for command in commands() {
        for (path, marker) in &secrets {
            let path = path.display().to_string();
            let args: Vec<&str> = command
                .iter()
                .map(|w| if w == "{}" { path.as_str() } else { w.as_str() })
                .collect();
            let (code, out, err) = run(&args);
            if out.contains(marker) || err.contains(marker) {
                leaks.push(format!("aloft {}: {}", args.join(" "), err.trim_end()));
            }
            // Not a file of the kind asked for: bad input, never an answer built from it.
            assert!(
                code == 2 || !out.contains(marker),
                "aloft {}: exit {code}",
                args.join(" ")
            );
        }
    }
    assert!(
        leaks.is_empty(),
        "{} leaks:\n{}",
        leaks.len(),
        leaks.join("\n")
    );
}
