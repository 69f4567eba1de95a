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
    /// rise is extrapolated, and the law not determined.
    RiseOutsideSpeeds {
        parameter: String,
        value: f64,
        lowest: f64,
        highest: f64,
    },
    /// Fs < Fc by more than two standard errors: the effort rises towards Fc at low
    /// speed instead of falling from a breakaway level — not a Stribeck curve.
    RiseNegative {
        difference: String,
        value: f64,
        std_error: f64,
    },
    /// The exponent delta lies outside [`DELTA_RANGE`]: the curve is a step (large
    /// delta) or a slow logarithm-like slope (small delta), not a Stribeck rise the
    /// runs resolve.
    ExponentOutside { value: f64, lower: f64, upper: f64 },
}

/// The range of the Stribeck exponent delta a determined law may have: the shapes
/// the literature fits to measured maps (Armstrong-Hélouvry et al. 1994 §2.1: 0.5 to
/// 2; Gaussian 2) with room to 3. Outside it the fit has found a step between two runs
/// or a slope spread over every speed, which the runs do not resolve.
pub const DELTA_RANGE: (f64, f64) = (0.5, 3.0);

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
                 ({lowest:.3e} to {highest:.3e}): the rise is extrapolated, not determined"
            ),
            Note::RiseNegative {
                difference,
                value,
                std_error,
            } => write!(
                f,
                "{difference} = {value:.3e} ± {std_error:.3e} < 0: the effort rises towards \
                 Fc at low speed, not a Stribeck curve (Fs ≥ Fc); not determined"
            ),
            Note::ExponentOutside {
                value,
                lower,
                upper,
            } => write!(
                f,
                "delta = {value:.3e} lies outside [{lower}, {upper}]: a step between two runs \
                 or a slope over all of them, not a rise the runs resolve; not determined"
            ),
        }
    }
}

/// The notes every fit may have: it did not converge (`iterations` at the limit), or
/// parameters `names` lack a standard error.
pub(super) fn general(
    names: &[&str],
    covariance: &Covariance,
    iterations: Option<usize>,
) -> Vec<Note> {
    let mut out = Vec::new();
    if let Some(iterations) = iterations {
        out.push(Note::NotConverged { iterations });
    }
    let undetermined: Vec<String> = (0..names.len())
        .filter(|&j| covariance.std_error(j).is_none())
        .map(|j| names[j].to_string())
        .collect();
    if !undetermined.is_empty() {
        out.push(Note::NotDetermined {
            parameters: undetermined,
        });
    }
    out
}

/// A Stribeck law's own checks of a fit with `values` over runs at `|speeds|` (per
/// direction: lowest and highest, positive first), given its covariance: the rise
/// shown and positive, vs within the speeds, delta within [`DELTA_RANGE`].
pub(super) fn stribeck_checks(
    law: Law,
    values: &[f64],
    covariance: &Covariance,
    span: [(f64, f64); 2],
) -> Vec<Note> {
    let mut out = Vec::new();
    let names = law.parameters();
    // (Fs, Fc, vs) indices and the speeds their direction(s) cover.
    let both = (span[0].0.min(span[1].0), span[0].1.max(span[1].1));
    let rises: &[(usize, usize, usize, (f64, f64))] = match law {
        Law::Stribeck => &[(1, 0, 2, both)],
        Law::StribeckAsymmetric => &[(1, 0, 2, span[0]), (5, 4, 6, span[1])],
        Law::Coulomb | Law::CoulombAsymmetric => &[],
    };
    let mut shown = false;
    for &(fs, fc, vs, (lowest, highest)) in rises {
        let value = values[fs] - values[fc];
        let difference = format!("{} − {}", names[fs], names[fc]);
        let std_error = covariance.std_error_of_difference(fs, fc);
        let Some(se) = std_error.filter(|se| value.abs() > 2.0 * se) else {
            out.push(Note::RiseNotShown {
                difference,
                value,
                std_error,
            });
            continue;
        };
        if value < 0.0 {
            out.push(Note::RiseNegative {
                difference,
                value,
                std_error: se,
            });
            continue;
        }
        shown = true;
        if !(lowest..=highest).contains(&values[vs]) {
            out.push(Note::RiseOutsideSpeeds {
                parameter: names[vs].to_string(),
                value: values[vs],
                lowest,
                highest,
            });
        }
    }
    let delta = values[names.iter().position(|&n| n == "delta").unwrap_or(0)];
    let (lower, upper) = DELTA_RANGE;
    if shown && !(lower..=upper).contains(&delta) {
        out.push(Note::ExponentOutside {
            value: delta,
            lower,
            upper,
        });
    }
    out
}
