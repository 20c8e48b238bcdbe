//! Ctrl-C while Rust steps with the interpreter's lock released. Python's own SIGINT handler
//! only sets a flag that the main thread reads when it next runs Python, and the steps run on
//! a worker thread of the simulation's pool; so a handler of ours, chained before Python's,
//! raises a flag that the step loop reads after every step. Once the run has stopped, the
//! caller hands the interrupt to Python (`Python::check_signals`), which raises
//! `KeyboardInterrupt`.
//!
//! The handler is installed for the length of each run ([`Armed`]), not once: anything that
//! sets a SIGINT handler between runs replaces the process's handler with its own
//! (`asyncio.run` does, on entry and on exit, and Jupyter kernels run on asyncio), and a
//! handler installed once would silently stop seeing Ctrl-C from then on.

use std::sync::atomic::{AtomicBool, Ordering};

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;

/// Raised by the handler; read after every step.
static CAUGHT: AtomicBool = AtomicBool::new(false);

/// Whether Ctrl-C came since the current run was armed.
pub(crate) fn caught() -> bool {
    CAUGHT.load(Ordering::SeqCst)
}

/// Our SIGINT handler, installed while it lives (runs nest: a callback may run another
/// simulation, and only the outermost installs and restores). Create and drop it holding the
/// interpreter's lock, which orders the nesting.
pub(crate) struct Armed {
    outermost: bool,
}

impl Armed {
    /// Forgets an earlier Ctrl-C and installs the handler, chained to the one in place.
    pub(crate) fn new(_py: Python<'_>) -> Self {
        CAUGHT.store(false, Ordering::SeqCst);
        Self {
            outermost: os::install(),
        }
    }
}

impl Drop for Armed {
    fn drop(&mut self) {
        os::uninstall(self.outermost);
    }
}

// The one unsafe code of the workspace's libraries: installing a signal handler has no safe
// interface in std, and signal-hook's installs once, for good (see the module's note).
#[cfg(unix)]
#[allow(unsafe_code)]
mod os {
    //! `sigaction`: ours in, the previous one kept and called after ours, and put back at the
    //! end unless someone replaced ours meanwhile.

    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::Mutex;

    use super::CAUGHT;

    /// How many runs are armed.
    static DEPTH: AtomicUsize = AtomicUsize::new(0);
    /// The handler before ours, as the signal handler reads it (no lock there).
    static PREV_HANDLER: AtomicUsize = AtomicUsize::new(libc::SIG_DFL);
    static PREV_SIGINFO: AtomicBool = AtomicBool::new(false);
    /// The whole previous action, to put back.
    static PREV: Mutex<Option<libc::sigaction>> = Mutex::new(None);

    extern "C" fn on_sigint(sig: libc::c_int, info: *mut libc::siginfo_t, ctx: *mut libc::c_void) {
        CAUGHT.store(true, Ordering::SeqCst);
        let prev = PREV_HANDLER.load(Ordering::SeqCst);
        if prev == libc::SIG_DFL || prev == libc::SIG_IGN {
            // No Python handler (an embedding without one): the flag alone stops the run.
            return;
        }
        // SAFETY: `prev` is the handler the kernel would have called, of the type its
        // SA_SIGINFO flag says, and it is called as the kernel would call it.
        unsafe {
            if PREV_SIGINFO.load(Ordering::SeqCst) {
                let f: extern "C" fn(libc::c_int, *mut libc::siginfo_t, *mut libc::c_void) =
                    std::mem::transmute(prev);
                f(sig, info, ctx);
            } else {
                let f: extern "C" fn(libc::c_int) = std::mem::transmute(prev);
                f(sig);
            }
        }
    }

    fn ours() -> usize {
        on_sigint as extern "C" fn(libc::c_int, *mut libc::siginfo_t, *mut libc::c_void) as usize
    }

    /// Installs ours if no run is armed; whether this call did.
    pub(super) fn install() -> bool {
        if DEPTH.fetch_add(1, Ordering::SeqCst) > 0 {
            return false;
        }
        // SAFETY: plain sigaction calls on zeroed, then filled, structures.
        unsafe {
            let mut old: libc::sigaction = std::mem::zeroed();
            if libc::sigaction(libc::SIGINT, std::ptr::null(), &mut old) != 0 {
                return true;
            }
            PREV_HANDLER.store(old.sa_sigaction, Ordering::SeqCst);
            PREV_SIGINFO.store(old.sa_flags & libc::SA_SIGINFO != 0, Ordering::SeqCst);
            *PREV.lock().unwrap_or_else(|p| p.into_inner()) = Some(old);
            let mut new: libc::sigaction = std::mem::zeroed();
            new.sa_sigaction = ours();
            new.sa_flags = libc::SA_SIGINFO | libc::SA_RESTART | libc::SA_ONSTACK;
            libc::sigemptyset(&mut new.sa_mask);
            libc::sigaction(libc::SIGINT, &new, std::ptr::null_mut());
        }
        true
    }

    /// Ends a run; the outermost puts the previous handler back if ours is still in place.
    pub(super) fn uninstall(outermost: bool) {
        DEPTH.fetch_sub(1, Ordering::SeqCst);
        if !outermost {
            return;
        }
        let Some(prev) = PREV.lock().unwrap_or_else(|p| p.into_inner()).take() else {
            return;
        };
        // SAFETY: as in `install`.
        unsafe {
            let mut now: libc::sigaction = std::mem::zeroed();
            if libc::sigaction(libc::SIGINT, std::ptr::null(), &mut now) == 0
                && now.sa_sigaction == ours()
            {
                libc::sigaction(libc::SIGINT, &prev, std::ptr::null_mut());
            }
        }
    }
}

#[cfg(not(unix))]
#[allow(unsafe_code)]
mod os {
    //! signal-hook's handler, registered once; it calls the handler that was there before.

    use std::sync::atomic::Ordering;
    use std::sync::OnceLock;

    static ONCE: OnceLock<()> = OnceLock::new();

    pub(super) fn install() -> bool {
        ONCE.get_or_init(|| {
            // SAFETY: the action only stores to an atomic.
            let _ = unsafe {
                signal_hook::low_level::register(signal_hook::consts::SIGINT, || {
                    super::CAUGHT.store(true, Ordering::SeqCst)
                })
            };
        });
        false
    }

    pub(super) fn uninstall(_outermost: bool) {}
}

/// After a run that a Ctrl-C stopped: says `what` on `sys.stderr`, then Python's handler
/// raises `KeyboardInterrupt` (or does what the user's handler does); if it did not (a
/// handler that returns), the interrupt is raised here with `what`.
pub(crate) fn deliver(py: Python<'_>, what: String) -> PyResult<()> {
    CAUGHT.store(false, Ordering::SeqCst);
    // Said on the notebook's or terminal's stderr, as the command line says it: Python's
    // handler raises a `KeyboardInterrupt` without a message.
    if let Ok(err) = py.import("sys").and_then(|s| s.getattr("stderr")) {
        let _ = err.call_method1("write", (format!("{what}\n"),));
    }
    py.check_signals()?;
    Err(PyKeyboardInterrupt::new_err(what))
}
