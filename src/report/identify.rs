//! Figures of an identification: each experiment's data against the model.

use super::figure::{Figure, Series, Style};
use crate::identify::intervals::profile::THRESHOLD;
use crate::identify::result::comparison::{Comparison, Role};
use crate::identify::result::profile::Profile;

/// The measured data as markers (frequency responses) or lines, the model at the
/// start dashed and at the identified values as a line.
pub fn comparison(c: &Comparison) -> Figure {
    let mut figure = Figure::new(
        format!("identification: {}", c.source),
        &c.x_label,
        &c.y_label,
    );
    // Measured lines (a frequency response, its Nyquist plot) are points, not a trace.
    let sampled = c.x_label.starts_with("frequency") || c.x_label == "real part";
    for curve in &c.curves {
        let style = match curve.role {
            Role::Measured if sampled => Style::Markers,
            Role::Measured => Style::Line,
            Role::Start => Style::Dashed,
            Role::Fitted if c.curves.iter().any(|k| k.role == Role::Start) => Style::Line,
            Role::Fitted => Style::Dashed,
        };
        figure = figure.with(Series::new(
            curve.label.clone(),
            curve.points.clone(),
            style,
        ));
    }
    figure
}

/// The statistic is drawn up to this multiple of the threshold: beyond, a leap
/// where the data stop being matched would flatten the part that matters.
const PLOT_CAP: f64 = 5.0;

/// A profile: the likelihood-ratio statistic against the held value (capped at
/// [`PLOT_CAP`] × the threshold), the fitted points as markers joined by a line,
/// the 95 % threshold dashed.
pub fn profile(name: &str, p: &Profile) -> Figure {
    let cap = PLOT_CAP * THRESHOLD;
    let points: Vec<(f64, f64)> = p
        .points
        .iter()
        .zip(&p.statistic)
        .map(|(q, &s)| (q[0], s.min(cap)))
        .collect();
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q.0), b.max(q.0))
        });
    Figure::new(
        format!("profile likelihood of {name}"),
        &format!("{name} (held), SI"),
        "likelihood-ratio statistic (capped at 19.2)",
    )
    .with(Series::new("profile", points.clone(), Style::Line))
    .with(Series::new("re-fitted points", points, Style::Markers))
    .with(Series::new(
        "95 % level (χ²₁ = 3.84)",
        vec![(lo, THRESHOLD), (hi, THRESHOLD)],
        Style::Dashed,
    ))
}
