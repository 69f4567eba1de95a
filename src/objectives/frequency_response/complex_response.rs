//! The complex residual of a frequency response with phase: per line, the error of
//! the natural log of the gain and the error of the phase, each over its noise —
//! the real and imaginary parts of ln(H_model/H_measured). A relative complex noise
//! H·(1 + ε), ε = ε_r + i·ε_i with σ per part, moves ln|H| by ε_r and the phase by
//! ε_i (rad): the same σ in both, so 2 % complex noise weighs alike in gain and phase.
//!
//! **Wrapping.** The phase error is taken modulo 2π into (−π, π]: a file's phase may
//! be wrapped or unwrapped, and either reads the same.
//!
//! **Delay.** A delay given in the manifest is taken out of the phase when the file is
//! read ([`measured::complex_points`](crate::experiments::frequency_response::measured::complex_points)); an unknown one is fitted at every
//! evaluation, for the model being evaluated (variable projection: the cost the
//! search sees is already minimised over the delay, and finite differences of these
//! residuals give the Jacobian of the reduced problem). It starts from a straight
//! line through the unwrapped phase error against frequency and is refined by
//! Gauss–Newton on the wrapped errors.

use std::f64::consts::TAU;

pub use crate::experiments::frequency_response::measured::rms_errors;
use crate::experiments::frequency_response::measured::ComplexPoints;

pub use crate::angle::wrap;

/// The measured lines' noise: σ of ln|H| and of the phase (rad) per line, the
/// stated one or, where none is stated, `default` for both.
pub fn sigmas(m: &ComplexPoints, default: f64) -> (Vec<f64>, Vec<f64>) {
    let n = m.frequency_hz.len();
    let or_default = |s: &Option<Vec<f64>>| {
        s.clone()
            .unwrap_or_else(|| vec![default; n])
            .into_iter()
            .map(|v| if v.is_finite() && v > 0.0 { v } else { default })
            .collect()
    };
    (or_default(&m.sigma_ln), or_default(&m.sigma_phase))
}

/// The delay (s) that best explains the phase errors `error` (model − measured, rad)
/// at angular frequencies `omega` with weights `w`: the measured phase carries
/// `−sign·ω·delay` more than the model's.
pub fn fit_delay(error: &[f64], omega: &[f64], w: &[f64], sign: f64) -> f64 {
    let x: Vec<f64> = omega.iter().map(|o| sign * o).collect();
    let mut tau = straight_line_slope(&unwrap(error), &x, w);
    for _ in 0..6 {
        let (mut num, mut den) = (0.0, 0.0);
        for ((e, xk), wk) in error.iter().zip(&x).zip(w) {
            let d = wrap(e - xk * tau);
            num += wk * xk * d;
            den += wk * xk * xk;
        }
        if den <= 0.0 {
            return 0.0;
        }
        let step = num / den;
        tau += step;
        if step.abs() <= 1e-12 * tau.abs().max(1e-15) {
            break;
        }
    }
    if tau.is_finite() {
        tau
    } else {
        0.0
    }
}

/// The phases made continuous along the lines (jumps of more than π taken out).
pub fn unwrap(phase: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(phase.len());
    let mut offset = 0.0;
    for (k, &p) in phase.iter().enumerate() {
        if k > 0 {
            let jump: f64 = p + offset - out[k - 1];
            offset -= TAU * (jump / TAU).round();
        }
        out.push(p + offset);
    }
    out
}

/// The slope of the weighted least-squares line y ≈ a + b·x (0 when x does not vary).
fn straight_line_slope(y: &[f64], x: &[f64], w: &[f64]) -> f64 {
    let sw: f64 = w.iter().sum();
    if sw <= 0.0 {
        return 0.0;
    }
    let mean = |v: &[f64]| v.iter().zip(w).map(|(a, b)| a * b).sum::<f64>() / sw;
    let (mx, my) = (mean(x), mean(y));
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for ((xk, yk), wk) in x.iter().zip(y).zip(w) {
        sxy += wk * (xk - mx) * (yk - my);
        sxx += wk * (xk - mx) * (xk - mx);
    }
    if sxx > 0.0 {
        sxy / sxx
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_delay_is_found_through_the_wraps_of_its_phase() {
        let tau = 3.7e-3;
        let omega: Vec<f64> = (1..400).map(|k| TAU * k as f64).collect();
        // The measured phase lags the model's by ω·τ; stored wrapped, with noise.
        let error: Vec<f64> = omega
            .iter()
            .enumerate()
            .map(|(k, o)| wrap(o * tau + 0.01 * ((k * 7919 % 13) as f64 - 6.0) / 6.0))
            .collect();
        let w = vec![1.0; omega.len()];
        let fitted = fit_delay(&error, &omega, &w, 1.0);
        assert!((fitted - tau).abs() < 1e-6, "{fitted}");
        let inverted = fit_delay(&error, &omega, &w, -1.0);
        assert!((inverted + tau).abs() < 1e-6, "{inverted}");
    }
}
