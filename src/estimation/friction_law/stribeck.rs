//! The Stribeck laws by Levenberg–Marquardt, in scaled coordinates: efforts divided
//! by the efforts' RMS Tₑ, speeds by the speeds' RMS Vₑ, vs and delta in log space
//! (which keeps them positive):
//!
//! ```text
//! effort  F  = Tₑ·p            (Fc, Fs, Fo)
//! viscous Fv = (Tₑ/Vₑ)·p
//! speed   vs = Vₑ·exp(p)
//! delta      = exp(p)
//! ```
//!
//! and the residuals (law − effort)/Tₑ, of order 1 whatever the units.
//!
//! Starts: the Coulomb law's fit (Fc, Fv, Fo — per direction for the asymmetric law),
//! Fs the Coulomb-corrected effort of the runs at the lowest speed, vs the geometric
//! mean of the lowest and highest speed, delta = 1 and delta = 2; the better of the
//! two fits is kept.

use nalgebra::{DMatrix, DVector};

use super::law::{Law, Quantity};
use super::linear;
use super::map::{distinct_speeds, Direction};
use crate::estimation::least_squares::{self as lm, Problem};

/// The starting values of delta.
pub const DELTA_STARTS: [f64; 2] = [1.0, 2.0];

/// A Stribeck law's fit: the values (in the law's order), the iterations of the kept
/// start, and whether it converged.
pub(super) struct Fitted {
    pub values: Vec<f64>,
    pub iterations: usize,
    pub converged: bool,
}

/// Fits a Stribeck `law` to a map that passed the checks, with at least 3 distinct
/// speeds per direction.
pub(super) fn fit(law: Law, speed: &[f64], effort: &[f64]) -> Fitted {
    let problem = Scaled::new(law, speed, effort);
    let settings = lm::Settings::default();
    let outcomes = DELTA_STARTS.map(|delta| {
        let start = problem.to_internal(&start(law, speed, effort, delta));
        lm::minimise(&problem, start, &settings)
    });
    let [first, second] = outcomes;
    let best = if second.cost < first.cost {
        second
    } else {
        first
    };
    Fitted {
        values: problem.to_reported(&best.p),
        iterations: best.iterations,
        converged: best.converged(),
    }
}

/// The starting values of `law` with `delta`.
fn start(law: Law, speed: &[f64], effort: &[f64], delta: f64) -> Vec<f64> {
    let runs = || speed.iter().zip(effort);
    // The runs in `direction` at its lowest speed, and the geometric mean of its
    // lowest and highest speed.
    let lowest = |direction: Direction| {
        let u = distinct_speeds(speed, direction);
        let (low, high) = (u[0], u[u.len() - 1]);
        let at_low =
            move |v: f64| Direction::of(v) == direction && (v.abs() - low).abs() <= 1e-9 * low;
        (at_low, (low * high).sqrt())
    };
    let (pos, vs_pos) = lowest(Direction::Positive);
    let (neg, vs_neg) = lowest(Direction::Negative);
    let mean = |values: Vec<f64>| values.iter().sum::<f64>() / values.len() as f64;
    match law {
        Law::Stribeck => {
            let c = linear::fit(Law::Coulomb, speed, effort);
            let (fc, fv, fo) = (c[0], c[1], c[2]);
            let fs = mean(
                runs()
                    .filter(|(&v, _)| pos(v) || neg(v))
                    .map(|(&v, &e)| v.signum() * (e - fv * v - fo))
                    .collect(),
            );
            let u = speed.iter().map(|v| v.abs());
            let (low, high) = (
                u.clone().fold(f64::INFINITY, f64::min),
                u.fold(0.0, f64::max),
            );
            let vs = (low * high).sqrt();
            vec![fc, fs, vs, delta, fv, fo]
        }
        Law::StribeckAsymmetric => {
            let c = linear::fit(Law::CoulombAsymmetric, speed, effort);
            let (fv_pos, fv_neg) = (c[1], c[3]);
            let fs_pos = mean(
                runs()
                    .filter(|(&v, _)| pos(v))
                    .map(|(&v, &e)| e - fv_pos * v)
                    .collect(),
            );
            let fs_neg = mean(
                runs()
                    .filter(|(&v, _)| neg(v))
                    .map(|(&v, &e)| fv_neg * v - e)
                    .collect(),
            );
            vec![
                c[0], fs_pos, vs_pos, fv_pos, c[2], fs_neg, vs_neg, fv_neg, delta,
            ]
        }
        Law::Coulomb | Law::CoulombAsymmetric => unreachable!("a linear law"),
    }
}

/// The scaled least-squares problem of a law over a map.
struct Scaled<'a> {
    law: Law,
    speed: &'a [f64],
    effort: &'a [f64],
    /// The efforts' and the speeds' RMS.
    effort_scale: f64,
    speed_scale: f64,
}

impl<'a> Scaled<'a> {
    fn new(law: Law, speed: &'a [f64], effort: &'a [f64]) -> Self {
        let rms = |x: &[f64]| (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
        Scaled {
            law,
            speed,
            effort,
            effort_scale: rms(effort),
            speed_scale: rms(speed),
        }
    }

    fn to_internal(&self, values: &[f64]) -> DVector<f64> {
        let (te, ve) = (self.effort_scale, self.speed_scale);
        DVector::from_iterator(
            values.len(),
            values
                .iter()
                .zip(self.law.quantities())
                .map(|(&x, q)| match q {
                    Quantity::Effort => x / te,
                    Quantity::Viscous => x * ve / te,
                    Quantity::Speed => (x / ve).ln(),
                    Quantity::Exponent => x.ln(),
                }),
        )
    }

    fn to_reported(&self, p: &DVector<f64>) -> Vec<f64> {
        let (te, ve) = (self.effort_scale, self.speed_scale);
        p.iter()
            .zip(self.law.quantities())
            .map(|(&x, q)| match q {
                Quantity::Effort => x * te,
                Quantity::Viscous => x * te / ve,
                Quantity::Speed => ve * x.exp(),
                Quantity::Exponent => x.exp(),
            })
            .collect()
    }
}

impl Problem for Scaled<'_> {
    fn residual_count(&self) -> usize {
        self.speed.len()
    }

    fn residuals(&self, p: &DVector<f64>, r: &mut DVector<f64>) {
        let values = self.to_reported(p);
        for (i, (&v, &e)) in self.speed.iter().zip(self.effort).enumerate() {
            r[i] = (self.law.evaluate(&values, v) - e) / self.effort_scale;
        }
    }

    fn jacobian(&self, p: &DVector<f64>, j: &mut DMatrix<f64>) {
        let values = self.to_reported(p);
        let (te, ve) = (self.effort_scale, self.speed_scale);
        // dθ/dp of each parameter, over Tₑ.
        let chain: Vec<f64> = values
            .iter()
            .zip(self.law.quantities())
            .map(|(&x, q)| match q {
                Quantity::Effort => 1.0,
                Quantity::Viscous => 1.0 / ve,
                Quantity::Speed | Quantity::Exponent => x / te,
            })
            .collect();
        let mut g = vec![0.0; values.len()];
        for (i, &v) in self.speed.iter().enumerate() {
            self.law.gradient(&values, v, &mut g);
            for (c, (gc, f)) in g.iter().zip(&chain).enumerate() {
                j[(i, c)] = gc * f;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scaled Jacobian against central differences of the scaled residuals.
    #[test]
    fn the_scaled_jacobian_matches_finite_differences() {
        let speed = [-20.0, -5.0, -1.0, -0.2, 0.2, 1.0, 5.0, 20.0];
        for (law, values) in [
            (Law::Stribeck, vec![2e-3, 3.5e-3, 1.5, 1.3, 1e-4, 2e-4]),
            (
                Law::StribeckAsymmetric,
                vec![2e-3, 3e-3, 1.2, 1e-4, 1.5e-3, 3.5e-3, 2.0, 1.2e-4, 1.4],
            ),
        ] {
            let effort: Vec<f64> = speed
                .iter()
                .map(|&v| law.evaluate(&values, v) * 1.01)
                .collect();
            let problem = Scaled::new(law, &speed, &effort);
            let p = problem.to_internal(&values);
            let back = problem.to_reported(&p);
            for (b, v) in back.iter().zip(&values) {
                assert!((b / v - 1.0).abs() < 1e-14);
            }
            let mut j = DMatrix::zeros(speed.len(), p.len());
            problem.jacobian(&p, &mut j);
            let (mut up, mut down) = (DVector::zeros(speed.len()), DVector::zeros(speed.len()));
            for c in 0..p.len() {
                let h = 1e-6;
                let (mut pu, mut pd) = (p.clone(), p.clone());
                pu[c] += h;
                pd[c] -= h;
                problem.residuals(&pu, &mut up);
                problem.residuals(&pd, &mut down);
                for i in 0..speed.len() {
                    let fd = (up[i] - down[i]) / (2.0 * h);
                    assert!(
                        (fd - j[(i, c)]).abs() < 1e-7 * (1.0 + j[(i, c)].abs()),
                        "{law} column {c} row {i}: {} vs {fd}",
                        j[(i, c)]
                    );
                }
            }
        }
    }
}
