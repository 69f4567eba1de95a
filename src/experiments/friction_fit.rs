//! The friction law of an axis fitted to any recorded motion — a servo trace, a
//! torque curve, a positioning cycle — by inverse-dynamic least squares (IDIM-LS;
//! M. Gautier, "Dynamic identification of robots with power model", ICRA 1997;
//! A. Janot, M. Gautier, M. Brunot, "Data Set and Reference Models of EMPS",
//! Nonlinear System Identification Benchmarks workshop, 2019):
//!
//! ```text
//! F = M·a + Fv·v + Fc·sign(v) + offset
//! ```
//!
//! F is the drive's force (N) or torque (N·m at the motor); v and a the velocity and
//! acceleration of the recorded position (m or rad; for a geared table the table
//! angle, so M, Fv are referred to it and Fc is the friction seen at the motor:
//! fm + fw·Rg + ft·Rg·Rw). The offset is the EMPS model's OF, −Tload of rtid's.
//!
//! Method: the position is low-passed by a zero-phase 4th-order Butterworth filter
//! (lowpass.rs; default 20 Hz) and differentiated by central differences, so v and a
//! are the filtered velocity and acceleration; the force and the sign(v) column pass
//! the same filter, so that every term of the law is filtered alike ("parallel
//! filtering"; exact for the linear terms, the sign column's smoothing matching the
//! measured force's near reversals). All are then low-passed again at 0.8 × the new
//! Nyquist frequency and decimated ("parallel decimation"); a number of samples at
//! each end is dropped (filter ends); the law is solved by SVD least squares, with
//! standard errors from σ²·(WᵀW)⁻¹ (white-residual assumption: lower bounds for a
//! filtered, correlated residual). On the EMPS estimation record this gives M 94.98 kg,
//! Fv 202.96 N·s/m, Fc 20.44 N, offset −3.18 N against the published 95.11, 203.50,
//! 20.39, −3.16, and M stays within 1 % from 10 to 50 Hz (tests/servo_trace.rs);
//! filtering the position alone, as the shared README's reference computation does,
//! gives M 96.1 kg at 20 Hz and a mass that moves with the cut-off.
//!
//! Unlike the torque-curve evaluation by reversal windows (torque_curve.rs), which
//! assumes the harmonic test motion, this works on any trajectory with enough motion
//! in both directions. Option: only the constant-velocity stretches
//! (`max_acceleration`), where the law is F = Fv·v + Fc·sign(v) + offset and the
//! inertia is not fitted.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::lowpass::Butterworth;
use super::torque_curve::TorqueCurve;

/// How to fit (defaults: those of the EMPS reference computation, README of
/// shared/data/emps).
#[derive(Clone, Debug, PartialEq)]
pub struct FrictionFitOptions {
    /// Cut-off of the zero-phase low-pass on the position before differentiating,
    /// Hz (default 20).
    pub cutoff_hz: f64,
    /// Keep one sample in this many after the parallel low-pass (default 10; 1 keeps
    /// every sample and filters nothing more).
    pub decimate: usize,
    /// Samples dropped at each end of the record (default 200).
    pub trim: usize,
    /// Samples with |v| below this are left out, rad/s or m/s (default 0: none).
    pub min_speed: f64,
    /// Only the constant-velocity stretches: samples with |a| above this (rad/s² or
    /// m/s²) are left out and the inertia is not fitted (default `None`: every
    /// sample, inertia fitted).
    pub max_acceleration: Option<f64>,
}

impl Default for FrictionFitOptions {
    fn default() -> Self {
        FrictionFitOptions {
            cutoff_hz: 20.0,
            decimate: 10,
            trim: 200,
            min_speed: 0.0,
            max_acceleration: None,
        }
    }
}

/// One fitted coefficient and its standard error (same unit).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    pub value: f64,
    pub std_error: f64,
}

/// The fitted law F = M·a + Fv·v + Fc·sign(v) + offset.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrictionFit {
    /// M: kg or kg·m² (force per unit of the position's acceleration); `None` when
    /// only constant-velocity stretches were fitted.
    pub inertia: Option<Estimate>,
    /// Fv: N·s/m or N·m·s/rad.
    pub viscous: Estimate,
    /// Fc: N or N·m.
    pub coulomb: Estimate,
    /// The constant force (torque) in the law, N or N·m: EMPS's OF, −Tload.
    pub offset: Estimate,
    /// RMS of the force residual over the samples fitted, N or N·m.
    pub residual_rms: f64,
    /// Samples fitted (after trimming, decimation and selection).
    pub samples: usize,
}

/// A record the law cannot be fitted to, or options that cannot work.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FrictionFitError {
    #[error("{field} has {len} samples, time_s has {expected}")]
    Length {
        field: &'static str,
        len: usize,
        expected: usize,
    },
    #[error("{field} row {row} is {value}: every sample must be a finite number")]
    NotFinite {
        field: &'static str,
        row: usize,
        value: f64,
    },
    #[error(transparent)]
    NotUniform(#[from] NotUniform),
    #[error(
        "cutoff_hz = {cutoff_hz} Hz must lie between 0 and the Nyquist frequency {nyquist_hz} Hz"
    )]
    Cutoff { cutoff_hz: f64, nyquist_hz: f64 },
    #[error("decimate = 0: keep at least one sample in one (1 decimates nothing)")]
    Decimate,
    #[error("only {samples} samples are left to fit after trimming, decimation and selection; at least {needed} are needed")]
    TooShort { samples: usize, needed: usize },
    #[error("the motion does not determine the friction law (rank {rank} of {columns}: {hint})")]
    Singular {
        rank: usize,
        columns: usize,
        hint: &'static str,
    },
    #[error("the torque curve has no table_angle column: the friction law needs the motion")]
    NoTableAngle,
}

/// A time base that is not a uniform sampling.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "time_s is not uniformly sampled: the step to row {row} is {step} s, the mean step {period} s"
)]
pub struct NotUniform {
    pub row: usize,
    pub step: f64,
    pub period: f64,
}

/// Relative deviation of a step from the mean step that still counts as uniform
/// (storage jitter: 2e-5 on the EMPS record; a missing sample is 1).
pub const UNIFORM_TOLERANCE: f64 = 1e-3;

/// The mean sample period of `time_s` (at least 2 samples), if every step is within
/// [`UNIFORM_TOLERANCE`] of it.
pub fn uniform_period(time_s: &[f64]) -> Result<f64, NotUniform> {
    let n = time_s.len();
    let period = (time_s[n - 1] - time_s[0]) / (n - 1) as f64;
    for row in 1..n {
        let step = time_s[row] - time_s[row - 1];
        // Written so that NaN and a non-positive period fail too.
        if !((step - period).abs() <= UNIFORM_TOLERANCE * period && period > 0.0) {
            return Err(NotUniform { row, step, period });
        }
    }
    Ok(period)
}

/// Fits the friction law to a record of position (rad or m) and force (N·m or N)
/// over uniformly sampled times (s).
pub fn fit_friction_law(
    time_s: &[f64],
    position: &[f64],
    force: &[f64],
    options: &FrictionFitOptions,
) -> Result<FrictionFit, FrictionFitError> {
    let period = check_record(time_s, &[("position", position), ("force", force)])?;
    let fs = 1.0 / period;
    if !(options.cutoff_hz > 0.0 && options.cutoff_hz < 0.5 * fs) {
        return Err(FrictionFitError::Cutoff {
            cutoff_hz: options.cutoff_hz,
            nyquist_hz: 0.5 * fs,
        });
    }
    if options.decimate == 0 {
        return Err(FrictionFitError::Decimate);
    }
    let low_pass = Butterworth::new(2, options.cutoff_hz, fs);
    let q = low_pass.filtfilt(position);
    let n = q.len();
    let mut columns = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![1.0; n]];
    for k in 1..n - 1 {
        let v = (q[k + 1] - q[k - 1]) / (2.0 * period);
        columns[0][k] = (q[k + 1] - 2.0 * q[k] + q[k - 1]) / (period * period);
        columns[1][k] = v;
        columns[2][k] = if v == 0.0 { 0.0 } else { v.signum() };
    }
    // a and v passed the low-pass through q; the force and the sign column pass it
    // too, so that every term of the law is filtered alike.
    columns[2] = low_pass.filtfilt(&columns[2]);
    let mut y = low_pass.filtfilt(force);
    if options.decimate > 1 {
        let anti_alias = Butterworth::new(2, 0.4 * fs / options.decimate as f64, fs);
        y = anti_alias.filtfilt(&y);
        for c in &mut columns[..3] {
            *c = anti_alias.filtfilt(c);
        }
    }
    let keep: Vec<usize> = (options.trim.max(1)..n.saturating_sub(options.trim.max(1)))
        .step_by(options.decimate)
        .filter(|&k| columns[1][k].abs() >= options.min_speed)
        .filter(|&k| {
            options
                .max_acceleration
                .map_or(true, |a| columns[0][k].abs() <= a)
        })
        .collect();
    let with_inertia = options.max_acceleration.is_none();
    let used: Vec<&Vec<f64>> = columns.iter().skip(usize::from(!with_inertia)).collect();
    solve(&keep, &used, &y, with_inertia)
}

/// Fits the friction law to a torque curve (paper §4.2): the table angle is the
/// motion, the motor torque the force, so Fc is the friction at the motor,
/// fm + fw·Rg + ft·Rg·Rw — the quantity `torque_curve::evaluate` estimates from the
/// reversal windows, here from the whole curve.
pub fn fit_torque_curve(
    curve: &TorqueCurve,
    options: &FrictionFitOptions,
) -> Result<FrictionFit, FrictionFitError> {
    if curve.table_angle.is_empty() {
        return Err(FrictionFitError::NoTableAngle);
    }
    fit_friction_law(
        &curve.time,
        &curve.table_angle,
        &curve.motor_torque,
        options,
    )
}

/// Checks equal lengths, finite values and a uniform time base; the sample period.
fn check_record(
    time_s: &[f64],
    series: &[(&'static str, &[f64])],
) -> Result<f64, FrictionFitError> {
    const NEEDED: usize = 8;
    if time_s.len() < NEEDED {
        return Err(FrictionFitError::TooShort {
            samples: time_s.len(),
            needed: NEEDED,
        });
    }
    for &(field, s) in [("time_s", time_s)].iter().chain(series) {
        if s.len() != time_s.len() {
            return Err(FrictionFitError::Length {
                field,
                len: s.len(),
                expected: time_s.len(),
            });
        }
        if let Some(row) = s.iter().position(|v| !v.is_finite()) {
            return Err(FrictionFitError::NotFinite {
                field,
                row,
                value: s[row],
            });
        }
    }
    Ok(uniform_period(time_s)?)
}

/// Least squares of `y` on the `columns` at the rows `keep` (the last three columns
/// are v, sign(v), 1; the first is a when `with_inertia`).
fn solve(
    keep: &[usize],
    columns: &[&Vec<f64>],
    y: &[f64],
    with_inertia: bool,
) -> Result<FrictionFit, FrictionFitError> {
    let p = columns.len();
    let m = keep.len();
    if m < 2 * p {
        return Err(FrictionFitError::TooShort {
            samples: m,
            needed: 2 * p,
        });
    }
    let w = DMatrix::from_fn(m, p, |i, j| columns[j][keep[i]]);
    let obs = DVector::from_iterator(m, keep.iter().map(|&k| y[k]));
    let svd = w.clone().svd(true, true);
    let largest = svd.singular_values.max();
    let rank = svd
        .singular_values
        .iter()
        .filter(|&&s| s > 1e-10 * largest)
        .count();
    if rank < p {
        return Err(FrictionFitError::Singular {
            rank,
            columns: p,
            hint: "it needs motion in both directions, with changes of speed unless only constant-velocity stretches are fitted",
        });
    }
    let theta = svd
        .solve(&obs, 1e-10 * largest)
        .expect("the SVD was computed with U and V");
    let residual = &obs - &w * &theta;
    let sigma2 = residual.norm_squared() / (m - p) as f64;
    let v_t = svd.v_t.as_ref().expect("computed with V");
    let errors: Vec<f64> = (0..p)
        .map(|j| {
            let var: f64 = (0..p)
                .map(|k| (v_t[(k, j)] / svd.singular_values[k]).powi(2))
                .sum();
            (sigma2 * var).sqrt()
        })
        .collect();
    let est = |j: usize| Estimate {
        value: theta[j],
        std_error: errors[j],
    };
    let first = usize::from(with_inertia);
    Ok(FrictionFit {
        inertia: with_inertia.then(|| est(0)),
        viscous: est(first),
        coulomb: est(first + 1),
        offset: est(first + 2),
        residual_rms: (residual.norm_squared() / m as f64).sqrt(),
        samples: m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record of the exact law along q(t) = A·sin(ωt) + B·sin(3ωt).
    fn synthetic(n: usize, dt: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (m, fv, fc, off) = (95.0, 200.0, 20.0, -3.0);
        let (a, b, w) = (0.1, 0.02, 2.0);
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let q = t
            .iter()
            .map(|t| a * (w * t).sin() + b * (3.0 * w * t).sin())
            .collect();
        let f = t
            .iter()
            .map(|t| {
                let v = a * w * (w * t).cos() + 3.0 * b * w * (3.0 * w * t).cos();
                let acc = -a * w * w * (w * t).sin() - 9.0 * b * w * w * (3.0 * w * t).sin();
                m * acc + fv * v + fc * v.signum() + off
            })
            .collect();
        (t, q, f)
    }

    #[test]
    fn the_exact_law_is_recovered() {
        let (t, q, f) = synthetic(20_000, 1e-3);
        let fit = fit_friction_law(&t, &q, &f, &FrictionFitOptions::default()).unwrap();
        let m = fit.inertia.unwrap().value;
        assert!((m - 95.0).abs() < 0.5, "{fit:?}");
        assert!((fit.viscous.value - 200.0).abs() < 1.0, "{fit:?}");
        assert!((fit.coulomb.value - 20.0).abs() < 0.2, "{fit:?}");
        assert!((fit.offset.value + 3.0).abs() < 0.1, "{fit:?}");
    }

    #[test]
    fn constant_velocity_stretches_give_the_friction_without_the_inertia() {
        let (t, q, f) = synthetic(20_000, 1e-3);
        let options = FrictionFitOptions {
            max_acceleration: Some(0.05),
            min_speed: 0.02,
            ..Default::default()
        };
        let fit = fit_friction_law(&t, &q, &f, &options).unwrap();
        assert_eq!(fit.inertia, None);
        assert!((fit.coulomb.value - 20.0).abs() < 1.0, "{fit:?}");
    }

    #[test]
    fn bad_records_and_options_are_named_errors() {
        let (t, q, f) = synthetic(2000, 1e-3);
        let short = &q[..100];
        assert!(matches!(
            fit_friction_law(&t, short, &f, &Default::default()),
            Err(FrictionFitError::Length {
                field: "position",
                ..
            })
        ));
        let mut nan = f.clone();
        nan[7] = f64::NAN;
        assert!(matches!(
            fit_friction_law(&t, &q, &nan, &Default::default()),
            Err(FrictionFitError::NotFinite {
                field: "force",
                row: 7,
                ..
            })
        ));
        let mut gap = t.clone();
        gap[500] += 0.5e-3;
        assert!(matches!(
            fit_friction_law(&gap, &q, &f, &Default::default()),
            Err(FrictionFitError::NotUniform(NotUniform { row: 500, .. }))
        ));
        let high = FrictionFitOptions {
            cutoff_hz: 600.0,
            ..Default::default()
        };
        assert!(matches!(
            fit_friction_law(&t, &q, &f, &high),
            Err(FrictionFitError::Cutoff { .. })
        ));
        let still = vec![0.3; t.len()];
        assert!(matches!(
            fit_friction_law(&t, &still, &f, &Default::default()),
            Err(FrictionFitError::Singular { .. })
        ));
    }
}
