//! The identified point assessed: each experiment's residuals (one evaluation serves
//! the report, the cost and the uncertainty), the uncertainty, the check of a linear
//! fit on the nonlinear test, and the warnings a user should read.

use super::config::Config;
use super::plan::Plan;
use super::problem::{describe, Best, Monitor};
use super::result::{ExperimentResidual, NonlinearCheck};
use super::search::StartRecord;
use super::space::ParamSpace;
use super::stages::Ran;
use super::uncertainty::{self, Uncertainty};
use super::warning::Warning;
use super::IdentifyError;
use crate::model::Params;
use crate::objectives::model_peaks::nonlinear_peak_on_grid;
use crate::objectives::{measured, sum_of_squares, Detail, Joint, ObjectiveError, Source};

/// What the assessment finds.
pub struct Assessment {
    pub residuals: Vec<ExperimentResidual>,
    pub cost: f64,
    pub uncertainty: Option<Uncertainty>,
    pub nonlinear_check: Option<Vec<NonlinearCheck>>,
    pub warnings: Vec<Warning>,
}

/// A resonance missed by more than this, Hz, is worth a warning.
const RESONANCE_MISS_HZ: f64 = 1.0;
/// A nonlinear shift of the resonances beyond this fraction is worth a warning.
const NONLINEAR_SHIFT: f64 = 1e-2;

/// Assesses the best point `best` (= `params`) of the stages `ran`.
pub fn assess(
    config: &Config,
    plan: &Plan,
    space: &ParamSpace,
    ran: &Ran,
    best: &Best,
    params: &Params,
    monitor: &Monitor,
) -> Result<Assessment, IdentifyError> {
    let interrupted = monitor.stopped();
    let joint = &ran.joint;
    let mut warnings = search_warnings(space, &ran.starts, best, monitor);
    let parts = joint.part_residuals(params)?;
    let stacked = joint.stack(&parts);
    let residuals = residual_report(joint, parts);
    warnings.extend(resonance_misses(&residuals));
    let uncertainty = if interrupted {
        None
    } else {
        let a = uncertainty::with_residuals(
            space,
            joint,
            &best.values,
            &stacked,
            plan.uncertainty_step,
        )?;
        warnings.extend(a.warnings);
        if plan.declared.rough {
            warnings.push(Warning::RoughCost);
        }
        Some(a.uncertainty)
    };
    let nonlinear_check = if plan.check_nonlinear && !interrupted {
        let checks = nonlinear_check(config, params)?;
        warnings.extend(checks.iter().filter_map(shift_warning));
        Some(checks)
    } else {
        None
    };
    Ok(Assessment {
        residuals,
        cost: sum_of_squares(&stacked),
        uncertainty,
        nonlinear_check,
        warnings,
    })
}

/// How the search went: stopped, failures, distinct optima of the same cost,
/// parameters at their bounds.
fn search_warnings(
    space: &ParamSpace,
    starts: &[StartRecord],
    best: &Best,
    monitor: &Monitor,
) -> Vec<Warning> {
    let mut out = Vec::new();
    if monitor.stopped() {
        out.push(Warning::Interrupted {
            evaluations: monitor.evaluations(),
        });
    }
    if let Some(example) = monitor.failure() {
        out.push(Warning::EvaluationFailures { example });
    }
    for s in starts {
        let Some(v) = &s.result else { continue };
        let far = v
            .iter()
            .zip(&best.values)
            .any(|(a, b)| ((a - b) / b).abs() > 0.05);
        if far && s.cost_or_infinity() <= best.cost.max(1e-6) * 1.5 + 1e-6 {
            out.push(Warning::DistinctSolution {
                start: s.index + 1,
                solution: describe(space, v),
            });
        }
    }
    for (name, side) in space.at_bounds(&best.values) {
        out.push(Warning::AtBound {
            name: name.into(),
            side,
        });
    }
    out
}

/// Each part's residuals at the result, with their details in the measurement's units.
fn residual_report(joint: &Joint, parts: Vec<Vec<f64>>) -> Vec<ExperimentResidual> {
    joint
        .parts
        .iter()
        .zip(parts)
        .map(|(part, r)| ExperimentResidual {
            source: part.source.clone(),
            objective: part.objective.name().into(),
            weight: part.weight,
            scale: part.objective.scale(),
            rms: (sum_of_squares(&r) / r.len().max(1) as f64).sqrt(),
            detail: part.objective.detail(&r),
            residuals: r,
        })
        .collect()
}

/// Resonances the fitted model misses by more than [`RESONANCE_MISS_HZ`].
fn resonance_misses(residuals: &[ExperimentResidual]) -> Vec<Warning> {
    residuals
        .iter()
        .filter_map(|r| match &r.detail {
            Some(Detail::Resonance { max_miss_hz, .. }) if *max_miss_hz > RESONANCE_MISS_HZ => {
                Some(Warning::ResonanceMiss {
                    source: r.source.clone(),
                    max_miss_hz: *max_miss_hz,
                })
            }
            _ => None,
        })
        .collect()
}

/// The warning for a nonlinear check whose resonances moved beyond
/// [`NONLINEAR_SHIFT`] (a NaN counts as beyond).
fn shift_warning(c: &NonlinearCheck) -> Option<Warning> {
    let worst = c
        .model_hz
        .iter()
        .zip(&c.measured_hz)
        .map(|(m, f)| ((m - f) / f).abs())
        .fold(
            0.0,
            |a: f64, b| if b.is_nan() { f64::INFINITY } else { a.max(b) },
        );
    (worst > NONLINEAR_SHIFT).then(|| Warning::NonlinearShift {
        source: c.source.clone(),
        model_hz: c.model_hz.clone(),
        measured_hz: c.measured_hz.clone(),
        max_miss_hz: c.max_miss_hz,
    })
}

/// The measured resonances against those of the nonlinear virtual test at the
/// identified parameters, per measured gain curve — like for like: the test is
/// simulated at the measured frequencies near each measured peak and its peak located
/// as the measurement's was ([`nonlinear_peak_on_grid`]), so that at the true
/// parameters it reproduces the measurement exactly and a difference is the
/// linearisation's bias.
fn nonlinear_check(config: &Config, p: &Params) -> Result<Vec<NonlinearCheck>, IdentifyError> {
    let mut out = Vec::new();
    for spec in &config.experiments {
        let Some(grid) = measured::grid(&spec.experiment) else {
            continue;
        };
        let source = Source {
            file: &spec.source,
            experiment: &spec.experiment,
        };
        let measured: Vec<f64> = measured::peaks(&source)?
            .iter()
            .map(|pk| pk.frequency_hz)
            .collect();
        let test = measured::frequency_test(&spec.experiment);
        let model = measured
            .iter()
            .map(|&f| nonlinear_peak_on_grid(p, &test, &grid, f).map(|pk| pk.frequency_hz))
            .collect::<Result<Vec<f64>, _>>()
            .map_err(ObjectiveError::from)?;
        let max_miss_hz = model
            .iter()
            .zip(&measured)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        out.push(NonlinearCheck {
            source: spec.source.clone(),
            measured_hz: measured,
            model_hz: model,
            max_miss_hz,
        });
    }
    Ok(out)
}
