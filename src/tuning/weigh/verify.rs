//! The settings checked on the nonlinear model — backlash, friction, quantised
//! encoders, the torque limit, all of which the margins leave out: a step of the
//! position command, and a constant-speed move out and back with its reversal. The
//! step is read on the motor encoder times the ratio (what the semi-closed loop
//! controls) and at the table (what the machine is judged by): its overshoot, when it
//! settles, and the table's motion once it should be at rest (a limit cycle); in the
//! axis's report unit (arc-seconds, µm). Parameter sets run side by side in the
//! kernel's lanes (`sim::batch`), each with the result it gives alone.

use serde::Serialize;

use crate::controller::Compensation;
use crate::experiments::positioning::ensemble::{in_member_lanes, Ensemble, MemberRun};
use crate::experiments::positioning::iso230::ReportUnits;
use crate::input::{Move, Trajectory};
use crate::model::idx::{THETA_M, THETA_T};
use crate::model::rest::{rest_state, Preload};
use crate::model::{Axis, Params, NSTATE};
use crate::recorder::Recorder;
use crate::sim::batch::{in_lanes, LaneRun};
use crate::sim::{common_step, LaneSimulation, SimError};

/// The responses of one setting.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Responses {
    /// The step's size (1° or 1 mm), in the report's target unit.
    pub step: f64,
    /// The step's largest excursion beyond the target on the motor encoder × the
    /// ratio, % of the step.
    pub step_overshoot_percent: f64,
    /// When the motor encoder × the ratio stays within [`SETTLED`] report units of
    /// the target, s; `None` when it has not by the end (1 s).
    pub step_settling_s: Option<f64>,
    /// The step's largest excursion beyond the target at the table, % of the step.
    pub table_overshoot_percent: f64,
    /// When the table stays within [`SETTLED`] report units of the target, s;
    /// `None` when it has not by the end.
    pub table_settling_s: Option<f64>,
    /// The table's peak-to-peak motion over the step's last [`REST_WINDOW_S`], in
    /// report units: what a limit cycle leaves.
    pub table_motion_at_rest: f64,
    /// The following error on the move's constant-speed part (its second half), the
    /// largest magnitude.
    pub following_error: f64,
    /// The reversal spike: the largest following error after the reversal beyond the
    /// constant-speed level that follows.
    pub reversal_spike: f64,
    /// The largest motor torque (force) of the step and the move, N·m (N).
    pub peak_effort: f64,
    /// The largest motor torque (force) of the move alone (a ramp, not a step
    /// command), N·m (N).
    pub move_peak_effort: f64,
    /// The unit of the excursions (`″`, `µm`).
    pub unit: &'static str,
}

/// Within this many report units (20″, 20 µm) the step has settled.
pub const SETTLED: f64 = 20.0;
/// The step's length, s.
pub const STEP_S: f64 = 1.0;
/// The end of the step over which the table's motion at rest is measured, s.
pub const REST_WINDOW_S: f64 = 0.25;

/// The step and the out-and-back move of `p` on the nonlinear model.
pub fn responses(p: &Params) -> Result<Responses, SimError> {
    responses_with(p, &Compensation::default())
}

/// The same with the controller's compensations `c` on.
pub fn responses_with(p: &Params, c: &Compensation) -> Result<Responses, SimError> {
    let each = Compensations {
        servo: c.clone(),
        table: None,
    };
    responses_each(std::slice::from_ref(p), std::slice::from_ref(&each))
        .pop()
        .expect("one set, one result")
}

/// The compensations one set's step and move run with.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Compensations {
    /// The controller's compensation during the step and the move read on the motor
    /// encoder (the following error, the reversal spike, the effort).
    pub servo: Compensation,
    /// The compensation of the axis during a second step, read at the table (its
    /// settling, overshoot and motion at rest: the axis as the machine runs it, its
    /// lost motion compensated); `None`: the table is read in the first step.
    pub table: Option<Compensation>,
}

/// [`responses_with`] for each of `sets` (of one axis kind) with `each[i]`'s
/// compensations for `sets[i]`, in the kernel's lanes (a lane's set is found among
/// `sets` by equality: equal sets get the first one's compensations).
pub fn responses_each(sets: &[Params], each: &[Compensations]) -> Vec<Result<Responses, SimError>> {
    in_lanes(sets, &Runs { sets, each })
}

/// Members `0..ensemble.members` of `p`'s step and move (docs/tuning.md, "The
/// check"): member k with `base`'s compensations perturbed as the positioning
/// ensemble perturbs them ([`Ensemble::compensation`]), in the kernel's lanes.
pub fn responses_members(
    p: &Params,
    base: &Compensations,
    ensemble: &Ensemble,
) -> Vec<Result<Responses, SimError>> {
    in_member_lanes(&Members { p, base, ensemble }, ensemble.members)
}

/// The step and the move of sets found by equality, for `sim::batch`.
struct Runs<'a> {
    sets: &'a [Params],
    each: &'a [Compensations],
}

impl Runs<'_> {
    fn of(&self, p: &Params) -> &Compensations {
        static NONE: Compensations = Compensations {
            servo: Compensation {
                backlash: None,
                table: None,
                friction: None,
            },
            table: None,
        };
        self.sets
            .iter()
            .position(|s| s == p)
            .map_or(&NONE, |i| &self.each[i])
    }
}

impl LaneRun for Runs<'_> {
    type Out = Responses;

    fn lone(&self, p: &Params) -> Result<Responses, SimError> {
        let [one] = lanes(std::array::from_ref(p), [self.of(p)], [0.0])?;
        one
    }

    fn lanes<const L: usize>(
        &self,
        params: &[Params; L],
    ) -> Result<[Result<Responses, SimError>; L], SimError> {
        if params.iter().any(|p| p.axis != params[0].axis) {
            return Ok(params.each_ref().map(|p| self.lone(p)));
        }
        lanes(params, params.each_ref().map(|p| self.of(p)), [0.0; L])
    }
}

/// An ensemble's members of one set, for [`in_member_lanes`].
struct Members<'a> {
    p: &'a Params,
    base: &'a Compensations,
    ensemble: &'a Ensemble,
}

impl MemberRun for Members<'_> {
    type Out = Responses;

    fn lanes<const L: usize>(
        &self,
        members: [usize; L],
    ) -> Result<[Result<Responses, SimError>; L], SimError> {
        let perturbed = |c: &Compensation, k| self.ensemble.compensation(k, self.p, c);
        let each = members.map(|k| Compensations {
            servo: perturbed(&self.base.servo, k),
            table: self.base.table.as_ref().map(|t| perturbed(t, k)),
        });
        let starts = members.map(|k| self.ensemble.perturbation(k, self.p).offset);
        lanes(
            &std::array::from_fn(|_| self.p.clone()),
            each.each_ref(),
            starts,
        )
    }
}

/// The step and the move of `L` sets of one axis kind, each with its compensations,
/// from rest at `starts`.
fn lanes<const L: usize>(
    params: &[Params; L],
    each: [&Compensations; L],
    starts: [f64; L],
) -> Result<[Result<Responses, SimError>; L], SimError> {
    let axis = params[0].axis;
    let (step, speed) = match axis {
        Axis::Rotary => (1f64.to_radians(), 10f64.to_radians()),
        Axis::Linear => (1e-3, 10e-3),
    };
    let servo = each.map(|c| &c.servo);
    let stepped = [(0.0, step, None, STEP_S)];
    let steps = run(params, (servo, starts), &stepped)?;
    let leg = 5.0 * step / speed;
    let moves = run(
        params,
        (servo, starts),
        &[
            (0.0, 5.0 * step, Some(speed), leg),
            (5.0 * step, 0.0, Some(speed), leg),
        ],
    )?;
    let table_steps = if each.iter().any(|c| c.table.is_some()) {
        let table = each.map(|c| c.table.as_ref().unwrap_or(&c.servo));
        Some(run(params, (table, starts), &stepped)?)
    } else {
        None
    };
    let mut moves = moves.into_iter();
    let mut table_steps = table_steps.map(|t| t.into_iter());
    Ok(steps.map(|s| {
        let m = moves.next().expect("one per lane");
        let t = table_steps
            .as_mut()
            .map(|t| t.next().expect("one per lane"));
        let s = s?;
        let t = match t {
            Some(t) => t?,
            None => s.clone(),
        };
        Ok(figures(&s, &t, &m?, step, leg, ReportUnits::of(axis)))
    }))
}

/// The figures of one set's step (on the motor, `steps`; at the table,
/// `table_steps`) and move samples.
fn figures(
    steps: &[Sample],
    table_steps: &[Sample],
    moves: &[Sample],
    step: f64,
    leg: f64,
    u: ReportUnits,
) -> Responses {
    let k = u.deviation_per_si;
    let motor = |s: &Sample| s.1;
    let table = |s: &Sample| s.2;
    let (following, spike) = following_errors(moves, leg);
    let effort = |samples: &[Sample]| samples.iter().map(|s| s.4.abs()).fold(0.0, f64::max);
    Responses {
        step: step * u.target_per_si,
        step_overshoot_percent: overshoot(steps, step, motor),
        step_settling_s: settling(steps, step, k, motor),
        table_overshoot_percent: overshoot(table_steps, step, table),
        table_settling_s: settling(table_steps, step, k, table),
        table_motion_at_rest: motion_after(table_steps, STEP_S - REST_WINDOW_S, table) * k,
        following_error: following * k,
        reversal_spike: spike * k,
        peak_effort: effort(steps).max(effort(moves)),
        move_peak_effort: effort(moves),
        unit: u.deviation,
    }
}

/// The largest excursion of `at` beyond `step`, % of it.
fn overshoot(samples: &[Sample], step: f64, at: impl Fn(&Sample) -> f64) -> f64 {
    let peak = samples.iter().map(at).fold(f64::MIN, f64::max);
    ((peak / step - 1.0) * 100.0).max(0.0)
}

/// When `at` stays within [`SETTLED`] report units (`k` per SI unit) of `step`.
fn settling(samples: &[Sample], step: f64, k: f64, at: impl Fn(&Sample) -> f64) -> Option<f64> {
    let last_out = samples
        .iter()
        .rev()
        .find(|s| (at(s) - step).abs() * k > SETTLED)
        .map(|s| s.0);
    match last_out {
        Some(t) if t >= STEP_S - 1e-9 => None,
        Some(t) => Some(t),
        None => Some(0.0),
    }
}

/// The peak-to-peak of `at` from time `from` on.
fn motion_after(samples: &[Sample], from: f64, at: impl Fn(&Sample) -> f64) -> f64 {
    let (lo, hi) = samples
        .iter()
        .filter(|s| s.0 >= from)
        .map(at)
        .fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
    (hi - lo).max(0.0)
}

/// (t, motor × ratio, table, reference, effort) every step.
type Sample = (f64, f64, f64, f64, f64);

/// A lane's samples of one move (the reference filled in afterwards).
struct Positions {
    ratio: f64,
    samples: Vec<Sample>,
}

impl Recorder for Positions {
    fn record(&mut self, t: f64, y: &[f64; NSTATE], effort: f64) {
        self.samples
            .push((t, y[THETA_M] * self.ratio, y[THETA_T], 0.0, effort));
    }
}

/// Runs the moves (from, to, speed, duration) one after the other from rest at
/// `starts` (0, or a sub-count offset of an ensemble's member), every set in a lane
/// with its compensation: each lane's samples, or its error.
fn run<const L: usize>(
    params: &[Params; L],
    (compensations, starts): ([&Compensation; L], [f64; L]),
    moves: &[(f64, f64, Option<f64>, f64)],
) -> Result<[Result<Vec<Sample>, SimError>; L], SimError> {
    let mut sim = LaneSimulation::<L>::of(params, common_step(params)?)?;
    for (l, (p, &start)) in params.iter().zip(&starts).enumerate() {
        if start != 0.0 {
            sim.start(l, rest_state(p, start, Preload::None), 0.0);
        }
    }
    let mut controllers = sim.controllers(params)?;
    for (controller, c) in controllers.iter_mut().zip(compensations) {
        controller.set_compensation(c.clone());
    }
    let mut out: [Vec<Sample>; L] = std::array::from_fn(|_| Vec::new());
    let mut failed: [Option<SimError>; L] = std::array::from_fn(|_| None);
    for &(from, to, speed, duration) in moves {
        let m = Move { from, to, speed };
        let t0 = sim.time(0);
        let reference = |t: f64| m.angle(t - t0);
        let mut recorders = params.each_ref().map(|p| Positions {
            ratio: p.ratio(),
            samples: Vec::new(),
        });
        sim.run_closed_loop(
            (&mut controllers, &mut recorders),
            &reference,
            duration,
            &mut failed,
        )?;
        for (o, r) in out.iter_mut().zip(recorders) {
            o.extend(
                r.samples
                    .into_iter()
                    .map(|s| (s.0, s.1, s.2, reference(s.0), s.4)),
            );
        }
    }
    let mut out = out.into_iter();
    Ok(failed.map(|f| {
        let samples = out.next().expect("one per lane");
        f.map_or(Ok(samples), Err)
    }))
}

/// The largest following error on the second half of the first leg, and the spike:
/// the largest error on the second leg less its own second half's largest.
fn following_errors(samples: &[Sample], leg: f64) -> (f64, f64) {
    let error = |s: &Sample| (s.3 - s.1).abs();
    let largest = |from: f64, to: f64| {
        samples
            .iter()
            .filter(|s| s.0 >= from && s.0 < to)
            .map(error)
            .fold(0.0, f64::max)
    };
    let steady_out = largest(0.5 * leg, leg);
    let steady_back = largest(1.5 * leg, 2.0 * leg);
    let back = largest(leg, 2.0 * leg);
    (steady_out, (back - steady_back).max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_following_error_is_the_speed_over_the_position_gain() {
        // Semi-closed loop, no feed-forward: e = v/Kpp at constant speed, within the
        // friction's and the quantisation's share.
        let p = presets::load("worm-gear").unwrap();
        let r = responses(&p).unwrap();
        let expected = 10f64.to_radians() / p.controller.kpp * ReportUnits::ROTARY.deviation_per_si;
        assert!(
            (r.following_error / expected - 1.0).abs() < 0.05,
            "{} against {expected}″",
            r.following_error
        );
        assert!(
            r.step_settling_s.is_some_and(|t| t > 0.05 && t < 0.5),
            "{r:?}"
        );
    }
}
