//! A record of a periodic excitation cut into whole periods and transformed: the
//! period (given, or detected from the autocorrelation of the reference), the leading
//! transient periods dropped, a steady drift removed, the DFT of every remaining period
//! with a rectangular window, and the excited lines (given, or detected as the lines
//! where the reference's spectrum stands far above the rest). The frequency-response
//! estimate ([`super::estimate`]) and the distortion analysis
//! ([`super::nonlinear_distortion`]) work on these spectra.
//!
//! Method: Pintelon & Schoukens, *System Identification: A Frequency Domain Approach*,
//! 2nd ed., Wiley–IEEE Press 2012, ch. 2–3. In the periodic steady state every period
//! holds whole cycles of every line, so the DFT of a period (no window) has no leakage;
//! the spread of the spectra over periods measures the noise, line by line.
//!
//! **Normalisation.** The spectrum of period p at line k is X_p[k] = (2/N)·DFT, the
//! amplitude of the cosine at k·fs/N in the signal's unit (the DC line holds twice the
//! mean; it is never used).
//!
//! **Drift.** An axis under an open-loop excitation may creep: a ramp, which the
//! rectangular window would leak onto every line (as 1/k). Each channel has the
//! straight line through its period means removed before the transform
//! ([`PeriodicOptions::remove_drift`]): a steady drift goes entirely, the periodic part
//! is untouched (its mean is the same every period). This is rtid's choice, not P&S's.

use rustfft::{num_complex::Complex, FftPlanner};

/// Settings of the periodic estimate.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodicOptions {
    /// Samples per period N; `None`: detected from the reference ([`detect_period`]).
    pub samples_per_period: Option<usize>,
    /// Leading periods dropped as transient (default 1).
    pub drop_periods: usize,
    /// Harmonic numbers of the excited lines (line k at k·fs/N); `None`: detected
    /// from the reference ([`detect_lines`]).
    pub excited_lines: Option<Vec<usize>>,
    /// Line detection: the least drop, dB, between the weakest excited line and the
    /// strongest other line of the reference (default 10: on the two-mass bench
    /// record the measured current's strongest line outside the multisine, at 331 Hz,
    /// is 14.8 dB below its weakest excited line).
    pub min_line_gap_db: f64,
    /// Remove each channel's steady drift (module docs; default true).
    pub remove_drift: bool,
    /// Band edges for the distortion levels, Hz, ascending; `None`: octaves from the
    /// lowest excited line to the highest ([`super::nonlinear_distortion`]).
    pub band_edges_hz: Option<Vec<f64>>,
    /// A band's distortion is reported as detected when the normal score of its power
    /// over its noise exceeds this ([`super::nonlinear_distortion`]; default 3).
    pub distortion_z: f64,
    /// How many nearby non-excited odd lines give the nonlinear variance at an
    /// excited line (default 4).
    pub nonlinear_neighbours: usize,
    /// Lines either side over which the gain's line-to-line scatter is measured
    /// ([`super::line_scatter`], default 5).
    pub scatter_half_window: usize,
}

impl Default for PeriodicOptions {
    fn default() -> Self {
        PeriodicOptions {
            samples_per_period: None,
            drop_periods: 1,
            excited_lines: None,
            min_line_gap_db: 10.0,
            remove_drift: true,
            band_edges_hz: None,
            distortion_z: 3.0,
            nonlinear_neighbours: 4,
            scatter_half_window: 5,
        }
    }
}

/// Why a periodic record cannot be analysed. Channels are named by their role
/// (`reference`, `input`, `output`, `numerator`, `denominator`); options by their field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PeriodicError {
    #[error("sample_rate_hz = {0} must be positive and finite")]
    SampleRate(f64),
    #[error("the {channel} has {samples} samples where the reference has {expected}: the channels must be sampled together")]
    Lengths {
        channel: &'static str,
        samples: usize,
        expected: usize,
    },
    #[error("the {channel} is not finite at sample {index} ({value})")]
    NonFinite {
        channel: &'static str,
        index: usize,
        value: f64,
    },
    #[error("the reference has {0} samples: too short to hold two periods")]
    TooShort(usize),
    #[error("no period found in the reference: its autocorrelation reaches only {best:.3} beyond lag 0 (at least {needed}); give samples_per_period")]
    NoPeriod { best: f64, needed: f64 },
    #[error("samples_per_period = {samples_per_period} does not divide the record of {samples} samples into whole periods")]
    NotWholePeriods {
        samples: usize,
        samples_per_period: usize,
    },
    #[error("samples_per_period = {0} must be at least 4")]
    SamplesPerPeriod(usize),
    #[error("the record holds {periods} periods and drop_periods = {drop}: at least 2 must remain to measure the noise")]
    TooFewPeriods { periods: usize, drop: usize },
    #[error("excited_lines: line {line} is outside 1 … {max} (below fs/2)")]
    LineOutOfRange { line: usize, max: usize },
    #[error("excited_lines: none given")]
    NoLines,
    #[error("excited_lines: line {line} carries no power in the {channel}")]
    LineNotExcited { channel: &'static str, line: usize },
    #[error("no excited lines stand out of the reference's spectrum: the largest drop between lines is {gap_db:.1} dB, less than min_line_gap_db = {min_gap_db} dB; give excited_lines")]
    LinesNotDistinct { gap_db: f64, min_gap_db: f64 },
    #[error("{field} = {value} is out of range")]
    BadOption { field: &'static str, value: f64 },
}

/// The spectra of one channel: `periods` rows of `bins` = N/2 + 1 lines each.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodSpectra {
    /// Samples per period N.
    n: usize,
    bins: usize,
    data: Vec<Complex<f64>>,
}

impl PeriodSpectra {
    /// Periods held.
    pub fn periods(&self) -> usize {
        self.data.len() / self.bins
    }

    /// Lines per period, 0 ..= N/2.
    pub fn bins(&self) -> usize {
        self.bins
    }

    /// The highest line strictly below fs/2: (N − 1)/2.
    pub(crate) fn top_line(&self) -> usize {
        (self.n - 1) / 2
    }

    /// Line `k` of every period.
    pub fn line(&self, k: usize) -> impl Iterator<Item = Complex<f64>> + '_ {
        self.data.iter().skip(k).step_by(self.bins).copied()
    }

    /// The mean over periods at line `k`.
    pub fn mean(&self, k: usize) -> Complex<f64> {
        self.line(k).sum::<Complex<f64>>() / self.periods() as f64
    }

    /// The sample variance of that mean, Σ|X_p − X̄|² / (P·(P − 1)), unit².
    pub(crate) fn mean_variance(&self, k: usize) -> f64 {
        let (p, m) = (self.periods() as f64, self.mean(k));
        self.line(k).map(|x| (x - m).norm_sqr()).sum::<f64>() / (p * (p - 1.0))
    }
}

/// A record framed into periods, with the reference's spectra and the excited lines.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodicRecord {
    pub sample_rate_hz: f64,
    /// N.
    pub samples_per_period: usize,
    /// Whole periods in the record.
    pub periods_in_record: usize,
    /// Leading periods left out.
    pub periods_dropped: usize,
    /// Whether N was detected rather than given.
    pub period_detected: bool,
    /// Harmonic numbers of the excited lines, ascending.
    pub excited: Vec<usize>,
    /// Whether the lines were detected rather than given.
    pub lines_detected: bool,
    /// The reference's spectra over the periods used.
    pub reference: PeriodSpectra,
    pub options: PeriodicOptions,
}

impl PeriodicRecord {
    /// Frames `reference` (the excitation as measured: the current, the torque) sampled
    /// at `sample_rate_hz` by `options` (module docs).
    pub fn new(
        reference: &[f64],
        sample_rate_hz: f64,
        options: &PeriodicOptions,
    ) -> Result<Self, PeriodicError> {
        if !(sample_rate_hz > 0.0 && sample_rate_hz.is_finite()) {
            return Err(PeriodicError::SampleRate(sample_rate_hz));
        }
        check_options(options)?;
        finite("reference", reference)?;
        let (n, period_detected) = match options.samples_per_period {
            Some(n) => (n, false),
            None => (detect_period(reference)?, true),
        };
        let periods = whole_periods(reference.len(), n, options.drop_periods)?;
        let mut rec = PeriodicRecord {
            sample_rate_hz,
            samples_per_period: n,
            periods_in_record: periods,
            periods_dropped: options.drop_periods,
            period_detected,
            excited: Vec::new(),
            lines_detected: options.excited_lines.is_none(),
            reference: PeriodSpectra {
                n,
                bins: 1,
                data: Vec::new(),
            },
            options: options.clone(),
        };
        rec.reference = rec.spectra("reference", reference)?;
        rec.excited = match &options.excited_lines {
            Some(lines) => given_lines(lines, &rec.reference)?,
            None => detect_lines(&rec.reference, options.min_line_gap_db)?,
        };
        Ok(rec)
    }

    /// Line spacing fs/N, Hz.
    pub(crate) fn spacing_hz(&self) -> f64 {
        self.sample_rate_hz / self.samples_per_period as f64
    }

    /// Periods used, after the dropped ones.
    pub fn periods_used(&self) -> usize {
        self.periods_in_record - self.periods_dropped
    }

    /// The spectra of another channel sampled with the reference, over the same
    /// periods, drift removed if the options say so.
    pub fn spectra(
        &self,
        channel: &'static str,
        x: &[f64],
    ) -> Result<PeriodSpectra, PeriodicError> {
        let n = self.samples_per_period;
        let expected = n * self.periods_in_record;
        if x.len() != expected {
            return Err(PeriodicError::Lengths {
                channel,
                samples: x.len(),
                expected,
            });
        }
        finite(channel, x)?;
        let mut used = x[n * self.periods_dropped..].to_vec();
        if self.options.remove_drift {
            remove_drift(&mut used, n);
        }
        Ok(transform(&used, n))
    }
}

fn check_options(o: &PeriodicOptions) -> Result<(), PeriodicError> {
    let bad = |field, value: f64| Err(PeriodicError::BadOption { field, value });
    if !(o.min_line_gap_db > 0.0 && o.min_line_gap_db.is_finite()) {
        return bad("min_line_gap_db", o.min_line_gap_db);
    }
    if !(o.distortion_z >= 0.0 && o.distortion_z.is_finite()) {
        return bad("distortion_z", o.distortion_z);
    }
    if o.nonlinear_neighbours == 0 {
        return bad("nonlinear_neighbours", 0.0);
    }
    if o.scatter_half_window == 0 {
        return bad("scatter_half_window", 0.0);
    }
    if let Some(edges) = &o.band_edges_hz {
        let sorted = edges.windows(2).all(|w| w[0] < w[1]);
        if edges.len() < 2 || !sorted || edges.iter().any(|e| !(e.is_finite() && *e >= 0.0)) {
            return bad("band_edges_hz", edges.first().copied().unwrap_or(f64::NAN));
        }
    }
    Ok(())
}

fn finite(channel: &'static str, x: &[f64]) -> Result<(), PeriodicError> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(PeriodicError::NonFinite {
            channel,
            index,
            value: x[index],
        }),
        None => Ok(()),
    }
}

/// Whole periods of `n` in `samples`, at least two left after `drop`.
fn whole_periods(samples: usize, n: usize, drop: usize) -> Result<usize, PeriodicError> {
    if n < 4 {
        return Err(PeriodicError::SamplesPerPeriod(n));
    }
    if samples % n != 0 {
        return Err(PeriodicError::NotWholePeriods {
            samples,
            samples_per_period: n,
        });
    }
    let periods = samples / n;
    if periods < drop + 2 {
        return Err(PeriodicError::TooFewPeriods { periods, drop });
    }
    Ok(periods)
}

/// Least autocorrelation (normalised to lag 0) at the detected period.
pub const MIN_PERIOD_CORRELATION: f64 = 0.5;

/// The period of `u`, samples: the first lag, beyond the main lobe at 0 (the first
/// lag where the autocorrelation turns negative) and up to half the record, where the
/// normalised unbiased autocorrelation ρ(τ) = [Σ u[i]·u[i+τ]/(n − τ)] / [Σ u²/n] of
/// the mean-removed signal comes within 10 % of its largest value there, climbed to
/// its local maximum. Taking the first such lag, not the largest, picks the period
/// rather than a multiple of it, whose correlation is as high.
pub(crate) fn detect_period(u: &[f64]) -> Result<usize, PeriodicError> {
    let n = u.len();
    if n < 8 {
        return Err(PeriodicError::TooShort(n));
    }
    let rho = autocorrelation(u);
    let needed = MIN_PERIOD_CORRELATION;
    let no_period = |best| PeriodicError::NoPeriod { best, needed };
    let Some(start) = (1..=n / 2).find(|&t| rho[t] < 0.0) else {
        return Err(no_period(rho.get(n / 2).copied().unwrap_or(0.0)));
    };
    let best = rho[start..=n / 2].iter().copied().fold(f64::MIN, f64::max);
    if best < needed {
        return Err(no_period(best));
    }
    let mut lag = (start..=n / 2)
        .find(|&t| rho[t] >= 0.9 * best)
        .expect("rho = best ≥ 0.9·best at the maximum, which is in range");
    while lag < n / 2 && rho[lag + 1] > rho[lag] {
        lag += 1;
    }
    Ok(lag)
}

/// ρ(τ), τ = 0 … n − 1 (module docs of [`detect_period`]); all zeros for a constant.
fn autocorrelation(u: &[f64]) -> Vec<f64> {
    let n = u.len();
    let mean = u.iter().sum::<f64>() / n as f64;
    let m = (2 * n).next_power_of_two();
    let mut buf = vec![Complex::new(0.0, 0.0); m];
    for (b, v) in buf.iter_mut().zip(u) {
        b.re = v - mean;
    }
    let mut planner = FftPlanner::new();
    planner.plan_fft_forward(m).process(&mut buf);
    buf.iter_mut()
        .for_each(|c| *c = Complex::new(c.norm_sqr(), 0.0));
    planner.plan_fft_inverse(m).process(&mut buf);
    let r0 = buf[0].re / n as f64;
    (0..n)
        .map(|t| {
            if r0 > 0.0 {
                buf[t].re / (n - t) as f64 / r0
            } else {
                0.0
            }
        })
        .collect()
}

/// Removes the straight line through the period means (module docs).
fn remove_drift(x: &mut [f64], n: usize) {
    let periods = x.len() / n;
    let means: Vec<f64> = x
        .chunks(n)
        .map(|c| c.iter().sum::<f64>() / n as f64)
        .collect();
    let mid = (periods as f64 - 1.0) / 2.0;
    let grand = means.iter().sum::<f64>() / periods as f64;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (p, m) in means.iter().enumerate() {
        sxy += (p as f64 - mid) * (m - grand);
        sxx += (p as f64 - mid).powi(2);
    }
    let per_sample = if sxx > 0.0 { sxy / sxx / n as f64 } else { 0.0 };
    let centre = (x.len() as f64 - 1.0) / 2.0;
    for (i, v) in x.iter_mut().enumerate() {
        *v -= per_sample * (i as f64 - centre);
    }
}

/// (2/N)·DFT of each period of `x`, lines 0 ..= N/2.
fn transform(x: &[f64], n: usize) -> PeriodSpectra {
    let bins = n / 2 + 1;
    let fft = FftPlanner::new().plan_fft_forward(n);
    let mut buf = vec![Complex::new(0.0, 0.0); n];
    let mut data = Vec::with_capacity(bins * x.len() / n);
    for period in x.chunks(n) {
        for (b, v) in buf.iter_mut().zip(period) {
            *b = Complex::new(*v, 0.0);
        }
        fft.process(&mut buf);
        data.extend(buf[..bins].iter().map(|c| c * (2.0 / n as f64)));
    }
    PeriodSpectra { n, bins, data }
}

/// `lines` sorted, checked against the range and the reference's power.
fn given_lines(lines: &[usize], reference: &PeriodSpectra) -> Result<Vec<usize>, PeriodicError> {
    if lines.is_empty() {
        return Err(PeriodicError::NoLines);
    }
    let max = reference.top_line();
    let mut sorted = lines.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    for &line in &sorted {
        if line == 0 || line > max {
            return Err(PeriodicError::LineOutOfRange { line, max });
        }
        if reference.line(line).all(|x| x.norm_sqr() == 0.0) {
            return Err(PeriodicError::LineNotExcited {
                channel: "reference",
                line,
            });
        }
    }
    Ok(sorted)
}

/// Levels below the strongest line further down than this are clamped there, so that
/// exact zeros (synthetic data) do not make a gap of their own.
const LEVEL_FLOOR_DB: f64 = 200.0;

/// The excited lines of a reference: its mean spectrum's levels |X̄_k|² (dB, lines
/// 1 … below fs/2) sorted, cut at the largest drop between consecutive levels, which
/// must reach `min_gap_db`; the lines above the cut are the excited ones.
pub(crate) fn detect_lines(
    reference: &PeriodSpectra,
    min_gap_db: f64,
) -> Result<Vec<usize>, PeriodicError> {
    let top = reference.top_line();
    let mut levels: Vec<(f64, usize)> = (1..=top)
        .map(|k| (10.0 * reference.mean(k).norm_sqr().max(1e-300).log10(), k))
        .collect();
    levels.sort_by(|a, b| b.0.total_cmp(&a.0));
    let floor = levels.first().map_or(0.0, |l| l.0) - LEVEL_FLOOR_DB;
    let (mut gap, mut cut) = (0.0, 0);
    for i in 1..levels.len() {
        let drop = levels[i - 1].0.max(floor) - levels[i].0.max(floor);
        if drop > gap {
            (gap, cut) = (drop, i);
        }
    }
    if gap < min_gap_db {
        return Err(PeriodicError::LinesNotDistinct {
            gap_db: gap,
            min_gap_db,
        });
    }
    let mut lines: Vec<usize> = levels[..cut].iter().map(|l| l.1).collect();
    lines.sort_unstable();
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// Three cosines on lines 3, 5, 9 of a 64-sample period, 6 periods, plus a ramp.
    fn record(drift: f64) -> Vec<f64> {
        (0..6 * 64)
            .map(|i| {
                let t = i as f64 / 64.0;
                (TAU * 3.0 * t).cos()
                    + 0.5 * (TAU * 5.0 * t + 1.0).cos()
                    + 0.25 * (TAU * 9.0 * t).sin()
                    + drift * i as f64
            })
            .collect()
    }

    #[test]
    fn the_period_and_the_lines_are_found_and_a_drift_does_not_leak() {
        let u = record(1e-3);
        assert_eq!(detect_period(&u).unwrap(), 64);
        let rec = PeriodicRecord::new(&u, 64.0, &PeriodicOptions::default()).unwrap();
        assert!(rec.period_detected && rec.lines_detected);
        assert_eq!((rec.periods_in_record, rec.periods_used()), (6, 5));
        assert_eq!(rec.excited, vec![3, 5, 9]);
        let s = &rec.reference;
        assert!((s.mean(3) - Complex::new(1.0, 0.0)).norm() < 1e-12);
        assert!((s.mean(5) - Complex::from_polar(0.5, 1.0)).norm() < 1e-12);
        assert!((s.mean(9) - Complex::new(0.0, -0.25)).norm() < 1e-12);
        assert!(s.mean(4).norm() < 1e-12 && s.mean_variance(3) < 1e-24);
        // Without the drift removal the ramp leaks onto every line.
        let keep = PeriodicOptions {
            remove_drift: false,
            excited_lines: Some(vec![3, 5, 9]),
            ..Default::default()
        };
        let raw = PeriodicRecord::new(&u, 64.0, &keep).unwrap();
        assert!(raw.reference.mean(4).norm() > 1e-3);
    }

    #[test]
    fn bad_records_are_typed_errors() {
        let u = record(0.0);
        let o = |n| PeriodicOptions {
            samples_per_period: Some(n),
            ..Default::default()
        };
        assert!(matches!(
            PeriodicRecord::new(&u, 64.0, &o(60)),
            Err(PeriodicError::NotWholePeriods { .. })
        ));
        assert!(matches!(
            PeriodicRecord::new(&u[..128], 64.0, &o(64)),
            Err(PeriodicError::TooFewPeriods {
                periods: 2,
                drop: 1
            })
        ));
        let mut nan = u.clone();
        nan[7] = f64::NAN;
        let e = PeriodicRecord::new(&nan, 64.0, &o(64)).unwrap_err();
        assert!(
            matches!(e, PeriodicError::NonFinite { index: 7, .. }),
            "{e}"
        );
        let given = PeriodicOptions {
            excited_lines: Some(vec![3, 4]),
            ..o(64)
        };
        assert!(PeriodicRecord::new(&u, 64.0, &given).is_ok());
        let zero = vec![0.0; u.len()];
        assert!(matches!(
            PeriodicRecord::new(&zero, 64.0, &given),
            Err(PeriodicError::LineNotExcited { line: 3, .. })
        ));
        assert!(matches!(
            PeriodicRecord::new(&zero, 64.0, &PeriodicOptions::default()),
            Err(PeriodicError::NoPeriod { .. })
        ));
        let rec = PeriodicRecord::new(&u, 64.0, &o(64)).unwrap();
        assert!(matches!(
            rec.spectra("output", &u[1..]),
            Err(PeriodicError::Lengths {
                channel: "output",
                ..
            })
        ));
        let out_of_range = PeriodicOptions {
            excited_lines: Some(vec![32]),
            ..o(64)
        };
        assert!(matches!(
            PeriodicRecord::new(&u, 64.0, &out_of_range),
            Err(PeriodicError::LineOutOfRange { line: 32, max: 31 })
        ));
    }
}
