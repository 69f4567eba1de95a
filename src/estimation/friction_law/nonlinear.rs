//! A nonlinear law ([`MapLaw::is_linear`] false, the Stribeck laws) by
//! Levenberg–Marquardt, in scaled coordinates: efforts divided
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
//! and the residuals (law − effort)/Tₑ, of order 1 whatever the units; from each of
//! the law's starts ([`MapLaw::starts`]), the best end kept.

use nalgebra::{DMatrix, DVector};

use super::law::Quantity;
use super::map_law::MapLaw;
use crate::estimation::least_squares::{self as lm, Problem};

/// A nonlinear law's fit: the values (in the law's order), the iterations of the kept
/// start, and whether it converged.
pub(super) struct Fitted {
    pub values: Vec<f64>,
    pub iterations: usize,
    pub converged: bool,
}

/// Fits a nonlinear `law` to a map that passed the checks, with the distinct speeds
/// per direction it needs, from each of its starts (at least one).
pub(super) fn fit<L: MapLaw>(law: &L, speed: &[f64], effort: &[f64]) -> Fitted {
    let problem = Scaled::new(law, speed, effort);
    let settings = lm::Settings::default();
    let best = law
        .starts(speed, effort)
        .iter()
        .map(|start| lm::minimise(&problem, problem.to_internal(start), &settings))
        .reduce(|best, next| if next.cost < best.cost { next } else { best })
        .expect("a nonlinear law offers at least one start");
    Fitted {
        values: problem.to_reported(&best.p),
        iterations: best.iterations,
        converged: best.converged(),
    }
}

/// The scaled least-squares problem of a law over a map.
struct Scaled<'a, L> {
    law: &'a L,
    speed: &'a [f64],
    effort: &'a [f64],
    /// The efforts' and the speeds' RMS.
    effort_scale: f64,
    speed_scale: f64,
}

impl<'a, L: MapLaw> Scaled<'a, L> {
    fn new(law: &'a L, speed: &'a [f64], effort: &'a [f64]) -> Self {
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

impl<L: MapLaw> Problem for Scaled<'_, L> {
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
    use crate::estimation::friction_law::Law;

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
            let problem = Scaled::new(&law, &speed, &effort);
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
