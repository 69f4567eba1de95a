//! A servo trace's evaluation: its friction law by IDIM-LS, at the motor where the
//! ratio is known, and on a model its replay with the simulation error — what
//! `rtid evaluate` prints and `rtid.evaluate` returns.

use super::{replay, simulation_error, FitError, Misfit, Replay, ServoTrace, TraceError};
use crate::estimation::inverse_dynamics::{IdimFit, IdimSettings};
use crate::io::experiment_file::{Axis, Experiment};
use crate::model::Params;

/// What the evaluation of a trace finds.
#[derive(Clone, Debug)]
pub struct TraceEvaluation {
    /// M, Fv, Fc, OF of F = M·a + Fv·v + Fc·sign(v) + OF.
    pub fit: IdimFit,
    /// Table turns per motor turn the positions were divided by (the law at the
    /// motor); `None`: as recorded.
    pub ratio: Option<f64>,
    /// The trace replayed on the model, and its simulation error.
    pub replay: Option<(Replay, Misfit)>,
}

/// A trace that cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EvaluateError {
    #[error("`conditions.ratio` is {0}: it must be positive (table turns per motor turn, Rg·Rw)")]
    Ratio(f64),
    #[error("the trace is of a {trace} axis, the parameters (--preset/--params) of a {model} one")]
    Axis { trace: Axis, model: Axis },
    #[error("inverse dynamics: {0}")]
    Fit(#[from] FitError),
    #[error("replay: {0}")]
    Replay(#[from] TraceError),
}

/// Evaluates `trace` (of `exp`, on `axis`) with the IDIM-LS `settings`, and replays
/// it on `model` when one is given.
pub fn evaluate(
    exp: &Experiment,
    (trace, axis): (&ServoTrace, Axis),
    settings: &IdimSettings,
    model: Option<&Params>,
) -> Result<TraceEvaluation, EvaluateError> {
    let ratio = frame_ratio(exp, model)?;
    let fit = match ratio {
        Some(r) => trace.fit_friction_at_motor(r, settings),
        None => trace.fit_friction(settings),
    }?;
    let replay = match model {
        Some(p) if p.axis != axis => {
            return Err(EvaluateError::Axis {
                trace: axis,
                model: p.axis,
            })
        }
        Some(p) => {
            let run = replay(p, trace)?;
            let misfit = simulation_error(trace, &run)?;
            Some((run, misfit))
        }
        None => None,
    };
    Ok(TraceEvaluation { fit, ratio, replay })
}

/// The ratio that takes the trace's (table-side) positions to the motor:
/// `conditions.ratio`, else the model's when it is geared; none for a direct or
/// ungeared axis, or when neither says.
fn frame_ratio(exp: &Experiment, model: Option<&Params>) -> Result<Option<f64>, EvaluateError> {
    if let Some(r) = exp.manifest.conditions.ratio {
        if !(r.is_finite() && r > 0.0) {
            return Err(EvaluateError::Ratio(r));
        }
        return Ok(Some(r));
    }
    Ok(model.map(Params::ratio).filter(|&r| r != 1.0))
}
