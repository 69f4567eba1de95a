//! `rtid.run_experiment`: the virtual tests `rtid experiment KIND` runs on the model,
//! written as the command line writes them — the same manifest and CSV, numbers to
//! the bit. The settings arrive checked by the wrapper (`rtid/_experiments.py`), named
//! as the flags are, with every default filled in; each test's own checks (the
//! command line's, the work limits among them) run here before any work, and the
//! work runs interruptibly (Ctrl-C: `KeyboardInterrupt`).

mod friction_map;
mod paper;
mod positioning;
mod servo_trace;
mod time_record;

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{bad_argument, rtid_error, with_context};
use crate::interruptible;
use crate::params::PyParams;
use rtid::io::experiment_file::{Data, Manifest};
use rtid::model::{LoopMode, Params};

/// A test's run, its settings checked: the manifest and data it writes.
pub type Work = Box<dyn FnOnce() -> PyResult<(Manifest, Data)> + Send>;

/// Runs test `kind` on `params` with `settings` and writes it as `STEM.json` and
/// `STEM.csv` in `out` (`STEM` the kind's name); returns the manifest's path.
#[pyfunction]
pub fn run_experiment(
    py: Python<'_>,
    kind: &str,
    params: PyRef<'_, PyParams>,
    settings: &Bound<'_, PyDict>,
    out: PathBuf,
) -> PyResult<PathBuf> {
    let p = params.inner.clone();
    drop(params);
    let s = Settings(settings);
    let work = match kind {
        "frequency_response" => paper::frequency_response(&s, &p)?,
        "torque_curve" => paper::torque(&s, &p)?,
        "fluctuation" | "unbalance" => paper::turning(&s, &p, kind == "unbalance")?,
        "positioning" => positioning::prepare(&s, &p)?,
        "friction_map" => friction_map::prepare(&s, &p)?,
        "servo_trace" => servo_trace::prepare(&s, &p)?,
        "frequency_response_time" => time_record::prepare(&s, &p)?,
        other => return Err(bad_argument("kind", format!("unknown test `{other}`"))),
    };
    let (manifest, data) = interruptible::simple(py, work)??;
    write(&out, kind, manifest, &data)
}

/// The settings dict, read by name.
pub struct Settings<'a, 'py>(&'a Bound<'py, PyDict>);

impl Settings<'_, '_> {
    pub fn get<T: for<'py> FromPyObjectOwned<'py>>(&self, name: &str) -> PyResult<T> {
        match self.0.get_item(name)? {
            Some(v) => v.extract::<T>().map_err(|e| {
                let e: PyErr = e.into();
                bad_argument(name, e)
            }),
            None => Err(bad_argument(name, "missing setting")),
        }
    }
}

/// Where the experiment file is written, as `Common::write_and_report` writes it.
fn write(
    out: &std::path::Path,
    stem: &str,
    mut manifest: Manifest,
    data: &Data,
) -> PyResult<PathBuf> {
    let path = out.join(format!("{stem}.json"));
    manifest.data = Some(format!("{stem}.csv"));
    rtid::write_experiment(&path, &manifest, data).map_err(|e| rtid_error(&e))?;
    Ok(path)
}

/// The command line's work limit (`rtid::limits::work`) on `amount` of `what`, asked
/// for by the settings `options`.
pub fn limit(amount: f64, limit: f64, what: &str, options: &str) -> PyResult<()> {
    rtid::limits::work(amount, limit, what, options).map_err(|e| rtid_error(&e))
}

/// `manifest` with `note` appended to its notes.
pub fn add_note(manifest: &mut Manifest, note: Option<String>) {
    if let Some(note) = note {
        manifest.notes = Some(match manifest.notes.take() {
            Some(notes) => format!("{notes}; {note}"),
            None => note,
        });
    }
}

/// The loop a test runs in where `loop` overrides the set's, with the note the
/// command line adds to the manifest.
pub fn loop_note(given: Option<LoopMode>, p: &Params) -> Option<String> {
    let own = p.controller.loop_mode;
    let mode = given.filter(|&m| m != own)?;
    Some(format!(
        "--loop {mode} overrides the parameter set's controller.loop ({own})"
    ))
}

pub fn loop_mode(s: &Settings, name: &str) -> PyResult<Option<LoopMode>> {
    let given: Option<String> = s.get(name)?;
    given
        .map(|text| text.parse().map_err(|e| with_context(name, &e)))
        .transpose()
}
