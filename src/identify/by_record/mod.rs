//! Identification by plan (docs/identification.md): with several records, each
//! fitted parameter is determined first by the record that carries the most
//! information about it ([`information`], [`assign`]), the others held, one record
//! after the other — the closed-loop simulations first, since a frequency response's
//! nonlinear test takes their backlash and friction as given — and then the
//! parameters whose information the records share are refined jointly from there.
//!
//! Each stage is a whole identification of its record alone (its own search, its
//! corrections by the nonlinear test), so a torque curve never runs through a
//! frequency response's correction loop: fitted at once, the worm's frequency
//! response and torque curve put fm 70 % off (12 standard errors); by plan all five
//! parameters land within 0.6 %. The refinement and the uncertainty use each
//! record's objective as its stage left it (a corrected frequency response is its
//! linear response plus the corrections' last shift: smooth), and the uncertainty
//! takes each record's Jacobian at the step its cost allows.

pub mod assign;
pub mod information;
mod report;
mod stacked;

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::identify::config::{Config, Staging};
use crate::identify::error::IdentifyError;
use crate::identify::plan::Plan;
use crate::identify::result::record_plan::{RecordPlan, RecordStage};
use crate::identify::result::starts::StartRecord;
use crate::identify::result::warning::Warning;
use crate::identify::run::{identify_one, Identified, Replay, ReplayStage};
use crate::identify::search::problem::Monitor;
use crate::identify::search::search;
use crate::identify::search::settings::{Method, Settings, SIMPLEX_STEP_NEAR};
use crate::identify::setup;
use crate::identify::space::{Bound, ParamSpace};
use crate::identify::start::start;
use crate::model::Params;
use crate::objectives::{sum_of_squares, Fidelity, Objective, ObjectiveError, Smoothness, Stage};
use assign::{Assignment, RecordInformation};
pub use stacked::Stacked;

/// An identification planned by record.
pub struct Planned {
    /// Every fitted parameter, in the plan's order.
    fit: Vec<String>,
    /// The whole fit's space: its start (with direct estimates) and bounds.
    space: ParamSpace,
    start: crate::identify::start::Start,
    records: Vec<RecordInformation>,
    assignment: Assignment,
}

/// The plan of `config` by record, or `None` where it is the joint fit anyway (every
/// parameter refined jointly, none determined by a record alone).
pub fn plan(config: &Config, monitor: &Monitor) -> Result<Option<Planned>, IdentifyError> {
    let fit = Plan::new(config)?.fit;
    let started = start(config, &fit)?;
    let space = ParamSpace::new(started.base.clone(), &fit, &config.bounds)?;
    let records = information::measure(config, &space)?;
    monitor.add_evaluations(2 * fit.len() * records.len());
    let assignment = assign::assign(fit.len(), &records);
    let staged = assignment.owned.iter().filter(|o| !o.is_empty()).count();
    if assignment.undetermined.is_empty()
        && (staged == 0 || assignment.refined.len() == fit.len() && staged == 1)
    {
        return Ok(None);
    }
    Ok(Some(Planned {
        fit,
        space,
        start: started,
        records,
        assignment,
    }))
}

/// One record's stage as it ran.
struct StageRun {
    record: usize,
    identified: Identified,
}

/// Runs `planned`: the records' stages, then the joint refinement, then the
/// assessment of the whole.
pub fn run(
    config: &Config,
    planned: Planned,
    monitor: &Monitor,
) -> Result<Identified, IdentifyError> {
    let clock = Instant::now();
    let (stages, mut current) = run_stages(config, &planned, monitor)?;
    let replayed: Vec<ReplayStage> = stages.iter().map(StageRun::replayed).collect();
    let stage_records: Vec<RecordStage> = (stages.iter()).map(|s| s.record_stage(config)).collect();
    let Records {
        parts,
        reports,
        warnings,
    } = records(config, &planned, stages)?;
    let stacked = Stacked { parts };
    let refined = planned.names(&planned.assignment.refined);
    let mut refinement = None;
    let settings = planned.refinement_settings(config);
    if !refined.is_empty() && !monitor.stopped() {
        let (starts, at) = refine(&planned, &stacked, &refined, &current, settings, monitor)?;
        current = at;
        refinement = Some(starts);
    }
    let plan = RecordPlan {
        stages: stage_records,
        refined: refined.clone(),
        refinement: refinement
            .as_ref()
            .and_then(|s: &Vec<StartRecord>| s.first())
            .map(|s| s.termination.to_string()),
        undetermined: planned.names(&planned.assignment.undetermined),
        shares: planned.shares(config),
    };
    report::assemble(
        config,
        &planned,
        report::Found {
            params: current,
            objective: stacked,
            reports,
            settings,
            refinement: refinement.unwrap_or_default(),
            plan,
            replay: Replay {
                stages: replayed,
                refined,
                refinement: settings,
            },
            warnings,
            evaluations: monitor.evaluations(),
            wall_time_s: clock.elapsed().as_secs_f64(),
            interrupted: monitor.stopped(),
        },
    )
}

/// Each record's stage, in the order they run, each from where the ones before left
/// the parameters; and the parameter set after the last.
fn run_stages(
    config: &Config,
    planned: &Planned,
    monitor: &Monitor,
) -> Result<(Vec<StageRun>, Params), IdentifyError> {
    let mut current = planned.space.base.clone();
    let mut stages: Vec<StageRun> = Vec::new();
    for (k, e) in order(planned).into_iter().enumerate() {
        if monitor.stopped() {
            break;
        }
        let names = planned.names(&planned.assignment.owned[e]);
        let sub = planned.sub_config(config, e, &current, &names, k);
        monitor.reset_best();
        let before = monitor.evaluations();
        let mut identified = identify_one(&sub, monitor)?;
        identified.result.evaluations -= before;
        current = identified.params.clone();
        stages.push(StageRun {
            record: e,
            identified,
        });
    }
    Ok((stages, current))
}

impl StageRun {
    /// The stage as a bootstrap replicate runs it again.
    fn replayed(&self) -> ReplayStage {
        ReplayStage {
            part: self.record,
            names: self.identified.result.parameters.keys().cloned().collect(),
            settings: self.identified.settings,
        }
    }

    /// The stage as the plan in the result reports it.
    fn record_stage(&self, config: &Config) -> RecordStage {
        let r = &self.identified.result;
        RecordStage {
            record: config.experiments[self.record].source.clone(),
            parameters: r.parameters.keys().cloned().collect(),
            evaluations: r.evaluations,
            wall_time_s: r.wall_time_s,
            termination: r.termination.0.to_string(),
        }
    }
}

/// Each record's objective as its stage left it (the search's where it ran none),
/// its report objective, and the stages' warnings with the start's.
struct Records {
    parts: Vec<Box<dyn Objective>>,
    reports: Vec<Option<(Stage, Fidelity)>>,
    warnings: Vec<Warning>,
}

/// The [`Records`] of `config`'s experiments, in their order, from `stages`.
fn records(
    config: &Config,
    planned: &Planned,
    stages: Vec<StageRun>,
) -> Result<Records, IdentifyError> {
    let n = config.experiments.len();
    let mut by_record: Vec<Option<StageRun>> = (0..n).map(|_| None).collect();
    for s in stages {
        let e = s.record;
        by_record[e] = Some(s);
    }
    let mut out = Records {
        parts: Vec::with_capacity(n),
        reports: Vec::with_capacity(n),
        warnings: planned.start.warnings.clone(),
    };
    for (spec, stage) in config.experiments.iter().zip(by_record) {
        match stage {
            Some(s) => {
                out.warnings.extend(stage_warnings(&s.identified));
                out.reports.push(Some(s.identified.report));
                out.parts.push(s.identified.objective);
            }
            None => {
                let first = planned.first_fidelity(config);
                let spec = std::slice::from_ref(spec);
                let objective = setup::build(spec, Stage::Search, first)?;
                out.parts.push(Box::new(objective));
                out.reports.push(None);
            }
        }
    }
    Ok(out)
}

/// The records in the order their stages run: rough ones (closed-loop simulations)
/// first, then the smooth ones, each group in the order given; records that
/// determine nothing run no stage.
fn order(planned: &Planned) -> Vec<usize> {
    let n = planned.records.len();
    let owns = |e: &usize| !planned.assignment.owned[*e].is_empty();
    let rough = (0..n).filter(|e| planned.records[*e].rough).filter(owns);
    let smooth = (0..n).filter(|e| !planned.records[*e].rough).filter(owns);
    rough.chain(smooth).collect()
}

/// Warnings of a stage worth keeping for the whole: all but the one that a rough
/// cost's standard errors are lower bounds (the whole says it once).
fn stage_warnings(identified: &Identified) -> Vec<Warning> {
    identified
        .result
        .warnings
        .iter()
        .map(|w| w.0.clone())
        .filter(|w| *w != Warning::RoughCost)
        .collect()
}

/// The joint refinement of `refined` from `current`: one local search on the
/// records' objectives together. Returns its start record and the parameter set at
/// its best point (`current` where it found nothing lower).
fn refine(
    planned: &Planned,
    stacked: &Stacked,
    refined: &[String],
    current: &Params,
    settings: Settings,
    monitor: &Monitor,
) -> Result<(Vec<StartRecord>, Params), IdentifyError> {
    let bounds = planned.bounds(refined);
    let space = ParamSpace::new(current.clone(), refined, &bounds)?;
    monitor.reset_best();
    let here = sum_of_squares(&stacked.residuals(current)?);
    monitor.offer(here, &space.start);
    let starts = search(&space, stacked, &settings, monitor, &[], &|_| {});
    let best = monitor.best().map_or(space.start.clone(), |b| b.values);
    let params = space.params(&best).map_err(ObjectiveError::from)?;
    Ok((starts, params))
}

impl Planned {
    /// The names of the fitted parameters at `indices`.
    fn names(&self, indices: &[usize]) -> Vec<String> {
        indices.iter().map(|&i| self.fit[i].clone()).collect()
    }

    /// The whole fit's bounds of `names` (a stage's default range is the whole fit's,
    /// around the start, not around where an earlier stage left it).
    fn bounds(&self, names: &[String]) -> Vec<(String, Bound)> {
        names
            .iter()
            .map(|n| {
                let i = self.fit.iter().position(|f| f == n).unwrap_or(0);
                (n.clone(), self.space.bounds[i])
            })
            .collect()
    }

    /// The model a record without a stage is evaluated with: the search's.
    fn first_fidelity(&self, config: &Config) -> Fidelity {
        match config.fidelity {
            crate::identify::config::FidelityChoice::Nonlinear => Fidelity::Nonlinear,
            _ => Fidelity::Linear,
        }
    }

    /// Stage `k`'s configuration: record `e` alone, `names` fitted from `current`.
    fn sub_config(
        &self,
        config: &Config,
        e: usize,
        current: &Params,
        names: &[String],
        k: usize,
    ) -> Config {
        Config {
            experiments: vec![config.experiments[e].clone()],
            base: current.clone(),
            fit: names.to_vec(),
            bounds: self.bounds(names),
            checkpoint: config.checkpoint.as_deref().map(|p| stage_checkpoint(p, k)),
            staging: Staging::Joint,
            ..config.clone()
        }
    }

    /// The refinement's search: one start from where the stages left the
    /// parameters; Nelder–Mead with a small simplex where a record's cost is rough at
    /// any step, Levenberg–Marquardt where it is grainy, Gauss–Newton where smooth.
    fn refinement_settings(&self, config: &Config) -> Settings {
        let o = &config.search;
        let rough = self.records.iter().any(|r| r.rough);
        let derivative_free = rough && config.base.topology != crate::model::Topology::DirectDrive;
        let method = o.method.unwrap_or(match (rough, derivative_free) {
            (false, _) => Method::Lsq,
            (true, true) => Method::NelderMead,
            (true, false) => Method::Lm,
        });
        Settings {
            method,
            starts: 1,
            seed: o.seed,
            max_iters: o.max_iters,
            fd_step: match (rough, method) {
                (false, _) => 1e-5,
                (true, Method::Lm) => 3e-2,
                (true, _) => 1e-3,
            },
            max_evaluations: o.max_evaluations,
            simplex_step: SIMPLEX_STEP_NEAR,
        }
    }

    /// Each parameter's shares of information, by record.
    fn shares(&self, config: &Config) -> Vec<(String, Vec<(String, f64)>)> {
        self.fit
            .iter()
            .zip(&self.assignment.shares)
            .map(|(n, s)| {
                let by = config
                    .experiments
                    .iter()
                    .zip(s)
                    .map(|(e, v)| (e.source.clone(), *v))
                    .collect();
                (n.clone(), by)
            })
            .collect()
    }
}

/// Stage `k`'s checkpoint beside the whole's: `fit.ckpt.json` → `fit.ckpt.stage-1.json`.
fn stage_checkpoint(path: &Path, k: usize) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let ext = path
        .extension()
        .map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    path.with_file_name(format!("{stem}.stage-{}{ext}", k + 1))
}

/// How the whole's cost varies: the roughest record's.
pub(crate) fn smoothness(records: &[RecordInformation], config: &Config) -> Smoothness {
    if !records.iter().any(|r| r.rough) {
        Smoothness::Smooth
    } else if config.base.topology != crate::model::Topology::DirectDrive {
        Smoothness::Rough
    } else {
        Smoothness::Grainy
    }
}
