//! The optimisation problem the solvers see: solver coordinates → parameter set →
//! scaled residuals of the objective. It implements argmin's `CostFunction` (sum of
//! squares, for Nelder–Mead and particle swarm), `Operator` (the residual vector) and
//! `Jacobian` (forward differences, one column per rayon task) for Gauss–Newton.
//!
//! Every evaluation goes through a shared [`Monitor`]: it counts evaluations, keeps
//! the best point seen (so an interrupted search still has a result), and carries the
//! stop flag that Ctrl-C sets — the next evaluation then returns an error, which ends
//! the solver. A parameter set the model rejects, or a simulation that diverges,
//! counts as a very bad point (residuals of [`PENALTY`]), not as a failure of the
//! search; the first such error is kept for the report.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use argmin::core::{CostFunction, Error, Jacobian, Operator, SendAlias, SyncAlias};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::identify::search::progress::Progress;
use crate::identify::search::settings::Settings;
use crate::identify::space::ParamSpace;
use crate::objectives::{points_per_task, sum_of_squares, Objective, ObjectiveError};
use crate::sim::batch::on_valid;
use crate::sim::LANES;

/// Residuals at points, and the Jacobian at one of them if asked for.
type WithJacobian = (Vec<Vec<f64>>, Option<DMatrix<f64>>);

/// The scaled residual given to every entry at a point the model cannot evaluate.
pub const PENALTY: f64 = 1e6;

/// The best point seen.
#[derive(Clone, Debug, PartialEq)]
pub struct Best {
    pub cost: f64,
    /// Physical values of the fitted parameters.
    pub values: Vec<f64>,
}

/// A forward-difference Jacobian a search took (solver coordinates).
#[derive(Clone, Debug)]
pub(crate) struct SearchJacobian {
    /// Where, in solver coordinates.
    pub x: Vec<f64>,
    pub j: DMatrix<f64>,
    /// The difference step, solver units.
    pub step: f64,
}

/// Shared bookkeeping of a search.
#[derive(Default)]
pub struct Monitor {
    evaluations: AtomicUsize,
    best: Mutex<Option<Best>>,
    jacobian: Mutex<Option<SearchJacobian>>,
    failure: Mutex<Option<String>>,
    stop: AtomicBool,
    progress: Arc<Progress>,
}

impl Monitor {
    /// The searches' iterations done of their budget.
    pub fn progress(&self) -> &Progress {
        &self.progress
    }

    /// A handle on the progress for a solver's observer.
    pub(crate) fn progress_handle(&self) -> Arc<Progress> {
        Arc::clone(&self.progress)
    }

    pub fn evaluations(&self) -> usize {
        self.evaluations.load(Ordering::Relaxed)
    }

    /// Adds evaluations done elsewhere (a resumed checkpoint).
    pub(crate) fn add_evaluations(&self, n: usize) {
        self.evaluations.fetch_add(n, Ordering::Relaxed);
    }

    pub fn best(&self) -> Option<Best> {
        self.best.lock().map(|b| b.clone()).unwrap_or(None)
    }

    /// Offers a point; kept if it is the best so far.
    pub(crate) fn offer(&self, cost: f64, values: &[f64]) {
        if let Ok(mut b) = self.best.lock() {
            if cost.is_finite() && b.as_ref().map_or(true, |b| cost < b.cost) {
                *b = Some(Best {
                    cost,
                    values: values.to_vec(),
                });
            }
        }
    }

    /// Forgets the best point (between stages whose costs differ in kind), and the
    /// last Jacobian.
    pub(crate) fn reset_best(&self) {
        if let Ok(mut b) = self.best.lock() {
            *b = None;
        }
        if let Ok(mut j) = self.jacobian.lock() {
            *j = None;
        }
    }

    /// Keeps the last Jacobian a search took (Levenberg–Marquardt), for the
    /// uncertainty at its result.
    pub(crate) fn keep_jacobian(&self, jacobian: SearchJacobian) {
        if let Ok(mut j) = self.jacobian.lock() {
            *j = Some(jacobian);
        }
    }

    /// The last Jacobian kept.
    pub(crate) fn jacobian(&self) -> Option<SearchJacobian> {
        self.jacobian.lock().map(|j| j.clone()).unwrap_or(None)
    }

    /// The first evaluation error (an invalid parameter set, a diverged simulation).
    pub fn failure(&self) -> Option<String> {
        self.failure.lock().map(|f| f.clone()).unwrap_or(None)
    }

    /// Asks every running solver to stop at its next evaluation.
    pub fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    pub fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// An evaluation budget: stop after `n` evaluations (for tests of the interrupt
    /// path and for `--max-evaluations`).
    pub(crate) fn check_budget(&self, limit: Option<usize>) {
        if limit.is_some_and(|n| self.evaluations() >= n) {
            self.stop();
        }
    }
}

/// The Jacobian's JᵀJ is singular at a point: Gauss–Newton cannot take a step there
/// (the residuals do not depend on every parameter). Returned by the Jacobian, so the
/// solver's error says so by type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("JᵀJ is singular at this point")]
pub struct SingularJacobian;

/// The problem of one start.
pub struct Problem<'a> {
    pub space: &'a ParamSpace,
    pub objective: &'a dyn Objective,
    pub monitor: &'a Monitor,
    /// Forward-difference step in solver coordinates.
    pub fd_step: f64,
    /// Stop after this many evaluations in all.
    pub max_evaluations: Option<usize>,
    /// The last point evaluated and its residuals: Gauss–Newton asks for the
    /// residuals and then the Jacobian at the same point.
    last: Mutex<Option<(DVector<f64>, Vec<f64>)>>,
}

impl<'a> Problem<'a> {
    /// The problem of one start of a search with `settings`.
    pub fn new(
        space: &'a ParamSpace,
        objective: &'a dyn Objective,
        monitor: &'a Monitor,
        settings: &Settings,
    ) -> Self {
        Problem {
            space,
            objective,
            monitor,
            fd_step: settings.fd_step,
            max_evaluations: settings.max_evaluations,
            last: Mutex::new(None),
        }
    }

    /// Scaled residuals at solver coordinates `x`.
    pub fn residuals(&self, x: &DVector<f64>) -> Result<Vec<f64>, ObjectiveError> {
        if let Ok(last) = self.last.lock() {
            if let Some((lx, lr)) = last.as_ref() {
                if lx == x {
                    return Ok(lr.clone());
                }
            }
        }
        let r = self.evaluate(x)?;
        if let Ok(mut last) = self.last.lock() {
            *last = Some((x.clone(), r.clone()));
        }
        Ok(r)
    }

    fn evaluate(&self, x: &DVector<f64>) -> Result<Vec<f64>, ObjectiveError> {
        let mut one = self.evaluate_batch(std::slice::from_ref(x))?;
        Ok(one.pop().expect("one point, one result"))
    }

    /// The residuals at each of `xs`, the points' models run together where the
    /// objective can ([`Objective::residuals_batch`]).
    fn evaluate_batch(&self, xs: &[DVector<f64>]) -> Result<Vec<Vec<f64>>, ObjectiveError> {
        self.monitor.check_budget(self.max_evaluations);
        if self.monitor.stopped() {
            return Err(ObjectiveError::Interrupted);
        }
        let values: Vec<Vec<f64>> = xs.iter().map(|x| self.space.physical(x)).collect();
        let sets = values
            .iter()
            .map(|v| self.space.params(v).map_err(ObjectiveError::from))
            .collect();
        let results = on_valid(sets, |sets| self.objective.residuals_batch(sets));
        results
            .into_iter()
            .zip(&values)
            .map(|(r, values)| self.settle(r, values))
            .collect()
    }

    /// Counts an evaluation at `values` and turns its result `r` into residuals: a
    /// non-finite or failed one into the penalty (the first failure kept for the
    /// report), an interruption into an error.
    fn settle(
        &self,
        r: Result<Vec<f64>, ObjectiveError>,
        values: &[f64],
    ) -> Result<Vec<f64>, ObjectiveError> {
        self.monitor.evaluations.fetch_add(1, Ordering::Relaxed);
        match r {
            Ok(r) if r.iter().all(|v| v.is_finite()) => {
                self.monitor.offer(sum_of_squares(&r), values);
                Ok(r)
            }
            Ok(_) => Ok(vec![PENALTY; self.objective.len()]),
            Err(ObjectiveError::Interrupted) => Err(ObjectiveError::Interrupted),
            Err(e) => {
                if let Ok(mut f) = self.monitor.failure.lock() {
                    f.get_or_insert_with(|| format!("{} at {}", e, describe(self.space, values)));
                }
                Ok(vec![PENALTY; self.objective.len()])
            }
        }
    }

    /// The residuals at each of `points`, in parallel: one point per task, or, for
    /// an objective that runs in lanes, up to `LANES` points per task (fewer when
    /// that would leave a worker idle).
    pub(crate) fn evaluate_all(
        &self,
        points: &[DVector<f64>],
    ) -> Result<Vec<Vec<f64>>, ObjectiveError> {
        let per_task = points_per_task(self.objective, points.len());
        let batches: Vec<Vec<Vec<f64>>> = points
            .par_chunks(per_task)
            .map(|xs| self.evaluate_batch(xs))
            .collect::<Result<_, _>>()?;
        Ok(batches.into_iter().flatten().collect())
    }

    /// Whether `n` points take one batch per worker: an objective that runs in
    /// lanes, at most [`LANES`] points per worker. Up to there a point added costs a
    /// lane of a batch that runs anyway, not a batch of its own.
    pub(crate) fn one_round(&self, n: usize) -> bool {
        self.objective.in_lanes() && n <= LANES * rayon::current_num_threads()
    }

    /// Forward-difference Jacobian of the residuals in solver coordinates, the columns
    /// in parallel; `r0` are the residuals at `x`.
    pub(crate) fn jacobian_at(
        &self,
        x: &DVector<f64>,
        r0: &[f64],
    ) -> Result<DMatrix<f64>, ObjectiveError> {
        let columns = self.evaluate_all(&self.shifted(x))?;
        Ok(self.differences(r0, &columns))
    }

    /// The residuals at `x` and their forward-difference Jacobian there, evaluated
    /// together (one batch, `x` with its shifted points): for a search that starts
    /// from a point it has not evaluated.
    pub(crate) fn residuals_and_jacobian(
        &self,
        x: &DVector<f64>,
    ) -> Result<(Vec<f64>, DMatrix<f64>), ObjectiveError> {
        let (mut r, j) = self.evaluate_with_jacobian(std::slice::from_ref(x), Some(0))?;
        let j = j.expect("a Jacobian asked for");
        Ok((r.pop().expect("the point's own residuals"), j))
    }

    /// The residuals at each of `points` and, where `at` names one of them, the
    /// forward-difference Jacobian there: its shifted points evaluated in the same
    /// batch.
    pub(crate) fn evaluate_with_jacobian(
        &self,
        points: &[DVector<f64>],
        at: Option<usize>,
    ) -> Result<WithJacobian, ObjectiveError> {
        let mut all = points.to_vec();
        if let Some(k) = at {
            all.extend(self.shifted(&points[k]));
        }
        let mut residuals = self.evaluate_all(&all)?;
        let columns = residuals.split_off(points.len());
        let j = at.map(|k| self.differences(&residuals[k], &columns));
        Ok((residuals, j))
    }

    /// `x` shifted by the difference step along each coordinate.
    fn shifted(&self, x: &DVector<f64>) -> Vec<DVector<f64>> {
        (0..x.len())
            .map(|j| {
                let mut xj = x.clone();
                xj[j] += self.fd_step;
                xj
            })
            .collect()
    }

    /// The Jacobian from the residuals `r0` at a point and `columns[j]` at the
    /// point shifted along coordinate j.
    fn differences(&self, r0: &[f64], columns: &[Vec<f64>]) -> DMatrix<f64> {
        let h = self.fd_step;
        DMatrix::from_fn(r0.len(), columns.len(), |i, j| (columns[j][i] - r0[i]) / h)
    }
}

/// `Kw = 3.1e5, Kg = 850` for messages.
pub fn describe(space: &ParamSpace, values: &[f64]) -> String {
    space
        .names
        .iter()
        .zip(values)
        .map(|(n, v)| format!("{n} = {v:.6e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

impl CostFunction for Problem<'_> {
    type Param = DVector<f64>;
    type Output = f64;

    fn cost(&self, x: &Self::Param) -> Result<f64, Error> {
        Ok(sum_of_squares(&self.residuals(x)?))
    }

    /// A swarm's particles, evaluated in parallel and, where the objective runs in
    /// lanes, in lane batches ([`Problem::evaluate_all`]): argmin's own bulk cost
    /// evaluates them one after another without its `rayon` feature.
    fn bulk_cost<P>(&self, params: &[P]) -> Result<Vec<f64>, Error>
    where
        P: std::borrow::Borrow<Self::Param> + SyncAlias,
        f64: SendAlias,
        Self: SyncAlias,
    {
        let points: Vec<DVector<f64>> = params.iter().map(|p| p.borrow().clone()).collect();
        let residuals = self.evaluate_all(&points)?;
        Ok(residuals.iter().map(|r| sum_of_squares(r)).collect())
    }
}

impl Operator for Problem<'_> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;

    fn apply(&self, x: &Self::Param) -> Result<Self::Output, Error> {
        Ok(DVector::from_vec(self.residuals(x)?))
    }
}

impl Jacobian for Problem<'_> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;

    fn jacobian(&self, x: &Self::Param) -> Result<Self::Jacobian, Error> {
        let r0 = self.residuals(x)?;
        let j = self.jacobian_at(x, &r0)?;
        if (j.transpose() * &j).try_inverse().is_none() {
            return Err(SingularJacobian.into());
        }
        Ok(j)
    }
}
