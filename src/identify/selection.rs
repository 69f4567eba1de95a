//! Model selection between identifications of the same data (docs/identification.md):
//! which fitted set — or which model — the data support. For each result, with n
//! residuals, k fitted parameters and the cost SSR (sum of squared scaled residuals):
//!
//! - AIC = n·ln(SSR/n) + 2k, and AICc = AIC + 2k(k+1)/(n−k−1) (the small-sample
//!   correction, which matters when n/k < 40);
//! - BIC = n·ln(SSR/n) + k·ln n (a heavier price per parameter: it prefers the
//!   smaller model unless the data clearly ask for more);
//! - Akaike weights exp(−ΔAICc/2), normalised: the relative support of each model
//!   (by AIC when a fit has too few residuals for AICc: one criterion for all);
//! - for nested pairs (one fitted set inside the other, same data), the F-test
//!   F = ((SSR_r − SSR_f)/(k_f − k_r)) / (SSR_f/(n − k_f)) and its p-value: a small
//!   p says the extra parameters lower the cost by more than noise would.
//!
//! The arithmetic is [`crate::estimation::information`]'s, on each result's figures.
//! These compare fits of the same residuals only: the same experiment files with the
//! same objectives, weights and scales. That is checked, and fits of other data are
//! refused (their costs are not on one scale).

use crate::estimation::information::{self, Figures, InformationError};
use crate::identify::result::IdentifyResult;

pub use crate::estimation::information::{Candidate, Nested, Selection};

/// Why results cannot be compared.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SelectionError {
    #[error("at least two results are needed to compare models")]
    TooFew,
    #[error("{label} fits other residuals than {first} ({what}): AIC and BIC compare fits of the same residuals — the same experiment files, objectives, weights and scales")]
    DifferentData {
        label: String,
        first: String,
        what: String,
    },
    #[error("{label}: the fit was interrupted; compare finished fits")]
    Interrupted { label: String },
    #[error("{label}: cost {cost} with {n} residuals: nothing to compare (a zero cost is an exact fit, where AIC is −∞)")]
    Degenerate { label: String, cost: f64, n: usize },
}

/// What identifies the residuals of a result: per experiment, its file, objective,
/// weight, scale and residual count.
fn layout(r: &IdentifyResult) -> Vec<(String, String, String, String, usize)> {
    r.residuals
        .iter()
        .map(|e| {
            (
                e.source.clone(),
                e.objective.clone(),
                format!("{}", e.weight),
                e.scale.clone(),
                e.residuals.len(),
            )
        })
        .collect()
}

/// Compares `results` (label, result): figures for each, nested F-tests.
pub fn select(results: &[(String, IdentifyResult)]) -> Result<Selection, SelectionError> {
    let [(first_label, first), ..] = results else {
        return Err(SelectionError::TooFew);
    };
    if results.len() < 2 {
        return Err(SelectionError::TooFew);
    }
    for (label, r) in results {
        check(label, r, first_label, first)?;
    }
    let figures = results.iter().map(|(l, r)| figures(l, r)).collect();
    information::compare(figures).map_err(|e| match e {
        InformationError::Degenerate { label, cost, n } => {
            SelectionError::Degenerate { label, cost, n }
        }
        _ => SelectionError::TooFew,
    })
}

/// Checks that `r` fits the data `first` fits, finished and with a usable cost.
fn check(
    label: &str,
    r: &IdentifyResult,
    first_label: &str,
    first: &IdentifyResult,
) -> Result<(), SelectionError> {
    let differs = |what: String| SelectionError::DifferentData {
        label: label.into(),
        first: first_label.into(),
        what,
    };
    let (mine, theirs) = (layout(r), layout(first));
    if mine.len() != theirs.len() {
        return Err(differs(format!(
            "{} experiment objectives against {}",
            mine.len(),
            theirs.len()
        )));
    }
    for (a, b) in mine.iter().zip(&theirs) {
        if a != b {
            return Err(differs(format!(
                "{} [{}], weight {}, scale {}, {} residuals, where it has {} [{}], weight {}, scale {}, {} residuals",
                a.0, a.1, a.2, a.3, a.4, b.0, b.1, b.2, b.3, b.4
            )));
        }
    }
    if r.interrupted {
        return Err(SelectionError::Interrupted {
            label: label.into(),
        });
    }
    let n: usize = mine.iter().map(|e| e.4).sum();
    if !(r.cost.is_finite() && r.cost > 0.0) || n == 0 {
        return Err(SelectionError::Degenerate {
            label: label.into(),
            cost: r.cost,
            n,
        });
    }
    Ok(())
}

/// One result's own criteria — n, k, the cost, AIC, AICc, BIC — as `select` computes
/// them (Δ and weight 0: they need other fits).
pub fn statistics(label: &str, r: &IdentifyResult) -> Candidate {
    information::candidate(figures(label, r))
}

/// The figures of one result.
fn figures(label: &str, r: &IdentifyResult) -> Figures {
    Figures {
        label: label.into(),
        fitted: r.parameters.keys().cloned().collect(),
        n: r.residuals.iter().map(|e| e.residuals.len()).sum::<usize>(),
        k: r.parameters.len(),
        cost: r.cost,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fits to n = 100 residuals with costs giving a known F.
    fn fake(label: &str, fitted: &[&str], cost: f64) -> (String, IdentifyResult) {
        let text = serde_json::json!({
            "mechanism": "x", "experiments": ["e.json"],
            "parameters": fitted.iter().map(|p| (p.to_string(), 1.0)).collect::<std::collections::BTreeMap<_, _>>(),
            "initial": {}, "bounds": {}, "method": "lsq", "fidelity": "linear",
            "cost": cost,
            "residuals": [{"source": "e.json", "objective": "gain_curve", "weight": 1.0,
                           "scale": "0.1 dB", "residuals": vec![0.1; 100], "rms": 0.1}],
            "evaluations": 1, "wall_time_s": 0.0,
            "termination": {"code": "converged"}, "interrupted": false, "starts": [],
            "uncertainty": null, "warnings": []
        });
        (label.into(), serde_json::from_value(text).unwrap())
    }

    #[test]
    fn figures_follow_their_definitions() {
        let s = select(&[
            fake("small", &["Kw"], 200.0),
            fake("big", &["Kw", "Kg"], 100.0),
        ])
        .unwrap();
        let big = &s.candidates[0];
        assert_eq!(big.label, "big");
        let fit = 100.0 * (100.0f64 / 100.0).ln();
        assert!((big.aic - (fit + 4.0)).abs() < 1e-12);
        assert!((big.bic - (fit + 2.0 * 100f64.ln())).abs() < 1e-12);
        assert!((big.aicc.unwrap() - (big.aic + 12.0 / 97.0)).abs() < 1e-12);
        assert!((s.candidates.iter().map(|c| c.weight).sum::<f64>() - 1.0).abs() < 1e-12);
        // F = (100/1)/(100/98) = 98, p tiny.
        let t = &s.nested[0];
        assert_eq!(
            (t.restricted.as_str(), t.full.as_str(), t.df),
            ("small", "big", (1, 98))
        );
        assert!((t.f - 98.0).abs() < 1e-9 && t.p_value < 1e-12, "{t:?}");
        assert_eq!(t.added, vec!["Kg".to_string()]);
    }

    #[test]
    fn an_extra_parameter_that_does_not_lower_the_cost_is_not_supported() {
        let s = select(&[
            fake("small", &["Kw"], 100.0),
            fake("big", &["Kw", "Kb"], 99.9),
        ])
        .unwrap();
        assert_eq!(s.candidates[0].label, "small");
        assert!(s.nested[0].p_value > 0.5, "{:?}", s.nested[0]);
    }

    #[test]
    fn fits_of_other_data_are_refused() {
        let (label, mut other) = fake("other", &["Kw"], 100.0);
        other.residuals[0].weight = 2.0;
        let e = select(&[fake("a", &["Kw"], 100.0), (label, other)]).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("other fits other residuals than a (e.json [gain_curve], weight 2"),
            "{e}"
        );
        assert!(select(&[fake("a", &["Kw"], 1.0)]).is_err());
    }
}
