//! Stepped-sine demodulation of a recorded frequency-response test: the drive held at
//! each frequency for a dwell, one after the other, recorded as one time series.
//!
//! Per dwell k (from `t0 + k·dwell` to `t0 + (k+1)·dwell`, t0 the first sample) the
//! first `settle_fraction` of the dwell is discarded (the transient of the frequency
//! change), and over the largest whole number of drive cycles that follows, motor
//! angle, table angle and torque are each fitted by least squares with an offset, a
//! quadratic drift (the open-loop drive wanders) and sin/cos at the drive frequency
//! ([`fit`], the same model as the virtual test of `frequency_response.rs`). Gain =
//! 20·log10(|table| / (|motor|·ratio)); phase = table − motor.
//!
//! Over whole cycles the fit rejects every other harmonic and a steady drift exactly;
//! what is left of the frequency-change transient (modes ringing at their own
//! frequency) leaks in as ~ its amplitude / (number of cycles × frequency offset), so a
//! lightly damped mode needs a long dwell or a large `settle_fraction`.

use serde::Serialize;

/// Settings of the demodulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteppedSineOptions {
    /// Fraction of each dwell discarded at its start, 0..1 (default 0.5).
    pub settle_fraction: f64,
}

impl Default for SteppedSineOptions {
    fn default() -> Self {
        SteppedSineOptions {
            settle_fraction: 0.5,
        }
    }
}

/// A fitted sinusoid `amplitude·sin(ωt + phase)` on top of a quadratic drift.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SineFit {
    pub amplitude: f64,
    /// rad, relative to sin(ωt) at absolute time t.
    pub phase: f64,
    /// RMS of what the fit leaves, in the signal's unit.
    pub residual_rms: f64,
}

/// The design row [1, τ, τ², sin ωt, cos ωt] at `ti` (τ the time scaled to [−1, 1]
/// over [t0, t0 + span]).
fn row(ti: f64, t0: f64, span: f64, omega: f64) -> nalgebra::Vector5<f64> {
    let tau = 2.0 * (ti - t0) / span - 1.0;
    let (s, c) = (omega * ti).sin_cos();
    nalgebra::Vector5::new(1.0, tau, tau * tau, s, c)
}

/// Least-squares coefficients of each `x[k](t) − x[k](0)` on the design row, with one
/// normal matrix for all signals (`None` without samples or when it is singular).
fn coefficients<const K: usize>(
    t: &[f64],
    x: [&[f64]; K],
    omega: f64,
) -> Option<[nalgebra::Vector5<f64>; K]> {
    if t.is_empty() || x.iter().any(|x| x.len() != t.len()) {
        return None;
    }
    let (t0, span) = (t[0], (t[t.len() - 1] - t[0]).max(f64::MIN_POSITIVE));
    let mut ata = nalgebra::Matrix5::<f64>::zeros();
    let mut atb = [nalgebra::Vector5::<f64>::zeros(); K];
    let x0 = x.map(|x| x[0]);
    for (i, &ti) in t.iter().enumerate() {
        let r = row(ti, t0, span, omega);
        ata += r * r.transpose();
        for k in 0..K {
            atb[k] += r * (x[k][i] - x0[k]);
        }
    }
    let lu = ata.lu();
    let mut out = [nalgebra::Vector5::<f64>::zeros(); K];
    for k in 0..K {
        out[k] = lu.solve(&atb[k])?;
    }
    Some(out)
}

/// Amplitude and phase: a_s·sin + a_c·cos = A·sin(ωt + φ).
fn amplitude_phase(coef: &nalgebra::Vector5<f64>) -> (f64, f64) {
    let (a_s, a_c) = (coef[3], coef[4]);
    ((a_s * a_s + a_c * a_c).sqrt(), a_c.atan2(a_s))
}

/// Amplitude and phase (rad) of the component at `omega` of each signal `x[k](t)`,
/// fitted with an offset and a quadratic drift; (0, 0) without samples. One normal
/// matrix serves all signals (the frequency-response test fits motor and table).
pub fn components<const K: usize>(t: &[f64], x: [&[f64]; K], omega: f64) -> [(f64, f64); K] {
    match coefficients(t, x, omega) {
        Some(c) => c.map(|c| amplitude_phase(&c)),
        None => [(0.0, 0.0); K],
    }
}

/// Least squares of `x(t)` on [1, τ, τ², sin ωt, cos ωt] (τ the time scaled to [−1, 1]),
/// with the RMS of what the fit leaves.
pub fn fit(t: &[f64], x: &[f64], omega: f64) -> SineFit {
    let Some([coef]) = coefficients(t, [x], omega) else {
        return SineFit {
            amplitude: 0.0,
            phase: 0.0,
            residual_rms: 0.0,
        };
    };
    let (t0, span) = (t[0], (t[t.len() - 1] - t[0]).max(f64::MIN_POSITIVE));
    let sum_sq: f64 = t
        .iter()
        .zip(x)
        .map(|(&ti, &xi)| (xi - x[0] - row(ti, t0, span, omega).dot(&coef)).powi(2))
        .sum();
    let (amplitude, phase) = amplitude_phase(&coef);
    SineFit {
        amplitude,
        phase,
        residual_rms: (sum_sq / t.len() as f64).sqrt(),
    }
}

/// The result at one drive frequency.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SinePoint {
    pub frequency_hz: f64,
    /// 20·log10(table amplitude / (motor amplitude × ratio)), dB.
    pub gain_db: f64,
    /// Table relative to motor angle, degrees in (−180, 180].
    pub phase_deg: f64,
    pub motor_amplitude_rad: f64,
    pub table_amplitude_rad: f64,
    /// Amplitude of the torque at the drive frequency, N·m.
    pub torque_amplitude_nm: f64,
    /// 20·log10(table amplitude / torque amplitude), dB re 1 rad/(N·m).
    pub compliance_db: f64,
    /// Whole drive cycles fitted.
    pub cycles: usize,
    /// RMS residual of the table fit over the table amplitude/√2: 0 for a clean
    /// sinusoid; near 1 or above, the table motion is not a sine at the drive
    /// frequency (noise, backlash rattle, an unsettled transient).
    pub table_residual: f64,
}

/// Why a record cannot be demodulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SteppedSineError {
    #[error("the record lasts {record_s:.6} s but {count} frequencies × dwell {dwell_s} s need {needed_s:.6} s")]
    TooShort {
        record_s: f64,
        count: usize,
        dwell_s: f64,
        needed_s: f64,
    },
    #[error("{frequency_hz} Hz: the kept part of its dwell ({kept_s:.4} s) holds no whole cycle; lengthen the dwell or lower the settle fraction")]
    NoCycle { frequency_hz: f64, kept_s: f64 },
    #[error("{frequency_hz} Hz is above a quarter of the sampling rate {rate_hz:.1} Hz: too few samples per cycle")]
    Undersampled { frequency_hz: f64, rate_hz: f64 },
    #[error("the settle fraction {0} must be in [0, 1)")]
    BadSettle(f64),
    #[error("{frequency_hz} Hz: the motor shows no motion at the drive frequency")]
    NoMotion { frequency_hz: f64 },
}

/// Demodulates a stepped-sine record (module docs). `time` uniformly sampled, all
/// series of its length, `ratio` = Rg·Rw.
#[allow(clippy::too_many_arguments)]
pub fn demodulate(
    time: &[f64],
    torque: &[f64],
    motor: &[f64],
    table: &[f64],
    ratio: f64,
    frequencies_hz: &[f64],
    dwell_s: f64,
    opts: &SteppedSineOptions,
) -> Result<Vec<SinePoint>, SteppedSineError> {
    if !(0.0..1.0).contains(&opts.settle_fraction) {
        return Err(SteppedSineError::BadSettle(opts.settle_fraction));
    }
    let n = time.len();
    let period = crate::io::experiment_file::sample_period(time).unwrap_or(f64::INFINITY);
    let t0 = time[0];
    let record_s = time[n - 1] - t0 + period.min(1e9);
    let needed_s = frequencies_hz.len() as f64 * dwell_s;
    // Within half a sample: a last time stamp jittered within the sampling tolerance
    // still covers the last dwell (its samples are all there).
    if record_s < needed_s - 0.5 * period.min(needed_s) {
        return Err(SteppedSineError::TooShort {
            record_s,
            count: frequencies_hz.len(),
            dwell_s,
            needed_s,
        });
    }
    let index = |t: f64| (((t - t0) / period).ceil().max(0.0) as usize).min(n);
    let mut points = Vec::with_capacity(frequencies_hz.len());
    for (k, &f) in frequencies_hz.iter().enumerate() {
        if f > 0.25 / period {
            return Err(SteppedSineError::Undersampled {
                frequency_hz: f,
                rate_hz: 1.0 / period,
            });
        }
        let start = t0 + (k as f64 + opts.settle_fraction) * dwell_s;
        let kept_s = (1.0 - opts.settle_fraction) * dwell_s;
        let cycles = (kept_s * f + 1e-9).floor() as usize;
        if cycles == 0 {
            return Err(SteppedSineError::NoCycle {
                frequency_hz: f,
                kept_s,
            });
        }
        // Samples in [start, start + cycles/f): whole cycles to within a sample.
        let (a, b) = (index(start), index(start + cycles as f64 / f));
        let omega = std::f64::consts::TAU * f;
        let t = &time[a..b];
        let (m, y, q) = (
            fit(t, &motor[a..b], omega),
            fit(t, &table[a..b], omega),
            fit(t, &torque[a..b], omega),
        );
        if m.amplitude <= 0.0 || !m.amplitude.is_finite() {
            return Err(SteppedSineError::NoMotion { frequency_hz: f });
        }
        let mut phase = (y.phase - m.phase).to_degrees();
        phase -= 360.0 * ((phase + 180.0) / 360.0).ceil() - 360.0;
        let floor = f64::MIN_POSITIVE;
        points.push(SinePoint {
            frequency_hz: f,
            gain_db: 20.0 * (y.amplitude.max(floor) / (m.amplitude * ratio)).log10(),
            phase_deg: phase,
            motor_amplitude_rad: m.amplitude,
            table_amplitude_rad: y.amplitude,
            torque_amplitude_nm: q.amplitude,
            compliance_db: 20.0 * (y.amplitude.max(floor) / q.amplitude.max(floor)).log10(),
            cycles,
            table_residual: y.residual_rms / (y.amplitude / 2f64.sqrt()).max(floor),
        });
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::experiment_file::SAMPLING_TOLERANCE;

    #[test]
    fn the_fit_ignores_offset_and_drift_and_has_no_residual() {
        let omega = std::f64::consts::TAU * 50.0;
        let t: Vec<f64> = (0..400).map(|i| i as f64 * 1e-4).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|&t| 3.0 + 20.0 * t - 5.0 * t * t + 0.7 * (omega * t + 0.4).sin())
            .collect();
        let f = fit(&t, &x, omega);
        assert!((f.amplitude - 0.7).abs() < 1e-9 && (f.phase - 0.4).abs() < 1e-9);
        assert!(f.residual_rms < 1e-9, "{f:?}");
    }

    /// Two dwells of a synthetic record: table = 2·ratio·motor delayed by 30°.
    #[test]
    fn demodulation_recovers_gain_and_phase_per_dwell() {
        let ratio = 0.01;
        let dt = 1e-4;
        let freqs = [20.0, 73.0];
        let dwell = 0.5;
        let time: Vec<f64> = (0..10_000).map(|i| i as f64 * dt).collect();
        let f_at = |t: f64| freqs[((t / dwell) as usize).min(1)];
        let motor: Vec<f64> = time
            .iter()
            .map(|&t| 0.3 * t + 1e-3 * (std::f64::consts::TAU * f_at(t) * t).sin())
            .collect();
        let table: Vec<f64> = time
            .iter()
            .map(|&t| {
                let w = std::f64::consts::TAU * f_at(t);
                ratio * 0.3 * t + 2.0 * ratio * 1e-3 * (w * t - 30f64.to_radians()).sin()
            })
            .collect();
        let torque: Vec<f64> = time
            .iter()
            .map(|&t| 5.0 * (std::f64::consts::TAU * f_at(t) * t).sin())
            .collect();
        let opts = SteppedSineOptions::default();
        let p = demodulate(&time, &torque, &motor, &table, ratio, &freqs, dwell, &opts).unwrap();
        for q in &p {
            assert!((q.gain_db - 20.0 * 2f64.log10()).abs() < 1e-6, "{q:?}");
            assert!((q.phase_deg + 30.0).abs() < 1e-6, "{q:?}");
            assert!((q.torque_amplitude_nm - 5.0).abs() < 1e-6, "{q:?}");
        }
        assert_eq!(p[1].cycles, 18);
        let mut jittered = time.clone();
        let step = time[1] - time[0];
        *jittered.last_mut().unwrap() -= 0.9 * SAMPLING_TOLERANCE * step;
        let q = demodulate(
            &jittered, &torque, &motor, &table, ratio, &freqs, dwell, &opts,
        );
        assert_eq!(
            q.unwrap().len(),
            freqs.len(),
            "a jittered last time stamp is accepted"
        );
        let long = [20.0, 73.0, 90.0];
        let e = demodulate(&time, &torque, &motor, &table, ratio, &long, dwell, &opts);
        assert!(matches!(e, Err(SteppedSineError::TooShort { .. })), "{e:?}");
    }
}
