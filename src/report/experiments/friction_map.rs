//! Figures of the friction map: effort over speed in both directions with the fitted
//! laws drawn over it, and the selected law's residuals.

use crate::estimation::friction_law::LawFit;
use crate::experiments::friction_map::MapEvaluation;
use crate::model::Axis;
use crate::report::figure::{Figure, Series, Style};

/// Speeds in the field's unit: rpm on a rotary axis, mm/s on a linear one.
fn speed_unit(axis: Axis) -> (f64, &'static str) {
    match axis {
        Axis::Rotary => (60.0 / std::f64::consts::TAU, "motor speed, rpm"),
        Axis::Linear => (1e3, "speed, mm/s"),
    }
}

fn effort_label(axis: Axis) -> &'static str {
    match axis {
        Axis::Rotary => "motor torque, N·m",
        Axis::Linear => "force, N",
    }
}

/// The map: measured runs (markers) and each fitted law (the selected one solid, the
/// Coulomb law dashed), drawn per direction so that no line crosses zero speed.
pub fn map(e: &MapEvaluation, title: &str) -> Figure {
    let (to_unit, x_label) = speed_unit(e.axis);
    let measured = e
        .runs
        .iter()
        .map(|r| (r.speed * to_unit, r.effort))
        .collect();
    let mut figure = Figure::new(title, x_label, effort_label(e.axis)).with(Series::new(
        "runs (mean)",
        measured,
        Style::Markers,
    ));
    let selected = e.selected();
    let coulomb = coulomb(e).filter(|f| f.law != selected.law);
    for (fit, style) in [(Some(selected), Style::Line), (coulomb, Style::Dashed)] {
        if let Some(fit) = fit {
            for (direction, points) in curve(e, fit, to_unit) {
                let name = format!("{} law, {direction}", fit.law.name());
                figure = figure.with(Series::new(name, points, style));
            }
        }
    }
    figure
}

fn coulomb(e: &MapEvaluation) -> Option<&LawFit> {
    e.laws.fit(crate::estimation::friction_law::Law::Coulomb)
}

/// The law over each direction's measured speed range, 200 points spaced evenly in
/// the logarithm of the speed.
fn curve(e: &MapEvaluation, fit: &LawFit, to_unit: f64) -> Vec<(&'static str, Vec<(f64, f64)>)> {
    let values = fit.values();
    [(-1.0, "negative"), (1.0, "positive")]
        .iter()
        .filter_map(|&(sign, direction)| {
            let speeds: Vec<f64> = e
                .runs
                .iter()
                .map(|r| r.speed * sign)
                .filter(|v| *v > 0.0)
                .collect();
            let lo = speeds.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = speeds.iter().copied().fold(0.0, f64::max);
            (lo < hi).then(|| {
                let points = (0..200)
                    .map(|k| {
                        let v = sign * lo * (hi / lo).powf(k as f64 / 199.0);
                        (v * to_unit, fit.law.evaluate(&values, v))
                    })
                    .collect();
                (direction, points)
            })
        })
        .collect()
}

/// The selected law's residuals (measured − law) over speed.
pub fn residuals(e: &MapEvaluation, title: &str) -> Figure {
    let (to_unit, x_label) = speed_unit(e.axis);
    let points = e
        .runs
        .iter()
        .map(|r| (r.speed * to_unit, r.residual))
        .collect();
    let y = match e.axis {
        Axis::Rotary => "measured − law, N·m",
        Axis::Linear => "measured − law, N",
    };
    Figure::new(title, x_label, y).with(Series::new(
        format!("{} law", e.selected().law.name()),
        points,
        Style::Markers,
    ))
}
