//! The H1 frequency-response estimator with Welch averaging, and the coherence, from
//! an input and an output record sampled together (Bendat & Piersol, *Random Data*,
//! 4th ed., §9.2–9.3; Welch 1967).
//!
//! Both records are cut into segments of `L` samples overlapping by half; each segment
//! is detrended (least-squares straight line), multiplied by a periodic Hann window and
//! transformed (rustfft). Summed over the segments, per bin k:
//!
//! ```text
//! Sxx = Σ |X|²    Syy = Σ |Y|²    Sxy = Σ conj(X)·Y
//! H1  = Sxy / Sxx                 γ² = |Sxy|² / (Sxx·Syy)
//! ```
//!
//! H1 is unbiased by noise on the output and biased low by noise on the input; γ² is 1
//! for a noise-free linear system and falls as uncorrelated noise, nonlinearity
//! (backlash, friction) or leakage take a share of the output: γ² = 1/(1 + N/S) for
//! output noise N. Bin k is at k/(L·T) Hz: the segment length sets the resolution
//! 1/(L·T), and a peak narrower than a few bins is smeared by the window (its height
//! underestimated, its frequency kept to a fraction of a bin). The lowest two or three
//! bins are unreliable: the straight line removed from each segment takes most of
//! their content, and what is left is leakage from the bins above.
//!
//! **Prewhitening.** By default both records are first differenced (x[i] − x[i−1]).
//! The same linear filter on input and output cancels in H1 and γ² exactly, but an
//! open-loop drive drifts like a random walk, whose steep low-frequency spectrum would
//! otherwise leak through the window's sidelobes into the higher bins.

use rustfft::{num_complex::Complex, FftPlanner};
use serde::Serialize;

/// Settings of the estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WelchOptions {
    /// Samples per segment, L (≥ 8); the resolution is 1/(L·T).
    pub segment_len: usize,
    /// Overlap of successive segments as a fraction of L (default 0.5).
    pub overlap: f64,
    /// Difference both records before the estimate (default true; module docs).
    pub difference: bool,
}

impl WelchOptions {
    /// Segments of `segment_len` samples, 50 % overlap, differenced records.
    pub fn new(segment_len: usize) -> Self {
        WelchOptions {
            segment_len,
            overlap: 0.5,
            difference: true,
        }
    }
}

/// The estimate at the bins 1 ..= L/2 (the detrended DC bin is left out).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// Bin frequencies, Hz.
    pub frequency_hz: Vec<f64>,
    /// H1 = Sxy/Sxx, output unit per input unit (0 where the input has no power).
    #[serde(skip)]
    pub h: Vec<Complex<f64>>,
    /// Ordinary coherence γ², 0..1 (0 where input or output has no power).
    pub coherence: Vec<f64>,
    /// Number of segments averaged.
    pub segments: usize,
    /// Bin spacing 1/(L·T), Hz.
    pub resolution_hz: f64,
}

/// Why an estimate cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum WelchError {
    #[error("input and output have {x} and {y} samples: they must be sampled together")]
    Lengths { x: usize, y: usize },
    #[error("the sampling period {period} s must be positive and finite")]
    BadPeriod { period: f64 },
    #[error("a segment of {segment} samples is too short (at least 8)")]
    ShortSegment { segment: usize },
    #[error("the record has {samples} samples, fewer than one segment of {segment}: record longer or choose a shorter segment")]
    ShortRecord { samples: usize, segment: usize },
    #[error("the overlap {overlap} must be in [0, 1)")]
    BadOverlap { overlap: f64 },
}

/// H1 and γ² of output `y` over input `x`, both sampled every `period` s.
pub fn h1(x: &[f64], y: &[f64], period: f64, opts: &WelchOptions) -> Result<Estimate, WelchError> {
    if x.len() != y.len() {
        return Err(WelchError::Lengths {
            x: x.len(),
            y: y.len(),
        });
    }
    if !(period > 0.0 && period.is_finite()) {
        return Err(WelchError::BadPeriod { period });
    }
    let l = opts.segment_len;
    if l < 8 {
        return Err(WelchError::ShortSegment { segment: l });
    }
    if !(0.0..1.0).contains(&opts.overlap) {
        return Err(WelchError::BadOverlap {
            overlap: opts.overlap,
        });
    }
    let (x, y): (Vec<f64>, Vec<f64>) = if opts.difference {
        (difference(x), difference(y))
    } else {
        (x.to_vec(), y.to_vec())
    };
    if x.len() < l {
        return Err(WelchError::ShortRecord {
            samples: x.len(),
            segment: l,
        });
    }
    let hop = ((l as f64 * (1.0 - opts.overlap)).round() as usize).max(1);
    let segments = (x.len() - l) / hop + 1;
    let window: Vec<f64> = (0..l)
        .map(|k| 0.5 * (1.0 - (std::f64::consts::TAU * k as f64 / l as f64).cos()))
        .collect();
    let fft = FftPlanner::new().plan_fft_forward(l);
    let bins = l / 2;
    let (mut sxx, mut syy) = (vec![0.0; bins + 1], vec![0.0; bins + 1]);
    let mut sxy = vec![Complex::new(0.0, 0.0); bins + 1];
    let (mut bx, mut by) = (Vec::with_capacity(l), Vec::with_capacity(l));
    for s in 0..segments {
        let range = s * hop..s * hop + l;
        for (buf, v) in [(&mut bx, &x[range.clone()]), (&mut by, &y[range])] {
            buf.clear();
            buf.extend(
                detrended(v)
                    .zip(&window)
                    .map(|(a, w)| Complex::new(a * w, 0.0)),
            );
            fft.process(buf);
        }
        for k in 0..=bins {
            sxx[k] += bx[k].norm_sqr();
            syy[k] += by[k].norm_sqr();
            sxy[k] += bx[k].conj() * by[k];
        }
    }
    let mut est = Estimate {
        frequency_hz: Vec::with_capacity(bins),
        h: Vec::with_capacity(bins),
        coherence: Vec::with_capacity(bins),
        segments,
        resolution_hz: 1.0 / (l as f64 * period),
    };
    for k in 1..=bins {
        est.frequency_hz.push(k as f64 * est.resolution_hz);
        let powered = sxx[k] > 0.0 && syy[k] > 0.0;
        est.h.push(if sxx[k] > 0.0 {
            sxy[k] / sxx[k]
        } else {
            Complex::new(0.0, 0.0)
        });
        est.coherence.push(if powered {
            (sxy[k].norm_sqr() / (sxx[k] * syy[k])).min(1.0)
        } else {
            0.0
        });
    }
    Ok(est)
}

/// x[i] − x[i−1].
fn difference(x: &[f64]) -> Vec<f64> {
    x.windows(2).map(|w| w[1] - w[0]).collect()
}

/// `v` minus its least-squares straight line.
fn detrended(v: &[f64]) -> impl Iterator<Item = f64> + '_ {
    let n = v.len() as f64;
    let mid = (n - 1.0) / 2.0;
    let mean = v.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, a) in v.iter().enumerate() {
        let d = i as f64 - mid;
        sxy += d * (a - mean);
        sxx += d * d;
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    v.iter()
        .enumerate()
        .map(move |(i, a)| a - mean - slope * (i as f64 - mid))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// Bins not compared.
    const LOW_BINS: usize = 3;

    /// White noise through y[i] = 0.5·x[i] + 0.3·x[i−1] (+ output noise): H1 must be
    /// H(f) = 0.5 + 0.3·e^{−iωT} and γ² = S/(S + N).
    fn fir(noise: f64) -> (Estimate, Vec<Complex<f64>>, f64) {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let white = Normal::new(0.0, 1.0).unwrap();
        let x: Vec<f64> = (0..64 * 1024).map(|_| white.sample(&mut rng)).collect();
        let y: Vec<f64> = (0..x.len())
            .map(|i| {
                0.5 * x[i]
                    + if i > 0 { 0.3 * x[i - 1] } else { 0.0 }
                    + noise * white.sample(&mut rng)
            })
            .collect();
        let t = 1e-3;
        let est = h1(&x, &y, t, &WelchOptions::new(256)).unwrap();
        let exact = est
            .frequency_hz
            .iter()
            .map(|f| {
                Complex::new(0.5, 0.0)
                    + 0.3 * Complex::from_polar(1.0, -std::f64::consts::TAU * f * t)
            })
            .collect();
        (est, exact, noise)
    }

    #[test]
    fn h1_recovers_a_known_filter_and_its_coherence_is_one() {
        let (est, exact, _) = fir(0.0);
        assert_eq!(est.frequency_hz.len(), 128);
        assert!((est.resolution_hz - 1000.0 / 256.0).abs() < 1e-12);
        assert_eq!(est.segments, (64 * 1024 - 1 - 256) / 128 + 1);
        // The first bins hold what the per-segment detrend (a straight line) took away
        // and the window's leakage from the bins above: skip them (module docs).
        let mut worst = (0.0f64, 0.0f64);
        for ((h, e), g) in est.h.iter().zip(&exact).zip(&est.coherence).skip(LOW_BINS) {
            worst = (worst.0.max((h - e).norm() / e.norm()), worst.1.max(1.0 - g));
        }
        // The filter remembers one sample from before each segment: errors ~ 1/L.
        assert!(worst.0 < 1.0 / 256.0 && worst.1 < 1e-3, "{worst:?}");
    }

    #[test]
    fn output_noise_lowers_the_coherence_as_s_over_s_plus_n() {
        let (est, exact, noise) = fir(0.4);
        let mut worst: f64 = 0.0;
        for ((h, e), g) in est.h.iter().zip(&exact).zip(&est.coherence).skip(LOW_BINS) {
            // Signal and noise spectra are both white (before the common difference).
            let expected = e.norm_sqr() / (e.norm_sqr() + noise * noise);
            worst = worst.max((g - expected).abs());
            // Within 4 normalised random errors √(1 − γ²)/(|γ|·√(2·n_d)).
            let sigma = ((1.0 - expected) / expected).sqrt() / (2.0 * est.segments as f64).sqrt();
            assert!((h - e).norm() < 4.0 * sigma * e.norm(), "{h} vs {e}");
        }
        assert!(worst < 0.08, "coherence off by {worst}");
    }

    #[test]
    fn bad_input_is_an_error() {
        let x = vec![0.0; 100];
        assert!(h1(&x, &x[..50], 1.0, &WelchOptions::new(16)).is_err());
        assert!(h1(&x, &x, 0.0, &WelchOptions::new(16)).is_err());
        assert!(h1(&x, &x, 1.0, &WelchOptions::new(4)).is_err());
        assert!(h1(&x, &x, 1.0, &WelchOptions::new(128)).is_err());
        let est = h1(&x, &x, 1.0, &WelchOptions::new(16)).unwrap();
        assert!(est.coherence.iter().all(|&g| g == 0.0));
        assert!(est.h.iter().all(|h| h.norm() == 0.0));
    }
}
