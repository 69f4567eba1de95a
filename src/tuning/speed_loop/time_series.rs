//! A drive measurement's response recomputed from its own time series with rtid's
//! periodic estimator ([`crate::estimation::periodic`]), as a check of the spectra
//! the drive stored.
//!
//! The file holds one PRBS period per direction of the offset. The negative
//! direction's series are the positive one's mirrored (setpoint −offset ∓ the same
//! PRBS), so negated they are a second period of the same excitation about the same
//! operating speed, mirrored: the two directions become two periods of one record.
//! Over them the estimate is H1 = Σ Y_p·X_p*/Σ |X_p|² at every DFT line, the spread
//! of the two periods its noise and γ² its coherence — the sums the drive's own
//! spectra are averages of, so where the estimator is right the two agree to
//! rounding. The noise of two periods rests on one degree of freedom, and it takes in
//! whatever differs between the directions (friction acts against the motion in
//! each), which the drive's coherence does as well.

use crate::estimation::periodic::estimate::{h1, FrfEstimate};
use crate::estimation::periodic::record::{PeriodicError, PeriodicOptions, PeriodicRecord};
use crate::io::experiment_file::{Columns, Data};
use crate::io::formats::sinumerik_trace::response::{self, ResponseError, StoredResponse};
use crate::io::formats::sinumerik_trace::Measurement;

/// Why the response cannot be recomputed.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum RecomputeError {
    #[error(transparent)]
    File(#[from] ResponseError),
    #[error("{0} time series per signal: the noise needs two periods (both directions)")]
    OneDirection(usize),
    #[error("the time series: {0}")]
    Estimate(#[from] PeriodicError),
}

/// H1 of the primary output over its input from the time series of both directions.
pub fn recompute(m: &Measurement) -> Result<FrfEstimate, RecomputeError> {
    let n = response::samples_per_period(m)?;
    let directions = response::directions(m)?;
    if directions.len() < 2 {
        return Err(RecomputeError::OneDirection(directions.len()));
    }
    let (mut input, mut output) = (Vec::new(), Vec::new());
    for d in &directions {
        input.extend(d.input.iter().map(|v| d.sign * v));
        output.extend(d.output.iter().map(|v| d.sign * v));
    }
    let options = PeriodicOptions {
        samples_per_period: Some(n),
        drop_periods: 0,
        excited_lines: Some((1..(n - 1) / 2).collect()),
        remove_drift: false,
        ..Default::default()
    };
    let record = PeriodicRecord::new(&input, 1.0 / m.sample_time_s, &options)?;
    Ok(h1(&record, &input, &output)?)
}

/// How the recomputed response agrees with the stored one on the lines where the
/// stored coherence is at least `min_coherence`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Agreement {
    pub min_coherence: f64,
    /// Lines compared.
    pub lines: usize,
    /// The largest differences, dB and degrees, and the lines (Hz) they are at.
    pub max_gain_db: f64,
    pub at_gain_hz: f64,
    pub max_phase_deg: f64,
    pub at_phase_hz: f64,
}

/// The agreement of `recomputed` with `stored` line by line.
pub fn agreement(
    stored: &StoredResponse,
    recomputed: &FrfEstimate,
    min_coherence: f64,
) -> Agreement {
    let mut a = Agreement {
        min_coherence,
        lines: 0,
        max_gain_db: 0.0,
        at_gain_hz: 0.0,
        max_phase_deg: 0.0,
        at_phase_hz: 0.0,
    };
    for line in &recomputed.lines {
        let Some(i) = stored.lines.iter().position(|&k| k == line.line) else {
            continue;
        };
        if stored.coherence[i] < min_coherence {
            continue;
        }
        a.lines += 1;
        let ratio = line.h() / stored.h[i];
        let gain = (20.0 * ratio.norm().log10()).abs();
        let phase = ratio.arg().to_degrees().abs();
        if gain > a.max_gain_db {
            (a.max_gain_db, a.at_gain_hz) = (gain, line.frequency_hz);
        }
        if phase > a.max_phase_deg {
            (a.max_phase_deg, a.at_phase_hz) = (phase, line.frequency_hz);
        }
    }
    a
}

/// The recomputed response as experiment-file data: gain, phase and coherence per
/// line (the noise the two directions' spread gives rests on one degree of freedom
/// per line, too rough to weigh a fit by: the coherence, as the drive's spectra
/// give it, stands for it).
pub fn to_data(estimate: &FrfEstimate) -> Data {
    let lines = &estimate.lines;
    let mut extra = Columns::new();
    extra.insert(
        "coherence".into(),
        lines.iter().map(|l| l.coherence).collect(),
    );
    Data::FrequencyResponse {
        frequency_hz: lines.iter().map(|l| l.frequency_hz).collect(),
        gain_db: lines.iter().map(|l| l.gain_db).collect(),
        phase_rad: Some(lines.iter().map(|l| l.phase_deg.to_radians()).collect()),
        extra,
    }
}
