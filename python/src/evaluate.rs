//! `rtid.evaluate`: the statistics `rtid evaluate --json` prints for an experiment, for
//! the kinds whose evaluation is the library's alone (frequency response, torque
//! curve, servo trace without a model to replay it on).

use std::path::PathBuf;

use pyo3::prelude::*;
use serde_json::{json, Value};

use crate::errors::{bad_argument, rtid_error, with_context};
use crate::params::PyParams;
use rtid::estimation::inverse_dynamics::IdimSettings;
use rtid::experiments::frequency_response as fr;
use rtid::experiments::positioning as pos;
use rtid::experiments::positioning::iso230::{self, ReportUnits};
use rtid::experiments::servo_trace::ServoTrace;
use rtid::experiments::torque_curve::{self, TorqueTest};
use rtid::io::experiment_file::{Data, Experiment, Kind, Response};
use rtid::report::evaluation::{self, TraceReport};

/// The evaluation of the experiment at `path` as JSON, `source` naming it.
#[pyfunction]
#[pyo3(signature = (path, source, params=None))]
pub fn evaluate(
    py: Python<'_>,
    path: PathBuf,
    source: String,
    params: Option<PyRef<'_, PyParams>>,
) -> PyResult<String> {
    let exp = rtid::read_experiment(&path).map_err(|e| with_context("experiment", &e))?;
    let model = params.map(|p| p.inner.clone());
    let value = py.detach(|| match exp.manifest.kind {
        Kind::FrequencyResponse => frequency_response(&exp, &source),
        Kind::TorqueCurve => torque(&exp, &source),
        Kind::ServoTrace => servo_trace(&exp, &source, model.as_ref()),
        Kind::Positioning => positioning(&exp, &source),
        Kind::FrictionMap => friction(&exp, &source),
        Kind::Fluctuation | Kind::Unbalance => fluctuation(&exp, &source),
        other => Err(bad_argument(
            "experiment",
            format!("evaluating a `{}` experiment from Python is not part of this version yet: run `rtid evaluate`", other.name()),
        )),
    })?;
    rtid::io::json::pretty(&value).map_err(|e| rtid_error(&e))
}

/// Reads the experiment at `path` as `rtid` reads it: its kind and number of rows.
#[pyfunction]
pub fn read_experiment(path: PathBuf) -> PyResult<(&'static str, usize)> {
    let exp = rtid::read_experiment(&path).map_err(|e| with_context("experiment", &e))?;
    Ok((exp.manifest.kind.name(), exp.data.len()))
}

/// The resonances of a gain curve.
fn frequency_response(exp: &Experiment, source: &str) -> PyResult<Value> {
    let Data::FrequencyResponse {
        frequency_hz,
        gain_db,
        ..
    } = &exp.data
    else {
        return Err(bad_argument(
            "experiment",
            format!("{source}: not a frequency-response experiment"),
        ));
    };
    let peaks = fr::evaluate(frequency_hz, gain_db).peaks;
    let mut value = json!({
        "kind": "frequency_response",
        "source": source,
        "peaks": rtid::io::json::value(&peaks).map_err(|e| rtid_error(&e))?,
        "points": frequency_hz.len(),
    });
    // With the phase: the modes of the complex response, as the command line adds them.
    if let Some(c) =
        fr::measured::complex_points(exp, |_| true).filter(|c| !c.frequency_hz.is_empty())
    {
        let form = fr::measured::form(exp);
        let integrators = match form.response {
            Response::TableOverMotor => 0,
            Response::MotorCompliance => 2,
            Response::SpeedLoop => 0,
        };
        let found = fr::modal::modes(&c, integrators);
        value["modes"] = rtid::io::json::value(&found.modes).map_err(|e| rtid_error(&e))?;
        value["prominent_peaks"] = found.prominent.into();
        value["response"] = form.response.name().into();
        value["noise_stated"] = (c.sigma_ln.is_some() || c.sigma_phase.is_some()).into();
    }
    Ok(value)
}

/// RMS and peak torque, the reversals and the friction law of a torque curve.
fn torque(exp: &Experiment, source: &str) -> PyResult<Value> {
    let Some(curve) = torque_curve::from_data(&exp.data) else {
        return Err(bad_argument(
            "experiment",
            format!("{source}: not a torque curve"),
        ));
    };
    let test = TorqueTest::from_conditions(&exp.manifest.conditions);
    let report = torque_curve::evaluate(&curve, &test).map_err(|e| with_context(source, &e))?;
    let axis = exp.data.axis().unwrap_or_default();
    evaluation::torque_curve(&report, axis, source).map_err(|e| rtid_error(&e))
}

/// The ISO 230-2 values of a positioning record, in the command line's units
/// (arc-seconds or µm).
fn positioning(exp: &Experiment, source: &str) -> PyResult<Value> {
    let Some(readings) = pos::from_data(&exp.data) else {
        return Err(bad_argument(
            "experiment",
            format!("{source}: not a positioning experiment"),
        ));
    };
    let u = ReportUnits::of(exp.data.axis().unwrap_or_default());
    let report = iso230::evaluate(&readings).map_err(|e| with_context(source, &e))?;
    evaluation::positioning(&report, u, source).map_err(|e| rtid_error(&e))
}

/// The deviation statistics of a fluctuation or unbalance test, in arc-seconds.
fn fluctuation(exp: &Experiment, source: &str) -> PyResult<Value> {
    let e = rtid::fluctuation::evaluate_experiment(exp).map_err(|e| with_context(source, &e))?;
    evaluation::fluctuation(&e, exp.manifest.kind, source).map_err(|e| rtid_error(&e))
}

/// The friction laws fitted to a friction map, and the one the data support.
fn friction(exp: &Experiment, source: &str) -> PyResult<Value> {
    let Data::FrictionMap(map) = &exp.data else {
        return Err(bad_argument(
            "experiment",
            format!("{source}: not a friction map"),
        ));
    };
    let e = rtid::friction_map::evaluate(map)
        .map_err(|m| bad_argument("experiment", format!("{source}: {m}")))?;
    evaluation::friction_map(&e, source).map_err(|e| rtid_error(&e))
}

/// The friction law of a servo trace by IDIM-LS (the default settings), and on
/// `model` its replay's simulation error.
fn servo_trace(exp: &Experiment, source: &str, model: Option<&rtid::Params>) -> PyResult<Value> {
    let (Data::ServoTrace(file), Some(trace)) = (&exp.data, ServoTrace::from_experiment(exp))
    else {
        return Err(bad_argument(
            "experiment",
            format!("{source}: not a servo trace"),
        ));
    };
    let period = trace.check().map_err(|e| with_context(source, &e))?;
    let settings = IdimSettings::for_sample_period(period);
    let e = rtid::servo_trace::evaluate(exp, (&trace, file.axis), &settings, model)
        .map_err(|e| with_context(source, &e))?;
    let report = TraceReport::new(source.to_string(), file.axis, (trace.len(), period), e);
    rtid::io::json::value(&report).map_err(|e| rtid_error(&e))
}
