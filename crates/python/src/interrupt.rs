//! Ctrl-C while Rust steps with the interpreter's lock released. Python's own SIGINT handler
//! only sets a flag that the main thread reads when it next runs Python, and the steps run on
//! a worker thread of the simulation's pool; so a handler of ours, chained before Python's,
//! raises a flag that the step loop reads after every step. Once the run has stopped, the
//! caller hands the interrupt to Python (`Python::check_signals`), which raises
//! `KeyboardInterrupt`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;

static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The flag SIGINT raises, its handler installed on first use (signal-hook calls the handler
/// that was there before, Python's, after its own).
pub(crate) fn flag() -> Arc<AtomicBool> {
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        // Without a handler (an embedding that forbids one) Ctrl-C still reaches Python
        // between calls.
        let _ = signal_hook::flag::register(signal_hook::consts::SIGINT, flag.clone());
        flag
    })
    .clone()
}

/// Whether Ctrl-C came since the last [`clear`].
pub(crate) fn caught() -> bool {
    flag().load(Ordering::SeqCst)
}

/// Forgets a Ctrl-C, before a run starts.
pub(crate) fn clear() {
    flag().store(false, Ordering::SeqCst);
}

/// After a run that a Ctrl-C stopped: says `what` on `sys.stderr`, then Python's handler
/// raises `KeyboardInterrupt` (or does what the user's handler does); if it did not (a
/// handler that returns), the interrupt is raised here with `what`.
pub(crate) fn deliver(py: Python<'_>, what: String) -> PyResult<()> {
    clear();
    // Said on the notebook's or terminal's stderr, as the command line says it: Python's
    // handler raises a `KeyboardInterrupt` without a message.
    if let Ok(err) = py.import("sys").and_then(|s| s.getattr("stderr")) {
        let _ = err.call_method1("write", (format!("{what}\n"),));
    }
    py.check_signals()?;
    Err(PyKeyboardInterrupt::new_err(what))
}
