//! The frequency response of a periodically excited system at its excited lines, with
//! the coherence, the noise level of every line from the spread over periods, and the
//! nonlinear distortion (Pintelon & Schoukens, *System Identification: A Frequency
//! Domain Approach*, 2nd ed., Wiley–IEEE Press 2012, ch. 2–3).
//!
//! The record is framed by [`PeriodicRecord`] (period, transient periods dropped,
//! rectangular-window DFT of each whole period, excited lines). With X_p, Y_p the
//! spectra of period p = 1 … P at an excited line, two estimates:
//!
//! ```text
//! H1            H = Σ Y_p·X_p* / Σ |X_p|²          any input x, output y
//! reference     H = Σ Y_p·R_p* / Σ X_p·R_p*        two outputs y/x over the reference r
//! ```
//!
//! **Which for an output over an output** (load angle over motor angle): H1 with the
//! motor angle as input divides by Σ|X_p|² = P·(|X₀|² + σ²_x): noise on the motor
//! channel biases it low by 1/(1 + σ²_x/|X₀|²), worst where the motor barely moves —
//! at the motor's antiresonance, which is exactly the load/motor resonance. The
//! reference ratio uses the excitation r (the current) as an instrument: noise on
//! either output is uncorrelated with r and averages out of both sums, so the ratio is
//! consistent (with an exactly periodic r it is Ȳ/X̄, the ratio of the mean spectra).
//! Use [`reference_ratio`] for load/motor; [`h1`] when the input is the excitation.
//!
//! **Noise level.** Both are ratios of means over periods, H = Ā/B̄. To first order
//! H − H₀ = (Ā − H₀·B̄)/B̄, so the sample variance over periods of e_p = (A_p − H·B_p)/B̄,
//! divided by P, is the variance of H (the delta method; P&S's sample variance of the
//! FRF is its special case for a noise-free input). Its components along H and across
//! it give the standard deviations of |H| and of the phase directly, without assuming
//! circular noise: `gain_sigma_db` = 8.686·σ_|H|/|H| is **σ of |H| in dB**, one
//! standard deviation; `noise_sigma_rel` = √(E|H − H₀|²)/|H| the relative standard
//! deviation of the complex H.
//!
//! **Coherence** γ² = |Σ Y·X*|² / (Σ|X|²·Σ|Y|²) over the periods (for the reference
//! ratio, between the two outputs). For a periodic excitation it measures the noise's
//! share only: a periodic nonlinear distortion keeps γ² = 1.
//!
//! **Nonlinear distortion** at the excited lines is periodic, so neither σ nor γ² sees
//! it. With a random-odd multisine its level is read at the nearby left-out odd lines
//! ([`nonlinear_distortion::power_at_excited`]) and reported as `nonlinear_sigma_rel`;
//! `total_gain_sigma_db` adds it to the noise (half of it radial, as for any random
//! complex error of uniform phase). H is then the best linear approximation of the
//! system at this excitation level, and the total σ its uncertainty (P&S ch. 3).

use rustfft::num_complex::Complex;
use serde::Serialize;

use super::line_scatter;
use super::nonlinear_distortion::{self, DistortionBand};
use super::record::{PeriodSpectra, PeriodicError, PeriodicRecord};

/// Which estimate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Estimator {
    /// Σ Y·X* / Σ |X|².
    H1,
    /// Σ Y·R* / Σ X·R*, R the reference.
    ReferenceRatio,
}

/// The estimate at one excited line.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FrfLine {
    /// Harmonic number k of the period.
    pub line: usize,
    /// k·fs/N, Hz.
    pub frequency_hz: f64,
    /// Real and imaginary part of H, output unit per input unit.
    pub h_re: f64,
    pub h_im: f64,
    /// 20·log10|H|, dB re 1 output unit per input unit.
    pub gain_db: f64,
    /// arg H, degrees (−180, 180].
    pub phase_deg: f64,
    /// γ² over the periods, 0 … 1.
    pub coherence: f64,
    /// Noise: standard deviation of the complex H over |H| (module docs).
    pub noise_sigma_rel: f64,
    /// Noise: standard deviation of |H|, dB.
    pub gain_sigma_db: f64,
    /// Noise: standard deviation of the phase, degrees.
    pub phase_sigma_deg: f64,
    /// Odd-degree nonlinear distortion over |Y| (relative standard deviation of H);
    /// `None` unless the excitation leaves odd lines out.
    pub nonlinear_sigma_rel: Option<f64>,
    /// σ of |H| in dB from noise and nonlinear distortion together.
    pub total_gain_sigma_db: f64,
    /// The gain's scatter from line to line, dB ([`super::line_scatter`]): what the
    /// periods cannot show (stochastic nonlinear distortion of a full multisine).
    pub scatter_gain_sigma_db: f64,
}

impl FrfLine {
    pub fn h(&self) -> Complex<f64> {
        Complex::new(self.h_re, self.h_im)
    }
}

/// The estimate of one channel pair.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrfEstimate {
    pub estimator: Estimator,
    pub sample_rate_hz: f64,
    /// N, and its duration N/fs in s.
    pub samples_per_period: usize,
    pub period_s: f64,
    pub period_detected: bool,
    pub periods_in_record: usize,
    pub periods_dropped: usize,
    pub periods_used: usize,
    pub lines_detected: bool,
    /// One entry per excited line, ascending.
    pub lines: Vec<FrfLine>,
    /// Distortion levels of the output (numerator), per band.
    pub output_distortion: Vec<DistortionBand>,
    /// Distortion levels of the input (denominator), per band.
    pub input_distortion: Vec<DistortionBand>,
}

impl FrfEstimate {
    pub fn frequency_hz(&self) -> Vec<f64> {
        self.lines.iter().map(|l| l.frequency_hz).collect()
    }
    pub fn gain_db(&self) -> Vec<f64> {
        self.lines.iter().map(|l| l.gain_db).collect()
    }
    /// σ of the gain from the noise alone, dB.
    pub fn gain_sigma_db(&self) -> Vec<f64> {
        self.lines.iter().map(|l| l.gain_sigma_db).collect()
    }
    /// σ of the gain from noise and nonlinear distortion, dB.
    pub fn total_gain_sigma_db(&self) -> Vec<f64> {
        self.lines.iter().map(|l| l.total_gain_sigma_db).collect()
    }
    /// The uncertainty of the gain as far as the record tells, dB: the larger of
    /// `total_gain_sigma_db` and `scatter_gain_sigma_db` at each line — the σ to
    /// search resonances with ([`crate::estimation::extrema`]).
    pub fn gain_uncertainty_db(&self) -> Vec<f64> {
        let larger = |l: &FrfLine| l.total_gain_sigma_db.max(l.scatter_gain_sigma_db);
        self.lines.iter().map(larger).collect()
    }
    /// H at each line.
    pub fn h(&self) -> Vec<Complex<f64>> {
        self.lines.iter().map(FrfLine::h).collect()
    }
}

/// H1 of `output` over `input` (module docs), both sampled with the record's
/// reference; `input` may be the reference itself.
pub fn h1(
    rec: &PeriodicRecord,
    input: &[f64],
    output: &[f64],
) -> Result<FrfEstimate, PeriodicError> {
    let x = rec.spectra("input", input)?;
    let y = rec.spectra("output", output)?;
    let nl = nonlinear_relative(rec, &[&y], &[]);
    let lines = rec
        .excited
        .iter()
        .zip(nl)
        .map(|(&k, nl)| {
            let (a, b) = (cross(&y, &x, k), cross(&x, &x, k));
            let g = coherence(&x, &y, k);
            line(rec, k, &a, &b, g, nl, "input")
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(estimate(rec, Estimator::H1, lines, &y, &x))
}

/// `numerator` over `denominator`, two outputs sampled with the reference, by the
/// reference ratio (module docs: the right estimate when the denominator is noisy).
pub fn reference_ratio(
    rec: &PeriodicRecord,
    numerator: &[f64],
    denominator: &[f64],
) -> Result<FrfEstimate, PeriodicError> {
    let y = rec.spectra("numerator", numerator)?;
    let x = rec.spectra("denominator", denominator)?;
    let r = &rec.reference;
    let nl = nonlinear_relative(rec, &[&y], &[&x]);
    let lines = rec
        .excited
        .iter()
        .zip(nl)
        .map(|(&k, nl)| {
            let (a, b) = (cross(&y, r, k), cross(&x, r, k));
            let g = coherence(&x, &y, k);
            line(rec, k, &a, &b, g, nl, "denominator")
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(estimate(rec, Estimator::ReferenceRatio, lines, &y, &x))
}

fn estimate(
    rec: &PeriodicRecord,
    estimator: Estimator,
    mut lines: Vec<FrfLine>,
    y: &PeriodSpectra,
    x: &PeriodSpectra,
) -> FrfEstimate {
    let f: Vec<f64> = lines.iter().map(|l| l.frequency_hz).collect();
    let g: Vec<f64> = lines.iter().map(|l| l.gain_db).collect();
    let scatter = line_scatter::scatter(&f, &g, rec.options.scatter_half_window);
    for (l, s) in lines.iter_mut().zip(scatter) {
        l.scatter_gain_sigma_db = s;
    }
    let spacing = rec.spacing_hz();
    let edges = match &rec.options.band_edges_hz {
        Some(e) => e.clone(),
        None => nonlinear_distortion::octave_edges(
            rec.excited[0] as f64 * spacing,
            rec.excited[rec.excited.len() - 1] as f64 * spacing,
        ),
    };
    let z = rec.options.distortion_z;
    FrfEstimate {
        estimator,
        sample_rate_hz: rec.sample_rate_hz,
        samples_per_period: rec.samples_per_period,
        period_s: rec.samples_per_period as f64 / rec.sample_rate_hz,
        period_detected: rec.period_detected,
        periods_in_record: rec.periods_in_record,
        periods_dropped: rec.periods_dropped,
        periods_used: rec.periods_used(),
        lines_detected: rec.lines_detected,
        lines,
        output_distortion: nonlinear_distortion::bands(y, &rec.excited, spacing, &edges, z),
        input_distortion: nonlinear_distortion::bands(x, &rec.excited, spacing, &edges, z),
    }
}

/// γ² between x and y at line k over the periods.
/// Per period, line `k` of `a` times the conjugate of `b`'s (a cross-spectrum's terms).
fn cross(a: &PeriodSpectra, b: &PeriodSpectra, k: usize) -> Vec<Complex<f64>> {
    a.line(k)
        .zip(b.line(k))
        .map(|(a, b)| a * b.conj())
        .collect()
}

fn coherence(x: &PeriodSpectra, y: &PeriodSpectra, k: usize) -> f64 {
    let sxy: Complex<f64> = cross(y, x, k).into_iter().sum();
    let sxx: f64 = x.line(k).map(|v| v.norm_sqr()).sum();
    let syy: f64 = y.line(k).map(|v| v.norm_sqr()).sum();
    if sxx > 0.0 && syy > 0.0 {
        (sxy.norm_sqr() / (sxx * syy)).min(1.0)
    } else {
        0.0
    }
}

/// Relative nonlinear variance of H at each excited line: the sum over the channels
/// of their odd-degree distortion power over |X̄|² (H1: the output's only — the
/// input's distortion is part of the excitation the system sees).
fn nonlinear_relative(
    rec: &PeriodicRecord,
    outputs: &[&PeriodSpectra],
    inputs: &[&PeriodSpectra],
) -> Vec<Option<f64>> {
    let k = rec.options.nonlinear_neighbours;
    let per_channel: Vec<(Vec<Option<f64>>, &PeriodSpectra)> = outputs
        .iter()
        .chain(inputs)
        .map(|s| {
            (
                nonlinear_distortion::power_at_excited(s, &rec.excited, k),
                *s,
            )
        })
        .collect();
    rec.excited
        .iter()
        .enumerate()
        .map(|(i, &line)| {
            per_channel.iter().try_fold(0.0, |acc, (power, s)| {
                let level = s.mean(line).norm_sqr();
                power[i].map(|p| acc + if level > 0.0 { p / level } else { 0.0 })
            })
        })
        .collect()
}

/// Large finite stand-in for an infinite σ (JSON has no infinity).
const NO_INFORMATION: f64 = 1e9;
const DB_PER_NEPER: f64 = 20.0 / std::f64::consts::LN_10;

/// H = ΣA/ΣB at line k with its noise (module docs), γ² and the relative nonlinear
/// variance `nl`.
fn line(
    rec: &PeriodicRecord,
    k: usize,
    a: &[Complex<f64>],
    b: &[Complex<f64>],
    coherence: f64,
    nl: Option<f64>,
    channel: &'static str,
) -> Result<FrfLine, PeriodicError> {
    let p = a.len() as f64;
    let b_mean = b.iter().sum::<Complex<f64>>() / p;
    if b_mean.norm_sqr() == 0.0 {
        return Err(PeriodicError::LineNotExcited { channel, line: k });
    }
    let h = a.iter().sum::<Complex<f64>>() / p / b_mean;
    let unit = if h.norm() > 0.0 {
        h / h.norm()
    } else {
        Complex::new(1.0, 0.0)
    };
    let (mut radial, mut across) = (0.0, 0.0);
    for (a, b) in a.iter().zip(b) {
        let e = (a - h * b) / b_mean * unit.conj();
        radial += e.re * e.re;
        across += e.im * e.im;
    }
    let norm = p * (p - 1.0);
    let (radial, across) = (radial / norm, across / norm);
    let modulus = h.norm();
    let rel = |v: f64| {
        if modulus > 0.0 {
            v.sqrt() / modulus
        } else {
            NO_INFORMATION
        }
    };
    let gain_rel = rel(radial);
    let total = (gain_rel * gain_rel + nl.unwrap_or(0.0) / 2.0).sqrt();
    Ok(FrfLine {
        line: k,
        frequency_hz: k as f64 * rec.spacing_hz(),
        h_re: h.re,
        h_im: h.im,
        gain_db: 20.0 * modulus.max(1e-300).log10(),
        phase_deg: h.arg().to_degrees(),
        coherence,
        noise_sigma_rel: rel(radial + across),
        gain_sigma_db: (DB_PER_NEPER * gain_rel).min(NO_INFORMATION),
        phase_sigma_deg: rel(across).atan().to_degrees(),
        nonlinear_sigma_rel: nl.map(f64::sqrt),
        total_gain_sigma_db: (DB_PER_NEPER * total).min(NO_INFORMATION),
        scatter_gain_sigma_db: 0.0, // filled in by `estimate`
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimation::periodic::record::PeriodicOptions;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    use std::f64::consts::TAU;

    /// 400 periods of 64 samples: r = cos on lines 3 and 7; the "motor" m = r plus white
    /// noise of `noise` rms; the "load" l = 2·(r delayed by one sample) plus a little
    /// noise of its own (l/m = 2·e^{−iω} on the periodic part).
    fn channels(noise: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let mut rng = rand::rngs::StdRng::seed_from_u64(9);
        let white = Normal::new(0.0, noise).unwrap();
        let r = |i: usize| {
            let t = i as f64 / 64.0;
            (TAU * 3.0 * t).cos() + (TAU * 7.0 * t + 0.5).cos()
        };
        let n = 400 * 64;
        let reference: Vec<f64> = (0..n).map(r).collect();
        let motor: Vec<f64> = (0..n).map(|i| r(i) + white.sample(&mut rng)).collect();
        let load: Vec<f64> = (0..n)
            .map(|i| 2.0 * r(i + 63) + 0.05 * white.sample(&mut rng))
            .collect();
        (reference, motor, load)
    }

    #[test]
    fn the_reference_ratio_is_unbiased_where_h1_over_a_noisy_motor_is_not() {
        let (r, m, l) = channels(2.0);
        let o = PeriodicOptions {
            samples_per_period: Some(64),
            ..Default::default()
        };
        let rec = PeriodicRecord::new(&r, 64.0, &o).unwrap();
        assert_eq!(rec.excited, vec![3, 7]);
        let ratio = reference_ratio(&rec, &l, &m).unwrap();
        let biased = h1(&rec, &m, &l).unwrap();
        for (a, b) in ratio.lines.iter().zip(&biased.lines) {
            let truth = Complex::from_polar(2.0, -TAU * a.line as f64 / 64.0);
            // Within 3 σ of the truth.
            let sigma = a.noise_sigma_rel * truth.norm();
            assert!((a.h() - truth).norm() < 3.0 * sigma, "{a:?} vs {truth}");
            // H1 divides by Σ|M|² = P·(|M₀|² + σ²): low by 1/(1 + σ²/|M₀|²). Line
            // amplitude 1; white noise of 2 rms leaves (2/N)²·N·4 = 0.25 per line: 0.8.
            // Its random error: √(0.25/2/399) ≈ 0.018 radially; 3.5 of them allowed.
            let expected = 1.0 / (1.0 + 0.25);
            let low = b.h().norm() / truth.norm();
            assert!((low - expected).abs() < 0.063, "{low} vs {expected}");
        }
    }

    #[test]
    fn a_line_without_input_power_is_an_error_naming_it() {
        let (r, m, l) = channels(0.1);
        let o = PeriodicOptions {
            samples_per_period: Some(64),
            ..Default::default()
        };
        let rec = PeriodicRecord::new(&r, 64.0, &o).unwrap();
        let silent = vec![0.0; r.len()];
        let e = h1(&rec, &silent, &l).unwrap_err();
        assert!(
            matches!(
                e,
                PeriodicError::LineNotExcited {
                    channel: "input",
                    line: 3
                }
            ),
            "{e}"
        );
        assert!(reference_ratio(&rec, &l, &m).is_ok());
    }
}
