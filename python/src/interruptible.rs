//! Long calls, interruptible: the work runs on a thread of its own while the calling
//! thread waits with the GIL released and looks for signals every [`POLL`]
//! (Ctrl-C, a notebook's ■). A signal — or a `KeyboardInterrupt` raised inside the
//! caller's progress function — stops the work through `stop` (for most calls the
//! library's stop request, `rtid::interrupt`, which the simulations check every few
//! thousand steps) and is raised once the work has returned, so that a caller keeps
//! what was finished. A panic of the work is an `RtidError`, never a
//! `PanicException`.

use std::time::Duration;

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;

use crate::errors::RtidError;

/// How often the waiting thread looks for signals and reports progress.
pub const POLL: Duration = Duration::from_millis(20);

/// What a long call returned, and the signal that stopped it if one did.
pub struct Finished<T> {
    /// The work's own result (an error or a partial result if it was stopped).
    pub value: T,
    /// The exception of the signal (a `KeyboardInterrupt`) that stopped the work.
    pub interrupted: Option<PyErr>,
}

impl<T> Finished<T> {
    /// The value, or the signal's exception with `partial` (if any) as its `partial`
    /// attribute, for the package to turn into its result object.
    pub fn or_interrupted(
        self,
        py: Python<'_>,
        partial: impl FnOnce(T) -> PyResult<Option<Py<PyAny>>>,
    ) -> PyResult<T> {
        let Some(signal) = self.interrupted else {
            return Ok(self.value);
        };
        if let Some(p) = partial(self.value)? {
            signal.value(py).setattr("partial", p)?;
        }
        Err(signal)
    }
}

/// Runs `work` on a thread of its own; `tick` is called on this thread every [`POLL`]
/// with the GIL held (progress; once more at the end), `stop` when a signal arrives.
/// An exception from `tick` other than `KeyboardInterrupt` stops the work too and is
/// raised.
pub fn run<T: Send>(
    py: Python<'_>,
    stop: &(dyn Fn() + Sync),
    work: impl FnOnce() -> T + Send,
    mut tick: impl FnMut(Python<'_>) -> PyResult<()>,
) -> PyResult<Finished<T>> {
    let _scope = rtid::interrupt::enter();
    let mut interrupted: Option<PyErr> = None;
    let mut failed: Option<PyErr> = None;
    let joined = std::thread::scope(|s| {
        let worker = s.spawn(work);
        loop {
            let finished = worker.is_finished();
            if !finished {
                py.detach(|| std::thread::sleep(POLL));
            }
            if interrupted.is_none() {
                if let Err(e) = py.check_signals() {
                    stop();
                    interrupted = Some(e);
                }
            }
            if interrupted.is_none() && failed.is_none() {
                if let Err(e) = tick(py) {
                    stop();
                    if e.is_instance_of::<PyKeyboardInterrupt>(py) {
                        interrupted = Some(e);
                    } else {
                        failed = Some(e);
                    }
                }
            }
            if finished {
                break;
            }
        }
        worker.join()
    });
    if let Some(e) = failed {
        return Err(e);
    }
    if interrupted.is_none() && rtid::interrupt::requested() {
        // Another thread's call was interrupted: the request stops every call.
        interrupted = Some(PyKeyboardInterrupt::new_err(
            "stopped by an interrupt of another rtid call in this process",
        ));
    }
    match joined {
        Ok(value) => Ok(Finished { value, interrupted }),
        Err(panic) => Err(interrupted.unwrap_or_else(|| panicked(&panic))),
    }
}

/// A panic of the work as an `RtidError` (a bug of rtid's: its message and a plea).
fn panicked(payload: &Box<dyn std::any::Any + Send>) -> PyErr {
    let text = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "no message".into());
    RtidError::new_err(format!(
        "internal error of rtid ({text}): please report it with the call that caused it"
    ))
}

/// `stop` for calls whose work checks the library's stop request.
pub fn request_stop() {
    rtid::interrupt::request();
}

/// Runs `work` as [`run`] does, without progress, stopped by the library's stop
/// request: its value, or the signal's exception.
pub fn simple<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    run(py, &request_stop, work, |_| Ok(()))?.or_interrupted(py, |_| Ok(None))
}

/// A `tick` for [`run`] that calls `progress` (if given) with `counts()` each time they
/// change — and once more at the end, where a bar ends.
pub fn progress<'a, T>(
    progress: &'a Option<Py<PyAny>>,
    counts: impl Fn() -> T + 'a,
) -> impl FnMut(Python<'_>) -> PyResult<()> + 'a
where
    T: PartialEq + Clone + for<'py> pyo3::call::PyCallArgs<'py> + 'a,
{
    let mut shown: Option<T> = None;
    move |py| {
        let Some(callback) = progress else {
            return Ok(());
        };
        let now = counts();
        if shown.as_ref() == Some(&now) {
            return Ok(());
        }
        shown = Some(now.clone());
        callback.call1(py, now).map(drop)
    }
}
