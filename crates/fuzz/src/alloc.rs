//! A counting allocator: the largest single request and the peak of live bytes while an input
//! runs. It only counts (atomics, no locks, no allocation, never a panic: a panic inside the
//! allocator is undefined behaviour); the runner checks the figures after the input.
//!
//! A binary or test that wants the memory check declares it:
//!
//! ```ignore
//! #[global_allocator]
//! static ALLOC: aloft_fuzz::CountingAlloc = aloft_fuzz::CountingAlloc;
//! ```
//!
//! Without it, [`installed`] is false and the memory check is skipped (and says so).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering::Relaxed};

/// The system allocator, counted.
#[derive(Debug, Clone, Copy, Default)]
pub struct CountingAlloc;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
static LARGEST: AtomicUsize = AtomicUsize::new(0);
static SEEN: AtomicBool = AtomicBool::new(false);

fn grew(size: usize) {
    LARGEST.fetch_max(size, Relaxed);
    let live = LIVE.fetch_add(size, Relaxed) + size;
    PEAK.fetch_max(live, Relaxed);
}

fn shrank(size: usize) {
    LIVE.fetch_sub(size, Relaxed);
}

/// Count a fresh allocation of `size` bytes that gave `p`: a refused request (null) still counts
/// as the largest asked for.
fn allocated(p: *mut u8, size: usize) -> *mut u8 {
    if p.is_null() {
        LARGEST.fetch_max(size, Relaxed);
    } else {
        grew(size);
    }
    p
}

// SAFETY: every call is forwarded to `System` with the same layout; the counters are atomics
// and the functions neither allocate nor panic.
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        SEEN.store(true, Relaxed);
        allocated(unsafe { System.alloc(layout) }, layout.size())
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        SEEN.store(true, Relaxed);
        allocated(unsafe { System.alloc_zeroed(layout) }, layout.size())
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        shrank(layout.size());
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            LARGEST.fetch_max(new_size, Relaxed);
        } else {
            shrank(layout.size());
            grew(new_size);
        }
        p
    }
}

/// Memory figures of one input, bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MemoryUse {
    /// The largest single request (allocation or reallocation).
    pub largest_request: usize,
    /// The peak of live bytes above what was live when the input started.
    pub peak_live: usize,
}

/// True when [`CountingAlloc`] is the global allocator of this program (it has seen a request).
pub fn installed() -> bool {
    // Make sure at least one allocation has gone through whatever allocator is global.
    drop(std::hint::black_box(Box::new(0u64)));
    SEEN.load(Relaxed)
}

/// Start counting an input: the largest request and the peak are reset; returns the live bytes
/// now (the baseline).
pub fn start() -> usize {
    let live = LIVE.load(Relaxed);
    LARGEST.store(0, Relaxed);
    PEAK.store(live, Relaxed);
    live
}

/// The figures since [`start`] returned `baseline`.
pub fn since(baseline: usize) -> MemoryUse {
    MemoryUse {
        largest_request: LARGEST.load(Relaxed),
        peak_live: PEAK.load(Relaxed).saturating_sub(baseline),
    }
}
