//! Measurement noise for virtual experiments (seeded, Gaussian), so that fixtures
//! can stand in for real data: a gain curve's amplitude ratio or a torque record
//! disturbed by a given percentage, an angle record by a given standard deviation.
//! The levels given must be finite (the command line checks them): a non-finite one
//! is the caller's error and panics.

use rand::{rngs::StdRng, SeedableRng};
use rand_distr::{Distribution, Normal};

/// N(0, σ²).
fn normal(sigma: f64) -> Normal<f64> {
    // Invariant: Normal refuses only a non-finite σ, and the levels given are finite
    // (module docs), as is the RMS of a simulated record.
    Normal::new(0.0, sigma).expect("a finite σ")
}

/// Multiplies each gain's amplitude ratio by (1 + ε), ε ~ N(0, (percent/100)²):
/// adds 20·log10(1 + ε) dB.
pub fn perturb_gain_db(gain_db: &mut [f64], percent: f64, seed: u64) {
    if percent <= 0.0 {
        return;
    }
    let normal = normal(percent / 100.0);
    let mut rng = StdRng::seed_from_u64(seed);
    for g in gain_db {
        let e: f64 = normal.sample(&mut rng);
        *g += 20.0 * (1.0 + e).max(1e-3).log10();
    }
}

/// Multiplies each complex ratio (gain dB, phase rad) by 1 + ε_r + i·ε_i, ε_r and
/// ε_i ~ N(0, (percent/100)²) each: an analyser's complex noise, which moves ln|H|
/// and the phase alike.
pub fn perturb_complex(gain_db: &mut [f64], phase_rad: &mut [f64], percent: f64, seed: u64) {
    if percent <= 0.0 {
        return;
    }
    let normal = normal(percent / 100.0);
    let mut rng = StdRng::seed_from_u64(seed);
    for (g, ph) in gain_db.iter_mut().zip(phase_rad.iter_mut()) {
        let (re, im): (f64, f64) = (1.0 + normal.sample(&mut rng), normal.sample(&mut rng));
        *g += 20.0 * re.hypot(im).max(1e-3).log10();
        *ph += im.atan2(re);
    }
}

/// Adds N(0, σ²) with σ = percent/100 of the record's RMS to every sample.
pub fn perturb_by_rms(values: &mut [f64], percent: f64, seed: u64) {
    if percent <= 0.0 || values.is_empty() {
        return;
    }
    let rms = (values.iter().map(|v| v * v).sum::<f64>() / values.len() as f64).sqrt();
    let normal = normal(percent / 100.0 * rms);
    let mut rng = StdRng::seed_from_u64(seed);
    for v in values {
        *v += normal.sample(&mut rng);
    }
}

/// Multiplies each value by (1 + ε), ε ~ N(0, (percent/100)²): a scatter of that
/// percentage of each value (the runs of a friction map).
pub fn perturb_relative(values: &mut [f64], percent: f64, seed: u64) {
    if percent <= 0.0 {
        return;
    }
    let normal = normal(percent / 100.0);
    let mut rng = StdRng::seed_from_u64(seed);
    for v in values {
        *v *= 1.0 + normal.sample(&mut rng);
    }
}

/// Adds N(0, σ²) to every sample (σ in the values' unit): e.g. encoder-reading noise
/// on an angle record.
pub fn perturb_absolute(values: &mut [f64], sigma: f64, seed: u64) {
    if sigma <= 0.0 {
        return;
    }
    let normal = normal(sigma);
    let mut rng = StdRng::seed_from_u64(seed);
    for v in values {
        *v += normal.sample(&mut rng);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_has_the_asked_size_and_is_seeded() {
        let mut a = vec![2.0; 20_000];
        perturb_by_rms(&mut a, 1.0, 3);
        let sd = (a.iter().map(|v| (v - 2.0) * (v - 2.0)).sum::<f64>() / a.len() as f64).sqrt();
        assert!((sd / 0.02 - 1.0).abs() < 0.03, "{sd}");
        let mut b = vec![2.0; 20_000];
        perturb_by_rms(&mut b, 1.0, 3);
        assert_eq!(a, b);
        let mut c = vec![0.0; 20_000];
        perturb_absolute(&mut c, 0.5, 4);
        let sd = (c.iter().map(|v| v * v).sum::<f64>() / c.len() as f64).sqrt();
        assert!((sd / 0.5 - 1.0).abs() < 0.03, "{sd}");
    }
}
