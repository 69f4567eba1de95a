//! Angles: a phase wrapped into one turn, as the frequency-response readers, the
//! virtual records and the objectives all need it.

use std::f64::consts::{PI, TAU};

/// A phase in (−π, π].
pub fn wrap(phase: f64) -> f64 {
    let w = phase - TAU * (phase / TAU).round();
    if w <= -PI {
        w + TAU
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrapping_keeps_the_half_open_interval() {
        assert_eq!(wrap(PI), PI);
        assert!((wrap(-PI) - PI).abs() < 1e-15);
        assert!((wrap(3.0 * TAU + 0.5) - 0.5).abs() < 1e-12);
        assert!((wrap(-7.0) - (-7.0 + TAU)).abs() < 1e-12);
    }
}
