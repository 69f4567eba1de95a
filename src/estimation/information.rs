//! Information criteria: which of several least-squares fits of the same data the
//! data support, from plain figures — each fit's label, fitted parameter names, n
//! residuals, k fitted parameters and its cost SSR (sum of squared residuals):
//!
//! - AIC = n·ln(SSR/n) + 2k, and AICc = AIC + 2k(k+1)/(n−k−1) (the small-sample
//!   correction, which matters when n/k < 40);
//! - BIC = n·ln(SSR/n) + k·ln n (a heavier price per parameter: it prefers the
//!   smaller model unless the data clearly ask for more);
//! - Akaike weights exp(−ΔAICc/2), normalised: the relative support of each model
//!   (by AIC when a fit has too few residuals for AICc: one criterion for all);
//! - for nested pairs (the smaller model a special case of the larger, same data), the
//!   F-test F = ((SSR_r − SSR_f)/(k_f − k_r)) / (SSR_f/(n − k_f)) and its p-value: a
//!   small p says the extra parameters lower the cost by more than noise would.
//!
//! The figures must come from fits of the same residuals (same data, same scales):
//! that is the caller's to ensure — [`crate::identify::selection`] checks it for
//! identifications, [`crate::estimation::friction_law`] fits every law to one map.
//! K. P. Burnham, D. R. Anderson, *Model Selection and Multimodel Inference*, 2nd ed.,
//! Springer 2002, §2.2 (AIC), §2.4 (AICc), §2.9 (Akaike weights), §6.4 (BIC).

use serde::Serialize;
use statrs::distribution::{ContinuousCDF, FisherSnedecor};

/// One fit's plain figures: what the criteria are computed from.
#[derive(Clone, Debug, PartialEq)]
pub struct Figures {
    /// The fit's label (its file, its law).
    pub label: String,
    /// The fitted parameters' names (they decide nesting in [`compare`]).
    pub fitted: Vec<String>,
    /// Residuals n.
    pub n: usize,
    /// Fitted parameters k.
    pub k: usize,
    /// The cost: the sum of squared residuals, > 0.
    pub cost: f64,
}

/// One fit's figures and criteria.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Candidate {
    /// The result's label (its file).
    pub label: String,
    /// The fitted parameters.
    pub fitted: Vec<String>,
    /// Residuals n, fitted parameters k, the cost.
    pub n: usize,
    pub k: usize,
    pub cost: f64,
    pub aic: f64,
    /// `None` when n − k − 1 ≤ 0 (the correction is undefined).
    pub aicc: Option<f64>,
    pub bic: f64,
    /// The ranking criterion ([`Selection::criterion`]) minus the lowest of all.
    pub delta: f64,
    /// Akaike weight: the relative support of this model among those compared.
    pub weight: f64,
}

/// The F-test of a nested pair.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Nested {
    /// The smaller (restricted) and the larger (full) result's labels.
    pub restricted: String,
    pub full: String,
    /// The parameters the full fit adds.
    pub added: Vec<String>,
    pub f: f64,
    /// Degrees of freedom (k_f − k_r, n − k_f).
    pub df: (usize, usize),
    pub p_value: f64,
    /// The full fit's cost is above the restricted one's, which it contains: it
    /// stopped short of its optimum (F is then 0, and says nothing).
    pub full_stopped_short: bool,
}

impl Nested {
    /// What the test says, in words.
    pub fn verdict(&self) -> &'static str {
        if self.full_stopped_short {
            "but its cost is above the smaller fit's, which it contains: it stopped short of its optimum (more --max-iters or --starts), and the test says nothing"
        } else if self.p_value < 0.05 {
            "the data ask for it"
        } else {
            "not supported by the data"
        }
    }
}

/// The comparison of several fits.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Selection {
    /// What ranks them: `aicc`, or `aic` when a fit has too few residuals for the
    /// correction (n ≤ k + 1) — one criterion for all, never a mix.
    pub criterion: &'static str,
    /// By the criterion, best first.
    pub candidates: Vec<Candidate>,
    pub nested: Vec<Nested>,
}

/// Why figures cannot be compared.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum InformationError {
    #[error("no fit to compare")]
    Empty,
    #[error("{label}: cost {cost} with {n} residuals: nothing to compare (a zero cost is an exact fit, where AIC is −∞)")]
    Degenerate { label: String, cost: f64, n: usize },
}

/// Compares fits, taking a pair as nested when the smaller one's fitted names are all
/// among the larger one's ([`by_names`]).
pub fn compare(figures: Vec<Figures>) -> Result<Selection, InformationError> {
    compare_nested(figures, by_names)
}

/// Compares fits, with `nesting(restricted, full)` saying whether `restricted` is a
/// special case of `full` and, if so, what `full` adds (in words or names).
pub fn compare_nested(
    figures: Vec<Figures>,
    nesting: impl Fn(&Candidate, &Candidate) -> Option<Vec<String>>,
) -> Result<Selection, InformationError> {
    if figures.is_empty() {
        return Err(InformationError::Empty);
    }
    if let Some(f) = figures
        .iter()
        .find(|f| !(f.cost.is_finite() && f.cost > 0.0) || f.n == 0)
    {
        return Err(InformationError::Degenerate {
            label: f.label.clone(),
            cost: f.cost,
            n: f.n,
        });
    }
    let mut candidates: Vec<Candidate> = figures.into_iter().map(candidate).collect();
    let corrected = candidates.iter().all(|c| c.aicc.is_some());
    let score = |c: &Candidate| {
        if corrected {
            c.aicc.unwrap_or(c.aic)
        } else {
            c.aic
        }
    };
    let best = candidates.iter().map(score).fold(f64::INFINITY, f64::min);
    for c in &mut candidates {
        c.delta = score(c) - best;
    }
    let total: f64 = candidates.iter().map(|c| (-0.5 * c.delta).exp()).sum();
    for c in &mut candidates {
        c.weight = (-0.5 * c.delta).exp() / total;
    }
    let mut nested = Vec::new();
    for r in &candidates {
        for f in &candidates {
            if r.k >= f.k || f.n <= f.k {
                continue;
            }
            if let Some(added) = nesting(r, f) {
                nested.push(f_test(r, f, added));
            }
        }
    }
    candidates.sort_by(|a, b| a.delta.total_cmp(&b.delta));
    Ok(Selection {
        criterion: if corrected { "aicc" } else { "aic" },
        candidates,
        nested,
    })
}

/// Nesting by names: `restricted` is inside `full` when all its fitted names are among
/// `full`'s; `full` adds the names `restricted` lacks.
pub fn by_names(restricted: &Candidate, full: &Candidate) -> Option<Vec<String>> {
    let inside = restricted.fitted.iter().all(|p| full.fitted.contains(p));
    inside.then(|| {
        full.fitted
            .iter()
            .filter(|p| !restricted.fitted.contains(p))
            .cloned()
            .collect()
    })
}

/// A fit's criteria (Δ and weight left at 0: they depend on the others).
pub fn candidate(f: Figures) -> Candidate {
    let (nf, kf) = (f.n as f64, f.k as f64);
    let fit = nf * (f.cost / nf).ln();
    let aic = fit + 2.0 * kf;
    let aicc = (f.n > f.k + 1).then(|| aic + 2.0 * kf * (kf + 1.0) / (nf - kf - 1.0));
    Candidate {
        label: f.label,
        fitted: f.fitted,
        n: f.n,
        k: f.k,
        cost: f.cost,
        aic,
        aicc,
        bic: fit + kf * nf.ln(),
        delta: 0.0,
        weight: 0.0,
    }
}

/// The F-test of `full` (k_f > k_r, n > k_f) against `restricted`, a special case of it.
pub fn f_test(restricted: &Candidate, full: &Candidate, added: Vec<String>) -> Nested {
    let (r, f) = (restricted, full);
    let df = (f.k - r.k, f.n - f.k);
    let stat = ((r.cost - f.cost).max(0.0) / df.0 as f64) / (f.cost / df.1 as f64);
    let p_value = FisherSnedecor::new(df.0 as f64, df.1 as f64)
        .map(|d| 1.0 - d.cdf(stat))
        .unwrap_or(f64::NAN);
    Nested {
        restricted: r.label.clone(),
        full: f.label.clone(),
        added,
        f: stat,
        df,
        p_value,
        full_stopped_short: f.cost > r.cost * (1.0 + 1e-9),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figures(label: &str, fitted: &[&str], n: usize, cost: f64) -> Figures {
        Figures {
            label: label.into(),
            fitted: fitted.iter().map(|s| s.to_string()).collect(),
            n,
            k: fitted.len(),
            cost,
        }
    }

    #[test]
    fn criteria_follow_their_definitions() {
        let c = candidate(figures("a", &["x", "y", "z"], 20, 4.0));
        let fit = 20.0 * (0.2f64).ln();
        assert!((c.aic - (fit + 6.0)).abs() < 1e-12);
        assert!((c.aicc.unwrap() - (c.aic + 24.0 / 16.0)).abs() < 1e-12);
        assert!((c.bic - (fit + 3.0 * 20f64.ln())).abs() < 1e-12);
        assert_eq!(candidate(figures("b", &["x", "y"], 3, 1.0)).aicc, None);
    }

    #[test]
    fn one_fit_without_aicc_ranks_all_by_aic() {
        let s = compare(vec![
            figures("small", &["x"], 3, 1.0),
            figures("big", &["x", "y"], 3, 0.5),
        ])
        .unwrap();
        assert_eq!(s.criterion, "aic");
        let big = s.candidates.iter().find(|c| c.label == "big").unwrap();
        let small = s.candidates.iter().find(|c| c.label == "small").unwrap();
        assert!((big.delta - small.delta - (big.aic - small.aic)).abs() < 1e-12);
        // n − k_f = 1: the F-test is still defined.
        assert_eq!(s.nested.len(), 1);
    }

    #[test]
    fn a_custom_nesting_names_what_the_full_model_adds() {
        let s = compare_nested(
            vec![
                figures("line", &["a", "b"], 30, 10.0),
                figures("two lines", &["a1", "b1", "a2"], 30, 5.0),
            ],
            |r, f| (r.label == "line" && f.label == "two lines").then(|| vec!["a1 ≠ a2".into()]),
        )
        .unwrap();
        assert_eq!(s.nested.len(), 1);
        let t = &s.nested[0];
        assert_eq!(t.added, vec!["a1 ≠ a2".to_string()]);
        // F = (5/1)/(5/27) = 27.
        assert!((t.f - 27.0).abs() < 1e-9 && t.p_value < 1e-4, "{t:?}");
        // By names they do not nest.
        let s = compare(vec![
            figures("line", &["a", "b"], 30, 10.0),
            figures("two lines", &["a1", "b1", "a2"], 30, 5.0),
        ])
        .unwrap();
        assert!(s.nested.is_empty());
    }

    #[test]
    fn zero_costs_and_no_fits_are_refused() {
        assert_eq!(compare(vec![]), Err(InformationError::Empty));
        let e = compare(vec![figures("exact", &["x"], 5, 0.0)]).unwrap_err();
        assert!(matches!(e, InformationError::Degenerate { .. }), "{e}");
        assert!(compare(vec![figures("nan", &["x"], 5, f64::NAN)]).is_err());
    }
}
