//! The binary's two signal handlers: a closed stdout ends vista quietly,
//! and Ctrl-C during `check` ends the run with the report of what
//! finished. Each handler does only async-signal-safe work.

/// A closed stdout (`vista list | head -1`) ends vista quietly like other
/// Unix tools: Rust ignores SIGPIPE, which turns every println! after the
/// reader left into a panic. Only a closed stdout: a worker that died
/// between cases also raises SIGPIPE (on the parent's next request), and
/// that write must fail with EPIPE so the parent starts another worker.
/// Called first thing in `main`, before any thread starts.
pub(crate) fn die_quietly_on_closed_pipe() {
    #[cfg(unix)]
    install(libc::SIGPIPE, on_sigpipe);
}

/// From here on, SIGINT (Ctrl-C) marks the run interrupted instead of
/// ending the process: `vista check` stops starting cases, writes the
/// report of those that finished and exits 130. A second Ctrl-C ends it
/// at once (the handler is reset to the default after the first).
pub(crate) fn stop_on_interrupt() {
    #[cfg(unix)]
    install(libc::SIGINT, on_sigint);
}

#[cfg(unix)]
fn install(signal: libc::c_int, handler: extern "C" fn(libc::c_int)) {
    // SAFETY: both handlers below are async-signal-safe (poll, an atomic
    // store, signal, raise).
    unsafe {
        libc::signal(signal, handler as *const () as libc::sighandler_t);
    }
}

#[cfg(unix)]
extern "C" fn on_sigpipe(_: libc::c_int) {
    // A pipe whose reader left reports POLLERR.
    let mut out = libc::pollfd { fd: libc::STDOUT_FILENO, events: libc::POLLOUT, revents: 0 };
    // SAFETY: one valid pollfd, no wait.
    let closed = unsafe { libc::poll(&mut out, 1, 0) } == 1 && out.revents & libc::POLLERR != 0;
    if closed {
        // SAFETY: the default action ends the process as SIGPIPE would have.
        unsafe {
            libc::signal(libc::SIGPIPE, libc::SIG_DFL);
            libc::raise(libc::SIGPIPE);
        }
    }
}

#[cfg(unix)]
extern "C" fn on_sigint(_: libc::c_int) {
    vista_check::interrupt();
    // SAFETY: signal() is async-signal-safe; SIG_DFL is valid.
    unsafe {
        libc::signal(libc::SIGINT, libc::SIG_DFL);
    }
}
