//! Running the torque test on the model: the servo follows the harmonic command, every
//! `sample`-th step recorded after the run-in; and the model's torque on a recorded
//! curve's time base, the model side of a friction fit.

use super::{interpolate, TorqueCurve, TorqueTest};
use crate::model::idx::THETA_T;
use crate::model::params::Params;
use crate::model::NSTATE;
use crate::recorder::{NullRecorder, Recorder};
use crate::sim::batch::{in_lanes, LaneRun};
use crate::sim::{common_step, LaneSimulation, SimError};

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

/// Runs the test on `L` models at once (`params`, with the test's loop mode):
/// run-in, then `duration` seconds recorded, lane `l` as a lone run of `params[l]`
/// computes it (a set that diverges fails alone). `progress(done, total)` counts
/// periods (run-in included).
fn simulate_lanes<const L: usize>(
    params: &[Params; L],
    test: &TorqueTest,
    duration: f64,
    mut progress: impl FnMut(usize, usize),
) -> Result<[Result<TorqueCurve, SimError>; L], SimError> {
    let dt = common_step(params)?;
    let mut sim = LaneSimulation::<L>::of(params, dt)?;
    let mut controllers = sim.controllers(params)?;
    let reference = test.trajectory();
    let every = (test.sample / dt).round().max(1.0) as u64;
    let interval = every as f64 * dt;
    let samples = (duration / interval + 1e-9).floor() as usize + 1;
    let per_period = ((test.period / dt).round() as u64).max(1);
    let mut left_steps = (samples as u64 - 1) * every;
    let total =
        test.run_in_periods.max(0.0).ceil() as usize + left_steps.div_ceil(per_period) as usize;
    let mut done = 0;
    let mut failed: [Option<SimError>; L] = std::array::from_fn(|_| None);
    // Run-in, a period at a time.
    let mut left = test.run_in_periods * test.period;
    let mut null: [NullRecorder; L] = std::array::from_fn(|_| NullRecorder);
    while left > 0.5 * dt {
        let span = left.min(test.period);
        sim.run_closed_loop((&mut controllers, &mut null), &reference, span, &mut failed)?;
        left -= span;
        done += 1;
        progress(done.min(total), total);
    }
    let mut rec: [EveryNth; L] = std::array::from_fn(|_| EveryNth::new(every, interval, samples));
    // The sample at the end of the run-in: the torque held over its last step.
    for (l, r) in rec.iter_mut().enumerate() {
        r.record(sim.time(l), &sim.state(l), controllers[l].torque());
    }
    while left_steps > 0 {
        let n = left_steps.min(per_period);
        let run = (&mut controllers, &mut rec);
        sim.run_closed_loop(run, &reference, n as f64 * dt, &mut failed)?;
        left_steps -= n;
        done += 1;
        progress(done.min(total), total);
    }
    let mut rec = rec.into_iter();
    Ok(failed.map(|f| {
        let curve = rec.next().expect("one per lane").curve;
        f.map_or(Ok(curve), Err)
    }))
}

/// `params` with the test's feedback arrangement.
fn test_params(params: &Params, test: &TorqueTest) -> Params {
    let mut p = params.clone();
    p.controller.loop_mode = test.loop_mode;
    p
}

/// Runs the test on the model. `progress(done, total)` is called after each period.
pub fn run(
    params: &Params,
    test: &TorqueTest,
    progress: impl FnMut(usize, usize),
) -> Result<TorqueCurve, SimError> {
    let [one] = simulate_lanes(
        &[test_params(params, test)],
        test,
        test.duration(),
        progress,
    )?;
    one
}

/// [`run`] on each of `params`, in order, in the kernel's lanes where the sets can
/// share them (`sim::batch`): each curve is what `run` gives for its set alone.
pub fn run_batch(params: &[Params], test: &TorqueTest) -> Vec<Result<TorqueCurve, SimError>> {
    let sets: Vec<Params> = params.iter().map(|p| test_params(p, test)).collect();
    in_lanes(&sets, &Curves(test))
}

/// The whole test, for `sim::batch`.
struct Curves<'a>(&'a TorqueTest);

impl LaneRun for Curves<'_> {
    type Out = TorqueCurve;

    fn lone(&self, p: &Params) -> Result<TorqueCurve, SimError> {
        let [one] = self.lanes(std::array::from_ref(p))?;
        one
    }

    fn lanes<const L: usize>(
        &self,
        params: &[Params; L],
    ) -> Result<[Result<TorqueCurve, SimError>; L], SimError> {
        simulate_lanes(params, self.0, self.0.duration(), |_, _| {})
    }
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
    TorqueAt::new(conditions, times).lone(&test_params(params, conditions))
}

/// [`simulate_torque`] for each of `params`, in order, in the kernel's lanes where
/// the sets can share them (`sim::batch`): each result is what `simulate_torque`
/// gives for its set alone.
pub fn simulate_torque_batch(
    params: &[Params],
    conditions: &TorqueTest,
    times: &[f64],
) -> Vec<Result<Vec<f64>, SimError>> {
    let sets: Vec<Params> = params.iter().map(|p| test_params(p, conditions)).collect();
    in_lanes(&sets, &TorqueAt::new(conditions, times))
}

/// The model's torque at given times: the test run to the last of them.
struct TorqueAt<'a> {
    test: &'a TorqueTest,
    times: &'a [f64],
    duration: f64,
}

impl<'a> TorqueAt<'a> {
    fn new(test: &'a TorqueTest, times: &'a [f64]) -> Self {
        let end = times
            .iter()
            .copied()
            .filter(|t| t.is_finite())
            .fold(0.0, f64::max);
        // One sample beyond the last time, so it always lies inside the record.
        TorqueAt {
            test,
            times,
            duration: end + test.sample,
        }
    }

    fn at_times(&self, curve: TorqueCurve) -> Vec<f64> {
        self.times
            .iter()
            .map(|&t| interpolate(&curve.time, &curve.motor_torque, t))
            .collect()
    }
}

impl LaneRun for TorqueAt<'_> {
    type Out = Vec<f64>;

    fn lone(&self, p: &Params) -> Result<Vec<f64>, SimError> {
        let [one] = self.lanes(std::slice::from_ref(p).try_into().expect("one set"))?;
        one
    }

    fn lanes<const L: usize>(
        &self,
        params: &[Params; L],
    ) -> Result<[Result<Vec<f64>, SimError>; L], SimError> {
        let curves = simulate_lanes(params, self.test, self.duration, |_, _| {})?;
        Ok(curves.map(|c| c.map(|c| self.at_times(c))))
    }
}
