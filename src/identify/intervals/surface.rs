//! The profile of a rough cost (docs/identification.md, "Profile likelihood"). A
//! closed-loop simulation read through quantised encoders (a torque curve, an
//! unbalance test, a servo trace: [`Smoothness::Rough`] or [`Smoothness::Grainy`])
//! has a cost that is a bowl plus roughness: on the worm's clean torque curve the
//! bowl rises by 22·δ² (δ the relative change of fm, Cm re-fitted) under a roughness
//! of about ±0.015 — 15 % of the fit's cost, the rise of a 2.6 % step. A walk of
//! re-fits reads that roughness as the profile: its re-fitted costs jumped between
//! 0.100 and 0.132 within ±1.3 % of the fit, each point a whole search of ~110
//! evaluations, and the interval was wherever the first jump crossed the level.
//!
//! Here the cost is instead evaluated at a design of points around the fit — along
//! each parameter and each pair's diagonals, at three radii of the standard errors'
//! ellipse, in the parameters' own units — all in parallel; a quadratic is fitted to
//! them by least squares, and each parameter's profile is the quadratic's, minimised
//! over the others in closed form. The ellipse is scaled so that the bowl rises by
//! half the fit's cost at the outer radius, several times the roughness; where the
//! fitted quadratic is not a bowl, or rises less than [`ROUGHNESS_MARGIN`] times the
//! points' scatter about it, the scale doubles (at most [`ROUNDS`] rounds).
//!
//! The statistic is n_eff·ln(cost / cost at the minimum), n_eff the residual count
//! over the factor by which their correlation inflates the parameter's variance
//! ([`inflation`]: Newey–West). The roughness adds the uncertainty of where the
//! bowl's minimum lies, from the scatter of the points about the quadratic (a
//! resampling of those residuals): the interval's half-width is √(h² + (1.96·sd)²),
//! h the statistic's.

use std::collections::BTreeMap;

use nalgebra::{DMatrix, DVector};
use rand::{rngs::StdRng, Rng, SeedableRng};
use rayon::prelude::*;

use super::request::{Request, LEVEL, THRESHOLD, Z};
use crate::identify::intervals::resample::block_length;
use crate::identify::result::profile::{Profile, Surface, Variance};
use crate::identify::space::Bound;
use crate::objectives::{points_per_task, sum_of_squares, Objective};
use crate::sim::batch::on_valid;

/// Radii of the design, as fractions of the outer one.
const RADII: [f64; 3] = [1.0 / 3.0, 2.0 / 3.0, 1.0];
/// The bowl's rise at the outer radius, predicted by the standard errors, as a
/// fraction of the fit's cost.
const RISE: f64 = 0.5;
/// The fitted bowl must rise by this many times the points' scatter about it at the
/// outer radius, along its flattest direction.
const ROUGHNESS_MARGIN: f64 = 4.0;
/// Designs tried, each at twice the previous scale.
const ROUNDS: usize = 3;
/// Resamplings of the design's residuals behind the minimum's uncertainty.
const RESAMPLES: usize = 400;
/// Points of the plotted profile curve.
const CURVE_POINTS: usize = 61;
/// The curve reaches a quarter beyond where the statistic is this (five times the
/// level, where the plot caps it): the design's outer points lie far above.
const CURVE_TOP: f64 = 5.0 * THRESHOLD;

/// The fitted parameters around the fit, in their own units: a friction or damping
/// coefficient enters a torque linearly, so its cost is a quadratic in the value
/// (in ln p the worm torque curve's bowl is skewed, and a quadratic fitted over
/// ±10 % put the minimum of fm 0.35 % low).
struct Coordinates {
    names: Vec<String>,
    bounds: Vec<Bound>,
    u0: DVector<f64>,
    /// u − u0 = scale · w for the design's w.
    scale: DMatrix<f64>,
}

impl Coordinates {
    /// The coordinates of `request`'s fit, with the standard errors' ellipse as the
    /// unit of w; `None` where the standard errors or correlations are missing.
    fn of(request: &Request) -> Option<Coordinates> {
        let result = request.result;
        let unc = result.uncertainty.as_ref()?;
        let names: Vec<String> = result.parameters.keys().cloned().collect();
        let bounds: Vec<Bound> = names
            .iter()
            .map(|n| {
                let [lo, hi] = result.bounds[n];
                Bound { lo, hi }
            })
            .collect();
        let u0 = DVector::from_iterator(names.len(), names.iter().map(|n| result.parameters[n]));
        let se: Vec<f64> = names
            .iter()
            .map(|n| {
                let se = result.standard_error(n)?;
                (se.is_finite() && se > 0.0).then_some(se)
            })
            .collect::<Option<_>>()?;
        let index = |n: &String| unc.names.iter().position(|m| m == n);
        let k = names.len();
        let mut cov = DMatrix::zeros(k, k);
        for i in 0..k {
            for j in 0..k {
                let rho = if i == j {
                    1.0
                } else {
                    *unc.correlation
                        .get(index(&names[i])?)?
                        .get(index(&names[j])?)?
                };
                cov[(i, j)] = rho * se[i] * se[j];
            }
        }
        let scale = cov.cholesky()?.l();
        Some(Coordinates {
            names,
            bounds,
            u0,
            scale,
        })
    }

    fn dim(&self) -> usize {
        self.names.len()
    }

    /// The design point `w` at `radius`, clamped to the bounds: its u and actual w.
    fn place(&self, w: &DVector<f64>, radius: f64) -> (DVector<f64>, DVector<f64>) {
        let mut u = &self.u0 + &self.scale * w * radius;
        for (x, b) in u.iter_mut().zip(&self.bounds) {
            *x = x.clamp(b.lo, b.hi);
        }
        let w = self
            .scale
            .solve_lower_triangular(&(&u - &self.u0))
            .unwrap_or_else(|| w * radius);
        (u, w)
    }
}

/// The unit directions of the design: ± each axis and ± each pair's two diagonals.
fn directions(k: usize) -> Vec<DVector<f64>> {
    let unit = |i: usize| DVector::from_fn(k, |r, _| if r == i { 1.0 } else { 0.0 });
    let mut out = Vec::new();
    for i in 0..k {
        out.push(unit(i));
        out.push(-unit(i));
        for j in i + 1..k {
            for (a, b) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                out.push((unit(i) * a + unit(j) * b) / 2f64.sqrt());
            }
        }
    }
    out
}

/// One evaluated point of the design.
struct Evaluated {
    u: DVector<f64>,
    w: DVector<f64>,
    cost: f64,
    /// The joint residuals, kept at the first round's innermost points along the
    /// axes ([`inflation`]).
    residuals: Option<Vec<f64>>,
}

/// The quadratic c + gᵀw + ½wᵀHw fitted to the design's costs.
struct Quadratic {
    c: f64,
    g: DVector<f64>,
    h: DMatrix<f64>,
}

/// The columns of the quadratic's least-squares problem at w: 1, each w_i, each
/// w_i·w_j (i ≤ j).
fn features(w: &DVector<f64>) -> Vec<f64> {
    let k = w.len();
    let mut f = Vec::with_capacity(1 + k + k * (k + 1) / 2);
    f.push(1.0);
    f.extend(w.iter());
    for i in 0..k {
        for j in i..k {
            f.push(w[i] * w[j]);
        }
    }
    f
}

impl Quadratic {
    fn from_coefficients(k: usize, beta: &DVector<f64>) -> Quadratic {
        let mut h = DMatrix::zeros(k, k);
        let mut idx = 1 + k;
        for i in 0..k {
            for j in i..k {
                if i == j {
                    h[(i, i)] = 2.0 * beta[idx];
                } else {
                    h[(i, j)] = beta[idx];
                    h[(j, i)] = beta[idx];
                }
                idx += 1;
            }
        }
        Quadratic {
            c: beta[0],
            g: beta.rows(1, k).into_owned(),
            h,
        }
    }

    /// The minimum's w and cost, where the quadratic is a bowl (H positive definite).
    fn minimum(&self) -> Option<(DVector<f64>, f64, DMatrix<f64>)> {
        let inv = self.h.clone().cholesky()?.inverse();
        let w = -(&inv * &self.g);
        let cost = self.c + 0.5 * self.g.dot(&w);
        Some((w, cost, inv))
    }
}

/// A least-squares fit of the quadratic to the design: the coefficients' solver,
/// the fitted values, the residuals and their RMS scatter (over n − p, p the
/// quadratic's coefficients).
struct Fitted {
    pinv: DMatrix<f64>,
    fitted: DVector<f64>,
    residuals: DVector<f64>,
    /// The quadratic's coefficient count p.
    coefficients: usize,
    scatter: f64,
    quadratic: Quadratic,
}

fn fit(points: &[Evaluated], k: usize) -> Option<Fitted> {
    let rows: Vec<Vec<f64>> = points.iter().map(|p| features(&p.w)).collect();
    let p = rows.first()?.len();
    if points.len() <= p {
        return None;
    }
    let x = DMatrix::from_fn(points.len(), p, |i, j| rows[i][j]);
    let y = DVector::from_iterator(points.len(), points.iter().map(|q| q.cost));
    let pinv = x.clone().pseudo_inverse(1e-12).ok()?;
    let beta = &pinv * &y;
    let fitted = &x * &beta;
    let residuals = &y - &fitted;
    let scatter = (residuals.norm_squared() / (points.len() - p) as f64).sqrt();
    Some(Fitted {
        pinv,
        fitted,
        residuals,
        coefficients: p,
        scatter,
        quadratic: Quadratic::from_coefficients(k, &beta),
    })
}

/// The profiles of `request.names` on a rough cost, or `None` where the fit has no
/// standard errors to scale the design by (the walk profiles it then).
pub(crate) fn profiles(request: &Request, r0: &[f64]) -> Option<BTreeMap<String, Profile>> {
    let coords = Coordinates::of(request)?;
    let (points, fitted, mut notes) = design(request, &coords, sum_of_squares(r0));
    let effective = effective_residuals(request, &coords, &points, r0);
    let bowl = fitted.and_then(|f| Bowl::new(f, &points, request.settings.seed));
    if bowl.is_none() && notes.is_empty() {
        let outer = points.iter().map(|q| q.w.norm()).fold(0.0, f64::max);
        notes.push(format!(
            "the cost around the fit is not a bowl above its roughness up to {outer:.0} \
             standard errors: the data do not bound it there"
        ));
    }
    let profile = |name: &String| {
        let j = coords.names.iter().position(|n| n == name).unwrap_or(0);
        match &bowl {
            Some(bowl) => bowl.profile(&coords, (j, effective[j]), &points, &notes),
            None => unbounded(j, &points, &notes),
        }
    };
    Some(
        request
            .names
            .iter()
            .map(|n| (n.clone(), profile(n)))
            .collect(),
    )
}

/// n_eff of each coordinate: the residual count over the factor by which their
/// correlation inflates the coordinate's variance ([`inflation`]); where the design
/// lacks the points for that, the count over the block length of each experiment's
/// residuals (the inflation of a mean, the most it can be for a slowly varying
/// parameter's effect).
fn effective_residuals(
    request: &Request,
    coords: &Coordinates,
    points: &[Evaluated],
    r0: &[f64],
) -> Vec<f64> {
    let parts: Vec<(usize, usize)> = (request.result.residuals.iter())
        .map(|r| (r.residuals.len(), block_length(&r.residuals)))
        .collect();
    let m = r0.len() as f64;
    match inflation(coords, points, r0, &parts) {
        Some(c) => c.iter().map(|c| m / c.max(1.0)).collect(),
        None => {
            let n: f64 = parts.iter().map(|(n, b)| *n as f64 / *b as f64).sum();
            vec![n; coords.dim()]
        }
    }
}

/// The factor by which the residuals' correlation inflates each coordinate's
/// variance: the Newey–West covariance (JᵀJ)⁻¹·Σ_l w_l Σ_t r_t r_(t+l) J_tᵀJ_(t+l)·(JᵀJ)⁻¹
/// (Bartlett weights w_l = 1 − l/(L+1) up to lag L = twice an experiment's block
/// length, within each experiment) against the white σ²(JᵀJ)⁻¹. J is the design's
/// central difference along each whitened axis at its innermost radius — above the
/// cost's roughness, and no evaluation more.
fn inflation(
    coords: &Coordinates,
    points: &[Evaluated],
    r0: &[f64],
    parts: &[(usize, usize)],
) -> Option<Vec<f64>> {
    let k = coords.dim();
    let m = r0.len();
    if parts.iter().map(|p| p.0).sum::<usize>() != m || m <= k {
        return None;
    }
    let jac = axial_jacobian(points, k, m)?;
    let bread = (jac.transpose() * &jac).try_inverse()?;
    // g_t = r_t · J_t, the score of each residual.
    let g = DMatrix::from_fn(m, k, |t, i| r0[t] * jac[(t, i)]);
    let mut meat = DMatrix::zeros(k, k);
    let mut offset = 0;
    for &(len, block) in parts {
        let lags = (2 * block).min(len / 4);
        for l in 0..=lags {
            let a = g.rows(offset, len - l);
            let b = g.rows(offset + l, len - l);
            let s = a.transpose() * b;
            let w = 1.0 - l as f64 / (lags + 1) as f64;
            meat += if l == 0 { s } else { (&s + s.transpose()) * w };
        }
        offset += len;
    }
    let robust = &bread * meat * &bread;
    let sigma2 = sum_of_squares(r0) / (m - k) as f64;
    let white = bread * sigma2;
    let factor = |j: usize| {
        let row = coords.scale.row(j).transpose();
        row.dot(&(&robust * &row)) / row.dot(&(&white * &row))
    };
    let c: Vec<f64> = (0..k).map(factor).collect();
    c.iter().all(|c| c.is_finite() && *c > 0.0).then_some(c)
}

/// ∂r/∂w_i by central differences of the residuals kept at ± each whitened axis.
fn axial_jacobian(points: &[Evaluated], k: usize, m: usize) -> Option<DMatrix<f64>> {
    let mut jac = DMatrix::zeros(m, k);
    for i in 0..k {
        let along = |sign: f64| {
            points.iter().find(|p| {
                p.residuals.is_some()
                    && p.w[i] * sign > 0.0
                    && (0..k).all(|o| o == i || p.w[o].abs() < 1e-9 * p.w[i].abs())
            })
        };
        let (plus, minus) = (along(1.0)?, along(-1.0)?);
        let (rp, rm) = (plus.residuals.as_ref()?, minus.residuals.as_ref()?);
        let h = plus.w[i] - minus.w[i];
        if rp.len() != m || rm.len() != m || h <= 0.0 {
            return None;
        }
        for t in 0..m {
            jac[(t, i)] = (rp[t] - rm[t]) / h;
        }
    }
    Some(jac)
}

/// The evaluated design — the fit, then rounds at doubling radii until the quadratic
/// fitted to all points rises above their scatter — the accepted fit, and notes.
fn design(
    request: &Request,
    coords: &Coordinates,
    cost0: f64,
) -> (Vec<Evaluated>, Option<Fitted>, Vec<String>) {
    let k = coords.dim();
    let m: usize = request
        .result
        .residuals
        .iter()
        .map(|r| r.residuals.len())
        .sum();
    let mut radius = (RISE * m.saturating_sub(k) as f64).sqrt();
    let mut points = vec![Evaluated {
        u: coords.u0.clone(),
        w: DVector::zeros(k),
        cost: cost0,
        residuals: None,
    }];
    let mut notes = Vec::new();
    for _ in 0..ROUNDS {
        if (request.stop)() {
            notes.push("stopped (Ctrl-C)".to_string());
            break;
        }
        // A round at twice the radius repeats none of the last one's points (its
        // ⅓ is the last ⅔).
        let inner = if points.len() > 1 { radius / 2.0 } else { 0.0 };
        points.extend(evaluate(request, coords, (inner, radius), &mut notes));
        if let Some(f) = fit(&points, k).filter(|f| rises_above_roughness(f, &points)) {
            return (points, Some(f), notes);
        }
        radius *= 2.0;
    }
    (points, None, notes)
}

/// Evaluates the design at `radius`, beyond `inner`, in parallel (failed points are
/// left out, noted).
fn evaluate(
    request: &Request,
    coords: &Coordinates,
    (inner, radius): (f64, f64),
    notes: &mut Vec<String>,
) -> Vec<Evaluated> {
    let radii: Vec<f64> = (RADII.iter().map(|r| r * radius))
        .filter(|r| *r > inner * (1.0 + 1e-9))
        .collect();
    let innermost = inner == 0.0;
    let design: Vec<(DVector<f64>, DVector<f64>, bool)> = directions(coords.dim())
        .iter()
        .flat_map(|d| {
            let axial = d.iter().filter(|x| **x != 0.0).count() == 1;
            radii.iter().enumerate().map(move |(i, r)| {
                let (u, w) = coords.place(d, *r);
                (u, w, innermost && axial && i == 0)
            })
        })
        .collect();
    let per_task = points_per_task(request.objective, design.len());
    let evaluated: Vec<Result<(f64, Vec<f64>), String>> = design
        .par_chunks(per_task)
        .flat_map_iter(|chunk| {
            let at: Vec<&DVector<f64>> = chunk.iter().map(|(u, _, _)| u).collect();
            let r = if (request.stop)() {
                at.iter().map(|_| Err("stopped (Ctrl-C)".into())).collect()
            } else {
                residuals_at(request.objective, request.params, coords, &at)
            };
            at.iter().for_each(|_| (request.on_point)());
            r.into_iter().map(|r| r.map(|r| (sum_of_squares(&r), r)))
        })
        .collect();
    let mut out = Vec::new();
    for ((u, w, keep), result) in design.into_iter().zip(evaluated) {
        match result {
            Ok((cost, r)) if cost.is_finite() => out.push(Evaluated {
                u,
                w,
                cost,
                residuals: keep.then_some(r),
            }),
            Ok(_) => {}
            Err(e) => {
                if !notes.contains(&e) {
                    notes.push(e);
                }
            }
        }
    }
    out
}

/// The joint residuals at each of the design coordinates `at`, together
/// ([`Objective::residuals_batch`]).
fn residuals_at(
    objective: &dyn Objective,
    base: &crate::model::Params,
    coords: &Coordinates,
    at: &[&DVector<f64>],
) -> Vec<Result<Vec<f64>, String>> {
    let sets = at
        .iter()
        .map(|u| {
            let mut p = base.clone();
            for (name, x) in coords.names.iter().zip(u.iter()) {
                p.set(name, *x).map_err(|e| e.to_string())?;
            }
            Ok(p)
        })
        .collect();
    on_valid(sets, |sets| {
        let r = objective.residuals_batch(sets);
        r.into_iter()
            .map(|r| r.map_err(|e| e.to_string()))
            .collect()
    })
}

/// Whether the fitted quadratic is a bowl whose rise at the outer radius, along its
/// flattest direction, stands [`ROUGHNESS_MARGIN`] times above the points' scatter.
fn rises_above_roughness(f: &Fitted, points: &[Evaluated]) -> bool {
    let outer = points.iter().map(|q| q.w.norm()).fold(0.0, f64::max);
    let flattest = f.quadratic.h.symmetric_eigenvalues().min();
    flattest > 0.0 && 0.5 * flattest * outer * outer > ROUGHNESS_MARGIN * f.scatter
}

/// The fitted bowl: its minimum, and how the roughness moves it.
struct Bowl {
    minimum: DVector<f64>,
    cost: f64,
    inverse: DMatrix<f64>,
    /// The minimum of each resampled fit (those that are bowls).
    resampled: Vec<DVector<f64>>,
    scatter: f64,
}

impl Bowl {
    fn new(fitted: Fitted, points: &[Evaluated], seed: u64) -> Option<Bowl> {
        let k = points[0].w.len();
        let (minimum, cost, inverse) = fitted.quadratic.minimum()?;
        if cost <= 0.0 {
            return None;
        }
        let n = points.len();
        // The residuals scaled up by √(n / (n − p)): a fit's residuals are smaller
        // than its errors by that factor.
        let inflate = (n as f64 / (n - fitted.coefficients) as f64).sqrt();
        let mut rng = StdRng::seed_from_u64(seed ^ 0x0073_7572_6661_6365);
        let resampled = (0..RESAMPLES)
            .filter_map(|_| {
                let y = DVector::from_fn(n, |i, _| {
                    fitted.fitted[i] + inflate * fitted.residuals[rng.random_range(0..n)]
                });
                let beta = &fitted.pinv * y;
                Quadratic::from_coefficients(k, &beta)
                    .minimum()
                    .map(|m| m.0)
            })
            .collect();
        Some(Bowl {
            minimum,
            cost,
            inverse,
            resampled,
            scatter: fitted.scatter,
        })
    }

    /// The profile of coordinate `j`: the quadratic minimised over the others.
    fn profile(
        &self,
        coords: &Coordinates,
        (j, effective): (usize, f64),
        points: &[Evaluated],
        notes: &[String],
    ) -> Profile {
        let row = coords.scale.row(j).transpose();
        // u_j − u0_j = rowᵀ w; along the profile cost = cost* + ½ (u_j − centre)² / v.
        let centre = coords.u0[j] + row.dot(&self.minimum);
        let v = row.dot(&(&self.inverse * &row));
        let rise = self.cost * ((THRESHOLD / effective).exp() - 1.0);
        let half_statistic = (2.0 * v * rise).sqrt();
        let centres: Vec<f64> = self.resampled.iter().map(|m| row.dot(m)).collect();
        let spread = standard_deviation(&centres);
        let half = half_statistic.hypot(Z * spread);
        let b = &coords.bounds[j];
        let end = |u: f64| (b.lo < u && u < b.hi).then_some(u);
        let design = projected(points, j);
        let top = (2.0 * v * self.cost * ((CURVE_TOP / effective).exp() - 1.0)).sqrt();
        let reach = (1.25 * top).max(1.5 * half);
        Profile {
            lower: end(centre - half),
            upper: end(centre + half),
            level: LEVEL,
            statistic: design
                .iter()
                .map(|q| self.statistic(effective, q[1]))
                .collect(),
            points: design,
            variance: Variance::Estimated,
            family: BTreeMap::new(),
            notes: notes.to_vec(),
            surface: Some(Surface {
                minimum: centre,
                cost: self.cost,
                effective_residuals: effective,
                roughness: self.scatter,
                minimum_spread: spread,
                statistic_half_width: half_statistic,
                curve: self.curve(effective, b, (centre, v), reach),
            }),
        }
    }

    /// The statistic of a cost against the bowl's minimum, for `effective` residuals.
    fn statistic(&self, effective: f64, cost: f64) -> f64 {
        effective * (cost.max(f64::MIN_POSITIVE) / self.cost).ln().max(0.0)
    }

    /// `[value, statistic]` of the profile centre ± reach (within the bounds), whose
    /// cost is cost* + ½ (u − centre)² / v.
    fn curve(
        &self,
        effective: f64,
        b: &Bound,
        (centre, v): (f64, f64),
        reach: f64,
    ) -> Vec<[f64; 2]> {
        (0..CURVE_POINTS)
            .map(|i| {
                let t = -reach + 2.0 * reach * i as f64 / (CURVE_POINTS - 1) as f64;
                let u = (centre + t).clamp(b.lo, b.hi);
                [
                    u,
                    self.statistic(effective, self.cost + 0.5 * (u - centre).powi(2) / v),
                ]
            })
            .collect()
    }
}

/// The design's points on coordinate `j`: `[value, cost]`, by value.
fn projected(points: &[Evaluated], j: usize) -> Vec<[f64; 2]> {
    let mut design: Vec<[f64; 2]> = points.iter().map(|q| [q.u[j], q.cost]).collect();
    design.sort_by(|a, c| a[0].total_cmp(&c[0]));
    design
}

/// A profile whose cost is no bowl: both sides open.
fn unbounded(j: usize, points: &[Evaluated], notes: &[String]) -> Profile {
    let design = projected(points, j);
    Profile {
        lower: None,
        upper: None,
        level: LEVEL,
        statistic: vec![0.0; design.len()],
        points: design,
        variance: Variance::Estimated,
        family: BTreeMap::new(),
        notes: notes.to_vec(),
        surface: None,
    }
}

fn standard_deviation(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    if x.len() < 2 {
        return 0.0;
    }
    let mean = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::StdRng, Rng, SeedableRng};

    /// One coordinate (unit scale), the design's two innermost axial points with the
    /// residuals r0 ± h·x of a linear model with regressor x, and the AR(1) errors
    /// r0 of coefficient `phi`.
    fn inflation_of(phi: f64, regressor: impl Fn(usize) -> f64) -> f64 {
        let n = 20_000;
        let mut rng = StdRng::seed_from_u64(11);
        let mut e = 0.0;
        let r0: Vec<f64> = (0..n)
            .map(|_| {
                e = phi * e + rng.random_range(-1.0..1.0);
                e
            })
            .collect();
        let coords = Coordinates {
            names: vec!["x".into()],
            bounds: vec![Bound { lo: -1e9, hi: 1e9 }],
            u0: DVector::zeros(1),
            scale: DMatrix::identity(1, 1),
        };
        let h = 0.5;
        let point = |sign: f64| Evaluated {
            u: DVector::from_element(1, sign * h),
            w: DVector::from_element(1, sign * h),
            cost: 0.0,
            residuals: Some((0..n).map(|t| r0[t] + sign * h * regressor(t)).collect()),
        };
        let points = [point(1.0), point(-1.0)];
        let b = block_length(&r0);
        inflation(&coords, &points, &r0, &[(n, b)]).unwrap()[0]
    }

    #[test]
    fn correlated_errors_inflate_a_slow_parameters_variance_and_not_a_fast_ones() {
        // White errors: no inflation.
        let white = inflation_of(0.0, |_| 1.0);
        assert!((0.9..1.1).contains(&white), "{white}");
        // AR(1) of 0.9 under a constant regressor (an offset): the variance of a
        // mean grows by the integrated correlation time (1 + φ)/(1 − φ) = 19; the
        // Bartlett window up to twice the block length (19) catches most of it.
        let slow = inflation_of(0.9, |_| 1.0);
        assert!((12.0..21.0).contains(&slow), "{slow}");
        // The same errors under a regressor alternating each sample: its effect and
        // the errors' correlation do not line up, and the variance shrinks
        // ((1 − φ)/(1 + φ) ≈ 0.05) — which a count over the block length misses.
        let fast = inflation_of(0.9, |t| if t % 2 == 0 { 1.0 } else { -1.0 });
        assert!(fast < 0.2, "{fast}");
    }
}
