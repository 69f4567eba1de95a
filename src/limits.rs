//! The work one call may ask for, estimated before it starts: beyond these a request
//! is taken for a slip (a period in seconds given in milliseconds, a rate in Hz given
//! in kHz) and refused naming its options, unless [`ALLOW_LARGE`] is set to 1 for a
//! rare large job. The command line and the Python module check the same limits.

use crate::names::Num;

/// The environment variable that lifts the work limits for a rare large job.
pub const ALLOW_LARGE: &str = "RTID_ALLOW_LARGE";

/// Frequencies, samples or points one call may ask for.
pub const MAX_POINTS: f64 = 1e5;

/// Seconds of simulated time one run may ask for (an hour: the paper's tests need
/// minutes; a worm-gear run simulates ≈ 40 s per wall-clock second on one core).
pub const MAX_SIMULATED_S: f64 = 3600.0;

/// Integration steps of one simulation.
pub const MAX_STEPS: f64 = 1e9;

/// Samples of one simulation's output (rows of `rtid simulate`'s CSV).
pub const MAX_ROWS: f64 = 2e7;

/// Samples of one raw time record (`frequency_response_time`).
pub const MAX_RECORD_SAMPLES: f64 = 1e8;

/// Work above its limit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LimitError {
    /// More than can be counted (an infinite or NaN estimate).
    #[error("{options}: ask for more {what} than can be counted")]
    Uncountable {
        /// What is counted ("simulated seconds").
        what: String,
        /// The options that ask for it, as the caller names them.
        options: String,
    },
    /// Above the limit.
    #[error("{options}: ask for {amount:.3e} {what}, over the limit of {} (set {ALLOW_LARGE}=1 to run it anyway)", Num(*limit))]
    Over {
        /// The work asked for, in `what`.
        amount: f64,
        /// The limit, in `what`.
        limit: f64,
        /// What is counted ("simulated seconds").
        what: String,
        /// The options that ask for it, as the caller names them.
        options: String,
    },
}

/// Whether the limits are lifted ([`ALLOW_LARGE`]`=1`).
pub fn lifted() -> bool {
    std::env::var(ALLOW_LARGE).is_ok_and(|v| v == "1")
}

/// Work estimated before it starts: `amount` (of `what`, e.g. "simulated seconds")
/// asked for by `options` (as the caller names them) must stay within `limit`,
/// unless the limits are [`lifted`]. A non-finite amount is always refused.
pub fn work(amount: f64, limit: f64, what: &str, options: &str) -> Result<(), LimitError> {
    if amount.is_finite() && (amount <= limit || lifted()) {
        return Ok(());
    }
    if !amount.is_finite() {
        return Err(LimitError::Uncountable {
            what: what.into(),
            options: options.into(),
        });
    }
    Err(LimitError::Over {
        amount,
        limit,
        what: what.into(),
        options: options.into(),
    })
}

/// The frequencies `from`, `from + step`, … up to `to` (Hz), their number checked
/// against [`MAX_POINTS`] before the list is made (`options` naming from, to and step
/// as the caller does).
pub fn frequency_grid(
    from: f64,
    to: f64,
    step: f64,
    options: &str,
) -> Result<Vec<f64>, LimitError> {
    let count = ((to - from) / step + 1e-9).floor();
    work(count + 1.0, MAX_POINTS, "frequencies", options)?;
    Ok((0..=count as usize)
        .map(|i| from + step * i as f64)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn work_over_the_limit_is_refused_naming_the_options() {
        assert!(work(3600.0, MAX_SIMULATED_S, "simulated seconds", "period_s").is_ok());
        let e = work(f64::NAN, 1.0, "steps", "dt_s")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "dt_s: ask for more steps than can be counted");
        if !lifted() {
            let e = work(
                1e7,
                MAX_SIMULATED_S,
                "simulated seconds",
                "period_s, periods",
            );
            let e = e.unwrap_err().to_string();
            assert!(
                e.starts_with(
                    "period_s, periods: ask for 1.000e7 simulated seconds, over the limit of 3600"
                ),
                "{e}"
            );
        }
    }
}
