//! Figures of the frequency-response test (paper Fig. 8): the gain over frequency, the
//! linear model's curve where the file carries one, the resonances marked.

use super::figure::{Figure, Series, Style};
use crate::estimation::peaks::Peak;

/// The gain curve (`frequency_hz`, `gain_db`), the linear model's gain at the same
/// frequencies when given, and the resonances.
pub fn gain(
    frequency_hz: &[f64],
    gain_db: &[f64],
    linear_db: Option<&[f64]>,
    peaks: &[Peak],
    title: &str,
) -> Figure {
    let curve = |g: &[f64]| {
        frequency_hz
            .iter()
            .copied()
            .zip(g.iter().copied())
            .collect()
    };
    let mut figure = Figure::new(title, "frequency, Hz", "gain, dB").with(Series::new(
        "gain (simulated or measured)",
        curve(gain_db),
        Style::Line,
    ));
    if let Some(lin) = linear_db {
        figure = figure.with(Series::new("linear model", curve(lin), Style::Dashed));
    }
    figure.with(Series::new(
        "resonances",
        peaks.iter().map(|p| (p.frequency_hz, p.gain_db)).collect(),
        Style::Markers,
    ))
}
