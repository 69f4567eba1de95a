//! What a user should know about a law's fit, typed: a stable `code` (for scripts and
//! tests) and a text (`Display`, for people).

use std::fmt;

use serde::Serialize;

use super::covariance::Covariance;
use super::law::Law;

/// A note on a fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "code", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Note {
    /// The solver stopped at its iteration limit.
    NotConverged { iterations: usize },
    /// These parameters have no standard error: the data do not determine them (no
    /// effect on the law, or a combination the data leave free).
    NotDetermined { parameters: Vec<String> },
    /// The Stribeck rise `difference` (Fs − Fc) is within two standard errors of 0 (or
    /// has none): the data show no rise, and its speed and shape (vs, delta) mean
    /// nothing.
    RiseNotShown {
        difference: String,
        value: f64,
        std_error: Option<f64>,
    },
    /// The Stribeck speed lies outside the measured speeds of its direction(s): the
    /// rise is extrapolated.
    RiseOutsideSpeeds {
        parameter: String,
        value: f64,
        lowest: f64,
        highest: f64,
    },
}

impl fmt::Display for Note {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Note::NotConverged { iterations } => write!(
                f,
                "the fit stopped at its limit of {iterations} iterations before converging"
            ),
            Note::NotDetermined { parameters } => write!(
                f,
                "{} not determined by the data: no standard error",
                parameters.join(", ")
            ),
            Note::RiseNotShown {
                difference,
                value,
                std_error,
            } => {
                let se = std_error.map_or("undetermined".into(), |s| format!("{s:.3e}"));
                write!(
                    f,
                    "{difference} = {value:.3e} ± {se}: the data show no Stribeck rise \
                     (the law reduces to Coulomb's), so its speed and exponent are not \
                     determined"
                )
            }
            Note::RiseOutsideSpeeds {
                parameter,
                value,
                lowest,
                highest,
            } => write!(
                f,
                "{parameter} = {value:.3e} lies outside the measured speeds \
                 ({lowest:.3e} to {highest:.3e}): the rise is extrapolated"
            ),
        }
    }
}

/// The notes on a fit of `law` with `values` over runs at `|speeds|` (per direction:
/// lowest and highest, positive first), given its covariance.
pub(super) fn notes(
    law: Law,
    values: &[f64],
    covariance: &Covariance,
    span: [(f64, f64); 2],
    iterations: Option<usize>,
) -> Vec<Note> {
    let mut out = Vec::new();
    if let Some(iterations) = iterations {
        out.push(Note::NotConverged { iterations });
    }
    let names = law.parameters();
    let undetermined: Vec<String> = (0..names.len())
        .filter(|&j| covariance.std_error(j).is_none())
        .map(|j| names[j].to_string())
        .collect();
    if !undetermined.is_empty() {
        out.push(Note::NotDetermined {
            parameters: undetermined,
        });
    }
    // (Fs, Fc, vs) indices and the speeds their direction(s) cover.
    let both = (span[0].0.min(span[1].0), span[0].1.max(span[1].1));
    let rises: &[(usize, usize, usize, (f64, f64))] = match law {
        Law::Stribeck => &[(1, 0, 2, both)],
        Law::StribeckAsymmetric => &[(1, 0, 2, span[0]), (5, 4, 6, span[1])],
        Law::Coulomb | Law::CoulombAsymmetric => &[],
    };
    for &(fs, fc, vs, (lowest, highest)) in rises {
        let value = values[fs] - values[fc];
        let std_error = covariance.std_error_of_difference(fs, fc);
        if !matches!(std_error, Some(se) if value.abs() > 2.0 * se) {
            out.push(Note::RiseNotShown {
                difference: format!("{} − {}", names[fs], names[fc]),
                value,
                std_error,
            });
        } else if !(lowest..=highest).contains(&values[vs]) {
            out.push(Note::RiseOutsideSpeeds {
                parameter: names[vs].to_string(),
                value: values[vs],
                lowest,
                highest,
            });
        }
    }
    out
}
