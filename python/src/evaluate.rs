//! `rtid.evaluate`: the statistics `rtid evaluate --json` prints for an experiment of
//! every kind with a table — frequency responses, torque curves, positioning records
//! (some runs, a compensation), friction maps, servo traces (with their IDIM-LS
//! options, replayed on a model), fluctuation and unbalance tests, raw time records
//! (H1, stepped sine, multisine) — with the command line's options.

use std::path::PathBuf;

use pyo3::prelude::*;
use serde_json::{json, Value};

use crate::compensate;
use crate::errors::{bad_argument, rtid_error, with_context};
use crate::interruptible;
use crate::params::PyParams;
use rtid::estimation::inverse_dynamics::{IdimOverrides, IdimSettings};
use rtid::experiments::frequency_response as fr;
use rtid::experiments::frequency_response::time_evaluation::{self, EstimateOptions};
use rtid::experiments::positioning as pos;
use rtid::experiments::positioning::iso230::{self, ReportUnits};
use rtid::experiments::servo_trace::ServoTrace;
use rtid::experiments::torque_curve::{self, TorqueTest};
use rtid::io::experiment_file::{Data, Experiment, Kind, Response};
use rtid::report::evaluation::{self, TraceReport};

/// How an experiment is evaluated: `rtid evaluate`'s options (each `None` where not
/// given: the command line's default).
#[derive(FromPyObject, Default)]
#[pyo3(from_item_all)]
pub struct Options {
    /// Positioning: these runs (`4-5`).
    runs: Option<String>,
    /// Positioning: the values as the axis compensated by this compensation.json text
    /// would show them.
    compensation: Option<String>,
    /// Raw time records: `--segment-s`, `--min-coherence`, `--settle-fraction`.
    segment_s: Option<f64>,
    min_coherence: Option<f64>,
    settle_fraction: Option<f64>,
    /// Servo traces: `--cutoff-hz`, `--decimation`, `--trim-s`, `--min-speed`.
    cutoff_hz: Option<f64>,
    decimation: Option<usize>,
    trim_s: Option<f64>,
    min_speed: Option<f64>,
}

/// The evaluation of the experiment at `path` as JSON, `source` naming it.
#[pyfunction]
#[pyo3(signature = (path, source, params=None, options=None))]
pub fn evaluate(
    py: Python<'_>,
    path: PathBuf,
    source: String,
    params: Option<PyRef<'_, PyParams>>,
    options: Option<Options>,
) -> PyResult<String> {
    let exp = rtid::read_experiment(&path).map_err(|e| with_context("experiment", &e))?;
    let model = params.map(|p| p.inner.clone());
    let o = options.unwrap_or_default();
    let positioning_only = o.runs.is_some() || o.compensation.is_some();
    if positioning_only && exp.manifest.kind != Kind::Positioning {
        return Err(bad_argument(
            "runs, compensation",
            format!(
                "for positioning records; {source} is a `{}` experiment",
                exp.manifest.kind.name()
            ),
        ));
    }
    let work = || {
        match exp.manifest.kind {
        Kind::FrequencyResponse => frequency_response(&exp, &source),
        Kind::TorqueCurve => torque(&exp, &source),
        Kind::ServoTrace => servo_trace(&exp, &source, model.as_ref(), &o),
        Kind::Positioning => match (&o.compensation, &o.runs) {
            (Some(c), runs) => compensate::evaluate_compensated(&exp, &source, c, runs.as_deref()),
            (None, Some(runs)) => compensate::evaluate_runs(&exp, &source, runs),
            (None, None) => positioning(&exp, &source),
        },
        Kind::FrictionMap => friction(&exp, &source),
        Kind::Fluctuation | Kind::Unbalance => fluctuation(&exp, &source),
        Kind::FrequencyResponseTime => time_record(&exp, &source, &o),
        other => Err(bad_argument(
            "experiment",
            format!("{source}: a `{}` experiment lists its resonances in its manifest: there is nothing to evaluate", other.name()),
        )),
    }
    };
    let value = interruptible::simple(py, work)??;
    rtid::io::json::pretty(&value).map_err(|e| rtid_error(&e))
}

/// The gain curve of a raw time record (stepped-sine demodulation or H1/Welch), or a
/// periodic multisine's two channels, with `rtid evaluate`'s options.
fn time_record(exp: &Experiment, source: &str, o: &Options) -> PyResult<Value> {
    let mut opts = EstimateOptions::default();
    if let Some(s) = o.segment_s {
        if !(s > 0.0 && s.is_finite()) {
            return Err(bad_argument(
                "segment_s",
                format!("{s}: must be a positive number of seconds"),
            ));
        }
        opts.segment_s = Some(s);
    }
    if let Some(g) = o.min_coherence {
        if !(0.0..=1.0).contains(&g) {
            return Err(bad_argument(
                "min_coherence",
                format!("{g}: a coherence γ² lies in 0..1"),
            ));
        }
        opts.min_coherence = g;
    }
    if let Some(f) = o.settle_fraction {
        if !(0.0..1.0).contains(&f) {
            return Err(bad_argument(
                "settle_fraction",
                format!("{f}: the fraction of each dwell discarded lies in 0..1 (below 1: some must be kept)"),
            ));
        }
        opts.settle_fraction = f;
    }
    let e =
        time_evaluation::evaluate_experiment(exp, &opts).map_err(|e| with_context(source, &e))?;
    evaluation::frequency_response_time(&e, exp.manifest.kind, source).map_err(|e| rtid_error(&e))
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
fn servo_trace(
    exp: &Experiment,
    source: &str,
    model: Option<&rtid::Params>,
    o: &Options,
) -> PyResult<Value> {
    let (Data::ServoTrace(file), Some(trace)) = (&exp.data, ServoTrace::from_experiment(exp))
    else {
        return Err(bad_argument(
            "experiment",
            format!("{source}: not a servo trace"),
        ));
    };
    let period = trace.check().map_err(|e| with_context(source, &e))?;
    let settings = idim_settings(o, period)?;
    let e = rtid::servo_trace::evaluate(exp, (&trace, file.axis), &settings, model)
        .map_err(|e| with_context(source, &e))?;
    let report = TraceReport::new(source.to_string(), file.axis, (trace.len(), period), e);
    rtid::io::json::value(&report).map_err(|e| rtid_error(&e))
}

/// The IDIM-LS settings for a record sampled every `period_s`: the defaults with what
/// was given (`rtid evaluate --cutoff-hz …`).
fn idim_settings(o: &Options, period_s: f64) -> PyResult<IdimSettings> {
    let overrides = IdimOverrides {
        cutoff_hz: o.cutoff_hz,
        decimation: o.decimation,
        trim_s: o.trim_s,
        min_speed: o.min_speed,
    };
    overrides.settings(period_s).map_err(|e| rtid_error(&e))
}
