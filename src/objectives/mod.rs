//! Objective functions of the identification (MODEL.md §6): each compares the model
//! with one measured experiment and returns a vector of **scaled residuals** —
//! (model − measured) / (the measurement's typical error) — so that objectives of
//! different units add up in one weighted least-squares cost (χ²-like, ~1 per point
//! at a perfect fit to noisy data). One objective per file:
//!
//! - [`resonance`]: relative error of the resonance frequencies;
//! - [`peak_amplitude`]: dB error of the resonance peak heights;
//! - [`gain_curve`]: dB error of the whole gain curve at the measured frequencies;
//! - [`torque_curve`]: error of the motor torque of the closed-loop torque test;
//! - [`unbalance_step`]: error of the table angles where the unbalance test's
//!   deviation steps across the backlash (the table friction ft);
//! - [`joint`]: several of these, weighted, as one.
//!
//! Every objective is a plain `Sync` struct holding the measured data; the simulator
//! is built inside [`Objective::residuals`], so rayon can evaluate it from any thread.
//! Each also implements argmin's [`CostFunction`] over a parameter set ([`Params`]):
//! the cost is the sum of squared scaled residuals.

pub mod gain_curve;
pub mod joint;
pub mod model_peaks;
pub mod peak_amplitude;
pub mod resonance;
pub mod torque_curve;
pub mod unbalance_step;

use crate::model::{ParamError, Params};
use crate::sim::SimError;

pub use joint::Joint;

/// What the model's frequency response is computed with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// The exact linear response solved in the frequency domain, with damping (no
    /// backlash, no friction): microseconds per frequency, smooth in the parameters.
    Linear,
    /// The nonlinear time simulation of the virtual frequency-response test at the
    /// experiment's conditions (amplitude, preload): what the rig measures.
    Nonlinear,
}

impl Fidelity {
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Linear => "linear",
            Fidelity::Nonlinear => "nonlinear",
        }
    }
}

/// Why an objective could not be evaluated.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum ObjectiveError {
    #[error(transparent)]
    Param(#[from] ParamError),
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error("{what}: {reason}")]
    Data { what: String, reason: String },
    #[error("interrupted")]
    Interrupted,
}

/// One comparison of the model with measured data.
pub trait Objective: Sync + Send {
    /// Short name, e.g. `resonance`.
    fn name(&self) -> &'static str;
    /// Scaled residuals (model − measured) / scale, for the parameter set `p`.
    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError>;
    /// The residual count (fixed for a given objective).
    fn len(&self) -> usize;
    /// Whether there is nothing to compare.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// What one unit of scaled residual means, for reports, e.g. `0.1 % of frequency`.
    fn scale(&self) -> String;
    /// The residuals `r` in the measurement's own units, for reports (e.g. the
    /// resonance misses in Hz).
    fn detail(&self, r: &[f64]) -> Option<serde_json::Value> {
        let _ = r;
        None
    }
}

/// Sum of squares of scaled residuals.
pub fn sum_of_squares(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// Implements argmin's `CostFunction` over [`Params`] for an objective type.
macro_rules! cost_function {
    ($t:ty) => {
        impl argmin::core::CostFunction for $t {
            type Param = $crate::model::Params;
            type Output = f64;
            fn cost(&self, p: &Self::Param) -> Result<f64, argmin::core::Error> {
                Ok($crate::objectives::sum_of_squares(
                    &$crate::objectives::Objective::residuals(self, p)?,
                ))
            }
        }
    };
}
pub(crate) use cost_function;
