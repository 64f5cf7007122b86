//! SIGINT and SIGTERM (Ctrl-C, a service manager's stop): one handler for the whole command line
//! (the `ctrlc` crate, feature `signals`), so that an interrupted command leaves no file behind.
//!
//! [`install`] (every command but `serve`, whose server stops on its own signal handling): the
//! first signal removes the temporary files of every output this process is writing
//! ([`aloft::engine::abandon_outputs`]: a set of files being placed is finished first, so a
//! folder holds the whole set or none of it) and exits with 130, the shell's code for Ctrl-C.
//!
//! [`stop_flag`] (`aloft live`, whose stream ends with its summary): the first signal only sets
//! the flag, the live loop ends as at the end of a log and places its recording; a second signal
//! exits as above.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// The flag of `aloft live`, when it asked for one.
static STOP: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// 128 + SIGINT: the shell's code for a process stopped by Ctrl-C.
const INTERRUPTED: i32 = 130;

/// Set the handler (once; later calls do nothing). Without the `signals` feature, or where the
/// handler cannot be set, the signals stop the process as they would otherwise.
pub fn install() {
    #[cfg(feature = "signals")]
    {
        static SET: std::sync::Once = std::sync::Once::new();
        SET.call_once(|| {
            // An error here (a handler already set by the program) leaves the default.
            let _ = ctrlc::set_handler(on_signal);
        });
    }
}

/// What a signal does: set `aloft live`'s flag the first time, else abandon the outputs and exit.
#[cfg_attr(not(feature = "signals"), allow(dead_code))]
fn on_signal() {
    if let Some(stop) = STOP.get() {
        if !stop.swap(true, Ordering::SeqCst) {
            return;
        }
    }
    aloft::engine::abandon_outputs();
    std::process::exit(INTERRUPTED);
}

/// A flag the first SIGINT or SIGTERM sets instead of exiting (a second one exits); `None` when
/// no handler can be set, so that the signal stops the process as it would otherwise.
pub fn stop_flag() -> Option<Arc<AtomicBool>> {
    if !cfg!(feature = "signals") {
        return None;
    }
    install();
    Some(
        STOP.get_or_init(|| Arc::new(AtomicBool::new(false)))
            .clone(),
    )
}
