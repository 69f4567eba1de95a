//! What the user should know about a fit, typed: each warning has a stable code (for
//! scripts and tests) and a message (for people). The result file carries both; the
//! command line may add which option to change.

use std::fmt;

use serde::{Deserialize, Serialize};

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
    /// (removed by a bootstrap's intervals, [`super::resample::attach`]).
    RoughCost,
    /// An experiment's direct estimate of where to start was not used.
    EstimateUnused { source: String, values: String },
    /// `--model auto` went on to the nonlinear fit: the nonlinear virtual test at the
    /// linear fit puts the resonances more than 0.5 % from the measured ones.
    Escalated {
        source: String,
        model_hz: Vec<f64>,
        measured_hz: Vec<f64>,
        max_miss_hz: f64,
        max_miss_percent: f64,
        linear_misfit_db: f64,
    },
    /// A profile stays below the 95 % level up to the parameter's bound on one side:
    /// the data bound it on the other side only; `family` are the other fitted
    /// parameters that moved along it (ratio of largest to smallest value).
    ProfileOpen {
        name: String,
        side: Side,
        bound: f64,
        family: Vec<(String, f64)>,
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
            Warning::NoEffect { .. } => "no_effect",
            Warning::TooFewResiduals { .. } => "too_few_residuals",
            Warning::Singular { .. } => "singular",
            Warning::Correlated { .. } => "correlated",
            Warning::RoughCost => "rough_cost",
            Warning::EstimateUnused { .. } => "estimate_unused",
            Warning::Escalated { .. } => "escalated",
            Warning::ProfileOpen { .. } => "profile_open",
            Warning::ProfileBetterFit { .. } => "profile_better_fit",
        }
    }
}

fn hz(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.2}"))
        .collect::<Vec<_>>()
        .join(", ")
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::MethodSwitched { residuals, parameters } => write!(
                f,
                "{residuals} residuals for {parameters} parameters: Gauss–Newton cannot run (JᵀJ singular), Nelder–Mead used instead"
            ),
            Warning::CheckpointNotWritten { path, error } => {
                write!(f, "the checkpoint {path} could not be written: {error}")
            }
            Warning::Interrupted { evaluations } => write!(
                f,
                "the search was stopped after {evaluations} evaluations: this is the best point found so far, not a converged fit (resuming from the checkpoint continues it)"
            ),
            Warning::EvaluationFailures { example } => write!(
                f,
                "some trial parameter sets could not be evaluated, e.g. {example}"
            ),
            Warning::DistinctSolution { start, solution } => write!(
                f,
                "start {start} ended at a different solution ({solution}) with the same cost: the data do not determine a unique solution"
            ),
            Warning::AtBound { name, side } => write!(
                f,
                "{name} ended at its {side} bound: the data pull it further — widen its bounds, or another parameter (fixed now) must change"
            ),
            Warning::ResonanceMiss { source, max_miss_hz } => write!(
                f,
                "{source}: the fitted model misses the measured resonances by up to {max_miss_hz:.1} Hz — the fitted parameters alone cannot reach them"
            ),
            Warning::NoEffect { name } => write!(
                f,
                "{name} has no effect on the residuals: the data say nothing about it"
            ),
            Warning::TooFewResiduals { residuals, parameters } => write!(
                f,
                "{residuals} residuals for {parameters} parameters: the data cannot determine them all"
            ),
            Warning::Singular { conditioning, names } => write!(
                f,
                "JᵀJ is singular (conditioning {conditioning:.1e}): the data cannot separate {}",
                names.join(", ")
            ),
            Warning::Correlated { a, b, correlation } => write!(
                f,
                "{a} and {b} are correlated {correlation:+.3}: the data cannot separate them (fix one, or add an experiment that moves them differently)"
            ),
            Warning::RoughCost => f.write_str(
                "the standard errors of a fit to a closed-loop simulation (torque curve, unbalance test, servo trace) count the residuals' scatter only: the quantised encoders make the cost rough, and the search stops in its local minima (fm +0.67 % against a 0.08 % standard error on the worm fixture from fm 0.2): read them as lower bounds, or run --resample for an interval that holds",
            ),
            Warning::EstimateUnused { source, values } => write!(
                f,
                "{source}: its direct estimate ({values}) is not a valid parameter set, so the search starts at the given values instead — check the record (too little motion, a wrong unit or sign)"
            ),
            Warning::Escalated {
                source,
                model_hz,
                measured_hz,
                max_miss_hz,
                max_miss_percent,
                linear_misfit_db,
            } => write!(
                f,
                "{source}: the linear fit does not explain the data — the nonlinear virtual test at its parameters puts the resonances at {} Hz (measured {} Hz), up to {max_miss_hz:.2} Hz ({max_miss_percent:.2} %) off, and the linear model's gain misses the measured curve by {linear_misfit_db:.2} dB RMS — beyond 0.5 % (a stiffness biased twice as much) or 1 dB (a flattened or misplaced peak): backlash or friction at the test's amplitude. So the result is the nonlinear fit, the linear one corrected by the nonlinear test",
                hz(model_hz),
                hz(measured_hz)
            ),
            Warning::ProfileOpen {
                name,
                side,
                bound,
                family,
            } => {
                write!(
                    f,
                    "{name}'s profile stays below the 95 % level up to its {side} bound {}: the data do not bound it on that side",
                    crate::names::Num(*bound)
                )?;
                if !family.is_empty() {
                    let moved: Vec<String> = family
                        .iter()
                        .map(|(n, r)| format!("{n} ×{r:.2}"))
                        .collect();
                    let names: Vec<&str> = family.iter().map(|(n, _)| n.as_str()).collect();
                    write!(
                        f,
                        "; along the profile {} moved with it: the data determine a combination of {name}, {}, not each",
                        moved.join(", "),
                        names.join(", ")
                    )?;
                }
                Ok(())
            }
            Warning::ProfileBetterFit {
                name,
                value,
                cost,
                fit_cost,
            } => write!(
                f,
                "holding {name} at {} fits better than the result (cost {cost:.4e} against {fit_cost:.4e}): the search stopped short of the optimum — rerun with more --starts, or from there",
                crate::names::Num(*value)
            ),
        }
    }
}

/// A typed value with its message, as written to result files: the value's own fields
/// (with its `code`) and `message`, its text.
#[derive(Clone, Debug, PartialEq)]
pub struct Coded<T>(pub T);

impl<T: Serialize + fmt::Display> Serialize for Coded<T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut value = serde_json::to_value(&self.0).map_err(serde::ser::Error::custom)?;
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
