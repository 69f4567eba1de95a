//! SVG line charts (plotters). One generic [`Figure`] serves every chart of the
//! tests, identifications and sweeps: a title, axis labels and named series of (x, y)
//! points, each drawn as a line, a dashed line or markers. The x axis is linear or
//! logarithmic (frequency), the axes optionally to equal scale (Nyquist), and a
//! second panel may sit under the first on the same x axis (Bode: gain over phase).
//! The legend is a strip under the plot with each series' own symbol. Rendered to a
//! string (for embedding in a page) or written to a file atomically.

mod axis;
mod legend;

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

pub use axis::label as tick_label;

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

/// How an axis is scaled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scale {
    #[default]
    Linear,
    /// Logarithmic (positive values only; the others are not drawn), ticks at the
    /// decades.
    Log,
}

/// A panel under the figure's first, on the same x axis: its y label and series.
#[derive(Clone, Debug)]
pub struct Panel {
    pub y_label: String,
    pub series: Vec<Series>,
}

/// A chart: its title, axis labels and series.
#[derive(Clone, Debug)]
pub struct Figure {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub x_scale: Scale,
    /// Values the x axis spans at least, drawn or not (a phase plot on its gain
    /// plot's frequency range).
    pub x_extent: Option<(f64, f64)>,
    /// One unit is as long on the y axis as on the x axis (a Nyquist plot: a mode's
    /// circle stays a circle). Applies to the first panel of a figure with one only.
    pub equal_axes: bool,
    /// A second panel under the first, sharing its x axis. A series there named
    /// like one above shares its colour and legend entry.
    pub lower: Option<Panel>,
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
            x_scale: Scale::Linear,
            x_extent: None,
            equal_axes: false,
            lower: None,
        }
    }

    /// Adds a series.
    pub fn with(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// The same figure on a logarithmic x axis.
    pub fn log_x(mut self) -> Self {
        self.x_scale = Scale::Log;
        self
    }

    /// The same figure with its x axis spanning at least `lo` to `hi`.
    pub fn spanning(mut self, lo: f64, hi: f64) -> Self {
        self.x_extent = Some((lo, hi));
        self
    }

    /// The same figure with its axes to equal scale.
    pub fn to_equal_scale(mut self) -> Self {
        self.equal_axes = true;
        self
    }

    /// This figure with `lower`'s series in a panel under it, on this figure's x
    /// axis (`lower`'s title, x label and scale are not used).
    pub fn above(mut self, lower: Figure) -> Self {
        self.lower = Some(Panel {
            y_label: lower.y_label,
            series: lower.series,
        });
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

    fn log(&self) -> bool {
        self.x_scale == Scale::Log
    }

    /// The panels' series, the first panel's first.
    fn panels(&self) -> Vec<&[Series]> {
        let mut panels = vec![self.series.as_slice()];
        panels.extend(self.lower.as_ref().map(|p| p.series.as_slice()));
        panels
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

/// Width of the document, px.
const WIDTH: u32 = 900;
/// Height of the title strip, px.
const TITLE: u32 = 40;
/// Height of a lone panel and of each of two, px.
const ONE_PANEL: u32 = 520;
const TWO_PANELS: u32 = 380;
/// Around the plot area, px: the margin, the y labels', the x labels' (the upper
/// of two panels has no x labels).
const MARGIN: u32 = 16;
const Y_LABELS: u32 = 70;
const X_LABELS: u32 = 44;
const NO_X_LABELS: u32 = 12;

/// Where the data go: each panel's x and y ranges (x in decades on a log axis) and
/// the plot area of the first, px.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Frame {
    pub x: Range<f64>,
    pub y: Vec<Range<f64>>,
    pub plot_px: (u32, u32),
}

/// The points of a series as drawn: finite, on a log axis positive and in decades.
fn drawn(points: &[(f64, f64)], log: bool) -> Vec<(f64, f64)> {
    points
        .iter()
        .filter(|(x, y)| x.is_finite() && y.is_finite() && (!log || *x > 0.0))
        .map(|&(x, y)| (if log { x.log10() } else { x }, y))
        .collect()
}

/// The frame of `figure`: the data's padded ranges, made equal in scale if asked.
pub(crate) fn frame(figure: &Figure) -> Result<Frame, FigureError> {
    let log = figure.log();
    let empty = || FigureError::Empty {
        title: figure.title.clone(),
    };
    let panels: Vec<Vec<(f64, f64)>> = figure
        .panels()
        .iter()
        .map(|s| s.iter().flat_map(|s| drawn(&s.points, log)).collect())
        .collect();
    let extent = drawn(
        &figure
            .x_extent
            .map_or(vec![], |(a, b)| vec![(a, 0.0), (b, 0.0)]),
        log,
    );
    let x = axis::span(panels.iter().flatten().chain(&extent).map(|p| p.0)).ok_or_else(empty)?;
    let x = if log {
        axis::padded_log(x)
    } else {
        axis::padded(x)
    };
    let mut y = Vec::new();
    for points in &panels {
        y.push(axis::padded(
            axis::span(points.iter().map(|p| p.1)).ok_or_else(empty)?,
        ));
    }
    let height = if panels.len() > 1 {
        TWO_PANELS
    } else {
        ONE_PANEL
    };
    let x_labels = if panels.len() > 1 {
        NO_X_LABELS
    } else {
        X_LABELS
    };
    let plot_px = (
        WIDTH - 2 * MARGIN - Y_LABELS,
        height - 2 * MARGIN - x_labels,
    );
    let mut frame = Frame { x, y, plot_px };
    if figure.equal_axes && panels.len() == 1 {
        equalise(&mut frame);
    }
    for (axis, r) in std::iter::once(("x", &frame.x)).chain(frame.y.iter().map(|r| ("y", r))) {
        // The axis' tick search never ends on a span that overflows.
        if !(r.end - r.start).is_finite() {
            return Err(FigureError::Range {
                title: figure.title.clone(),
                axis,
                lo: r.start,
                hi: r.end,
            });
        }
    }
    Ok(frame)
}

/// Widens the x or the y range of the first panel about its middle until a unit
/// takes as many pixels on both.
fn equalise(frame: &mut Frame) {
    let (w, h) = (f64::from(frame.plot_px.0), f64::from(frame.plot_px.1));
    let y = &mut frame.y[0];
    let per_px = ((frame.x.end - frame.x.start) / w).max((y.end - y.start) / h);
    let widen = |r: &mut Range<f64>, px: f64| {
        let mid = 0.5 * (r.start + r.end);
        *r = (mid - 0.5 * per_px * px)..(mid + 0.5 * per_px * px);
    };
    widen(&mut frame.x, w);
    widen(y, h);
}

/// Each panel's series' colours and the legend's entries: a named series takes the
/// next colour and an entry, or those of the series of its name drawn before; one
/// without a name continues the previous series.
fn colours(panels: &[&[Series]]) -> (Vec<Vec<RGBColor>>, Vec<legend::Entry>) {
    let mut entries: Vec<legend::Entry> = Vec::new();
    // The entry of the series drawn last.
    let mut current: Option<usize> = None;
    let mut colour_of = |s: &Series| {
        if s.name.is_empty() {
            let e = current.and_then(|k| entries.get_mut(k));
            return e.map_or(COLOURS[0], |e| {
                e.marked |= s.style == Style::Markers;
                e.colour
            });
        }
        let k = match entries.iter().position(|e| e.name == s.name) {
            Some(k) => k,
            None => {
                entries.push(legend::Entry {
                    name: s.name.clone(),
                    style: s.style,
                    marked: false,
                    colour: COLOURS[entries.len() % COLOURS.len()],
                });
                entries.len() - 1
            }
        };
        current = Some(k);
        entries[k].colour
    };
    let per_panel = panels
        .iter()
        .map(|series| series.iter().map(&mut colour_of).collect())
        .collect();
    (per_panel, entries)
}

/// Renders a figure into an SVG document.
fn render(figure: &Figure) -> Result<String, FigureError> {
    let frame = frame(figure)?;
    let text = |e: &dyn std::fmt::Display| FigureError::Draw {
        title: figure.title.clone(),
        message: e.to_string(),
    };
    let panels = figure.panels();
    let (colours, entries) = colours(&panels);
    let legend_px = legend::height(&entries);
    let panel_px = if panels.len() > 1 {
        TWO_PANELS
    } else {
        ONE_PANEL
    };
    let height = TITLE + panel_px * panels.len() as u32 + legend_px;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| text(&e))?;
        let (title, rest) = root.split_vertically(TITLE);
        let style = ("sans-serif", 22)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Center));
        let centre = ((WIDTH / 2) as i32, (TITLE / 2) as i32 + 4);
        title
            .draw(&Text::new(figure.title.as_str(), centre, style))
            .map_err(|e| text(&e))?;
        let (charts, strip) = rest.split_vertically(panel_px * panels.len() as u32);
        let areas = charts.split_evenly((panels.len(), 1));
        let y_labels = [figure.y_label.as_str()]
            .into_iter()
            .chain(figure.lower.as_ref().map(|p| p.y_label.as_str()));
        for (k, ((area, series), y_label)) in areas.iter().zip(&panels).zip(y_labels).enumerate() {
            let last = k + 1 == panels.len();
            let spec = PanelSpec {
                log: figure.log(),
                x: &frame.x,
                y: &frame.y[k],
                x_label: last.then_some(figure.x_label.as_str()),
                y_label,
                series,
                colours: &colours[k],
            };
            draw_panel(area, &spec).map_err(|e| text(&e))?;
        }
        legend::draw(&strip, &entries).map_err(|e| text(&e))?;
        root.present().map_err(|e| text(&e))?;
    }
    Ok(svg)
}

/// What one panel draws.
struct PanelSpec<'a> {
    log: bool,
    x: &'a Range<f64>,
    y: &'a Range<f64>,
    /// The x axis' label, `None` for a panel with another under it (no x labels).
    x_label: Option<&'a str>,
    y_label: &'a str,
    series: &'a [Series],
    colours: &'a [RGBColor],
}

type DrawResult = Result<(), DrawingAreaErrorKind<std::io::Error>>;

/// Draws one panel: its mesh with the ticks' labels, and its series.
fn draw_panel(area: &DrawingArea<SVGBackend<'_>, Shift>, p: &PanelSpec) -> DrawResult {
    let (x_ticks, x_grid) = if p.log {
        axis::log_ticks(p.x)
    } else {
        (axis::linear_ticks(p.x), Vec::new())
    };
    let log = p.log;
    let x_format = move |v: &f64| axis::label(if log { 10f64.powf(*v) } else { *v });
    let no_label = |_: &f64| String::new();
    let mut c = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(if p.x_label.is_some() {
            X_LABELS
        } else {
            NO_X_LABELS
        })
        .y_label_area_size(Y_LABELS)
        .build_cartesian_2d(
            axis::Ticked {
                range: p.x.clone(),
                ticks: x_ticks,
                grid: x_grid,
            },
            axis::Ticked {
                range: p.y.clone(),
                ticks: axis::linear_ticks(p.y),
                grid: Vec::new(),
            },
        )?;
    let mut mesh = c.configure_mesh();
    mesh.y_desc(p.y_label)
        .y_label_formatter(&|v| axis::label(*v))
        .light_line_style(RGBColor(235, 235, 235));
    match p.x_label {
        Some(label) => mesh.x_desc(label).x_label_formatter(&x_format),
        None => mesh.x_label_formatter(&no_label),
    };
    mesh.draw()?;
    for (s, &colour) in p.series.iter().zip(p.colours) {
        let pts = drawn(&s.points, p.log);
        match s.style {
            Style::Line => c.draw_series(LineSeries::new(pts, colour.stroke_width(2))),
            Style::Dashed => {
                c.draw_series(DashedLineSeries::new(pts, 6, 4, colour.stroke_width(1)))
            }
            Style::Markers => {
                c.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, colour.filled())))
            }
        }?;
    }
    Ok(())
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

    /// Whether `svg` has a text element reading exactly `s`.
    fn has_text(svg: &str, s: &str) -> bool {
        svg.contains(&format!(">\n{s}\n</text>"))
    }

    fn bode() -> Figure {
        let f: Vec<f64> = (0..200)
            .map(|k| 10f64.powf(0.5 + 2.5 * k as f64 / 199.0))
            .collect();
        let gain = f.iter().map(|&f| (f, -20.0 * f.log10())).collect();
        let phase = f.iter().map(|&f| (f, -90.0 - f / 10.0)).collect();
        Figure::new("loop", "frequency, Hz", "gain, dB")
            .with(Series::new("L", gain, Style::Line))
            .log_x()
            .above(Figure::new("", "", "phase, deg").with(Series::new("L", phase, Style::Line)))
    }

    #[test]
    fn a_log_axis_labels_its_decades_without_decimals() {
        let svg = bode().render().unwrap();
        for decade in ["10", "100", "1000"] {
            assert!(has_text(&svg, decade), "{decade}");
        }
        assert!(!has_text(&svg, "100.0") && !has_text(&svg, "10.0"));
        // Both panels: the gain's and the phase's y labels; one legend entry for L.
        assert!(svg.contains("gain, dB") && svg.contains("phase, deg"));
        assert_eq!(svg.matches(">\nL\n<").count(), 1);
    }

    #[test]
    fn an_extent_widens_the_x_axis() {
        let f = Figure::new("t", "f", "y")
            .with(Series::new(
                "s",
                vec![(10.0, 0.0), (20.0, 1.0)],
                Style::Line,
            ))
            .log_x();
        let narrow = frame(&f).unwrap().x;
        let wide = frame(&f.spanning(1.0, 1000.0)).unwrap().x;
        assert!(
            narrow.start > 0.9 && wide.start < 0.0 && wide.end > 3.0,
            "{wide:?}"
        );
    }

    #[test]
    fn linear_ticks_print_without_a_trailing_zero() {
        let svg = Figure::new("t", "x", "y")
            .with(Series::new(
                "s",
                vec![(0.0, 0.0), (450.0, 0.5)],
                Style::Line,
            ))
            .render()
            .unwrap();
        assert!(has_text(&svg, "400") && has_text(&svg, "0.5"), "{svg}");
        assert!(!has_text(&svg, "400.0"));
    }

    #[test]
    fn equal_axes_give_a_unit_the_same_pixels_on_both() {
        let circle: Vec<(f64, f64)> = (0..100)
            .map(|k| {
                let a = k as f64 / 99.0 * std::f64::consts::TAU;
                (3.0 + a.cos(), 0.01 * a.sin())
            })
            .collect();
        let figure = Figure::new("n", "Re", "Im").with(Series::new("H", circle, Style::Line));
        let unequal = frame(&figure).unwrap();
        let f = frame(&figure.to_equal_scale()).unwrap();
        let per_px = |r: &Range<f64>, px: u32| (r.end - r.start) / f64::from(px);
        let (x, y) = (per_px(&f.x, f.plot_px.0), per_px(&f.y[0], f.plot_px.1));
        assert!((x / y - 1.0).abs() < 1e-12, "{x} vs {y}");
        assert!(
            (per_px(&unequal.y[0], f.plot_px.1) / y) < 0.1,
            "the y range widened"
        );
    }

    #[test]
    fn a_legend_shows_each_series_symbol_outside_the_plot() {
        let markers = Figure::new("t", "x", "y")
            .with(Series::new(
                "measured",
                vec![(0.0, 1.0), (1.0, 2.0)],
                Style::Markers,
            ))
            .render()
            .unwrap();
        // Two data points and one legend marker; no line of the series' colour.
        assert_eq!(markers.matches("<circle").count(), 3, "{markers}");
        assert!(!markers.contains("polyline fill=\"none\" opacity=\"1\" stroke=\"#1F77B4\""));
        // A line continued by its markers: both in the legend.
        let both = Figure::new("t", "x", "y")
            .with(Series::new("H", vec![(0.0, 1.0), (1.0, 2.0)], Style::Line))
            .with(Series::new(
                "",
                vec![(0.0, 1.0), (1.0, 2.0)],
                Style::Markers,
            ))
            .render()
            .unwrap();
        assert_eq!(both.matches("<circle").count(), 3, "{both}");
        let dashed = Figure::new("t", "x", "y")
            .with(Series::new(
                "model",
                vec![(0.0, 1.0), (1.0, 2.0)],
                Style::Dashed,
            ))
            .render()
            .unwrap();
        assert!(!dashed.contains("<circle"));
        // The legend strip lies below the plot area (the document is taller than a
        // figure without a legend would be).
        let height = TITLE + ONE_PANEL;
        assert!(
            dashed.contains(&format!("height=\"{}\"", height + 30)),
            "{dashed}"
        );
    }
}
