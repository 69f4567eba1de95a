//! Morris elementary effects from the trajectories of [`super::designs`].
//!
//! Each step of a trajectory changes one factor i by ±Δ in unit coordinates; its
//! elementary effect is EE_i = (y(after) − y(before))/(±Δ), the change of the output
//! per full range of the factor. Over the r trajectories (Campolongo et al. 2007):
//! μ*_i = mean |EE_i| (importance), μ_i = mean EE_i (sign, cancels for non-monotonic
//! effects), σ_i = sample standard deviation of EE_i (interaction or non-linearity).
//! All three carry the output's unit.

use ndarray::{ArrayView2, Axis};
use serde::Serialize;

/// Elementary-effect statistics of one factor for one output, output units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MorrisIndex {
    pub mu_star: f64,
    pub mu: f64,
    pub sigma: f64,
}

/// The statistics of each factor from unit points `unit` and outputs `y` in design
/// order (trajectories of k + 1 points). `None` if the points are not trajectories.
pub fn indices(unit: ArrayView2<f64>, y: &[f64], k: usize) -> Option<Vec<MorrisIndex>> {
    let n = unit.nrows();
    if y.len() != n || n % (k + 1) != 0 || n == 0 || unit.ncols() != k {
        return None;
    }
    let mut effects: Vec<Vec<f64>> = vec![Vec::new(); k];
    for (points, values) in unit.axis_chunks_iter(Axis(0), k + 1).zip(y.chunks(k + 1)) {
        for s in 0..k {
            let (x0, x1) = (points.row(s), points.row(s + 1));
            let i = (0..k).find(|&i| x0[i] != x1[i])?;
            effects[i].push((values[s + 1] - values[s]) / (x1[i] - x0[i]));
        }
    }
    Some(
        effects
            .iter()
            .map(|e| {
                let r = e.len() as f64;
                let mu = e.iter().sum::<f64>() / r;
                let mu_star = e.iter().map(|v| v.abs()).sum::<f64>() / r;
                let var = e.iter().map(|v| (v - mu) * (v - mu)).sum::<f64>() / (r - 1.0).max(1.0);
                MorrisIndex {
                    mu_star,
                    mu,
                    sigma: var.sqrt(),
                }
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::designs::{Design, Method};
    use crate::sweep::spec::{Factor, Scale};

    #[test]
    fn linear_effects_are_their_slopes_with_no_spread_and_products_spread() {
        let factors: Vec<Factor> = (0..3)
            .map(|i| Factor::new(&format!("x{i}"), 0.0, 1.0, Scale::Lin, 2).unwrap())
            .collect();
        let m = Method::Morris {
            trajectories: 40,
            levels: 4,
        };
        let d = Design::new(&m, &factors, &[], 11).unwrap();
        // y = 3·x0 − 2·x1 + 4·x1·x2
        let y: Vec<f64> = d
            .unit
            .rows()
            .into_iter()
            .map(|x| 3.0 * x[0] - 2.0 * x[1] + 4.0 * x[1] * x[2])
            .collect();
        let s = indices(d.unit.view(), &y, 3).unwrap();
        assert!((s[0].mu_star - 3.0).abs() < 1e-12 && (s[0].mu - 3.0).abs() < 1e-12);
        assert!(s[0].sigma < 1e-12);
        assert!(s[1].sigma > 0.5 && s[2].sigma > 0.5, "{s:?}");
        assert!(s[2].mu > 0.0);
    }
}
