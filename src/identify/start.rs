//! Where the search starts: the given parameter set, or — where an experiment offers
//! a direct estimate made before any simulation (a servo trace's inverse-dynamics
//! least squares) — that estimate for the fitted parameters it gives. The default
//! bounds then lie around the estimate, and a Nelder–Mead simplex starts small
//! ([`crate::identify::plan::Plan::from_estimate`]): the estimate is close, where the given
//! values may be guesses.

use crate::identify::config::StartChoice;
use crate::identify::result::starts::StartEstimate;
use std::collections::BTreeMap;

use crate::identify::config::Config;
use crate::identify::result::warning::Warning;
use crate::identify::setup::selection;
use crate::model::Params;
use crate::objectives::{Estimated, SetupError, Source, Stage};

/// Where the search starts.
pub struct Start {
    /// The given parameter set with the estimates written in.
    pub base: Params,
    /// The estimates used (empty with [`StartChoice::Given`] or when no experiment
    /// offers one).
    pub estimates: Vec<StartEstimate>,
    /// Estimates that were not used (unphysical values from poor data).
    pub warnings: Vec<Warning>,
}

/// The start of `config`'s search for the fitted `fit`. A parameter estimated by
/// several experiments takes the first one's value.
pub fn start(config: &Config, fit: &[String]) -> Result<Start, SetupError> {
    let mut out = Start {
        base: config.base.clone(),
        estimates: Vec::new(),
        warnings: Vec::new(),
    };
    if config.start == StartChoice::Given {
        return Ok(out);
    }
    for spec in &config.experiments {
        let source = Source {
            file: &spec.source,
            experiment: &spec.experiment,
        };
        for (kind, _) in selection(spec, Stage::Search)? {
            if let Some(estimate) = kind.first_estimate(&source, &out.base)? {
                out.apply(&spec.source, kind.name(), estimate, fit);
            }
        }
    }
    Ok(out)
}

impl Start {
    /// Writes the fitted, not yet estimated values of `estimate` into the start, or
    /// warns when they make the set unphysical.
    fn apply(&mut self, source: &str, objective: &str, estimate: Estimated, fit: &[String]) {
        let values: BTreeMap<String, f64> = estimate
            .values
            .into_iter()
            .filter(|(name, _)| fit.contains(name) && !self.estimated(name))
            .collect();
        if values.is_empty() {
            return;
        }
        let mut trial = self.base.clone();
        let valid =
            values.iter().all(|(n, &v)| trial.set(n, v).is_ok()) && trial.validate().is_ok();
        if !valid {
            self.warnings.push(Warning::EstimateUnused {
                source: source.into(),
                values: values
                    .iter()
                    .map(|(n, v)| format!("{n} = {v:.4e}"))
                    .collect::<Vec<_>>()
                    .join(", "),
            });
            return;
        }
        self.base = trial;
        self.estimates.push(StartEstimate {
            source: source.into(),
            objective: objective.into(),
            method: estimate.method,
            values,
        });
    }

    fn estimated(&self, name: &str) -> bool {
        self.estimates.iter().any(|e| e.values.contains_key(name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    fn empty_start() -> Start {
        Start {
            base: presets::load("direct-drive").unwrap(),
            estimates: Vec::new(),
            warnings: Vec::new(),
        }
    }

    fn estimated(values: &[(&str, f64)]) -> Estimated {
        Estimated {
            values: values.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
            method: "test".into(),
        }
    }

    #[test]
    fn an_estimate_starts_the_fitted_parameters_only() {
        let mut s = empty_start();
        let jt = s.base.jt;
        let fit = vec!["ft".to_string(), "Tload".to_string()];
        s.apply(
            "a.json",
            "servo_trace",
            estimated(&[("Jt", 2.0 * jt), ("ft", 3.0), ("Tload", -1.5)]),
            &fit,
        );
        assert_eq!(s.base.jt, jt, "Jt is not fitted: it keeps its value");
        assert_eq!((s.base.ft, s.base.tload), (3.0, -1.5));
        assert_eq!(s.estimates[0].values.len(), 2);
        assert!(s.warnings.is_empty());
        // A second experiment does not overwrite the first one's estimates.
        s.apply("b.json", "servo_trace", estimated(&[("ft", 4.0)]), &fit);
        assert_eq!(s.base.ft, 3.0);
        assert_eq!(s.estimates.len(), 1);
    }

    #[test]
    fn an_unphysical_estimate_is_not_used_and_said() {
        let mut s = empty_start();
        let ft = s.base.ft;
        let fit = vec!["ft".to_string()];
        s.apply("a.json", "servo_trace", estimated(&[("ft", -2.0)]), &fit);
        assert_eq!(s.base.ft, ft);
        assert!(s.estimates.is_empty());
        assert_eq!(s.warnings.len(), 1);
        assert!(
            s.warnings[0].to_string().contains("a.json"),
            "{}",
            s.warnings[0]
        );
    }
}
