//! The section of a sweep file (`rtid sweep --out`): the design, the indices table
//! and the charts. The indices come from `sweep::analysis` and the charts from
//! `report::sweep`, exactly as `rtid sweep` computes and draws them.

use std::path::Path;

use super::markup::{escape, facts, svg_block, table};
use super::{HtmlError, Kind, Section};
use crate::sweep::analysis::{self, Indices};
use crate::sweep::{self, Method, Scale, Sweep};

const WHAT: &str = "sweep file (`rtid sweep --out`)";

/// The section of the finished sweep file `path`.
pub fn section(path: &Path) -> Result<Section, HtmlError> {
    let bad = |message: String| HtmlError::Malformed {
        path: path.to_path_buf(),
        what: WHAT,
        message,
    };
    let (sweep, rows) =
        sweep::load_complete(&[path.to_path_buf()]).map_err(|e| bad(e.to_string()))?;
    let indices = analysis::analyse(&sweep, &rows).map_err(|e| bad(e.to_string()))?;
    let charts = if sweep.method == Method::Grid {
        let design = sweep.design().map_err(|e| bad(e.to_string()))?;
        let y = sweep::output_matrix(&sweep, &rows);
        crate::report::sweep::grid_plots(
            &sweep.factors,
            design.values.view(),
            &sweep.output_columns(),
            y.view(),
        )
    } else {
        crate::report::sweep::tornadoes(&indices)
    }
    .map_err(|e| bad(e.to_string()))?;
    let mut body = design(&sweep, rows.len());
    body.push_str(&indices_table(&indices));
    for (_, svg) in &charts {
        body.push_str(&svg_block(svg));
    }
    Ok(Section {
        kind: Kind::Sweep,
        file: path.to_path_buf(),
        title: format!("Sweep: {} method", sweep.method.name()),
        body,
    })
}

/// The design's settings in words.
fn settings(m: &Method) -> String {
    match m {
        Method::Grid => "every combination of the factors' levels".into(),
        Method::Local { step } => format!("one at a time at the base point, relative step {step}"),
        Method::Morris {
            trajectories,
            levels,
        } => format!("{trajectories} trajectories over {levels} levels"),
        Method::Sobol { samples, bootstrap } => {
            format!("base sample {samples}, {bootstrap} bootstrap resamples for the 95 % intervals")
        }
    }
}

/// Method, outputs and the factors' ranges.
fn design(s: &Sweep, points: usize) -> String {
    let outputs: Vec<&str> = s.outputs.iter().map(|o| o.name()).collect();
    let mut html = facts(&[
        (
            "method",
            format!("{} — {}", s.method.name(), settings(&s.method)),
        ),
        ("points", points.to_string()),
        ("outputs", outputs.join(", ")),
        ("seed", s.seed.to_string()),
        ("mechanism", s.params.name.clone()),
    ]);
    let rows: Vec<Vec<String>> = s
        .factors
        .iter()
        .map(|f| {
            let scale = match f.scale {
                Scale::Lin => "linear",
                Scale::Log => "log",
            };
            vec![
                f.name.clone(),
                format!("{:.4e}", f.low),
                format!("{:.4e}", f.high),
                scale.to_string(),
            ]
        })
        .collect();
    html.push_str("<h3>Factors</h3>\n");
    html.push_str(&table(&["parameter", "low", "high", "scale"], &rows));
    html
}

/// One row per (output, factor) with the method's index columns.
fn indices_table(ix: &Indices) -> String {
    if ix.rows.is_empty() && ix.notes.is_empty() {
        return String::new();
    }
    let mut header = vec!["output", "parameter"];
    header.extend(ix.columns.iter().copied());
    let rows: Vec<Vec<String>> = ix
        .rows
        .iter()
        .map(|r| {
            let mut row = vec![r.output.clone(), r.parameter.clone()];
            row.extend(
                r.values
                    .iter()
                    .map(|v| v.map_or("–".to_string(), |v| format!("{v:.4}"))),
            );
            row
        })
        .collect();
    let mut html = format!("<h3>Indices ({})</h3>\n", escape(ix.method));
    html.push_str(&table(&header, &rows));
    for n in &ix.notes {
        html.push_str(&format!("<p>Note: {}</p>\n", escape(n)));
    }
    html
}
