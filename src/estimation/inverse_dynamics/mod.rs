//! Inverse-dynamic identification by least squares (IDIM-LS) of a rigid axis:
//!
//! ```text
//! F = M·q'' + Fv·q' + Fc·sign(q') + OF
//! ```
//!
//! i.e. docs/model.md §1's direct drive M·q'' = F − Fv·q' − Fc·sign(q') − OF with the
//! drive's effort F (N or N·m) on the left: M the mass or inertia (kg or kg·m²), Fv the
//! viscous coefficient (N·s/m or N·m·s/rad), Fc the Coulomb friction (N or N·m) and OF
//! a constant offset effort (N or N·m; on EMPS, OF = −3.16 N). The regression's
//! constant column estimates +OF. Units follow the position's: metres give kg, N·s/m, N;
//! radians give kg·m², N·m·s/rad, N·m.
//!
//! The method is Gautier's (M. Gautier, "Dynamic identification of robots with power
//! model", Proc. IEEE ICRA 1997; A. Janot, P.-O. Vandanjon, M. Gautier, "A generic
//! instrumental variable approach for industrial robot identification", IEEE Trans.
//! Control Syst. Technol. 22(1), 2014, §II), as used for the EMPS benchmark's reference
//! model (A. Janot, M. Gautier, M. Brunot, "Data Set and Reference Models of EMPS",
//! Nonlinear System Identification Benchmarks, Eindhoven, 2019):
//!
//! 1. the position is low-passed by a zero-phase Butterworth filter
//!    ([`butterworth`]), then differentiated by central differences:
//!    q'_k = (q_{k+1} − q_{k−1})/(2Ts), q''_k = (q_{k+1} − 2q_k + q_{k−1})/Ts²;
//! 2. *parallel decimation*: the effort and every column of the regressor
//!    [q'', q', sign(q'), 1] are low-passed by the same zero-phase filter (8th-order
//!    Butterworth at 0.8 of the decimated Nyquist frequency, the band of MATLAB's
//!    `decimate`), then every k-th row is kept. The filter is linear and applied to
//!    both sides, so the equation still holds row by row: it does not bias the
//!    estimate, it removes the effort's high-frequency content that the rigid model
//!    does not explain and decorrelates the rows that are kept;
//! 3. `trim` samples at each end are dropped (the filters' edge transients), and the
//!    rows at which |q'| < `min_speed` (sign(q') is ill-defined there: the sign of a
//!    near-zero estimate is noise, and stiction is not Coulomb friction);
//! 4. ordinary least squares, with standard errors from σ²(WᵀW)⁻¹,
//!    σ² = ‖r‖²/(rows − 4).
//!
//! **The cut-off's bias.** The position filter also attenuates the acceleration inside
//! the band the decimation filter keeps, where the effort is not attenuated; M absorbs
//! the difference and rises as the cut-off falls. On EMPS with decimation by 10 (a
//! 40 Hz decimation filter) and no speed threshold, M is 98.17 kg at a 10 Hz cut-off,
//! 96.16 kg at 20 Hz, 95.08 kg at 50 Hz and 95.06 kg from 80 Hz up (the independent
//! computation in shared/data/emps/README.md: 98.2, 96.19, 95.15 kg); from 10 Hz up,
//! Fv, Fc and OF move by less than 0.5 %. The default cut-off, 100 Hz, lies 2.5 times
//! above the decimation filter's band, where the forward-backward filter attenuates
//! by less than 0.06 % (|H(40 Hz)|² = 0.99948): the estimate no longer depends on it.
//! On a pure sine of frequency f the bias is exact and known: M and Fv come out
//! divided by |H(f)|² times the central differences' gain, sin(ωTs)/(ωTs) for q' and
//! (2 − 2cos ωTs)/(ωTs)² for q'' (tested; 0.09 % on M for 8 Hz through a 20 Hz
//! filter). The edge transients are a matter of trimming: on that noise-free sine,
//! 200 samples (eight periods of the 20 Hz cut-off) leave 7e-6 of Fc, 400 leave 1e-9.

pub mod butterworth;

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use butterworth::Butterworth;

/// Order of the decimation filter (MATLAB's `decimate` uses an 8th-order prototype).
pub const DECIMATION_FILTER_ORDER: usize = 8;
/// Cut-off of the decimation filter as a fraction of the decimated Nyquist frequency
/// fs/(2k) (as MATLAB's `decimate`).
pub const DECIMATION_BAND: f64 = 0.8;

/// How the record is filtered, differentiated, decimated and trimmed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct IdimSettings {
    /// Cut-off (−3 dB of one pass) of the zero-phase Butterworth low-pass applied to
    /// the position before differentiation, Hz.
    pub cutoff_hz: f64,
    /// Order of that filter (each pass; forward-backward doubles it).
    pub filter_order: usize,
    /// Parallel decimation factor k: keep every k-th row after the decimation filter
    /// (1: no decimation filter, every row).
    pub decimation: usize,
    /// Samples dropped at each end of the record (at the record's rate), s·fs.
    pub trim: usize,
    /// Rows whose filtered speed |q'| is below this are left out, in position units per
    /// second (m/s or rad/s).
    pub min_speed: f64,
}

impl Default for IdimSettings {
    /// A 100 Hz 4th-order position filter, decimation by 10, 200 samples trimmed at
    /// each end, rows below 1 mm/s (or 1 mrad/s) left out — for a 1 kHz record like
    /// EMPS's. The trimming and decimation are those of the reference computation in
    /// shared/data/emps/README.md; the cut-off lies above the decimation band (see the
    /// module documentation), so the estimates do not depend on it. The speed threshold
    /// is some 40 times the velocity noise of a 5e-8 m encoder differentiated at 1 kHz
    /// and 1 % of EMPS's top speed: it leaves out the rows at the reversals whose sign
    /// is in doubt (23 of 2445 on EMPS) and moves the estimates by < 0.1 % (OF by
    /// 0.03 N). Larger thresholds start to trade Fc against Fv (10 mm/s: Fv −2.4 %,
    /// Fc +2.4 %), as the rows near the reversals are what tells them apart.
    fn default() -> Self {
        IdimSettings {
            cutoff_hz: 100.0,
            filter_order: 4,
            decimation: 10,
            trim: 200,
            min_speed: 1e-3,
        }
    }
}

impl IdimSettings {
    /// The default design carried to a record sampled every `period_s`: the same
    /// filters relative to the sampling frequency (the position filter at fs/10, the
    /// decimation by 10, 200 samples trimmed), the 1 mm/s (1 mrad/s) speed threshold
    /// unchanged. At 1 kHz, [`IdimSettings::default`].
    pub fn for_sample_period(period_s: f64) -> Self {
        let d = IdimSettings::default();
        IdimSettings {
            cutoff_hz: d.cutoff_hz * 1e-3 / period_s,
            ..d
        }
    }
}

/// What a caller changes of [`IdimSettings::for_sample_period`] (`rtid evaluate
/// --cutoff-hz …`, `rtid.evaluate(cutoff_hz=…)`): `None` keeps the default.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IdimOverrides {
    pub cutoff_hz: Option<f64>,
    pub decimation: Option<usize>,
    /// Seconds dropped at each end (rounded to samples).
    pub trim_s: Option<f64>,
    pub min_speed: Option<f64>,
}

/// An override that is not a setting.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum IdimOverrideError {
    /// A cut-off, trim or speed threshold that is negative or not finite; `name` is
    /// the field's (`cutoff_hz`, `trim_s`, `min_speed`).
    #[error("{name} {value}: must be a finite number ≥ 0")]
    Negative { name: &'static str, value: f64 },
    #[error("decimation 0: must be at least 1 (1: no decimation)")]
    Decimation,
}

impl IdimOverrides {
    /// The settings for a record sampled every `period_s`, these overrides applied.
    pub fn settings(&self, period_s: f64) -> Result<IdimSettings, IdimOverrideError> {
        for (name, value) in [
            ("cutoff_hz", self.cutoff_hz),
            ("trim_s", self.trim_s),
            ("min_speed", self.min_speed),
        ] {
            if let Some(v) = value.filter(|v| !v.is_finite() || *v < 0.0) {
                return Err(IdimOverrideError::Negative { name, value: v });
            }
        }
        if self.decimation == Some(0) {
            return Err(IdimOverrideError::Decimation);
        }
        let mut s = IdimSettings::for_sample_period(period_s);
        s.cutoff_hz = self.cutoff_hz.unwrap_or(s.cutoff_hz);
        s.decimation = self.decimation.unwrap_or(s.decimation);
        s.min_speed = self.min_speed.unwrap_or(s.min_speed);
        if let Some(t) = self.trim_s {
            s.trim = (t / period_s).round() as usize;
        }
        Ok(s)
    }
}

/// One estimated parameter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    pub value: f64,
    /// Standard error from σ²(WᵀW)⁻¹: a lower bound where the residuals are correlated
    /// or the model misses effects.
    pub std_error: f64,
}

impl Estimate {
    /// The standard error relative to |value|, % (infinite for a zero value).
    pub fn relative_error_percent(&self) -> f64 {
        100.0 * self.std_error / self.value.abs()
    }
}

/// The result of an IDIM-LS identification, with the settings that produced it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IdimFit {
    /// M: mass, kg (linear), or inertia, kg·m² (rotary).
    pub inertia: Estimate,
    /// Fv: viscous coefficient, N·s/m or N·m·s/rad.
    pub viscous: Estimate,
    /// Fc: Coulomb friction, N or N·m.
    pub coulomb: Estimate,
    /// OF: constant offset effort, N or N·m (F = … + OF).
    pub offset: Estimate,
    /// RMS of the regression's residual (filtered effort minus model), N or N·m.
    pub residual_rms: f64,
    /// Rows in the regression.
    pub rows: usize,
    /// Rows left out for a speed below `min_speed`.
    pub slow_rows: usize,
    /// Ratio of the largest to the smallest singular value of the regressor (its
    /// columns as they are, in SI units).
    pub condition_number: f64,
    /// The record's sample period, s.
    pub sample_period_s: f64,
    /// Cut-off of the decimation filter, Hz (none without decimation).
    pub decimation_cutoff_hz: Option<f64>,
    pub settings: IdimSettings,
}

/// Why an identification cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IdimError {
    #[error("the position has {position} samples but the effort has {effort}")]
    LengthMismatch { position: usize, effort: usize },
    #[error("{series} sample {index} is {value}: every sample must be a finite number")]
    NotFinite {
        series: &'static str,
        index: usize,
        value: f64,
    },
    #[error("`{name}` is {value}: {reason}")]
    Setting {
        name: &'static str,
        value: f64,
        reason: &'static str,
    },
    #[error(
        "{rows} rows are left for 4 parameters after trimming, decimation and leaving out \
         slow rows ({slow} of them): the record is too short or too slow"
    )]
    TooFewRows { rows: usize, slow: usize },
    #[error(
        "the regressor is singular (condition number {condition:.3e}): the record does \
         not excite every parameter (it needs motion both ways at changing speed)"
    )]
    Singular { condition: f64 },
    #[error(
        "the {what} is not a finite number: the record's positions, efforts or sample \
         period are out of any physical range"
    )]
    Overflow { what: &'static str },
}

/// Identifies M, Fv, Fc and OF from a uniformly sampled `position` (m or rad) and the
/// drive's `effort` (N or N·m) sampled every `sample_period_s`, with `settings`.
pub fn identify(
    sample_period_s: f64,
    position: &[f64],
    effort: &[f64],
    settings: &IdimSettings,
) -> Result<IdimFit, IdimError> {
    check_inputs(sample_period_s, position, effort, settings)?;
    let rate = 1.0 / sample_period_s;
    let smooth = Butterworth::low_pass(settings.filter_order, settings.cutoff_hz, rate)
        .ok_or_else(|| setting("cutoff_hz", settings.cutoff_hz, "must lie in (0, fs/2)"))?;
    let q = smooth.zero_phase(position);
    let (velocity, acceleration) = central_differences(&q, sample_period_s);
    let sign: Vec<f64> = velocity.iter().map(|v| sign(*v)).collect();
    let mut columns = [acceleration, velocity, sign, effort.to_vec()];
    let decimation_cutoff_hz = parallel_filter(&mut columns, rate, settings.decimation)?;
    let [acceleration, velocity, sign, effort] = &columns;
    // Records out of any physical range (angles of 1e308, a sample period of
    // 1e-300 s) overflow here: a NaN speed would pass for a slow row, and the SVD
    // never returns on a non-finite regressor.
    if acceleration.iter().chain(velocity).any(|v| !v.is_finite()) {
        return Err(IdimError::Overflow {
            what: "speed or acceleration derived from the positions",
        });
    }
    if effort.iter().any(|v| !v.is_finite()) {
        return Err(IdimError::Overflow {
            what: "filtered effort",
        });
    }
    let (rows, slow_rows) = select_rows(velocity, settings);
    if rows.len() < 2 * 4 {
        return Err(IdimError::TooFewRows {
            rows: rows.len(),
            slow: slow_rows,
        });
    }
    let w = DMatrix::from_fn(rows.len(), 4, |i, j| {
        let k = rows[i];
        [acceleration[k], velocity[k], sign[k], 1.0][j]
    });
    let y = DVector::from_iterator(rows.len(), rows.iter().map(|&k| effort[k]));
    let ls = least_squares(&w, &y)?;
    let estimate = |j: usize| Estimate {
        value: ls.theta[j],
        std_error: ls.std_errors[j],
    };
    Ok(IdimFit {
        inertia: estimate(0),
        viscous: estimate(1),
        coulomb: estimate(2),
        offset: estimate(3),
        residual_rms: ls.residual_rms,
        rows: rows.len(),
        slow_rows,
        condition_number: ls.condition_number,
        sample_period_s,
        decimation_cutoff_hz,
        settings: *settings,
    })
}

fn setting(name: &'static str, value: f64, reason: &'static str) -> IdimError {
    IdimError::Setting {
        name,
        value,
        reason,
    }
}

/// Equal lengths, finite samples, sensible settings.
fn check_inputs(
    sample_period_s: f64,
    position: &[f64],
    effort: &[f64],
    s: &IdimSettings,
) -> Result<(), IdimError> {
    if position.len() != effort.len() {
        return Err(IdimError::LengthMismatch {
            position: position.len(),
            effort: effort.len(),
        });
    }
    for (series, values) in [("position", position), ("effort", effort)] {
        if let Some((index, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(IdimError::NotFinite {
                series,
                index,
                value,
            });
        }
    }
    if !(sample_period_s > 0.0 && sample_period_s.is_finite()) {
        return Err(setting(
            "sample_period_s",
            sample_period_s,
            "must be positive",
        ));
    }
    if s.filter_order == 0 {
        return Err(setting("filter_order", 0.0, "must be at least 1"));
    }
    if s.decimation == 0 {
        return Err(setting("decimation", 0.0, "must be at least 1 (1: none)"));
    }
    if !(s.min_speed >= 0.0 && s.min_speed.is_finite()) {
        return Err(setting("min_speed", s.min_speed, "must be finite and ≥ 0"));
    }
    Ok(())
}

/// Central differences of `q` at every inner sample (the two end samples repeat their
/// neighbours' values; the trimming removes them): velocity and acceleration.
fn central_differences(q: &[f64], ts: f64) -> (Vec<f64>, Vec<f64>) {
    let n = q.len();
    let mut v = vec![0.0; n];
    let mut a = vec![0.0; n];
    for k in 1..n.saturating_sub(1) {
        v[k] = (q[k + 1] - q[k - 1]) / (2.0 * ts);
        a[k] = (q[k + 1] - 2.0 * q[k] + q[k - 1]) / (ts * ts);
    }
    if n >= 3 {
        (v[0], a[0], v[n - 1], a[n - 1]) = (v[1], a[1], v[n - 2], a[n - 2]);
    }
    (v, a)
}

/// sign(v), 0 at 0.
fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// With decimation k > 1, low-passes every column by the same zero-phase decimation
/// filter and returns its cut-off, Hz.
fn parallel_filter(
    columns: &mut [Vec<f64>; 4],
    rate: f64,
    k: usize,
) -> Result<Option<f64>, IdimError> {
    if k == 1 {
        return Ok(None);
    }
    let cutoff = DECIMATION_BAND * rate / (2.0 * k as f64);
    let filter = Butterworth::low_pass(DECIMATION_FILTER_ORDER, cutoff, rate)
        .ok_or_else(|| setting("decimation", k as f64, "leaves no band to keep"))?;
    for column in columns.iter_mut() {
        *column = filter.zero_phase(column);
    }
    Ok(Some(cutoff))
}

/// Every k-th row between the trimmed ends (the end samples always excluded), less
/// those slower than `min_speed`; returns the rows and how many were too slow.
fn select_rows(velocity: &[f64], s: &IdimSettings) -> (Vec<usize>, usize) {
    let n = velocity.len();
    let first = s.trim.max(1);
    let last = n.saturating_sub(s.trim.max(1));
    let candidates = (first..last).step_by(s.decimation);
    let (rows, slow): (Vec<usize>, Vec<usize>) =
        candidates.partition(|&k| velocity[k].abs() >= s.min_speed);
    (rows, slow.len())
}

/// θ minimising ‖y − Wθ‖, with standard errors, residual RMS and condition number.
struct LeastSquares {
    theta: [f64; 4],
    std_errors: [f64; 4],
    residual_rms: f64,
    condition_number: f64,
}

/// Iterations of the SVD at most (it takes a few dozen on a well-posed record; the
/// cap makes a pathological one an error, not a hang).
const SVD_MAX_ITERATIONS: usize = 10_000;

/// Least squares through the SVD of W (robust to the columns' different scales;
/// [`identify`] has refused non-finite columns).
fn least_squares(w: &DMatrix<f64>, y: &DVector<f64>) -> Result<LeastSquares, IdimError> {
    let svd = w
        .clone()
        .try_svd(true, true, f64::EPSILON, SVD_MAX_ITERATIONS)
        .ok_or(IdimError::Singular {
            condition: f64::INFINITY,
        })?;
    let (max, min) = (svd.singular_values.max(), svd.singular_values.min());
    let condition = max / min;
    if !(condition.is_finite() && condition < 1e12) {
        return Err(IdimError::Singular { condition });
    }
    let theta = svd
        .solve(y, 0.0)
        .map_err(|_| IdimError::Singular { condition })?;
    let residual = y - w * &theta;
    let rows = w.nrows() as f64;
    let sigma2 = residual.norm_squared() / (rows - 4.0);
    // (WᵀW)⁻¹ = V Σ⁻² Vᵀ.
    let v_t = svd.v_t.as_ref().ok_or(IdimError::Singular { condition })?;
    let mut std_errors = [0.0; 4];
    for (j, e) in std_errors.iter_mut().enumerate() {
        let var: f64 = (0..4)
            .map(|i| (v_t[(i, j)] / svd.singular_values[i]).powi(2))
            .sum();
        *e = (sigma2 * var).sqrt();
    }
    let residual_rms = (residual.norm_squared() / rows).sqrt();
    if !(residual_rms.is_finite() && theta.iter().chain(&std_errors).all(|v| v.is_finite())) {
        return Err(IdimError::Overflow {
            what: "least-squares fit (its residual or standard errors)",
        });
    }
    Ok(LeastSquares {
        theta: [theta[0], theta[1], theta[2], theta[3]],
        std_errors,
        residual_rms,
        condition_number: condition,
    })
}

#[cfg(test)]
mod tests;
