//! An input as the engine's readers take it: some targets read several files from one input,
//! split at a separator line, and the readers take paths, so the parts are written to a scratch
//! directory first. Shared by the seeds, which make inputs of this shape, and the targets.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

/// The line between the column map and the CSV log in an input of the `column-map` target.
pub const MAP_SEPARATOR: &[u8] = b"\n#--- csv ---\n";

/// The line between the tables of an input of the `px4-csv` target.
pub const TABLE_SEPARATOR: &[u8] = b"\n#--- table ---\n";

thread_local! {
    static SCRATCH: RefCell<Option<PathBuf>> = const { RefCell::new(None) };
}

/// A file in this thread's scratch directory (on tmpfs, `/dev/shm`, when there is one): the
/// engine's log readers take paths, so an input is written there and read back.
pub fn scratch(name: &str) -> PathBuf {
    SCRATCH.with(|s| {
        let mut s = s.borrow_mut();
        let dir = s.get_or_insert_with(|| {
            static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
            let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let base = if Path::new("/dev/shm").is_dir() {
                PathBuf::from("/dev/shm")
            } else {
                std::env::temp_dir()
            };
            let dir = base.join(format!("aloft-fuzz-{}-{n}", std::process::id()));
            let _ = std::fs::create_dir_all(&dir);
            dir
        });
        dir.join(name)
    })
}

/// Remove this thread's scratch directory.
pub fn remove_scratch() {
    SCRATCH.with(|s| {
        if let Some(dir) = s.borrow_mut().take() {
            let _ = std::fs::remove_dir_all(dir);
        }
    });
}
