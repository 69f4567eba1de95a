//! SVG line charts (plotters), written atomically. One generic chart serves every
//! figure: a set of named series of (x, y) points, each drawn as a line, a dashed
//! line or markers.

use std::path::Path;

use plotters::prelude::*;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    Line,
    Dashed,
    Markers,
}

/// One named series.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub style: Style,
}

impl Series {
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Self {
        Series {
            name: name.into(),
            points,
            style,
        }
    }
}

/// Axis titles and the chart title.
#[derive(Clone, Debug)]
pub struct Chart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// Renders `series` into an SVG document.
pub fn render(chart: &Chart, series: &[Series]) -> Result<String, String> {
    let finite = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in finite {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if x0 > x1 {
        return Err("nothing to plot: no finite points".into());
    }
    let pad = |a: f64, b: f64| {
        let m = if b > a {
            0.05 * (b - a)
        } else {
            a.abs().max(1.0) * 0.05
        };
        (a - m, b + m)
    };
    let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(text)?;
        let mut c = ChartBuilder::on(&root)
            .caption(chart.title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(text)?;
        c.configure_mesh()
            .x_desc(chart.x_label)
            .y_desc(chart.y_label)
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(text)?;
        // A series without a name continues the previous one (same colour, no legend).
        let mut colour_index = 0;
        for (i, s) in series.iter().enumerate() {
            if i > 0 && !s.name.is_empty() {
                colour_index += 1;
            }
            let colour = COLOURS[colour_index % COLOURS.len()];
            let pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
            let anno = match s.style {
                Style::Line => c.draw_series(LineSeries::new(pts, colour.stroke_width(2))),
                Style::Dashed => {
                    c.draw_series(DashedLineSeries::new(pts, 6, 4, colour.stroke_width(1)))
                }
                Style::Markers => {
                    c.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, colour.filled())))
                }
            }
            .map_err(text)?;
            if !s.name.is_empty() {
                anno.label(s.name.as_str()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                });
            }
        }
        c.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(text)?;
        root.present().map_err(text)?;
    }
    Ok(svg)
}

fn text<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// Renders and writes an SVG chart atomically.
pub fn write(path: &Path, chart: &Chart, series: &[Series]) -> std::io::Result<()> {
    let svg = render(chart, series).map_err(std::io::Error::other)?;
    crate::io::atomic::write(path, svg.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_every_series_with_its_legend() {
        let svg = render(
            &Chart {
                title: "t",
                x_label: "angle deg",
                y_label: "deviation arc-sec",
            },
            &[
                Series::new("up", vec![(0.0, 1.0), (30.0, 2.0)], Style::Line),
                Series::new("down", vec![(0.0, -1.0), (30.0, f64::NAN)], Style::Dashed),
                Series::new("runs", vec![(0.0, 0.5)], Style::Markers),
            ],
        )
        .unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("up") && svg.contains("down"));
        assert!(svg.contains("deviation arc-sec"));
    }

    #[test]
    fn an_empty_chart_is_an_error_not_a_panic() {
        let chart = Chart {
            title: "",
            x_label: "",
            y_label: "",
        };
        assert!(render(
            &chart,
            &[Series::new("x", vec![(f64::NAN, 1.0)], Style::Line)]
        )
        .is_err());
    }
}
