//! The nonlinear stage of `--model nonlinear`: the fit on the nonlinear virtual test,
//! reached through the linear response corrected by the nonlinear one (output space
//! mapping, or defect correction).
//!
//! At the current point x_k the nonlinear residuals r_N(x_k) (one evaluation of the
//! virtual test: time simulations) and the linear ones r_L(x_k) (microseconds) differ
//! by d_k = r_N(x_k) − r_L(x_k): the shift of the peaks by backlash and friction. The
//! next point minimises the corrected linear residuals ‖r_L(x) + d̄‖² — a smooth
//! problem, solved by Gauss–Newton on the linear response alone — where d̄ is the
//! mean of the shifts met since the last large step ([`RESTART_STEP`]). Where the
//! iteration stops moving, r_L(x*) + d̄ ≈ r_N(x*): x* is a least-squares point of
//! the linear model corrected to agree with the nonlinear test there; when the data
//! can be matched (zero residuals, the usual case for resonances) it is the
//! nonlinear fit itself. The shift changes slowly with
//! the parameters, so a few nonlinear evaluations suffice, where a derivative-based
//! search on the nonlinear cost spends most of its evaluations on its roughness.
//!
//! Why the mean: the nonlinear test is not a smooth function of the parameters. Near
//! the worm's second resonance its gain varies irregularly by ±0.1 dB from one
//! frequency to the next (friction and backlash in the spur and worm stages; a ten
//! times tighter settling tolerance does not remove it), so the located peak jitters
//! by about ±1 Hz (±0.5 %) for parameter changes of 0.2 %. An iteration on the last
//! shift alone wanders by that much; the mean converges to the systematic shift, the
//! part of the nonlinear behaviour that the data can speak to.
//!
//! The nonlinear evaluations are counted in the caller's [`Monitor`], which holds the
//! result at the end; the linear sub-searches have monitors of their own.

use crate::identify::result::starts::StartRecord;
use crate::identify::result::termination::Termination;
use crate::identify::search::problem::{describe, Monitor};
use crate::identify::search::search;
use crate::identify::search::settings::Settings;
use crate::identify::space::ParamSpace;
use crate::objectives::{sum_of_squares, Objective, ObjectiveError};

/// Corrections at most.
pub const MAX_CORRECTIONS: usize = 6;

/// The iteration has converged when no fitted parameter moves by more than this
/// (relative) in one correction.
pub const STEP_TOLERANCE: f64 = 1e-4;

/// A correction that moves a parameter by more than this (relative) leaves the
/// shifts met before it behind: they were met too far away to average with (the
/// shift of a peak changes with the parameters; the jitter it averages out is that of
/// changes of ~0.2 %). From a linear fit 26 % off, keeping them biased Kg by +0.8 %.
pub const RESTART_STEP: f64 = 1e-2;

/// The linear residuals plus a fixed offset (the mean nonlinear shift): borrowed
/// (`&dyn Objective`) during the corrections; owned (a [`crate::objectives::Joint`])
/// as the smooth stand-in for the nonlinear cost that a profile of the result walks.
pub struct Corrected<L> {
    pub linear: L,
    pub offset: Vec<f64>,
}

impl<L: std::ops::Deref<Target = O> + Sync + Send, O: Objective + ?Sized> Objective
    for Corrected<L>
{
    fn name(&self) -> &'static str {
        "corrected linear"
    }

    fn residuals(&self, p: &crate::model::Params) -> Result<Vec<f64>, ObjectiveError> {
        Ok(self.offset_by(self.linear.residuals(p)?))
    }

    fn residuals_batch(
        &self,
        points: &[crate::model::Params],
    ) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        let r = self.linear.residuals_batch(points);
        r.into_iter().map(|r| Ok(self.offset_by(r?))).collect()
    }

    fn in_lanes(&self) -> bool {
        self.linear.in_lanes()
    }

    fn len(&self) -> usize {
        self.linear.len()
    }

    fn scale(&self) -> String {
        self.linear.scale()
    }
}

impl<L> Corrected<L> {
    /// `r` plus the offset.
    fn offset_by(&self, mut r: Vec<f64>) -> Vec<f64> {
        for (r, d) in r.iter_mut().zip(&self.offset) {
            *r += d;
        }
        r
    }
}

/// How the corrections ended.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The record of the stage, as one start: from the linear result to the best point.
    pub record: StartRecord,
    /// Evaluations of the nonlinear test.
    pub nonlinear_evaluations: usize,
    /// The shift of the last corrected fit, whose optimum the result is.
    pub offset: Vec<f64>,
}

/// Runs the corrections from `from` (physical values of the fitted parameters).
/// `linear` and `nonlinear` must be the same objectives at the two fidelities (same
/// residual layout). `settings` are those of the linear sub-searches (one start each).
/// Leaves the result as the monitor's best point, with its nonlinear cost.
pub(crate) fn polish(
    space: &ParamSpace,
    linear: &dyn Objective,
    nonlinear: &dyn Objective,
    from: &[f64],
    settings: &Settings,
    monitor: &Monitor,
) -> Result<Outcome, ObjectiveError> {
    assert_eq!(linear.len(), nonlinear.len(), "same residual layout");
    // The shift d(x) = r_N(x) − r_L(x) at one point.
    let shift = |values: &[f64]| -> Result<(Vec<f64>, f64), ObjectiveError> {
        let p = space.params(values)?;
        let r_n = nonlinear.residuals(&p)?;
        monitor.add_evaluations(1);
        let r_l = linear.residuals(&p)?;
        let d = r_n.iter().zip(&r_l).map(|(n, l)| n - l).collect();
        Ok((d, sum_of_squares(&r_n)))
    };
    let mut x = from.to_vec();
    let (d, mut cost) = shift(&x)?;
    let mut sum = d;
    // The shifts in `sum`.
    let mut met = 1;
    let mut nonlinear_evaluations = 1;
    let mut corrections = 0;
    let mut mean: Vec<f64> = sum.clone();
    let termination = loop {
        if monitor.stopped() {
            break Termination::Interrupted;
        }
        mean = sum.iter().map(|s| s / met as f64).collect();
        let Some(next) = corrected_fit(space, linear, mean.clone(), &x, settings, monitor) else {
            break Termination::CorrectionFailed {
                at: describe(space, &x),
            };
        };
        corrections += 1;
        let steps: Vec<f64> = next
            .iter()
            .zip(&x)
            .map(|(a, b)| ((a - b) / b).abs())
            .collect();
        let step = steps.iter().copied().fold(0.0, f64::max);
        x = next;
        let (d, c) = shift(&x)?;
        nonlinear_evaluations += 1;
        cost = c;
        if step < STEP_TOLERANCE || corrections == MAX_CORRECTIONS {
            break Termination::Corrections {
                corrections,
                nonlinear_evaluations,
                converged: step < STEP_TOLERANCE,
                last_step: step,
                moved: if step < STEP_TOLERANCE {
                    Vec::new()
                } else {
                    space
                        .names
                        .iter()
                        .map(|n| n.to_string())
                        .zip(steps)
                        .collect()
                },
            };
        }
        if step > RESTART_STEP {
            sum = d;
            met = 1;
        } else {
            for (s, d) in sum.iter_mut().zip(&d) {
                *s += d;
            }
            met += 1;
        }
    };
    monitor.reset_best();
    monitor.offer(cost, &x);
    Ok(Outcome {
        record: StartRecord {
            index: 0,
            initial: from.to_vec(),
            result: Some(x),
            cost: cost.is_finite().then_some(cost),
            iterations: corrections as u64,
            termination,
        },
        nonlinear_evaluations,
        offset: mean,
    })
}

/// The fit of the linear residuals plus `offset` from `x` (one start, Gauss–Newton
/// on the linear response alone, its evaluations counted in `monitor`); `None` when
/// nothing could be evaluated.
fn corrected_fit(
    space: &ParamSpace,
    linear: &dyn Objective,
    offset: Vec<f64>,
    x: &[f64],
    settings: &Settings,
    monitor: &Monitor,
) -> Option<Vec<f64>> {
    let corrected = Corrected { linear, offset };
    let mut from_x = space.clone();
    from_x.start = x.to_vec();
    let inner = Monitor::default();
    let sub = Settings {
        starts: 1,
        max_evaluations: None,
        ..*settings
    };
    search(&from_x, &corrected, &sub, &inner, &[], &|_| {});
    monitor.add_evaluations(inner.evaluations());
    inner.best().map(|b| b.values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::Bound;
    use crate::model::{presets, Params};

    /// Residuals (kw·gain − 3e5)/1e3 plus a shift: a stand-in for the linear
    /// (gain 1, no shift) and the nonlinear (a shifted, differently scaled) model.
    struct Toy {
        gain: f64,
        shift: f64,
    }

    impl Objective for Toy {
        fn name(&self) -> &'static str {
            "toy"
        }
        fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
            let r = (p.kw * self.gain - 3e5) / 1e3 + self.shift;
            Ok(vec![r, 0.5 * r])
        }
        fn len(&self) -> usize {
            2
        }
        fn scale(&self) -> String {
            String::new()
        }
    }

    #[test]
    fn a_shifted_nonlinear_model_is_fitted_exactly() {
        let base = presets::load("worm-gear").unwrap();
        let bound = Bound { lo: 1e5, hi: 1e6 };
        let space = ParamSpace::new(base, &["Kw".to_string()], &[("Kw".into(), bound)]).unwrap();
        let linear = Toy {
            gain: 1.0,
            shift: 0.0,
        };
        // The nonlinear optimum: kw = (3e5 − 1e3·7)/1.0 = 2.93e5.
        let nonlinear = Toy {
            gain: 1.0,
            shift: 7.0,
        };
        let monitor = Monitor::default();
        let out = polish(
            &space,
            &linear,
            &nonlinear,
            &[3e5],
            &Settings::default(),
            &monitor,
        )
        .unwrap();
        let kw = out.record.result.as_ref().unwrap()[0];
        assert!((kw - 2.93e5).abs() < 1.0, "{kw} {out:?}");
        assert!(out.record.termination.converged(), "{out:?}");
        assert!(out.nonlinear_evaluations <= 3, "{out:?}");
        assert_eq!(monitor.best().unwrap().values, vec![kw]);
    }
}
