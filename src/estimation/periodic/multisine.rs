//! Periodic multisine excitation: a sum of cosines on the harmonics of one period,
//! repeated for P periods, so that every period of the steady-state response holds a
//! whole number of cycles of every excited line and the DFT of a period has no leakage
//! (Pintelon & Schoukens, *System Identification: A Frequency Domain Approach*, 2nd ed.,
//! Wiley–IEEE Press 2012, ch. 2–3: periodic excitations and their FRF measurement).
//!
//! One period of N samples at fs:
//!
//! ```text
//! u[n] = Σᵢ A·cos(2π·kᵢ·n/N + φᵢ),   n = 0 … N−1,   line kᵢ at kᵢ·fs/N Hz
//! ```
//!
//! **Line sets** (the harmonic numbers kᵢ inside the band):
//! - *full*: every line;
//! - *odd*: odd kᵢ only — even-degree nonlinearities then show at the even lines and
//!   leave the excited lines alone;
//! - *random odd*: the odd lines cut into groups of `group` consecutive odd lines, one
//!   line of each whole group left out at random (a trailing partial group is kept
//!   whole). The left-out odd lines catch odd-degree nonlinear distortion separately
//!   from the noise (P&S ch. 3; groups of 3 or 4 are usual).
//!
//! **Phases.** Schroeder's, φᵢ = −π·i·(i−1)/F for the i-th of F lines of equal
//! amplitude (M. R. Schroeder, "Synthesis of low-peak-factor signals and binary
//! sequences with low autocorrelation", IEEE Trans. Inf. Theory 16(1), 85–89, 1970),
//! which spreads the lines' energy like a chirp and keeps the crest factor near 1.7 for
//! a dense band, or independent uniform random phases (seeded), whose crest factor
//! grows towards that of Gaussian noise (3–4) — and whose amplitude distribution is
//! close to Gaussian, which is what the best-linear-approximation theory assumes.
//!
//! Random choices use `rand::rngs::StdRng` seeded from the spec: the same seed gives
//! the same signal with the same `rand` version (pinned in `Cargo.lock`).

use rand::{rngs::StdRng, Rng, SeedableRng};
use rustfft::{num_complex::Complex, FftPlanner};
use serde::{Deserialize, Serialize};

/// Which lines of the band are excited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum LineSet {
    /// Every line.
    Full,
    /// Odd harmonic numbers only.
    Odd,
    /// Odd lines, one of each group of `group` consecutive odd lines left out at
    /// random (`group` ≥ 2).
    RandomOdd { group: usize, seed: u64 },
}

/// How the phases are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PhaseRule {
    /// φᵢ = −π·i·(i−1)/F (module docs).
    Schroeder,
    /// Independent, uniform on [0, 2π).
    Random { seed: u64 },
}

/// The level the signal is scaled to, in the signal's unit (A, V, N·m…).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Level {
    /// Root mean square over a period.
    Rms(f64),
    /// Largest |u| over a period.
    Peak(f64),
}

/// What to generate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MultisineSpec {
    /// Sampling rate fs, Hz.
    pub sample_rate_hz: f64,
    /// Samples per period N (≥ 4); the line spacing is fs/N.
    pub samples_per_period: usize,
    /// Periods in the record, P (≥ 1).
    pub periods: usize,
    /// Lowest excited frequency, Hz (> 0; lines at or above it).
    pub min_frequency_hz: f64,
    /// Highest excited frequency, Hz (below fs/2; lines at or below it).
    pub max_frequency_hz: f64,
    pub lines: LineSet,
    pub phases: PhaseRule,
    pub level: Level,
}

/// A generated multisine: its lines, phases and one period of samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Multisine {
    /// Harmonic numbers kᵢ of the excited lines, ascending.
    pub lines: Vec<usize>,
    /// kᵢ·fs/N, Hz.
    pub frequency_hz: Vec<f64>,
    /// φᵢ, rad (cosine convention).
    pub phase_rad: Vec<f64>,
    /// Amplitude A of every cosine, signal unit.
    pub amplitude: f64,
    /// Largest |u| over RMS of a period.
    pub crest_factor: f64,
    /// One period, N samples.
    pub period: Vec<f64>,
    /// Periods in the record.
    pub periods: usize,
}

impl Multisine {
    /// The whole record: the period repeated P times (N·P samples).
    pub fn record(&self) -> Vec<f64> {
        self.period.repeat(self.periods)
    }
}

/// Why a multisine cannot be generated; each names the field of [`MultisineSpec`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MultisineError {
    #[error("sample_rate_hz = {0} must be positive and finite")]
    SampleRate(f64),
    #[error("samples_per_period = {0} must be at least 4")]
    SamplesPerPeriod(usize),
    #[error("periods = 0: at least one period is needed")]
    NoPeriods,
    #[error("the band min_frequency_hz = {min} … max_frequency_hz = {max} must satisfy 0 < min ≤ max < fs/2 = {nyquist} Hz")]
    Band { min: f64, max: f64, nyquist: f64 },
    #[error("no line k·{spacing} Hz (k = 1, 2, …) of the requested kind lies in {min} … {max} Hz: widen the band or lengthen the period")]
    NoLines { min: f64, max: f64, spacing: f64 },
    #[error("lines: random-odd group = {0} must be at least 2")]
    Group(usize),
    #[error("level = {0} must be positive and finite")]
    Level(f64),
}

/// The harmonic numbers excited by `spec` (module docs), ascending.
pub fn excited_lines(spec: &MultisineSpec) -> Result<Vec<usize>, MultisineError> {
    let (fs, n) = (spec.sample_rate_hz, spec.samples_per_period);
    if !(fs > 0.0 && fs.is_finite()) {
        return Err(MultisineError::SampleRate(fs));
    }
    if n < 4 {
        return Err(MultisineError::SamplesPerPeriod(n));
    }
    let (min, max) = (spec.min_frequency_hz, spec.max_frequency_hz);
    let nyquist = fs / 2.0;
    if !(min > 0.0 && min <= max && max < nyquist) {
        return Err(MultisineError::Band { min, max, nyquist });
    }
    let spacing = fs / n as f64;
    // Lines strictly below Nyquist: a cosine at fs/2 has no phase.
    let band = (1..n.div_ceil(2)).filter(|&k| {
        let f = k as f64 * spacing;
        f >= min * (1.0 - 1e-12) && f <= max * (1.0 + 1e-12)
    });
    let lines: Vec<usize> = match spec.lines {
        LineSet::Full => band.collect(),
        LineSet::Odd => band.filter(|k| k % 2 == 1).collect(),
        LineSet::RandomOdd { group, seed } => {
            if group < 2 {
                return Err(MultisineError::Group(group));
            }
            random_odd(band.filter(|k| k % 2 == 1).collect(), group, seed)
        }
    };
    if lines.is_empty() {
        return Err(MultisineError::NoLines { min, max, spacing });
    }
    Ok(lines)
}

/// `odd` without one randomly chosen line of each whole group of `group`.
fn random_odd(odd: Vec<usize>, group: usize, seed: u64) -> Vec<usize> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut kept = Vec::with_capacity(odd.len());
    for chunk in odd.chunks(group) {
        let left_out = if chunk.len() == group {
            Some(rng.random_range(0..group))
        } else {
            None
        };
        kept.extend(
            chunk
                .iter()
                .enumerate()
                .filter(|(i, _)| Some(*i) != left_out)
                .map(|(_, &k)| k),
        );
    }
    kept
}

/// The phases of `count` lines by `rule`, rad.
pub fn phases(count: usize, rule: PhaseRule) -> Vec<f64> {
    match rule {
        PhaseRule::Schroeder => (1..=count)
            .map(|i| -std::f64::consts::PI * (i * (i - 1)) as f64 / count as f64)
            .collect(),
        PhaseRule::Random { seed } => {
            let mut rng = StdRng::seed_from_u64(seed);
            (0..count)
                .map(|_| rng.random_range(0.0..std::f64::consts::TAU))
                .collect()
        }
    }
}

/// Generates the multisine `spec` describes.
pub fn generate(spec: &MultisineSpec) -> Result<Multisine, MultisineError> {
    let lines = excited_lines(spec)?;
    if spec.periods == 0 {
        return Err(MultisineError::NoPeriods);
    }
    let target = match spec.level {
        Level::Rms(v) | Level::Peak(v) => v,
    };
    if !(target > 0.0 && target.is_finite()) {
        return Err(MultisineError::Level(target));
    }
    let phase_rad = phases(lines.len(), spec.phases);
    let unit = unit_period(spec.samples_per_period, &lines, &phase_rad);
    let rms = (unit.iter().map(|v| v * v).sum::<f64>() / unit.len() as f64).sqrt();
    let peak = unit.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale = match spec.level {
        Level::Rms(r) => r / rms,
        Level::Peak(p) => p / peak,
    };
    let spacing = spec.sample_rate_hz / spec.samples_per_period as f64;
    Ok(Multisine {
        frequency_hz: lines.iter().map(|&k| k as f64 * spacing).collect(),
        lines,
        phase_rad,
        amplitude: scale,
        crest_factor: peak / rms,
        period: unit.iter().map(|v| v * scale).collect(),
        periods: spec.periods,
    })
}

/// One period of Σ cos(2π·k·n/N + φ) (unit amplitudes), by one inverse FFT.
fn unit_period(n: usize, lines: &[usize], phase_rad: &[f64]) -> Vec<f64> {
    let mut spectrum = vec![Complex::new(0.0, 0.0); n];
    for (&k, &phi) in lines.iter().zip(phase_rad) {
        spectrum[k] = Complex::from_polar(1.0, phi);
    }
    FftPlanner::new().plan_fft_inverse(n).process(&mut spectrum);
    // Re Σ e^{i(2πkn/N + φ)} = Σ cos(2πkn/N + φ).
    spectrum.iter().map(|c| c.re).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(lines: LineSet, phases: PhaseRule) -> MultisineSpec {
        MultisineSpec {
            sample_rate_hz: 2500.0,
            samples_per_period: 2500,
            periods: 3,
            min_frequency_hz: 11.0,
            max_frequency_hz: 250.0,
            lines,
            phases,
            level: Level::Rms(2.0),
        }
    }

    /// |DFT| of one period, normalised to the cosine amplitude (2/N).
    fn amplitudes(period: &[f64]) -> Vec<f64> {
        let n = period.len();
        let mut buf: Vec<Complex<f64>> = period.iter().map(|&v| Complex::new(v, 0.0)).collect();
        FftPlanner::new().plan_fft_forward(n).process(&mut buf);
        buf[..n / 2]
            .iter()
            .map(|c| 2.0 * c.norm() / n as f64)
            .collect()
    }

    #[test]
    fn the_spectrum_lies_exactly_on_the_lines() {
        let m = generate(&spec(LineSet::Full, PhaseRule::Schroeder)).unwrap();
        assert_eq!(m.lines, (11..=250).collect::<Vec<_>>());
        assert_eq!(m.record().len(), 3 * 2500);
        let a = amplitudes(&m.period);
        for (k, &amp) in a.iter().enumerate() {
            if m.lines.contains(&k) {
                assert!((amp - m.amplitude).abs() < 1e-12 * m.amplitude, "line {k}");
            } else {
                assert!(amp < 1e-12 * m.amplitude, "line {k} holds {amp}");
            }
        }
        let rms = (m.period.iter().map(|v| v * v).sum::<f64>() / 2500.0).sqrt();
        assert!((rms - 2.0).abs() < 1e-12, "{rms}");
        // RMS of F equal cosines: A·√(F/2).
        assert!((m.amplitude - 2.0 / 120f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn schroeder_phases_have_a_much_lower_crest_factor_than_random_ones() {
        let schroeder = generate(&spec(LineSet::Full, PhaseRule::Schroeder)).unwrap();
        let worst_random = (0..10)
            .map(|seed| {
                generate(&spec(LineSet::Full, PhaseRule::Random { seed }))
                    .unwrap()
                    .crest_factor
            })
            .fold(f64::INFINITY, f64::min);
        // Schroeder's chirp-like phases: ≈ 1.7 for a dense band; random phases:
        // Gaussian-like, ≈ 3–4 for 240 lines.
        assert!(schroeder.crest_factor < 2.0, "{}", schroeder.crest_factor);
        assert!(worst_random > 2.5, "{worst_random}");
        let mut peak = spec(LineSet::Full, PhaseRule::Schroeder);
        peak.level = Level::Peak(5.0);
        let p = generate(&peak).unwrap();
        let max = p.period.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!((max - 5.0).abs() < 1e-12);
    }

    #[test]
    fn odd_and_random_odd_line_sets_are_as_specified() {
        let odd = excited_lines(&spec(LineSet::Odd, PhaseRule::Schroeder)).unwrap();
        assert_eq!(odd, (11..=249).step_by(2).collect::<Vec<_>>());
        let group = 3;
        let ro = LineSet::RandomOdd { group, seed: 7 };
        let random = excited_lines(&spec(ro, PhaseRule::Schroeder)).unwrap();
        assert!(random.iter().all(|k| k % 2 == 1 && odd.contains(k)));
        // 120 odd lines: 40 whole groups of 3, one left out of each.
        assert_eq!(random.len(), 80);
        for chunk in odd.chunks(group) {
            let kept = chunk.iter().filter(|k| random.contains(k)).count();
            assert_eq!(kept, group - 1, "{chunk:?}");
        }
        // Seeded: the same seed the same set, another seed another set.
        assert_eq!(
            random,
            excited_lines(&spec(ro, PhaseRule::Schroeder)).unwrap()
        );
        let other = LineSet::RandomOdd { group, seed: 8 };
        assert_ne!(
            random,
            excited_lines(&spec(other, PhaseRule::Schroeder)).unwrap()
        );
    }

    #[test]
    fn bad_specs_are_typed_errors_naming_the_field() {
        let good = spec(LineSet::Full, PhaseRule::Schroeder);
        let mut s = good;
        s.max_frequency_hz = 1300.0;
        let e = generate(&s).unwrap_err();
        assert!(matches!(e, MultisineError::Band { .. }));
        assert!(e.to_string().contains("max_frequency_hz"), "{e}");
        s = good;
        s.min_frequency_hz = 11.2;
        s.max_frequency_hz = 11.8;
        assert!(matches!(generate(&s), Err(MultisineError::NoLines { .. })));
        s = good;
        s.level = Level::Rms(f64::NAN);
        assert!(matches!(generate(&s), Err(MultisineError::Level(_))));
        s = good;
        s.periods = 0;
        assert_eq!(generate(&s), Err(MultisineError::NoPeriods));
        s = good;
        s.lines = LineSet::RandomOdd { group: 1, seed: 0 };
        assert_eq!(generate(&s), Err(MultisineError::Group(1)));
        s = good;
        s.sample_rate_hz = 0.0;
        assert_eq!(generate(&s), Err(MultisineError::SampleRate(0.0)));
    }
}
