//! The 95 % interval of a fitted parameter that holds, as the result file gives it:
//! the bootstrap's, the standard error widened by the held ranges' shifts, or the
//! standard error alone where it is not a lower bound. `rtid identify` prints it
//! first; `rtid tune` varies the machine over it.

use super::IdentifyResult;
use crate::model::Spread;

/// A fitted parameter's interval, or why it has none.
#[derive(Clone, Debug, PartialEq)]
pub enum FitInterval {
    /// From `lower` to `upper` (SI), and what it comes from.
    Bounds {
        lower: f64,
        upper: f64,
        from: String,
    },
    /// No interval: why (no record determines it, no standard error).
    NotDetermined(&'static str),
    /// The standard error is a lower bound and no bootstrap gave an interval.
    LowerBound,
}

impl IdentifyResult {
    /// The interval of fitted parameter `name` (`None` where the fit did not fit it).
    pub fn interval(&self, name: &str) -> Option<FitInterval> {
        let v = *self.parameters.get(name)?;
        let undetermined = self
            .plan
            .as_ref()
            .is_some_and(|p| p.undetermined.iter().any(|n| n == name));
        if undetermined {
            return Some(FitInterval::NotDetermined("no record determines it"));
        }
        if let Some(i) = self.resampling.as_ref().and_then(|s| s.intervals.get(name)) {
            if i.at_bound.is_some() {
                return Some(FitInterval::NotDetermined(
                    "its bootstrap replicates ran to a bound",
                ));
            }
            let n = self.resampling.as_ref().map_or(0, |s| s.fitted);
            return Some(FitInterval::Bounds {
                lower: i.lower,
                upper: i.upper,
                from: format!("bootstrap, {n} replicates"),
            });
        }
        let lower_bounds = self.uncertainty.as_ref().is_some_and(|u| u.lower_bounds);
        let around = |s: f64, from: &str| FitInterval::Bounds {
            lower: v - 1.96 * s,
            upper: v + 1.96 * s,
            from: from.into(),
        };
        Some(match self.standard_error(name) {
            None => FitInterval::NotDetermined("no standard error"),
            Some(_) if lower_bounds => FitInterval::LowerBound,
            Some(se) if !self.held.is_empty() => {
                let held: f64 = self.held.iter().map(|h| h.spread(name).powi(2)).sum();
                around((se * se + held).sqrt(), "standard error and held ranges")
            }
            Some(se) => around(se, "±1.96 standard errors"),
        })
    }
}

/// What a fit says of how far the machine may be from its values: each fitted
/// parameter's interval as a ratio, each held range it carried; and the fitted
/// parameters without an interval, with the reason.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FitSpreads {
    pub spreads: Vec<Spread>,
    pub without: Vec<(String, String)>,
}

impl IdentifyResult {
    /// The fit's [`FitSpreads`].
    pub fn spreads(&self) -> FitSpreads {
        let mut out = FitSpreads::default();
        for (name, &value) in &self.parameters {
            let why = match self.interval(name) {
                Some(FitInterval::Bounds { lower, upper, from }) => {
                    match Spread::fitted(name, value, lower, upper, &from) {
                        Some(s) => {
                            out.spreads.push(s);
                            continue;
                        }
                        None => format!("its interval ({from}) reaches 0 or misses the value"),
                    }
                }
                Some(FitInterval::NotDetermined(why)) => format!("not determined: {why}"),
                Some(FitInterval::LowerBound) | None => {
                    "no interval: its standard error is a lower bound".into()
                }
            };
            out.without.push((name.clone(), why));
        }
        for h in &self.held {
            if h.half_width > 0.0 {
                let carried = "the range the fit carried";
                out.spreads
                    .push(Spread::held(&h.name, 100.0 * h.half_width, carried));
            } else {
                out.without.push((h.name.clone(), "held exactly".into()));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::result::held::Held;
    use crate::identify::result::resampling::{Interval, Resampling};

    fn shipped() -> IdentifyResult {
        let text = include_str!("../../../fixtures/predict/worm-gear/fit.json");
        serde_json::from_str(text).unwrap()
    }

    #[test]
    fn a_lower_bound_gives_no_interval_and_a_bootstrap_gives_its_own() {
        let mut fit = shipped();
        // The torque curve's standard errors are lower bounds: no interval, named.
        assert_eq!(fit.interval("fm"), Some(FitInterval::LowerBound));
        assert_eq!(fit.interval("Kw"), None);
        let s = fit.spreads();
        assert!(s.spreads.is_empty());
        assert_eq!(s.without.len(), 3);
        assert!(s.without.iter().all(|(_, why)| why.contains("lower bound")));
        // A bootstrap's interval is the one given, as a ratio of the value.
        let fm = fit.parameters["fm"];
        let interval = Interval {
            lower: 0.8 * fm,
            upper: 1.1 * fm,
            standard_error: 0.0,
            bias: 0.0,
            at_bound: None,
        };
        fit.resampling = Some(Resampling {
            method: "residual block bootstrap".into(),
            level: 0.95,
            asked: 12,
            fitted: 12,
            block_lengths: vec![],
            intervals: [("fm".to_string(), interval)].into(),
            values: Default::default(),
            notes: vec![],
        });
        let s = fit.spreads();
        assert_eq!(s.spreads.len(), 1);
        let spread = &s.spreads[0];
        assert!((spread.low - 0.8).abs() < 1e-12 && (spread.high - 1.1).abs() < 1e-12);
        assert!(
            spread.from.contains("bootstrap, 12 replicates"),
            "{spread:?}"
        );
        // A held range the fit carried is a spread; one held exactly is named.
        for (name, half_width) in [("Jt", 0.25), ("Kw", 0.0)] {
            fit.held.push(Held {
                name: name.into(),
                value: 1.0,
                half_width,
                shifts: Default::default(),
            });
        }
        let s = fit.spreads();
        assert!(s.spreads.iter().any(|x| x.name == "Jt" && x.low == 0.75));
        assert!(s
            .without
            .iter()
            .any(|(n, why)| n == "Kw" && why == "held exactly"));
    }
}
