//! Checks of numeric option values, each naming the option: run before any work, so a
//! bad value fails at once and not after a simulation.

use anyhow::bail;

/// A positive finite value.
pub fn positive(v: f64, option: &str) -> anyhow::Result<f64> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        bail!("{option} {v}: must be a positive number")
    }
}

/// Zero or a positive finite value.
pub fn non_negative(v: f64, option: &str) -> anyhow::Result<f64> {
    if v >= 0.0 && v.is_finite() {
        Ok(v)
    } else {
        bail!("{option} {v}: must be zero or positive")
    }
}

/// A finite value.
pub fn finite(v: f64, option: &str) -> anyhow::Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        bail!("{option} {v}: must be a finite number")
    }
}
