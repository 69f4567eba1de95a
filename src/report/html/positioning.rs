//! The section of an ISO 230-2 positioning test: the standard's table per target and
//! direction, the axis figures, the deviation chart, and the acceptance verdict of
//! the bidirectional accuracy A against the user's tolerance.

use std::path::Path;

use super::markup::{escape, fixed, svg_block, table};
use super::prediction::{file_name, Measured};
use super::{HtmlError, Kind, Section, Tolerances};
use crate::experiments::positioning;
use crate::experiments::positioning::iso230::{self, AxisStats, Iso230Report, ReportUnits};
use crate::io::experiment_file::{self, Kind as ExperimentKind};

const WHAT: &str = "positioning experiment";

/// The section of the positioning manifest `path`, and its axis values in the
/// report's unit (for the predictions beside it).
pub fn section(path: &Path, tolerances: &Tolerances) -> Result<(Section, Measured), HtmlError> {
    let bad = |message: String| HtmlError::Malformed {
        path: path.to_path_buf(),
        what: WHAT,
        message,
    };
    let exp = experiment_file::read(path).map_err(|e| bad(e.to_string()))?;
    if exp.manifest.kind != ExperimentKind::Positioning {
        return Err(bad(format!("kind `{}`", exp.manifest.kind.name())));
    }
    let readings = positioning::from_data(&exp.data)
        .ok_or_else(|| bad("the data file holds no positioning readings".into()))?;
    let units = ReportUnits::of(exp.data.axis().unwrap_or_default());
    let tolerance = tolerance(path, units, tolerances)?;
    let report = iso230::evaluate(&readings).map_err(|e| bad(e.to_string()))?;
    let mechanism = exp.manifest.mechanism.as_deref().unwrap_or("table");
    let title = format!("{mechanism}: ISO 230-2 positioning");
    let chart = crate::report::positioning::deviations(&report, &title, units)
        .render()
        .map_err(|e| bad(e.to_string()))?;
    let a = report.axis.a * units.deviation_per_si;
    let mut body = verdict(a, tolerance, units);
    body.push_str(&format!(
        "<h3>Axis</h3>\n<p>ISO 230-2 figures of the axis, {}.</p>\n",
        units.deviation_name
    ));
    body.push_str(&axis_table(&report.axis.scaled(units.deviation_per_si)));
    body.push_str("<h3>Targets</h3>\n");
    body.push_str(&targets_table(&report, units));
    body.push_str(&svg_block(&chart));
    let section = Section {
        kind: Kind::Positioning,
        file: path.to_path_buf(),
        title: format!("Positioning (ISO 230-2): {mechanism}"),
        body,
    };
    let measured = Measured {
        file: file_name(path),
        axis: report.axis.scaled(units.deviation_per_si),
    };
    Ok((section, measured))
}

/// The tolerance of the axis's kind, if given; the other kind's option is refused
/// (a rotary tolerance in µm is a mistake, not a value to convert).
fn tolerance(path: &Path, u: ReportUnits, t: &Tolerances) -> Result<Option<f64>, HtmlError> {
    let rotary = u == ReportUnits::ROTARY;
    let (mine, other) = if rotary {
        (t.arcsec, t.um)
    } else {
        (t.um, t.arcsec)
    };
    if mine.is_none() && other.is_some() {
        let (given, given_axis, axis, wanted) = if rotary {
            ("--tolerance-um", "linear", "rotary", "--tolerance-arcsec")
        } else {
            ("--tolerance-arcsec", "rotary", "linear", "--tolerance-um")
        };
        return Err(HtmlError::WrongTolerance {
            path: path.to_path_buf(),
            given,
            given_axis,
            axis,
            wanted,
        });
    }
    Ok(mine)
}

/// PASS when A ≤ tolerance, FAIL above, or a note that no tolerance was given.
pub fn verdict(a: f64, tolerance: Option<f64>, u: ReportUnits) -> String {
    let d = u.deviation;
    match tolerance {
        None => format!(
            "<p><span class=\"verdict none\">no tolerance given</span> A = {} {d} \
             (give --tolerance-{} for a PASS/FAIL verdict)</p>\n",
            fixed(a),
            u.deviation_key
        ),
        Some(t) => {
            let (class, word, sign) = if a <= t {
                ("pass", "PASS", "≤")
            } else {
                ("fail", "FAIL", ">")
            };
            format!(
                "<p><span class=\"verdict {class}\">{word}</span> bidirectional accuracy \
                 A = {} {d} {sign} tolerance {} {d}</p>\n",
                fixed(a),
                escape(&t.to_string())
            )
        }
    }
}

/// B, B̄, R↑, R↓, R, E↑, E↓, E, M, A↑, A↓, A (already in report units).
fn axis_table(a: &AxisStats) -> String {
    let values = [
        ("B", "reversal value, max |Bi|", a.b),
        ("B̄", "mean reversal value", a.b_mean),
        ("R↑", "unidirectional repeatability", a.r_up),
        ("R↓", "unidirectional repeatability", a.r_down),
        ("R", "bidirectional repeatability", a.r),
        ("E↑", "unidirectional systematic deviation", a.e_up),
        ("E↓", "unidirectional systematic deviation", a.e_down),
        ("E", "bidirectional systematic deviation", a.e),
        ("M", "mean bidirectional deviation", a.m),
        ("A↑", "unidirectional accuracy", a.a_up),
        ("A↓", "unidirectional accuracy", a.a_down),
        ("A", "bidirectional accuracy", a.a),
    ];
    let rows: Vec<Vec<String>> = values
        .iter()
        .map(|(s, what, v)| vec![s.to_string(), what.to_string(), fixed(*v)])
        .collect();
    table(&["figure", "meaning", "value"], &rows)
}

/// Per target: x̄↑, x̄↓, s↑, s↓, Bi, x̄i, R↑i, R↓i, Ri.
fn targets_table(report: &Iso230Report, u: ReportUnits) -> String {
    let d = u.deviation;
    let header = [
        format!("target {}", u.target),
        "n↑/n↓".to_string(),
        format!("x̄↑ {d}"),
        format!("x̄↓ {d}"),
        format!("s↑ {d}"),
        format!("s↓ {d}"),
        format!("Bi {d}"),
        format!("x̄i {d}"),
        format!("R↑i {d}"),
        format!("R↓i {d}"),
        format!("Ri {d}"),
    ];
    let rows: Vec<Vec<String>> = report
        .targets
        .iter()
        .map(|s| {
            let a = s.scaled(u.deviation_per_si);
            let mut row = vec![
                format!("{:.3}", s.target * u.target_per_si),
                format!("{}/{}", s.n_up, s.n_down),
            ];
            row.extend(
                [
                    a.mean_up,
                    a.mean_down,
                    a.s_up,
                    a.s_down,
                    a.reversal,
                    a.mean_bidirectional,
                    a.repeat_up,
                    a.repeat_down,
                    a.repeat,
                ]
                .map(fixed),
            );
            row
        })
        .collect();
    table(&header, &rows)
}
