//! Running the torque test on the model: the servo follows the harmonic command, every
//! `sample`-th step recorded after the run-in; and the model's torque on a recorded
//! curve's time base, the model side of a friction fit.

use super::{interpolate, TorqueCurve, TorqueTest};
use crate::model::idx::THETA_T;
use crate::model::params::Params;
use crate::model::NSTATE;
use crate::recorder::{NullRecorder, Recorder};
use crate::sim::{SimError, Simulation};

/// Keeps every `every`-th step into pre-reserved vectors; the sample's time is its
/// index times the sample interval (exact, restarted at 0).
struct EveryNth {
    every: u64,
    count: u64,
    interval: f64,
    curve: TorqueCurve,
}

impl EveryNth {
    fn new(every: u64, interval: f64, capacity: usize) -> Self {
        EveryNth {
            every,
            count: 0,
            interval,
            curve: TorqueCurve {
                time: Vec::with_capacity(capacity),
                motor_torque: Vec::with_capacity(capacity),
                table_angle: Vec::with_capacity(capacity),
            },
        }
    }
}

impl Recorder for EveryNth {
    #[inline]
    fn record(&mut self, _t: f64, y: &[f64; NSTATE], motor_torque: f64) {
        if self.count % self.every == 0 {
            let c = &mut self.curve;
            c.time
                .push((self.count / self.every) as f64 * self.interval);
            c.motor_torque.push(motor_torque);
            c.table_angle.push(y[THETA_T]);
        }
        self.count += 1;
    }
}

/// Runs the test on the model: run-in, then `duration` seconds recorded.
/// `progress(done, total)` counts periods (run-in included).
fn simulate(
    params: &Params,
    test: &TorqueTest,
    duration: f64,
    mut progress: impl FnMut(usize, usize),
) -> Result<TorqueCurve, SimError> {
    let mut p = params.clone();
    p.controller.loop_mode = test.loop_mode;
    let mut sim = Simulation::with_default_step(&p)?;
    let mut controller = sim.controller(&p)?;
    let reference = test.trajectory();
    let dt = sim.dt();
    let every = (test.sample / dt).round().max(1.0) as u64;
    let interval = every as f64 * dt;
    let samples = (duration / interval + 1e-9).floor() as usize + 1;
    let per_period = ((test.period / dt).round() as u64).max(1);
    let mut left_steps = (samples as u64 - 1) * every;
    let total =
        test.run_in_periods.max(0.0).ceil() as usize + left_steps.div_ceil(per_period) as usize;
    let mut done = 0;
    // Run-in, a period at a time.
    let mut left = test.run_in_periods * test.period;
    while left > 0.5 * dt {
        let span = left.min(test.period);
        sim.run_closed_loop(&mut controller, &reference, span, &mut NullRecorder)?;
        left -= span;
        done += 1;
        progress(done.min(total), total);
    }
    let mut rec = EveryNth::new(every, interval, samples);
    // The sample at the end of the run-in: the torque held over its last step.
    rec.record(sim.time(), &sim.state(), controller.torque());
    while left_steps > 0 {
        let n = left_steps.min(per_period);
        sim.run_closed_loop(&mut controller, &reference, n as f64 * dt, &mut rec)?;
        left_steps -= n;
        done += 1;
        progress(done.min(total), total);
    }
    Ok(rec.curve)
}

/// Runs the test on the model. `progress(done, total)` is called after each period.
pub fn run(
    params: &Params,
    test: &TorqueTest,
    progress: impl FnMut(usize, usize),
) -> Result<TorqueCurve, SimError> {
    simulate(params, test, test.duration(), progress)
}

/// The motor torque of the test on the model at `times` (s after the run-in, as in a
/// recorded file), linearly interpolated between the recorded samples; times before 0
/// give the first sample. `test.periods` is ignored: the run lasts to the last time.
/// At the recorded times it reproduces [`run`]'s torque exactly.
pub fn simulate_torque(
    params: &Params,
    conditions: &TorqueTest,
    times: &[f64],
) -> Result<Vec<f64>, SimError> {
    let end = times
        .iter()
        .copied()
        .filter(|t| t.is_finite())
        .fold(0.0, f64::max);
    // One sample beyond the last time, so it always lies inside the record.
    let curve = simulate(params, conditions, end + conditions.sample, |_, _| {})?;
    Ok(times
        .iter()
        .map(|&t| interpolate(&curve.time, &curve.motor_torque, t))
        .collect())
}
