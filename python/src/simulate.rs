//! `rtid.simulate`: the run `rtid simulate` makes, its every column as a numpy array.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{bad_argument, rtid_error, with_context};
use crate::interruptible;
use crate::params::PyParams;
use rtid::input::{Move, Samples, Trajectory};
use rtid::input_spec::{self, InputSpec};
use rtid::io::torque_file;
use rtid::model::{Params, NSTATE};
use rtid::recorder::Recorder;
use rtid::sim::{SimError, Simulation, STATE_NAMES};

/// Every `every`-th sample, column by column: time, torque, the states, the reference.
struct Columns {
    every: u64,
    count: u64,
    columns: Vec<Vec<f64>>,
    reference: Option<Move>,
}

impl Recorder for Columns {
    fn record(&mut self, t: f64, y: &[f64; NSTATE], motor_torque: f64) {
        let keep = self.count % self.every == 0;
        self.count += 1;
        if !keep {
            return;
        }
        self.columns[0].push(t);
        self.columns[1].push(motor_torque);
        for (c, v) in self.columns[2..2 + NSTATE].iter_mut().zip(y) {
            c.push(*v);
        }
        if let Some(m) = &self.reference {
            self.columns[2 + NSTATE].push(m.angle(t));
        }
    }
}

/// What drives the run: a parsed specification, or recorded torques.
enum Drive {
    Spec(InputSpec),
    Torques(Vec<f64>, Vec<f64>),
}

/// Runs `duration_s` of `input` on `params` and returns the CLI's CSV columns.
#[pyfunction]
#[pyo3(signature = (params, duration_s, input=None, torque=None, time_s=None, dt_s=None, sample_s=1e-4, load_nm=0.0))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    params: PyRef<'_, PyParams>,
    duration_s: f64,
    input: Option<&str>,
    torque: Option<PyReadonlyArray1<'py, f64>>,
    time_s: Option<PyReadonlyArray1<'py, f64>>,
    dt_s: Option<f64>,
    sample_s: f64,
    load_nm: f64,
) -> PyResult<Bound<'py, PyDict>> {
    check_numbers(duration_s, sample_s, dt_s, load_nm)?;
    let drive = match (input, torque, time_s) {
        (Some(spec), None, None) => spec_drive(spec)?,
        (None, Some(q), Some(t)) => recorded(t.as_slice()?, q.as_slice()?)?,
        _ => {
            return Err(bad_argument(
                "input",
                "give a specification or torque with time_s",
            ))
        }
    };
    let p = params.inner.clone();
    // Not borrowed while the GIL is released: another thread may change the set.
    drop(params);
    let mut sim = match dt_s {
        Some(dt) => Simulation::new(&p, dt).map_err(|e| with_context("dt_s", &e))?,
        None => Simulation::with_default_step(&p).map_err(|e| rtid_error(&e))?,
    };
    sim.set_load(load_nm);
    let steps = duration_s / sim.dt();
    let every = ((sample_s / sim.dt()).round() as u64).max(1);
    check_work(steps, every)?;
    let rows = (steps / every as f64) as usize + 2;
    let closed = matches!(drive, Drive::Spec(InputSpec::Move { .. }));
    let mut rec = Columns {
        every,
        count: 0,
        columns: vec![Vec::with_capacity(rows); 2 + NSTATE + usize::from(closed)],
        reference: None,
    };
    let done = interruptible::run(
        py,
        &interruptible::request_stop,
        || run(&mut sim, &p, drive, duration_s, &mut rec),
        |_| Ok(()),
    )?;
    let stopped = done.interrupted.is_some();
    let outcome =
        done.or_interrupted(py, |_| Ok(Some(columns(py, &mut rec)?.into_any().unbind())))?;
    if !stopped {
        outcome.map_err(|e| with_context("the run of input", &e))?;
    }
    columns(py, &mut rec)
}

/// The recorded columns by the CSV's names (those of a run stopped early: up to
/// where it stopped).
fn columns<'py>(py: Python<'py>, rec: &mut Columns) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let mut names = vec!["time_s", "motor_torque_nm"];
    names.extend(STATE_NAMES);
    names.push("reference_rad");
    for (name, column) in names.into_iter().zip(std::mem::take(&mut rec.columns)) {
        out.set_item(name, PyArray1::from_vec(py, column))?;
    }
    Ok(out)
}

/// The command line's checks of the numeric options.
fn check_numbers(duration_s: f64, sample_s: f64, dt_s: Option<f64>, load_nm: f64) -> PyResult<()> {
    if !(duration_s > 0.0 && duration_s.is_finite()) {
        return Err(bad_argument(
            "duration_s",
            format!("{duration_s}: must be a positive number of seconds"),
        ));
    }
    if !(sample_s > 0.0 && sample_s.is_finite()) {
        return Err(bad_argument(
            "sample_s",
            format!("{sample_s}: must be a positive number of seconds"),
        ));
    }
    if let Some(dt) = dt_s.filter(|dt| !(*dt > 0.0 && dt.is_finite())) {
        return Err(bad_argument(
            "dt_s",
            format!("{dt}: must be a positive number of seconds"),
        ));
    }
    if !load_nm.is_finite() {
        return Err(bad_argument(
            "load_nm",
            format!("{load_nm}: must be a finite torque in N·m"),
        ));
    }
    Ok(())
}

/// The command line's limits on the work (`RTID_ALLOW_LARGE=1` lifts them).
fn check_work(steps: f64, every: u64) -> PyResult<()> {
    use rtid::limits::{work, MAX_ROWS, MAX_STEPS};
    work(
        steps,
        MAX_STEPS,
        "integration steps",
        "duration_s over dt_s (or the default step)",
    )
    .and_then(|()| {
        work(
            steps / every as f64,
            MAX_ROWS,
            "samples",
            "duration_s over sample_s",
        )
    })
    .map_err(|e| rtid_error(&e))
}

/// A specification, a `file:` one read as the command line reads it.
fn spec_drive(spec: &str) -> PyResult<Drive> {
    let parsed = input_spec::parse(spec).map_err(|e| bad_argument("input", e))?;
    Ok(match parsed {
        InputSpec::File(path) => {
            let (t, q) = torque_file::read(&path).map_err(|e| with_context("input", &e))?;
            Drive::Torques(t, q)
        }
        other => Drive::Spec(other),
    })
}

/// Recorded torques at strictly increasing times, as a torque file must give them.
fn recorded(time: &[f64], torque: &[f64]) -> PyResult<Drive> {
    if time.is_empty() {
        return Err(bad_argument("time_s", "no samples"));
    }
    if time.len() != torque.len() {
        return Err(bad_argument(
            "torque",
            format!(
                "{} values for {} times in time_s: give one torque per time",
                torque.len(),
                time.len()
            ),
        ));
    }
    if let Some(i) = torque.iter().position(|v| !v.is_finite()) {
        return Err(bad_argument(
            "torque",
            format!("[{i}] = {}: not a finite number", torque[i]),
        ));
    }
    if let Some(i) = time.iter().position(|v| !v.is_finite()) {
        return Err(bad_argument(
            "time_s",
            format!("[{i}] = {}: not a finite number", time[i]),
        ));
    }
    if let Some(i) = time.windows(2).position(|w| w[1] <= w[0]) {
        return Err(bad_argument(
            "time_s",
            format!(
                "[{}] = {} does not increase (previous {})",
                i + 1,
                time[i + 1],
                time[i]
            ),
        ));
    }
    Ok(Drive::Torques(time.to_vec(), torque.to_vec()))
}

/// The run, as `rtid simulate` drives it (a move's reference recorded beside the
/// states).
fn run(
    sim: &mut Simulation,
    p: &Params,
    drive: Drive,
    duration: f64,
    rec: &mut Columns,
) -> Result<(), SimError> {
    match drive {
        Drive::Torques(t, q) => {
            InputSpec::None.run(sim, p, Some(Samples::new(t, q)), duration, rec)
        }
        Drive::Spec(spec) => {
            rec.reference = spec.reference();
            spec.run(sim, p, None, duration, rec)
        }
    }
}
