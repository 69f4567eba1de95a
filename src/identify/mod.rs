//! Identification (MODEL.md §6): the fitted parameters ([`space`]), the problem the
//! solvers see ([`problem`]), one local search ([`solvers`]), several starts in
//! parallel ([`search`] here), the uncertainty at the optimum ([`uncertainty`]) and
//! the result and checkpoint files ([`result`]).
//!
//! Parallelism: starts run in parallel (rayon); inside one cost evaluation the
//! frequencies of a nonlinear frequency response, and the Jacobian's columns, run in
//! parallel too — rayon's work stealing nests them, so two cores stay busy with one
//! start or with eight.

pub mod comparison;
pub mod correction;
pub mod problem;
pub mod result;
pub mod run;
pub mod setup;
pub mod solvers;
pub mod space;
pub mod uncertainty;

use rayon::prelude::*;

pub use problem::{Best, Monitor};
pub use run::{identify, Config, FidelityChoice, Identified, IdentifyError};
pub use solvers::Method;
pub use space::{Bound, ParamSpace};

use crate::objectives::Objective;

/// How to search.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub method: Method,
    /// Starts: the given start, then a Latin hypercube in the bounds.
    pub starts: usize,
    pub seed: u64,
    pub max_iters: u64,
    /// Forward-difference step of the Gauss–Newton Jacobian, solver coordinates
    /// (≈ 2× as much in ln p for the default ×100 range).
    pub fd_step: f64,
    /// Stop after this many evaluations in all (None: no limit).
    pub max_evaluations: Option<usize>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            method: Method::Lsq,
            starts: 4,
            seed: 1,
            max_iters: 50,
            fd_step: 1e-5,
            max_evaluations: None,
        }
    }
}

/// One start of a search, as reported and checkpointed.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StartRecord {
    pub index: usize,
    /// Physical start values of the fitted parameters.
    pub initial: Vec<f64>,
    /// Physical result values (`None` if interrupted before a result).
    pub result: Option<Vec<f64>>,
    pub cost: f64,
    pub iterations: u64,
    pub termination: String,
    pub interrupted: bool,
}

impl StartRecord {
    /// A start that ran to its end (not interrupted).
    pub fn finished(&self) -> bool {
        !self.interrupted && self.result.is_some()
    }
}

/// Runs the starts of `settings` (skipping those `done` already holds as finished),
/// in parallel; `on_done` is called after each start (to checkpoint). Returns every
/// start, in index order. The best point of all evaluations is in `monitor`.
pub fn search(
    space: &ParamSpace,
    objective: &dyn Objective,
    settings: &Settings,
    monitor: &Monitor,
    done: &[StartRecord],
    on_done: &(dyn Fn(&StartRecord) + Sync),
) -> Vec<StartRecord> {
    for d in done.iter().filter(|d| d.finished()) {
        if let Some(v) = &d.result {
            monitor.offer(d.cost, v);
        }
    }
    let starts = space.starts(settings.starts, settings.seed);
    let mut records: Vec<StartRecord> = starts
        .into_par_iter()
        .enumerate()
        .map(|(index, initial)| {
            if let Some(d) = done.iter().find(|d| d.index == index && d.finished()) {
                return d.clone();
            }
            // A start interrupted earlier continues from where it had got to.
            let from = done
                .iter()
                .find(|d| d.index == index)
                .and_then(|d| d.result.clone())
                .unwrap_or_else(|| initial.clone());
            let problem = problem::Problem {
                space,
                objective,
                monitor,
                fd_step: settings.fd_step,
                max_evaluations: settings.max_evaluations,
                last: Default::default(),
            };
            let limits = solvers::Limits {
                max_iters: settings.max_iters,
                seed: settings.seed.wrapping_add(index as u64),
            };
            let out = solvers::run(settings.method, problem, space.to_solver(&from), limits);
            let result = (!out.x.is_empty())
                .then(|| space.from_solver(&nalgebra::DVector::from_vec(out.x.clone())));
            let record = StartRecord {
                index,
                initial,
                result,
                cost: out.cost,
                iterations: out.iterations,
                termination: out.termination,
                interrupted: out.interrupted,
            };
            on_done(&record);
            record
        })
        .collect();
    records.sort_by_key(|r| r.index);
    records
}
