//! The Levenberg–Marquardt least-squares solver: its damped step, which every
//! least-squares fit of rtid takes, and the whole solver with an analytic Jacobian for
//! a handful of parameters (the friction laws' fits); the identification's search
//! (`identify/search/levenberg_marquardt.rs`) takes the same step with
//! finite-difference Jacobians and trial dampings in parallel (K. Madsen, H. B. Nielsen, O. Tingleff, *Methods for
//! Non-Linear Least Squares Problems*, 2nd ed., DTU 2004, §3.2, with Marquardt's
//! scaling of the damping by the diagonal of JᵀJ).
//!
//! Each iteration solves (JᵀJ + λ·D)·h = −Jᵀr, D = diag(JᵀJ) floored at
//! [`DAMPING_FLOOR`] of its largest element (so that a parameter without effect gets
//! no step rather than a division by zero). A step is taken when it lowers the cost
//! Σr² (to a finite value), and λ falls tenfold; otherwise λ rises tenfold and the
//! step is tried again. It stops when a step lowers the cost by less than
//! `cost_tolerance` of it *and* is shorter than `step_tolerance`·(1 + ‖p‖), when the
//! cost falls below [`EXACT`] (an exact fit), when no step lowers the cost even with λ
//! at [`MAX_DAMPING`] (a minimum to rounding), or after `max_iterations`.

use nalgebra::{DMatrix, DVector};

/// The floor of the damping's diagonal, relative to its largest element.
pub const DAMPING_FLOOR: f64 = 1e-12;
/// λ beyond which no step is tried: the gradient is zero to rounding.
pub const MAX_DAMPING: f64 = 1e16;
/// A cost below which the fit is exact (residuals scaled to order 1).
pub const EXACT: f64 = 1e-28;

/// A least-squares problem: residuals r(p) and their Jacobian ∂r/∂p.
pub trait Problem {
    /// The number of residuals.
    fn residual_count(&self) -> usize;
    /// r(p) into `r`.
    fn residuals(&self, p: &DVector<f64>, r: &mut DVector<f64>);
    /// ∂r/∂p at p into `j` (residuals by parameters).
    fn jacobian(&self, p: &DVector<f64>, j: &mut DMatrix<f64>);
}

/// When to stop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    pub max_iterations: usize,
    /// Relative decrease of the cost below which a step counts as no progress.
    pub cost_tolerance: f64,
    /// Step length below which (relative to 1 + ‖p‖) a step counts as no progress.
    pub step_tolerance: f64,
}

impl Default for Settings {
    /// 500 iterations, relative cost change 1e-12, step 1e-10.
    fn default() -> Self {
        Settings {
            max_iterations: 500,
            cost_tolerance: 1e-12,
            step_tolerance: 1e-10,
        }
    }
}

/// Why the solver stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// The last step changed cost and parameters by less than the tolerances.
    Converged,
    /// The cost is zero to rounding.
    Exact,
    /// No step lowers the cost: a minimum to rounding.
    NoDescent,
    /// The iteration limit came first.
    IterationLimit,
}

/// Where the solver stopped.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    pub p: DVector<f64>,
    /// Σr² at p.
    pub cost: f64,
    /// Iterations (Jacobian evaluations).
    pub iterations: usize,
    pub stop: Stop,
}

impl Outcome {
    /// Whether the solver reached a minimum (every stop but the iteration limit).
    pub fn converged(&self) -> bool {
        self.stop != Stop::IterationLimit
    }
}

/// Minimises Σr(p)² from `start`, whose cost must be finite.
pub fn minimise(problem: &impl Problem, start: DVector<f64>, settings: &Settings) -> Outcome {
    let (m, k) = (problem.residual_count(), start.len());
    let mut p = start;
    let mut r = DVector::zeros(m);
    problem.residuals(&p, &mut r);
    let mut cost = r.norm_squared();
    let mut j = DMatrix::zeros(m, k);
    let mut trial_r = DVector::zeros(m);
    let mut lambda = 1e-3;
    let mut iterations = 0;
    let stop = loop {
        if cost < EXACT {
            break Stop::Exact;
        }
        if iterations == settings.max_iterations {
            break Stop::IterationLimit;
        }
        iterations += 1;
        problem.jacobian(&p, &mut j);
        let jtj = j.transpose() * &j;
        let gradient = j.transpose() * &r;
        let damping = damping(&jtj);
        let taken = loop {
            if lambda > MAX_DAMPING {
                break None;
            }
            if let Some(h) = damped_step(&jtj, &gradient, &damping, lambda) {
                let trial = &p + &h;
                problem.residuals(&trial, &mut trial_r);
                let trial_cost = trial_r.norm_squared();
                if trial_cost.is_finite() && trial_cost < cost {
                    lambda = (lambda / 10.0).max(1e-15);
                    break Some((trial, trial_cost, h.norm()));
                }
            }
            lambda *= 10.0;
        };
        let Some((trial, trial_cost, step)) = taken else {
            break Stop::NoDescent;
        };
        let small_change = cost - trial_cost <= settings.cost_tolerance * cost;
        let small_step = step <= settings.step_tolerance * (1.0 + trial.norm());
        p = trial;
        cost = trial_cost;
        std::mem::swap(&mut r, &mut trial_r);
        if small_change && small_step {
            break Stop::Converged;
        }
    };
    Outcome {
        p,
        cost,
        iterations,
        stop,
    }
}

/// Marquardt's scaling D: JᵀJ's diagonal, floored at [`DAMPING_FLOOR`] of its
/// largest element.
pub(crate) fn damping(jtj: &DMatrix<f64>) -> DVector<f64> {
    let largest = jtj.diagonal().max();
    jtj.diagonal().map(|d| d.max(DAMPING_FLOOR * largest))
}

/// The step h of (JᵀJ + λ·D)·h = −Jᵀr (`gradient` = Jᵀr), if the system is
/// solvable and h finite.
pub(crate) fn damped_step(
    jtj: &DMatrix<f64>,
    gradient: &DVector<f64>,
    damping: &DVector<f64>,
    lambda: f64,
) -> Option<DVector<f64>> {
    let mut a = jtj.clone();
    for i in 0..damping.len() {
        a[(i, i)] += lambda * damping[i];
    }
    a.cholesky()
        .map(|c| c.solve(&(-gradient)))
        .filter(|h| h.iter().all(|x| x.is_finite()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = a·exp(−b·t) + c sampled at t = 0, 0.5, …, 5.5.
    struct Decay {
        t: Vec<f64>,
        y: Vec<f64>,
    }

    impl Problem for Decay {
        fn residual_count(&self) -> usize {
            self.t.len()
        }
        fn residuals(&self, p: &DVector<f64>, r: &mut DVector<f64>) {
            for (i, (&t, &y)) in self.t.iter().zip(&self.y).enumerate() {
                r[i] = p[0] * (-p[1] * t).exp() + p[2] - y;
            }
        }
        fn jacobian(&self, p: &DVector<f64>, j: &mut DMatrix<f64>) {
            for (i, &t) in self.t.iter().enumerate() {
                let e = (-p[1] * t).exp();
                (j[(i, 0)], j[(i, 1)], j[(i, 2)]) = (e, -p[0] * t * e, 1.0);
            }
        }
    }

    fn decay(noise: &[f64]) -> Decay {
        let t: Vec<f64> = (0..12).map(|i| 0.5 * i as f64).collect();
        let y = t
            .iter()
            .zip(noise.iter().cycle())
            .map(|(&t, e)| 2.0 * (-0.7 * t).exp() + 0.3 + e)
            .collect();
        Decay { t, y }
    }

    #[test]
    fn an_exact_decay_is_found_from_far_away() {
        let out = minimise(
            &decay(&[0.0]),
            DVector::from_vec(vec![0.5, 3.0, -1.0]),
            &Settings::default(),
        );
        assert_eq!(out.stop, Stop::Exact, "{out:?}");
        for (got, want) in out.p.iter().zip([2.0, 0.7, 0.3]) {
            assert!((got - want).abs() < 1e-12, "{:?}", out.p);
        }
    }

    /// With noise the minimum has a non-zero cost; there the gradient vanishes and
    /// both stopping tolerances are met.
    #[test]
    fn a_noisy_decay_stops_at_a_stationary_point() {
        let problem = decay(&[0.01, -0.02, 0.015, -0.005, 0.0]);
        let out = minimise(
            &problem,
            DVector::from_vec(vec![1.0, 1.0, 0.0]),
            &Settings::default(),
        );
        assert!(out.converged() && out.stop != Stop::Exact, "{out:?}");
        assert!(out.iterations < 100, "{}", out.iterations);
        let mut j = DMatrix::zeros(12, 3);
        let mut r = DVector::zeros(12);
        problem.jacobian(&out.p, &mut j);
        problem.residuals(&out.p, &mut r);
        // A step below 1e-10·(1 + ‖p‖) ≈ 2e-10 leaves a gradient of at most ‖JᵀJ‖ ≈ 20
        // times that.
        let gradient = j.transpose() * r;
        assert!(gradient.norm() < 5e-9, "{gradient}");
        assert!((out.p[1] - 0.7).abs() < 0.05, "{:?}", out.p);
    }

    #[test]
    fn the_iteration_limit_is_reported() {
        let settings = Settings {
            max_iterations: 2,
            ..Settings::default()
        };
        let out = minimise(
            &decay(&[0.01, -0.02]),
            DVector::from_vec(vec![0.5, 3.0, -1.0]),
            &settings,
        );
        assert_eq!((out.stop, out.iterations), (Stop::IterationLimit, 2));
        assert!(!out.converged());
    }
}
