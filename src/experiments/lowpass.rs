//! Zero-phase low-pass filtering of sampled signals: a Butterworth filter of order
//! 2·sections run forwards and backwards ("filtfilt"), as used before differentiating
//! measured positions in inverse-dynamic identification (IDIM; M. Gautier, "Dynamic
//! identification of robots with power model", ICRA 1997; A. Janot, M. Gautier,
//! M. Brunot, "Data Set and Reference Models of EMPS", 2019).
//!
//! Each section is the bilinear-transform low-pass biquad with the cut-off prewarped
//! (R. Bristow-Johnson, "Cookbook formulae for audio EQ biquad filter coefficients"),
//! with the Butterworth quality factors Q_k = 1/(2·cos((2k − 1)·π/(4·sections))), so
//! the cascade is the Butterworth response of order 2·sections: −3 dB at the cut-off.
//! Run forwards and backwards, the phase cancels and the gain is squared (−6 dB at the
//! cut-off). As MATLAB's and SciPy's `filtfilt` do, the ends are padded by odd
//! reflection (2·x₀ − x_i; here six periods of the cut-off long) and each pass
//! starts in the steady state of its first value, so a signal's ends carry no
//! start-up transient.

use std::f64::consts::PI;

/// One second-order section: y = b0·x + b1·x₁ + b2·x₂ − a1·y₁ − a2·y₂.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
}

impl Biquad {
    /// The low-pass section with cut-off `fc` (Hz) at sample rate `fs` (Hz), quality `q`.
    fn low_pass(fc: f64, fs: f64, q: f64) -> Self {
        let w0 = 2.0 * PI * fc / fs;
        let (sin, cos) = w0.sin_cos();
        let alpha = sin / (2.0 * q);
        let a0 = 1.0 + alpha;
        let b1 = (1.0 - cos) / a0;
        Biquad {
            b: [0.5 * b1, b1, 0.5 * b1],
            a: [-2.0 * cos / a0, (1.0 - alpha) / a0],
        }
    }

    /// Filters `x` in place (transposed direct form II), starting in the steady
    /// state of a constant input equal to `x[0]` (no start-up step).
    fn run(&self, x: &mut [f64]) {
        let Some(&first) = x.first() else { return };
        let dc = (self.b[0] + self.b[1] + self.b[2]) / (1.0 + self.a[0] + self.a[1]);
        let out = dc * first;
        let mut s2 = self.b[2] * first - self.a[1] * out;
        let mut s1 = self.b[1] * first - self.a[0] * out + s2;
        for v in x.iter_mut() {
            let input = *v;
            let y = self.b[0] * input + s1;
            s1 = self.b[1] * input - self.a[0] * y + s2;
            s2 = self.b[2] * input - self.a[1] * y;
            *v = y;
        }
    }
}

/// A Butterworth low-pass of order 2·`sections`.
#[derive(Clone, Debug, PartialEq)]
pub struct Butterworth {
    sections: Vec<Biquad>,
    /// Samples of odd reflection at each end: six periods of the cut-off, so that
    /// the start-up of a non-constant signal decays before its first sample.
    pad: usize,
}

impl Butterworth {
    /// The low-pass of order 2·`sections` with cut-off `cutoff_hz` at `sample_hz`.
    /// The cut-off must lie in (0, sample_hz/2); the caller checks it.
    pub fn new(sections: usize, cutoff_hz: f64, sample_hz: f64) -> Self {
        let order = 2 * sections;
        let sections = (1..=sections)
            .map(|k| {
                let q = 1.0 / (2.0 * ((2 * k - 1) as f64 * PI / (2.0 * order as f64)).cos());
                Biquad::low_pass(cutoff_hz, sample_hz, q)
            })
            .collect();
        let pad = (6.0 * sample_hz / cutoff_hz).ceil() as usize + 3 * (order + 1);
        Butterworth { sections, pad }
    }

    /// `x` filtered forwards and backwards: zero phase, gain squared. Signals shorter
    /// than 2 samples are returned unchanged.
    pub fn filtfilt(&self, x: &[f64]) -> Vec<f64> {
        let n = x.len();
        if n < 2 {
            return x.to_vec();
        }
        let pad = self.pad.min(n - 1);
        let mut y = Vec::with_capacity(n + 2 * pad);
        y.extend((1..=pad).rev().map(|i| 2.0 * x[0] - x[i]));
        y.extend_from_slice(x);
        y.extend((1..=pad).map(|i| 2.0 * x[n - 1] - x[n - 1 - i]));
        for pass in 0..2 {
            for s in &self.sections {
                s.run(&mut y);
            }
            if pass == 0 {
                y.reverse();
            }
        }
        y.reverse();
        y[pad..pad + n].to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steady amplitude ratio of a sine through the zero-phase filter.
    fn gain(f: &Butterworth, hz: f64, fs: f64) -> f64 {
        let n = 20_000;
        let x: Vec<f64> = (0..n)
            .map(|i| (2.0 * PI * hz * i as f64 / fs).sin())
            .collect();
        let y = f.filtfilt(&x);
        let mid = n / 4..3 * n / 4;
        let peak = |v: &[f64]| v[mid.clone()].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        peak(&y) / peak(&x)
    }

    #[test]
    fn the_butterworth_cascade_is_minus_six_db_at_the_cutoff_zero_phase() {
        let f = Butterworth::new(2, 20.0, 1000.0);
        assert!((gain(&f, 20.0, 1000.0) - 0.5).abs() < 2e-3);
        assert!((gain(&f, 2.0, 1000.0) - 1.0).abs() < 1e-6);
        // Fourth order, squared: 80 dB/decade → 1/(1 + 10^8) at 200 Hz.
        assert!(gain(&f, 200.0, 1000.0) < 2e-8 * 1e2);
        // Zero phase: a slow sine comes out where it went in.
        let x: Vec<f64> = (0..5000).map(|i| (i as f64 * 0.005).sin()).collect();
        let y = f.filtfilt(&x);
        for i in 500..4500 {
            assert!((y[i] - x[i]).abs() < 1e-6, "{i}");
        }
    }

    #[test]
    fn a_straight_line_passes_unchanged_to_its_ends() {
        // Odd-reflection padding keeps a ramp a ramp, ends included (to 1e-8 of
        // its 0.6 range: what is left of the start-up after six cut-off periods).
        let f = Butterworth::new(2, 20.0, 1000.0);
        let x: Vec<f64> = (0..300).map(|i| 0.5 + 2e-3 * i as f64).collect();
        let y = f.filtfilt(&x);
        for (a, b) in x.iter().zip(&y) {
            assert!((a - b).abs() < 1e-8, "{a} {b}");
        }
        // Far from the ends, a ramp to rounding.
        for (a, b) in x[100..200].iter().zip(&y[100..200]) {
            assert!((a - b).abs() < 1e-10, "{a} {b}");
        }
    }
}
