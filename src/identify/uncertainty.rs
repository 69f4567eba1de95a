//! How well the data determine the identified parameters: standard errors from the
//! Jacobian at the optimum, σ²(JᵀJ)⁻¹ with σ² = Σr²/(m − n), the correlation matrix,
//! and warnings for what the data cannot separate (|correlation| > 0.95, or a JᵀJ
//! that is singular to working precision).
//!
//! The Jacobian is taken with respect to ln p for positive parameters (so the
//! standard error is relative, then converted back) by central differences of
//! relative step `step`, the 2n evaluations in parallel. Columns are scaled to unit
//! norm before the singular-value check, so units do not decide identifiability.

use nalgebra::{DMatrix, SVD};
use rayon::prelude::*;

use super::space::ParamSpace;
use crate::objectives::{Objective, ObjectiveError};

/// Above this |correlation| two parameters are reported as not separable.
pub const CORRELATION_LIMIT: f64 = 0.95;
/// Below this ratio of smallest to largest singular value (of the column-scaled
/// Jacobian) JᵀJ counts as singular.
pub const SINGULAR_RATIO: f64 = 1e-6;

/// The uncertainty of a result.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Uncertainty {
    /// Name → standard error in the parameter's unit (absent when undefined).
    pub standard_errors: Vec<(String, Option<f64>)>,
    /// Parameter names, and the correlation matrix in their order.
    pub names: Vec<String>,
    pub correlation: Vec<Vec<f64>>,
    /// σ² of the scaled residuals: ~1 when the model fits to the assumed measurement
    /// error, ≪ 1 on noise-free virtual data.
    pub residual_variance: f64,
    /// Smallest / largest singular value of the column-scaled Jacobian.
    pub conditioning: f64,
    pub warnings: Vec<String>,
}

/// Evaluates the uncertainty at `values`.
pub fn at_optimum(
    space: &ParamSpace,
    objective: &dyn Objective,
    values: &[f64],
    step: f64,
) -> Result<Uncertainty, ObjectiveError> {
    let r0 = objective.residuals(&space.params(values)?)?;
    with_residuals(space, objective, values, &r0, step)
}

/// [`at_optimum`] when the residuals `r0` at `values` are known already.
pub fn with_residuals(
    space: &ParamSpace,
    objective: &dyn Objective,
    values: &[f64],
    r0: &[f64],
    step: f64,
) -> Result<Uncertainty, ObjectiveError> {
    let n = space.dim();
    let names: Vec<String> = space.names.iter().map(|s| s.to_string()).collect();
    let m = r0.len();
    // Each column: ∂r/∂ln p (log parameters) or ∂r/∂p scaled by the range.
    let shifted = |j: usize, sign: f64| -> Result<Vec<f64>, ObjectiveError> {
        let mut v = values.to_vec();
        v[j] = if space.bounds[j].log() {
            values[j] * (sign * step).exp()
        } else {
            values[j] + sign * step * (space.bounds[j].hi - space.bounds[j].lo)
        };
        objective.residuals(&space.params(&v)?)
    };
    let columns: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|j| {
            let (up, down) = (shifted(j, 1.0)?, shifted(j, -1.0)?);
            Ok(up
                .iter()
                .zip(&down)
                .map(|(a, b)| (a - b) / (2.0 * step))
                .collect())
        })
        .collect::<Result<_, ObjectiveError>>()?;
    let jac = DMatrix::from_fn(m, n, |i, j| columns[j][i]);
    let mut warnings = Vec::new();

    // Identifiability from the column-scaled Jacobian.
    let norms: Vec<f64> = (0..n).map(|j| jac.column(j).norm()).collect();
    for (j, &c) in norms.iter().enumerate() {
        if c == 0.0 {
            warnings.push(format!(
                "{} has no effect on the residuals: the data say nothing about it",
                names[j]
            ));
        }
    }
    let scaled = DMatrix::from_fn(m, n, |i, j| jac[(i, j)] / norms[j].max(f64::MIN_POSITIVE));
    let sv = SVD::new(scaled.clone(), false, true);
    let (smax, smin) = sv
        .singular_values
        .iter()
        .fold((0.0f64, f64::INFINITY), |(a, b), &s| (a.max(s), b.min(s)));
    let conditioning = if smax > 0.0 { smin / smax } else { 0.0 };
    if m < n {
        warnings.push(format!(
            "{m} residuals for {n} parameters: the data cannot determine them all"
        ));
    }
    if conditioning < SINGULAR_RATIO {
        if let Some(vt) = sv.v_t.as_ref() {
            let k = sv
                .singular_values
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(b.1))
                .map_or(0, |(k, _)| k);
            let combo: Vec<String> = (0..n)
                .filter(|&j| vt[(k, j)].abs() > 0.1)
                .map(|j| names[j].clone())
                .collect();
            warnings.push(format!(
                "JᵀJ is singular (conditioning {conditioning:.1e}): the data cannot separate {}",
                combo.join(", ")
            ));
        }
    }

    // Covariance in the column coordinates (ln p or range-scaled p).
    let sigma2 = if m > n {
        r0.iter().map(|r| r * r).sum::<f64>() / (m - n) as f64
    } else {
        f64::NAN
    };
    let jtj = jac.transpose() * &jac;
    let inv = if conditioning >= SINGULAR_RATIO {
        jtj.clone().try_inverse()
    } else {
        None
    };
    let mut correlation = vec![vec![f64::NAN; n]; n];
    let mut standard_errors = Vec::new();
    // Correlations do not depend on σ²; take them from the pseudo-inverse of the
    // scaled matrix when JᵀJ is singular, so a ±1 still shows.
    let cov_shape = match &inv {
        Some(c) => c.clone(),
        None => {
            let st = scaled.transpose() * &scaled;
            let pinv = st
                .pseudo_inverse(1e-14)
                .unwrap_or_else(|_| DMatrix::zeros(n, n));
            DMatrix::from_fn(n, n, |a, b| {
                pinv[(a, b)] / (norms[a] * norms[b]).max(f64::MIN_POSITIVE)
            })
        }
    };
    for a in 0..n {
        for b in 0..n {
            let d = (cov_shape[(a, a)] * cov_shape[(b, b)]).sqrt();
            correlation[a][b] = if d > 0.0 {
                cov_shape[(a, b)] / d
            } else {
                f64::NAN
            };
        }
    }
    for a in 0..n {
        for b in a + 1..n {
            let c = correlation[a][b];
            if c.abs() > CORRELATION_LIMIT {
                warnings.push(format!(
                    "{} and {} are correlated {c:+.3}: the data cannot separate them (fix one, or add an experiment that moves them differently)",
                    names[a], names[b]
                ));
            }
        }
    }
    for j in 0..n {
        let se = inv.as_ref().and_then(|c| {
            let s = (sigma2 * c[(j, j)]).sqrt();
            s.is_finite().then(|| {
                if space.bounds[j].log() {
                    values[j] * s
                } else {
                    s * (space.bounds[j].hi - space.bounds[j].lo)
                }
            })
        });
        standard_errors.push((names[j].clone(), se));
    }
    let correlation = correlation
        .into_iter()
        .map(|row| {
            row.into_iter()
                .map(|c| if c.is_finite() { c } else { 0.0 })
                .collect()
        })
        .collect();
    Ok(Uncertainty {
        standard_errors,
        names,
        correlation,
        residual_variance: if sigma2.is_finite() { sigma2 } else { 0.0 },
        conditioning,
        warnings,
    })
}
