//! SVG line charts (plotters). One generic [`Figure`] serves every chart of the
//! tests, identifications and sweeps: a title, axis labels and named series of (x, y)
//! points, each drawn as a line, a dashed line or markers. Rendered to a string (for
//! embedding in a page) or written to a file atomically.

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

    /// The series with at most `max` of its points, evenly picked (SVG size).
    pub fn thinned(mut self, max: usize) -> Self {
        let every = self.points.len().div_ceil(max.max(1)).max(1);
        self.points = self.points.into_iter().step_by(every).collect();
        self
    }
}

/// A chart: its title, axis labels and series.
#[derive(Clone, Debug)]
pub struct Figure {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
}

/// Why a figure could not be drawn or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FigureError {
    #[error("{title}: nothing to plot (no finite points)")]
    Empty { title: String },
    #[error("{title}: the {axis} values span {lo:e} … {hi:e}, beyond what an axis can scale")]
    Range {
        title: String,
        axis: &'static str,
        lo: f64,
        hi: f64,
    },
    #[error("{title}: drawing failed: {message}")]
    Draw { title: String, message: String },
    #[error("cannot write {path}: {source}")]
    Write {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
}

impl Figure {
    /// A figure with no series yet.
    pub fn new(title: impl Into<String>, x_label: &str, y_label: &str) -> Self {
        Figure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
        }
    }

    /// Adds a series.
    pub fn with(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// The SVG document.
    pub fn render(&self) -> Result<String, FigureError> {
        render(self)
    }

    /// Renders and writes the SVG atomically.
    pub fn write(&self, path: &Path) -> Result<(), FigureError> {
        let svg = self.render()?;
        crate::io::atomic::write(path, svg.as_bytes()).map_err(|source| FigureError::Write {
            path: path.to_path_buf(),
            source,
        })
    }
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// Renders a figure into an SVG document.
fn render(figure: &Figure) -> Result<String, FigureError> {
    let series = &figure.series;
    let text = |e: &dyn std::fmt::Display| FigureError::Draw {
        title: figure.title.clone(),
        message: e.to_string(),
    };
    let finite = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in finite {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if x0 > x1 {
        return Err(FigureError::Empty {
            title: figure.title.clone(),
        });
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
    for (axis, lo, hi) in [("x", x0, x1), ("y", y0, y1)] {
        // The axis' tick search never ends on a span that overflows.
        if !(hi - lo).is_finite() {
            return Err(FigureError::Range {
                title: figure.title.clone(),
                axis,
                lo,
                hi,
            });
        }
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| text(&e))?;
        let mut c = ChartBuilder::on(&root)
            .caption(figure.title.as_str(), ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| text(&e))?;
        c.configure_mesh()
            .x_desc(figure.x_label.as_str())
            .y_desc(figure.y_label.as_str())
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| text(&e))?;
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
            .map_err(|e| text(&e))?;
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
            .map_err(|e| text(&e))?;
        root.present().map_err(|e| text(&e))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_every_series_with_its_legend() {
        let svg = Figure::new("t", "angle deg", "deviation arc-sec")
            .with(Series::new(
                "up",
                vec![(0.0, 1.0), (30.0, 2.0)],
                Style::Line,
            ))
            .with(Series::new(
                "down",
                vec![(0.0, -1.0), (30.0, f64::NAN)],
                Style::Dashed,
            ))
            .with(Series::new("runs", vec![(0.0, 0.5)], Style::Markers))
            .render()
            .unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("up") && svg.contains("down"));
        assert!(svg.contains("deviation arc-sec"));
    }

    #[test]
    fn an_empty_chart_is_an_error_not_a_panic() {
        let figure =
            Figure::new("", "", "").with(Series::new("x", vec![(f64::NAN, 1.0)], Style::Line));
        assert!(matches!(figure.render(), Err(FigureError::Empty { .. })));
    }

    #[test]
    fn a_span_that_overflows_is_an_error_not_a_hang() {
        let points = vec![(0.0, -1e308), (1.0, 1e308)];
        let figure = Figure::new("t", "", "").with(Series::new("x", points, Style::Line));
        let e = figure.render().unwrap_err();
        assert!(matches!(e, FigureError::Range { axis: "y", .. }), "{e}");
    }
}
