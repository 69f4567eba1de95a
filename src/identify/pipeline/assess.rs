//! The identified point assessed: each experiment's residuals (one evaluation serves
//! the report, the cost and the uncertainty), the uncertainty, and the warnings a
//! user should read.

use crate::identify::error::IdentifyError;
use crate::identify::intervals::uncertainty;
use crate::identify::pipeline::stages::Ran;
use crate::identify::plan::Plan;
use crate::identify::result::starts::StartRecord;
use crate::identify::result::termination::Termination;
use crate::identify::result::uncertainty::Uncertainty;
use crate::identify::result::warning::Warning;
use crate::identify::result::{ExperimentResidual, NonlinearCheck};
use crate::identify::search::problem::{describe, Best, Monitor, SearchJacobian};
use crate::identify::search::settings::Method;
use crate::identify::space::ParamSpace;
use crate::model::Params;
use crate::objectives::{sum_of_squares, Detail, Joint};

/// What the assessment finds.
pub struct Assessment {
    pub residuals: Vec<ExperimentResidual>,
    pub cost: f64,
    pub uncertainty: Option<Uncertainty>,
    pub nonlinear_check: Option<Vec<NonlinearCheck>>,
    pub warnings: Vec<Warning>,
}

/// A resonance missed by more than this, Hz, is worth a warning.
const RESONANCE_MISS_HZ: f64 = 1.0;

/// Assesses the best point `best` (= `params`) of the stages `ran`.
pub fn assess(
    plan: &Plan,
    space: &ParamSpace,
    ran: &Ran,
    best: &Best,
    params: &Params,
    monitor: &Monitor,
) -> Result<Assessment, IdentifyError> {
    let interrupted = monitor.stopped();
    let joint = &ran.joint;
    let mut warnings = search_warnings(space, &ran.starts, best, monitor);
    let parts = joint.part_residuals(params)?;
    let stacked = joint.stack(&parts);
    let residuals = residual_report(joint, params, parts);
    warnings.extend(resonance_misses(&residuals));
    warnings.extend(phase_delays(&residuals));
    warnings.extend(traces_not_followed(&residuals));
    let uncertainty = if interrupted {
        None
    } else {
        let one_lm_stage = ran.stages == 1 && plan.stages[0].settings.method == Method::Lm;
        let kept = one_lm_stage.then(|| search_jacobian(space, best, monitor));
        let a = match kept.flatten() {
            Some(kept) => {
                uncertainty::from_solver_jacobian(space, &best.values, (&kept.x, &kept.j), &stacked)
            }
            None => uncertainty::with_residuals(
                space,
                joint,
                &best.values,
                &stacked,
                plan.uncertainty_step(ran.stages),
            )?,
        };
        warnings.extend(a.warnings);
        let mut a_uncertainty = a.uncertainty;
        let unconverged = unconverged_corrections(&ran.starts, &best.values, &mut a_uncertainty);
        a_uncertainty.lower_bounds = plan.declared.rough || unconverged.is_some();
        warnings.extend(unconverged);
        if plan.declared.rough {
            warnings.push(Warning::RoughCost);
        }
        Some(a_uncertainty)
    };
    Ok(Assessment {
        residuals,
        cost: sum_of_squares(&stacked),
        uncertainty,
        nonlinear_check: ran.check.clone(),
        warnings,
    })
}

/// A parameter that one correction still moves by more than this (relative) is not
/// determined by the record through the nonlinear test: the worm mesh's damping Ciw,
/// acting on a mode above the record's band, moved by 55 % and 90 %.
const UNDETERMINED_STEP: f64 = 0.25;

/// The warning that the nonlinear corrections ended still moving by more than half
/// a standard error of some parameter (a smaller move is immaterial beside the
/// interval). A standard error is a converged optimum's: a parameter that moved
/// beyond its own has it widened to the move (the corrections' own spread), and one
/// that moved beyond [`UNDETERMINED_STEP`] has it withdrawn (not determined).
fn unconverged_corrections(
    starts: &[StartRecord],
    values: &[f64],
    uncertainty: &mut Uncertainty,
) -> Option<Warning> {
    let (corrections, moved) = starts.iter().find_map(|s| match &s.termination {
        Termination::Corrections {
            corrections,
            converged: false,
            moved,
            ..
        } => Some((*corrections, moved.clone())),
        _ => None,
    })?;
    let (mut undetermined, mut widened) = (Vec::new(), Vec::new());
    let mut material = false;
    for ((name, step), value) in moved.iter().zip(values) {
        let Some(slot) = uncertainty
            .standard_errors
            .iter_mut()
            .find(|(n, _)| n == name)
        else {
            continue;
        };
        let relative_se = slot.1.map_or(0.0, |se| se / value.abs());
        material |= *step > 0.5 * relative_se;
        if *step > UNDETERMINED_STEP {
            slot.1 = None;
            undetermined.push(name.clone());
        } else if *step > relative_se {
            slot.1 = Some(step * value.abs());
            widened.push(name.clone());
        }
    }
    material.then_some(Warning::CorrectionsNotConverged {
        corrections,
        moved,
        widened,
        undetermined,
    })
}

/// The Jacobian the search took last (Levenberg–Marquardt), where it lies within its
/// own difference step of the result in every solver coordinate: its last step
/// lowered the cost by less than 0.1 %, or none did. It serves the uncertainty in
/// place of 2k more evaluations (8 replays of the EMPS record); its forward
/// differences of 0.03 solver units sit above the replay's roughness, as the
/// uncertainty's own central differences of 0.1 in ln p do.
fn search_jacobian(space: &ParamSpace, best: &Best, monitor: &Monitor) -> Option<SearchJacobian> {
    let kept = monitor.jacobian()?;
    let at = space.to_solver(&best.values);
    let near = kept.x.len() == at.len()
        && kept
            .x
            .iter()
            .zip(at.iter())
            .all(|(a, b)| (a - b).abs() <= kept.step);
    near.then_some(kept)
}

/// How the search went: stopped, failures, distinct optima of the same cost,
/// parameters at their bounds.
fn search_warnings(
    space: &ParamSpace,
    starts: &[StartRecord],
    best: &Best,
    monitor: &Monitor,
) -> Vec<Warning> {
    let mut out = Vec::new();
    if monitor.stopped() {
        out.push(Warning::Interrupted {
            evaluations: monitor.evaluations(),
        });
    }
    if let Some(example) = monitor.failure() {
        out.push(Warning::EvaluationFailures { example });
    }
    for s in starts {
        let Some(v) = &s.result else { continue };
        let far = v
            .iter()
            .zip(&best.values)
            .any(|(a, b)| ((a - b) / b).abs() > 0.05);
        if far && s.cost_or_infinity() <= best.cost.max(1e-6) * 1.5 + 1e-6 {
            out.push(Warning::DistinctSolution {
                start: s.index + 1,
                solution: describe(space, v),
            });
        }
    }
    for (name, side) in space.at_bounds(&best.values) {
        out.push(Warning::AtBound {
            name: name.into(),
            side,
        });
    }
    out
}

/// Each part's residuals at the result, with their details in the measurement's units.
pub(crate) fn residual_report(
    joint: &Joint,
    p: &Params,
    parts: Vec<Vec<f64>>,
) -> Vec<ExperimentResidual> {
    joint
        .parts
        .iter()
        .zip(parts)
        .map(|(part, r)| ExperimentResidual {
            source: part.source.clone(),
            objective: part.objective.name().into(),
            weight: part.weight,
            scale: part.objective.scale(),
            rms: (sum_of_squares(&r) / r.len().max(1) as f64).sqrt(),
            detail: part.objective.detail(p, &r),
            residuals: r,
        })
        .collect()
}

/// A replay whose position error's RMS exceeds this fraction of the record's span
/// does not follow the record (EMPS's fit: 2 µm over 0.2 m, 1e-5).
const NOT_FOLLOWED: f64 = 0.1;

/// Servo traces whose replay at the result does not follow the record.
fn traces_not_followed(residuals: &[ExperimentResidual]) -> Vec<Warning> {
    residuals
        .iter()
        .filter_map(|r| match &r.detail {
            Some(Detail::Trace {
                position_rms,
                position_span,
                ..
            }) if position_rms.is_nan() || *position_rms > NOT_FOLLOWED * position_span => {
                Some(Warning::NotFollowed {
                    source: r.source.clone(),
                    position_rms: *position_rms,
                    position_span: *position_span,
                })
            }
            _ => None,
        })
        .collect()
}

/// Complex responses whose phase errors show a delay the manifest does not state.
fn phase_delays(residuals: &[ExperimentResidual]) -> Vec<Warning> {
    residuals
        .iter()
        .filter_map(|r| match &r.detail {
            Some(Detail::ComplexResponse {
                unstated_delay_s: Some(d),
                ..
            }) => Some(Warning::PhaseDelay {
                source: r.source.clone(),
                delay_s: *d,
            }),
            _ => None,
        })
        .collect()
}

/// Resonances the fitted model misses by more than [`RESONANCE_MISS_HZ`].
fn resonance_misses(residuals: &[ExperimentResidual]) -> Vec<Warning> {
    residuals
        .iter()
        .filter_map(|r| match &r.detail {
            Some(Detail::Resonance { max_miss_hz, .. }) if *max_miss_hz > RESONANCE_MISS_HZ => {
                Some(Warning::ResonanceMiss {
                    source: r.source.clone(),
                    max_miss_hz: *max_miss_hz,
                })
            }
            _ => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(position_rms: f64, position_span: f64) -> ExperimentResidual {
        ExperimentResidual {
            source: "trace.json".into(),
            objective: "servo_trace".into(),
            weight: 1.0,
            scale: String::new(),
            residuals: vec![],
            rms: 0.0,
            detail: Some(Detail::Trace {
                force_rms: 1.0,
                position_rms,
                position_max: position_rms,
                position_span,
            }),
        }
    }

    /// EMPS's fit (2 µm over 0.2 m) follows; a replay 59 rad off a 1.5 rad record
    /// does not, nor one whose error is NaN.
    #[test]
    fn a_replay_far_off_the_record_is_said_not_to_follow_it() {
        assert!(traces_not_followed(&[trace(2e-6, 0.2)]).is_empty());
        let off = traces_not_followed(&[trace(59.0, 1.5)]);
        assert!(matches!(&off[..], [Warning::NotFollowed { .. }]), "{off:?}");
        assert!(off[0].to_string().contains("does not follow"), "{}", off[0]);
        assert_eq!(traces_not_followed(&[trace(f64::NAN, 1.5)]).len(), 1);
    }
}
