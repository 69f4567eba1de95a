//! The result of an identification by plan: each record's residuals at the end
//! (its own report objective: a corrected frequency response's nonlinear test), the
//! uncertainty from every record's Jacobian at the step its cost allows, the stages'
//! warnings and the plan.

use std::collections::BTreeMap;

use nalgebra::DMatrix;

use super::{Planned, Stacked};
use crate::identify::config::Config;
use crate::identify::error::IdentifyError;
use crate::identify::intervals::uncertainty::{self, jacobian};
use crate::identify::pipeline::assess::residual_report;
use crate::identify::plan::uncertainty_step;
use crate::identify::result::record_plan::RecordPlan;
use crate::identify::result::starts::StartRecord;
use crate::identify::result::termination::Termination;
use crate::identify::result::uncertainty::Uncertainty;
use crate::identify::result::warning::{Coded, Warning};
use crate::identify::result::IdentifyResult;
use crate::identify::run::{Identified, Replay};
use crate::identify::search::settings::Settings;
use crate::identify::setup;
use crate::identify::space::ParamSpace;
use crate::model::Params;
use crate::objectives::{sum_of_squares, Fidelity, Objective, Stage};

/// What the stages and the refinement found.
pub(super) struct Found {
    pub params: Params,
    pub objective: Stacked,
    /// Each record's report objective (its last stage's; `None`: it ran no stage).
    pub reports: Vec<Option<(Stage, Fidelity)>>,
    pub settings: Settings,
    pub refinement: Vec<StartRecord>,
    pub plan: RecordPlan,
    /// The stages and refinement for a bootstrap to run again.
    pub replay: Replay,
    pub warnings: Vec<Warning>,
    pub evaluations: usize,
    pub wall_time_s: f64,
    pub interrupted: bool,
}

/// The identification of `config` by `planned`, from what it `found`.
pub(super) fn assemble(
    config: &Config,
    planned: &Planned,
    found: Found,
) -> Result<Identified, IdentifyError> {
    let p = &found.params;
    let first = planned.first_fidelity(config);
    let mut residuals = Vec::new();
    for (spec, report) in config.experiments.iter().zip(&found.reports) {
        let (stage, fidelity) = report.unwrap_or((Stage::Search, first));
        let joint = setup::build(std::slice::from_ref(spec), stage, fidelity)?;
        let parts = joint.part_residuals(p)?;
        residuals.extend(residual_report(&joint, p, parts));
    }
    let cost = sum_of_squares(&found.objective.residuals(p)?);
    let mut warnings = found.warnings.clone();
    if !found.plan.undetermined.is_empty() {
        warnings.push(Warning::NotDetermined {
            names: found.plan.undetermined.clone(),
        });
    }
    let uncertainty = if found.interrupted {
        None
    } else {
        let (u, w) = uncertainty(planned, &found, &found.plan.undetermined)?;
        warnings.extend(w);
        Some(u)
    };
    if planned.records.iter().any(|r| r.rough) {
        warnings.push(Warning::RoughCost);
    }
    dedup(&mut warnings);
    if found.interrupted {
        warnings.push(Warning::Interrupted {
            evaluations: found.evaluations,
        });
    }
    let named = |get: &dyn Fn(&str) -> f64| -> BTreeMap<String, f64> {
        planned.fit.iter().map(|n| (n.clone(), get(n))).collect()
    };
    let value = |n: &str| {
        crate::model::spec(n)
            .ok()
            .and_then(|s| s.get(p))
            .unwrap_or(f64::NAN)
    };
    let initial = |n: &str| {
        let i = planned.fit.iter().position(|f| f == n).unwrap_or(0);
        planned.space.start[i]
    };
    let termination = if found.interrupted {
        Termination::Interrupted
    } else {
        found
            .refinement
            .first()
            .map_or(Termination::Converged, |s| s.termination.clone())
    };
    let result = IdentifyResult {
        mechanism: config.base.name.clone(),
        experiments: config
            .experiments
            .iter()
            .map(|e| e.source.clone())
            .collect(),
        parameters: named(&value),
        initial: named(&initial),
        start_estimates: planned.start.estimates.clone(),
        bounds: planned
            .fit
            .iter()
            .zip(&planned.space.bounds)
            .map(|(n, b)| (n.clone(), [b.lo, b.hi]))
            .collect(),
        method: format!("by record, then {}", found.settings.method.name()),
        fidelity: fidelity_label(&found.reports),
        cost,
        residuals,
        evaluations: found.evaluations,
        wall_time_s: found.wall_time_s,
        termination: Coded(termination),
        interrupted: found.interrupted,
        starts: found.refinement,
        uncertainty,
        plan: Some(found.plan),
        nonlinear_check: None,
        warnings: warnings.into_iter().map(Coded).collect(),
        profiles: None,
        resampling: None,
        held: Vec::new(),
        comparisons: Vec::new(),
        provenance: None,
    };
    Ok(Identified {
        result,
        params: found.params,
        smoothness: super::smoothness(&planned.records, config),
        objective: Box::new(found.objective),
        settings: found.settings,
        report: (Stage::Search, first),
        replay: Some(found.replay),
    })
}

/// The standard errors and correlations of the determined parameters from every
/// record's Jacobian — each at the step its own cost allows (0.1 in ln p on a
/// closed-loop simulation, 1e-4 on a linear or corrected response) — stacked; a
/// stage's standard error where its own was wider (its corrections still moving)
/// or withdrawn.
fn uncertainty(
    planned: &Planned,
    found: &Found,
    undetermined: &[String],
) -> Result<(Uncertainty, Vec<Warning>), IdentifyError> {
    let names: Vec<String> = (planned.fit.iter())
        .filter(|n| !undetermined.contains(n))
        .cloned()
        .collect();
    if names.is_empty() {
        return Ok((empty(&planned.fit), Vec::new()));
    }
    let space = ParamSpace::new(found.params.clone(), &names, &planned.bounds(&names))?;
    let mut blocks: Vec<DMatrix<f64>> = Vec::new();
    let mut r0: Vec<f64> = Vec::new();
    for (part, record) in found.objective.parts.iter().zip(&planned.records) {
        let step = uncertainty_step(record.rough, Fidelity::Linear);
        blocks.push(jacobian(&space, part.as_ref(), &space.start, step)?);
        r0.extend(part.residuals(&found.params)?);
    }
    let m = r0.len();
    let jac = DMatrix::from_fn(m, names.len(), |i, j| {
        let mut i = i;
        for b in &blocks {
            if i < b.nrows() {
                return b[(i, j)];
            }
            i -= b.nrows();
        }
        0.0
    });
    let sigma2 = uncertainty::residual_variance(&r0, m, names.len());
    let assessed = uncertainty::from_jacobian(&space, &space.start, &jac, sigma2);
    let mut u = with_undetermined(assessed.uncertainty, &planned.fit);
    u.lower_bounds = planned.records.iter().any(|r| r.rough);
    for w in &found.warnings {
        if let Warning::CorrectionsNotConverged {
            undetermined,
            widened,
            moved,
            ..
        } = w
        {
            widen(&mut u, &found.params, undetermined, widened, moved);
            u.lower_bounds = true;
        }
    }
    Ok((u, assessed.warnings))
}

/// A stage's corrections that did not converge: its withdrawn parameters have no
/// standard error in the whole either, its widened ones at least their last move.
fn widen(
    u: &mut Uncertainty,
    p: &Params,
    undetermined: &[String],
    widened: &[String],
    moved: &[(String, f64)],
) {
    for (name, se) in &mut u.standard_errors {
        if undetermined.contains(name) {
            *se = None;
        } else if widened.contains(name) {
            let step = moved.iter().find(|(n, _)| n == name).map_or(0.0, |m| m.1);
            let value = crate::model::spec(name)
                .ok()
                .and_then(|s| s.get(p))
                .unwrap_or(0.0);
            *se = se.map(|s| s.max(step * value.abs()));
        }
    }
}

/// `u` over `all` names: those it lacks without a standard error, their
/// correlations undefined.
fn with_undetermined(u: Uncertainty, all: &[String]) -> Uncertainty {
    let index = |n: &String| u.names.iter().position(|x| x == n);
    let correlation = all
        .iter()
        .map(|a| {
            all.iter()
                .map(|b| match (index(a), index(b)) {
                    (Some(i), Some(j)) => u.correlation[i][j],
                    _ => f64::NAN,
                })
                .collect()
        })
        .collect();
    let standard_errors = all
        .iter()
        .map(|n| {
            let se = u
                .standard_errors
                .iter()
                .find(|(x, _)| x == n)
                .and_then(|s| s.1);
            (n.clone(), se)
        })
        .collect();
    Uncertainty {
        standard_errors,
        names: all.to_vec(),
        correlation,
        residual_variance: u.residual_variance,
        conditioning: u.conditioning,
        lower_bounds: u.lower_bounds,
    }
}

/// No standard error for any of `all`.
fn empty(all: &[String]) -> Uncertainty {
    let n = all.len();
    Uncertainty {
        standard_errors: all.iter().map(|a| (a.clone(), None)).collect(),
        names: all.to_vec(),
        correlation: vec![vec![f64::NAN; n]; n],
        residual_variance: 0.0,
        conditioning: 0.0,
        lower_bounds: false,
    }
}

/// `linear, then nonlinear` where any record's last stage was the nonlinear
/// correction; `nonlinear time simulation` where none depends on the frequency
/// response model.
fn fidelity_label(reports: &[Option<(Stage, Fidelity)>]) -> String {
    let corrected = reports
        .iter()
        .flatten()
        .any(|(s, f)| *s == Stage::Correction || *f == Fidelity::Nonlinear);
    if corrected {
        "by record: linear, then nonlinear".into()
    } else {
        "by record".into()
    }
}

/// Each warning once, in the order first given.
fn dedup(warnings: &mut Vec<Warning>) {
    let mut seen: Vec<Warning> = Vec::new();
    warnings.retain(|w| {
        if seen.contains(w) {
            false
        } else {
            seen.push(w.clone());
            true
        }
    });
}
