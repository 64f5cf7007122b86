//! The shared real-data folder of the tests, for the root's tests and the crates' own (included
//! by path): `ALOFT_DATA_DIR`, or `../shared/data` beside the repository.

use std::path::{Path, PathBuf};

/// The shared real-data folder: `ALOFT_DATA_DIR`, or `../shared/data` beside the repository (the
/// folder above the test's crate that holds `Cargo.lock`).
pub fn data_dir() -> PathBuf {
    let dir = std::env::var_os("ALOFT_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
            let root = crate_dir
                .ancestors()
                .find(|d| d.join("Cargo.lock").is_file())
                .unwrap_or(crate_dir);
            root.join("../shared/data")
        });
    assert!(
        dir.is_dir(),
        "ALOFT_DATA_DIR={} is not a directory: the data_val tests need the shared data \
         (set ALOFT_DATA_DIR or place it at ../shared/data)",
        dir.display()
    );
    dir
}

/// The files of the data folder `sub` whose names pass `filter`, sorted.
// Included by path into test crates that list no folder.
#[allow(dead_code)]
pub fn files(sub: &str, filter: impl Fn(&str) -> bool) -> Vec<PathBuf> {
    let dir = data_dir().join(sub);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(&filter))
        .collect();
    v.sort();
    v
}
