//! Every law the data allow, fitted and compared by the information criteria: which
//! law the map supports.
//!
//! The laws nest — each smaller one is a special case of a larger one — though not
//! always by parameter names, so the F-tests are of these pairs, with what the larger
//! law adds:
//!
//! | restricted | full | the full law adds |
//! |---|---|---|
//! | coulomb | stribeck | Fs, vs, delta |
//! | coulomb | coulomb_asymmetric | Fv_pos ≠ Fv_neg (Fc_pos = Fc + Fo, Fc_neg = Fc − Fo) |
//! | coulomb | stribeck_asymmetric | both of the above, per direction |
//! | coulomb_asymmetric | stribeck_asymmetric | Fs_pos, vs_pos, Fs_neg, vs_neg, delta |
//! | stribeck | stribeck_asymmetric | Fv_pos ≠ Fv_neg, vs_pos ≠ vs_neg, unequal rises |
//!
//! Where the smaller law is the larger one with a rise of 0, vs and delta are not
//! determined under it, and the F-test's p-value is only indicative (the test's
//! regularity conditions fail); AICc does not need them.
//!
//! **The cost floor.** A cost below rounding carries no information, but its
//! logarithm would rank exact fits by their rounding errors. Each law's cost enters
//! the criteria as at least n·([`COST_FLOOR`]·RMS effort)²: below that, laws tie on
//! fit and the one with fewer parameters wins. Measured efforts are never that exact.

use serde::Serialize;

use super::law::Law;
use super::{fit, FitError, LawFit, MapProblem};
use crate::estimation::information::{self, Candidate, Figures, Selection};

/// The smallest residual that counts, relative to the efforts' RMS.
pub const COST_FLOOR: f64 = 1e-9;

/// A law that was not fitted, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Refused {
    pub law: Law,
    pub reason: String,
}

/// The laws fitted to a map and their comparison.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// The laws the data allow, in the order of [`Law::ALL`] — those not determined
    /// ([`LawFit::determined`]) too, ranked apart: they are not in `selection`.
    pub fits: Vec<LawFit>,
    /// The others.
    pub refused: Vec<Refused>,
    /// AIC, AICc, BIC, Akaike weights and the F-tests of nested laws, labelled by the
    /// laws' names, best first.
    pub selection: Selection,
    /// The law the data support: the lowest AICc (AIC when a fit lacks AICc).
    pub selected: Law,
    /// The cost below which laws tie on fit ([`COST_FLOOR`]), (N·m)² or N².
    pub cost_floor: f64,
}

impl Comparison {
    /// The fit of `law`, if made.
    pub fn fit(&self, law: Law) -> Option<&LawFit> {
        self.fits.iter().find(|f| f.law == law)
    }
}

/// Fits every law the map (runs' mean `speed` and `effort`) allows and compares them.
/// Fails only when the map fails [`super::check_map`] (then no law can be fitted).
pub fn fit_all(speed: &[f64], effort: &[f64]) -> Result<Comparison, MapProblem> {
    super::check_map(speed, effort)?;
    let mut fits = Vec::new();
    let mut refused = Vec::new();
    for law in Law::ALL {
        match fit(law, speed, effort) {
            Ok(f) => fits.push(f),
            Err(FitError::Map(e)) => return Err(e),
            Err(e) => refused.push(Refused {
                law,
                reason: e.to_string(),
            }),
        }
    }
    let n = speed.len() as f64;
    let rms = (effort.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
    let cost_floor = (n * (COST_FLOOR * rms).powi(2)).max(f64::MIN_POSITIVE);
    let figures = fits
        .iter()
        .filter(|f| f.determined)
        .map(|f| Figures {
            label: f.law.name().into(),
            fitted: f.law.parameters().iter().map(|s| s.to_string()).collect(),
            n: f.n,
            k: f.k,
            cost: f.ssr.max(cost_floor),
        })
        .collect();
    // The map passed its checks, so Coulomb's law (3 parameters, at least 4 runs) is
    // always fitted and determined (linear), and the floor keeps every cost positive.
    let selection = information::compare_nested(figures, nesting)
        .expect("the Coulomb law is fitted to every checked map, at a positive cost");
    let selected = Law::from_name(&selection.candidates[0].label)
        .expect("the candidates are labelled with the laws' names");
    Ok(Comparison {
        fits,
        refused,
        selection,
        selected,
        cost_floor,
    })
}

/// Whether `restricted` is a special case of `full`, and what `full` adds.
fn nesting(restricted: &Candidate, full: &Candidate) -> Option<Vec<String>> {
    use Law::*;
    let law = |c: &Candidate| Law::from_name(&c.label);
    let added: &[&str] = match (law(restricted)?, law(full)?) {
        (Coulomb, Stribeck) => &["Fs", "vs", "delta"],
        (Coulomb, CoulombAsymmetric) => &["Fv_pos ≠ Fv_neg"],
        (Coulomb, StribeckAsymmetric) => &[
            "Fv_pos ≠ Fv_neg",
            "Fs_pos",
            "vs_pos",
            "Fs_neg",
            "vs_neg",
            "delta",
        ],
        (CoulombAsymmetric, StribeckAsymmetric) => {
            &["Fs_pos", "vs_pos", "Fs_neg", "vs_neg", "delta"]
        }
        (Stribeck, StribeckAsymmetric) => &[
            "Fv_pos ≠ Fv_neg",
            "vs_pos ≠ vs_neg",
            "Fs_pos − Fc_pos ≠ Fs_neg − Fc_neg",
        ],
        _ => return None,
    };
    Some(added.iter().map(|s| s.to_string()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What each nested pair adds is the difference of their parameter counts.
    #[test]
    fn each_nesting_adds_the_difference_in_parameters() {
        let candidate = |law: Law| {
            information::candidate(Figures {
                label: law.name().into(),
                fitted: vec![],
                n: 32,
                k: law.parameters().len(),
                cost: 1.0,
            })
        };
        let mut pairs = 0;
        for r in Law::ALL {
            for f in Law::ALL {
                if let Some(added) = nesting(&candidate(r), &candidate(f)) {
                    pairs += 1;
                    assert_eq!(
                        added.len(),
                        f.parameters().len() - r.parameters().len(),
                        "{r} in {f}"
                    );
                }
            }
        }
        assert_eq!(pairs, 5);
    }
}
