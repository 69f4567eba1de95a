//! The laws linear in their parameters (`coulomb`, `coulomb_asymmetric`, any
//! [`MapLaw`] whose `is_linear` holds): ordinary
//! least squares through the SVD of the regressor, whose rows are the law's gradient.

use nalgebra::{DMatrix, DVector};

use super::map_law::MapLaw;

/// The least-squares values of a linear `law` over the runs (`speed`, `effort`) of a
/// map that passed [`super::check_map`] (which makes the regressor full rank).
pub(super) fn fit<L: MapLaw>(law: &L, speed: &[f64], effort: &[f64]) -> Vec<f64> {
    debug_assert!(law.is_linear());
    let k = law.parameters().len();
    let zeros = vec![0.0; k];
    let mut row = vec![0.0; k];
    let mut w = DMatrix::zeros(speed.len(), k);
    for (i, &v) in speed.iter().enumerate() {
        law.gradient(&zeros, v, &mut row);
        for (j, &x) in row.iter().enumerate() {
            w[(i, j)] = x;
        }
    }
    // Unit columns: the speed's column is in rad/s, the others are ±1.
    let norms: Vec<f64> = w.column_iter().map(|c| c.norm()).collect();
    for (j, &norm) in norms.iter().enumerate() {
        w.column_mut(j).unscale_mut(norm);
    }
    let y = DVector::from_column_slice(effort);
    let svd = w.svd(true, true);
    let eps = 1e-13 * svd.singular_values.max();
    match svd.solve(&y, eps) {
        Ok(theta) => theta.iter().zip(&norms).map(|(t, n)| t / n).collect(),
        Err(_) => zeros,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimation::friction_law::Law;

    #[test]
    fn exact_linear_laws_are_recovered() {
        let speed = [-20.0, -3.0, -0.2, 0.2, 3.0, 20.0];
        for (law, values) in [
            (Law::Coulomb, vec![2e-3, 1e-4, -3e-4]),
            (Law::CoulombAsymmetric, vec![2e-3, 1e-4, 1.5e-3, 1.3e-4]),
        ] {
            let effort: Vec<f64> = speed.iter().map(|&v| law.evaluate(&values, v)).collect();
            let got = fit(&law, &speed, &effort);
            for (g, w) in got.iter().zip(&values) {
                assert!((g - w).abs() < 1e-15, "{law}: {got:?}");
            }
        }
    }
}
