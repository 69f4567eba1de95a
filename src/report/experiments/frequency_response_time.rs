//! Figures of a frequency response estimated from raw time series: the gain (stepped
//! sine or H1) with its resonances, and the coherence of an H1 estimate.

use crate::experiments::frequency_response::time_evaluation::{kept_runs, Bin, Evaluation};
use crate::report::figure::{Figure, Series, Style};

/// The gain with the resonances marked, and for H1 the coherence figure too.
pub fn figures(e: &Evaluation, mechanism: &str) -> (Figure, Option<Figure>) {
    let markers = Series::new(
        "resonances",
        e.peaks()
            .iter()
            .map(|p| (p.frequency_hz, p.gain_db))
            .collect(),
        Style::Markers,
    );
    match e {
        Evaluation::SteppedSine { points, .. } => {
            let mut curve: Vec<(f64, f64)> =
                points.iter().map(|q| (q.frequency_hz, q.gain_db)).collect();
            curve.sort_by(|a, b| a.0.total_cmp(&b.0));
            let gain = Figure::new(
                format!("{mechanism}: frequency response (stepped sine)"),
                "frequency, Hz",
                "gain, dB",
            )
            .with(Series::new("gain (stepped sine)", curve, Style::Line))
            .with(markers)
            .log_x();
            (gain, None)
        }
        Evaluation::H1 {
            bins,
            min_coherence,
            ..
        } => {
            let mut gain = Figure::new(
                format!("{mechanism}: frequency response (H1, Welch)"),
                "frequency, Hz",
                "gain, dB",
            );
            for (i, run) in kept_runs(bins).into_iter().enumerate() {
                let name = if i == 0 {
                    format!("H1 gain where γ² ≥ {min_coherence}")
                } else {
                    String::new()
                };
                gain = gain.with(Series::new(name, run, Style::Line));
            }
            let coherence = coherence(bins, *min_coherence, mechanism);
            (gain.with(markers).log_x(), Some(coherence))
        }
        Evaluation::Periodic(p) => crate::report::periodic::figures(p, mechanism),
    }
}

/// The coherence up to a little beyond the highest kept bin (above it is noise), with
/// the threshold, on a log frequency axis (the 0 Hz bin not drawn).
fn coherence(bins: &[Bin], min_coherence: f64, mechanism: &str) -> Figure {
    let top = bins
        .iter()
        .filter(|b| b.kept)
        .map(|b| b.frequency_hz)
        .fold(0.0, f64::max);
    let top = if top > 0.0 { 1.2 * top } else { f64::INFINITY };
    let points: Vec<(f64, f64)> = bins
        .iter()
        .filter(|b| b.frequency_hz <= top)
        .map(|b| (b.frequency_hz, b.coherence))
        .collect();
    let x0 = points.iter().map(|c| c.0).find(|f| *f > 0.0).unwrap_or(1.0);
    let x1 = points.last().map_or(1.0, |c| c.0);
    Figure::new(
        format!("{mechanism}: coherence, motor angle → table angle"),
        "frequency, Hz",
        "γ²",
    )
    .with(Series::new("coherence γ²", points, Style::Line))
    .with(Series::new(
        "threshold",
        vec![(x0, min_coherence), (x1, min_coherence)],
        Style::Dashed,
    ))
    .log_x()
}
