//! `rtid.identify`: the configuration `rtid identify` builds from its options, the
//! search run on a thread of its own while this one waits with the GIL released and
//! looks for Ctrl-C (which stops the search: the best point so far is the result).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::curves;
use crate::errors::{bad_argument, rtid_error, with_context};
use crate::interruptible;
use crate::params::PyParams;
use rtid::identify::{
    Bound, Config, ExperimentSpec, FidelityChoice, Identified, Method, Monitor, SearchOptions,
    Staging, StartChoice,
};
use rtid::objectives::ObjectiveKind;

/// The result file's JSON, the identified set, the curves, whether Ctrl-C stopped
/// the work, and the fit's statistics.
type Identification<'py> = (
    String,
    PyParams,
    pyo3::Bound<'py, PyList>,
    bool,
    pyo3::Bound<'py, PyDict>,
);

/// Options of the search, as `rtid identify`'s flags give them.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct Options {
    fit: Vec<String>,
    bounds: Vec<(String, f64, f64)>,
    method: Option<String>,
    fidelity: String,
    starts: Option<usize>,
    seed: u64,
    max_iters: u64,
    start: String,
    weights: Option<Vec<f64>>,
    objectives: Option<Vec<String>>,
    /// `--profile`: the names to profile (empty: every fitted parameter).
    profile: Option<Vec<String>>,
    /// `--resample`: bootstrap replicates.
    resample: Option<usize>,
    /// `--uncertain`: held parameters and their relative half-ranges (0: exact), in
    /// place of or beside the parameter set's own ranges.
    uncertain: Vec<(String, f64)>,
    /// `--intervals`: `auto` (by the cost), `standard-errors` or `bootstrap`.
    intervals: String,
    /// `--joint`: every fitted parameter on the joint cost at once, not by plan.
    joint: bool,
    /// `--checkpoint`: the search's state, written as it goes.
    checkpoint: Option<PathBuf>,
    /// `--resume`: continue the search `checkpoint` holds.
    resume: bool,
}

/// Identifies the parameters of `options.fit` from the experiment manifests
/// `experiments` (path, name to report it by); returns the result file's JSON, the
/// identified parameter set, the curves and whether Ctrl-C stopped the work (the
/// search: its best point; the intervals: what they finished). `progress(done,
/// budget, evaluations)`, if given, is called as the searches' iterations advance
/// (an exception from it stops the search and is raised; a `KeyboardInterrupt` from
/// it is Ctrl-C).
#[pyfunction]
#[pyo3(signature = (experiments, params, options, progress=None))]
pub fn identify<'py>(
    py: Python<'py>,
    experiments: Vec<(PathBuf, String)>,
    params: PyRef<'_, PyParams>,
    options: Options,
    progress: Option<Py<PyAny>>,
) -> PyResult<Identification<'py>> {
    let base = params.inner.clone();
    drop(params);
    let config = config(&experiments, base, &options)?;
    if options.resample == Some(0) {
        return Err(bad_argument(
            "resample",
            "0: at least one replicate is needed",
        ));
    }
    let monitor = Monitor::default();
    let finished = interruptible::run(
        py,
        &|| monitor.stop(),
        || {
            let fit = rtid::identify(&config, &monitor).map_err(|e| rtid_error(&e))?;
            let fit = with_intervals(fit, &options, &monitor)?;
            let curves = curves::compute(
                &config.experiments,
                &start_params(&config.base, &fit.result),
                &fit.params,
            );
            Ok::<_, PyErr>((fit, curves))
        },
        interruptible::progress(&progress, || {
            let (done, budget) = monitor.progress().iterations();
            (done, budget, monitor.evaluations())
        }),
    )?;
    // Ctrl-C ends the search with its best point (or the intervals with what they
    // finished): the result, marked as stopped, not the exception.
    // Stopped before a single evaluation: nothing to keep, the interrupt itself.
    let (fit, stopped) = match (finished.value, finished.interrupted) {
        (Ok(fit), signal) => (fit, signal.is_some()),
        (Err(_), Some(signal)) => return Err(signal),
        (Err(e), None) => return Err(e),
    };
    let (Identified { result, params, .. }, curves) = fit;
    let json = rtid::io::json::pretty(&result).map_err(|e| rtid_error(&e))?;
    let curves = curves::to_python(py, curves)?;
    let statistics = statistics(py, &result)?;
    let params = PyParams { inner: params };
    Ok((json, params, curves, stopped, statistics))
}

/// The fit's statistics under lmfit's names, as `rtid select` computes them:
/// `ndata` residuals, `nvarys` fitted parameters, `chisqr` the cost (the sum of
/// squares the search minimises), `redchi` = chisqr/(ndata − nvarys), `aic`, `aicc`
/// (None where ndata ≤ nvarys + 1), `bic`.
fn statistics<'py>(
    py: Python<'py>,
    r: &rtid::identify::IdentifyResult,
) -> PyResult<pyo3::Bound<'py, PyDict>> {
    let c = rtid::identify::selection::statistics("", r);
    let d = PyDict::new(py);
    d.set_item("ndata", c.n)?;
    d.set_item("nvarys", c.k)?;
    d.set_item("chisqr", c.cost)?;
    let dof = c.n as f64 - c.k as f64;
    d.set_item("redchi", if dof > 0.0 { c.cost / dof } else { f64::NAN })?;
    d.set_item("aic", c.aic)?;
    d.set_item("aicc", c.aicc)?;
    d.set_item("bic", c.bic)?;
    Ok(d)
}

/// The parameters the search started from: the base set with the recorded start
/// values (a direct estimate may have replaced the base's), as the command line
/// takes them for its comparisons.
fn start_params(
    base: &rtid::Params,
    result: &rtid::identify::result::IdentifyResult,
) -> rtid::Params {
    let mut p = base.clone();
    for (name, &v) in &result.initial {
        // A name the result holds is one of the set's: set() cannot refuse it.
        let _ = p.set(name, v);
    }
    p
}

/// The fit with the intervals `options` ask for, as `rtid identify --profile` and
/// `--resample` add them (Ctrl-C stops them too: `monitor`).
fn with_intervals(
    mut fit: Identified,
    options: &Options,
    monitor: &Monitor,
) -> PyResult<Identified> {
    use rtid::identify::intervals::{chosen, profile, resample};
    use rtid::identify::result::warning::Coded;
    if fit.result.interrupted {
        // A search stopped early: no intervals about a point that is not its end.
        return Ok(fit);
    }
    if let Some(names) = &options.profile {
        let names = if names.is_empty() {
            fit.result.parameters.keys().cloned().collect()
        } else {
            names.clone()
        };
        let request = profile::Request {
            result: &fit.result,
            params: &fit.params,
            objective: fit.objective.as_ref(),
            settings: fit.settings,
            smoothness: fit.smoothness,
            names,
            stop: &|| monitor.stopped(),
            on_point: &|| {},
        };
        let (profiles, warnings) = profile::profiles(&request).map_err(|e| rtid_error(&e))?;
        fit.result.warnings.extend(warnings.into_iter().map(Coded));
        profile::attach(&mut fit.result, profiles);
    }
    let fitted: Vec<String> = fit.result.parameters.keys().cloned().collect();
    let overrides = crate::params::overrides(&options.uncertain)?;
    let held = chosen::held_ranges(&fit.params, &fitted, &overrides)
        .map_err(|e| bad_argument("uncertain", e))?;
    let choice = match options.intervals.as_str() {
        "auto" => chosen::Choice::Auto,
        "standard-errors" => chosen::Choice::StandardErrors,
        "bootstrap" => chosen::Choice::Bootstrap,
        other => {
            return Err(bad_argument(
                "intervals",
                format!("{other}: auto, standard-errors or bootstrap"),
            ))
        }
    };
    match chosen::decide(&fit.result, fit.smoothness, choice, options.resample) {
        chosen::Chosen::Bootstrap(replicates) => {
            let request = resample::Request {
                result: &fit.result,
                params: &fit.params,
                objective: fit.objective.as_ref(),
                settings: fit.settings,
                replay: fit.replay.as_ref(),
                replicates,
                held: &held,
                stop: &|| monitor.stopped(),
                on_replicate: &|| {},
            };
            let resampling = resample::resample(&request).map_err(|e| rtid_error(&e))?;
            resample::attach(&mut fit.result, resampling);
        }
        chosen::Chosen::StandardErrors
            if !held.is_empty() && !chosen::rough(&fit.result, fit.smoothness) =>
        {
            let shifts = rtid::identify::intervals::held::shifts(
                &rtid::identify::intervals::held::Fit {
                    result: &fit.result,
                    params: &fit.params,
                    objective: fit.objective.as_ref(),
                    settings: fit.settings,
                },
                &held,
            );
            fit.result.held = shifts.map_err(|e| rtid_error(&e))?;
        }
        chosen::Chosen::StandardErrors => {}
    }
    Ok(fit)
}

/// The configuration, checked before any work as the command line checks it.
fn config(experiments: &[(PathBuf, String)], base: rtid::Params, o: &Options) -> PyResult<Config> {
    if experiments.is_empty() {
        return Err(bad_argument("experiments", "no experiment given"));
    }
    if let Some(w) = &o.weights {
        if w.len() != experiments.len() {
            return Err(bad_argument(
                "weights",
                format!(
                    "{} weights for {} experiments: give one per experiment, in order",
                    w.len(),
                    experiments.len()
                ),
            ));
        }
    }
    let chosen: Option<Vec<ObjectiveKind>> = o
        .objectives
        .as_ref()
        .map(|v| v.iter().map(|n| ObjectiveKind::named(n)).collect())
        .transpose()
        .map_err(|e| with_context("objectives", &e))?;
    let mut specs = Vec::new();
    for (i, (path, source)) in experiments.iter().enumerate() {
        let exp = rtid::read_experiment(path).map_err(|e| with_context("experiments", &e))?;
        let mut spec = ExperimentSpec::new(source.clone(), exp);
        if let Some(&w) = o.weights.as_ref().and_then(|w| w.get(i)) {
            if !rtid::identify::config::WEIGHTS.contains(&w) {
                return Err(bad_argument(
                    "weights",
                    format!("{w}: a weight is relative (default 1): give one within 1e-6..1e6"),
                ));
            }
            spec.weight = w;
        }
        if let Some(all) = &chosen {
            spec.objectives = Some(usable(all, &spec)?);
        }
        specs.push(spec);
    }
    if o.fit.iter().any(|n| n.trim().is_empty()) {
        return Err(bad_argument("fit", "an empty name in the list"));
    }
    if o.starts == Some(0) {
        return Err(bad_argument("starts", "0: at least one start is needed"));
    }
    if o.resume && o.checkpoint.is_none() {
        return Err(bad_argument(
            "resume",
            "give checkpoint=, the file of the search to continue",
        ));
    }
    if o.max_iters == 0 {
        return Err(bad_argument(
            "max_iters",
            "0: each local search needs at least one iteration",
        ));
    }
    let bounds = o
        .bounds
        .iter()
        .map(|(n, lo, hi)| (n.clone(), Bound { lo: *lo, hi: *hi }));
    Ok(Config {
        experiments: specs,
        base,
        fit: o.fit.iter().map(|s| s.trim().to_string()).collect(),
        bounds: bounds.collect(),
        fidelity: fidelity(&o.fidelity)?,
        search: SearchOptions {
            method: o.method.as_deref().map(method).transpose()?,
            starts: o.starts,
            seed: o.seed,
            max_iters: o.max_iters,
            max_evaluations: None,
        },
        checkpoint: o.checkpoint.clone(),
        resume: o.resume,
        start: start(&o.start)?,
        staging: if o.joint {
            Staging::Joint
        } else {
            Staging::ByRecord
        },
    })
}

/// The objectives of `all` that `spec`'s experiment can feed.
fn usable(all: &[ObjectiveKind], spec: &ExperimentSpec) -> PyResult<Vec<ObjectiveKind>> {
    let kind = spec.experiment.manifest.kind;
    let mine: Vec<ObjectiveKind> = all.iter().copied().filter(|o| o.reads(kind)).collect();
    if mine.is_empty() {
        return Err(bad_argument(
            "objectives",
            format!(
                "{} is a {kind} experiment, which none of them reads",
                spec.source
            ),
        ));
    }
    Ok(mine)
}

fn method(name: &str) -> PyResult<Method> {
    Ok(match name.replace('_', "-").as_str() {
        "lsq" => Method::Lsq,
        "lm" => Method::Lm,
        "nelder-mead" => Method::NelderMead,
        "pso" => Method::Pso,
        other => {
            return Err(bad_argument(
                "method",
                format!("unknown method `{other}`: expected lsq, lm, nelder-mead or pso"),
            ))
        }
    })
}

fn fidelity(name: &str) -> PyResult<FidelityChoice> {
    Ok(match name {
        "auto" => FidelityChoice::Auto,
        "linear" => FidelityChoice::Linear,
        "nonlinear" => FidelityChoice::Nonlinear,
        other => {
            return Err(bad_argument(
                "model",
                format!("unknown model `{other}`: expected auto, linear or nonlinear"),
            ))
        }
    })
}

fn start(name: &str) -> PyResult<StartChoice> {
    Ok(match name {
        "estimate" => StartChoice::Estimate,
        "given" => StartChoice::Given,
        other => {
            return Err(bad_argument(
                "start",
                format!("unknown start `{other}`: expected estimate or given"),
            ))
        }
    })
}
