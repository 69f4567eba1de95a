//! Levenberg–Marquardt on the scaled residuals, for costs that are rough only below a
//! few per cent of the parameters ([`crate::objectives::Smoothness::Grainy`]: a servo
//! trace's replay, its quantised encoder and sampled servo) — a bowl at the scale of
//! the Jacobian's forward-difference step. Nelder–Mead throws away that the residuals
//! are a vector and spends one replay of the record per evaluation, stopping at its
//! iteration limit; here each iteration costs a Jacobian, its columns in parallel,
//! and one batch of trial steps, also in parallel. (On torque curves and unbalance
//! tests, rough at any step, it stops above Nelder–Mead's cost: they keep Nelder–Mead,
//! docs/identification.md.)
//!
//! Each iteration solves (JᵀJ + λ·D)·h = −Jᵀr, D = diag(JᵀJ) floored (Marquardt's
//! scaling; the damped step of the one least-squares solver,
//! [`crate::estimation::least_squares`], which fits the friction laws), for [`TRIALS`] dampings λ and 10λ at once, and takes the trial of
//! lower cost if it lowers the cost; λ then becomes a tenth of the damping that won.
//! If neither does, λ rises [`GROWTH`]-fold and the batch is tried again. Where the
//! linear model predicts a step that will not end the search, the batch also holds
//! the Jacobian's points at the trial likeliest to win ([`ahead`]): when it wins, the
//! next iteration starts without a batch of its own. That changes when points are
//! evaluated, never which are taken. It stops:
//! - converged, when a step lowered the cost by less than [`COST_TOLERANCE`] of it;
//! - converged, when [`BATCHES`] batches lower it nowhere: a minimum to the cost's
//!   roughness;
//! - at the iteration limit.

use nalgebra::{DMatrix, DVector};

use crate::estimation::least_squares::{damped_step, damping};
use crate::identify::result::termination::Termination;
use crate::identify::search::problem::{Problem, SearchJacobian};
use crate::objectives::{sum_of_squares, ObjectiveError};

/// The first damping.
const FIRST_DAMPING: f64 = 1e-3;
/// Dampings tried at once, λ and 10λ: two cores evaluate them in the time of one.
const TRIALS: usize = 2;
/// Batches of trials before a point counts as a minimum, and the damping's growth
/// between them: λ, 10λ, then 1000λ, 10⁴λ — a step that short is inside the cost's
/// roughness.
const BATCHES: usize = 2;
const GROWTH: f64 = 1e3;
/// A step that lowers the cost by less than this fraction of it is no progress. (A
/// step length is no test on a rough cost: short steps there still lower it.) On the
/// EMPS trace the step after one of 3e-4 finds no descent: at 1e-4 the search costs
/// 21 replays instead of 13 and ends at the same point.
pub const COST_TOLERANCE: f64 = 1e-3;

/// Where a search is: the point, its residuals and cost.
struct Point {
    x: DVector<f64>,
    r: Vec<f64>,
    cost: f64,
}

impl Point {
    fn new(x: DVector<f64>, r: Vec<f64>) -> Point {
        let cost = sum_of_squares(&r);
        Point { x, r, cost }
    }
}

/// The result: solver coordinates, cost Σr², iterations and why it stopped.
pub(crate) type Found = (Vec<f64>, f64, u64, Termination);

/// Runs Levenberg–Marquardt from solver coordinates `x0` for at most `max_iters`
/// iterations; each iteration done advances the search's progress by one.
pub(crate) fn run(
    problem: &Problem<'_>,
    x0: DVector<f64>,
    max_iters: u64,
) -> Result<Found, ObjectiveError> {
    if max_iters == 0 {
        let r0 = problem.residuals(&x0)?;
        return Ok(done(Point::new(x0, r0), 0, Termination::IterationLimit));
    }
    // The start's residuals with its Jacobian's columns: one batch.
    let (r0, j0) = problem.residuals_and_jacobian(&x0)?;
    let mut at = Point::new(x0, r0);
    // The Jacobian at `at`, where a batch has evaluated it already.
    let mut ready = Some(j0);
    let mut lambda = FIRST_DAMPING;
    for iteration in 1..=max_iters {
        problem.monitor.progress().advance(1);
        let j = match ready.take() {
            Some(j) => j,
            None => problem.jacobian_at(&at.x, &at.r)?,
        };
        problem.monitor.keep_jacobian(SearchJacobian {
            x: at.x.iter().copied().collect(),
            j: j.clone(),
            step: problem.fd_step,
        });
        let Some(step) = descend(problem, &at, &j, lambda)? else {
            return Ok(done(at, iteration, Termination::Converged));
        };
        let decrease = (at.cost - step.point.cost) / at.cost;
        at = step.point;
        lambda = step.damping / 10.0;
        ready = step.jacobian;
        if decrease < COST_TOLERANCE {
            return Ok(done(at, iteration, Termination::Converged));
        }
    }
    Ok(done(at, max_iters, Termination::IterationLimit))
}

fn done(at: Point, iterations: u64, termination: Termination) -> Found {
    (
        at.x.iter().copied().collect(),
        at.cost,
        iterations,
        termination,
    )
}

/// A step taken: the trial point, the damping that gave it and, where its batch
/// evaluated it, the Jacobian there.
struct Step {
    point: Point,
    damping: f64,
    jacobian: Option<DMatrix<f64>>,
}

/// The best trial that lowers the cost from `at`, raising the damping
/// [`GROWTH`]-fold after a batch that does not; `None` after [`BATCHES`] such
/// batches.
fn descend(
    problem: &Problem<'_>,
    at: &Point,
    j: &DMatrix<f64>,
    mut lambda: f64,
) -> Result<Option<Step>, ObjectiveError> {
    let jtj = j.transpose() * j;
    let r = DVector::from_column_slice(&at.r);
    let g = j.transpose() * &r;
    let d = damping(&jtj);
    for _ in 0..BATCHES {
        let (steps, dampings): (Vec<DVector<f64>>, Vec<f64>) = (0..TRIALS)
            .map(|k| lambda * 10f64.powi(k as i32))
            .filter_map(|l| damped_step(&jtj, &g, &d, l).map(|h| (h, l)))
            .unzip();
        let predicted: Vec<f64> = steps
            .iter()
            .map(|h| (at.cost - (j * h + &r).norm_squared()) / at.cost)
            .collect();
        let points: Vec<DVector<f64>> = steps.iter().map(|h| &at.x + h).collect();
        let ahead = ahead(&predicted).filter(|_| problem.one_round(points.len() + at.x.len()));
        let (residuals, jacobian) = problem.evaluate_with_jacobian(&points, ahead)?;
        let best = points
            .into_iter()
            .zip(residuals)
            .map(|(x, r)| Point::new(x, r))
            .enumerate()
            .min_by(|a, b| a.1.cost.total_cmp(&b.1.cost));
        if let Some((k, point)) = best.filter(|(_, p)| p.cost < at.cost) {
            return Ok(Some(Step {
                point,
                damping: dampings[k],
                jacobian: jacobian.filter(|_| ahead == Some(k)),
            }));
        }
        lambda *= GROWTH;
    }
    Ok(None)
}

/// Predicted decreases within this fraction of the largest count as one: the
/// damping barely moves the linear model's prediction.
const LEVEL: f64 = 0.01;

/// Which trial's Jacobian to evaluate with the batch, from the linear model's
/// predicted relative decrease of each trial (in order of rising damping): none
/// where the largest is below [`COST_TOLERANCE`] — a step that ends the search,
/// whose Jacobian would go unused — else the most damped trial predicted within
/// [`LEVEL`] of the largest decrease. Where the damping barely moves the
/// prediction, the shorter step is the likelier winner, the model's error growing
/// with the step's length (EMPS's first iteration: 1.535 % and 1.532 % predicted,
/// 1.470 % and 1.528 % found).
fn ahead(predicted: &[f64]) -> Option<usize> {
    // (f64::max passes over NaN: predictions that are all NaN leave −∞.)
    let top = predicted.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if top < COST_TOLERANCE {
        return None;
    }
    predicted
        .iter()
        .rposition(|&p| p >= top - LEVEL * top.abs())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::search::problem::Monitor;
    use crate::identify::search::settings::Settings;
    use crate::identify::{Bound, ParamSpace};
    use crate::model::{presets, Params};
    use crate::objectives::in_lanes::InLanes;
    use crate::objectives::Objective;

    /// Rosenbrock's valley in Kw and Kg (scaled to 3e5 and 900) with rounding noise
    /// of `rough` on each residual: a curved valley, rough at small scales.
    struct Valley {
        rough: f64,
    }

    impl Objective for Valley {
        fn name(&self) -> &'static str {
            "valley"
        }
        fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
            let (a, b) = (p.kw / 3e5, p.kg.unwrap_or(0.0) / 900.0);
            let q = |v: f64| match self.rough {
                0.0 => v,
                s => (v / s).round() * s,
            };
            Ok(vec![q(10.0 * (b - a * a)), q(1.0 - a)])
        }
        fn len(&self) -> usize {
            2
        }
        fn scale(&self) -> String {
            String::new()
        }
    }

    fn space() -> ParamSpace {
        let base = presets::load("worm-gear").unwrap();
        let names = ["Kw".to_string(), "Kg".to_string()];
        let bounds = [
            ("Kw".to_string(), Bound { lo: 3e4, hi: 3e6 }),
            ("Kg".to_string(), Bound { lo: 90.0, hi: 9e3 }),
        ];
        ParamSpace::new(base, &names, &bounds).unwrap()
    }

    fn settings() -> Settings {
        Settings {
            fd_step: 1e-3,
            ..Settings::default()
        }
    }

    fn solve(rough: f64, from: [f64; 2]) -> (Vec<f64>, Found, usize) {
        solve_with(&Valley { rough }, from)
    }

    fn solve_with(objective: &dyn Objective, from: [f64; 2]) -> (Vec<f64>, Found, usize) {
        let space = space();
        let monitor = Monitor::default();
        let problem = Problem::new(&space, objective, &monitor, &settings());
        let found = run(&problem, space.to_solver(&from), 200).unwrap();
        let values = space.physical(&DVector::from_vec(found.0.clone()));
        (values, found, monitor.evaluations())
    }

    #[test]
    fn a_curved_valley_is_followed_to_its_minimum() {
        let (v, (_, cost, iterations, stop), evaluations) = solve(0.0, [1.5e5, 2e3]);
        assert_eq!(stop, Termination::Converged, "{iterations} iterations");
        assert!(
            (v[0] / 3e5 - 1.0).abs() < 1e-3 && (v[1] / 900.0 - 1.0).abs() < 2e-3,
            "{v:?}"
        );
        assert!(cost < 1e-6, "{cost}");
        // Each iteration: one Jacobian (two columns) and one batch of trials.
        assert!(
            evaluations <= 1 + iterations as usize * (2 + 3 * 3),
            "{evaluations}"
        );
    }

    #[test]
    fn a_rough_cost_ends_converged_at_its_roughness_not_the_iteration_limit() {
        let (v, (_, _, iterations, stop), _) = solve(1e-6, [2.4e5, 500.0]);
        assert_eq!(stop, Termination::Converged, "{iterations} iterations");
        assert!(iterations < 200);
        assert!((v[0] / 3e5 - 1.0).abs() < 1e-3, "{v:?}");
    }

    /// In lanes, a batch of trials also evaluates the Jacobian at the trial
    /// [`ahead`] names; where that trial wins, the Jacobian handed on is the one the
    /// next iteration would have taken, bit for bit — so the search takes the same
    /// points, and ends at the same point, as without lanes.
    #[test]
    fn the_jacobian_taken_ahead_is_the_one_the_next_iteration_takes() {
        let space = space();
        let monitor = Monitor::default();
        let objective = InLanes::new(Valley { rough: 0.0 });
        let problem = Problem::new(&space, &objective, &monitor, &settings());
        let (r0, j0) = problem
            .residuals_and_jacobian(&space.to_solver(&[1.5e5, 2e3]))
            .unwrap();
        let mut at = Point::new(space.to_solver(&[1.5e5, 2e3]), r0);
        let (mut j, mut lambda, mut ahead_taken) = (j0, FIRST_DAMPING, 0);
        while let Some(step) = descend(&problem, &at, &j, lambda).unwrap() {
            let next = problem.jacobian_at(&step.point.x, &step.point.r).unwrap();
            if let Some(kept) = &step.jacobian {
                assert_eq!(*kept, next);
                ahead_taken += 1;
            }
            (at, j, lambda) = (step.point, next, step.damping / 10.0);
        }
        assert!(ahead_taken > 0, "no trial's Jacobian was taken ahead");
        let plain = solve(0.0, [1.5e5, 2e3]);
        let lanes = solve_with(&objective, [1.5e5, 2e3]);
        assert_eq!((plain.0, plain.1), (lanes.0, lanes.1));
    }

    #[test]
    fn the_jacobian_ahead_is_the_most_damped_trial_near_the_best_prediction() {
        assert_eq!(ahead(&[0.015350, 0.015316]), Some(1));
        assert_eq!(ahead(&[0.5384, 0.1431]), Some(0));
        assert_eq!(ahead(&[0.10, 0.25]), Some(1));
        // A step that ends the search: no Jacobian ahead.
        assert_eq!(ahead(&[5.3e-4, 5.2e-4]), None);
        assert_eq!(ahead(&[]), None);
        assert_eq!(ahead(&[f64::NAN, f64::NAN]), None);
    }
}
