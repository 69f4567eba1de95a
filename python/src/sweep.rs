//! `rtid.sweep`: the sweep `rtid sweep` runs — design, rows streamed to a CSV, the
//! complete file read back, the indices — with the design and outputs as arrays.

use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{bad_argument, rtid_error, with_context};
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

/// Runs the sweep into the CSV `out` and returns its arrays and indices, on a
/// thread of its own while this one waits with the GIL released; `progress(done,
/// total)`, if given, is called as rows are computed (an exception from it is raised
/// once the sweep ends).
#[pyfunction]
#[pyo3(signature = (params, options, out, progress=None))]
pub fn sweep<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    options: Options,
    out: PathBuf,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let base = params.inner.clone();
    drop(params);
    let s = build(base, &options)?;
    let design = py.detach(|| s.design()).map_err(|e| rtid_error(&e))?;
    let total = design.values.nrows();
    let done = AtomicUsize::new(0);
    let on_row = || {
        done.fetch_add(1, Ordering::Relaxed);
    };
    let mut failed = None;
    let mut shown = None;
    let outcome = std::thread::scope(|scope| {
        let run = scope.spawn(|| -> PyResult<_> {
            let opts = RunOptions {
                overwrite: true,
                on_row: &on_row,
                ..RunOptions::default()
            };
            sw::run(&s, &out, &opts).map_err(|e| rtid_error(&e))?;
            let (_, rows) =
                sw::load_complete(std::slice::from_ref(&out)).map_err(|e| rtid_error(&e))?;
            let indices = sw::analysis::analyse(&s, &rows).map_err(|e| rtid_error(&e))?;
            Ok((rows, indices))
        });
        loop {
            let finished = run.is_finished();
            if !finished {
                py.detach(|| std::thread::sleep(Duration::from_millis(20)));
            }
            // Once more when finished: a bar ends at the end.
            let now = done.load(Ordering::Relaxed);
            if let (Some(callback), None) = (&progress, &failed) {
                if shown != Some(now) {
                    shown = Some(now);
                    failed = callback.call1(py, (now, total)).err();
                }
            }
            if finished {
                break;
            }
        }
        run.join()
    });
    if let Some(e) = failed {
        return Err(e);
    }
    let (rows, indices) = match outcome {
        Ok(r) => r?,
        Err(_) => return Err(bad_argument("sweep", "the sweep panicked")),
    };
    let y = sw::output_matrix(&s, &rows);
    let rows_of = |a: &rtid::sweep::Design| -> Vec<Vec<f64>> {
        a.values.rows().into_iter().map(|r| r.to_vec()).collect()
    };
    let result = PyDict::new(py);
    result.set_item(
        "factors",
        s.factors.iter().map(|f| f.name.clone()).collect::<Vec<_>>(),
    )?;
    result.set_item("design", matrix(py, &rows_of(&design), s.factors.len())?)?;
    let columns = s.output_columns();
    let outputs: Vec<Vec<f64>> = y.rows().into_iter().map(|r| r.to_vec()).collect();
    result.set_item("outputs", matrix(py, &outputs, columns.len())?)?;
    result.set_item("output_columns", columns)?;
    result.set_item(
        "index",
        PyArray1::from_vec(py, rows.keys().map(|&i| i as u64).collect()),
    )?;
    result.set_item(
        "indices_json",
        rtid::io::json::pretty(&indices).map_err(|e| rtid_error(&e))?,
    )?;
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
