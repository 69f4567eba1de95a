//! Friction laws fitted to a friction map: each constant-speed run's mean speed v
//! (rad/s or m/s, ≠ 0) and mean effort T (N·m or N), measured at the motor. The laws,
//! with their parameters as named in JSON and tables (sgn(v) = ±1):
//!
//! ```text
//! coulomb             T = Fc·sgn(v) + Fv·v + Fo                          [Fc, Fv, Fo]
//! stribeck            T = sgn(v)·(Fc + (Fs − Fc)·exp(−(|v|/vs)^delta)) + Fv·v + Fo
//!                                                        [Fc, Fs, vs, delta, Fv, Fo]
//! coulomb_asymmetric  T = Fc_pos + Fv_pos·v (v > 0),  −Fc_neg + Fv_neg·v (v < 0)
//!                                                     [Fc_pos, Fv_pos, Fc_neg, Fv_neg]
//! stribeck_asymmetric v > 0: T = Fc_pos + (Fs_pos − Fc_pos)·exp(−(v/vs_pos)^delta) + Fv_pos·v
//!                     v < 0: T = −(Fc_neg + (Fs_neg − Fc_neg)·exp(−(|v|/vs_neg)^delta)) + Fv_neg·v
//!                         [Fc_pos, Fs_pos, vs_pos, Fv_pos, Fc_neg, Fs_neg, vs_neg, Fv_neg, delta]
//! ```
//!
//! with vs > 0 and delta > 0 — the Stribeck curve of B. Armstrong-Hélouvry,
//! P. Dupont, C. Canudas de Wit, "A survey of models, analysis tools and compensation
//! methods for the control of machines with friction", Automatica 30(7), 1994, §2.1.
//!
//! Each law is fitted to the runs' mean efforts by unweighted least squares: the
//! Coulomb laws by linear least squares (`linear.rs`), the Stribeck laws by
//! Levenberg–Marquardt ([`crate::estimation::least_squares`]) in scaled coordinates from two
//! starts (`stribeck.rs`). A law is fitted only to more runs than it has parameters,
//! and a Stribeck law only to at least 3 distinct speeds per direction. Standard
//! errors: s² = SSR/(n − k), cov = s²·(JᵀJ)⁻¹ with J the Jacobian of the residuals
//! with respect to the reported parameters (`covariance.rs`); a parameter the data do
//! not determine has none (`None`, with a [`Note`]), never a NaN. [`fit_all`] fits
//! every law the data allow and ranks them by AICc ([`crate::estimation::information`]).
//!
//! **Bounds of a Stribeck law.** The fit itself is unconstrained; a Stribeck law is
//! *determined* only when its fit converged and every parameter has a standard error,
//! each rise Fs − Fc is positive beyond two standard errors (Fc ≤ Fs: the effort falls
//! from a breakaway level Fs to Fc as the speed rises — a curve that rises towards Fc
//! instead is not a Stribeck effect), each vs lies within the speeds of the runs of
//! its direction(s) (lowest to highest |v|: outside them the rise is extrapolated),
//! and delta lies within [`DELTA_RANGE`] = [0.5, 3] (outside, the fit has found a
//! step between two runs or a slope spread over all of them). Otherwise its
//! [`Note`]s say why it is not determined, and it is ranked apart: it stays in the
//! comparison's `fits`, with its parameters and notes, but not in the AICc ranking, so
//! an unconverged or degenerate law is never the one "the data support".

mod builtin;
mod compare;
mod covariance;
mod law;
mod linear;
mod map;
mod map_law;
mod nonlinear;
mod note;
mod stribeck;

#[cfg(test)]
mod tests;

use nalgebra::DMatrix;
use serde::Serialize;

use crate::model::friction::{Rise, SteadyFriction};

pub use compare::{fit_all, Comparison, Refused, COST_FLOOR};
pub use covariance::Covariance;
pub use law::{Law, Quantity};
pub use map::{check_map, distinct_speeds, Direction, MapProblem};
pub use map_law::MapLaw;
pub use note::{Note, DELTA_RANGE};

/// The Stribeck laws need this many distinct speeds per direction: the rise's start,
/// middle and end.
pub const STRIBECK_SPEEDS: usize = 3;

/// A fitted parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Parameter {
    /// As in [`Law::parameters`].
    pub name: &'static str,
    /// N·m or N (Fc, Fs, Fo), N·m·s/rad or N·s/m (Fv), rad/s or m/s (vs), 1 (delta).
    pub value: f64,
    /// `None` when the data do not determine it (see the fit's notes).
    pub std_error: Option<f64>,
}

/// A law fitted to a map: one of [`Law`] unless another [`MapLaw`] was fitted.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LawFit<L = Law> {
    pub law: L,
    /// In the order of [`Law::parameters`].
    pub parameters: Vec<Parameter>,
    /// The sum of squared residuals, (N·m)² or N².
    pub ssr: f64,
    /// Runs n and parameters k.
    pub n: usize,
    pub k: usize,
    /// Each run's measured effort minus the law's, in the runs' order.
    pub residuals: Vec<f64>,
    /// The law evaluated at each run's speed.
    pub evaluated: Vec<f64>,
    /// Levenberg–Marquardt iterations of the kept start (0 for the linear laws, solved
    /// directly).
    pub iterations: usize,
    /// Whether the fit reached a minimum (always for the linear laws).
    pub converged: bool,
    /// Whether the data determine the law: always for the linear laws; for a Stribeck
    /// law, when its fit has no note (converged, every parameter with a standard error,
    /// a rise Fs − Fc > 0 beyond two standard errors, vs within the runs' speeds, delta
    /// within [`DELTA_RANGE`]). A law not determined is ranked apart ([`fit_all`]).
    pub determined: bool,
    pub notes: Vec<Note>,
}

impl<L> LawFit<L> {
    /// The values, in the order of [`Law::parameters`].
    pub fn values(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.value).collect()
    }

    /// The parameter called `name`.
    pub fn parameter(&self, name: &str) -> Option<&Parameter> {
        self.parameters.iter().find(|p| p.name == name)
    }

    /// The residuals' RMS, N·m or N.
    pub fn residual_rms(&self) -> f64 {
        (self.ssr / self.n as f64).sqrt()
    }
}

impl LawFit<Law> {
    /// A symmetric law as the model states a body's friction, with the offset Fo
    /// (N·m or N) apart: Fc the Coulomb level, Fv the viscous slope, Fs − Fc, vs and
    /// delta the rise. `None` for the asymmetric laws, which no body of the model has.
    pub fn steady(&self) -> Option<(SteadyFriction, f64)> {
        let v = self.values();
        match self.law {
            Law::Coulomb => Some((
                SteadyFriction {
                    coulomb: v[0],
                    viscous: v[1],
                    rise: None,
                },
                v[2],
            )),
            Law::Stribeck => Some((
                SteadyFriction {
                    coulomb: v[0],
                    viscous: v[4],
                    rise: Some(Rise {
                        rise: v[1] - v[0],
                        speed: v[2],
                        shape: v[3],
                    }),
                },
                v[5],
            )),
            Law::CoulombAsymmetric | Law::StribeckAsymmetric => None,
        }
    }
}

/// Why a law is not fitted.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    #[error(transparent)]
    Map(#[from] MapProblem),
    #[error("{law}: {n} runs for {k} parameters: a law is fitted only to more runs than it has parameters")]
    TooFewRuns {
        law: &'static str,
        n: usize,
        k: usize,
    },
    #[error(
        "{law}: {distinct} distinct speeds in the {direction} direction: the law \
         needs at least {needed} per direction (its curve's start, middle and end)"
    )]
    TooFewSpeeds {
        law: &'static str,
        direction: Direction,
        distinct: usize,
        needed: usize,
    },
}

/// Fits `law` to the runs' mean `speed` (rad/s or m/s) and mean `effort` (N·m or N),
/// after [`check_map`]: any [`MapLaw`], the four of [`Law`] among them.
pub fn fit<L: MapLaw>(law: L, speed: &[f64], effort: &[f64]) -> Result<LawFit<L>, FitError> {
    check_map(speed, effort)?;
    let (n, k) = (speed.len(), law.parameters().len());
    if n <= k {
        return Err(FitError::TooFewRuns {
            law: law.name(),
            n,
            k,
        });
    }
    let directions = [Direction::Positive, Direction::Negative];
    let speeds = directions.map(|d| distinct_speeds(speed, d));
    for (direction, u) in directions.into_iter().zip(&speeds) {
        if u.len() < law.speeds_needed() {
            return Err(FitError::TooFewSpeeds {
                law: law.name(),
                direction,
                distinct: u.len(),
                needed: law.speeds_needed(),
            });
        }
    }
    let (values, iterations, converged) = if law.is_linear() {
        (linear::fit(&law, speed, effort), 0, true)
    } else {
        let f = nonlinear::fit(&law, speed, effort);
        (f.values, f.iterations, f.converged)
    };
    let evaluated: Vec<f64> = speed.iter().map(|&v| law.evaluate(&values, v)).collect();
    let residuals: Vec<f64> = effort.iter().zip(&evaluated).map(|(e, t)| e - t).collect();
    let ssr = residuals.iter().map(|r| r * r).sum();
    let covariance = covariance::Covariance::new(&jacobian(&law, &values, speed), ssr);
    let span = speeds.map(|u| (u[0], u[u.len() - 1]));
    let mut notes = note::general(
        law.parameters(),
        &covariance,
        (!converged).then_some(iterations),
    );
    notes.extend(law.checks(&values, &covariance, span));
    let parameters = law
        .parameters()
        .iter()
        .zip(&values)
        .enumerate()
        .map(|(j, (&name, &value))| Parameter {
            name,
            value,
            std_error: covariance.std_error(j),
        })
        .collect();
    Ok(LawFit {
        determined: law.is_linear() || notes.is_empty(),
        law,
        parameters,
        ssr,
        n,
        k,
        residuals,
        evaluated,
        iterations,
        converged,
        notes,
    })
}

/// The Jacobian of `law`'s efforts at `values` over the runs' speeds (runs × parameters).
fn jacobian<L: MapLaw>(law: &L, values: &[f64], speed: &[f64]) -> DMatrix<f64> {
    let k = values.len();
    let mut jacobian = DMatrix::zeros(speed.len(), k);
    let mut row = vec![0.0; k];
    for (i, &v) in speed.iter().enumerate() {
        law.gradient(values, v, &mut row);
        for (j, &x) in row.iter().enumerate() {
            jacobian[(i, j)] = x;
        }
    }
    jacobian
}
