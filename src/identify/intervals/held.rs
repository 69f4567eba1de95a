//! Held parameters' uncertainty carried into the fit ("consider" parameters, as
//! orbit determination calls them). A fit holds most of the model at assumed
//! values — a stiffness from a catalogue, an inertia from a drawing — and its
//! standard errors take them as exact. Where one of them is wrong the fit absorbs
//! it. Given a held parameter's range value·(1 ± h), the fit is repeated with it at
//! each end, from the fit's values, by the same search: half the difference of the
//! two results is the fitted parameters' shift across the range ([`Held`]), which
//! `rtid predict` uses to move them as it draws the held one, so a prediction keeps
//! what the data determine while the parts move.
//!
//! Not the linear step −(JᵀJ)⁻¹Jᵀ·Δr: where the model misses the record (the
//! linear model on the worm's frequency response, cost 82 on 158 lines) the
//! residuals' curvature counts, and for Jt ± 10 % that step gave Kw +12 % where the
//! refits give +24 % and −19 %. On a closed-loop simulation's rough cost a refit
//! stops where the roughness lets it, so there the bootstrap draws the held
//! parameters instead ([`super::resample`]).

use std::collections::BTreeMap;

use crate::identify::error::IdentifyError;
use crate::identify::result::held::Held;
use crate::identify::result::IdentifyResult;
use crate::identify::search::problem::Monitor;
use crate::identify::search::search;
use crate::identify::search::settings::Settings;
use crate::identify::space::{Bound, ParamSpace, SpaceError};
use crate::model::Params;
use crate::objectives::{Objective, ObjectiveError};

/// Why the shifts cannot be computed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HeldError {
    #[error("--uncertain: the fit was stopped before it converged")]
    Interrupted,
    #[error("--uncertain {0}: {0} is fitted; its uncertainty is the fit's")]
    Fitted(String),
    #[error("--uncertain: {0}")]
    Space(#[from] SpaceError),
    #[error("--uncertain {name}: the fit with {name} at {value:e} failed: {error}")]
    Refit {
        name: String,
        value: f64,
        error: IdentifyError,
    },
}

/// What the shifts are computed from: the fit, its parameter set, the objective it
/// minimises and its search's settings.
pub struct Fit<'a> {
    pub result: &'a IdentifyResult,
    pub params: &'a Params,
    pub objective: &'a dyn Objective,
    pub settings: Settings,
}

/// Each held parameter (name, value, relative half-width) with the fit's shifts;
/// the refits run in parallel.
pub fn shifts(fit: &Fit, held: &[(String, f64, f64)]) -> Result<Vec<Held>, HeldError> {
    use rayon::prelude::*;
    if fit.result.interrupted {
        return Err(HeldError::Interrupted);
    }
    if let Some((name, ..)) = (held.iter()).find(|h| fit.result.parameters.contains_key(&h.0)) {
        return Err(HeldError::Fitted(name.clone()));
    }
    let names: Vec<String> = fit.result.parameters.keys().cloned().collect();
    let ends: Vec<(usize, f64)> = (0..held.len())
        .flat_map(|i| [(i, 1.0), (i, -1.0)])
        .collect();
    let refits = ends
        .par_iter()
        .map(|&(i, sign)| {
            let (name, value, half) = &held[i];
            let at = value * (1.0 + sign * half);
            refit(fit, &names, name, at).map_err(|e| match e {
                RefitError::Space(e) => HeldError::Space(e),
                RefitError::Fit(error) => HeldError::Refit {
                    name: name.clone(),
                    value: at,
                    error,
                },
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((held.iter().zip(refits.chunks(2)))
        .map(|((name, value, half), ends)| Held {
            name: name.clone(),
            value: *value,
            half_width: *half,
            shifts: (names.iter().enumerate())
                .map(|(j, n)| (n.clone(), (ends[0][j] - ends[1][j]) / 2.0))
                .collect::<BTreeMap<_, _>>(),
        })
        .collect())
}

enum RefitError {
    Space(SpaceError),
    Fit(IdentifyError),
}

/// The fit repeated from its values with `held` at `at`: the fitted values, in
/// `names`' order.
fn refit(fit: &Fit, names: &[String], held: &str, at: f64) -> Result<Vec<f64>, RefitError> {
    let mut base = fit.params.clone();
    base.set(held, at)
        .map_err(|e| RefitError::Fit(ObjectiveError::from(e).into()))?;
    let bounds: Vec<(String, Bound)> = (names.iter())
        .map(|n| {
            let [lo, hi] = fit.result.bounds[n];
            (n.clone(), Bound { lo, hi })
        })
        .collect();
    let space = ParamSpace::new(base, names, &bounds).map_err(RefitError::Space)?;
    let settings = Settings {
        starts: 1,
        max_evaluations: None,
        ..fit.settings
    };
    let monitor = Monitor::default();
    search(&space, fit.objective, &settings, &monitor, &[], &|_| {});
    monitor.best().map(|b| b.values).ok_or_else(|| {
        RefitError::Fit(IdentifyError::NothingEvaluated(
            monitor.failure().unwrap_or_default(),
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    /// y_i = (Kw/3.1e5)·a_i + (Kg/850)·b_i + Jt·c_i: with Kw and Kg fitted and Jt
    /// held, the fit's response to Jt is the linear least squares' step exactly.
    struct Linear {
        rows: Vec<[f64; 3]>,
        y: Vec<f64>,
    }

    fn get(p: &Params, n: &str) -> f64 {
        p.get(n).unwrap().unwrap()
    }

    impl Objective for Linear {
        fn name(&self) -> &'static str {
            "linear"
        }
        fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
            let (kw, kg, jt) = (get(p, "Kw") / 3.1e5, get(p, "Kg") / 850.0, get(p, "Jt"));
            Ok((self.rows.iter().zip(&self.y))
                .map(|(a, y)| kw * a[0] + kg * a[1] + jt * a[2] - y)
                .collect())
        }
        fn len(&self) -> usize {
            self.y.len()
        }
        fn scale(&self) -> String {
            "one unit".into()
        }
    }

    #[test]
    fn the_shift_is_the_least_squares_response_to_the_held_parameter() {
        let rows: Vec<[f64; 3]> = (0..20)
            .map(|i| {
                let t = i as f64 / 19.0;
                [1.0, t, t * t + 0.5]
            })
            .collect();
        let y = rows.iter().map(|a| a[0] + a[1] + 0.1 * a[2]).collect();
        let o = Linear { rows, y };
        let mut p = presets::load("worm-gear").unwrap();
        p.set("Jt", 0.1).unwrap();
        let mut result: IdentifyResult = serde_json::from_str(include_str!(
            "../../prediction/tests/two_parameter_fit.json"
        ))
        .unwrap();
        result.parameters = [("Kw".into(), 3.1e5), ("Kg".into(), 850.0)].into();
        result.bounds = [("Kw".into(), [3.1e4, 3.1e6]), ("Kg".into(), [85.0, 8500.0])].into();
        let fit = Fit {
            result: &result,
            params: &p,
            objective: &o,
            settings: Settings::default(),
        };
        let held = shifts(&fit, &[("Jt".into(), 0.1, 0.2)]).unwrap();
        // Jt ± 0.02 adds ±0.02·(t² + 0.5), which Kw and Kg absorb by least squares:
        // in the model's units (Kw/3.1e5, Kg/850) the shift is −(AᵀA)⁻¹Aᵀ·0.02·c.
        let a = nalgebra::DMatrix::from_fn(20, 2, |i, j| o.rows[i][j]);
        let c = nalgebra::DVector::from_fn(20, |i, _| 0.02 * o.rows[i][2]);
        let step = -(a.transpose() * &a).try_inverse().unwrap() * a.transpose() * c;
        let kw = held[0].shifts["Kw"] / 3.1e5;
        let kg = held[0].shifts["Kg"] / 850.0;
        assert!((kw - step[0]).abs() < 1e-6, "{kw} {step}");
        assert!((kg - step[1]).abs() < 1e-6, "{kg} {step}");
        let s = held[0].shifts["Kg"];
        assert!((held[0].spread("Kg") - s.abs() / 3f64.sqrt()).abs() < 1e-12);
    }
}
