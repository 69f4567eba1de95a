//! One local search from one start, with an argmin solver (`--method`):
//!
//! - `lsq`: Gauss–Newton with a backtracking (Armijo) line search on the scaled
//!   residuals, the Jacobian by forward differences computed in parallel — the
//!   default: a least-squares problem converges in a few iterations;
//! - `nelder-mead`: derivative-free simplex, robust to the noise of nonlinear
//!   simulations;
//! - `pso`: particle swarm over the whole bounded box (global, many evaluations).
//!
//! All run in the bound-respecting solver coordinates of [`crate::identify::space`].

use super::settings::Method;
use std::sync::atomic::{AtomicUsize, Ordering};

use argmin::core::observers::ObserverMode;
use argmin::core::{CostFunction, Executor, State, TerminationReason, TerminationStatus};
use argmin::solver::gaussnewton::GaussNewtonLS;
use argmin::solver::linesearch::{condition::ArmijoCondition, BacktrackingLineSearch};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::ParticleSwarm;
use nalgebra::DVector;
use rand::{rngs::StdRng, SeedableRng};

use crate::identify::result::termination::Termination;
use crate::identify::search::problem::{Problem, SingularJacobian};
use crate::identify::search::progress::CountIterations;
use crate::objectives::ObjectiveError;

/// Iteration limits.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub max_iters: u64,
    /// Nelder–Mead's initial simplex step, solver coordinates.
    pub simplex_step: f64,
    /// Seed of the particle swarm.
    pub seed: u64,
}

/// How one local search ended.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// Solver coordinates of the result (empty: no result).
    pub x: Vec<f64>,
    pub cost: f64,
    pub iterations: u64,
    pub termination: Termination,
}

/// Runs `method` from solver coordinates `x0`.
pub fn run(method: Method, problem: Problem<'_>, x0: DVector<f64>, limits: Limits) -> Outcome {
    let monitor = problem.monitor;
    let count = || CountIterations(monitor.progress_handle());
    let n = x0.len();
    let result = match method {
        Method::Lsq => {
            let ls = BacktrackingLineSearch::new(
                ArmijoCondition::new(1e-4).expect("c = 1e-4 lies in 0 < c < 1"),
            );
            let solver = GaussNewtonLS::new(ls)
                .with_tolerance(1e-10)
                .expect("the tolerance 1e-10 is positive");
            Executor::new(problem, solver)
                .configure(|s| s.param(x0.clone()).max_iters(limits.max_iters))
                .add_observer(count(), ObserverMode::Always)
                .run()
                .map(|r| {
                    // Gauss–Newton's cost is ‖r‖; report Σr² like the other solvers.
                    let (x, c, i, t) = summarize(r.state());
                    (x, c * c, i, t)
                })
        }
        Method::Lm => super::levenberg_marquardt::run(&problem, x0, limits.max_iters)
            .map_err(argmin::core::Error::from),
        Method::NelderMead => {
            let mut simplex = vec![x0.clone()];
            for j in 0..n {
                let mut v = x0.clone();
                // Towards the middle of the solver coordinate's range.
                let step = limits.simplex_step;
                v[j] += if x0[j] > 0.0 { -step } else { step };
                simplex.push(v);
            }
            let solver = NelderMead::new(simplex)
                .with_sd_tolerance(1e-8)
                .expect("the tolerance 1e-8 is positive");
            let problem = SimplexStart {
                problem,
                left: AtomicUsize::new(n + 1),
            };
            Executor::new(problem, solver)
                .configure(|s| s.max_iters(limits.max_iters))
                .add_observer(count(), ObserverMode::Always)
                .run()
                .map(|r| summarize(r.state()))
        }
        Method::Pso => {
            let half = std::f64::consts::FRAC_PI_2;
            let bounds = (
                DVector::from_element(n, -half),
                DVector::from_element(n, half),
            );
            let solver = ParticleSwarm::new(bounds, 10 + 5 * n)
                .with_rng_generator(StdRng::seed_from_u64(limits.seed));
            Executor::new(problem, solver)
                .configure(|s| s.max_iters(limits.max_iters))
                .add_observer(count(), ObserverMode::Always)
                .run()
                .map(|r| {
                    let s = r.state();
                    let x = s
                        .get_best_param()
                        .map(|p| p.position.iter().copied().collect())
                        .unwrap_or_default();
                    (
                        x,
                        s.get_best_cost(),
                        s.get_iter(),
                        reason(s.get_termination_status()),
                    )
                })
        }
    };
    match result {
        Ok((x, cost, iterations, termination)) => Outcome {
            x,
            cost,
            iterations,
            termination,
        },
        Err(e) => Outcome {
            x: Vec::new(),
            cost: f64::INFINITY,
            iterations: 0,
            termination: failure(&e, monitor.stopped()),
        },
    }
}

/// The problem as Nelder–Mead sees it. argmin 0.11's Nelder–Mead unwraps the costs of
/// its starting simplex, so a stop (Ctrl-C, an evaluation budget reached by another
/// start) during those n + 1 evaluations would panic: there an interrupted evaluation
/// costs +∞ instead, and the first evaluation after them reports the interruption.
struct SimplexStart<'a> {
    problem: Problem<'a>,
    /// Evaluations of the starting simplex still to come.
    left: AtomicUsize,
}

impl CostFunction for SimplexStart<'_> {
    type Param = DVector<f64>;
    type Output = f64;

    fn cost(&self, x: &Self::Param) -> Result<f64, argmin::core::Error> {
        let starting = self
            .left
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |k| k.checked_sub(1))
            .is_ok();
        match self.problem.cost(x) {
            Err(_) if starting && self.problem.monitor.stopped() => Ok(f64::INFINITY),
            r => r,
        }
    }
}

/// The termination of a search that ended in an error.
fn failure(e: &argmin::core::Error, stopped: bool) -> Termination {
    if stopped || matches!(e.downcast_ref(), Some(ObjectiveError::Interrupted)) {
        Termination::Interrupted
    } else if e.downcast_ref::<SingularJacobian>().is_some() {
        Termination::Singular
    } else {
        Termination::SolverError {
            message: e.to_string(),
        }
    }
}

fn summarize<S>(s: &S) -> (Vec<f64>, f64, u64, Termination)
where
    S: State<Param = DVector<f64>, Float = f64>,
{
    (
        s.get_best_param()
            .map(|p| p.iter().copied().collect())
            .unwrap_or_default(),
        s.get_best_cost(),
        s.get_iter(),
        reason(s.get_termination_status()),
    )
}

fn reason(t: &TerminationStatus) -> Termination {
    match t {
        TerminationStatus::Terminated(TerminationReason::SolverConverged) => Termination::Converged,
        TerminationStatus::Terminated(TerminationReason::MaxItersReached) => {
            Termination::IterationLimit
        }
        TerminationStatus::Terminated(r) => Termination::Solver {
            reason: r.text().to_string(),
        },
        TerminationStatus::NotTerminated => Termination::Solver {
            reason: "not terminated".into(),
        },
    }
}
