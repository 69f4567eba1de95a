//! The evaluation of a periodic multisine record (`"excitation": "multisine"`): both
//! channels estimated over whole periods ([`crate::estimation::periodic::estimate`]), each one's
//! resonances and antiresonances that stand above its noise ([`crate::estimation::extrema`]),
//! located by a rational fit over the band around them ([`crate::estimation::local_mode_fit`]),
//! the nonlinear distortion at the lines the excitation leaves out, and the two-mass
//! ratios the motor channel determines ([`crate::estimation::two_mass_ratios`]). docs/multisine.md
//! works the method through on a real bench record.
//!
//! The channels: the table (or load) angle over the motor angle × the drive ratio — the
//! paper's gain, whose peaks are the motor-held modes — by the reference ratio (the
//! excitation as instrument: noise on the motor angle does not bias it); and the motor
//! angle over the input (torque, or current without a torque constant) by H1, whose
//! resonances are the motor-free modes and whose antiresonances are the motor-held
//! ones.

use serde::Serialize;

use crate::estimation::extrema::{extrema, ExtremaOptions, Extremum};
use crate::estimation::local_mode_fit::{fit, ModeFitOptions, SecondOrder};
use crate::estimation::peaks::Peak;
use crate::estimation::periodic::estimate::{h1, reference_ratio, FrfEstimate, FrfLine};
use crate::estimation::periodic::nonlinear_distortion::DistortionBand;
use crate::estimation::periodic::record::{PeriodicError, PeriodicOptions, PeriodicRecord};
use crate::estimation::two_mass_ratios::{self, TwoMassRatios};
use crate::io::experiment_file::Conditions;

/// The input the record's motor channel responds to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Input {
    /// `motor_torque_nm`: responses per N·m.
    Torque,
    /// `motor_current_a` without a torque constant: responses per ampere.
    Current,
}

impl Input {
    /// The motor channel's name and unit.
    fn channel(self) -> (&'static str, &'static str) {
        match self {
            Input::Torque => ("motor angle / motor torque", "rad/(N·m)"),
            Input::Current => ("motor angle / motor current", "rad/A"),
        }
    }
}

/// The record's time series, SI.
pub struct Series<'a> {
    pub sample_rate_hz: f64,
    pub input: Input,
    /// The excitation as measured (torque or current).
    pub excitation: &'a [f64],
    pub motor_angle_rad: &'a [f64],
    pub table_angle_rad: &'a [f64],
    /// Motor angle × ratio = table angle of a rigid drive.
    pub ratio: f64,
}

/// One resonance or antiresonance of a channel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Mode {
    /// Where it is: the rational fit's undamped frequency, or the extremum's when the
    /// fit could not place it in its band.
    pub frequency_hz: f64,
    /// Standard error of the fitted frequency (`None`: from the extremum).
    pub frequency_se_hz: Option<f64>,
    /// Damping ratio of the fitted pole or zero pair.
    pub damping_ratio: Option<f64>,
    /// The extremum of the measured gain (parabola in dB through three lines).
    pub extremum_hz: f64,
    pub gain_db: f64,
    /// How far it stands out, and the level it had to reach (the noise's), dB.
    pub prominence_db: f64,
    pub threshold_db: f64,
}

/// One channel's estimate and what it shows.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Channel {
    pub name: &'static str,
    pub unit: &'static str,
    pub resonances: Vec<Mode>,
    pub antiresonances: Vec<Mode>,
    /// The lowest coherence over the excited lines.
    pub min_coherence: f64,
    /// Distortion levels per band at the output (odd and even non-excited lines).
    pub distortion: Vec<DistortionBand>,
    pub lines: Vec<FrfLine>,
}

/// The evaluation of a multisine record.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PeriodicEvaluation {
    pub input: Input,
    pub ratio: f64,
    pub sample_rate_hz: f64,
    pub period_s: f64,
    pub period_detected: bool,
    pub periods_in_record: usize,
    pub periods_used: usize,
    pub excited_lines: usize,
    pub lines_detected: bool,
    pub first_line_hz: f64,
    pub last_line_hz: f64,
    /// Table (load) angle over motor angle × ratio.
    pub table: Channel,
    /// Motor angle over the input.
    pub motor: Channel,
    /// The two-mass ratios from the motor channel's resonance and antiresonance, when
    /// it has exactly one of each, the antiresonance below.
    pub two_mass: Option<TwoMassRatios>,
    /// The table channel's resonances as peaks (frequency, gain).
    pub peaks: Vec<Peak>,
}

/// Why a multisine record cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PeriodicEvaluationError {
    #[error("{0}")]
    Record(#[from] PeriodicError),
    #[error("period_s = {period_s} s is not a whole number of samples at {sample_rate_hz} Hz")]
    Period { period_s: f64, sample_rate_hz: f64 },
    #[error("{field} = {value} Hz is not a whole multiple of 1/period_s = {spacing_hz} Hz")]
    Line {
        field: &'static str,
        value: f64,
        spacing_hz: f64,
    },
    #[error("{0}")]
    Extrema(#[from] crate::estimation::extrema::ExtremaError),
}

/// Evaluates the series of a multisine record under the manifest's `conditions`.
pub fn evaluate(
    s: &Series<'_>,
    c: &Conditions,
) -> Result<PeriodicEvaluation, PeriodicEvaluationError> {
    let options = options(s.sample_rate_hz, c)?;
    let rec = PeriodicRecord::new(s.excitation, s.sample_rate_hz, &options)?;
    let scaled: Vec<f64> = s.motor_angle_rad.iter().map(|m| m * s.ratio).collect();
    let table = reference_ratio(&rec, s.table_angle_rad, &scaled)?;
    let motor = h1(&rec, s.excitation, s.motor_angle_rad)?;
    let band = c.band_hz.map(|[lo, hi]| (lo, hi));
    let table = channel(
        "table angle / motor angle × ratio",
        "rad/rad",
        &table,
        0,
        band,
    )?;
    let (name, unit) = s.input.channel();
    let motor = channel(name, unit, &motor, 2, band)?;
    let two_mass = match (&motor.resonances[..], &motor.antiresonances[..]) {
        ([res], [anti]) => {
            two_mass_ratios::from_frequencies(res.frequency_hz, anti.frequency_hz).ok()
        }
        _ => None,
    };
    let spacing = rec.sample_rate_hz / rec.samples_per_period as f64;
    Ok(PeriodicEvaluation {
        input: s.input,
        ratio: s.ratio,
        sample_rate_hz: s.sample_rate_hz,
        period_s: 1.0 / spacing,
        period_detected: rec.period_detected,
        periods_in_record: rec.periods_in_record,
        periods_used: rec.periods_used(),
        excited_lines: rec.excited.len(),
        lines_detected: rec.lines_detected,
        first_line_hz: rec.excited.first().map_or(0.0, |&k| k as f64 * spacing),
        last_line_hz: rec.excited.last().map_or(0.0, |&k| k as f64 * spacing),
        peaks: table
            .resonances
            .iter()
            .map(|m| Peak {
                frequency_hz: m.frequency_hz,
                gain_db: m.gain_db,
            })
            .collect(),
        table,
        motor,
        two_mass,
    })
}

/// The framing the manifest names: the period (in samples), the excited lines, the
/// transient periods; what it leaves out is detected.
fn options(fs: f64, c: &Conditions) -> Result<PeriodicOptions, PeriodicEvaluationError> {
    let mut o = PeriodicOptions {
        drop_periods: c.transient_periods.unwrap_or(1) as usize,
        ..PeriodicOptions::default()
    };
    let Some(period_s) = c.period_s else {
        return Ok(o);
    };
    let n = period_s * fs;
    if !(n >= 1.0 && (n - n.round()).abs() < 1e-6 * n) {
        return Err(PeriodicEvaluationError::Period {
            period_s,
            sample_rate_hz: fs,
        });
    }
    o.samples_per_period = Some(n.round() as usize);
    if let (Some(first), Some(last)) = (c.first_line_hz, c.last_line_hz) {
        let line = |field: &'static str, hz: f64| {
            let k = hz * period_s;
            if k >= 1.0 && (k - k.round()).abs() < 1e-6 * k {
                Ok(k.round() as usize)
            } else {
                Err(PeriodicEvaluationError::Line {
                    field,
                    value: hz,
                    spacing_hz: 1.0 / period_s,
                })
            }
        };
        let (k0, k1) = (line("first_line_hz", first)?, line("last_line_hz", last)?);
        let step = line("line_step_hz", c.line_step_hz.unwrap_or(1.0 / period_s))?;
        o.excited_lines = Some((k0..=k1).step_by(step).collect());
    }
    Ok(o)
}

/// A channel's modes: the extrema above its noise (within `band`, else the excited
/// lines), each located by the rational fit with `integrators` (2 for an angle over a
/// torque or current, 0 for an angle over an angle).
fn channel(
    name: &'static str,
    unit: &'static str,
    e: &FrfEstimate,
    integrators: u32,
    band: Option<(f64, f64)>,
) -> Result<Channel, PeriodicEvaluationError> {
    let f = e.frequency_hz();
    let opts = ExtremaOptions {
        band_hz: band,
        ..ExtremaOptions::default()
    };
    let found = extrema(&f, &e.gain_db(), &e.gain_uncertainty_db(), &opts)?;
    let located = locate(e, &found.maxima, &found.minima, integrators);
    Ok(Channel {
        name,
        unit,
        resonances: located.0,
        antiresonances: located.1,
        min_coherence: e.lines.iter().map(|l| l.coherence).fold(1.0, f64::min),
        distortion: e.output_distortion.clone(),
        lines: e.lines.clone(),
    })
}

/// A rational fit's pole and zero pairs.
type Pairs = (Option<SecondOrder>, Option<SecondOrder>);

/// The maxima and minima as modes. One of each: one fit over 0.8× the lower to 1.2×
/// the higher (docs/multisine.md: the bench record's validated band); otherwise each
/// alone over 0.8…1.2× its frequency. A fit that fails, or puts the pair outside its
/// band, leaves the extremum's frequency.
fn locate(
    e: &FrfEstimate,
    maxima: &[Extremum],
    minima: &[Extremum],
    integrators: u32,
) -> (Vec<Mode>, Vec<Mode>) {
    if let ([max], [min]) = (maxima, minima) {
        let lo = max.frequency_hz.min(min.frequency_hz);
        let hi = max.frequency_hz.max(min.frequency_hz);
        let band = (0.8 * lo, 1.2 * hi);
        let fitted = fit_band(e, band, integrators);
        let pole = fitted.and_then(|(p, _)| p);
        let zero = fitted.and_then(|(_, z)| z);
        return (vec![mode(max, pole, band)], vec![mode(min, zero, band)]);
    }
    let alone = |x: &Extremum, pick: fn(Pairs) -> Option<SecondOrder>| {
        let band = (0.8 * x.frequency_hz, 1.2 * x.frequency_hz);
        mode(x, fit_band(e, band, integrators).and_then(pick), band)
    };
    (
        maxima.iter().map(|x| alone(x, |f| f.0)).collect(),
        minima.iter().map(|x| alone(x, |f| f.1)).collect(),
    )
}

/// The pole and zero pairs of the rational fit over `band`, lines weighted alike
/// (docs/multisine.md, weighting); `None` when the fit fails.
fn fit_band(e: &FrfEstimate, band: (f64, f64), integrators: u32) -> Option<Pairs> {
    let alike = vec![1.0; e.lines.len()];
    let opts = ModeFitOptions::new(band, integrators);
    fit(&e.frequency_hz(), &e.h(), &alike, &opts)
        .ok()
        .map(|m| (m.pole, m.zero))
}

/// The extremum `x` as a mode, at the fitted pair when it lies in `band`.
fn mode(x: &Extremum, fitted: Option<SecondOrder>, band: (f64, f64)) -> Mode {
    let fitted = fitted
        .filter(|p| (band.0..=band.1).contains(&p.frequency_hz) && p.frequency_se_hz.is_finite());
    Mode {
        frequency_hz: fitted.map_or(x.frequency_hz, |p| p.frequency_hz),
        frequency_se_hz: fitted.map(|p| p.frequency_se_hz),
        damping_ratio: fitted.map(|p| p.damping_ratio),
        extremum_hz: x.frequency_hz,
        gain_db: x.gain_db,
        prominence_db: x.prominence_db,
        threshold_db: x.threshold_db,
    }
}
