//! Running the plan's stages: the multi-start search, then (with `--model nonlinear`,
//! or with `auto` when the linear fit fails the nonlinear check: [`escalation`]) the
//! corrections of its result by the nonlinear test, each from where a checkpoint left
//! off.

use crate::identify::config::Config;
use crate::identify::error::IdentifyError;
use crate::identify::pipeline::checkpoint::Checkpointer;
use crate::identify::pipeline::correction::{self, Corrected};
use crate::identify::pipeline::escalation;
use crate::identify::plan::{Plan, StagePlan};
use crate::identify::result::starts::StartRecord;
use crate::identify::result::warning::Warning;
use crate::identify::result::NonlinearCheck;
use crate::identify::search::problem::Monitor;
use crate::identify::search::search;
use crate::identify::search::settings::Method;
use crate::identify::space::ParamSpace;
use crate::objectives::{sum_of_squares, Fidelity, Joint, Objective, ObjectiveError, Stage};

/// What the stages leave: the last stage's starts and objective.
pub struct Ran {
    pub starts: Vec<StartRecord>,
    /// The objective of the last stage run (that of the result).
    pub joint: Joint,
    pub fidelity: Fidelity,
    pub warnings: Vec<Warning>,
    /// How many of the plan's stages ran (or were resumed past).
    pub stages: usize,
    /// The nonlinear check of the search's result (`auto`), when it was made.
    pub check: Option<Vec<NonlinearCheck>>,
    /// After corrections: the linear objective with their last shift, a smooth
    /// stand-in for the nonlinear cost, minimised at the result.
    pub surrogate: Option<Corrected<Box<Joint>>>,
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
    let mut check = None;
    let mut notes = Vec::new();
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
            let inside = k == resumed.stage;
            let best = match (inside, &resumed.stage0_best) {
                (true, Some(v)) => v.clone(),
                _ => match monitor.best() {
                    Some(b) => b.values,
                    None => break,
                },
            };
            if stage.escalation {
                let at = space.params(&best).map_err(ObjectiveError::from)?;
                let checks = escalation::check(config, &at)?;
                let assumed = escalation::assumed(&at, &space.names);
                let verdict = escalation::verdict(&checks, &assumed);
                if verdict.is_none() && !inside {
                    notes.extend(escalation::stands(&checks, &assumed));
                }
                check = Some(checks);
                // Resumed inside the stage: the decision was taken before.
                match verdict {
                    Some(w) => notes.push(w),
                    None if !inside => break,
                    None => {}
                }
            }
            let best = if stage.stage == Stage::Correction && !inside {
                correction_start(config, stage, space, best, ran.as_ref(), monitor)?
            } else {
                best
            };
            checkpoint.enter_stage(k, &best, monitor.evaluations());
            monitor.reset_best();
            from = best;
        }
        let mut r = run_stage(config, stage, space, &from, checkpoint, monitor)?;
        r.stages = k + 1;
        ran = Some(r);
    }
    match ran {
        Some(mut r) => {
            r.check = check;
            r.warnings.splice(0..0, notes);
            Ok(r)
        }
        // Stopped before any stage ran: the search's objective serves the report.
        None => Ok(Ran {
            starts: resumed.starts,
            joint: crate::identify::setup::build(
                &config.experiments,
                Stage::Search,
                plan.stages[0].fidelity,
            )?,
            fidelity: plan.stages[0].fidelity,
            warnings: Vec::new(),
            stages: resumed.stage,
            check: None,
            surrogate: None,
        }),
    }
}

/// Where the corrections start: of the search's results (the best, and each start's
/// where they differ), the one the nonlinear test fits best. The search's objectives
/// may be met exactly along a whole curve of parameters — one resonance and its
/// height for two stiffnesses, when friction flattens the second peak — and the
/// lowest linear cost is then any point of it; the nonlinear gain curve tells them
/// apart. A point the test cannot evaluate is passed over.
fn correction_start(
    config: &Config,
    stage: &StagePlan,
    space: &ParamSpace,
    best: Vec<f64>,
    search: Option<&Ran>,
    monitor: &Monitor,
) -> Result<Vec<f64>, IdentifyError> {
    let mut candidates = vec![best];
    for x in search
        .iter()
        .flat_map(|r| &r.starts)
        .filter_map(|s| s.result.as_ref())
    {
        if !candidates.iter().any(|c| same_point(c, x)) {
            candidates.push(x.clone());
        }
    }
    if candidates.len() == 1 {
        return Ok(candidates.swap_remove(0));
    }
    let test = crate::identify::setup::build(&config.experiments, stage.stage, stage.fidelity)?;
    let cost = |x: &[f64]| -> f64 {
        monitor.add_evaluations(1);
        space
            .params(x)
            .map_err(ObjectiveError::from)
            .and_then(|p| test.residuals(&p))
            .map_or(f64::INFINITY, |r| sum_of_squares(&r))
    };
    let costs: Vec<f64> = candidates.iter().map(|x| cost(x)).collect();
    let k = (0..candidates.len())
        .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
        .unwrap_or(0);
    Ok(candidates.swap_remove(k))
}

/// Two results within 0.1 % in every parameter.
fn same_point(a: &[f64], b: &[f64]) -> bool {
    a.iter()
        .zip(b)
        .all(|(x, y)| (x - y).abs() <= 1e-3 * x.abs().max(y.abs()))
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
    let joint = crate::identify::setup::build(&config.experiments, stage.stage, stage.fidelity)?;
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
    let mut surrogate = None;
    let starts = match stage.stage {
        Stage::Correction => {
            let linear =
                crate::identify::setup::build(&config.experiments, stage.stage, Fidelity::Linear)?;
            let out = correction::polish(space, &linear, &joint, from, &settings, monitor)?;
            surrogate = Some(Corrected {
                linear: Box::new(linear),
                offset: out.offset,
            });
            vec![out.record]
        }
        Stage::Search => {
            let mut here = space.clone();
            here.start = from.to_vec();
            let resumed = checkpoint.snapshot();
            if let Some(b) = &resumed.best {
                monitor.offer(b.cost, &b.values);
            }
            let done = resumed.starts;
            let on_done = |r: &StartRecord| checkpoint.save_start(r, monitor);
            search(&here, &joint, &settings, monitor, &done, &on_done)
        }
    };
    Ok(Ran {
        starts,
        joint,
        fidelity: stage.fidelity,
        warnings,
        stages: 0,
        check: None,
        surrogate,
    })
}
