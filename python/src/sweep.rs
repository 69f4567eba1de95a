//! `rtid.sweep`: the sweep `rtid sweep` runs — design, rows streamed to a CSV, the
//! complete file read back, the indices — with the design and outputs as arrays.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{bad_argument, rtid_error, with_context};
use crate::interruptible;
use crate::params::{matrix, PyParams};
use rtid::sweep as sw;
use rtid::sweep::{Method, Output, RunOptions, Sweep, TestLength};

/// The design's options (`rtid sweep`'s flags).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct Options {
    vary: Vec<String>,
    outputs: Vec<String>,
    method: String,
    samples: usize,
    bootstrap: usize,
    trajectories: usize,
    levels: usize,
    step: f64,
    seed: u64,
    tests: String,
}

/// Runs (or with `resume` continues) the sweep into the CSV `out` and returns its
/// arrays and indices, on a thread of its own while this one waits with the GIL
/// released; `progress(done, total)`, if given, is called as rows are computed (an
/// exception from it stops the sweep and is raised). Ctrl-C stops it: the
/// `KeyboardInterrupt` carries the rows done as `partial`.
#[pyfunction]
#[pyo3(signature = (params, options, out, progress=None, resume=false))]
pub fn sweep<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    options: Options,
    out: PathBuf,
    progress: Option<Py<PyAny>>,
    resume: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let base = params.inner.clone();
    drop(params);
    let s = build(base, &options)?;
    let design = interruptible::simple(py, || s.design())?.map_err(|e| rtid_error(&e))?;
    let total = design.values.nrows();
    let done = AtomicUsize::new(0);
    let on_row = || {
        done.fetch_add(1, Ordering::Relaxed);
    };
    let finished = interruptible::run(
        py,
        &interruptible::request_stop,
        || -> PyResult<_> {
            let opts = RunOptions {
                overwrite: !resume,
                resume,
                on_row: &on_row,
                ..RunOptions::default()
            };
            let report = sw::run(&s, &out, &opts).map_err(|e| rtid_error(&e))?;
            if !report.complete {
                // Stopped: the rows written so far, no indices.
                let (file, _) = sw::stream::read(&out).map_err(|e| rtid_error(&e))?;
                return Ok((file.rows, None));
            }
            let (_, rows) =
                sw::load_complete(std::slice::from_ref(&out)).map_err(|e| rtid_error(&e))?;
            let indices = sw::analysis::analyse(&s, &rows).map_err(|e| rtid_error(&e))?;
            let json = rtid::io::json::pretty(&indices).map_err(|e| rtid_error(&e))?;
            Ok((rows, Some(json)))
        },
        interruptible::progress(&progress, || (done.load(Ordering::Relaxed), total)),
    )?;
    let (rows, indices) = finished.or_interrupted(py, |value| {
        Ok(match value {
            Ok((rows, _)) => Some(result(py, &s, &design, &rows, None)?.into_any().unbind()),
            Err(_) => None,
        })
    })??;
    result(py, &s, &design, &rows, indices)
}

/// The sweep's arrays: the design points of `rows` (all of them, or those done
/// before a stop) with their outputs, and the indices' JSON where there are any.
fn result<'py>(
    py: Python<'py>,
    s: &Sweep,
    design: &rtid::sweep::Design,
    rows: &BTreeMap<usize, Vec<String>>,
    indices: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let y = sw::output_matrix(s, rows);
    let points: Vec<Vec<f64>> = rows
        .keys()
        .map(|&i| design.values.row(i).to_vec())
        .collect();
    let result = PyDict::new(py);
    result.set_item(
        "factors",
        s.factors.iter().map(|f| f.name.clone()).collect::<Vec<_>>(),
    )?;
    result.set_item("design", matrix(py, &points, s.factors.len())?)?;
    let columns = s.output_columns();
    let outputs: Vec<Vec<f64>> = y.rows().into_iter().map(|r| r.to_vec()).collect();
    result.set_item("outputs", matrix(py, &outputs, columns.len())?)?;
    result.set_item("output_columns", columns)?;
    result.set_item(
        "index",
        PyArray1::from_vec(py, rows.keys().map(|&i| i as u64).collect()),
    )?;
    result.set_item("indices_json", indices.unwrap_or_else(|| "{}".into()))?;
    Ok(result)
}

/// The sweep, checked as `rtid sweep` checks its options.
fn build(params: rtid::Params, o: &Options) -> PyResult<Sweep> {
    if o.vary.is_empty() {
        return Err(bad_argument(
            "vary",
            "no parameter to vary: give e.g. vary=[\"Kw=1e5..1e6:log:20\"]",
        ));
    }
    let factors = sw::spec::parse_all(&o.vary, &params).map_err(|e| with_context("vary", &e))?;
    if o.outputs.is_empty() {
        return Err(bad_argument(
            "outputs",
            format!(
                "no output: give e.g. outputs=[\"resonances\"] (all: {})",
                sw::outputs::ALL.map(Output::name).join(",")
            ),
        ));
    }
    let mut outputs = Vec::new();
    for name in &o.outputs {
        let output: Output = name.parse().map_err(|e| with_context("outputs", &e))?;
        if !outputs.contains(&output) {
            outputs.push(output);
        }
    }
    let method = match o.method.as_str() {
        "grid" => Method::Grid,
        "local" => Method::Local { step: o.step },
        "morris" => Method::Morris {
            trajectories: o.trajectories,
            levels: o.levels,
        },
        "sobol" => Method::Sobol {
            samples: o.samples,
            bootstrap: o.bootstrap,
        },
        other => {
            return Err(bad_argument(
                "method",
                format!("unknown method `{other}`: expected grid, local, morris or sobol"),
            ))
        }
    };
    let tests: TestLength = o.tests.parse().map_err(|e| with_context("tests", &e))?;
    Sweep::new(params, factors, method, outputs, tests, o.seed).map_err(|e| rtid_error(&e))
}
