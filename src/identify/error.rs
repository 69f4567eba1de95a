//! Why an identification could not run.

use crate::identify::pipeline::checkpoint::CheckpointError;
use crate::identify::space::SpaceError;
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
