//! Digital Butterworth low-pass filters as cascaded second-order sections, and their
//! zero-phase (forward-backward) application.
//!
//! Design: the analog Butterworth prototype's poles, the cut-off pre-warped and mapped
//! by the bilinear transform (Oppenheim & Schafer, *Discrete-Time Signal Processing*,
//! 3rd ed., 2010, §7.2.3), both zeros of each section at z = −1, unit gain at DC. The
//! magnitude is then exactly |H(f)|² = 1 / (1 + (tan(πf/fs) / tan(πfc/fs))^(2N)).
//!
//! Forward-backward filtering squares the magnitude and cancels the phase. Its edges
//! follow MATLAB's `filtfilt` and SciPy's `sosfiltfilt`: the signal is extended at
//! each end by its odd reflection about the end sample (which continues a local linear
//! trend), and every section starts in the steady state of a step to the first sample
//! of the pass (the step-response initial conditions; F. Gustafsson, "Determining the
//! initial states in forward-backward filtering", IEEE Trans. Signal Process. 44(4),
//! 1996, derives the exact ones). The extension is longer than SciPy's (three periods
//! of the cut-off), so that the start-up transient of each pass — a lag of a ramp, for
//! instance — dies out in it rather than in the signal; what little is left is cut off
//! by the caller's trimming. Written here rather than taken from a crate: the crates that have it
//! (sci-rs) bring a second nalgebra and three more dependencies for ~100 lines.

/// One second-order section in transposed direct form II:
/// H(z) = (b0 + b1 z⁻¹ + b2 z⁻²) / (1 + a1 z⁻¹ + a2 z⁻²).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Section {
    b: [f64; 3],
    a: [f64; 2],
}

impl Section {
    /// The DC gain H(1).
    fn dc_gain(&self) -> f64 {
        self.b.iter().sum::<f64>() / (1.0 + self.a[0] + self.a[1])
    }

    /// The state after a long step of height 1 at the input.
    fn step_state(&self) -> [f64; 2] {
        let g = self.dc_gain();
        [g - self.b[0], self.b[2] - self.a[1] * g]
    }

    /// Filters `x` in place from state `z`.
    fn run(&self, x: &mut [f64], mut z: [f64; 2]) {
        let ([b0, b1, b2], [a1, a2]) = (self.b, self.a);
        for v in x.iter_mut() {
            let y = b0 * *v + z[0];
            z[0] = b1 * *v - a1 * y + z[1];
            z[1] = b2 * *v - a2 * y;
            *v = y;
        }
    }
}

/// A digital Butterworth low-pass filter of a given order.
#[derive(Clone, Debug, PartialEq)]
pub struct Butterworth {
    sections: Vec<Section>,
    /// tan(π·fc/fs): the pre-warped cut-off.
    warped: f64,
    /// fc/fs.
    cutoff_per_sample: f64,
    order: usize,
}

impl Butterworth {
    /// The low-pass of `order` (≥ 1) with its −3 dB point at `cutoff_hz`, for samples
    /// at `sample_rate_hz`; `None` unless 0 < cutoff < sample_rate/2.
    pub fn low_pass(order: usize, cutoff_hz: f64, sample_rate_hz: f64) -> Option<Butterworth> {
        let nyquist = 0.5 * sample_rate_hz;
        if order == 0 || !(cutoff_hz > 0.0 && cutoff_hz < nyquist) {
            return None;
        }
        let warped = (std::f64::consts::PI * cutoff_hz / sample_rate_hz).tan();
        // With s normalised by 2·fs, the analog pole c·p maps to z = (1 + c·p)/(1 − c·p).
        let n = order as f64;
        let mut sections = Vec::with_capacity(order.div_ceil(2));
        for k in 0..order / 2 {
            let theta = std::f64::consts::PI * (2.0 * k as f64 + 1.0) / (2.0 * n);
            // The prototype pole −sin θ + i cos θ, scaled by the warped cut-off.
            let (re, im) = (-warped * theta.sin(), warped * theta.cos());
            let den = (1.0 - re).powi(2) + im * im;
            let z_re = (1.0 - re * re - im * im) / den;
            let z_abs2 = ((1.0 + re).powi(2) + im * im) / den;
            let a = [-2.0 * z_re, z_abs2];
            let g = (1.0 + a[0] + a[1]) / 4.0;
            sections.push(Section {
                b: [g, 2.0 * g, g],
                a,
            });
        }
        if order % 2 == 1 {
            let pole = (1.0 - warped) / (1.0 + warped);
            let g = (1.0 - pole) / 2.0;
            sections.push(Section {
                b: [g, g, 0.0],
                a: [-pole, 0.0],
            });
        }
        Some(Butterworth {
            sections,
            warped,
            cutoff_per_sample: cutoff_hz / sample_rate_hz,
            order,
        })
    }

    /// |H| at `f_hz` (one pass) for samples at `sample_rate_hz`: the design's closed form.
    pub fn gain(&self, f_hz: f64, sample_rate_hz: f64) -> f64 {
        let x = (std::f64::consts::PI * f_hz / sample_rate_hz).tan() / self.warped;
        1.0 / (1.0 + x.powi(2 * self.order as i32)).sqrt()
    }

    /// |H| at `f_hz` evaluated from the sections' coefficients (for tests of the
    /// design against its closed form).
    pub fn section_gain(&self, f_hz: f64, sample_rate_hz: f64) -> f64 {
        let w = 2.0 * std::f64::consts::PI * f_hz / sample_rate_hz;
        let (c1, s1, c2, s2) = (w.cos(), w.sin(), (2.0 * w).cos(), (2.0 * w).sin());
        self.sections
            .iter()
            .map(|s| {
                let num = (s.b[0] + s.b[1] * c1 + s.b[2] * c2).hypot(s.b[1] * s1 + s.b[2] * s2);
                let den = (1.0 + s.a[0] * c1 + s.a[1] * c2).hypot(s.a[0] * s1 + s.a[1] * s2);
                num / den
            })
            .product()
    }

    /// Samples of odd extension at each end: three periods of the cut-off, in which
    /// the start-up transient of each pass dies out (a 4th-order Butterworth's step
    /// response settles to 1 % in about 1.3 periods), and at least SciPy's
    /// `sosfiltfilt` default 3·(2·sections + 1), less one per first-order section.
    fn pad_len(&self) -> usize {
        let first_order = self.sections.iter().filter(|s| s.b[2] == 0.0).count();
        let scipy = 3 * (2 * self.sections.len() + 1 - first_order);
        let settle = (3.0 / self.cutoff_per_sample).ceil() as usize;
        scipy.max(settle)
    }

    /// `x` filtered forward then backward: zero phase, magnitude |H|². Fewer than two
    /// samples are returned as they are.
    pub fn zero_phase(&self, x: &[f64]) -> Vec<f64> {
        let n = x.len();
        if n < 2 {
            return x.to_vec();
        }
        let pad = self.pad_len().min(n - 1);
        let (first, last) = (x[0], x[n - 1]);
        let mut ext = Vec::with_capacity(n + 2 * pad);
        ext.extend((1..=pad).rev().map(|i| 2.0 * first - x[i]));
        ext.extend_from_slice(x);
        ext.extend((1..=pad).map(|i| 2.0 * last - x[n - 1 - i]));
        self.pass(&mut ext);
        ext.reverse();
        self.pass(&mut ext);
        ext.reverse();
        ext[pad..pad + n].to_vec()
    }

    /// One pass through every section, each started in the steady state of a step to
    /// the first sample it sees.
    fn pass(&self, x: &mut [f64]) {
        for s in &self.sections {
            let start = x[0];
            let [z0, z1] = s.step_state();
            s.run(x, [z0 * start, z1 * start]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sections_have_the_butterworth_magnitude() {
        for order in 1..=8 {
            let f = Butterworth::low_pass(order, 20.0, 1000.0).unwrap();
            assert_eq!(f.sections.len(), order.div_ceil(2));
            for freq in [0.0, 1.0, 10.0, 19.0, 20.0, 21.0, 40.0, 100.0, 499.0] {
                let (design, sections) = (f.gain(freq, 1000.0), f.section_gain(freq, 1000.0));
                assert!(
                    (design - sections).abs() < 1e-9 * design.max(1e-6),
                    "order {order}, {freq} Hz: {design} vs {sections}"
                );
            }
            let half_power = f.section_gain(20.0, 1000.0);
            assert!((half_power - 0.5f64.sqrt()).abs() < 1e-12, "{half_power}");
            assert!((f.section_gain(0.0, 1000.0) - 1.0).abs() < 1e-12);
        }
    }

    /// A sine through the zero-phase filter comes out scaled by |H|² and in phase.
    #[test]
    fn zero_phase_filtering_scales_a_sine_by_the_squared_gain_without_shifting_it() {
        let fs = 1000.0;
        let f = Butterworth::low_pass(4, 20.0, fs).unwrap();
        for freq in [5.0, 15.0, 20.0, 30.0] {
            let w = 2.0 * std::f64::consts::PI * freq / fs;
            let x: Vec<f64> = (0..8000).map(|k| (w * k as f64).sin()).collect();
            let y = f.zero_phase(&x);
            // Fit a·sin + b·cos over the middle (whole periods, edges excluded).
            let (mut s, mut c) = (0.0, 0.0);
            let middle = 2000..6000;
            for k in middle.clone() {
                s += y[k] * (w * k as f64).sin();
                c += y[k] * (w * k as f64).cos();
            }
            let m = middle.len() as f64 / 2.0;
            let (a, b) = (s / m, c / m);
            let expected = f.gain(freq, fs).powi(2);
            assert!((a - expected).abs() < 2e-3, "{freq} Hz: {a} vs {expected}");
            assert!(b.abs() < 2e-3, "{freq} Hz: phase term {b}");
        }
    }

    /// The initial conditions: a constant passes unchanged, edges included; a ramp (which
    /// the odd extension continues) to within 2e-4 of its rise over one period of the
    /// cut-off at the very ends (the start-up lag not quite died out in the extension)
    /// and to rounding from 300 samples (six periods) in.
    #[test]
    fn constants_and_ramps_pass_unchanged() {
        let f = Butterworth::low_pass(4, 20.0, 1000.0).unwrap();
        let constant = vec![3.25; 500];
        let y = f.zero_phase(&constant);
        assert!(y.iter().all(|v| (v - 3.25).abs() < 1e-12), "{y:?}");
        let ramp: Vec<f64> = (0..2000).map(|k| 0.5 + 1e-3 * k as f64).collect();
        let y = f.zero_phase(&ramp);
        let error = |range: std::ops::Range<usize>| {
            range.map(|k| (y[k] - ramp[k]).abs()).fold(0.0, f64::max)
        };
        let rise_per_period = 1e-3 * 1000.0 / 20.0;
        let ends = error(0..2000);
        assert!(ends < 2e-4 * rise_per_period && ends > 0.0, "{ends}");
        let inside = error(300..1700);
        assert!(inside < 1e-11, "{inside}");
    }

    #[test]
    fn impossible_designs_are_refused() {
        assert!(Butterworth::low_pass(0, 10.0, 100.0).is_none());
        assert!(Butterworth::low_pass(2, 50.0, 100.0).is_none());
        assert!(Butterworth::low_pass(2, 0.0, 100.0).is_none());
        assert!(Butterworth::low_pass(2, f64::NAN, 100.0).is_none());
        assert_eq!(
            Butterworth::low_pass(3, 10.0, 100.0)
                .unwrap()
                .zero_phase(&[2.0]),
            [2.0]
        );
    }
}
