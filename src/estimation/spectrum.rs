//! Signals over table angle: uniform resampling, detrending and the one-sided power
//! spectrum over cycles per revolution (the paper's Fig. 12), with its peaks.
//!
//! Normalisation. A record of `M` samples spaced Δ revolutions apart (span `S = M·Δ`
//! revolutions) has the discrete Fourier transform `X[k]`, `k = 0..M`. Bin `k` is the
//! order `k/S` cycles per revolution; the one-sided power spectral density is
//! `P[k] = c·|X[k]|²·Δ/M` (unit²/(cycle/rev)) with `c = 2` for `0 < k < M/2` and
//! `c = 1` at 0 and M/2, so that `Σ P[k]·(1/S) = mean(x²)` (Parseval). A sinusoid
//! `A·sin(2π·n·θ)` with a whole number of cycles in the record falls into one bin with
//! amplitude `2|X[k]|/M = A`. No window is applied: the record is whole revolutions,
//! where a rotational error is periodic and a rectangular window does not leak.

use rustfft::{num_complex::Complex, FftPlanner};
use serde::Serialize;

/// A one-sided power spectrum over order (cycles per revolution).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spectrum {
    /// Order of each bin, cycles/rev (0, 1/S, 2/S, …).
    pub order: Vec<f64>,
    /// Power spectral density, unit² per (cycle/rev).
    pub psd: Vec<f64>,
    /// Amplitude of the sinusoid each bin holds, unit.
    pub amplitude: Vec<f64>,
}

/// One peak of a spectrum.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Peak {
    /// Cycles per revolution.
    pub order: f64,
    /// Amplitude of the sinusoid at that order (unit of the signal).
    pub amplitude: f64,
    /// Power spectral density there, unit² per (cycle/rev).
    pub psd: f64,
}

/// `y` (sampled at strictly increasing `x`) linearly interpolated at `m` points
/// `x0 + span·j/m`, `j = 0..m` (the end point excluded, as for a periodic record).
/// Points outside `x` take the nearest end value.
pub fn resample(x: &[f64], y: &[f64], x0: f64, span: f64, m: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(m);
    let mut i = 0;
    for j in 0..m {
        let xi = x0 + span * j as f64 / m as f64;
        while i + 2 < x.len() && x[i + 1] < xi {
            i += 1;
        }
        let v = if x.len() < 2 || xi <= x[0] {
            y[0]
        } else if xi >= x[x.len() - 1] {
            y[y.len() - 1]
        } else {
            let f = (xi - x[i]) / (x[i + 1] - x[i]);
            y[i] + f * (y[i + 1] - y[i])
        };
        out.push(v);
    }
    out
}

/// Removes the least-squares straight line (mean and linear trend) over the index.
pub fn detrend(v: &mut [f64]) {
    let n = v.len() as f64;
    if v.len() < 2 {
        v.iter_mut().for_each(|x| *x = 0.0);
        return;
    }
    let xm = (n - 1.0) / 2.0;
    let ym = v.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (j, &y) in v.iter().enumerate() {
        let dx = j as f64 - xm;
        sxy += dx * (y - ym);
        sxx += dx * dx;
    }
    let slope = sxy / sxx;
    for (j, y) in v.iter_mut().enumerate() {
        *y -= ym + slope * (j as f64 - xm);
    }
}

/// The one-sided spectrum of `v` (already detrended), `v` spanning `span_rev`
/// revolutions (module docs give the normalisation).
pub fn power_spectrum(v: &[f64], span_rev: f64) -> Spectrum {
    let m = v.len();
    let mut buf: Vec<Complex<f64>> = v.iter().map(|&x| Complex::new(x, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(m).process(&mut buf);
    let delta = span_rev / m as f64;
    let half = m / 2;
    let mut s = Spectrum {
        order: Vec::with_capacity(half + 1),
        psd: Vec::with_capacity(half + 1),
        amplitude: Vec::with_capacity(half + 1),
    };
    for (k, x) in buf.iter().enumerate().take(half + 1) {
        let interior = k > 0 && !(m % 2 == 0 && k == half);
        let c = if interior { 2.0 } else { 1.0 };
        s.order.push(k as f64 / span_rev);
        s.psd.push(c * x.norm_sqr() * delta / m as f64);
        s.amplitude.push(c * x.norm() / m as f64);
    }
    s
}

impl Spectrum {
    /// The `count` largest local maxima above order 0, largest first.
    pub fn peaks(&self, count: usize) -> Vec<Peak> {
        let p = &self.psd;
        let mut peaks: Vec<Peak> = (1..p.len())
            .filter(|&k| p[k] > p[k - 1] && (k + 1 == p.len() || p[k] >= p[k + 1]))
            .map(|k| Peak {
                order: self.order[k],
                amplitude: self.amplitude[k],
                psd: p[k],
            })
            .collect();
        peaks.sort_by(|a, b| b.psd.total_cmp(&a.psd));
        peaks.truncate(count);
        peaks
    }

    /// The PSD at the bin nearest `order`.
    pub fn psd_at(&self, order: f64) -> f64 {
        let step = self.order.get(1).copied().unwrap_or(1.0);
        let k = ((order / step).round() as usize).min(self.psd.len().saturating_sub(1));
        self.psd[k]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn a_whole_number_of_cycles_lands_in_one_bin_with_its_amplitude() {
        let m = 4096;
        let revs = 2.0;
        let v: Vec<f64> = (0..m)
            .map(|j| 3.0 * (TAU * 72.0 * revs * j as f64 / m as f64).sin())
            .collect();
        let s = power_spectrum(&v, revs);
        let peak = s.peaks(1)[0];
        assert_eq!(peak.order, 72.0);
        assert!((peak.amplitude - 3.0).abs() < 1e-9, "{peak:?}");
        // Parseval: Σ P·Δorder = mean square = A²/2.
        let total: f64 = s.psd.iter().sum::<f64>() / revs;
        assert!((total - 4.5).abs() < 1e-9, "{total}");
    }

    #[test]
    fn detrend_removes_a_line_and_resample_interpolates() {
        let mut v: Vec<f64> = (0..10).map(|j| 2.0 + 0.5 * j as f64).collect();
        detrend(&mut v);
        assert!(v.iter().all(|x| x.abs() < 1e-12));
        let r = resample(&[0.0, 1.0, 3.0], &[0.0, 1.0, 5.0], 0.0, 3.0, 6);
        assert_eq!(r, vec![0.0, 0.5, 1.0, 2.0, 3.0, 4.0]);
    }
}
