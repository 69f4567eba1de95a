//! Local (one-at-a-time) sensitivities: the normalised derivative ∂ln y/∂ln p at the
//! base point, by the central difference over the points p·e^{±h} of
//! [`super::designs`]:
//!
//! ```text
//! S = (y(p·e^{+h}) − y(p·e^{−h})) / (2h·y(p))
//! ```
//!
//! accurate to O(h²). S = 0.5 means y ∝ √p near the base; undefined when y(p) = 0.

/// The sensitivity of each of the `k` factors from outputs `y` in design order
/// (base, then +h and −h for each factor); `None` where the base output is 0.
pub fn sensitivities(y: &[f64], k: usize, step: f64) -> Vec<Option<f64>> {
    (0..k)
        .map(|j| {
            let (y0, plus, minus) = (y[0], y[1 + 2 * j], y[2 + 2 * j]);
            let s = (plus - minus) / (2.0 * step * y0);
            (y0 != 0.0 && s.is_finite()).then_some(s)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_power_law_gives_its_exponent() {
        let h = 0.01f64;
        let f = |a: f64, b: f64| 3.0 * a.sqrt() / b.powi(2);
        let (a, b) = (2.0, 5.0);
        let y = [
            f(a, b),
            f(a * h.exp(), b),
            f(a * (-h).exp(), b),
            f(a, b * h.exp()),
            f(a, b * (-h).exp()),
        ];
        let s = sensitivities(&y, 2, h);
        assert!((s[0].unwrap() - 0.5).abs() < 1e-4 && (s[1].unwrap() + 2.0).abs() < 1e-3);
    }
}
