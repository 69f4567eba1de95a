//! The virtual tests a prediction runs on each parameter set, and the values it reads
//! from them, in the units the field reports them in.

use crate::controller::Compensation;
use crate::experiments::positioning::iso230::{self, Iso230Error, ReportUnits};
use crate::experiments::positioning::{self, PositioningTest};
use crate::model::params::ControllerParams;
use crate::model::{Axis, Params};
use crate::sim::SimError;
use crate::tuning::verify;

/// One output of a case.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Output {
    pub name: &'static str,
    pub value: f64,
}

/// A virtual test with its settings, under a label (`compensated`).
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    pub label: String,
    pub test: Test,
    /// The controller settings the case runs with instead of the model's (a tuning).
    pub controller: Option<ControllerParams>,
}

/// The tests a case may run.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Test {
    /// The ISO 230-2 positioning test: B̄, B, E, M, R, A of the axis.
    Positioning { test: PositioningTest, axis: Axis },
    /// The servo's responses (`tuning::verify`): a step's overshoot, the following
    /// error at constant speed, the reversal spike, the peak effort.
    Servo {
        compensation: Compensation,
        axis: Axis,
    },
}

/// Why a case did not give its outputs.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CaseError {
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error(transparent)]
    Iso230(#[from] Iso230Error),
}

impl Case {
    /// The outputs on the model `p`.
    pub fn run(&self, p: &Params) -> Result<Vec<Output>, CaseError> {
        let tuned;
        let p = match &self.controller {
            Some(c) => {
                tuned = Params {
                    controller: c.clone(),
                    ..p.clone()
                };
                &tuned
            }
            None => p,
        };
        let values: Vec<(&'static str, f64)> = match &self.test {
            Test::Positioning { test, axis } => {
                let readings = positioning::run(p, test, |_, _| {})?;
                let stats = iso230::evaluate(&readings)?.axis;
                let s = stats.scaled(ReportUnits::of(*axis).deviation_per_si);
                vec![
                    ("B_mean", s.b_mean),
                    ("B", s.b),
                    ("E", s.e),
                    ("M", s.m),
                    ("R", s.r),
                    ("A", s.a),
                ]
            }
            Test::Servo { compensation, .. } => {
                let r = verify::responses_with(p, compensation)?;
                vec![
                    ("step_overshoot_percent", r.step_overshoot_percent),
                    ("following_error", r.following_error),
                    ("reversal_spike", r.reversal_spike),
                    ("peak_effort", r.peak_effort),
                ]
            }
        };
        Ok(values
            .into_iter()
            .map(|(name, value)| Output { name, value })
            .collect())
    }

    /// The test's name (`positioning`, `servo`).
    pub fn test_name(&self) -> &'static str {
        match &self.test {
            Test::Positioning { .. } => "positioning",
            Test::Servo { .. } => "servo",
        }
    }

    /// The outputs' unit (`″`, `µm`).
    pub fn unit(&self) -> &'static str {
        match &self.test {
            Test::Positioning { axis, .. } | Test::Servo { axis, .. } => {
                ReportUnits::of(*axis).deviation
            }
        }
    }
}
