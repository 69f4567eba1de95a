//! The settings checked on the nonlinear model — backlash, friction, quantised
//! encoders, the torque limit, all of which the margins leave out: a step of the
//! position command, and a constant-speed move out and back with its reversal.
//! Positions are the motor encoder's times the ratio (what the semi-closed loop
//! controls), in the axis's report unit (arc-seconds, µm).

use serde::Serialize;

use crate::controller::Compensation;
use crate::experiments::positioning::iso230::ReportUnits;
use crate::input::{Move, Trajectory};
use crate::model::idx::THETA_M;
use crate::model::{Axis, Params};
use crate::recorder::Trace;
use crate::sim::{SimError, Simulation};

/// The responses of one setting.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Responses {
    /// The step's size (1° or 1 mm), in the report's target unit.
    pub step: f64,
    /// The step's largest excursion beyond the target, % of the step.
    pub step_overshoot_percent: f64,
    /// When the step stays within [`SETTLED`] report units of the target, s; `None`
    /// when it has not by the end (1 s).
    pub step_settling_s: Option<f64>,
    /// The following error on the move's constant-speed part (its second half), the
    /// largest magnitude.
    pub following_error: f64,
    /// The reversal spike: the largest following error after the reversal beyond the
    /// constant-speed level that follows.
    pub reversal_spike: f64,
    /// The largest motor torque (force) of the step and the move, N·m (N).
    pub peak_effort: f64,
    /// The unit of the excursions (`″`, `µm`).
    pub unit: &'static str,
}

/// Within this many report units (20″, 20 µm) the step has settled.
pub const SETTLED: f64 = 20.0;

/// The step and the out-and-back move of `p` on the nonlinear model.
pub fn responses(p: &Params) -> Result<Responses, SimError> {
    responses_with(p, &Compensation::default())
}

/// The same with the controller's compensations `c` on.
pub fn responses_with(p: &Params, c: &Compensation) -> Result<Responses, SimError> {
    let u = ReportUnits::of(p.axis);
    let k = u.deviation_per_si;
    let (step, speed) = match p.axis {
        Axis::Rotary => (1f64.to_radians(), 10f64.to_radians()),
        Axis::Linear => (1e-3, 10e-3),
    };
    let samples = run(p, c, &[(0.0, step, None, 1.0)])?;
    let peak_step = samples.iter().map(|s| s.1).fold(f64::MIN, f64::max);
    let settled = samples
        .iter()
        .rev()
        .find(|s| (s.1 - step).abs() * k > SETTLED)
        .map(|s| s.0);
    let leg = 5.0 * step / speed;
    let out_and_back = run(
        p,
        c,
        &[
            (0.0, 5.0 * step, Some(speed), leg),
            (5.0 * step, 0.0, Some(speed), leg),
        ],
    )?;
    let (following, spike) = following_errors(&out_and_back, leg);
    let peak = samples
        .iter()
        .chain(&out_and_back)
        .map(|s| s.3.abs())
        .fold(0.0, f64::max);
    Ok(Responses {
        step: step * u.target_per_si,
        step_overshoot_percent: ((peak_step / step - 1.0) * 100.0).max(0.0),
        step_settling_s: match settled {
            Some(t) if t >= 1.0 - 1e-9 => None,
            Some(t) => Some(t),
            None => Some(0.0),
        },
        following_error: following * k,
        reversal_spike: spike * k,
        peak_effort: peak,
        unit: u.deviation,
    })
}

/// (t, position, reference, effort) every step.
type Sample = (f64, f64, f64, f64);

/// Runs the moves (from, to, speed, duration) one after the other from rest.
fn run(
    p: &Params,
    c: &Compensation,
    moves: &[(f64, f64, Option<f64>, f64)],
) -> Result<Vec<Sample>, SimError> {
    let mut sim = Simulation::with_default_step(p)?;
    let mut controller = sim.controller(p)?;
    controller.set_compensation(c.clone());
    let mut out = Vec::new();
    for &(from, to, speed, duration) in moves {
        let m = Move { from, to, speed };
        let t0 = sim.time();
        let reference = |t: f64| m.angle(t - t0);
        let mut trace = Trace::every(1);
        sim.run_closed_loop(&mut controller, &reference, duration, &mut trace)?;
        out.extend(trace.samples.iter().map(|s| {
            (
                s.t,
                s.y[THETA_M] * p.ratio(),
                reference(s.t),
                s.motor_torque,
            )
        }));
    }
    Ok(out)
}

/// The largest following error on the second half of the first leg, and the spike:
/// the largest error on the second leg less its own second half's largest.
fn following_errors(samples: &[Sample], leg: f64) -> (f64, f64) {
    let error = |s: &Sample| (s.2 - s.1).abs();
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
