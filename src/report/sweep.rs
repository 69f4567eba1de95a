//! Sweep figures (SVG, plotters): a tornado chart of each output's sensitivities, and
//! for a grid the output over one factor (a line [`Figure`]) or over two (a heat map).
//! Each is returned as (output column, SVG document); the caller decides where it goes.

use std::collections::BTreeMap;

use ndarray::{ArrayView1, ArrayView2};
use plotters::prelude::*;

use super::figure::{tick_label, Figure, FigureError, Series, Style};
use crate::sweep::analysis::Indices;
use crate::sweep::spec::{Factor, Scale};

const BAR: RGBColor = RGBColor(31, 119, 180);
const SECOND: RGBColor = RGBColor(255, 127, 14);

/// A drawing error of the chart titled `title`.
fn drawing(title: &str) -> impl Fn(&dyn std::fmt::Display) -> FigureError + '_ {
    move |e| FigureError::Draw {
        title: title.to_string(),
        message: e.to_string(),
    }
}

/// One bar of a tornado chart: a label, the main value, an optional second value
/// (Sobol S1 beside ST) and an optional interval of the main value.
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    pub label: String,
    pub value: f64,
    pub second: Option<f64>,
    pub interval: Option<(f64, f64)>,
}

/// Renders a tornado chart: horizontal bars, the largest |value| on top.
pub fn tornado_svg(
    title: &str,
    x_label: &str,
    legend: (&str, Option<&str>),
    bars: &[Bar],
) -> Result<String, FigureError> {
    let text = drawing(title);
    let mut bars: Vec<&Bar> = bars.iter().filter(|b| b.value.is_finite()).collect();
    if bars.is_empty() {
        return Err(FigureError::Empty {
            title: title.to_string(),
        });
    }
    bars.sort_by(|a, b| a.value.abs().total_cmp(&b.value.abs()));
    let n = bars.len();
    let (lo, hi) = extent(&bars);
    let pad = 0.08 * (hi - lo).max(1e-12);
    let mut svg = String::new();
    {
        let height = 140 + 44 * n as u32;
        let root = SVGBackend::with_string(&mut svg, (900, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| text(&e))?;
        let labels: Vec<String> = bars.iter().map(|b| b.label.clone()).collect();
        let mut c = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(120)
            .build_cartesian_2d((lo - pad)..(hi + pad), -0.5..(n as f64 - 0.5))
            .map_err(|e| text(&e))?;
        c.configure_mesh()
            .x_desc(x_label)
            .x_label_formatter(&|v: &f64| tick_label(*v))
            .y_labels(n)
            .y_label_formatter(&|y: &f64| {
                let i = y.round();
                if (y - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < labels.len() {
                    labels[i as usize].clone()
                } else {
                    String::new()
                }
            })
            .disable_y_mesh()
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| text(&e))?;
        draw_bars(&mut c, &bars, legend).map_err(|e| text(&e))?;
        c.draw_series(std::iter::once(PathElement::new(
            vec![(0.0, -0.5), (0.0, n as f64 - 0.5)],
            BLACK.stroke_width(1),
        )))
        .map_err(|e| text(&e))?;
        c.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| text(&e))?;
        root.present().map_err(|e| text(&e))?;
    }
    Ok(svg)
}

/// The range of every value, second value and interval end of `bars`, 0 included.
fn extent(bars: &[&Bar]) -> (f64, f64) {
    bars.iter()
        .flat_map(|b| {
            [
                Some(b.value),
                b.second,
                b.interval.map(|i| i.0),
                b.interval.map(|i| i.1),
            ]
        })
        .flatten()
        .filter(|v| v.is_finite())
        .fold((0.0f64, 0.0f64), |(l, h), v| (l.min(v), h.max(v)))
}

type Tornado<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// The bars, the second values beside them (when any) and the intervals, with legends.
fn draw_bars(
    c: &mut Tornado<'_, '_>,
    bars: &[&Bar],
    legend: (&str, Option<&str>),
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let has_second = bars.iter().any(|b| b.second.is_some());
    let (h_main, h_second) = if has_second { (0.38, 0.2) } else { (0.35, 0.0) };
    c.draw_series(bars.iter().enumerate().map(|(i, b)| {
        let y = i as f64;
        Rectangle::new(
            [(0.0, y - h_main), (b.value, y + h_main)],
            BAR.mix(0.8).filled(),
        )
    }))?
    .label(legend.0)
    .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 18, y + 5)], BAR.filled()));
    if has_second {
        c.draw_series(bars.iter().enumerate().filter_map(|(i, b)| {
            let y = i as f64;
            b.second
                .map(|s| Rectangle::new([(0.0, y - h_second), (s, y + h_second)], SECOND.filled()))
        }))?
        .label(legend.1.unwrap_or(""))
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 18, y + 5)], SECOND.filled()));
    }
    c.draw_series(bars.iter().enumerate().filter_map(|(i, b)| {
        let y = i as f64;
        b.interval
            .map(|(l, h)| PathElement::new(vec![(l, y), (h, y)], BLACK.stroke_width(2)))
    }))?;
    Ok(())
}

/// Tornado charts of every output column of `indices`: (column, SVG).
pub fn tornadoes(indices: &Indices) -> Result<Vec<(String, String)>, FigureError> {
    let Some(main) = indices.main_column() else {
        return Ok(Vec::new());
    };
    let mut by_output: BTreeMap<&str, Vec<Bar>> = BTreeMap::new();
    let mut order = Vec::new();
    for r in &indices.rows {
        if !by_output.contains_key(r.output.as_str()) {
            order.push(r.output.as_str());
        }
        let v = |i: usize| r.values.get(i).copied().flatten();
        let bar = match indices.method {
            "sobol" => Bar {
                label: r.parameter.clone(),
                value: v(3).unwrap_or(f64::NAN),
                second: v(0),
                interval: v(4).zip(v(5)),
            },
            _ => Bar {
                label: r.parameter.clone(),
                value: v(main).unwrap_or(f64::NAN),
                second: None,
                interval: None,
            },
        };
        by_output.entry(r.output.as_str()).or_default().push(bar);
    }
    let (x_label, legend) = match indices.method {
        "local" => (
            "normalised sensitivity ∂ln y / ∂ln p",
            ("∂ln y/∂ln p", None),
        ),
        "morris" => ("Morris μ* (output units per full range)", ("μ*", None)),
        _ => (
            "Sobol index (bars: ST with 95 % interval, S1)",
            ("ST", Some("S1")),
        ),
    };
    let mut charts = Vec::new();
    for output in order {
        let bars = &by_output[output];
        if bars.iter().all(|b| !b.value.is_finite()) {
            continue;
        }
        let title = format!("{output}: {} sensitivities", indices.method);
        charts.push((
            output.to_string(),
            tornado_svg(&title, x_label, legend, bars)?,
        ));
    }
    Ok(charts)
}

/// A factor's axis coordinate and label: the value, or its log10 for a log range.
fn axis(f: &Factor, v: f64) -> f64 {
    match f.scale {
        Scale::Lin => v,
        Scale::Log => v.log10(),
    }
}

fn axis_label(f: &Factor) -> String {
    let unit = crate::model::spec(&f.name).map_or("", |s| s.unit);
    match f.scale {
        Scale::Lin => format!("{} ({unit})", f.name),
        Scale::Log => format!("log10 {} ({unit})", f.name),
    }
}

/// Plots of a grid: each output column over the factor (one factor: a line per
/// output column) or over the two factors (a heat map per column); none for more
/// factors. Row `i` of `values` holds the factor values of design point `i`, row `i`
/// of `y` its outputs (columns `names`; NaN: missing). Returns (column, SVG).
pub fn grid_plots(
    factors: &[Factor],
    values: ArrayView2<f64>,
    names: &[String],
    y: ArrayView2<f64>,
) -> Result<Vec<(String, String)>, FigureError> {
    let mut charts = Vec::new();
    for (name, col) in names.iter().zip(y.columns()) {
        if col.iter().all(|v| !v.is_finite()) {
            continue;
        }
        let svg = match factors.len() {
            1 => {
                let pts = values
                    .rows()
                    .into_iter()
                    .zip(col)
                    .map(|(v, &c)| (axis(&factors[0], v[0]), c))
                    .collect();
                Figure::new(name.as_str(), &axis_label(&factors[0]), name)
                    .with(Series::new(name.clone(), pts, Style::Line))
                    .render()?
            }
            2 => heat_map(name, factors, values, col)?,
            _ => break,
        };
        charts.push((name.clone(), svg));
    }
    Ok(charts)
}

/// A colour from blue (0) through green to yellow (1), after viridis.
fn colour(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = t.clamp(0.0, 1.0) * 4.0;
    let i = (t.floor() as usize).min(3);
    let f = t - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |x: f64, y: f64| (x + f * (y - x)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// A heat map of `col` over a two-factor grid, with a colour bar.
fn heat_map(
    name: &str,
    factors: &[Factor],
    values: ArrayView2<f64>,
    col: ArrayView1<f64>,
) -> Result<String, FigureError> {
    let text = drawing(name);
    let (fx, fy) = (&factors[0], &factors[1]);
    let cell = |f: &Factor| {
        let (a, b) = (axis(f, f.low), axis(f, f.high));
        (b - a) / (f.levels - 1) as f64
    };
    let (dx, dy) = (cell(fx), cell(fy));
    let (x0, x1) = (axis(fx, fx.low) - dx / 2.0, axis(fx, fx.high) + dx / 2.0);
    let (y0, y1) = (axis(fy, fy.low) - dy / 2.0, axis(fy, fy.high) + dy / 2.0);
    let finite = col.iter().copied().filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
    let span = if hi > lo { hi - lo } else { 1.0 };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 640)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| text(&e))?;
        let (main, bar) = root.split_horizontally(780);
        let mut c = ChartBuilder::on(&main)
            .caption(name, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| text(&e))?;
        c.configure_mesh()
            .x_desc(axis_label(fx))
            .y_desc(axis_label(fy))
            .x_label_formatter(&|v: &f64| tick_label(*v))
            .y_label_formatter(&|v: &f64| tick_label(*v))
            .disable_mesh()
            .draw()
            .map_err(|e| text(&e))?;
        c.draw_series(values.rows().into_iter().zip(col).map(|(v, &z)| {
            let (x, y) = (axis(fx, v[0]), axis(fy, v[1]));
            let fill = if z.is_finite() {
                colour((z - lo) / span).filled()
            } else {
                RGBColor(200, 200, 200).filled()
            };
            Rectangle::new(
                [(x - dx / 2.0, y - dy / 2.0), (x + dx / 2.0, y + dy / 2.0)],
                fill,
            )
        }))
        .map_err(|e| text(&e))?;
        let mut b = ChartBuilder::on(&bar)
            .margin_top(60)
            .margin_bottom(60)
            .margin_right(10)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..1.0, lo..(lo + span))
            .map_err(|e| text(&e))?;
        // Enough decimals to tell the colour bar's ticks apart.
        let decimals = (2.0 - span.log10().floor()).clamp(0.0, 12.0) as usize;
        b.configure_mesh()
            .disable_x_axis()
            .disable_mesh()
            .y_labels(8)
            .y_label_style(("sans-serif", 14))
            .y_label_formatter(&|v: &f64| format!("{v:.decimals$}"))
            .draw()
            .map_err(|e| text(&e))?;
        b.draw_series((0..100).map(|i| {
            let (t0, t1) = (i as f64 / 100.0, (i + 1) as f64 / 100.0);
            Rectangle::new(
                [(0.0, lo + t0 * span), (1.0, lo + t1 * span)],
                colour(t0 + 0.005).filled(),
            )
        }))
        .map_err(|e| text(&e))?;
        root.present().map_err(|e| text(&e))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tornado_lists_every_parameter() {
        let bars = vec![
            Bar {
                label: "Kw".into(),
                value: 0.8,
                second: Some(0.7),
                interval: Some((0.75, 0.85)),
            },
            Bar {
                label: "Jt".into(),
                value: -0.3,
                second: None,
                interval: None,
            },
        ];
        let svg = tornado_svg("t", "x", ("ST", Some("S1")), &bars).unwrap();
        assert!(svg.contains("Kw") && svg.contains("Jt") && svg.contains("S1"));
    }
}
