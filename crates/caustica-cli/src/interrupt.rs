//! Ctrl-C: the first asks the render to stop and save what it has; the second exits at once.

use std::sync::atomic::{AtomicBool, Ordering};

static CANCEL: AtomicBool = AtomicBool::new(false);

/// Installs the handler and returns the flag it sets.
pub fn install() -> &'static AtomicBool {
    let _ = ctrlc::set_handler(|| {
        if CANCEL.swap(true, Ordering::SeqCst) {
            eprintln!("\ninterrupted again: exiting without saving");
            std::process::exit(i32::from(crate::EXIT_INTERRUPTED));
        }
        eprintln!("\ninterrupted: finishing the current tiles and saving what is done (Ctrl-C again to quit now)");
    });
    &CANCEL
}
