//! `rtid.identify`: the configuration `rtid identify` builds from its options, the
//! search run on a thread of its own while this one waits with the GIL released and
//! looks for Ctrl-C (which stops the search: the best point so far is the result).

use std::path::PathBuf;
use std::time::Duration;

use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::curves;
use crate::errors::{bad_argument, rtid_error, with_context};
use crate::params::PyParams;
use rtid::identify::{
    Bound, Config, ExperimentSpec, FidelityChoice, Identified, Method, Monitor, SearchOptions,
    StartChoice,
};
use rtid::objectives::ObjectiveKind;

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
    /// `--uncertain`: held parameters and their relative half-ranges.
    uncertain: Vec<(String, f64)>,
}

/// Identifies the parameters of `options.fit` from the experiment manifests
/// `experiments` (path, name to report it by); returns the result file's JSON, the
/// identified parameter set and the curves. `progress(done, budget, evaluations)`,
/// if given, is called as the searches' iterations advance (an exception from it
/// stops the search and is raised).
#[pyfunction]
#[pyo3(signature = (experiments, params, options, progress=None))]
pub fn identify<'py>(
    py: Python<'py>,
    experiments: Vec<(PathBuf, String)>,
    params: PyRef<'_, PyParams>,
    options: Options,
    progress: Option<Py<PyAny>>,
) -> PyResult<(String, PyParams, pyo3::Bound<'py, PyList>)> {
    let base = params.inner.clone();
    drop(params);
    let config = config(&experiments, base, &options)?;
    if options.resample == Some(0) {
        return Err(bad_argument(
            "resample",
            "0: at least one replicate is needed",
        ));
    }
    let rough = || rtid::identify::plan::Plan::new(&config).is_ok_and(|p| p.declared.rough);
    if !options.uncertain.is_empty() && options.resample.is_none() && rough() {
        return Err(bad_argument(
            "uncertain",
            "on a closed-loop simulation's rough cost (torque curve, unbalance test, servo trace) it needs resample=N: each replicate draws the held parameters and is fitted again",
        ));
    }
    let monitor = Monitor::default();
    let mut failed = None;
    let mut shown = None;
    let outcome = std::thread::scope(|s| {
        let search = s.spawn(|| {
            let fit = rtid::identify(&config, &monitor).map_err(|e| rtid_error(&e))?;
            let fit = with_intervals(fit, &options, &monitor)?;
            let curves = curves::compute(
                &config.experiments,
                &start_params(&config.base, &fit.result),
                &fit.params,
            );
            Ok::<_, PyErr>((fit, curves))
        });
        loop {
            let finished = search.is_finished();
            if !finished {
                py.detach(|| std::thread::sleep(Duration::from_millis(20)));
                if py.check_signals().is_err() {
                    // Ctrl-C (KeyboardInterrupt): end the search, keep its best point.
                    monitor.stop();
                }
            }
            // Once more when finished: a bar ends at the end.
            if let (Some(callback), None) = (&progress, &failed) {
                let now = monitor.progress().iterations();
                if shown != Some(now) {
                    shown = Some(now);
                    if let Err(e) = callback.call1(py, (now.0, now.1, monitor.evaluations())) {
                        monitor.stop();
                        failed = Some(e);
                    }
                }
            }
            if finished {
                break;
            }
        }
        search.join()
    });
    if let Some(e) = failed {
        return Err(e);
    }
    let (Identified { result, params, .. }, curves) = match outcome {
        Ok(r) => r?,
        Err(_) => return Err(bad_argument("identify", "the search panicked")),
    };
    let json = rtid::io::json::pretty(&result).map_err(|e| rtid_error(&e))?;
    let curves = curves::to_python(py, curves)?;
    Ok((json, PyParams { inner: params }, curves))
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
    use rtid::identify::intervals::{profile, resample};
    use rtid::identify::result::warning::Coded;
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
    let held = held_ranges(&fit, &options.uncertain)?;
    if let Some(replicates) = options.resample {
        let request = resample::Request {
            result: &fit.result,
            params: &fit.params,
            objective: fit.objective.as_ref(),
            settings: fit.settings,
            replicates,
            held: &held,
            stop: &|| monitor.stopped(),
            on_replicate: &|| {},
        };
        let resampling = resample::resample(&request).map_err(|e| rtid_error(&e))?;
        resample::attach(&mut fit.result, resampling);
    } else if !held.is_empty() {
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
    Ok(fit)
}

/// `uncertain` as (name, value, relative half-range), each a parameter the fit held
/// at a nonzero value.
fn held_ranges(fit: &Identified, uncertain: &[(String, f64)]) -> PyResult<Vec<(String, f64, f64)>> {
    let mut out = Vec::new();
    for (name, half) in uncertain {
        let spec = rtid::model::spec(name).map_err(|e| bad_argument("uncertain", e))?;
        if fit.result.parameters.contains_key(spec.name) {
            return Err(bad_argument(
                "uncertain",
                format!("{}: fitted; its uncertainty is the fit's", spec.name),
            ));
        }
        if !(*half > 0.0 && *half < 1.0) {
            return Err(bad_argument(
                "uncertain",
                format!(
                    "{}: {half}: the relative half-range must lie between 0 and 1",
                    spec.name
                ),
            ));
        }
        let value = spec.get(&fit.params).filter(|v| *v != 0.0).ok_or_else(|| {
            bad_argument(
                "uncertain",
                format!(
                    "{}: zero or not a parameter of this model: a relative range needs a value",
                    spec.name
                ),
            )
        })?;
        out.push((spec.name.to_string(), value, *half));
    }
    Ok(out)
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
        checkpoint: None,
        resume: false,
        start: start(&o.start)?,
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
