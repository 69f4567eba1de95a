//! Uniform sampling of a time record: the check the reader makes on
//! `frequency_response_time` and `servo_trace` records, and the sampling period the
//! estimators use.

use std::fmt;

/// Largest departure of one time step from the record's median step, as a fraction of
/// that step, that a uniformly sampled record may have (a DAQ writing times rounded
/// to 1 µs at 20 kHz stays within 2 %; EMPS's stored times jitter by 2e-8 s on a 1 ms
/// step, 0.002 %; one dropped sample is a 100 % departure).
pub const SAMPLING_TOLERANCE: f64 = 0.05;

/// A time step of a record that should be uniformly sampled but is not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NonUniform {
    /// Index of the sample that ends the step.
    pub row: usize,
    /// The step there, s.
    pub step: f64,
    /// The record's median step, s.
    pub median: f64,
}

impl fmt::Display for NonUniform {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the step from the previous row is {:.6e} s where the record steps {:.6e} s: \
             the samples must be uniformly spaced (within {:.0} % of a step)",
            self.step,
            self.median,
            100.0 * SAMPLING_TOLERANCE
        )
    }
}

/// Checks that strictly increasing `time` is uniformly sampled: every step within
/// [`SAMPLING_TOLERANCE`] of the median step. Fewer than two samples pass.
pub fn check_uniform(time: &[f64]) -> Result<(), NonUniform> {
    let steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return Ok(());
    }
    let mut sorted = steps.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    match steps
        .iter()
        .position(|s| (s - median).abs() > SAMPLING_TOLERANCE * median)
    {
        Some(i) => Err(NonUniform {
            row: i + 1,
            step: steps[i],
            median,
        }),
        None => Ok(()),
    }
}

/// The sampling period of a uniformly sampled record: the mean step, which rounding
/// of the individual times does not bias. `None` for fewer than two samples.
pub fn sample_period(time: &[f64]) -> Option<f64> {
    (time.len() >= 2).then(|| (time[time.len() - 1] - time[0]) / (time.len() - 1) as f64)
}
