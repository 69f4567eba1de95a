//! Figures of the rotational-fluctuation and unbalance tests (paper Figs. 11, 12, 14).

use crate::experiments::fluctuation::Evaluation;
use crate::io::experiment_file::Direction;
use crate::report::figure::{Figure, Series, Style};

/// Points per curve kept in the SVG.
const MAX_POINTS: usize = 4000;

/// The paper's Fig. 11 / Fig. 14: the deviation θt − θm·Rg·Rw over table angle, one
/// curve per direction.
pub fn deviation(e: &Evaluation, title: &str) -> Figure {
    let mut figure = Figure::new(title, "table angle, deg", "θt − θm·Rg·Rw, arc-sec");
    for p in &e.passes {
        let name = match p.direction {
            Direction::Up => "CCW (up)",
            Direction::Down => "CW (down)",
        };
        let points = p
            .angle_deg
            .iter()
            .copied()
            .zip(p.deviation_arcsec.iter().copied())
            .collect();
        figure = figure.with(Series::new(name, points, Style::Line).thinned(MAX_POINTS));
    }
    figure
}

/// The paper's Fig. 12: the power spectrum of the deviation up to `max_order` cycles
/// per revolution.
pub fn spectrum(e: &Evaluation, title: &str, max_order: f64) -> Figure {
    let points: Vec<(f64, f64)> = e
        .spectrum
        .order
        .iter()
        .zip(&e.spectrum.psd)
        .filter(|(o, _)| **o > 0.0 && **o <= max_order)
        .map(|(&o, &p)| (o, p))
        .collect();
    Figure::new(
        title,
        "cycles per revolution",
        "power spectral density, arc-sec² per cycle/rev",
    )
    .with(Series::new("mean of the directions", points, Style::Line))
}
