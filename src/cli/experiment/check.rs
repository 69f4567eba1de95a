//! Checks of numeric option values, each naming the option: run before any work, so a
//! bad value fails at once and not after a simulation.

use anyhow::bail;
use rtid::names::Num;

/// The largest magnitude an option's value may have (in its own unit): beyond, no
/// drive test's quantity, but a slip (1e308 made infinite samples that were then
/// named by the file's cell rather than by the option).
pub const MAX_OPTION: f64 = 1e15;

/// A positive finite value.
pub fn positive(v: f64, option: &str) -> anyhow::Result<f64> {
    within(v, option)?;
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        bail!("{option} {}: must be a positive number", Num(v))
    }
}

/// Zero or a positive finite value.
pub fn non_negative(v: f64, option: &str) -> anyhow::Result<f64> {
    within(v, option)?;
    if v >= 0.0 && v.is_finite() {
        Ok(v)
    } else {
        bail!("{option} {}: must be zero or positive", Num(v))
    }
}

/// A noise or scatter level, %: from 0 to 100 (beyond, the noise is not a
/// measurement's; 1e308 % made infinite samples that the writer then named as a cell
/// rather than as the option).
pub fn percent(v: f64, option: &str) -> anyhow::Result<f64> {
    if (0.0..=100.0).contains(&v) {
        Ok(v)
    } else {
        bail!("{option} {}: must lie in 0..100 (%)", Num(v))
    }
}

/// A finite value.
pub fn finite(v: f64, option: &str) -> anyhow::Result<f64> {
    within(v, option)?;
    if v.is_finite() {
        Ok(v)
    } else {
        bail!("{option} {}: must be a finite number", Num(v))
    }
}

/// `v` within ±[`MAX_OPTION`] (NaN and infinities are left to the caller's check).
fn within(v: f64, option: &str) -> anyhow::Result<()> {
    if v.is_finite() && v.abs() > MAX_OPTION {
        bail!(
            "{option} {}: beyond ±1e15, no drive test's value (a unit slip?)",
            Num(v)
        );
    }
    Ok(())
}

pub use rtid::limits::{MAX_POINTS, MAX_SIMULATED_S};

/// Work estimated before it starts (`rtid::limits::work`): `amount` (of `what`) from
/// `options` must stay within `limit`, unless `RTID_ALLOW_LARGE` is set to 1.
pub fn work(amount: f64, limit: f64, what: &str, options: &str) -> anyhow::Result<()> {
    Ok(rtid::limits::work(amount, limit, what, options)?)
}

/// The frequencies `from`, `from + step`, … up to `to` (Hz), their number checked
/// against [`MAX_POINTS`] before the list is made.
pub fn frequency_grid(from: f64, to: f64, step: f64) -> anyhow::Result<Vec<f64>> {
    Ok(rtid::limits::frequency_grid(
        from,
        to,
        step,
        "--from-hz, --to-hz, --step-hz",
    )?)
}
