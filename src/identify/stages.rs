//! Running the plan's stages: the multi-start search, then (with `--model nonlinear`)
//! the corrections of its result by the nonlinear test, each from where a checkpoint
//! left off.

use super::checkpoint::Checkpointer;
use super::config::Config;
use super::correction;
use super::plan::{Plan, StagePlan};
use super::problem::Monitor;
use super::search::{search, StartRecord};
use super::solvers::Method;
use super::space::ParamSpace;
use super::warning::Warning;
use super::IdentifyError;
use crate::objectives::{Fidelity, Joint, Objective, Stage};

/// What the stages leave: the last stage's starts and objective.
pub struct Ran {
    pub starts: Vec<StartRecord>,
    /// The objective of the last stage run (that of the result).
    pub joint: Joint,
    pub fidelity: Fidelity,
    pub warnings: Vec<Warning>,
}

/// Runs every stage of `plan` not finished before a resume. The best point is left
/// in `monitor`.
pub fn run(
    config: &Config,
    plan: &Plan,
    space: &ParamSpace,
    checkpoint: &Checkpointer,
    monitor: &Monitor,
) -> Result<Ran, IdentifyError> {
    let resumed = checkpoint.snapshot();
    let mut ran: Option<Ran> = None;
    for (k, stage) in plan.stages.iter().enumerate() {
        if k < resumed.stage {
            continue;
        }
        let mut from = space.start.clone();
        if k > 0 {
            if monitor.stopped() {
                break;
            }
            // Entered now (from this run's search), or resumed inside this stage.
            let best = match (k == resumed.stage, &resumed.stage0_best) {
                (true, Some(v)) => v.clone(),
                _ => match monitor.best() {
                    Some(b) => b.values,
                    None => break,
                },
            };
            checkpoint.enter_stage(k, &best, monitor.evaluations());
            monitor.reset_best();
            from = best;
        }
        ran = Some(run_stage(config, stage, space, &from, checkpoint, monitor)?);
    }
    match ran {
        Some(r) => Ok(r),
        // Stopped before any stage ran: the search's objective serves the report.
        None => Ok(Ran {
            starts: resumed.starts,
            joint: super::setup::build(
                &config.experiments,
                Stage::Search,
                plan.stages[0].fidelity,
            )?,
            fidelity: plan.stages[0].fidelity,
            warnings: Vec::new(),
        }),
    }
}

/// One stage from `from` (physical values of the fitted parameters).
fn run_stage(
    config: &Config,
    stage: &StagePlan,
    space: &ParamSpace,
    from: &[f64],
    checkpoint: &Checkpointer,
    monitor: &Monitor,
) -> Result<Ran, IdentifyError> {
    let joint = super::setup::build(&config.experiments, stage.stage, stage.fidelity)?;
    let mut settings = stage.settings;
    let mut warnings = Vec::new();
    if settings.method == Method::Lsq && joint.len() < space.dim() {
        // Gauss–Newton needs JᵀJ invertible: fewer residuals than parameters never
        // give that.
        settings.method = Method::NelderMead;
        settings.max_iters = settings.max_iters.max(400);
        warnings.push(Warning::MethodSwitched {
            residuals: joint.len(),
            parameters: space.dim(),
        });
    }
    let starts = match stage.stage {
        Stage::Correction => {
            let linear = super::setup::build(&config.experiments, stage.stage, Fidelity::Linear)?;
            let out = correction::polish(space, &linear, &joint, from, &settings, monitor)?;
            vec![out.record]
        }
        Stage::Search => {
            let mut here = space.clone();
            here.start = from.to_vec();
            let done = checkpoint.snapshot().starts;
            let on_done = |r: &StartRecord| checkpoint.save_start(r, monitor.evaluations());
            search(&here, &joint, &settings, monitor, &done, &on_done)
        }
    };
    Ok(Ran {
        starts,
        joint,
        fidelity: stage.fidelity,
        warnings,
    })
}
