//! A measured speed-loop response (a `frequency_response` experiment with `response:
//! "speed_loop"`) against the model: its valid lines with their noise, the model's
//! closed loop at them ([`super::model`]), the complex residuals — the errors of
//! ln|T| and of the phase over each line's σ (`objectives::complex_response`'s
//! form) — and how far the model is from explaining the record.

use nalgebra::Complex;
use serde::Serialize;

use super::model::{as_measured, ClosedSpeedLoop};
use crate::angle::wrap;
use crate::experiments::frequency_response::measured::{self, DB_PER_NEPER};
use crate::io::experiment_file::{Conditions, Experiment, Kind, Response};
use crate::model::{ParamError, Params};

/// σ of ln|H| and of the phase (rad) per line where the file states no noise: 1 %.
pub const DEFAULT_SIGMA: f64 = 0.01;

/// A reduced χ² above this is a misfit beyond the record's noise: the model misses
/// each line by more than √2 of its σ on average.
pub const MISFIT_CHI2: f64 = 2.0;

/// Why an experiment is not a measured speed-loop response.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum NotSpeedLoop {
    #[error("not a speed-loop response (a frequency_response with response \"speed_loop\")")]
    Kind,
    #[error("a speed-loop response needs its phase (phase_deg)")]
    NoPhase,
    #[error("no valid line (every line outside band_hz?)")]
    NoLine,
}

/// The measured lines of a speed-loop response.
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredSpeedLoop {
    pub frequency_hz: Vec<f64>,
    pub ln_gain: Vec<f64>,
    /// The phase, rad, as the file has it (wrapped or not).
    pub phase_rad: Vec<f64>,
    pub sigma_ln: Vec<f64>,
    pub sigma_phase: Vec<f64>,
    /// Whether the noise is the file's (coherence, or stated σ) rather than the default.
    pub noise_stated: bool,
    pub conditions: Conditions,
}

/// How well a parameter set explains a measured response.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Misfit {
    /// RMS of the gain errors, dB, and of the phase errors, deg.
    pub gain_rms_db: f64,
    pub phase_rms_deg: f64,
    /// Σ r² / (number of residuals): 1 where the model misses by the noise alone.
    pub reduced_chi2: f64,
    /// Whether the misfit lies within the record's noise ([`MISFIT_CHI2`]).
    pub explained: bool,
}

/// Whether `exp` is a speed-loop response.
pub fn is_speed_loop(exp: &Experiment) -> bool {
    exp.manifest.kind == Kind::FrequencyResponse
        && measured::form(exp).response == Response::SpeedLoop
}

impl MeasuredSpeedLoop {
    /// The lines of `exp`, or why it is not a speed-loop response with phase.
    pub fn of(exp: &Experiment) -> Result<MeasuredSpeedLoop, NotSpeedLoop> {
        if !is_speed_loop(exp) {
            return Err(NotSpeedLoop::Kind);
        }
        let m = measured::complex_points(exp, |_| true).ok_or(NotSpeedLoop::NoPhase)?;
        if m.frequency_hz.is_empty() {
            return Err(NotSpeedLoop::NoLine);
        }
        let noise_stated = m.sigma_ln.is_some();
        let or_default = |s: Option<Vec<f64>>| {
            s.unwrap_or_else(|| vec![DEFAULT_SIGMA; m.frequency_hz.len()])
                .into_iter()
                .map(|v| {
                    if v.is_finite() && v > 0.0 {
                        v
                    } else {
                        DEFAULT_SIGMA
                    }
                })
                .collect()
        };
        Ok(MeasuredSpeedLoop {
            sigma_ln: or_default(m.sigma_ln),
            sigma_phase: or_default(m.sigma_phase),
            frequency_hz: m.frequency_hz,
            ln_gain: m.ln_gain,
            phase_rad: m.phase_rad,
            noise_stated,
            conditions: exp.manifest.conditions.clone(),
        })
    }

    /// The model's T at the lines, `p` run as the measurement ran it.
    pub fn model(&self, p: &Params) -> Result<Vec<Option<Complex<f64>>>, ParamError> {
        let t = ClosedSpeedLoop::new(&as_measured(p, &self.conditions))?;
        Ok(self.frequency_hz.iter().map(|&f| t.at(f)).collect())
    }

    /// The scaled residuals: the ln-gain errors, then the phase errors (model −
    /// measured over σ); a large finite one where the model has no value.
    pub fn residuals(&self, p: &Params) -> Result<Vec<f64>, ParamError> {
        let model = self.model(p)?;
        let n = model.len();
        let mut r = vec![0.0; 2 * n];
        for (i, t) in model.iter().enumerate() {
            let (gain, phase) = match t {
                Some(t) if t.norm() > 0.0 => (
                    (t.norm().ln() - self.ln_gain[i]) / self.sigma_ln[i],
                    wrap(t.arg() - self.phase_rad[i]) / self.sigma_phase[i],
                ),
                _ => (f64::NAN, f64::NAN),
            };
            r[i] = finite_or_large(gain);
            r[n + i] = finite_or_large(phase);
        }
        Ok(r)
    }

    /// The misfit of `p`.
    pub fn misfit(&self, p: &Params) -> Result<Misfit, ParamError> {
        Ok(self.misfit_of(&self.residuals(p)?))
    }

    /// The misfit of residuals `r` ([`Self::residuals`]).
    pub fn misfit_of(&self, r: &[f64]) -> Misfit {
        let (gain_rms_db, phase_rms_deg) =
            measured::rms_errors(r, &self.sigma_ln, &self.sigma_phase);
        let chi2 = r.iter().map(|x| x * x).sum::<f64>() / r.len().max(1) as f64;
        Misfit {
            gain_rms_db,
            phase_rms_deg,
            reduced_chi2: chi2,
            explained: chi2 <= MISFIT_CHI2,
        }
    }

    /// The measured gain (dB) and phase (deg, unwrapped from the first line).
    pub fn bode(&self) -> (Vec<f64>, Vec<f64>) {
        let gain = self.ln_gain.iter().map(|g| g * DB_PER_NEPER).collect();
        (gain, continuous(self.phase_rad.iter().copied()))
    }

    /// The lowest and highest line, Hz.
    pub fn span_hz(&self) -> (f64, f64) {
        let lo = self
            .frequency_hz
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let hi = self.frequency_hz.iter().copied().fold(0.0, f64::max);
        (lo, hi)
    }
}

/// The model's gain (dB) and phase (deg, unwrapped) of `p` at `frequency_hz`, run as
/// a measurement with `conditions` ran it; `None` at a line where it has none.
pub fn model_bode(
    p: &Params,
    conditions: &Conditions,
    frequency_hz: &[f64],
) -> Result<Vec<Option<(f64, f64)>>, ParamError> {
    let t = ClosedSpeedLoop::new(&as_measured(p, conditions))?;
    let values: Vec<Option<Complex<f64>>> = frequency_hz.iter().map(|&f| t.at(f)).collect();
    let mut phases = continuous(values.iter().flatten().map(|t| t.arg())).into_iter();
    Ok(values
        .iter()
        .map(|t| Some((20.0 * t.as_ref()?.norm().log10(), phases.next()?)))
        .collect())
}

/// Phases (rad) made continuous from one to the next, from the first wrapped into
/// (−π, π], in degrees.
fn continuous(phases: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut previous: Option<f64> = None;
    phases
        .map(|p| {
            let next = previous.map_or(wrap(p), |q| q + wrap(p - q));
            previous = Some(next);
            next.to_degrees()
        })
        .collect()
}

/// A scaled residual, or a large finite one where the model has no value.
fn finite_or_large(r: f64) -> f64 {
    if r.is_finite() {
        r
    } else {
        1e3
    }
}

/// What a speed-loop response shows at a glance.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Summary {
    pub lines: usize,
    pub lowest_hz: f64,
    pub highest_hz: f64,
    /// The first line where the gain falls 3 dB below its value at the lowest line,
    /// Hz, and the phase there, deg (`None`: it never does).
    pub bandwidth_hz: Option<f64>,
    pub phase_at_bandwidth_deg: Option<f64>,
    /// The highest gain below the bandwidth, dB, and its line (the loop's overshoot).
    pub peak_db: f64,
    pub peak_hz: f64,
}

impl MeasuredSpeedLoop {
    /// The summary of the lines as measured.
    pub fn summary(&self) -> Summary {
        let (gain, phase) = self.bode();
        summary(&self.frequency_hz, &gain, &phase)
    }
}

/// The summary of gains (dB) and phases (deg) at ascending lines `f`.
pub fn summary(f: &[f64], gain: &[f64], phase: &[f64]) -> Summary {
    let first = gain.first().copied().unwrap_or(0.0);
    let band = gain.iter().position(|g| *g < first - 3.0);
    let upto = band.unwrap_or(gain.len());
    let (peak_i, peak_db) =
        gain[..upto]
            .iter()
            .copied()
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |a, (i, g)| if g > a.1 { (i, g) } else { a },
            );
    Summary {
        lines: f.len(),
        lowest_hz: f.first().copied().unwrap_or(0.0),
        highest_hz: f.last().copied().unwrap_or(0.0),
        bandwidth_hz: band.map(|i| f[i]),
        phase_at_bandwidth_deg: band.map(|i| phase[i]),
        peak_db,
        peak_hz: f.get(peak_i).copied().unwrap_or(0.0),
    }
}
