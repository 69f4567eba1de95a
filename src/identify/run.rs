//! A whole identification: objectives from the experiments, the search (in one or
//! two stages), the uncertainty, the result. The command line and the tests both
//! come through [`identify`].
//!
//! **Stages.** With `Fidelity` auto and a measured gain curve among the experiments,
//! the search runs twice: first every start on the exact linear frequency response
//! (fast and smooth: it finds the basin), then one Gauss–Newton polish on the
//! nonlinear virtual test at the experiment's conditions (what the rig measured,
//! backlash and friction included). Otherwise one stage at the chosen fidelity.

use std::path::PathBuf;
use std::time::Instant;

use super::result::{bounds_map, Checkpoint, ExperimentResidual, IdentifyResult, NonlinearCheck};
use super::setup::{
    build, build_with, default_fit, has_frequency_response, ObjectiveKind, SetupError,
};
use super::space::{Bound, ParamSpace, SpaceError};
use super::uncertainty::{with_residuals, Uncertainty};
use super::{search, Monitor, Settings, StartRecord};
use crate::io::experiment_file::Experiment;
use crate::model::Params;
use crate::objectives::{sum_of_squares, Fidelity, Joint, Objective, ObjectiveError};

/// Which frequency-response model the objectives use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FidelityChoice {
    /// The linear response for the search, then the nonlinear virtual test at the
    /// result as a check of the linearisation (a warning if it moves the peaks).
    Auto,
    /// The linear response only.
    Linear,
    /// The linear response for every start, then a Gauss–Newton polish of the best
    /// on the nonlinear virtual test.
    Nonlinear,
}

/// Everything one identification needs.
pub struct Config {
    /// (file name, experiment).
    pub experiments: Vec<(String, Experiment)>,
    pub base: Params,
    /// Fitted names (empty: the default for the experiments).
    pub fit: Vec<String>,
    pub bounds: Vec<(String, Bound)>,
    pub objectives: Option<Vec<ObjectiveKind>>,
    pub weights: Vec<f64>,
    pub fidelity: FidelityChoice,
    pub settings: Settings,
    /// Checkpoint file, written after every finished start.
    pub checkpoint: Option<PathBuf>,
    /// Continue from the checkpoint.
    pub resume: bool,
}

impl Config {
    /// `fit` from `experiments` on `base`, everything else at its default (default
    /// bounds and objectives, weights 1, `--model auto`, [`Settings::default`], no
    /// checkpoint).
    pub fn new(experiments: Vec<(String, Experiment)>, base: Params, fit: &[&str]) -> Config {
        Config {
            experiments,
            base,
            fit: fit.iter().map(|s| s.to_string()).collect(),
            bounds: Vec::new(),
            objectives: None,
            weights: Vec::new(),
            fidelity: FidelityChoice::Auto,
            settings: Settings::default(),
            checkpoint: None,
            resume: false,
        }
    }
}

/// Why an identification could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IdentifyError {
    #[error(transparent)]
    Setup(#[from] SetupError),
    #[error(transparent)]
    Space(#[from] SpaceError),
    #[error(transparent)]
    Objective(#[from] ObjectiveError),
    #[error("checkpoint {0}")]
    Checkpoint(String),
    #[error("no parameter set could be evaluated: {0}")]
    NothingEvaluated(String),
}

/// The identified parameters and the complete parameter set.
pub struct Identified {
    pub result: IdentifyResult,
    pub params: Params,
}

struct Stage {
    fidelity: Fidelity,
    settings: Settings,
}

/// Runs the identification. `monitor` carries the stop flag (Ctrl-C) and the count
/// of evaluations; stopping it ends the search early with the best point so far.
pub fn identify(config: &Config, monitor: &Monitor) -> Result<Identified, IdentifyError> {
    let clock = Instant::now();
    let fit = if config.fit.is_empty() {
        default_fit(&config.experiments, &config.base)
    } else {
        config.fit.clone()
    };
    let space0 = ParamSpace::new(config.base.clone(), &fit, &config.bounds)?;
    let has_fr = has_frequency_response(&config.experiments);
    // A closed-loop time simulation in the objective (torque curve, unbalance test):
    // quantised encoders make its cost piecewise constant on tiny scales, so
    // differences need larger steps.
    let simulated = config.experiments.iter().any(|(_, e)| {
        use crate::io::experiment_file::Kind;
        matches!(e.manifest.kind, Kind::TorqueCurve | Kind::Unbalance)
    });
    let two_stage = config.fidelity == FidelityChoice::Nonlinear && has_fr;
    let mut stages = Vec::new();
    let first = match config.fidelity {
        FidelityChoice::Nonlinear if !has_fr => Fidelity::Nonlinear,
        _ => Fidelity::Linear,
    };
    stages.push(Stage {
        fidelity: first,
        settings: Settings {
            fd_step: if first == Fidelity::Linear && !simulated {
                1e-5
            } else {
                1e-3
            },
            ..config.settings
        },
    });
    if two_stage {
        stages.push(Stage {
            fidelity: Fidelity::Nonlinear,
            // The settings of the linear sub-searches of the corrections.
            settings: Settings {
                method: super::Method::Lsq,
                starts: 1,
                max_iters: 50,
                fd_step: if simulated { 1e-3 } else { 1e-5 },
                ..config.settings
            },
        });
    }
    let fingerprint = fingerprint(config, &space0, two_stage);
    let mut checkpoint = Checkpoint {
        problem: fingerprint.clone(),
        stage: 0,
        starts: Vec::new(),
        stage0_best: None,
        evaluations: 0,
    };
    if config.resume {
        let path = config
            .checkpoint
            .as_ref()
            .ok_or_else(|| IdentifyError::Checkpoint("--resume needs --checkpoint FILE".into()))?;
        if path.exists() {
            let c = Checkpoint::read(path).map_err(IdentifyError::Checkpoint)?;
            if c.problem != fingerprint {
                return Err(IdentifyError::Checkpoint(format!(
                    "{} belongs to another problem (experiments, --fit, --bound, --method, --starts or --seed differ)",
                    path.display()
                )));
            }
            monitor.add_evaluations(c.evaluations);
            checkpoint = c;
        }
    }

    let mut space = space0.clone();
    let mut all_starts: Vec<StartRecord> = Vec::new();
    let mut objective: Option<Joint> = None;
    let mut last_fidelity = first;
    let mut notes: Vec<String> = Vec::new();
    for (k, stage) in stages.iter().enumerate() {
        if k < checkpoint.stage {
            // Finished before the resume.
            if let Some(v) = &checkpoint.stage0_best {
                space = space_from(&space0, v);
            }
            continue;
        }
        if k > 0 {
            let Some(best) = monitor.best() else { break };
            if monitor.stopped() {
                break;
            }
            checkpoint.stage0_best = Some(best.values.clone());
            checkpoint.stage = k;
            checkpoint.starts.clear();
            space = space_from(&space0, &best.values);
            monitor.reset_best();
        }
        let defaults = if k > 0 {
            super::setup::default_nonlinear_objectives
        } else {
            super::setup::default_objectives
        };
        let joint = build_with(
            &config.experiments,
            config.objectives.as_deref(),
            &config.weights,
            stage.fidelity,
            defaults,
        )?;
        let mut stage_settings = stage.settings;
        if stage_settings.method == super::Method::Lsq && joint.len() < space.dim() {
            // Gauss–Newton needs JᵀJ invertible: fewer residuals than parameters
            // never give that.
            stage_settings.method = super::Method::NelderMead;
            stage_settings.max_iters = stage_settings.max_iters.max(400);
            notes.push(format!(
                "{} residuals for {} parameters: Gauss–Newton cannot run (JᵀJ singular), Nelder–Mead used instead",
                joint.len(),
                space.dim()
            ));
        }
        if k > 0 {
            // The nonlinear stage: corrections of the linear fit (see `correction`).
            let linear = build_with(
                &config.experiments,
                config.objectives.as_deref(),
                &config.weights,
                Fidelity::Linear,
                defaults,
            )?;
            let out = super::correction::polish(
                &space0,
                &linear,
                &joint,
                &space.start,
                &stage_settings,
                monitor,
            )?;
            all_starts = vec![out.record];
            objective = Some(joint);
            last_fidelity = stage.fidelity;
            continue;
        }
        let done = checkpoint.starts.clone();
        let saved = std::sync::Mutex::new(checkpoint.clone());
        let on_done = |r: &StartRecord| {
            if let (Some(path), Ok(mut c)) = (&config.checkpoint, saved.lock()) {
                c.starts.retain(|s| s.index != r.index);
                c.starts.push(r.clone());
                c.evaluations = monitor.evaluations();
                let _ = c.write(path);
            }
        };
        let starts = search(&space, &joint, &stage_settings, monitor, &done, &on_done);
        checkpoint = saved.into_inner().unwrap_or(checkpoint);
        all_starts = starts;
        objective = Some(joint);
        last_fidelity = stage.fidelity;
    }
    let joint = match objective {
        Some(j) => j,
        None => build(
            &config.experiments,
            config.objectives.as_deref(),
            &config.weights,
            last_fidelity,
        )?,
    };
    let best = monitor.best().ok_or_else(|| {
        IdentifyError::NothingEvaluated(monitor.failure().unwrap_or_else(|| "interrupted".into()))
    })?;
    let params = space0.params(&best.values).map_err(ObjectiveError::from)?;
    let interrupted = monitor.stopped();
    if let Some(path) = &config.checkpoint {
        checkpoint.evaluations = monitor.evaluations();
        if let Err(e) = checkpoint.write(path) {
            notes.push(format!(
                "the checkpoint {} could not be written: {e}",
                path.display()
            ));
        }
    }

    let mut warnings = notes;
    if interrupted {
        warnings.push(format!(
            "the search was stopped after {} evaluations: this is the best point found so far, not a converged fit (--resume continues it)",
            monitor.evaluations()
        ));
    }
    if let Some(f) = monitor.failure() {
        warnings.push(format!(
            "some trial parameter sets could not be evaluated, e.g. {f}"
        ));
    }
    // Distinct optima of (nearly) the same cost: the data do not pick one.
    for s in &all_starts {
        let Some(v) = &s.result else { continue };
        let far = v
            .iter()
            .zip(&best.values)
            .any(|(a, b)| ((a - b) / b).abs() > 0.05);
        if far && s.cost <= best.cost.max(1e-6) * 1.5 + 1e-6 {
            warnings.push(format!(
                "start {} ended at a different solution ({}) with the same cost: the data do not determine a unique solution",
                s.index + 1,
                super::problem::describe(&space0, v)
            ));
        }
    }
    for (name, side) in space0.at_bounds(&best.values) {
        warnings.push(format!(
            "{name} ended at its {side} bound: the data pull it further — widen --bound {name}=LO..HI, or another parameter (fixed now) must change"
        ));
    }
    // One evaluation at the result serves the report, the cost and the uncertainty.
    let parts = joint.part_residuals(&params)?;
    let stacked = joint.stack(&parts);
    let cost = sum_of_squares(&stacked);
    let residuals = residual_report(&joint, parts);
    for r in &residuals {
        if let Some(miss) = r
            .detail
            .as_ref()
            .and_then(|d| d.get("max_miss_hz"))
            .and_then(|v| v.as_f64())
        {
            if miss > 1.0 {
                warnings.push(format!(
                    "{}: the fitted model misses the measured resonances by up to {miss:.1} Hz — the fitted parameters alone cannot reach them",
                    r.source
                ));
            }
        }
    }
    let uncertainty: Option<Uncertainty> = if interrupted {
        None
    } else {
        let step = uncertainty_step(simulated, last_fidelity);
        let u = with_residuals(&space0, &joint, &best.values, &stacked, step)?;
        warnings.extend(u.warnings.iter().cloned());
        if simulated {
            warnings.push(ROUGH_COST.into());
        }
        Some(u)
    };
    let nonlinear_check = if config.fidelity == FidelityChoice::Auto && has_fr && !interrupted {
        let checks = nonlinear_check(config, &params)?;
        for c in &checks {
            let worst = c
                .model_hz
                .iter()
                .zip(&c.measured_hz)
                .map(|(m, f)| ((m - f) / f).abs())
                .fold(
                    0.0,
                    |a: f64, b| if b.is_nan() { f64::INFINITY } else { a.max(b) },
                );
            if worst > 1e-2 {
                warnings.push(format!(
                    "{}: fitted on the linear response, but the nonlinear virtual test at the measured conditions puts the resonances at {} Hz (measured {} Hz): a shift of up to {:.2} Hz (over 1 %): backlash or friction bias the linear fit — use --model nonlinear (slower), or a preloaded test",
                    c.source,
                    fmt_hz(&c.model_hz),
                    fmt_hz(&c.measured_hz),
                    c.max_miss_hz
                ));
            }
        }
        Some(checks)
    } else {
        None
    };
    let termination = if interrupted {
        "interrupted".to_string()
    } else {
        all_starts
            .iter()
            .min_by(|a, b| a.cost.total_cmp(&b.cost))
            .map_or_else(|| "no start ran".into(), |s| s.termination.clone())
    };
    let names: Vec<&str> = space0.names.to_vec();
    let result = IdentifyResult {
        mechanism: config.base.name.clone(),
        experiments: config.experiments.iter().map(|(f, _)| f.clone()).collect(),
        parameters: names
            .iter()
            .map(|n| n.to_string())
            .zip(best.values.iter().copied())
            .collect(),
        initial: names
            .iter()
            .map(|n| n.to_string())
            .zip(space0.start.iter().copied())
            .collect(),
        bounds: bounds_map(&names, &space0.bounds),
        method: config.settings.method.name().into(),
        fidelity: if frequency_dependent(&config.experiments) {
            stages
                .iter()
                .map(|s| s.fidelity.name())
                .collect::<Vec<_>>()
                .join(", then ")
        } else {
            // Torque curves and the like: always a time simulation.
            "nonlinear time simulation".into()
        },
        cost,
        residuals,
        evaluations: monitor.evaluations(),
        wall_time_s: clock.elapsed().as_secs_f64(),
        termination,
        interrupted,
        starts: all_starts,
        uncertainty,
        nonlinear_check,
        warnings,
    };
    Ok(Identified { result, params })
}

/// Said with every fit of a closed-loop simulation: its standard errors see only the
/// residuals' scatter, not the roughness of the cost surface, which on noise-free
/// data dominates (the worm torque-curve fixture: fm −1.8 % off with a standard error
/// of 0.1 %; the cost is exactly 0 at the truth and ≥ 0.12 a few per cent around it).
const ROUGH_COST: &str = "the standard errors of a fit to a closed-loop simulation (torque curve, unbalance test) count the residuals' scatter only: the quantised encoders make the cost rough, and on clean data that roughness, not the scatter, sets the error (fm −1.8 % against a 0.1 % standard error on the worm fixture) — read them as lower bounds";

/// The central-difference step (in ln p) of the Jacobian behind the standard errors
/// and correlations. It must be larger than the scale on which the cost is rough, or
/// the Jacobian's columns are that roughness and the warnings say nothing: with a
/// closed-loop time simulation (torque curve, unbalance) the quantised encoders'
/// jitter fills the columns at steps below ~0.1 — at 2e-3 the torque curve's fm–fw
/// correlation reads −0.04, at 0.1 −0.89, at 0.3 −0.98 (the physics: fm and fw·Rg add
/// up) — and the nonlinear frequency response varies irregularly by ±0.03 dB near a
/// friction-flattened peak, which a 2 % step (a 1 % shift of the peak, ~0.7 dB on its
/// flanks) rises well above. The exact linear response is smooth: 1e-4.
fn uncertainty_step(simulated: bool, fidelity: Fidelity) -> f64 {
    if simulated {
        0.1
    } else if fidelity == Fidelity::Nonlinear {
        2e-2
    } else {
        1e-4
    }
}

/// Whether any experiment feeds a frequency-response objective, for which the
/// fidelity (linear or nonlinear response) means something.
fn frequency_dependent(experiments: &[(String, Experiment)]) -> bool {
    use crate::io::experiment_file::Kind;
    experiments
        .iter()
        .any(|(_, e)| matches!(e.manifest.kind, Kind::FrequencyResponse | Kind::Resonance))
}

fn space_from(space0: &ParamSpace, values: &[f64]) -> ParamSpace {
    let mut s = space0.clone();
    s.start = values.to_vec();
    s
}

/// Identity of a problem for checkpoints.
fn fingerprint(config: &Config, space: &ParamSpace, two_stage: bool) -> String {
    format!(
        "{:?}|{:?}|{:?}|{:?}|{:?}|{}|{}|{}|{:?}|{}",
        config
            .experiments
            .iter()
            .map(|(f, _)| f)
            .collect::<Vec<_>>(),
        space.names,
        space
            .bounds
            .iter()
            .map(|b| (b.lo, b.hi))
            .collect::<Vec<_>>(),
        space.start,
        config.objectives,
        config.settings.method.name(),
        config.settings.starts,
        config.settings.seed,
        config.weights,
        two_stage
    )
}

/// Each part's residuals at the result (`parts`, from [`Joint::part_residuals`]),
/// with the resonance misses in Hz.
fn residual_report(joint: &Joint, parts: Vec<Vec<f64>>) -> Vec<ExperimentResidual> {
    joint
        .parts
        .iter()
        .zip(parts)
        .map(|(part, r)| {
            let rms = (sum_of_squares(&r) / r.len().max(1) as f64).sqrt();
            let detail = part.objective.detail(&r);
            ExperimentResidual {
                source: part.source.clone(),
                objective: part.objective.name().into(),
                weight: part.weight,
                scale: part.objective.scale(),
                residuals: r,
                rms,
                detail,
            }
        })
        .collect()
}

/// The measured resonances against those of the nonlinear virtual test at the
/// identified parameters, per frequency-response experiment — like for like: the
/// test is simulated at the measured frequencies near each measured peak and its peak
/// located as the measurement's was
/// ([`crate::objectives::model_peaks::nonlinear_peak_on_grid`]), so that at the true
/// parameters it reproduces the measurement exactly and a difference is the
/// linearisation's bias.
fn nonlinear_check(config: &Config, p: &Params) -> Result<Vec<NonlinearCheck>, IdentifyError> {
    use crate::objectives::model_peaks::nonlinear_peak_on_grid;
    let mut out = Vec::new();
    for (file, exp) in &config.experiments {
        let Some(grid) = super::setup::measured_grid(exp) else {
            continue;
        };
        let measured: Vec<f64> = super::setup::measured_peaks(file, exp)?
            .iter()
            .map(|pk| pk.frequency_hz)
            .collect();
        let test = super::setup::frequency_test(exp);
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
            source: file.clone(),
            measured_hz: measured,
            model_hz: model,
            max_miss_hz,
        });
    }
    Ok(out)
}

fn fmt_hz(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.2}"))
        .collect::<Vec<_>>()
        .join(", ")
}
