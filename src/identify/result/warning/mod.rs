//! What the user should know about a fit, typed: each warning has a stable code (for
//! scripts and tests) and a message (for people). The result file carries both; the
//! command line may add which option to change.

use std::fmt;

use serde::{Deserialize, Serialize};

mod message;

/// Which end of its bounds a parameter ended at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    Lower,
    Upper,
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::Lower => "lower",
            Side::Upper => "upper",
        })
    }
}

/// A warning about an identification.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "code", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Warning {
    /// Fewer residuals than parameters: Gauss–Newton cannot run.
    MethodSwitched { residuals: usize, parameters: usize },
    /// The checkpoint could not be written at the end.
    CheckpointNotWritten { path: String, error: String },
    /// The search was stopped (Ctrl-C or an evaluation budget).
    Interrupted { evaluations: usize },
    /// Some trial parameter sets could not be evaluated.
    EvaluationFailures { example: String },
    /// A start ended at a different solution of the same cost.
    DistinctSolution { start: usize, solution: String },
    /// A parameter ended at one of its bounds.
    AtBound { name: String, side: Side },
    /// The fitted model misses measured resonances by more than 1 Hz.
    ResonanceMiss { source: String, max_miss_hz: f64 },
    /// A servo trace's replay does not follow the record: its position error's RMS
    /// is more than a tenth of the span the record's position covers (m or rad).
    NotFollowed {
        source: String,
        position_rms: f64,
        position_span: f64,
    },
    /// The phase errors of a complex frequency response grow with frequency like a
    /// delay the manifest does not state (`delay_s`): removing it would halve them.
    PhaseDelay { source: String, delay_s: f64 },
    /// A parameter has no effect on the residuals.
    NoEffect { name: String },
    /// Fewer residuals than parameters: they cannot all be determined.
    TooFewResiduals { residuals: usize, parameters: usize },
    /// JᵀJ is singular: a combination of parameters is not determined.
    Singular {
        conditioning: f64,
        names: Vec<String>,
    },
    /// Two parameters are correlated beyond the limit.
    Correlated {
        a: String,
        b: String,
        correlation: f64,
    },
    /// The standard errors of a fit to a closed-loop simulation are lower bounds
    /// (removed by a bootstrap's intervals, [`crate::identify::intervals::resample::attach`]).
    RoughCost,
    /// An experiment's direct estimate of where to start was not used.
    EstimateUnused { source: String, values: String },
    /// `--model auto` went on to the nonlinear fit: the nonlinear virtual test at the
    /// linear fit puts the resonances more than 0.5 % from the measured ones.
    Escalated {
        source: String,
        model_hz: Vec<f64>,
        measured_hz: Vec<f64>,
        /// The linear fit's own peaks ([`crate::identify::result::NonlinearCheck`]).
        #[serde(default)]
        linear_hz: Vec<f64>,
        max_miss_hz: f64,
        max_miss_percent: f64,
        linear_misfit_db: f64,
        /// The nonlinear parameters the correction takes as given (name = value, SI),
        /// which this record does not determine.
        #[serde(default)]
        assumed: String,
    },
    /// `--model auto` kept the linear fit: it explains the gain curve within the
    /// curve's own noise, so the nonlinear test's disagreement is not the data's.
    LinearStands {
        source: String,
        linear_misfit_db: f64,
        noise_db: f64,
        max_miss_percent: f64,
        /// The nonlinear parameters the test would have assumed.
        assumed: String,
    },
    /// The nonlinear corrections ended at their limit still moving: the result is
    /// not an optimum; `moved` gives each parameter's relative move in the last
    /// correction; `widened` those whose standard error was widened to that move,
    /// `undetermined` those it withdrew (a move beyond a quarter of the value).
    CorrectionsNotConverged {
        corrections: usize,
        moved: Vec<(String, f64)>,
        #[serde(default)]
        widened: Vec<String>,
        undetermined: Vec<String>,
    },
    /// By plan: no record determines these parameters, nor all together (their
    /// information is nil, or a combination of the others'): held at their start
    /// values, without an interval.
    NotDetermined { names: Vec<String> },
    /// A profile stays below the 95 % level up to the parameter's bound on one side:
    /// the data bound it on the other side only; `family` are the other fitted
    /// parameters that moved along it (ratio of largest to smallest value).
    ProfileOpen {
        name: String,
        side: Side,
        bound: f64,
        family: Vec<(String, f64)>,
    },
    /// `replicates` of a bootstrap's `of` ran to the parameter's bound on `side`:
    /// the records do not bound it there, and it is not determined (no interval).
    BootstrapAtBound {
        name: String,
        side: Side,
        replicates: usize,
        of: usize,
    },
    /// A point of a profile fits better than the fit itself: the search stopped
    /// short of the optimum.
    ProfileBetterFit {
        name: String,
        value: f64,
        cost: f64,
        fit_cost: f64,
    },
}

impl Warning {
    /// The stable code, as in the result file (`at_bound`, `correlated`…).
    pub fn code(&self) -> &'static str {
        match self {
            Warning::MethodSwitched { .. } => "method_switched",
            Warning::CheckpointNotWritten { .. } => "checkpoint_not_written",
            Warning::Interrupted { .. } => "interrupted",
            Warning::EvaluationFailures { .. } => "evaluation_failures",
            Warning::DistinctSolution { .. } => "distinct_solution",
            Warning::AtBound { .. } => "at_bound",
            Warning::ResonanceMiss { .. } => "resonance_miss",
            Warning::NotFollowed { .. } => "not_followed",
            Warning::PhaseDelay { .. } => "phase_delay",
            Warning::NoEffect { .. } => "no_effect",
            Warning::TooFewResiduals { .. } => "too_few_residuals",
            Warning::Singular { .. } => "singular",
            Warning::Correlated { .. } => "correlated",
            Warning::RoughCost => "rough_cost",
            Warning::EstimateUnused { .. } => "estimate_unused",
            Warning::Escalated { .. } => "escalated",
            Warning::LinearStands { .. } => "linear_stands",
            Warning::CorrectionsNotConverged { .. } => "corrections_not_converged",
            Warning::NotDetermined { .. } => "not_determined",
            Warning::ProfileOpen { .. } => "profile_open",
            Warning::BootstrapAtBound { .. } => "bootstrap_at_bound",
            Warning::ProfileBetterFit { .. } => "profile_better_fit",
        }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&message::text(self))
    }
}

/// A typed value with its message, as written to result files: the value's own fields
/// (with its `code`) and `message`, its text.
#[derive(Clone, Debug, PartialEq)]
pub struct Coded<T>(pub T);

impl<T: Serialize + fmt::Display> Serialize for Coded<T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut value = crate::io::json::value(&self.0).map_err(serde::ser::Error::custom)?;
        if let serde_json::Value::Object(map) = &mut value {
            map.insert("message".into(), self.0.to_string().into());
        }
        value.serialize(s)
    }
}

impl<'de, T: serde::de::DeserializeOwned> Deserialize<'de> for Coded<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut value = serde_json::Value::deserialize(d)?;
        if let serde_json::Value::Object(map) = &mut value {
            map.remove("message");
        }
        serde_json::from_value(value)
            .map(Coded)
            .map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_warning_round_trips_with_its_code_and_message() {
        let w = Warning::AtBound {
            name: "Kw".into(),
            side: Side::Upper,
        };
        let text = serde_json::to_string(&Coded(w.clone())).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["code"], "at_bound");
        assert_eq!(v["code"], w.code());
        assert!(v["message"]
            .as_str()
            .unwrap()
            .contains("Kw ended at its upper bound"));
        let back: Coded<Warning> = serde_json::from_str(&text).unwrap();
        assert_eq!(back.0, w);
        let unit: Coded<Warning> =
            serde_json::from_str(r#"{"code": "rough_cost", "message": "…"}"#).unwrap();
        assert_eq!(unit.0, Warning::RoughCost);
    }
}
