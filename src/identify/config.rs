//! What one identification is asked to do: the experiments (each with its weight and,
//! optionally, its objectives), the parameter set, what to fit within which bounds,
//! the frequency-response model, the search options and the checkpoint.

use std::path::PathBuf;

use crate::identify::search::settings::Method;
use crate::identify::space::Bound;
use crate::io::experiment_file::Experiment;
use crate::model::Params;
use crate::objectives::ObjectiveKind;

/// The weights an experiment may have: relative, 1 by default. Beyond, the weighted
/// residuals of the others vanish beside it, or its own overflow (a weight of 1e308
/// made every cost infinite and the search never stop).
pub const WEIGHTS: std::ops::RangeInclusive<f64> = 1e-6..=1e6;

/// One experiment of an identification.
#[derive(Clone, Debug)]
pub struct ExperimentSpec {
    /// Where it came from (its file), for reports.
    pub source: String,
    pub experiment: Experiment,
    /// Its weight in the joint cost (default 1; within [`WEIGHTS`]).
    pub weight: f64,
    /// The objectives it feeds (`None`: the defaults of its kind).
    pub objectives: Option<Vec<ObjectiveKind>>,
}

impl ExperimentSpec {
    /// `experiment` from `source`, weight 1, default objectives.
    pub fn new(source: impl Into<String>, experiment: Experiment) -> Self {
        ExperimentSpec {
            source: source.into(),
            experiment,
            weight: 1.0,
            objectives: None,
        }
    }
}

/// Which frequency-response model the objectives use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FidelityChoice {
    /// The linear response for the search, then the nonlinear virtual test at the
    /// result as a check of the linearisation (a warning if it moves the peaks).
    Auto,
    /// The linear response only.
    Linear,
    /// The linear response for every start, then corrections of that fit by the
    /// nonlinear virtual test.
    Nonlinear,
}

/// How to search; `None` fields follow from the objectives ([`crate::identify::plan`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchOptions {
    /// The solver (default: Gauss–Newton; Nelder–Mead when an objective is rough).
    pub method: Option<Method>,
    /// Starts: the given start, then a Latin hypercube in the bounds (default 4; 1
    /// when an objective is rough: each evaluation is seconds of simulation).
    pub starts: Option<usize>,
    pub seed: u64,
    /// Iteration limit of each local search.
    pub max_iters: u64,
    /// Stop after this many evaluations in all (None: no limit).
    pub max_evaluations: Option<usize>,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            method: None,
            starts: None,
            seed: 1,
            max_iters: 50,
            max_evaluations: None,
        }
    }
}

/// Everything one identification needs.
#[derive(Clone, Debug)]
pub struct Config {
    pub experiments: Vec<ExperimentSpec>,
    pub base: Params,
    /// Fitted names (empty: what the objectives determine).
    pub fit: Vec<String>,
    pub bounds: Vec<(String, Bound)>,
    pub fidelity: FidelityChoice,
    pub search: SearchOptions,
    /// Checkpoint file, written after every finished start.
    pub checkpoint: Option<PathBuf>,
    /// Continue from the checkpoint.
    pub resume: bool,
    /// Where the search starts: at an experiment's direct estimate (default) or the
    /// given values.
    pub start: StartChoice,
    /// How several experiments are fitted: each parameter first from the record that
    /// determines it, then jointly (default), or all at once on their joint cost.
    pub staging: Staging,
}

/// How an identification of several experiments proceeds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Staging {
    /// By plan ([`crate::identify::by_record`]): each parameter from the record that
    /// carries the most information about it, the others held, then the parameters
    /// whose information the records share refined jointly.
    #[default]
    ByRecord,
    /// Every fitted parameter on the joint cost of every experiment at once.
    Joint,
}

impl Config {
    /// `fit` from `experiments` on `base`, everything else at its default (default
    /// bounds and objectives, weights 1, the auto model, [`SearchOptions::default`],
    /// no checkpoint, the start at a direct estimate where there is one).
    pub fn new(experiments: Vec<ExperimentSpec>, base: Params, fit: &[&str]) -> Config {
        Config {
            experiments,
            base,
            fit: fit.iter().map(|s| s.to_string()).collect(),
            bounds: Vec::new(),
            fidelity: FidelityChoice::Auto,
            search: SearchOptions::default(),
            checkpoint: None,
            resume: false,
            start: StartChoice::default(),
            staging: Staging::default(),
        }
    }

    /// Every experiment feeds these objectives (instead of its kind's defaults).
    pub fn with_objectives(mut self, objectives: &[ObjectiveKind]) -> Config {
        for e in &mut self.experiments {
            e.objectives = Some(objectives.to_vec());
        }
        self
    }
}

/// Where to start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum StartChoice {
    /// At the direct estimate where an experiment offers one, else the given values.
    #[default]
    Estimate,
    /// At the given parameter set's values.
    Given,
}
