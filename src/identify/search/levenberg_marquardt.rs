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
//! If neither does, λ rises [`GROWTH`]-fold and the batch is tried again. It stops:
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
    let mut first = Some(j0);
    let mut lambda = FIRST_DAMPING;
    for iteration in 1..=max_iters {
        problem.monitor.progress().advance(1);
        let j = match first.take() {
            Some(j) => j,
            None => problem.jacobian_at(&at.x, &at.r)?,
        };
        problem.monitor.keep_jacobian(SearchJacobian {
            x: at.x.iter().copied().collect(),
            j: j.clone(),
            step: problem.fd_step,
        });
        let Some((next, won)) = descend(problem, &at, &j, lambda)? else {
            return Ok(done(at, iteration, Termination::Converged));
        };
        let decrease = (at.cost - next.cost) / at.cost;
        at = next;
        lambda = won / 10.0;
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

/// The best trial that lowers the cost from `at` and the damping that gave it, raising
/// the damping [`GROWTH`]-fold after a batch that does not; `None` after
/// [`BATCHES`] such batches.
fn descend(
    problem: &Problem<'_>,
    at: &Point,
    j: &DMatrix<f64>,
    mut lambda: f64,
) -> Result<Option<(Point, f64)>, ObjectiveError> {
    let jtj = j.transpose() * j;
    let g = j.transpose() * DVector::from_column_slice(&at.r);
    let d = damping(&jtj);
    for _ in 0..BATCHES {
        let (points, dampings): (Vec<DVector<f64>>, Vec<f64>) = (0..TRIALS)
            .map(|k| lambda * 10f64.powi(k as i32))
            .filter_map(|l| damped_step(&jtj, &g, &d, l).map(|h| (&at.x + h, l)))
            .unzip();
        let residuals = problem.evaluate_all(&points)?;
        let best = points
            .into_iter()
            .zip(residuals)
            .zip(dampings)
            .map(|((x, r), l)| (Point::new(x, r), l))
            .min_by(|a, b| a.0.cost.total_cmp(&b.0.cost));
        if let Some((p, l)) = best.filter(|(p, _)| p.cost < at.cost) {
            return Ok(Some((p, l)));
        }
        lambda *= GROWTH;
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::search::problem::Monitor;
    use crate::identify::search::settings::Settings;
    use crate::identify::{Bound, ParamSpace};
    use crate::model::{presets, Params};
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

    fn solve(rough: f64, from: [f64; 2]) -> (Vec<f64>, Found, usize) {
        let space = space();
        let monitor = Monitor::default();
        let objective = Valley { rough };
        let settings = Settings {
            fd_step: 1e-3,
            ..Settings::default()
        };
        let problem = Problem::new(&space, &objective, &monitor, &settings);
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
}
