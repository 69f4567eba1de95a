//! Sweep designs: which parameter points a sweep evaluates, in a fixed order.
//!
//! Every design is a deterministic function of (method, factors, base values, seed):
//! point `i` is always the same, so a resumed, sharded or merged sweep computes
//! exactly the rows of a straight run.
//!
//! - **grid**: the full factorial of each factor's levels, the first factor varying
//!   slowest;
//! - **local**: one at a time around the base point: index 0 the base, then for
//!   factor j the points p·e^{+h} (index 1 + 2j) and p·e^{−h} (index 2 + 2j), so the
//!   central difference gives ∂ln y/∂ln p ([`super::local`]);
//! - **morris**: `trajectories` one-at-a-time paths on a `levels`-level grid of the
//!   unit cube, step Δ = levels/(2·(levels − 1)) (Morris 1991; Saltelli et al.,
//!   *Global Sensitivity Analysis: The Primer*, 2008, §3.3), k + 1 points each;
//! - **sobol**: Saltelli's radial scheme (Saltelli et al. 2010, *Comput. Phys.
//!   Commun.* 181, 259): matrices A and B of `samples` rows from an Owen-scrambled
//!   Sobol sequence (dimensions 0..k for A, k..2k for B; `sobol_burley`, scrambled by
//!   the seed), and A_B^(i) (A with column i from B). Base row j gives the k + 2
//!   points A_j, B_j, A_B^(1)_j … A_B^(k)_j, at indices j·(k + 2) + 0, 1, 2 + i.

use ndarray::Array2;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

use super::spec::Factor;

/// Largest base sample of the Sobol design (the `sobol_burley` sequence length).
pub const MAX_SOBOL_SAMPLES: usize = 1 << 16;
/// Largest number of factors of the Sobol design (2k sequence dimensions ≤ 256).
pub const MAX_SOBOL_FACTORS: usize = 128;

/// The design and its settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "lowercase")]
pub enum Method {
    /// Full grid of every factor's levels.
    Grid,
    /// One-at-a-time logarithmic derivatives at the base point, relative step `step`.
    Local { step: f64 },
    /// Morris elementary effects.
    Morris { trajectories: usize, levels: usize },
    /// Sobol indices from Saltelli sampling, with `bootstrap` resamples for the
    /// confidence intervals.
    Sobol { samples: usize, bootstrap: usize },
}

impl Method {
    /// The method's name on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Grid => "grid",
            Method::Local { .. } => "local",
            Method::Morris { .. } => "morris",
            Method::Sobol { .. } => "sobol",
        }
    }
}

/// A design that cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DesignError {
    #[error("no parameter to vary")]
    NoFactors,
    #[error("{name}: the {method} method needs a range LOW..HIGH")]
    NoRange { name: String, method: &'static str },
    #[error("{name} is {value} at the base point: a logarithmic sensitivity needs a value other than 0 (set another base value, or use a global method)")]
    ZeroBase { name: String, value: f64 },
    #[error("the grid has {points} points, more than the limit of {limit}: use fewer levels, or a Morris or Sobol design")]
    TooLarge { points: f64, limit: usize },
    #[error("{what} = {value}: {reason}")]
    Setting {
        what: &'static str,
        value: f64,
        reason: &'static str,
    },
}

/// Most points a grid may have (beyond this a global method is the better tool).
pub const MAX_GRID_POINTS: usize = 1_000_000;

/// The points of a design, as unit coordinates and as parameter values: one row per
/// point, one column per factor.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    pub method: Method,
    pub factors: Vec<Factor>,
    /// Unit coordinates in [0, 1]^k (local: the log step, −h, 0 or +h).
    pub unit: Array2<f64>,
    /// Parameter values, SI.
    pub values: Array2<f64>,
}

impl Design {
    /// Builds the design. `base` holds the base value of each factor (local method).
    pub fn new(
        method: &Method,
        factors: &[Factor],
        base: &[f64],
        seed: u64,
    ) -> Result<Self, DesignError> {
        let k = factors.len();
        if k == 0 {
            return Err(DesignError::NoFactors);
        }
        if !matches!(method, Method::Local { .. }) {
            if let Some(f) = factors.iter().find(|f| f.is_point()) {
                return Err(DesignError::NoRange {
                    name: f.name.clone(),
                    method: method.name(),
                });
            }
        }
        let to_values = |unit: &[Vec<f64>]| -> Vec<Vec<f64>> {
            unit.iter()
                .map(|u| u.iter().zip(factors).map(|(&u, f)| f.value(u)).collect())
                .collect()
        };
        let (unit, values) = match *method {
            Method::Grid => {
                let unit = grid(factors)?;
                let values = to_values(&unit);
                (unit, values)
            }
            Method::Local { step } => local(factors, base, step)?,
            Method::Morris {
                trajectories,
                levels,
            } => {
                let unit = morris(k, trajectories, levels, seed)?;
                let values = to_values(&unit);
                (unit, values)
            }
            Method::Sobol { samples, .. } => {
                let unit = saltelli(k, samples, seed)?;
                let values = to_values(&unit);
                (unit, values)
            }
        };
        Ok(Design {
            method: method.clone(),
            factors: factors.to_vec(),
            unit: matrix(unit, k),
            values: matrix(values, k),
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.values.nrows()
    }

    /// Whether the design has no point.
    pub fn is_empty(&self) -> bool {
        self.values.nrows() == 0
    }
}

/// Points (rows of `k` values) as a matrix.
fn matrix(rows: Points, k: usize) -> Array2<f64> {
    let n = rows.len();
    Array2::from_shape_vec((n, k), rows.into_iter().flatten().collect())
        .expect("every point has one value per factor")
}

fn setting(what: &'static str, value: f64, reason: &'static str) -> DesignError {
    DesignError::Setting {
        what,
        value,
        reason,
    }
}

/// Points of a design, one `Vec` per point.
type Points = Vec<Vec<f64>>;

/// Full factorial, first factor slowest; levels at u = l/(levels − 1).
fn grid(factors: &[Factor]) -> Result<Vec<Vec<f64>>, DesignError> {
    let points: f64 = factors.iter().map(|f| f.levels as f64).product();
    if points > MAX_GRID_POINTS as f64 {
        return Err(DesignError::TooLarge {
            points,
            limit: MAX_GRID_POINTS,
        });
    }
    let n = points as usize;
    Ok((0..n)
        .map(|mut i| {
            let mut u = vec![0.0; factors.len()];
            for (j, f) in factors.iter().enumerate().rev() {
                u[j] = (i % f.levels) as f64 / (f.levels - 1) as f64;
                i /= f.levels;
            }
            u
        })
        .collect())
}

/// Base point, then p·e^{±step} for each factor in turn.
fn local(factors: &[Factor], base: &[f64], step: f64) -> Result<(Points, Points), DesignError> {
    if !(step > 0.0 && step <= 0.5) {
        return Err(setting(
            "step",
            step,
            "the relative step must lie in (0, 0.5]",
        ));
    }
    if let Some((f, &v)) = factors.iter().zip(base).find(|(_, &v)| v == 0.0) {
        return Err(DesignError::ZeroBase {
            name: f.name.clone(),
            value: v,
        });
    }
    let k = factors.len();
    let mut unit = vec![vec![0.0; k]];
    let mut values = vec![base.to_vec()];
    for j in 0..k {
        for h in [step, -step] {
            let mut u = vec![0.0; k];
            u[j] = h;
            let mut v = base.to_vec();
            v[j] = base[j] * h.exp();
            unit.push(u);
            values.push(v);
        }
    }
    Ok((unit, values))
}

/// Morris trajectories on the `levels`-grid of [0, 1]^k with Δ = levels/(2(levels − 1)).
fn morris(
    k: usize,
    trajectories: usize,
    levels: usize,
    seed: u64,
) -> Result<Vec<Vec<f64>>, DesignError> {
    if trajectories < 2 {
        return Err(setting(
            "trajectories",
            trajectories as f64,
            "at least 2 are needed for σ",
        ));
    }
    if levels < 2 || levels % 2 != 0 {
        return Err(setting(
            "levels",
            levels as f64,
            "the Morris grid needs an even number of levels ≥ 2",
        ));
    }
    let delta = levels as f64 / (2.0 * (levels - 1) as f64);
    // Base coordinates l/(levels − 1) with l < levels/2, so that x + Δ ≤ 1.
    let starts = levels / 2;
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed ^ 0x6d6f_7272_6973);
    let mut out = Vec::with_capacity(trajectories * (k + 1));
    let mut order: Vec<usize> = (0..k).collect();
    for _ in 0..trajectories {
        let mut x: Vec<f64> = (0..k)
            .map(|_| rng.random_range(0..starts) as f64 / (levels - 1) as f64)
            .collect();
        let up: Vec<bool> = (0..k).map(|_| rng.random_bool(0.5)).collect();
        for (xi, &u) in x.iter_mut().zip(&up) {
            if !u {
                *xi += delta;
            }
        }
        order.shuffle(&mut rng);
        out.push(x.clone());
        for &i in &order {
            x[i] += if up[i] { delta } else { -delta };
            out.push(x.clone());
        }
    }
    Ok(out)
}

/// Saltelli's A, B, A_B^(i) points (module docs), base row by base row.
fn saltelli(k: usize, samples: usize, seed: u64) -> Result<Vec<Vec<f64>>, DesignError> {
    if !(2..=MAX_SOBOL_SAMPLES).contains(&samples) {
        return Err(setting(
            "samples",
            samples as f64,
            "the base sample must lie in 2..=65536",
        ));
    }
    if k > MAX_SOBOL_FACTORS {
        return Err(setting(
            "factors",
            k as f64,
            "the Sobol design takes at most 128 factors",
        ));
    }
    let seed32 = (seed ^ (seed >> 32)) as u32;
    let mut out = Vec::with_capacity(samples * (k + 2));
    for j in 0..samples as u32 {
        let a: Vec<f64> = (0..k as u32)
            .map(|d| sobol_burley::sample(j, d, seed32) as f64)
            .collect();
        let b: Vec<f64> = (0..k as u32)
            .map(|d| sobol_burley::sample(j, k as u32 + d, seed32) as f64)
            .collect();
        out.push(a.clone());
        out.push(b.clone());
        for i in 0..k {
            let mut ab = a.clone();
            ab[i] = b[i];
            out.push(ab);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::spec::Scale;

    fn factors(k: usize) -> Vec<Factor> {
        (0..k)
            .map(|i| Factor::new(&format!("x{i}"), 1.0, 2.0, Scale::Lin, 3).unwrap())
            .collect()
    }

    #[test]
    fn the_grid_varies_the_first_factor_slowest() {
        let d = Design::new(&Method::Grid, &factors(2), &[], 0).unwrap();
        assert_eq!(d.len(), 9);
        assert_eq!(d.values.row(1).to_vec(), vec![1.0, 1.5]);
        assert_eq!(d.values.row(3).to_vec(), vec![1.5, 1.0]);
        assert_eq!(d.values.row(8).to_vec(), vec![2.0, 2.0]);
    }

    #[test]
    fn morris_steps_change_one_coordinate_by_delta_inside_the_cube() {
        let (k, levels) = (5, 4);
        let d = Design::new(
            &Method::Morris {
                trajectories: 30,
                levels,
            },
            &factors(k),
            &[],
            7,
        )
        .unwrap();
        let delta = 4.0 / 6.0;
        for t in d.unit.axis_chunks_iter(ndarray::Axis(0), k + 1) {
            let mut changed = vec![false; k];
            for s in 0..k {
                let (a, b) = (t.row(s), t.row(s + 1));
                let diff: Vec<usize> = (0..k).filter(|&i| a[i] != b[i]).collect();
                assert_eq!(diff.len(), 1);
                let i = diff[0];
                assert!(((b[i] - a[i]).abs() - delta).abs() < 1e-12);
                assert!(!changed[i]);
                changed[i] = true;
            }
            assert!(t.iter().all(|&u| (-1e-12..=1.0 + 1e-12).contains(&u)));
        }
    }

    #[test]
    fn saltelli_rows_share_a_and_b() {
        let k = 3;
        let d = Design::new(
            &Method::Sobol {
                samples: 8,
                bootstrap: 0,
            },
            &factors(k),
            &[],
            1,
        )
        .unwrap();
        assert_eq!(d.len(), 8 * (k + 2));
        for block in d.unit.axis_chunks_iter(ndarray::Axis(0), k + 2) {
            let (a, b) = (block.row(0), block.row(1));
            for i in 0..k {
                for j in 0..k {
                    assert_eq!(block[[2 + i, j]], if i == j { b[j] } else { a[j] });
                }
            }
        }
        let again = Design::new(&d.method, &factors(k), &[], 1).unwrap();
        assert_eq!(again, d, "same seed, same design");
    }

    #[test]
    fn a_zero_base_value_has_no_log_derivative() {
        let err = Design::new(&Method::Local { step: 0.01 }, &factors(1), &[0.0], 0).unwrap_err();
        assert!(err.to_string().contains("x0 is 0"), "{err}");
    }
}
