//! Figures of a multisine record's evaluation: both channels' gains with their
//! resonances and antiresonances, and their coherence over the excited lines.

use crate::experiments::frequency_response::periodic_evaluation::{Channel, PeriodicEvaluation};
use crate::report::figure::{Figure, Series, Style};

/// The gains (each channel in its own unit, dB) with the modes marked, and the
/// coherence.
pub fn figures(p: &PeriodicEvaluation, mechanism: &str) -> (Figure, Option<Figure>) {
    let mut gain = Figure::new(
        format!("{mechanism}: frequency response, periodic multisine"),
        "frequency, Hz",
        "gain, dB (each channel in its unit)",
    );
    let mut coherence = Figure::new(
        format!("{mechanism}: coherence over the periods"),
        "frequency, Hz",
        "γ²",
    );
    for c in [&p.table, &p.motor] {
        gain = gain.with(Series::new(
            format!("{} ({})", c.name, c.unit),
            c.lines
                .iter()
                .map(|l| (l.frequency_hz, l.gain_db))
                .collect(),
            Style::Line,
        ));
        coherence = coherence.with(Series::new(
            c.name,
            c.lines
                .iter()
                .map(|l| (l.frequency_hz, l.coherence))
                .collect(),
            Style::Line,
        ));
    }
    let marks =
        |pick: fn(
            &Channel,
        )
            -> &[crate::experiments::frequency_response::periodic_evaluation::Mode]| {
            [&p.table, &p.motor]
                .into_iter()
                .flat_map(|c| pick(c).iter().map(|m| (m.extremum_hz, m.gain_db)))
                .collect::<Vec<_>>()
        };
    gain = gain
        .with(Series::new(
            "resonances",
            marks(|c| &c.resonances),
            Style::Markers,
        ))
        .with(Series::new(
            "antiresonances",
            marks(|c| &c.antiresonances),
            Style::Markers,
        ))
        .log_x();
    (gain, Some(coherence.log_x()))
}
