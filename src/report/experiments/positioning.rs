//! Figures of the positioning test (ISO 230-2; paper Fig. 10).

use crate::experiments::positioning::iso230::{Iso230Report, ReportUnits, TargetStats};
use crate::report::figure::{Figure, Series, Style};

/// The paper's Fig. 10: x̄↑, x̄↓, their ±2s bands and x̄ over the target, in the
/// axis's report units (degrees and arc-seconds, or mm and µm).
pub fn deviations(report: &Iso230Report, title: &str, units: ReportUnits) -> Figure {
    let pts = |f: &dyn Fn(&TargetStats) -> f64| -> Vec<(f64, f64)> {
        report
            .targets
            .iter()
            .map(|s| {
                (
                    s.target * units.target_per_si,
                    f(s) * units.deviation_per_si,
                )
            })
            .collect()
    };
    let (x, y) = if units == ReportUnits::ROTARY {
        ("target angle, deg", "positional deviation, arc-sec")
    } else {
        ("target position, mm", "positional deviation, µm")
    };
    Figure::new(title, x, y)
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
