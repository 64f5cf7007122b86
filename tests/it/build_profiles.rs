//! `.ci/run` builds the Python extension's wheel in the dev profile into the workspace's target
//! directory, so that cargo reuses the dependencies the tests built (aloft's own crates build
//! again: a path dependency's build is keyed by its path from its workspace's root, and the
//! extension has its own workspace). It does so only while the two manifests' dev profiles and
//! the two lock files' versions agree: drift would cost CI a second build of every dependency,
//! silently. These tests make it loud.

use std::collections::BTreeMap;
use std::path::Path;

fn read_toml(relative: &str) -> toml::Table {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(relative);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{relative}: {e}"));
    text.parse()
        .unwrap_or_else(|e| panic!("{relative} is not TOML: {e}"))
}

/// Each package of a lock file, by name, with its versions (the workspace's dev-dependencies
/// may pull in a second version of one).
fn versions(relative: &str) -> BTreeMap<String, Vec<String>> {
    let lock = read_toml(relative);
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for package in lock["package"].as_array().expect("[[package]]") {
        let name = package["name"].as_str().expect("name").to_string();
        let version = package["version"].as_str().expect("version").to_string();
        out.entry(name).or_default().push(version);
    }
    out
}

#[test]
fn the_python_manifest_builds_with_the_workspaces_dev_profile() {
    let root = read_toml("Cargo.toml");
    let python = read_toml("python/Cargo.toml");
    let built = versions("python/Cargo.lock");
    let dev = |t: &toml::Table| {
        t["profile"]["dev"]
            .as_table()
            .expect("[profile.dev]")
            .clone()
    };
    // The workspace's overrides of packages the extension does not build (cbindgen, criterion)
    // are left out of its copy: cargo warns of a package spec that matches nothing.
    let mut expected = dev(&root);
    if let Some(toml::Value::Table(packages)) = expected.get_mut("package") {
        packages.retain(|name, _| name == "*" || built.contains_key(name));
    }
    assert_eq!(
        dev(&python),
        expected,
        "python/Cargo.toml's [profile.dev] tables differ from Cargo.toml's"
    );
}

#[test]
fn the_python_lock_pins_the_workspaces_versions() {
    let root = versions("Cargo.lock");
    let python = versions("python/Cargo.lock");
    let differ: Vec<String> = python
        .iter()
        .filter_map(|(name, vs)| {
            let theirs = root.get(name)?;
            let other = vs.iter().any(|v| !theirs.contains(v));
            other.then(|| format!("{name}: python {vs:?}, workspace {theirs:?}"))
        })
        .collect();
    assert!(
        differ.is_empty(),
        "python/Cargo.lock resolves other versions than Cargo.lock (`cargo update \
         --manifest-path python/Cargo.toml -p NAME --precise VERSION`): {differ:?}"
    );
}
