//! Identification (docs/identification.md): parameters from experiment files, in
//! steps — argmin's split, the executor holding the loop mechanics and the policy
//! beside it:
//!
//! 1. [`config`]: what is asked (experiments with weights and objectives, the
//!    parameter set, what to fit, bounds, model, search options, checkpoint, start);
//! 2. [`plan`]: what follows from it and from what the objectives declare — the
//!    fitted parameters, the stages with their solver, starts and steps — pure;
//!    [`setup`] builds the objectives, [`start`] the start values;
//! 3. [`space`]: the fitted parameters in the solvers' bounded coordinates;
//! 4. [`pipeline::stages`]: the multi-start [`search`] ([`search::problem`],
//!    [`search::solvers`]), then with `--model nonlinear` — or `auto` when the
//!    [`pipeline::escalation`] check finds the linear fit off — the
//!    [`pipeline::correction`]s by the nonlinear test, resumable from a
//!    [`pipeline::checkpoint`];
//! 5. [`pipeline::assess`]: residuals, [`intervals::uncertainty`] and typed warnings
//!    at the best point; [`pipeline::assemble`]: the [`result`];
//!    [`pipeline::comparison`]: the fitted model against the data;
//! 6. on request, [`intervals::profile`]: the profile likelihood of fitted
//!    parameters, each point an identification of the others;
//!    [`intervals::resample`]: the residual block bootstrap of the fit, each replicate
//!    the whole search again.
//!
//! Beside the pipeline: [`selection`] (AIC/BIC between results) and [`design`]
//! (candidate tests ranked by the uncertainty they would give).
//!
//! The imports run one way: [`result`] is plain data and imports none of the steps;
//! [`search`] knows nothing of the pipeline; the [`pipeline`] and the [`intervals`]
//! use both; [`run`] drives them in order.
//!
//! Parallelism: starts run in parallel (rayon); inside one cost evaluation the
//! frequencies of a nonlinear frequency response, and the Jacobian's columns, run in
//! parallel too — rayon's work stealing nests them, so two cores stay busy with one
//! start or with eight.

pub mod by_record;
pub mod config;
pub mod design;
pub mod dispatch;
pub mod error;
pub mod intervals;
pub mod pipeline;
pub mod plan;
pub mod result;
pub mod run;
pub mod search;
pub mod selection;
pub mod setup;
pub mod space;
pub mod start;

pub use config::{Config, ExperimentSpec, FidelityChoice, SearchOptions, Staging, StartChoice};
pub use dispatch::identify;
pub use error::IdentifyError;
pub use pipeline::checkpoint::CheckpointError;
pub use result::starts::{StartEstimate, StartRecord};
pub use result::termination::Termination;
pub use result::warning::Warning;
pub use result::IdentifyResult;
pub use run::{Identified, Replay, ReplayStage};
pub use search::problem::{Best, Monitor};
pub use search::settings::Method;
pub use search::settings::Settings;
pub use space::{Bound, ParamSpace, SpaceError};
