//! A whole identification of experiments together, step by step: the plan, the
//! search space, the checkpoint, the stages, the assessment of the best point, the
//! result. The command line and the tests come through
//! [`crate::identify::dispatch::identify`], which runs several records by plan
//! ([`crate::identify::by_record`]), its stages through [`identify_one`].

use std::borrow::Cow;
use std::time::Instant;

use crate::identify::config::Config;
use crate::identify::error::IdentifyError;
use crate::identify::pipeline::assemble::{assemble, Run};
use crate::identify::pipeline::assess::assess;
use crate::identify::pipeline::checkpoint::{Checkpointer, Fingerprint};
use crate::identify::pipeline::stages;
use crate::identify::plan::Plan;
use crate::identify::result::warning::Warning;
use crate::identify::result::IdentifyResult;
use crate::identify::search::problem::Monitor;
use crate::identify::search::settings::Settings;
use crate::identify::space::ParamSpace;
use crate::identify::start::start;
use crate::model::Params;
use crate::objectives::{Fidelity, Objective, ObjectiveError, Smoothness, Stage};

/// The identified parameters and the complete parameter set, with the objective
/// the result minimises and the search's settings (for a profile of the result).
pub struct Identified {
    pub result: IdentifyResult,
    pub params: Params,
    /// The smooth objective the result minimises: the last stage's, or after
    /// nonlinear corrections the linear one corrected by their last shift (whose
    /// value at `params` is near, not equal to, the result's nonlinear cost).
    pub objective: Box<dyn Objective>,
    /// The settings of the search stage.
    pub settings: Settings,
    /// How `objective`'s cost varies (the roughest of its parts).
    pub smoothness: Smoothness,
    /// The stage and model of the objectives whose residuals the result reports
    /// (the last stage run).
    pub(crate) report: (Stage, Fidelity),
    /// A fit by plan's stages, for a bootstrap to run them again (`None`: one
    /// search of `objective` with `settings`).
    pub replay: Option<Replay>,
}

/// The estimator a fit by plan ran ([`crate::identify::by_record`]), as a bootstrap
/// replicate repeats it: each stage's search of its parameters on its record alone
/// (part `part` of `objective`, whose parts are the records side by side), one
/// after the other, then the joint refinement.
#[derive(Clone, Debug, PartialEq)]
pub struct Replay {
    pub stages: Vec<ReplayStage>,
    /// The parameters refined jointly after the stages, and that search.
    pub refined: Vec<String>,
    pub refinement: Settings,
}

impl Replay {
    /// The searches one replicate runs: the stages and the refinement.
    pub fn steps(&self) -> usize {
        self.stages.len() + usize::from(!self.refined.is_empty())
    }
}

/// One stage of a [`Replay`].
#[derive(Clone, Debug, PartialEq)]
pub struct ReplayStage {
    /// The record's index among the objective's parts.
    pub part: usize,
    pub names: Vec<String>,
    pub settings: Settings,
}

/// One identification of all of `config`'s experiments together: its plan's search
/// (and corrections) on their joint cost.
pub(crate) fn identify_one(
    config: &Config,
    monitor: &Monitor,
) -> Result<Identified, IdentifyError> {
    let clock = Instant::now();
    let plan = Plan::new(config)?;
    let start = start(config, &plan.fit)?;
    // Only a start moved by an estimate needs its own configuration (a copy of the
    // experiments' data): otherwise the caller's serves.
    let (config, plan) = if start.estimates.is_empty() {
        (Cow::Borrowed(config), plan)
    } else {
        let config = Config {
            base: start.base.clone(),
            ..config.clone()
        };
        (Cow::Owned(config), plan.from_estimate())
    };
    let config: &Config = &config;
    let space = ParamSpace::new(config.base.clone(), &plan.fit, &config.bounds)?;
    let checkpoint = Checkpointer::open(
        config.checkpoint.as_deref(),
        config.resume,
        Fingerprint::of(config, &plan, &space),
    )?;
    monitor.add_evaluations(checkpoint.snapshot().evaluations);
    let ran = stages::run(config, &plan, &space, &checkpoint, monitor)?;
    let best = monitor.best().ok_or_else(|| {
        IdentifyError::NothingEvaluated(
            monitor
                .failure()
                .unwrap_or_else(|| "stopped before any evaluation".into()),
        )
    })?;
    let params = space.params(&best.values).map_err(ObjectiveError::from)?;
    let mut warnings = start.warnings;
    warnings.extend(ran.warnings.iter().cloned());
    if let Some((path, error)) = checkpoint.finish(monitor) {
        warnings.push(Warning::CheckpointNotWritten { path, error });
    }
    let assessment = assess(&plan, &space, &ran, &best, &params, monitor)?;
    let report = (
        plan.stages[ran.stages.clamp(1, plan.stages.len()) - 1].stage,
        ran.fidelity,
    );
    let run = Run {
        values: best.values,
        start_estimates: start.estimates,
        stages: ran.stages,
        starts: ran.starts,
        evaluations: monitor.evaluations(),
        wall_time_s: clock.elapsed().as_secs_f64(),
        interrupted: monitor.stopped(),
        warnings,
    };
    Ok(Identified {
        result: assemble(config, &plan, &space, run, assessment),
        params,
        smoothness: match (&ran.surrogate, plan.declared) {
            (Some(_), _) => Smoothness::Smooth,
            (None, d) if d.derivative_free => Smoothness::Rough,
            (None, d) if d.rough => Smoothness::Grainy,
            _ => Smoothness::Smooth,
        },
        objective: match ran.surrogate {
            Some(s) => Box::new(s),
            None => Box::new(ran.joint),
        },
        settings: plan.stages[0].settings,
        report,
        replay: None,
    })
}
