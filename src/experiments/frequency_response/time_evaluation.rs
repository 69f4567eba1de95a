//! The gain curve of a `frequency_response_time` record (raw motor torque, motor angle
//! and table angle over time): stepped-sine demodulation ([`crate::estimation::stepped_sine`]) or
//! the H1 estimate with Welch averaging ([`crate::estimation::welch`]), then the resonances.
//!
//! Both give the paper's gain, table angle over motor angle × ratio (docs/experiments.md (frequency response)),
//! with ratio = Rg·Rw from `conditions.ratio` or the preset named in `mechanism`. H1
//! also gives the compliance table angle / motor torque. Bins whose coherence is below
//! `min_coherence` are kept in the result but flagged and left out of the peak search
//! and the plotted curve; peaks are local maxima of the kept gain, located by
//! [`crate::estimation::peaks::vertex`], whose prominence — the height above the
//! lowest gain between them and the nearest higher point on either side — is at least
//! `min_prominence_db` plus twice the random errors (one standard deviation each) of
//! the peak bin and of that lowest bin: the noise ripple of an estimate, largest where
//! the coherence is low, does not count as a resonance, while a low mode beside a
//! higher one (the worm's 234 Hz mode stands 2.7 dB above the valley towards its
//! 187 Hz mode) does.

use serde::Serialize;

use super::periodic_evaluation::{
    self, Input, PeriodicEvaluation, PeriodicEvaluationError, Series,
};
use crate::estimation::peaks::{self, Peak};
use crate::estimation::stepped_sine::{self, SinePoint, SteppedSineError, SteppedSineOptions};
use crate::estimation::welch::{self, WelchError, WelchOptions};
use crate::experiments::fluctuation::{self, FluctuationError};
use crate::io::experiment_file::{sample_period, Conditions, Data, Excitation, Experiment, Kind};

/// Default Welch segment length, s: 0.5 Hz resolution, several bins across the
/// half-power width of the worm preset's 187 Hz mode (≈ 4.5 Hz).
pub const DEFAULT_SEGMENT_S: f64 = 2.0;

/// Settings of the evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateOptions {
    /// H1: length of a Welch segment, s, rounded to an even number of samples; the
    /// resolution is its inverse (default [`DEFAULT_SEGMENT_S`], or a quarter of the
    /// record if that is shorter, so that ≥ 7 segments are averaged).
    pub segment_s: Option<f64>,
    /// H1: coherence below which a bin is flagged and left out (default 0.8).
    pub min_coherence: f64,
    /// Stepped sine: fraction of each dwell discarded (default 0.5).
    pub settle_fraction: f64,
    /// Peaks: smallest prominence beyond the random errors, dB (default 1).
    pub min_prominence_db: f64,
    /// Peaks: how many, the highest (default 4).
    pub max_peaks: usize,
}

impl Default for EstimateOptions {
    fn default() -> Self {
        EstimateOptions {
            segment_s: None,
            min_coherence: 0.8,
            settle_fraction: SteppedSineOptions::default().settle_fraction,
            min_prominence_db: 1.0,
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
    /// Normalised random error of the gain, as dB (one standard deviation):
    /// 8.69·√(1 − γ²)/(|γ|·√(2·n_d)), n_d the number of segments (Bendat & Piersol
    /// eq. 9.90; 50 %-overlapped Hann segments are not quite independent, so this is
    /// slightly optimistic). 1e9 where γ² = 0.
    pub gain_sigma_db: f64,
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
    /// A periodic multisine: both channels over whole periods
    /// ([`super::periodic_evaluation`]).
    Periodic(Box<PeriodicEvaluation>),
}

impl Evaluation {
    /// The resonances found (of the table channel).
    pub fn peaks(&self) -> &[Peak] {
        match self {
            Evaluation::SteppedSine { peaks, .. } | Evaluation::H1 { peaks, .. } => peaks,
            Evaluation::Periodic(p) => &p.peaks,
        }
    }
}

/// Why a record cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EstimateError {
    #[error("not a frequency_response_time experiment")]
    WrongKind,
    #[error("a record driven by motor_current_a is evaluated as a periodic multisine only: its manifest must say \"excitation\": \"multisine\" (with \"period_s\")")]
    CurrentNotMultisine,
    #[error("{0}")]
    Periodic(#[from] PeriodicEvaluationError),
    #[error("{0}")]
    Ratio(#[from] FluctuationError),
    #[error("{0}")]
    Welch(#[from] WelchError),
    #[error("{0}")]
    SteppedSine(#[from] SteppedSineError),
    #[error("the record has {0} samples: too short to estimate anything")]
    TooShort(usize),
    #[error("the segment length {0} s must be positive")]
    BadSegment(f64),
    #[error("the coherence threshold {0} must be in [0, 1]")]
    BadCoherence(f64),
}

/// A multisine record, torque- or current-driven.
fn periodic(exp: &Experiment, c: &Conditions) -> Result<Evaluation, EstimateError> {
    let r = exp.data.time_record().ok_or(EstimateError::WrongKind)?;
    let input = if r.current {
        Input::Current
    } else {
        Input::Torque
    };
    let (time_s, excitation, motor, table) =
        (r.time_s, r.drive, r.motor_angle_rad, r.table_angle_rad);
    let period = sample_period(time_s).ok_or(EstimateError::TooShort(time_s.len()))?;
    let series = Series {
        sample_rate_hz: 1.0 / period,
        input,
        excitation,
        motor_angle_rad: motor,
        table_angle_rad: table,
        ratio: fluctuation::ratio(exp)?,
    };
    Ok(Evaluation::Periodic(Box::new(
        periodic_evaluation::evaluate(&series, c)?,
    )))
}

/// Evaluates a `frequency_response_time` experiment with `opts`.
pub fn evaluate_experiment(
    exp: &Experiment,
    opts: &EstimateOptions,
) -> Result<Evaluation, EstimateError> {
    let c = exp
        .manifest
        .conditions
        .with_defaults(Kind::FrequencyResponseTime);
    if c.excitation == Some(Excitation::Multisine) {
        return periodic(exp, &c);
    }
    let Data::FrequencyResponseTime {
        time_s,
        motor_torque_nm,
        motor_angle_rad,
        table_angle_rad,
        ..
    } = &exp.data
    else {
        return Err(match exp.data {
            Data::FrequencyResponseTimeCurrent { .. } => EstimateError::CurrentNotMultisine,
            _ => EstimateError::WrongKind,
        });
    };
    let ratio = fluctuation::ratio(exp)?;
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
        let peaks = peaks::maxima(&curve, opts.max_peaks);
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
    let segment_len = match opts.segment_s {
        Some(s) if !(s > 0.0 && s.is_finite()) => return Err(EstimateError::BadSegment(s)),
        Some(s) => ((s / period).round() as usize) & !1,
        None => {
            ((DEFAULT_SEGMENT_S / period)
                .min((n - 1) as f64 / 4.0)
                .max(8.0) as usize)
                & !1
        }
    };
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
            gain_sigma_db: random_error_db(gain.coherence[k], gain.segments),
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

/// 8.69·√(1 − γ²)/(|γ|·√(2·segments)), dB; a large finite number where γ² = 0 (JSON
/// has no infinity).
fn random_error_db(coherence: f64, segments: usize) -> f64 {
    if coherence <= 0.0 {
        return 1e9;
    }
    let e = ((1.0 - coherence).max(0.0) / coherence).sqrt() / (2.0 * segments as f64).sqrt();
    20.0 / std::f64::consts::LN_10 * e
}

/// The runs of consecutive kept bins, as (frequency, gain) curves.
pub(crate) fn kept_runs(bins: &[Bin]) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut open = false;
    for b in bins {
        if b.kept {
            if !open {
                runs.push(Vec::new());
            }
            runs.last_mut()
                .expect("pushed when the run opened")
                .push((b.frequency_hz, b.gain_db));
        }
        open = b.kept;
    }
    runs
}

/// The prominent peaks of the kept runs (module docs), highest `max_peaks`, ascending.
fn kept_peaks(bins: &[Bin], opts: &EstimateOptions) -> Vec<Peak> {
    let mut found: Vec<Peak> = Vec::new();
    let mut start = 0;
    while start < bins.len() {
        if !bins[start].kept {
            start += 1;
            continue;
        }
        let end = start + bins[start..].iter().take_while(|b| b.kept).count();
        let run = &bins[start..end];
        let curve: Vec<(f64, f64)> = run.iter().map(|b| (b.frequency_hz, b.gain_db)).collect();
        let sigma: Vec<f64> = run.iter().map(|b| b.gain_sigma_db).collect();
        found.extend(peaks::prominent(
            &curve,
            Some(&sigma),
            opts.min_prominence_db,
        ));
        start = end;
    }
    peaks::highest(found, opts.max_peaks)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kept_runs_split_at_flagged_bins() {
        let bin = |f: f64, kept: bool| Bin {
            frequency_hz: f,
            gain_db: 0.0,
            phase_deg: 0.0,
            coherence: 1.0,
            compliance_db: 0.0,
            compliance_coherence: 1.0,
            gain_sigma_db: 0.0,
            kept,
        };
        let bins = [
            bin(1.0, true),
            bin(2.0, true),
            bin(3.0, false),
            bin(4.0, true),
        ];
        let runs = kept_runs(&bins);
        assert_eq!(runs.len(), 2);
        assert_eq!((runs[0].len(), runs[1].len()), (2, 1));
    }
}
