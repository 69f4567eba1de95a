//! Figures of the positioning test (ISO 230-2; paper Fig. 10).

use super::figure::{Figure, Series, Style};
use crate::experiments::iso230::{Iso230Report, TargetStats, ARCSEC_PER_RAD};

/// The paper's Fig. 10: x̄↑, x̄↓, their ±2s bands and x̄ over the target angle, in
/// arc-seconds.
pub fn deviations(report: &Iso230Report, title: &str) -> Figure {
    let pts = |f: &dyn Fn(&TargetStats) -> f64| -> Vec<(f64, f64)> {
        report
            .targets
            .iter()
            .map(|s| (s.target.to_degrees(), f(s) * ARCSEC_PER_RAD))
            .collect()
    };
    Figure::new(title, "target angle, deg", "positional deviation, arc-sec")
        .with(Series::new("x̄↑", pts(&|s| s.mean_up), Style::Line))
        .with(Series::new(
            "x̄↑ ± 2s↑",
            pts(&|s| s.mean_up + 2.0 * s.s_up),
            Style::Dashed,
        ))
        .with(Series::new(
            "",
            pts(&|s| s.mean_up - 2.0 * s.s_up),
            Style::Dashed,
        ))
        .with(Series::new("x̄↓", pts(&|s| s.mean_down), Style::Line))
        .with(Series::new(
            "x̄↓ ± 2s↓",
            pts(&|s| s.mean_down + 2.0 * s.s_down),
            Style::Dashed,
        ))
        .with(Series::new(
            "",
            pts(&|s| s.mean_down - 2.0 * s.s_down),
            Style::Dashed,
        ))
        .with(Series::new(
            "x̄",
            pts(&|s| s.mean_bidirectional),
            Style::Markers,
        ))
}
