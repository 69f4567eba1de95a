//! Figures of an identification: each experiment's data against the model.

use super::figure::{Figure, Series, Style};
use crate::identify::intervals::profile::THRESHOLD;
use crate::identify::result::comparison::{Comparison, Role};
use crate::identify::result::profile::Profile;

/// The measured data as markers (frequency responses) or lines, the model at the
/// start dashed and at the identified values as a line; a frequency on a log axis,
/// the complex plane to equal scale. The title names the experiment's file, not its
/// folder.
pub fn comparison(c: &Comparison) -> Figure {
    let mut figure = Figure::new(
        format!("identification: {}", file_name(&c.source)),
        &c.x_label,
        &c.y_label,
    );
    if c.x_label.starts_with("frequency") {
        figure = figure.log_x();
    }
    if c.x_label == "real part" {
        figure = figure.to_equal_scale();
    }
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

/// The last component of a file's path (the path itself where it has none): a
/// title names the file, not where it lies on the machine that ran the command.
pub fn file_name(source: &str) -> String {
    std::path::Path::new(source)
        .file_name()
        .map_or_else(|| source.to_string(), |n| n.to_string_lossy().into_owned())
}

/// The statistic is drawn up to this multiple of the threshold: beyond, a leap
/// where the data stop being matched would flatten the part that matters.
const PLOT_CAP: f64 = 5.0;

/// A profile: the likelihood-ratio statistic against the held value (capped at
/// [`PLOT_CAP`] × the threshold), the fitted points as markers joined by a line,
/// the 95 % threshold dashed.
///
/// On a rough cost ([`Profile::surface`]) the line is the fitted bowl's profile and
/// the markers the evaluated design, whose scatter about it is the roughness.
pub fn profile(name: &str, p: &Profile) -> Figure {
    let cap = PLOT_CAP * THRESHOLD;
    let points: Vec<(f64, f64)> = p
        .points
        .iter()
        .zip(&p.statistic)
        .map(|(q, &s)| (q[0], s.min(cap)))
        .collect();
    if let Some(surface) = &p.surface {
        let curve: Vec<(f64, f64)> = surface
            .curve
            .iter()
            .map(|q| (q[0], q[1].min(cap)))
            .collect();
        // The design's points within the curve's span: the outer ones lie far above
        // the cap and would squeeze the bowl into the middle of the plot.
        let (lo, hi) = (
            curve.first().map_or(0.0, |q| q.0),
            curve.last().map_or(0.0, |q| q.0),
        );
        let points = points
            .into_iter()
            .filter(|q| lo <= q.0 && q.0 <= hi)
            .collect();
        return profile_figure(
            name,
            &curve,
            "bowl fitted to the rough cost",
            points,
            "evaluated points",
        );
    }
    profile_figure(name, &points.clone(), "profile", points, "re-fitted points")
}

fn profile_figure(
    name: &str,
    line: &[(f64, f64)],
    line_label: &str,
    points: Vec<(f64, f64)>,
    points_label: &str,
) -> Figure {
    let points_and_line = points.iter().chain(line);
    let (lo, hi) = points_and_line.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
        (a.min(q.0), b.max(q.0))
    });
    Figure::new(
        format!("profile likelihood of {name}"),
        &format!("{name} (held), SI"),
        "likelihood-ratio statistic (capped at 19.2)",
    )
    .with(Series::new(line_label, line.to_vec(), Style::Line))
    .with(Series::new(points_label, points, Style::Markers))
    .with(Series::new(
        "95 % level (χ²₁ = 3.84)",
        vec![(lo, THRESHOLD), (hi, THRESHOLD)],
        Style::Dashed,
    ))
}
