//! Identification (docs/identification.md): parameters from experiment files, in
//! steps — argmin's split, the executor holding the loop mechanics and the policy
//! beside it:
//!
//! 1. [`config`]: what is asked (experiments with weights and objectives, the
//!    parameter set, what to fit, bounds, model, search options, checkpoint);
//! 2. [`plan`]: what follows from it and from what the objectives declare — the
//!    fitted parameters, the stages with their solver, starts and steps — pure;
//! 3. [`space`]: the fitted parameters in the solvers' bounded coordinates;
//! 4. [`stages`]: the multi-start [`search`] ([`problem`], [`solvers`]), then with
//!    `--model nonlinear` — or `auto` when the [`escalation`] check finds the linear
//!    fit off — the [`correction`]s by the nonlinear test, resumable from a
//!    [`checkpoint`];
//! 5. [`assess`]: residuals, [`uncertainty`] and typed [`warning`]s at the best point;
//! 6. [`result`]: the result file; [`comparison`]: the fitted model against the data;
//! 7. on request, [`profile`]: the profile likelihood of fitted parameters, each point
//!    an identification of the others; [`resample`]: the residual block bootstrap of
//!    the fit, each replicate the whole search again.
//!
//! Parallelism: starts run in parallel (rayon); inside one cost evaluation the
//! frequencies of a nonlinear frequency response, and the Jacobian's columns, run in
//! parallel too — rayon's work stealing nests them, so two cores stay busy with one
//! start or with eight.

pub mod assess;
pub mod checkpoint;
pub mod comparison;
pub mod config;
pub mod correction;
pub mod design;
pub mod escalation;
pub mod plan;
pub mod problem;
pub mod profile;
pub mod progress;
pub mod resample;
pub mod result;
pub mod run;
pub mod search;
pub mod selection;
pub mod setup;
pub mod solvers;
pub mod space;
pub mod stages;
pub mod start;
pub mod termination;
pub mod uncertainty;
pub mod warning;

pub use checkpoint::CheckpointError;
pub use config::{Config, ExperimentSpec, FidelityChoice, SearchOptions};
pub use problem::{Best, Monitor};
pub use result::IdentifyResult;
pub use run::{identify, Identified};
pub use search::{Settings, StartRecord};
pub use solvers::Method;
pub use space::{Bound, ParamSpace, SpaceError};
pub use start::{StartChoice, StartEstimate};
pub use termination::Termination;
pub use warning::Warning;

use crate::objectives::{ObjectiveError, SetupError};

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
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    #[error("no parameter set could be evaluated: {0}")]
    NothingEvaluated(String),
}
