//! The section of a prediction (`rtid predict -o`): each output before and after the
//! settings, at the fit's values with the draws' interval; and, where the page also
//! holds positioning records, the predicted values beside the measured ones.

use std::path::Path;

use super::markup::{escape, facts, fixed, table};
use super::{HtmlError, Kind, Section};
use crate::experiments::positioning::iso230::AxisStats;
use crate::prediction::{CasePrediction, DrawSource, Predicted, Prediction};

/// The section of the prediction `value` read from `path`.
pub fn section(path: &Path, value: serde_json::Value) -> Result<(Section, Prediction), HtmlError> {
    let p: Prediction = serde_json::from_value(value).map_err(|e| HtmlError::Malformed {
        path: path.to_path_buf(),
        what: "prediction (`rtid predict -o`)",
        message: e.to_string(),
    })?;
    let source = match p.source {
        DrawSource::Covariance => "normal draws from the fit's standard errors and correlations",
        DrawSource::Bootstrap => "the fit's bootstrap replicates",
    };
    let mut body = facts(&[
        (
            "parameter sets",
            format!("{} of {} ({source})", p.completed, p.asked),
        ),
        ("drawn", p.drawn.join(", ")),
        ("held at the fit", none_or(&p.held)),
        ("interval", format!("central {} %", fixed(p.level * 100.0))),
    ]);
    body.push_str(&format!(
        "<p>Each value at the fit's parameters, then the draws' interval; {}. The \
         intervals carry the drawn parameters' uncertainty only: every other parameter of \
         the model keeps its value.</p>\n",
        escape(
            &p.cases
                .first()
                .map_or(String::new(), |c| format!("in {}", c.unit))
        )
    ));
    body.push_str(&values_table(&p));
    for n in &p.notes {
        body.push_str(&format!("<p class=\"note\">{}</p>\n", escape(n)));
    }
    let section = Section {
        kind: Kind::Prediction,
        file: path.to_path_buf(),
        title: "Prediction: before and after the settings".into(),
        body,
    };
    Ok((section, p))
}

fn none_or(names: &[String]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

fn values_table(p: &Prediction) -> String {
    p.by_test()
        .into_iter()
        .map(|(test, cases)| {
            let mut header = vec![format!("{test}, {}", cases[0].unit)];
            header.extend(cases.iter().map(|c| c.case.clone()));
            let rows: Vec<Vec<String>> = cases[0]
                .values
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    let mut row = vec![label(&v.name)];
                    row.extend(cases.iter().map(|c| cell(&c.values[k])));
                    row
                })
                .collect();
            table(&header, &rows)
        })
        .collect()
}

fn label(name: &str) -> String {
    match name {
        "B_mean" => "mean reversal B̄".into(),
        "B" => "reversal B".into(),
        "E" => "systematic deviation E".into(),
        "M" => "mean deviation M".into(),
        "R" => "repeatability R".into(),
        "A" => "accuracy A".into(),
        "step_overshoot_percent" => "step overshoot, %".into(),
        "following_error" => "following error".into(),
        "reversal_spike" => "reversal spike".into(),
        "peak_effort" => "peak torque or force (N·m, N)".into(),
        other => other.into(),
    }
}

fn cell(v: &Predicted) -> String {
    match (v.lower, v.upper) {
        (Some(lo), Some(hi)) => format!("{} [{} … {}]", fixed(v.nominal), fixed(lo), fixed(hi)),
        _ => format!("{} (no interval)", fixed(v.nominal)),
    }
}

/// A measured record's ISO 230-2 values for the comparison: its file and the axis
/// figures in the report's unit.
#[derive(Clone, Debug)]
pub struct Measured {
    pub file: String,
    pub axis: AxisStats,
}

/// The predictions beside the page's positioning records, output by output, when the
/// page has both.
pub fn comparison(predictions: &[(String, Prediction)], records: &[Measured]) -> Option<Section> {
    if predictions.is_empty() || records.is_empty() {
        return None;
    }
    let mut header = vec!["output".to_string()];
    for (file, p) in predictions {
        header.extend(
            positioning(p)
                .iter()
                .map(|c| format!("{} predicted ({file})", c.case)),
        );
    }
    header.extend(records.iter().map(|r| format!("measured ({})", r.file)));
    let rows: Vec<Vec<String>> = ["B_mean", "B", "E", "M", "R", "A"]
        .iter()
        .map(|&name| {
            let mut row = vec![label(name)];
            for (_, p) in predictions {
                row.extend(positioning(p).iter().map(|c| {
                    c.values
                        .iter()
                        .find(|v| v.name == name)
                        .map_or("—".into(), cell)
                }));
            }
            row.extend(records.iter().map(|r| fixed(value(&r.axis, name))));
            row
        })
        .collect();
    let body = format!(
        "<p>Predicted on the identified model and measured, side by side (the page's \
         predictions and positioning records).</p>\n{}",
        table(&header, &rows)
    );
    Some(Section {
        kind: Kind::Prediction,
        file: predictions[0].0.clone().into(),
        title: "Before, after and predicted".into(),
        body,
    })
}

/// A prediction's positioning cases (the ones a record can be set beside).
fn positioning(p: &Prediction) -> Vec<&CasePrediction> {
    p.cases.iter().filter(|c| c.test == "positioning").collect()
}

/// A file's name for a table heading: its folder and name (records are often all
/// `positioning.json`), never an absolute path.
pub fn file_name(path: &Path) -> String {
    let last: Vec<String> = path
        .components()
        .rev()
        .filter_map(|c| match c {
            std::path::Component::Normal(n) => Some(n.to_string_lossy().into_owned()),
            _ => None,
        })
        .take(2)
        .collect();
    last.into_iter().rev().collect::<Vec<_>>().join("/")
}

fn value(a: &AxisStats, name: &str) -> f64 {
    match name {
        "B_mean" => a.b_mean,
        "B" => a.b,
        "E" => a.e,
        "M" => a.m,
        "R" => a.r,
        _ => a.a,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_heading_names_the_folder_and_the_file_only() {
        assert_eq!(
            file_name(Path::new("/home/lab/runs/after/positioning.json")),
            "after/positioning.json"
        );
        assert_eq!(file_name(Path::new("p.json")), "p.json");
    }
}
