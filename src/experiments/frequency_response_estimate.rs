//! The gain curve of a `frequency_response_time` record (raw motor torque, motor angle
//! and table angle over time): stepped-sine demodulation ([`super::stepped_sine`]) or
//! the H1 estimate with Welch averaging ([`super::welch`]), then the resonances.
//!
//! Both give the paper's gain, table angle over motor angle × ratio (MODEL.md §5.1),
//! with ratio = Rg·Rw from `conditions.ratio` or the preset named in `mechanism`. H1
//! also gives the compliance table angle / motor torque. Bins whose coherence is below
//! `min_coherence` are kept in the result but flagged and left out of the peak search
//! and the plotted curve; peaks are local maxima of the kept gain, located by
//! [`frequency_response::peaks`]' parabola, standing at least `min_prominence_db`
//! above the lowest gain between them and any higher point (so the noise ripple of
//! an estimate does not count as a resonance).

use serde::Serialize;

use super::fluctuation::{self, FluctuationError};
use super::frequency_response::{self, Peak};
use super::stepped_sine::{self, SinePoint, SteppedSineError, SteppedSineOptions};
use super::welch::{self, WelchError, WelchOptions};
use crate::io::experiment_file::{sample_period, Data, Excitation, Experiment, Kind};

/// Settings of the evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateOptions {
    /// H1: samples per Welch segment (default: the largest power of two ≤ 1 s of
    /// samples and ≤ a quarter of the record, so that ≥ 7 segments are averaged).
    pub segment_len: Option<usize>,
    /// H1: coherence below which a bin is flagged and left out (default 0.8).
    pub min_coherence: f64,
    /// Stepped sine: fraction of each dwell discarded (default 0.5).
    pub settle_fraction: f64,
    /// Peaks: smallest prominence, dB (default 3).
    pub min_prominence_db: f64,
    /// Peaks: how many, the highest (default 4).
    pub max_peaks: usize,
}

impl Default for EstimateOptions {
    fn default() -> Self {
        EstimateOptions {
            segment_len: None,
            min_coherence: 0.8,
            settle_fraction: SteppedSineOptions::default().settle_fraction,
            min_prominence_db: 3.0,
            max_peaks: 4,
        }
    }
}

/// One frequency bin of the H1 estimate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bin {
    pub frequency_hz: f64,
    /// |H1| of table angle over motor angle × ratio, dB.
    pub gain_db: f64,
    /// Its phase, degrees.
    pub phase_deg: f64,
    /// γ² between motor angle and table angle.
    pub coherence: f64,
    /// |H1| of table angle over motor torque, dB re 1 rad/(N·m).
    pub compliance_db: f64,
    /// γ² between motor torque and table angle.
    pub compliance_coherence: f64,
    /// Whether `coherence` reaches `min_coherence` (used for peaks and the plot).
    pub kept: bool,
}

/// The evaluation of a record.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "estimator", rename_all = "snake_case")]
pub enum Evaluation {
    /// Demodulation of a stepped sine, one point per drive frequency.
    SteppedSine {
        ratio: f64,
        settle_fraction: f64,
        points: Vec<SinePoint>,
        peaks: Vec<Peak>,
    },
    /// H1 with Welch averaging of a broadband record.
    H1 {
        ratio: f64,
        sample_rate_hz: f64,
        segment_len: usize,
        segments: usize,
        resolution_hz: f64,
        min_coherence: f64,
        /// Bins at or above `min_coherence`.
        kept: usize,
        bins: Vec<Bin>,
        peaks: Vec<Peak>,
    },
}

impl Evaluation {
    /// The resonances found.
    pub fn peaks(&self) -> &[Peak] {
        match self {
            Evaluation::SteppedSine { peaks, .. } | Evaluation::H1 { peaks, .. } => peaks,
        }
    }
}

/// Why a record cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EstimateError {
    #[error("not a frequency_response_time experiment")]
    WrongKind,
    #[error("{0}")]
    Ratio(#[from] FluctuationError),
    #[error("{0}")]
    Welch(#[from] WelchError),
    #[error("{0}")]
    SteppedSine(#[from] SteppedSineError),
    #[error("the record has {0} samples: too short to estimate anything")]
    TooShort(usize),
    #[error("the coherence threshold {0} must be in [0, 1]")]
    BadCoherence(f64),
}

/// Evaluates a `frequency_response_time` experiment with `opts`.
pub fn evaluate_experiment(
    exp: &Experiment,
    opts: &EstimateOptions,
) -> Result<Evaluation, EstimateError> {
    let Data::FrequencyResponseTime {
        time_s,
        motor_torque_nm,
        motor_angle_rad,
        table_angle_rad,
        ..
    } = &exp.data
    else {
        return Err(EstimateError::WrongKind);
    };
    let ratio = fluctuation::ratio(exp)?;
    let c = exp
        .manifest
        .conditions
        .with_defaults(Kind::FrequencyResponseTime);
    let period = sample_period(time_s).ok_or(EstimateError::TooShort(time_s.len()))?;
    if c.excitation == Some(Excitation::SteppedSine) {
        // The reader has checked both conditions for a stepped sine.
        let frequencies = c.frequencies_hz.unwrap_or_default();
        let dwell = c.dwell_s.unwrap_or(0.0);
        let so = SteppedSineOptions {
            settle_fraction: opts.settle_fraction,
        };
        let points = stepped_sine::demodulate(
            time_s,
            motor_torque_nm,
            motor_angle_rad,
            table_angle_rad,
            ratio,
            &frequencies,
            dwell,
            &so,
        )?;
        let mut curve: Vec<(f64, f64)> =
            points.iter().map(|q| (q.frequency_hz, q.gain_db)).collect();
        curve.sort_by(|a, b| a.0.total_cmp(&b.0));
        let peaks = frequency_response::peaks(&curve, opts.max_peaks);
        return Ok(Evaluation::SteppedSine {
            ratio,
            settle_fraction: opts.settle_fraction,
            points,
            peaks,
        });
    }
    if !(0.0..=1.0).contains(&opts.min_coherence) {
        return Err(EstimateError::BadCoherence(opts.min_coherence));
    }
    let n = time_s.len();
    let segment_len = opts.segment_len.unwrap_or_else(|| {
        let cap = ((1.0 / period).min((n - 1) as f64 / 4.0)).max(8.0) as usize;
        1usize << (usize::BITS - 1 - cap.leading_zeros())
    });
    let wo = WelchOptions::new(segment_len);
    let x: Vec<f64> = motor_angle_rad.iter().map(|m| m * ratio).collect();
    let gain = welch::h1(&x, table_angle_rad, period, &wo)?;
    let compliance = welch::h1(motor_torque_nm, table_angle_rad, period, &wo)?;
    let db = |h: f64| 20.0 * h.max(1e-300).log10();
    let bins: Vec<Bin> = (0..gain.frequency_hz.len())
        .map(|k| Bin {
            frequency_hz: gain.frequency_hz[k],
            gain_db: db(gain.h[k].norm()),
            phase_deg: gain.h[k].arg().to_degrees(),
            coherence: gain.coherence[k],
            compliance_db: db(compliance.h[k].norm()),
            compliance_coherence: compliance.coherence[k],
            kept: gain.coherence[k] >= opts.min_coherence && gain.h[k].norm() > 0.0,
        })
        .collect();
    let peaks = kept_peaks(&bins, opts);
    Ok(Evaluation::H1 {
        ratio,
        sample_rate_hz: 1.0 / period,
        segment_len,
        segments: gain.segments,
        resolution_hz: gain.resolution_hz,
        min_coherence: opts.min_coherence,
        kept: bins.iter().filter(|b| b.kept).count(),
        bins,
        peaks,
    })
}

/// The runs of consecutive kept bins, as (frequency, gain) curves.
pub fn kept_runs(bins: &[Bin]) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut open = false;
    for b in bins {
        if b.kept {
            if !open {
                runs.push(Vec::new());
            }
            runs.last_mut()
                .expect("pushed")
                .push((b.frequency_hz, b.gain_db));
        }
        open = b.kept;
    }
    runs
}

/// The prominent peaks of the kept runs (module docs), highest `max_peaks`, ascending.
fn kept_peaks(bins: &[Bin], opts: &EstimateOptions) -> Vec<Peak> {
    let mut found: Vec<Peak> = kept_runs(bins)
        .iter()
        .flat_map(|run| prominent_peaks(run, opts.min_prominence_db))
        .collect();
    found.sort_by(|a, b| b.gain_db.total_cmp(&a.gain_db));
    found.truncate(opts.max_peaks);
    found.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    found
}

/// Interior local maxima of `curve` at least `min_prominence` above the lowest point
/// between them and the nearest higher point on each side (or the curve's end), each
/// located by the parabola of [`frequency_response::peaks`].
pub fn prominent_peaks(curve: &[(f64, f64)], min_prominence: f64) -> Vec<Peak> {
    let y: Vec<f64> = curve.iter().map(|c| c.1).collect();
    let mut out = Vec::new();
    for i in 1..y.len().saturating_sub(1) {
        if !(y[i] > y[i - 1] && y[i] >= y[i + 1]) {
            continue;
        }
        let base = |range: &mut dyn Iterator<Item = usize>| {
            let mut low = y[i];
            for j in range {
                if y[j] > y[i] {
                    break;
                }
                low = low.min(y[j]);
            }
            low
        };
        let left = base(&mut (0..i).rev());
        let right = base(&mut (i + 1..y.len()));
        if y[i] - left.max(right) >= min_prominence {
            out.extend(frequency_response::peaks(&curve[i - 1..=i + 1], 1));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ripple_is_not_a_peak_but_a_resonance_is() {
        // A resonance at 50 with ripple of ±0.5 dB every other point.
        let curve: Vec<(f64, f64)> = (0..100)
            .map(|i| {
                let f = i as f64;
                let ripple = if i % 2 == 0 { 0.5 } else { -0.5 };
                (f, 20.0 / (1.0 + ((f - 50.0) / 3.0).powi(2)) + ripple)
            })
            .collect();
        let p = prominent_peaks(&curve, 3.0);
        assert_eq!(p.len(), 1, "{p:?}");
        assert!((p[0].frequency_hz - 50.0).abs() < 1.0, "{p:?}");
        assert!(prominent_peaks(&curve, 0.5).len() > 10);
    }

    #[test]
    fn kept_runs_split_at_flagged_bins() {
        let bin = |f: f64, kept: bool| Bin {
            frequency_hz: f,
            gain_db: 0.0,
            phase_deg: 0.0,
            coherence: 1.0,
            compliance_db: 0.0,
            compliance_coherence: 1.0,
            kept,
        };
        let bins = [bin(1.0, true), bin(2.0, true), bin(3.0, false), bin(4.0, true)];
        let runs = kept_runs(&bins);
        assert_eq!(runs.len(), 2);
        assert_eq!((runs[0].len(), runs[1].len()), (2, 1));
    }
}
