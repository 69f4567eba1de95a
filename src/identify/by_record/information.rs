//! The information each record carries about each fitted parameter, at the start:
//! the Jacobian of the record's share of the joint cost with respect to ln p (central
//! differences, the step the uncertainty takes for that record's objectives: 0.1 on a
//! closed-loop simulation, whose quantised encoders make smaller steps read jitter,
//! 1e-4 on the exact linear response), and its JᵀJ — what `rtid design` predicts
//! standard errors from. A frequency response is measured on its linear response:
//! milliseconds, and the stiffnesses and dampings it determines are the linear
//! model's; backlash and friction, which the linear response does not see, go to the
//! records that do.

use rayon::prelude::*;

use super::assign::RecordInformation;
use crate::identify::config::Config;
use crate::identify::error::IdentifyError;
use crate::identify::intervals::uncertainty::jacobian;
use crate::identify::plan::uncertainty_step;
use crate::identify::setup;
use crate::identify::space::ParamSpace;
use crate::objectives::{Fidelity, Stage};

/// Each of `config`'s experiments' information about the parameters of `space`, at
/// its start.
pub fn measure(
    config: &Config,
    space: &ParamSpace,
) -> Result<Vec<RecordInformation>, IdentifyError> {
    config
        .experiments
        .par_iter()
        .map(|spec| {
            let joint = setup::build(std::slice::from_ref(spec), Stage::Search, Fidelity::Linear)?;
            let rough = joint.rough();
            let step = uncertainty_step(rough, Fidelity::Linear);
            let j = jacobian(space, &joint, &space.start, step)?;
            Ok(RecordInformation {
                label: spec.source.clone(),
                fisher: j.transpose() * &j,
                rough,
            })
        })
        .collect()
}
