//! Experiment design (docs/identification.md): which test to run next. Each
//! candidate test — a frequency response at an amplitude and preload over a band, a
//! torque curve at an amplitude and period, an unbalance test with a mass, radius and
//! speed — is run on the model at the given parameters (the nonlinear virtual test:
//! backlash and friction included), and the objectives `rtid identify` would fit to
//! it by default give, through the Jacobian of their scaled residuals with respect to
//! ln p, the Fisher information JᵀJ/σ² (σ: the measurement error in units of each
//! objective's scale, 1 by default). Its inverse predicts the standard errors and
//! correlations the fit of that test would have. Candidates rank by
//!
//! - `d` (D-optimal): det(cov)^(1/2k), the geometric mean of the relative standard
//!   errors over the principal axes — small when the data pin every combination;
//! - `a` (A-optimal): √(trace(cov)/k), the RMS relative standard error.
//!
//! A candidate whose JᵀJ is singular (a parameter or combination it cannot see)
//! ranks last, with no score. Candidates run in parallel.

use std::collections::BTreeMap;
use std::path::PathBuf;

use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::Serialize;

use crate::experiments::fluctuation::{self, FluctuationTest};
use crate::experiments::frequency_response::{self as fr, FrequencyTest};
use crate::experiments::torque_curve::{self, TorqueTest};
use crate::identify::config::ExperimentSpec;
use crate::identify::intervals::uncertainty::{self, jacobian};
use crate::identify::setup;
use crate::identify::space::ParamSpace;
use crate::io::experiment_file::{Experiment, Response};
use crate::model::Params;
use crate::objectives::{Fidelity, Stage};

/// A test to run on the model.
#[derive(Clone, Debug)]
pub enum Test {
    FrequencyResponse(FrequencyTest),
    TorqueCurve(TorqueTest),
    Unbalance(FluctuationTest),
}

/// A candidate: its label, the settings it was given (for the report) and its test.
#[derive(Clone, Debug)]
pub struct Candidate {
    pub label: String,
    pub settings: BTreeMap<String, f64>,
    pub test: Test,
}

/// How candidates rank.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Criterion {
    D,
    A,
}

/// A candidate assessed.
#[derive(Clone, Debug, Serialize)]
pub struct Assessed {
    pub label: String,
    pub settings: BTreeMap<String, f64>,
    /// Name → predicted relative standard error (fraction of the value; `None` when
    /// the candidate cannot determine the fitted set).
    pub predicted_se: BTreeMap<String, Option<f64>>,
    pub names: Vec<String>,
    /// In the order of `names` (from the pseudo-inverse when not determined, so a
    /// ±1 still shows).
    pub correlations: Vec<Vec<f64>>,
    /// Smallest / largest singular value of the column-scaled Jacobian.
    pub conditioning: f64,
    /// Residuals the test gives its objectives.
    pub residuals: usize,
    /// The criterion's value (lower is better); `None` when not determined.
    pub score: Option<f64>,
}

/// Why a design cannot be assessed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DesignError {
    #[error("{label}: the test could not be run on the model: {message}")]
    Run { label: String, message: String },
    #[error("{label}: {message}")]
    Objective { label: String, message: String },
    #[error("{0}")]
    Space(#[from] crate::identify::space::SpaceError),
}

/// What every candidate shares.
pub struct Request<'a> {
    pub params: &'a Params,
    pub fit: &'a [String],
    /// Measurement error in units of the objectives' scales.
    pub noise: f64,
    pub criterion: Criterion,
    /// Called after each candidate (progress).
    pub on_done: &'a (dyn Fn() + Sync),
}

/// The candidates assessed, best first (undetermined ones last, in their order).
pub fn rank(request: &Request, candidates: &[Candidate]) -> Result<Vec<Assessed>, DesignError> {
    let space = ParamSpace::new(request.params.clone(), request.fit, &[])?;
    let mut out: Vec<Assessed> = candidates
        .par_iter()
        .map(|c| {
            let a = assess(request, &space, c);
            (request.on_done)();
            a
        })
        .collect::<Result<_, _>>()?;
    out.sort_by(|a, b| {
        let key = |s: Option<f64>| s.unwrap_or(f64::INFINITY);
        key(a.score).total_cmp(&key(b.score))
    });
    Ok(out)
}

/// One candidate: its virtual experiment, its objectives' Jacobian, the prediction.
fn assess(request: &Request, space: &ParamSpace, c: &Candidate) -> Result<Assessed, DesignError> {
    let objective_error = |e: &dyn std::fmt::Display| DesignError::Objective {
        label: c.label.clone(),
        message: e.to_string(),
    };
    let spec = ExperimentSpec::new(c.label.clone(), experiment(request.params, c)?);
    let specs = std::slice::from_ref(&spec);
    let rough = setup::declared(specs, Stage::Search)
        .map_err(|e| objective_error(&e))?
        .rough;
    let joint =
        setup::build(specs, Stage::Search, Fidelity::Nonlinear).map_err(|e| objective_error(&e))?;
    let step = crate::identify::plan::uncertainty_step(rough, Fidelity::Nonlinear);
    let jac = jacobian(space, &joint, &space.start, step).map_err(|e| objective_error(&e))?;
    Ok(predict(request, c, space, &jac))
}

/// The virtual experiment of a candidate.
fn experiment(p: &Params, c: &Candidate) -> Result<Experiment, DesignError> {
    let failed = |e: &dyn std::fmt::Display| DesignError::Run {
        label: c.label.clone(),
        message: e.to_string(),
    };
    let (manifest, data) = match &c.test {
        Test::FrequencyResponse(t) => {
            let points = fr::sweep(p, t, &|| {}).map_err(|e| failed(&e))?;
            let mut data =
                fr::to_data(p, &points, Response::TableOverMotor).map_err(|e| failed(&e))?;
            // By its gain (its resonances, as `rtid identify` fits a gain-only file).
            // The complex curve, on the nonlinear test, is not smooth at the
            // Jacobian's step where a mesh rattles in its backlash: on the worm
            // unloaded at ±5 N·m (spur mesh out of contact) its finite differences
            // predicted Kw and Kg to 0.08 %, five times better than the preloaded
            // test's 0.38 %: the roughness read as information.
            data.drop_phase();
            (fr::manifest(p, t, false, Response::TableOverMotor), data)
        }
        Test::TorqueCurve(t) => {
            let curve = torque_curve::run(p, t, |_, _| {}).map_err(|e| failed(&e))?;
            (
                torque_curve::manifest(p, t),
                torque_curve::to_data(&curve, p.axis),
            )
        }
        Test::Unbalance(t) => {
            let record = fluctuation::run(p, t, |_, _| {}).map_err(|e| failed(&e))?;
            (
                fluctuation::manifest(p, t),
                fluctuation::to_data(&record, t.kind()),
            )
        }
    };
    Ok(Experiment {
        manifest,
        data,
        path: PathBuf::from(&c.label),
        data_path: None,
    })
}

/// Standard errors, correlations and score from the Jacobian `jac` (as
/// [`jacobian`] takes it) with σ = `request.noise`.
fn predict(request: &Request, c: &Candidate, space: &ParamSpace, jac: &DMatrix<f64>) -> Assessed {
    let u = uncertainty::from_jacobian(space, &space.start, jac, request.noise.powi(2)).uncertainty;
    let relative: Vec<Option<f64>> = u
        .standard_errors
        .iter()
        .zip(&space.start)
        .map(|((_, se), v)| se.map(|s| s / v.abs().max(f64::MIN_POSITIVE)))
        .collect();
    Assessed {
        label: c.label.clone(),
        settings: c.settings.clone(),
        predicted_se: u
            .names
            .iter()
            .cloned()
            .zip(relative.iter().copied())
            .collect(),
        score: score(request.criterion, &relative, &u.correlation),
        names: u.names,
        correlations: u.correlation,
        conditioning: u.conditioning,
        residuals: jac.nrows(),
    }
}

/// The criterion on the relative covariance ρᵢⱼ·seᵢ·seⱼ (`None` when a standard
/// error is undefined).
fn score(criterion: Criterion, se: &[Option<f64>], correlation: &[Vec<f64>]) -> Option<f64> {
    let se: Vec<f64> = se.iter().copied().collect::<Option<_>>()?;
    let k = se.len();
    let cov = DMatrix::from_fn(k, k, |i, j| correlation[i][j] * se[i] * se[j]);
    Some(match criterion {
        Criterion::D => cov.determinant().max(0.0).powf(0.5 / k as f64),
        Criterion::A => (cov.trace() / k as f64).max(0.0).sqrt(),
    })
}
