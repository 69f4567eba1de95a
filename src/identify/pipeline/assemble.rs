//! The result assembled from what the run found and the assessment of its best point.

use std::collections::BTreeMap;

use crate::identify::config::Config;
use crate::identify::pipeline::assess::Assessment;
use crate::identify::plan::Plan;
use crate::identify::result::starts::{StartEstimate, StartRecord};
use crate::identify::result::termination::Termination;
use crate::identify::result::warning::{Coded, Warning};
use crate::identify::result::IdentifyResult;
use crate::identify::space::ParamSpace;

/// What the run contributes to the result beside the assessment.
pub struct Run {
    pub values: Vec<f64>,
    pub start_estimates: Vec<StartEstimate>,
    pub starts: Vec<StartRecord>,
    pub evaluations: usize,
    pub wall_time_s: f64,
    pub interrupted: bool,
    pub warnings: Vec<Warning>,
    /// How many of the plan's stages ran.
    pub stages: usize,
}

/// The result of `config` run under `plan` in `space`.
pub fn assemble(
    config: &Config,
    plan: &Plan,
    space: &ParamSpace,
    run: Run,
    assessment: Assessment,
) -> IdentifyResult {
    let named = |v: &[f64]| -> BTreeMap<String, f64> {
        space
            .names
            .iter()
            .map(|n| n.to_string())
            .zip(v.iter().copied())
            .collect()
    };
    let termination = if run.interrupted {
        Termination::Interrupted
    } else {
        run.starts
            .iter()
            .min_by(|a, b| a.cost_or_infinity().total_cmp(&b.cost_or_infinity()))
            .map_or(Termination::NoStart, |s| s.termination.clone())
    };
    let mut warnings = run.warnings;
    warnings.extend(assessment.warnings);
    IdentifyResult {
        mechanism: config.base.name.clone(),
        experiments: config
            .experiments
            .iter()
            .map(|e| e.source.clone())
            .collect(),
        parameters: named(&run.values),
        initial: named(&space.start),
        start_estimates: run.start_estimates,
        bounds: space
            .names
            .iter()
            .zip(&space.bounds)
            .map(|(n, b)| (n.to_string(), [b.lo, b.hi]))
            .collect(),
        method: plan.stages[0].settings.method.name().into(),
        fidelity: plan.fidelity_label(run.stages),
        cost: assessment.cost,
        residuals: assessment.residuals,
        evaluations: run.evaluations,
        wall_time_s: run.wall_time_s,
        termination: Coded(termination),
        interrupted: run.interrupted,
        starts: run.starts,
        uncertainty: assessment.uncertainty,
        plan: None,
        nonlinear_check: assessment.nonlinear_check,
        warnings: warnings.into_iter().map(Coded).collect(),
        profiles: None,
        resampling: None,
        held: Vec::new(),
        comparisons: Vec::new(),
        provenance: None,
    }
}
