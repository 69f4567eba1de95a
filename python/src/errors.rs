//! rtid's errors as Python exceptions: `RtidError`, a `ValueError`, with the whole
//! chain of causes in one line (file, line, parameter), as the command line prints it.

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::PyErr;

create_exception!(
    _rtid,
    RtidError,
    PyValueError,
    "An error of rtid (a bad parameter, file or option): its message names what is wrong."
);

/// `e` and its sources, `: `-joined, as an `RtidError`.
pub fn rtid_error(e: &(dyn std::error::Error + 'static)) -> PyErr {
    let mut message = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let text = s.to_string();
        if !message.contains(&text) {
            message.push_str(": ");
            message.push_str(&text);
        }
        source = s.source();
    }
    RtidError::new_err(message)
}

/// An `RtidError` with `context` before `e`'s message (which option or argument).
pub fn with_context(context: &str, e: &(dyn std::error::Error + 'static)) -> PyErr {
    let inner = rtid_error(e);
    RtidError::new_err(format!("{context}: {}", message_of(&inner)))
}

/// A `ValueError` naming the argument.
pub fn bad_argument(argument: &str, message: impl std::fmt::Display) -> PyErr {
    RtidError::new_err(format!("{argument}: {message}"))
}

fn message_of(e: &PyErr) -> String {
    pyo3::Python::attach(|py| e.value(py).to_string())
}
