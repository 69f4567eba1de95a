//! `rtid.compensate` and the compensation's forms: the backlash and error table of
//! an ISO 230-2 record (or a model's own virtual test), checked on the runs it was
//! not built from, with a friction compensation from a map or the model — the calls
//! `rtid compensate` makes, so the numbers are its own — and the file, the SINUMERIK
//! program and the CSV of it.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;

use crate::errors::{bad_argument, rtid_error, with_context};
use crate::interruptible;
use crate::params::PyParams;
use rtid::experiments::friction_map::compensation as friction;
use rtid::experiments::positioning::compensate::{self as building, Runs};
use rtid::experiments::positioning::iso230::{Measurement, ReportUnits};
use rtid::experiments::positioning::{self, PositioningTest};
use rtid::io::compensation_file::{self, sinumerik, table_csv as csv, CompensationFile, Source};
use rtid::io::experiment_file::Experiment;
use rtid::model::Axis;

/// Where a compensation comes from: a record's file, or a model.
#[derive(FromPyObject)]
pub enum Origin {
    /// A positioning record: its manifest and the name it goes by.
    Record(PathBuf, String),
    /// A model (an identified one: `fit.params`), whose standard cycle is run.
    Model(Py<PyParams>),
}

/// The compensation of `origin` built from `runs` (all: `None`), with the friction
/// law of the friction map `friction_map` (a manifest path and its name) or of the
/// model (`friction`); returns `rtid compensate --json`'s JSON and the
/// compensation.json text.
#[pyfunction]
#[pyo3(signature = (origin, runs=None, friction_map=None, friction=false))]
pub fn compensate(
    py: Python<'_>,
    origin: Origin,
    runs: Option<String>,
    friction_map: Option<(PathBuf, String)>,
    friction: bool,
) -> PyResult<(String, String)> {
    let runs: Option<Runs> = runs
        .map(|r| r.parse().map_err(|e| bad_argument("runs", e)))
        .transpose()?;
    let (name, measurements, axis, model) = match origin {
        Origin::Record(path, name) => {
            let exp = rtid::read_experiment(&path).map_err(|e| with_context("record", &e))?;
            let (m, axis) = record(&exp, &name)?;
            (name, m, axis, None)
        }
        Origin::Model(p) => {
            let p = p.borrow(py).inner.clone();
            let test = PositioningTest::standard(p.axis);
            let run = || positioning::run(&p, &test, |_, _| {});
            let m = interruptible::simple(py, run)?.map_err(|e| rtid_error(&e))?;
            (p.name.clone(), m, p.axis, Some(p))
        }
    };
    if friction && model.is_none() {
        return Err(bad_argument(
            "friction",
            "the model's friction law needs a model (params), not a record: give friction_map= for a record",
        ));
    }
    let mut computed = building::compute(&measurements, axis, runs.as_ref())
        .map_err(|e| with_context(&name, &e))?;
    if let Some((path, map_name)) = &friction_map {
        let exp = rtid::read_experiment(path).map_err(|e| with_context("friction_map", &e))?;
        let law = friction::of_experiment(&exp, axis)
            .map_err(|e| with_context(&format!("friction_map {map_name}"), &e))?;
        computed.compensation.friction = Some(law);
    }
    if let Some(p) = model.as_ref().filter(|_| friction) {
        let law = friction::of_model(p)
            .map_err(|e| with_context(&format!("friction: the steady map of {name}"), &e))?;
        computed.compensation.friction = Some(law);
    }
    let summary = rtid::report::compensation::compensation(&name, &computed, None)
        .map_err(|e| rtid_error(&e))?;
    let file = CompensationFile {
        axis,
        compensation: computed.compensation.clone(),
        source: std::iter::once(Source {
            file: name,
            runs: runs.as_ref().map(Runs::to_string),
            model: model
                .as_ref()
                .map(|_| compensation_file::MODEL_SOURCE.to_string()),
        })
        .chain(friction_map.map(|(_, n)| Source {
            file: n,
            runs: None,
            model: None,
        }))
        .collect(),
    };
    let text = compensation_file::to_text(&file).map_err(|e| rtid_error(&e))?;
    let json = rtid::io::json::pretty(&summary).map_err(|e| rtid_error(&e))?;
    Ok((json, text))
}

/// The measurements (SI) and the axis of a positioning record.
fn record(exp: &Experiment, name: &str) -> PyResult<(Vec<Measurement>, Axis)> {
    let Some(m) = positioning::from_data(&exp.data) else {
        return Err(bad_argument(
            "record",
            format!(
                "{name}: a `{}` experiment, not a positioning record",
                exp.manifest.kind.name()
            ),
        ));
    };
    Ok((m, exp.data.axis().unwrap_or_default()))
}

/// A compensation.json text, checked.
fn parse(text: &str) -> PyResult<CompensationFile> {
    compensation_file::parse(text, Path::new("the compensation"))
        .map_err(|e| with_context("compensation", &e))
}

/// The SINUMERIK EEC program of a compensation for machine axis `axis_number`, zero
/// at `reference` (rad or m; default the table's first point), with `note` in its
/// header; and the reference and shift (SI).
#[pyfunction]
#[pyo3(signature = (text, axis_number, reference=None, note=String::new()))]
pub fn sinumerik_program(
    text: &str,
    axis_number: u32,
    reference: Option<f64>,
    note: String,
) -> PyResult<(String, f64, f64)> {
    let file = parse(text)?;
    let grid = sinumerik::Grid::of(table_of(&file)?).map_err(|e| rtid_error(&e))?;
    let (start, end) = (grid.start, grid.end());
    let zeroed = grid
        .zeroed_at(reference.unwrap_or(start))
        .map_err(|e| match e {
            sinumerik::SinumerikError::ReferenceOutside { .. } => {
                let u = ReportUnits::of(file.axis);
                let k = u.target_per_si;
                bad_argument(
                    "reference",
                    format!(
                        "{}: outside the SINUMERIK table, which runs from {:.3} to {:.3} {}",
                        reference.unwrap_or(start) * k,
                        start * k,
                        end * k,
                        u.target_key
                    ),
                )
            }
            other => rtid_error(&other),
        })?;
    let (grid, reference) = zeroed;
    let program = sinumerik::program(
        &grid,
        &reference,
        file.axis,
        axis_number,
        file.compensation.backlash,
        &note,
    );
    Ok((program, reference.position, reference.shift))
}

/// The error table of a compensation as CSV (`rtid compensate --csv`).
#[pyfunction]
pub fn table_csv(text: &str) -> PyResult<String> {
    let file = parse(text)?;
    let table = table_of(&file)?;
    Ok(csv::text(table, file.axis, file.compensation.backlash))
}

/// The compensation's error table.
fn table_of(file: &CompensationFile) -> PyResult<&rtid::controller::ErrorTable> {
    file.compensation
        .table
        .as_ref()
        .ok_or_else(|| bad_argument("compensation", "it has no error table"))
}

/// The ISO 230-2 values of runs `runs` of a positioning record as the axis
/// compensated by `text` would show them (`rtid evaluate --compensation --json`).
pub fn evaluate_compensated(
    exp: &Experiment,
    source: &str,
    text: &str,
    runs: Option<&str>,
) -> PyResult<serde_json::Value> {
    let (all, axis) = record(exp, source)?;
    let file = parse(text)?;
    file.check_axis(Path::new("the compensation"), axis)
        .map_err(|e| with_context("compensation", &e))?;
    let runs: Option<Runs> = runs
        .map(|r| r.parse().map_err(|e| bad_argument("runs", e)))
        .transpose()?;
    let measurements = building::select(&all, runs.as_ref());
    if measurements.is_empty() {
        return Err(bad_argument(
            "runs",
            format!(
                "{source}: no measurement of runs {} (its runs: {:?})",
                runs.map_or(String::new(), |r| r.to_string()),
                building::run_numbers(&all)
            ),
        ));
    }
    let b = building::before_after(&measurements, &file.compensation)
        .map_err(|e| with_context(source, &e))?;
    let used = building::run_numbers(&measurements);
    let value = rtid::report::compensation::compensated(
        source,
        "the compensation",
        &used,
        &b,
        ReportUnits::of(axis),
    );
    value.map_err(|e| rtid_error(&e))
}

/// The ISO 230-2 values of runs `runs` of a positioning record (`rtid evaluate
/// --runs --json`).
pub fn evaluate_runs(exp: &Experiment, source: &str, runs: &str) -> PyResult<serde_json::Value> {
    let (all, axis) = record(exp, source)?;
    let runs: Runs = runs.parse().map_err(|e| bad_argument("runs", e))?;
    let readings = building::select(&all, Some(&runs));
    if readings.is_empty() {
        return Err(bad_argument(
            "runs",
            format!("{source}: no measurement of the runs asked for"),
        ));
    }
    let report = rtid::experiments::positioning::iso230::evaluate(&readings)
        .map_err(|e| with_context(source, &e))?;
    rtid::report::evaluation::positioning(&report, ReportUnits::of(axis), source)
        .map_err(|e| rtid_error(&e))
}
