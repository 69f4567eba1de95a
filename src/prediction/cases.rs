//! The virtual tests a prediction runs on each parameter set, and the values it reads
//! from them, in the units the field reports them in.

use crate::controller::Compensation;
use crate::experiments::positioning::ensemble::{self, Ensemble, EnsembleError};
use crate::experiments::positioning::iso230::{self, Iso230Error, Measurement, ReportUnits};
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

/// A case's outputs at the fit and, where the test is run as an ensemble there, the
/// widening (below, above) of each output's interval by the test's own spread.
#[derive(Clone, Debug, PartialEq)]
pub struct AtFit {
    pub outputs: Vec<Output>,
    pub spread: Option<Vec<(f64, f64)>>,
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
    #[error(transparent)]
    Ensemble(#[from] EnsembleError),
}

impl Case {
    /// The outputs on the model `p`.
    pub fn run(&self, p: &Params) -> Result<Vec<Output>, CaseError> {
        self.run_batch(std::slice::from_ref(p))
            .pop()
            .expect("one set, one result")
    }

    /// The outputs on each of the models `ps`, in order: the positioning test in
    /// the kernel's lanes (each set's outputs are those it gives alone), the
    /// servo's responses one set after another.
    pub fn run_batch(&self, ps: &[Params]) -> Vec<Result<Vec<Output>, CaseError>> {
        let sets: Vec<Params> = ps.iter().map(|p| self.tuned(p)).collect();
        match &self.test {
            Test::Positioning { test, axis } => positioning::run_batch(&sets, test)
                .into_iter()
                .map(|readings| positioning_outputs(&readings?, *axis))
                .collect(),
            Test::Servo { compensation, .. } => sets
                .iter()
                .map(|p| servo_outputs(p, compensation))
                .collect(),
        }
    }

    /// The outputs on the model `p` (the fit), and the test's own spread there: for
    /// each output, the range (largest less least) of its runs under `ensemble` (the
    /// rest positions' stick, sub-count offsets of the compensation, the noise's
    /// seed: issue 58's ensemble), as the widening (below, above) of an interval: a
    /// draw is one run of the test, the machine's another, so either may lie at
    /// either end of the range. The outputs are the ensemble's member 0, the test as
    /// given (bit for bit [`Case::run`]'s). No spread without an ensemble or for a
    /// test run once (the servo's responses).
    pub fn at_fit(&self, p: &Params, ensemble: Option<&Ensemble>) -> Result<AtFit, CaseError> {
        let (Test::Positioning { test, .. }, Some(ensemble)) = (&self.test, ensemble) else {
            return Ok(AtFit {
                outputs: self.run(p)?,
                spread: None,
            });
        };
        let e = ensemble::run(&self.tuned(p), test, ensemble)?;
        let (least, largest) = (iso_values(&e.min), iso_values(&e.max));
        let range = least.iter().zip(&largest).map(|(lo, hi)| hi.1 - lo.1);
        Ok(AtFit {
            outputs: outputs(iso_values(&e.members[0]).to_vec()),
            spread: Some(range.map(|r| (-r, r)).collect()),
        })
    }

    /// `p` with the case's controller settings, if it has its own.
    fn tuned(&self, p: &Params) -> Params {
        match &self.controller {
            Some(c) => Params {
                controller: c.clone(),
                ..p.clone()
            },
            None => p.clone(),
        }
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

/// B̄, B, E, M, R, A of an ISO 230-2 run's `readings`, in the axis's report units.
fn positioning_outputs(readings: &[Measurement], axis: Axis) -> Result<Vec<Output>, CaseError> {
    let stats = iso230::evaluate(readings)?.axis;
    let s = stats.scaled(ReportUnits::of(axis).deviation_per_si);
    Ok(outputs(iso_values(&s).to_vec()))
}

/// The signed one of the ISO 230-2 outputs; the others are magnitudes.
pub const SIGNED: &str = "B_mean";

/// B̄, B, E, M, R, A of `s`, named as the prediction reports them.
fn iso_values(s: &iso230::AxisStats) -> [(&'static str, f64); 6] {
    [
        (SIGNED, s.b_mean),
        ("B", s.b),
        ("E", s.e),
        ("M", s.m),
        ("R", s.r),
        ("A", s.a),
    ]
}

/// The servo's responses on `p` with `compensation`.
fn servo_outputs(p: &Params, compensation: &Compensation) -> Result<Vec<Output>, CaseError> {
    let r = verify::responses_with(p, compensation)?;
    Ok(outputs(vec![
        ("step_overshoot_percent", r.step_overshoot_percent),
        ("following_error", r.following_error),
        ("reversal_spike", r.reversal_spike),
        ("peak_effort", r.peak_effort),
    ]))
}

fn outputs(values: Vec<(&'static str, f64)>) -> Vec<Output> {
    values
        .into_iter()
        .map(|(name, value)| Output { name, value })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    /// A group of drawn sets runs the positioning test in lanes: each set's outputs
    /// are those it gives alone, bit for bit.
    #[test]
    fn a_group_of_sets_gives_each_its_lone_outputs() {
        let case = Case {
            label: "before".into(),
            test: Test::Positioning {
                test: PositioningTest {
                    targets: vec![0.0, 10f64.to_radians()],
                    runs: 2,
                    ..Default::default()
                },
                axis: Axis::Rotary,
            },
            controller: None,
        };
        let base = presets::load("worm-gear").unwrap();
        let sets: Vec<Params> = [(0.14, 8e-5), (0.16, 7e-5), (0.12, 9e-5)]
            .iter()
            .map(|&(fm, theta_bw)| Params {
                fm,
                theta_bw,
                ..base.clone()
            })
            .collect();
        let together = case.run_batch(&sets);
        for (p, r) in sets.iter().zip(together) {
            let alone = case.run(p).unwrap();
            assert_eq!(r.unwrap(), alone, "fm {}", p.fm);
        }
    }
}
