//! The covariance of a least-squares fit: s² = SSR/(n − k), cov = s²·(JᵀJ)⁻¹ with J
//! the Jacobian of the residuals with respect to the reported parameters at the
//! optimum. Parameters the data do not determine get no variance instead of a NaN or
//! an infinity.
//!
//! J's columns have the parameters' units (an effort and a speed differ by orders of
//! magnitude), so (JᵀJ)⁻¹ is computed from the SVD of J with unit columns,
//! J = U·Σ·Vᵀ·D⁻¹ (D the column norms): (JᵀJ)⁻¹ = D⁻¹·V·Σ⁻²·Vᵀ·D⁻¹. A parameter is
//! not determined when its column is zero (it has no effect) or when it takes part
//! in a direction whose singular value is below [`RANK_TOLERANCE`] of the largest (a
//! combination the data leave free).

use nalgebra::DMatrix;

/// Singular values of the unit-column Jacobian below this fraction of the largest
/// span directions the data do not determine.
pub const RANK_TOLERANCE: f64 = 1e-10;

/// A parameter takes part in an undetermined direction when the squares of its
/// components along such directions add up to more than this.
const INVOLVED: f64 = 1e-12;

/// The covariance of the reported parameters, where determined.
#[derive(Clone, Debug)]
pub struct Covariance {
    /// cov[(a, b)], N·m and rad/s units as the parameters' (0 where undetermined).
    matrix: DMatrix<f64>,
    /// Whether each parameter is determined by the data.
    determined: Vec<bool>,
}

impl Covariance {
    /// From `jacobian` (n × k, residuals by reported parameters) and the cost `ssr`,
    /// n > k.
    pub fn new(jacobian: &DMatrix<f64>, ssr: f64) -> Covariance {
        let (n, k) = jacobian.shape();
        let s2 = ssr / (n - k) as f64;
        let norms: Vec<f64> = jacobian.column_iter().map(|c| c.norm()).collect();
        let active: Vec<usize> = (0..k)
            .filter(|&j| norms[j] > 0.0 && norms[j].is_finite())
            .collect();
        let mut determined = vec![false; k];
        let mut matrix = DMatrix::zeros(k, k);
        if active.is_empty() {
            return Covariance { matrix, determined };
        }
        let unit = DMatrix::from_fn(n, active.len(), |i, a| {
            jacobian[(i, active[a])] / norms[active[a]]
        });
        let svd = unit.svd(false, true);
        let Some(v_t) = svd.v_t else {
            return Covariance { matrix, determined };
        };
        let sigma = &svd.singular_values;
        let largest = sigma.max();
        let free: Vec<bool> = sigma
            .iter()
            .map(|&s| s <= RANK_TOLERANCE * largest || s.is_nan())
            .collect();
        for (a, &ja) in active.iter().enumerate() {
            let along_free: f64 = (0..sigma.len())
                .filter(|&i| free[i])
                .map(|i| v_t[(i, a)].powi(2))
                .sum();
            determined[ja] = along_free <= INVOLVED;
        }
        for (a, &ja) in active.iter().enumerate() {
            for (b, &jb) in active.iter().enumerate() {
                if !(determined[ja] && determined[jb]) {
                    continue;
                }
                let c: f64 = (0..sigma.len())
                    .filter(|&i| !free[i])
                    .map(|i| v_t[(i, a)] * v_t[(i, b)] / (sigma[i] * sigma[i]))
                    .sum();
                matrix[(ja, jb)] = s2 * c / (norms[ja] * norms[jb]);
            }
        }
        Covariance { matrix, determined }
    }

    /// The standard error of parameter `j`, `None` where not determined.
    pub fn std_error(&self, j: usize) -> Option<f64> {
        self.variance(&[(j, 1.0)])
    }

    /// The standard error of the difference of parameters `a` − `b`, `None` where
    /// either is not determined.
    pub fn std_error_of_difference(&self, a: usize, b: usize) -> Option<f64> {
        self.variance(&[(a, 1.0), (b, -1.0)])
    }

    /// The standard deviation of a combination Σ wⱼ·θⱼ given as (j, wⱼ).
    fn variance(&self, weights: &[(usize, f64)]) -> Option<f64> {
        if weights.iter().any(|&(j, _)| !self.determined[j]) {
            return None;
        }
        let var: f64 = weights
            .iter()
            .flat_map(|&(a, wa)| weights.iter().map(move |&(b, wb)| (a, wa, b, wb)))
            .map(|(a, wa, b, wb)| wa * wb * self.matrix[(a, b)])
            .sum();
        let se = var.max(0.0).sqrt();
        se.is_finite().then_some(se)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight line y = a + b·x: the textbook variances s²·Σx²/(n·Sxx) and s²/Sxx.
    #[test]
    fn a_straight_line_has_the_textbook_standard_errors() {
        let x = [1.0, 2.0, 4.0, 7.0, 11.0];
        let j = DMatrix::from_fn(5, 2, |i, c| if c == 0 { 1.0 } else { x[i] * 1e3 });
        let ssr = 0.6;
        let cov = Covariance::new(&j, ssr);
        let n = 5.0;
        let mean = x.iter().sum::<f64>() / n;
        let sxx: f64 = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() * 1e6;
        let sum_x2: f64 = x.iter().map(|v| (v * 1e3).powi(2)).sum();
        let s2 = ssr / 3.0;
        let se_a = (s2 * sum_x2 / (n * sxx)).sqrt();
        let se_b = (s2 / sxx).sqrt();
        assert!((cov.std_error(0).unwrap() / se_a - 1.0).abs() < 1e-12);
        assert!((cov.std_error(1).unwrap() / se_b - 1.0).abs() < 1e-12);
        // var(a − b) = var a + var b − 2 cov(a, b), cov(a, b) = −x̄·s²/Sxx.
        let cov_ab = -mean * 1e3 * s2 / sxx;
        let want = (se_a * se_a + se_b * se_b - 2.0 * cov_ab).sqrt();
        assert!((cov.std_error_of_difference(0, 1).unwrap() / want - 1.0).abs() < 1e-12);
    }

    #[test]
    fn parameters_without_effect_or_in_a_free_combination_have_none() {
        // Column 1 is zero; columns 2 and 3 are equal (only their sum is determined).
        let j = DMatrix::from_fn(6, 4, |i, c| match c {
            0 => 1.0,
            1 => 0.0,
            _ => (i as f64).powi(2),
        });
        let cov = Covariance::new(&j, 1.0);
        assert!(cov.std_error(0).is_some());
        assert_eq!(
            (cov.std_error(1), cov.std_error(2), cov.std_error(3)),
            (None, None, None)
        );
        assert_eq!(cov.std_error_of_difference(0, 2), None);
    }
}
