//! Ctrl-C for long commands that have something to show when stopped (`verify`): the first
//! one asks the running step to stop where it is, so the command prints what it has so far;
//! a second one ends the process at once, as Ctrl-C does anywhere else.

use std::sync::atomic::{AtomicBool, Ordering};

/// Set by the first SIGINT after [`catch`].
static REQUESTED: AtomicBool = AtomicBool::new(false);

/// The SIGINT handler: async-signal-safe (one atomic store, and `signal` itself, which POSIX
/// lists as safe), so it may run between any two instructions of any thread.
extern "C" fn on_interrupt(_signal: libc::c_int) {
    REQUESTED.store(true, Ordering::SeqCst);
    // SAFETY: restoring the default action is async-signal-safe; the next Ctrl-C ends the
    // process as it would without this handler.
    unsafe {
        libc::signal(libc::SIGINT, libc::SIG_DFL);
    }
}

/// From now on, the first Ctrl-C sets [`requested`] instead of ending the process.
pub fn catch() {
    // SAFETY: `on_interrupt` has the signature of a signal handler and does only
    // async-signal-safe work. The cast to `sighandler_t` is how libc takes a handler.
    unsafe {
        libc::signal(libc::SIGINT, on_interrupt as extern "C" fn(libc::c_int) as libc::sighandler_t);
    }
}

/// Whether Ctrl-C was pressed since [`catch`] (never without it).
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// Exit status after an interrupted run that printed what it had: 128 + SIGINT (2), as a
/// shell reports a process that Ctrl-C ended.
pub const INTERRUPTED_EXIT: u8 = 130;

/// What a command returns after printing what it had when Ctrl-C stopped it: the process
/// exits with [`INTERRUPTED_EXIT`] and this message, not as an error.
#[derive(Debug, thiserror::Error)]
#[error("interrupted: {0}")]
pub struct Interrupted(pub String);
