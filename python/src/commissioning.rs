//! `rtid.tune`, `rtid.predict`, `rtid.select` and the drive's forms of a tuning: the
//! library calls `rtid tune`, `rtid predict` and `rtid select` make, so the numbers
//! are the command line's; the long ones interruptible (Ctrl-C: `KeyboardInterrupt`,
//! a prediction from the draws done).

use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use pyo3::prelude::*;

use crate::errors::{bad_argument, rtid_error, with_context};
use crate::interruptible;
use crate::params::PyParams;
use rtid::identify::result::IdentifyResult;
use rtid::io::compensation_file;
use rtid::io::drive_settings::{sinamics, sinumerik, ServoSettings};
use rtid::prediction::request::{self, Request, RequestError};
use rtid::prediction::{self, DrawSource, Setup};
use rtid::tuning::{self, Limits, Objective, Options, Range, Targets, Vary};

/// `rtid tune`'s options.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct TuneOptions {
    phase_margin_deg: f64,
    gain_margin_db: f64,
    objective: String,
    #[pyo3(item("loop"))]
    loop_mode: Option<String>,
    max_kpp: Option<f64>,
    max_bandwidth_hz: Option<f64>,
    notch_depth_db: f64,
    notch_min_width: f64,
    torque_reserve: f64,
    /// `--vary`: (name, low, high) ratios.
    vary: Vec<(String, f64, f64)>,
    delay_periods: u32,
    nominal: bool,
}

/// Tunes the cascade of `params` (with `fit`'s values set, where given) on the
/// nonlinear model (`rtid tune`); returns `rtid tune --json`'s JSON and the tuned set.
/// The range as the command line's: `vary` and `delay_periods`, the nominal machine,
/// or the fit's intervals and the held ranges. `progress(done, total)`, if given, is
/// called as the candidates are weighed.
#[pyfunction]
#[pyo3(signature = (params, options, fit=None, progress=None))]
pub fn tune(
    py: Python<'_>,
    params: PyRef<'_, PyParams>,
    options: TuneOptions,
    fit: Option<&str>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(String, PyParams)> {
    let mut p = params.inner.clone();
    drop(params);
    let fit = fit.map(|text| read_fit(text, "fit")).transpose()?;
    if let Some(f) = &fit {
        f.apply_to(&mut p)
            .and_then(|()| p.validate())
            .map_err(|e| with_context("fit: its values on the model", &e))?;
    }
    if let Some(mode) = &options.loop_mode {
        p.controller.loop_mode = mode.parse().map_err(|e| with_context("loop", &e))?;
    }
    let objective: Objective = options
        .objective
        .parse()
        .map_err(|e: String| bad_argument("objective", e))?;
    let o = Options {
        targets: Targets {
            phase_margin_deg: options.phase_margin_deg,
            gain_margin_db: options.gain_margin_db,
        },
        objective,
        limits: Limits {
            max_kpp: options.max_kpp,
            max_bandwidth_hz: options.max_bandwidth_hz,
            notch_depth_db: options.notch_depth_db,
            notch_min_width: options.notch_min_width,
        },
        torque_reserve: options.torque_reserve,
        range: tune_range(&options, &p, fit.as_ref()),
        ensemble: Default::default(),
    };
    let (done, total) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let on_step = |d: usize, t: usize| {
        done.store(d, Ordering::Relaxed);
        total.store(t, Ordering::Relaxed);
    };
    let finished = interruptible::run(
        py,
        &interruptible::request_stop,
        || tuning::tune(&p, &o, &on_step),
        interruptible::progress(&progress, || {
            (done.load(Ordering::Relaxed), total.load(Ordering::Relaxed))
        }),
    )?;
    let t = finished
        .or_interrupted(py, |_| Ok(None))?
        .map_err(|e| rtid_error(&e))?;
    let json = rtid::io::json::value(&t)
        .and_then(|v| rtid::io::json::pretty(&v))
        .map_err(|e| rtid_error(&e))?;
    Ok((json, PyParams { inner: t.params }))
}

/// The range `options` ask for on `p` ([`tuning::range::default::asked`]).
fn tune_range(options: &TuneOptions, p: &rtid::Params, fit: Option<&IdentifyResult>) -> Range {
    let f = fit.map(|f| f.spreads()).unwrap_or_default();
    let vary = options
        .vary
        .iter()
        .map(|(name, low, high)| Vary {
            name: name.clone(),
            low: *low,
            high: *high,
        })
        .collect();
    let (delay, nominal) = (options.delay_periods, options.nominal);
    tuning::range::default::asked(vary, delay, nominal, p, (&f.spreads, &f.without))
}

/// The servo settings of `params` as a SINAMICS parameter list (`rtid tune
/// --sinamics`).
/// `closed_loop` (equivalent time constant s, speed bandwidth Hz) is the tuned speed
/// loop's, as `rtid tune` writes MD32810 from it.
#[pyfunction]
#[pyo3(signature = (params, closed_loop=(None, None)))]
pub fn sinamics_settings(
    params: PyRef<'_, PyParams>,
    closed_loop: (Option<f64>, Option<f64>),
) -> PyResult<String> {
    let s = servo_settings(&params.inner, closed_loop);
    sinamics::program(&s, &sinamics::SinamicsContext::default())
        .map_err(|e| with_context("sinamics", &e))
}

/// The servo settings of `params` as SINUMERIK machine data for axis `axis_number`
/// (`rtid tune --sinumerik --axis-number N [--gear-ratio M:L]`).
#[pyfunction]
#[pyo3(signature = (params, axis_number, gear_ratio=None, closed_loop=(None, None)))]
pub fn sinumerik_settings(
    params: PyRef<'_, PyParams>,
    axis_number: u32,
    gear_ratio: Option<(u64, u64)>,
    closed_loop: (Option<f64>, Option<f64>),
) -> PyResult<String> {
    if gear_ratio.is_some_and(|(m, l)| m == 0 || l == 0) {
        return Err(bad_argument(
            "gear_ratio",
            "give (motor, load) revolutions as whole numbers above 0, e.g. (90, 1)",
        ));
    }
    let s = servo_settings(&params.inner, closed_loop);
    let ctx = sinumerik::SinumerikContext {
        axis_number: Some(axis_number),
        gear: gear_ratio,
        ..Default::default()
    };
    sinumerik::program(&s, &ctx).map_err(|e| with_context("sinumerik", &e))
}

/// `rtid predict`'s options.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct PredictOptions {
    compensation: Option<String>,
    tune: Option<PyParams>,
    tests: Vec<String>,
    draws: usize,
    from_: Option<String>,
    hold: Vec<String>,
    uncertain: Vec<(String, f64)>,
    runs: u32,
    level: f64,
    seed: u64,
}

/// The effect of a compensation and a tuning on the model `params` with the fit's
/// values set (`rtid predict`), the fit's uncertainty carried through; returns the
/// prediction's JSON (`rtid predict --json`). `progress(done, total)` after each
/// draw. Ctrl-C stops the draws: the prediction is made from those done.
#[pyfunction]
#[pyo3(signature = (fit, params, options, progress=None))]
pub fn predict(
    py: Python<'_>,
    fit: &str,
    params: PyRef<'_, PyParams>,
    options: PredictOptions,
    progress: Option<Py<PyAny>>,
) -> PyResult<(String, bool)> {
    let fit = read_fit(fit, "fit")?;
    let mut model = params.inner.clone();
    drop(params);
    fit.apply_to(&mut model)
        .and_then(|()| model.validate())
        .map_err(|e| with_context("fit: its values on the model", &e))?;
    let request = request(&fit, &model, &options)?;
    let (source, draws, cases) = request::prepare(&request).map_err(|e| match e {
        RequestError::Draw(e) => with_context("fit", &e),
        other => rtid_error(&other),
    })?;
    let stop = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    let total = draws.sets.len();
    let setup = Setup {
        params: &model,
        draws: &draws,
        source,
        held: options.hold.clone(),
        level: options.level,
        cases: &cases,
        // The command line's default: the positioning test's ensemble at the fit.
        ensemble: Some(Default::default()),
    };
    let on_draw = || {
        done.fetch_add(1, Ordering::Relaxed);
    };
    // Ctrl-C stops the draws in flight too: they are left out, as not run.
    let stop_all = || {
        stop.store(true, Ordering::SeqCst);
        rtid::interrupt::request();
    };
    let finished = interruptible::run(
        py,
        &stop_all,
        || prediction::predict(&setup, &on_draw, &stop),
        interruptible::progress(&progress, || (done.load(Ordering::Relaxed), total)),
    )?;
    // Ctrl-C: the prediction from the draws done (its notes say how many); stopped
    // before any, the interrupt itself.
    let (p, stopped) = match (finished.value, finished.interrupted) {
        (Ok(p), signal) => (p, signal.is_some()),
        (Err(_), Some(signal)) => return Err(signal),
        (Err(e), None) => return Err(rtid_error(&e)),
    };
    let json = rtid::io::json::pretty(&p).map_err(|e| rtid_error(&e))?;
    Ok((json, stopped))
}

/// The request the options describe.
fn request<'a>(
    fit: &'a IdentifyResult,
    model: &'a rtid::Params,
    o: &PredictOptions,
) -> PyResult<Request<'a>> {
    let compensation = match &o.compensation {
        Some(text) => {
            let path = Path::new("the compensation");
            let file = compensation_file::parse(text, path)
                .map_err(|e| with_context("compensation", &e))?;
            file.check_axis(path, model.axis)
                .map_err(|e| with_context("compensation", &e))?;
            Some(file.compensation)
        }
        None => None,
    };
    let controller = match &o.tune {
        Some(t) => Some(
            model
                .controller_for(&t.inner)
                .map_err(|e| with_context("tune", &e))?,
        ),
        None => None,
    };
    let from = match o.from_.as_deref() {
        None => None,
        Some("covariance") => Some(DrawSource::Covariance),
        Some("bootstrap") => Some(DrawSource::Bootstrap),
        Some(other) => {
            return Err(bad_argument(
                "from_",
                format!("unknown source `{other}`: expected covariance or bootstrap"),
            ))
        }
    };
    Ok(Request {
        fit,
        params: model,
        compensation,
        controller,
        tests: o.tests.clone(),
        draws: o.draws,
        from,
        hold: o.hold.clone(),
        uncertain: crate::params::overrides(&o.uncertain)?,
        runs: o.runs,
        seed: o.seed,
    })
}

/// An identification result from its JSON (`IdentifyResult.to_dict()`, a result
/// file's text).
fn read_fit(text: &str, argument: &str) -> PyResult<IdentifyResult> {
    serde_json::from_str(rtid::io::without_bom(text)).map_err(|e| {
        bad_argument(
            argument,
            format!("not an identification result (rtid.identify, rtid identify --out): {e}"),
        )
    })
}

/// Compares identifications of the same data (`rtid select --json`): `results` as
/// (label, the result's JSON).
#[pyfunction]
pub fn select(results: Vec<(String, String)>) -> PyResult<String> {
    let mut read = Vec::with_capacity(results.len());
    for (label, text) in results {
        let r = read_fit(&text, &format!("results[{label}]"))?;
        read.push((label, r));
    }
    let s = rtid::identify::selection::select(&read).map_err(|e| with_context("results", &e))?;
    rtid::io::json::pretty(&s).map_err(|e| rtid_error(&e))
}

/// The servo settings of `p` with the tuned speed loop's equivalent time constant and
/// bandwidth where given (as `rtid tune`'s drive forms take them).
fn servo_settings(p: &rtid::Params, closed_loop: (Option<f64>, Option<f64>)) -> ServoSettings {
    let s = ServoSettings::from_params(p);
    ServoSettings {
        equivalent_time_s: closed_loop.0.or(s.equivalent_time_s),
        speed_bandwidth_hz: closed_loop.1.or(s.speed_bandwidth_hz),
        ..s
    }
}
