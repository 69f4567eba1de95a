//! How well the data determine the identified parameters: standard errors from the
//! Jacobian at the optimum, σ²(JᵀJ)⁻¹ with σ² = Σr²/(m − n), the correlation matrix,
//! and warnings for what the data cannot separate (|correlation| > 0.95, or a JᵀJ
//! that is singular to working precision).
//!
//! The Jacobian is taken with respect to ln p for positive parameters (so the
//! standard error is relative, then converted back) by central differences of
//! relative step `step`, the 2n evaluations in parallel. Columns are scaled to unit
//! norm before the singular-value check, so units do not decide identifiability.

use crate::identify::result::uncertainty::Uncertainty;
use nalgebra::{DMatrix, SVD};

use crate::identify::result::warning::Warning;
use crate::identify::space::ParamSpace;
use crate::objectives::{residuals_all, Objective, ObjectiveError};

/// Above this |correlation| two parameters are reported as not separable.
pub const CORRELATION_LIMIT: f64 = 0.95;
/// Below this ratio of smallest to largest singular value (of the column-scaled
/// Jacobian) JᵀJ counts as singular.
pub const SINGULAR_RATIO: f64 = 1e-6;

/// The uncertainty and what it warns of.
#[derive(Clone, Debug)]
pub struct Assessed {
    pub uncertainty: Uncertainty,
    pub warnings: Vec<Warning>,
}

/// Evaluates the uncertainty at `values`.
pub fn at_optimum(
    space: &ParamSpace,
    objective: &dyn Objective,
    values: &[f64],
    step: f64,
) -> Result<Assessed, ObjectiveError> {
    let r0 = objective.residuals(&space.params(values)?)?;
    with_residuals(space, objective, values, &r0, step)
}

/// [`at_optimum`] when the residuals `r0` at `values` are known already.
pub(crate) fn with_residuals(
    space: &ParamSpace,
    objective: &dyn Objective,
    values: &[f64],
    r0: &[f64],
    step: f64,
) -> Result<Assessed, ObjectiveError> {
    let jac = jacobian(space, objective, values, step)?;
    let (m, n) = jac.shape();
    let sigma2 = residual_variance(r0, m, n);
    Ok(from_jacobian(space, values, &jac, sigma2))
}

/// The uncertainty at `values` (residuals `r0`) from the Jacobian `solver_jac` a
/// search took at solver coordinates `x` near them. The solver's coordinate is
/// x = asin(2u − 1) of the unit coordinate u in the bounds (u = ln(p/lo)/ln(hi/lo)
/// for a log parameter, (p − lo)/(hi − lo) for a linear one), so each column ∂r/∂x
/// becomes [`jacobian`]'s ∂r/∂u = ∂r/∂x / (cos x / 2), then divided by ln(hi/lo)
/// for a log parameter (∂r/∂ln p).
pub(crate) fn from_solver_jacobian(
    space: &ParamSpace,
    values: &[f64],
    (x, solver_jac): (&[f64], &DMatrix<f64>),
    r0: &[f64],
) -> Assessed {
    let mut jac = solver_jac.clone();
    for (j, (b, x)) in space.bounds.iter().zip(x).enumerate() {
        let du_dx = 0.5 * x.cos();
        let dlnp_du = if b.log() { (b.hi / b.lo).ln() } else { 1.0 };
        jac.column_mut(j).unscale_mut(du_dx * dlnp_du);
    }
    let (m, n) = jac.shape();
    let sigma2 = residual_variance(r0, m, n);
    from_jacobian(space, values, &jac, sigma2)
}

/// σ² = Σr²/(m − n) of `m` residuals `r0` after fitting `n` parameters (NaN: unknown,
/// no more residuals than parameters).
pub(crate) fn residual_variance(r0: &[f64], m: usize, n: usize) -> f64 {
    if m > n {
        r0.iter().map(|r| r * r).sum::<f64>() / (m - n) as f64
    } else {
        f64::NAN
    }
}

/// The uncertainty at `values` from the Jacobian `jac` (columns as [`jacobian`]
/// takes them) and the residual variance `sigma2` (NaN: unknown): what the data of
/// a fit determine, or — with a stated σ² — what a planned test would
/// ([`crate::identify::design`]).
pub(crate) fn from_jacobian(
    space: &ParamSpace,
    values: &[f64],
    jac: &DMatrix<f64>,
    sigma2: f64,
) -> Assessed {
    let names: Vec<String> = space.names.iter().map(|s| s.to_string()).collect();
    let shape = Shape::of(jac);
    let mut warnings = shape.warnings(&names);
    let inv = (shape.conditioning >= SINGULAR_RATIO)
        .then(|| (jac.transpose() * jac).try_inverse())
        .flatten();
    let correlation = correlation(inv.as_ref(), &shape);
    warnings.extend(correlated(&correlation, &names));
    let standard_errors = names
        .iter()
        .enumerate()
        .map(|(j, name)| {
            (
                name.clone(),
                standard_error(space, values, inv.as_ref(), sigma2, j),
            )
        })
        .collect();
    Assessed {
        uncertainty: Uncertainty {
            standard_errors,
            names,
            correlation: zero_undefined(correlation),
            residual_variance: if sigma2.is_finite() { sigma2 } else { 0.0 },
            conditioning: shape.conditioning,
            lower_bounds: false,
        },
        warnings,
    }
}

/// Central-difference Jacobian of the residuals: each column ∂r/∂ln p (log
/// parameters) or ∂r/∂p scaled by the range, the 2n evaluations in parallel.
pub(crate) fn jacobian(
    space: &ParamSpace,
    objective: &dyn Objective,
    values: &[f64],
    step: f64,
) -> Result<DMatrix<f64>, ObjectiveError> {
    let shifted = |j: usize, sign: f64| {
        let mut v = values.to_vec();
        let b = space.bounds[j];
        v[j] = if b.log() {
            values[j] * (sign * step).exp()
        } else {
            values[j] + sign * step * (b.hi - b.lo)
        };
        space.params(&v)
    };
    // Up and down of every parameter, [up 0, down 0, up 1, …], together.
    let sets = (0..space.dim())
        .flat_map(|j| [shifted(j, 1.0), shifted(j, -1.0)])
        .collect::<Result<Vec<_>, _>>()?;
    let r = residuals_all(objective, &sets)
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?;
    let columns: Vec<Vec<f64>> = r
        .chunks(2)
        .map(|ud| {
            let (up, down) = (&ud[0], &ud[1]);
            up.iter()
                .zip(down)
                .map(|(a, b)| (a - b) / (2.0 * step))
                .collect()
        })
        .collect();
    let m = columns.first().map_or(0, Vec::len);
    Ok(DMatrix::from_fn(m, space.dim(), |i, j| columns[j][i]))
}

/// The Jacobian with its columns scaled to unit norm, and its singular values.
struct Shape {
    residuals: usize,
    norms: Vec<f64>,
    scaled: DMatrix<f64>,
    svd: SVD<f64, nalgebra::Dyn, nalgebra::Dyn>,
    conditioning: f64,
}

impl Shape {
    fn of(jac: &DMatrix<f64>) -> Shape {
        let (m, n) = jac.shape();
        let norms: Vec<f64> = (0..n).map(|j| jac.column(j).norm()).collect();
        let scaled = DMatrix::from_fn(m, n, |i, j| jac[(i, j)] / norms[j].max(f64::MIN_POSITIVE));
        let svd = SVD::new(scaled.clone(), false, true);
        let (smax, smin) = svd
            .singular_values
            .iter()
            .fold((0.0f64, f64::INFINITY), |(a, b), &s| (a.max(s), b.min(s)));
        Shape {
            residuals: m,
            norms,
            scaled,
            svd,
            conditioning: if smax > 0.0 { smin / smax } else { 0.0 },
        }
    }

    /// What the shape alone says: parameters without effect, too few residuals, a
    /// singular JᵀJ and the combination it cannot separate.
    fn warnings(&self, names: &[String]) -> Vec<Warning> {
        let n = names.len();
        let mut out: Vec<Warning> = self
            .norms
            .iter()
            .zip(names)
            .filter(|(c, _)| **c == 0.0)
            .map(|(_, name)| Warning::NoEffect { name: name.clone() })
            .collect();
        if self.residuals < n {
            out.push(Warning::TooFewResiduals {
                residuals: self.residuals,
                parameters: n,
            });
        }
        if self.conditioning < SINGULAR_RATIO {
            if let Some(vt) = self.svd.v_t.as_ref() {
                let k = self
                    .svd
                    .singular_values
                    .iter()
                    .enumerate()
                    .min_by(|a, b| a.1.total_cmp(b.1))
                    .map_or(0, |(k, _)| k);
                out.push(Warning::Singular {
                    conditioning: self.conditioning,
                    names: (0..n)
                        .filter(|&j| vt[(k, j)].abs() > 0.1)
                        .map(|j| names[j].clone())
                        .collect(),
                });
            }
        }
        out
    }
}

/// The correlation matrix, from (JᵀJ)⁻¹ — or, when JᵀJ is singular, from the
/// pseudo-inverse of the scaled matrix, so that a ±1 still shows (correlations do not
/// depend on σ²). NaN where undefined.
fn correlation(inv: Option<&DMatrix<f64>>, shape: &Shape) -> Vec<Vec<f64>> {
    let n = shape.norms.len();
    let cov = match inv {
        Some(c) => c.clone(),
        None => {
            let st = shape.scaled.transpose() * &shape.scaled;
            let pinv = st
                .pseudo_inverse(1e-14)
                .unwrap_or_else(|_| DMatrix::zeros(n, n));
            DMatrix::from_fn(n, n, |a, b| {
                pinv[(a, b)] / (shape.norms[a] * shape.norms[b]).max(f64::MIN_POSITIVE)
            })
        }
    };
    (0..n)
        .map(|a| {
            (0..n)
                .map(|b| {
                    let d = (cov[(a, a)] * cov[(b, b)]).sqrt();
                    if d > 0.0 {
                        cov[(a, b)] / d
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect()
}

/// A warning for each pair correlated beyond [`CORRELATION_LIMIT`].
fn correlated(correlation: &[Vec<f64>], names: &[String]) -> Vec<Warning> {
    let n = names.len();
    let mut out = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            let c = correlation[a][b];
            if c.abs() > CORRELATION_LIMIT {
                out.push(Warning::Correlated {
                    a: names[a].clone(),
                    b: names[b].clone(),
                    correlation: c,
                });
            }
        }
    }
    out
}

/// The standard error of parameter `j` in its own unit (`None` when undefined).
fn standard_error(
    space: &ParamSpace,
    values: &[f64],
    inv: Option<&DMatrix<f64>>,
    sigma2: f64,
    j: usize,
) -> Option<f64> {
    let s = (sigma2 * inv?[(j, j)]).sqrt();
    let b = space.bounds[j];
    s.is_finite().then(|| {
        if b.log() {
            values[j] * s
        } else {
            s * (b.hi - b.lo)
        }
    })
}

/// Undefined correlations written as 0 (JSON has no NaN).
fn zero_undefined(correlation: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    correlation
        .into_iter()
        .map(|row| {
            row.into_iter()
                .map(|c| if c.is_finite() { c } else { 0.0 })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::search::problem::{Monitor, Problem};
    use crate::identify::search::settings::Settings;
    use crate::identify::space::Bound;
    use crate::model::{presets, Params};

    /// Three smooth residuals of Kw and Kg (no exact fit: σ² > 0).
    struct Smooth;

    impl Objective for Smooth {
        fn name(&self) -> &'static str {
            "smooth"
        }
        fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
            let (a, b) = (p.kw / 3e5, p.kg.unwrap_or(0.0) / 900.0);
            Ok(vec![a * b - 1.1, (a - 1.0).exp() - 0.9, b * b - 0.8 * a])
        }
        fn len(&self) -> usize {
            3
        }
        fn scale(&self) -> String {
            String::new()
        }
    }

    #[test]
    fn a_searchs_jacobian_in_solver_coordinates_gives_the_central_differences_errors() {
        // Kw in log space, Kg linear: both conversions (asin coordinate, ln p).
        let base = presets::load("worm-gear").unwrap();
        let names = ["Kw".to_string(), "Kg".to_string()];
        let bounds = [
            ("Kw".to_string(), Bound { lo: 3e4, hi: 3e6 }),
            (
                "Kg".to_string(),
                Bound {
                    lo: 0.0,
                    hi: 2000.0,
                },
            ),
        ];
        let space = ParamSpace::new(base, &names, &bounds).unwrap();
        let values = [3.3e5, 870.0];
        let direct = at_optimum(&space, &Smooth, &values, 1e-5).unwrap();
        let monitor = Monitor::default();
        let settings = Settings {
            fd_step: 1e-7,
            ..Settings::default()
        };
        let problem = Problem::new(&space, &Smooth, &monitor, &settings);
        let x = space.to_solver(&values);
        let r0 = Smooth.residuals(&space.params(&values).unwrap()).unwrap();
        let j = problem.jacobian_at(&x, &r0).unwrap();
        let converted = from_solver_jacobian(&space, &values, (x.as_slice(), &j), &r0);
        let pairs = direct
            .uncertainty
            .standard_errors
            .iter()
            .zip(&converted.uncertainty.standard_errors);
        for ((name, a), (_, b)) in pairs {
            let (a, b) = (a.unwrap(), b.unwrap());
            assert!((b / a - 1.0).abs() < 1e-4, "{name}: {a} against {b}");
        }
        let (ca, cb) = (
            direct.uncertainty.correlation[0][1],
            converted.uncertainty.correlation[0][1],
        );
        assert!((ca - cb).abs() < 1e-4, "{ca} against {cb}");
    }
}
