//! The noise of a sampled curve read off the curve itself: what a file that states no
//! noise still tells about it.

use crate::io::import::glitches::median;

/// Points below which a curve's noise is not estimated.
pub const MIN_POINTS: usize = 20;

/// The noise (one standard deviation) of the values `y`, in their unit, along an
/// ascending abscissa, from their second differences y[k−1] − 2y[k] + y[k+1]: for
/// white noise of σ their variance is 6σ², and a smooth curve adds next to nothing;
/// the median of their magnitudes (×1.4826, a normal's σ) is not moved by the few
/// points where a resonance bends sharply. `None` on fewer than [`MIN_POINTS`].
pub fn second_difference(y: &[f64]) -> Option<f64> {
    if y.len() < MIN_POINTS {
        return None;
    }
    let mut d: Vec<f64> = y
        .windows(3)
        .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
        .collect();
    Some(1.4826 * median(&mut d) / 6f64.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// White noise of σ reads as σ; a smooth curve as next to nothing; a bend at one
    /// point does not move it.
    #[test]
    fn the_noise_of_a_curve_is_its_second_differences_spread() {
        use rand::{rngs::StdRng, SeedableRng};
        use rand_distr::{Distribution, Normal};
        let mut rng = StdRng::seed_from_u64(7);
        let normal = Normal::new(0.0, 0.17).unwrap();
        let mut e: Vec<f64> = (0..2000).map(|_| normal.sample(&mut rng)).collect();
        let sigma = second_difference(&e).unwrap();
        assert!((sigma / 0.17 - 1.0).abs() < 0.06, "{sigma}");
        let smooth: Vec<f64> = (0..2000).map(|k| (k as f64 / 300.0).sin()).collect();
        assert!(second_difference(&smooth).unwrap() < 1e-4);
        e[1000] += 20.0;
        assert!((second_difference(&e).unwrap() / sigma - 1.0).abs() < 0.01);
        assert_eq!(second_difference(&e[..19]), None);
    }
}
