//! Objective functions of the identification (docs/model.md, "Identification"): each
//! compares the model with one measured experiment and returns a vector of **scaled
//! residuals** — (model − measured) / (the measurement's typical error) — so that
//! objectives of different units add up in one weighted least-squares cost (χ²-like,
//! ~1 per point at a perfect fit to noisy data). One objective per file, each with its
//! [`Definition`] (name, the experiments it reads, its properties, what it determines,
//! how it is built), listed once in [`registry::REGISTRY`] (the types a definition is made of are
//! [`definition`]'s, apart from the list):
//!
//! - [`resonance`]: relative error of the resonance frequencies;
//! - [`peak_amplitude`]: dB error of the resonance peak heights;
//! - [`gain_curve`]: dB error of the gain at every measured frequency, or only near
//!   the resonances (`gain-near-peaks`);
//! - [`torque_curve`]: error of the motor torque of the closed-loop torque test;
//! - [`unbalance_step`]: error of the table angles where the unbalance test's
//!   deviation steps across the backlash (the table friction ft);
//! - [`friction_map`]: error of the steady-state motor torque at each run of a
//!   friction map (the friction law: Coulomb, Stribeck, viscous, offset);
//! - [`speed_loop`]: complex error of a drive's measured closed speed loop (actual
//!   speed over setpoint) against the model inside its speed controller;
//! - [`joint`]: several of these, weighted, as one.
//!
//! Every objective is a plain `Sync` struct holding the measured data; the simulator
//! is built inside [`Objective::residuals`], so rayon can evaluate it from any thread.
//! Adding an objective is one new file (the struct, its `Objective` impl and its
//! `DEFINITION`) and one line in [`registry::REGISTRY`].

pub mod definition;
pub mod detail;
pub mod frequency_response;
pub mod friction_map;
#[cfg(test)]
pub(crate) mod in_lanes {
    //! For tests: an objective handed its points in batches, as one that runs in the
    //! kernel's lanes is, noting the largest batch.

    use std::sync::atomic::{AtomicUsize, Ordering};

    use super::{Objective, ObjectiveError};
    use crate::model::Params;

    /// `inner`, declared to run in lanes.
    pub(crate) struct InLanes<O> {
        pub inner: O,
        /// The most points one batch held.
        pub largest: AtomicUsize,
    }

    impl<O> InLanes<O> {
        pub fn new(inner: O) -> Self {
            InLanes {
                inner,
                largest: AtomicUsize::new(0),
            }
        }

        pub fn largest(&self) -> usize {
            self.largest.load(Ordering::Relaxed)
        }
    }

    impl<O: Objective> Objective for InLanes<O> {
        fn name(&self) -> &'static str {
            self.inner.name()
        }
        fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
            self.inner.residuals(p)
        }
        fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
            self.largest.fetch_max(points.len(), Ordering::Relaxed);
            self.inner.residuals_batch(points)
        }
        fn in_lanes(&self) -> bool {
            true
        }
        fn len(&self) -> usize {
            self.inner.len()
        }
        fn scale(&self) -> String {
            self.inner.scale()
        }
    }
}
pub mod joint;
pub mod registry;
pub mod servo_trace;
pub mod torque_curve;
pub mod unbalance_step;

use serde::Serialize;

use crate::model::{ParamError, Params};
use crate::sim::SimError;

pub use definition::{Definition, Estimated, ObjectiveKind, SetupError, Source, Stage};
pub use detail::Detail;
pub use frequency_response::{
    complex_response, gain_curve, measured_peaks, model_peaks, peak_amplitude, resonance,
    speed_loop,
};
pub use joint::Joint;

/// What the model's frequency response is computed with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
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

/// How an objective's cost varies with the parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Smoothness {
    /// Smooth on the scale of finite differences (the exact linear response, or a
    /// nonlinear test whose roughness the correction stage averages out).
    Smooth,
    /// A closed-loop replay whose roughness (quantised encoders, a sampled servo)
    /// lies below a few per cent of the parameters: a bowl at the scale of a
    /// Jacobian's difference step of 0.03 solver units, so Levenberg–Marquardt
    /// converges on it (the EMPS servo trace: docs/performance.md); one start,
    /// standard errors that are lower bounds.
    Grainy,
    /// A closed-loop time simulation read through quantised encoders: the cost is
    /// piecewise constant on tiny scales, rough up to the scale of any difference
    /// step, and each evaluation costs seconds — a derivative-free search from one
    /// start, larger difference steps, and standard errors that are lower bounds.
    Rough,
}

/// What an objective declares about itself; the identification's defaults follow
/// from these, not from the experiment kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Properties {
    pub smoothness: Smoothness,
    /// Whether it depends on the frequency-response model ([`Fidelity`]).
    pub frequency_response: bool,
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
    /// The residuals at each of `points`, in order, each what
    /// [`residuals`](Objective::residuals) gives for it; an objective whose model
    /// runs in the kernel's lanes ([`in_lanes`](Objective::in_lanes)) computes them
    /// together.
    fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        points.iter().map(|p| self.residuals(p)).collect()
    }
    /// Whether [`residuals_batch`](Objective::residuals_batch) runs its points in
    /// the kernel's lanes (then the search hands it several points at a time).
    fn in_lanes(&self) -> bool {
        false
    }
    /// The residual count (fixed for a given objective).
    fn len(&self) -> usize;
    /// Whether there is nothing to compare.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// What one unit of scaled residual means, for reports, e.g. `0.1 % of frequency`.
    fn scale(&self) -> String;
    /// Part `i` of an objective whose residuals are its parts' side by side (the
    /// records of a fit by plan), in the order of its residuals; `None` for others.
    fn part(&self, i: usize) -> Option<&dyn Objective> {
        let _ = i;
        None
    }
    /// The residuals `r` (at the parameter set `p`) in the measurement's own units,
    /// for reports.
    fn detail(&self, p: &Params, r: &[f64]) -> Option<Detail> {
        let _ = (p, r);
        None
    }
}

/// How many of `n` points one parallel task evaluates: one, or for an objective
/// that runs in the kernel's lanes up to [`LANES`](crate::sim::LANES) (fewer when
/// that would leave a worker idle).
pub fn points_per_task(objective: &dyn Objective, n: usize) -> usize {
    if objective.in_lanes() {
        n.div_ceil(rayon::current_num_threads())
            .clamp(1, crate::sim::LANES)
    } else {
        1
    }
}

/// The residuals at each of `points`, in order, in parallel ([`points_per_task`]
/// points per task, together where the objective runs in lanes).
pub fn residuals_all(
    objective: &dyn Objective,
    points: &[Params],
) -> Vec<Result<Vec<f64>, ObjectiveError>> {
    use rayon::prelude::*;
    points
        .par_chunks(points_per_task(objective, points.len()))
        .flat_map_iter(|chunk| objective.residuals_batch(chunk))
        .collect()
}

/// Sum of squares of scaled residuals.
pub fn sum_of_squares(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}
