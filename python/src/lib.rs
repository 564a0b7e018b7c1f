//! `caustica._caustica`, the native half of the `caustica` Python package: the library's render
//! API with Python types. Options go through the library's `RenderConfig` under the command
//! line's names, so `render(path, **options)` makes the pixels `caustica render path --…` does.
//!
//! Every long call runs on a thread of its own while the calling thread waits without the GIL,
//! looking for Ctrl-C every few milliseconds ([`wait`]): other Python threads run meanwhile,
//! Ctrl-C cancels the work through the library's cancel flag, and a panic comes back as
//! `caustica.InternalError` instead of crossing into Python.

mod arrays;
mod options;
mod photons;
mod progressive;
mod scene;
mod scene_dict;

use caustica::diagnostic::Diagnostic;
use caustica::error::Error;
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

create_exception!(
    caustica,
    SceneError,
    PyValueError,
    "A scene file is malformed. The message starts with file:line:col; the attributes `path`, \
     `line`, `column`, `reason` and `help` (or None) hold the parts."
);
create_exception!(
    caustica,
    InternalError,
    PyRuntimeError,
    "A bug in caustica (a Rust panic caught before it reached Python)."
);

/// How often a waiting call looks for Ctrl-C.
const SIGNAL_POLL: Duration = Duration::from_millis(20);

/// What a worker thread sends back: its result, or the panic that ended it.
type Outcome<T> = std::thread::Result<caustica::Result<T>>;

/// Runs `work` on a thread of its own and waits for it without the GIL ([`wait`]).
pub(crate) fn run_interruptible<T: Send + 'static>(
    py: Python<'_>,
    cancel: &Arc<AtomicBool>,
    wait_after_interrupt: bool,
    work: impl FnOnce() -> caustica::Result<T> + Send + 'static,
) -> PyResult<T> {
    let (tx, rx) = mpsc::channel();
    std::thread::Builder::new()
        .name("caustica".into())
        .spawn(move || {
            let _ = tx.send(catch_unwind(AssertUnwindSafe(work)));
        })
        .map_err(|e| InternalError::new_err(format!("cannot start a thread: {e}")))?;
    wait(py, cancel, rx, wait_after_interrupt)
}

/// Waits for a worker's answer with the GIL released, checking for signals between short
/// waits. On Ctrl-C (or any exception a signal handler raises) it sets `cancel` and, when
/// `wait_after_interrupt`, waits for the worker to stop before raising, so nothing of the
/// cancelled work runs on afterwards.
pub(crate) fn wait<T: Send>(
    py: Python<'_>,
    cancel: &AtomicBool,
    mut rx: Receiver<Outcome<T>>,
    wait_after_interrupt: bool,
) -> PyResult<T> {
    loop {
        // The receiver moves into the GIL-free closure and back: it is not shareable.
        let (answer, back) = py.detach(move || (rx.recv_timeout(SIGNAL_POLL), rx));
        rx = back;
        match answer {
            Ok(Ok(result)) => return result.map_err(|e| to_py(py, e)),
            Ok(Err(panic)) => return Err(internal(panic)),
            Err(RecvTimeoutError::Disconnected) => {
                return Err(InternalError::new_err("the worker thread ended without an answer"))
            }
            Err(RecvTimeoutError::Timeout) => {
                if let Err(interrupt) = py.check_signals() {
                    cancel.store(true, Ordering::SeqCst);
                    if wait_after_interrupt {
                        let _ = py.detach(move || rx.recv());
                    }
                    return Err(interrupt);
                }
            }
        }
    }
}

/// A caught panic as a Python exception.
fn internal(panic: Box<dyn Any + Send>) -> PyErr {
    let message = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".into());
    InternalError::new_err(format!("internal error in caustica (please report it): {message}"))
}

/// The library's error as the Python exception that fits it.
pub(crate) fn to_py(py: Python<'_>, error: Error) -> PyErr {
    match error {
        Error::Scene { .. } => {
            let d = Diagnostic::new(&error);
            let Some(at) = &d.excerpt else {
                return SceneError::new_err(d.headline());
            };
            let mut message = d.headline();
            if let Some(help) = &d.help {
                message.push_str(&format!("\nhelp: {help}"));
            }
            let err = SceneError::new_err(message);
            let value = err.value(py);
            let _ = value.setattr("path", d.path.clone());
            let _ = value.setattr("line", at.line);
            let _ = value.setattr("column", at.column);
            let _ = value.setattr("reason", d.message.clone());
            let _ = value.setattr("help", d.help.clone());
            // The line around the place, a window of it if it is long, with a caret under it.
            let _ = value.setattr("excerpt", at.render());
            err
        }
        Error::InvalidSettings(message) => PyValueError::new_err(python_names(&message)),
        Error::Io { path, source } => match source.raw_os_error() {
            // OSError(errno, strerror, filename) becomes FileNotFoundError and its kin.
            Some(code) => {
                let text = source.to_string();
                let reason = text.split(" (os error").next().unwrap_or(&text).to_string();
                PyOSError::new_err((code, reason, path.display().to_string()))
            }
            None => PyOSError::new_err(format!("{}: {source}", path.display())),
        },
        error @ Error::Image { .. } => PyOSError::new_err(error.to_string()),
        Error::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
    }
}

/// The library names options as the command line spells them (`--cone-filter`); Python users
/// know them as keywords (`cone_filter`).
fn python_names(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(i) = rest.find("--") {
        out.push_str(&rest[..i]);
        let after = &rest[i + 2..];
        let name_len = after
            .find(|c: char| !(c.is_ascii_lowercase() || c == '-'))
            .unwrap_or(after.len());
        if name_len == 0 {
            out.push_str("--");
        } else {
            out.push_str(&after[..name_len].replace('-', "_"));
        }
        rest = &after[name_len..];
    }
    out.push_str(rest);
    out
}

/// For the tests: a panic on a worker thread, which must come back as `InternalError`.
#[pyfunction]
fn _panic_on_worker(py: Python<'_>) -> PyResult<()> {
    let cancel = Arc::new(AtomicBool::new(false));
    run_interruptible(py, &cancel, true, || -> caustica::Result<()> {
        panic!("a deliberate panic for the tests")
    })
}

/// The native module of the `caustica` package.
#[pymodule]
fn _caustica(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add_class::<scene::PyScene>()?;
    m.add_class::<progressive::Progressive>()?;
    m.add_class::<photons::Photons>()?;
    m.add_function(wrap_pyfunction!(scene::render, m)?)?;
    m.add_function(wrap_pyfunction!(progressive::progressive, m)?)?;
    m.add_function(wrap_pyfunction!(progressive::merge, m)?)?;
    m.add_function(wrap_pyfunction!(photons::photons, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_on_worker, m)?)?;
    Ok(())
}
