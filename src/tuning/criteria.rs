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

use serde::Serialize;

use super::verify::{self, Responses};
use crate::controller::Compensation;
use crate::experiments::positioning::compensate::{self, CompensateError};
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
/// compensation built from a first cycle and run in the controller for a second;
/// in the kernel's lanes.
pub fn screen(sets: &[Params]) -> Vec<Result<Criteria, CriteriaError>> {
    let Some(first) = sets.first() else {
        return Vec::new();
    };
    let test = short_cycle(first);
    let servo = verify::responses_batch(sets, &Compensation::default());
    let built: Vec<Result<(AxisStats, Compensation), CriteriaError>> =
        positioning::run_batch(sets, &test)
            .into_iter()
            .map(|readings| {
                let readings = readings?;
                let before = iso230::evaluate(&readings)?.axis;
                Ok((
                    before,
                    compensate::compute(&readings, first.axis, None)?.compensation,
                ))
            })
            .collect();
    let compensations: Vec<Compensation> = built
        .iter()
        .map(|b| {
            b.as_ref()
                .map_or_else(|_| Compensation::default(), |b| b.1.clone())
        })
        .collect();
    let second = positioning::run_batch_compensated(sets, &test, &compensations);
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

/// The figures of `p` on the standard cycle, compensated in the controller.
pub fn check(p: &Params) -> Result<Criteria, CriteriaError> {
    let mut test = standard_cycle(p);
    let (servo, readings) = rayon::join(
        || verify::responses(p),
        || positioning::run(p, &test, |_, _| {}),
    );
    let readings = readings?;
    let before = iso230::evaluate(&readings)?.axis;
    let computed = compensate::compute(&readings, p.axis, None)?;
    test.compensation = computed.compensation;
    let after = iso230::evaluate(&positioning::run(p, &test, |_, _| {})?)?.axis;
    Ok(Criteria {
        servo: servo?,
        positioning: figures(&before, &after, &test, p.axis, "controller"),
    })
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
