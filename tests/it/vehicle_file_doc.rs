//! The vehicle-file reference (`docs/vehicle-file.md`, issue 35 item 3) against the reader
//! itself: every key each table accepts is documented in that table, and every key the reference
//! documents is accepted. The accepted keys are the reader's own list, the one its error names when
//! a table holds a key it does not know (`unknown field, expected one of ...`), so a key added to
//! the code without its line in the reference fails here. The template `aloft vehicles template`
//! prints loads and flies (the reference's commands run in `tests/it/doc_commands.rs`).

use std::collections::BTreeSet;

use aloft::engine::{Vehicle, VEHICLE_TEMPLATE};

const REFERENCE: &str = include_str!("../../docs/vehicle-file.md");
const M100: &str = include_str!("../../fixtures/vehicles/dji-m100.toml");
const AEC: &str = include_str!("../../fixtures/vehicles/aec-quadrotor.toml");

/// The keys a table accepts: `text` with an unknown key put first in the table whose header line
/// is `header` (or at the top for `""`), and the list its error names.
fn accepted(text: &str, header: &str) -> BTreeSet<String> {
    let probe = "zz_not_a_key = 1";
    let changed = match header {
        "" => format!("{probe}\n{text}"),
        h => {
            let at = text
                .lines()
                .position(|l| l.trim() == h)
                .unwrap_or_else(|| panic!("no {h} in the file"));
            let mut lines: Vec<&str> = text.lines().collect();
            lines.insert(at + 1, probe);
            lines.join("\n")
        }
    };
    let e = Vehicle::from_toml(&changed, "probe")
        .unwrap_err()
        .to_string();
    // serde's words: "expected one of `a`, `b`, `c`", or "expected `a` or `b`" for two.
    let list = e
        .split("expected one of ")
        .nth(1)
        .or_else(|| e.split("expected ").nth(1))
        .unwrap_or_else(|| panic!("{header}: no list of keys in {e}"));
    list.split(", ")
        .flat_map(|k| k.split(" or "))
        .map(|k| k.trim().trim_matches('`').to_string())
        .collect()
}

/// The keys the reference documents in the section whose heading starts with `heading` (up to
/// the next heading of the same or a higher level, or a line naming another table): the
/// backticked names in the first column of its tables.
fn documented(heading: &str) -> BTreeSet<String> {
    let start = REFERENCE
        .find(heading)
        .unwrap_or_else(|| panic!("no section {heading}"));
    let rest = &REFERENCE[start + heading.len()..];
    let end = rest
        .find("\n#")
        .into_iter()
        .chain(rest.find("\n`["))
        .min()
        .unwrap_or(rest.len());
    rest[..end]
        .lines()
        .filter(|l| l.starts_with("| `"))
        .flat_map(|l| {
            let first = l.split('|').nth(1).unwrap_or_default();
            first
                .split(',')
                .map(|k| k.trim().trim_matches('`').to_string())
                .collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn every_key_of_every_table_is_in_the_reference_and_no_other() {
    let subtables = ["source", "power", "propulsion", "airframe", "battery"];
    let cases: [(&str, &str, &str); 10] = [
        (M100, "", "## Top level"),
        (M100, "[source]", "## `[source]`"),
        (M100, "[power]", "## `[power]`"),
        (M100, "[airframe]", "## `[airframe]`"),
        (M100, "[[battery]]", "## `[[battery]]`"),
        (AEC, "[propulsion]", "## `[propulsion]`"),
        (AEC, "[propulsion.propeller]", "`[propulsion.propeller]`:"),
        (AEC, "[propulsion.motor]", "`[propulsion.motor]`:"),
        (AEC, "[propulsion.esc]", "`[propulsion.esc]`"),
        (AEC, "[propulsion.battery]", "## `[[battery]]`"),
    ];
    for (file, header, heading) in cases {
        let mut keys = accepted(file, header);
        // Sub-tables are documented by their own sections.
        for t in subtables {
            if header.is_empty() {
                keys.remove(t);
            }
        }
        if header == "[propulsion]" {
            for t in ["propeller", "motor", "esc", "battery"] {
                keys.remove(t);
            }
        }
        let doc = documented(heading);
        let missing: Vec<&String> = keys.difference(&doc).collect();
        let unknown: Vec<&String> = doc.difference(&keys).collect();
        assert!(
            missing.is_empty() && unknown.is_empty(),
            "{header}: not documented {missing:?}; documented but not read {unknown:?}"
        );
    }
}

/// The template loads, flies a mission's figures (its pack and airframe are complete), and marks
/// what the user changes.
#[test]
fn the_template_loads_and_flies() {
    let v = Vehicle::from_toml(VEHICLE_TEMPLATE, "template").unwrap();
    let summary = aloft::engine::endurance(&v, &Default::default()).unwrap();
    assert!(summary.report.hover_endurance_s > 60.0);
    assert!(VEHICLE_TEMPLATE.matches("CHANGE").count() >= 8);
}
