//! Figures of an identification: each experiment's data against the model.

use super::figure::{Figure, Series, Style};
use crate::identify::comparison::{Comparison, Role};

/// The measured data as markers (frequency responses) or lines, the model at the
/// start dashed and at the identified values as a line.
pub fn comparison(c: &Comparison) -> Figure {
    let mut figure = Figure::new(
        format!("identification: {}", c.source),
        c.x_label,
        c.y_label,
    );
    let sampled = c.x_label.starts_with("frequency");
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
