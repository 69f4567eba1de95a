//! Indices of a finished sweep: local sensitivities, Morris μ*/μ/σ or Sobol S1/ST,
//! one row per (output column, factor), written as `…-indices.csv`.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use super::designs::Method;
use super::{local, morris, sobol, Sweep, SweepError};

/// Confidence level of the Sobol bootstrap intervals.
pub const CONFIDENCE: f64 = 0.95;

/// One factor's indices for one output column.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IndexRow {
    /// Output column (with its unit).
    pub output: String,
    /// Factor (registry name).
    pub parameter: String,
    /// One value per entry of [`Indices::columns`]; `None`: undefined.
    pub values: Vec<Option<f64>>,
}

/// The indices of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Indices {
    pub method: &'static str,
    /// Names of the values of each row.
    pub columns: Vec<&'static str>,
    pub rows: Vec<IndexRow>,
    /// Output columns without indices, and why.
    pub notes: Vec<String>,
}

impl Indices {
    /// The column whose magnitude ranks the factors (tornado bars).
    pub fn main_column(&self) -> Option<usize> {
        match self.method {
            "local" => Some(0),
            "morris" => Some(0),
            "sobol" => Some(3),
            _ => None,
        }
    }
}

/// The values of output column `c` (position in the row) in design order; `Err` names
/// why some are missing.
fn column(
    rows: &BTreeMap<usize, Vec<String>>,
    c: usize,
    error_col: usize,
) -> Result<Vec<f64>, String> {
    let mut out = Vec::with_capacity(rows.len());
    let mut missing = Vec::new();
    for (&i, r) in rows {
        match r[c].parse::<f64>() {
            Ok(v) if v.is_finite() => out.push(v),
            _ => {
                missing.push(i);
                out.push(f64::NAN);
            }
        }
    }
    if let Some(&first) = missing.first() {
        let why = if rows[&first][error_col].is_empty() {
            "no value (e.g. fewer gain peaks than modes)".to_string()
        } else {
            format!("an error: {}", rows[&first][error_col])
        };
        return Err(format!(
            "{} of {} rows have no value (first: index {first}, {why})",
            missing.len(),
            rows.len()
        ));
    }
    Ok(out)
}

/// Computes the indices of `sweep` from its complete rows.
pub fn analyse(sweep: &Sweep, rows: &BTreeMap<usize, Vec<String>>) -> Result<Indices, SweepError> {
    let design = sweep.design()?;
    let k = sweep.factors.len();
    let columns = match sweep.method {
        Method::Grid => vec![],
        Method::Local { .. } => vec!["sensitivity"],
        Method::Morris { .. } => vec!["mu_star", "mu", "sigma"],
        Method::Sobol { .. } => vec!["s1", "s1_low", "s1_high", "st", "st_low", "st_high"],
    };
    let mut out = Indices {
        method: sweep.method.name(),
        columns,
        rows: Vec::new(),
        notes: Vec::new(),
    };
    if sweep.method == Method::Grid {
        return Ok(out);
    }
    let error_col = sweep.columns().len() - 1;
    for (j, name) in sweep.output_columns().into_iter().enumerate() {
        let y = match column(rows, 1 + k + j, error_col) {
            Ok(y) => y,
            Err(why) => {
                out.notes.push(format!("{name}: {why}"));
                continue;
            }
        };
        let per_factor: Vec<Vec<Option<f64>>> = match sweep.method {
            Method::Grid => unreachable!("returned above"),
            Method::Local { step } => local::sensitivities(&y, k, step)
                .into_iter()
                .map(|s| vec![s])
                .collect(),
            Method::Morris { .. } => match morris::indices(design.unit.view(), &y, k) {
                Some(m) => m
                    .iter()
                    .map(|m| vec![Some(m.mu_star), Some(m.mu), Some(m.sigma)])
                    .collect(),
                None => {
                    out.notes
                        .push(format!("{name}: the rows are not Morris trajectories"));
                    continue;
                }
            },
            Method::Sobol { samples, bootstrap } => {
                match sobol::indices(&y, k, samples, bootstrap, CONFIDENCE, sweep.seed) {
                    Ok(s) => s
                        .iter()
                        .map(|s| {
                            [s.s1, s.s1_low, s.s1_high, s.st, s.st_low, s.st_high]
                                .map(Some)
                                .to_vec()
                        })
                        .collect(),
                    Err(e) => {
                        out.notes.push(format!("{name}: {e}"));
                        continue;
                    }
                }
            }
        };
        for (f, values) in sweep.factors.iter().zip(per_factor) {
            out.rows.push(IndexRow {
                output: name.clone(),
                parameter: f.name.clone(),
                values,
            });
        }
    }
    Ok(out)
}

/// Writes the indices as CSV (`output,parameter,<columns>`), atomically.
pub fn write(path: &Path, indices: &Indices) -> std::io::Result<()> {
    crate::io::atomic::write_with(path, |w| {
        let mut csv = csv::Writer::from_writer(w);
        let header: Vec<&str> = ["output", "parameter"]
            .into_iter()
            .chain(indices.columns.iter().copied())
            .collect();
        csv.write_record(&header)?;
        for r in &indices.rows {
            let mut fields = vec![r.output.clone(), r.parameter.clone()];
            fields.extend(
                r.values
                    .iter()
                    .map(|v| v.map_or(String::new(), |v| v.to_string())),
            );
            csv.write_record(&fields)?;
        }
        csv.flush()?;
        Ok::<(), std::io::Error>(())
    })
}
