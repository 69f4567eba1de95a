//! The section of an identification result (`rtid identify --out`): what was fitted
//! to which data (with the data's SHA-256, so the record shows it was this data),
//! the values with their uncertainty, the correlations, the residuals and the
//! warnings.

use std::path::{Path, PathBuf};

use super::markup::{escape, facts, figure, sci, table};
use super::{correlation, HtmlError, Kind, Section};
use crate::identify::IdentifyResult;
use crate::io::provenance::sha256;
use crate::report::figure::{Figure, FigureError, Series, Style};

/// Most residuals drawn per experiment (the SVG stays small).
const MAX_POINTS: usize = 2000;

/// The section of `result`, read from `path`.
pub fn section(path: &Path, result: &IdentifyResult) -> Result<Section, HtmlError> {
    let drawn = |e: FigureError| HtmlError::Malformed {
        path: path.to_path_buf(),
        what: "identification result (`rtid identify --out`)",
        message: e.to_string(),
    };
    let mut body = summary(result);
    body.push_str("<h3>Input files</h3>\n");
    body.push_str(&inputs(path, result));
    body.push_str("<h3>Parameters</h3>\n");
    body.push_str(&parameters(result));
    body.push_str(&correlations(result));
    body.push_str(&fit_against_data(result).map_err(drawn)?);
    body.push_str(&residuals(result).map_err(drawn)?);
    body.push_str(&profiles(result).map_err(drawn)?);
    body.push_str(&warnings(result));
    Ok(Section {
        kind: Kind::Identification,
        file: path.to_path_buf(),
        title: format!("Identification: {}", result.mechanism),
        body,
    })
}

/// Command, version, mechanism, method, cost, effort and how the search ended.
fn summary(r: &IdentifyResult) -> String {
    let mut pairs = Vec::new();
    if let Some(p) = &r.provenance {
        pairs.push(("command", p.command.clone()));
        pairs.push(("fitted by", format!("rtid {}", p.version)));
    }
    pairs.extend([
        ("mechanism", r.mechanism.clone()),
        ("method", format!("{} ({} model)", r.method, r.fidelity)),
        ("cost", format!("{:.4e}", r.cost)),
        ("evaluations", r.evaluations.to_string()),
        ("wall time", format!("{:.2} s", r.wall_time_s)),
        ("termination", r.termination.0.to_string()),
        ("report by", format!("rtid {}", crate::version::VERSION)),
    ]);
    if r.interrupted {
        pairs.push((
            "interrupted",
            "yes: the values are the best found before Ctrl-C".into(),
        ));
    }
    facts(&pairs)
}

/// Each input file with the SHA-256 recorded when it was fitted and whether the
/// file found now still has it; a result without a record gets today's hashes of
/// its experiment files.
fn inputs(path: &Path, r: &IdentifyResult) -> String {
    let folder = path.parent().unwrap_or(Path::new(""));
    let now = |name: &str| -> Option<String> {
        let file = locate(folder, name)?;
        Some(sha256(&file).unwrap_or_else(|err| format!("not readable: {err}")))
    };
    let Some(p) = &r.provenance else {
        let rows: Vec<Vec<String>> = r
            .experiments
            .iter()
            .map(|e| vec![e.clone(), now(e).unwrap_or_else(|| "not found".into())])
            .collect();
        return format!(
            "<p>The result does not record its inputs' hashes: these are the files found now.</p>\n{}",
            table(&["file", "SHA-256 now"], &rows)
        );
    };
    let rows: Vec<Vec<String>> = p
        .inputs
        .iter()
        .map(|i| {
            let check = match now(&i.path) {
                None => "not found".to_string(),
                Some(h) if h == i.sha256 => "same".to_string(),
                Some(h) => format!("CHANGED since the fit: {h}"),
            };
            vec![i.path.clone(), i.sha256.clone(), check]
        })
        .collect();
    table(&["file", "SHA-256 when fitted", "the file now"], &rows)
}

/// An input file as the result names it: beside the result first (where
/// `rtid identify` was usually run from), else from the current folder.
fn locate(folder: &Path, name: &str) -> Option<PathBuf> {
    [folder.join(name), PathBuf::from(name)]
        .into_iter()
        .find(|p| p.is_file())
}

/// One row per fitted parameter: start, value, standard error, bounds and the
/// profile and bootstrap intervals when the fit has them.
fn parameters(r: &IdentifyResult) -> String {
    let mut header = vec![
        "parameter",
        "start",
        "identified",
        "std. error",
        "std. error %",
        "lower bound",
        "upper bound",
    ];
    if r.profiles.is_some() {
        header.extend(["profile lower", "profile upper"]);
    }
    if r.resampling.is_some() {
        header.extend([
            "bootstrap lower",
            "bootstrap upper",
            "bootstrap s.e.",
            "bootstrap bias",
        ]);
    }
    let rows: Vec<Vec<String>> = r
        .parameters
        .iter()
        .map(|(name, &value)| {
            let se = r.standard_error(name);
            let bounds = r.bounds.get(name);
            let mut row = vec![
                name.clone(),
                r.initial.get(name).map_or("–".into(), |&v| sci(v)),
                sci(value),
                se.map_or("–".into(), |s| format!("{s:.3e}")),
                se.map_or("–".into(), |s| format!("{:.2}", 100.0 * s / value.abs())),
                bounds.map_or("–".into(), |b| sci(b[0])),
                bounds.map_or("–".into(), |b| sci(b[1])),
            ];
            row.extend(interval_cells(r, name));
            row
        })
        .collect();
    table(&header, &rows)
}

/// A parameter's profile interval ("open" for an unbounded side) and bootstrap
/// interval, spread and bias, for the columns the fit has.
fn interval_cells(r: &IdentifyResult, name: &str) -> Vec<String> {
    let dash = || "–".to_string();
    let open = |v: Option<f64>| v.map_or("open".into(), sci);
    let mut cells = Vec::new();
    if let Some(profiles) = &r.profiles {
        match profiles.get(name) {
            Some(p) => cells.extend([open(p.lower), open(p.upper)]),
            None => cells.extend([dash(), dash()]),
        }
    }
    if let Some(s) = &r.resampling {
        match s.intervals.get(name) {
            Some(i) => cells.extend([
                sci(i.lower),
                sci(i.upper),
                format!("{:.3e}", i.standard_error),
                format!("{:.3e}", i.bias),
            ]),
            None => cells.extend([dash(), dash(), dash(), dash()]),
        }
    }
    cells
}

/// The correlation heat map, when the fit has an uncertainty estimate.
fn correlations(r: &IdentifyResult) -> String {
    let Some(u) = &r.uncertainty else {
        return "<p>No uncertainty estimate: the fit has no standard errors or correlations.</p>\n"
            .into();
    };
    format!(
        "<h3>Correlations</h3>\n<p>Near ±1: the data cannot tell the two parameters apart.</p>\n{}",
        correlation::heat_map(&u.names, &u.correlation)
    )
}

/// Each experiment's data against the model at the start and identified values.
fn fit_against_data(r: &IdentifyResult) -> Result<String, FigureError> {
    if r.comparisons.is_empty() {
        return Ok(String::new());
    }
    let mut html = String::from("<h3>Fit against data</h3>\n");
    for c in &r.comparisons {
        html.push_str(&format!("<p><code>{}</code></p>\n", escape(&c.source)));
        html.push_str(&figure(&crate::report::identify::comparison(c))?);
    }
    Ok(html)
}

/// One chart of the scaled residuals per experiment, against their index.
fn residuals(r: &IdentifyResult) -> Result<String, FigureError> {
    let mut html = String::from("<h3>Residuals</h3>\n");
    for e in &r.residuals {
        let points: Vec<(f64, f64)> = e
            .residuals
            .iter()
            .enumerate()
            .map(|(i, &v)| (i as f64, v))
            .collect();
        html.push_str(&format!(
            "<p><code>{}</code> ({}): RMS {:.4e}; one unit is {}.</p>\n",
            escape(&e.source),
            escape(&e.objective),
            e.rms,
            escape(&e.scale)
        ));
        if points.iter().all(|p| !p.1.is_finite()) {
            html.push_str("<p>No finite residuals to draw.</p>\n");
            continue;
        }
        let chart = Figure::new(
            format!(
                "residuals: {}",
                crate::report::identify::file_name(&e.source)
            ),
            "index",
            "scaled residual",
        )
        .with(Series::new("residual", points, Style::Markers).thinned(MAX_POINTS));
        html.push_str(&figure(&chart)?);
    }
    Ok(html)
}

/// The profile-likelihood charts, when the fit was profiled.
fn profiles(r: &IdentifyResult) -> Result<String, FigureError> {
    let Some(profiles) = &r.profiles else {
        return Ok(String::new());
    };
    let mut html = String::from("<h3>Profiles</h3>\n");
    for (name, p) in profiles {
        if p.points.is_empty() {
            continue;
        }
        html.push_str(&figure(&crate::report::identify::profile(name, p))?);
    }
    Ok(html)
}

/// The warnings in plain words.
fn warnings(r: &IdentifyResult) -> String {
    if r.warnings.is_empty() {
        return "<h3>Warnings</h3>\n<p>None.</p>\n".into();
    }
    let mut html = String::from("<h3>Warnings</h3>\n<ul>\n");
    for w in &r.warnings {
        html.push_str(&format!("<li>{}</li>\n", escape(&w.0.to_string())));
    }
    html.push_str("</ul>\n");
    html
}
