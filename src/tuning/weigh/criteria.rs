//! What a machine builder checks of a servo setting, on the nonlinear model
//! (docs/tuning.md, "The search"): the servo's responses ([`verify`]: a step's
//! overshoot and settling at the table, the table's motion at rest, the following
//! error, the reversal spike, the peak torque) and the ISO 230-2 positioning cycle
//! at the table after the compensation built for this setting (A, R, B̄).
//!
//! Two depths, each with the compensation built from a first cycle and then run in
//! the controller for a second (as the machine would run it). [`screen`] weighs many
//! candidates on a short cycle (every 90° or 125 mm, two runs per direction), in the
//! kernel's lanes; [`check`] weighs the setting proposed and today's on the standard
//! cycle (`rtid experiment positioning`'s).

use rayon::prelude::*;
use serde::Serialize;

use super::verify::{self, Compensations, Responses};
use crate::controller::Compensation;
use crate::experiments::positioning::compensate::{self, CompensateError};
use crate::experiments::positioning::ensemble::{Ensemble, EnsembleError};
use crate::experiments::positioning::iso230::{self, AxisStats, Iso230Error, ReportUnits};
use crate::experiments::positioning::{self, PositioningTest};
use crate::model::{Axis, Params};
use crate::sim::SimError;

/// The figures of one setting.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Criteria {
    pub servo: Responses,
    pub positioning: Positioning,
}

/// The ISO 230-2 values of the cycle at the table, in report units (″, µm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Positioning {
    /// Accuracy A without compensation.
    pub a_uncompensated: f64,
    /// Mean reversal value B̄ without compensation.
    pub b_mean_uncompensated: f64,
    /// A, R, B̄ and E with the compensation built for this setting.
    #[serde(rename = "A")]
    pub a: f64,
    #[serde(rename = "R")]
    pub r: f64,
    #[serde(rename = "B_mean")]
    pub b_mean: f64,
    #[serde(rename = "E")]
    pub e: f64,
    /// Targets per direction and runs of the cycle.
    pub targets: usize,
    pub runs: u32,
    /// Where the compensation acted: `controller` (run in the servo).
    pub compensated_in: &'static str,
}

/// Why a setting's figures could not be had.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CriteriaError {
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error(transparent)]
    Iso230(#[from] Iso230Error),
    #[error(transparent)]
    Compensate(#[from] CompensateError),
    #[error(transparent)]
    Ensemble(#[from] EnsembleError),
    /// Not weighed (a place kept for a setting weighed apart).
    #[error("not weighed")]
    Unscreened,
}

/// The short cycle of the screening, on `p`'s axis (in the set's own loop).
pub fn short_cycle(p: &Params) -> PositioningTest {
    let standard = PositioningTest::standard(p.axis);
    let (span, step) = match p.axis {
        Axis::Rotary => (360f64.to_radians(), 90f64.to_radians()),
        Axis::Linear => (0.5, 0.125),
    };
    PositioningTest {
        targets: (0..=(span / step).round() as usize)
            .map(|i| i as f64 * step)
            .collect(),
        runs: 2,
        ..standard
    }
}

/// The standard cycle on `p`'s axis (in the set's own loop).
pub fn standard_cycle(p: &Params) -> PositioningTest {
    PositioningTest::standard(p.axis)
}

/// The figures of each of `sets` (one axis kind) on the short cycle, its
/// compensation built from a first cycle and run in the controller for a second,
/// the step read at the table on the axis so compensated; in the kernel's lanes.
pub fn screen(sets: &[Params]) -> Vec<Result<Criteria, CriteriaError>> {
    let Some(first) = sets.first() else {
        return Vec::new();
    };
    let test = short_cycle(first);
    let built = first_cycles(sets, &test);
    let compensations = compensations_of(&built);
    let second = positioning::run_batch_compensated(sets, &test, &compensations);
    let each: Vec<Compensations> = compensations
        .iter()
        .map(|c| Compensations {
            servo: Compensation::default(),
            table: Some(c.clone()),
        })
        .collect();
    let servo = verify::responses_each(sets, &each);
    servo
        .into_iter()
        .zip(built)
        .zip(second)
        .map(|((servo, built), readings)| {
            let (before, _) = built?;
            let after = iso230::evaluate(&readings?)?.axis;
            Ok(Criteria {
                servo: servo?,
                positioning: figures(&before, &after, &test, first.axis, "controller"),
            })
        })
        .collect()
}

/// Each set's first cycle of `test` (in lanes): its ISO 230-2 values and the
/// compensation built from it.
fn first_cycles(
    sets: &[Params],
    test: &PositioningTest,
) -> Vec<Result<(AxisStats, Compensation), CriteriaError>> {
    positioning::run_batch(sets, test)
        .into_iter()
        .zip(sets)
        .map(|(readings, p)| {
            let readings = readings?;
            let before = iso230::evaluate(&readings)?.axis;
            Ok((
                before,
                compensate::compute(&readings, p.axis, None)?.compensation,
            ))
        })
        .collect()
}

/// The compensations of `built` (none where it failed: that set's error is kept).
fn compensations_of(
    built: &[Result<(AxisStats, Compensation), CriteriaError>],
) -> Vec<Compensation> {
    built
        .iter()
        .map(|b| {
            b.as_ref()
                .map_or_else(|_| Compensation::default(), |b| b.1.clone())
        })
        .collect()
}

/// One setting's figures over an ensemble (docs/tuning.md, "The check"): member k's
/// compensated cycle and step and move perturbed as [`Ensemble`] says, the first
/// cycle (uncompensated, the compensation built from it) shared by all.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Checked {
    /// Each member's figures, the unperturbed run first.
    pub members: Vec<Criteria>,
}

/// The figures of each of `sets` on the standard cycle, as an ensemble: the first
/// cycles in lanes across the sets, each set's members in lanes.
pub fn check(sets: &[Params], ensemble: &Ensemble) -> Vec<Result<Checked, CriteriaError>> {
    let Some(first) = sets.first() else {
        return Vec::new();
    };
    let test = standard_cycle(first);
    let built = first_cycles(sets, &test);
    sets.par_iter()
        .zip(built)
        .map(|(p, built)| {
            let (before, compensation) = built?;
            check_members(p, &test, &before, compensation, ensemble)
        })
        .collect()
}

/// `p`'s members, its first cycle's values `before` and the compensation built from
/// it given.
fn check_members(
    p: &Params,
    test: &PositioningTest,
    before: &AxisStats,
    compensation: Compensation,
    ensemble: &Ensemble,
) -> Result<Checked, CriteriaError> {
    let compensated = PositioningTest {
        compensation: compensation.clone(),
        ..test.clone()
    };
    let base = Compensations {
        servo: Compensation::default(),
        table: Some(compensation),
    };
    let (cycles, servo) = rayon::join(
        || positioning::ensemble::readings(p, &compensated, ensemble),
        || verify::responses_members(p, &base, ensemble),
    );
    let members = cycles?
        .iter()
        .zip(servo)
        .map(|(readings, servo)| {
            let after = iso230::evaluate(readings)?.axis;
            Ok(Criteria {
                servo: servo?,
                positioning: figures(before, &after, test, p.axis, "controller"),
            })
        })
        .collect::<Result<Vec<_>, CriteriaError>>()?;
    Ok(Checked { members })
}

fn figures(
    before: &AxisStats,
    after: &AxisStats,
    test: &PositioningTest,
    axis: Axis,
    compensated_in: &'static str,
) -> Positioning {
    let k = ReportUnits::of(axis).deviation_per_si;
    Positioning {
        a_uncompensated: before.a * k,
        b_mean_uncompensated: before.b_mean * k,
        a: after.a * k,
        r: after.r * k,
        b_mean: after.b_mean * k,
        e: after.e * k,
        targets: test.targets.len(),
        runs: test.runs,
        compensated_in,
    }
}
